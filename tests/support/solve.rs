//! Solving a bundled scene the way the joint tests do.

use bondmech::{FormulationKind, Model, Scene, Solution};

/// The bundled scene at `path` with `"reactions"` among its outputs (the joint forces the
/// tests check; the bundled scenes leave them out to keep their default runs lean).
pub fn model_with_reactions(path: &str) -> Model {
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    json["outputs"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!("reactions"));
    Model::new(&Scene::from_json_str(&json.to_string()).unwrap()).unwrap()
}

/// `model` solved under `formulation` at rtol 1e-10, atol 1e-12, on the scene's output times.
pub fn solve_tight(model: &Model, formulation: FormulationKind) -> Solution {
    let mut o = model.default_options();
    o.formulation = formulation;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    model
        .solve(&o)
        .unwrap_or_else(|e| panic!("{formulation:?}: {e}"))
}

/// `base` with joint `joint`'s field `key` set to `value`, or removed when `value` is null.
pub fn with_joint_field(
    base: &serde_json::Value,
    joint: usize,
    key: &str,
    value: serde_json::Value,
) -> serde_json::Value {
    let mut v = base.clone();
    if value.is_null() {
        v["joints"][joint].as_object_mut().unwrap().remove(key);
    } else {
        v["joints"][joint][key] = value;
    }
    v
}

/// The scene `v` is refused (`what` names the case) with an error that names `path`.
pub fn assert_refused_at(v: &serde_json::Value, what: &str, path: &str) {
    let err = Scene::from_json_str(&v.to_string())
        .expect_err(what)
        .to_string();
    assert!(err.contains(path), "{what}: {err}");
}
