//! The partitioned right-hand side against independent derivations (Lagrange's equations in
//! the minimal coordinates, `common::double_pendulum` and `common::slider_crank`), on both of
//! its paths: the full dependent block (Newton on every dependent coordinate) and the
//! symbolic elimination of the coordinates affine in their rows (`solve::formulation::partitioned::elimination`: no
//! Newton for a tree, Newton on the loop closure for the slider-crank).

mod common;

use std::sync::Arc;

use bondmech::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use bondmech::partition::Partition;
use bondmech::solve::formulation::{PartitionedRhs, PartitionedSystem};
use bondmech::{Model, Scene};
use common::double_pendulum::DoublePendulum;
use common::slider_crank::SliderCrank;

/// The partitioned system of a bundled scene at its consistent start: the right-hand side's
/// inputs, the partition chosen there, the start `[q, v]` and the coordinates' names.
fn partitioned(scene: &str) -> (Arc<PartitionedSystem>, Partition, Vec<f64>, Vec<String>) {
    let scene = Scene::from_path(format!("scenes/{scene}.json")).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut sys = model.system().clone();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, 0.0).unwrap();
    let names: Vec<String> = sys.coords.iter().map(|c| c.name.clone()).collect();
    let psys = Arc::new(PartitionedSystem::new(&mut sys, &c));
    let x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    // the translations dependent, as the seed's causality makes them (Fig. 19, 16.8)
    let preferred: Vec<bool> = sys
        .velocities
        .iter()
        .map(|v| v.name.ends_with(".vx") || v.name.ends_with(".vy"))
        .collect();
    let part = psys.choose(0.0, &x, &preferred).unwrap();
    (psys, part, x, names)
}

fn double_pendulum_against_lagrange(mut rhs: PartitionedRhs, names: &[String], newton: u64) {
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
        let before = rhs.newton_iterations();
        rhs.rhs(0.0, &[t1, t2, w1, w2], &mut yd).unwrap();
        assert_eq!(rhs.newton_iterations() - before, newton, "Newton steps");
        let (a1, a2) = reference.accelerations(t1, t2, w1, w2);
        assert_eq!(&yd[..2], &[w1, w2], "q_I' = v_I");
        for (got, want) in [(yd[2], a1), (yd[3], a2)] {
            assert!(
                (got - want).abs() < 1e-9 * (1.0 + want.abs()),
                "{got} vs {want}"
            );
        }
        rhs.complete(0.0, &[t1, t2, w1, w2]).unwrap();
        let q = rhs.full_state();
        let centre2 = [t1.cos() + 0.5 * t2.cos(), t1.sin() + 0.5 * t2.sin()];
        let v2 = [
            -w1 * t1.sin() - 0.5 * w2 * t2.sin(),
            w1 * t1.cos() + 0.5 * w2 * t2.cos(),
        ];
        let nq = names.len();
        assert!((q[idx("bar2.x")] - centre2[0]).abs() < 1e-12);
        assert!((q[idx("bar2.y")] - centre2[1]).abs() < 1e-12);
        assert!((q[nq + idx("bar2.x")] - v2[0]).abs() < 1e-12);
        assert!((q[nq + idx("bar2.x") + 1] - v2[1]).abs() < 1e-12);
    }
}

#[test]
fn double_pendulum_block_rhs_matches_lagrange_with_one_newton_step_per_call() {
    let (psys, part, x, names) = partitioned("double_pendulum");
    let independent: Vec<&str> = part.ind_q.iter().map(|&i| names[i].as_str()).collect();
    assert_eq!(
        independent,
        ["bar1.angle", "bar2.angle"],
        "translations dependent"
    );
    let rhs = PartitionedRhs::new(psys, part, &x, 1e-13).without_elimination();
    assert_eq!(rhs.elimination(), None);
    // pins affine in the dependent translations: one Newton step per evaluation
    double_pendulum_against_lagrange(rhs, &names, 1);
}

#[test]
fn double_pendulum_eliminated_rhs_is_lagranges_equations_without_newton() {
    let (psys, part, x, names) = partitioned("double_pendulum");
    let rhs = PartitionedRhs::new(psys, part, &x, 1e-13);
    // a tree: every translation eliminated, no loop closure left
    assert_eq!(rhs.elimination(), Some((2, 0)));
    double_pendulum_against_lagrange(rhs, &names, 0);
}

#[test]
fn slider_crank_eliminated_rhs_matches_lagrange_with_newton_on_the_loop_closure_only() {
    let (psys, part, x, names) = partitioned("slider_crank");
    let independent: Vec<&str> = part.ind_q.iter().map(|&i| names[i].as_str()).collect();
    assert_eq!(independent, ["crank.angle"]);
    let idx = |n: &str| names.iter().position(|x| x == n).unwrap();
    let sc = SliderCrank::bundled();
    let mut rhs = PartitionedRhs::new(psys.clone(), part.clone(), &x, 1e-13);
    let mut block = PartitionedRhs::new(psys, part, &x, 1e-13).without_elimination();
    // one loop: the crank angle and one dependent coordinate left implicit
    assert_eq!(rhs.elimination(), Some((2, 1)));
    let mut rnd = common::uniform(7);
    let mut yd = [0.0; 2];
    let mut phi = x[idx("crank.angle")];
    let (mut newton_elim, mut newton_block) = (0, 0);
    // around two turns in steps of 0.05 rad (each evaluation warm-starts from the last)
    for _ in 0..250 {
        phi += 0.05;
        let w = 30.0 * rnd();
        // (the completion first: the right-hand side's tangent predictor then carries its
        // curvature term to the next point)
        let before = rhs.newton_iterations();
        rhs.complete(0.0, &[phi, w]).unwrap();
        let k = sc.state(0.0, phi, w);
        let q = rhs.full_state();
        let nq = names.len();
        for (name, want) in [
            ("piston.y", k.piston_y),
            ("rod.x", k.rod_centre[0]),
            ("rod.y", k.rod_centre[1]),
            ("crank.x", k.crank_centre[0]),
        ] {
            assert!((q[idx(name)] - want).abs() < 1e-12, "{name}");
        }
        let dangle = (q[idx("rod.angle")] - k.rod_angle).rem_euclid(std::f64::consts::TAU);
        assert!(
            dangle.min(std::f64::consts::TAU - dangle) < 1e-12,
            "rod angle"
        );
        assert!((q[nq + idx("piston.y")] - k.piston_vy).abs() < 1e-10);
        rhs.rhs(0.0, &[phi, w], &mut yd).unwrap();
        newton_elim += rhs.newton_iterations() - before;
        let gas = -10.0 * phi.cos().max(0.0);
        let want = sc.acceleration(phi, w, gas);
        assert_eq!(yd[0], w);
        assert!(
            (yd[1] - want).abs() < 1e-9 * (1.0 + want.abs()),
            "φ'' at φ = {phi}: {} vs {want}",
            yd[1]
        );
        let before = block.newton_iterations();
        block.complete(0.0, &[phi, w]).unwrap();
        block.rhs(0.0, &[phi, w], &mut yd).unwrap();
        newton_block += block.newton_iterations() - before;
    }
    // Newton on one closure converges in no more iterations than on the whole block
    assert!(
        newton_elim <= newton_block,
        "{newton_elim} > {newton_block}"
    );
}
