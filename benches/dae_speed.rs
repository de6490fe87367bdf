//! The default DAE on IDA (issue 25) at matched error against the hand-written
//! minimal-coordinate model on CVODE BDF (the limit), on the two problems of
//! `../shared/docs/peers.md`: the double pendulum (3 s, outputs at 0.5, 1, 2, 3 s) and the
//! smooth slider-crank (1 s, outputs at 0.1, 0.25, 0.5, 1 s). Each method at the loosest rtol
//! of 1e-4 … 1e-11 (half decades, atol = rtol/100) whose error against the minimal model on
//! CVODE Adams at rtol 1e-12, and that of every tighter grid point, is ≤ 1e-6; CPU the median
//! of 9 solves (`summary.cpu_seconds`: integration and output rows). Also the error at each
//! decade rtol 1e-6 … 1e-10 of every formulation, for the process-level measurement
//! (`docs/perf/dae_hard_way.sh`).
//!
//! Run with `cargo bench --bench dae_speed` (`BONDMECH_DAE_BENCH=quick` skips criterion).

#[path = "common/case.rs"]
mod bench_case;
#[path = "common/minimal.rs"]
mod minimal;
use bench_case::{bench_chosen, peer_cases, Case, Run};

use bondmech::report::sweep::median;
use bondmech::{FormulationKind, SolveOptions};

const TARGET: f64 = 1e-6;
const REPEATS: usize = 9;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Method {
    Limit,
    Formulation(FormulationKind),
}

impl Method {
    fn label(self) -> String {
        match self {
            Method::Limit => "minimal CVODE BDF".into(),
            Method::Formulation(f) => f.name().into(),
        }
    }
}

const METHODS: [Method; 5] = [
    Method::Limit,
    Method::Formulation(FormulationKind::Dae),
    Method::Formulation(FormulationKind::Index1),
    Method::Formulation(FormulationKind::Ggl),
    Method::Formulation(FormulationKind::Partitioned),
];

fn options(case: &Case, f: FormulationKind, rtol: f64) -> SolveOptions {
    let mut o = case.options(rtol);
    o.formulation = f;
    o
}

fn run(case: &Case, m: Method, rtol: f64) -> Option<Run> {
    match m {
        Method::Limit => Some(Run::minimal(case.limit(rtol))),
        Method::Formulation(f) => Run::bondmech(case, &options(case, f, rtol)),
    }
}

/// The median CPU of [`REPEATS`] solves and the last run's counters.
fn timed(case: &Case, m: Method, rtol: f64) -> Option<Run> {
    let mut cpus = Vec::with_capacity(REPEATS);
    let mut last = None;
    for _ in 0..REPEATS {
        let r = run(case, m, rtol)?;
        cpus.push(r.cpu);
        last = Some(r);
    }
    let mut r = last?;
    r.cpu = median(&mut cpus);
    Some(r)
}

fn main() {
    let cases = peer_cases();
    let mut chosen: Vec<Vec<(Method, f64)>> = Vec::new();
    for case in &cases {
        println!("== {} (target max error {TARGET:.0e})", case.name);
        println!(
            "{:<20} {:>8} {:>9} {:>10} {:>7} {:>7} {:>7} {:>9} {:>8}",
            "method", "rtol", "error", "cpu µs", "steps", "res", "jac", "µs/step", "× limit"
        );
        let mut limit_cpu = None;
        let mut picks = Vec::new();
        for m in METHODS {
            let Some((rtol, _)) =
                minimal::matched_rtol(TARGET, |r| run(case, m, r).map(|x| x.error))
            else {
                println!("{:<20} never reaches {TARGET:.0e}", m.label());
                continue;
            };
            let Some(r) = timed(case, m, rtol) else {
                println!("{:<20} fails at rtol {rtol:.1e}", m.label());
                continue;
            };
            let lim = *limit_cpu.get_or_insert(r.cpu);
            println!(
                "{:<20} {:>8.1e} {:>9.2e} {:>10.0} {:>7} {:>7} {:>7} {:>9.2} {:>8.2}",
                m.label(),
                rtol,
                r.error,
                r.cpu * 1e6,
                r.steps,
                r.res,
                r.jac,
                r.cpu * 1e6 / r.steps.max(1) as f64,
                r.cpu / lim
            );
            picks.push((m, rtol));
        }
        println!("-- errors at the decades (for docs/perf/dae_hard_way.sh)");
        for m in METHODS {
            let row: Vec<String> = (6..=10)
                .map(|e| {
                    let rtol = 10f64.powi(-e);
                    match run(case, m, rtol) {
                        Some(r) => format!("1e-{e}: {:.2e} ({} steps)", r.error, r.steps),
                        None => format!("1e-{e}: fails"),
                    }
                })
                .collect();
            println!("{:<20} {}", m.label(), row.join("  "));
        }
        chosen.push(picks);
    }
    if std::env::var("BONDMECH_DAE_BENCH").as_deref() == Ok("quick") {
        return;
    }
    bench_chosen("dae_", &cases, &chosen, Method::label, |c, m, rtol| {
        run(c, m, rtol).map(|r| r.error)
    });
}
