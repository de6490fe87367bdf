//! Heap probe for leak tests: bytes currently allocated through `malloc`.
//!
//! SUNDIALS allocates with `malloc` and Rust's default global allocator is the
//! system `malloc` too, so on glibc one `mallinfo2()` call sees both the C side
//! (contexts, vectors, matrices, solver memory, flag-name strings) and the Rust side
//! (boxed closures, error strings).

#[cfg(all(target_os = "linux", target_env = "gnu"))]
mod imp {
    /// `struct mallinfo2` from glibc's `<malloc.h>` (glibc ≥ 2.33), ten `size_t` fields.
    #[repr(C)]
    struct MallInfo2 {
        arena: usize,
        ordblks: usize,
        smblks: usize,
        hblks: usize,
        hblkhd: usize,
        usmblks: usize,
        fsmblks: usize,
        uordblks: usize,
        fordblks: usize,
        keepcost: usize,
    }

    extern "C" {
        fn mallinfo2() -> MallInfo2;
    }

    pub(super) fn in_use() -> Option<usize> {
        // SAFETY: `mallinfo2` takes no arguments, only reads allocator statistics
        // (under the arena locks) and returns the struct by value; the layout above
        // matches glibc's definition (ten `size_t`).
        let m = unsafe { mallinfo2() };
        // uordblks: bytes in use in arena chunks; hblkhd: bytes in mmap'ed chunks.
        Some(m.uordblks + m.hblkhd)
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
mod imp {
    pub(super) fn in_use() -> Option<usize> {
        None
    }
}

/// Bytes currently allocated by `malloc` in the whole process (glibc
/// `mallinfo2().uordblks + hblkhd`, summed over all arenas), or `None` on
/// platforms without glibc.
pub fn malloc_in_use() -> Option<usize> {
    imp::in_use()
}
