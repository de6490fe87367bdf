//! `compare --json` ends in a verdict: the decoupled twin is recommended only where it is both
//! cheaper than the DAE and within the scene's tolerance. The test recomputes the verdict's
//! inputs from the document's own run summaries and the tolerance from an independent `run` of
//! the scene (its CSV's largest position coordinate, the scene's rtol and atol).

mod support;

use serde_json::Value;
use support::cli::{bondmech, scene, tmp};

fn compare(k: &str) -> (Value, String) {
    let json = tmp(&format!("verdict-{k}.json"));
    let out = bondmech(&[
        "compare",
        &scene("double_pendulum.json"),
        "--joint-stiffness",
        k,
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// The largest |x| or |y| of the double pendulum's motion, from `run`'s CSV.
fn extent() -> f64 {
    let csv = tmp("verdict-run.csv");
    let out = bondmech(&[
        "run",
        &scene("double_pendulum.json"),
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let pos: Vec<usize> = (0..header.len())
        .filter(|&c| header[c].ends_with(".x") || header[c].ends_with(".y"))
        .collect();
    lines
        .flat_map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            pos.iter().map(|&c| v[c].abs()).collect::<Vec<_>>()
        })
        .fold(0.0, f64::max)
}

#[test]
fn compare_verdict_recommends_the_twin_only_when_cheaper_and_within_tolerance() {
    let (rtol, atol) = (1e-8, 1e-10); // the scene's solve settings
    let tolerance = atol + rtol * extent();
    for k in ["1e4", "1e8"] {
        let (doc, table) = compare(k);
        let v = &doc["verdict"];
        let f = |x: &Value| {
            x.as_f64()
                .unwrap_or_else(|| panic!("k = {k}: {x} is a number"))
        };
        let cpu = f(&doc["decoupled"]["cpu_seconds"]) / f(&doc["dae"]["cpu_seconds"]);
        let steps = f(&doc["decoupled"]["steps"]) / f(&doc["dae"]["steps"]);
        assert!(
            (f(&v["cpu_ratio"]) - cpu).abs() <= 1e-9 * cpu,
            "k = {k}: {v}"
        );
        assert!((f(&v["steps_ratio"]) - steps).abs() <= 1e-9 * steps);
        let d = f(&v["max_position_difference"]);
        assert_eq!(d, f(&doc["position"]["value"]));
        assert!(
            (f(&v["position_tolerance"]) - tolerance).abs() <= 1e-3 * tolerance,
            "k = {k}: tolerance {} against atol + rtol·L = {tolerance}",
            v["position_tolerance"]
        );
        let recommended = v["recommended"].as_str().unwrap();
        assert!(recommended == "dae" || recommended == "decoupled");
        let twin_wins = cpu < 1.0 && d <= tolerance;
        assert_eq!(
            recommended == "decoupled",
            twin_wins,
            "k = {k}: {v} (cpu ratio {cpu}, difference {d} m, tolerance {tolerance} m)"
        );
        assert!(!v["reason"].as_str().unwrap().is_empty());
        assert!(
            table.contains(&format!("verdict: use {recommended}")),
            "{table}"
        );
        // no reactions were computed: their differences are null, not 0
        assert!(
            doc["force"].is_null() && doc["moment"].is_null(),
            "{}",
            doc["force"]
        );
        assert!(doc["decoupled_energy_note"]
            .as_str()
            .unwrap()
            .contains("joint springs"));
    }
    // at k = 1e4 the twin is centimetres off; at 1e8 it is costly: the DAE either way
    assert_eq!(compare("1e4").0["verdict"]["recommended"], "dae");
}

#[test]
fn compare_reports_reaction_differences_when_computed() {
    let json = tmp("verdict-reactions.json");
    let out = bondmech(&[
        "compare",
        &scene("double_pendulum.json"),
        "--t-end",
        "0.5",
        "--reactions",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert!(
        doc["force"]["value"].as_f64().unwrap() > 0.0,
        "{}",
        doc["force"]
    );
    assert!(doc["moment"].is_null(), "pins transmit no moment");
}
