//! The one interface between a formulation and the executor (`super::executor`), after
//! diffsol's problem/method split and argmin's executor: a formulation says *what* is
//! integrated, the executor *how* (output times, events, budgets, partial rows, statistics,
//! energy drift, streaming), for IDA, CVODE and ARKODE alike.
//!
//! A run is a sequence of segments. Each segment integrates one `Problem` from a time `t`:
//!
//! * `Problem::Implicit`: the fully implicit DAE `F(t, y, y') = 0` on IDA, with its exact
//!   iteration matrix `J = ∂F/∂y + c_j ∂F/∂y'` and its sparsity (`DaeFormulation`), the id
//!   vector (differential or algebraic unknowns), per-unknown absolute tolerances and a
//!   consistent start `(y₀, y₀')`; optionally the dependent blocks whose elimination solves
//!   the Newton matrix (a Schur complement);
//! * `Problem::Explicit`: the ODE `y' = f(t, y)` with its exact Jacobian `∂f/∂y` and
//!   sparsity (`ExplicitOde`) on CVODE BDF;
//! * `Problem::Reduced`: an ODE `y' = f(t, y)` on few states (the partitioned formulation's
//!   degrees of freedom) on CVODE (Adams or BDF, difference-quotient Jacobian) or ARKODE
//!   (explicit Runge–Kutta), with root functions of its own (switching functions).
//!
//! The integrator's state `y` is completed into the *row state* `x = [q, v, …]` the output rows
//! and events read (`Formulation::row_state`). The formulation keeps its own recoveries: the
//! executor calls `Formulation::recover` when the integrator fails and
//! `Formulation::at_output` after each output row, and the formulation answers with a
//! `Next`: go on, restart with a fresh segment (index-1 re-selection of the dependent set,
//! partitioned re-partition), or hand the rest of the run to another formulation (the `dae`
//! formulation's hand-over to the GGL). A switch that keeps the integrator (the GGL's
//! compliant switch at a singular passage: a new `ε` and a re-initialised IDA) is done in
//! place through `Solver`.

pub mod decoupled;
pub mod ggl;
pub mod implicit;
pub mod index1;
pub mod partitioned;
pub mod raw_graph;
pub(crate) mod shared;

pub use decoupled::DecoupledFormulation;
pub use ggl::GglFormulation;
pub use implicit::{DaeFormulation, GglDae, IdDae};
pub use index1::{error_test_mask, EnergyInvariant, Index1Formulation};
pub use partitioned::{PartitionedRhs, PartitionedSystem};

use std::sync::Arc;

use super::reactions::EventEval;
use super::solution::Summary;
use super::solver::Solver;
use crate::dae::ExplicitOde;
use crate::mech::EventFunction;
use crate::settings::Integrator;
use crate::solve::SolveError;
use crate::sundials::{CvodeRootFn, RhsFn, SolverError};

/// What one segment integrates (see the module documentation).
pub(crate) enum Problem {
    /// `F(t, y, y') = 0` on IDA.
    Implicit(ImplicitProblem),
    /// `y' = f(t, y)` with its exact Jacobian on CVODE BDF.
    Explicit(ExplicitProblem),
    /// `y' = f(t, y)` on a few states, on CVODE or ARKODE.
    Reduced(ReducedProblem),
}

/// The implicit DAE of a segment, on IDA.
pub(crate) struct ImplicitProblem {
    /// Residual, iteration matrix, sparsity and id vector.
    pub dae: Arc<dyn DaeFormulation>,
    /// Absolute tolerance of each unknown.
    pub atol: Vec<f64>,
    /// Consistent `y₀`.
    pub y0: Vec<f64>,
    /// Consistent `y₀'`.
    pub yp0: Vec<f64>,
    /// Solve the Newton matrix by eliminating the split's dependent blocks and factoring the
    /// Schur complement on its outer set, where the structure allows (else the linear solver of
    /// the options).
    pub schur: Option<crate::sundials::schur::SchurSplit>,
    /// Error weights raised above `1 / (rtol |y| + atol)` where an unknown's error reaches
    /// others the error test leaves out ([`crate::sundials::Ida::set_error_weights`]).
    pub weights: Option<crate::sundials::ErrorWeightFn>,
}

/// The explicit ODE of a segment, on CVODE BDF with Newton and the exact Jacobian.
pub(crate) struct ExplicitProblem {
    /// Right-hand side, Jacobian and sparsity.
    pub ode: Arc<ExplicitOde>,
    /// `y₀`.
    pub y0: Vec<f64>,
    /// CVODE's largest BDF order (`None`: 5).
    pub max_order: Option<i32>,
    /// CVODE's BDF stability limit detection.
    pub stab_lim_det: bool,
}

/// A reduced ODE of a segment (the partitioned formulation's degrees of freedom).
pub(crate) struct ReducedProblem {
    /// `adams` or `bdf` (CVODE, Newton on a difference-quotient Jacobian) or `erk` (ARKODE).
    pub integrator: Integrator,
    /// `y' = f(t, y)`.
    pub rhs: RhsFn,
    /// `y₀`.
    pub y0: Vec<f64>,
    /// Root functions over `y` (the events' and the switching functions'), their number, and
    /// whether the scene's events are among them (ARKODE then interpolates to the step's order).
    pub roots: Option<(usize, CvodeRootFn, bool)>,
    /// ARKODE's first step (its last step size before a restart).
    pub init_step: Option<f64>,
}

/// How a segment starts.
pub(crate) enum Start<'a> {
    /// Integrate this problem.
    Run(Problem),
    /// Hand the rest of the run to another formulation.
    HandOver(Box<HandOver<'a>>),
}

/// The rest of a run handed to another formulation, from the last output row at `t`.
pub(crate) struct HandOver<'a> {
    /// The formulation that continues, its rows and events.
    pub job: Job<'a>,
    /// Time of the last output row (where the other formulation starts).
    pub t: f64,
    /// The warning that names the hand-over.
    pub warning: String,
    /// CPU seconds spent building the other formulation.
    pub build_seconds: f64,
}

/// What the executor does after a recovery hook or an output check.
pub(crate) enum Next<'a> {
    /// Go on with the integrator as it is (the hook may have re-initialised it in place).
    Continue,
    /// Start a fresh segment ([`Formulation::segment`]) at the time given.
    Restart(f64),
    /// Hand the rest of the run to another formulation.
    HandOver(Box<HandOver<'a>>),
    /// Stop with the rows so far: after an integrator failure, with its error (a failure the
    /// formulation does not handle); after an examination at a step or an output, as
    /// stalled there.
    Fail,
    /// Stop with the rows so far and this error instead of the integrator's (the formulation
    /// names the cause: the block, the joints, the time).
    FailWith(SolverError),
}

/// How a run ended, for [`Formulation::finish`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ending {
    /// Reached the last output (or an observer or a `stop` event ended it).
    Completed,
    /// A budget or a failure stopped it part-way.
    Stopped,
    /// Handed to another formulation.
    HandedOver,
}

/// A formulation as the executor sees it (see the module documentation).
pub(crate) trait Formulation<'a> {
    /// The row state `[q, v, …]` of the first output row, at the start.
    fn first_row_state(&self) -> Vec<f64>;

    /// The problem of the segment starting at `t` (the first output time, or the time a
    /// [`Next::Restart`] named), or a hand-over. Sets the summary's `solver`, `unknowns` and
    /// `linear_solver` (the executor writes `schur` or the resolved linear solver where the
    /// problem asks for a Schur complement).
    fn segment(&mut self, t: f64, summary: &mut Summary) -> Result<Start<'a>, SolveError>;

    /// The row state of the integrator's `y` at `t` into `x` (default: `y` itself).
    fn row_state(&mut self, t: f64, y: &[f64], x: &mut Vec<f64>) -> Result<(), SolveError> {
        let _ = t;
        x.clear();
        x.extend_from_slice(y);
        Ok(())
    }

    /// After the output row at `t` (row state `x`; `more`: outputs remain): conditioning
    /// checks that re-choose a partition, switch the error test or hand over.
    fn at_output(
        &mut self,
        t: f64,
        x: &[f64],
        solver: &mut Solver,
        more: bool,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let _ = (t, x, solver, more, summary);
        Ok(Next::Continue)
    }

    /// Whether the executor asks [`Formulation::watch_step`] about every internal step of an
    /// implicit problem (IDA) between the outputs (default: no).
    fn watches_steps(&self) -> bool {
        false
    }

    /// A cheap check of IDA's internal step at `t` (its own state `y(t)`, not interpolated):
    /// `true` stops the integration there and the executor calls [`Formulation::at_step`].
    fn watch_step(&mut self, t: f64, y: &[f64]) -> bool {
        let _ = (t, y);
        false
    }

    /// After [`Formulation::watch_step`] stopped the integration at the step `t` with state
    /// `y`: go on, restart a segment there (a re-chosen partition), hand over, or fail.
    fn at_step(
        &mut self,
        t: f64,
        y: &[f64],
        solver: &mut Solver,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let _ = (t, y, solver, summary);
        Ok(Next::Continue)
    }

    /// The recovery hook: the integrator failed with `e` (not a budget) after the last row at
    /// `last.0` with row state `last.1`. Default: [`Next::Fail`].
    fn recover(
        &mut self,
        e: &SolverError,
        solver: &mut Solver,
        last: (f64, &[f64]),
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let _ = (e, solver, last, summary);
        Ok(Next::Fail)
    }

    /// At a root return at `t` whose roots `info` lie beyond the scene's events (the switching
    /// functions of a reduced problem): the formulation may integrate again to `t` and restart
    /// the integrator in place (default: nothing to do).
    fn at_switch(
        &mut self,
        t: f64,
        info: &[i32],
        solver: &mut Solver,
        summary: &mut Summary,
    ) -> Result<(), SolveError> {
        let _ = (t, info, solver, summary);
        Ok(())
    }

    /// A sensitivity run's `∂F/∂p_k` for the segment just started ([`Formulation::segment`])
    /// and what its start needs ([`ParameterRows`]; default: `None`, the formulation has no
    /// sensitivities).
    fn parameter_rows(
        &mut self,
        sym: &mut dyn ParameterSymbols,
    ) -> Option<Result<ParameterRows, SolveError>> {
        let _ = sym;
        None
    }

    /// The formulation's own figures in the summary at the end of the run (the executor has
    /// written the counters, CPU time, constraint error and energy).
    fn finish(
        &mut self,
        summary: &mut Summary,
        solver: Option<&Solver>,
        t_last: Option<f64>,
        ending: Ending,
    ) {
        let _ = (summary, solver, t_last, ending);
    }
}

/// The output rows of a run: columns, one row per output time from the row state
/// `x = [q, v, …]`, and the figures the summary reports from them.
pub(crate) trait RowEval {
    /// Column names (without `t`).
    fn columns(&self) -> Vec<String>;
    /// The row at `(t, x)`.
    fn row(&mut self, t: f64, x: &[f64]) -> Vec<f64>;
    /// Largest constraint error over the rows so far.
    fn max_constraint_error(&self) -> f64;
    /// `max |E(t) − E(0)|` relative to the energy's scale over the rows so far.
    fn energy_drift(&self) -> f64;
    /// Why energy is not conserved, if it is not.
    fn energy_exchange(&self) -> Option<String>;
    /// The drivers' work `∫ Σ P_d dt` over the rows so far (trapezoidal rule on the rows'
    /// `<driver>.power`), `None` without drivers.
    fn driver_work(&self) -> Option<f64> {
        None
    }
    /// How [`RowEval::driver_work`] was computed (the rule, the rows, the largest spacing),
    /// empty without drivers.
    fn driver_work_note(&self) -> String {
        String::new()
    }
}

/// What a sensitivity run needs of a formulation ([`Formulation::parameter_rows`]).
pub(crate) struct ParameterRows {
    /// `∂F/∂p_k`: one list of rows over `[t, y, y']` (in the DAE's row order) per parameter.
    pub rows: Vec<Vec<crate::expr::Expr>>,
    /// Rows `H(t, y, y'; p) = 0` the start must also meet where `F`'s rows leave unknowns
    /// undetermined (an index-2 DAE's hidden acceleration constraints), over `[t, y, y']` and
    /// the parameters' symbols; empty for an index-1 DAE.
    pub hidden: Vec<crate::expr::Expr>,
    /// Unknowns whose sensitivity starts at zero (multipliers that vanish on the solution).
    pub pinned: Vec<usize>,
}

/// The scene's events: their functions over the row state and what each does.
#[derive(Clone)]
pub(crate) struct Events {
    /// The event functions (root functions over `[t, q, v, …]`).
    pub eval: EventEval,
    /// Direction and action of each.
    pub defs: Vec<EventFunction>,
}

/// What the executor runs: a formulation, its rows and its events.
pub(crate) struct Job<'a> {
    /// The formulation.
    pub formulation: Box<dyn Formulation<'a> + 'a>,
    /// Its output rows.
    pub rows: Box<dyn RowEval + 'a>,
    /// The scene's events (none: `None`), registered as root functions on the implicit and
    /// explicit problems; a reduced problem brings its own root functions, the events first.
    pub events: Option<Events>,
}

/// A mechanism whose parameters are symbols in its expressions (a sensitivity run's:
/// `crate::sensitivity::symbols::SymbolicSystem` implements it): what a formulation needs to
/// build `∂F/∂p_k` from its own residual rows (a formulation's `parameter_rows`).
pub trait ParameterSymbols {
    /// The system, its expressions over `[t, q, v]` and the parameters' slots.
    fn system(&mut self) -> &mut crate::mech::MultibodySystem;
    /// `∂e/∂p_k` at the parameters' values, for every parameter `k` (expressions over the
    /// other slots).
    fn derivatives(&mut self, exprs: &[crate::expr::Expr]) -> Vec<Vec<crate::expr::Expr>>;
}
