//! The bond graph is the model: a mechanism's equations are read off its own bond graph
//! ([`bondmech::bond::mechanics`]), and they agree with an independently written
//! absolute-coordinate multibody assembly (`tests/oracle`, once bondmech's own equation path)
//! at random states on every bundled scene: `M`, `K(q) v`, `Q`, `g`, `G_v v`, the energy, and
//! the decoupled twin's right-hand side (the graph with its joints opened).

mod oracle;

use bondmech::expr::ExprGraph;
use bondmech::mech::{self, EquationSource, MultibodySystem};
use bondmech::scene::Scene;
use bondmech::solve::formulation::DecoupledFormulation;

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
    let (mut oracle, potential) = oracle::assembled(&s);
    assert_eq!(bg.mass, oracle.mass, "{name}: inertias");
    let names = |c: &[mech::Coordinate]| c.iter().map(|c| c.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&bg.coords), names(&oracle.coords), "{name}");
    assert_eq!(names(&bg.velocities), names(&oracle.velocities), "{name}");
    let gvv = oracle.velocity_constraints();
    // the oracle's energy: ½ Σ M v² + the weight's and the springs' potential
    let nq = oracle.nq();
    let mut kinetic = Vec::new();
    for (j, &m) in oracle.mass.clone().iter().enumerate() {
        let v = oracle.graph.var((1 + nq + j) as u32);
        let v2 = oracle.graph.mul(v, v);
        kinetic.push(oracle.graph.scale(0.5 * m, v2));
    }
    kinetic.push(potential);
    let energy = oracle.graph.sum(&kinetic);
    for x in states(&bg, 5) {
        for (what, ours, theirs) in [
            ("kinematics", &bg.kinematics, &oracle.kinematics),
            ("forces", &bg.forces, &oracle.forces),
            ("closures", &bg.constraints, &oracle.constraints),
            ("constraint flows", &bg.flow_rows, &gvv),
            ("energy", &vec![bg.energy], &vec![energy]),
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
    twin_agrees_with_oracle(name, &bg, &mut oracle, &gvv);
}

/// The decoupled twin read off the graph with its joints opened (a C of stiffness k with the
/// closure as displacement and an R of damping c on every constraint junction) against the
/// oracle's `M v' = Q − G_vᵀ (k g + c G_v v)`, `G_v = ∂(G_v v)/∂v`.
fn twin_agrees_with_oracle(
    name: &str,
    bg: &MultibodySystem,
    oracle: &mut MultibodySystem,
    gvv: &[bondmech::expr::Expr],
) {
    if bg.mass.iter().any(|&m| m <= 0.0) {
        return; // no twin without an inertia on every velocity
    }
    let (k, c) = (1e4, 3.0);
    let mut twin_sys = bg.clone();
    let twin = DecoupledFormulation::build(&mut twin_sys, k, c).unwrap();
    let (nq, nv) = (oracle.nq(), oracle.nv());
    let mut ws = twin.ode.workspace();
    for x in states(bg, 3) {
        let y = &x[1..];
        let mut ours = vec![0.0; nq + nv];
        twin.ode.rhs(&mut ws, x[0], y, &mut ours);
        let g = eval_all(&oracle.graph, &oracle.constraints, &x);
        let rate = eval_all(&oracle.graph, gvv, &x);
        // Q_j − Σ_i G_ij (k g_i + c G_i v), and the largest term of the whole system: the
        // joints' spring forces cancel, so rounding is relative to that scale
        let mut want = vec![0.0; nv];
        let mut scale = 0.0f64;
        for (j, w) in want.iter_mut().enumerate() {
            let slot = (1 + nq + j) as u32;
            let mut q = oracle.graph.eval(oracle.forces[j], &x);
            scale = scale.max(q.abs());
            for (i, &row) in gvv.iter().enumerate() {
                let gij = oracle.graph.diff(row, slot);
                let term = oracle.graph.eval(gij, &x) * (k * g[i] + c * rate[i]);
                q -= term;
                scale = scale.max(term.abs());
            }
            *w = q;
        }
        for j in 0..nv {
            let m = oracle.mass[j];
            let (got, want) = (ours[nq + j], want[j] / m);
            assert!(
                (got - want).abs() <= 1e-11 * (1.0 + scale / m),
                "{name}: twin v'[{j}] from the opened graph {got} vs oracle {want} (force scale {scale}, inertia {m})"
            );
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

/// `scenes/<name>.json` with a JSON edit applied.
fn edited(name: &str, edit: impl Fn(&mut serde_json::Value)) -> Scene {
    let path = format!("{}/scenes/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut v);
    Scene::from_json_str(&v.to_string()).unwrap()
}

/// Gravity with an x component (the seed's planar fragments carry the weight along y only; the
/// completion adds the x part on each centre's global x junction) in both body frames, and a
/// torque on a spatial body (an Se on the modulated sum `R ω`, the global angular velocity):
/// the cases the graph used to leave to the assembled equations.
#[test]
fn sideways_gravity_and_spatial_torques_are_read_off_the_bond_graph() {
    let sideways = |v: &mut serde_json::Value| v["gravity"] = serde_json::json!([3.0, -9.81]);
    agrees_with_oracle_on("double_pendulum", &edited("double_pendulum", sideways));
    agrees_with_oracle_on(
        "double_pendulum, body-fixed",
        &edited("double_pendulum", |v| {
            sideways(v);
            for b in v["bodies"].as_array_mut().unwrap() {
                b["frame"] = "body".into();
            }
        }),
    );
    agrees_with_oracle_on(
        "free body with a torque",
        &edited("free_body_3d", |v| {
            v["gravity"] = serde_json::json!([0.5, 0.0, -9.81]);
            v["loads"] = serde_json::json!([
                {"name": "twist", "type": "torque", "body": "body", "value": [0.3, -0.2, 0.7]}
            ]);
        }),
    );
}
