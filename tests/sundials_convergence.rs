//! Harmonic oscillator y'' = -y as a first-order system, y = (sin t, cos t) exactly.
//! On CVODE (BDF and Adams) and IDA with analytic Jacobians, the maximum error over
//! t = 1..10 must shrink strictly as rtol goes 1e-4 → 1e-6 → 1e-8 (atol = rtol).

use bondmech::sundials::{
    CallbackResult, Cvode, CvodeOptions, DenseMatrixMut, Ida, IdaOptions, Multistep, StepEvent,
};

const TOLERANCES: [f64; 3] = [1e-4, 1e-6, 1e-8];

fn exact(t: f64) -> [f64; 2] {
    [t.sin(), t.cos()]
}

fn rhs(_t: f64, y: &[f64], yd: &mut [f64]) -> CallbackResult {
    yd[0] = y[1];
    yd[1] = -y[0];
    Ok(())
}

fn rhs_jacobian(_t: f64, _y: &[f64], _f: &[f64], j: &mut DenseMatrixMut<'_>) -> CallbackResult {
    j.set(0, 1, 1.0);
    j.set(1, 0, -1.0);
    Ok(())
}

fn cvode_max_error(method: Multistep, rtol: f64) -> f64 {
    let opts = CvodeOptions {
        rtol,
        atol: vec![rtol],
        max_steps: Some(100_000),
        ..CvodeOptions::default()
    };
    let mut cv = Cvode::new(
        method,
        0.0,
        &exact(0.0),
        Box::new(rhs),
        Some(Box::new(rhs_jacobian)),
        &opts,
    )
    .unwrap();
    (1..=10)
        .map(|k| {
            let t = k as f64;
            let step = cv.solve_to(t).unwrap();
            assert_eq!(step.event, StepEvent::Reached);
            assert_eq!(step.t, t);
            let e = exact(t);
            (cv.y()[0] - e[0]).abs().max((cv.y()[1] - e[1]).abs())
        })
        .fold(0.0, f64::max)
}

fn ida_max_error(rtol: f64) -> f64 {
    let opts = IdaOptions {
        rtol,
        atol: vec![rtol],
        max_steps: Some(100_000),
        ..IdaOptions::default()
    };
    let residual = |_t: f64, y: &[f64], yp: &[f64], r: &mut [f64]| -> CallbackResult {
        r[0] = y[1] - yp[0];
        r[1] = -y[0] - yp[1];
        Ok(())
    };
    let jacobian =
        |_t: f64, cj: f64, _y: &[f64], _yp: &[f64], j: &mut DenseMatrixMut<'_>| -> CallbackResult {
            j.set(0, 0, -cj);
            j.set(0, 1, 1.0);
            j.set(1, 0, -1.0);
            j.set(1, 1, -cj);
            Ok(())
        };
    let mut ida = Ida::new(
        0.0,
        &exact(0.0),
        &[1.0, 0.0],
        Box::new(residual),
        Some(Box::new(jacobian)),
        &opts,
    )
    .unwrap();
    (1..=10)
        .map(|k| {
            let t = k as f64;
            ida.solve_to(t).unwrap();
            let e = exact(t);
            // y' = (cos t, -sin t) must come back interpolated too.
            let yp_err = (ida.yp()[0] - e[1]).abs().max((ida.yp()[1] + e[0]).abs());
            assert!(
                yp_err < 1e3 * rtol.max(1e-7),
                "yp error {yp_err} at t = {t}"
            );
            (ida.y()[0] - e[0]).abs().max((ida.y()[1] - e[1]).abs())
        })
        .fold(0.0, f64::max)
}

fn assert_strictly_decreasing(label: &str, errors: &[f64]) {
    for w in errors.windows(2) {
        assert!(
            w[1] < w[0],
            "{label}: errors {errors:?} do not shrink with the tolerance"
        );
    }
    assert!(
        errors[2] < 1e-5,
        "{label}: error {} at rtol 1e-8 is too large",
        errors[2]
    );
}

#[test]
fn cvode_bdf_error_on_harmonic_oscillator_shrinks_with_tolerance() {
    let errors: Vec<f64> = TOLERANCES
        .iter()
        .map(|&r| cvode_max_error(Multistep::Bdf, r))
        .collect();
    assert_strictly_decreasing("CVODE BDF", &errors);
}

#[test]
fn cvode_adams_error_on_harmonic_oscillator_shrinks_with_tolerance() {
    let errors: Vec<f64> = TOLERANCES
        .iter()
        .map(|&r| cvode_max_error(Multistep::Adams, r))
        .collect();
    assert_strictly_decreasing("CVODE Adams", &errors);
}

#[test]
fn ida_error_on_harmonic_oscillator_shrinks_with_tolerance() {
    let errors: Vec<f64> = TOLERANCES.iter().map(|&r| ida_max_error(r)).collect();
    assert_strictly_decreasing("IDA", &errors);
}
