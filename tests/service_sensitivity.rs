//! `POST /v1/sensitivity` is `bondmech sensitivity` (the same CSV) and `POST /v1/fit` fits
//! data sent as columns in JSON; a bad path is a 422 naming `param`, bad data one naming `data`.

mod service_support;

use bondmech::service::Config;
use service_support::*;

const PARAM: &str = "bodies%5Bbar2%5D.mass";

fn short_pendulum() -> String {
    let mut v: serde_json::Value =
        serde_json::from_str(&scene_text("double_pendulum.json")).unwrap();
    v["solve"]["t_end"] = serde_json::json!(0.5);
    v["solve"]["output_step"] = serde_json::json!(0.05);
    v.to_string()
}

#[test]
fn sensitivity_route_equals_the_cli_csv() {
    let server = start(Config::default());
    let scene = short_pendulum();
    let r = post(
        server.addr(),
        &format!("/v1/sensitivity?param={PARAM}"),
        scene.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dp.json");
    std::fs::write(&path, &scene).unwrap();
    let out = dir.path().join("s.csv");
    let (ok, _, err) = cli(&[
        "sensitivity",
        path.to_str().unwrap(),
        "--param",
        "bodies[bar2].mass",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let want = std::fs::read_to_string(&out).unwrap();
    assert_eq!(r.text(), want);
    let (columns, rows) = parse_csv(&want);
    assert!(
        columns.contains(&"d(bar2.angle)/d(bodies[bar2].mass)".to_string()),
        "{columns:?}"
    );
    assert_eq!(rows.len(), 11);

    let p = post(
        server.addr(),
        "/v1/sensitivity?param=bodies%5Bbar9%5D.mass",
        scene.as_bytes(),
    )
    .problem(422);
    assert_eq!(p["parameter"], "param", "{p}");
    assert!(p["detail"].as_str().unwrap().contains("bar9"), "{p}");
    post(server.addr(), "/v1/sensitivity", scene.as_bytes()).problem(400);
    server.shutdown().unwrap();
}

#[test]
fn fit_route_fits_columns_sent_as_json() {
    let server = start(Config::default());
    let (m, k, c, x0): (f64, f64, f64, f64) = (2.0, 50.0, 1.5, 0.1);
    let a = c / (2.0 * m);
    let w = (k / m - a * a).sqrt();
    let t: Vec<f64> = (1..=40).map(|i| 0.05 * i as f64).collect();
    let x: Vec<f64> = t
        .iter()
        .map(|&t| x0 * (-a * t).exp() * ((w * t).cos() + a / w * (w * t).sin()))
        .collect();
    let scene = serde_json::json!({
        "name": "block", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [{"name": "block", "mass": m, "inertia": 0.01, "points": {"c": [0.0, 0.0]},
                    "position": [x0, 0.0], "angle": 0.0}],
        "joints": [{"name": "rail", "type": "prismatic", "bodies": ["ground", "block"],
                    "points": [[0.0, 0.0], "c"], "axis": [1.0, 0.0]}],
        "springs": [{"name": "s1", "bodies": ["ground", "block"], "points": [[0.0, 0.0], "c"],
                     "stiffness": 1.2 * k, "damping": c, "rest_length": 0.0}],
        "solve": {"t_end": 2.0, "output_step": 0.05, "rtol": 1e-9, "atol": 1e-11}
    });
    let body = serde_json::json!({"scene": scene, "data": {"t": t, "block.x": x}}).to_string();
    let r = post(
        server.addr(),
        "/v1/fit?param=springs%5Bs1%5D.stiffness",
        body.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let j = r.json();
    assert_eq!(j["converged"], true, "{j}");
    let kf = j["parameters"]["springs[s1].stiffness"].as_f64().unwrap();
    assert!((kf - k).abs() < 1e-4 * k, "{kf}");
    let bad =
        serde_json::json!({"scene": scene, "data": {"time": [0.1], "block.x": [0.0]}}).to_string();
    let p = post(
        server.addr(),
        "/v1/fit?param=springs%5Bs1%5D.stiffness",
        bad.as_bytes(),
    )
    .problem(422);
    assert_eq!(p["parameter"], "data", "{p}");
    assert!(
        p["detail"].as_str().unwrap().contains("no column 't'"),
        "{p}"
    );
    server.shutdown().unwrap();
}
