//! The chapter's causality counts, now produced from scenes (16.1, 16.5, 16.7), and the link
//! between the bond graph and the DAE: one independent constraint row per differential inertia.

use bondmech::graph::SceneGraph;
use bondmech::mech::{assemble, Variant};
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
        let sys = assemble(&s).unwrap();
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
