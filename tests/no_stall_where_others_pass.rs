//! Issue 34: "A 'cannot advance' stop is never the answer where another formulation passes".
//! Every bundled mechanism scene (the raw bond graphs `bg_*` have no partition: `dae` and
//! `index1` do not apply to them, as the CLI says) under `dae` and `index1`, at the scene's
//! own output spacing, the default one ((t_end − t_start)/100), 0.05 s and 0.1 s (at most the
//! horizon): where a run stops with "cannot advance the time", `ggl` and `partitioned` are run
//! on the same scene, and the test fails if either of them completes.
//!
//! Each run has a wall-clock budget ([`BUDGET`]): a run that merely needs longer in the test
//! profile stops on the budget, which is not a stall.

mod common;

use std::time::Duration;

use bondmech::{FormulationKind, Model, Scene};
use serde_json::{json, Value};

/// Wall-clock budget of one run.
const BUDGET: Duration = Duration::from_secs(4);

/// `(completed, error message)` of the scene `v` under `f`.
fn run(v: &Value, f: FormulationKind) -> (bool, String) {
    let model = match Scene::from_json_str(&v.to_string())
        .map_err(|e| e.to_string())
        .and_then(|s| Model::new(&s).map_err(|e| e.to_string()))
    {
        Ok(m) => m,
        Err(e) => return (false, e),
    };
    let mut o = model.default_options();
    o.formulation = f;
    o.max_wall_clock = Some(BUDGET);
    match model.solve(&o) {
        Ok(sol) => (sol.summary.completed, String::new()),
        Err(e) => (false, e.to_string()),
    }
}

/// The scene with its output spacing replaced (`None`: the default spacing).
fn with_spacing(scene: &Value, step: Option<f64>) -> Value {
    let mut v = scene.clone();
    let solve = v["solve"].as_object_mut().unwrap();
    solve.remove("output_times");
    solve.remove("output_step");
    if let Some(h) = step {
        let t0 = solve.get("t_start").and_then(Value::as_f64).unwrap_or(0.0);
        let t1 = solve["t_end"].as_f64().unwrap();
        solve.insert("output_step".into(), json!(h.min(t1 - t0)));
    }
    v
}

#[test]
fn dae_and_index1_never_stall_on_a_bundled_scene_where_ggl_or_partitioned_passes() {
    let mut stalls = Vec::new();
    for path in common::bundled_scene_paths() {
        let scene: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        if scene.get("bond_graph").is_some() {
            continue;
        }
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let own = scene["solve"]["output_step"].as_f64();
        let mut spacings = vec![None, Some(0.05), Some(0.1)];
        if own.is_some() {
            spacings.push(own);
        }
        for step in spacings {
            let v = with_spacing(&scene, step);
            for f in [FormulationKind::Dae, FormulationKind::Index1] {
                let (_, err) = run(&v, f);
                if !err.contains("cannot advance") {
                    continue;
                }
                let others: Vec<_> = [FormulationKind::Ggl, FormulationKind::Partitioned]
                    .into_iter()
                    .filter(|&g| run(&v, g).0)
                    .collect();
                if !others.is_empty() {
                    stalls.push(format!(
                        "{name}, outputs {step:?}: {f:?} stalls ({err}) where {others:?} pass"
                    ));
                }
            }
        }
    }
    assert!(stalls.is_empty(), "{}", stalls.join("\n"));
}
