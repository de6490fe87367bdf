//! The default keeps what the tolerance promises (issue 46): on a five-bar whose couplers' block
//! degrades before its re-selection, the default's largest coordinate error against an
//! independent reference is at most 3× the GGL's at rtol 1e-7, 1e-8 and 1e-9 (atol rtol / 100),
//! and shrinks at least 10× from 1e-7 to 1e-9.
//!
//! The reference is Newton–Euler with multipliers in absolute coordinates
//! (`tests/common/pinned_planar.rs`), integrated at 1e-13; its loop closure is checked here.
//! The whole table (nine mechanisms, CPU too) is `tests/references/matched_tolerance.py`, its
//! output in docs/performance.md.
//!
//! Regression: the dependent velocities were out of IDA's error test, and the couplers' block
//! (grip up to 10–100 before a re-selection) passed the independent velocities' error on
//! amplified: 12×, 8.6× and 4.1× the GGL's error.

mod common;

use std::sync::OnceLock;

use bondmech::{FormulationKind, Model, Scene};
use common::pinned_planar::{Pin, PinnedPlanar};

/// Ground pivots `d` apart, cranks `c`, couplers `k`; uniform bars of 1 kg/m.
const D: f64 = 0.4;
const CRANK: f64 = 0.3;
const COUPLER: f64 = 0.7;
const T_END: f64 = 1.0;

fn lengths() -> [f64; 4] {
    [CRANK, COUPLER, COUPLER, CRANK]
}

/// The initial angles: crank 1 at 120°, crank 4 at 60°, the couplers' joint above.
fn initial_angles() -> [f64; 4] {
    let (q1, q4) = (120f64.to_radians(), 60f64.to_radians());
    let b = [CRANK * q1.cos(), CRANK * q1.sin()];
    let e = [D + CRANK * q4.cos(), CRANK * q4.sin()];
    let s = ((e[0] - b[0]).powi(2) + (e[1] - b[1]).powi(2)).sqrt();
    let u = [(e[0] - b[0]) / s, (e[1] - b[1]) / s];
    let a = s / 2.0;
    let h = (COUPLER * COUPLER - a * a).sqrt();
    let c = [b[0] + a * u[0] - h * u[1], b[1] + a * u[1] + h * u[0]];
    [
        q1,
        (c[1] - b[1]).atan2(c[0] - b[0]),
        (c[1] - e[1]).atan2(c[0] - e[0]),
        q4,
    ]
}

/// Centres `[(x, y); 4]` of the bars at the angles `q` (each bar's first point at its pivot
/// or at the previous joint: crank 1 from the origin, coupler 2 from crank 1's tip, coupler 3
/// and crank 4 from crank 4's ground pivot).
fn centres(q: &[f64; 4]) -> [[f64; 2]; 4] {
    let l = lengths();
    let u = |a: f64| [a.cos(), a.sin()];
    let b = [l[0] * q[0].cos(), l[0] * q[0].sin()];
    let e = [D + l[3] * q[3].cos(), l[3] * q[3].sin()];
    [
        [l[0] / 2.0 * u(q[0])[0], l[0] / 2.0 * u(q[0])[1]],
        [
            b[0] + l[1] / 2.0 * u(q[1])[0],
            b[1] + l[1] / 2.0 * u(q[1])[1],
        ],
        [
            e[0] + l[2] / 2.0 * u(q[2])[0],
            e[1] + l[2] / 2.0 * u(q[2])[1],
        ],
        [D + l[3] / 2.0 * u(q[3])[0], l[3] / 2.0 * u(q[3])[1]],
    ]
}

fn names() -> [&'static str; 4] {
    ["c1", "k2", "k3", "c4"]
}

fn scene_json() -> String {
    let q = initial_angles();
    let c = centres(&q);
    let bodies: Vec<serde_json::Value> = (0..4)
        .map(|i| {
            let l = lengths()[i];
            serde_json::json!({
                "name": names()[i], "mass": l, "inertia": l * l * l / 12.0,
                "points": {"O": [-l / 2.0, 0.0], "A": [l / 2.0, 0.0]},
                "position": c[i], "angle": q[i]
            })
        })
        .collect();
    serde_json::json!({
        "name": "five_bar", "dimension": 2, "gravity": [0.0, -9.81], "bodies": bodies,
        "joints": [
            {"name": "A", "type": "revolute", "bodies": ["ground", "c1"], "points": [[0.0, 0.0], "O"]},
            {"name": "B", "type": "revolute", "bodies": ["c1", "k2"], "points": ["A", "O"]},
            {"name": "C", "type": "revolute", "bodies": ["k2", "k3"], "points": ["A", "A"]},
            {"name": "D", "type": "revolute", "bodies": ["k3", "c4"], "points": ["O", "A"]},
            {"name": "E", "type": "revolute", "bodies": ["ground", "c4"], "points": [[D, 0.0], "O"]}
        ],
        "solve": {"t_end": T_END, "output_step": 0.01}
    })
    .to_string()
}

fn output_times() -> Vec<f64> {
    (0..=100).map(|k| k as f64 * T_END / 100.0).collect()
}

/// The reference's centres at the output times.
fn reference() -> &'static [Vec<f64>] {
    static REF: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    REF.get_or_init(|| {
        let l = lengths();
        let q = initial_angles();
        let c = centres(&q);
        let half = |i: usize| l[i] / 2.0;
        let model = PinnedPlanar {
            bodies: (0..4).map(|i| (l[i], l[i].powi(3) / 12.0)).collect(),
            pins: vec![
                Pin {
                    a: (None, [0.0, 0.0]),
                    b: (0, [-half(0), 0.0]),
                },
                Pin {
                    a: (Some(0), [half(0), 0.0]),
                    b: (1, [-half(1), 0.0]),
                },
                Pin {
                    a: (Some(1), [half(1), 0.0]),
                    b: (2, [half(2), 0.0]),
                },
                Pin {
                    a: (Some(2), [-half(2), 0.0]),
                    b: (3, [half(3), 0.0]),
                },
                Pin {
                    a: (None, [D, 0.0]),
                    b: (3, [-half(3), 0.0]),
                },
            ],
            g: 9.81,
        };
        let z0: Vec<f64> = (0..4).flat_map(|i| [c[i][0], c[i][1], q[i]]).collect();
        let z = model.simulate(&z0, &[0.0; 12], &output_times());
        // the loop stays closed: the couplers' common point from both sides
        let mut gap = 0.0f64;
        for zk in &z {
            let tip = |i: usize, s: f64| {
                [
                    zk[3 * i] + s * zk[3 * i + 2].cos(),
                    zk[3 * i + 1] + s * zk[3 * i + 2].sin(),
                ]
            };
            let (p, r) = (tip(1, half(1)), tip(2, half(2)));
            gap = gap.max((p[0] - r[0]).hypot(p[1] - r[1]));
        }
        assert!(gap < 1e-10, "the reference's loop opens by {gap:e} m");
        z
    })
}

/// The largest error of the bars' centres against the reference, at rtol `rtol`.
fn error(formulation: FormulationKind, rtol: f64) -> f64 {
    let m = Model::new(&Scene::from_json_str(&scene_json()).expect("valid scene")).expect("builds");
    let mut o = m.default_options();
    o.formulation = formulation;
    o.rtol = rtol;
    o.atol = rtol / 100.0;
    o.output_times = output_times();
    let s = m.solve(&o).expect("solves");
    let mut worst = 0.0f64;
    for (k, z) in reference().iter().enumerate() {
        for (i, name) in names().iter().enumerate() {
            for (d, axis) in ["x", "y"].iter().enumerate() {
                let v = s.value(k, &format!("{name}.{axis}")).expect("column");
                worst = worst.max((v - z[3 * i + d]).abs());
            }
        }
    }
    worst
}

#[test]
fn regression_the_five_bars_error_was_twelve_times_the_ggls_with_the_dependent_velocities_out_of_the_error_test(
) {
    let mut errors = Vec::new();
    for rtol in [1e-7, 1e-8, 1e-9] {
        let (default, ggl) = (
            error(FormulationKind::Dae, rtol),
            error(FormulationKind::Ggl, rtol),
        );
        eprintln!(
            "rtol {rtol:e}: default {default:.2e}, ggl {ggl:.2e}, ratio {:.2}",
            default / ggl
        );
        // measured 1.67, 0.52, 0.61 (12.2, 8.6, 4.1 before)
        assert!(
            default <= 3.0 * ggl,
            "rtol {rtol:e}: {default:e} against the GGL's {ggl:e}"
        );
        errors.push(default);
    }
    // measured 53×
    assert!(
        errors[0] >= 10.0 * errors[2],
        "the default's error from rtol 1e-7 to 1e-9: {errors:?}"
    );
}
