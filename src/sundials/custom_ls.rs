//! A user-supplied linear solver for IDA's Newton systems `J x = b`,
//! `J = ∂F/∂y + cj ∂F/∂y'`, wrapped as a custom "matrix-embedded" `SUNLinearSolver`
//! (`SUNLinSolNewEmpty` + ops; IDA then passes no `SUNMatrix` and never calls
//! `lsetup`, so `solve` re-runs the user's `setup` whenever `(t, cj)` changed, i.e.
//! once per Newton solve; the Jacobian is reused across the iterations of a step).
//!
//! Limitation: during `calc_ic` the state reported by `IDAGetCurrentY` is the step
//! state, not the IC iterate; use the dense solver for `calc_ic`-heavy problems.

use super::callback::CallbackStatus;
use super::context::Context;
use super::error::{CallbackResult, SolverError};
use super::linsol::{self, LinearSolver};
use super::vector::{slice_of, slice_of_mut};
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

unsafe extern "C" fn get_type(_s: sys::SUNLinearSolver) -> sys::SUNLinearSolver_Type {
    sys::SUNLinearSolver_Type_SUNLINEARSOLVER_MATRIX_EMBEDDED
}

unsafe extern "C" fn no_op(_s: sys::SUNLinearSolver) -> c_int {
    0
}

unsafe extern "C" fn no_setup(_s: sys::SUNLinearSolver, _a: sys::SUNMatrix) -> c_int {
    0
}

unsafe extern "C" fn zero_iters(_s: sys::SUNLinearSolver) -> c_int {
    0
}

unsafe extern "C" fn solve(
    s: sys::SUNLinearSolver,
    _a: sys::SUNMatrix,
    x: sys::N_Vector,
    b: sys::N_Vector,
    _tol: f64,
) -> c_int {
    // SAFETY: `content` is the Box<Content> installed by new_linear_solver, attached
    // to live IDA memory and a live CallbackStatus (both owned by the same Ida);
    // x and b are serial vectors of length n, the current y/y' vectors belong to IDA.
    unsafe {
        let c = &mut *((*s).content as *mut Content);
        if c.ida_mem.is_null() || c.status.is_null() {
            return -1;
        }
        let status = &mut *c.status;
        let (mut t, mut cj) = (0.0, 0.0);
        let (mut ycur, mut ypcur): (sys::N_Vector, sys::N_Vector) =
            (ptr::null_mut(), ptr::null_mut());
        sys::IDAGetCurrentTime(c.ida_mem, &mut t);
        sys::IDAGetCurrentCj(c.ida_mem, &mut cj);
        sys::IDAGetCurrentY(c.ida_mem, &mut ycur);
        sys::IDAGetCurrentYp(c.ida_mem, &mut ypcur);
        if ycur.is_null() || ypcur.is_null() {
            return -1;
        }
        if c.last_setup != Some((t, cj)) {
            let (y, yp) = (slice_of(ycur, c.n), slice_of(ypcur, c.n));
            let solver = &mut c.solver;
            let code = status.guard(t, || solver.setup(t, cj, y, yp));
            if code != 0 {
                c.last_setup = None;
                return code;
            }
            c.last_setup = Some((t, cj));
        }
        let xs = slice_of_mut(x, c.n);
        xs.copy_from_slice(slice_of(b, c.n));
        let solver = &mut c.solver;
        let code = status.guard(t, || solver.solve(xs));
        if code == 0 && xs.iter().any(|v| !v.is_finite()) {
            return 1;
        }
        code
    }
}

/// Build the custom `SUNLinearSolver` (not yet attached to IDA memory).
pub(crate) fn new_linear_solver(
    ctx: &Context,
    solver: Box<dyn IdaLinearSolver>,
    n: usize,
) -> Result<LinearSolver, SolverError> {
    let content = Box::new(Content {
        solver,
        n,
        ida_mem: ptr::null_mut(),
        status: ptr::null_mut(),
        last_setup: None,
    });
    linsol::custom(ctx, get_type, content, |ops| {
        ops.initialize = Some(no_op);
        ops.setup = Some(no_setup);
        ops.solve = Some(solve);
        ops.numiters = Some(zero_iters);
    })
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
    // SAFETY: guaranteed by the caller: content is our Box<Content>.
    unsafe {
        let c = &mut *((*ls.raw()).content as *mut Content);
        c.ida_mem = ida_mem;
        c.status = status;
    }
}
