//! The output rows of a mechanism's solve: the standard and requested outputs, the joints'
//! reactions, the constraint error, with the energy and constraint-error figures of the
//! summary gathered on the way.

use super::formulation::RowEval;
use super::reactions::{Multipliers, ReactionEval, StateMultipliers};
use crate::dae::MechanicsTapes;
use crate::mech::MultibodySystem;

/// The columns of a mechanism's rows (without `t`): the standard and requested outputs, every
/// joint's reaction columns when asked for (`"outputs": ["reactions"]`), every driver's
/// columns (`<name>.torque|force`, `<name>.power`), then
/// `constraint_error` (always written: cheap and always meaningful).
pub fn output_columns(sys: &MultibodySystem) -> Vec<String> {
    let mut columns: Vec<String> = sys.outputs.iter().map(|o| o.name.clone()).collect();
    if sys.reaction_outputs {
        columns.extend(sys.reaction_columns());
    } else {
        columns.extend(sys.driver_columns());
    }
    columns.push("constraint_error".into());
    columns
}

/// Evaluates output rows from states `[q, v]`.
pub(crate) struct OutputEval {
    tapes: MechanicsTapes,
    columns: Vec<String>,
    unwrap: Vec<bool>,
    /// Output indices of each spatial body's `(ψ, θ, φ)`.
    cardan: Vec<[usize; 3]>,
    want_constraint_error: bool,
    /// Joint reaction columns (`"outputs": ["reactions"]`) and the drivers' columns after them,
    /// written before `constraint_error`.
    reactions: Option<ReactionEval>,
    vars: Vec<f64>,
    work: Vec<f64>,
    work_g: Vec<f64>,
    out: Vec<f64>,
    g: Vec<f64>,
    energy0: Option<f64>,
    energy_dev: f64,
    kinetic_max: f64,
    max_g: f64,
    prev: Option<Vec<f64>>,
    /// Why energy is not conserved (from the system), if it is not.
    energy_exchange: Option<String>,
    /// The row positions of the drivers' `<name>.power` columns.
    power_columns: Vec<usize>,
    /// The drivers' work so far and the last row's `(t, Σ P)`.
    driver_work: (f64, Option<(f64, f64)>),
    /// The rows the work was summed over and their largest spacing (s).
    driver_rows: (usize, f64),
}

impl OutputEval {
    /// The evaluator of [`output_columns`]; the reactions (when asked for) read their
    /// constraint forces from `multipliers`.
    pub(crate) fn new(
        sys: impl std::borrow::Borrow<MultibodySystem>,
        tapes: MechanicsTapes,
        multipliers: &Multipliers,
    ) -> Self {
        let sys = sys.borrow();
        let columns = output_columns(sys);
        let unwrap = sys.outputs.iter().map(|o| o.unwrap).collect();
        let at = |n: String| columns.iter().position(|c| *c == n);
        let cardan = columns
            .iter()
            .filter_map(|c| c.strip_suffix(".psi"))
            .filter_map(|b| {
                Some([
                    at(format!("{b}.psi"))?,
                    at(format!("{b}.theta"))?,
                    at(format!("{b}.phi"))?,
                ])
            })
            .collect();
        // the joints' reactions and the drivers' efforts, one evaluator: from the multipliers
        // solved at the row's state (`[M G_vᵀ; G_v 0] [v'; λ] = [Q; −γ]`, the dynamics of the
        // motion the row holds, as every formulation's row state `[q, v]` is exact at the row:
        // never IDA's interpolant of λ, which its error test leaves out — a DOF-0 run's steps
        // are long) or, in the twin, from its joint springs
        let reactions = (sys.reaction_outputs || !sys.drivers.is_empty()).then(|| {
            let source = match multipliers {
                Multipliers::Springs(_) => multipliers.clone(),
                _ => Multipliers::FromState(Box::new(StateMultipliers::new(
                    tapes.forces.clone(),
                    tapes.gamma.clone(),
                    sys.mass.clone(),
                ))),
            };
            ReactionEval::new(sys, &tapes.gv, source, (sys.reaction_outputs, true))
        });
        let n_out = tapes.outputs.n_outputs();
        let nc = tapes.dims.2;
        OutputEval {
            work: tapes.outputs.workspace(),
            work_g: tapes.g.workspace(),
            vars: vec![0.0; 1 + tapes.dims.0 + tapes.dims.1],
            out: vec![0.0; n_out],
            g: vec![0.0; nc],
            tapes,
            columns: columns.clone(),
            unwrap,
            cardan,
            want_constraint_error: true,
            reactions,
            energy0: None,
            energy_dev: 0.0,
            kinetic_max: 0.0,
            max_g: 0.0,
            prev: None,
            energy_exchange: sys.energy_exchange.clone(),
            power_columns: sys
                .drivers
                .iter()
                .filter_map(|d| columns.iter().position(|c| *c == d.columns()[1]))
                .collect(),
            driver_work: (0.0, None),
            driver_rows: (0, 0.0),
        }
    }

    /// The row at `(t, x)`; `x` is the solver's state vector, `[q, v]` followed by the
    /// formulation's own unknowns (where the reactions read their multipliers).
    fn row(&mut self, t: f64, x: &[f64]) -> Vec<f64> {
        self.vars[0] = t;
        let n = self.vars.len() - 1;
        self.vars[1..].copy_from_slice(&x[..n]);
        // the work buffers are these tapes' own (constants in place)
        self.tapes
            .outputs
            .eval_prepared(&self.vars, &mut self.work, &mut self.out);
        self.tapes
            .g
            .eval_prepared(&self.vars, &mut self.work_g, &mut self.g);
        let k = self.out.len();
        let (energy, kinetic) = (self.out[k - 2], self.out[k - 1]);
        let e0 = *self.energy0.get_or_insert(energy);
        self.energy_dev = self.energy_dev.max((energy - e0).abs());
        self.kinetic_max = self.kinetic_max.max(kinetic.abs());
        let ge = self.g.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        self.max_g = self.max_g.max(ge);
        let mut row: Vec<f64> = self.out[..k - 2].to_vec();
        // continuous angles: add the multiple of 2π closest to the previous value; a Cardan
        // triple may also switch to its twin (ψ + π, π − θ, φ + π), the same attitude, so that
        // θ passes ±π/2 continuously instead of ψ and φ jumping by π
        if let Some(prev) = &self.prev {
            let near = |a: f64, p: f64| {
                a - ((a - p) / std::f64::consts::TAU).round() * std::f64::consts::TAU
            };
            for &[i, j, k] in &self.cardan {
                let pi = std::f64::consts::PI;
                let dist = |a: f64, b: f64, c: f64| {
                    (near(a, prev[i]) - prev[i]).powi(2)
                        + (near(b, prev[j]) - prev[j]).powi(2)
                        + (near(c, prev[k]) - prev[k]).powi(2)
                };
                let (a, b, c) = (row[i] + pi, pi - row[j], row[k] + pi);
                if dist(a, b, c) < dist(row[i], row[j], row[k]) {
                    (row[i], row[j], row[k]) = (a, b, c);
                }
                row[j] = near(row[j], prev[j]);
            }
            for (i, u) in self.unwrap.iter().enumerate() {
                if *u {
                    let d = row[i] - prev[i];
                    row[i] -= (d / std::f64::consts::TAU).round() * std::f64::consts::TAU;
                }
            }
        }
        match &mut self.prev {
            Some(p) => p.clone_from(&row),
            None => self.prev = Some(row.clone()),
        }
        if let Some(r) = &mut self.reactions {
            let at = row.len();
            row.resize(at + r.n_columns, 0.0);
            r.eval(t, x, &mut row[at..]);
        }
        if self.want_constraint_error {
            row.push(ge);
        }
        if !self.power_columns.is_empty() {
            let p: f64 = self.power_columns.iter().map(|&k| row[k]).sum();
            let (w, last) = &mut self.driver_work;
            if let Some((t0, p0)) = *last {
                *w += 0.5 * (t - t0) * (p + p0);
                self.driver_rows.1 = self.driver_rows.1.max(t - t0);
            }
            self.driver_rows.0 += 1;
            *last = Some((t, p));
        }
        row
    }

    fn energy_drift(&self) -> f64 {
        let scale = self.energy0.unwrap_or(0.0).abs().max(self.kinetic_max);
        if scale > 0.0 {
            self.energy_dev / scale
        } else {
            self.energy_dev
        }
    }
}

impl RowEval for OutputEval {
    fn columns(&self) -> Vec<String> {
        self.columns.clone()
    }
    fn row(&mut self, t: f64, x: &[f64]) -> Vec<f64> {
        OutputEval::row(self, t, x)
    }
    fn max_constraint_error(&self) -> f64 {
        self.max_g
    }
    fn energy_drift(&self) -> f64 {
        OutputEval::energy_drift(self)
    }
    fn energy_exchange(&self) -> Option<String> {
        self.energy_exchange.clone()
    }
    fn driver_work(&self) -> Option<f64> {
        (!self.power_columns.is_empty()).then_some(self.driver_work.0)
    }
    fn driver_work_note(&self) -> String {
        if self.power_columns.is_empty() {
            return String::new();
        }
        let (n, h) = self.driver_rows;
        format!(
            "the trapezoidal rule on the {n} rows' <driver>.power (largest spacing {h:e} s): its error is O(h²) in the output spacing (a smooth power's, h² T max|P''| / 12), not the solver's; a finer output_step makes it smaller"
        )
    }
}
