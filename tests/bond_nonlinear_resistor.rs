//! Nonlinear resistors (`R` with a constitutive law instead of a resistance), checked against
//! hand derivations and closed forms written here:
//! - a mass falling under a constant force against quadratic drag `e = c·f·|f|` (resistance
//!   causality): `m v' = F − c v|v|`, from rest `v(t) = v_t tanh(t √(F c)/m)`, `v_t = √(F/c)`;
//! - a capacitor discharging through a cubic conductance `f = g·e³` (conductance causality):
//!   `q' = −g (q/C)³`, so `q(t) = q₀ / √(1 + 2 g q₀² t / C³)`;
//! - errors that name the element, the JSON path and the missing form of the law.

mod support;

use bondmech::bond::equations::BondEquations;
use bondmech::bond::{assign_causality, RawBondGraph};
use bondmech::solve::bond_run::solve_bond_graph;
use bondmech::SolveOptions;
use serde_json::{json, Value};
use support::bond::{graph, rhs_at};

fn raw(v: Value) -> RawBondGraph {
    serde_json::from_value(v).unwrap()
}

fn drag(m: f64, f: f64, c: f64, reversed: bool) -> Value {
    // `reversed` draws the drag bond out of the resistor: the law is still in the flow *into*
    // the resistor, so the dynamics must not change
    let bond = if reversed {
        json!({"from": "drag", "to": "v"})
    } else {
        json!({"from": "v", "to": "drag"})
    };
    json!({"elements": [
        {"name": "F", "kind": "Se", "value": f}, {"name": "v", "kind": "1"},
        {"name": "m", "kind": "I", "value": m},
        {"name": "drag", "kind": "R", "effort_law": format!("{c}*f*abs(f)")}],
     "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"}, bond]})
}

#[test]
fn quadratic_drag_equations_match_hand_derivation_in_both_bond_directions() {
    let (m, f, c) = (2.0, 9.0, 0.5);
    for reversed in [false, true] {
        let g = graph(drag(m, f, c, reversed));
        let e = BondEquations::new(&g, &assign_causality(&g).unwrap()).unwrap();
        assert_eq!(e.rhs.len(), 1);
        for p in [-3.0, -0.4, 0.0, 0.7, 5.0] {
            let v: f64 = p / m;
            let want = f - c * v * v.abs();
            let got = rhs_at(&e, 0.0, &[p])[0];
            assert!((got - want).abs() < 1e-12, "p = {p}: {got} vs {want}");
        }
    }
}

#[test]
fn falling_mass_with_quadratic_drag_reaches_tanh_terminal_velocity() {
    let (m, f, c) = (2.0, 9.0, 0.5);
    let g = graph(drag(m, f, c, false));
    let o = SolveOptions {
        rtol: 1e-10,
        atol: 1e-12,
        output_times: SolveOptions::times(6.0, 0.05),
        ..SolveOptions::default()
    };
    let sol = solve_bond_graph(&g, &o).unwrap();
    let v = sol.column("f_m").unwrap();
    let vt = (f / c).sqrt();
    for (k, t) in sol.times.iter().enumerate() {
        let want = vt * (t * (f * c).sqrt() / m).tanh();
        assert!((v[k] - want).abs() < 1e-7, "t = {t}: {} vs {want}", v[k]);
    }
    assert!((v.last().unwrap() - vt).abs() < 1e-3 * vt);
}

fn discharge(cap: f64, q0: f64, law: (&str, String)) -> Value {
    let mut r = json!({"name": "leak", "kind": "R"});
    r[law.0] = json!(law.1);
    json!({"elements": [
        {"name": "u", "kind": "0"},
        {"name": "cap", "kind": "C", "compliance": cap, "initial": q0},
        r],
     "bonds": [{"from": "u", "to": "cap"}, {"from": "u", "to": "leak"}]})
}

#[test]
fn capacitor_through_cubic_conductance_follows_the_closed_form() {
    let (cap, gain, q0) = (0.5, 0.2, 0.8);
    let g = graph(discharge(cap, q0, ("flow_law", format!("{gain}*e^3"))));
    let e = BondEquations::new(&g, &assign_causality(&g).unwrap()).unwrap();
    for q in [-1.0f64, 0.1, 0.8] {
        let want = -gain * (q / cap).powi(3);
        let got = rhs_at(&e, 0.0, &[q])[0];
        assert!((got - want).abs() < 1e-12, "q = {q}: {got} vs {want}");
    }
    let o = SolveOptions {
        rtol: 1e-10,
        atol: 1e-12,
        output_times: SolveOptions::times(5.0, 0.1),
        ..SolveOptions::default()
    };
    let sol = solve_bond_graph(&g, &o).unwrap();
    let q = sol.column("q_cap").unwrap();
    for (k, t) in sol.times.iter().enumerate() {
        let want = q0 / (1.0 + 2.0 * gain * q0 * q0 * t / cap.powi(3)).sqrt();
        assert!((q[k] - want).abs() < 1e-8, "t = {t}: {} vs {want}", q[k]);
    }
}

#[test]
fn law_missing_for_the_assigned_causality_names_the_needed_form() {
    // the capacitor imposes the effort on the resistor (conductance causality), but only
    // e = Φ(f) is given
    let g = graph(discharge(0.5, 0.8, ("effort_law", "f^3".into())));
    let err = BondEquations::new(&g, &assign_causality(&g).unwrap())
        .map(|_| ())
        .expect_err("no flow law for conductance causality");
    let msg = err.to_string();
    assert!(
        msg.contains("leak") && msg.contains("flow_law") && msg.contains("conductance"),
        "{msg}"
    );
}

#[test]
fn bad_laws_are_refused_with_their_json_paths() {
    // unknown variable in the law
    let err = raw(json!({"elements": [
        {"name": "F", "kind": "Se", "value": 1.0}, {"name": "v", "kind": "1"},
        {"name": "m", "kind": "I", "value": 1.0},
        {"name": "drag", "kind": "R", "effort_law": "c*f"}],
     "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"}, {"from": "v", "to": "drag"}]}))
    .to_graph()
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("elements[3].effort_law") && err.contains('c'),
        "{err}"
    );
    // the flow law may not name f (only e)
    let err = raw(json!({"elements": [
        {"name": "u", "kind": "0"}, {"name": "cap", "kind": "C", "compliance": 1.0},
        {"name": "leak", "kind": "R", "flow_law": "f*2"}],
     "bonds": [{"from": "u", "to": "cap"}, {"from": "u", "to": "leak"}]}))
    .to_graph()
    .unwrap_err()
    .to_string();
    assert!(err.contains("elements[2].flow_law"), "{err}");
    // a law on an inertia, and a law together with a value
    let err = raw(json!({"elements": [
        {"name": "F", "kind": "Se", "value": 1.0}, {"name": "v", "kind": "1"},
        {"name": "m", "kind": "I", "value": 1.0, "effort_law": "f"},
        {"name": "drag", "kind": "R", "value": 2.0, "effort_law": "f"}],
     "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"}, {"from": "v", "to": "drag"}]}))
    .to_graph()
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("elements[2].effort_law") && err.contains("R elements only"),
        "{err}"
    );
    assert!(
        err.contains("elements[3].effort_law") && err.contains("not both"),
        "{err}"
    );
}

#[test]
fn nonlinear_resistor_survives_a_json_round_trip() {
    let g = graph(drag(2.0, 9.0, 0.5, false));
    let back = g.to_raw().to_graph().unwrap();
    assert_eq!(back, g);
    let text = serde_json::to_string(&g.to_raw()).unwrap();
    assert!(text.contains("\"effort_law\":\"0.5*f*abs(f)\""), "{text}");
}
