//! Work-precision diagrams: error against CPU time for the partitioned formulation (its
//! automatic integrator choice, explicit Runge–Kutta here, and CVODE Adams), the GGL
//! DAE, the index-1 DAE and the decoupled twin (k = 1e8 N/m) at rtol 1e-4 … 1e-10 (atol =
//! rtol/100), with the hand-written minimal-coordinate model on CVODE BDF (the limit) and on
//! ARKODE's explicit Runge–Kutta beside them, on the double pendulum (3 s) and the slider-crank
//! (1 s). The error is the largest difference over the positions and angles at all output
//! times against the minimal model on CVODE Adams at rtol 1e-12 (independent of bondmech); CPU
//! is the median of three solves (integration only: `summary.cpu_seconds`).
//!
//! Writes `docs/work-precision-double_pendulum.svg` and `docs/work-precision-slider_crank.svg`
//! (drawn by `bondmech::report::plot::work_precision_svg`, as `bondmech sweep` draws its own)
//! and prints the points. Not timed by criterion: the points are the result.
//!
//! Run with `cargo bench --bench work_precision`.

#[path = "common/minimal.rs"]
mod minimal;

use std::path::Path;

use bondmech::report::plot::work_precision_svg;
use bondmech::report::sweep::{median, WorkPoint};
use bondmech::report::SweepReport;
use bondmech::sundials::Multistep;
use bondmech::{FormulationKind, Integrator, Model, Scene};
use minimal::{bondmech_rows, max_difference, solve_minimal};

const REPEATS: usize = 3;
const TWIN_K: f64 = 1e8;

fn point(series: &str, rtol: f64, error: f64, cpu: f64, steps: u64) -> WorkPoint {
    WorkPoint {
        series: series.into(),
        formulation: series.into(),
        joint_stiffness: 0.0,
        rtol,
        atol: rtol * 1e-2,
        error,
        cpu_seconds: cpu,
        cpu_seconds_min: cpu,
        steps,
        residual_evals: 0,
        jacobian_evals: 0,
        error_test_failures: 0,
        max_constraint_error: 0.0,
        failure: None,
    }
}

fn main() {
    let rtols: Vec<f64> = (4..=10).map(|e| 10f64.powi(-e)).collect();
    for (name, mm) in [
        ("double_pendulum", minimal::DOUBLE_PENDULUM),
        ("slider_crank", minimal::SLIDER_CRANK),
    ] {
        let scene = Scene::from_path(format!("scenes/{name}.json")).expect("scene loads");
        let model = Model::new(&scene).expect("model builds");
        let times = scene.output_times();
        let reference = solve_minimal(&mm, Multistep::Adams, 1e-12, 1e-14, &times).rows;
        let mut points = Vec::new();
        println!("\n{name}: error vs minimal reference / CPU ms (median of {REPEATS}) / steps");
        for &rtol in &rtols {
            for series in [
                "partitioned",
                "partitioned adams",
                "ggl",
                "index1",
                "decoupled k=1e8",
                "minimal CVODE BDF",
                "minimal ARKODE ERK",
            ] {
                let mut cpu = Vec::new();
                let mut last = None;
                for _ in 0..REPEATS {
                    let (rows, c, steps) = match series {
                        "minimal CVODE BDF" => {
                            let r = solve_minimal(&mm, Multistep::Bdf, rtol, rtol * 1e-2, &times);
                            (r.rows, r.cpu_seconds, r.steps)
                        }
                        "minimal ARKODE ERK" => {
                            let r = minimal::solve_minimal_erk(&mm, rtol, rtol * 1e-2, &times);
                            (r.rows, r.cpu_seconds, r.steps)
                        }
                        _ => {
                            let mut o = model.default_options();
                            if series == "partitioned adams" {
                                o.integrator = Integrator::Adams;
                            }
                            o.formulation = match series {
                                "partitioned" | "partitioned adams" => FormulationKind::Partitioned,
                                "ggl" => FormulationKind::Ggl,
                                "index1" => FormulationKind::Index1,
                                _ => FormulationKind::Decoupled,
                            };
                            o.joint_stiffness = TWIN_K;
                            o.rtol = rtol;
                            o.atol = rtol * 1e-2;
                            o.max_steps = Some(10_000_000);
                            let Ok(s) = model.solve(&o) else { break };
                            (
                                bondmech_rows(&s, mm.columns),
                                s.summary.cpu_seconds,
                                s.summary.steps,
                            )
                        }
                    };
                    cpu.push(c);
                    last = Some((max_difference(&rows, &reference), steps));
                }
                let Some((error, steps)) = last else {
                    println!("{series:<20} rtol {rtol:.0e} failed");
                    continue;
                };
                let med = median(&mut cpu);
                println!(
                    "{series:<20} rtol {rtol:.0e} {error:>10.2e} {:>9.3} {steps:>8}",
                    med * 1e3
                );
                points.push(point(series, rtol, error, med, steps));
            }
        }
        let reference_point = point("reference", 1e-12, 0.0, 0.0, 0);
        let report = SweepReport {
            scene: name.into(),
            t_end: *times.last().expect("output times"),
            reference_source: "minimal-coordinate model, CVODE Adams rtol 1e-12".into(),
            reference: reference_point.clone(),
            work_precision: points,
            stiffness_rtol: 0.0,
            dae_baseline: reference_point,
            stiffness: Vec::new(),
            accuracy: 1e-6,
            sufficient_stiffness: None,
            repeats: REPEATS,
            machine: String::new(),
        };
        let path = format!("docs/work-precision-{name}.svg");
        work_precision_svg(&report, Path::new(&path)).expect("SVG written");
        println!("wrote {path}");
    }
}
