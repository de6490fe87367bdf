//! The partitioned right-hand side against an independent derivation: the double pendulum's
//! joint-angle accelerations from Lagrange's equations (`common::double_pendulum`), at random
//! states far apart (each evaluation starts from the last one's dependent coordinates), with
//! the translations dependent (pins affine in them: one Newton step per evaluation).

mod common;

use std::sync::Arc;

use bondmech::dae::{
    consistent_state, ConstraintExprs, MechanicsTapes, PartitionedRhs, PartitionedSystem,
};
use bondmech::{Model, Scene};
use common::double_pendulum::DoublePendulum;

#[test]
fn double_pendulum_partitioned_rhs_matches_lagrange_with_one_newton_step_per_call() {
    let scene = Scene::from_path("scenes/double_pendulum.json").unwrap();
    let model = Model::new(&scene).unwrap();
    let mut sys = model.system().clone();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, 0.0).unwrap();
    let names: Vec<String> = sys.coords.iter().map(|c| c.name.clone()).collect();
    let psys = Arc::new(PartitionedSystem::new(&mut sys, &c));
    let x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    let part = psys.choose(0.0, &x).unwrap();
    let independent: Vec<&str> = part.ind_q.iter().map(|&i| names[i].as_str()).collect();
    assert_eq!(
        independent,
        ["bar1.angle", "bar2.angle"],
        "translations dependent"
    );
    let mut rhs = PartitionedRhs::new(psys, part.clone(), &x, 1e-13);
    let reference = DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let idx = |n: &str| names.iter().position(|x| x == n).unwrap();
    let mut rnd = common::uniform(3);
    let mut yd = [0.0; 4];
    for _ in 0..50 {
        let (t1, t2, w1, w2) = (3.0 * rnd(), 3.0 * rnd(), 4.0 * rnd(), 4.0 * rnd());
        let before = rhs.newton_iterations;
        rhs.rhs(0.0, &[t1, t2, w1, w2], &mut yd).unwrap();
        assert_eq!(rhs.newton_iterations - before, 1, "one Newton step");
        let (a1, a2) = reference.accelerations(t1, t2, w1, w2);
        assert_eq!(&yd[..2], &[w1, w2], "q_I' = v_I");
        for (got, want) in [(yd[2], a1), (yd[3], a2)] {
            assert!(
                (got - want).abs() < 1e-9 * (1.0 + want.abs()),
                "{got} vs {want}"
            );
        }
        let q = rhs.full_state();
        let centre2 = [t1.cos() + 0.5 * t2.cos(), t1.sin() + 0.5 * t2.sin()];
        assert!((q[idx("bar2.x")] - centre2[0]).abs() < 1e-12);
        assert!((q[idx("bar2.y")] - centre2[1]).abs() < 1e-12);
    }
}
