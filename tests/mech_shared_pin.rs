//! Joints where four bodies meet at one pin.
//!
//! * Ground and three bars on one fixed pin: with frictionless pins the only torque about the
//!   pin on each bar is its weight, so each bar is an independent compound pendulum,
//!   `(J + m d²) θ'' = −m g d cos θ` (d = distance pin–centre), integrated by `tests/common`.
//! * Four bars on one moving pin, free in the plane without gravity: the total momentum, the
//!   angular momentum about the origin `Σ m (r × v) + J ω` and the energy are conserved.

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::integrate::integrate;

const G: f64 = 9.81;

/// (name, mass, length, initial angle, initial rate); the bar's end O = (−L/2, 0) is on the pin.
const BARS: [(&str, f64, f64, f64, f64); 3] = [
    ("a", 1.0, 1.0, 0.0, 0.0),
    ("b", 0.5, 0.6, -2.5, 1.0),
    ("c", 2.0, 1.4, -0.4, -2.0),
];

#[test]
fn ground_and_three_bars_on_one_pin_swing_as_independent_compound_pendulums() {
    let bodies: Vec<String> = BARS
        .iter()
        .map(|&(n, m, l, th, w)| {
            let (s, c) = th.sin_cos();
            let d = 0.5 * l;
            format!(
                r#"{{"name":"{n}","mass":{m},"inertia":{},"points":{{"O":[{},0]}},"position":[{},{}],
                   "angle":{th},"velocity":[{},{}],"angular_velocity":{w}}}"#,
                m * l * l / 12.0,
                -d,
                d * c,
                d * s,
                -d * w * s,
                d * w * c
            )
        })
        .collect();
    // ground–a, a–b, b–c: four bodies (ground, a, b, c) on one pin at the origin
    let json = format!(
        r#"{{"name":"shared_pin","dimension":2,"gravity":[0,-{G}],"bodies":[{}],
        "joints":[
          {{"name":"ga","type":"revolute","bodies":["ground","a"],"points":[[0,0],"O"]}},
          {{"name":"ab","type":"revolute","bodies":["a","b"],"points":["O","O"]}},
          {{"name":"bc","type":"revolute","bodies":["b","c"],"points":["O","O"]}}],
        "solve":{{"t_end":3.0,"output_step":0.1}},"outputs":["energy","c.O"]}}"#,
        bodies.join(",")
    );
    let scene = Scene::from_json_str(&json).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let sol = model.solve(&o).unwrap();
    assert!(sol.summary.max_constraint_error < 1e-9, "{:?}", sol.summary);
    for &(n, m, l, th0, w0) in &BARS {
        let d = 0.5 * l;
        let i_pin = m * l * l / 12.0 + m * d * d;
        let reference = integrate(
            |_t, y, dy| {
                dy[0] = y[1];
                dy[1] = -m * G * d * y[0].cos() / i_pin;
            },
            0.0,
            &[th0, w0],
            &sol.times,
            1e-13,
            1e-13,
        );
        for (k, y) in reference.iter().enumerate() {
            let got = sol.value(k, &format!("{n}.angle")).unwrap();
            assert!(
                (got - y[0]).abs() < 1e-6,
                "{n}, t = {}: angle {got} vs reference {}",
                sol.times[k],
                y[0]
            );
        }
    }
    let k = sol.times.len() - 1;
    let pin = [
        sol.value(k, "c.O.x").unwrap(),
        sol.value(k, "c.O.y").unwrap(),
    ];
    assert!(pin[0].abs() < 1e-9 && pin[1].abs() < 1e-9, "{pin:?}");
}

#[test]
fn four_bars_on_one_moving_pin_conserve_momentum_angular_momentum_and_energy() {
    // a free star: bar1's O is the pin; bars 2–4 are pinned to it there; no gravity
    let spec = [
        ("s1", 1.0, 1.0, 0.3, 1.0),
        ("s2", 0.7, 0.8, 1.9, -2.0),
        ("s3", 1.3, 1.2, 3.5, 0.5),
        ("s4", 0.4, 0.5, 5.0, 3.0),
    ];
    let pin = [0.2, -0.1];
    let pin_v = [0.3, -0.4];
    let bodies: Vec<String> = spec
        .iter()
        .map(|&(n, m, l, th, w): &(&str, f64, f64, f64, f64)| {
            let (s, c) = th.sin_cos();
            let d = 0.5 * l;
            format!(
                r#"{{"name":"{n}","mass":{m},"inertia":{},"points":{{"O":[{},0]}},"position":[{},{}],
                   "angle":{th},"velocity":[{},{}],"angular_velocity":{w}}}"#,
                m * l * l / 12.0,
                -d,
                pin[0] + d * c,
                pin[1] + d * s,
                pin_v[0] - d * w * s,
                pin_v[1] + d * w * c
            )
        })
        .collect();
    let json = format!(
        r#"{{"name":"star","dimension":2,"gravity":[0,0],"bodies":[{}],
        "joints":[
          {{"name":"p12","type":"revolute","bodies":["s1","s2"],"points":["O","O"]}},
          {{"name":"p13","type":"revolute","bodies":["s1","s3"],"points":["O","O"]}},
          {{"name":"p14","type":"revolute","bodies":["s1","s4"],"points":["O","O"]}}],
        "solve":{{"t_end":3.0,"output_step":0.05}},
        "outputs":["energy","s1.O","s2.O","s3.O","s4.O"]}}"#,
        bodies.join(",")
    );
    let scene = Scene::from_json_str(&json).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let sol = model.solve(&o).unwrap();
    assert!(sol.summary.max_constraint_error < 1e-9, "{:?}", sol.summary);
    let totals = |k: usize| {
        let (mut px, mut py, mut lz) = (0.0, 0.0, 0.0);
        for &(n, m, l, _, _) in &spec {
            let v = |c: &str| sol.value(k, &format!("{n}.{c}")).unwrap();
            px += m * v("vx");
            py += m * v("vy");
            lz += m * (v("x") * v("vy") - v("y") * v("vx")) + m * l * l / 12.0 * v("omega");
        }
        (px, py, lz)
    };
    let (px0, py0, lz0) = totals(0);
    let e = sol.column("energy").unwrap();
    let mut spread = 0.0f64;
    for k in 0..sol.times.len() {
        let (px, py, lz) = totals(k);
        assert!(
            (px - px0).abs() < 1e-8 && (py - py0).abs() < 1e-8,
            "momentum at {k}"
        );
        assert!(
            (lz - lz0).abs() < 1e-8 * lz0.abs().max(1.0),
            "L at {k}: {lz} vs {lz0}"
        );
        assert!(
            (e[k] - e[0]).abs() < 1e-8 * e[0],
            "energy at {k}: {} vs {}",
            e[k],
            e[0]
        );
        let o1 = [
            sol.value(k, "s1.O.x").unwrap(),
            sol.value(k, "s1.O.y").unwrap(),
        ];
        for n in ["s2", "s3", "s4"] {
            let on = [
                sol.value(k, &format!("{n}.O.x")).unwrap(),
                sol.value(k, &format!("{n}.O.y")).unwrap(),
            ];
            assert!(
                (on[0] - o1[0]).hypot(on[1] - o1[1]) < 1e-9,
                "{n} left the pin at {k}"
            );
        }
        spread = spread.max((sol.value(k, "s4.angle").unwrap() - 5.0).abs());
    }
    assert!(spread > 0.5, "the bars must move relative to each other");
}
