//! Solver-statistics snapshots: every bundled scene under every formulation, at fixed
//! tolerances, through the CLI (`bondmech run --formulation F --rtol 1e-6 --atol 1e-8`).
//!
//! What is pinned, per scene × formulation: the formulation and solver that ran (or the
//! refusal's message), the internal steps, the residual or right-hand-side evaluations, the
//! Jacobian evaluations, the Newton convergence failures and the error-test failures. The
//! snapshot lives in `tests/snapshots/solver_stats/<scene>.json`, one file per bundled scene
//! (a new scene adds its own file and edits none), and is checked in: a change that doubles
//! the steps of a scene shows here, and a change that alters them on purpose re-writes the
//! files with
//!
//! ```sh
//! BONDMECH_UPDATE_SNAPSHOTS=1 cargo test --test solver_stats_snapshot
//! ```
//!
//! and says why in its commit.
//!
//! Besides the bundled scenes, the hard cases of issue 34 that are too large or slow for the
//! every-scene tests of `scenes/` live in `tests/snapshots/scenes/` (one file per scene, each
//! run with its own end time and tolerances: the N-link pendulum at N = 128 for 1 s; the bead
//! in a slot through its pivot for 3 s at rtol 1e-10, past the passage at 0.78 s; the A01
//! point-mass pendulum for 100 s at rtol 1e-9): they are pinned on the IDA formulations
//! ([`HARD_CASE_FORMULATIONS`]; the partitioned and decoupled runs of the 128-link chain take
//! 15 s and 4 s, and the issue's question there is the default's) into the same snapshot folder.
//!
//! These are regression pins, not accuracy references: the
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

/// The formulations the hard cases of `tests/snapshots/scenes/` are pinned on.
const HARD_CASE_FORMULATIONS: [&str; 4] = ["dae", "ggl", "compliant_ggl", "index1"];

/// The hard cases pinned besides the bundled scenes: `tests/snapshots/scenes/*.json`.
fn hard_case_paths() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/scenes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.expect("a directory entry").path())
                .filter(|p| p.extension().is_some_and(|e| e == "json"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

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

/// The snapshot folder: one `<scene>.json` per bundled scene, its formulations as keys.
fn snapshot_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/solver_stats")
}

/// Every pinned `"<scene> / <formulation>"` entry of the snapshot folder.
fn pinned_entries() -> BTreeMap<String, Value> {
    let mut pinned = BTreeMap::new();
    let files = std::fs::read_dir(snapshot_dir()).expect("tests/snapshots/solver_stats/");
    for file in files {
        let path = file.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("json") {
            continue;
        }
        let scene = path.file_stem().unwrap().to_string_lossy().to_string();
        let by_formulation: BTreeMap<String, Value> =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        for (f, value) in by_formulation {
            pinned.insert(format!("{scene} / {f}"), value);
        }
    }
    pinned
}

/// Re-writes the snapshot folder from this run, one file per scene.
fn write_snapshot(now: &BTreeMap<String, BTreeMap<String, Value>>) {
    let dir = snapshot_dir();
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    for (scene, by_formulation) in now {
        let text = serde_json::to_string_pretty(by_formulation).unwrap() + "\n";
        std::fs::write(dir.join(format!("{scene}.json")), text).unwrap();
    }
}

/// The scene's own `solve.t_end` (the scene format's default, 5 s, when absent).
fn scene_t_end(path: &std::path::Path) -> f64 {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v.pointer("/solve/t_end")
        .and_then(Value::as_f64)
        .unwrap_or(5.0)
}

/// One run's pinned statistics, or the first line of its refusal: a bundled scene over
/// [`HORIZON`] at rtol 1e-6, atol 1e-8; a hard case (`own`) with its file's own end time and
/// tolerances (the passage through the pivot, the long horizon are what is pinned there).
fn run(scene: &std::path::Path, formulation: &str, dir: &std::path::Path, own: bool) -> Value {
    let t_end = HORIZON.min(scene_t_end(scene));
    let summary = dir.join(format!(
        "{}-{formulation}.json",
        scene.file_stem().unwrap().to_string_lossy()
    ));
    let mut cmd = Command::new(BIN);
    cmd.arg("run")
        .arg(scene)
        .args(["--formulation", formulation]);
    if !own {
        cmd.args(["--rtol", "1e-6", "--atol", "1e-8"])
            .args(["--t-end", &t_end.to_string()]);
    }
    let out = cmd
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
    let mut by_scene: BTreeMap<String, BTreeMap<String, Value>> = BTreeMap::new();
    let bundled = common::bundled_scene_paths()
        .into_iter()
        .map(|p| (p, &FORMULATIONS[..], false));
    let hard = hard_case_paths()
        .into_iter()
        .map(|p| (p, &HARD_CASE_FORMULATIONS[..], true));
    for (scene, formulations, own) in bundled.chain(hard) {
        let name = scene.file_stem().unwrap().to_string_lossy().to_string();
        for &f in formulations {
            let value = run(&scene, f, &dir, own);
            by_scene
                .entry(name.clone())
                .or_default()
                .insert(f.to_string(), value);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    if std::env::var_os("BONDMECH_UPDATE_SNAPSHOTS").is_some() {
        write_snapshot(&by_scene);
        return;
    }
    let now: BTreeMap<String, Value> = by_scene
        .iter()
        .flat_map(|(scene, fs)| {
            fs.iter()
                .map(move |(f, v)| (format!("{scene} / {f}"), v.clone()))
        })
        .collect();
    let pinned = pinned_entries();
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
