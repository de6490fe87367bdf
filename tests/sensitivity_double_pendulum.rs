//! `d(bar2.angle)/d(bodies[bar2].mass)` of the double pendulum (scenes/double_pendulum.json)
//! against central differences of two plain runs at `m ± h` (the reference uses no
//! sensitivity code: two ordinary solves at a tight tolerance).

use bondmech::sensitivity::{sensitivity, SensitivityRequest};
use bondmech::{Model, Scene};

const T_END: f64 = 2.0;
const PATH: &str = "bodies[bar2].mass";

fn scene(formulation: &str, mass: f64, rtol: f64) -> Scene {
    let sets = [
        format!("solve.formulation=\"{formulation}\""),
        format!("solve.t_end={T_END}"),
        "solve.output_step=0.02".to_string(),
        format!("solve.rtol={rtol:e}"),
        format!("solve.atol={:e}", rtol * 1e-2),
        format!("{PATH}={mass:?}"),
    ];
    bondmech::scene::path::scene_from_path_with("scenes/double_pendulum.json", &sets).unwrap()
}

fn angle(formulation: &str, mass: f64) -> (Vec<f64>, Vec<f64>) {
    let model = Model::new(&scene(formulation, mass, 1e-12)).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    let i = sol.columns.iter().position(|c| c == "bar2.angle").unwrap();
    (sol.times.clone(), sol.rows.iter().map(|r| r[i]).collect())
}

fn check(formulation: &str) {
    let h = 2e-4;
    let (times, plus) = angle(formulation, 1.0 + h);
    let (_, minus) = angle(formulation, 1.0 - h);
    let reference: Vec<f64> = plus
        .iter()
        .zip(&minus)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect();
    let s = sensitivity(
        &scene(formulation, 1.0, 1e-10),
        &SensitivityRequest::new(&[PATH]),
    )
    .unwrap();
    assert_eq!(s.times.len(), times.len());
    let got = s.column(&format!("d(bar2.angle)/d({PATH})")).unwrap();
    let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 1e-2, "the mass moves the angle: {scale}");
    let err = got
        .iter()
        .zip(&reference)
        .fold(0.0f64, |m, (g, r)| m.max((g - r).abs()));
    eprintln!(
        "{formulation}: max |sensitivity − central difference| = {err:.3e} of {scale:.3e} ({:.2e} relative); {} steps, {} sensitivity residuals",
        err / scale,
        s.stats.steps,
        s.sens_stats.residual_evals
    );
    assert!(
        err <= 1e-5 * scale,
        "{formulation}: {err:.3e} > 1e-5 × {scale:.3e}"
    );
}

#[test]
fn mass_sensitivity_matches_central_differences_dae() {
    check("dae");
}

#[test]
fn mass_sensitivity_matches_central_differences_ggl() {
    check("ggl");
}
