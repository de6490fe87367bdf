//! RAII owner of a `SUNLinearSolver` (dense LU, or a custom one from [`super::custom_ls`]).

use super::context::Context;
use super::error::SolverError;
use super::matrix::DenseMatrix;
use super::vector::NVector;
use sundials_sys as sys;

/// Owned `SUNLinearSolver`, freed with `SUNLinSolFree` on drop.
pub(crate) struct LinearSolver {
    raw: sys::SUNLinearSolver,
}

impl LinearSolver {
    /// Dense direct solver for `a` (template vector `y`).
    pub(crate) fn dense(
        ctx: &Context,
        y: &NVector,
        a: &DenseMatrix,
    ) -> Result<LinearSolver, SolverError> {
        // SAFETY: vector, matrix and context are live and compatible (serial, n x n).
        let raw = unsafe { sys::SUNLinSol_Dense(y.raw(), a.raw(), ctx.raw()) };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("SUNLinSol_Dense failed".into()));
        }
        Ok(LinearSolver { raw })
    }

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
