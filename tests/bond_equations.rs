//! Equations generated from causal bond graphs against hand derivations (written here from the
//! physics, not from the code): mass-spring-damper, two masses and a spring, a DC motor (GY),
//! a lever (TF), an algebraic loop of two resistors, two masses rigidly coupled (one
//! differential inertia); and every generated Jacobian against finite differences.

mod support;

use bondmech::bond::equations::{BondEquations, EquationError, VariableKind};
use bondmech::bond::{assign_causality, BondGraph, RawBondGraph};
use bondmech::dae::ImplicitDae;
use proptest::prelude::*;
use serde_json::{json, Value};
use support::bond::{eqs, graph, rhs_at, Lcg};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

fn msd(force: Value) -> Value {
    json!({"elements": [
        {"name": "F", "kind": "Se", "value": force},
        {"name": "j", "kind": "1"},
        {"name": "m", "kind": "I", "value": 2.0},
        {"name": "k", "kind": "C", "stiffness": 5.0},
        {"name": "b", "kind": "R", "value": 0.3}],
     "bonds": [{"from": "F", "to": "j"}, {"from": "j", "to": "m"},
               {"from": "j", "to": "k"}, {"from": "j", "to": "b"}]})
}

#[test]
fn mass_spring_damper_matches_hand_a_and_b() {
    // x = [p, q]: ṗ = F − k q − b p/m, q̇ = p/m  →  A = [[−b/m, −k], [1/m, 0]], B = [1, 0]
    let (m, k, b) = (2.0, 5.0, 0.3);
    let a = [[-b / m, -k], [1.0 / m, 0.0]];
    let e = eqs(&graph(msd(json!("3*sin(t)"))));
    assert_eq!(e.names, vec!["p_m", "q_k"]);
    assert!(e.is_ode());
    let mut r = Lcg(1);
    for _ in 0..20 {
        let (t, p, q) = (r.next(0.0, 5.0), r.next(-3.0, 3.0), r.next(-3.0, 3.0));
        let u = 3.0 * t.sin();
        let got = rhs_at(&e, t, &[p, q]);
        let want = [a[0][0] * p + a[0][1] * q + u, a[1][0] * p + a[1][1] * q];
        for i in 0..2 {
            assert!(close(got[i], want[i], 1e-13), "{got:?} vs {want:?}");
        }
    }
}

#[test]
fn two_masses_coupled_by_a_spring_match_hand_derivation() {
    // ṗ1 = F − k q, ṗ2 = k q − c p2/m2, q̇ = p1/m1 − p2/m2
    let (f, m1, m2, k, c) = (1.5, 1.0, 3.0, 40.0, 0.7);
    let g = graph(json!({"elements": [
        {"name": "F", "kind": "Se", "value": f},
        {"name": "1a", "kind": "1"}, {"name": "m1", "kind": "I", "value": m1},
        {"name": "0s", "kind": "0"}, {"name": "ks", "kind": "C", "stiffness": k},
        {"name": "1b", "kind": "1"}, {"name": "m2", "kind": "I", "value": m2},
        {"name": "c2", "kind": "R", "value": c}],
     "bonds": [{"from": "F", "to": "1a"}, {"from": "1a", "to": "m1"}, {"from": "1a", "to": "0s"},
               {"from": "0s", "to": "ks"}, {"from": "0s", "to": "1b"},
               {"from": "1b", "to": "m2"}, {"from": "1b", "to": "c2"}]}));
    let e = eqs(&g);
    assert_eq!(e.names, vec!["p_m1", "p_m2", "q_ks"]);
    let mut r = Lcg(2);
    for _ in 0..20 {
        let y = [r.next(-2.0, 2.0), r.next(-2.0, 2.0), r.next(-2.0, 2.0)];
        let want = [
            f - k * y[2],
            k * y[2] - c * y[1] / m2,
            y[0] / m1 - y[1] / m2,
        ];
        let got = rhs_at(&e, 0.0, &y);
        for i in 0..3 {
            assert!(close(got[i], want[i], 1e-13), "{got:?} vs {want:?}");
        }
    }
}

fn dc_motor() -> Value {
    json!({"elements": [
        {"name": "V", "kind": "Se", "value": 12.0},
        {"name": "1e", "kind": "1"}, {"name": "Ra", "kind": "R", "value": 1.2},
        {"name": "La", "kind": "I", "value": 0.05},
        {"name": "gy", "kind": "GY", "modulus": 0.08},
        {"name": "1m", "kind": "1"}, {"name": "J", "kind": "I", "value": 0.02},
        {"name": "bm", "kind": "R", "value": 0.003}],
     "bonds": [{"from": "V", "to": "1e"}, {"from": "1e", "to": "Ra"}, {"from": "1e", "to": "La"},
               {"from": "1e", "to": "gy"}, {"from": "gy", "to": "1m"},
               {"from": "1m", "to": "J"}, {"from": "1m", "to": "bm"}]})
}

#[test]
fn dc_motor_gyrator_matches_hand_derivation() {
    // L di/dt = V − R i − K ω, J dω/dt = K i − b ω with p_L = L i, p_J = J ω
    let (v, ra, la, kt, j, bm) = (12.0, 1.2, 0.05, 0.08, 0.02, 0.003);
    let e = eqs(&graph(dc_motor()));
    assert_eq!(e.names, vec!["p_La", "p_J"]);
    let mut r = Lcg(3);
    for _ in 0..20 {
        let y = [r.next(-2.0, 2.0), r.next(-2.0, 2.0)];
        let (i, w) = (y[0] / la, y[1] / j);
        let want = [v - ra * i - kt * w, kt * i - bm * w];
        let got = rhs_at(&e, 0.0, &y);
        for n in 0..2 {
            assert!(close(got[n], want[n], 1e-12), "{got:?} vs {want:?}");
        }
    }
}

#[test]
fn lever_transformer_matches_hand_derivation() {
    // output velocity a·v1 drives a spring-damper; the force comes back multiplied by a:
    // ṗ1 = F − a (k q + c a p1/m1), q̇ = a p1/m1
    let (f, m1, a, k, c) = (2.0, 0.5, 3.0, 10.0, 0.4);
    let g = graph(json!({"elements": [
        {"name": "F", "kind": "Se", "value": f},
        {"name": "1a", "kind": "1"}, {"name": "m1", "kind": "I", "value": m1},
        {"name": "lev", "kind": "TF", "modulus": a},
        {"name": "1b", "kind": "1"}, {"name": "k", "kind": "C", "stiffness": k},
        {"name": "c", "kind": "R", "value": c}],
     "bonds": [{"from": "F", "to": "1a"}, {"from": "1a", "to": "m1"}, {"from": "1a", "to": "lev"},
               {"from": "lev", "to": "1b"}, {"from": "1b", "to": "k"}, {"from": "1b", "to": "c"}]}));
    let e = eqs(&g);
    assert_eq!(e.names, vec!["p_m1", "q_k"]);
    let mut r = Lcg(4);
    for _ in 0..20 {
        let y = [r.next(-2.0, 2.0), r.next(-2.0, 2.0)];
        let v1 = y[0] / m1;
        let want = [f - a * (k * y[1] + c * a * v1), a * v1];
        let got = rhs_at(&e, 0.0, &y);
        for n in 0..2 {
            assert!(close(got[n], want[n], 1e-13), "{got:?} vs {want:?}");
        }
    }
}

fn resistor_loop(v: f64, r1: f64, r2: f64, r3: f64, l: f64) -> Value {
    json!({"elements": [
        {"name": "V", "kind": "Se", "value": v},
        {"name": "1a", "kind": "1"}, {"name": "R1", "kind": "R", "value": r1},
        {"name": "0", "kind": "0"}, {"name": "R2", "kind": "R", "value": r2},
        {"name": "1b", "kind": "1"}, {"name": "L", "kind": "I", "value": l},
        {"name": "R3", "kind": "R", "value": r3}],
     "bonds": [{"from": "V", "to": "1a"}, {"from": "1a", "to": "R1"}, {"from": "1a", "to": "0"},
               {"from": "0", "to": "R2"}, {"from": "0", "to": "1b"},
               {"from": "1b", "to": "L"}, {"from": "1b", "to": "R3"}]})
}

#[test]
fn algebraic_loop_of_two_resistors_gives_the_thevenin_equivalent() {
    // V with R1 in series, R2 across: Thevenin source V R2/(R1+R2) behind R1 R2/(R1+R2),
    // so L di/dt = V R2/(R1+R2) − (R1 R2/(R1+R2) + R3) i
    let (v, r1, r2, r3, l) = (10.0, 2.0, 3.0, 0.5, 0.2);
    let g = graph(resistor_loop(v, r1, r2, r3, l));
    let c = assign_causality(&g).unwrap();
    assert_eq!(c.algebraic_loops.len(), 1);
    let e = BondEquations::new(&g, &c).unwrap();
    assert!(e.n_loops >= 1);
    assert!(e.ode().is_none());
    assert!(e.kinds[1..].iter().all(|k| *k == VariableKind::Loop));
    let (vth, rth) = (v * r2 / (r1 + r2), r1 * r2 / (r1 + r2));
    for p in [-1.0, 0.0, 0.3, 2.0] {
        let mut y0 = e.initial.clone();
        y0[0] = p;
        let (_, yp) = e.consistent_start(0.0, &y0).unwrap();
        let want = vth - (rth + r3) * p / l;
        assert!(close(yp[0], want, 1e-12), "{} vs {want}", yp[0]);
    }
}

fn rigid_pair(f: f64, m1: f64, m2: f64, k: f64) -> Value {
    json!({"elements": [
        {"name": "F", "kind": "Se", "value": f},
        {"name": "j", "kind": "1"},
        {"name": "m1", "kind": "I", "value": m1},
        {"name": "m2", "kind": "I", "value": m2},
        {"name": "k", "kind": "C", "stiffness": k}],
     "bonds": [{"from": "F", "to": "j"}, {"from": "j", "to": "m1"},
               {"from": "j", "to": "m2"}, {"from": "j", "to": "k"}]})
}

#[test]
fn rigidly_coupled_masses_have_one_constraint_row_and_the_combined_acceleration() {
    // one body of mass m1 + m2: a = (F − k q)/(m1 + m2); the force on m2 is λ = m2 a
    let (f, m1, m2, k) = (3.0, 1.0, 2.0, 4.0);
    let e = eqs(&graph(rigid_pair(f, m1, m2, k)));
    assert_eq!(e.names, vec!["p_m1", "q_k", "p_m2", "lambda_m2"]);
    assert_eq!((e.n_dependent, e.constraints.len()), (1, 1));
    assert_eq!(e.algebraic_names(), vec!["lambda_m2"]);
    assert_eq!(e.id(), vec![1.0, 1.0, 1.0, 0.0]);
    let (v0, q0) = (0.7, 0.25);
    let (y, yp) = e.consistent_start(0.0, &[m1 * v0, q0, 0.0, 0.0]).unwrap();
    let acc = (f - k * q0) / (m1 + m2);
    assert!(close(y[2], m2 * v0, 1e-13), "p_m2 = {}", y[2]);
    assert!(close(y[3], m2 * acc, 1e-12), "λ = {}", y[3]);
    assert!(close(yp[0], m1 * acc, 1e-12));
    assert!(close(yp[1], v0, 1e-12));
    // the index-2 residual vanishes at the consistent start
    let dae = e.velocity_index2();
    let mut ws = dae.workspace();
    let mut r = vec![0.0; 4];
    dae.residual(&mut ws, 0.0, &y, &yp, &mut r);
    assert!(r.iter().all(|x| x.abs() < 1e-12), "{r:?}");
    // sparsity (rows: ṗ1, q̇, ṗ2 − λ, constraint): the constraint row touches p_m1 and p_m2
    // only, the ṗ2 row p_m2 (through y') and λ
    let s = e.sparsity();
    let row =
        |i: usize| -> Vec<usize> { s.iter().filter(|(r, _)| *r == i).map(|(_, c)| *c).collect() };
    assert_eq!(row(3), vec![0, 2]);
    assert_eq!(row(2), vec![2, 3]);
}

#[test]
fn conflicting_causality_is_refused_with_the_junction_name() {
    // two flow sources on one 1-junction
    let g = graph(json!({"elements": [
        {"name": "S1", "kind": "Sf", "value": 1.0}, {"name": "S2", "kind": "Sf", "value": 2.0},
        {"name": "j", "kind": "1"}, {"name": "m", "kind": "I", "value": 1.0}],
     "bonds": [{"from": "S1", "to": "j"}, {"from": "S2", "to": "j"}, {"from": "j", "to": "m"}]}));
    let err = BondEquations::new(&g, &assign_causality(&g).unwrap()).unwrap_err();
    assert!(
        matches!(err, EquationError::Conflict { ref junction, .. } if junction == "j"),
        "{err}"
    );
}

#[test]
fn initial_values_are_read_from_json_and_checked() {
    let mut v = msd(json!(0.0));
    v["elements"][2]["initial"] = json!(0.5);
    v["elements"][3]["initial"] = json!(-0.1);
    let g = graph(v.clone());
    assert_eq!(eqs(&g).initial, vec![0.5, -0.1]);
    // round trip keeps them
    let back = g.to_raw().to_graph().unwrap();
    assert_eq!(eqs(&back).initial, vec![0.5, -0.1]);
    // not on a resistor
    v["elements"][4]["initial"] = json!(1.0);
    let raw: RawBondGraph = serde_json::from_value(v).unwrap();
    let err = raw.to_graph().unwrap_err().to_string();
    assert!(err.contains("elements[4].initial"), "{err}");
}

fn modulated() -> Value {
    // a crank-like MTF whose modulus depends on the integrated flow of the inertia, with a
    // time-varying source: exercises x_ states, sin/cos and t in the Jacobians
    json!({"elements": [
        {"name": "F", "kind": "Se", "value": "sin(2*t) + 0.5"},
        {"name": "1a", "kind": "1"}, {"name": "m1", "kind": "I", "value": 1.3},
        {"name": "tf", "kind": "MTF", "modulus": "2 + cos(x_m1)"},
        {"name": "0b", "kind": "0"}, {"name": "k", "kind": "C", "stiffness": "3 + t"},
        {"name": "c", "kind": "R", "value": 0.4}],
     "bonds": [{"from": "F", "to": "1a"}, {"from": "1a", "to": "m1"}, {"from": "1a", "to": "tf"},
               {"from": "tf", "to": "0b"}, {"from": "0b", "to": "k"}, {"from": "0b", "to": "c"}]})
}

#[test]
fn modulus_displacement_becomes_a_state_with_the_inertia_flow() {
    let e = eqs(&graph(modulated()));
    assert_eq!(e.names, vec!["p_m1", "q_k", "x_m1"]);
    // ẋ_m1 = p1/m1
    let got = rhs_at(&e, 0.3, &[0.65, 0.1, 0.2]);
    assert!(close(got[2], 0.5, 1e-14));
}

fn all_graphs() -> Vec<BondGraph> {
    vec![
        graph(msd(json!("3*sin(t)"))),
        graph(dc_motor()),
        graph(resistor_loop(10.0, 2.0, 3.0, 0.5, 0.2)),
        graph(rigid_pair(3.0, 1.0, 2.0, 4.0)),
        graph(modulated()),
    ]
}

/// Largest relative difference between the exact Jacobian `∂F/∂y + cj ∂F/∂y'` and central
/// differences of the residual.
fn jacobian_error(dae: &ImplicitDae, t: f64, y: &[f64], yp: &[f64], cj: f64) -> f64 {
    let n = dae.n;
    let mut ws = dae.workspace();
    let mut exact = vec![0.0; n * n];
    dae.jacobian(&mut ws, t, cj, y, yp, |r, c, v| exact[r * n + c] += v);
    let mut worst = 0.0f64;
    let h = 1e-6;
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    for c in 0..n {
        let mut fd = vec![0.0; n];
        for (w, which) in [(1.0, 0), (cj, 1)] {
            let (mut yy, mut yyp) = (y.to_vec(), yp.to_vec());
            let v = if which == 0 { &mut yy } else { &mut yyp };
            v[c] += h;
            dae.residual(&mut ws, t, &yy, &yyp, &mut rp);
            let v = if which == 0 { &mut yy } else { &mut yyp };
            v[c] -= 2.0 * h;
            dae.residual(&mut ws, t, &yy, &yyp, &mut rm);
            for r in 0..n {
                fd[r] += w * (rp[r] - rm[r]) / (2.0 * h);
            }
        }
        for r in 0..n {
            let d = (exact[r * n + c] - fd[r]).abs() / (1.0 + fd[r].abs());
            worst = worst.max(d);
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn every_generated_jacobian_matches_finite_differences(
        which in 0usize..5,
        t in 0.0f64..3.0,
        cj in 0.1f64..100.0,
        raw in proptest::collection::vec(-2.0f64..2.0, 16),
    ) {
        let g = &all_graphs()[which];
        let e = eqs(g);
        let n = e.n;
        let (y, yp) = (&raw[..n], &raw[8..8 + n]);
        for dae in [e.velocity_index2(), e.index1()] {
            let err = jacobian_error(&dae, t, y, yp, cj);
            prop_assert!(err < 1e-6, "graph {which}: jacobian error {err}");
        }
        if let Some(ode) = e.ode() {
            let mut ws = ode.workspace();
            let mut exact = vec![0.0; n * n];
            ode.jacobian(&mut ws, t, y, |r, c, v| exact[r * n + c] += v);
            let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
            for c in 0..n {
                let (mut a, mut b) = (y.to_vec(), y.to_vec());
                a[c] += 1e-6;
                b[c] -= 1e-6;
                ode.rhs(&mut ws, t, &a, &mut fp);
                ode.rhs(&mut ws, t, &b, &mut fm);
                for r in 0..n {
                    let fd = (fp[r] - fm[r]) / 2e-6;
                    prop_assert!((exact[r * n + c] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "graph {which}: ode jacobian ({r},{c}) {} vs {fd}", exact[r * n + c]);
                }
            }
        }
    }
}
