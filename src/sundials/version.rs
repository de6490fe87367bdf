//! Version of the SUNDIALS library actually linked, and of the headers compiled against.

use std::os::raw::{c_char, c_int};

extern "C" {
    // Declared in <sundials/sundials_version.h>, which sundials-sys does not bind.
    fn SUNDIALSGetVersionNumber(
        major: *mut c_int,
        minor: *mut c_int,
        patch: *mut c_int,
        label: *mut c_char,
        len: c_int,
    ) -> c_int;
}

/// `(major, minor, patch)` of the SUNDIALS shared library linked at run time.
pub fn version() -> (u32, u32, u32) {
    let (mut major, mut minor, mut patch) = (0, 0, 0);
    let mut label = [0 as c_char; 32];
    // SAFETY: all pointers are valid for writes; `len` is the label buffer length.
    unsafe {
        SUNDIALSGetVersionNumber(
            &mut major,
            &mut minor,
            &mut patch,
            label.as_mut_ptr(),
            label.len() as c_int,
        );
    }
    (major as u32, minor as u32, patch as u32)
}

/// SUNDIALS version string of the headers found by `build.rs` (e.g. `"6.4.1"`).
pub fn header_version() -> &'static str {
    env!("BONDMECH_SUNDIALS_HEADER_VERSION")
}
