//! IDA inequality constraints (`IdaOptions::constraints`, `IDASetConstraints`) on Robertson
//! kinetics as an index-1 DAE with loose tolerances (rtol 1e-3, atol 1e-4).
//!
//! Independent facts used: concentrations cannot become negative (the positive orthant is
//! invariant: y_i = 0 implies y_i' ≥ 0 for every species), and y1 + y2 + y3 = 1 holds exactly.
//!
//! Without constraints IDA at these tolerances lets y2 go negative; the −3e7·y2² term then
//! drives it further down and the solve blows up (measured: y2 reaches −2.3e150 and IDASolve
//! fails with IDA_CONV_FAIL at t ≈ 3.8). With constraints y ≥ 0 IDA rejects and shrinks such
//! steps. IDA does not enforce y ≥ 0 exactly: it accepts a step whose violation is within the
//! corrector's convergence test (weighted RMS norm of the violation below the Newton tolerance,
//! which is < 1 in error-weight units), so the guarantee checked is y_i ≥ −(rtol·|y_i| + atol)
//! at every internal step (measured minima: y1 −2.4e-5, y2 −9.9e-11, with atol 1e-4).

use bondmech::sundials::{Ida, IdaOptions, SolverError};

const RTOL: f64 = 1e-3;
const ATOL: f64 = 1e-4;
const T_END: f64 = 4.0e10;

/// Runs internal steps to `T_END`; returns the minimum of each component over the steps, the
/// largest invariant violation, and the error that stopped the run if any.
fn run(constraints: Option<Vec<f64>>) -> ([f64; 3], f64, Option<SolverError>) {
    let mut ida = Ida::new(
        0.0,
        &[1.0, 0.0, 0.0],
        &[-0.04, 0.04, 0.0],
        Box::new(|_t, y, yp, r| {
            r[0] = -0.04 * y[0] + 1.0e4 * y[1] * y[2];
            r[1] = -r[0] - 3.0e7 * y[1] * y[1] - yp[1];
            r[0] -= yp[0];
            r[2] = y[0] + y[1] + y[2] - 1.0;
            Ok(())
        }),
        None,
        &IdaOptions {
            rtol: RTOL,
            atol: vec![ATOL],
            constraints,
            max_steps: Some(100_000),
            stop_time: Some(T_END),
            ..IdaOptions::default()
        },
    )
    .unwrap();
    let mut min = [f64::INFINITY; 3];
    let mut invariant: f64 = 0.0;
    while ida.t() < T_END {
        if let Err(e) = ida.step(T_END) {
            return (min, invariant, Some(e));
        }
        let y = ida.y();
        for (m, v) in min.iter_mut().zip(y) {
            *m = m.min(*v);
        }
        invariant = invariant.max((y[0] + y[1] + y[2] - 1.0).abs());
    }
    (min, invariant, None)
}

#[test]
fn robertson_without_constraints_goes_negative_at_loose_tolerances() {
    // Shows the constrained test below is not vacuous at these tolerances.
    let (min, _, err) = run(None);
    assert!(
        err.is_some() || min[1] < -1.0,
        "expected the unconstrained run to blow up, got min {min:?}, error {err:?}"
    );
    assert!(
        min[1] < -10.0 * ATOL,
        "min y2 without constraints: {:e}",
        min[1]
    );
}

#[test]
fn robertson_with_constraints_stays_nonnegative_within_ida_tolerance_to_4e10() {
    let (min, invariant, err) = run(Some(vec![1.0, 1.0, 1.0]));
    assert!(err.is_none(), "constrained run failed: {err:?}");
    for (i, m) in min.iter().enumerate() {
        // At a negative minimum |y_i| is tiny, so the bound is atol plus a negligible rtol term.
        let bound = -(ATOL + RTOL * m.abs());
        assert!(
            *m >= bound,
            "y{} went down to {m:e}, below IDA's constraint tolerance {bound:e}",
            i + 1
        );
    }
    assert!(invariant < 1e-12, "y1+y2+y3-1 reached {invariant:e}");
}
