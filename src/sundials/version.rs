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

/// `true` when the NUL-terminated C string `c` equals `s`.
const fn c_str_eq(c: &[u8], s: &str) -> bool {
    let s = s.as_bytes();
    if c.len() != s.len() + 1 || c[s.len()] != 0 {
        return false;
    }
    let mut i = 0;
    while i < s.len() {
        if c[i] != s[i] {
            return false;
        }
        i += 1;
    }
    true
}

// Compile-time guard against sundials-sys's vendored fallback: the bindings it
// generated (from whichever headers bindgen actually read, which also decide the
// libraries it links) must declare SUNDIALS 6 and the very version build.rs found
// in the system headers. A vendored 7.x build fails to compile here.
const _: () = {
    assert!(
        sundials_sys::SUNDIALS_VERSION_MAJOR == 6,
        "sundials-sys bindings are not SUNDIALS 6.x (vendored fallback?): \
         apt-get install libsundials-dev libclang-dev pkg-config"
    );
    assert!(
        c_str_eq(
            sundials_sys::SUNDIALS_VERSION,
            env!("BONDMECH_SUNDIALS_HEADER_VERSION")
        ),
        "sundials-sys bindings and the headers checked by build.rs declare different \
         SUNDIALS versions: apt-get install libsundials-dev libclang-dev pkg-config"
    );
};
