//! A panic in any user callback other than the residual/RHS (those are covered in
//! sundials_callbacks.rs): the IDA and CVODE Jacobians, the IDA and CVODE root functions, and
//! the custom linear solver's `setup` and `solve`. Each panic must come back from the solve call
//! as `SolverError::CallbackPanic` carrying the panic message and a time after the first
//! panicking time, and the process must go on solving (a healthy solve follows each).
//! Test problem: the harmonic oscillator y0' = y1, y1' = −y0 with y = (sin t, cos t).

use bondmech::sundials::{
    CallbackResult, Cvode, CvodeOptions, DenseMatrixMut, Ida, IdaLinearSolver, IdaOptions,
    Multistep, SolverError,
};

const T_PANIC: f64 = 0.5;
const T_END: f64 = 2.0;

fn residual(_t: f64, y: &[f64], yp: &[f64], r: &mut [f64]) -> CallbackResult {
    r[0] = y[1] - yp[0];
    r[1] = -y[0] - yp[1];
    Ok(())
}

fn rhs(_t: f64, y: &[f64], yd: &mut [f64]) -> CallbackResult {
    yd[0] = y[1];
    yd[1] = -y[0];
    Ok(())
}

/// dF/dy + cj dF/dy' of `residual`: [[−cj, 1], [−1, −cj]].
fn ida_jacobian(cj: f64, j: &mut DenseMatrixMut<'_>) {
    j.set(0, 0, -cj);
    j.set(0, 1, 1.0);
    j.set(1, 0, -1.0);
    j.set(1, 1, -cj);
}

fn new_ida(jac: Option<bondmech::sundials::IdaJacobianFn>) -> Ida {
    Ida::new(
        0.0,
        &[0.0, 1.0],
        &[1.0, 0.0],
        Box::new(residual),
        jac,
        &IdaOptions::default(),
    )
    .unwrap()
}

fn new_cvode(jac: Option<bondmech::sundials::CvodeJacobianFn>) -> Cvode {
    Cvode::new(
        Multistep::Bdf,
        0.0,
        &[0.0, 1.0],
        Box::new(rhs),
        jac,
        &CvodeOptions::default(),
    )
    .unwrap()
}

/// The error is a caught panic with `needle` in its message, at a time past `t_min`.
fn assert_caught_panic(
    result: Result<bondmech::sundials::Step, SolverError>,
    needle: &str,
    t_min: f64,
) {
    match result {
        Err(SolverError::CallbackPanic { t, message }) => {
            assert!(t > t_min, "panic reported at t = {t}, not after {t_min}");
            assert!(
                message.contains(needle),
                "message {message:?} lacks {needle:?}"
            );
        }
        other => panic!("expected CallbackPanic({needle}), got {other:?}"),
    }
}

/// A healthy IDA and CVODE solve in the same process still reach (sin 2, cos 2).
fn assert_process_keeps_solving() {
    let mut ida = new_ida(None);
    ida.solve_to(T_END).unwrap();
    let mut cv = new_cvode(None);
    cv.solve_to(T_END).unwrap();
    for y in [ida.y(), cv.y()] {
        assert!((y[0] - T_END.sin()).abs() < 1e-3 && (y[1] - T_END.cos()).abs() < 1e-3);
    }
}

// The oscillator is linear, so the solvers re-evaluate the Jacobian only when the step size
// changes enough: the Jacobians panic on their second call instead of after a time (the first
// call is at t = 0 + h > 0).
#[test]
fn ida_jacobian_panic_becomes_callback_panic() {
    let mut calls = 0;
    let mut ida = new_ida(Some(Box::new(move |t, cj, _y, _yp, j| {
        calls += 1;
        if calls >= 2 {
            panic!("ida jacobian blew up at {t}");
        }
        ida_jacobian(cj, j);
        Ok(())
    })));
    assert_caught_panic(ida.solve_to(T_END), "ida jacobian blew up", 0.0);
    assert_process_keeps_solving();
}

#[test]
fn cvode_jacobian_panic_becomes_callback_panic() {
    let mut calls = 0;
    let mut cv = new_cvode(Some(Box::new(move |t, _y, _f, j| {
        calls += 1;
        if calls >= 2 {
            panic!("cvode jacobian blew up at {t}");
        }
        j.set(0, 1, 1.0);
        j.set(1, 0, -1.0);
        Ok(())
    })));
    // CVODE refreshes the Jacobian at least every 51 steps: integrate long enough for that.
    assert_caught_panic(cv.solve_to(50.0), "cvode jacobian blew up", 0.0);
    assert_process_keeps_solving();
}

#[test]
fn ida_root_function_panic_becomes_callback_panic() {
    let mut ida = new_ida(None);
    ida.set_roots(
        1,
        Box::new(|t, y, _yp, g| {
            if t > T_PANIC {
                panic!("ida root function blew up at {t}");
            }
            g[0] = y[0] - 10.0; // never crosses
            Ok(())
        }),
    )
    .unwrap();
    assert_caught_panic(ida.solve_to(T_END), "ida root function blew up", T_PANIC);
    assert_process_keeps_solving();
}

#[test]
fn cvode_root_function_panic_becomes_callback_panic() {
    let mut cv = new_cvode(None);
    cv.set_roots(
        1,
        Box::new(|t, y, g| {
            if t > T_PANIC {
                panic!("cvode root function blew up at {t}");
            }
            g[0] = y[0] - 10.0; // never crosses
            Ok(())
        }),
    )
    .unwrap();
    assert_caught_panic(cv.solve_to(T_END), "cvode root function blew up", T_PANIC);
    assert_process_keeps_solving();
}

/// Solves [[−cj, 1], [−1, −cj]] x = b in closed form (inverse: [[−cj, −1], [1, −cj]] / (cj² + 1)),
/// panicking in `setup` or `solve` once the time passes `T_PANIC`.
struct PanickyOscillatorSolver {
    panic_in_setup: bool,
    t: f64,
    cj: f64,
}

impl IdaLinearSolver for PanickyOscillatorSolver {
    fn setup(&mut self, t: f64, cj: f64, _y: &[f64], _yp: &[f64]) -> CallbackResult {
        if self.panic_in_setup && t > T_PANIC {
            panic!("custom setup blew up at {t}");
        }
        self.t = t;
        self.cj = cj;
        Ok(())
    }

    fn solve(&mut self, b: &mut [f64]) -> CallbackResult {
        if !self.panic_in_setup && self.t > T_PANIC {
            panic!("custom solve blew up at {}", self.t);
        }
        let (c, det) = (self.cj, self.cj * self.cj + 1.0);
        let (b0, b1) = (b[0], b[1]);
        b[0] = (-c * b0 - b1) / det;
        b[1] = (b0 - c * b1) / det;
        Ok(())
    }
}

fn custom_ida(panic_in_setup: bool) -> Ida {
    Ida::new_with_linear_solver(
        0.0,
        &[0.0, 1.0],
        &[1.0, 0.0],
        Box::new(residual),
        Box::new(PanickyOscillatorSolver {
            panic_in_setup,
            t: 0.0,
            cj: 0.0,
        }),
        &IdaOptions::default(),
    )
    .unwrap()
}

#[test]
fn custom_linear_solver_setup_panic_becomes_callback_panic() {
    let mut ida = custom_ida(true);
    assert_caught_panic(ida.solve_to(T_END), "custom setup blew up", T_PANIC);
    assert_process_keeps_solving();
}

#[test]
fn custom_linear_solver_solve_panic_becomes_callback_panic() {
    let mut ida = custom_ida(false);
    assert_caught_panic(ida.solve_to(T_END), "custom solve blew up", T_PANIC);
    assert_process_keeps_solving();
}

#[test]
fn custom_linear_solver_without_panic_reaches_the_exact_solution() {
    // Control for the two tests above: the closed-form solver is right, so the panics are
    // what stops them. Requested panic time is never reached.
    let mut ida = Ida::new_with_linear_solver(
        0.0,
        &[0.0, 1.0],
        &[1.0, 0.0],
        Box::new(residual),
        Box::new(PanickyOscillatorSolver {
            panic_in_setup: true,
            t: 0.0,
            cj: 0.0,
        }),
        &IdaOptions::default(),
    )
    .unwrap();
    ida.solve_to(0.4).unwrap();
    let y = ida.y();
    assert!((y[0] - 0.4f64.sin()).abs() < 1e-4 && (y[1] - 0.4f64.cos()).abs() < 1e-4);
}
