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
