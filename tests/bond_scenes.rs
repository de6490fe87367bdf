//! The chapter's causality counts, now produced from scenes (16.1, 16.5, 16.7), and the link
//! between the bond graph and the DAE: one independent constraint row per differential inertia.

use bondmech::graph::SceneGraph;
use bondmech::mech::{build, Variant};
use bondmech::Scene;

fn counts(scene: &str, variant: Variant) -> (usize, usize) {
    let path = format!("{}/scenes/{scene}", env!("CARGO_MANIFEST_DIR"));
    let s = Scene::from_path(path).unwrap();
    let r = SceneGraph::new(&s, variant).unwrap().report();
    assert!(r.conflicts.is_empty(), "{scene}: {:?}", r.conflicts);
    (r.integral_inertias, r.differential.len())
}

#[test]
fn rigid_body_ejs_has_six_integral_inertias() {
    assert_eq!(counts("free_body_3d.json", Variant::Pinned), (6, 0));
}

#[test]
fn two_hinged_bars_have_four_integral_two_differential() {
    assert_eq!(counts("two_bars.json", Variant::Pinned), (4, 2));
}

#[test]
fn double_pendulum_has_two_integral_four_differential() {
    assert_eq!(counts("double_pendulum.json", Variant::Pinned), (2, 4));
}

#[test]
fn decoupled_double_pendulum_has_six_integral_inertias() {
    assert_eq!(counts("double_pendulum.json", Variant::Decoupled), (6, 0));
}

#[test]
fn decoupled_two_bars_have_six_integral_inertias() {
    assert_eq!(counts("two_bars.json", Variant::Decoupled), (6, 0));
}

#[test]
fn differential_inertias_match_constraint_rows_of_every_planar_scene() {
    for scene in [
        "pendulum.json",
        "pendulum_point_mass.json",
        "two_bars.json",
        "double_pendulum.json",
        "slider_crank.json",
        "four_bar.json",
    ] {
        let path = format!("{}/scenes/{scene}", env!("CARGO_MANIFEST_DIR"));
        let s = Scene::from_path(path).unwrap();
        let sys = build(&s).unwrap();
        let r = SceneGraph::new(&s, Variant::Pinned).unwrap().report();
        // DOF by Grübler from the multibody system = integral inertias of the bond graph
        let dof = sys.nv() - sys.nc();
        assert_eq!((r.integral_inertias, r.dof), (dof, dof), "{scene}: {r:?}");
    }
}

#[test]
fn graph_dot_marks_differential_inertias_in_red() {
    let path = format!("{}/scenes/double_pendulum.json", env!("CARGO_MANIFEST_DIR"));
    let s = Scene::from_path(path).unwrap();
    let dot = SceneGraph::new(&s, Variant::Pinned).unwrap().dot();
    assert!(dot.starts_with("digraph"), "{}", &dot[..40.min(dot.len())]);
    assert!(
        dot.matches("red").count() >= 4,
        "four differential inertias drawn in red"
    );
}

/// A planar scene file with every body written in its body-fixed frame (seed 16.3).
fn body_frame_scene(scene: &str, only: Option<&str>) -> Scene {
    let path = format!("{}/scenes/{scene}", env!("CARGO_MANIFEST_DIR"));
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for b in v["bodies"].as_array_mut().unwrap() {
        if only.is_none_or(|n| b["name"] == n) {
            b["frame"] = "body".into();
        }
    }
    Scene::from_json_str(&v.to_string()).unwrap()
}

fn graph_counts(s: &Scene, variant: Variant) -> (usize, usize) {
    let r = SceneGraph::new(s, variant).unwrap().report();
    assert!(r.conflicts.is_empty(), "{}: {:?}", s.name, r.conflicts);
    (r.integral_inertias, r.differential.len())
}

#[test]
fn body_frame_bars_keep_the_seed_counts_and_the_multibody_rank() {
    // 16.5: two hinged bars 4 + 2; 16.7: double pendulum 2 + 4; decoupled: all 6 integral;
    // with all bars body-fixed and with one bar body-fixed next to a non-rotating one
    for (scene, only, expected) in [
        ("two_bars.json", None, (4, 2)),
        ("double_pendulum.json", None, (2, 4)),
        ("two_bars.json", Some("bar2"), (4, 2)),
        ("double_pendulum.json", Some("bar1"), (2, 4)),
        // 3 bodies × 3 velocities; 3 pins × 2 rows + the cylinder's normal and angle rows
        ("slider_crank.json", None, (1, 8)),
        // 3 bars, 4 pins × 2 rows
        ("four_bar.json", None, (1, 8)),
    ] {
        let s = body_frame_scene(scene, only);
        assert_eq!(
            graph_counts(&s, Variant::Pinned),
            expected,
            "{scene} {only:?}"
        );
        let n = expected.0 + expected.1;
        assert_eq!(
            graph_counts(&s, Variant::Decoupled),
            (n, 0),
            "{scene} {only:?}"
        );
        let d = bondmech::Model::new(&s).unwrap().dof().unwrap();
        assert_eq!(
            (d.dof, d.rank),
            expected,
            "{scene} {only:?}: multibody system"
        );
    }
}

#[test]
fn hinge_between_body_frame_bars_changes_frame_by_the_relative_angle() {
    // seed 16.4–16.5 (Fig. 9–10, 15): the velocity of A in bar 1's axes reaches the hinge's
    // 1-junctions only through MTFs modulated by the relative angle α2 − α1, never directly.
    // This is the chapter's drawing (`mech::scene_bond_graph`): its rows hold in the rotated
    // axes only on the joint (d/dt of no closure at other states), so the graph the solver
    // reads writes the rows of body-fixed bars in the global axes (see bond_graph_model.rs).
    let s = body_frame_scene("two_bars.json", None);
    let g = bondmech::mech::scene_bond_graph(&s, Variant::Pinned).unwrap();
    let id = |n: &str| {
        g.elements
            .iter()
            .position(|e| e.name == n)
            .unwrap_or_else(|| panic!("{n} missing"))
    };
    let neighbours = |i: usize| -> Vec<&str> {
        g.bonds
            .iter()
            .filter_map(|b| {
                if b.from.0 == i {
                    Some(b.to.0)
                } else if b.to.0 == i {
                    Some(b.from.0)
                } else {
                    None
                }
            })
            .map(|k| g.elements[k].name.as_str())
            .collect()
    };
    let rel = "x_bar2.omega - x_bar1.omega";
    let mtfs: Vec<&bondmech::bond::model::Element> = g
        .elements
        .iter()
        .filter(|e| {
            e.kind == bondmech::bond::model::ElementKind::MTF
                && matches!(&e.parameter, Some(bondmech::bond::model::Parameter::Expr(x)) if x.contains(rel))
        })
        .collect();
    // u' = cosθ u + sinθ v, v' = −sinθ u + cosθ v: four MTFs
    assert_eq!(
        mtfs.len(),
        4,
        "{:?}",
        mtfs.iter().map(|e| &e.name).collect::<Vec<_>>()
    );
    for axis in ["x", "y"] {
        let row = neighbours(id(&format!("hinge.{axis}")));
        assert!(
            row.contains(&format!("bar2.A.v_{axis}").as_str()),
            "hinge.{axis} meets bar 2's A: {row:?}"
        );
        assert!(
            !row.contains(&format!("bar1.A.v_{axis}").as_str()),
            "hinge.{axis} must not equate bar 1's body-frame components directly: {row:?}"
        );
        // bar 1's A feeds both frame-change MTFs of its component
        let from_a = neighbours(id(&format!("bar1.A.v_{axis}")));
        assert_eq!(
            from_a
                .iter()
                .filter(|n| n.contains(".in_bar2.mtf_"))
                .count(),
            2,
            "{from_a:?}"
        );
    }
}

#[test]
fn bar_welded_to_ground_has_three_differential_inertias_and_no_conflict() {
    // a weld to ground fixes x, y and the angle: 3 velocities, 3 independent rows, 0 DOF
    let s = Scene::from_json_str(
        r#"{"name":"w","dimension":2,"gravity":[0,-9.81],
            "bodies":[{"name":"bar","mass":1,"inertia":0.1,"points":{"O":[-0.5,0]},"position":[0.5,0]}],
            "joints":[{"name":"glue","type":"weld","bodies":["ground","bar"],"points":[[0,0],"O"]}],
            "solve":{"t_end":1,"output_step":0.1},"outputs":["energy"]}"#,
    )
    .unwrap();
    assert_eq!(graph_counts(&s, Variant::Pinned), (0, 3));
    let d = bondmech::Model::new(&s).unwrap().dof().unwrap();
    assert_eq!((d.dof, d.rank), (0, 3));
}
