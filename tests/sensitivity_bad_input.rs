//! Every refusal of `sensitivity` and `fit` names the parameter's path or the data's column
//! (issue 49's list), and none panics; the command line exits 1 on them and on a fit that does
//! not converge, with its last iterate on standard output.

use std::process::Command;

use bondmech::sensitivity::{fit, sensitivity, FitData, FitRequest, SensitivityRequest};
use bondmech::Scene;

fn block() -> Scene {
    let s = serde_json::json!({
        "name": "block", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [{"name": "block", "mass": 2.0, "inertia": 0.01, "points": {"c": [0.0, 0.0]},
                    "position": [0.1, 0.0], "angle": 0.0}],
        "joints": [{"name": "rail", "type": "prismatic", "bodies": ["ground", "block"],
                    "points": [[0.0, 0.0], "c"], "axis": [1.0, 0.0]}],
        "springs": [{"name": "s1", "bodies": ["ground", "block"], "points": [[0.0, 0.0], "c"],
                     "stiffness": 50.0, "damping": 1.5, "rest_length": 0.0}],
        "solve": {"t_end": 1.0, "output_step": 0.05, "rtol": 1e-8, "atol": 1e-10}
    });
    Scene::from_json_str(&s.to_string()).unwrap()
}

fn refusal(params: &[&str]) -> String {
    sensitivity(&block(), &SensitivityRequest::new(params))
        .expect_err("refused")
        .to_string()
}

fn data(text: &str) -> String {
    FitData::from_csv(text).expect_err("refused").to_string()
}

/// Closed-form data of the block at its own values (2 kg, 50 N/m, 1.5 N·s/m).
fn block_data() -> FitData {
    let (m, k, c, x0): (f64, f64, f64, f64) = (2.0, 50.0, 1.5, 0.1);
    let a = c / (2.0 * m);
    let w = (k / m - a * a).sqrt();
    let rows = (1..=20)
        .map(|i| {
            let t = 0.05 * i as f64;
            vec![
                t,
                x0 * (-a * t).exp() * ((w * t).cos() + a / w * (w * t).sin()),
            ]
        })
        .collect();
    FitData::from_table(vec!["t".into(), "block.x".into()], rows).unwrap()
}

fn req(params: &[&str]) -> FitRequest {
    FitRequest {
        params: params.iter().map(|s| s.to_string()).collect(),
        columns: None,
        max_iterations: None,
    }
}

#[test]
fn unknown_paths_and_non_numbers_are_refused_naming_the_path() {
    let e = refusal(&["springs[s2].stiffness"]);
    assert!(
        e.contains("springs[s2].stiffness") && e.contains("s2"),
        "{e}"
    );
    let e = refusal(&["bodies[block].mas"]);
    assert!(e.contains("bodies[block].mas") && e.contains("mass"), "{e}");
    let e = refusal(&["bodies[block].points.c"]);
    assert!(
        e.contains("bodies[block].points.c") && e.contains("array"),
        "{e}"
    );
    let e = refusal(&["bodies[block].name"]);
    assert!(e.contains("not a number"), "{e}");
    let e = refusal(&["springs[s1].damping", "springs[s1].damping"]);
    assert!(e.contains("given twice"), "{e}");
}

#[test]
fn a_parameter_the_scene_does_not_depend_on_is_reported_with_zero_sensitivities() {
    let s = sensitivity(&block(), &SensitivityRequest::new(&["solve.atol"])).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("solve.atol") && w.contains("does not depend")),
        "{:?}",
        s.warnings
    );
    let d = s.column("d(block.x)/d(solve.atol)").unwrap();
    assert!(d.iter().all(|&v| v == 0.0));
}

#[test]
fn bad_data_is_refused_naming_the_column() {
    let e = data("time,block.x\n0.1,0.0\n");
    assert!(e.contains("no column 't'"), "{e}");
    let e = data("t,block.x\n0.1,NaN\n");
    assert!(e.contains("'block.x'") && e.contains("row 1"), "{e}");
    let e = data("t,block.x\n0.1,abc\n");
    assert!(e.contains("'block.x'") && e.contains("not a number"), "{e}");
    let e = data("t,block.x\n0.2,0\n0.1,0\n");
    assert!(e.contains("column 't'") && e.contains("increase"), "{e}");
    // a column the run does not write
    let d = FitData::from_table(
        vec!["t".into(), "block.z".into()],
        vec![vec![0.1, 0.0], vec![0.2, 0.0], vec![0.3, 0.0]],
    )
    .unwrap();
    let e = fit(&block(), &d, &req(&["springs[s1].stiffness"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'block.z'") && e.contains("not a column of the run"),
        "{e}"
    );
    // times outside the scene's span
    let d = FitData::from_table(
        vec!["t".into(), "block.x".into()],
        vec![vec![0.5, 0.0], vec![1.5, 0.0], vec![2.0, 0.0]],
    )
    .unwrap();
    let e = fit(&block(), &d, &req(&["springs[s1].stiffness"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("column 't'") && e.contains("outside"), "{e}");
}

#[test]
fn a_non_identifiable_pair_is_named() {
    // x(t) depends on k/m and c/m only: mass and stiffness and damping together are not
    // identifiable from it
    let e = fit(
        &block(),
        &block_data(),
        &req(&[
            "springs[s1].stiffness",
            "springs[s1].damping",
            "bodies[block].mass",
        ]),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("not identifiable") && e.contains("--param"),
        "{e}"
    );
    // a parameter the fitted columns do not depend on
    let e = fit(&block(), &block_data(), &req(&["solve.atol"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("solve.atol") && e.contains("do not depend"),
        "{e}"
    );
}

#[test]
fn a_fit_that_does_not_converge_reports_its_last_iterate() {
    let mut scene = block();
    scene.springs[0].stiffness = 60.0;
    let r = fit(
        &scene,
        &block_data(),
        &FitRequest {
            max_iterations: Some(1),
            ..req(&["springs[s1].stiffness"])
        },
    )
    .unwrap();
    assert!(!r.converged);
    assert!(r.reason.contains("1 iterations"), "{}", r.reason);
    assert!(
        r.values[0] != 60.0,
        "the last iterate moved: {}",
        r.values[0]
    );
}

#[test]
fn the_command_line_exits_1_naming_the_path_and_on_no_convergence() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("block.json");
    let mut scene = block();
    scene.springs[0].stiffness = 60.0;
    std::fs::write(&scene_path, scene.to_json_string()).unwrap();
    let bin = env!("CARGO_BIN_EXE_bondmech");
    let out = Command::new(bin)
        .args([
            "sensitivity",
            scene_path.to_str().unwrap(),
            "--param",
            "springs[s9].stiffness",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("springs[s9].stiffness"), "{err}");
    let d = block_data();
    let mut csv = String::from("t,block.x\n");
    for (t, v) in d.times.iter().zip(&d.values) {
        csv.push_str(&format!("{t},{}\n", v[0]));
    }
    let data_path = dir.path().join("x.csv");
    std::fs::write(&data_path, csv).unwrap();
    let out = Command::new(bin)
        .args([
            "fit",
            scene_path.to_str().unwrap(),
            "--data",
            data_path.to_str().unwrap(),
            "--param",
            "springs[s1].stiffness",
            "--max-iterations",
            "1",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("springs[s1].stiffness") && table.contains("NOT converged"),
        "{table}"
    );
    let out = Command::new(bin)
        .args([
            "fit",
            scene_path.to_str().unwrap(),
            "--data",
            data_path.to_str().unwrap(),
            "--param",
            "springs[s1].stiffness",
            "--json",
            dir.path().join("fit.json").to_str().unwrap(),
            "--out",
            dir.path().join("fitted.json").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("fit.json")).unwrap())
            .unwrap();
    let k = j["parameters"]["springs[s1].stiffness"].as_f64().unwrap();
    assert!((k - 50.0).abs() < 1e-4, "{k}");
    let fitted = Scene::from_path(dir.path().join("fitted.json")).unwrap();
    assert!((fitted.springs[0].stiffness - k).abs() < 1e-12);
}
