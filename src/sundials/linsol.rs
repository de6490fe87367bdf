//! RAII owner of a `SUNLinearSolver` (the dense LU of `super::dense_lu`, or a custom one from
//! [`super::custom_ls`]).

use super::context::Context;
use super::error::SolverError;
use std::os::raw::{c_int, c_void};
use sundials_sys as sys;

/// Owned `SUNLinearSolver`, freed with `SUNLinSolFree` on drop.
pub(crate) struct LinearSolver {
    raw: sys::SUNLinearSolver,
}

impl LinearSolver {
    /// Take ownership of an already-built solver.
    ///
    /// # Safety
    /// `raw` must be a valid solver whose `free` op releases everything it owns.
    pub(crate) unsafe fn from_raw(raw: sys::SUNLinearSolver) -> LinearSolver {
        LinearSolver { raw }
    }

    pub(crate) fn raw(&self) -> sys::SUNLinearSolver {
        self.raw
    }
}

impl Drop for LinearSolver {
    fn drop(&mut self) {
        // SAFETY: `raw` is owned and freed exactly once, after the integrator memory.
        unsafe {
            sys::SUNLinSolFree(self.raw);
        }
    }
}

/// `gettype` of a matrix-based direct solver of ours.
pub(crate) unsafe extern "C" fn direct_type(_s: sys::SUNLinearSolver) -> sys::SUNLinearSolver_Type {
    sys::SUNLinearSolver_Type_SUNLINEARSOLVER_DIRECT
}

/// `getid` of every solver of ours.
unsafe extern "C" fn custom_id(_s: sys::SUNLinearSolver) -> sys::SUNLinearSolver_ID {
    sys::SUNLinearSolver_ID_SUNLINEARSOLVER_CUSTOM
}

/// `free` of a solver built by [`custom`] with content `Box<T>`.
unsafe extern "C" fn free_boxed<T>(s: sys::SUNLinearSolver) -> c_int {
    // SAFETY: `s` was built by `custom::<T>`; its content is our Box<T>, reclaimed once here,
    // then the empty shell and ops are freed by SUNDIALS.
    unsafe {
        if s.is_null() {
            return 0;
        }
        if !(*s).content.is_null() {
            drop(Box::from_raw((*s).content as *mut T));
            (*s).content = std::ptr::null_mut();
        }
        sys::SUNLinSolFreeEmpty(s);
    }
    0
}

/// A user-supplied `SUNLinearSolver` owning `content` (freed with it), of type `kind`, id
/// `CUSTOM`, with the remaining operations set by `ops` (`initialize`, `setup`, `solve`, …).
/// The operations find their content as `(*s).content as *mut T`.
pub(crate) fn custom<T>(
    ctx: &Context,
    kind: unsafe extern "C" fn(sys::SUNLinearSolver) -> sys::SUNLinearSolver_Type,
    content: Box<T>,
    ops: impl FnOnce(&mut sys::_generic_SUNLinearSolver_Ops),
) -> Result<LinearSolver, SolverError> {
    // SAFETY: valid context; NULL checked; the ops table was allocated by SUNLinSolNewEmpty
    // and is ours to fill; the content pointer is reclaimed by `free_boxed::<T>`.
    unsafe {
        let s = sys::SUNLinSolNewEmpty(ctx.raw());
        if s.is_null() {
            return Err(SolverError::InvalidInput("SUNLinSolNewEmpty failed".into()));
        }
        let table = &mut *(*s).ops;
        table.gettype = Some(kind);
        table.getid = Some(custom_id);
        table.free = Some(free_boxed::<T>);
        ops(table);
        (*s).content = Box::into_raw(content) as *mut c_void;
        Ok(LinearSolver::from_raw(s))
    }
}
