//! The GGL error test without the dependent velocities (opt-in,
//! `SolveOptions::ggl_dependent_velocity_error_test = false`, the set re-chosen along the run)
//! against the error test on every velocity (the default): it must stay as accurate against the
//! independent minimal-coordinate models (tests/common/double_pendulum.rs,
//! tests/common/slider_crank.rs) while taking fewer steps. The step counts are pinned in bands
//! around the measured ones.

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};
use common::slider_crank::{simulate_slider_crank, SliderCrank};

#[test]
fn ggl_without_dependent_velocities_in_error_test_keeps_accuracy_with_fewer_steps() {
    let m = Model::new(&Scene::from_path("scenes/double_pendulum.json").unwrap()).unwrap();
    let p = DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let mut runs = Vec::new();
    for keep in [true, false] {
        let mut o = m.default_options();
        o.formulation = FormulationKind::Ggl;
        o.rtol = 1e-8;
        o.atol = 1e-10;
        o.ggl_dependent_velocity_error_test = keep;
        let s = m.solve(&o).unwrap();
        let r = simulate_double_pendulum(&p, [0.0; 4], &s.times);
        let (mut pos, mut vel) = (0.0f64, 0.0f64);
        for (k, rk) in r.iter().enumerate() {
            for (c, w) in [("bar2.x", rk.c2[0]), ("bar2.y", rk.c2[1])] {
                pos = pos.max((s.value(k, c).unwrap() - w).abs());
            }
            for (c, w) in [("bar2.vx", rk.v2[0]), ("bar2.vy", rk.v2[1])] {
                vel = vel.max((s.value(k, c).unwrap() - w).abs());
            }
        }
        eprintln!(
            "keep dependent v in error test {keep}: {} steps, positions {pos:e}, velocities \
             {vel:e}, constraint error {:e}",
            s.summary.steps, s.summary.max_constraint_error
        );
        runs.push((s.summary.steps, pos, vel, s.summary.max_constraint_error));
    }
    let (default, opt_in) = (runs[0], runs[1]);
    assert!(opt_in.0 < default.0, "steps {} vs {}", opt_in.0, default.0);
    // accuracy: within a factor 2 of the default run's errors (measured smaller)
    assert!(
        opt_in.1 < 2.0 * default.1,
        "positions {:e} vs {:e}",
        opt_in.1,
        default.1
    );
    assert!(
        opt_in.2 < 2.0 * default.2,
        "velocities {:e} vs {:e}",
        opt_in.2,
        default.2
    );
    // the position constraints at interpolated output times: tolerance level either way
    assert!(
        opt_in.3 < 1e-8 && default.3 < 1e-8,
        "constraint error {:e} vs {:e}",
        opt_in.3,
        default.3
    );
}

/// The bundled slider-crank (crank turning about 14 times in 1 s, constant drive torque and a
/// gas force on the piston) at its rtol 1e-8: with every velocity in IDA's error test GGL takes
/// 1.4 times the steps, for an error against the minimal-coordinate model of the same size.
///
/// It was 2.4 times (12 761 and 5 275 steps) while IDA's masked error norm divided by every
/// unknown: leaving the dependent velocities out of the test then also loosened it on the
/// others by `sqrt(n / n_tested)`; the norm now averages over the tested unknowns
/// (`sundials::fast_ops`), and the Newton matrix follows `c_j` (`solve::integrators`).
#[test]
fn ggl_slider_crank_without_dependent_velocities_in_error_test_takes_fewer_steps() {
    let m = Model::new(&Scene::from_path("scenes/slider_crank.json").unwrap()).unwrap();
    let p = SliderCrank::bundled();
    let mut runs = Vec::new();
    for keep in [true, false] {
        let mut o = m.default_options();
        o.formulation = FormulationKind::Ggl;
        o.ggl_dependent_velocity_error_test = keep;
        let s = m.solve(&o).unwrap();
        let r = simulate_slider_crank(
            &p,
            [std::f64::consts::FRAC_PI_3, 0.0],
            |phi| -10.0 * phi.cos().max(0.0),
            &s.times,
        );
        let err = r.iter().enumerate().fold(0.0f64, |a, (k, rk)| {
            a.max((s.value(k, "piston.y").unwrap() - rk.piston_y).abs())
                .max((s.value(k, "crank.angle").unwrap() - rk.phi).abs())
        });
        eprintln!(
            "keep dependent v in error test {keep}: {} steps, {} Jacobians, error {err:e}, \
             re-chosen {} times",
            s.summary.steps, s.summary.jacobian_evals, s.summary.ggl_error_test_reselections
        );
        runs.push((s.summary.steps, err));
    }
    let (all_v, opt_in) = (runs[0], runs[1]);
    // measured in the test profile: 10 013 and 7 075 steps (errors 2.1e-5 and 4.2e-5: the
    // scene's rtol 1e-8 is loose for 14 crank turns)
    const STEPS_ALL_V: f64 = 10_013.0;
    const STEPS_DEPENDENT_OUT: f64 = 7_075.0;
    for (steps, pinned) in [(all_v.0, STEPS_ALL_V), (opt_in.0, STEPS_DEPENDENT_OUT)] {
        assert!(
            (steps as f64 - pinned).abs() < 0.15 * pinned,
            "steps {steps}, pinned {pinned}"
        );
    }
    assert!(
        (opt_in.0 as f64) < 0.8 * all_v.0 as f64,
        "steps {} vs {}",
        opt_in.0,
        all_v.0
    );
    // accuracy: within a factor 2 of the default run's error
    assert!(
        opt_in.1 < 2.0 * all_v.1,
        "error {:e} vs {:e}",
        opt_in.1,
        all_v.1
    );
}
