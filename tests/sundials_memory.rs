//! Leak check: thousands of small IDA and CVODE solves (each with its own context,
//! vectors, matrix, linear solver, closures, a root function, an error return and a
//! flag-name string) must leave the `malloc` heap where it was (glibc `mallinfo2`,
//! which counts the C and the Rust side alike, since Rust allocates through
//! `malloc`) and must not grow the resident set size (from /proc/self/statm).
//!
//! This binary holds a single test on purpose: another test running in parallel
//! would allocate on the same heap and blur the byte count.
//!
//! valgrind run (result in vendor-notes/sundials.md), after `cargo test --test sundials_memory`:
//! `BONDMECH_LEAK_ROUNDS=200 valgrind --leak-check=full target/debug/deps/sundials_memory-<hash> --test-threads=1`
//! Under valgrind the RSS check is skipped (valgrind quarantines freed blocks) and the heap
//! check sees nothing (valgrind replaces `malloc`; glibc's `mallinfo2` then reports 0 growth):
//! valgrind's leak summary is the check there.

use bondmech::sundials::heap::malloc_in_use;
use bondmech::sundials::{CallbackError, Cvode, CvodeOptions, Ida, IdaOptions, Multistep};

fn rss_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").expect("/proc/self/statm");
    let resident_pages: u64 = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    resident_pages * 4096
}

fn one_round(k: usize) {
    let mut ida = Ida::new(
        0.0,
        &[0.0, 1.0],
        &[1.0, 0.0],
        Box::new(|_t, y, yp, r| {
            r[0] = y[1] - yp[0];
            r[1] = -y[0] - yp[1];
            Ok(())
        }),
        None,
        &IdaOptions::default(),
    )
    .unwrap();
    ida.set_roots(
        1,
        Box::new(|_t, y, _yp, g| {
            g[0] = y[0] - 0.5;
            Ok(())
        }),
    )
    .unwrap();
    ida.solve_to(1.0).unwrap();
    let mut cv = Cvode::new(
        Multistep::Bdf,
        0.0,
        &[1.0],
        Box::new(move |t, y, yd| {
            if k.is_multiple_of(2) && t > 0.5 {
                return Err(CallbackError::Fatal("stop".into()));
            }
            yd[0] = -y[0];
            Ok(())
        }),
        None,
        &CvodeOptions::default(),
    )
    .unwrap();
    let r = cv.solve_to(1.0);
    assert_eq!(r.is_err(), k.is_multiple_of(2));
    // Flag-name strings (malloc'ed by SUNDIALS) are produced on this path.
    let _ = cv.dky(10.0, 0, &mut [0.0]).unwrap_err().to_string();
}

/// Rounds measured (after 450 warm-up rounds); `BONDMECH_LEAK_ROUNDS` overrides it
/// (valgrind runs use fewer).
fn rounds() -> usize {
    std::env::var("BONDMECH_LEAK_ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000)
}

#[test]
fn two_thousand_solves_leave_the_malloc_heap_and_rss_unchanged() {
    // Warm-up: the heap settles after a few hundred rounds. Measured with checkpoints every
    // 250 rounds (after 200 warm-up rounds): +7616, +7952, +7952 … +7952, +8528 … +8528 bytes
    // over 4750 rounds, i.e. one-off steps of the allocator's bookkeeping (glibc counts the
    // per-thread tcache as "in use"), not growth per round. A 100-byte-per-round leak would add
    // 25 000 bytes per checkpoint.
    for k in 0..450 {
        one_round(k);
    }
    let rounds = rounds();
    let heap_before = malloc_in_use();
    let rss_before = rss_bytes();
    for k in 0..rounds {
        one_round(k);
    }
    let heap_after = malloc_in_use();
    let rss_after = rss_bytes();

    // A leak of one SUNContext, one flag-name string or one boxed closure per round is
    // tens to hundreds of bytes. Allowed: 4 KiB for one-off allocator steps (measured up to
    // 3.6 KiB after warm-up) plus 4 bytes per round; a 100-byte leak over 2000 rounds is 200 KB.
    if let (Some(before), Some(after)) = (heap_before, heap_after) {
        let growth = after as i64 - before as i64;
        let limit = 4096 + 4 * rounds as i64;
        println!("malloc heap growth over {rounds} rounds: {growth} bytes (limit {limit})");
        assert!(
            growth <= limit,
            "malloc heap grew by {growth} bytes over {rounds} rounds (limit {limit})"
        );
    }
    // Under valgrind (which preloads its vgpreload_*.so) freed blocks are quarantined and
    // RSS grows by design (measured 6 MB over 200 rounds), so only the heap check applies
    // there; valgrind's own leak report is the check in that case.
    let under_valgrind = std::env::var("LD_PRELOAD").is_ok_and(|p| p.contains("vgpreload"));
    let growth = rss_after.saturating_sub(rss_before);
    assert!(
        under_valgrind || growth < 2 * 1024 * 1024,
        "RSS grew by {growth} bytes over {rounds} rounds"
    );
}
