//! `--reactions` and scene events on the command line: the reaction columns in the CSV, a
//! `stop` event ending the run successfully with its row last, `summary.events`, and bad
//! events refused with the JSON path.

mod support;

use serde_json::{json, Value};
use support::cli::{bondmech, scene, tmp};

/// `scenes/pendulum.json` (a 1 m, 1 kg bar released horizontal) with `events`.
fn pendulum_with(events: Value, name: &str) -> String {
    let text = std::fs::read_to_string(scene("pendulum.json")).unwrap();
    let mut v: Value = serde_json::from_str(&text).unwrap();
    v["events"] = events;
    let path = tmp(name);
    std::fs::write(&path, v.to_string()).unwrap();
    path.display().to_string()
}

#[test]
fn run_reactions_and_stop_event() {
    let events =
        json!([{ "name": "vertical", "when": "bar.x", "direction": "falling", "action": "stop" }]);
    let file = pendulum_with(events, "pendulum_stop.json");
    let (csv, sum) = (tmp("stop.csv"), tmp("stop.json"));
    let out = bondmech(&[
        "run",
        &file,
        "--reactions",
        "--rtol",
        "1e-10",
        "--atol",
        "1e-12",
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
    let at = |c: &str| header.iter().position(|h| *h == c).unwrap();
    // the pin's columns, before constraint_error; a pin has no moment column
    assert!(at("pivot.Fx") < at("constraint_error") && at("pivot.Fy") == at("pivot.Fx") + 1);
    assert!(!header.contains(&"pivot.Mz"));
    let last: Vec<f64> = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
    let events = summary["events"].as_array().unwrap();
    assert_eq!(events.len(), 1);
    assert_eq!(events[0]["name"], "vertical");
    // the last row is the event's, the bar vertical, the pin carrying 2.5 m g (tests/reactions.rs)
    assert_eq!(last[0], events[0]["t"].as_f64().unwrap());
    assert!(last[at("bar.x")].abs() < 1e-9);
    assert!((last[at("pivot.Fy")] - 2.5 * 9.81).abs() < 1e-5);
}

#[test]
fn bad_event_direction_exits_non_zero_naming_the_path() {
    let events = json!([{ "when": "bar.x", "direction": "downwards" }]);
    let file = pendulum_with(events, "pendulum_bad.json");
    let out = bondmech(&["run", &file, "--table"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("events[0].direction"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}
