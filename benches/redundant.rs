//! Redundant joints: Bricard's mechanism (IFToMM A04, `scenes/bricard.json`, 10 s, 1000
//! outputs) on the default `dae` (the chapter's partition with the redundant row left out),
//! `partitioned` (the same partition, an ODE) and `ggl` (the compliant GGL). Issue 34 asks the
//! default not to be slower than the compliant GGL here.
//!
//! Run with `cargo bench --bench redundant`: first a table of CPU seconds per solve (median of
//! 5, the formulations alternating, so the ratios come from one run on one machine load), then
//! criterion's timings.

use std::time::{Duration, Instant};

use bondmech::{FormulationKind, Model, Scene};
use criterion::Criterion;

const FORMULATIONS: [FormulationKind; 3] = [
    FormulationKind::Dae,
    FormulationKind::Partitioned,
    FormulationKind::Ggl,
];

fn model() -> Model {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/bricard.json"))
        .expect("scenes/bricard.json");
    Model::new(&Scene::from_json_str(&text).expect("valid scene")).expect("model builds")
}

fn solve(m: &Model, f: FormulationKind) -> (f64, u64) {
    let mut o = m.default_options();
    o.formulation = f;
    let s = m.solve(&o).expect("Bricard solves");
    (s.summary.cpu_seconds, s.summary.steps)
}

fn table(m: &Model) {
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); FORMULATIONS.len()];
    let mut steps = vec![0; FORMULATIONS.len()];
    for _ in 0..5 {
        for (k, &f) in FORMULATIONS.iter().enumerate() {
            let clock = Instant::now();
            let (_, n) = solve(m, f);
            times[k].push(clock.elapsed().as_secs_f64());
            steps[k] = n;
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let medians: Vec<f64> = times.iter_mut().map(median).collect();
    let ggl = medians[2];
    println!("Bricard (A04), 10 s, 1000 outputs: seconds per solve (median of 5, alternating)");
    println!("  formulation      steps    seconds   / ggl");
    for (k, f) in FORMULATIONS.iter().enumerate() {
        println!(
            "  {:<14} {:>7} {:>10.4} {:>7.2}",
            f.name(),
            steps[k],
            medians[k],
            medians[k] / ggl
        );
    }
}

fn main() {
    let m = model();
    table(&m);
    let mut c = Criterion::default()
        .sample_size(10)
        .measurement_time(Duration::from_secs(20))
        .configure_from_args();
    let mut group = c.benchmark_group("bricard");
    for f in FORMULATIONS {
        group.bench_function(f.name(), |b| b.iter(|| solve(&m, f)));
    }
    group.finish();
    c.final_summary();
}
