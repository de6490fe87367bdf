//! The solve layer's own error: what can stop a solve, each from the layer below that owns it
//! (no consistent start: [`InitError`]; a formulation that cannot be built: [`MechError`]; the
//! integrator: [`SolverError`]), and a solve stopped part-way with the rows it kept
//! ([`SolveError::Incomplete`]). [`crate::Error`] wraps it at the top (`From`), variant by
//! variant, with the same messages.

use super::solution::Solution;
use crate::dae::InitError;
use crate::mech::{MechError, NonFiniteValue};
use crate::sundials::SolverError;

/// Everything that can stop a solve.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SolveError {
    /// No consistent initial state (or no regular partition where one is needed).
    #[error("initialisation: {0}")]
    Init(#[from] InitError),
    /// The formulation cannot be built.
    #[error("{0}")]
    Mechanism(#[from] MechError),
    /// The integrator failed (function, flag and time in the message).
    #[error("{0}")]
    Solver(#[from] SolverError),
    /// A load of the scene (or a parameter or law of a raw bond graph element) evaluates to NaN
    /// or ±∞ during the solve, or grows without bound where the steps stopped (a pole of a
    /// load of time, `1/(t - 0.1)`): which one (JSON path, name, expression) and when.
    #[error("{culprit}{}", if *stuck { "; the solver cannot step past it" } else { "" })]
    NonFinite {
        /// The culprit, its value and the time.
        culprit: Box<NonFiniteValue>,
        /// Whether the solver's steps piled up against it (rather than failing otherwise).
        stuck: bool,
        /// The solver's own error.
        #[source]
        solver: Box<SolverError>,
    },
    /// Invalid solve options.
    #[error("invalid options: {0}")]
    Options(String),
    /// A raw bond graph is invalid or cannot be turned into equations.
    #[error("bond graph: {0}")]
    BondGraph(String),
    /// The solve stopped before its last output time — a budget (`max_steps`,
    /// `max_wall_seconds`) ran out or the solver failed — and kept what it had computed:
    /// `partial` holds the rows up to the time reached (its summary has `completed: false`,
    /// `t_reached` and `stopped_by`).
    #[error("{cause}; {}", kept(partial))]
    Incomplete {
        /// Why the solve stopped.
        cause: Box<SolveError>,
        /// The rows computed up to the time reached, and the statistics so far.
        partial: Box<Solution>,
    },
}

impl SolveError {
    /// The rows computed before the solve stopped, when it stopped part-way.
    pub fn partial_solution(&self) -> Option<&Solution> {
        match self {
            SolveError::Incomplete { partial, .. } => Some(partial),
            _ => None,
        }
    }

    /// Applies `f` to the partial solution of an [`SolveError::Incomplete`]; other errors pass.
    pub fn map_partial(mut self, f: impl FnOnce(&mut Solution)) -> Self {
        if let SolveError::Incomplete { partial, .. } = &mut self {
            f(partial);
        }
        self
    }
}

/// What raises the budget that stopped a solve (`summary.stopped_by`), as a parenthesis for
/// the message; empty when no budget stopped it.
pub fn budget_hint(stopped_by: Option<&str>) -> &'static str {
    match stopped_by {
        Some("max_steps") => " (raise solve.max_steps or --max-steps to go further)",
        Some("max_wall_seconds") => {
            " (raise solve.max_wall_seconds or --max-wall-seconds to go further)"
        }
        _ => "",
    }
}

/// "stopped at t = …: the rows up to t = … are kept".
pub(crate) fn kept(partial: &Solution) -> String {
    let s = &partial.summary;
    let hint = budget_hint(s.stopped_by.as_deref());
    match partial.times.last() {
        Some(t) => format!(
            "stopped at t = {}{hint}; the {} rows up to t = {t} are kept",
            s.t_reached,
            partial.times.len()
        ),
        None => format!(
            "stopped at t = {}{hint}; no rows were computed",
            s.t_reached
        ),
    }
}
