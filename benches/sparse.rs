//! Large mechanisms: cost per step of the dense LU against the sparse ones (faer, KLU).
//!
//! 1. The N-link pendulum (uniform 1 m, 1 kg bars hanging from a ground pin, released
//!    horizontal; `report::generate::n_link_pendulum`), GGL DAE, rtol 1e-6, atol 1e-8, 1 s:
//!    `cpu_seconds / steps` at N = 32 … 512 for each linear solver, and its growth against
//!    N = 32 (linear in N would be 2×, 4×, 8×, 16×). The dense LU is measured only while one
//!    solve stays under [`DENSE_BUDGET`] s of CPU (it grows like N³).
//! 2. The chain of 40 parallelogram four-bars in series over 20 s (about 20 singular passages),
//!    rtol 1e-8 and 5e-9, atol = rtol / 100 as `tests/singular_fourbar_chain.rs`, with the error
//!    of the first crank's top against the exact 1-DOF model (`tests/common/four_bar_chain.rs`);
//!    also with the dependent velocities out of IDA's error test (rows "faer−", "klu−").
//!
//! 3. The model build of the N-link pendulum at N = 32 … 512, phase by phase: scene → `Model`
//!    (`Model::new`: the bond graph and its equations), then what a solve builds before its
//!    first step — the constraint derivatives (`ConstraintExprs::derive`), the numeric tapes
//!    (`MechanicsTapes::new`), the consistent start and the GGL residual with its Jacobian
//!    tapes (`GglFormulation::build`) — each with its growth against N = 32 (linear: 2×, 4×,
//!    8×, 16×).
//!
//! 4. The default `dae` (the index-1 DAE: faer's sparse LU from
//!    `LinearSolverKind::AUTO_SCHUR_UNKNOWNS` unknowns, the output checks on the non-zeros from
//!    `SPARSE_GRIP_ROWS` joint rows) against `ggl` on the N-link pendulum as in 1. (outputs
//!    every 0.01 s), N = 32 … 256: `cpu_seconds / steps` (median of 5 solves, alternating),
//!    the ratio dae / ggl per step and per solve, the same for `dae` with faer's LU in COLAMD's
//!    column order (the index-1 DAE's before `ColumnOrdering::Cheapest`), and each one's growth
//!    against N = 32 (linear: 2×, 4×, 8×); and where `auto`
//!    stops eliminating the dependent blocks (`dae_crossover`: the Schur elimination against
//!    faer below the threshold).
//!
//! One solve per cell (the tables are ratios from one run); criterion then times one step-heavy
//! solve per solver at N = 64 and `Model::new` at N = 32, 128, 512. Run with
//! `cargo bench --bench sparse` (`BONDMECH_SPARSE_BENCH=build|n_link|chain|crossover|monitor`
//! for some tables only, comma-separated; `dae`, `dae_crossover`: the default at scale; `chain_sparse`: the chain without its minutes-long dense run; `monitor`: the
//! singular-passage monitor's κ, dense against sparse).

#[allow(unused_imports)]
#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Duration;

use bondmech::report::generate::n_link_pendulum;
use bondmech::sundials::ColumnOrdering;
use bondmech::{FormulationKind, LinearSolverKind, Model, Scene, Solution};
use common::four_bar_chain::{chain_json, chain_json_at, simulate_four_bar_chain, FourBarChain};
use criterion::Criterion;

/// CPU seconds of one dense solve beyond which the dense column stops.
const DENSE_BUDGET: f64 = 60.0;

const SOLVERS: [(LinearSolverKind, &str); 3] = [
    (LinearSolverKind::Dense, "dense"),
    (LinearSolverKind::Sparse, "faer"),
    (LinearSolverKind::Klu, "klu"),
];

fn n_link_solve(model: &Model, ls: LinearSolverKind) -> Solution {
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = 1e-6;
    o.atol = 1e-8;
    o.linear_solver = ls;
    model.solve(&o).expect("the N-link pendulum solves")
}

fn n_link_table() {
    println!("\nN-link pendulum, GGL DAE, rtol 1e-6, atol 1e-8, 1 s (one solve per cell)");
    println!(
        "{:>4} {:>8} {:>10} {:>6} {:>7} {:>10} {:>12} {:>8}",
        "N", "unknowns", "build (s)", "solver", "steps", "CPU (s)", "µs per step", "vs N=32"
    );
    let mut base = [None; 3];
    let mut dense_over = false;
    for n in [32usize, 64, 128, 256, 512] {
        let scene = n_link_pendulum(n, 1.0, 0.01).expect("generated scene is valid");
        let model = Model::new(&scene).expect("model builds");
        for (k, (ls, label)) in SOLVERS.iter().enumerate() {
            if *ls == LinearSolverKind::Dense && dense_over {
                println!(
                    "{n:>4} {:>8} {:>10} {label:>6}  (skipped: over {DENSE_BUDGET} s)",
                    "", ""
                );
                continue;
            }
            let s = n_link_solve(&model, *ls);
            let build = s.summary.build_cpu_seconds;
            let per_step = s.summary.cpu_seconds / s.summary.steps.max(1) as f64;
            let b = *base[k].get_or_insert(per_step);
            println!(
                "{:>4} {:>8} {:>10.2} {:>6} {:>7} {:>10.3} {:>12.1} {:>7.1}×",
                n,
                s.summary.unknowns,
                build,
                label,
                s.summary.steps,
                s.summary.cpu_seconds,
                per_step * 1e6,
                per_step / b
            );
            if *ls == LinearSolverKind::Dense && s.summary.cpu_seconds > DENSE_BUDGET / 8.0 {
                // the next N costs about 8 times as much
                dense_over = true;
            }
        }
    }
}

/// Where `auto` should switch: dense against faer on small N-link pendulums (median of 5).
fn crossover_table() {
    println!("\nCrossover: N-link pendulum as above, µs per step (median of 5 solves)");
    println!(
        "{:>4} {:>8} {:>12} {:>12} {:>12} {:>12}",
        "N", "unknowns", "dense", "faer", "klu", "dense/faer"
    );
    for n in [1usize, 2, 3, 4, 6, 8, 12, 16] {
        let scene = n_link_pendulum(n, 1.0, 0.01).expect("generated scene is valid");
        let model = Model::new(&scene).expect("model builds");
        let mut cells = Vec::new();
        let mut unknowns = 0;
        for (ls, _) in SOLVERS {
            let mut per_step: Vec<f64> = (0..5)
                .map(|_| {
                    let s = n_link_solve(&model, ls);
                    unknowns = s.summary.unknowns;
                    s.summary.cpu_seconds / s.summary.steps.max(1) as f64
                })
                .collect();
            per_step.sort_by(f64::total_cmp);
            cells.push(per_step[2]);
        }
        println!(
            "{:>4} {:>8} {:>12.1} {:>12.1} {:>12.1} {:>12.2}",
            n,
            unknowns,
            cells[0] * 1e6,
            cells[1] * 1e6,
            cells[2] * 1e6,
            cells[0] / cells[1]
        );
    }
}

/// Largest distance of the first crank's top from the exact 1-DOF model.
fn chain_error(n: usize, s: &Solution) -> f64 {
    let p = FourBarChain {
        loops: n,
        m: 1.0,
        l: 1.0,
        g: 9.81,
    };
    let r = simulate_four_bar_chain(&p, [std::f64::consts::FRAC_PI_2, 1.0], &s.times);
    r.iter()
        .enumerate()
        .map(|(k, rk)| {
            let x = s.value(k, "crank0.A.x").unwrap();
            let y = s.value(k, "crank0.A.y").unwrap();
            (x - rk.first_crank_top[0]).hypot(y - rk.first_crank_top[1])
        })
        .fold(0.0, f64::max)
}

/// The chain's GGL solve over 20 s with outputs every 0.05 s, atol = rtol / 100.
fn chain_try_solve(
    model: &Model,
    ls: LinearSolverKind,
    rtol: f64,
    error_test: bool,
) -> Result<Solution, bondmech::Error> {
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = rtol;
    o.atol = rtol / 100.0;
    o.output_times = (0..=400).map(|i| 0.05 * i as f64).collect();
    o.max_steps = Some(2_000_000);
    o.linear_solver = ls;
    o.ggl_dependent_velocity_error_test = error_test;
    model.solve(&o)
}

fn chain_solve(model: &Model, ls: LinearSolverKind, rtol: f64, error_test: bool) -> Solution {
    chain_try_solve(model, ls, rtol, error_test).expect("the chain solves")
}

fn chain_table(with_dense: bool) {
    let n = 40;
    println!(
        "\nChain of {n} four-bars, GGL (compliant at the passages), 20 s, outputs every 0.05 s"
    );
    println!(
        "{:>6} {:>6} {:>8} {:>7} {:>10} {:>12} {:>9} {:>10} {:>10}",
        "solver",
        "rtol",
        "unknowns",
        "steps",
        "CPU (s)",
        "µs per step",
        "passages",
        "error",
        "build (s)"
    );
    let model = Model::new(&Scene::from_json_str(&chain_json(n)).unwrap()).unwrap();
    // atol = rtol / 100 as tests/singular_fourbar_chain.rs; dense last (minutes)
    // the last field: `ggl_dependent_velocity_error_test` (false: the opt-in that takes the
    // dependent velocities out of IDA's error test, "faer−"/"klu−")
    let runs = [
        (LinearSolverKind::Sparse, "faer", 1e-8, true),
        (LinearSolverKind::Klu, "klu", 1e-8, true),
        (LinearSolverKind::Sparse, "faer", 5e-9, true),
        (LinearSolverKind::Klu, "klu", 5e-9, true),
        (LinearSolverKind::Sparse, "faer−", 1e-8, false),
        (LinearSolverKind::Klu, "klu−", 1e-8, false),
        (LinearSolverKind::Dense, "dense", 1e-8, true),
    ];
    for (ls, label, rtol, error_test) in runs {
        if ls == LinearSolverKind::Dense && !with_dense {
            continue;
        }
        match chain_try_solve(&model, ls, rtol, error_test) {
            Ok(s) => println!(
                "{:>6} {:>6.0e} {:>8} {:>7} {:>10.2} {:>12.1} {:>9} {:>10.2e} {:>10.2}",
                label,
                rtol,
                s.summary.unknowns,
                s.summary.steps,
                s.summary.cpu_seconds,
                s.summary.cpu_seconds * 1e6 / s.summary.steps.max(1) as f64,
                s.summary.singular_passages.len(),
                chain_error(n, &s),
                s.summary.build_cpu_seconds
            ),
            Err(e) => println!("{label:>6} {rtol:>6.0e} failed: {e}"),
        }
    }
}

/// The singular-passage monitor's κ on four-bar chains of N loops (2 + 6 N joint rows), dense
/// eigenvalues against the sparse Lanczos path: µs per call (median of 21 calls), upright (φ = 1) and near an alignment (φ = 0.01).
fn monitor_table() {
    use bondmech::dae::{ConstraintExprs, MechanicsTapes};
    use bondmech::partition::{dense_joint_condition_number, sparse_joint_condition_number};
    println!("\nMonitor κ(G_v M⁺ G_vᵀ), four-bar chains: µs per call (median of 21)");
    println!(
        "{:>4} {:>5} {:>6} {:>12} {:>12} {:>12} {:>14}",
        "N", "rows", "φ", "κ", "dense µs", "sparse µs", "dense/sparse"
    );
    for n in [3usize, 5, 8, 10, 15, 20, 40] {
        for phi in [1.0, 0.01] {
            let scene = Scene::from_json_str(&chain_json_at(n, phi, 1.0)).unwrap();
            let model = Model::new(&scene).unwrap();
            let mut sys = model.system().clone();
            let c = ConstraintExprs::derive(&mut sys);
            let tapes = MechanicsTapes::new(&mut sys, &c, None);
            let x = sys.initial_state();
            let median = |f: &dyn Fn() -> f64| {
                let mut t: Vec<f64> = (0..21)
                    .map(|_| {
                        let c = cpu_time::ThreadTime::now();
                        std::hint::black_box(f());
                        c.elapsed().as_secs_f64()
                    })
                    .collect();
                t.sort_by(f64::total_cmp);
                t[10]
            };
            let gv = tapes.gv.matrix(0.0, &x);
            let kappa = dense_joint_condition_number(&gv, &sys.mass);
            let td = median(&|| dense_joint_condition_number(&gv, &sys.mass));
            let ts = median(&|| sparse_joint_condition_number(&gv, &sys.mass).unwrap_or(f64::NAN));
            println!(
                "{:>4} {:>5} {:>6} {:>12.3e} {:>12.1} {:>12.1} {:>14.2}",
                n,
                gv.nrows(),
                phi,
                kappa,
                td * 1e6,
                ts * 1e6,
                td / ts
            );
        }
    }
}

/// CPU seconds of `f` on this thread.
fn cpu<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = cpu_time::ThreadTime::now();
    let v = f();
    (v, t.elapsed().as_secs_f64())
}

fn build_table() {
    use bondmech::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
    use bondmech::solve::formulation::GglFormulation;
    println!("\nModel build of the N-link pendulum, CPU seconds by phase (one build per cell)");
    let phases = [
        "Model::new",
        "derive",
        "tapes",
        "consistent start",
        "GGL build",
        "total",
    ];
    print!("{:>4}", "N");
    for p in phases {
        print!(" {p:>16}");
    }
    println!();
    let mut base: Option<Vec<f64>> = None;
    for n in [32usize, 64, 128, 256, 512] {
        let scene = n_link_pendulum(n, 1.0, 0.01).expect("generated scene is valid");
        let (model, t_model) = cpu(|| Model::new(&scene).expect("model builds"));
        let mut sys = model.system().clone();
        let (c, t_derive) = cpu(|| ConstraintExprs::derive(&mut sys));
        let (tapes, t_tapes) = cpu(|| MechanicsTapes::new(&mut sys, &c, None));
        let (_, t_init) = cpu(|| consistent_state(&sys, &tapes, 0.0).expect("consistent start"));
        let (_, t_ggl) = cpu(|| GglFormulation::build(&mut sys, &c, 0.0));
        let t = [
            t_model,
            t_derive,
            t_tapes,
            t_init,
            t_ggl,
            t_model + t_derive + t_tapes + t_init + t_ggl,
        ];
        let b = base.get_or_insert_with(|| t.to_vec()).clone();
        print!("{n:>4}");
        for (x, x0) in t.iter().zip(&b) {
            print!(" {:>8.3} {:>6.1}×", x, x / x0.max(1e-9));
        }
        println!();
    }
}

/// `cpu_seconds / steps` of the N-link pendulum on `formulation` (median of `runs` solves),
/// with the summary of the last.
fn per_step(
    model: &Model,
    formulation: FormulationKind,
    ls: LinearSolverKind,
    runs: usize,
) -> (f64, Solution) {
    per_step_ordered(model, formulation, ls, None, runs)
}

/// [`per_step`] with faer's column ordering of the Newton matrix given (`None`: the
/// formulation's own, `SolveOptions::sparse_ordering`).
fn per_step_ordered(
    model: &Model,
    formulation: FormulationKind,
    ls: LinearSolverKind,
    ordering: Option<ColumnOrdering>,
    runs: usize,
) -> (f64, Solution) {
    let mut o = model.default_options();
    o.formulation = formulation;
    o.rtol = 1e-6;
    o.atol = 1e-8;
    o.linear_solver = ls;
    o.sparse_ordering = ordering;
    let mut last = None;
    let mut cells: Vec<f64> = (0..runs)
        .map(|_| {
            let s = model.solve(&o).expect("the N-link pendulum solves");
            let c = s.summary.cpu_seconds / s.summary.steps.max(1) as f64;
            last = Some(s);
            c
        })
        .collect();
    cells.sort_by(f64::total_cmp);
    (cells[runs / 2], last.expect("at least one run"))
}

/// The default at scale: `dae` against `ggl`, µs per step (median of 5 solves, the three
/// columns alternating), and `dae` with
/// faer ordering its Newton matrix by COLAMD (before `ColumnOrdering::Cheapest`, the index-1
/// DAE's own choice since 2026-11-27): each one's ratio to `ggl` per step and per solve
/// (µs per step × steps).
fn dae_table() {
    println!(
        "\nThe default at scale: N-link pendulum, rtol 1e-6, atol 1e-8, 1 s, outputs every 0.01 s, \
         µs per step (median of 5 solves); colamd: dae with faer's LU in COLAMD's column order"
    );
    println!(
        "{:>4} {:>8} {:>6} {:>9} {:>6} {:>9} {:>6} {:>9} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7}",
        "N",
        "unknowns",
        "steps",
        "dae",
        "steps",
        "colamd",
        "steps",
        "ggl",
        "dae/ggl",
        "(solve)",
        "col/ggl",
        "(solve)",
        "dae ×",
        "ggl ×"
    );
    let mut base = None;
    for n in [32usize, 64, 128, 256] {
        let scene = n_link_pendulum(n, 1.0, 0.01).expect("generated scene is valid");
        let model = Model::new(&scene).expect("model builds");
        // the three alternating (a load that changes during the run weighs on each alike)
        let cases = [
            (FormulationKind::Dae, None),
            (FormulationKind::Dae, Some(ColumnOrdering::Colamd)),
            (FormulationKind::Ggl, None),
        ];
        let mut cells: Vec<Vec<f64>> = vec![Vec::new(); cases.len()];
        let mut last: Vec<Option<Solution>> = vec![None, None, None];
        for _ in 0..5 {
            for (k, &(f, ordering)) in cases.iter().enumerate() {
                let (c, s) = per_step_ordered(&model, f, LinearSolverKind::Auto, ordering, 1);
                cells[k].push(c);
                last[k] = Some(s);
            }
        }
        let median = |c: &mut Vec<f64>| {
            c.sort_by(f64::total_cmp);
            c[c.len() / 2]
        };
        let (dae, col, ggl) = (
            median(&mut cells[0]),
            median(&mut cells[1]),
            median(&mut cells[2]),
        );
        let [Some(sd), Some(sc), Some(sg)] = [&last[0], &last[1], &last[2]] else {
            unreachable!("five runs of each");
        };
        assert_eq!(sd.summary.formulation, "dae", "the default ran its own DAE");
        let (b_dae, b_ggl) = *base.get_or_insert((dae, ggl));
        let solve = |c: f64, s: &Solution| c * s.summary.steps as f64;
        println!(
            "{:>4} {:>8} {:>6} {:>9.1} {:>6} {:>9.1} {:>6} {:>9.1} {:>8.2} {:>8.2} {:>8.2} {:>8.2} {:>6.2}× {:>6.2}×  ({}, {})",
            n,
            sd.summary.unknowns,
            sd.summary.steps,
            dae * 1e6,
            sc.summary.steps,
            col * 1e6,
            sg.summary.steps,
            ggl * 1e6,
            dae / ggl,
            solve(dae, sd) / solve(ggl, sg),
            col / ggl,
            solve(col, sc) / solve(ggl, sg),
            dae / b_dae,
            ggl / b_ggl,
            sd.summary.linear_solver,
            sg.summary.linear_solver
        );
    }
}

/// Where `auto` should stop eliminating the dependent blocks: `dae` with `auto` (the Schur
/// elimination below `AUTO_SCHUR_UNKNOWNS`) against faer, µs per step (median of 5).
fn dae_crossover_table() {
    println!(
        "\ndae crossover: N-link pendulum as above, µs per step (median of 5 solves); auto is \
         the Schur elimination below {} unknowns",
        LinearSolverKind::AUTO_SCHUR_UNKNOWNS
    );
    println!(
        "{:>4} {:>8} {:>12} {:>12} {:>12}",
        "N", "unknowns", "auto", "faer", "auto/faer"
    );
    // below the threshold only: above it `auto` is faer itself
    for n in [2usize, 4, 6, 8, 9] {
        let scene = n_link_pendulum(n, 1.0, 0.01).expect("generated scene is valid");
        let model = Model::new(&scene).expect("model builds");
        let (auto, s) = per_step(&model, FormulationKind::Dae, LinearSolverKind::Auto, 5);
        let (faer, _) = per_step(&model, FormulationKind::Dae, LinearSolverKind::Sparse, 5);
        println!(
            "{:>4} {:>8} {:>12.1} {:>12.1} {:>12.2}  ({})",
            n,
            s.summary.unknowns,
            auto * 1e6,
            faer * 1e6,
            auto / faer,
            s.summary.linear_solver
        );
    }
}

fn main() {
    let only = std::env::var("BONDMECH_SPARSE_BENCH").unwrap_or_default();
    let only: Vec<&str> = only.split(',').filter(|s| !s.is_empty()).collect();
    let want = |t: &str| only.is_empty() || only.contains(&t);
    if want("build") {
        build_table();
    }
    if want("monitor") {
        monitor_table();
    }
    if want("crossover") {
        crossover_table();
    }
    if want("n_link") {
        n_link_table();
    }
    if want("chain") || only.contains(&"chain_sparse") {
        chain_table(want("chain"));
    }
    if want("dae") {
        dae_table();
    }
    if want("dae_crossover") {
        dae_crossover_table();
    }
    let scene = n_link_pendulum(64, 1.0, 0.01).expect("generated scene is valid");
    let model = Model::new(&scene).expect("model builds");
    let mut crit = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5))
        .configure_from_args();
    let mut g = crit.benchmark_group("n_link_64");
    for (ls, label) in SOLVERS {
        g.bench_function(label, |b| b.iter(|| n_link_solve(&model, ls)));
    }
    g.finish();
    // the default against ggl at N = 128, one whole solve each (`-- dae_n_link_128`)
    let scene = n_link_pendulum(128, 1.0, 0.01).expect("generated scene is valid");
    let model = Model::new(&scene).expect("model builds");
    let mut g = crit.benchmark_group("dae_n_link_128");
    for (f, label) in [(FormulationKind::Dae, "dae"), (FormulationKind::Ggl, "ggl")] {
        g.bench_function(label, |b| {
            b.iter(|| per_step(&model, f, LinearSolverKind::Auto, 1))
        });
    }
    g.finish();
    // the 40-four-bar chain's whole 20 s solve (faer, rtol 1e-8, as the chain table's first
    // row): the "under 5 s CPU" target; `cargo bench --bench sparse -- chain_40`
    let chain = Model::new(&Scene::from_json_str(&chain_json(40)).unwrap()).unwrap();
    let mut g = crit.benchmark_group("chain_40");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(40));
    for (ls, label) in [
        (LinearSolverKind::Sparse, "faer"),
        (LinearSolverKind::Klu, "klu"),
    ] {
        // CPU time of this thread (the target is CPU seconds; wall time on the shared machine
        // counts the other builds too), the model's solve-time build included
        g.bench_function(label, |b| {
            b.iter_custom(|iters| {
                let t = cpu_time::ThreadTime::now();
                for _ in 0..iters {
                    std::hint::black_box(chain_solve(&chain, ls, 1e-8, true));
                }
                t.elapsed()
            })
        });
    }
    g.finish();
    let mut g = crit.benchmark_group("model_new");
    for n in [32usize, 128, 512] {
        let scene = n_link_pendulum(n, 1.0, 0.01).expect("generated scene is valid");
        g.bench_function(format!("n_link_{n}"), |b| {
            b.iter(|| Model::new(&scene).expect("model builds"))
        });
    }
    g.finish();
    crit.final_summary();
}
