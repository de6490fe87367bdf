//! Issue 12, "bad input that crashes, hangs or loses data": absurd numbers in a scene, non-finite
//! load values, single-bond junctions, models beyond the machine's memory and huge expressions
//! each get a clear error (or warning) naming the field, load, element or limit.

mod support;

use bondmech::scene::validate::{
    check_atol, check_joint_stiffness, check_mass, check_rtol, check_t_end, BoundError,
};
use bondmech::scene::Scene;
use serde_json::{json, Value};
use support::cli::{bondmech, tmp};

/// The compound pendulum of `scenes/pendulum.json`, 1 s.
fn pendulum() -> Value {
    json!({
        "name": "pendulum", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [
            { "name": "bar", "mass": 1.0, "inertia": 0.08333333333333333,
              "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] }, "position": [0.5, 0.0] }
        ],
        "joints": [
            { "name": "pivot", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "O"] }
        ],
        "solve": { "t_end": 1.0, "output_step": 0.1, "rtol": 1e-8, "atol": 1e-10 }
    })
}

/// The problems (`path: message`) of an invalid scene; panics when it is accepted.
fn refused(v: &Value) -> Vec<String> {
    match Scene::from_json_str(&v.to_string()) {
        Ok(_) => panic!("scene accepted:\n{v}"),
        Err(e) => e.problems().iter().map(|p| p.to_string()).collect(),
    }
}

fn assert_refused(edit: impl FnOnce(&mut Value), path: &str, fragment: &str) {
    let mut v = pendulum();
    edit(&mut v);
    let problems = refused(&v);
    assert!(
        problems
            .iter()
            .any(|p| p.starts_with(&format!("{path}: ")) && p.contains(fragment)),
        "expected a problem at {path} containing {fragment:?}, got {problems:#?}"
    );
}

#[test]
fn regression_subnormal_mass_1e_320_is_refused_naming_the_field() {
    assert_refused(
        |v| v["bodies"][0]["mass"] = json!(1e-320),
        "bodies[0].mass",
        "1e-100",
    );
    assert_refused(
        |v| v["bodies"][0]["mass"] = json!(1e300),
        "bodies[0].mass",
        "<= 1e100",
    );
}

#[test]
fn regression_subnormal_inertia_1e_320_is_refused_naming_the_field() {
    assert_refused(
        |v| v["bodies"][0]["inertia"] = json!(1e-320),
        "bodies[0].inertia",
        ">= 1e-100",
    );
    // a point mass (inertia 0) is still allowed
    let mut v = pendulum();
    v["bodies"][0]["inertia"] = json!(0.0);
    Scene::from_json_str(&v.to_string()).expect("inertia 0 is a point mass");
}

#[test]
fn regression_rtol_1e308_is_refused_naming_the_field() {
    assert_refused(
        |v| v["solve"]["rtol"] = json!(1e308),
        "solve.rtol",
        "<= 1e0",
    );
    assert_refused(
        |v| v["solve"]["rtol"] = json!(1e-17),
        "solve.rtol",
        ">= 1e-15",
    );
}

#[test]
fn regression_atol_larger_than_the_mechanism_is_refused() {
    // the pendulum reaches 1 m from the origin: an absolute error of 10 m controls nothing
    assert_refused(|v| v["solve"]["atol"] = json!(10.0), "solve.atol", "size");
}

#[test]
fn regression_absurd_joint_stiffness_1e300_and_1e_minus_300_is_refused() {
    assert_refused(
        |v| v["solve"]["joint_stiffness"] = json!(1e300),
        "solve.joint_stiffness",
        "<= 1e16",
    );
    assert_refused(
        |v| v["solve"]["joint_stiffness"] = json!(1e-300),
        "solve.joint_stiffness",
        ">= 1e-100",
    );
}

#[test]
fn shared_bound_checks_accept_the_sane_and_state_the_rule() {
    assert!(check_rtol(1e-8).is_ok() && check_rtol(1e-13).is_ok() && check_rtol(1.0).is_ok());
    assert!(matches!(
        check_rtol(f64::NAN),
        Err(BoundError::NotPositive { .. })
    ));
    assert!(matches!(
        check_rtol(0.0),
        Err(BoundError::NotPositive { .. })
    ));
    assert!(check_atol(1e-10, Some(1.0)).is_ok() && check_atol(1e3, None).is_ok());
    assert!(check_joint_stiffness(1e12).is_ok() && check_joint_stiffness(1e-3).is_ok());
    assert!(check_mass(1e-30).is_ok() && check_mass(5.0e-324).is_err());
    assert!(check_t_end(2000.0, Some(0.5)).is_ok());
    let e = check_t_end(1e12, Some(0.01)).unwrap_err();
    assert!(e.to_string().contains("1e7 output rows"), "{e}");
}

#[test]
fn regression_rtol_1e308_is_refused_through_the_cli() {
    let mut v = pendulum();
    v["solve"]["rtol"] = json!(1e308);
    let path = tmp("rtol_1e308.json");
    std::fs::write(&path, v.to_string()).unwrap();
    let out = bondmech(&["run", path.to_str().unwrap(), "--table"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted: {err}");
    assert!(err.contains("solve.rtol"), "{err}");
}
