//! Interrupts asked of a running command (SIGINT from Ctrl-C, SIGTERM from `kill` or a
//! container's stop): the command-line program's signal handler records the first signal here
//! ([`request`]); the solver loop (`src/sundials/stepping.rs`) reads it between internal steps
//! and stops the solve there as a budget does — the rows so far kept, the summary's
//! `stopped_by: "interrupt"` — and the program then exits with `128 + signal` (130 for SIGINT,
//! 143 for SIGTERM), the shell's convention for a command ended by a signal.
//!
//! Nothing in the library sets it: a solve from the library, the Python module or the HTTP
//! service is never stopped by it unless its host calls [`request`].

use std::sync::atomic::{AtomicI32, Ordering};

/// The signal number of the first interrupt asked for, 0 while none was.
static SIGNAL: AtomicI32 = AtomicI32::new(0);

/// SIGINT's number (Ctrl-C).
pub const SIGINT: i32 = 2;
/// SIGTERM's number (`kill`, a container's stop).
pub const SIGTERM: i32 = 15;

/// Records that `signal` asks the running solve to stop at its next step; a later signal does
/// not replace the first. Returns `true` when this is the first.
pub fn request(signal: i32) -> bool {
    SIGNAL
        .compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst)
        .is_ok()
}

/// The signal of the interrupt asked for, if any.
pub fn requested() -> Option<i32> {
    match SIGNAL.load(Ordering::Relaxed) {
        0 => None,
        s => Some(s),
    }
}

/// `SIGINT`, `SIGTERM`, or `signal N`.
pub fn signal_name(signal: i32) -> String {
    match signal {
        SIGINT => "SIGINT".into(),
        SIGTERM => "SIGTERM".into(),
        n => format!("signal {n}"),
    }
}
