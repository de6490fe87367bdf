//! Solver-statistics snapshots: every bundled scene under every formulation, at fixed
//! tolerances, through the CLI (`bondmech run --formulation F --rtol 1e-6 --atol 1e-8`).
//!
//! What is pinned, per scene × formulation: the formulation and solver that ran (or the
//! refusal's message), the internal steps, the residual or right-hand-side evaluations, the
//! Jacobian evaluations, the Newton convergence failures and the error-test failures. The
//! snapshot lives in `tests/snapshots/solver_stats.json` and is checked in: a change that
//! doubles the steps of a scene shows here, and a change that alters them on purpose
//! re-writes the file with
//!
//! ```sh
//! BONDMECH_UPDATE_SNAPSHOTS=1 cargo test --test solver_stats_snapshot
//! ```
//!
//! and says why in its commit. These are regression pins, not accuracy references: the
//! accuracy of each formulation is checked against independent models elsewhere
//! (tests/solve_accuracy.rs, tests/long_horizon_pendulum.rs, …).

mod common;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Command;

use serde_json::{json, Value};

const BIN: &str = env!("CARGO_BIN_EXE_bondmech");

/// Every formulation name the CLI accepts.
const FORMULATIONS: [&str; 6] = [
    "dae",
    "ggl",
    "compliant_ggl",
    "index1",
    "partitioned",
    "decoupled",
];

/// The horizon of every run (s), or the scene's own `t_end` when shorter.
const HORIZON: f64 = 0.5;

/// The summary fields pinned by the snapshot.
const PINNED: [&str; 7] = [
    "formulation",
    "solver",
    "steps",
    "residual_evals",
    "jacobian_evals",
    "nonlinear_conv_failures",
    "error_test_failures",
];

fn snapshot_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/solver_stats.json")
}

/// The scene's own `solve.t_end` (the scene format's default, 5 s, when absent).
fn scene_t_end(path: &std::path::Path) -> f64 {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v.pointer("/solve/t_end")
        .and_then(Value::as_f64)
        .unwrap_or(5.0)
}

/// One run's pinned statistics, or the first line of its refusal.
fn run(scene: &std::path::Path, formulation: &str, dir: &std::path::Path) -> Value {
    let t_end = HORIZON.min(scene_t_end(scene));
    let summary = dir.join(format!(
        "{}-{formulation}.json",
        scene.file_stem().unwrap().to_string_lossy()
    ));
    let out = Command::new(BIN)
        .arg("run")
        .arg(scene)
        .args(["--formulation", formulation])
        .args(["--rtol", "1e-6", "--atol", "1e-8"])
        .args(["--t-end", &t_end.to_string()])
        .arg("--summary")
        .arg(&summary)
        .arg("--out")
        .arg(dir.join("rows.csv"))
        .output()
        .expect("bondmech runs");
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let first = stderr.lines().next().unwrap_or("").to_string();
        return json!({ "error": first });
    }
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let mut pinned = serde_json::Map::new();
    for key in PINNED {
        pinned.insert(key.to_string(), s[key].clone());
    }
    Value::Object(pinned)
}

#[test]
fn solver_statistics_of_every_bundled_scene_and_formulation_match_the_snapshot() {
    let dir = std::env::temp_dir().join(format!("bondmech-stats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut now: BTreeMap<String, Value> = BTreeMap::new();
    for scene in common::bundled_scene_paths() {
        let name = scene.file_stem().unwrap().to_string_lossy().to_string();
        for f in FORMULATIONS {
            now.insert(format!("{name} / {f}"), run(&scene, f, &dir));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    let text = serde_json::to_string_pretty(&now).unwrap() + "\n";
    if std::env::var_os("BONDMECH_UPDATE_SNAPSHOTS").is_some() {
        std::fs::create_dir_all(snapshot_path().parent().unwrap()).unwrap();
        std::fs::write(snapshot_path(), text).unwrap();
        return;
    }
    let pinned: BTreeMap<String, Value> = serde_json::from_str(
        &std::fs::read_to_string(snapshot_path()).expect("tests/snapshots/solver_stats.json"),
    )
    .unwrap();
    let mut changed = Vec::new();
    for (key, value) in &now {
        match pinned.get(key) {
            Some(p) if p == value => {}
            Some(p) => changed.push(format!("{key}:\n  pinned {p}\n  now    {value}")),
            None => changed.push(format!("{key}: not in the snapshot (now {value})")),
        }
    }
    for key in pinned.keys().filter(|k| !now.contains_key(*k)) {
        changed.push(format!("{key}: in the snapshot, no longer run"));
    }
    assert!(
        changed.is_empty(),
        "solver statistics changed ({} of {}); if on purpose, re-run with \
         BONDMECH_UPDATE_SNAPSHOTS=1 and say why in the commit:\n{}",
        changed.len(),
        now.len(),
        changed.join("\n")
    );
}
