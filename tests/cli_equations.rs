//! `bondmech equations`: the residual a scene is solved with, each constraint row named after
//! its joint, the bond graph's constraint junction and the inertia the row puts in
//! differential causality (the `element` names of `graph --causality`).

mod support;
use support::cli::{bondmech, scene};

fn stdout(args: &[&str]) -> String {
    let out = bondmech(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The differential inertias named by `equations` are exactly the ones `graph --causality`
/// reports, each against the junction its row comes from.
fn rows_match_causality(name: &str) {
    let eq = stdout(&["equations", &scene(name)]);
    assert!(
        eq.starts_with("equations   read off the bond graph"),
        "{eq}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&stdout(&["graph", &scene(name), "--causality"])).unwrap();
    let diff = report["differential"].as_array().unwrap();
    assert!(!diff.is_empty());
    for d in diff {
        let (element, origin) = (
            d["element"].as_str().unwrap(),
            d["origin"].as_str().unwrap(),
        );
        let tag = format!("[junction {origin}, differential {element}]");
        assert!(eq.contains(&tag), "{name}: no row tagged {tag} in\n{eq}");
    }
    // every constraint row is tagged, and each junction imposes its flow row
    let rows = eq.lines().filter(|l| l.contains("[junction ")).count();
    let flows = eq
        .split("junction flows")
        .nth(1)
        .map(|s| s.lines().filter(|l| l.ends_with("= 0")).count())
        .unwrap_or(0);
    assert_eq!(rows, flows, "{name}");
    assert_eq!(
        rows,
        diff.len() + report["redundant"].as_array().unwrap().len(),
        "{name}"
    );
}

#[test]
fn double_pendulum_rows_name_the_seed_junctions_and_inertias() {
    rows_match_causality("double_pendulum.json");
    let eq = stdout(&["equations", &scene("double_pendulum.json")]);
    // Fig. 20: the pivot's Sf = 0 and the knee's 1-junction take bar1's and bar2's translations
    assert!(
        eq.contains("pivot (x) [junction pivot.x, differential bar1.I_m_x]"),
        "{eq}"
    );
    assert!(
        eq.contains("knee (y) [junction knee.y, differential bar2.I_m_y]"),
        "{eq}"
    );
    // the knee's flow row is V_A(bar1) − V_O(bar2), in the scene's names
    let knee = eq
        .lines()
        .find(|l| l.trim_start().starts_with("knee.x:"))
        .unwrap();
    assert!(
        knee.contains("bar1.vx") && knee.contains("bar2.omega"),
        "{knee}"
    );
}

#[test]
fn slider_crank_and_andrews_rows_name_their_junctions() {
    rows_match_causality("slider_crank.json");
    rows_match_causality("andrews_squeezer.json");
    rows_match_causality("four_bar.json");
}

#[test]
fn equations_of_a_raw_bond_graph_are_refused_with_a_pointer() {
    let out = bondmech(&["equations", &scene("bg_dc_motor.json")]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("graph --causality"), "{err}");
}
