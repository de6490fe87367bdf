//! Callback failure handling, budgets, events, input validation and version checks.
//! The test problem is the harmonic oscillator y'' = -y, y = (sin t, cos t).

use bondmech::sundials::{
    header_version, version, CallbackError, CallbackResult, Cvode, CvodeOptions, Ida, IdaOptions,
    Multistep, SolverError, StepEvent,
};
use std::time::Duration;

fn exact(t: f64) -> [f64; 2] {
    [t.sin(), t.cos()]
}

fn oscillator(_t: f64, y: &[f64], yp: &[f64], r: &mut [f64]) {
    r[0] = y[1] - yp[0];
    r[1] = -y[0] - yp[1];
}

fn ida_with(residual: bondmech::sundials::ResidualFn, opts: &IdaOptions) -> Ida {
    Ida::new(0.0, &exact(0.0), &[1.0, 0.0], residual, None, opts).unwrap()
}

fn close_to_exact(y: &[f64], t: f64, tol: f64) -> bool {
    let e = exact(t);
    (y[0] - e[0]).abs() < tol && (y[1] - e[1]).abs() < tol
}

#[test]
fn residual_panic_becomes_callback_panic_and_process_keeps_solving() {
    let mut ida = ida_with(
        Box::new(|t, y, yp, r| {
            if t > 0.5 {
                panic!("boom at {t}");
            }
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &IdaOptions::default(),
    );
    match ida.solve_to(2.0) {
        Err(SolverError::CallbackPanic { t, message }) => {
            assert!(t > 0.5 && t < 2.0, "t = {t}");
            assert!(message.contains("boom"), "{message}");
        }
        other => panic!("expected CallbackPanic, got {other:?}"),
    }
    // A second, healthy solve in the same process works.
    let mut ok = ida_with(
        Box::new(|t, y, yp, r| {
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &IdaOptions::default(),
    );
    ok.solve_to(2.0).unwrap();
    assert!(close_to_exact(ok.y(), 2.0, 1e-4));
}

#[test]
fn cvode_rhs_panic_becomes_callback_panic() {
    let mut cv = Cvode::new(
        Multistep::Bdf,
        0.0,
        &[1.0],
        Box::new(|t, _y, _yd| panic!("rhs exploded at {t}")),
        None,
        &CvodeOptions::default(),
    )
    .unwrap();
    let err = cv.solve_to(1.0).unwrap_err();
    assert!(
        matches!(&err, SolverError::CallbackPanic { message, .. } if message.contains("exploded")),
        "{err:?}"
    );
}

#[test]
fn single_nan_residual_is_retried_and_solve_succeeds() {
    let mut nan_done = false;
    let mut ida = ida_with(
        Box::new(move |t, y, yp, r| {
            oscillator(t, y, yp, r);
            if t > 1.0 && !nan_done {
                nan_done = true;
                r[0] = f64::NAN;
            }
            Ok(())
        }),
        &IdaOptions::default(),
    );
    ida.solve_to(3.0).unwrap();
    assert!(close_to_exact(ida.y(), 3.0, 1e-4), "{:?}", ida.y());
}

#[test]
fn nan_rhs_from_the_start_is_a_non_finite_error_with_component_state_and_time() {
    // before issue 12 this was a bare `CV_FIRST_RHSFUNC_ERR` flag
    let mut cv = Cvode::new(
        Multistep::Adams,
        0.0,
        &exact(0.0),
        Box::new(|_t, _y, yd| {
            yd[0] = f64::NAN;
            yd[1] = 0.0;
            Ok(())
        }),
        None,
        &CvodeOptions::default(),
    )
    .unwrap();
    let err = cv.solve_to(3.0).unwrap_err();
    match &err {
        SolverError::NonFinite {
            function,
            what,
            t,
            index,
            y,
            ..
        } => {
            assert_eq!(*function, "CVode");
            assert_eq!(*what, "right-hand side");
            assert_eq!(*t, 0.0);
            assert_eq!(*index, 0);
            assert_eq!(y, &exact(0.0));
            assert_eq!(
                err.to_string(),
                "CVode: the right-hand side evaluates to NaN (component 0) at t = 0"
            );
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    assert!(
        cv.last_error_message().is_some(),
        "error handler captured nothing"
    );
}

#[test]
fn persistent_nan_rhs_beyond_t1_stops_as_stuck_just_after_t1() {
    // Every step crossing t = 1 fails recoverably, so steps shrink toward t = 1 forever; the
    // callbacks notice the trial times piling up at t = 1 and stop long before the budget.
    let mut cv = Cvode::new(
        Multistep::Adams,
        0.0,
        &exact(0.0),
        Box::new(|t, y, yd| {
            yd[0] = y[1];
            yd[1] = if t > 1.0 { f64::INFINITY } else { -y[0] };
            Ok(())
        }),
        None,
        &CvodeOptions::default(),
    )
    .unwrap();
    match cv.solve_to(3.0) {
        Err(SolverError::NonFinite {
            t, stuck, index, ..
        }) => {
            assert!(stuck);
            assert_eq!(index, 1);
            assert!((1.0..=1.0 + 1e-9).contains(&t), "t = {t}");
        }
        other => panic!("expected a non-finite error near t = 1, got {other:?}"),
    }
    assert!(cv.stats().steps < 500, "{} steps", cv.stats().steps);
}

#[test]
fn recoverable_failure_once_then_success_is_ok() {
    let failed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let failed_in = failed.clone();
    let mut ida = ida_with(
        Box::new(move |t, y, yp, r| {
            use std::sync::atomic::Ordering;
            if t > 1.0 && !failed_in.swap(true, Ordering::Relaxed) {
                return Err(CallbackError::Recoverable("try a smaller step".into()));
            }
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &IdaOptions::default(),
    );
    ida.solve_to(3.0).unwrap();
    assert!(close_to_exact(ida.y(), 3.0, 1e-4));
    // The recoverable path was really taken, and IDA counted it as a failed Newton solve
    // (it then retries the step with a smaller h).
    assert!(failed.load(std::sync::atomic::Ordering::Relaxed));
    let stats = ida.stats();
    assert!(stats.nonlinear_conv_failures >= 1, "{stats:?}");
}

#[test]
fn fatal_callback_error_becomes_callback_failed_with_message() {
    let mut ida = ida_with(
        Box::new(|t, y, yp, r| {
            if t > 1.0 {
                return Err(CallbackError::Fatal("link broke".into()));
            }
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &IdaOptions::default(),
    );
    match ida.solve_to(3.0) {
        Err(SolverError::CallbackFailed { t, message }) => {
            assert!(t > 1.0 && t < 3.0);
            assert_eq!(message, "link broke");
        }
        other => panic!("expected CallbackFailed, got {other:?}"),
    }
}

#[test]
fn step_budget_gives_too_much_work_with_time_reached() {
    let opts = IdaOptions {
        max_steps: Some(10),
        ..IdaOptions::default()
    };
    let mut ida = ida_with(
        Box::new(|t, y, yp, r| {
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &opts,
    );
    let err = ida.solve_to(100.0).unwrap_err();
    match err {
        SolverError::TooMuchWork { t, max_steps } => {
            assert_eq!(max_steps, 10);
            assert!(t > 0.0 && t < 100.0);
            assert_eq!(ida.stats().steps, 10);
        }
        other => panic!("expected TooMuchWork, got {other:?}"),
    }
}

#[test]
fn wall_clock_budget_gives_wall_clock_error() {
    let limit = Duration::from_millis(50);
    let opts = CvodeOptions {
        max_wall_clock: Some(limit),
        ..CvodeOptions::default()
    };
    let mut cv = Cvode::new(
        Multistep::Bdf,
        0.0,
        &exact(0.0),
        Box::new(|_t, y, yd| {
            std::thread::sleep(Duration::from_millis(2));
            yd[0] = y[1];
            yd[1] = -y[0];
            Ok(())
        }),
        None,
        &CvodeOptions {
            rtol: 1e-10,
            atol: vec![1e-10],
            ..opts
        },
    )
    .unwrap();
    let start = std::time::Instant::now();
    match cv.solve_to(1.0e4) {
        Err(e @ SolverError::WallClock { .. }) => {
            assert!(e.time().unwrap() > 0.0);
            assert!(matches!(e, SolverError::WallClock { limit: l, .. } if l == limit));
        }
        other => panic!("expected WallClock, got {other:?}"),
    }
    assert!(start.elapsed() < Duration::from_secs(2));
}

/// Drives `solve_to` over 100 output intervals of 0.1 (to t = 10) and returns the error that
/// stopped it, with the wall time the whole loop took and how many intervals were completed.
fn run_100_intervals(
    mut solve_to: impl FnMut(f64) -> Result<bondmech::sundials::Step, SolverError>,
) -> (Option<SolverError>, Duration, usize) {
    let start = std::time::Instant::now();
    for k in 1..=100 {
        if let Err(e) = solve_to(0.1 * k as f64) {
            return (Some(e), start.elapsed(), k - 1);
        }
    }
    (None, start.elapsed(), 100)
}

/// Every evaluation sleeps 1 ms and steps are capped at 0.01 (first step 1e-3), so each output
/// interval of 0.1 costs about 10 steps, below the 100 ms budget, while the 100 intervals
/// together cost over a second (`wall_clock_calibration_without_budget` measured: IDA 1.2 s
/// total, longest interval 64 ms; CVODE 1.3 s, 42 ms).
/// A per-call budget would never fire; the whole-solve budget must stop the solve with the
/// time reached, within 10× the budget.
const WHOLE_SOLVE_BUDGET: Duration = Duration::from_millis(100);

fn paced_ida_options() -> IdaOptions {
    IdaOptions {
        rtol: 1e-8,
        atol: vec![1e-8],
        max_step: Some(0.01),
        init_step: Some(1e-3),
        ..IdaOptions::default()
    }
}

fn paced_cvode_options() -> CvodeOptions {
    CvodeOptions {
        rtol: 1e-8,
        atol: vec![1e-8],
        max_step: Some(0.01),
        init_step: Some(1e-3),
        ..CvodeOptions::default()
    }
}

fn sleepy_ida(opts: &IdaOptions) -> Ida {
    ida_with(
        Box::new(|t, y, yp, r| {
            std::thread::sleep(Duration::from_millis(1));
            oscillator(t, y, yp, r);
            Ok(())
        }),
        opts,
    )
}

fn sleepy_cvode(opts: &CvodeOptions) -> Cvode {
    Cvode::new(
        Multistep::Bdf,
        0.0,
        &exact(0.0),
        Box::new(|_t, y, yd| {
            std::thread::sleep(Duration::from_millis(1));
            yd[0] = y[1];
            yd[1] = -y[0];
            Ok(())
        }),
        None,
        opts,
    )
    .unwrap()
}

fn check_whole_solve_wall_clock(err: Option<SolverError>, elapsed: Duration, done: usize) {
    let limit = WHOLE_SOLVE_BUDGET;
    match err {
        Some(SolverError::WallClock { t, limit: l }) => {
            assert_eq!(l, limit);
            assert!(
                t > 0.0 && t < 10.0,
                "time reached {t} should be inside (0, 10)"
            );
            assert!(
                t >= 0.1 * done as f64,
                "time reached {t} is before the {done} completed intervals"
            );
        }
        other => panic!("expected WallClock after {done} intervals, got {other:?}"),
    }
    assert!(
        elapsed < 10 * limit,
        "solve ran {elapsed:?}, more than 10× the {limit:?} budget"
    );
}

#[test]
fn wall_clock_budget_bounds_a_whole_100_interval_ida_solve() {
    let opts = IdaOptions {
        max_wall_clock: Some(WHOLE_SOLVE_BUDGET),
        ..paced_ida_options()
    };
    let mut ida = sleepy_ida(&opts);
    let (err, elapsed, done) = run_100_intervals(|t| ida.solve_to(t));
    check_whole_solve_wall_clock(err, elapsed, done);
    assert!(ida.wall_clock_used() > WHOLE_SOLVE_BUDGET);
}

#[test]
fn wall_clock_budget_bounds_a_whole_100_interval_cvode_solve() {
    let opts = CvodeOptions {
        max_wall_clock: Some(WHOLE_SOLVE_BUDGET),
        ..paced_cvode_options()
    };
    let mut cv = sleepy_cvode(&opts);
    let (err, elapsed, done) = run_100_intervals(|t| cv.solve_to(t));
    check_whole_solve_wall_clock(err, elapsed, done);
    assert!(cv.wall_clock_used() > WHOLE_SOLVE_BUDGET);
}

/// Calibration for the two tests above (run with `--ignored --nocapture`): without a budget,
/// how long do the 100 intervals take, and the longest single interval?
#[test]
#[ignore]
fn wall_clock_calibration_without_budget() {
    fn longest_interval(mut solve_to: impl FnMut(f64)) -> (Duration, Duration) {
        let mut longest = Duration::ZERO;
        let start = std::time::Instant::now();
        for k in 1..=100 {
            let s = std::time::Instant::now();
            solve_to(0.1 * k as f64);
            longest = longest.max(s.elapsed());
        }
        (start.elapsed(), longest)
    }
    let mut ida = sleepy_ida(&paced_ida_options());
    let (total, longest) = longest_interval(|t| {
        ida.solve_to(t).unwrap();
    });
    println!("IDA: total {total:?}, longest interval {longest:?}");
    let mut cv = sleepy_cvode(&paced_cvode_options());
    let (total, longest) = longest_interval(|t| {
        cv.solve_to(t).unwrap();
    });
    println!("CVODE: total {total:?}, longest interval {longest:?}");
}

#[test]
fn root_beyond_tout_is_returned_by_the_next_call_at_pi() {
    let mut cv = Cvode::new(
        Multistep::Adams,
        0.0,
        &exact(0.0),
        Box::new(|_t, y, yd| {
            yd[0] = y[1];
            yd[1] = -y[0];
            Ok(())
        }),
        None,
        &CvodeOptions {
            rtol: 1e-8,
            atol: vec![1e-10],
            ..CvodeOptions::default()
        },
    )
    .unwrap();
    // g = y1 = sin t crosses zero (decreasing) at t = pi.
    cv.set_roots(
        1,
        Box::new(|_t, y, g| {
            g[0] = y[0];
            Ok(())
        }),
    )
    .unwrap();
    let mut events = Vec::new();
    for tout in [1.0, 2.0, 3.0, 3.1, 3.5] {
        loop {
            let step = cv.solve_to(tout).unwrap();
            events.push((step.t, step.event.clone()));
            if step.event == StepEvent::Reached {
                assert!(close_to_exact(cv.y(), tout, 1e-6));
                break;
            }
        }
    }
    let roots: Vec<_> = events
        .iter()
        .filter(|(_, e)| matches!(e, StepEvent::Root(_)))
        .collect();
    assert_eq!(roots.len(), 1, "{events:?}");
    assert!(
        (roots[0].0 - std::f64::consts::PI).abs() < 1e-6,
        "{events:?}"
    );
    assert_eq!(roots[0].1, StepEvent::Root(vec![-1]));
    let times: Vec<f64> = events.iter().map(|(t, _)| *t).collect();
    assert!(
        times.windows(2).all(|w| w[0] <= w[1]),
        "times not monotone: {times:?}"
    );
}

#[test]
fn stop_time_is_reported_and_not_passed() {
    let opts = IdaOptions {
        stop_time: Some(1.5),
        ..IdaOptions::default()
    };
    let mut ida = ida_with(
        Box::new(|t, y, yp, r| {
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &opts,
    );
    let s1 = ida.solve_to(1.0).unwrap();
    assert_eq!((s1.t, s1.event), (1.0, StepEvent::Reached));
    let s2 = ida.solve_to(2.0).unwrap();
    assert_eq!((s2.t, s2.event), (1.5, StepEvent::StopTime));
    assert!(close_to_exact(ida.y(), 1.5, 1e-4));
}

#[test]
fn invalid_inputs_are_reported_not_panicking() {
    let residual = || -> bondmech::sundials::ResidualFn {
        Box::new(|t, y, yp, r| {
            oscillator(t, y, yp, r);
            Ok(())
        })
    };
    let bad_atol = IdaOptions {
        atol: vec![1e-8, 1e-8, 1e-8],
        ..IdaOptions::default()
    };
    let err = Ida::new(0.0, &[0.0, 1.0], &[1.0, 0.0], residual(), None, &bad_atol)
        .err()
        .unwrap();
    assert!(
        matches!(&err, SolverError::InvalidInput(m) if m.contains("atol")),
        "{err}"
    );
    let err = Ida::new(
        0.0,
        &[0.0, 1.0],
        &[1.0],
        residual(),
        None,
        &IdaOptions::default(),
    )
    .err()
    .unwrap();
    assert!(
        matches!(&err, SolverError::InvalidInput(m) if m.contains("yp0")),
        "{err}"
    );
    let err = Ida::new(
        0.0,
        &[f64::NAN, 1.0],
        &[1.0, 0.0],
        residual(),
        None,
        &IdaOptions::default(),
    )
    .err()
    .unwrap();
    assert!(matches!(err, SolverError::InvalidInput(_)));
    let mut ida = Ida::new(
        0.0,
        &[0.0, 1.0],
        &[1.0, 0.0],
        residual(),
        None,
        &IdaOptions::default(),
    )
    .unwrap();
    ida.solve_to(1.0).unwrap();
    assert!(matches!(
        ida.solve_to(0.5),
        Err(SolverError::InvalidInput(_))
    ));
    let mut out = [0.0; 3];
    assert!(matches!(
        ida.dky(1.0, 0, &mut out),
        Err(SolverError::InvalidInput(_))
    ));
}

#[test]
fn reinit_restarts_and_stats_accumulate() {
    let mut ida = ida_with(
        Box::new(|t, y, yp, r| {
            oscillator(t, y, yp, r);
            Ok(())
        }),
        &IdaOptions::default(),
    );
    ida.solve_to(1.0).unwrap();
    let mut total = ida.stats();
    ida.reinit(0.0, &exact(0.0), &[1.0, 0.0]).unwrap();
    assert_eq!(ida.t(), 0.0);
    ida.solve_to(1.0).unwrap();
    let second = ida.stats();
    assert!(close_to_exact(ida.y(), 1.0, 1e-4));
    let first_steps = total.steps;
    total.accumulate(&second);
    assert_eq!(total.steps, first_steps + second.steps);
    assert!(second.steps > 0 && second.residual_evals > 0);
}

#[test]
fn solvers_are_send() {
    fn is_send<T: Send>() {}
    is_send::<Ida>();
    is_send::<Cvode>();
    // And actually usable from another thread.
    let handle = std::thread::spawn(|| {
        let mut ida = ida_with(
            Box::new(|t, y, yp, r| {
                oscillator(t, y, yp, r);
                Ok(())
            }),
            &IdaOptions::default(),
        );
        ida.solve_to(1.0).unwrap();
        ida.y().to_vec()
    });
    assert!(close_to_exact(&handle.join().unwrap(), 1.0, 1e-4));
}

#[test]
fn linked_sundials_is_6_4_and_matches_build_header_version() {
    let (major, minor, patch) = version();
    assert_eq!((major, minor), (6, 4));
    assert_eq!(header_version(), format!("{major}.{minor}.{patch}"));
}

#[test]
fn unused_result_type_alias_compiles() {
    let ok: CallbackResult = Ok(());
    assert!(ok.is_ok());
}
