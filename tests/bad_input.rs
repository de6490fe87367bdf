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

// ---------------------------------------------------------------------------------------------
// Non-finite load values: name the load (JSON path, name, expression) and the time
// ---------------------------------------------------------------------------------------------

/// The pendulum with `loads`, formulation `formulation`.
fn loaded(loads: Value, formulation: &str) -> Value {
    let mut v = pendulum();
    v["loads"] = loads;
    v["solve"]["formulation"] = json!(formulation);
    v
}

/// The error of solving `v` through the library.
fn library_error(v: &Value) -> bondmech::Error {
    let scene = Scene::from_json_str(&v.to_string()).expect("valid scene");
    let model = bondmech::Model::new(&scene).expect("model");
    model
        .solve(&model.default_options())
        .expect_err("the solve must fail")
}

/// The cause of `e`: `e` itself, or what stopped an incomplete solve (which keeps its rows).
fn root(e: &bondmech::Error) -> &bondmech::Error {
    match e {
        bondmech::Error::Incomplete { cause, .. } => root(cause),
        other => other,
    }
}

/// The stderr of `bondmech run` on `v` (written to `name`); asserts a failure exit.
fn cli_error(v: &Value, name: &str) -> String {
    let path = tmp(name);
    std::fs::write(&path, v.to_string()).unwrap();
    let out = bondmech(&["run", path.to_str().unwrap(), "--table"]);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "exit 0: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    err
}

#[test]
fn regression_load_1_over_t_at_t0_names_the_load_and_time() {
    let v = loaded(
        json!([{ "type": "torque", "body": "bar", "value": 0.5 },
               { "name": "kick", "type": "torque", "body": "bar", "value": "1/t" }]),
        "dae",
    );
    let e = library_error(&v).to_string();
    assert!(
        e.contains("loads[1].value") && e.contains("'kick'") && e.contains("\"1/t\""),
        "{e}"
    );
    assert!(e.contains("inf at t = 0"), "{e}");
    let cli = cli_error(&v, "load_1_over_t.json");
    assert!(
        cli.contains("loads[1].value (load 'kick', \"1/t\") evaluates to inf at t = 0"),
        "{cli}"
    );
}

#[test]
fn regression_load_sqrt_of_minus_1_names_the_component() {
    let v = loaded(
        json!([{ "type": "force", "body": "bar", "point": "A", "value": ["0", "sqrt(-1)"] }]),
        "dae",
    );
    let e = library_error(&v).to_string();
    assert!(
        e.contains("loads[0].value[1]") && e.contains("NaN at t = 0"),
        "{e}"
    );
}

#[test]
fn regression_load_log_turning_non_finite_mid_solve_names_the_load_and_time() {
    // log(0.5 − t) is −∞ at t = 0.5 and NaN after: every formulation must name the load and
    // stop at 0.5 (before issue 12: a bare IDA_CONV_FAIL, or 100 000 steps of "too much work")
    for formulation in ["dae", "index1", "decoupled"] {
        let v = loaded(
            json!([{ "name": "gas", "type": "torque", "body": "bar", "value": "log(0.5 - t)" }]),
            formulation,
        );
        let e = library_error(&v);
        let bondmech::Error::NonFinite { culprit, .. } = root(&e) else {
            panic!("{formulation}: expected NonFinite, got {e:?}");
        };
        assert_eq!(culprit.path, "loads[0].value", "{formulation}");
        assert!(culprit.what.contains("'gas'"), "{formulation}: {e}");
        assert!(
            (0.5..0.5 + 1e-9).contains(&culprit.t),
            "{formulation}: t = {}",
            culprit.t
        );
        let cli = cli_error(&v, &format!("load_log_{formulation}.json"));
        assert!(
            cli.contains("loads[0].value (load 'gas', \"log(0.5 - t)\")")
                && cli.contains("at t = 0.5"),
            "{formulation}: {cli}"
        );
    }
}

#[test]
fn regression_load_depending_on_the_state_turning_nan_names_the_load() {
    // sqrt(angle + 0.5) turns NaN when the falling bar passes −0.5 rad
    let v = loaded(
        json!([{ "type": "torque", "body": "bar", "value": "sqrt(bar.angle + 0.5)" }]),
        "dae",
    );
    let e = library_error(&v);
    let bondmech::Error::NonFinite { culprit, .. } = root(&e) else {
        panic!("expected NonFinite, got {e:?}");
    };
    assert_eq!(culprit.path, "loads[0].value");
    assert!(culprit.t > 0.1 && culprit.t < 1.0, "{e}");
}

/// The mass–spring–damper of `scenes/bg_mass_spring_damper.json` with force `force`.
fn spring_mass(force: &str) -> Value {
    json!({
        "bond_graph": {
            "elements": [
                {"name": "F", "kind": "Se", "value": force},
                {"name": "v", "kind": "1"},
                {"name": "m", "kind": "I", "value": 1.5},
                {"name": "k", "kind": "C", "stiffness": 6.0, "initial": 0.1},
                {"name": "b", "kind": "R", "value": 0.3}
            ],
            "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"},
                      {"from": "v", "to": "k"}, {"from": "v", "to": "b"}]
        },
        "solve": {"t_end": 1.0, "output_step": 0.1}
    })
}

#[test]
fn regression_raw_bond_graph_source_1_over_t_names_the_element_not_a_cvode_flag() {
    // before issue 12: "CVode failed with CV_FIRST_RHSFUNC_ERR (-8) at t = 0"
    let v = spring_mass("1/t");
    let e = library_error(&v).to_string();
    assert!(
        e.starts_with("bond_graph.elements[0] (Se 'F', value \"1/t\") evaluates to inf at t = 0"),
        "{e}"
    );
    let cli = cli_error(&v, "bg_1_over_t.json");
    assert!(
        cli.contains("bond_graph.elements[0] (Se 'F'") && !cli.contains("RHSFUNC"),
        "{cli}"
    );
}

#[test]
fn regression_raw_bond_graph_resistance_turning_nan_mid_solve_names_the_element() {
    // the DC motor (an IDA DAE) with an armature resistance sqrt(0.5 − t)
    let mut v: Value = serde_json::from_str(
        &std::fs::read_to_string(support::cli::scene("bg_dc_motor.json")).unwrap(),
    )
    .unwrap();
    v["bond_graph"]["elements"][2]["value"] = json!("sqrt(0.5-t)");
    v["solve"]["t_end"] = json!(1.0);
    let e = library_error(&v);
    let bondmech::Error::NonFinite { culprit, .. } = root(&e) else {
        panic!("expected NonFinite, got {e:?}");
    };
    assert_eq!(culprit.path, "bond_graph.elements[2]");
    assert!(culprit.what.contains("'Ra'"), "{e}");
    assert!((0.5..0.5 + 1e-9).contains(&culprit.t), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Raw bond graphs: single-bond junctions, unknown fields
// ---------------------------------------------------------------------------------------------

fn dc_motor() -> Value {
    serde_json::from_str(&std::fs::read_to_string(support::cli::scene("bg_dc_motor.json")).unwrap())
        .unwrap()
}

#[test]
fn regression_single_bond_zero_junction_locking_the_dc_motor_is_refused() {
    // a 0-junction hung on the rotor's 1-junction forces its flow (the rotor speed) to zero
    let mut v = dc_motor();
    v["bond_graph"]["elements"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "lock", "kind": "0"}));
    v["bond_graph"]["bonds"]
        .as_array_mut()
        .unwrap()
        .push(json!({"from": "omega", "to": "lock"}));
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(
        e.contains("bond_graph.elements[8]") && e.contains("0-junction 'lock' has a single bond"),
        "{e}"
    );
    let cli = cli_error(&v, "bg_single_bond.json");
    assert!(cli.contains("'lock'"), "{cli}");
}

#[test]
fn regression_unknown_field_in_a_bond_graph_element_names_its_index_and_name() {
    let mut v = dc_motor();
    v["bond_graph"]["elements"][2] = json!({"name": "Ra", "kind": "R", "resistence": 1.0});
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(
        e.contains("bond_graph.elements[2] (name \"Ra\"): unknown field \"resistence\" (did you mean \"value\"?"),
        "{e}"
    );
    v["bond_graph"]["elements"][2] = json!({"name": "Ra", "kind": "R", "valeu": 1.0});
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(
        e.contains("unknown field \"valeu\" (did you mean \"value\"?"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// Huge expressions: the error shows the offending part only
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_100_kb_expression_is_not_echoed_whole_in_its_error() {
    let mut expr = "0.001*t + ".repeat(10_000);
    expr.push_str("nosuchname");
    assert!(expr.len() > 100_000);
    let v = loaded(
        json!([{ "type": "torque", "body": "bar", "value": expr }]),
        "dae",
    );
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(
        e.len() < 400,
        "{} characters: {}",
        e.len(),
        &e[..400.min(e.len())]
    );
    assert!(
        e.contains("loads[0].value") && e.contains("nosuchname"),
        "{e}"
    );
    assert!(
        e.contains('…') && e.contains("column 100001 of 100010"),
        "{e}"
    );
    // unbalanced parentheses (found by the scene validation)
    let mut expr = "(t + ".repeat(30_000);
    expr.push_str(" 1");
    let v = loaded(
        json!([{ "type": "torque", "body": "bar", "value": expr }]),
        "dae",
    );
    let problems = refused(&v);
    assert!(problems.iter().all(|p| p.len() < 300), "{problems:?}");
    assert!(
        problems[0].contains("unbalanced parentheses"),
        "{problems:?}"
    );
}

#[test]
fn regression_100_kb_bond_graph_expression_is_not_echoed_whole() {
    let mut expr = "0.001*t + ".repeat(10_000);
    expr.push_str("x_nosuch");
    let v = spring_mass(&expr);
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(e.len() < 500, "{} characters", e.len());
    assert!(
        e.contains("bond_graph.elements[0]") && e.contains("x_nosuch"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// A joint stiffness that makes the decoupled twin meaningless: warned
// ---------------------------------------------------------------------------------------------

/// The summary warnings of the pendulum's decoupled twin at stiffness `k`.
fn twin_warnings(k: f64) -> Vec<String> {
    let mut v = pendulum();
    v["solve"]["formulation"] = json!("decoupled");
    v["solve"]["joint_stiffness"] = json!(k);
    v["solve"]["t_end"] = json!(0.1);
    v["solve"]["output_step"] = json!(0.05);
    let scene = Scene::from_json_str(&v.to_string()).expect("a soft joint is not refused");
    let model = bondmech::Model::new(&scene).unwrap();
    model
        .solve(&model.default_options())
        .unwrap()
        .summary
        .warnings
}

#[test]
fn regression_joint_stiffness_1e_minus_3_warns_that_the_twin_starts_kilometres_away() {
    // the pivot carries m g / 4 = 2.45 N at the start: λ/k = 2.45 km at k = 1e-3 N/m
    let w = twin_warnings(1e-3);
    let prestress: Vec<&String> = w.iter().filter(|w| w.contains("λ/k")).collect();
    assert_eq!(prestress.len(), 1, "{w:#?}");
    assert!(
        prestress[0].contains("solve.joint_stiffness")
            && prestress[0].contains("2.452e3 m")
            && prestress[0].contains("'pivot'"),
        "{}",
        prestress[0]
    );
    // the default stiffness (stretch 2.45e-8 m) says nothing
    assert!(
        twin_warnings(1e8).iter().all(|w| !w.contains("λ/k")),
        "{:#?}",
        twin_warnings(1e8)
    );
}

// ---------------------------------------------------------------------------------------------
// Models beyond the machine: refused before they are built, naming the limit
// ---------------------------------------------------------------------------------------------

/// `n` free planar bars side by side under gravity.
fn free_bodies(n: usize) -> Scene {
    let bodies: Vec<Value> = (0..n)
        .map(|i| json!({ "name": format!("b{i}"), "mass": 1.0, "inertia": 0.1, "position": [i as f64, 0.0] }))
        .collect();
    Scene::from_json_str(
        &json!({ "gravity": [0.0, -9.81], "bodies": bodies, "solve": { "t_end": 0.01 } })
            .to_string(),
    )
    .unwrap()
}

/// An `n`-link pendulum of 1 m bars.
fn chain(n: usize) -> Scene {
    let bodies: Vec<Value> = (0..n)
        .map(|i| json!({ "name": format!("b{i}"), "mass": 1.0, "inertia": 0.08,
                         "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] }, "position": [i as f64 + 0.5, 0.0] }))
        .collect();
    let mut joints = vec![
        json!({ "type": "revolute", "bodies": ["ground", "b0"], "points": [[0.0, 0.0], "O"] }),
    ];
    joints.extend((1..n).map(|i| {
        json!({ "type": "revolute", "bodies": [format!("b{}", i - 1), format!("b{i}")], "points": ["A", "O"] })
    }));
    Scene::from_json_str(
        &json!({ "gravity": [0.0, -9.81], "bodies": bodies, "joints": joints, "solve": { "t_end": 0.01 } })
            .to_string(),
    )
    .unwrap()
}

#[test]
fn regression_6000_free_bodies_are_refused_on_a_4_gib_machine_naming_the_limit() {
    use bondmech::mech::size::{check_memory, estimate_memory, estimate_memory_with};
    use bondmech::FormulationKind;
    use bondmech::LinearSolverKind;
    const GIB: u64 = 1 << 30;
    let scene = free_bodies(6000);
    let est = estimate_memory_with(&scene, FormulationKind::Dae, LinearSolverKind::Dense);
    // 18 000 coordinates and velocities: the GGL Newton matrix (36 000²) and the start's SVD
    // (4 × 18 000²) are both 9.7 GiB
    assert_eq!(
        (est.coordinates, est.velocities, est.constraint_rows),
        (18_000, 18_000, 0)
    );
    assert!((est.bytes / GIB as f64 - 9.8).abs() < 0.2, "{est:?}");
    let e = check_memory(&est, Some(4 * GIB)).unwrap_err().to_string();
    assert!(
        e.contains("~9.8 GiB") && e.contains("4.0 GiB available") && e.contains("limit: 80 %"),
        "{e}"
    );
    // the decoupled twin keeps two dense matrices of 36 000²
    let twin = estimate_memory_with(&scene, FormulationKind::Decoupled, LinearSolverKind::Dense);
    assert!(
        twin.bytes > 1.9 * est.bytes && twin.what.contains("CVODE"),
        "{twin:?}"
    );
    // chains of a few hundred bodies are far from the limit
    for n in [300, 500] {
        let est = estimate_memory(&chain(n), FormulationKind::Dae);
        assert_eq!(est.constraint_rows, 2 * n);
        check_memory(&est, Some(4 * GIB)).unwrap_or_else(|e| panic!("{n}-link chain: {e}"));
    }
    assert!(check_memory(&est, None).is_ok(), "no known limit: accepted");
}

#[test]
fn regression_model_far_beyond_the_machine_is_refused_by_model_new() {
    // 20 000 free bodies: the consistent start alone needs 4 × 60 000² doubles (107 GiB)
    let scene = free_bodies(20_000);
    let e = bondmech::Model::new(&scene).unwrap_err();
    assert!(matches!(e, bondmech::Error::TooLarge(_)), "{e:?}");
    let text = e.to_string();
    // (the default linear solver is sparse at this size: the start's dense SVD is what is
    // too large)
    assert!(
        text.contains("MemAvailable")
            && text.contains("60000 coordinates")
            && text.contains("GiB for the SVD of the dense mass–constraint matrix"),
        "{text}"
    );
}

/// `n` free spatial bodies (7 coordinates, 6 velocities each, no joints).
fn free_spatial_bodies(n: usize) -> Scene {
    let bodies: Vec<Value> = (0..n)
        .map(|i| {
            json!({ "name": format!("b{i}"), "mass": 1.0, "inertia": [1.0, 2.0, 3.0],
                         "position": [i as f64, 0.0, 0.0] })
        })
        .collect();
    Scene::from_json_str(
        &json!({ "dimension": 3, "gravity": [0.0, 0.0, -9.81], "bodies": bodies,
                 "solve": { "t_end": 0.01 } })
        .to_string(),
    )
    .unwrap()
}

#[test]
fn model_too_large_for_a_dense_newton_matrix_is_accepted_with_a_sparse_linear_solver() {
    use bondmech::mech::size::{check_memory, estimate_memory_with, SPARSE_BYTES_PER_UNKNOWN};
    use bondmech::FormulationKind;
    use bondmech::LinearSolverKind;
    // 4000 free spatial bodies: 52 000 GGL unknowns. Dense Newton matrix 8 · 52 000² bytes
    // = 21.6e9; the consistent start's SVD 4 · 8 · 24 000² = 18.4e9; symbolic part 4096 B
    // per unknown = 0.21e9.
    let scene = free_spatial_bodies(4000);
    let n = 52_000.0;
    let dense = estimate_memory_with(&scene, FormulationKind::Dae, LinearSolverKind::Dense);
    assert_eq!(dense.unknowns, 52_000);
    assert_eq!(dense.bytes, 8.0 * n * n + 4096.0 * n);
    // a machine with 25 GiB available (limit 80 % = 21.5e9 bytes) refuses it dense …
    let available = Some(25u64 << 30);
    let e = check_memory(&dense, available).unwrap_err().to_string();
    assert!(
        e.contains("the dense Newton matrix of the DAE on IDA"),
        "{e}"
    );
    // … and accepts it with faer or KLU, whose Newton matrix grows linearly: the start's
    // dense SVD (24 000 unknowns) is now the largest term
    for ls in [
        LinearSolverKind::Sparse,
        LinearSolverKind::Klu,
        LinearSolverKind::Auto,
    ] {
        let sparse = estimate_memory_with(&scene, FormulationKind::Dae, ls);
        assert_eq!(
            sparse.bytes,
            4.0 * 8.0 * 24_000f64.powi(2) + 4096.0 * n,
            "{ls:?}"
        );
        assert!(sparse.what.contains("SVD"), "{sparse:?}");
        check_memory(&sparse, available).unwrap_or_else(|e| panic!("{ls:?}: {e}"));
        // the sparse Newton matrix itself: linear in the unknowns
        let newton = SPARSE_BYTES_PER_UNKNOWN * n;
        assert!(newton < 0.03 * 8.0 * n * n);
    }
    // the scene's own solve.linear_solver decides the estimate of Model::new
    let mut dense_scene = scene.clone();
    dense_scene.solve.linear_solver = LinearSolverKind::Dense;
    assert_eq!(
        bondmech::mech::size::estimate_memory(&dense_scene, FormulationKind::Dae),
        dense
    );
    // the decoupled twin likewise: two dense 52 000² matrices, or a sparse one
    let twin_dense =
        estimate_memory_with(&scene, FormulationKind::Decoupled, LinearSolverKind::Dense);
    assert!(check_memory(&twin_dense, available).is_err());
    let twin_sparse =
        estimate_memory_with(&scene, FormulationKind::Decoupled, LinearSolverKind::Klu);
    check_memory(&twin_sparse, available).unwrap();
}
