//! Callback types and the panic-safe guard every trampoline runs closures under.
//!
//! A closure result maps to the SUNDIALS convention: `Ok` → 0, `Recoverable` → +1
//! (retry with a smaller step), `Fatal` or a panic → -1 (stop); the fatal message or
//! panic payload is remembered in `CallbackStatus` and surfaces from the solve call.

use super::error::{CallbackError, CallbackResult, SolverError};
use super::matrix::DenseMatrixMut;
use super::sparse::SparseMatrixMut;
use std::os::raw::c_int;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// IDA residual `F(t, y, y') → r`.
pub type ResidualFn = Box<dyn FnMut(f64, &[f64], &[f64], &mut [f64]) -> CallbackResult + Send>;
/// IDA Jacobian `(t, cj, y, y', J)`: fill `J = ∂F/∂y + cj ∂F/∂y'`.
pub type IdaJacobianFn =
    Box<dyn FnMut(f64, f64, &[f64], &[f64], &mut DenseMatrixMut<'_>) -> CallbackResult + Send>;
/// IDA sparse Jacobian `(t, cj, y, y', J)`: fill the values of `J = ∂F/∂y + cj ∂F/∂y'` in
/// its fixed [`super::sparse::CscPattern`] (they arrive zeroed).
pub type IdaSparseJacobianFn =
    Box<dyn FnMut(f64, f64, &[f64], &[f64], &mut SparseMatrixMut<'_>) -> CallbackResult + Send>;
/// IDA root functions `g(t, y, y') → gout`.
pub type IdaRootFn = Box<dyn FnMut(f64, &[f64], &[f64], &mut [f64]) -> CallbackResult + Send>;
/// IDA error weights `(t, y, ewt)`: `ewt` arrives as `1 / (rtol |y_i| + atol_i)` and the
/// closure may raise entries (never lower them to zero or below); `t` is the time of the last
/// residual evaluation (IDA asks for weights after a step, at the step's end).
pub type ErrorWeightFn = Box<dyn FnMut(f64, &[f64], &mut [f64]) -> CallbackResult + Send>;
/// CVODE right-hand side `f(t, y) → ydot`.
pub type RhsFn = Box<dyn FnMut(f64, &[f64], &mut [f64]) -> CallbackResult + Send>;
/// CVODE Jacobian `(t, y, f(t, y), J)`: fill `J = ∂f/∂y`.
pub type CvodeJacobianFn =
    Box<dyn FnMut(f64, &[f64], &[f64], &mut DenseMatrixMut<'_>) -> CallbackResult + Send>;
/// CVODE sparse Jacobian `(t, y, f(t, y), J)`: fill the values of `J = ∂f/∂y` in its fixed
/// [`super::sparse::CscPattern`] (they arrive zeroed).
pub type CvodeSparseJacobianFn =
    Box<dyn FnMut(f64, &[f64], &[f64], &mut SparseMatrixMut<'_>) -> CallbackResult + Send>;
/// CVODE root functions `g(t, y) → gout`.
pub type CvodeRootFn = Box<dyn FnMut(f64, &[f64], &mut [f64]) -> CallbackResult + Send>;

/// Non-finite outputs of a residual or right-hand side in a row, all within
/// [`STUCK_WINDOW`] (relative) of each other in time, after which the solver is stuck: the
/// integrator keeps shrinking its step against a NaN or ∞ it cannot step past (steps accumulate
/// toward the point like Zeno's), and the callback stops the solve with
/// [`SolverError::NonFinite`] instead of letting it run to the step or wall-clock budget.
pub(crate) const STUCK_EVALUATIONS: usize = 25;
/// Relative time window of [`STUCK_EVALUATIONS`].
pub(crate) const STUCK_WINDOW: f64 = 1e-9;

/// The last evaluation of a residual or right-hand side with a non-finite output.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct NonFiniteEval {
    pub(crate) t: f64,
    pub(crate) y: Vec<f64>,
    pub(crate) index: usize,
    pub(crate) value: f64,
}

/// What went wrong inside callbacks during the current solve call.
#[derive(Debug, Default)]
pub(crate) struct CallbackStatus {
    panic: Option<(f64, String)>,
    fatal: Option<(f64, String)>,
    /// Last message SUNDIALS passed to the error handler.
    pub(crate) last_message: Option<String>,
    /// Last residual / right-hand side evaluation with a non-finite output.
    non_finite: Option<NonFiniteEval>,
    /// Times of the latest non-finite evaluations (at most [`STUCK_EVALUATIONS`]).
    recent: std::collections::VecDeque<f64>,
    /// Set when the solver was found stuck on non-finite values.
    stuck: Option<(&'static str, NonFiniteEval)>,
}

impl CallbackStatus {
    pub(crate) fn clear(&mut self) {
        *self = CallbackStatus::default();
    }

    /// Run `f`, translating its outcome to a SUNDIALS return code. Inlined into each
    /// trampoline (once per residual: left to LLVM, a change elsewhere in the crate turned it
    /// into a call, +0.2 % of the peers' double pendulum's instructions).
    #[inline(always)]
    pub(crate) fn guard(&mut self, t: f64, f: impl FnOnce() -> CallbackResult) -> c_int {
        if self.panic.is_some() || self.fatal.is_some() || self.stuck.is_some() {
            return -1;
        }
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(Ok(())) => 0,
            Ok(Err(CallbackError::Recoverable(_))) => 1,
            Ok(Err(CallbackError::Fatal(message))) => {
                self.fatal = Some((t, message));
                -1
            }
            Err(payload) => {
                let message = payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "non-string panic payload".to_string());
                self.panic = Some((t, message));
                -1
            }
        }
    }

    /// After `guard` of a residual or right-hand side (`what`): a non-finite output turns
    /// success into a recoverable failure (SUNDIALS retries with a smaller step) and is
    /// remembered with `(t, y)`; once [`STUCK_EVALUATIONS`] of them fall within
    /// [`STUCK_WINDOW`] in time, the failure is fatal and the solve call returns
    /// [`SolverError::NonFinite`].
    pub(crate) fn check_output(
        &mut self,
        what: &'static str,
        code: c_int,
        t: f64,
        y: &[f64],
        out: &[f64],
    ) -> c_int {
        if code != 0 {
            return code;
        }
        // the common case first: one pass without early exit, which the compiler vectorises
        // (the search for the first non-finite entry cost ~9 instructions per entry: 8k per
        // 30 × 30 Newton matrix)
        if !out.iter().fold(false, |bad, v| bad | !v.is_finite()) {
            return 0;
        }
        let Some((index, &value)) = out.iter().enumerate().find(|(_, v)| !v.is_finite()) else {
            return 0;
        };
        let eval = NonFiniteEval {
            t,
            y: y.to_vec(),
            index,
            value,
        };
        if self.recent.len() == STUCK_EVALUATIONS {
            self.recent.pop_front();
        }
        self.recent.push_back(t);
        let (lo, hi) = self
            .recent
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        self.non_finite = Some(eval.clone());
        if self.recent.len() == STUCK_EVALUATIONS && hi - lo <= STUCK_WINDOW * hi.abs().max(1.0) {
            self.stuck = Some((what, eval));
            return -1;
        }
        1
    }

    /// The solver failed at `t_reached` (its last accepted time): when a residual or
    /// right-hand side was non-finite after it, that is the likely cause, returned as
    /// [`SolverError::NonFinite`] for `function`.
    pub(crate) fn take_non_finite(
        &mut self,
        function: &'static str,
        what: &'static str,
        t_reached: f64,
    ) -> Option<SolverError> {
        let e = self.non_finite.take().filter(|e| e.t >= t_reached)?;
        Some(SolverError::NonFinite {
            function,
            what,
            t: e.t,
            index: e.index,
            value: e.value,
            y: e.y,
            stuck: false,
        })
    }

    /// Error recorded by a callback, preferred over the SUNDIALS flag it caused.
    pub(crate) fn take_error(&mut self) -> Option<SolverError> {
        if let Some((t, message)) = self.panic.take() {
            return Some(SolverError::CallbackPanic { t, message });
        }
        if let Some((what, e)) = self.stuck.take() {
            return Some(SolverError::NonFinite {
                function: "",
                what,
                t: e.t,
                index: e.index,
                value: e.value,
                y: e.y,
                stuck: true,
            });
        }
        self.fatal
            .take()
            .map(|(t, message)| SolverError::CallbackFailed { t, message })
    }
}

/// Like `guard`, but non-finite outputs turn success into a recoverable failure.
pub(crate) fn finite_or_recoverable(code: c_int, out: &[f64]) -> c_int {
    if code == 0 && out.iter().any(|x| !x.is_finite()) {
        1
    } else {
        code
    }
}

/// Error-handler trampoline (`IDASetErrHandlerFn`/`CVodeSetErrHandlerFn`): keep the
/// last message in the [`CallbackStatus`] at `eh_data` instead of printing to stderr.
pub(crate) unsafe extern "C" fn error_handler(
    _code: c_int,
    module: *const std::os::raw::c_char,
    function: *const std::os::raw::c_char,
    msg: *mut std::os::raw::c_char,
    eh_data: *mut std::os::raw::c_void,
) {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: eh_data is the CallbackStatus registered together with this handler,
        // which lives in a Box owned by the solver for as long as the SUNDIALS memory;
        // the strings are NUL-terminated C strings valid for this call (or NULL).
        unsafe {
            let status = &mut *(eh_data as *mut CallbackStatus);
            let text = |p: *const std::os::raw::c_char| {
                if p.is_null() {
                    String::new()
                } else {
                    std::ffi::CStr::from_ptr(p).to_string_lossy().into_owned()
                }
            };
            status.last_message = Some(format!(
                "[{} {}] {}",
                text(module),
                text(function),
                text(msg)
            ));
        }
    }));
}
