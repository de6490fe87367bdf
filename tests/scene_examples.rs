//! The example scenes load, are assembled (joint points coincide), and round-trip.

use bondmech::scene::{Body, Dimension, JointKind, PointRef, Scene, GROUND};
use std::path::{Path, PathBuf};

fn example_paths() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenes/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    paths
}

fn load(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(format!("{name}.json"));
    Scene::from_path(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn every_example_scene_passes_validation() {
    let paths = example_paths();
    assert!(
        paths.len() >= 6,
        "expected the six seed examples, found {paths:?}"
    );
    for p in paths {
        let s = Scene::from_path(&p).unwrap_or_else(|e| panic!("{}:\n{e}", p.display()));
        assert!(
            s.description.is_some(),
            "{} names its seed figure",
            p.display()
        );
    }
}

/// Global position of a point of a planar body: x + R(angle) r.
fn planar_global(b: &Body, r: &[f64]) -> [f64; 2] {
    let (s, c) = b.angle.sin_cos();
    [
        b.position[0] + c * r[0] - s * r[1],
        b.position[1] + s * r[0] + c * r[1],
    ]
}

fn global_point(scene: &Scene, body: &str, p: &PointRef) -> [f64; 2] {
    if body == GROUND {
        let PointRef::Coords(c) = p else {
            panic!("ground point by name")
        };
        return [c[0], c[1]];
    }
    let b = &scene.bodies[scene.body_index(body).unwrap()];
    let r = match p {
        PointRef::Named(n) => b.point(n).unwrap().to_vec(),
        PointRef::Coords(c) => c.clone(),
    };
    planar_global(b, &r)
}

/// Every planar example is assembled: revolute points coincide, prismatic points lie on the
/// axis line through the ground point, and link lengths match the descriptions (hand geometry).
#[test]
fn planar_examples_are_geometrically_consistent() {
    for name in [
        "pendulum",
        "two_bars",
        "double_pendulum",
        "slider_crank",
        "four_bar",
    ] {
        let s = load(name);
        assert_eq!(s.dimension, Dimension::Planar);
        for j in &s.joints {
            let a = global_point(&s, &j.bodies[0], &j.points[0]);
            let b = global_point(&s, &j.bodies[1], &j.points[1]);
            match &j.kind {
                JointKind::Revolute(r) if r.axis.is_none() => {
                    let gap = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                    assert!(gap < 1e-12, "{name}.{}: gap {gap}", j.name);
                }
                JointKind::Prismatic(k) => {
                    let axis = &k.axis;
                    assert_eq!(j.bodies[0], GROUND);
                    let cross = (b[0] - a[0]) * axis[1] - (b[1] - a[1]) * axis[0];
                    assert!(cross.abs() < 1e-12, "{name}.{}: off axis {cross}", j.name);
                }
                other => panic!("unexpected joint {other:?}"),
            }
        }
    }
}

/// The hinge of `two_bars` has the same velocity seen from both bars:
/// v1 + w1 k x R r1 = v2 + w2 k x R r2.
#[test]
fn two_bars_initial_velocities_agree_at_the_hinge() {
    let s = load("two_bars");
    let vel = |b: &Body, r: &[f64]| {
        let (sn, c) = b.angle.sin_cos();
        let rg = [c * r[0] - sn * r[1], sn * r[0] + c * r[1]];
        let w = b.angular_velocity[0];
        [b.velocity[0] - w * rg[1], b.velocity[1] + w * rg[0]]
    };
    let j = &s.joints[0];
    let b1 = &s.bodies[s.body_index(&j.bodies[0]).unwrap()];
    let b2 = &s.bodies[s.body_index(&j.bodies[1]).unwrap()];
    let name = |p: &PointRef| match p {
        PointRef::Named(n) => n.clone(),
        _ => panic!(),
    };
    let v1 = vel(b1, b1.point(&name(&j.points[0])).unwrap());
    let v2 = vel(b2, b2.point(&name(&j.points[1])).unwrap());
    assert!((v1[0] - v2[0]).abs() < 1e-15 && (v1[1] - v2[1]).abs() < 1e-15);
    assert!(s.bodies.iter().any(|b| b.angular_velocity[0] != 0.0));
}

#[test]
fn slider_crank_link_lengths_match_the_description() {
    let s = load("slider_crank");
    let dist = |b: &str, p: &str, q: &str| {
        let body = &s.bodies[s.body_index(b).unwrap()];
        let (a, c) = (body.point(p).unwrap(), body.point(q).unwrap());
        ((a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2)).sqrt()
    };
    assert!((dist("crank", "O", "A") - 0.1).abs() < 1e-15);
    assert!((dist("rod", "A", "B") - 0.3).abs() < 1e-15);
    let piston = &s.bodies[s.body_index("piston").unwrap()];
    assert_eq!(piston.mass, 0.3);
    assert_eq!(piston.position[0], 0.0, "piston on the cylinder axis x = 0");
}

#[test]
fn four_bar_satisfies_grashof_crank_rocker() {
    let s = load("four_bar");
    let len = |b: &str| {
        let body = &s.bodies[s.body_index(b).unwrap()];
        let pts: Vec<&[f64]> = body.points.iter().map(|(_, c)| c.as_slice()).collect();
        ((pts[0][0] - pts[1][0]).powi(2) + (pts[0][1] - pts[1][1]).powi(2)).sqrt()
    };
    let ground = 0.4;
    let mut l = [len("crank"), len("coupler"), len("rocker"), ground];
    let crank = l[0];
    l.sort_by(f64::total_cmp);
    assert!(l[0] + l[3] <= l[1] + l[2], "Grashof s + l <= p + q");
    assert_eq!(crank, l[0], "the crank is the shortest link");
}

/// The example of docs/scene-format.md, copied verbatim.
const CONTRACT_EXAMPLE: &str = r#"{
  "name": "double_pendulum",
  "dimension": 2,
  "gravity": [0.0, -9.81],
  "bodies": [
    { "name": "bar1", "mass": 1.0, "inertia": 0.0833333333333333,
      "frame": "inertial",
      "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] },
      "position": [0.5, 0.0], "angle": 0.0,
      "velocity": [0.0, 0.0], "angular_velocity": 0.0 },
    { "name": "bar2", "mass": 1.0, "inertia": 0.0833333333333333,
      "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] },
      "position": [1.5, 0.0], "angle": 0.0 }
  ],
  "joints": [
    { "name": "pivot", "type": "revolute",
      "bodies": ["ground", "bar1"], "points": [[0.0, 0.0], "O"] },
    { "name": "knee", "type": "revolute",
      "bodies": ["bar1", "bar2"], "points": ["A", "O"] }
  ],
  "springs": [],
  "loads": [],
  "solve": { "formulation": "dae", "t_end": 3.0, "output_step": 0.01,
             "rtol": 1e-8, "atol": 1e-10 },
  "outputs": ["bar2.A", "energy", "constraint_error"]
}"#;

#[test]
fn double_pendulum_json_equals_the_contract_example() {
    let contract = Scene::from_json_str(CONTRACT_EXAMPLE).unwrap();
    let mut ours = load("double_pendulum");
    ours.description = None;
    assert_eq!(ours, contract);
}

#[test]
fn double_pendulum_is_the_documented_example() {
    let s = load("double_pendulum");
    assert_eq!(s.bodies.len(), 2);
    assert_eq!(s.joints.len(), 2);
    assert_eq!(s.solve.t_end, 3.0);
    assert_eq!(s.bodies[1].points[0].0, "O", "point order kept");
    assert_eq!(s.output_times().len(), 301);
}

#[test]
fn free_body_spins_mostly_about_the_intermediate_axis() {
    let s = load("free_body_3d");
    assert_eq!(s.dimension, Dimension::Spatial);
    let w = &s.bodies[0].angular_velocity;
    assert!(w[1].abs() > 10.0 * w[0].abs().max(w[2].abs()));
    assert!(w[0] != 0.0 || w[2] != 0.0, "perturbed");
    assert!(s.warnings().is_empty(), "a lone free body is intentional");
}

#[test]
fn parse_serialize_parse_gives_an_equal_scene() {
    for p in example_paths() {
        let s = Scene::from_path(&p).unwrap();
        let text = serde_json::to_string(&s).unwrap();
        let again = Scene::from_json_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert_eq!(s, again, "{}", p.display());
        let pretty = Scene::from_json_str(&s.to_json_string()).unwrap();
        assert_eq!(s, pretty);
    }
}

#[test]
fn name_defaults_to_the_file_stem() {
    let dir = std::env::temp_dir().join(format!("bondmech-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("my_scene.json");
    std::fs::write(
        &p,
        r#"{"bodies":[{"name":"b","mass":1,"inertia":0}],"solve":{"t_end":1}}"#,
    )
    .unwrap();
    let s = Scene::from_path(&p).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(s.name, "my_scene");
}
