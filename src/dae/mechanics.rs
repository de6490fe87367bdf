//! The constraint calculus every formulation shares, derived once from a [`MultibodySystem`]:
//!
//! * `g(q)` and `G_q = ∂g/∂q` (position level),
//! * `G_v v = G_q K(q) v` and `G_v = ∂(G_v v)/∂v` (velocity level, the flows that the
//!   differential-causality inertias receive from the junction structure),
//! * `γ = ∂(G_v v)/∂q · K(q) v`, so that the acceleration-level constraint reads `G_v v' + γ = 0`,
//!
//! plus numeric tapes of all of them for initialisation, diagnostics and outputs.

use crate::expr::{Expr, Tape};
use crate::mech::MultibodySystem;

/// Symbolic constraint quantities (see the module documentation).
#[derive(Clone, Debug)]
pub struct ConstraintExprs {
    /// `g(q)`.
    pub g: Vec<Expr>,
    /// `∂g/∂q`, `nc × nq`.
    pub gq: Vec<Vec<Expr>>,
    /// `G_v v`.
    pub gvv: Vec<Expr>,
    /// `G_v`, `nc × nv`.
    pub gv: Vec<Vec<Expr>>,
    /// `γ`.
    pub gamma: Vec<Expr>,
}

impl ConstraintExprs {
    /// Derives every constraint quantity from the system's `g` and `K`.
    pub fn derive(sys: &mut MultibodySystem) -> Self {
        let nq = sys.nq();
        let g = sys.constraints.clone();
        // the flows the bond graph's constraint junctions impose, or d/dt g
        let gvv = if sys.flow_rows.len() == g.len() && !g.is_empty() {
            sys.flow_rows.clone()
        } else {
            sys.velocity_constraints()
        };
        let gv = sys.velocity_jacobian(&gvv);
        let mut gq = Vec::with_capacity(g.len());
        for &gi in &g {
            let row = (0..nq)
                .map(|k| {
                    let s = sys.q_slot(k);
                    sys.graph.diff(gi, s)
                })
                .collect();
            gq.push(row);
        }
        let mut gamma = Vec::with_capacity(g.len());
        for &e in &gvv {
            let mut terms = Vec::new();
            for k in 0..nq {
                let s = sys.q_slot(k);
                if sys.graph.depends_on(e, s) {
                    let d = sys.graph.diff(e, s);
                    terms.push(sys.graph.mul(d, sys.kinematics[k]));
                }
            }
            gamma.push(sys.graph.sum(&terms));
        }
        ConstraintExprs {
            g,
            gq,
            gvv,
            gv,
            gamma,
        }
    }
}

/// Numeric tapes over the state layout `[t, q, v]`.
#[derive(Clone, Debug)]
pub struct MechanicsTapes {
    /// nq, nv, nc
    pub dims: (usize, usize, usize),
    /// `g(q)`
    pub g: Tape,
    /// `∂g/∂q`, row-major `nc × nq`
    pub gq: Tape,
    /// `G_v`, row-major `nc × nv`
    pub gv: Tape,
    /// `Q(t, q, v)`
    pub forces: Tape,
    /// `K(q) v`
    pub kinematics: Tape,
    /// `γ`
    pub gamma: Tape,
    /// output columns, then energy, then kinetic energy
    pub outputs: Tape,
}

impl MechanicsTapes {
    /// Compiles the numeric tapes; `extra_energy` (the decoupled twin's joint springs) is added
    /// to the mechanical energy.
    pub fn new(sys: &mut MultibodySystem, c: &ConstraintExprs, extra_energy: Option<Expr>) -> Self {
        let energy = match extra_energy {
            Some(e) => sys.graph.add(sys.energy, e),
            None => sys.energy,
        };
        let gr = &sys.graph;
        let flat = |m: &Vec<Vec<Expr>>| m.iter().flatten().copied().collect::<Vec<_>>();
        let mut outs: Vec<Expr> = sys
            .outputs
            .iter()
            .map(|o| if o.name == "energy" { energy } else { o.expr })
            .collect();
        outs.push(energy);
        outs.push(sys.kinetic);
        MechanicsTapes {
            dims: (sys.nq(), sys.nv(), sys.nc()),
            g: gr.compile(&c.g),
            gq: gr.compile(&flat(&c.gq)),
            gv: gr.compile(&flat(&c.gv)),
            forces: gr.compile(&sys.forces),
            kinematics: gr.compile(&sys.kinematics),
            gamma: gr.compile(&c.gamma),
            outputs: gr.compile(&outs),
        }
    }

    /// Evaluates a tape at `(t, x)` with `x = [q, v]` (allocating; for one-off use).
    pub fn eval(tape: &Tape, t: f64, x: &[f64]) -> Vec<f64> {
        let mut vars = Vec::with_capacity(1 + x.len());
        vars.push(t);
        vars.extend_from_slice(x);
        let mut work = tape.workspace();
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(&vars, &mut work, &mut out);
        out
    }
}
