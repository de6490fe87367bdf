//! The bond graph of jointed 3D mechanisms (seed 16.1–16.2 bodies, 16.5–16.7 joints): its SCAP
//! causality gives one integral inertia per degree of freedom and one differential inertia per
//! independent constraint row. Two independent references: the count by hand written in each
//! case (inertias: 6 per rigid body, 3 per point mass; rows: spherical 3, hinge 5, prismatic 5
//! (2 to a point mass), weld 6) and the multibody system's own count (velocities and the rank
//! of the velocity constraint Jacobian at the consistent initial state, `Model::dof`).

use bondmech::graph::SceneGraph;
use bondmech::mech::Variant;
use bondmech::{Model, Scene};

/// A rigid bar along body x (1 m, 1 kg) with points O (−0.5, 0, 0) and A (0.5, 0, 0).
fn bar(name: &str, x: f64) -> String {
    format!(
        r#"{{"name":"{name}","mass":1.0,"inertia":[0.02,0.0833,0.0833],
            "points":{{"O":[-0.5,0,0],"A":[0.5,0,0]}},"position":[{x},0,0],"cardan":[0,0,0]}}"#
    )
}

fn scene(name: &str, bodies: &[String], joints: &str) -> Scene {
    let json = format!(
        r#"{{"name":"{name}","dimension":3,"gravity":[0,0,-9.81],"bodies":[{}],"joints":[{joints}],
            "solve":{{"t_end":1.0,"output_step":0.1}},"outputs":["energy"]}}"#,
        bodies.join(",")
    );
    Scene::from_json_str(&json).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// (inertias, integral, differential) of the bond graph's causality report.
fn counts(s: &Scene, variant: Variant) -> (usize, usize, usize) {
    let r = SceneGraph::new(s, variant)
        .unwrap_or_else(|e| panic!("{}: {e}", s.name))
        .report();
    // the only over-determined junctions allowed are the redundant rows the report names
    // (Bricard's geometry: one hinge row; the multibody count says the same, see below): the
    // row's own 1-junction, or the junction its Sf = 0 holds
    for c in &r.conflicts {
        assert!(
            r.redundant
                .iter()
                .any(|x| x.junction == c.junction || c.elements.contains(&x.junction)),
            "{}: {:?} (redundant: {:?})",
            s.name,
            r.conflicts,
            r.redundant
        );
    }
    assert_eq!(r.conflicts.len(), r.redundant.len(), "{}", s.name);
    let inertias = r.storages.iter().filter(|x| x.kind == "I").count();
    (inertias, r.integral_inertias, r.differential.len())
}

/// Checks the hand count, the multibody count and the decoupled twin.
fn check(s: &Scene, inertias: usize, dof: usize) {
    let (n, integral, differential) = counts(s, Variant::Pinned);
    assert_eq!(
        (n, integral, differential),
        (inertias, dof, inertias - dof),
        "{}: bond graph vs hand count",
        s.name
    );
    let d = Model::new(s).unwrap().dof().unwrap();
    assert_eq!(
        (d.velocities, d.dof, d.rank),
        (n, integral, differential),
        "{}: multibody system vs bond graph",
        s.name
    );
    assert_eq!(
        counts(s, Variant::Decoupled),
        (inertias, inertias, 0),
        "{}: decoupled twin",
        s.name
    );
}

#[test]
fn spherical_bar_pendulum_has_three_integral_three_differential() {
    let s = scene(
        "spherical_bar",
        &[bar("bar", 0.5)],
        r#"{"name":"ball","type":"spherical","bodies":["ground","bar"],"points":[[0,0,0],"O"]}"#,
    );
    check(&s, 6, 3);
}

#[test]
fn hinged_double_pendulum_3d_has_two_integral_ten_differential() {
    let path = format!(
        "{}/scenes/hinged_double_pendulum_3d.json",
        env!("CARGO_MANIFEST_DIR")
    );
    check(&Scene::from_path(path).unwrap(), 12, 2);
}

#[test]
fn free_body_3d_scene_keeps_six_integral_inertias() {
    let path = format!("{}/scenes/free_body_3d.json", env!("CARGO_MANIFEST_DIR"));
    check(&Scene::from_path(path).unwrap(), 6, 6);
}

#[test]
fn block_on_prismatic_rail_has_one_integral_five_differential() {
    let s = scene(
        "rail",
        &[bar("block", 0.0)],
        r#"{"name":"rail","type":"prismatic","bodies":["ground","block"],"points":[[0,0,0],[0,0,0]],"axis":[1,1,0]}"#,
    );
    check(&s, 6, 1);
}

#[test]
fn point_mass_on_spherical_joint_at_bar_tip_has_three_integral() {
    let s = scene(
        "rod_and_bob",
        &[
            bar("bar", 0.5),
            r#"{"name":"bob","mass":0.5,"inertia":[0,0,0],"position":[1,0,0]}"#.into(),
        ],
        r#"{"name":"ball","type":"spherical","bodies":["ground","bar"],"points":[[0,0,0],"O"]},
           {"name":"tip","type":"spherical","bodies":["bar","bob"],"points":["A",[0,0,0]]}"#,
    );
    // 6 + 3 inertias, 3 + 3 rows
    check(&s, 9, 3);
}

#[test]
fn bar_welded_to_hinged_bar_has_one_integral() {
    let s = scene(
        "welded",
        &[bar("bar1", 0.5), bar("bar2", 1.5)],
        r#"{"name":"pivot","type":"revolute","bodies":["ground","bar1"],"points":[[0,0,0],"O"],"axis":[0,1,0]},
           {"name":"glue","type":"weld","bodies":["bar1","bar2"],"points":["A","O"]}"#,
    );
    // 12 inertias, 5 + 6 rows
    check(&s, 12, 1);
}

#[test]
fn bead_sliding_on_hinged_arm_has_two_integral() {
    let s = scene(
        "bead_on_arm",
        &[
            bar("arm", 0.5),
            r#"{"name":"bead","mass":0.2,"inertia":[0,0,0],"position":[0.5,0,0]}"#.into(),
        ],
        r#"{"name":"pivot","type":"revolute","bodies":["ground","arm"],"points":[[0,0,0],"O"],"axis":[0,0,1]},
           {"name":"slide","type":"prismatic","bodies":["arm","bead"],"points":[[0,0,0],[0,0,0]],"axis":[1,0,0]}"#,
    );
    // 6 + 3 inertias, 5 + 2 rows (a point mass has no rotation to fix)
    check(&s, 9, 2);
}

#[test]
fn spatial_joints_are_drawn_with_named_rows() {
    let path = format!(
        "{}/scenes/hinged_double_pendulum_3d.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let s = Scene::from_path(path).unwrap();
    let g = SceneGraph::new(&s, Variant::Pinned).unwrap();
    let names: Vec<&str> = g.graph.elements.iter().map(|e| e.name.as_str()).collect();
    for n in [
        "bar1.I_m_x",
        "bar1.I_J_z",
        "bar1.mgy_wyz",
        // the attitude quaternion: junctions fed by MTFs from ω modulated by e (16.2)
        "bar1.e0.rate",
        "bar2.e3.m2",
        // every joint row: a modulated sum of the bodies' flows held at zero by an Sf
        "knee.x.sum",
        "knee.x.v",
        "pivot.x",
        "pivot.axis1",
        "knee.z",
        "knee.axis2",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    let dot = g.dot();
    assert!(
        dot.contains("knee.axis1"),
        "the drawing names the hinge rows"
    );
}

#[test]
fn every_spatial_scene_file_counts_like_its_multibody_system() {
    let dir = format!("{}/scenes", env!("CARGO_MANIFEST_DIR"));
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let s = Scene::from_path(&path).unwrap();
        if s.bond_graph.is_some() || s.dimension != bondmech::scene::Dimension::Spatial {
            continue;
        }
        let d = Model::new(&s).unwrap().dof().unwrap();
        // no scene is skipped any more: the causality follows the numeric rank of the
        // constraint rows at the initial configuration, so a mechanism redundant by geometry
        // (Bricard's: Grübler 0, mobility 1) counts like its multibody system too
        let (n, integral, differential) = counts(&s, Variant::Pinned);
        assert_eq!(
            (d.velocities, d.dof, d.rank),
            (n, integral, differential),
            "{}",
            path.display()
        );
        assert_eq!(
            counts(&s, Variant::Decoupled),
            (n, n, 0),
            "{}",
            path.display()
        );
        seen += 1;
    }
    assert!(seen >= 2, "the spatial scenes of scenes/ were found");
}

#[test]
fn hinge_on_a_point_mass_is_refused_naming_the_joint_body() {
    let s = scene(
        "bad",
        &[r#"{"name":"bob","mass":0.5,"inertia":[0,0,0],"position":[1,0,0]}"#.into()],
        r#"{"name":"pivot","type":"revolute","bodies":["ground","bob"],"points":[[1,0,0],[0,0,0]],"axis":[0,1,0]}"#,
    );
    let e = SceneGraph::new(&s, Variant::Pinned)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joints[0].bodies[1]") && e.contains("point mass"),
        "{e}"
    );
}
