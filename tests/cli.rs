//! The command-line contract of docs/scene-format.md: columns, summary keys, exit codes and
//! one-line error messages naming the JSON path or the solver failure and its time.

mod support;

use support::cli::{bondmech, scene, tmp};

#[test]
fn run_writes_standard_columns_and_summary_keys() {
    let csv = tmp("dp.csv");
    let sum = tmp("dp.json");
    let out = bondmech(&[
        "run",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.5",
        "--out",
        csv.to_str().unwrap(),
        "--summary",
        sum.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    for col in [
        "t",
        "bar1.x",
        "bar1.y",
        "bar1.angle",
        "bar1.vx",
        "bar1.vy",
        "bar1.omega",
        "bar2.x",
        "bar2.omega",
        "bar2.A.x",
        "bar2.A.y",
        "energy",
        "constraint_error",
    ] {
        assert!(header.contains(&col), "missing column {col} in {header:?}");
    }
    let rows = text.lines().count() - 1;
    assert!(rows >= 2);
    let last: Vec<&str> = text.lines().last().unwrap().split(',').collect();
    assert_eq!(last[0].parse::<f64>().unwrap(), 0.5);
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
    for key in [
        "formulation",
        "steps",
        "residual_evals",
        "jacobian_evals",
        "error_test_failures",
        "nonlinear_iterations",
        "cpu_seconds",
        "max_constraint_error",
        "energy_drift",
    ] {
        assert!(s.get(key).is_some(), "summary lacks {key}: {s}");
    }
    assert_eq!(s["formulation"], "dae");
}

#[test]
fn cli_and_library_agree_on_the_same_scene() {
    let csv = tmp("agree.csv");
    let out = bondmech(&[
        "run",
        &scene("two_bars.json"),
        "--t-end",
        "0.3",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let sc = bondmech::Scene::from_path(scene("two_bars.json")).unwrap();
    let model = bondmech::Model::new(&sc).unwrap();
    let mut o = model.default_options();
    o.output_times = model.output_times_until(0.3).unwrap(); // the rule of --t-end
    let sol = model.solve(&o).unwrap();
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), sol.to_csv());
}

#[test]
fn bad_scene_exits_nonzero_with_one_line_naming_the_path() {
    let bad = tmp("bad.json");
    std::fs::write(
        &bad,
        r#"{"name":"b","dimension":2,"gravity":[0,-9.81],
           "bodies":[{"name":"bar1","mass":-1.0,"inertia":0.1,"position":[0,0],"angle":0}],
           "joints":[{"name":"pin","type":"revolute","bodies":["ground","bar9"],"points":[[0,0],[0,0]]}],
           "solve":{"t_end":1.0}}"#,
    )
    .unwrap();
    let out = bondmech(&["run", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains("bodies[0].mass"), "{err}");
    assert!(err.contains("joints[0].bodies[1]"), "{err}");
}

#[test]
fn missing_file_names_the_file() {
    let out = bondmech(&["run", "/nonexistent/scene.json"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/scene.json"), "{err}");
}

#[test]
fn solver_failure_exits_nonzero_naming_the_time() {
    let s = tmp("budget.json");
    let text = std::fs::read_to_string(scene("double_pendulum.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["solve"]["max_steps"] = serde_json::json!(2);
    std::fs::write(&s, v.to_string()).unwrap();
    let out = bondmech(&[
        "run",
        s.to_str().unwrap(),
        "--out",
        tmp("x.csv").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("t = "), "{err}");
}

#[test]
fn unknown_formulation_flag_is_refused() {
    let out = bondmech(&["run", &scene("pendulum.json"), "--formulation", "magic"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--formulation"));
}

#[test]
fn compare_prints_both_sides_and_writes_json() {
    let j = tmp("cmp.json");
    let out = bondmech(&[
        "compare",
        &scene("pendulum.json"),
        "--t-end",
        "0.5",
        "--json",
        j.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("DAE") && table.contains("decoupled"),
        "{table}"
    );
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&j).unwrap()).unwrap();
    assert_eq!(v["dae"]["solver"], "IDA");
    assert_eq!(v["decoupled"]["solver"], "CVODE");
    assert!(v["position"]["value"].as_f64().unwrap().is_finite());
}

#[test]
fn run_solves_a_raw_bond_graph_scene_and_compare_refuses_it() {
    let csv = tmp("msd.csv");
    let out = bondmech(&[
        "run",
        &scene("bg_mass_spring_damper.json"),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.lines().count() > 2);
    let out = bondmech(&["compare", &scene("bg_mass_spring_damper.json")]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("raw bond graph"));
}

/// Parses JSON text and blanks the CPU timings of both summaries (they differ run to run).
fn without_timings(text: &str) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
    for side in ["dae", "decoupled"] {
        for key in ["cpu_seconds", "build_cpu_seconds"] {
            assert!(v[side].get(key).is_some(), "{side}.{key} missing");
            v[side][key] = serde_json::Value::Null;
        }
    }
    // the verdict's CPU ratio (and the reason quoting it) are timings too
    if v.get("verdict").is_some() {
        v["verdict"]["cpu_ratio"] = serde_json::Value::Null;
        v["verdict"]["reason"] = serde_json::Value::Null;
    }
    v
}

#[test]
fn compare_json_from_the_cli_equals_model_compare() {
    let j = tmp("cmp_agree.json");
    let out = bondmech(&[
        "compare",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.5",
        "--json",
        j.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let model =
        bondmech::Model::new(&bondmech::Scene::from_path(scene("double_pendulum.json")).unwrap())
            .unwrap();
    let mut o = model.default_options();
    o.output_times = model.output_times_until(0.5).unwrap();
    let (cmp, _, _) = model.compare(&o).unwrap();
    let lib = serde_json::to_string_pretty(&cmp).unwrap();
    let cli = std::fs::read_to_string(&j).unwrap();
    assert_eq!(without_timings(&cli), without_timings(&lib));
    // the printed table is the library's table (but for the CPU time line)
    let no_cpu = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| !l.starts_with("CPU time") && !l.starts_with("verdict:"))
            .map(String::from)
            .collect()
    };
    assert_eq!(
        no_cpu(&String::from_utf8_lossy(&out.stdout)),
        no_cpu(&cmp.table())
    );
}

#[test]
fn graph_causality_json_from_the_cli_equals_model_causality() {
    for name in [
        "double_pendulum.json",
        "slider_crank.json",
        "bg_mass_spring_damper.json",
    ] {
        let out = bondmech(&["graph", &scene(name), "--causality"]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let model =
            bondmech::Model::new(&bondmech::Scene::from_path(scene(name)).unwrap()).unwrap();
        let report = model.causality().unwrap();
        let lib = serde_json::to_string_pretty(&report).unwrap() + "\n";
        assert_eq!(String::from_utf8(out.stdout).unwrap(), lib, "{name}");
    }
    // seed 16.7 through the command line too: 2 integral, 4 differential inertias
    let out = bondmech(&["graph", &scene("double_pendulum.json"), "--causality"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["integral_inertias"], 2);
    assert_eq!(v["differential"].as_array().unwrap().len(), 4);
}

#[test]
fn readme_first_command_prints_a_table_with_header_rows_and_summary() {
    // README.md: `cargo run -- run scenes/double_pendulum.json --table`
    let out = bondmech(&["run", &scene("double_pendulum.json"), "--table"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<&str> = lines[0].split_whitespace().collect();
    assert_eq!(header[..3], ["t", "bar1.x", "bar1.y"], "{text}");
    assert!(
        lines[..lines.len() - 1].iter().all(|l| !l.contains(',')),
        "a table, not CSV: {text}"
    );
    // the scene runs to t_end = 3 s: the last table row is t = 3 and the summary follows it
    let summary = lines[lines.len() - 1];
    assert!(
        summary.starts_with("dae: ")
            && summary.contains(" steps")
            && summary.contains("energy drift"),
        "{summary}"
    );
    let last: Vec<f64> = lines[lines.len() - 2]
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(last[0], 3.0);
    assert!(lines.len() > 12, "header, 11 rows and the summary: {text}");
    // the row's numbers are the library's solution at t = 3 (to the 6 printed decimals)
    let model =
        bondmech::Model::new(&bondmech::Scene::from_path(scene("double_pendulum.json")).unwrap())
            .unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    let k = sol.times.len() - 1;
    for (c, name) in header[1..].iter().enumerate() {
        let v = sol.value(k, name).unwrap();
        assert!(
            (last[c + 1] - v).abs() <= 5e-7,
            "{name}: {} vs {v}",
            last[c + 1]
        );
    }
}

#[test]
fn run_prints_each_summary_warning_to_stderr_as_one_line() {
    // A bar pinned twice at the same point: pin2's rows depend on pin1's (redundant joint),
    // which the solve reports in Summary.warnings; the CLI prints each on its own line.
    let path = tmp("pinned_twice.json");
    std::fs::write(
        &path,
        r#"{"dimension": 2, "gravity": [0, -9.81],
            "bodies": [{"name": "bar", "mass": 1, "inertia": 0.0833,
                        "points": {"O": [-0.5, 0]}, "position": [0.5, 0], "angle": 0}],
            "joints": [
              {"name": "pin1", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0, 0], "O"]},
              {"name": "pin2", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0, 0], "O"]}],
            "solve": {"t_end": 0.2}}"#,
    )
    .unwrap();
    let out = bondmech(&["run", path.to_str().unwrap(), "--table"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let model = bondmech::Model::new(&bondmech::Scene::from_path(&path).unwrap()).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    assert!(
        sol.summary.warnings.iter().any(|w| w.contains("redundant")),
        "{:?}",
        sol.summary.warnings
    );
    let want: Vec<String> = sol
        .summary
        .warnings
        .iter()
        .map(|w| format!("bondmech: warning: {w}"))
        .collect();
    let stderr = String::from_utf8(out.stderr).unwrap();
    let got: Vec<&str> = stderr.lines().collect();
    assert_eq!(got, want);
}

#[test]
fn linear_solver_flag_picks_the_newton_solver_and_unknown_names_are_refused() {
    // the double pendulum under the default `dae`: `auto` eliminates the dependent blocks of
    // the index-1 Newton matrix (the Schur solver, src/sundials/schur.rs)
    for (flag, used) in [
        ("dense", "dense"),
        ("sparse", "faer"),
        ("klu", "klu"),
        ("auto", "schur"),
    ] {
        let sum = tmp(&format!("ls_{flag}.json"));
        let out = bondmech(&[
            "run",
            &scene("double_pendulum.json"),
            "--t-end",
            "0.1",
            "--linear-solver",
            flag,
            "--out",
            tmp(&format!("ls_{flag}.csv")).to_str().unwrap(),
            "--summary",
            sum.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
        assert_eq!(s["linear_solver"], used, "--linear-solver {flag}");
    }
    let out = bondmech(&[
        "run",
        &scene("double_pendulum.json"),
        "--linear-solver",
        "cholesky",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--linear-solver") && err.contains("cholesky"),
        "{err}"
    );
}
