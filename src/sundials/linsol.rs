//! RAII owner of a `SUNLinearSolver` (dense LU, [`super::dense_lu`], or a custom one from
//! [`super::custom_ls`]).

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
    /// Dense direct solver (LU with partial pivoting, [`super::dense_lu`]) for the dense
    /// matrix the integrator attaches with it (the template vector and matrix are kept in the
    /// signature of `SUNLinSol_Dense`, which it replaces).
    pub(crate) fn dense(
        ctx: &Context,
        _y: &NVector,
        _a: &DenseMatrix,
    ) -> Result<LinearSolver, SolverError> {
        super::dense_lu::new(ctx)
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
