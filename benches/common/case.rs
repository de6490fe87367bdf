//! One mechanism of the speed benches: the bundled scene's model, its hand-written
//! minimal-coordinate twin ([`super::minimal`]), the output times, and the reference
//! trajectory (the minimal model on CVODE Adams at rtol 1e-12).

use bondmech::sundials::Multistep;
use bondmech::{Model, Scene};

use crate::minimal::{solve_minimal, MinimalModel};

/// A bench case.
pub struct Case {
    pub name: &'static str,
    pub model: Model,
    pub minimal: MinimalModel,
    pub times: Vec<f64>,
    pub reference: Vec<Vec<f64>>,
}

/// Loads `scenes/<name>.json` and solves its reference.
pub fn case(name: &'static str, minimal: MinimalModel) -> Case {
    let scene = Scene::from_path(format!("scenes/{name}.json")).expect("scene loads");
    let model = Model::new(&scene).expect("model builds");
    let times = scene.output_times();
    let r = solve_minimal(&minimal, Multistep::Adams, 1e-12, 1e-14, &times);
    Case {
        name,
        model,
        minimal,
        times,
        reference: r.rows,
    }
}
