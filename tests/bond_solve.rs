//! Raw bond graphs solved over time against closed forms: the damped oscillator on CVODE, two
//! rigidly coupled masses (a differential inertia) on IDA as the velocity-level index-2 DAE and
//! its index-1 variant, a resistor loop on IDA, and the bundled `bg_*` scenes.

use bondmech::bond::{BondGraph, RawBondGraph};
use bondmech::solve::bond_run::{raw_bond_graph_options, solve_bond_graph, solve_raw_bond_graph};
use bondmech::{FormulationKind, Scene, SolveOptions};
use serde_json::{json, Value};

fn graph(v: Value) -> BondGraph {
    let raw: RawBondGraph = serde_json::from_value(v).unwrap();
    raw.to_graph().unwrap()
}

fn opts(t_end: f64, step: f64, rtol: f64, atol: f64) -> SolveOptions {
    SolveOptions {
        rtol,
        atol,
        output_times: SolveOptions::times(t_end, step),
        ..SolveOptions::default()
    }
}

/// Free response of m ẍ + b ẋ + k x = 0 from (x0, 0).
fn damped(m: f64, k: f64, b: f64, x0: f64, t: f64) -> (f64, f64) {
    let w0 = (k / m).sqrt();
    let z = b / (2.0 * (k * m).sqrt());
    let wd = w0 * (1.0 - z * z).sqrt();
    let decay = (-z * w0 * t).exp();
    let x = decay * (x0 * (wd * t).cos() + z * w0 * x0 / wd * (wd * t).sin());
    let v = -decay * x0 * w0 * w0 / wd * (wd * t).sin();
    (x, v)
}

#[test]
fn mass_spring_damper_free_response_matches_the_damped_oscillation() {
    let (m, k, b, x0) = (1.5, 6.0, 0.3, 0.1);
    let g = graph(json!({"elements": [
        {"name": "F", "kind": "Se", "value": 0.0}, {"name": "v", "kind": "1"},
        {"name": "m", "kind": "I", "value": m},
        {"name": "k", "kind": "C", "stiffness": k, "initial": x0},
        {"name": "b", "kind": "R", "value": b}],
     "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"},
               {"from": "v", "to": "k"}, {"from": "v", "to": "b"}]}));
    let sol = solve_bond_graph(&g, &opts(10.0, 0.1, 1e-8, 1e-10)).unwrap();
    assert_eq!(sol.summary.solver, "CVODE");
    let q = sol.column("q_k").unwrap();
    let v = sol.column("f_m").unwrap();
    let mut worst = 0.0f64;
    for (i, &t) in sol.times.iter().enumerate() {
        let (xe, ve) = damped(m, k, b, x0, t);
        worst = worst.max((q[i] - xe).abs()).max((v[i] - ve).abs());
    }
    assert!(worst < 1e-6, "largest error {worst:e}");
    // energy only decreases (the damper dissipates)
    let e = sol.column("energy").unwrap();
    assert!((e[0] - x0 * x0 * k / 2.0).abs() < 1e-15);
    assert!(e.windows(2).all(|w| w[1] <= w[0] + 1e-12));
}

fn rigid_pair(f: f64, m1: f64, m2: f64, k: f64) -> BondGraph {
    graph(json!({"elements": [
        {"name": "F", "kind": "Se", "value": f}, {"name": "j", "kind": "1"},
        {"name": "m1", "kind": "I", "value": m1}, {"name": "m2", "kind": "I", "value": m2},
        {"name": "k", "kind": "C", "stiffness": k}],
     "bonds": [{"from": "F", "to": "j"}, {"from": "j", "to": "m1"},
               {"from": "j", "to": "m2"}, {"from": "j", "to": "k"}]}))
}

fn check_rigid_pair(formulation: FormulationKind, tol: f64) {
    // one body of mass M = m1 + m2 pushed by F against a spring from rest at q = 0:
    // q = (F/k)(1 − cos ωt), v = (F/k) ω sin ωt, ω² = k/M; the force on m2 is λ = m2 (F − k q)/M
    let (f, m1, m2, k): (f64, f64, f64, f64) = (3.0, 1.0, 2.0, 12.0);
    let total = m1 + m2;
    let w = (k / total).sqrt();
    let mut o = opts(5.0, 0.05, 1e-9, 1e-11);
    o.formulation = formulation;
    let sol = solve_bond_graph(&rigid_pair(f, m1, m2, k), &o).unwrap();
    assert_eq!(sol.summary.solver, "IDA");
    let (q, v1, v2, lam) = (
        sol.column("q_k").unwrap(),
        sol.column("f_m1").unwrap(),
        sol.column("f_m2").unwrap(),
        sol.column("lambda_m2").unwrap(),
    );
    let (mut eq, mut ev, mut el) = (0.0f64, 0.0f64, 0.0f64);
    for (i, &t) in sol.times.iter().enumerate() {
        let qe = f / k * (1.0 - (w * t).cos());
        let ve = f / k * w * (w * t).sin();
        eq = eq.max((q[i] - qe).abs());
        ev = ev.max((v1[i] - ve).abs()).max((v2[i] - ve).abs());
        if i > 0 {
            el = el.max((lam[i] - m2 * (f - k * qe) / total).abs());
        }
    }
    assert!(
        eq < tol && ev < tol,
        "position error {eq:e}, velocity error {ev:e}"
    );
    assert!(el < 100.0 * tol, "multiplier error {el:e}");
    assert!(sol.summary.max_constraint_error < tol);
}

#[test]
fn rigidly_coupled_masses_as_index2_dae_move_as_one_mass() {
    check_rigid_pair(FormulationKind::Dae, 1e-6);
}

#[test]
fn rigidly_coupled_masses_as_index1_dae_move_as_one_mass() {
    check_rigid_pair(FormulationKind::Index1, 1e-6);
}

#[test]
fn resistor_loop_charges_the_inductor_like_its_thevenin_equivalent() {
    // i(t) = (Vth/Rt)(1 − e^{−Rt t/L}), Vth = V R2/(R1+R2), Rt = R1 R2/(R1+R2) + R3
    let (v, r1, r2, r3, l) = (10.0, 2.0, 3.0, 0.5, 0.2);
    let g = graph(json!({"elements": [
        {"name": "V", "kind": "Se", "value": v},
        {"name": "1a", "kind": "1"}, {"name": "R1", "kind": "R", "value": r1},
        {"name": "0", "kind": "0"}, {"name": "R2", "kind": "R", "value": r2},
        {"name": "1b", "kind": "1"}, {"name": "L", "kind": "I", "value": l},
        {"name": "R3", "kind": "R", "value": r3}],
     "bonds": [{"from": "V", "to": "1a"}, {"from": "1a", "to": "R1"}, {"from": "1a", "to": "0"},
               {"from": "0", "to": "R2"}, {"from": "0", "to": "1b"},
               {"from": "1b", "to": "L"}, {"from": "1b", "to": "R3"}]}));
    let sol = solve_bond_graph(&g, &opts(1.0, 0.02, 1e-9, 1e-11)).unwrap();
    let (vth, rt) = (v * r2 / (r1 + r2), r1 * r2 / (r1 + r2) + r3);
    let i = sol.column("f_L").unwrap();
    for (k, &t) in sol.times.iter().enumerate() {
        let want = vth / rt * (1.0 - (-rt * t / l).exp());
        assert!((i[k] - want).abs() < 1e-6, "t = {t}: {} vs {want}", i[k]);
    }
}

fn scene(name: &str) -> Scene {
    Scene::from_path(format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

#[test]
fn bundled_mass_spring_damper_scene_matches_the_closed_form() {
    let s = scene("bg_mass_spring_damper.json");
    let sol = solve_raw_bond_graph(&s, &raw_bond_graph_options(&s)).unwrap();
    let q = sol.column("q_k").unwrap();
    for (i, &t) in sol.times.iter().enumerate() {
        assert!((q[i] - damped(1.5, 6.0, 0.3, 0.1, t).0).abs() < 1e-6);
    }
    assert_eq!(*sol.times.last().unwrap(), 10.0);
}

#[test]
fn bundled_dc_motor_scene_reaches_the_steady_speed() {
    // ω∞ = K V/(R b + K²), i∞ = b ω∞ / K
    let (v, r, kt, b) = (12.0, 1.0, 0.1, 0.001);
    let s = scene("bg_dc_motor.json");
    let sol = solve_raw_bond_graph(&s, &raw_bond_graph_options(&s)).unwrap();
    let w = *sol.column("f_J").unwrap().last().unwrap();
    let i = *sol.column("f_La").unwrap().last().unwrap();
    let w_ss = kt * v / (r * b + kt * kt);
    assert!((w - w_ss).abs() < 1e-5 * w_ss, "{w} vs {w_ss}");
    assert!((i - b * w_ss / kt).abs() < 1e-5, "{i}");
}

#[test]
fn signals_in_a_raw_scene_are_refused_with_their_name() {
    let g = graph(json!({"signals": ["u"], "elements": [
        {"name": "F", "kind": "Se", "value": "u"}, {"name": "j", "kind": "1"},
        {"name": "m", "kind": "I", "value": 1.0}],
     "bonds": [{"from": "F", "to": "j"}, {"from": "j", "to": "m"}]}));
    let err = solve_bond_graph(&g, &SolveOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("signal 'u'"), "{err}");
}
