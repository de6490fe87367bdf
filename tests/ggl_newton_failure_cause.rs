//! A GGL Newton failure that is not a singular passage names its cause (issue 46, the trial's
//! F2): the change-point four-bar (`tests/references/trial/findings/f2_…`: ground 1, crank 1,
//! coupler 1, rocker 1, which passes a change point where two bars fold) at rtol 1e-12,
//! atol 1e-14 stopped with a bare `IDA_CONV_FAIL` after the default handed over to the GGL,
//! where the partitioned formulation completes.

use bondmech::{FormulationKind, Model, Scene};

const SCENE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/references/trial/findings/f2_change_point_four_bar_rtol1e-12.json"
);

fn model() -> Model {
    let json = std::fs::read_to_string(SCENE).expect("the finding's scene");
    Model::new(&Scene::from_json_str(&json).expect("valid")).expect("builds")
}

#[test]
fn regression_a_bare_ida_conv_fail_on_the_change_point_four_bar_at_rtol_1e12() {
    let m = model();
    let o = m.default_options();
    assert_eq!((o.rtol, o.atol), (1e-12, 1e-14), "the finding's tolerances");
    match m.solve(&o) {
        // a build whose default passes here says so: the cause then needs no naming
        Ok(sol) => assert!(sol.summary.completed, "{:?}", sol.summary),
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains("IDA_CONV_FAIL"), "{text}");
            assert!(text.contains("Newton iteration failed"), "{text}");
            assert!(text.contains("κ(G_v M⁺ G_vᵀ)"), "{text}");
            assert!(text.contains("partitioned formulation"), "{text}");
        }
    }
}

/// What the message offers passes: the partitioned formulation completes the run.
#[test]
fn the_partitioned_formulation_completes_the_change_point_four_bar_at_rtol_1e12() {
    let m = model();
    let mut o = m.default_options();
    o.formulation = FormulationKind::Partitioned;
    let sol = m.solve(&o).expect("the partitioned formulation completes");
    assert!(sol.summary.completed);
}
