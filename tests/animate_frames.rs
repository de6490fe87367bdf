//! `animate --frames`: the frames exactly as drawn, checked against references that do not
//! come from the animation code:
//! - every body's point distances against the scene's own body geometry (rigid to 1e-9 of the
//!   body's size, in every frame);
//! - every point against `bondmech run`'s value at the frame's time (a second, independent
//!   run of the scene asked for exactly the frames' times and every body point), to 1e-6 m;
//! - no body turning more than 15° between two frames, measured on `run`'s attitude columns
//!   (`b.angle` in the plane, the quaternion `b.qw…b.qz` in space).

mod support;

use serde_json::Value;
use support::cli::{bondmech, read_csv, scene, tmp};

fn run_ok(args: &[&str]) -> String {
    let out = bondmech(args);
    assert!(
        out.status.success(),
        "bondmech {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A body's named points: `(point, coords)`.
type Points = Vec<(String, Vec<f64>)>;

/// `name → [(point, coords)]` of every body, from the scene file.
fn bodies(scene: &Value) -> Vec<(String, Points)> {
    scene["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            let points = b["points"]
                .as_object()
                .map(|m| {
                    m.iter()
                        .map(|(k, v)| {
                            let c = v.as_array().unwrap();
                            (k.clone(), c.iter().map(|x| x.as_f64().unwrap()).collect())
                        })
                        .collect()
                })
                .unwrap_or_default();
            (b["name"].as_str().unwrap().to_string(), points)
        })
        .collect()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn check_scene(file: &str) {
    let name = file.trim_end_matches(".json");
    let svg = tmp(&format!("frames-{name}.svg"));
    let frames_path = tmp(&format!("frames-{name}.json"));
    run_ok(&[
        "animate",
        &scene(file),
        "--out",
        svg.to_str().unwrap(),
        "--frames",
        frames_path.to_str().unwrap(),
    ]);
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&frames_path).unwrap()).unwrap();
    let frames = doc["frames"].as_array().unwrap();
    assert!(frames.len() > 10, "{name}: {} frames", frames.len());
    assert_eq!(
        doc["interpolated_frames"], 0,
        "{name}: animate solves densely enough that every frame is a row"
    );
    let scene_json: Value =
        serde_json::from_str(&std::fs::read_to_string(scene(file)).unwrap()).unwrap();
    let spatial = scene_json["dimension"] == 3;
    let dims = if spatial { 3 } else { 2 };
    let bodies = bodies(&scene_json);
    let times: Vec<f64> = frames.iter().map(|f| f["t"].as_f64().unwrap()).collect();
    assert!(
        times.windows(2).all(|w| w[1] > w[0]),
        "{name}: times increase"
    );

    // 1. rigid: every pair of a body's points keeps the scene's distance
    let mut worst_rigid = 0.0f64;
    for f in frames {
        let pts = f["points"].as_object().unwrap();
        for (b, points) in &bodies {
            let size = points
                .iter()
                .map(|(_, p)| p.iter().map(|c| c * c).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            let world = |p: &str| -> Vec<f64> {
                let v = pts
                    .get(&format!("{b}.{p}"))
                    .unwrap_or_else(|| panic!("{name}: no point {b}.{p} in a frame"));
                let v: Vec<f64> = v
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect();
                assert_eq!(v.len(), dims);
                v
            };
            for (i, (pi, ci)) in points.iter().enumerate() {
                for (pj, cj) in &points[i + 1..] {
                    let d = (dist(&world(pi), &world(pj)) - dist(ci, cj)).abs() / size;
                    worst_rigid = worst_rigid.max(d);
                }
            }
        }
    }
    assert!(
        worst_rigid <= 1e-9,
        "{name}: a body's point distance changed by {worst_rigid:e} of its size"
    );

    // 2. every point against an independent run at exactly the frames' times
    let mut s2 = scene_json.clone();
    let mut outputs: Vec<Value> = Vec::new();
    for (b, points) in &bodies {
        for (p, _) in points {
            outputs.push(Value::from(format!("{b}.{p}")));
        }
    }
    s2["outputs"] = Value::from(outputs);
    let solve = s2["solve"].as_object_mut().unwrap();
    solve.remove("output_step");
    solve.insert("output_times".into(), Value::from(times.clone()));
    let scene2 = tmp(&format!("frames-{name}-run.json"));
    std::fs::write(&scene2, serde_json::to_string(&s2).unwrap()).unwrap();
    let csv = tmp(&format!("frames-{name}-run.csv"));
    run_ok(&[
        "run",
        scene2.to_str().unwrap(),
        "--out",
        csv.to_str().unwrap(),
    ]);
    let (header, rows) = read_csv(&std::fs::read_to_string(&csv).unwrap());
    let col = |c: &str| {
        header
            .iter()
            .position(|h| h == c)
            .unwrap_or_else(|| panic!("{name}: no column {c} in run's CSV"))
    };
    let mut worst = 0.0f64;
    let mut row_of = Vec::new();
    for (f, &t) in frames.iter().zip(&times) {
        let row = rows
            .iter()
            .find(|r| (r[0] - t).abs() <= 1e-12 * t.abs().max(1.0))
            .unwrap_or_else(|| panic!("{name}: run has no row at t = {t}"));
        row_of.push(row);
        for (key, v) in f["points"].as_object().unwrap() {
            for (i, axis) in ["x", "y", "z"].iter().take(dims).enumerate() {
                let want = row[col(&format!("{key}.{axis}"))];
                let got = v[i].as_f64().unwrap();
                worst = worst.max((got - want).abs());
            }
        }
    }
    assert!(
        worst <= 1e-6,
        "{name}: a frame's point differs from run's by {worst:e} m"
    );

    // 3. no body turns more than 15° between frames (run's attitude columns)
    let mut worst_turn = 0.0f64;
    for (b, _) in &bodies {
        for w in row_of.windows(2) {
            let turn = if spatial {
                let q = |r: &Vec<f64>| -> [f64; 4] {
                    ["qw", "qx", "qy", "qz"].map(|c| r[col(&format!("{b}.{c}"))])
                };
                let (a, c) = (q(w[0]), q(w[1]));
                let dot: f64 = (0..4).map(|i| a[i] * c[i]).sum::<f64>().abs();
                let n = (a.iter().map(|v| v * v).sum::<f64>()
                    * c.iter().map(|v| v * v).sum::<f64>())
                .sqrt();
                2.0 * (dot / n).min(1.0).acos()
            } else {
                let a = col(&format!("{b}.angle"));
                (w[1][a] - w[0][a]).abs()
            };
            worst_turn = worst_turn.max(turn.to_degrees());
        }
    }
    assert!(
        worst_turn <= 15.0 + 1e-6,
        "{name}: a body turns {worst_turn}° between two frames"
    );
    eprintln!(
        "{name}: {} frames, rigid to {worst_rigid:.1e}, run to {worst:.1e} m, largest turn {worst_turn:.2}°",
        frames.len()
    );
}

#[test]
fn slider_crank_frames_are_rigid_true_to_run_and_dense() {
    check_scene("slider_crank.json");
}

#[test]
fn andrews_squeezer_frames_are_rigid_true_to_run_and_dense() {
    check_scene("andrews_squeezer.json");
}

#[test]
fn bricard_frames_are_rigid_true_to_run_and_dense() {
    check_scene("bricard.json");
}

#[test]
fn frames_refuse_a_file_that_is_not_json() {
    let out = bondmech(&[
        "animate",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.1",
        "--out",
        tmp("frames-bad.svg").to_str().unwrap(),
        "--frames",
        tmp("frames-bad.txt").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--frames") && err.contains(".json"), "{err}");
}
