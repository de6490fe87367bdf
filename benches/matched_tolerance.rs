//! The CPU side of issue 46's matched-tolerance table (`tests/matched_tolerance.rs` measures
//! the errors): on the same nine mechanisms, scenes, horizons and output times, the default
//! formulation (`dae`) against `ggl` at rtol 1e-8 (atol 1e-10). One criterion group per
//! mechanism with the two solves (`default`, `ggl`), so that the CPU ratio of each mechanism
//! is read from one run; first a table of each solve's steps and `summary.cpu_seconds` (one
//! solve each).
//!
//! Run with `cargo bench --bench matched_tolerance` (a few minutes: 10 samples a solve).

#[path = "../tests/common/mod.rs"]
mod common;

use std::f64::consts::FRAC_PI_2;
use std::time::Duration;

use bondmech::{FormulationKind, Model, Scene, SolveOptions};
use common::five_bar::FiveBar;
use common::slider_crank::OffsetSliderCrank;
use common::spherical_pendulum::SphericalPendulum;
use criterion::Criterion;
use serde_json::json;

const RTOL: f64 = 1e-8;
const STEP: f64 = 0.01;

struct Case {
    name: &'static str,
    model: Model,
    t_end: f64,
}

fn model_from(json: &str) -> Model {
    Model::new(&Scene::from_json_str(json).expect("scene is valid")).expect("model builds")
}

fn bundled(name: &'static str, file: &str, t_end: f64) -> Case {
    let path = format!("{}/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    Case {
        name,
        model: model_from(&std::fs::read_to_string(path).expect("scene file")),
        t_end,
    }
}

/// The mechanisms of `tests/matched_tolerance.rs`, in its order.
fn cases() -> Vec<Case> {
    let solve = |t_end: f64| json!({"t_end": t_end, "output_step": STEP});
    let five = FiveBar::issue_46();
    let q0 = five.start(120f64.to_radians(), 60f64.to_radians(), true);
    let spherical = SphericalPendulum {
        length: 1.0,
        g: 9.81,
    };
    vec![
        Case {
            name: "five_bar",
            model: model_from(&five.scene("five_bar", &q0, solve(1.0))),
            t_end: 1.0,
        },
        Case {
            name: "slider_crank_fast",
            model: model_from(
                &OffsetSliderCrank::trial_case_2().scene([FRAC_PI_2, 14.0], solve(1.0)),
            ),
            t_end: 1.0,
        },
        Case {
            name: "spherical",
            model: model_from(&spherical.scene(2.0, solve(10.0))),
            t_end: 10.0,
        },
        bundled("double_pendulum", "double_pendulum.json", 3.0),
        bundled("slider_crank", "slider_crank.json", 1.0),
        bundled("bricard", "bricard.json", 10.0),
        bundled("bead_pivot", "bead_slot_through_pivot.json", 3.0),
        bundled("heavy_top", "heavy_top.json", 5.0),
        bundled("a01", "distance_pendulum.json", 100.0),
    ]
}

/// The test's options: rtol 1e-8, atol 1e-10, an output every 0.01 s; `ggl` or the default.
fn options(case: &Case, ggl: bool) -> SolveOptions {
    let mut o = case.model.default_options();
    if ggl {
        o.formulation = FormulationKind::Ggl;
    }
    o.rtol = RTOL;
    o.atol = RTOL / 100.0;
    let n = (case.t_end / STEP).round() as usize;
    o.output_times = (0..=n).map(|k| k as f64 * STEP).collect();
    o.max_steps = Some(20_000_000);
    o
}

fn main() {
    let cases = cases();
    println!("matched tolerance, rtol {RTOL:.0e}: one solve each");
    println!(
        "{:<18} {:>8} {:>10} | {:>8} {:>10} | {:>7}",
        "mechanism", "steps", "CPU (s)", "ggl", "CPU (s)", "CPU ×"
    );
    for c in &cases {
        let d = c.model.solve(&options(c, false)).expect("default solves");
        let g = c.model.solve(&options(c, true)).expect("ggl solves");
        let (d, g) = (&d.summary, &g.summary);
        println!(
            "{:<18} {:>8} {:>10.4} | {:>8} {:>10.4} | {:>7.2}",
            c.name,
            d.steps,
            d.cpu_seconds,
            g.steps,
            g.cpu_seconds,
            d.cpu_seconds / g.cpu_seconds
        );
    }

    let mut crit = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    for c in &cases {
        let mut g = crit.benchmark_group(c.name);
        for (label, ggl) in [("default", false), ("ggl", true)] {
            let o = options(c, ggl);
            g.bench_function(label, |b| b.iter(|| c.model.solve(&o).expect("solves")));
        }
        g.finish();
    }
    crit.final_summary();
}
