//! Joint reactions and event functions evaluated along a solve.
//!
//! [`ReactionEval`] turns a solver state into every joint's reaction columns through the one
//! mapping of [`crate::mech::reactions`]: the constraint forces come from the DAE's multipliers
//! λ (GGL, compliant GGL, index 1: unknowns of the residual) or from the twin's joint
//! spring-dampers `k g + c G_v v` ([`crate::solve::formulation::DecoupledFormulation::row_force`]).
//! [`EventEval`] evaluates the scene's event functions over `[t, q, v, reactions]`.

use crate::dae::mechanics::MatrixTape;
use crate::expr::{Expr, Tape};
use crate::mech::{EventFunction, JointReaction, MultibodySystem};
use crate::sundials::{CallbackError, CallbackResult};

/// Where the constraint forces of a formulation are.
#[derive(Clone, Debug)]
pub(crate) enum Multipliers {
    /// λ are the solver unknowns `y[offset .. offset + nc]`.
    Unknowns(usize),
    /// The decoupled twin: the row forces, a tape over `[t, q, v]`.
    Springs(Tape),
    /// Solved from the state `(t, q, v)`: `[M G_vᵀ; G_v 0] [v'; λ] = [Q; −γ]` (least-norm λ
    /// where the joints are redundant). IDA leaves the multipliers out of its error test, so
    /// between its steps (where its root finding interpolates) their interpolant is not
    /// error-controlled, while that of `q` and `v` is: an event on a joint force is then
    /// located as accurately as the motion (measured on the falling bar of `tests/events.rs`
    /// at rtol 1e-10, GGL: sin²φ at the event 1.4e-8 off with the interpolated λ, 3.8e-10 with
    /// the solved one).
    FromState(Box<StateMultipliers>),
}

/// What [`Multipliers::FromState`] solves λ with.
#[derive(Clone, Debug)]
pub(crate) struct StateMultipliers {
    /// `Q(t, q, v)`.
    forces: Tape,
    /// `γ(t, q, v)`.
    gamma: Tape,
    /// The diagonal of `M`.
    mass: Vec<f64>,
    /// Scratch (no allocation per evaluation: events read it at every step): the tapes'
    /// workspaces and values, the system `[M G_vᵀ; G_v 0]` and its right-hand side, the pivots.
    scratch: SaddleScratch,
}

#[derive(Clone, Debug, Default)]
struct SaddleScratch {
    forces_work: Vec<f64>,
    forces: Vec<f64>,
    gamma_work: Vec<f64>,
    gamma: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    pivots: Vec<usize>,
}

impl StateMultipliers {
    /// The multipliers' source from the tapes of `Q` and `γ` and the diagonal of `M`.
    pub(crate) fn new(forces: Tape, gamma: Tape, mass: Vec<f64>) -> Self {
        let n = mass.len() + gamma.n_outputs();
        let scratch = SaddleScratch {
            forces_work: forces.workspace(),
            forces: vec![0.0; forces.n_outputs()],
            gamma_work: gamma.workspace(),
            gamma: vec![0.0; gamma.n_outputs()],
            a: vec![0.0; n * n],
            b: vec![0.0; n],
            pivots: vec![0; n],
        };
        StateMultipliers {
            forces,
            gamma,
            mass,
            scratch,
        }
    }

    /// Solves λ at `vars = [t, q, v]` from `M v' + G_vᵀ λ = Q`, `G_v v' = −γ`
    /// ([`crate::dae::init::dynamics_system`]) into `lambda`; `gv` is `G_v` row-major. Where the
    /// system is singular (redundant joints) the least-squares λ is taken.
    fn solve(&mut self, vars: &[f64], gv: &[f64], lambda: &mut [f64]) {
        let s = &mut self.scratch;
        let (nv, nc) = (self.mass.len(), lambda.len());
        let n = nv + nc;
        self.forces.eval(vars, &mut s.forces_work, &mut s.forces);
        self.gamma.eval(vars, &mut s.gamma_work, &mut s.gamma);
        let gv_at = |i: usize, j: usize| gv[i * nv + j];
        let (a, b) = (&mut s.a, &mut s.b);
        crate::dae::init::dynamics_system(&self.mass, gv_at, (&s.forces, &s.gamma), a, b);
        if crate::sundials::dense_lu::factor(a, n, &mut s.pivots) == 0 {
            crate::sundials::dense_lu::solve(a, n, &s.pivots, b);
            lambda.copy_from_slice(&b[nv..]);
            return;
        }
        // singular (redundant joints): the least-squares multipliers, rebuilt (factor
        // overwrote `a`); rare, so it may allocate
        crate::dae::init::dynamics_system(&self.mass, gv_at, (&s.forces, &s.gamma), a, b);
        let am = nalgebra::DMatrix::from_column_slice(n, n, a);
        let tol = 1e-12 * am.norm();
        if let Ok(x) = am
            .svd(true, true)
            .solve(&nalgebra::DVector::from_column_slice(b), tol)
        {
            lambda.copy_from_slice(&x.as_slice()[nv..]);
        }
    }
}

/// Evaluates every joint's reaction columns from a solver state.
#[derive(Clone, Debug)]
pub(crate) struct ReactionEval {
    joints: Vec<JointReaction>,
    /// Each driver's constraint row: its effort is `−λ_row`, its power the effort times the
    /// prescribed rate `ṡ(t)` (the tape's outputs after the joints').
    drivers: Vec<usize>,
    /// `B` then the lever of every joint, concatenated, over `[t, q, v]`.
    tape: Tape,
    gv: MatrixTape,
    source: Multipliers,
    dims: (usize, usize, usize),
    vars: Vec<f64>,
    work: Vec<f64>,
    vals: Vec<f64>,
    gv_work: (Vec<f64>, Vec<f64>),
    gv_vals: Vec<f64>,
    lambda: Vec<f64>,
    lambda_work: Vec<f64>,
    /// Total number of reaction columns.
    pub n_columns: usize,
}

impl ReactionEval {
    /// Compiles the evaluator; `gv` is the tape of `G_v` (`nc × nv`); `joints`, `drivers`:
    /// whether the joints' reaction columns and the drivers' columns (after them) are written.
    pub(crate) fn new(
        sys: &MultibodySystem,
        gv: &MatrixTape,
        source: Multipliers,
        (joints, drivers): (bool, bool),
    ) -> Self {
        let driver_list: Vec<crate::mech::DriverOutput> = if drivers {
            sys.drivers.clone()
        } else {
            Vec::new()
        };
        let reactions: Vec<JointReaction> = if joints {
            sys.reactions.clone()
        } else {
            Vec::new()
        };
        let mut exprs: Vec<Expr> = reactions
            .iter()
            .flat_map(|r| r.basis.iter().chain(&r.lever).copied())
            .collect();
        exprs.extend(driver_list.iter().map(|d| d.rate));
        let tape = sys.graph.compile(&exprs);
        let lambda_work = match &source {
            Multipliers::Springs(t) => t.workspace(),
            Multipliers::Unknowns(_) | Multipliers::FromState(_) => Vec::new(),
        };
        ReactionEval {
            n_columns: reactions.iter().map(|r| r.n_columns()).sum::<usize>()
                + 2 * driver_list.len(),
            joints: reactions,
            drivers: driver_list.iter().map(|d| d.row).collect(),
            work: tape.workspace(),
            vals: vec![0.0; tape.n_outputs()],
            gv_work: gv.workspace(),
            gv_vals: vec![0.0; gv.rows * gv.cols],
            tape,
            gv: gv.clone(),
            source,
            dims: (sys.nq(), sys.nv(), sys.nc()),
            vars: vec![0.0; 1 + sys.nq() + sys.nv()],
            lambda: vec![0.0; sys.nc()],
            lambda_work,
        }
    }

    /// Writes the reaction columns at `(t, y)` to `out` (`y` is the solver's state vector:
    /// `[q, v, …]`, with the multipliers where [`Multipliers`] says).
    pub(crate) fn eval(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        let (nq, nv, nc) = self.dims;
        self.vars[0] = t;
        self.vars[1..].copy_from_slice(&y[..nq + nv]);
        self.tape.eval(&self.vars, &mut self.work, &mut self.vals);
        self.gv
            .eval_into(&self.vars, &mut self.gv_work, &mut self.gv_vals);
        match &mut self.source {
            Multipliers::Unknowns(off) => self.lambda.copy_from_slice(&y[*off..*off + nc]),
            Multipliers::Springs(tape) => {
                tape.eval(&self.vars, &mut self.lambda_work, &mut self.lambda)
            }
            Multipliers::FromState(m) => m.solve(&self.vars, &self.gv_vals, &mut self.lambda),
        }
        let (mut at, mut col) = (0, 0);
        for j in &self.joints {
            let nb = j.basis.len();
            let nl = j.lever.len();
            let basis = &self.vals[at..at + nb];
            let lever = &self.vals[at + nb..at + nb + nl];
            let n = j.n_columns();
            j.wrench(
                basis,
                lever,
                &self.gv_vals,
                nv,
                &self.lambda,
                &mut out[col..col + n],
            );
            at += nb + nl;
            col += n;
        }
        for (k, &row) in self.drivers.iter().enumerate() {
            let effort = -self.lambda[row];
            out[col] = effort;
            out[col + 1] = effort * self.vals[at + k];
            col += 2;
        }
    }
}

/// Evaluates the scene's event functions `[t, q, v, reactions] → g_i`.
#[derive(Clone, Debug)]
pub(crate) struct EventEval {
    tape: Tape,
    reactions: Option<ReactionEval>,
    vars: Vec<f64>,
    work: Vec<f64>,
    n_state: usize,
    /// `(name, when)` of each event, for messages.
    sources: Vec<(String, String)>,
}

impl EventEval {
    /// Compiles the event functions; the reactions are evaluated only when an event uses them.
    pub(crate) fn new(sys: &MultibodySystem, reactions: impl FnOnce() -> ReactionEval) -> Self {
        let exprs: Vec<Expr> = sys.events.iter().map(|e| e.expr).collect();
        let tape = sys.graph.compile(&exprs);
        let uses = sys.events.iter().any(|e: &EventFunction| e.uses_reactions);
        let n_state = 1 + sys.nq() + sys.nv();
        let reactions = uses.then(reactions);
        let n_reactions = reactions.as_ref().map_or(0, |r| r.n_columns);
        let n_vars = (n_state + n_reactions).max(tape.n_vars());
        EventEval {
            work: tape.workspace(),
            tape,
            reactions,
            vars: vec![0.0; n_vars],
            n_state,
            sources: sys
                .events
                .iter()
                .map(|e| (e.name.clone(), e.when.clone()))
                .collect(),
        }
    }

    /// Some event function reads reaction columns (its state needs the multipliers).
    pub(crate) fn uses_reactions(&self) -> bool {
        self.reactions.is_some()
    }

    /// Number of event functions.
    pub(crate) fn len(&self) -> usize {
        self.tape.n_outputs()
    }

    /// The event functions at `(t, y)` into `out`, as a root-function callback: a value that
    /// is not finite stops the solve with a message naming the event's JSON path.
    pub(crate) fn roots(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> CallbackResult {
        self.eval(t, y, out);
        match out.iter().position(|v| !v.is_finite()) {
            None => Ok(()),
            Some(i) => Err(CallbackError::Fatal(format!(
                "events[{i}].when: event '{}' evaluates to {} (\"{}\")",
                self.sources[i].0, out[i], self.sources[i].1
            ))),
        }
    }

    /// The event functions at `(t, y)` into `out`.
    pub(crate) fn eval(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        let n = self.n_state;
        self.vars[0] = t;
        self.vars[1..n].copy_from_slice(&y[..n - 1]);
        if let Some(r) = &mut self.reactions {
            let nr = r.n_columns;
            r.eval(t, y, &mut self.vars[n..n + nr]);
        }
        self.tape.eval(&self.vars, &mut self.work, out);
    }
}
