//! RAII serial `N_Vector` and slice views of SUNDIALS-owned vectors.

use super::context::Context;
use super::error::SolverError;
use sundials_sys as sys;

/// Owned serial `N_Vector` of fixed length, destroyed on drop.
pub(crate) struct NVector {
    raw: sys::N_Vector,
    len: usize,
}

impl NVector {
    /// New vector holding a copy of `values` (length must be non-zero).
    pub(crate) fn from_slice(ctx: &Context, values: &[f64]) -> Result<NVector, SolverError> {
        if values.is_empty() {
            return Err(SolverError::InvalidInput("vector of length 0".into()));
        }
        // SAFETY: valid context and positive length; NULL is checked below.
        let raw = unsafe { sys::N_VNew_Serial(values.len() as sys::sunindextype, ctx.raw()) };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("N_VNew_Serial failed".into()));
        }
        // SAFETY: a live serial vector that owns its ops table (N_VNew_Serial allocates one).
        unsafe { super::fast_ops::install(raw) };
        let mut v = NVector {
            raw,
            len: values.len(),
        };
        v.as_mut_slice().copy_from_slice(values);
        Ok(v)
    }

    pub(crate) fn raw(&self) -> sys::N_Vector {
        self.raw
    }

    pub(crate) fn as_slice(&self) -> &[f64] {
        // SAFETY: a serial vector owns `len` contiguous f64s; borrowed from `self`.
        unsafe { slice_of(self.raw, self.len) }
    }

    pub(crate) fn as_mut_slice(&mut self) -> &mut [f64] {
        // SAFETY: as above, and `&mut self` guarantees exclusive access.
        unsafe { slice_of_mut(self.raw, self.len) }
    }
}

impl Drop for NVector {
    fn drop(&mut self) {
        // SAFETY: `raw` came from N_VNew_Serial and is destroyed exactly once.
        unsafe { sys::N_VDestroy(self.raw) }
    }
}

/// View of a serial `N_Vector` owned by SUNDIALS.
///
/// # Safety
/// `v` must be a live serial vector of length `len` not mutated during `'a`.
pub(crate) unsafe fn slice_of<'a>(v: sys::N_Vector, len: usize) -> &'a [f64] {
    // SAFETY: guaranteed by the caller.
    unsafe { std::slice::from_raw_parts(sys::N_VGetArrayPointer(v), len) }
}

/// Mutable view of a serial `N_Vector` owned by SUNDIALS.
///
/// # Safety
/// `v` must be a live serial vector of length `len`, not aliased during `'a`.
pub(crate) unsafe fn slice_of_mut<'a>(v: sys::N_Vector, len: usize) -> &'a mut [f64] {
    // SAFETY: guaranteed by the caller.
    unsafe { std::slice::from_raw_parts_mut(sys::N_VGetArrayPointer(v), len) }
}
