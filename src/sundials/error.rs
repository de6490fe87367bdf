//! Errors: [`SolverError`] from solver calls, [`CallbackError`] from user closures.

use std::ffi::CStr;
use std::os::raw::{c_char, c_long, c_void};
use std::time::Duration;

extern "C" {
    fn free(p: *mut c_void);
}

/// Failure reported by a user callback (residual, right-hand side, Jacobian, roots).
#[derive(Clone, Debug, PartialEq)]
pub enum CallbackError {
    /// SUNDIALS may retry with a smaller step (callback returns +1).
    Recoverable(String),
    /// Stop the integration (callback returns -1); becomes [`SolverError::CallbackFailed`].
    Fatal(String),
}

/// Result of a user callback.
pub type CallbackResult = Result<(), CallbackError>;

/// Error from a SUNDIALS solver call.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SolverError {
    /// A SUNDIALS function returned a failing flag.
    #[error("{function} failed with {name} ({flag}) at t = {t}")]
    Flag {
        /// SUNDIALS function name, e.g. `IDASolve`.
        function: &'static str,
        /// Raw return flag.
        flag: i32,
        /// Flag name from `IDAGetReturnFlagName`/`CVodeGetReturnFlagName`, e.g. `IDA_CONV_FAIL`.
        name: String,
        /// Time reached by the integrator.
        t: f64,
    },
    /// A user callback panicked; the panic was caught.
    #[error("callback panicked at t = {t}: {message}")]
    CallbackPanic {
        /// Time argument of the panicking call.
        t: f64,
        /// Panic payload.
        message: String,
    },
    /// A user callback returned [`CallbackError::Fatal`].
    #[error("callback failed at t = {t}: {message}")]
    CallbackFailed {
        /// Time argument of the failing call.
        t: f64,
        /// Message of the callback.
        message: String,
    },
    /// The step budget of one solve call was exhausted.
    #[error("too much work: {max_steps} steps taken, reached t = {t}")]
    TooMuchWork {
        /// Time reached.
        t: f64,
        /// The budget.
        max_steps: u64,
    },
    /// The step budget of the whole integration (all calls together, see
    /// `IdaOptions::max_total_steps`) was exhausted.
    #[error("step budget exhausted: {max_steps} steps taken in all, reached t = {t}")]
    StepBudget {
        /// Time reached.
        t: f64,
        /// The budget.
        max_steps: u64,
    },
    /// The wall-clock budget of the solver (all its solve calls together) was exhausted.
    #[error("wall-clock limit {limit:?} exceeded, reached t = {t}")]
    WallClock {
        /// Time reached.
        t: f64,
        /// The budget.
        limit: Duration,
    },
    /// An interrupt (SIGINT, SIGTERM: [`crate::interrupt`]) asked the solve to stop; it stopped
    /// between two internal steps, the state at `t` as sound as after a budget stop.
    #[error("interrupted by {}, reached t = {t}", crate::interrupt::signal_name(*signal))]
    Interrupted {
        /// Time reached.
        t: f64,
        /// The signal's number (2: SIGINT, 15: SIGTERM).
        signal: i32,
    },
    /// The residual or right-hand side evaluated to NaN or ±∞ and the solver could not step
    /// past it: either it failed after such an evaluation, or its trial steps shrank against it
    /// ([`NonFinite::stuck`](SolverError::NonFinite)). `y` is the state of that evaluation, so
    /// that the caller can name the culprit (a load, a bond graph element).
    #[error("{}the {what} evaluates to {value} (component {index}) at t = {t}{}", if function.is_empty() { String::new() } else { format!("{function}: ") }, if *stuck { "; the solver cannot step past it" } else { "" })]
    NonFinite {
        /// SUNDIALS function that failed (empty when the callback stopped the solve).
        function: &'static str,
        /// `residual` or `right-hand side`.
        what: &'static str,
        /// Time of the evaluation.
        t: f64,
        /// First non-finite component of the output.
        index: usize,
        /// Its value.
        value: f64,
        /// The state `y` of the evaluation.
        y: Vec<f64>,
        /// Whether the solver's trial steps piled up against the non-finite value.
        stuck: bool,
    },
    /// The steps stopped advancing the time: `t + h == t` in floating point, the step size
    /// is below the resolution of doubles at `t` (a run at `t = 1e300`).
    #[error("the step cannot advance the time at t = {t:e}: {steps} steps in a row left it unchanged (t + h == t: the step size collapsed below the resolution of doubles there{})", if t.abs() >= FAR_FROM_ZERO { "; move solve.t_start toward 0" } else { ", which at this t means the equations themselves stop the steps (a singular or degrading Newton matrix), not the time's magnitude" })]
    NoProgress {
        /// Time reached.
        t: f64,
        /// Steps that did not advance it.
        steps: u32,
    },
    /// The step size collapsed: over the last [`stepping::COLLAPSE_WINDOW`] steps the mean
    /// step `h` is so small that reaching the next output `tout` would take more than
    /// [`stepping::COLLAPSED_STEPS_TO_GO`] steps (a model whose state or load grows without
    /// bound: `exp(1e6*t)` as a torque turns the body faster than any step can follow long
    /// before the value overflows). `index` and `value`: the state's largest component there.
    ///
    /// [`stepping::COLLAPSE_WINDOW`]: crate::sundials::stepping::COLLAPSE_WINDOW
    /// [`stepping::COLLAPSED_STEPS_TO_GO`]: crate::sundials::stepping::COLLAPSED_STEPS_TO_GO
    #[error("the step size collapsed at t = {t:e}: the last steps were {h:.1e} s on average, so the next output at t = {tout} is {steps_to_go:.1e} steps away (the largest unknown is {value:.3e}, component {index}: the model is running away, a state or load growing without bound)")]
    StepCollapse {
        /// Time reached.
        t: f64,
        /// Mean step of the last window.
        h: f64,
        /// The next output time.
        tout: f64,
        /// Steps still needed at that pace.
        steps_to_go: f64,
        /// Index of the state's largest component.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The formulation's equations stopped the steps at `t` (a failure or a step size
    /// collapse it has diagnosed), `cause` naming what degraded (the block, the joints).
    #[error("the formulation cannot go on at t = {t}: {cause}")]
    Stalled {
        /// Time reached.
        t: f64,
        /// What degraded, in the formulation's terms.
        cause: String,
    },
    /// Bad arguments (lengths, non-finite values, ...).
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

/// `|t|` from which the resolution of doubles itself (`ulp(t) ≥ 2⁻²⁰ ≈ 1e-6`, at `|t| ≥ 2³² ≈
/// 4e9`) limits the steps, so that moving the start toward 0 is the remedy of a
/// [`SolverError::NoProgress`]; nearer 0 a step that leaves `t` unchanged has collapsed.
pub const FAR_FROM_ZERO: f64 = 4.294_967_296e9;

impl SolverError {
    /// Integration time at which the error happened, if there is one.
    pub fn time(&self) -> Option<f64> {
        match self {
            SolverError::Flag { t, .. }
            | SolverError::CallbackPanic { t, .. }
            | SolverError::CallbackFailed { t, .. }
            | SolverError::TooMuchWork { t, .. }
            | SolverError::StepBudget { t, .. }
            | SolverError::WallClock { t, .. }
            | SolverError::Interrupted { t, .. }
            | SolverError::NoProgress { t, .. }
            | SolverError::StepCollapse { t, .. }
            | SolverError::Stalled { t, .. }
            | SolverError::NonFinite { t, .. } => Some(*t),
            SolverError::InvalidInput(_) => None,
        }
    }
}

/// Which SUNDIALS package a flag comes from (for flag names).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Package {
    Ida,
    Cvode,
    Arkode,
}

/// Name of a return flag, e.g. `IDA_CONV_FAIL`.
pub(crate) fn flag_name(package: Package, flag: i32) -> String {
    // SAFETY: the Get*ReturnFlagName functions accept any flag value and return a
    // malloc'ed NUL-terminated string (or NULL), which we copy and then free.
    unsafe {
        let p: *mut c_char = match package {
            Package::Ida => sundials_sys::IDAGetReturnFlagName(flag as c_long),
            Package::Cvode => sundials_sys::CVodeGetReturnFlagName(flag as c_long),
            Package::Arkode => super::arkode_ffi::ERKStepGetReturnFlagName(flag as c_long),
        };
        if p.is_null() {
            return format!("UNKNOWN_FLAG_{flag}");
        }
        let name = CStr::from_ptr(p).to_string_lossy().into_owned();
        free(p.cast());
        name
    }
}

/// `Ok(())` for non-negative flags, else a [`SolverError::Flag`].
pub(crate) fn check(
    package: Package,
    function: &'static str,
    flag: i32,
    t: f64,
) -> Result<(), SolverError> {
    if flag >= 0 {
        Ok(())
    } else {
        Err(SolverError::Flag {
            function,
            flag,
            name: flag_name(package, flag),
            t,
        })
    }
}
