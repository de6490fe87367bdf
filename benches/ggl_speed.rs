//! Where GGL's time goes, change by change: the GGL DAE on the double pendulum and the
//! slider-crank at matched error (the loosest rtol on a half-decade grid whose error against the
//! minimal-coordinate reference, and that of every tighter grid point, is ≤ 1e-6), each variant
//! against the hand-written minimal-coordinate model on CVODE BDF (the limit) in the same run:
//!
//! * `before` — every q and v in IDA's error test, SUNDIALS' Jacobian policy;
//! * `no dependent v` — the dependent velocities out of the error test, re-chosen along the run
//!   (`SolveOptions::ggl_dependent_velocity_error_test = false`);
//! * `... + ΔcJ x` — and a new Jacobian only when `c_j` changes by more than `x`
//!   (`SolveOptions::ida_delta_cj`, `IDASetDeltaCjLSetup`; SUNDIALS' default 0.25, and values
//!   outside (0, 1) fall back to it).
//!
//! Prints rtol, error, steps, Jacobian evaluations, residual evaluations, CPU (median of 9) and
//! the ratio to the limit; then criterion's timings of the same solves.
//!
//! Run with `cargo bench --bench ggl_speed`.

#[path = "common/case.rs"]
mod bench_case;
#[path = "common/minimal.rs"]
mod minimal;
use bench_case::{bench_chosen, speed_cases, Case, Run};

use bondmech::report::sweep::median;
use bondmech::{FormulationKind, SolveOptions};

const TARGET: f64 = 1e-6;
const REPEATS: usize = 9;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Variant {
    Limit,
    Ggl {
        dependent_out: bool,
        delta_cj: Option<f64>,
    },
}

impl Variant {
    fn label(self) -> String {
        match self {
            Variant::Limit => "minimal CVODE BDF".into(),
            Variant::Ggl {
                dependent_out: false,
                delta_cj: None,
            } => "ggl before".into(),
            Variant::Ggl {
                dependent_out,
                delta_cj,
            } => {
                let mut s = String::from("ggl");
                if dependent_out {
                    s.push_str(" no dependent v");
                }
                if let Some(d) = delta_cj {
                    s.push_str(&format!(" + ΔcJ {d}"));
                }
                s
            }
        }
    }
}

fn options(case: &Case, dependent_out: bool, delta_cj: Option<f64>, rtol: f64) -> SolveOptions {
    let mut o = case.options(rtol);
    o.formulation = FormulationKind::Ggl;
    o.ggl_dependent_velocity_error_test = !dependent_out;
    o.ida_delta_cj = delta_cj;
    o
}

fn run(case: &Case, v: Variant, rtol: f64) -> Option<Run> {
    match v {
        Variant::Limit => Some(Run::minimal(case.limit(rtol))),
        Variant::Ggl {
            dependent_out,
            delta_cj,
        } => Run::bondmech(case, &options(case, dependent_out, delta_cj, rtol)),
    }
}

/// [`minimal::matched_rtol`] of this method on this case, at TARGET.
fn matched_rtol(case: &Case, v: Variant) -> Option<f64> {
    minimal::matched_rtol(TARGET, |r| run(case, v, r).map(|x| x.error)).map(|(r, _)| r)
}

const VARIANTS: [Variant; 6] = [
    Variant::Limit,
    Variant::Ggl {
        dependent_out: false,
        delta_cj: None,
    },
    Variant::Ggl {
        dependent_out: true,
        delta_cj: None,
    },
    Variant::Ggl {
        dependent_out: true,
        delta_cj: Some(0.5),
    },
    Variant::Ggl {
        dependent_out: true,
        delta_cj: Some(0.9),
    },
    Variant::Ggl {
        dependent_out: false,
        delta_cj: Some(0.9),
    },
];

fn table(case: &Case) -> Vec<(Variant, f64)> {
    println!(
        "\n{}: error target {TARGET:e}, CPU median of {REPEATS} runs",
        case.name
    );
    println!(
        "{:<28} {:>8} {:>10} {:>7} {:>6} {:>7} {:>10} {:>7}",
        "variant", "rtol", "error", "steps", "jac", "res", "CPU (µs)", "ratio"
    );
    let mut limit = f64::NAN;
    let mut chosen = Vec::new();
    for v in VARIANTS {
        let Some(rtol) = matched_rtol(case, v) else {
            println!("{:<28} never within {TARGET:e}", v.label());
            continue;
        };
        let mut cpu = Vec::new();
        let mut last = None;
        for _ in 0..REPEATS {
            let r = run(case, v, rtol).expect("matched run solves");
            cpu.push(r.cpu);
            last = Some(r);
        }
        let r = last.expect("REPEATS > 0");
        let med = median(&mut cpu);
        if v == Variant::Limit {
            limit = med;
        }
        println!(
            "{:<28} {:>8.1e} {:>10.2e} {:>7} {:>6} {:>7} {:>10.0} {:>7.2}",
            v.label(),
            rtol,
            r.error,
            r.steps,
            r.jac,
            r.res,
            med * 1e6,
            med / limit
        );
        chosen.push((v, rtol));
    }
    chosen
}

fn main() {
    let cases = speed_cases();
    let chosen: Vec<_> = cases.iter().map(table).collect();
    bench_chosen("ggl_", &cases, &chosen, Variant::label, run);
}
