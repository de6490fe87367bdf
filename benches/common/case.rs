//! One mechanism of the speed benches: the bundled scene's model, its hand-written
//! minimal-coordinate twin ([`super::minimal`]), the output times, and the reference
//! trajectory (the minimal model on CVODE Adams at rtol 1e-12); and what the speed benches
//! share: the two cases, the options at a tolerance, the limit's run, the criterion groups.
//! (Each bench includes this file and uses part of it.)
#![allow(dead_code)]

use std::time::Duration;

use bondmech::sundials::Multistep;
use bondmech::{Model, Scene, SolveOptions};
use criterion::Criterion;

use crate::minimal::{
    self, bondmech_rows, max_difference, solve_minimal, MinimalModel, MinimalRun,
};

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
    case_at(&format!("scenes/{name}.json"), name, minimal)
}

/// The double pendulum and the smooth slider-crank of `../shared/docs/peers.md` with their
/// output times (0.5, 1, 2, 3 s and 0.1, 0.25, 0.5, 1 s), `benches/scenes/peers_*.json`.
pub fn peer_cases() -> [Case; 2] {
    [
        case_at(
            "benches/scenes/peers_double_pendulum.json",
            "peers_double_pendulum",
            minimal::DOUBLE_PENDULUM,
        ),
        case_at(
            "benches/scenes/peers_slider_crank.json",
            "peers_slider_crank",
            minimal::PEERS_SLIDER_CRANK,
        ),
    ]
}

/// Loads the scene at `path` as the case `name` and solves its reference.
pub fn case_at(path: &str, name: &'static str, minimal: MinimalModel) -> Case {
    let scene = Scene::from_path(path).expect("scene loads");
    let model = Model::new(&scene).expect("model builds");
    // the minimal model starts at the first time: the start state comes first when the scene's
    // output times leave it out (the peers' problems list 0.5, 1, 2, 3 s)
    let mut times = scene.output_times();
    if times.first().is_some_and(|&t| t > scene.solve.t_start) {
        times.insert(0, scene.solve.t_start);
    }
    let r = solve_minimal(&minimal, Multistep::Adams, 1e-12, 1e-14, &times);
    Case {
        name,
        model,
        minimal,
        times,
        reference: r.rows,
    }
}

/// The double pendulum and the slider-crank, the mechanisms the speed benches compare.
pub fn speed_cases() -> [Case; 2] {
    [
        case("double_pendulum", minimal::DOUBLE_PENDULUM),
        case("slider_crank", minimal::SLIDER_CRANK),
    ]
}

impl Case {
    /// The scene's options at `rtol` (atol = rtol / 100) on the case's output times, with a
    /// step budget none of these solves reaches.
    pub fn options(&self, rtol: f64) -> SolveOptions {
        let mut o = self.model.default_options();
        o.rtol = rtol;
        o.atol = rtol * 1e-2;
        o.output_times = self.times.clone();
        o.max_steps = Some(10_000_000);
        o
    }

    /// The limit (the minimal model on CVODE BDF) at `rtol`, and its error.
    pub fn limit(&self, rtol: f64) -> (MinimalRun, f64) {
        let r = solve_minimal(
            &self.minimal,
            Multistep::Bdf,
            rtol,
            rtol * 1e-2,
            &self.times,
        );
        let e = max_difference(&r.rows, &self.reference);
        (r, e)
    }

    /// The minimal model on ARKODE's explicit Runge–Kutta at `rtol`, and its error.
    pub fn minimal_erk(&self, rtol: f64) -> (MinimalRun, f64) {
        let r = minimal::solve_minimal_erk(&self.minimal, rtol, rtol * 1e-2, &self.times);
        let e = max_difference(&r.rows, &self.reference);
        (r, e)
    }
}

/// One timed solve of a bench: its error against the case's reference and its counters.
pub struct Run {
    pub error: f64,
    pub cpu: f64,
    pub steps: u64,
    /// Jacobian evaluations.
    pub jac: u64,
    /// Residual (right-hand side) evaluations; 0 for the minimal model.
    pub res: u64,
    /// The integrator the solve reports (empty for the minimal model).
    pub integrator: String,
}

impl Run {
    /// A minimal-model solve with its error.
    pub fn minimal((r, error): (MinimalRun, f64)) -> Run {
        Run {
            error,
            cpu: r.cpu_seconds,
            steps: r.steps,
            jac: r.jacobian_evals,
            res: 0,
            integrator: String::new(),
        }
    }

    /// A bondmech solve of `case` with `opts` (`None` if it fails).
    pub fn bondmech(case: &Case, opts: &SolveOptions) -> Option<Run> {
        let s = case.model.solve(opts).ok()?;
        Some(Run {
            error: max_difference(&bondmech_rows(&s, case.minimal.columns), &case.reference),
            cpu: s.summary.cpu_seconds,
            steps: s.summary.steps,
            jac: s.summary.jacobian_evals,
            res: s.summary.residual_evals,
            integrator: s.summary.integrator.clone(),
        })
    }
}

/// Criterion groups `<prefix><case>`, timing each chosen `(method, rtol)` of each case.
pub fn bench_chosen<M: Copy, R>(
    prefix: &str,
    cases: &[Case],
    chosen: &[Vec<(M, f64)>],
    label: impl Fn(M) -> String,
    run: impl Fn(&Case, M, f64) -> R,
) {
    let mut crit = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .configure_from_args();
    for (c, ch) in cases.iter().zip(chosen) {
        let mut g = crit.benchmark_group(format!("{prefix}{}", c.name));
        for &(m, rtol) in ch {
            g.bench_function(label(m), |b| b.iter(|| run(c, m, rtol)));
        }
        g.finish();
    }
    crit.final_summary();
}
