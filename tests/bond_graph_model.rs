//! The bond graph is the model: a planar mechanism's equations are read off its own bond graph
//! ([`bondmech::bond::mechanics`]), and they agree with an independently written
//! absolute-coordinate multibody assembly (`mech::assemble`, kept as the oracle) at random
//! states on every bundled scene the graph can carry.

use bondmech::expr::ExprGraph;
use bondmech::mech::{self, EquationSource, MultibodySystem};
use bondmech::scene::Scene;

fn scene(name: &str) -> Scene {
    Scene::from_path(format!("{}/scenes/{name}.json", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// Deterministic states `[t, q, v]` around the initial one.
fn states(sys: &MultibodySystem, n: usize) -> Vec<Vec<f64>> {
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let x0 = sys.initial_state();
    (0..n)
        .map(|_| {
            let mut x = vec![0.3 + next()];
            x.extend(x0.iter().map(|&v| v + 0.4 * next()));
            x
        })
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-11 * (1.0 + a.abs().max(b.abs()))
}

fn eval_all(g: &ExprGraph, es: &[bondmech::expr::Expr], x: &[f64]) -> Vec<f64> {
    es.iter().map(|&e| g.eval(e, x)).collect()
}

/// The scene with every body written in its body-fixed frame (seed 16.3).
fn body_frame(name: &str) -> Scene {
    let path = format!("{}/scenes/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for b in v["bodies"].as_array_mut().unwrap() {
        b["frame"] = "body".into();
    }
    Scene::from_json_str(&v.to_string()).unwrap()
}

/// M, K(q)v, Q, g(q) and G_v v of the bond graph against the assembled oracle.
fn agrees_with_oracle(name: &str) {
    agrees_with_oracle_on(name, &scene(name));
}

fn agrees_with_oracle_on(name: &str, s: &Scene) {
    let s = s.clone();
    let bg = mech::build(&s).unwrap();
    assert_eq!(
        bg.source,
        EquationSource::BondGraph,
        "{name}: equations not read off the bond graph"
    );
    let mut oracle = mech::assemble(&s).unwrap();
    assert_eq!(bg.mass, oracle.mass, "{name}: inertias");
    let names = |c: &[mech::Coordinate]| c.iter().map(|c| c.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&bg.coords), names(&oracle.coords), "{name}");
    assert_eq!(names(&bg.velocities), names(&oracle.velocities), "{name}");
    let gvv = oracle.velocity_constraints();
    for x in states(&bg, 5) {
        for (what, ours, theirs) in [
            ("kinematics", &bg.kinematics, &oracle.kinematics),
            ("forces", &bg.forces, &oracle.forces),
            ("closures", &bg.constraints, &oracle.constraints),
            ("constraint flows", &bg.flow_rows, &gvv),
        ] {
            let a = eval_all(&bg.graph, ours, &x);
            let b = eval_all(&oracle.graph, theirs, &x);
            assert_eq!(a.len(), b.len(), "{name}: {what}");
            for (k, (u, v)) in a.iter().zip(&b).enumerate() {
                assert!(
                    close(*u, *v),
                    "{name}: {what}[{k}] bond graph {u} vs oracle {v} at {x:?}"
                );
            }
        }
    }
}

#[test]
fn double_pendulum_equations_are_read_off_its_bond_graph() {
    agrees_with_oracle("double_pendulum");
}

#[test]
fn pendulums_and_two_bars_equations_are_read_off_their_bond_graphs() {
    for n in ["pendulum", "pendulum_point_mass", "two_bars"] {
        agrees_with_oracle(n);
    }
}

#[test]
fn four_bars_equations_are_read_off_their_bond_graphs() {
    agrees_with_oracle("four_bar");
    agrees_with_oracle("four_bar_chain_3");
}

#[test]
fn slider_crank_equations_are_read_off_its_bond_graph() {
    agrees_with_oracle("slider_crank");
}

#[test]
fn andrews_squeezer_equations_are_read_off_its_bond_graph() {
    agrees_with_oracle("andrews_squeezer");
}

#[test]
fn spatial_bodies_equations_are_read_off_their_bond_graphs() {
    for n in [
        "free_body_3d",
        "hinged_double_pendulum_3d",
        "spatial_slider_crank",
    ] {
        agrees_with_oracle(n);
    }
}

#[test]
fn bricard_equations_are_read_off_its_bond_graph() {
    agrees_with_oracle("bricard");
}

/// Bars in their body-fixed frame (16.3: velocities along the body axes, the MGY `m ω`, the
/// weight through sin/cos of the angle) read the same equations as in the non-rotating frame's
/// oracle assembly of that frame.
#[test]
fn body_fixed_bars_equations_are_read_off_their_bond_graphs() {
    for n in ["double_pendulum", "two_bars", "slider_crank", "four_bar"] {
        agrees_with_oracle_on(n, &body_frame(n));
    }
}
