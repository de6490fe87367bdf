//! Integrator counters ([`SolverStats`]).

use serde::Serialize;

/// Counters of an integrator since creation (or last `reinit`, as SUNDIALS counts).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SolverStats {
    /// Internal steps taken.
    pub steps: u64,
    /// Residual evaluations (IDA) or right-hand-side evaluations (CVODE).
    pub residual_evals: u64,
    /// Jacobian evaluations (user or difference quotient).
    pub jacobian_evals: u64,
    /// Linear solver setups.
    pub linear_setups: u64,
    /// Nonlinear (Newton) iterations.
    pub nonlinear_iterations: u64,
    /// Nonlinear convergence failures.
    pub nonlinear_conv_failures: u64,
    /// Local error test failures.
    pub error_test_failures: u64,
    /// Root function evaluations.
    pub root_evals: u64,
    /// Last step size used.
    pub last_step: f64,
    /// Last method order used.
    pub last_order: i32,
}

/// A step that IDA had to retry: the Newton iteration failed to converge, or the local error
/// test failed, before the step at `t` was accepted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RecoveredFailure {
    /// Time reached by the accepted step.
    pub t: f64,
    /// Newton convergence failures before it was accepted.
    pub convergence_failures: u32,
    /// Error test failures before it was accepted.
    pub error_test_failures: u32,
}

/// At most this many [`RecoveredFailure`]s are logged per solver (the counters in
/// [`SolverStats`] keep counting beyond).
pub const MAX_LOGGED_FAILURES: usize = 10_000;

impl SolverStats {
    /// Add the counters of `other` (e.g. a run after a restart); `last_*` taken from `other`.
    pub fn accumulate(&mut self, other: &SolverStats) {
        self.steps += other.steps;
        self.residual_evals += other.residual_evals;
        self.jacobian_evals += other.jacobian_evals;
        self.linear_setups += other.linear_setups;
        self.nonlinear_iterations += other.nonlinear_iterations;
        self.nonlinear_conv_failures += other.nonlinear_conv_failures;
        self.error_test_failures += other.error_test_failures;
        self.root_evals += other.root_evals;
        self.last_step = other.last_step;
        self.last_order = other.last_order;
    }
}
