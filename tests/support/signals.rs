//! Children that a test signals get the default dispositions of SIGINT and SIGTERM, whatever
//! the test process inherited: a test started as a background job of a non-interactive shell
//! (`./scripts/test-all.sh &` in a script, some CI runners) runs with SIGINT ignored, the
//! child inherits that across `exec`, and bondmech rightly keeps a signal ignored at its start
//! (`nohup`), so a test that sends SIGINT would wait for nothing (issue 51).

use std::os::unix::process::CommandExt;
use std::process::Command;

/// Sets SIGINT and SIGTERM back to their default action in the child of `cmd`, between `fork`
/// and `exec` (an ignored disposition survives `exec`; a shell's `trap - INT` cannot undo one
/// ignored at the shell's own start).
pub fn default_signals(cmd: &mut Command) -> &mut Command {
    // SAFETY: the closure runs in the forked child before `exec`; it calls only `signal(2)`
    // (async-signal-safe, listed in signal-safety(7)) and `last_os_error` (reads errno), and
    // allocates nothing, so it is sound in a child forked from a multi-threaded process.
    unsafe {
        cmd.pre_exec(|| {
            for sig in [libc::SIGINT, libc::SIGTERM] {
                if libc::signal(sig, libc::SIG_DFL) == libc::SIG_ERR {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        })
    }
}
