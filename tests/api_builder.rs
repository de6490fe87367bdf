//! The builder API: a scene built in code equals the same scene read from JSON, solves to the
//! same bits, and its errors name the element at fault.

use bondmech::scene::{BodyFrame, LoadValue, PointRef};
use bondmech::FormulationKind;
use bondmech::{Error, Ground, Mechanism, Model, PlanarBody, Scene, SpatialBody, SpringDamper};

/// `scenes/double_pendulum.json`, built in code. The file writes the bars' inertia 1/12
/// rounded to 16 digits, so the code passes that number rather than `m L²/12`.
fn double_pendulum_in_code() -> Scene {
    let file_inertia = 0.0833333333333333;
    Mechanism::planar()
        .name("double_pendulum")
        .description(
            "Double pendulum of two hinged bars (seed 16.7-16.8, Fig. 19-21, 28): uniform bars 1 m, 1 kg, inertia 1/12, pivot at the origin, both horizontal at rest. The example of docs/scene-format.md.",
        )
        .gravity([0.0, -9.81])
        // the file writes bar1's velocities (zeros): written, they are the user's
        .body(
            PlanarBody::bar("bar1", 1.0, 1.0)
                .inertia(file_inertia)
                .at([0.5, 0.0], 0.0)
                .velocity([0.0, 0.0])
                .angular_velocity(0.0),
        )
        .body(PlanarBody::bar("bar2", 1.0, 1.0).inertia(file_inertia).at([1.5, 0.0], 0.0))
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .revolute("knee", ("bar1", "A"), ("bar2", "O"))
        .t_end(3.0)
        .output_step(0.01)
        .tolerances(1e-8, 1e-10)
        .output("bar2.A")
        .output("energy")
        .output("constraint_error")
        .build()
        .expect("the double pendulum builds")
}

fn problems(e: Error) -> Vec<String> {
    match e {
        Error::Scene(s) => s.problems().iter().map(|p| p.to_string()).collect(),
        other => panic!("expected a scene error, got {other}"),
    }
}

#[test]
fn double_pendulum_built_in_code_equals_the_json_file() {
    let from_file = Scene::from_path("scenes/double_pendulum.json").unwrap();
    assert_eq!(double_pendulum_in_code(), from_file);
}

#[test]
fn double_pendulum_built_in_code_solves_bit_for_bit_like_the_json_file() {
    let code = Model::new(&double_pendulum_in_code()).unwrap();
    let file = Model::new(&Scene::from_path("scenes/double_pendulum.json").unwrap()).unwrap();
    let mut opts = file.default_options();
    assert_eq!(code.default_options(), opts);
    opts.output_times.truncate(101); // t in [0, 1]
    let (a, b) = (code.solve(&opts).unwrap(), file.solve(&opts).unwrap());
    assert_eq!(a.columns, b.columns);
    assert_eq!(a.times, b.times);
    let bits = |s: &bondmech::Solution| -> Vec<Vec<u64>> {
        s.rows
            .iter()
            .map(|r| r.iter().map(|v| v.to_bits()).collect())
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(
        (
            a.summary.steps,
            a.summary.residual_evals,
            a.summary.jacobian_evals
        ),
        (
            b.summary.steps,
            b.summary.residual_evals,
            b.summary.jacobian_evals
        )
    );
}

#[test]
fn bar_has_the_uniform_bar_inertia_and_end_points() {
    // m L²/12 and O, A at ∓L/2: 2 kg, 0.3 m → 0.015 kg m².
    let s = Mechanism::planar()
        .body(PlanarBody::bar("b", 2.0, 0.3))
        .t_end(1.0)
        .build()
        .unwrap();
    let b = &s.bodies[0];
    assert_eq!(
        b.inertia,
        bondmech::scene::Inertia::Planar(2.0 * 0.09 / 12.0)
    );
    assert!((2.0 * 0.09 / 12.0 - 0.015f64).abs() < 1e-17);
    assert_eq!(b.point("O"), Some(&[-0.15, 0.0][..]));
    assert_eq!(b.point("A"), Some(&[0.15, 0.0][..]));
}

#[test]
fn slider_crank_built_in_code_equals_the_json_file() {
    let from_file = Scene::from_path("scenes/slider_crank.json").unwrap();
    let b = |i: usize| &from_file.bodies[i];
    let planar = |i: usize| {
        let body = b(i);
        let mut p = PlanarBody::new(
            &body.name,
            body.mass,
            match body.inertia {
                bondmech::scene::Inertia::Planar(j) => j,
                _ => unreachable!(),
            },
        )
        .at([body.position[0], body.position[1]], body.angle);
        for (n, c) in &body.points {
            p = p.point(n, [c[0], c[1]]);
        }
        p
    };
    let built = Mechanism::planar()
        .name("slider_crank")
        .description(from_file.description.as_deref().unwrap())
        .gravity([0.0, -9.81])
        .body(planar(0))
        .body(planar(1))
        .body(planar(2))
        .revolute("main_bearing", Ground.at([0.0, 0.0]), ("crank", "O"))
        .revolute("crank_pin", ("crank", "A"), ("rod", "A"))
        .revolute("wrist_pin", ("rod", "B"), ("piston", "P"))
        .prismatic(
            "cylinder",
            Ground.at([0.0, 0.0]),
            ("piston", "P"),
            [0.0, 1.0],
        )
        .torque("drive", "crank", 1.5)
        .force(
            "gas",
            ("piston", "P"),
            ["0", "-10*max(0, cos(crank.angle))"],
        )
        .t_end(1.0)
        .output_step(0.001)
        .tolerances(1e-8, 1e-10)
        .output("piston.P")
        .output("crank.A")
        .output("energy")
        .output("constraint_error")
        .build()
        .unwrap();
    assert_eq!(built, from_file);
}

#[test]
fn free_body_built_in_code_equals_the_json_file() {
    let from_file = Scene::from_path("scenes/free_body_3d.json").unwrap();
    let built = Mechanism::spatial()
        .name("free_body_3d")
        .description(from_file.description.as_deref().unwrap())
        .body(
            SpatialBody::new("body", 1.0, [1.0, 2.0, 3.0])
                .frame(BodyFrame::BodyFixed)
                .point("tip", [0.0, 1.0, 0.0])
                .velocity([0.0, 0.0, 0.0])
                .angular_velocity([0.01, 1.0, 0.01]),
        )
        .t_end(20.0)
        .output_step(0.01)
        .tolerances(1e-8, 1e-10)
        .formulation(FormulationKind::Dae)
        .output("body.tip")
        .output("energy")
        .build()
        .unwrap();
    assert_eq!(built, from_file);
}

#[test]
fn centre_of_mass_endpoint_is_the_zero_point() {
    let s = Mechanism::planar()
        .body(PlanarBody::point_mass("m", 1.0))
        .prismatic("rail", Ground.at([0.0, 0.0]), "m", [1.0, 0.0])
        .force("push", "m", [1.0, 0.0])
        .t_end(1.0)
        .build()
        .unwrap();
    assert_eq!(s.joints[0].points[1], PointRef::Coords(vec![0.0, 0.0]));
    assert_eq!(s.loads[0].point, None);
}

#[test]
fn negative_mass_error_names_the_body() {
    let e = Mechanism::planar()
        .body(PlanarBody::bar("bar1", 1.0, 1.0))
        .body(PlanarBody::bar("bar2", -1.0, 1.0))
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .t_end(1.0)
        .build()
        .unwrap_err();
    let p = problems(e);
    assert!(
        p.iter()
            .any(|l| l.starts_with("body 'bar2' (bodies[1]).mass:")),
        "{p:?}"
    );
}

#[test]
fn unknown_point_error_names_the_joint() {
    let e = Mechanism::planar()
        .body(PlanarBody::bar("bar1", 1.0, 1.0))
        .body(PlanarBody::bar("bar2", 1.0, 1.0))
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .revolute("knee", ("bar1", "A"), ("bar2", "Q"))
        .t_end(1.0)
        .build()
        .unwrap_err();
    let p = problems(e);
    assert!(
        p.iter()
            .any(|l| l.starts_with("joint 'knee' (joints[1])") && l.contains("'Q'")),
        "{p:?}"
    );
}

#[test]
fn unknown_body_in_a_load_error_names_the_load() {
    let e = Mechanism::planar()
        .body(PlanarBody::bar("bar1", 1.0, 1.0))
        .torque("drive", "crank", 1.0)
        .t_end(1.0)
        .build()
        .unwrap_err();
    let p = problems(e);
    assert!(
        p.iter()
            .any(|l| l.starts_with("load 'drive' (loads[0])") && l.contains("crank")),
        "{p:?}"
    );
}

#[test]
fn missing_end_time_is_reported() {
    let e = Mechanism::planar()
        .body(PlanarBody::bar("bar1", 1.0, 1.0))
        .build()
        .unwrap_err();
    let p = problems(e);
    assert!(p.iter().any(|l| l.starts_with("solve.t_end")), "{p:?}");
}

#[test]
fn spherical_joint_in_a_plane_is_refused_naming_the_joint() {
    let e = Mechanism::planar()
        .body(PlanarBody::bar("bar1", 1.0, 1.0))
        .spherical("ball", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .t_end(1.0)
        .build()
        .unwrap_err();
    let p = problems(e);
    assert!(p.iter().any(|l| l.starts_with("joint 'ball'")), "{p:?}");
}

#[test]
fn springs_and_load_kinds_built_in_code_equal_their_json() {
    let json = r#"{
      "name": "loads", "dimension": 2,
      "bodies": [{ "name": "m", "mass": 2, "inertia": 0.5,
                   "points": { "P": [0.1, 0] }, "position": [1, 0] }],
      "springs": [
        { "name": "s1", "bodies": ["ground", "m"], "points": [[0, 0], "P"], "stiffness": 10 },
        { "name": "s2", "bodies": ["ground", "m"], "points": [[0, 1], [0, 0]],
          "stiffness": 5, "rest_length": 0.5, "damping": 0.1 }],
      "loads": [
        { "name": "f", "type": "force", "body": "m", "point": "P", "value": [1, 2] },
        { "name": "g", "type": "force", "body": "m", "value": ["sin(t)", "m.x"] },
        { "name": "tt", "type": "torque", "body": "m",
          "value": { "table": { "t": [0, 1], "v": [0, 3] } } },
        { "name": "te", "type": "torque", "body": "m", "value": "-0.1*m.omega" }],
      "solve": { "t_end": 2 } }"#;
    let from_json = Scene::from_json_str(json).unwrap();
    let built = Mechanism::planar()
        .name("loads")
        .body(
            PlanarBody::new("m", 2.0, 0.5)
                .point("P", [0.1, 0.0])
                .at([1.0, 0.0], 0.0),
        )
        .spring(SpringDamper::new(
            "s1",
            Ground.at([0.0, 0.0]),
            ("m", "P"),
            10.0,
        ))
        .spring(
            SpringDamper::new("s2", Ground.at([0.0, 1.0]), "m", 5.0)
                .rest_length(0.5)
                .damping(0.1),
        )
        .force("f", ("m", "P"), [1.0, 2.0])
        .force("g", "m", ["sin(t)", "m.x"])
        .torque(
            "tt",
            "m",
            LoadValue::table(vec![0.0, 1.0], vec![vec![0.0], vec![3.0]]),
        )
        .torque("te", "m", "-0.1*m.omega")
        .t_end(2.0)
        .build()
        .unwrap();
    assert_eq!(built, from_json);
}

#[test]
fn built_scene_written_as_json_reads_back_equal() {
    let built = double_pendulum_in_code();
    let again = Scene::from_json_str(&built.to_json_string()).unwrap();
    assert_eq!(again, built);
}

#[test]
fn mechanism_from_a_loaded_scene_appends_elements() {
    let file = Scene::from_path("scenes/pendulum_point_mass.json").unwrap();
    let n = file.loads.len();
    let more = Mechanism::from(file)
        .torque("motor", "bob", 0.5)
        .build()
        .unwrap();
    assert_eq!(more.loads.len(), n + 1);
    assert_eq!(more.loads[n].name, "motor");
}

#[test]
fn hinged_double_pendulum_3d_built_in_code_equals_the_json_file() {
    let from_file = Scene::from_path("scenes/hinged_double_pendulum_3d.json").unwrap();
    // the file writes 1/12 rounded to 16 digits
    let inertia = [0.02, 0.08333333333333333, 0.08333333333333333];
    let bar = |name: &str, x: f64| {
        SpatialBody::new(name, 1.0, inertia)
            .point("O", [-0.5, 0.0, 0.0])
            .point("A", [0.5, 0.0, 0.0])
            .at([x, 0.0, 0.0], [0.0, 0.0, 0.0])
    };
    let built = Mechanism::spatial()
        .name("hinged_double_pendulum_3d")
        .description(from_file.description.as_deref().unwrap())
        .gravity([0.0, 0.0, -9.81])
        .body(bar("bar1", 0.5))
        .body(bar("bar2", 1.5))
        .hinge(
            "pivot",
            Ground.at([0.0, 0.0, 0.0]),
            ("bar1", "O"),
            [0.0, 1.0, 0.0],
        )
        .hinge("knee", ("bar1", "A"), ("bar2", "O"), [0.0, 1.0, 0.0])
        .t_end(5.0)
        .output_step(0.01)
        .tolerances(1e-8, 1e-10)
        .formulation(FormulationKind::Dae)
        .output("bar2.A")
        .output("energy")
        .output("constraint_error")
        .build()
        .unwrap();
    assert_eq!(built, from_file);
}

#[test]
fn hinge_in_a_plane_is_refused_naming_the_joint() {
    let e = Mechanism::planar()
        .body(PlanarBody::bar("bar1", 1.0, 1.0))
        .hinge(
            "pivot",
            Ground.at([0.0, 0.0]),
            ("bar1", "O"),
            [0.0, 0.0, 1.0],
        )
        .t_end(1.0)
        .build()
        .unwrap_err();
    let p = problems(e);
    assert!(p.iter().any(|l| l.starts_with("joint 'pivot'")), "{p:?}");
}
