//! `bondmech serve`, route by route, on 127.0.0.1: every route with a bundled scene, and each
//! bad input the issue lists. References are independent of the service: the command line's
//! own output (CSV, DOT, causality JSON, compare JSON, error lines) and RFC 9457 / RFC 9110
//! for the HTTP side.

mod service_support;

use std::io::Write;

use bondmech::service::Config;
use serde_json::Value;
use service_support::*;

/// `/v1/run` JSON rows and the CLI's CSV (same scene, same flags): same columns, same number of
/// rows, every value the same f64 (CSV printed with 17 decimals, JSON with shortest
/// round-trip digits, both parsed exactly).
fn assert_run_equals_cli(scene: &str, query: &str, flags: &[&str]) {
    let server = start(Config::default());
    let r = post(
        server.addr(),
        &format!("/v1/run?{query}"),
        scene_text(scene).as_bytes(),
    );
    assert_eq!(r.status, 200, "{scene}: {}", r.text());
    assert_eq!(r.header("content-type"), Some("application/json"));
    let j = r.json();
    let path = scene_path(scene);
    let summary_file = std::env::temp_dir().join(format!(
        "bondmech-service-summary-{}-{scene}",
        std::process::id()
    ));
    let summary_path = summary_file.display().to_string();
    let mut args = vec!["run", path.as_str(), "--summary", summary_path.as_str()];
    args.extend_from_slice(flags);
    let (ok, csv, err) = cli(&args);
    assert!(ok, "{err}");
    let mut summary: Value =
        serde_json::from_str(&std::fs::read_to_string(&summary_file).unwrap()).unwrap();
    std::fs::remove_file(&summary_file).ok();
    let (header, rows) = parse_csv(&csv);
    let columns: Vec<String> = j["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    assert_eq!(columns, header, "{scene}");
    let jrows = json_rows(&j["rows"]);
    assert_eq!(jrows.len(), rows.len(), "{scene}");
    for (k, (a, b)) in jrows.iter().zip(&rows).enumerate() {
        assert_eq!(a.len(), b.len());
        for (c, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                x.to_bits() == y.to_bits(),
                "{scene} row {k} column {}: JSON {x:e} against CLI {y:e}",
                header[c]
            );
        }
    }
    // the summary too, but for the CPU times
    let mut served = j["summary"].clone();
    for key in ["cpu_seconds", "build_cpu_seconds"] {
        served[key] = Value::Null;
        summary[key] = Value::Null;
    }
    assert_eq!(served, summary, "{scene}");
    assert!(summary["steps"].as_u64().unwrap() > 0);
    server.shutdown().unwrap();
}

#[test]
fn run_json_equals_cli_csv_to_the_last_digit_planar_dae() {
    assert_run_equals_cli("double_pendulum.json", "t_end=0.5", &["--t-end", "0.5"]);
}

#[test]
fn run_json_equals_cli_csv_spatial_and_flags() {
    assert_run_equals_cli(
        "free_body_3d.json",
        "t_end=0.3&rtol=1e-6&atol=1e-9",
        &["--t-end", "0.3", "--rtol", "1e-6", "--atol", "1e-9"],
    );
}

#[test]
fn run_json_equals_cli_csv_decoupled_and_index1() {
    assert_run_equals_cli(
        "slider_crank.json",
        "t_end=0.05&formulation=decoupled&joint_stiffness=1e6",
        &[
            "--t-end",
            "0.05",
            "--formulation",
            "decoupled",
            "--joint-stiffness",
            "1e6",
        ],
    );
    assert_run_equals_cli(
        "four_bar.json",
        "t_end=0.2&formulation=index1",
        &["--t-end", "0.2", "--formulation", "index1"],
    );
}

#[test]
fn run_linear_solver_parameter_is_the_cli_flag_and_reaches_the_summary() {
    // same rows and summary as `--linear-solver klu` on the command line (a double pendulum
    // has 10 unknowns, so auto would pick dense: the parameter is what makes it KLU)
    assert_run_equals_cli(
        "double_pendulum.json",
        "t_end=0.3&linear_solver=klu",
        &["--t-end", "0.3", "--linear-solver", "klu"],
    );
    let server = start(Config::default());
    let scene = scene_text("double_pendulum.json");
    for (value, used) in [
        ("klu", "klu"),
        ("sparse", "faer"),
        ("faer", "faer"),
        ("dense", "dense"),
        // the default dae: auto eliminates the index-1 Newton matrix's dependent blocks
        ("auto", "schur"),
    ] {
        let r = post(
            server.addr(),
            &format!("/v1/run?t_end=0.1&linear_solver={value}"),
            scene.as_bytes(),
        );
        assert_eq!(r.status, 200, "{value}: {}", r.text());
        assert_eq!(r.json()["summary"]["linear_solver"], used, "{value}");
    }
    let p = post(
        server.addr(),
        "/v1/run?linear_solver=superlu",
        scene.as_bytes(),
    )
    .problem(422);
    assert_eq!(p["parameter"], "linear_solver");
    let detail = p["detail"].as_str().unwrap();
    assert!(
        detail.contains("linear_solver") && detail.contains("superlu") && detail.contains("klu"),
        "{detail}"
    );
    server.shutdown().unwrap();
}

#[test]
fn run_json_equals_cli_csv_raw_bond_graph() {
    assert_run_equals_cli("bg_mass_spring_damper.json", "", &[]);
}

#[test]
fn run_csv_is_the_cli_csv_and_ndjson_streams_the_same_rows() {
    let server = start(Config::default());
    let scene = scene_text("double_pendulum.json");
    let (ok, cli_csv, err) = cli(&["run", &scene_path("double_pendulum.json"), "--t-end", "0.2"]);
    assert!(ok, "{err}");
    let r = post(
        server.addr(),
        "/v1/run?t_end=0.2&format=csv",
        scene.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert!(r.header("content-type").unwrap().starts_with("text/csv"));
    assert_eq!(r.text(), cli_csv);

    let r = post(
        server.addr(),
        "/v1/run?t_end=0.2&format=ndjson",
        scene.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("application/x-ndjson"));
    let lines: Vec<Value> = r
        .text()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let (header, rows) = parse_csv(&cli_csv);
    // first line: columns and the number of rows; then one array per row; then the summary
    assert_eq!(lines[0]["rows"], rows.len());
    let cols: Vec<&str> = lines[0]["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(cols, header);
    assert_eq!(lines.len(), rows.len() + 2);
    let streamed = json_rows(&Value::Array(lines[1..=rows.len()].to_vec()));
    assert_eq!(streamed, rows);
    assert!(lines.last().unwrap()["summary"]["steps"].as_u64().unwrap() > 0);
    server.shutdown().unwrap();
}

#[test]
fn malformed_json_is_400_with_line_and_column() {
    let server = start(Config::default());
    // line 2, the second comma is the 16th character: `  "bodies": [1,,]`
    let r = post(server.addr(), "/v1/run", b"{\n  \"bodies\": [1,,]\n}");
    let p = r.problem(400);
    assert_eq!(
        (p["line"].as_u64(), p["column"].as_u64()),
        (Some(2), Some(16)),
        "{p}"
    );
    // a body that is not UTF-8
    let r = post(server.addr(), "/v1/run", b"{\"name\": \"\xff\"}");
    r.problem(400);
    server.shutdown().unwrap();
}

#[test]
fn invalid_scene_is_422_with_the_clis_paths_and_messages() {
    let server = start(Config::default());
    let scene = r#"{"dimension": 2,
      "bodies": [{"name": "a", "mass": -1, "inertia": 1},
                 {"name": "b", "mass": 1, "inertia": -2}],
      "joints": [{"type": "revolute", "bodies": ["ground", "nobody"], "points": [[0, 0], "O"]}],
      "solve": {"t_end": 1, "rtol": 0}}"#;
    let file = std::env::temp_dir().join(format!("bondmech-service-{}.json", std::process::id()));
    std::fs::File::create(&file)
        .unwrap()
        .write_all(scene.as_bytes())
        .unwrap();
    let (ok, _, stderr) = cli(&["run", file.to_str().unwrap()]);
    std::fs::remove_file(&file).ok();
    assert!(!ok);
    let r = post(server.addr(), "/v1/run", scene.as_bytes());
    let p = r.problem(422);
    let errors = p["errors"].as_array().unwrap();
    assert!(errors.len() >= 3, "{p}");
    let lines: Vec<String> = errors
        .iter()
        .map(|e| {
            format!(
                "{}: {}",
                e["path"].as_str().unwrap(),
                e["message"].as_str().unwrap()
            )
        })
        .collect();
    // the CLI prints the same problems, one line each joined by "; "
    assert_eq!(
        format!("bondmech: {}", lines.join("; ")),
        stderr.trim_end(),
        "{p}"
    );
    assert!(
        lines.iter().any(|l| l.starts_with("bodies[0].mass: ")),
        "{lines:?}"
    );
    // the same list from every scene route
    for route in ["/v1/compare", "/v1/graph", "/v1/sweep"] {
        let q = post(server.addr(), route, scene.as_bytes()).problem(422);
        assert_eq!(q["errors"], p["errors"], "{route}");
    }
    server.shutdown().unwrap();
}

#[test]
fn body_over_the_limit_is_413_from_content_length_before_reading() {
    let server = start(Config::default());
    // only the head is sent: the answer cannot depend on the body
    let mut s = connect(server.addr());
    write_head(
        &mut s,
        "POST",
        "/v1/run",
        &[
            ("Content-Type", "application/json"),
            ("Content-Length", "10000000"),
        ],
    );
    let r = read_response(&mut s).unwrap();
    let p = r.problem(413);
    assert_eq!(p["limit"], "max_body");
    assert_eq!(p["limit_value"], 1 << 20);

    // a chunked body (no Content-Length) is cut as soon as it passes the limit
    let server2 = start(Config {
        limits: bondmech::service::Limits {
            max_body: 1000,
            ..Config::default().limits
        },
        ..Config::default()
    });
    let mut s = connect(server2.addr());
    write_head(
        &mut s,
        "POST",
        "/v1/run",
        &[
            ("Content-Type", "application/json"),
            ("Transfer-Encoding", "chunked"),
        ],
    );
    for _ in 0..3 {
        let chunk = format!("{:x}\r\n{}\r\n", 600, " ".repeat(600));
        if s.write_all(chunk.as_bytes()).is_err() {
            break;
        }
    }
    let _ = s.write_all(b"0\r\n\r\n");
    let r = read_response(&mut s).unwrap();
    r.problem(413);
    let m = get(server2.addr(), "/metrics").text();
    assert_eq!(
        metric(&m, "bondmech_rejections_total{reason=\"body_too_large\"}"),
        Some(1.0)
    );
    server.shutdown().unwrap();
    server2.shutdown().unwrap();
}

#[test]
fn other_limits_are_422_naming_the_limit() {
    let server = start(Config {
        limits: bondmech::service::Limits {
            max_elements: 5,
            ..Config::default().limits
        },
        ..Config::default()
    });
    // double pendulum: 2 bodies, 2 joints, 3 outputs
    let p = post(
        server.addr(),
        "/v1/run",
        scene_text("double_pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["limit"], "max_elements", "{p}");
    assert!(
        p["detail"].as_str().unwrap().contains("max_elements = 5"),
        "{p}"
    );
    let m = get(server.addr(), "/metrics").text();
    assert_eq!(
        metric(&m, "bondmech_rejections_total{reason=\"limit\"}"),
        Some(1.0)
    );
    server.shutdown().unwrap();
    let server = start(Config {
        limits: bondmech::service::Limits {
            max_expression_length: 20,
            max_rows: 1000,
            ..Config::default().limits
        },
        ..Config::default()
    });
    // the slider-crank's gas force is an expression longer than 20 bytes
    let text = scene_text("slider_crank.json");
    let p = post(server.addr(), "/v1/run", text.as_bytes()).problem(422);
    assert_eq!(p["limit"], "max_expression_length", "{p}");
    let doc: Value = serde_json::from_str(&text).unwrap();
    let path = p["path"].as_str().unwrap();
    let mut v = &doc;
    for part in path.split('.') {
        let (key, idx) = match part.split_once('[') {
            Some((k, i)) => (k, i.trim_end_matches(']').parse::<usize>().ok()),
            None => (part, None),
        };
        v = &v[key];
        if let Some(i) = idx {
            v = &v[i];
        }
    }
    assert!(v.as_str().unwrap().len() > 20, "{path} names a long string");
    // 1e9 s at the pendulum's output step: 1e11 rows, refused before any allocation
    let p = post(
        server.addr(),
        "/v1/run?t_end=1e9",
        scene_text("pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["limit"], "max_rows", "{p}");
    let p = post(
        server.addr(),
        "/v1/compare?t_end=1e9",
        scene_text("pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["limit"], "max_rows", "{p}");
    let p = post(
        server.addr(),
        "/v1/sweep?repeats=50",
        scene_text("pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["limit"], "max_sweep_repeats", "{p}");
    let m = get(server.addr(), "/metrics").text();
    assert_eq!(
        metric(&m, "bondmech_rejections_total{reason=\"limit\"}"),
        Some(4.0)
    );
    server.shutdown().unwrap();
}

#[test]
fn bad_query_parameters_name_the_parameter() {
    let server = start(Config::default());
    let scene = scene_text("pendulum.json");
    for (query, status, parameter) in [
        ("colour=red", 400, "colour"),
        ("rtol=abc", 400, "rtol"),
        ("rtol=1e-6&rtol=1e-7", 400, "rtol"),
        ("format=xml", 400, "format"),
        ("rtol=-1", 422, "rtol"),
        ("t_end=0", 422, "t_end"),
        ("t_end=nan", 422, "t_end"),
        ("joint_stiffness=inf", 422, "joint_stiffness"),
        ("formulation=magic", 422, "formulation"),
        ("linear_solver=lu", 422, "linear_solver"),
        // the scene's own bounds, as the command line's flags meet them (issue 12): these
        // were accepted by the service when it set the options beside the scene
        ("rtol=1e308", 422, "rtol"),
        ("joint_stiffness=1e300", 422, "joint_stiffness"),
        ("max_wall_seconds=0", 422, "max_wall_seconds"),
    ] {
        let p = post(server.addr(), &format!("/v1/run?{query}"), scene.as_bytes()).problem(status);
        assert_eq!(p["parameter"], parameter, "{query}: {p}");
    }
    let p = post(server.addr(), "/v1/graph?format=png", scene.as_bytes()).problem(400);
    assert_eq!(p["parameter"], "format");
    let p = post(server.addr(), "/v1/graph?decoupled=maybe", scene.as_bytes()).problem(400);
    assert_eq!(p["parameter"], "decoupled");
    let r = request(
        server.addr(),
        "POST",
        "/v1/run",
        Some("text/plain"),
        scene.as_bytes(),
    )
    .unwrap();
    r.problem(415);
    server.shutdown().unwrap();
}

#[test]
fn solve_past_its_budget_is_422_with_the_rows_computed_so_far() {
    let server = start(Config {
        limits: bondmech::service::Limits {
            max_solve_seconds: 1.0,
            ..Config::default().limits
        },
        ..Config::default()
    });
    // the twin at k = 1e10 needs about 580 000 steps per simulated second (README): 3 s of it
    // is far beyond a 1 s budget on any machine
    let scene = scene_text("double_pendulum.json");
    let q = "formulation=decoupled&joint_stiffness=1e10";
    let p = post(server.addr(), &format!("/v1/run?{q}"), scene.as_bytes()).problem(422);
    assert_eq!(p["limit"], "max_solve_seconds", "{p}");
    assert_eq!(p["limit_value"], 1.0);
    let t_reached = p["t_reached"].as_f64().unwrap();
    assert!(t_reached > 0.0 && t_reached < 3.0, "{p}");
    let rows = json_rows(&p["rows"]);
    assert!(!rows.is_empty());
    // the rows are those of the output grid up to the time reached, then (as the CLI writes
    // them) the state at the time reached itself
    let (last, grid) = rows.split_last().unwrap();
    for (k, r) in grid.iter().enumerate() {
        assert!(
            (r[0] - 0.01 * k as f64).abs() < 1e-12,
            "row {k} at t = {}",
            r[0]
        );
        assert!(r[0] < t_reached);
    }
    let k = grid.len() as f64;
    assert!(
        (last[0] - 0.01 * k).abs() < 1e-12 || last[0] == t_reached,
        "last row at t = {}, t_reached = {t_reached}",
        last[0]
    );
    // the columns are the run's (the CLI's header for the same flags)
    let (ok, csv, err) = cli(&[
        "run",
        &scene_path("double_pendulum.json"),
        "--t-end",
        "0.01",
        "--formulation",
        "decoupled",
        "--joint-stiffness",
        "1e4",
    ]);
    assert!(ok, "{err}");
    let (header, _) = parse_csv(&csv);
    let cols: Vec<&str> = p["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(cols, header);
    assert_eq!(rows[0].len(), header.len());

    // the scene's own, smaller budget is named when it is the one that stops the solve
    let mut doc: Value = serde_json::from_str(&scene).unwrap();
    doc["solve"]["max_wall_seconds"] = 0.5.into();
    let p = post(
        server.addr(),
        &format!("/v1/run?{q}"),
        doc.to_string().as_bytes(),
    )
    .problem(422);
    assert_eq!(p["limit"], "solve.max_wall_seconds", "{p}");

    // NDJSON: the rows went out as they came; the last line is the problem
    let r = post(
        server.addr(),
        &format!("/v1/run?{q}&format=ndjson"),
        scene.as_bytes(),
    );
    assert_eq!(r.status, 200);
    let last: Value = serde_json::from_str(r.text().lines().last().unwrap()).unwrap();
    assert_eq!(last["error"]["status"], 422, "{last}");
    assert_eq!(last["error"]["limit"], "max_solve_seconds", "{last}");
    let m = get(server.addr(), "/metrics").text();
    assert_eq!(metric(&m, "bondmech_solve_budget_stops_total"), Some(3.0));
    server.shutdown().unwrap();
}

#[test]
fn compare_equals_the_cli_compare_json() {
    let server = start(Config::default());
    let r = post(
        server.addr(),
        "/v1/compare?t_end=0.2&joint_stiffness=1e6",
        scene_text("double_pendulum.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let j = r.json();
    let file =
        std::env::temp_dir().join(format!("bondmech-service-cmp-{}.json", std::process::id()));
    let (ok, _, err) = cli(&[
        "compare",
        &scene_path("double_pendulum.json"),
        "--t-end",
        "0.2",
        "--joint-stiffness",
        "1e6",
        "--json",
        file.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let c: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    std::fs::remove_file(&file).ok();
    // everything but the CPU times
    for key in ["position", "angle", "velocity", "angular_velocity"] {
        assert_eq!(j[key], c[key], "{key}");
    }
    for run in ["dae", "decoupled"] {
        for key in [
            "steps",
            "residual_evals",
            "jacobian_evals",
            "max_constraint_error",
            "energy_drift",
        ] {
            assert_eq!(j[run][key], c[run][key], "{run}.{key}");
        }
    }
    // a raw bond graph has no twin: 422
    let p = post(
        server.addr(),
        "/v1/compare",
        scene_text("bg_dc_motor.json").as_bytes(),
    )
    .problem(422);
    assert!(
        p["detail"].as_str().unwrap().contains("decoupled twin"),
        "{p}"
    );
    server.shutdown().unwrap();
}

#[test]
fn graph_formats_equal_the_cli() {
    let server = start(Config::default());
    let scene = scene_text("double_pendulum.json");
    let path = scene_path("double_pendulum.json");
    for (query, args, ctype) in [
        (
            "",
            vec!["graph", path.as_str()],
            "text/vnd.graphviz; charset=utf-8",
        ),
        (
            "?format=dot&decoupled=true",
            vec!["graph", path.as_str(), "--decoupled"],
            "text/vnd.graphviz; charset=utf-8",
        ),
        (
            "?format=causality",
            vec!["graph", path.as_str(), "--causality"],
            "application/json",
        ),
    ] {
        let r = post(
            server.addr(),
            &format!("/v1/graph{query}"),
            scene.as_bytes(),
        );
        assert_eq!(r.status, 200, "{}", r.text());
        assert_eq!(r.header("content-type"), Some(ctype));
        let (ok, out, err) = cli(&args);
        assert!(ok, "{err}");
        assert_eq!(r.text(), out, "{query}");
    }
    let r = post(server.addr(), "/v1/graph?format=svg", scene.as_bytes());
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("image/svg+xml"));
    assert!(r.text().contains("<svg"), "{}", r.text());
    // the causality report of a raw bond graph
    let r = post(
        server.addr(),
        "/v1/graph?format=causality",
        scene_text("bg_mass_spring_damper.json").as_bytes(),
    );
    assert_eq!(r.json()["dof"], 1);
    server.shutdown().unwrap();
}

#[test]
fn sweep_streams_progress_then_the_report() {
    let server = start(Config::default());
    let r = post(
        server.addr(),
        "/v1/sweep?quick=true&t_end=0.1",
        scene_text("pendulum.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("application/x-ndjson"));
    let lines: Vec<Value> = r
        .text()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // quick: 3 tolerances × (GGL, index 1, 1 twin) + 3 stiffnesses + the DAE baseline + the
    // reference = 14 points, each reported once
    let total = 3 * (2 + 1) + 3 + 2;
    assert_eq!(lines.len(), total + 1, "{}", r.text());
    for (k, l) in lines[..total].iter().enumerate() {
        assert_eq!(l["progress"]["done"], k + 1);
        assert_eq!(l["progress"]["total"], total);
    }
    let report = &lines[total]["sweep"];
    assert_eq!(report["work_precision"].as_array().unwrap().len(), 9);
    assert_eq!(report["stiffness"].as_array().unwrap().len(), 3);
    assert_eq!(report["t_end"], 0.1);
    let p = post(
        server.addr(),
        "/v1/sweep",
        scene_text("bg_dc_motor.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["errors"][0]["path"], "bond_graph");
    server.shutdown().unwrap();
}

#[test]
fn healthz_metrics_openapi_and_unknown_routes() {
    let server = start(Config::default());
    let r = get(server.addr(), "/healthz");
    assert_eq!(r.status, 200);
    let j = r.json();
    let (ma, mi, pa) = bondmech::sundials::version::version();
    assert_eq!(j["sundials"], format!("{ma}.{mi}.{pa}"));
    assert_eq!(ma, 6);
    assert_eq!(j["version"], env!("CARGO_PKG_VERSION"));

    let _ = post(
        server.addr(),
        "/v1/run?t_end=0.05",
        scene_text("pendulum.json").as_bytes(),
    );
    let _ = post(server.addr(), "/v1/run", b"{");
    let m = get(server.addr(), "/metrics");
    assert_eq!(m.status, 200);
    assert!(m
        .header("content-type")
        .unwrap()
        .starts_with("text/plain; version=0.0.4"));
    let m = m.text();
    assert_eq!(
        metric(
            &m,
            "bondmech_requests_total{route=\"/v1/run\",status=\"200\"}"
        ),
        Some(1.0)
    );
    assert_eq!(
        metric(
            &m,
            "bondmech_requests_total{route=\"/v1/run\",status=\"400\"}"
        ),
        Some(1.0)
    );
    assert_eq!(
        metric(
            &m,
            "bondmech_requests_total{route=\"/healthz\",status=\"200\"}"
        ),
        Some(1.0)
    );
    assert_eq!(metric(&m, "bondmech_solves_in_flight"), Some(0.0));
    assert_eq!(metric(&m, "bondmech_queue_length"), Some(0.0));
    assert_eq!(metric(&m, "bondmech_solve_seconds_count"), Some(1.0));
    assert_eq!(
        metric(&m, "bondmech_solve_seconds_bucket{le=\"+Inf\"}"),
        Some(1.0)
    );
    for l in m.lines().filter(|l| !l.starts_with('#') && !l.is_empty()) {
        // every sample line: a name (with labels) and a number
        let (_, v) = l.rsplit_once(' ').unwrap();
        v.parse::<f64>().unwrap_or_else(|_| panic!("{l}"));
    }

    let o = get(server.addr(), "/openapi.json");
    assert_eq!(o.status, 200);
    let o = o.json();
    assert_eq!(o["openapi"], "3.1.0");
    for (path, method) in [
        ("/healthz", "get"),
        ("/metrics", "get"),
        ("/openapi.json", "get"),
        ("/v1/run", "post"),
        ("/v1/compare", "post"),
        ("/v1/graph", "post"),
        ("/v1/equilibrium", "post"),
        ("/v1/linearize", "post"),
        ("/v1/sensitivity", "post"),
        ("/v1/fit", "post"),
        ("/v1/sweep", "post"),
    ] {
        assert!(o["paths"][path][method].is_object(), "{path} {method}");
        if method == "post" {
            for code in ["200", "400", "413", "422", "503"] {
                assert!(
                    o["paths"][path][method]["responses"][code].is_object(),
                    "{path} {code}"
                );
            }
        }
    }

    get(server.addr(), "/v2/run").problem(404);
    let r = get(server.addr(), "/v1/run");
    r.problem(405);
    assert_eq!(r.header("allow"), Some("POST"));
    server.shutdown().unwrap();
}

/// The service announces columns before solving (NDJSON header, budget stops) through
/// `Model::row_columns` (the raw bond graph's from its equations, its twin's under
/// `decoupled`): they must be the columns every solve writes.
#[test]
fn model_columns_are_the_solution_columns_on_every_bundled_scene() {
    use bondmech::{FormulationKind, Model, Scene};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut scenes: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 14);
    for path in scenes {
        let model = Model::new(&Scene::from_path(&path).unwrap()).unwrap();
        let forms: &[FormulationKind] = if model.is_raw_bond_graph() {
            // the bundled raw graphs have no joint rows: their twin is refused by both, by
            // name (issue 51: it ran the graph as it is)
            let mut opts = model.default_options();
            opts.formulation = FormulationKind::Decoupled;
            for e in [
                model.row_columns(&opts).unwrap_err().to_string(),
                model.solve(&opts).unwrap_err().to_string(),
            ] {
                assert!(e.contains("nothing to decouple"), "{}: {e}", path.display());
            }
            &[FormulationKind::Dae]
        } else {
            &[
                FormulationKind::Ggl,
                FormulationKind::Index1,
                FormulationKind::Decoupled,
            ]
        };
        for &f in forms {
            let mut opts = model.default_options();
            opts.formulation = f;
            opts.joint_stiffness = 1e4;
            opts.output_times.truncate(2);
            // index 1 refuses redundant joints (Bricard): only GGL must solve every scene
            let sol = match model.solve(&opts) {
                Ok(sol) => sol,
                Err(e) if f != FormulationKind::Ggl && !model.is_raw_bond_graph() => {
                    eprintln!("{} {f:?}: {e}", path.display());
                    continue;
                }
                Err(e) => panic!("{}: {e}", path.display()),
            };
            assert_eq!(
                model.row_columns(&opts).unwrap(),
                sol.columns,
                "{} {f:?}",
                path.display()
            );
        }
    }
}

/// A step budget stops a solve at the same step every time: the rows the service returns with
/// its 422 are the rows the CLI writes when the same budget stops it.
#[test]
fn step_budget_rows_so_far_equal_the_clis_partial_rows() {
    let server = start(Config::default());
    let q = "formulation=decoupled&joint_stiffness=1e8&max_steps=3000";
    let p = post(
        server.addr(),
        &format!("/v1/run?{q}"),
        scene_text("double_pendulum.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["limit"], "solve.max_steps", "{p}");
    assert_eq!(p["limit_value"], 3000);
    let rows = json_rows(&p["rows"]);
    assert!(rows.len() >= 2, "{p}");
    let out =
        std::env::temp_dir().join(format!("bondmech-service-steps-{}.csv", std::process::id()));
    let (ok, _, err) = cli(&[
        "run",
        &scene_path("double_pendulum.json"),
        "--formulation",
        "decoupled",
        "--joint-stiffness",
        "1e8",
        "--max-steps",
        "3000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok, "the CLI stops on the budget too");
    assert!(err.contains("3000"), "{err}");
    let (header, cli_rows) = parse_csv(&std::fs::read_to_string(&out).unwrap());
    std::fs::remove_file(&out).ok();
    let cols: Vec<&str> = p["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(cols, header);
    assert_eq!(rows, cli_rows, "the same rows, bit for bit");
    server.shutdown().unwrap();
}

#[test]
fn reactions_query_equals_the_cli_reactions_flag() {
    assert_run_equals_cli(
        "double_pendulum.json",
        "t_end=0.1&reactions=true",
        &["--t-end", "0.1", "--reactions"],
    );
}

/// `POST /v1/equilibrium` is `bondmech equilibrium --json` (same document, value for value);
/// `POST /v1/run` carries a driven scene's driver columns as `run` does.
#[test]
fn equilibrium_route_equals_the_cli_json_and_run_carries_driver_columns() {
    let server = start(Config::default());
    let r = post(
        server.addr(),
        "/v1/equilibrium",
        scene_text("four_bar.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let j = r.json();
    let out = std::env::temp_dir().join(format!("bondmech-eq-{}.json", std::process::id()));
    let path = scene_path("four_bar.json");
    let (ok, _, err) = cli(&["equilibrium", &path, "--json", &out.display().to_string()]);
    assert!(ok, "{err}");
    let mut want: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    std::fs::remove_file(&out).ok();
    // the CPU time is each run's own
    let mut j = j;
    assert!(j["cpu_seconds"].as_f64().unwrap() >= 0.0, "{j}");
    j.as_object_mut().unwrap().remove("cpu_seconds");
    want.as_object_mut().unwrap().remove("cpu_seconds");
    assert_eq!(j, want);
    let r = post(
        server.addr(),
        "/v1/run",
        scene_text("slider_crank_driven.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let columns = r.json()["columns"].clone();
    let names: Vec<&str> = columns
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"motor.torque") && names.contains(&"motor.power"),
        "{names:?}"
    );
}

/// `POST /v1/linearize` is `bondmech linearize --json` (same document, value for value); a
/// malformed `at` is a 400 naming the parameter, an unknown output a 422 naming it.
#[test]
fn linearize_route_equals_the_cli_json_and_names_bad_parameters() {
    let server = start(Config::default());
    let scene = scene_text("four_bar.json");
    let r = post(
        server.addr(),
        "/v1/linearize?output=rocker.angle,coupler.B.y",
        scene.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let j = r.json();
    let out = std::env::temp_dir().join(format!("bondmech-lin-{}.json", std::process::id()));
    let path = scene_path("four_bar.json");
    let (ok, _, err) = cli(&[
        "linearize",
        &path,
        "--output",
        "rocker.angle",
        "--output",
        "coupler.B.y",
        "--json",
        &out.display().to_string(),
    ]);
    assert!(ok, "{err}");
    let mut want: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    std::fs::remove_file(&out).ok();
    // the CPU time is each run's own
    let mut j = j;
    assert!(j["cpu_seconds"].as_f64().unwrap() >= 0.0, "{j}");
    j.as_object_mut().unwrap().remove("cpu_seconds");
    want.as_object_mut().unwrap().remove("cpu_seconds");
    assert_eq!(j, want);
    assert_eq!(
        j["outputs"],
        serde_json::json!(["rocker.angle", "coupler.B.y"])
    );
    let p = post(server.addr(), "/v1/linearize?at=t%3Dsoon", scene.as_bytes()).problem(400);
    assert_eq!(p["parameter"], "at", "{p}");
    assert!(
        p["detail"]
            .as_str()
            .unwrap()
            .contains("'soon' is not a number"),
        "{p}"
    );
    let p = post(server.addr(), "/v1/linearize?output=nope", scene.as_bytes()).problem(422);
    assert_eq!(p["parameter"], "output", "{p}");
    // the query parameter by its name, not the CLI's flag
    let detail = p["detail"].as_str().unwrap();
    assert!(
        detail.contains("output 'nope'") && !detail.contains("--output"),
        "{p}"
    );
    server.shutdown().unwrap();
}

/// Issue 48: a scene `linearize` refuses (a raw bond graph; spatial rigid bodies, refused
/// before, are linearized now) is titled as a refusal, not "The solve failed", and an unknown
/// output names the query parameter `output`, not the CLI's flag.
#[test]
fn linearize_refusal_is_titled_as_one_and_names_the_query_parameter() {
    let server = start(Config::default());
    let p = post(
        server.addr(),
        "/v1/linearize",
        scene_text("bg_mass_spring_damper.json").as_bytes(),
    )
    .problem(422);
    assert_eq!(p["title"], "The scene cannot be linearized", "{p}");
    assert_eq!(p["type"], "urn:bondmech:problem:linearize-refused", "{p}");
    assert!(
        p["detail"].as_str().unwrap().contains("raw bond graph"),
        "{p}"
    );
    let p = post(
        server.addr(),
        "/v1/linearize?output=crank.angel",
        scene_text("four_bar.json").as_bytes(),
    )
    .problem(422);
    let detail = p["detail"].as_str().unwrap();
    assert!(
        detail.starts_with("output 'crank.angel'")
            && detail.contains("did you mean 'crank.angle'?"),
        "{p}"
    );
    server.shutdown().unwrap();
}
