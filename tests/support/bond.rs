//! Raw bond graphs from JSON values and their equations evaluated by the reference interpreter.

use bondmech::bond::equations::BondEquations;
use bondmech::bond::{assign_causality, BondGraph, RawBondGraph};
use serde_json::Value;

/// A validated graph from a JSON value (panics on invalid input: tests build valid graphs).
pub fn graph(v: Value) -> BondGraph {
    let raw: RawBondGraph = serde_json::from_value(v).unwrap();
    raw.to_graph().unwrap()
}

/// The equations of `g` under its SCAP causality.
pub fn eqs(g: &BondGraph) -> BondEquations {
    BondEquations::new(g, &assign_causality(g).unwrap()).unwrap()
}

/// Right-hand sides at `(t, y)` by the reference interpreter.
pub fn rhs_at(e: &BondEquations, t: f64, y: &[f64]) -> Vec<f64> {
    let mut vars = vec![t];
    vars.extend_from_slice(y);
    e.rhs.iter().map(|&r| e.graph.eval(r, &vars)).collect()
}

/// Deterministic pseudo-random numbers in `[lo, hi)`.
pub struct Lcg(pub u64);
impl Lcg {
    /// The next number in `[lo, hi)`.
    pub fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}
