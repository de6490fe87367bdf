//! `SolveOptions::max_wall_clock` bounds the *whole* `Model::solve` (all output intervals,
//! restarts and index-1 re-selections), not each output interval.
//!
//! Calibration inside the test: a solve of the double pendulum (seed chapter, Fig. 19) over
//! 100 output intervals at tight tolerances is timed without a budget (`T_full`, once the model
//! is built); then the same solve gets a budget of `T_full / 10`. Each interval alone costs about
//! `T_full / 100`, under the budget, so a per-interval budget would let the solve finish;
//! the whole-solve budget must stop it with `SolverError::WallClock` and the time reached,
//! within 10× the budget.

use bondmech::sundials::SolverError;
use bondmech::{Error, FormulationKind, Model, Scene, SolveOptions};
use std::time::{Duration, Instant};

fn model() -> Model {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/double_pendulum.json");
    Model::new(&Scene::from_path(path).unwrap()).unwrap()
}

const T_END: f64 = 20.0;

fn options(kind: FormulationKind, budget: Option<Duration>) -> SolveOptions {
    SolveOptions {
        formulation: kind,
        rtol: 1e-10,
        atol: 1e-10,
        output_times: (0..=100).map(|k| T_END * k as f64 / 100.0).collect(),
        max_steps: None,
        max_wall_clock: budget,
        ..SolveOptions::default()
    }
}

fn check(kind: FormulationKind) {
    let model = model();
    let start = Instant::now();
    model.solve(&options(kind, None)).unwrap();
    let full = start.elapsed();
    let budget = full / 10;
    let start = Instant::now();
    let result = model.solve(&options(kind, Some(budget)));
    let elapsed = start.elapsed();
    match result {
        Err(Error::Incomplete { cause, partial }) => {
            let Error::Solver(SolverError::WallClock { t, limit }) = *cause else {
                panic!("{kind:?}: stopped by {cause}, not the wall clock");
            };
            assert_eq!(limit, budget);
            assert!(t > 0.0 && t < T_END, "{kind:?}: time reached {t}");
            // the rows computed so far are kept, up to the time reached
            assert_eq!(partial.summary.t_reached, t);
            assert_eq!(partial.times.last().copied(), Some(t));
        }
        other => panic!(
            "{kind:?}: expected WallClock with budget {budget:?} (full solve {full:?}), got {:?}",
            other.map(|s| s.times.len())
        ),
    }
    assert!(
        elapsed < 10 * budget,
        "{kind:?}: solve ran {elapsed:?} with a budget of {budget:?}"
    );
}

#[test]
fn wall_clock_budget_bounds_the_whole_ggl_solve() {
    check(FormulationKind::Ggl);
}

#[test]
fn wall_clock_budget_bounds_the_whole_index1_solve() {
    check(FormulationKind::Index1);
}

#[test]
fn wall_clock_budget_bounds_the_whole_decoupled_solve() {
    check(FormulationKind::Decoupled);
}
