//! One test per validation error class: each checks the error kind and that the message names
//! the JSON path and the element or bond concerned. Also checks that all errors are collected.

use bondmech::bond::json::RawBondGraph;
use bondmech::bond::model::{BondGraph, ElementKind, Parameter};
use bondmech::bond::validate::{validate, BondError};
use bondmech::bond::BondJsonError;
use serde_json::{json, Value};

fn errors(v: Value) -> Vec<BondError> {
    let raw: RawBondGraph = serde_json::from_value(v).expect("raw JSON");
    raw.to_graph().expect_err("graph must be rejected").0
}

/// A valid mass on a 1-junction driven by a force, to be broken by each test.
fn base() -> Value {
    json!({
        "elements": [
            {"name": "F", "kind": "Se", "value": 1.0},
            {"name": "j", "kind": "1"},
            {"name": "m", "kind": "I", "value": 2.0}
        ],
        "bonds": [{"from": "F", "to": "j"}, {"from": "j", "to": "m"}]
    })
}

fn one(v: Value) -> String {
    let e = errors(v);
    assert_eq!(e.len(), 1, "{e:?}");
    e[0].to_string()
}

#[test]
fn base_graph_is_valid() {
    let raw: RawBondGraph = serde_json::from_value(base()).unwrap();
    assert!(raw.to_graph().is_ok());
}

#[test]
fn unknown_bond_end_names_path_and_element() {
    let mut v = base();
    v["bonds"][0]["to"] = json!("j9");
    let e = errors(v);
    // the source at the resolved end is not also reported as having the wrong bond count
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(matches!(e[0], BondError::UnknownElement { .. }));
    assert_eq!(
        e[0].to_string(),
        "bond_graph.bonds[0].to: unknown element 'j9' in bond 'b0'"
    );
}

#[test]
fn duplicate_element_name_is_reported_with_both_paths() {
    let mut v = base();
    v["elements"][2]["name"] = json!("F");
    v["bonds"][1]["to"] = json!("j");
    let e = errors(v);
    let d = e
        .iter()
        .find(|e| matches!(e, BondError::DuplicateName { .. }))
        .expect("duplicate");
    assert_eq!(
        d.to_string(),
        "bond_graph.elements[2].name: duplicate name 'F' (already used at bond_graph.elements[0])"
    );
}

#[test]
fn duplicate_bond_name_is_reported() {
    let mut v = base();
    v["bonds"][0]["name"] = json!("x");
    v["bonds"][1]["name"] = json!("x");
    let msg = one(v);
    assert!(
        msg.starts_with("bond_graph.bonds[1].name: duplicate name 'x'"),
        "{msg}"
    );
}

#[test]
fn one_port_with_two_bonds_is_rejected() {
    let mut v = base();
    v["elements"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "j2", "kind": "0"}));
    v["bonds"]
        .as_array_mut()
        .unwrap()
        .push(json!({"from": "j2", "to": "m"}));
    let msg = one(v);
    assert_eq!(
        msg,
        "bond_graph.elements[2]: I element 'm' needs exactly 1 bond(s), has 2"
    );
}

#[test]
fn two_port_with_one_bond_is_rejected() {
    let mut v = base();
    v["elements"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "tf", "kind": "TF", "modulus": 2.0}));
    v["bonds"]
        .as_array_mut()
        .unwrap()
        .push(json!({"from": "j", "to": "tf"}));
    let msg = one(v);
    assert!(
        msg.starts_with("bond_graph.elements[3]: TF element 'tf' needs exactly 2 bond(s), has 1"),
        "{msg}"
    );
}

#[test]
fn two_port_with_both_bonds_inward_is_rejected() {
    let mut v = base();
    let el = v["elements"].as_array_mut().unwrap();
    el.push(json!({"name": "g", "kind": "MGY", "modulus": "p_m"}));
    el.push(json!({"name": "k", "kind": "1"}));
    let b = v["bonds"].as_array_mut().unwrap();
    b.push(json!({"from": "j", "to": "g"}));
    b.push(json!({"from": "k", "to": "g"}));
    let e = errors(v);
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(matches!(
        e[0],
        BondError::TwoPortDirection {
            inward: 2,
            outward: 0,
            ..
        }
    ));
    assert!(e[0]
        .to_string()
        .starts_with("bond_graph.elements[3]: two-port 'g'"));
}

#[test]
fn isolated_junction_is_rejected() {
    let mut v = base();
    v["elements"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "lonely", "kind": "0"}));
    assert_eq!(
        one(v),
        "bond_graph.elements[3]: junction 'lonely' has no bonds"
    );
}

#[test]
fn empty_graph_is_rejected() {
    let msg = one(json!({"elements": [], "bonds": []}));
    assert_eq!(msg, "bond_graph.elements: empty bond graph (no elements)");
}

#[test]
fn modulus_with_unknown_variable_is_rejected() {
    let mut v = base();
    let el = v["elements"].as_array_mut().unwrap();
    el.push(json!({"name": "tf", "kind": "MTF", "modulus": "0.5*cos(x_J) + x_j + p_m + t"}));
    el.push(json!({"name": "k", "kind": "1"}));
    let b = v["bonds"].as_array_mut().unwrap();
    b.push(json!({"from": "j", "to": "tf"}));
    b.push(json!({"from": "tf", "to": "k"}));
    let e = errors(v);
    // x_J is unknown (no element J); x_j (1-junction), p_m (inertia) and t are known
    assert_eq!(e.len(), 1, "{e:?}");
    let msg = e[0].to_string();
    assert!(msg.starts_with("bond_graph.elements[3].modulus:"), "{msg}");
    assert!(
        msg.contains("'tf'") && msg.contains("unknown variable 'x_J'"),
        "{msg}"
    );
}

#[test]
fn malformed_expression_is_rejected() {
    let mut v = base();
    v["elements"][0]["value"] = json!("100*sinh(t)");
    let msg = one(v);
    assert!(msg.starts_with("bond_graph.elements[0].value:"), "{msg}");
    assert!(msg.contains("unknown function 'sinh'"), "{msg}");
}

#[test]
fn non_finite_parameter_is_rejected() {
    let mut g = BondGraph::new();
    let f = g.add_element("F", ElementKind::Se, Some(Parameter::Const(f64::NAN)));
    let j = g.add_junction("j", ElementKind::One);
    let m = g.add_element("m", ElementKind::I, Some(Parameter::Const(f64::INFINITY)));
    g.add_bond(f, j);
    g.add_bond(j, m);
    let e = validate(&g).unwrap_err().0;
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(e.iter().all(|e| matches!(e, BondError::NonFinite { .. })));
    assert!(e[0]
        .to_string()
        .starts_with("bond_graph.elements[0].value: parameter of 'F' is not finite"));
    assert!(e[1]
        .to_string()
        .starts_with("bond_graph.elements[2].value: parameter of 'm'"));
}

#[test]
fn negative_inertia_and_non_positive_stiffness_are_rejected() {
    let mut v = base();
    v["elements"][2]["value"] = json!(-1.0);
    assert_eq!(
        one(v),
        "bond_graph.elements[2].value: inertia of 'm' must be positive, got -1"
    );
    let v = json!({
        "elements": [{"name": "j", "kind": "1"}, {"name": "k", "kind": "C", "stiffness": -5.0}],
        "bonds": [{"from": "j", "to": "k"}]
    });
    assert_eq!(
        one(v),
        "bond_graph.elements[1].stiffness: stiffness of 'k' must be positive, got -5"
    );
}

/// A zero inertia is a massless flow (a mechanism body without rotational inertia): the graph
/// is valid, but a graph without joint closures cannot fix that flow, so its equations are
/// refused with the element named.
#[test]
fn zero_inertia_is_valid_but_its_flow_needs_closures() {
    let mut v = base();
    v["elements"][2]["value"] = json!(0.0);
    let raw: RawBondGraph = serde_json::from_value(v).expect("raw JSON");
    let g = raw.to_graph().expect("a zero inertia is valid");
    let err = bondmech::bond::equations::equations(&g).unwrap_err();
    assert!(
        err.contains("'m'") && err.contains("nonzero inertia"),
        "{err}"
    );
}

#[test]
fn negative_resistance_is_rejected() {
    let v = json!({
        "elements": [{"name": "j", "kind": "1"}, {"name": "c", "kind": "R", "value": -1.0}],
        "bonds": [{"from": "j", "to": "c"}]
    });
    assert_eq!(
        one(v),
        "bond_graph.elements[1].value: resistance of 'c' must be non-negative, got -1"
    );
}

#[test]
fn self_bond_is_rejected() {
    let mut v = base();
    v["bonds"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "loop", "from": "j", "to": "j"}));
    assert_eq!(
        one(v),
        "bond_graph.bonds[2]: bond 'loop' connects element 'j' to itself"
    );
}

#[test]
fn unknown_kind_and_misplaced_field_are_rejected() {
    let mut v = base();
    v["elements"][1]["kind"] = json!("2");
    let msg = one(v);
    assert!(
        msg.starts_with("bond_graph.elements[1].kind: unknown element kind '2' for 'j'"),
        "{msg}"
    );

    let mut v = base();
    v["elements"][2]["modulus"] = json!(3.0);
    let msg = one(v);
    assert!(
        msg.starts_with("bond_graph.elements[2].modulus: 'm': field `modulus` does not apply"),
        "{msg}"
    );
}

#[test]
fn missing_parameter_is_rejected() {
    let mut v = base();
    v["elements"][2].as_object_mut().unwrap().remove("value");
    assert_eq!(
        one(v),
        "bond_graph.elements[2]: I element 'm' needs a parameter (`value`)"
    );
}

#[test]
fn bad_table_is_rejected() {
    let mut v = base();
    v["elements"][0]["value"] = json!({"table": {"t": [0.0, 1.0, 1.0], "v": [0.0, 1.0, 2.0]}});
    let msg = one(v);
    assert!(
        msg.starts_with("bond_graph.elements[0].value.table.t: 'F'"),
        "{msg}"
    );
}

#[test]
fn all_errors_are_collected_not_just_the_first() {
    let v = json!({
        "elements": [
            {"name": "F", "kind": "Se", "value": 1.0},
            {"name": "F", "kind": "I", "value": -1.0},
            {"name": "z", "kind": "0"}
        ],
        "bonds": [{"from": "F", "to": "nowhere"}]
    });
    let e = errors(v);
    assert!(e
        .iter()
        .any(|e| matches!(e, BondError::DuplicateName { .. })));
    assert!(e.iter().any(|e| matches!(e, BondError::NonPositive { .. })));
    assert!(e
        .iter()
        .any(|e| matches!(e, BondError::IsolatedJunction { .. })));
    assert!(e
        .iter()
        .any(|e| matches!(e, BondError::UnknownElement { .. })));
    let text = bondmech::bond::ValidationErrors(e.clone()).to_string();
    assert!(text.starts_with(&format!("{} error(s) in bond graph:", e.len())));
}

#[test]
fn malformed_json_is_a_parse_error_not_a_panic() {
    let err = BondGraph::from_json_str(r#"{"elements": [{"name": "a", "kind": "I", "valeu": 1}]}"#)
        .unwrap_err();
    assert!(matches!(err, BondJsonError::Parse(_)));
    assert!(err.to_string().contains("valeu"), "{err}");
}

#[test]
fn source_with_no_bond_is_rejected_with_its_path() {
    let mut v = base();
    v["elements"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "S", "kind": "Sf", "value": 1.0}));
    let e = errors(v);
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(matches!(e[0], BondError::WrongBondCount { .. }), "{e:?}");
    assert_eq!(
        e[0].to_string(),
        "bond_graph.elements[3]: Sf element 'S' needs exactly 1 bond(s), has 0"
    );
}

/// `base()` with a two-port of `kind` and `modulus` between the mass junction and a new spring.
fn with_two_port(kind: &str, modulus: Value) -> Value {
    let mut v = base();
    let el = v["elements"].as_array_mut().unwrap();
    el.push(json!({"name": "tp", "kind": kind, "modulus": modulus}));
    el.push(json!({"name": "k", "kind": "C", "stiffness": 3.0}));
    let b = v["bonds"].as_array_mut().unwrap();
    b.push(json!({"from": "j", "to": "tp"}));
    b.push(json!({"from": "tp", "to": "k"}));
    v
}

#[test]
fn zero_two_port_modulus_is_rejected_with_its_path() {
    for kind in ["TF", "GY", "MTF", "MGY"] {
        for modulus in [
            json!(0.0),
            json!("0"),
            json!("p_m - p_m"),
            json!("0*sin(t)"),
        ] {
            let e = errors(with_two_port(kind, modulus.clone()));
            assert_eq!(e.len(), 1, "{kind} {modulus}: {e:?}");
            assert!(matches!(e[0], BondError::ZeroModulus { .. }), "{e:?}");
            assert_eq!(
                e[0].to_string(),
                format!(
                    "bond_graph.elements[3].modulus: {kind} element 'tp': modulus is identically zero (the equations divide by it)"
                )
            );
        }
    }
    // a modulus that only passes through zero is a modelling choice, not an error
    for modulus in [json!(-2.0), json!("cos(x_m)"), json!("p_m")] {
        let raw: RawBondGraph = serde_json::from_value(with_two_port("MTF", modulus)).unwrap();
        assert!(raw.to_graph().is_ok());
    }
}
