//! The service side of the workbench page (issue 50): a streamed run draws its animation from
//! its own rows (`/v1/run?format=ndjson&animate=svg|view3d`: no second solve), and a streamed
//! comparison solves the DAE and the twin once each, with progress, and sends the twin's rows
//! and motion (`/v1/compare?format=ndjson&animate=svg`). References owe nothing to the
//! service: the command line's `run` CSV, `animate --csv` of that CSV, and `compare --json`.

mod service_support;

use bondmech::service::Config;
use serde_json::Value;
use service_support::*;

fn lines(text: &str) -> Vec<Value> {
    text.lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect()
}

fn tmp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("bondmech-workbench-{}-{name}", std::process::id()))
}

/// The command line's animation of the rows `bondmech run` wrote for `scene` (with `flags`),
/// drawn by `animate --csv` (no solve).
fn cli_animation_of_csv(scene: &str, flags: &[&str], ext: &str) -> String {
    let stem: String = format!("{scene}{}", flags.join(""))
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let csv = tmp(&format!("{stem}.csv"));
    let out = tmp(&format!("{stem}.{ext}"));
    let mut args = vec!["run", scene, "--out"];
    let csv_s = csv.display().to_string();
    args.push(&csv_s);
    args.extend_from_slice(flags);
    let (ok, _, err) = cli(&args);
    assert!(ok, "{err}");
    let out_s = out.display().to_string();
    let (ok, _, err) = cli(&["animate", scene, "--csv", &csv_s, "--out", &out_s]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&csv).ok();
    std::fs::remove_file(&out).ok();
    text
}

#[test]
fn a_streamed_run_draws_its_animation_from_its_own_rows() {
    let server = start(Config::default());
    let path = scene_path("double_pendulum.json");
    let before = get(server.addr(), "/metrics").text();
    let solves_before = metric(&before, "bondmech_solve_seconds_count").unwrap_or(0.0);
    let r = post(
        server.addr(),
        "/v1/run?format=ndjson&animate=svg",
        scene_text("double_pendulum.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let l = lines(&r.text());
    let n = l[0]["rows"].as_u64().unwrap() as usize;
    // columns, n rows, the animation, the summary
    assert_eq!(l.len(), n + 3);
    assert!(l[1..=n].iter().all(Value::is_array));
    let anim = &l[n + 1]["animation"];
    assert_eq!(anim["format"], "svg", "{anim}");
    assert!(l[n + 2]["summary"]["steps"].as_u64().unwrap() > 0);
    // the picture `bondmech animate --csv` draws from the rows `bondmech run` writes: the same
    let svg = anim["svg"].as_str().unwrap();
    let reference = cli_animation_of_csv(&path, &[], "svg");
    assert_eq!(
        svg, reference,
        "the run's animation is the CLI's of the run's CSV"
    );
    let bodies: std::collections::BTreeSet<&str> = svg
        .match_indices("data-body=\"")
        .map(|(i, m)| {
            let rest = &svg[i + m.len()..];
            &rest[..rest.find('"').unwrap()]
        })
        .collect();
    assert_eq!(bodies.len(), 2, "two bodies drawn ({bodies:?})");
    // one solve, not two
    let after = get(server.addr(), "/metrics").text();
    let solves_after = metric(&after, "bondmech_solve_seconds_count").unwrap_or(0.0);
    assert!(
        solves_after - solves_before <= 1.0,
        "one solve for the run and its animation ({solves_before} → {solves_after})"
    );
    server.shutdown().unwrap();
}

#[test]
fn a_spatial_run_sends_the_3d_view_of_its_rows_and_bad_animate_values_are_refused() {
    let server = start(Config::default());
    let r = post(
        server.addr(),
        "/v1/run?format=ndjson&animate=view3d&t_end=0.5",
        scene_text("hinged_double_pendulum_3d.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let l = lines(&r.text());
    let n = l[0]["rows"].as_u64().unwrap() as usize;
    let data = &l[n + 1]["animation"]["data"];
    assert_eq!(l[n + 1]["animation"]["format"], "view3d");
    let t = data["t"].as_array().unwrap();
    assert_eq!(t.first().unwrap().as_f64(), Some(0.0));
    assert_eq!(t.last().unwrap().as_f64(), Some(0.5));
    assert_eq!(data["bodies"].as_array().unwrap().len(), 2);
    // a planar scene has no 3D view: said on the animation's line, the run itself succeeds
    let r = post(
        server.addr(),
        "/v1/run?format=ndjson&animate=view3d&t_end=0.1",
        scene_text("pendulum.json").as_bytes(),
    );
    assert_eq!(r.status, 200);
    let l = lines(&r.text());
    let n = l[0]["rows"].as_u64().unwrap() as usize;
    let detail = l[n + 1]["animation"]["error"]["detail"].as_str().unwrap();
    assert!(detail.contains("spatial scene"), "{detail}");
    assert!(l[n + 2]["summary"].is_object());
    // a raw bond graph has no geometry: said, and the run goes on
    let r = post(
        server.addr(),
        "/v1/run?format=ndjson&animate=svg",
        scene_text("bg_dc_motor.json").as_bytes(),
    );
    let l = lines(&r.text());
    let n = l[0]["rows"].as_u64().unwrap() as usize;
    let detail = l[n + 1]["animation"]["error"]["detail"].as_str().unwrap();
    assert!(detail.contains("no geometry"), "{detail}");
    // an unknown value is a 400 naming it; animate without ndjson is a 422 naming the format
    let scene = scene_text("pendulum.json");
    let p = post(
        server.addr(),
        "/v1/run?format=ndjson&animate=gif",
        scene.as_bytes(),
    )
    .problem(400);
    assert!(
        p["detail"].as_str().unwrap().contains("svg or view3d"),
        "{p}"
    );
    let p = post(server.addr(), "/v1/run?animate=svg", scene.as_bytes()).problem(422);
    assert!(
        p["detail"].as_str().unwrap().contains("format=ndjson"),
        "{p}"
    );
    assert_eq!(p["parameter"], "animate");
    server.shutdown().unwrap();
}

#[test]
fn a_streamed_comparison_solves_each_once_with_progress_and_sends_the_twin() {
    let server = start(Config::default());
    let path = scene_path("four_bar.json");
    let scene = scene_text("four_bar.json");
    let before = metric(
        &get(server.addr(), "/metrics").text(),
        "bondmech_solve_seconds_count",
    )
    .unwrap_or(0.0);
    let r = post(
        server.addr(),
        "/v1/compare?format=ndjson&animate=svg&t_end=1",
        scene.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("application/x-ndjson"));
    let l = lines(&r.text());
    // progress of the DAE, then of the twin, each from 0 to all the rows
    let progress: Vec<(String, u64, u64)> = l
        .iter()
        .filter_map(|v| v.get("progress"))
        .map(|p| {
            (
                p["solve"].as_str().unwrap().to_string(),
                p["rows"].as_u64().unwrap(),
                p["of"].as_u64().unwrap(),
            )
        })
        .collect();
    let (_, cli_csv_twin, _) = cli(&["run", &path, "--t-end", "1", "--formulation", "decoupled"]);
    let (header, twin_rows) = parse_csv(&cli_csv_twin);
    let n = twin_rows.len() as u64;
    assert!(progress.iter().any(|p| p.0 == "dae" && p.1 == 0));
    assert!(progress.iter().any(|p| p.0 == "dae" && p.1 > 0 && p.1 < n));
    assert!(progress.iter().any(|p| p.0 == "twin" && p.1 == 0));
    assert!(progress
        .iter()
        .any(|p| p.0 == "twin" && p.1 == n && p.2 == n));
    let first_twin = progress.iter().position(|p| p.0 == "twin").unwrap();
    assert!(progress[..first_twin].iter().all(|p| p.0 == "dae"));
    // the twin's rows: the command line's decoupled run, value for value
    let twin = l
        .iter()
        .find_map(|v| v.get("twin"))
        .expect("the twin's run");
    let cols: Vec<&str> = twin["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(cols, header);
    assert_eq!(json_rows(&twin["rows"]), twin_rows);
    // its motion: `animate --csv` of that CSV
    let svg = l
        .iter()
        .find_map(|v| v.get("twin_animation"))
        .expect("the twin's animation")["svg"]
        .as_str()
        .unwrap()
        .to_string();
    let reference = cli_animation_of_csv(
        &path,
        &["--t-end", "1", "--formulation", "decoupled"],
        "svg",
    );
    assert_eq!(svg, reference);
    // the verdict last, as `compare --json` gives it
    let cmp = &l.last().unwrap()["compare"];
    let cmp_file = tmp("four_bar_compare.json");
    let cmp_s = cmp_file.display().to_string();
    let (ok, _, err) = cli(&["compare", &path, "--t-end", "1", "--json", &cmp_s]);
    assert!(ok, "{err}");
    let cli_cmp: Value =
        serde_json::from_str(&std::fs::read_to_string(&cmp_file).unwrap()).unwrap();
    std::fs::remove_file(&cmp_file).ok();
    assert_eq!(
        cmp["verdict"]["recommended"],
        cli_cmp["verdict"]["recommended"]
    );
    assert_eq!(
        cmp["verdict"]["max_position_difference"],
        cli_cmp["verdict"]["max_position_difference"]
    );
    // two solves in all (the DAE and the twin)
    let after = metric(
        &get(server.addr(), "/metrics").text(),
        "bondmech_solve_seconds_count",
    )
    .unwrap_or(0.0);
    assert!(after - before <= 2.0, "{before} → {after}");
    // a raw bond graph has no twin: an ordinary error answer before any line
    let p = post(
        server.addr(),
        "/v1/compare?format=ndjson",
        scene_text("bg_dc_motor.json").as_bytes(),
    )
    .problem(422);
    assert!(
        p["detail"].as_str().unwrap().contains("decoupled twin"),
        "{p}"
    );
    server.shutdown().unwrap();
}
