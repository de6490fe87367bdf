//! `sweep --quick` on the bundled scenes: the scene's own horizon (at most 1 s), every point
//! bounded in wall clock, a point that fails reported in the JSON and left out of the plots'
//! legends, exit status 0.
//!
//! `quick_sweep_of_every_bundled_scene_within_30_s` runs them all (about 25 s in a debug build
//! on a 2-core machine) and is `#[ignore]`d for CI: `cargo test --test sweep_quick_scenes --
//! --ignored`.

mod support;

use std::time::Instant;

use serde_json::Value;
use support::cli::{bondmech, scene, tmp};

/// Runs `sweep --quick` on a bundled scene; returns its seconds and the report.
fn quick(file: &str) -> (f64, Value, String) {
    let dir = tmp(&format!("quick-{file}"));
    let start = Instant::now();
    let out = bondmech(&[
        "sweep",
        &scene(file),
        "--quick",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let secs = start.elapsed().as_secs_f64();
    assert!(
        out.status.success(),
        "sweep --quick {file}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap();
    let svg = std::fs::read_to_string(dir.join("work_precision.svg")).unwrap();
    (secs, report, svg)
}

/// Series whose every point failed do not appear in the plot's legend.
fn check_legend(file: &str, report: &Value, svg: &str) {
    let wp = report["work_precision"].as_array().unwrap();
    let mut series: Vec<&str> = wp.iter().map(|w| w["series"].as_str().unwrap()).collect();
    series.dedup();
    for s in series {
        let ok = wp
            .iter()
            .any(|w| w["series"] == s && w["failure"].is_null());
        let in_legend =
            svg.contains(&format!(">\n{s}\n</text>")) || svg.contains(&format!(">{s}</text>"));
        assert_eq!(
            ok, in_legend,
            "{file}: series {s} has usable points: {ok}, in the legend: {in_legend}"
        );
    }
}

#[test]
fn quick_sweep_keeps_the_scenes_own_short_horizon() {
    // Andrews' squeezer lasts 0.03 s: a quick sweep used to force 1 s and fail
    let (_, report, svg) = quick("andrews_squeezer.json");
    assert!(
        (report["t_end"].as_f64().unwrap() - 0.03).abs() < 1e-12,
        "{}",
        report["t_end"]
    );
    check_legend("andrews_squeezer.json", &report, &svg);
}

#[test]
fn quick_sweep_runs_up_to_a_reference_stopped_part_way() {
    // the tight GGL reference of the chain of four-bars stops at a singular passage
    let (_, report, svg) = quick("four_bar_chain_3.json");
    let t_end = report["t_end"].as_f64().unwrap();
    assert!(t_end > 0.1 && t_end < 1.0, "t_end {t_end}");
    assert!(report["reference_source"]
        .as_str()
        .unwrap()
        .contains("stopped part-way"));
    check_legend("four_bar_chain_3.json", &report, &svg);
}

#[test]
#[ignore = "about 25 s: every bundled scene"]
fn quick_sweep_of_every_bundled_scene_within_30_s() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json") && !n.starts_with("bg_"))
        .collect();
    names.sort();
    for name in &names {
        let (secs, report, svg) = quick(name);
        eprintln!(
            "sweep --quick {name}: {secs:.1} s (t_end {})",
            report["t_end"]
        );
        assert!(secs <= 30.0, "{name}: {secs} s");
        check_legend(name, &report, &svg);
    }
}
