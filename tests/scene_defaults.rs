//! Defaults and output times, checked against values written by hand.

use bondmech::scene::{BodyFrame, Dimension, LoadValue, Scene};
use bondmech::FormulationKind;

const MINIMAL: &str = r#"{
  "bodies": [{ "name": "b", "mass": 2, "inertia": 0.5 }],
  "solve": { "t_end": 2 }
}"#;

#[test]
fn omitted_fields_take_the_documented_defaults() {
    let s = Scene::from_json_str(MINIMAL).unwrap();
    assert_eq!(s.name, "scene");
    assert_eq!(s.dimension, Dimension::Planar);
    assert_eq!(s.gravity, vec![0.0, 0.0]);
    let b = &s.bodies[0];
    assert_eq!(b.frame, BodyFrame::Inertial);
    assert_eq!(b.position, vec![0.0, 0.0]);
    assert_eq!(b.velocity, vec![0.0, 0.0]);
    assert_eq!(b.angular_velocity, vec![0.0]);
    assert_eq!(s.solve.formulation, FormulationKind::Dae);
    assert_eq!(s.solve.rtol, 1e-6);
    assert_eq!(s.solve.atol, 1e-8);
    assert_eq!(s.solve.joint_stiffness, 1e8);
    assert_eq!(s.solve.joint_damping, 0.0);
}

#[test]
fn default_output_grid_is_a_hundred_intervals() {
    let s = Scene::from_json_str(MINIMAL).unwrap();
    let t = s.output_times();
    assert_eq!(t.len(), 101);
    assert_eq!(t[0], 0.0);
    assert_eq!(t[100], 2.0);
    assert!((t[37] - 0.74).abs() < 1e-15);
}

#[test]
fn output_step_that_does_not_divide_t_end_ends_exactly_at_t_end() {
    let mut s = Scene::from_json_str(MINIMAL).unwrap();
    s.solve.t_end = 1.0;
    s.solve.output_step = Some(0.3);
    let t = s.output_times();
    let want = [0.0, 0.3, 0.6, 0.9, 1.0];
    assert_eq!(t.len(), want.len(), "{t:?}");
    for (a, b) in t.iter().zip(want) {
        assert!((a - b).abs() < 1e-15, "{t:?}");
    }
}

#[test]
fn output_step_that_divides_t_end_up_to_rounding_gives_no_extra_point() {
    let mut s = Scene::from_json_str(MINIMAL).unwrap();
    s.solve.t_end = 3.0;
    s.solve.output_step = Some(0.1); // 3.0 / 0.1 = 29.999999999999996
    let t = s.output_times();
    assert_eq!(t.len(), 31);
    assert_eq!(*t.last().unwrap(), 3.0);
}

#[test]
fn explicit_output_times_are_used_as_given() {
    let text = MINIMAL.replace(
        "\"t_end\": 2",
        "\"t_end\": 2, \"output_times\": [0.5, 1.25, 2]",
    );
    let s = Scene::from_json_str(&text).unwrap();
    assert_eq!(s.output_times(), vec![0.5, 1.25, 2.0]);
}

#[test]
fn load_value_forms_are_read_into_components() {
    let text = r#"{
      "bodies": [{ "name": "b", "mass": 1, "inertia": 1, "points": {"P": [1, 0]} }],
      "loads": [
        { "type": "torque", "body": "b", "value": "sin(t)" },
        { "type": "force", "body": "b", "point": "P", "value": [0, "-50*max(0, cos(b.angle))"] },
        { "type": "torque", "body": "b", "value": { "table": { "t": [0, 1], "v": [0, 2] } } },
        { "type": "force", "body": "b", "value": { "table": { "t": [0, 1], "v": [[0, 1], [2, 3]] } } }
      ],
      "solve": { "t_end": 1 }
    }"#;
    let s = Scene::from_json_str(text).unwrap();
    assert_eq!(s.loads[0].value, LoadValue::Expr(vec!["sin(t)".into()]));
    assert_eq!(
        s.loads[1].value,
        LoadValue::Expr(vec!["0".into(), "-50*max(0, cos(b.angle))".into()])
    );
    assert_eq!(
        s.loads[2].value,
        LoadValue::Table {
            t: vec![0.0, 1.0],
            v: vec![vec![0.0], vec![2.0]]
        }
    );
    assert_eq!(
        s.loads[3].value,
        LoadValue::Table {
            t: vec![0.0, 1.0],
            v: vec![vec![0.0, 1.0], vec![2.0, 3.0]]
        }
    );
    assert_eq!(s.loads[1].name, "load1");
    let again = Scene::from_json_str(&s.to_json_string()).unwrap();
    assert_eq!(s, again);
}
