//! The partition every partitioning formulation starts from is the causality's (seed 16.5):
//! for every bundled scene, `summary.dependent` at the start is the `differential[].element`
//! set of `bondmech graph --causality`, and `summary.states` its `states`, under the default
//! (`dae`), `index1` and `partitioned` — through the CLI, as a user reads both.
//!
//! The reference is the causality assignment as `graph` reports it (the SCAP on the drawn
//! graph); the solvers' own choice is independent of it until they are handed it, which is
//! what this checks.

mod common;

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_bondmech");

fn names(v: &Value) -> BTreeSet<String> {
    v.as_array()
        .map(|a| {
            a.iter()
                .map(|x| x.as_str().unwrap_or_default().to_string())
                .collect()
        })
        .unwrap_or_default()
}

fn causality(scene: &Path) -> (BTreeSet<String>, BTreeSet<String>) {
    let out = Command::new(BIN)
        .arg("graph")
        .arg(scene)
        .arg("--causality")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{scene:?}: graph --causality failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let differential = r["differential"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["element"].as_str().unwrap().to_string())
        .collect();
    (names(&r["states"]), differential)
}

/// The run's summary, or `None` when the formulation refuses the scene.
fn summary(scene: &Path, formulation: Option<&str>, dir: &Path) -> Option<Value> {
    let path = dir.join("summary.json");
    let mut cmd = Command::new(BIN);
    cmd.arg("run").arg(scene).args(["--t-end", "0.01"]);
    if let Some(f) = formulation {
        cmd.args(["--formulation", f]);
    }
    let out = cmd
        .arg("--summary")
        .arg(&path)
        .arg("--out")
        .arg(dir.join("rows.csv"))
        .output()
        .unwrap();
    if !out.status.success() {
        return None;
    }
    Some(serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap())
}

#[test]
fn summary_partition_at_the_start_is_the_causality_of_graph() {
    let dir = std::env::temp_dir().join(format!("bondmech-partition-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut checked = 0;
    for scene in common::bundled_scene_paths() {
        let name = scene.file_name().unwrap().to_string_lossy().to_string();
        let (states, differential) = causality(&scene);
        for f in [None, Some("index1"), Some("partitioned")] {
            let Some(s) = summary(&scene, f, &dir) else {
                // index 1 refuses spatial bodies (q' ≠ v) and redundant joints, by name
                // (partitioned runs a scene whose drivers take every DOF as a kinematic
                // analysis: it may no longer refuse it)
                assert!(f == Some("index1"), "{name}: {f:?} failed");
                continue;
            };
            let ran = s["formulation"].as_str().unwrap().to_string();
            if ran == "ggl" || ran == "compliant_ggl" {
                // no partition exists (redundant joints) or the formulation needs q' = v: the
                // summary says why, and names no partition
                assert!(
                    !s["warnings"].as_array().unwrap().is_empty(),
                    "{name}: {f:?} ran ggl without saying why"
                );
                continue;
            }
            assert_eq!(
                names(&s["dependent"]),
                differential,
                "{name} under {ran}: summary.dependent"
            );
            assert_eq!(
                names(&s["states"]),
                states,
                "{name} under {ran}: summary.states"
            );
            checked += 1;
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    // every planar mechanism under three formulations, the spatial ones under `partitioned`,
    // the raw graphs under their own
    assert!(checked >= 35, "only {checked} runs compared");
}

/// Regression: a massless body that nothing turns (the bead of `bead_in_slot`, the peers'
/// massless piston) kept a bondless ω junction, and `graph --causality` refused the graph
/// ("junction 'bead.omega' has no bonds"); the default then fell back to a numeric partition.
#[test]
fn regression_massless_body_omega_junction_failed_graph_causality() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for scene in [
        "scenes/bead_in_slot.json",
        "benches/scenes/peers_slider_crank.json",
    ] {
        let (states, differential) = causality(&root.join(scene));
        assert!(!states.is_empty() && !differential.is_empty(), "{scene}");
    }
}
