//! RAII owner of a `SUNContext` (one per solver instance; nothing global).

use super::error::SolverError;
use std::ptr;
use sundials_sys as sys;

/// Owned `SUNContext`, freed with `SUNContext_Free` on drop.
pub(crate) struct Context {
    raw: sys::SUNContext,
}

impl Context {
    /// Create a context with no MPI communicator (6.x: `comm` is a `void*`, NULL).
    pub(crate) fn new() -> Result<Context, SolverError> {
        let mut raw: sys::SUNContext = ptr::null_mut();
        // SAFETY: `raw` is a valid out-pointer; a NULL communicator is allowed for serial use.
        let flag = unsafe { sys::SUNContext_Create(ptr::null_mut(), &mut raw) };
        if flag != 0 || raw.is_null() {
            return Err(SolverError::InvalidInput(format!(
                "SUNContext_Create failed with flag {flag}"
            )));
        }
        Ok(Context { raw })
    }

    pub(crate) fn raw(&self) -> sys::SUNContext {
        self.raw
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: `raw` came from SUNContext_Create and every object created with it
        // was freed before (owners declare the context as their last field).
        unsafe {
            sys::SUNContext_Free(&mut self.raw);
        }
    }
}
