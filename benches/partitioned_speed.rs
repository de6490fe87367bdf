//! The partitioned formulation at matched error, integrator by integrator, against the
//! hand-written minimal-coordinate model on CVODE BDF (the limit) and on ARKODE's explicit
//! Runge–Kutta, in one run: double pendulum (3 s, 301 outputs) and slider-crank (1 s, 1001
//! outputs). Each method at the loosest rtol of 1e-4 … 1e-11 (half decades, atol = rtol/100)
//! whose error against the minimal model on CVODE Adams at rtol 1e-12, and that of every
//! tighter grid point, is ≤ 1e-6; CPU the median of 9 solves (`summary.cpu_seconds`:
//! integration and output rows). Also the error at each decade rtol 1e-6 … 1e-10 of the
//! automatic choice, for the process-level measurement (`docs/perf/partitioned_hard_way.sh`).
//!
//! Run with `cargo bench --bench partitioned_speed`.

#[path = "common/case.rs"]
mod bench_case;
#[path = "common/minimal.rs"]
mod minimal;
use bench_case::{bench_chosen, speed_cases, Case, Run};

use bondmech::report::sweep::median;
use bondmech::{FormulationKind, Integrator, SolveOptions};

const TARGET: f64 = 1e-6;
const REPEATS: usize = 9;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Method {
    Limit,
    MinimalErk,
    Partitioned(Integrator),
}

impl Method {
    fn label(self) -> String {
        match self {
            Method::Limit => "minimal CVODE BDF".into(),
            Method::MinimalErk => "minimal ARKODE ERK".into(),
            Method::Partitioned(i) => format!("partitioned {}", i.name()),
        }
    }
}

fn options(case: &Case, i: Integrator, rtol: f64) -> SolveOptions {
    let mut o = case.options(rtol);
    o.formulation = FormulationKind::Partitioned;
    o.integrator = i;
    o
}

fn run(case: &Case, m: Method, rtol: f64) -> Option<Run> {
    match m {
        Method::Limit => Some(Run::minimal(case.limit(rtol))),
        Method::MinimalErk => Some(Run::minimal(case.minimal_erk(rtol))),
        Method::Partitioned(i) => Run::bondmech(case, &options(case, i, rtol)),
    }
}

/// [`minimal::matched_rtol`] of this method on this case, at TARGET.
fn matched_rtol(case: &Case, m: Method) -> Option<f64> {
    minimal::matched_rtol(TARGET, |r| run(case, m, r).map(|x| x.error)).map(|(r, _)| r)
}

fn table(case: &Case) -> Vec<(Method, f64)> {
    println!(
        "\n{}: error target {TARGET:e}, CPU median of {REPEATS} runs",
        case.name
    );
    println!(
        "{:<24} {:>8} {:>10} {:>7} {:>7} {:>10} {:>7} {:>9}",
        "method", "rtol", "error", "steps", "f evals", "CPU (µs)", "ratio", "/ min ERK"
    );
    let (mut limit, mut erk) = (f64::NAN, f64::NAN);
    let mut chosen = Vec::new();
    for m in [
        Method::Limit,
        Method::MinimalErk,
        Method::Partitioned(Integrator::Auto),
        Method::Partitioned(Integrator::Erk),
        Method::Partitioned(Integrator::Adams),
        Method::Partitioned(Integrator::Bdf),
    ] {
        let Some(rtol) = matched_rtol(case, m) else {
            println!("{:<24} never within {TARGET:e}", m.label());
            continue;
        };
        let mut cpu = Vec::new();
        let mut last = None;
        for _ in 0..REPEATS {
            let r = run(case, m, rtol).expect("matched run solves");
            cpu.push(r.cpu);
            last = Some(r);
        }
        let r = last.expect("REPEATS > 0");
        let med = median(&mut cpu);
        match m {
            Method::Limit => limit = med,
            Method::MinimalErk => erk = med,
            _ => {}
        }
        println!(
            "{:<24} {:>8.1e} {:>10.2e} {:>7} {:>7} {:>10.0} {:>7.2} {:>9.2} {}",
            m.label(),
            rtol,
            r.error,
            r.steps,
            r.res,
            med * 1e6,
            med / limit,
            med / erk,
            r.integrator
        );
        chosen.push((m, rtol));
    }
    println!("partitioned auto, error at each decade (for the process-level measurement):");
    for e in 6..=10 {
        let rtol = 10f64.powi(-e);
        if let Some(r) = run(case, Method::Partitioned(Integrator::Auto), rtol) {
            println!(
                "  rtol {rtol:.0e}: error {:.2e}, {} ({} steps)",
                r.error, r.integrator, r.steps
            );
        }
    }
    chosen
}

fn main() {
    let cases = speed_cases();
    let chosen: Vec<_> = cases.iter().map(table).collect();
    bench_chosen("partitioned_", &cases, &chosen, Method::label, run);
}
