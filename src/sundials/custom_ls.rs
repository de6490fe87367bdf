//! A user-supplied linear solver for IDA's Newton systems `J x = b`,
//! `J = ∂F/∂y + cj ∂F/∂y'`, wrapped as a custom "matrix-embedded" `SUNLinearSolver`
//! (`SUNLinSolNewEmpty` + ops; IDA then passes no `SUNMatrix` and never calls
//! `lsetup`, so `solve` re-runs the user's `setup` whenever `(t, cj)` changed, i.e.
//! once per Newton solve; the Jacobian is reused across the iterations of a step).
//!
//! Limitation: during `calc_ic` the state reported by `IDAGetCurrentY` is the step
//! state, not the IC iterate; use the dense solver for `calc_ic`-heavy problems.

use super::callback::{finite_or_recoverable, CallbackStatus};
use super::context::Context;
use super::error::{CallbackResult, SolverError};
use super::linsol::{self, LinearSolver, OwnLinearSolver};
use super::vector::slice_of;
use std::os::raw::{c_int, c_void};
use std::ptr;
use sundials_sys as sys;

/// A linear solver for IDA's Newton iteration matrix `J = ∂F/∂y + cj ∂F/∂y'`.
pub trait IdaLinearSolver: Send {
    /// Form and factor `J` at `(t, y, y')` with coefficient `cj`.
    fn setup(&mut self, t: f64, cj: f64, y: &[f64], yp: &[f64]) -> CallbackResult;
    /// Overwrite `b` with the solution `x` of `J x = b` for the last `setup`.
    fn solve(&mut self, b: &mut [f64]) -> CallbackResult;
}

struct Content {
    solver: Box<dyn IdaLinearSolver>,
    n: usize,
    ida_mem: *mut c_void,
    status: *mut CallbackStatus,
    last_setup: Option<(f64, f64)>,
}

impl OwnLinearSolver for Content {
    const KIND: sys::SUNLinearSolver_Type =
        sys::SUNLinearSolver_Type_SUNLINEARSOLVER_MATRIX_EMBEDDED;

    fn order(&self) -> Option<usize> {
        (!self.ida_mem.is_null() && !self.status.is_null()).then_some(self.n)
    }

    /// Sets the user's solver up again where `(t, cj)` changed, then solves.
    fn solve(&mut self, xs: &mut [f64]) -> c_int {
        // SAFETY: attached (`order` checked it) to live IDA memory and a live CallbackStatus,
        // both owned by the same Ida; the current y/y' vectors belong to IDA and have length n.
        let (status, t, cj, y, yp) = unsafe {
            let status = &mut *self.status;
            let (mut t, mut cj) = (0.0, 0.0);
            let (mut ycur, mut ypcur): (sys::N_Vector, sys::N_Vector) =
                (ptr::null_mut(), ptr::null_mut());
            sys::IDAGetCurrentTime(self.ida_mem, &mut t);
            sys::IDAGetCurrentCj(self.ida_mem, &mut cj);
            sys::IDAGetCurrentY(self.ida_mem, &mut ycur);
            sys::IDAGetCurrentYp(self.ida_mem, &mut ypcur);
            if ycur.is_null() || ypcur.is_null() {
                return -1;
            }
            (
                status,
                t,
                cj,
                slice_of(ycur, self.n),
                slice_of(ypcur, self.n),
            )
        };
        if self.last_setup != Some((t, cj)) {
            let solver = &mut self.solver;
            let code = status.guard(t, || solver.setup(t, cj, y, yp));
            if code != 0 {
                self.last_setup = None;
                return code;
            }
            self.last_setup = Some((t, cj));
        }
        let solver = &mut self.solver;
        let code = status.guard(t, || solver.solve(xs));
        finite_or_recoverable(code, xs)
    }
}

/// Build the custom `SUNLinearSolver` (not yet attached to IDA memory).
pub(crate) fn new_linear_solver(
    ctx: &Context,
    solver: Box<dyn IdaLinearSolver>,
    n: usize,
) -> Result<LinearSolver, SolverError> {
    linsol::own(
        ctx,
        Content {
            solver,
            n,
            ida_mem: ptr::null_mut(),
            status: ptr::null_mut(),
            last_setup: None,
        },
    )
}

/// Tell the custom solver which IDA memory and callback status it serves.
///
/// # Safety
/// `ls` must come from [`new_linear_solver`]; `ida_mem` and `status` must outlive it.
pub(crate) unsafe fn attach(
    ls: &mut LinearSolver,
    ida_mem: *mut c_void,
    status: *mut CallbackStatus,
) {
    if let Some(c) = ls.content_mut::<Content>() {
        c.ida_mem = ida_mem;
        c.status = status;
    }
}
