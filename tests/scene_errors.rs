//! Every class of bad input gets an error naming the JSON path of the bad field.

use bondmech::scene::{Scene, SceneError};
use serde_json::{json, Value};

/// A valid double pendulum, the base that each test breaks in one place.
fn base() -> Value {
    json!({
        "name": "dp", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [
            { "name": "bar1", "mass": 1.0, "inertia": 0.08, "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] },
              "position": [0.5, 0.0] },
            { "name": "bar2", "mass": 1.0, "inertia": 0.08, "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] },
              "position": [1.5, 0.0] }
        ],
        "joints": [
            { "name": "pivot", "type": "revolute", "bodies": ["ground", "bar1"], "points": [[0.0, 0.0], "O"] },
            { "name": "knee", "type": "revolute", "bodies": ["bar1", "bar2"], "points": ["A", "O"] }
        ],
        "loads": [ { "type": "torque", "body": "bar1", "value": 1.0 } ],
        "solve": { "t_end": 1.0, "output_step": 0.1 }
    })
}

fn problems_of(text: &str) -> Vec<(String, String)> {
    match Scene::from_json_str(text) {
        Ok(_) => panic!("scene accepted, expected an error:\n{text}"),
        Err(e) => e
            .problems()
            .iter()
            .map(|p| (p.path.clone(), p.message.clone()))
            .collect(),
    }
}

/// Asserts that breaking `base()` with `edit` yields a problem at exactly `path`
/// whose message contains `fragment`.
fn assert_problem(edit: impl FnOnce(&mut Value), path: &str, fragment: &str) {
    let mut v = base();
    edit(&mut v);
    assert_text_problem(&v.to_string(), path, fragment);
}

fn assert_text_problem(text: &str, path: &str, fragment: &str) {
    let problems = problems_of(text);
    assert!(
        problems
            .iter()
            .any(|(p, m)| p == path && m.contains(fragment)),
        "expected `{path}: ...{fragment}...`, got {problems:#?}"
    );
}

#[test]
fn the_base_scene_is_valid() {
    Scene::from_json_str(&base().to_string()).unwrap();
}

#[test]
fn malformed_json_reports_line_and_column() {
    // The second comma of `  "name": "x",,` is the 15th character of line 2.
    // The second comma of `  "name": "x",,` is the 15th character of line 2.
    let problems = problems_of("{\n  \"name\": \"x\",,\n}");
    assert_eq!(problems.len(), 1);
    assert_eq!(problems[0].0, "");
    assert!(problems[0].1.contains("line 2, column 15"), "{problems:?}");
}

#[test]
fn numbers_out_of_double_range_are_refused_not_infinite() {
    let text = base().to_string().replace("\"mass\":1.0", "\"mass\":1e999");
    let problems = problems_of(&text);
    assert!(problems[0].1.contains("malformed JSON"), "{problems:?}");
}

#[test]
fn deeply_nested_json_is_refused_without_overflowing_the_stack() {
    let text = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    let problems = problems_of(&text);
    assert!(problems[0].1.contains("recursion limit"), "{problems:?}");
}

#[test]
fn a_scene_that_is_not_an_object_is_refused() {
    assert_text_problem("[1, 2]", "", "must be a JSON object");
}

#[test]
fn unknown_top_level_field_is_an_error_with_its_path() {
    assert_problem(
        |v| v["gravty"] = json!([0, -9.81]),
        "gravty",
        "unknown field",
    );
}

#[test]
fn unknown_nested_field_is_an_error_with_its_path() {
    assert_problem(
        |v| v["bodies"][1]["masss"] = json!(1),
        "bodies[1].masss",
        "unknown field",
    );
    assert_problem(
        |v| v["solve"]["r_tol"] = json!(1e-6),
        "solve.r_tol",
        "unknown field",
    );
}

#[test]
fn comment_and_description_fields_are_allowed() {
    let mut v = base();
    v["comment"] = json!("top");
    v["description"] = json!("Fig. 19");
    v["bodies"][0]["comment"] = json!("the upper bar");
    v["solve"]["comment"] = json!("tight");
    let s = Scene::from_json_str(&v.to_string()).unwrap();
    assert_eq!(s.description.as_deref(), Some("Fig. 19"));
}

#[test]
fn duplicated_key_is_an_error() {
    let text = base()
        .to_string()
        .replacen("\"mass\":1.0", "\"mass\":1.0,\"mass\":2.0", 1);
    assert_text_problem(&text, "bodies[0].mass", "duplicate key");
}

#[test]
fn wrong_type_names_the_field_and_the_types() {
    assert_problem(
        |v| v["bodies"][0]["mass"] = json!("1"),
        "bodies[0].mass",
        "expected a number, got string",
    );
}

#[test]
fn dimension_must_be_2_or_3() {
    assert_problem(|v| v["dimension"] = json!(4), "dimension", "must be 2 or 3");
}

#[test]
fn vector_lengths_must_match_the_dimension() {
    assert_problem(
        |v| v["gravity"] = json!([0, -9.81, 0]),
        "gravity",
        "expected 2 components, got 3",
    );
    assert_problem(
        |v| v["bodies"][1]["position"] = json!([1.5]),
        "bodies[1].position",
        "expected 2 components, got 1",
    );
    assert_problem(
        |v| v["bodies"][0]["points"]["A"] = json!([0.5, 0, 0]),
        "bodies[0].points.A",
        "expected 2 components",
    );
    assert_problem(
        |v| v["joints"][0]["points"][0] = json!([0, 0, 0]),
        "joints[0].points[0]",
        "expected 2 components",
    );
    assert_problem(
        |v| v["bodies"][0]["angular_velocity"] = json!([1, 2, 3]),
        "bodies[0].angular_velocity",
        "one angular velocity",
    );
}

#[test]
fn spatial_body_needs_principal_moments_and_cardan_angles() {
    assert_problem(
        |v| {
            v["dimension"] = json!(3);
            v["gravity"] = json!([0, 0, -9.81]);
        },
        "bodies[0].inertia",
        "principal moments",
    );
    assert_problem(
        |v| v["bodies"][0]["inertia"] = json!([1, 2, 3]),
        "bodies[0].inertia",
        "scalar inertia",
    );
    assert_problem(
        |v| v["bodies"][0]["cardan"] = json!([0, 0, 0]),
        "bodies[0].cardan",
        "only spatial",
    );
}

#[test]
fn principal_moments_must_satisfy_the_triangle_inequality() {
    let text = r#"{"dimension": 3, "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 3]}],
                  "solve": {"t_end": 1}}"#;
    assert_text_problem(text, "bodies[0].inertia", "triangle inequality");
}

#[test]
fn mass_must_be_positive() {
    assert_problem(
        |v| v["bodies"][1]["mass"] = json!(0.0),
        "bodies[1].mass",
        "must be > 0",
    );
    assert_problem(
        |v| v["bodies"][1]["mass"] = json!(-2.0),
        "bodies[1].mass",
        "(got -2)",
    );
}

#[test]
fn inertia_must_be_non_negative_and_zero_is_a_point_mass() {
    assert_problem(
        |v| v["bodies"][0]["inertia"] = json!(-1),
        "bodies[0].inertia",
        "must be >= 0 and finite (got -1)",
    );
    let mut v = base();
    v["bodies"][0]["inertia"] = json!(0.0);
    Scene::from_json_str(&v.to_string()).unwrap();
}

#[test]
fn non_finite_numbers_in_a_scene_built_in_code_are_reported() {
    let mut s = Scene::from_json_str(&base().to_string()).unwrap();
    s.bodies[1].angle = f64::NAN;
    s.gravity[1] = f64::INFINITY;
    s.solve.rtol = f64::NAN;
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("bodies[1].angle: must be finite"), "{e}");
    assert!(e.contains("gravity[1]: must be finite"), "{e}");
    assert!(e.contains("solve.rtol: must be > 0 and finite"), "{e}");
}

#[test]
fn duplicate_body_and_joint_names_are_refused() {
    assert_problem(
        |v| v["bodies"][1]["name"] = json!("bar1"),
        "bodies[1].name",
        "duplicate body name 'bar1'",
    );
    assert_problem(
        |v| v["joints"][1]["name"] = json!("pivot"),
        "joints[1].name",
        "duplicate joint name 'pivot'",
    );
}

#[test]
fn a_body_may_not_be_called_ground() {
    assert_problem(
        |v| v["bodies"][1]["name"] = json!("ground"),
        "bodies[1].name",
        "reserved",
    );
}

#[test]
fn joint_to_unknown_body_names_the_body() {
    assert_problem(
        |v| v["joints"][1]["bodies"][0] = json!("bar3"),
        "joints[1].bodies[0]",
        "unknown body 'bar3'",
    );
}

#[test]
fn joint_to_unknown_point_lists_the_points_in_the_users_order() {
    let text = base()
        .to_string()
        .replace("\"points\":[\"A\",\"O\"]", "\"points\":[\"A\",\"C\"]");
    // serde_json::Value sorts keys, so write the body's points in the order O, A by hand.
    let text = text.replace(
        "{\"A\":[0.5,0.0],\"O\":[-0.5,0.0]}",
        "{\"O\":[-0.5,0.0],\"A\":[0.5,0.0]}",
    );
    assert_text_problem(
        &text,
        "joints[1].points[1]",
        "body 'bar2' has no point 'C' (it has: O, A)",
    );
}

#[test]
fn ground_points_must_be_coordinates() {
    assert_problem(
        |v| v["joints"][0]["points"][0] = json!("O"),
        "joints[0].points[0]",
        "ground has no named points",
    );
}

#[test]
fn joint_between_a_body_and_itself_is_refused() {
    assert_problem(
        |v| v["joints"][1]["bodies"] = json!(["bar1", "bar1"]),
        "joints[1].bodies",
        "same body 'bar1'",
    );
}

#[test]
fn prismatic_joint_needs_a_nonzero_axis() {
    assert_problem(
        |v| v["joints"][1]["type"] = json!("prismatic"),
        "joints[1].axis",
        "needs an axis",
    );
    assert_problem(
        |v| {
            v["joints"][1]["type"] = json!("prismatic");
            v["joints"][1]["axis"] = json!([0.0, 0.0]);
        },
        "joints[1].axis",
        "non-zero",
    );
    assert_problem(
        |v| v["joints"][1]["axis"] = json!([0.0, 1.0]),
        "joints[1].axis",
        "only a prismatic",
    );
}

#[test]
fn spherical_joint_in_a_planar_scene_is_refused() {
    assert_problem(
        |v| v["joints"][0]["type"] = json!("spherical"),
        "joints[0].type",
        "spatial scene",
    );
}

#[test]
fn unknown_joint_type_is_refused() {
    assert_problem(
        |v| v["joints"][0]["type"] = json!("hinge"),
        "joints[0].type",
        "unknown joint type \"hinge\"",
    );
}

#[test]
fn solve_settings_are_checked() {
    assert_problem(
        |v| v["solve"]["t_end"] = json!(0.0),
        "solve.t_end",
        "must be > 0",
    );
    assert_problem(
        |v| v["solve"]["t_end"] = json!(-1.0),
        "solve.t_end",
        "must be > 0",
    );
    assert_problem(
        |v| v["solve"]["output_step"] = json!(0.0),
        "solve.output_step",
        "must be > 0",
    );
    assert_problem(
        |v| v["solve"]["output_step"] = json!(2.0),
        "solve.output_step",
        "<= t_end",
    );
    assert_problem(
        |v| v["solve"]["rtol"] = json!(0.0),
        "solve.rtol",
        "must be > 0 and finite",
    );
    assert_problem(
        |v| v["solve"]["atol"] = json!(-1e-8),
        "solve.atol",
        "must be > 0",
    );
    assert_problem(
        |v| v["solve"]["joint_stiffness"] = json!(0.0),
        "solve.joint_stiffness",
        "must be > 0",
    );
    assert_problem(
        |v| v["solve"]["formulation"] = json!("rk4"),
        "solve.formulation",
        "unknown formulation",
    );
    assert_problem(
        |v| v["solve"]["max_steps"] = json!(1.5),
        "solve.max_steps",
        "positive integer",
    );
    assert_problem(
        |v| {
            v["solve"]
                .as_object_mut()
                .unwrap()
                .remove("t_end")
                .map(|_| ())
                .unwrap()
        },
        "solve.t_end",
        "required",
    );
}

#[test]
fn output_times_must_increase_within_the_horizon() {
    assert_problem(
        |v| {
            v["solve"].as_object_mut().unwrap().remove("output_step");
            v["solve"]["output_times"] = json!([0.0, 0.5, 0.5, 0.7]);
        },
        "solve.output_times",
        "strictly increasing",
    );
    assert_problem(
        |v| {
            v["solve"].as_object_mut().unwrap().remove("output_step");
            v["solve"]["output_times"] = json!([0.0, 2.0]);
        },
        "solve.output_times[1]",
        "must lie in [0, t_end",
    );
}

#[test]
fn empty_expressions_are_refused() {
    assert_problem(
        |v| v["loads"][0]["value"] = json!("  "),
        "loads[0].value",
        "must not be empty",
    );
    assert_problem(
        |v| {
            v["loads"][0] =
                json!({"type": "force", "body": "bar2", "point": "A", "value": ["", "-9*t"]});
        },
        "loads[0].value[0]",
        "must not be empty",
    );
}

#[test]
fn load_on_unknown_body_or_point_is_refused() {
    assert_problem(
        |v| v["loads"][0]["body"] = json!("bar9"),
        "loads[0].body",
        "unknown body 'bar9'",
    );
    assert_problem(
        |v| v["loads"][0] = json!({"type": "force", "body": "bar2", "point": "Q", "value": [0, 1]}),
        "loads[0].point",
        "body 'bar2' has no point 'Q'",
    );
}

#[test]
fn load_values_have_the_right_number_of_components() {
    assert_problem(
        |v| v["loads"][0]["value"] = json!([1, 2]),
        "loads[0].value",
        "expected 1 components",
    );
    assert_problem(
        |v| v["loads"][0] = json!({"type": "force", "body": "bar2", "value": [1, 2, 3]}),
        "loads[0].value",
        "expected 2 components",
    );
}

#[test]
fn table_times_must_be_strictly_increasing_and_match_values() {
    assert_problem(
        |v| v["loads"][0]["value"] = json!({"table": {"t": [0.0, 1.0, 0.5], "v": [0.0, 1.0, 2.0]}}),
        "loads[0].value.table.t",
        "must be strictly increasing",
    );
    assert_problem(
        |v| v["loads"][0]["value"] = json!({"table": {"t": [0.0, 1.0], "v": [0.0]}}),
        "loads[0].value.table.v",
        "expected 2 values",
    );
}

#[test]
fn a_scene_needs_bodies_or_a_bond_graph() {
    let text = r#"{"name": "empty", "solve": {"t_end": 1}}"#;
    assert_text_problem(text, "bodies", "neither");
    let bg =
        r#"{"name": "bg", "bond_graph": {"elements": [], "bonds": []}, "solve": {"t_end": 1}}"#;
    let s = Scene::from_json_str(bg).unwrap();
    assert!(s.bond_graph.is_some());
}

#[test]
fn outputs_must_name_known_bodies_points_or_quantities() {
    assert_problem(
        |v| v["outputs"] = json!(["bar2.A", "bar3.A"]),
        "outputs[1]",
        "unknown body 'bar3'",
    );
    assert_problem(
        |v| v["outputs"] = json!(["bar2.Z"]),
        "outputs[0]",
        "has no point 'Z'",
    );
    assert_problem(
        |v| v["outputs"] = json!(["enrgy"]),
        "outputs[0]",
        "unknown output 'enrgy'",
    );
}

#[test]
fn all_problems_are_reported_one_line_each() {
    let mut v = base();
    v["bodies"][0]["mass"] = json!(-1);
    v["joints"][1]["bodies"][1] = json!("bar7");
    v["solve"]["rtol"] = json!(0);
    let e = Scene::from_json_str(&v.to_string()).unwrap_err();
    assert_eq!(e.problems().len(), 3, "{e}");
    let text = e.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3);
    assert!(lines.iter().any(|l| l.starts_with("bodies[0].mass: ")));
    assert!(lines
        .iter()
        .any(|l| l.starts_with("joints[1].bodies[1]: unknown body 'bar7'")));
    assert!(lines
        .iter()
        .any(|l| l.starts_with("solve.rtol: must be > 0 and finite")));
}

#[test]
fn shape_problems_in_several_places_are_all_reported() {
    let mut v = base();
    v["bodies"][0]["mass"] = json!("heavy");
    v["joints"][0]["type"] = json!("pin");
    v["typo"] = json!(1);
    let problems = problems_of(&v.to_string());
    let paths: Vec<&str> = problems.iter().map(|(p, _)| p.as_str()).collect();
    for want in ["bodies[0].mass", "joints[0].type", "typo"] {
        assert!(paths.contains(&want), "{want} missing from {paths:?}");
    }
}

#[test]
fn missing_file_error_names_the_file() {
    let e = Scene::from_path(std::path::Path::new("/nonexistent/scene_xyz.json")).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/scene_xyz.json"), "{e}");
}

#[test]
fn unconnected_body_is_a_warning_not_an_error() {
    let mut v = base();
    v["bodies"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "orphan", "mass": 1.0, "inertia": 0.0}));
    let s = Scene::from_json_str(&v.to_string()).unwrap();
    let w = s.warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(
        w[0].to_string(),
        "bodies[2]: 'orphan' is not connected to anything"
    );
}
