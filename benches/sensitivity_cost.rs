//! The cost of forward sensitivities (issue 49): the double pendulum (scenes/double_pendulum.json,
//! 3 s, rtol 1e-8) solved plainly and with the sensitivities to one and to two masses on
//! IDAS; the integration's CPU (`summary.cpu_seconds` of the plain run, `cpu_seconds` of the
//! sensitivity run: from the integrator's creation to the last output row, sensitivity rows
//! included) as the median of 9 runs each. The bar: at most `1 + 0.5 · N_s` times the plain
//! run. Then criterion times the whole calls.
//!
//! Run with `cargo bench --bench sensitivity_cost` (`BONDMECH_SENS_BENCH=quick` skips criterion).

use bondmech::report::sweep::median;
use bondmech::sensitivity::{sensitivity, SensitivityRequest};
use bondmech::{Model, Scene};
use criterion::Criterion;

const REPEATS: usize = 9;
const PARAMS: [&str; 2] = ["bodies[bar2].mass", "bodies[bar1].mass"];

fn scene() -> Scene {
    Scene::from_path("scenes/double_pendulum.json").unwrap()
}

fn plain_cpu(scene: &Scene) -> (f64, u64) {
    let model = Model::new(scene).unwrap();
    let opts = model.default_options();
    let mut cpus = Vec::new();
    let mut steps = 0;
    for _ in 0..REPEATS {
        let sol = model.solve(&opts).unwrap();
        cpus.push(sol.summary.cpu_seconds);
        steps = sol.summary.steps;
    }
    (median(&mut cpus), steps)
}

fn sensitivity_cpu(scene: &Scene, np: usize) -> (f64, u64) {
    let req = SensitivityRequest::new(&PARAMS[..np]);
    let mut cpus = Vec::new();
    let mut steps = 0;
    for _ in 0..REPEATS {
        let s = sensitivity(scene, &req).unwrap();
        cpus.push(s.cpu_seconds);
        steps = s.stats.steps;
    }
    (median(&mut cpus), steps)
}

fn main() {
    let scene = scene();
    let (plain, plain_steps) = plain_cpu(&scene);
    println!("double pendulum, 3 s, rtol 1e-8: plain run {plain:.3e} s CPU ({plain_steps} steps)");
    for np in 1..=PARAMS.len() {
        let (sens, steps) = sensitivity_cpu(&scene, np);
        let bound = 1.0 + 0.5 * np as f64;
        let ratio = sens / plain;
        println!(
            "{np} parameter(s): {sens:.3e} s CPU ({steps} steps), ratio {ratio:.2} (bar {bound:.1}): {}",
            if ratio <= bound { "within" } else { "OVER" }
        );
    }
    if std::env::var("BONDMECH_SENS_BENCH").as_deref() == Ok("quick") {
        return;
    }
    let mut c = Criterion::default().configure_from_args().sample_size(10);
    let model = Model::new(&scene).unwrap();
    let opts = model.default_options();
    c.bench_function("double_pendulum/plain", |b| {
        b.iter(|| model.solve(&opts).unwrap())
    });
    let req = SensitivityRequest::new(&PARAMS[..1]);
    c.bench_function("double_pendulum/sensitivity_1", |b| {
        b.iter(|| sensitivity(&scene, &req).unwrap())
    });
    c.final_summary();
}
