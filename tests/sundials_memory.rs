//! Leak check: thousands of small IDA and CVODE solves (each with its own context,
//! vectors, matrix, linear solver, closures and an error return) must not grow the
//! resident set size (from /proc/self/statm) beyond a small bound.

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

#[test]
fn two_thousand_solves_do_not_grow_rss() {
    for k in 0..200 {
        one_round(k);
    }
    // BONDMECH_LEAK_ROUNDS lets a valgrind run use fewer rounds (RSS is meaningless
    // under valgrind, which quarantines freed blocks; the assertion is skipped then).
    let rounds: usize = std::env::var("BONDMECH_LEAK_ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let before = rss_bytes();
    for k in 0..rounds {
        one_round(k);
    }
    let after = rss_bytes();
    let growth = after.saturating_sub(before);
    assert!(
        growth < 2 * 1024 * 1024,
        "RSS grew by {growth} bytes over 2000 rounds"
    );
}
