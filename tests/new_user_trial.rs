//! Issue 38, "the product tried on several hundred bad inputs, as a new user would": a few
//! hundred scenes a new user writes by mistake — misspelt field names, values of the wrong type,
//! missing fields, out-of-range numbers, nonsense joints, empty arrays, duplicate names, unicode,
//! huge and tiny numbers, units written into strings, broken expressions, unknown functions,
//! `NaN`/`Infinity` literals, broken JSON, odd raw bond graphs, numbers each within its bounds
//! whose combination fails during the solve — each run through `bondmech run` and its outcome
//! classified:
//!
//! - **clear**: refused (exit 1) with a message naming a JSON path, element, joint or field;
//! - **warned**: accepted with a `bondmech: warning:` line;
//! - **legal**: accepted silently where the input is odd but means what it says (a unicode body
//!   name, `angular_velocity: [ω]`), so silence is right;
//! - **silent**: a mistake accepted without a word (counted: at most 6);
//! - **vague**: refused with a message that names no path, element, joint or field (counted: at
//!   most 10);
//! - **hang** (no answer within 30 s), **panic** (exit 101, "panicked"), **abort** (killed by a
//!   signal) or **data loss** (the scene file changed): each fails the test.
//!
//! The counts are printed (`cargo test --test new_user_trial -- --nocapture`) and recorded in
//! docs/scene-format.md §20.

mod support;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

/// How one case was written.
enum Input {
    /// A scene as JSON.
    Json(Value),
    /// A scene as raw text (broken JSON, literals JSON has no word for).
    Text(String),
}

struct Case {
    name: String,
    input: Input,
    /// The input is odd but legal: silence is the right answer.
    legal: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Outcome {
    Clear,
    Warned,
    Legal,
    Silent,
    Vague,
    Hang,
    Panic,
    Abort,
    DataLoss,
}

/// A double pendulum with a spring, a load, an event and extra outputs: every part of a
/// planar scene a new user touches.
fn planar() -> Value {
    json!({
        "name": "trial",
        "dimension": 2,
        "gravity": [0.0, -9.81],
        "bodies": [
            { "name": "bar", "mass": 1.0, "inertia": 0.0833,
              "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] }, "position": [0.5, 0.0],
              "angle": 0.0, "velocity": [0.0, 0.0], "angular_velocity": 0.0 },
            { "name": "arm", "mass": 0.5, "inertia": 0.02,
              "points": { "O": [-0.25, 0.0], "B": [0.25, 0.0] }, "position": [1.25, 0.0] }
        ],
        "joints": [
            { "name": "pivot", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "O"] },
            { "name": "knee", "type": "revolute", "bodies": ["bar", "arm"], "points": ["A", "O"] }
        ],
        "springs": [
            { "name": "s", "bodies": ["ground", "arm"], "points": [[1.5, 1.0], "B"],
              "stiffness": 10.0, "damping": 0.1, "rest_length": 1.0 }
        ],
        "loads": [
            { "name": "push", "type": "force", "body": "bar", "point": "A", "value": ["0.1*sin(t)", "0"] },
            { "name": "twist", "type": "torque", "body": "arm", "value": 0.01 }
        ],
        "events": [
            { "name": "down", "when": "bar.A.y + 2", "direction": "falling", "action": "stop" }
        ],
        "solve": { "t_end": 0.2, "output_step": 0.05, "rtol": 1e-6, "atol": 1e-8 },
        "outputs": ["bar.A", "energy"]
    })
}

/// A heavy top: a spatial body on a ball joint.
fn spatial() -> Value {
    json!({
        "dimension": 3,
        "gravity": [0.0, 0.0, -9.81],
        "bodies": [
            { "name": "top", "mass": 1.0, "inertia": [0.1, 0.1, 0.05],
              "points": { "tip": [0.0, 0.0, -0.5] }, "position": [0.0, 0.0, 0.5],
              "cardan": [0.0, 0.1, 0.0], "angular_velocity": [0.0, 0.0, 20.0] }
        ],
        "joints": [
            { "name": "ball", "type": "spherical", "bodies": ["ground", "top"], "points": [[0.0, 0.0, 0.0], "tip"] }
        ],
        "solve": { "t_end": 0.1, "output_step": 0.05 }
    })
}

/// The mass-spring-damper as a raw bond graph.
fn raw() -> Value {
    json!({
        "bond_graph": {
            "elements": [
                {"name": "F", "kind": "Se", "value": 0.0},
                {"name": "v", "kind": "1"},
                {"name": "m", "kind": "I", "value": 1.5},
                {"name": "k", "kind": "C", "stiffness": 6.0, "initial": 0.1},
                {"name": "b", "kind": "R", "value": 0.3}
            ],
            "bonds": [
                {"from": "F", "to": "v"}, {"from": "v", "to": "m"},
                {"from": "v", "to": "k"}, {"from": "v", "to": "b"}
            ]
        },
        "solve": {"t_end": 0.2, "output_step": 0.05}
    })
}

/// `v` with the value at JSON pointer `ptr` replaced by `x` (created when its parent exists).
fn set(mut v: Value, ptr: &str, x: Value) -> Value {
    let (parent, key) = ptr.rsplit_once('/').unwrap();
    match v.pointer_mut(parent).expect(ptr) {
        Value::Object(m) => {
            m.insert(key.to_string(), x);
        }
        Value::Array(a) => a[key.parse::<usize>().unwrap()] = x,
        _ => panic!("{ptr}"),
    }
    v
}

/// `v` without the value at `ptr`.
fn remove(mut v: Value, ptr: &str) -> Value {
    let (parent, key) = ptr.rsplit_once('/').unwrap();
    match v.pointer_mut(parent).expect(ptr) {
        Value::Object(m) => {
            m.remove(key).expect(ptr);
        }
        Value::Array(a) => {
            a.remove(key.parse::<usize>().unwrap());
        }
        _ => panic!("{ptr}"),
    }
    v
}

/// `v` with the key at `ptr` renamed to `new` (its value kept).
fn rename(mut v: Value, ptr: &str, new: &str) -> Value {
    let (parent, key) = ptr.rsplit_once('/').unwrap();
    let m = v.pointer_mut(parent).expect(ptr).as_object_mut().unwrap();
    let x = m.remove(key).expect(ptr);
    m.insert(new.to_string(), x);
    v
}

fn cases() -> Vec<Case> {
    let mut out: Vec<Case> = Vec::new();
    let mut add = |name: String, input: Input, legal: bool| out.push(Case { name, input, legal });

    // 1. misspelt field names, at every level (each also leaves its field missing or defaulted)
    let typos: &[(&str, &[&str])] = &[
        ("/dimension", &["dimensions", "dim"]),
        ("/gravity", &["gravty", "Gravity", "g"]),
        ("/bodies", &["body", "Bodies"]),
        ("/joints", &["joint", "constraints"]),
        ("/springs", &["spring"]),
        ("/loads", &["load", "forces"]),
        ("/events", &["event"]),
        ("/outputs", &["output"]),
        ("/solve", &["solver", "simulation"]),
        ("/bodies/0/mass", &["mas", "Mass", "masse", "m"]),
        ("/bodies/0/inertia", &["inertai", "I", "moment_of_inertia"]),
        (
            "/bodies/0/position",
            &["pos", "postion", "initial_position"],
        ),
        ("/bodies/0/angle", &["angel", "theta", "rotation"]),
        ("/bodies/0/velocity", &["vel", "velocities"]),
        ("/bodies/0/angular_velocity", &["omega", "angularVelocity"]),
        ("/bodies/0/points", &["point", "markers"]),
        ("/bodies/0/name", &["Name", "id"]),
        ("/joints/0/type", &["kind", "Type", "joint_type"]),
        ("/joints/0/bodies", &["body", "links"]),
        ("/joints/0/points", &["point", "anchors"]),
        (
            "/springs/0/stiffness",
            &["stifness", "k", "spring_constant"],
        ),
        ("/springs/0/damping", &["dampning", "c"]),
        (
            "/springs/0/rest_length",
            &["restlength", "rest-length", "l0"],
        ),
        ("/loads/0/value", &["values", "magnitude"]),
        ("/loads/0/type", &["kind"]),
        ("/loads/0/body", &["bodies", "target"]),
        ("/events/0/when", &["condition", "expr"]),
        ("/events/0/direction", &["dir"]),
        (
            "/solve/t_end",
            &["tend", "t-end", "T_end", "end_time", "duration"],
        ),
        ("/solve/output_step", &["outputstep", "dt", "step"]),
        ("/solve/rtol", &["reltol", "rel_tol"]),
        ("/solve/atol", &["abstol", "tol"]),
    ];
    for (ptr, news) in typos {
        for new in *news {
            add(
                format!("typo {ptr} -> {new}"),
                Input::Json(rename(planar(), ptr, new)),
                false,
            );
        }
    }
    for (ptr, new) in [
        ("/solve/formulation", "formulaton"),
        ("/solve/max_steps", "maxsteps"),
        ("/solve/t_start", "tstart"),
        ("/solve/linear_solver", "linearsolver"),
    ] {
        let v = set(planar(), ptr, json!(null));
        let v = remove(v, ptr);
        let (parent, _) = ptr.rsplit_once('/').unwrap();
        add(
            format!("unknown {parent}/{new}"),
            Input::Json(set(v, &format!("{parent}/{new}"), json!(1))),
            false,
        );
    }
    add(
        "typo /bodies/0/cardan in 3D -> cardan_angles".into(),
        Input::Json(rename(spatial(), "/bodies/0/cardan", "cardan_angles")),
        false,
    );
    add(
        "typo raw element kind -> type".into(),
        Input::Json(rename(raw(), "/bond_graph/elements/2/kind", "type")),
        false,
    );
    add(
        "typo raw C stiffness -> stifness".into(),
        Input::Json(rename(
            raw(),
            "/bond_graph/elements/3/stiffness",
            "stifness",
        )),
        false,
    );
    add(
        "typo raw bonds -> bond".into(),
        Input::Json(rename(raw(), "/bond_graph/bonds", "bond")),
        false,
    );
    add(
        "typo raw bond from -> source".into(),
        Input::Json(rename(raw(), "/bond_graph/bonds/0/from", "source")),
        false,
    );

    // 2. values of the wrong type
    let fields = [
        "/dimension",
        "/gravity",
        "/bodies",
        "/bodies/0",
        "/bodies/0/name",
        "/bodies/0/mass",
        "/bodies/0/inertia",
        "/bodies/0/points",
        "/bodies/0/points/A",
        "/bodies/0/position",
        "/bodies/0/angle",
        "/bodies/0/velocity",
        "/joints/0/type",
        "/joints/0/bodies",
        "/joints/0/points",
        "/springs/0/stiffness",
        "/loads/0/value",
        "/events/0/when",
        "/solve",
        "/solve/t_end",
        "/solve/rtol",
        "/outputs",
    ];
    let wrongs = [
        ("a string", json!("abc")),
        ("true", json!(true)),
        ("null", json!(null)),
        ("an object", json!({"x": 1})),
        ("a nested array", json!([[1.0, 2.0], [3.0]])),
    ];
    for f in fields {
        for (what, x) in &wrongs {
            // a string where an expression or a name is expected is a type the field has
            if (*what == "a string")
                && (f.ends_with("/name")
                    || f.ends_with("/when")
                    || f.ends_with("/value")
                    || f.ends_with("/type"))
            {
                continue;
            }
            add(
                format!("{f} = {what}"),
                Input::Json(set(planar(), f, x.clone())),
                false,
            );
        }
    }
    for (f, x) in [
        ("/bodies/0/mass", json!("1")),
        ("/bodies/0/mass", json!([1.0])),
        ("/solve/t_end", json!("5")),
        ("/dimension", json!("2")),
        ("/solve/max_steps", json!(1.5)),
        ("/solve/max_steps", json!(-3)),
        ("/solve/switching_functions", json!("true")),
        ("/bodies/0/angular_velocity", json!([0.0, 0.0, 1.0])),
        ("/gravity", json!([0.0, -9.81, 0.0])),
        ("/bodies/0/position", json!([0.5])),
        ("/bodies/0/position", json!([0.5, 0.0, 0.0])),
        ("/bodies/0/inertia", json!([0.1, 0.1, 0.1])),
        ("/joints/0/points", json!(["O"])),
        ("/joints/0/points", json!([[0.0, 0.0], "O", "A"])),
        ("/joints/0/bodies", json!(["bar"])),
        ("/joints/0/bodies", json!(["ground", "bar", "arm"])),
        ("/springs/0/points", json!([[1.5, 1.0]])),
        ("/loads/0/value", json!(["0"])),
        ("/loads/0/value", json!(["0", "0", "0"])),
        ("/loads/1/value", json!([0.01, 0.0])),
        ("/outputs", json!("bar.A")),
        ("/outputs", json!([1, 2])),
    ] {
        add(
            format!("{f} = {x}"),
            Input::Json(set(planar(), f, x)),
            false,
        );
    }
    for (f, x) in [
        ("/bond_graph/elements/2/value", json!(true)),
        ("/bond_graph/elements/2/kind", json!(3)),
        ("/bond_graph/elements", json!({"m": 1})),
        ("/bond_graph/bonds/0", json!(["F", "v"])),
        ("/bond_graph/bonds/0/from", json!(0)),
        ("/bodies", json!([])),
    ] {
        add(
            format!("raw {f} = {x}"),
            Input::Json(set(raw(), f, x)),
            false,
        );
    }

    // 3. missing fields
    for f in [
        "/solve",
        "/solve/t_end",
        "/bodies/0/mass",
        "/bodies/0/inertia",
        "/bodies/0/name",
        "/joints/0/type",
        "/joints/0/bodies",
        "/joints/0/points",
        "/springs/0/stiffness",
        "/springs/0/points",
        "/loads/0/value",
        "/loads/0/body",
        "/loads/0/type",
        "/events/0/when",
        "/bodies/0/points/A",
        "/bodies/1/points/O",
        "/bodies",
    ] {
        add(
            format!("missing {f}"),
            Input::Json(remove(planar(), f)),
            false,
        );
    }
    for f in [
        "/bond_graph/elements/2/value",
        "/bond_graph/elements/2/kind",
        "/bond_graph/elements/2/name",
        "/bond_graph/elements/3/stiffness",
        "/bond_graph/bonds",
        "/bond_graph/bonds/1/to",
    ] {
        add(
            format!("raw missing {f}"),
            Input::Json(remove(raw(), f)),
            false,
        );
    }
    add(
        "missing /bodies/0/inertia in 3D".into(),
        Input::Json(remove(spatial(), "/bodies/0/inertia")),
        false,
    );

    // 4. out-of-range values
    for (f, x) in [
        ("/bodies/0/mass", json!(0.0)),
        ("/bodies/0/mass", json!(-1.0)),
        ("/bodies/0/mass", json!(1e-320)),
        ("/bodies/0/mass", json!(1e200)),
        ("/bodies/0/inertia", json!(-0.1)),
        ("/bodies/0/inertia", json!(1e300)),
        ("/springs/0/stiffness", json!(-10.0)),
        ("/springs/0/damping", json!(-0.1)),
        ("/springs/0/rest_length", json!(-1.0)),
        ("/solve/t_end", json!(0.0)),
        ("/solve/t_end", json!(-1.0)),
        ("/solve/t_end", json!(1e300)),
        ("/solve/output_step", json!(0.0)),
        ("/solve/output_step", json!(-0.1)),
        ("/solve/output_step", json!(10.0)),
        ("/solve/output_step", json!(1e-12)),
        ("/solve/rtol", json!(0.0)),
        ("/solve/rtol", json!(10.0)),
        ("/solve/rtol", json!(1e-20)),
        ("/solve/atol", json!(-1.0)),
        ("/solve/atol", json!(1e6)),
        ("/solve/t_start", json!(5.0)),
        ("/solve/max_steps", json!(0)),
        ("/solve/max_wall_seconds", json!(0.0)),
        ("/solve/max_wall_seconds", json!(-1.0)),
        ("/solve/joint_stiffness", json!(0.0)),
        ("/solve/joint_stiffness", json!(1e30)),
        ("/solve/output_times", json!([0.1, 0.05])),
        ("/solve/output_times", json!([0.0, 5.0])),
        ("/solve/output_times", json!([])),
        ("/dimension", json!(4)),
        ("/dimension", json!(1)),
        ("/dimension", json!(2.5)),
        ("/dimension", json!(3)),
        ("/gravity", json!([0.0, -1e20])),
        ("/bodies/0/position", json!([1e13, 0.0])),
        ("/bodies/0/angle", json!(1e7)),
        ("/bodies/0/velocity", json!([1e13, 0.0])),
        ("/bodies/0/points/A", json!([1e13, 0.0])),
        ("/loads/1/value", json!(1e150)),
        ("/springs/0/stiffness", json!(1e150)),
    ] {
        add(
            format!("{f} = {x}"),
            Input::Json(set(planar(), f, x)),
            false,
        );
    }
    add(
        "both output_step and output_times".into(),
        Input::Json(set(planar(), "/solve/output_times", json!([0.0, 0.1]))),
        false,
    );
    for (f, x) in [
        ("/bodies/0/inertia", json!([1.0, 0.1, 0.1])),
        ("/bodies/0/inertia", json!([-0.1, 0.1, 0.05])),
        ("/bodies/0/inertia", json!([0.1, 0.1])),
        ("/bodies/0/cardan", json!([0.0, 1e7, 0.0])),
        ("/bodies/0/angle", json!(0.5)),
        ("/joints/0/type", json!("revolute")),
        ("/joints/0/type", json!("universal")),
        ("/gravity", json!([0.0, -9.81])),
    ] {
        add(
            format!("3D {f} = {x}"),
            Input::Json(set(spatial(), f, x)),
            false,
        );
    }
    for (f, x) in [
        ("/bond_graph/elements/2/value", json!(-1.5)),
        ("/bond_graph/elements/3/stiffness", json!(0.0)),
        ("/bond_graph/elements/3/stiffness", json!(-6.0)),
        ("/bond_graph/elements/4/value", json!(-0.3)),
        ("/bond_graph/elements/2/value", json!(1e200)),
        ("/bond_graph/elements/3/initial", json!(1e200)),
        ("/bond_graph/elements/2/value", json!("-1.5")),
        ("/bond_graph/elements/4/value", json!("-0.3*t - 1")),
        ("/bond_graph/elements/3/stiffness", json!("t")),
    ] {
        // a spring stiffening with time from 0 is legal (§11.2: stiffness >= 0)
        let legal = x == json!("t");
        add(
            format!("raw {f} = {x}"),
            Input::Json(set(raw(), f, x)),
            legal,
        );
    }

    // 5. nonsense joints
    for (what, j) in [
        (
            "same body twice",
            json!({ "name": "j", "type": "revolute", "bodies": ["bar", "bar"], "points": ["O", "A"] }),
        ),
        (
            "unknown body",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "barr"], "points": [[0, 0], "O"] }),
        ),
        (
            "unknown point",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0, 0], "Q"] }),
        ),
        (
            "ground named point",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "bar"], "points": ["O", "O"] }),
        ),
        (
            "ground to ground",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "ground"], "points": [[0, 0], [0, 0]] }),
        ),
        (
            "type hinge",
            json!({ "name": "j", "type": "hinge", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "type pin",
            json!({ "name": "j", "type": "pin", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "type Revolute",
            json!({ "name": "j", "type": "Revolute", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "spherical in 2D",
            json!({ "name": "j", "type": "spherical", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "prismatic without axis",
            json!({ "name": "j", "type": "prismatic", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "prismatic zero axis",
            json!({ "name": "j", "type": "prismatic", "bodies": ["ground", "bar"], "points": [[0, 0], "O"], "axis": [0, 0] }),
        ),
        (
            "revolute with axis in 2D",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0, 0], "O"], "axis": [0, 1] }),
        ),
        (
            "gear without ratio",
            json!({ "name": "j", "type": "gear", "bodies": ["bar", "arm"] }),
        ),
        (
            "gear ratio 0",
            json!({ "name": "j", "type": "gear", "bodies": ["bar", "arm"], "ratio": 0 }),
        ),
        (
            "gear with ground",
            json!({ "name": "j", "type": "gear", "bodies": ["ground", "bar"], "ratio": 2 }),
        ),
        (
            "gear with points",
            json!({ "name": "j", "type": "gear", "bodies": ["bar", "arm"], "ratio": 2, "points": ["O", "O"] }),
        ),
        (
            "rack without radius",
            json!({ "name": "j", "type": "rack_pinion", "bodies": ["bar", "arm"], "axis": [1, 0] }),
        ),
        (
            "rack radius -1",
            json!({ "name": "j", "type": "rack_pinion", "bodies": ["bar", "arm"], "axis": [1, 0], "radius": -1 }),
        ),
        (
            "distance length 0",
            json!({ "name": "j", "type": "distance", "bodies": ["ground", "bar"], "points": [[0, 0], "A"], "length": 0 }),
        ),
        (
            "distance length -1",
            json!({ "name": "j", "type": "distance", "bodies": ["ground", "bar"], "points": [[0, 0], "A"], "length": -1 }),
        ),
        (
            "distance with ratio",
            json!({ "name": "j", "type": "distance", "bodies": ["ground", "bar"], "points": [[0, 0], "A"], "ratio": 2 }),
        ),
        (
            "universal in 2D",
            json!({ "name": "j", "type": "universal", "bodies": ["ground", "bar"], "points": [[0, 0], "O"], "axes": [[1, 0], [0, 1]] }),
        ),
        (
            "slot without axis",
            json!({ "name": "j", "type": "slot", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "joint name empty",
            json!({ "name": "", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
        (
            "point 3 coordinates in 2D",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0, 0, 0], "O"] }),
        ),
        (
            "point as number",
            json!({ "name": "j", "type": "revolute", "bodies": ["ground", "bar"], "points": [0, "O"] }),
        ),
        (
            "body as index",
            json!({ "name": "j", "type": "revolute", "bodies": [0, 1], "points": [[0, 0], "O"] }),
        ),
        (
            "weld twice",
            json!({ "name": "j", "type": "weld", "bodies": ["ground", "bar"], "points": [[0, 0], "O"] }),
        ),
    ] {
        let mut v = planar();
        v["joints"].as_array_mut().unwrap().push(j);
        add(format!("joint: {what}"), Input::Json(v), false);
    }
    {
        // the same pin listed twice (redundant): legal, solved with a warning or silently
        let mut v = planar();
        let j = v["joints"][0].clone();
        let mut j2 = j.clone();
        j2["name"] = json!("pivot2");
        v["joints"].as_array_mut().unwrap().push(j2);
        add(
            "joint: the pivot listed twice (redundant)".into(),
            Input::Json(v),
            true,
        );
        // a mechanism locked by its joints (0 DOF and over-constrained)
        let mut v = planar();
        v["joints"]
            .as_array_mut()
            .unwrap()
            .push(json!({ "name": "lock", "type": "revolute", "bodies": ["ground", "arm"], "points": [[2.0, 0.0], "B"] }));
        add(
            "joint: a pin that cannot close (0 DOF, violated)".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["joints"]
            .as_array_mut()
            .unwrap()
            .push(json!({ "name": "far", "type": "revolute", "bodies": ["ground", "arm"], "points": [[5.0, 5.0], "B"] }));
        add(
            "joint: a pin that can never close".into(),
            Input::Json(v),
            false,
        );
    }

    // 6. empty arrays and empty things
    for (f, x, legal) in [
        ("/bodies", json!([]), false),
        ("/joints", json!([]), true),
        ("/springs", json!([]), true),
        ("/loads", json!([]), true),
        ("/events", json!([]), true),
        ("/outputs", json!([]), true),
        ("/gravity", json!([]), false),
        ("/bodies/0/points", json!({}), false), // its joints then name no point
        ("/bodies/0/position", json!([]), false),
        ("/joints/0/points", json!([]), false),
        ("/joints/0/bodies", json!([]), false),
        ("/loads/0/value", json!([]), false),
        (
            "/loads/0/value",
            json!({ "table": { "t": [], "v": [] } }),
            false,
        ),
        ("/solve", json!({}), false),
        ("/outputs", json!([""]), false),
        ("/bodies/0/name", json!(""), false),
        ("/events/0/when", json!(""), false),
        ("/loads/0/value", json!(["", "0"]), false),
    ] {
        add(
            format!("empty {f} = {x}"),
            Input::Json(set(planar(), f, x)),
            legal,
        );
    }
    add(
        "raw empty elements".into(),
        Input::Json(set(raw(), "/bond_graph/elements", json!([]))),
        false,
    );
    add(
        "raw empty bonds".into(),
        Input::Json(set(raw(), "/bond_graph/bonds", json!([]))),
        false,
    );
    add("empty object".into(), Input::Json(json!({})), false);

    // 7. duplicate and odd names
    for (what, v) in [
        (
            "duplicate body names",
            set(planar(), "/bodies/1/name", json!("bar")),
        ),
        (
            "duplicate joint names",
            set(planar(), "/joints/1/name", json!("pivot")),
        ),
        (
            "duplicate load names",
            set(planar(), "/loads/1/name", json!("push")),
        ),
        (
            "body named ground",
            set(planar(), "/bodies/0/name", json!("ground")),
        ),
        (
            "body named Ground",
            set(planar(), "/bodies/0/name", json!("Ground")),
        ),
        (
            "body name with a dot",
            set(planar(), "/bodies/0/name", json!("bar.1")),
        ),
        (
            "body name with a backquote",
            set(planar(), "/bodies/0/name", json!("bar`")),
        ),
        (
            "point name with a dot",
            rename(planar(), "/bodies/1/points/B", "B.1"),
        ),
        (
            "point name empty",
            rename(planar(), "/bodies/1/points/B", ""),
        ),
        (
            "spring name duplicates a load's",
            set(planar(), "/springs/0/name", json!("push")),
        ),
        (
            "joint name = body name",
            set(planar(), "/joints/0/name", json!("bar")),
        ),
    ] {
        let legal = what.starts_with("spring name")
            || what.starts_with("joint name")
            || what == "body named Ground";
        add(format!("names: {what}"), Input::Json(v), legal);
    }
    {
        let mut v = planar();
        v["raw"] = json!(1);
        add("unknown top-level key raw".into(), Input::Json(v), false);
        let mut v = raw();
        let e = v["bond_graph"]["elements"][2].clone();
        v["bond_graph"]["elements"].as_array_mut().unwrap().push(e);
        add("raw duplicate element names".into(), Input::Json(v), false);
        let mut v = raw();
        v["bond_graph"]["bonds"]
            .as_array_mut()
            .unwrap()
            .push(json!({"from": "v", "to": "nowhere"}));
        add(
            "raw bond to an unknown element".into(),
            Input::Json(v),
            false,
        );
        let mut v = raw();
        v["bond_graph"]["bonds"]
            .as_array_mut()
            .unwrap()
            .push(json!({"from": "v", "to": "v"}));
        add(
            "raw bond from an element to itself".into(),
            Input::Json(v),
            false,
        );
        let mut v = raw();
        v["bond_graph"]["elements"][1]["kind"] = json!("junction");
        add("raw unknown kind junction".into(), Input::Json(v), false);
        let mut v = raw();
        v["bond_graph"]["elements"][1]["kind"] = json!("2");
        add("raw unknown kind 2".into(), Input::Json(v), false);
        let mut v = raw();
        v["bond_graph"]["elements"][2]["kind"] = json!("i");
        add("raw kind in lower case i".into(), Input::Json(v), false);
        let mut v = raw();
        v["bond_graph"]["elements"][2]["value"] = json!("1.5*unknown");
        add(
            "raw value names an unknown variable".into(),
            Input::Json(v),
            false,
        );
        let mut v = raw();
        v["bond_graph"]["elements"][0]["value"] = json!("sin(");
        add("raw value syntax error".into(), Input::Json(v), false);
        let mut v = raw();
        v["events"] = json!([{ "when": "t - 0.1" }]);
        add("raw with events".into(), Input::Json(v), false);
        let mut v = planar();
        v["bond_graph"] = raw()["bond_graph"].clone();
        add("bodies and a bond_graph".into(), Input::Json(v), false);
    }
    // unicode: legal names, and look-alike field names
    for (what, v, legal) in [
        ("body name Ärm", rename_body(planar(), "Ärm"), true),
        (
            "body name in Cyrillic",
            rename_body(planar(), "рычаг"),
            true,
        ),
        (
            "body name with an emoji",
            rename_body(planar(), "bar🙂"),
            true,
        ),
        (
            "body name with a space",
            rename_body(planar(), "left arm"),
            true,
        ),
        (
            "field name mass with a zero-width space",
            rename(planar(), "/bodies/0/mass", "mass\u{200b}"),
            false,
        ),
        (
            "field name mass with a Cyrillic a",
            rename(planar(), "/bodies/0/mass", "m\u{0430}ss"),
            false,
        ),
        (
            "field name t_end with a trailing space",
            rename(planar(), "/solve/t_end", "t_end "),
            false,
        ),
        (
            "joint type with a trailing space",
            set(planar(), "/joints/0/type", json!("revolute ")),
            false,
        ),
        (
            "joint type in full-width letters",
            set(planar(), "/joints/0/type", json!("ｒｅｖｏｌｕｔｅ")),
            false,
        ),
        (
            "expression with a unicode minus",
            set(planar(), "/loads/0/value/0", json!("\u{2212}0.1*t")),
            false,
        ),
        (
            "expression with a multiplication sign",
            set(planar(), "/loads/0/value/0", json!("0.1\u{00d7}t")),
            false,
        ),
        (
            "expression with π",
            set(planar(), "/loads/0/value/0", json!("sin(π*t)")),
            false,
        ),
    ] {
        add(format!("unicode: {what}"), Input::Json(v), legal);
    }

    // 8. huge and tiny numbers in every numeric field
    let numeric = [
        "/gravity/1",
        "/bodies/0/mass",
        "/bodies/0/inertia",
        "/bodies/0/position/0",
        "/bodies/0/angle",
        "/bodies/0/velocity/0",
        "/bodies/0/angular_velocity",
        "/bodies/0/points/A/0",
        "/joints/0/points/0/0",
        "/springs/0/stiffness",
        "/springs/0/damping",
        "/springs/0/rest_length",
        "/loads/1/value",
        "/solve/t_end",
        "/solve/output_step",
        "/solve/rtol",
        "/solve/atol",
    ];
    for f in numeric {
        for x in [1e308, -1e308, 5e-324, -1e-310] {
            add(
                format!("{f} = {x:e}"),
                Input::Json(set(planar(), f, json!(x))),
                false,
            );
        }
    }
    for (f, x) in [
        ("/bond_graph/elements/2/value", 5e-324),
        ("/bond_graph/elements/3/stiffness", 1e308),
        ("/bond_graph/elements/3/stiffness", 5e-324),
        ("/bond_graph/elements/4/value", 1e308),
        ("/bond_graph/elements/0/value", -1e308),
        ("/solve/t_end", 1e-300),
    ] {
        add(
            format!("raw {f} = {x:e}"),
            Input::Json(set(raw(), f, json!(x))),
            false,
        );
    }

    // 9. units written into strings
    for (f, x) in [
        ("/bodies/0/mass", "1 kg"),
        ("/bodies/0/mass", "1kg"),
        ("/bodies/0/inertia", "0.08 kg m^2"),
        ("/bodies/0/angle", "90deg"),
        ("/bodies/0/angle", "90°"),
        ("/gravity/1", "-9.81 m/s^2"),
        ("/gravity", "earth"),
        ("/springs/0/stiffness", "10 N/m"),
        ("/solve/t_end", "5s"),
        ("/solve/t_end", "5 s"),
        ("/solve/output_step", "10ms"),
        ("/bodies/0/position/0", "50cm"),
        ("/loads/1/value", "0.01 N*m"),
        ("/loads/0/value/1", "-10 N"),
        ("/solve/rtol", "1e-6 rel"),
    ] {
        add(
            format!("units: {f} = {x:?}"),
            Input::Json(set(planar(), f, json!(x))),
            false,
        );
    }
    // numbers meant in degrees or grams: legal numbers, a wrong unit the scene cannot know
    add(
        "units: angle 90 (meant in degrees)".into(),
        Input::Json(set(planar(), "/bodies/0/angle", json!(90.0))),
        false,
    );

    // 10. expressions: syntax errors, unknown functions and names, non-finite values
    for x in [
        "1+",
        "sin(",
        "sin(t",
        "t)",
        "2**3",
        "t^",
        "1,5",
        "sin t",
        "t t",
        " ",
        "3 +* 4",
        "((t)",
        "sinh(t)",
        "foo(t)",
        "log10(t)",
        "sqrt(1, 2)",
        "atan2(t)",
        "max(t)",
        "x",
        "bar.nope",
        "bar.A.z",
        "nobody.x",
        "energy",
        "bar.Q.x",
        "arm.B",
        "e",
        "E",
        "1e",
        ".",
        "1..2",
        "t!",
        "if(t > 1, 1, 0)",
        "t > 1",
        "1/0",
        "0/0",
        "sqrt(-1)",
        "ln(0)",
        "1e400",
        "exp(1000)",
        "1/(t - 0.1)",
        "sqrt(0.1 - t)",
        "ln(bar.angle + 0.1)",
        "tan(pi/2)",
        "NaN",
        "inf",
        "Infinity",
        "\"t\"",
        "`bar`.x",
        "`bar.x",
    ] {
        // tan(pi/2) is 1.6e16 in doubles: finite, and what the user wrote
        add(
            format!("expr {x:?}"),
            Input::Json(set(planar(), "/loads/0/value/0", json!(x))),
            x == "tan(pi/2)",
        );
    }
    for x in ["bar.x +", "unknown.y", "sin(", "1/0", "pivot.Fq"] {
        add(
            format!("event when {x:?}"),
            Input::Json(set(planar(), "/events/0/when", json!(x))),
            false,
        );
    }
    for (f, x) in [
        ("/events/0/direction", json!("up")),
        ("/events/0/direction", json!("Rising")),
        ("/events/0/action", json!("halt")),
        ("/events/0/action", json!(true)),
        ("/solve/formulation", json!("DAE")),
        ("/solve/formulation", json!("rk4")),
        ("/solve/formulation", json!("euler")),
        ("/solve/integrator", json!("rk45")),
        ("/solve/linear_solver", json!("lapack")),
        ("/solve/energy_invariant", json!("yes")),
        ("/solve/energy_invariant", json!(true)),
        ("/loads/0/type", json!("moment")),
        ("/loads/0/type", json!("Force")),
        ("/loads/0/body", json!("ground")),
        ("/loads/0/body", json!("barr")),
        ("/loads/0/point", json!("Q")),
        ("/loads/1/point", json!("B")),
        ("/bodies/0/frame", json!("global")),
        ("/bodies/0/frame", json!("Body")),
        ("/springs/0/bodies", json!(["arm", "arm"])),
        ("/springs/0/bodies", json!(["ground", "nobody"])),
        ("/springs/0/points/1", json!("Z")),
        ("/outputs/0", json!("bar.Z")),
        ("/outputs/0", json!("foo")),
        ("/outputs/0", json!("Energy")),
        ("/outputs/0", json!("reactions ")),
        (
            "/loads/0/value",
            json!({ "table": { "t": [0.0, 0.0], "v": [[0, 0], [1, 0]] } }),
        ),
        (
            "/loads/0/value",
            json!({ "table": { "t": [0.0, 1.0], "v": [[0, 0]] } }),
        ),
        (
            "/loads/0/value",
            json!({ "table": { "t": [1.0, 0.0], "v": [[0, 0], [1, 0]] } }),
        ),
        (
            "/loads/0/value",
            json!({ "table": { "t": [0.0, 1.0], "v": [0, 1] } }),
        ),
        (
            "/loads/0/value",
            json!({ "tabel": { "t": [0.0], "v": [[0, 0]] } }),
        ),
        ("/inputs", json!([{ "name": "u" }])),
        ("/inputs", json!([{ "name": "t", "start": 0 }])),
        ("/inputs", json!([{ "name": "bar.x", "start": 0 }])),
    ] {
        // an input the loads do not use, its start defaulted to 0 (§22), is legal
        let legal = f == "/inputs" && x[0]["name"] == "u";
        add(
            format!("{f} = {x}"),
            Input::Json(set(planar(), f, x)),
            legal,
        );
    }

    // 11. numbers each within its bounds whose combination fails during the solve
    {
        let mut v = planar();
        v["bodies"][0]["mass"] = json!(1e100);
        v["bodies"][0]["inertia"] = json!(1e-100);
        add(
            "runtime: a body of 1e100 kg and 1e-100 kg m2".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["bodies"][1]["mass"] = json!(1e-100);
        v["bodies"][1]["inertia"] = json!(1e-100);
        v["springs"][0]["stiffness"] = json!(1e100);
        add(
            "runtime: a 1e-100 kg body on a 1e100 N/m spring".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["bodies"][0]["points"]["O"] = json!([-1e11, 0.0]);
        v["bodies"][0]["position"] = json!([1e11, 0.0]);
        add(
            "runtime: a pivot 1e11 m from its body".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["loads"][1]["value"] = json!("1e100*arm.omega^3");
        v["bodies"][1]["angular_velocity"] = json!(1.0);
        add(
            "runtime: a torque cubic in the speed, 1e100".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["loads"][1]["value"] = json!("exp(1000*t)");
        add(
            "runtime: a torque exp(1000 t)".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["springs"][0]["points"] = json!([[1.25, 0.25], "B"]);
        v["bodies"][1]["points"]["B"] = json!([0.0, 0.25]);
        add(
            "runtime: spring points coincident at the start".into(),
            Input::Json(v),
            false,
        );
        let mut v = planar();
        v["gravity"] = json!([0.0, -1e12]);
        v["bodies"][0]["velocity"] = json!([0.0, 1e12]);
        add(
            "runtime: gravity 1e12 and a speed of 1e12".into(),
            Input::Json(v),
            false,
        );
        let mut v = raw();
        v["bond_graph"]["elements"][0]["value"] = json!("1/(t - 0.1)");
        add(
            "runtime: raw source with a pole".into(),
            Input::Json(v),
            false,
        );
        let mut v = raw();
        v["bond_graph"]["elements"][2]["value"] = json!(1e-100);
        v["bond_graph"]["elements"][3]["stiffness"] = json!(1e100);
        add(
            "runtime: raw 1e-100 inertia on a 1e100 spring".into(),
            Input::Json(v),
            false,
        );
        let mut v = raw();
        v["bond_graph"]["elements"][4]["value"] = json!("1e300*exp(t*1e3)");
        add(
            "runtime: raw resistance overflowing".into(),
            Input::Json(v),
            false,
        );
    }

    // 12. text JSON cannot hold, and broken JSON
    let good = planar().to_string();
    for (what, text) in [
        (
            "NaN literal",
            good.replacen("\"mass\":1.0", "\"mass\":NaN", 1),
        ),
        (
            "Infinity literal",
            good.replacen("\"mass\":1.0", "\"mass\":Infinity", 1),
        ),
        (
            "-Infinity literal",
            good.replacen("\"stiffness\":10.0", "\"stiffness\":-Infinity", 1),
        ),
        (
            "1e999 literal",
            good.replacen("\"mass\":1.0", "\"mass\":1e999", 1),
        ),
        (
            "-1e999 literal",
            good.replacen("\"t_end\":0.2", "\"t_end\":-1e999", 1),
        ),
        (
            "hex literal",
            good.replacen("\"mass\":1.0", "\"mass\":0x10", 1),
        ),
        (
            "leading plus",
            good.replacen("\"mass\":1.0", "\"mass\":+1.0", 1),
        ),
        (
            "leading dot",
            good.replacen("\"mass\":1.0", "\"mass\":.5", 1),
        ),
        (
            "decimal comma",
            good.replacen("\"mass\":1.0", "\"mass\":1,0", 1),
        ),
        ("trailing comma", good.replacen("-9.81]", "-9.81,]", 1)),
        ("line comment", format!("// my scene\n{good}")),
        ("block comment", good.replacen("{", "{/* x */", 1)),
        ("single quotes", good.replace('"', "'")),
        ("unquoted keys", good.replacen("\"name\"", "name", 1)),
        ("truncated in half", good[..good.len() / 2].to_string()),
        ("truncated by one", good[..good.len() - 1].to_string()),
        ("two objects", format!("{good}{good}")),
        ("empty file", String::new()),
        ("whitespace only", "  \n ".into()),
        ("null", "null".into()),
        ("an array", format!("[{good}]")),
        ("a number", "42".into()),
        ("a string", "\"pendulum\"".into()),
        ("true", "true".into()),
        ("YAML", "bodies:\n  - name: bar\n    mass: 1\n".into()),
        (
            "duplicate key",
            good.replacen("\"mass\":1.0", "\"mass\":1.0,\"mass\":2.0", 1),
        ),
        ("NUL byte", good.replacen("\"trial\"", "\"tr\u{0}ial\"", 1)),
        (
            "control character in a string",
            good.replacen("\"trial\"", "\"tr\tial\"", 1),
        ),
        (
            "lone surrogate escape",
            good.replacen("\"trial\"", "\"\\ud800\"", 1),
        ),
        ("bad escape", good.replacen("\"trial\"", "\"\\q\"", 1)),
        (
            "deeply nested arrays",
            format!("{}{}", "[".repeat(100_000), "]".repeat(100_000)),
        ),
        (
            "deeply nested object",
            format!("{}1{}", "{\"a\":".repeat(50_000), "}".repeat(50_000)),
        ),
    ] {
        assert_ne!(text, good, "{what}: the mutation changed nothing");
        add(format!("text: {what}"), Input::Text(text), false);
    }
    add(
        "text: UTF-16 with a byte-order mark".into(),
        Input::Text(String::from_utf16_lossy(&[0xfeff, 0x7b, 0x7d])),
        false,
    );
    out
}

/// `v` with its first body renamed to `name` everywhere it is referred to.
fn rename_body(v: Value, name: &str) -> Value {
    let text = v.to_string().replace("\"bar\"", &format!("\"{name}\""));
    let text = text.replace("bar.A", &format!("`{name}`.A"));
    let mut v: Value = serde_json::from_str(&text).unwrap();
    // outputs take no backquotes
    v["outputs"] = json!([format!("{name}.A"), "energy"]);
    v
}

/// Whether an error message names what is wrong: a JSON path (`bodies[0].mass`, `solve.t_end`,
/// `gravity`), an element, joint or field in quotes, a flag, or a line and column of the text.
fn names_something(msg: &str) -> bool {
    let b = msg.as_bytes();
    let indexed = b
        .windows(3)
        .any(|w| w[0] == b'[' && w[1].is_ascii_digit() && (w[2] == b']' || w[2].is_ascii_digit()));
    let fields = [
        "gravity",
        "dimension",
        "solve",
        "bodies",
        "joints",
        "springs",
        "loads",
        "events",
        "outputs",
        "inputs",
        "bond_graph",
        "name",
        "description",
    ];
    let field = fields
        .iter()
        .any(|f| msg.contains(&format!("{f}:")) || msg.contains(&format!("{f}.")));
    let position = msg.contains("line ") && msg.contains("column");
    // `bondmech: PATH: message`, PATH a key or a path without spaces (`gravty: unknown field`),
    // or the document's top level
    let body = msg.strip_prefix("bondmech: ").unwrap_or(msg);
    let path = body
        .split_once(": ")
        .is_some_and(|(p, _)| !p.is_empty() && !p.contains(' '))
        || body.starts_with("the top level");
    let quoted = msg.contains('\'') || msg.contains('`') || msg.contains("\"");
    indexed || field || position || quoted || path
}

/// Runs one case; its outcome and the first line of its standard error.
fn run_case(dir: &Path, i: usize, case: &Case) -> (Outcome, String) {
    let scene = dir.join(format!("c{i}.json"));
    let bytes: Vec<u8> = match &case.input {
        Input::Json(v) => v.to_string().into_bytes(),
        Input::Text(t) => t.clone().into_bytes(),
    };
    std::fs::write(&scene, &bytes).unwrap();
    let out: PathBuf = dir.join(format!("c{i}.csv"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args([
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--max-wall-seconds",
            "20",
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bondmech runs");
    let mut se = child.stderr.take().unwrap();
    let err_t = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut se, &mut s).ok();
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let err = err_t.join().unwrap();
    let first = err.lines().next().unwrap_or("").chars().take(300).collect();
    if std::fs::read(&scene).unwrap() != bytes {
        return (Outcome::DataLoss, first);
    }
    let Some(status) = status else {
        return (Outcome::Hang, first);
    };
    use std::os::unix::process::ExitStatusExt;
    if status.signal().is_some() {
        return (Outcome::Abort, first);
    }
    if status.code() == Some(101) || err.contains("panicked") {
        return (Outcome::Panic, first);
    }
    if status.success() {
        return if err.contains("warning") {
            (
                Outcome::Warned,
                err.lines().find(|l| l.contains("warning")).unwrap().into(),
            )
        } else if case.legal {
            (Outcome::Legal, first)
        } else {
            (Outcome::Silent, first)
        };
    }
    // a refusal: every line of it must name something
    let named = err
        .lines()
        .filter(|l| !l.contains("warning"))
        .all(names_something);
    if named && !err.trim().is_empty() {
        (Outcome::Clear, first)
    } else {
        (Outcome::Vague, first)
    }
}

#[test]
fn several_hundred_new_user_mistakes_are_refused_clearly_or_warned_about() {
    let cases = cases();
    assert!(cases.len() >= 300, "{} cases", cases.len());
    let dir = support::cli::fresh_dir("trial", "cases");
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<(usize, Outcome, String)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..4)
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                        let Some(c) = cases.get(i) else { break };
                        let (o, msg) = run_case(&dir, i, c);
                        mine.push((i, o, msg));
                    }
                    mine
                })
            })
            .collect();
        let mut all: Vec<_> = workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect();
        all.sort_by_key(|r| r.0);
        all
    });
    let mut counts = std::collections::BTreeMap::new();
    for (i, o, msg) in &results {
        *counts.entry(*o).or_insert(0usize) += 1;
        if !matches!(o, Outcome::Clear) {
            println!("{o:?}\t{}\t{msg}", cases[*i].name);
        }
    }
    println!("{} cases: {counts:?}", results.len());
    let n = |o: Outcome| counts.get(&o).copied().unwrap_or(0);
    for bad in [
        Outcome::Hang,
        Outcome::Panic,
        Outcome::Abort,
        Outcome::DataLoss,
    ] {
        assert_eq!(n(bad), 0, "{bad:?}: {counts:?}");
    }
    assert!(n(Outcome::Silent) <= 6, "silently accepted: {counts:?}");
    assert!(n(Outcome::Vague) <= 10, "vague: {counts:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
