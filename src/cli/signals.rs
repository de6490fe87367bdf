//! SIGINT and SIGTERM: a solve stops at its next step and keeps its rows; the exit status
//! says which signal ended the command.

use std::process::ExitCode;

/// Whether `signal` was ignored when the program started (its bit in `SigIgn` of
/// `/proc/self/status`; `false` where that cannot be read).
pub(crate) fn ignored_at_start(signal: i32) -> bool {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else {
        return false;
    };
    status
        .lines()
        .find_map(|l| l.strip_prefix("SigIgn:"))
        .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
        .is_some_and(|mask| mask & (1 << (signal - 1)) != 0)
}

/// The shell's exit status of a command ended by `signal`: `128 + signal` (130 for SIGINT,
/// 143 for SIGTERM).
pub(crate) fn exit_status_of(signal: i32) -> ExitCode {
    ExitCode::from(u8::try_from(128 + signal).unwrap_or(u8::MAX))
}

/// Handles SIGINT and SIGTERM on a thread of their own (tokio's signal handling, which installs
/// the handlers safely and wakes the thread): the first asks the solve to stop at its next step
/// ([`bondmech::interrupt::request`]: the rows so far are written as after a budget stop, the
/// summary says `stopped_by: "interrupt"`, the exit status is 128 + signal); a second one exits
/// at once with 128 + its number, after removing the temporary files of the outputs being
/// written (their targets are left as they were). Returns once the handlers are in place.
pub(crate) fn watch_interrupts() {
    use bondmech::interrupt::{request, signal_name, SIGINT, SIGTERM};
    let (ready, wait_ready) = std::sync::mpsc::channel::<()>();
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let Ok(rt) = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
            else {
                let _ = ready.send(());
                return;
            };
            rt.block_on(async move {
                use tokio::signal::unix::{signal, Signal, SignalKind};
                // a signal ignored when the program started (`nohup`, `cmd &` in a script) stays
                // ignored, as it would without a handler
                let listen = |sig: i32, kind: SignalKind| -> Result<Option<Signal>, ()> {
                    if ignored_at_start(sig) {
                        return Ok(None);
                    }
                    signal(kind).map(Some).map_err(drop)
                };
                let (Ok(mut int), Ok(mut term)) = (
                    listen(SIGINT, SignalKind::interrupt()),
                    listen(SIGTERM, SignalKind::terminate()),
                ) else {
                    let _ = ready.send(());
                    return;
                };
                let _ = ready.send(());
                async fn next(s: &mut Option<Signal>) -> Option<()> {
                    match s {
                        Some(s) => s.recv().await,
                        None => std::future::pending().await,
                    }
                }
                loop {
                    let sig = tokio::select! {
                        Some(()) = next(&mut int) => SIGINT,
                        Some(()) = next(&mut term) => SIGTERM,
                        else => return,
                    };
                    if request(sig) {
                        eprintln!(
                            "bondmech: {} received: stopping at the next step, the rows so far are kept (again to quit at once)",
                            signal_name(sig)
                        );
                    } else {
                        bondmech::output::remove_temporaries();
                        std::process::exit(128 + sig);
                    }
                }
            });
        });
    if spawned.is_ok() {
        let _ = wait_ready.recv();
    }
}
