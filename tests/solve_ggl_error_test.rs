//! The opt-in GGL error test without the dependent velocities
//! (`SolveOptions::ggl_dependent_velocity_error_test = false`) on the double pendulum: it must
//! stay as accurate as the default against the independent minimal-coordinate model
//! (tests/common/double_pendulum.rs) while taking fewer steps (measured 2161 against 2724 at
//! rtol 1e-8).

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};

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
