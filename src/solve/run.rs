//! Running a formulation on IDA or CVODE: consistent start, output rows, statistics.
//!
//! The GGL runner handles singular configurations by itself: when plain GGL (ε = 0) fails with
//! a collapsing step (`IDA_CONV_FAIL`, `IDA_ERR_FAIL`) and `κ(G_v M⁺ G_vᵀ)` at its last accepted
//! step exceeds [`SINGULAR_CONDITION`], it restarts from the last output with the compliant GGL
//! (`g − εμ = 0`, `G_v v − ελ = 0`, ε = `1e-10 / m_ref` unless given) and records a
//! [`SingularPassage`] (time, joints, κ). Joints redundant everywhere use the compliant GGL from
//! the start.

mod partitioned;
pub use partitioned::MAX_SWITCHINGS_PER_OUTPUT;

use std::ops::ControlFlow;
use std::sync::Arc;

use cpu_time::ThreadTime;
use serde::Serialize;

use super::options::{FormulationKind, LinearSolverKind, SolveOptions};
use nalgebra::DMatrix;

use super::integrators::{make_cvode, make_ida, make_ida_schur};
use super::partition::CausalPartition;
use super::reactions::{EventEval, Multipliers, ReactionEval, StateMultipliers};
use crate::dae::{
    block_condition_bound, consistent_state, consistent_state_from, dependent_condition,
    joint_condition_number, joint_conditioning, select_dependent, ConsistentState, ConstraintExprs,
    DaeFormulation, DecoupledFormulation, GglDae, GglFormulation, Index1Formulation,
    MechanicsTapes,
};
use crate::mech::{EventFunction, MultibodySystem};
use crate::scene::EventAction;
use crate::sundials::{CvodeOptions, Ida, SolverError, SolverStats, StepEvent};
use crate::Error;

/// Statistics and quality figures of one solve (the `--summary` JSON).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// `ggl`, `compliant_ggl` or `decoupled`.
    pub formulation: String,
    /// `IDA` or `CVODE`.
    pub solver: String,
    /// The partition at the start, by element name (the `dae`, `index1` and `partitioned`
    /// formulations, and raw bond graphs): the integral-causality storages whose flows (the
    /// inertias) and displacements (the springs' capacitors) are the states, as
    /// `graph --causality` lists them in `states`.
    pub states: Vec<String>,
    /// The differential-causality inertias whose flows are dependent unknowns at the start (as
    /// `graph --causality` lists them in `differential[].element`).
    pub dependent: Vec<String>,
    /// Number of unknowns handed to the solver.
    pub unknowns: usize,
    /// Linear solver of the Newton iterations: `dense`, `faer` or `klu` (what `auto` chose).
    pub linear_solver: String,
    /// Internal steps.
    pub steps: u64,
    /// Residual (IDA) or right-hand side (CVODE) evaluations.
    pub residual_evals: u64,
    /// Jacobian evaluations.
    pub jacobian_evals: u64,
    /// Linear solver setups (factorisations).
    pub linear_setups: u64,
    /// Error test failures.
    pub error_test_failures: u64,
    /// Newton iterations.
    pub nonlinear_iterations: u64,
    /// Newton convergence failures.
    pub nonlinear_conv_failures: u64,
    /// Last step size.
    pub last_step: f64,
    /// CPU seconds of the integration (this thread; model building excluded).
    pub cpu_seconds: f64,
    /// CPU seconds spent building the model (scene → compiled tapes).
    pub build_cpu_seconds: f64,
    /// Largest |g(q)| at the output times (for the decoupled twin: the largest spring stretch).
    pub max_constraint_error: f64,
    /// `max |E(t) − E(0)| / max(|E(0)|, max T)` over the rows, reported only when the scene
    /// conserves energy (`energy_check` = `conserved`); `None` (JSON `null`) otherwise.
    pub energy_drift: Option<f64>,
    /// `conserved` (no dampers, no loads, no resistors or sources: `energy_drift` measures
    /// the integration's drift) or `not_conserved` (see `energy_note`).
    pub energy_check: String,
    /// Why energy is not conserved (the first damper, load, resistor or source that
    /// exchanges it), or empty.
    pub energy_note: String,
    /// Whether the solve reached its last output time.
    pub completed: bool,
    /// The time the integration reached (the last output time when `completed`).
    pub t_reached: f64,
    /// What stopped an incomplete solve: `max_steps`, `max_wall_seconds` or `solver_error`.
    pub stopped_by: Option<String>,
    /// ‖q − q₀‖ of the initial projection onto the joints.
    pub initial_position_correction: f64,
    /// ‖v − v₀‖ of the initial projection.
    pub initial_velocity_correction: f64,
    /// Joints found redundant at the start (linearly dependent rows).
    pub redundant_joints: Vec<String>,
    /// Compliance ε of the compliant GGL where it was used (0 when plain GGL did all the work).
    pub compliance: f64,
    /// Whether the compliant GGL was used at all (chosen, redundant joints, or singular passages).
    pub compliance_used: bool,
    /// Simulated time spent in the compliant GGL (s).
    pub compliant_time: f64,
    /// Singular passages met by the GGL: plain GGL failed near a rank-deficient `G_v` and the
    /// compliant GGL carried the motion through (the switch), and every later passage, found
    /// as a peak of `κ(G_v M⁺ G_vᵀ)` above [`PASSAGE_CONDITION`] at the output times.
    pub singular_passages: Vec<SingularPassage>,
    /// Times the index-1 formulation re-selected its dependent velocities.
    pub index1_reselections: u64,
    /// Times the partitioned formulation re-chose its dependent coordinates and velocities
    /// (its dependent block had degraded).
    pub partition_rechoices: u64,
    /// Zeros of the loads' switching functions the partitioned formulation stopped at (and
    /// mode corrections at outputs): each restarts its integrator on the other branch of a
    /// `max`, `min`, `abs`, `sign` or `select` (`expr::switches`).
    pub switchings: u64,
    /// Times the GGL re-chose the dependent velocities it leaves out of IDA's error test
    /// (including switches to and from keeping every velocity in it).
    pub ggl_error_test_reselections: u64,
    /// Integrator of the partitioned formulation (`adams`, `bdf` or `erk`; empty otherwise).
    pub integrator: String,
    /// Joint stiffness of the decoupled twin (0 otherwise).
    pub joint_stiffness: f64,
    /// Non-fatal remarks about the model.
    pub warnings: Vec<String>,
    /// Events met, in time order (`"events"` of the scene): name and time of each zero
    /// crossing that counted; a `stop` event is the last one.
    pub events: Vec<EventRecord>,
    /// GGL on IDA: the steps accepted after recovered Newton convergence or error test failures
    /// (time and counts), at most [`crate::sundials::MAX_LOGGED_FAILURES`]; empty for the
    /// other formulations.
    pub recovered_failures: Vec<crate::sundials::RecoveredFailure>,
}

/// One event met during a solve.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EventRecord {
    /// The event's name.
    pub name: String,
    /// Time of the zero crossing (located by the integrator's root finding).
    pub t: f64,
}

/// A solved trajectory: one row per output time.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Column names (without `t`).
    pub columns: Vec<String>,
    /// Output times.
    pub times: Vec<f64>,
    /// `rows[k][c]`: column `c` at `times[k]`.
    pub rows: Vec<Vec<f64>>,
    /// Statistics.
    pub summary: Summary,
}

impl Solution {
    /// The values of column `name` over time.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.columns.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| r[c]).collect())
    }

    /// The value of column `name` at output index `k`.
    pub fn value(&self, k: usize, name: &str) -> Option<f64> {
        let c = self.columns.iter().position(|n| n == name)?;
        self.rows.get(k).map(|r| r[c])
    }

    /// CSV text: header `t,<columns>`, one row per output time (written by the `csv` crate:
    /// a column name holding a comma or a quote is quoted per RFC 4180).
    pub fn to_csv(&self) -> String {
        let mut bytes = Vec::new();
        self.write_csv(&mut bytes)
            .expect("writing to memory does not fail");
        String::from_utf8(bytes).expect("CSV of UTF-8 names and numbers is UTF-8")
    }

    /// Writes [`Solution::to_csv`] to `w`, row by row.
    pub fn write_csv(&self, w: impl std::io::Write) -> std::io::Result<()> {
        let mut csv = crate::output::CsvRows::new(w, &self.columns)?;
        for (t, r) in self.times.iter().zip(&self.rows) {
            csv.row(*t, r)?;
        }
        csv.finish().map(drop)
    }
}

/// One output row handed to a streaming observer.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// Time.
    pub t: f64,
    /// Column values (same order as [`Solution::columns`]).
    pub values: &'a [f64],
}

/// The columns of a mechanism's rows (without `t`): the standard and requested outputs, every
/// joint's reaction columns when asked for (`"outputs": ["reactions"]`), then
/// `constraint_error` (always written: cheap and always meaningful).
pub fn output_columns(sys: &MultibodySystem) -> Vec<String> {
    let mut columns: Vec<String> = sys.outputs.iter().map(|o| o.name.clone()).collect();
    if sys.reaction_outputs {
        columns.extend(sys.reaction_columns());
    }
    columns.push("constraint_error".into());
    columns
}

/// Evaluates output rows from states `[q, v]`.
struct OutputEval {
    tapes: MechanicsTapes,
    columns: Vec<String>,
    unwrap: Vec<bool>,
    /// Output indices of each spatial body's `(ψ, θ, φ)`.
    cardan: Vec<[usize; 3]>,
    want_constraint_error: bool,
    /// Joint reaction columns (`"outputs": ["reactions"]`), written before `constraint_error`.
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
}

impl OutputEval {
    /// The evaluator of [`output_columns`]; the reactions (when asked for) read their
    /// constraint forces from `multipliers`.
    fn new(
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
        let reactions = sys
            .reaction_outputs
            .then(|| ReactionEval::new(sys, &tapes.gv, multipliers.clone()));
        let n_out = tapes.outputs.n_outputs();
        let nc = tapes.dims.2;
        OutputEval {
            work: tapes.outputs.workspace(),
            work_g: tapes.g.workspace(),
            vars: vec![0.0; 1 + tapes.dims.0 + tapes.dims.1],
            out: vec![0.0; n_out],
            g: vec![0.0; nc],
            tapes,
            columns,
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

/// Solves a multibody system with the chosen formulation, streaming rows to `observer`
/// (return `ControlFlow::Break(())` to stop early; the rows so far are returned).
///
/// The motion starts at `opts.t_start`; rows are written at `opts.output_times`.
pub fn solve_system(
    sys: MultibodySystem,
    opts: &SolveOptions,
    build_cpu_seconds: f64,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    from_t_start(opts, observer, |opts, observer| {
        solve_from_first_output(sys, opts, build_cpu_seconds, observer)
    })
}

/// [`solve_system`] with the first output time as the start time.
fn solve_from_first_output(
    mut sys: MultibodySystem,
    opts: &SolveOptions,
    build_cpu_seconds: f64,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    let t0 = *opts
        .output_times
        .first()
        .ok_or_else(|| Error::Options("no output times".into()))?;
    let clock = ThreadTime::now();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, t0)?;
    let mut summary = Summary {
        initial_position_correction: init.position_correction,
        initial_velocity_correction: init.velocity_correction,
        redundant_joints: init.redundant_joints.clone(),
        warnings: sys.warnings.clone(),
        formulation: opts.formulation.name().into(),
        ..Summary::default()
    };
    if !init.redundant_joints.is_empty() {
        summary.warnings.push(format!(
            "redundant constraints at t = {t0}: joints [{}] are linearly dependent; solved with the compliant GGL",
            init.redundant_joints.join(", ")
        ));
    }
    let mut build = build_cpu_seconds + clock.elapsed().as_secs_f64();
    let result = match opts.formulation {
        FormulationKind::Decoupled => {
            let t = ThreadTime::now();
            let dec =
                DecoupledFormulation::build(&mut sys, opts.joint_stiffness, opts.joint_damping)?;
            let tapes = MechanicsTapes::new(&mut sys, &c, Some(dec.spring_energy));
            build += t.elapsed().as_secs_f64();
            summary.joint_stiffness = opts.joint_stiffness;
            summary
                .warnings
                .extend(crate::dae::decoupled::prestress_warning(
                    &sys,
                    &init.lambda,
                    opts.joint_stiffness,
                ));
            if opts.joint_damping != 0.0 && sys.energy_exchange.is_none() {
                sys.energy_exchange = Some(format!(
                    "the twin's joint springs have damping {} (solve.joint_damping)",
                    opts.joint_damping
                ));
            }
            run_decoupled(&sys, dec, tapes, &init, opts, &mut summary, observer)
        }
        FormulationKind::Partitioned => {
            partitioned::run_partitioned(sys, &c, tapes, &init, opts, &mut summary, observer)
        }
        FormulationKind::Index1 => {
            summary.formulation = "index1".into();
            run_index1(sys.clone(), &c, tapes, &init, opts, &mut summary, observer)
        }
        FormulationKind::Dae if init.redundant_joints.is_empty() => {
            summary.formulation = "dae".into();
            run_index1(sys.clone(), &c, tapes, &init, opts, &mut summary, observer)
        }
        FormulationKind::Dae | FormulationKind::Ggl | FormulationKind::CompliantGgl => {
            if opts.formulation == FormulationKind::Dae {
                // the index-1 DAE does not apply (the arm above): the GGL, said so
                summary.formulation = "ggl".into();
                summary.warnings.push(
                    "dae: the chapter's index-1 DAE does not apply to this mechanism (its joints are redundant); solved with ggl".into()
                );
            }
            let t = ThreadTime::now();
            let eps_default = default_compliance(&sys, opts);
            let eps = if opts.formulation == FormulationKind::CompliantGgl
                || !init.redundant_joints.is_empty()
            {
                eps_default
            } else {
                0.0
            };
            let ggl = GglFormulation::build(&mut sys, &c, eps);
            build += t.elapsed().as_secs_f64();
            run_ggl(
                &sys,
                ggl,
                tapes,
                &init,
                eps,
                eps_default,
                opts,
                &mut summary,
                observer,
            )
        }
    };
    // a formulation rebuilt during the run (index 1, dae) adds its own build time
    let mut sol = result.map_err(|e| e.map_partial(|p| p.summary.build_cpu_seconds += build))?;
    sol.summary.build_cpu_seconds += build;
    Ok(sol)
}

/// What stopped a solve part-way, as `Summary::stopped_by` names it.
pub(crate) fn stop_reason(e: &SolverError) -> &'static str {
    match e {
        SolverError::StepBudget { .. } | SolverError::TooMuchWork { .. } => "max_steps",
        SolverError::WallClock { .. } => "max_wall_seconds",
        _ => "solver_error",
    }
}

/// Whether `e` is a budget running out (the state at the time reached is sound).
pub(crate) fn is_budget(e: &SolverError) -> bool {
    stop_reason(e) != "solver_error"
}

/// The [`Error::Incomplete`] of a solve stopped by `e`: the rows so far, plus `last_row` (the
/// state at the time reached, after a budget stop) when it lies beyond them.
pub(crate) fn stopped(
    e: SolverError,
    mut sol: Solution,
    mut summary: Summary,
    last_row: Option<(f64, Vec<f64>)>,
) -> Error {
    let t_last = sol.times.last().copied().unwrap_or(f64::NEG_INFINITY);
    summary.completed = false;
    summary.t_reached = e.time().unwrap_or(t_last).max(t_last);
    summary.stopped_by = Some(stop_reason(&e).into());
    if let Some((t, row)) = last_row {
        if t > t_last {
            sol.times.push(t);
            sol.rows.push(row);
            summary.t_reached = t;
        }
    }
    sol.summary = summary;
    Error::Incomplete {
        cause: Box::new(Error::Solver(e)),
        partial: Box::new(sol),
    }
}

/// Records the energy figures: the drift where energy is conserved (`exchange` is `None`),
/// else `not_conserved` with the reason.
pub(crate) fn set_energy(summary: &mut Summary, drift: f64, exchange: Option<&str>) {
    match exchange {
        None => {
            summary.energy_check = "conserved".into();
            summary.energy_drift = Some(drift);
            summary.energy_note.clear();
        }
        Some(why) => {
            summary.energy_check = "not_conserved".into();
            summary.energy_drift = None;
            summary.energy_note = why.into();
        }
    }
}

/// Marks a solve that reached its last row.
pub(crate) fn set_completed(summary: &mut Summary, sol: &Solution) {
    summary.completed = true;
    summary.t_reached = sol.times.last().copied().unwrap_or(0.0);
    summary.stopped_by = None;
}

/// Runs `solve` over the integration times of `opts` (`t_start`, then the output times after
/// it), and removes the row at `t_start` from the solution (and from the stream) unless the
/// caller listed it among the output times.
pub(crate) fn from_t_start(
    opts: &SolveOptions,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    solve: impl FnOnce(
        &SolveOptions,
        &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, Error>,
) -> Result<Solution, Error> {
    let (times, listed) = opts.integration_times()?;
    let inner = SolveOptions {
        output_times: times,
        ..opts.clone()
    };
    let mut skip = !listed;
    let mut filtered = |row: Row<'_>| {
        if std::mem::take(&mut skip) {
            ControlFlow::Continue(())
        } else {
            observer(row)
        }
    };
    let t0 = opts.t_start;
    // the row at t_start is the first one, if it is still there (a solve that keeps only its
    // latest row may have dropped it already)
    let drop_first = |sol: &mut Solution| {
        if !listed && sol.times.first() == Some(&t0) && !sol.rows.is_empty() {
            sol.times.remove(0);
            sol.rows.remove(0);
        }
    };
    match solve(&inner, &mut filtered) {
        Ok(mut sol) => {
            drop_first(&mut sol);
            Ok(sol)
        }
        Err(e) => Err(e.map_partial(drop_first)),
    }
}

/// The counters [`fill_stats`] wrote into a summary (the inverse of it).
fn counters_of(summary: &Summary) -> SolverStats {
    SolverStats {
        steps: summary.steps,
        residual_evals: summary.residual_evals,
        jacobian_evals: summary.jacobian_evals,
        linear_setups: summary.linear_setups,
        error_test_failures: summary.error_test_failures,
        nonlinear_iterations: summary.nonlinear_iterations,
        nonlinear_conv_failures: summary.nonlinear_conv_failures,
        last_step: summary.last_step,
        ..SolverStats::default()
    }
}

fn fill_stats(summary: &mut Summary, s: &SolverStats) {
    summary.steps = s.steps;
    summary.residual_evals = s.residual_evals;
    summary.jacobian_evals = s.jacobian_evals;
    summary.linear_setups = s.linear_setups;
    summary.error_test_failures = s.error_test_failures;
    summary.nonlinear_iterations = s.nonlinear_iterations;
    summary.nonlinear_conv_failures = s.nonlinear_conv_failures;
    summary.last_step = s.last_step;
}

/// An implicit DAE ready for IDA.
/// The compliant GGL's `ε`: `solve.compliance`, or `1e-10 / M_max` (a joint force of 1 N moves
/// the joint by 1e-10 m on the heaviest inertia's scale).
pub(super) fn default_compliance(sys: &MultibodySystem, opts: &SolveOptions) -> f64 {
    let mref = sys.mass.iter().fold(0.0f64, |a, &b| a.max(b)).max(1e-300);
    opts.compliance.unwrap_or(1e-10 / mref)
}

fn multiplier_atol(opts: &SolveOptions) -> f64 {
    opts.multiplier_atol.unwrap_or(1e-2)
}

/// `κ(G_v M⁺ G_vᵀ)` above which a failed plain-GGL step is taken as a singular passage. Measured
/// on the four-bar chains (N = 1, 3, 10) at the last accepted step before the failure:
/// κ ≈ 4e7 … 3e9 (further from the alignment at tighter tolerances); upright they have κ ≈ 10.
pub const SINGULAR_CONDITION: f64 = 1e4;

/// Where a singular passage was met, plain GGL would resume at the first output where κ has
/// fallen below this, if [`RESUME_PLAIN_GGL`] were set.
pub const REGULAR_CONDITION: f64 = 1e5;

/// Whether plain GGL resumes after a singular passage once the joints are well-conditioned.
/// Measured on the four-bar chains over 20 s (test profile), compliant to the end against
/// resuming (which then detects and reports every alignment, 19–21 passages):
/// N = 1, rtol 5e-9: 14 741 steps / 0.24 s against 15 723 / 0.30 s; N = 3, rtol 1e-9:
/// 27 507 / 1.59 s against 31 093 / 2.06 s (each switch restarts IDA at order 1 with small
/// steps), with errors of the same size; so resuming is not cheaper and stays off.
pub const RESUME_PLAIN_GGL: bool = false;

/// A singular passage: plain GGL failed near a rank-deficient `G_v` and the solve continued
/// with the compliant GGL from the last output before the failure.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SingularPassage {
    /// Time of plain GGL's last accepted step before it failed (where `G_v` was losing rank).
    pub t: f64,
    /// Joints whose rows were losing independence there.
    pub joints: Vec<String>,
    /// `κ(G_v M⁺ G_vᵀ)` at that step.
    pub condition: f64,
    /// The output time the compliant GGL restarted from (the last one plain GGL reached).
    pub restarted_at: f64,
    /// Time at which plain GGL resumed (`None`: compliant to the end).
    pub plain_again_at: Option<f64>,
    /// The IDA failure that revealed the passage (e.g. `IDA_CONV_FAIL`), or `conditioning
    /// peak` for a passage found while the compliant GGL was already running (no restart; then
    /// `t` is the peak of κ located between outputs and `restarted_at = t`).
    pub failure: String,
}

/// Completes the dependent coordinates and velocities of an output row `y = [q, v, …]` of the
/// index-1 DAE (dependent coordinates `coordinates`, dependent velocities `dependent`) from the
/// independent ones: Newton on `g(q_I, q_D) = 0` for `q_D` (with `G_q[:, D_q]`), then
/// `G_v[:, D] v_D = −G_v[:, I] v_I`.
///
/// IDA interpolates an output between its steps, and the algebraic unknowns, out of its error
/// test, are interpolated by a polynomial that satisfies the joints only at the steps (measured:
/// a pinned point moving at 1e-5 m/s at outputs of the double pendulum); the completed row lies
/// on the joints to the Newton tolerance, as the steps do.
fn complete_dependent(
    tapes: &MechanicsTapes,
    (dependent, coordinates): (&[usize], &[usize]),
    t: f64,
    y: &mut [f64],
) {
    let (nq, nv, nc) = tapes.dims;
    if nc == 0 || dependent.len() != nc || coordinates.len() != nc {
        return;
    }
    let scale = y[..nq].iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for _ in 0..4 {
        let g = MechanicsTapes::eval(&tapes.g, t, &y[..nq + nv]);
        if g.iter().all(|v| v.abs() <= 1e-15 * scale) {
            break;
        }
        let gq = tapes.gq.matrix(t, &y[..nq + nv]);
        let block = DMatrix::from_fn(nc, nc, |r, k| gq[(r, coordinates[k])]);
        let Some(dq) = block
            .lu()
            .solve(&nalgebra::DVector::from_iterator(nc, g.iter().map(|v| -v)))
        else {
            return;
        };
        for (k, &i) in coordinates.iter().enumerate() {
            y[i] += dq[k];
        }
    }
    let gv = tapes.gv.matrix(t, &y[..nq + nv]);
    let block = DMatrix::from_fn(nc, nc, |r, k| gv[(r, dependent[k])]);
    let rhs = nalgebra::DVector::from_fn(nc, |r, _| {
        -(0..nv)
            .filter(|j| !dependent.contains(j))
            .map(|j| gv[(r, j)] * y[nq + j])
            .sum::<f64>()
    });
    if let Some(vd) = block.lu().solve(&rhs) {
        for (k, &j) in dependent.iter().enumerate() {
            y[nq + j] = vd[k];
        }
    }
}

/// The dependent coordinates of the index-1 DAE for the dependent velocities `dependent`: the
/// same indices where `q' = v`; otherwise `nc` columns of `G_q` chosen as
/// [`select_dependent`] chooses velocities, the translations first (a 3D body's position, not
/// its quaternion). `None` when `G_q` has lower rank than its rows.
fn dependent_coordinates(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t: f64,
    x: &[f64],
    dependent: &[usize],
) -> Option<Vec<usize>> {
    if q_rates_are_v(sys) {
        return Some(dependent.to_vec());
    }
    let gq = tapes.gq.matrix(t, x);
    select_dependent(&gq, &crate::dae::partition::preferred_coordinates(sys))
}

/// Whether every coordinate's rate is its velocity (`q' = v`: planar bodies in the seed's
/// non-rotating frame, 16.8): then the index-1 DAE's dependent coordinates are its dependent
/// velocities' own.
fn q_rates_are_v(sys: &MultibodySystem) -> bool {
    if sys.nq() != sys.nv() {
        return false;
    }
    let mut g = sys.graph.clone();
    (0..sys.nq()).all(|i| sys.kinematics[i] == g.var(sys.v_slot(i)))
}

/// Which velocities the GGL leaves out of IDA's local error test
/// (`SolveOptions::ggl_dependent_velocity_error_test = false`).
///
/// The velocity rows `G_v(q) v = 0` fix the dependent velocities `v_D` in terms of the others,
/// `v_D = −G_v[:, D]⁻¹ G_v[:, I] v_I`: they are index-2 components, whose BDF error estimate
/// measures the constraint's differentiation rather than the dynamics, so the error test
/// weights them with 0 (IDA's `id` mask with suppressed algebraic error test). `D` is chosen as
/// the index-1 formulation chooses it ([`select_dependent`]), and re-chosen at output times
/// when `μ(D)` ([`dependent_condition`]) exceeds [`INDEX1_CHECK_CONDITION`] and a fresh
/// choice is [`INDEX1_RESELECT_GAIN`] times better conditioned. Where no set is well
/// conditioned (`κ(G_v[:, D]) >` [`GGL_ERROR_TEST_SINGULAR`], or no set exists), and while the
/// compliant GGL runs (there `G_v v = ε λ`: the velocities are no longer fixed by the joints
/// alone), every velocity is kept in the error test.
struct DependentErrorTest {
    /// Whether the exclusion was asked for.
    active: bool,
    /// The `id` of the formulation with every velocity in the error test.
    base_id: Vec<f64>,
    nq: usize,
    preferred: Vec<bool>,
    /// The velocities out of the error test (`None`: all in).
    dependent: Option<Vec<usize>>,
    /// Changes of the set after the first choice.
    reselections: u64,
    chosen_once: bool,
}

/// `κ(G_v[:, D])` above which the GGL keeps every velocity in its error test: the dependent
/// velocities are then ill-determined by the joints (near a singular configuration), and
/// leaving them out lets the step grow past what the independent ones can tell.
pub const GGL_ERROR_TEST_SINGULAR: f64 = 1e3;

impl DependentErrorTest {
    fn new(active: bool, base_id: Vec<f64>, nq: usize, preferred: Vec<bool>) -> Self {
        DependentErrorTest {
            active,
            base_id,
            nq,
            preferred,
            dependent: None,
            reselections: 0,
            chosen_once: false,
        }
    }

    /// The `id` vector for the current set.
    fn id(&self) -> Vec<f64> {
        let mut id = self.base_id.clone();
        for &j in self.dependent.iter().flatten() {
            id[self.nq + j] = 0.0;
        }
        id
    }

    /// A fresh choice at `G_v` with compliance `eps`; returns whether the set changed.
    fn choose(&mut self, gv: &DMatrix<f64>, eps: f64) -> bool {
        let fresh = if eps > 0.0 {
            None
        } else {
            select_dependent(gv, &self.preferred)
                .filter(|d| dependent_condition(gv, d) < GGL_ERROR_TEST_SINGULAR)
        };
        self.set(fresh)
    }

    fn set(&mut self, fresh: Option<Vec<usize>>) -> bool {
        let changed = fresh != self.dependent;
        if changed && self.chosen_once {
            self.reselections += 1;
        }
        self.chosen_once = true;
        self.dependent = fresh;
        changed
    }

    /// The check at an output time: re-chooses when the current set has degraded (or is empty
    /// and a set may exist again); returns whether the set changed.
    fn check(&mut self, gv: &DMatrix<f64>, eps: f64) -> bool {
        if eps > 0.0 {
            return self.set(None);
        }
        match &self.dependent {
            Some(d) => {
                let cond = dependent_condition(gv, d);
                if cond <= INDEX1_CHECK_CONDITION {
                    return false;
                }
                match select_dependent(gv, &self.preferred) {
                    Some(b) if b != *d => {
                        let cb = dependent_condition(gv, &b);
                        if cb * INDEX1_RESELECT_GAIN < cond && cb < GGL_ERROR_TEST_SINGULAR {
                            self.set(Some(b))
                        } else if cond > GGL_ERROR_TEST_SINGULAR {
                            self.set(None)
                        } else {
                            false
                        }
                    }
                    _ if cond > GGL_ERROR_TEST_SINGULAR => self.set(None),
                    _ => false,
                }
            }
            None => self.choose(gv, eps),
        }
    }
}

/// The GGL residual on IDA, with the compliance ε changeable between steps.
/// IDA on the GGL DAE whose compliance ε the runner switches at singular passages.
struct GglIda {
    ida: Ida,
    dae: Arc<GglDae>,
}

fn make_ggl_ida(
    ggl: &Arc<GglFormulation>,
    atol: Vec<f64>,
    eps: f64,
    t0: f64,
    y0: &[f64],
    yp0: &[f64],
    opts: &SolveOptions,
) -> Result<GglIda, Error> {
    let dae = Arc::new(GglDae::shared(ggl.clone(), eps));
    Ok(GglIda {
        ida: make_ida(dae.clone(), atol, t0, y0, yp0, opts)?,
        dae,
    })
}

impl GglIda {
    fn eps(&self) -> f64 {
        self.dae.compliance()
    }

    /// Restarts at `(t, y, y')` with compliance `eps` (IDA restarts at order 1).
    fn restart(&mut self, eps: f64, t: f64, y: &[f64], yp: &[f64]) -> Result<(), Error> {
        self.dae.set_compliance(eps);
        self.ida.reinit(t, y, yp)?;
        Ok(())
    }
}

/// Whether an IDA failure is the kind a singular passage causes (Newton or error test failing
/// with a collapsing step).
fn is_convergence_failure(e: &SolverError) -> Option<(f64, String)> {
    match e {
        SolverError::Flag { name, t, .. }
            if name == "IDA_CONV_FAIL" || name == "IDA_ERR_FAIL" || name == "IDA_LSETUP_FAIL" =>
        {
            Some((*t, name.clone()))
        }
        _ => None,
    }
}

/// Velocities that satisfy the velocity rows `G_v v = ε λ` of the (compliant, if `ε > 0`) GGL
/// with the least change, so that a (re)start does not begin with a jump IDA's error test sees.
fn compliant_velocities(
    tapes: &MechanicsTapes,
    nq: usize,
    nv: usize,
    eps: f64,
    t: f64,
    y: &mut [f64],
) {
    let nc = tapes.dims.2;
    if nc == 0 {
        return;
    }
    let gv = tapes.gv.matrix(t, &y[..nq + nv]);
    let v = nalgebra::DVector::from_column_slice(&y[nq..nq + nv]);
    let lam = nalgebra::DVector::from_column_slice(&y[nq + nv..nq + nv + nc]);
    let defect = &lam * eps - &gv * &v;
    let svd = gv.svd(true, true);
    // directions of (nearly) lost rank are left alone: there the row residual is small anyway
    let tol = 1e-6 * svd.singular_values.max().max(1e-300);
    if let Ok(dv) = svd.solve(&defect, tol) {
        for j in 0..nv {
            y[nq + j] += dv[j];
        }
    }
}

/// A consistent GGL state `(y, y')` at `(t, x = [q, v])` for compliance `eps`: positions and
/// velocities projected onto the joints, accelerations and (least-norm) multipliers from the
/// mass–constraint system, then velocities adjusted to `G_v v = ε λ`. The multipliers of the
/// failed plain-GGL step are not reused: near the singular configuration they grow without bound.
fn restart_state(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    eps: f64,
    t: f64,
    x: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let (nq, nv, nc) = tapes.dims;
    let st = consistent_state_from(sys, tapes, t, x)?;
    let mut y = st.q.clone();
    y.extend(&st.v);
    y.extend(&st.lambda);
    y.extend(std::iter::repeat_n(0.0, nc));
    compliant_velocities(tapes, nq, nv, eps, t, &mut y);
    let mut yp = MechanicsTapes::eval(&tapes.kinematics, t, &y[..nq + nv]);
    yp.extend(&st.vdot);
    yp.extend(std::iter::repeat_n(0.0, 2 * nc));
    Ok((y, yp))
}

#[allow(clippy::too_many_arguments)]
fn run_ggl(
    sys: &MultibodySystem,
    ggl: GglFormulation,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    eps_start: f64,
    eps_switch: f64,
    opts: &SolveOptions,
    summary: &mut Summary,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let t0 = opts.output_times[0];
    let mut y0 = init.q.clone();
    y0.extend(&init.v);
    y0.extend(&init.lambda);
    y0.extend(std::iter::repeat_n(0.0, nc));
    compliant_velocities(&tapes, nq, nv, eps_start, t0, &mut y0);
    let mut yp0 = MechanicsTapes::eval(&tapes.kinematics, t0, &y0[..nq + nv]);
    yp0.extend(&init.vdot);
    yp0.extend(std::iter::repeat_n(0.0, 2 * nc));
    let mut atol = vec![opts.atol; nq + nv];
    atol.extend(std::iter::repeat_n(multiplier_atol(opts), 2 * nc));
    summary.solver = "IDA".into();
    summary.unknowns = ggl.dae.n;
    summary.linear_solver = opts.linear_solver.resolved_name(ggl.dae.n).into();
    let mut error_test = DependentErrorTest::new(
        !opts.ggl_dependent_velocity_error_test && nc > 0,
        ggl.id.clone(),
        nq,
        CausalPartition::new(sys, t0).preferred_at(t0, &y0[..nq]),
    );
    let mut ggl = ggl;
    if error_test.active {
        let gv = tapes.gv.matrix(t0, &y0[..nq + nv]);
        error_test.choose(&gv, eps_start);
        ggl.id = error_test.id();
    }
    let ggl = Arc::new(ggl);
    let clock = ThreadTime::now();
    let mut solver = make_ggl_ida(&ggl, atol, eps_start, t0, &y0, &yp0, opts)?;
    let mut total = SolverStats::default();
    let multipliers = Multipliers::Unknowns(nq + nv);
    let mut out = OutputEval::new(sys, tapes.clone(), &multipliers);
    let events = event_eval(sys, &tapes, &solved_multipliers(sys, &tapes));
    set_ida_events(&mut solver.ida, &events)?;
    let mut sol = Solution {
        columns: out.columns.clone(),
        times: Vec::new(),
        rows: Vec::new(),
        summary: Summary::default(),
    };
    // κ alone at every output (eigenvalues only, `joint_condition_number`); the joints involved
    // (eigenvectors, `joint_conditioning`) only where they are reported: at a failure taken as
    // a passage, and at a peak of κ (the PeakFinder keeps `G_v` of its samples for that).
    // Measured on the 40-four-bar chain (242 joint rows, κ above PASSAGE_CONDITION at most
    // outputs): full eigen-decompositions at the 400 outputs took 40 % of the solve.
    let gv_at = |t: f64, y: &[f64]| tapes.gv.matrix(t, &y[..nq + nv]);
    let conditioning = |t: f64, y: &[f64]| joint_conditioning(&gv_at(t, y), &sys.mass, &sys.rows);
    let joints_of = |gv: &DMatrix<f64>| joint_conditioning(gv, &sys.mass, &sys.rows).joints;
    let resume_plain = RESUME_PLAIN_GGL;
    // joints redundant everywhere have κ = ∞ throughout: no passages to find there
    let monitor = init.redundant_joints.is_empty();
    let mut peaks = PeakFinder::default();
    let mut compliant_since: Option<f64> = (eps_start > 0.0).then_some(t0);
    let mut compliant_time = 0.0;
    let first = out.row(t0, &y0);
    let mut last_output = (t0, y0.clone());
    if !emit(&mut sol, observer, t0, first, opts.keep_rows) {
        let mut k = 1;
        while k < opts.output_times.len() {
            let t = opts.output_times[k];
            let step = match solver.ida.solve_to(t) {
                Ok(s) => s,
                Err(e) => {
                    // a singular passage: plain GGL failed to converge near a rank-deficient G_v
                    let passage = match is_convergence_failure(&e) {
                        Some((tf, name)) if solver.eps() == 0.0 && eps_switch > 0.0 => {
                            let mut y = vec![0.0; y0.len()];
                            solver.ida.dky(tf, 0, &mut y)?;
                            let c = conditioning(tf, &y);
                            (c.condition > SINGULAR_CONDITION).then_some((tf, name, c))
                        }
                        _ => None,
                    };
                    let Some((tf, name, c)) = passage else {
                        total.accumulate(&solver.ida.stats());
                        fill_stats(summary, &total);
                        let last = budget_row_ida(&e, &mut solver.ida, &mut out);
                        summary.cpu_seconds = clock.elapsed().as_secs_f64();
                        finish_ggl_summary(summary, &out, eps_start, eps_switch, compliant_time);
                        return Err(stopped(e, sol, summary.clone(), last));
                    };
                    if summary.singular_passages.len() >= MAX_SINGULAR_PASSAGES {
                        total.accumulate(&solver.ida.stats());
                        fill_stats(summary, &total);
                        summary.cpu_seconds = clock.elapsed().as_secs_f64();
                        finish_ggl_summary(summary, &out, eps_start, eps_switch, compliant_time);
                        return Err(stopped(e, sol, summary.clone(), None));
                    }
                    // restart from the last output: the steps plain GGL accepted just before
                    // failing are already degraded by the ill-conditioned Newton matrix (measured
                    // on the isosceles slider-crank: restarting from the last accepted step
                    // left a crank-angle error 60 times that of the compliant GGL throughout)
                    let (tr, xr) = (last_output.0, last_output.1.clone());
                    let (y, yp) = restart_state(sys, &tapes, eps_switch, tr, &xr[..nq + nv])?;
                    total.accumulate(&solver.ida.stats());
                    solver.restart(eps_switch, tr, &y, &yp)?;
                    if error_test.active && error_test.choose(&gv_at(tr, &y), eps_switch) {
                        solver.ida.set_id(&error_test.id())?;
                    }
                    compliant_since = Some(tr);
                    summary.warnings.push(format!(
                        "singular configuration at t = {tf:.6}: joints [{}] lose independence (κ = {:.1e}, {name}); continued with the compliant GGL (ε = {eps_switch:.1e}) from t = {tr}",
                        c.joints.join(", "),
                        c.condition
                    ));
                    summary.singular_passages.push(SingularPassage {
                        t: tf,
                        joints: c.joints,
                        condition: c.condition,
                        restarted_at: tr,
                        plain_again_at: None,
                        failure: name,
                    });
                    continue;
                }
            };
            if let StepEvent::Root(info) = &step.event {
                // an event row between output times; the next output time is still ahead
                let Some(stop) = events_fired(&sys.events, info, step.t, summary) else {
                    continue;
                };
                last_output = (step.t, solver.ida.y().to_vec());
                let row = out.row(step.t, solver.ida.y());
                if emit(&mut sol, observer, step.t, row, opts.keep_rows) || stop {
                    break;
                }
                continue;
            }
            k += 1;
            last_output = (step.t, solver.ida.y().to_vec());
            let row = out.row(step.t, solver.ida.y());
            if emit(&mut sol, observer, step.t, row, opts.keep_rows) {
                break;
            }
            if error_test.active && error_test.check(&gv_at(step.t, solver.ida.y()), solver.eps()) {
                solver.ida.set_id(&error_test.id())?;
            }
            // while compliant, every further singular passage shows as a peak of κ
            if monitor && solver.eps() > 0.0 {
                let gv = gv_at(step.t, solver.ida.y());
                let kappa = joint_condition_number(&gv, &sys.mass);
                if let Some(p) = peaks.push(step.t, kappa, gv, joints_of) {
                    let near_switch = summary
                        .singular_passages
                        .last()
                        .is_some_and(|q| (q.t - p.t).abs() < 2.0 * peaks.spacing());
                    if !near_switch {
                        summary.warnings.push(format!(
                            "singular configuration at t = {:.6}: joints [{}] lose independence (κ peak {:.1e}); carried through by the compliant GGL (ε = {:.1e})",
                            p.t,
                            p.joints.join(", "),
                            p.condition,
                            solver.eps()
                        ));
                        summary.singular_passages.push(p);
                    }
                }
            }
            // back to plain GGL once the joints are well-conditioned again
            let switched = summary
                .singular_passages
                .last()
                .is_some_and(|p| p.plain_again_at.is_none());
            if resume_plain && switched && solver.eps() > 0.0 && k < opts.output_times.len() {
                let kappa = joint_condition_number(&gv_at(step.t, solver.ida.y()), &sys.mass);
                if kappa < REGULAR_CONDITION {
                    let (mut y, yp) = (solver.ida.y().to_vec(), solver.ida.yp().to_vec());
                    compliant_velocities(&tapes, nq, nv, 0.0, step.t, &mut y);
                    total.accumulate(&solver.ida.stats());
                    solver.restart(0.0, step.t, &y, &yp)?;
                    if let Some(ts) = compliant_since.take() {
                        compliant_time += step.t - ts;
                    }
                    if let Some(p) = summary.singular_passages.last_mut() {
                        p.plain_again_at = Some(step.t);
                    }
                }
            }
        }
    }
    if let Some(ts) = compliant_since {
        compliant_time += sol.times.last().copied().unwrap_or(ts) - ts;
    }
    summary.cpu_seconds = clock.elapsed().as_secs_f64();
    total.accumulate(&solver.ida.stats());
    fill_stats(summary, &total);
    summary.recovered_failures = solver.ida.recovered_failures().to_vec();
    summary.ggl_error_test_reselections = error_test.reselections;
    finish_ggl_summary(summary, &out, eps_start, eps_switch, compliant_time);
    set_completed(summary, &sol);
    sol.summary = summary.clone();
    Ok(sol)
}

/// The GGL's compliance figures, constraint error and energy in the summary.
fn finish_ggl_summary(
    summary: &mut Summary,
    out: &OutputEval,
    eps_start: f64,
    eps_switch: f64,
    compliant_time: f64,
) {
    summary.compliance_used = eps_start > 0.0 || !summary.singular_passages.is_empty();
    summary.compliance = if summary.compliance_used {
        eps_start.max(eps_switch)
    } else {
        0.0
    };
    summary.compliant_time = compliant_time;
    summary.max_constraint_error = out.max_g;
    set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
}

/// After a budget stop on IDA: the output row at the time reached (IDA's current state).
fn budget_row_ida(e: &SolverError, ida: &mut Ida, out: &mut OutputEval) -> Option<(f64, Vec<f64>)> {
    let t = e.time().filter(|_| is_budget(e))?;
    let mut y = vec![0.0; ida.y().len()];
    ida.dky(t, 0, &mut y).ok()?;
    Some((t, out.row(t, &y)))
}

/// `κ(G_v M⁺ G_vᵀ)` at an output time above which a local maximum of κ, met while the
/// compliant GGL runs, is recorded as a singular passage. Measured on the four-bar chains
/// (output step 0.05 s): upright κ ≈ 10, at the output nearest an alignment κ ≳ 1e3.
pub const PASSAGE_CONDITION: f64 = 300.0;

/// Finds the peaks of κ over the output times (one output of delay) and locates each peak
/// between the outputs: near a rank loss `s = κ^{-1/2}` (the ratio of the smallest to the
/// largest singular value of `M^{-1/2} G_vᵀ`) falls linearly to zero, `s ≈ a |t − t*|`, so
/// `t*` follows from the steeper of the two one-sided slopes at the smallest sample.
#[derive(Default)]
struct PeakFinder {
    /// `(t, κ, G_v)` of the last three outputs.
    samples: Vec<(f64, f64, DMatrix<f64>)>,
}

impl PeakFinder {
    /// Output spacing seen last (0 before two samples).
    fn spacing(&self) -> f64 {
        match self.samples.as_slice() {
            [.., a, b] => b.0 - a.0,
            _ => 0.0,
        }
    }

    /// Adds the sample `κ(t)` with the `G_v` it came from; returns a passage when the previous
    /// sample was a peak, naming the joints `joints_of` finds in that sample's `G_v`.
    fn push(
        &mut self,
        t: f64,
        kappa: f64,
        gv: DMatrix<f64>,
        joints_of: impl Fn(&DMatrix<f64>) -> Vec<String>,
    ) -> Option<SingularPassage> {
        self.samples.push((t, kappa, gv));
        if self.samples.len() > 3 {
            self.samples.remove(0);
        }
        let [(t0, k0, _), (t1, k1, gv1), (t2, k2, _)] = self.samples.as_slice() else {
            return None;
        };
        let (k0, k1, k2) = (*k0, *k1, *k2);
        if !(k1 > PASSAGE_CONDITION && k1 >= k0 && k1 > k2 && k1.is_finite()) {
            return None;
        }
        let s = |k: f64| 1.0 / k.sqrt();
        let (sl, sm, sr) = (s(k0), s(k1), s(k2));
        let left = (sl - sm) / (t1 - t0);
        let right = (sr - sm) / (t2 - t1);
        let t_peak = if left >= right {
            (t1 + sm / left).min(*t2)
        } else {
            (t1 - sm / right).max(*t0)
        };
        Some(SingularPassage {
            t: t_peak,
            joints: joints_of(gv1),
            condition: k1,
            restarted_at: t_peak,
            plain_again_at: None,
            failure: "conditioning peak".into(),
        })
    }
}

/// Singular passages handled per solve before a failure is reported as such (a guard against
/// restarting forever at a configuration the compliant GGL cannot pass either).
const MAX_SINGULAR_PASSAGES: usize = 10_000;

/// Condition number of `G_v[:, D]` above which a fresh selection of dependent velocities is
/// considered (checked at the output times).
const INDEX1_CHECK_CONDITION: f64 = 10.0;

/// The fresh selection replaces the current one when its condition is this many times smaller.
/// The check happens at output times only, so it must fire well before the block is singular:
/// the condition grows like `1/|cos θ|` as a dependent coordinate loses its grip (measured on a
/// bead sliding along a pendulum bar: the dependent bead translation must change near the
/// vertical, and a threshold of 1e4 on the current set alone let IDA run into the singular
/// block between outputs).
const INDEX1_RESELECT_GAIN: f64 = 10.0;

fn run_index1(
    mut sys: MultibodySystem,
    c: &ConstraintExprs,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    opts: &SolveOptions,
    summary: &mut Summary,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let t0 = opts.output_times[0];
    let gv_at = |tapes: &MechanicsTapes, t: f64, x: &[f64]| tapes.gv.matrix(t, x);
    let mut x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    let mut state = init.clone();
    summary.solver = "IDA".into();
    let clock = ThreadTime::now();
    // the causality assignment is the model's analysis, not integration: build time
    let analysis = ThreadTime::now();
    let causal = CausalPartition::new(&sys, t0);
    let mut total = SolverStats::default();
    // y = [q, v, a_D, λ]
    let multipliers = Multipliers::Unknowns(nq + nv + nc);
    let mut out = OutputEval::new(sys.clone(), tapes.clone(), &multipliers);
    let events = event_eval(&sys, &tapes, &solved_multipliers(&sys, &tapes));
    let mut sol = Solution {
        columns: out.columns.clone(),
        times: Vec::new(),
        rows: Vec::new(),
        summary: Summary::default(),
    };
    let mut y_first = x.clone();
    y_first.extend(std::iter::repeat_n(0.0, nc));
    y_first.extend(&init.lambda);
    let first = out.row(t0, &y_first);
    if emit(&mut sol, observer, t0, first, opts.keep_rows) {
        set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
        set_completed(summary, &sol);
        sol.summary = summary.clone();
        return Ok(sol);
    }
    let mut t_start = t0;
    let mut k_next = 1;
    let mut reselections = 0u64;
    let wall_start = std::time::Instant::now();
    // `dae` hands the rest of the run to the GGL where the joints near a singular configuration
    // (no regular dependent block exists) or IDA fails: (time, state [q, v], why)
    let hands_over = summary.formulation == "dae";
    let mut handover: Option<(f64, String)> = None;
    let mut t_last = t0;
    // the chapter's partition at the start: the differential-causality inertias' flows
    // (kept unless its block is ill-conditioned there and a numeric choice is much better)
    let mut from_causality = causal.dependent().filter(|d| {
        let gv = gv_at(&tapes, t0, &x);
        let cond = dependent_condition(&gv, d);
        cond <= INDEX1_CHECK_CONDITION
            || select_dependent(&gv, &causal.preferred_at(t0, &x[..nq]))
                .is_none_or(|b| dependent_condition(&gv, &b) * INDEX1_RESELECT_GAIN >= cond)
    });
    // what the hand-over compares with: the joints' and the partition's conditioning at the start
    let watch = {
        let gv = gv_at(&tapes, t0, &x);
        // (the causality's preference, a graph assignment, only where the causality's block fails)
        let block = match &from_causality {
            Some(d) => dependent_condition(&gv, d),
            None => select_dependent(&gv, &causal.preferred_at(t0, &x[..nq]))
                .map_or(f64::INFINITY, |d| dependent_condition(&gv, &d)),
        };
        HandoverWatch {
            joints: if hands_over {
                crate::dae::joint_condition_number(&gv, &sys.mass)
            } else {
                f64::INFINITY
            },
            block: block.max(INDEX1_CHECK_CONDITION / 2.0),
        }
    };
    let mut formulation_build = analysis.elapsed().as_secs_f64();
    if from_causality.is_none() && !sys.inertias.is_empty() {
        summary.warnings.push(format!(
            "{}: the causality's dependent inertias are not a regular block of the joint rows at t = {t0}; chosen numerically",
            summary.formulation
        ));
    }
    'restart: loop {
        let gv = gv_at(&tapes, t_start, &x);
        let chosen = from_causality
            .take()
            .or_else(|| select_dependent(&gv, &causal.preferred_at(t_start, &x[..nq])));
        if chosen.is_none() && hands_over {
            handover = Some((t_start, "no regular set of dependent velocities".into()));
            break 'restart;
        }
        let dependent = chosen.ok_or_else(|| {
            let c = joint_conditioning(&gv, &sys.mass, &sys.rows);
            Error::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: format!(
                    "joints [{}] lose rank (κ = {:.1e}): no set of dependent velocities exists; use the ggl formulation",
                    c.joints.join(", "),
                    c.condition
                ),
            })
        })?;
        if reselections == 0 {
            (summary.states, summary.dependent) = causal.names(&dependent);
        }
        let Some(coordinates) = dependent_coordinates(&sys, &tapes, t_start, &x, &dependent) else {
            if hands_over {
                handover = Some((t_start, "no regular set of dependent coordinates".into()));
                break 'restart;
            }
            return Err(Error::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: "the joints' position rows lose rank: no set of dependent coordinates exists; use the ggl formulation".into(),
            }));
        };
        // the formulation's symbolic build is not integration time
        let tb = ThreadTime::now();
        let f = Index1Formulation::build_partitioned(&mut sys, c, &dependent, &coordinates)?;
        formulation_build += tb.elapsed().as_secs_f64();
        summary.unknowns = f.dae.n;
        let split = f.schur_split(nq);
        let mut y0 = state.q.clone();
        y0.extend(&state.v);
        y0.extend(dependent.iter().map(|&j| state.vdot[j]));
        y0.extend(&state.lambda);
        // q' = K(q) v
        let x_start: Vec<f64> = state.q.iter().chain(&state.v).copied().collect();
        let mut yp0 = MechanicsTapes::eval(&tapes.kinematics, t_start, &x_start);
        yp0.extend(&state.vdot);
        yp0.extend(std::iter::repeat_n(0.0, 2 * nc));
        let mut atol = vec![opts.atol; nq + nv];
        atol.extend(std::iter::repeat_n(opts.atol, nc));
        atol.extend(std::iter::repeat_n(multiplier_atol(opts), nc));
        let f: Arc<dyn DaeFormulation> = Arc::new(f);
        // `auto`: the Newton matrix by elimination of the dependent blocks (Schur complement)
        let schur = (opts.linear_solver == LinearSolverKind::Auto)
            .then(|| make_ida_schur(f.clone(), split, atol.clone(), t_start, (&y0, &yp0), opts))
            .flatten();
        summary.linear_solver = match schur {
            Some(_) => "schur".into(),
            None => opts.linear_solver.resolved_name(f.len()).into(),
        };
        let mut ida = match schur {
            Some(ida) => ida?,
            None => make_ida(f, atol, t_start, &y0, &yp0, opts)?,
        };
        set_ida_events(&mut ida, &events)?;
        // The wall-clock and step budgets cover the whole solve, earlier segments included.
        ida.charge_wall_clock(wall_start.elapsed());
        ida.charge_steps(total.steps);
        while k_next < opts.output_times.len() {
            let t = opts.output_times[k_next];
            let step = match ida.solve_to(t) {
                Ok(s) => s,
                Err(e) if hands_over && is_convergence_failure(&e).is_some() => {
                    total.accumulate(&ida.stats());
                    handover = Some((t_last, format!("IDA failed at t = {:.6}: {e}", ida.t())));
                    break 'restart;
                }
                Err(e) => {
                    total.accumulate(&ida.stats());
                    fill_stats(summary, &total);
                    summary.index1_reselections = reselections;
                    summary.cpu_seconds = clock.elapsed().as_secs_f64() - formulation_build;
                    summary.build_cpu_seconds = formulation_build;
                    summary.max_constraint_error = out.max_g;
                    set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
                    let last = budget_row_ida(&e, &mut ida, &mut out);
                    return Err(stopped(e, sol, summary.clone(), last));
                }
            };
            if let StepEvent::Root(info) = &step.event {
                let Some(stop) = events_fired(&sys.events, info, step.t, summary) else {
                    continue;
                };
                let mut yr = ida.y().to_vec();
                complete_dependent(&tapes, (&dependent, &coordinates), step.t, &mut yr);
                let row = out.row(step.t, &yr);
                if emit(&mut sol, observer, step.t, row, opts.keep_rows) || stop {
                    total.accumulate(&ida.stats());
                    break 'restart;
                }
                continue;
            }
            k_next += 1;
            let mut yr = ida.y().to_vec();
            complete_dependent(&tapes, (&dependent, &coordinates), step.t, &mut yr);
            x.copy_from_slice(&yr[..nq + nv]);
            t_last = step.t;
            let row = out.row(step.t, &yr);
            if emit(&mut sol, observer, step.t, row, opts.keep_rows) {
                total.accumulate(&ida.stats());
                break 'restart;
            }
            let cond = dependent_condition(&gv_at(&tapes, step.t, &x), &dependent);
            // the causality's preference at this output, assigned at most once
            let mut preferred: Option<Vec<bool>> = None;
            if hands_over && cond > 2.0 * watch.block && k_next < opts.output_times.len() {
                // the partition degrades: are the joints approaching a singular configuration?
                let gv = gv_at(&tapes, step.t, &x);
                let kappa = crate::dae::joint_condition_number(&gv, &sys.mass);
                // best ≤ cond: a fresh choice (a causality assignment) only matters above the
                // hand-over's threshold
                let best = if cond > DAE_HANDOVER_CONDITION {
                    let p = preferred.get_or_insert_with(|| causal.preferred_at(step.t, &x[..nq]));
                    select_dependent(&gv, p)
                        .map_or(f64::INFINITY, |b| dependent_condition(&gv, &b))
                        .min(cond)
                } else {
                    cond
                };
                if kappa > DAE_HANDOVER_RISE * watch.joints || best > DAE_HANDOVER_CONDITION {
                    total.accumulate(&ida.stats());
                    handover = Some((
                        step.t,
                        format!(
                            "the joints approach a singular configuration: κ(G_v M⁺ G_vᵀ) = {kappa:.1e} ({:.1e} at t = {t0}), the best dependent block's condition {best:.1e}",
                            watch.joints
                        ),
                    ));
                    break 'restart;
                }
            }
            if cond > INDEX1_CHECK_CONDITION && k_next < opts.output_times.len() {
                let gv = gv_at(&tapes, step.t, &x);
                // no block is INDEX1_RESELECT_GAIN times better conditioned than the bound allows:
                // then no fresh choice (a causality assignment) can replace this one
                let possible =
                    cond * (1.0 + 1e-9) > INDEX1_RESELECT_GAIN * block_condition_bound(&gv);
                let better = possible
                    .then(|| {
                        let p =
                            preferred.get_or_insert_with(|| causal.preferred_at(step.t, &x[..nq]));
                        select_dependent(&gv, p)
                    })
                    .flatten();
                if let Some(b) = better {
                    if b != dependent && dependent_condition(&gv, &b) * INDEX1_RESELECT_GAIN < cond
                    {
                        total.accumulate(&ida.stats());
                        reselections += 1;
                        t_start = step.t;
                        state = consistent_state_from(&sys, &tapes, t_start, &x)?;
                        summary.warnings.push(format!(
                            "index1: dependent velocities re-selected at t = {t_start:.6} (condition {cond:.1e})"
                        ));
                        continue 'restart;
                    }
                }
            }
            // the dependent coordinates, where they are chosen apart from the velocities
            if coordinates != dependent && k_next < opts.output_times.len() {
                let gq = tapes.gq.matrix(step.t, &x);
                let cond_q = dependent_condition(&gq, &coordinates);
                let better = (cond_q > INDEX1_CHECK_CONDITION)
                    .then(|| {
                        select_dependent(&gq, &crate::dae::partition::preferred_coordinates(&sys))
                    })
                    .flatten()
                    .filter(|b| dependent_condition(&gq, b) * INDEX1_RESELECT_GAIN < cond_q);
                if better.is_some() {
                    total.accumulate(&ida.stats());
                    reselections += 1;
                    t_start = step.t;
                    state = consistent_state_from(&sys, &tapes, t_start, &x)?;
                    summary.warnings.push(format!(
                        "index1: dependent coordinates re-selected at t = {t_start:.6} (condition {cond_q:.1e})"
                    ));
                    continue 'restart;
                }
            }
        }
        total.accumulate(&ida.stats());
        break;
    }
    summary.index1_reselections = reselections;
    summary.cpu_seconds = clock.elapsed().as_secs_f64() - formulation_build;
    summary.build_cpu_seconds = formulation_build;
    fill_stats(summary, &total);
    summary.max_constraint_error = out.max_g;
    set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
    if let Some((t_h, why)) = handover {
        // t_h is the last output reached: x is its (completed) state
        return continue_with_ggl(
            sys,
            c,
            tapes,
            (t_h, &x),
            k_next,
            opts,
            (summary, &total),
            sol,
            observer,
            &why,
        );
    }
    set_completed(summary, &sol);
    sol.summary = summary.clone();
    Ok(sol)
}

/// The joints' and the partition's conditioning at the start of a `dae` run.
struct HandoverWatch {
    /// `κ(G_v M⁺ G_vᵀ)`.
    joints: f64,
    /// `κ(G_v[:, D])` (at least half the re-selection threshold).
    block: f64,
}

/// The rise of the joints' condition number `κ(G_v M⁺ G_vᵀ)` over its value at the start above
/// which the `dae` formulation hands the rest of the run to the GGL (checked at the outputs
/// where the dependent block's condition has doubled). Measured on the bundled scenes: the
/// slider-crank's κ varies by 1.9× over its turns, Andrews' by 1.6×, the four-bar's by 2.9×;
/// the three-four-bar chain's rises 18× an output step before its alignment (κ peak 8e3).
const DAE_HANDOVER_RISE: f64 = 10.0;

/// The condition number of the best-conditioned dependent block `G_v[:, D]` above which the
/// `dae` formulation hands the rest of the run to the GGL (which passes singular configurations
/// with its compliant form and reports them): every partition is then degrading, as near a
/// singular configuration of the joints (a four-bar chain's alignment; a slider-crank's dead
/// centre is not one: the crank angle stays a regular state there).
const DAE_HANDOVER_CONDITION: f64 = 1e3;

/// The rest of a `dae` run, from the output time `t_h` and state `x_h = [q, v]` it reached, on
/// the GGL (plain, compliant at singular passages): the rows after `t_h` are appended to
/// `sol`, the counters of both parts added, and the hand-over named in the warnings.
#[allow(clippy::too_many_arguments)]
fn continue_with_ggl(
    mut sys: MultibodySystem,
    c: &ConstraintExprs,
    tapes: MechanicsTapes,
    (t_h, x_h): (f64, &[f64]),
    k_next: usize,
    opts: &SolveOptions,
    (summary, dae_counters): (&mut Summary, &SolverStats),
    mut sol: Solution,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    why: &str,
) -> Result<Solution, Error> {
    let before = summary.clone();
    summary.warnings.push(format!(
        "dae: the rest of the run from t = {t_h:.6} is solved by the GGL ({why})"
    ));
    let init = consistent_state_from(&sys, &tapes, t_h, x_h)?;
    let mut o = opts.clone();
    o.output_times = std::iter::once(t_h)
        .chain(
            opts.output_times[k_next.min(opts.output_times.len())..]
                .iter()
                .copied(),
        )
        .collect();
    let eps_default = default_compliance(&sys, opts);
    let t = ThreadTime::now();
    let ggl = GglFormulation::build(&mut sys, c, 0.0);
    summary.build_cpu_seconds += t.elapsed().as_secs_f64();
    // the row at t_h is the dae part's last one
    let mut first = true;
    let mut rest = |r: Row<'_>| {
        if std::mem::take(&mut first) {
            ControlFlow::Continue(())
        } else {
            observer(r)
        }
    };
    let merge = |part: &mut Solution, sol: &Solution, before: &Summary| {
        let mut times = sol.times.clone();
        let mut rows = sol.rows.clone();
        times.extend(part.times.iter().skip(1));
        rows.extend(part.rows.iter().skip(1).cloned());
        part.times = times;
        part.rows = rows;
        let s = &mut part.summary;
        s.formulation = "dae".into();
        let mut counters = dae_counters.clone();
        counters.accumulate(&counters_of(s));
        fill_stats(s, &counters);
        s.cpu_seconds += before.cpu_seconds;
        s.index1_reselections = before.index1_reselections;
        s.max_constraint_error = s.max_constraint_error.max(before.max_constraint_error);
        if let (Some(a), Some(b)) = (s.energy_drift, before.energy_drift) {
            s.energy_drift = Some(a + b);
        }
    };
    let result = run_ggl(
        &sys,
        ggl,
        tapes,
        &init,
        0.0,
        eps_default,
        &o,
        summary,
        &mut rest,
    );
    match result {
        Ok(mut part) => {
            merge(&mut part, &sol, &before);
            *summary = part.summary.clone();
            Ok(part)
        }
        Err(e) => {
            sol.summary = before.clone();
            Err(e.map_partial(|p| merge(p, &sol, &before)))
        }
    }
}

fn run_decoupled(
    sys: &MultibodySystem,
    dec: DecoupledFormulation,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    opts: &SolveOptions,
    summary: &mut Summary,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    let t0 = opts.output_times[0];
    let mut y0 = crate::dae::decoupled::prestressed_positions(
        &tapes,
        t0,
        &init.q,
        &init.v,
        &init.lambda,
        opts.joint_stiffness,
    );
    y0.extend(&init.v);
    // the joint springs' forces, compiled only when reactions are read
    let row_force = if needs_reactions(sys) {
        &dec.row_force[..]
    } else {
        &[]
    };
    let multipliers = Multipliers::Springs(sys.graph.compile(row_force));
    let cv_opts = CvodeOptions {
        rtol: opts.rtol,
        atol: vec![opts.atol],
        max_steps: Some(u64::MAX),
        max_total_steps: opts.max_steps,
        max_wall_clock: opts.max_wall_clock,
        stop_time: opts.output_times.last().copied(),
        max_order: opts.twin_max_order,
        stab_lim_det: opts.twin_stab_lim_det,
        ..CvodeOptions::default()
    };
    let ode = Arc::new(dec.ode);
    summary.solver = "CVODE".into();
    summary.unknowns = ode.n;
    summary.linear_solver = opts.linear_solver.resolved_name(ode.n).into();
    let clock = ThreadTime::now();
    let mut cv = make_cvode(ode, t0, &y0, &cv_opts, opts)?;
    let events = event_eval(sys, &tapes, &multipliers);
    if events.len() > 0 {
        let mut ev = events.clone();
        cv.set_roots(ev.len(), Box::new(move |t, y, g| ev.roots(t, y, g)))?;
    }
    let mut out = OutputEval::new(sys, tapes, &multipliers);
    let mut sol = Solution {
        columns: out.columns.clone(),
        times: Vec::new(),
        rows: Vec::new(),
        summary: Summary::default(),
    };
    let first = out.row(t0, &y0);
    let stop = emit(&mut sol, observer, t0, first, opts.keep_rows);
    if !stop {
        let mut k = 1;
        while k < opts.output_times.len() {
            let step = match cv.solve_to(opts.output_times[k]) {
                Ok(s) => s,
                Err(e) => {
                    fill_stats(summary, &cv.stats());
                    summary.cpu_seconds = clock.elapsed().as_secs_f64();
                    summary.max_constraint_error = out.max_g;
                    set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
                    let last = e.time().filter(|_| is_budget(&e)).and_then(|tr| {
                        let mut y = vec![0.0; cv.y().len()];
                        cv.dky(tr, 0, &mut y).ok()?;
                        Some((tr, out.row(tr, &y)))
                    });
                    return Err(stopped(e, sol, summary.clone(), last));
                }
            };
            if let StepEvent::Root(info) = &step.event {
                let Some(stop) = events_fired(&sys.events, info, step.t, summary) else {
                    continue;
                };
                let row = out.row(step.t, cv.y());
                if emit(&mut sol, observer, step.t, row, opts.keep_rows) || stop {
                    break;
                }
                continue;
            }
            k += 1;
            let row = out.row(step.t, cv.y());
            if emit(&mut sol, observer, step.t, row, opts.keep_rows) {
                break;
            }
        }
    }
    summary.cpu_seconds = clock.elapsed().as_secs_f64();
    fill_stats(summary, &cv.stats());
    summary.max_constraint_error = out.max_g;
    set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
    set_completed(summary, &sol);
    sol.summary = summary.clone();
    Ok(sol)
}

/// Hands a row to the observer and appends it to the solution (with `keep` false, the
/// solution keeps only its latest row: [`SolveOptions::keep_rows`]); `true` when the observer
/// asks to stop.
pub(crate) fn emit(
    sol: &mut Solution,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    t: f64,
    row: Vec<f64>,
    keep: bool,
) -> bool {
    let brk = observer(Row { t, values: &row }).is_break();
    if !keep {
        sol.times.clear();
        sol.rows.clear();
    }
    sol.times.push(t);
    sol.rows.push(row);
    brk
}

/// The scene's event functions with the reactions read from `multipliers`.
fn event_eval(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    multipliers: &Multipliers,
) -> EventEval {
    EventEval::new(sys, || {
        ReactionEval::new(sys, &tapes.gv, multipliers.clone())
    })
}

/// The multipliers an IDA formulation's events read: solved from the interpolated `(t, q, v)`
/// ([`Multipliers::FromState`]), not interpolated (IDA's error test leaves them out).
fn solved_multipliers(sys: &MultibodySystem, tapes: &MechanicsTapes) -> Multipliers {
    Multipliers::FromState(Box::new(StateMultipliers::new(
        tapes.forces.clone(),
        tapes.gamma.clone(),
        sys.mass.clone(),
    )))
}

/// Whether a solve computes reactions at all (as output columns or inside an event).
fn needs_reactions(sys: &MultibodySystem) -> bool {
    sys.reaction_outputs || sys.events.iter().any(|e| e.uses_reactions)
}

/// Registers the event functions as IDA root functions (nothing when there are none).
fn set_ida_events(ida: &mut Ida, events: &EventEval) -> Result<(), Error> {
    if events.len() == 0 {
        return Ok(());
    }
    let mut ev = events.clone();
    ida.set_roots(ev.len(), Box::new(move |t, y, _yp, g| ev.roots(t, y, g)))?;
    Ok(())
}

/// The events that count at a root return at `t` (`info[i]`: +1 rising, −1 falling, 0 not
/// crossing), recorded in the summary; `None` when none counts (a crossing in a direction the
/// event ignores), else whether one of them stops the run.
fn events_fired(
    events: &[EventFunction],
    info: &[i32],
    t: f64,
    summary: &mut Summary,
) -> Option<bool> {
    let mut stop = None;
    for (e, &sign) in events.iter().zip(info) {
        if e.direction.accepts(sign) {
            summary.events.push(EventRecord {
                name: e.name.clone(),
                t,
            });
            stop = Some(stop.unwrap_or(false) || e.action == EventAction::Stop);
        }
    }
    stop
}
