//! Helpers shared by the FMI 2.0 and 3.0 entry points: C strings, arrays, resource paths,
//! panics.
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]

use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

/// `n` elements at `p` as a slice (`None` for a null pointer with `n > 0`).
///
/// # Safety
/// `p` must be null or point to `n` initialised elements that stay valid and unaliased by
/// writes for `'a` (the FMI calling convention for input arrays).
pub(crate) unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        return Some(&[]);
    }
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the caller's contract, `n` valid elements.
    Some(unsafe { std::slice::from_raw_parts(p, n) })
}

/// `n` writable elements at `p` (`None` for a null pointer with `n > 0`).
///
/// # Safety
/// `p` must be null or point to `n` elements writable and not otherwise accessed for `'a`
/// (the FMI calling convention for output arrays).
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        return Some(&mut []);
    }
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the caller's contract, `n` writable elements.
    Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// A C string as Rust text (`None` for null).
///
/// # Safety
/// `p` must be null or a NUL-terminated string valid for the call.
pub(crate) unsafe fn text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

/// The directory of an FMI 2.0 resource location URI (`file:///tmp/x/resources`,
/// `file:/tmp/x/resources/`, percent-encoded) or an FMI 3.0 resource path.
pub(crate) fn resource_dir(location: &str) -> PathBuf {
    let path = match location.strip_prefix("file:") {
        Some(rest) => {
            let rest = rest
                .strip_prefix("//localhost")
                .or_else(|| rest.strip_prefix("//"))
                .unwrap_or(rest);
            percent_decode(rest)
        }
        None => location.to_string(),
    };
    PathBuf::from(path)
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok();
            if let Some(x) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(x);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Runs `f`, turning a panic into `Err` with its message: no panic unwinds into the importer.
pub(crate) fn no_panic<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        format!("internal error (panic): {what}")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resource_uris_become_paths() {
        assert_eq!(
            resource_dir("file:///tmp/a%20b/resources"),
            PathBuf::from("/tmp/a b/resources")
        );
        assert_eq!(
            resource_dir("file:/tmp/x/resources/"),
            PathBuf::from("/tmp/x/resources/")
        );
        assert_eq!(
            resource_dir("file://localhost/tmp/x"),
            PathBuf::from("/tmp/x")
        );
        assert_eq!(
            resource_dir("/tmp/x/resources/"),
            PathBuf::from("/tmp/x/resources/")
        );
    }

    #[test]
    fn panics_are_caught() {
        let r: Result<(), String> = no_panic(|| panic!("boom"));
        assert!(r.unwrap_err().contains("boom"));
    }
}
