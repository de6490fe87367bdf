//! Raw bond graphs under every formulation, through the CLI (issue 24's "one pipeline from
//! any bond graph"):
//!
//! * the seed-form double pendulum (Fig. 19: bars in the translating frame, pins as 1-junctions
//!   equating two point velocities and `Sf = 0`, no closures), in both element orders, runs
//!   under `index1` (the graph's own DAE) and `decoupled` (every joint row opened, a C on its
//!   integrated flow, seed 16.6) and matches the minimal-coordinate Lagrange model
//!   (tests/common/double_pendulum.rs); `ggl`, `compliant_ggl` and `partitioned` refuse it,
//!   naming the formulation and the missing closures;
//! * the double pendulum's `graph --as-scene` export (a raw graph with closures) runs under
//!   every formulation and matches the same model.
//!
//! `summary.formulation` names what ran, always.

mod common;
mod support;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};
use serde_json::{json, Value};
use support::cli::read_csv;

const BIN: &str = env!("CARGO_BIN_EXE_bondmech");
const G: f64 = 9.81;
/// Output times of the comparison (s), those of the double pendulum.
const TIMES: [f64; 4] = [0.5, 1.0, 2.0, 3.0];

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bondmech-raw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// One uniform bar `b` (mass 1, length 1) of the seed's Fig. 24 in the translating frame:
/// 1-junctions `vx vy w` with their inertias, gravity as an Se on `vy`, and per point P at
/// `r_P = along·(L/2)(cos θ, sin θ)` a 0-junction per axis adding `V` and the MTF term of
/// `ω × r_P` (moduli `−r_y`, `r_x`, over the bar angle `x_<b>w`).
fn bar(e: &mut Vec<Value>, b: &mut Vec<Value>, name: &str, points: &[(&str, f64)]) {
    let (m, j) = (1.0, 1.0 / 12.0);
    for (jn, i, v) in [("vx", "mx", m), ("vy", "my", m), ("w", "J", j)] {
        e.push(json!({"name": format!("{name}{jn}"), "kind": "1"}));
        e.push(json!({"name": format!("{name}{i}"), "kind": "I", "value": v}));
        b.push(json!({"from": format!("{name}{jn}"), "to": format!("{name}{i}")}));
    }
    e.push(json!({"name": format!("{name}g"), "kind": "Se", "value": -G * m}));
    b.push(json!({"from": format!("{name}g"), "to": format!("{name}vy")}));
    for (p, along) in points {
        let k = along * 0.5;
        for (axis, modulus) in [
            ("x", format!("-{k}*sin(x_{name}w)")),
            ("y", format!("{k}*cos(x_{name}w)")),
        ] {
            let s = format!("{name}s{p}{axis}");
            let mtf = format!("{name}m{p}{axis}");
            e.push(json!({"name": s, "kind": "0"}));
            e.push(json!({"name": mtf, "kind": "MTF", "modulus": modulus}));
            b.push(json!({"from": format!("{name}v{axis}"), "to": s}));
            b.push(json!({"from": format!("{name}w"), "to": mtf}));
            b.push(json!({"from": mtf, "to": s}));
        }
    }
}

/// The seed-form double pendulum released horizontal at rest (both bar angles 0): bar 1's
/// O pinned to the ground by `Sf = 0` per axis, its A hinged to bar 2's O by a 1-junction per
/// axis into which both point bonds flow (Fig. 16). `reversed` lists elements and bonds in
/// the opposite order.
fn seed_double_pendulum(reversed: bool) -> Value {
    let (mut e, mut b) = (vec![], vec![]);
    bar(&mut e, &mut b, "1", &[("A", 1.0), ("O", -1.0)]);
    bar(&mut e, &mut b, "2", &[("O", -1.0)]);
    for axis in ["x", "y"] {
        e.push(json!({"name": format!("A{axis}"), "kind": "1"}));
        b.push(json!({"from": format!("1sA{axis}"), "to": format!("A{axis}")}));
        b.push(json!({"from": format!("2sO{axis}"), "to": format!("A{axis}")}));
        e.push(json!({"name": format!("O{axis}"), "kind": "Sf", "value": 0.0}));
        b.push(json!({"from": format!("1sO{axis}"), "to": format!("O{axis}")}));
    }
    if reversed {
        e.reverse();
        b.reverse();
    }
    json!({
        "bond_graph": {"elements": e, "bonds": b},
        "solve": {"t_end": 3.0, "output_times": TIMES, "rtol": 1e-10, "atol": 1e-12}
    })
}

/// A run's summary, CSV columns and rows.
type Run = (Value, Vec<String>, Vec<Vec<f64>>);

/// `bondmech run` with `--formulation f`: the summary and the CSV's columns and rows, or the
/// error's text.
fn run(scene: &Path, f: &str, extra: &[&str]) -> Result<Run, String> {
    let tag = format!("{}-{f}", scene.file_stem().unwrap().to_string_lossy());
    let (summary, csv) = (tmp(&format!("{tag}.json")), tmp(&format!("{tag}.csv")));
    let out = Command::new(BIN)
        .arg("run")
        .arg(scene)
        .args(["--formulation", f])
        .args(extra)
        .arg("--summary")
        .arg(&summary)
        .arg("--out")
        .arg(&csv)
        .output()
        .unwrap();
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).to_string());
    }
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let (columns, rows) = read_csv(&std::fs::read_to_string(&csv).unwrap());
    Ok((s, columns, rows))
}

/// The largest difference of the columns `angles` (the bars' absolute angles) from the
/// Lagrange model at [`TIMES`].
fn angle_error(columns: &[String], rows: &[Vec<f64>], angles: [&str; 2]) -> f64 {
    let reference = simulate_double_pendulum(
        &DoublePendulum {
            m1: 1.0,
            l1: 1.0,
            m2: 1.0,
            l2: 1.0,
            g: G,
        },
        [0.0; 4],
        &TIMES,
    );
    let col = |n: &str| {
        columns
            .iter()
            .position(|c| c == n)
            .unwrap_or_else(|| panic!("no column {n} in {columns:?}"))
    };
    let (c1, c2) = (col(angles[0]), col(angles[1]));
    let mut worst: f64 = 0.0;
    for r in &reference {
        let row = rows
            .iter()
            .find(|row| (row[0] - r.t).abs() < 1e-12)
            .unwrap_or_else(|| panic!("no row at t = {}", r.t));
        worst = worst
            .max((row[c1] - r.theta1).abs())
            .max((row[c2] - r.theta2).abs());
    }
    worst
}

/// The twin's angles differ from the pinned mechanism's by its springs' stretch, λ/k with
/// joint forces λ ≲ 40 N (the bars' weights and their centripetal loads) at k = 1e8 N/m:
/// 4e-7 m on unit bars, grown by the chaotic motion over 3 s (the pinned runs' own 1e-10
/// tolerance grows about 1000× here, to ~1e-7): 4e-4 rad, bounded by 1e-3. It still fails a
/// twin that leaves the pinned motion: a spring of 1e4 N/m misses it by 0.2 rad
/// ([`a_softer_twin_drifts_from_the_pinned_motion`]). Measured: 6.6e-5 rad at 3 s.
const TWIN_BOUND: f64 = 1e-3;
/// The pinned runs at rtol 1e-10 against the Lagrange model at 1e-13 (a chaotic motion: the
/// local tolerance grows about 1000× over 3 s).
const PINNED_BOUND: f64 = 1e-6;

#[test]
fn seed_form_double_pendulum_runs_under_index1_and_decoupled_and_matches_lagrange() {
    for reversed in [false, true] {
        let path = tmp(&format!("seed_dp_{reversed}.json"));
        std::fs::write(&path, seed_double_pendulum(reversed).to_string()).unwrap();
        for (f, ran, bound) in [
            ("index1", "bond_index1", PINNED_BOUND),
            ("dae", "bond_velocity_index2", PINNED_BOUND),
            ("decoupled", "decoupled", TWIN_BOUND),
        ] {
            let (s, columns, rows) =
                run(&path, f, &[]).unwrap_or_else(|e| panic!("{f} (reversed {reversed}): {e}"));
            assert_eq!(s["formulation"], ran, "{f} (reversed {reversed})");
            let err = angle_error(&columns, &rows, ["x_1w", "x_2w"]);
            assert!(
                err < bound,
                "{f} (reversed {reversed}): angle error {err:e}"
            );
            if f == "decoupled" {
                // every joint row opened: the twin has no dependent inertias and one spring
                // per row
                assert!(s["dependent"].as_array().unwrap().is_empty(), "{s}");
                for spring in ["Ax.k", "Ay.k", "Ox.k", "Oy.k"] {
                    assert!(
                        s["states"].as_array().unwrap().iter().any(|x| x == spring),
                        "{spring} in {}",
                        s["states"]
                    );
                }
            }
        }
        for f in ["ggl", "compliant_ggl", "partitioned"] {
            let e = run(&path, f, &[]).expect_err(f);
            assert!(
                e.contains(&format!("formulation '{f}'")) && e.contains("closures"),
                "{f}: {e}"
            );
            for junction in ["'Ax'", "'Ay'", "'Ox'", "'Oy'"] {
                assert!(e.contains(junction), "{f}: {e}");
            }
        }
    }
}

#[test]
fn a_softer_twin_drifts_from_the_pinned_motion() {
    // the bound of the twin's check is not loose enough to pass anything: at k = 1e4 N/m the
    // springs stretch by ~4 mm and the angles leave the pinned motion
    let path = tmp("seed_dp_soft.json");
    std::fs::write(&path, seed_double_pendulum(false).to_string()).unwrap();
    let (_, columns, rows) = run(&path, "decoupled", &["--joint-stiffness", "1e4"]).unwrap();
    let err = angle_error(&columns, &rows, ["x_1w", "x_2w"]);
    assert!(err > TWIN_BOUND, "angle error {err:e}");
}

#[test]
fn exported_double_pendulum_graph_runs_under_every_formulation_and_matches_lagrange() {
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/double_pendulum.json");
    let out = Command::new(BIN)
        .arg("graph")
        .arg(&scene)
        .arg("--as-scene")
        .output()
        .unwrap();
    assert!(out.status.success());
    let mut raw: Value = serde_json::from_slice(&out.stdout).unwrap();
    raw["solve"] = json!({"t_end": 3.0, "output_times": TIMES, "rtol": 1e-10, "atol": 1e-12});
    let path = tmp("dp_exported.json");
    std::fs::write(&path, raw.to_string()).unwrap();
    for f in [
        "dae",
        "ggl",
        "compliant_ggl",
        "index1",
        "partitioned",
        "decoupled",
    ] {
        let (s, columns, rows) = run(&path, f, &[]).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert_eq!(s["formulation"], f, "what ran is named");
        let bound = if f == "decoupled" {
            TWIN_BOUND
        } else {
            PINNED_BOUND
        };
        let err = angle_error(&columns, &rows, ["bar1.angle", "bar2.angle"]);
        assert!(err < bound, "{f}: angle error {err:e}");
    }
}
