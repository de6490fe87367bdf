//! The calls the three integrator wrappers (IDA, CVODE, ARKODE's ERKStep) make the same way,
//! written once: each wrapper names its C entry points and return flags in a [`Calls`] table,
//! and the unsafe sequences that use them live here — the time reached, the roots' directions,
//! a stop time, the interpolant, the counters, one internal step's outcome, and a failing flag
//! turned into an error.

use super::callback::CallbackStatus;
use super::error::{check, Package, SolverError};
use super::stats::SolverStats;
use super::stepping::RawEvent;
use std::os::raw::{c_int, c_long, c_void};
use sundials_sys as sys;

/// A counter's getter (`IDAGetNumSteps`, `CVodeGetNumRhsEvals`, …).
pub(crate) type Counter = unsafe extern "C" fn(*mut c_void, *mut c_long) -> c_int;

/// One integrator's C entry points and return flags.
pub(crate) struct Calls {
    /// The package, for the flags' names.
    pub(crate) package: Package,
    /// What the user function computes (`"residual"`, `"right-hand side"`), for errors.
    pub(crate) user_function: &'static str,
    /// `*GetCurrentTime`.
    pub(crate) current_time: unsafe extern "C" fn(*mut c_void, *mut f64) -> c_int,
    /// `*GetRootInfo`.
    pub(crate) root_info: unsafe extern "C" fn(*mut c_void, *mut c_int) -> c_int,
    /// `*SetStopTime`, by name.
    pub(crate) set_stop_time: (
        &'static str,
        unsafe extern "C" fn(*mut c_void, f64) -> c_int,
    ),
    /// `*GetDky`, by name.
    #[allow(clippy::type_complexity)]
    pub(crate) dky: (
        &'static str,
        unsafe extern "C" fn(*mut c_void, f64, c_int, sys::N_Vector) -> c_int,
    ),
    /// `*GetLastStep`.
    pub(crate) last_step: unsafe extern "C" fn(*mut c_void, *mut f64) -> c_int,
    /// `*GetLastOrder`, where the method has orders that change.
    pub(crate) last_order: Option<unsafe extern "C" fn(*mut c_void, *mut c_int) -> c_int>,
    /// The counters of [`SolverStats`], in its order (steps, residual or right-hand-side
    /// evaluations, Jacobians, linear setups, nonlinear iterations and convergence failures,
    /// error test failures, root evaluations); `None` where the integrator has none.
    pub(crate) counters: [Option<Counter>; 8],
    /// The step's return flags: success, root return, stop time reached.
    pub(crate) returns: [c_int; 3],
    /// The flag of a step budget run out (`*_TOO_MUCH_WORK`).
    pub(crate) too_much_work: c_int,
}

impl Calls {
    /// The time the integrator has reached internally (`fallback` if it cannot say).
    ///
    /// # Safety
    /// `mem` is live memory of the integrator these calls are for.
    pub(crate) unsafe fn current_time(&self, mem: *mut c_void, fallback: f64) -> f64 {
        let mut t = fallback;
        // SAFETY: the caller's contract, and a valid out-pointer.
        unsafe { (self.current_time)(mem, &mut t) };
        t
    }

    /// The directions of the `n` roots after a root return.
    ///
    /// # Safety
    /// `mem` is live memory of the integrator these calls are for, with `n` roots.
    pub(crate) unsafe fn root_info(&self, mem: *mut c_void, n: usize) -> Vec<i32> {
        let mut info = vec![0 as c_int; n];
        // SAFETY: the caller's contract; `info` has room for the n entries.
        unsafe { (self.root_info)(mem, info.as_mut_ptr()) };
        info
    }

    /// Do not step past `t`: `Err((function, flag))` on a failing flag.
    ///
    /// # Safety
    /// `mem` is live memory of the integrator these calls are for.
    pub(crate) unsafe fn set_stop_time(
        &self,
        mem: *mut c_void,
        t: f64,
    ) -> Result<(), (&'static str, c_int)> {
        // SAFETY: the caller's contract.
        let flag = unsafe { (self.set_stop_time.1)(mem, t) };
        ok(self.set_stop_time.0, flag)
    }

    /// The `k`-th derivative of the interpolant at `t` into `v`: `Err((function, flag))` on a
    /// failing flag.
    ///
    /// # Safety
    /// `mem` is live memory of the integrator these calls are for; `v` a serial vector of its
    /// length.
    pub(crate) unsafe fn dky(
        &self,
        mem: *mut c_void,
        t: f64,
        k: c_int,
        v: sys::N_Vector,
    ) -> Result<(), (&'static str, c_int)> {
        // SAFETY: the caller's contract.
        let flag = unsafe { (self.dky.1)(mem, t, k, v) };
        ok(self.dky.0, flag)
    }

    /// The integrator's counters.
    ///
    /// # Safety
    /// `mem` is live memory of the integrator these calls are for.
    pub(crate) unsafe fn stats(&self, mem: *mut c_void) -> SolverStats {
        let get = |f: Option<Counter>| {
            f.map_or(0, |f| {
                let mut v: c_long = 0;
                // SAFETY: the caller's contract, and a valid out-pointer.
                unsafe { f(mem, &mut v) };
                v.max(0) as u64
            })
        };
        let mut last_step = 0.0;
        let mut last_order: c_int = 0;
        // SAFETY: the caller's contract, and valid out-pointers.
        unsafe {
            (self.last_step)(mem, &mut last_step);
            if let Some(f) = self.last_order {
                f(mem, &mut last_order);
            }
        }
        let [steps, residual_evals, jacobian_evals, linear_setups, nonlinear_iterations, nonlinear_conv_failures, error_test_failures, root_evals] =
            self.counters.map(get);
        SolverStats {
            steps,
            residual_evals,
            jacobian_evals,
            linear_setups,
            nonlinear_iterations,
            nonlinear_conv_failures,
            error_test_failures,
            root_evals,
            last_step,
            last_order,
        }
    }

    /// What one internal step's return `flag` means; `None` for a failure.
    pub(crate) fn step_event(&self, flag: c_int) -> Option<RawEvent> {
        let [success, root, stop] = self.returns;
        match flag {
            f if f == success => Some(RawEvent::Success),
            f if f == root => Some(RawEvent::Root),
            f if f == stop => Some(RawEvent::StopTime),
            f if f < 0 => None,
            _ => Some(RawEvent::Success),
        }
    }

    /// The error of a failing `flag` from `function`: a callback's own error first (named
    /// after `function`), then a non-finite value of the user function, then a step budget
    /// run out (`max_steps`), else what the flag means; `t` where the integrator stands.
    pub(crate) fn failure(
        &self,
        status: &mut CallbackStatus,
        (function, flag): (&'static str, c_int),
        t: f64,
        max_steps: Option<u64>,
    ) -> SolverError {
        if let Some(mut e) = status.take_error() {
            if let SolverError::NonFinite { function: f, .. } = &mut e {
                *f = function;
            }
            return e;
        }
        if let Some(e) = status.take_non_finite(function, self.user_function, t) {
            return e;
        }
        if flag == self.too_much_work {
            if let Some(max_steps) = max_steps {
                return SolverError::TooMuchWork { t, max_steps };
            }
        }
        check(self.package, function, flag, t).expect_err("flag is negative")
    }
}

/// `Ok` for a flag that is not negative, else `(function, flag)`.
pub(crate) fn ok(function: &'static str, flag: c_int) -> Result<(), (&'static str, c_int)> {
    if flag < 0 {
        Err((function, flag))
    } else {
        Ok(())
    }
}

/// Refuses an output slice `out` (named `what`) whose length is not `n`.
pub(crate) fn check_output(what: &str, out: &[f64], n: usize) -> Result<(), SolverError> {
    if out.len() != n {
        return Err(SolverError::InvalidInput(format!(
            "{what} has length {}, expected {n}",
            out.len()
        )));
    }
    Ok(())
}
