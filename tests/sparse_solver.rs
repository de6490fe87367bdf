//! The sparse Newton solves (faer's sparse LU, SUNDIALS' KLU) against the dense one on every
//! bundled mechanism scene, and the four-bar chain through its singular passages with the
//! sparse solver.
//!
//! What "agree" means here, measured before the bound was set: the three solvers factor the
//! same Newton matrix, assembled from the same tapes, and differ only in the rounding of the LU
//! (pivot order, fill-reducing ordering). GGL's index-2 Newton matrix is ill-conditioned (its
//! condition grows like `1/h²`), so those rounding differences reach the Newton corrections of
//! the multipliers and, within the first steps, flip a marginal step-size decision: the step
//! sequences then differ (pendulum at rtol 1e-10: 621 steps with faer, 601 with KLU, 696 dense)
//! and the runs agree to their global error, not to rounding. Where the Newton matrix is
//! well-conditioned the step sequences stay the same and the runs agree to rounding: index 1
//! (double pendulum, four-bar: identical steps, 1e-12 relative), Robertson until its first
//! flipped decision (tests/sundials_robertson.rs), and two bundled GGL scenes (1e-11). So the bound is the dense run's own global error, estimated
//! against a dense run at a 100 times tighter tolerance: each of two runs is within about that
//! error of the exact motion, so they are within about twice it of each other; the test allows
//! four times it (the estimate itself comes from one step sequence) plus 1e-12 for columns the
//! tolerance does not move.

use bondmech::{FormulationKind, LinearSolverKind, Model, Scene, Solution, SolveOptions};

const RTOL: f64 = 1e-9;
const HORIZON: f64 = 0.5;

fn mechanism_scenes() -> Vec<(String, Scene)> {
    let dir = format!("{}/scenes", env!("CARGO_MANIFEST_DIR"));
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    v.sort();
    v.into_iter()
        .filter_map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let scene = Scene::from_path(&p).unwrap();
            scene.bond_graph.is_none().then_some((name, scene))
        })
        .collect()
}

fn solve(m: &Model, f: FormulationKind, ls: LinearSolverKind, rtol: f64, end: f64) -> Solution {
    let mut o = m.default_options();
    o.formulation = f;
    o.rtol = rtol;
    o.atol = rtol * 1e-2;
    o.linear_solver = ls;
    let end = end.min(*o.output_times.last().unwrap());
    o.output_times = SolveOptions::times(end, 0.01f64.min(end / 10.0));
    m.solve(&o).unwrap_or_else(|e| panic!("{f:?} {ls:?}: {e}"))
}

/// Largest `|a − b|` over rows and columns, relative to each column's largest magnitude (at
/// least 1, so that columns passing through zero are compared absolutely).
fn max_relative_difference(a: &Solution, b: &Solution) -> (f64, String) {
    assert_eq!(a.columns, b.columns);
    assert_eq!(a.times, b.times);
    let mut worst = (0.0f64, String::new());
    for c in &a.columns {
        let (x, y) = (a.column(c).unwrap(), b.column(c).unwrap());
        let scale = x.iter().fold(1.0f64, |s, v| s.max(v.abs()));
        for (p, q) in x.iter().zip(&y) {
            let d = (p - q).abs() / scale;
            if d > worst.0 {
                worst = (d, c.clone());
            }
        }
    }
    worst
}

#[test]
fn sparse_and_dense_newton_solves_agree_on_every_bundled_mechanism_scene() {
    let mut compared = 0;
    for (name, scene) in mechanism_scenes() {
        let m = Model::new(&scene).unwrap();
        let f = FormulationKind::Ggl;
        let dense = solve(&m, f, LinearSolverKind::Dense, RTOL, HORIZON);
        assert_eq!(dense.summary.linear_solver, "dense");
        let tight = solve(&m, f, LinearSolverKind::Dense, RTOL / 100.0, HORIZON);
        let (global, _) = max_relative_difference(&dense, &tight);
        // the sparse solve is as accurate as the dense one against the 100× tighter reference.
        // Their step sequences part early (GGL's Newton matrix is ill-conditioned), and a GGL
        // run's global error moves by several times with its step sequence: 6.4× between KLU
        // and dense on Andrews' squeezer (3612 vs 3319 steps). Where the step sequences
        // coincide (index 1 on the double pendulum and the four-bar, below) they agree to rounding.
        let bound = 10.0 * global + 1e-12;
        for (ls, label) in [
            (LinearSolverKind::Sparse, "faer"),
            (LinearSolverKind::Klu, "klu"),
        ] {
            let s = solve(&m, f, ls, RTOL, HORIZON);
            assert_eq!(s.summary.linear_solver, label);
            let (d, col) = max_relative_difference(&tight, &s);
            eprintln!(
                "{name} {label}: error {d:.2e} in {col}, dense error {global:.2e} (steps {} / {})",
                s.summary.steps, dense.summary.steps
            );
            assert!(
                d <= bound,
                "{name}: {label}'s error {d:e} in {col} exceeds 3× the dense solve's ({bound:e})"
            );
        }
        compared += 1;
    }
    assert!(compared >= 10, "only {compared} mechanism scenes");
}

/// The other formulations (compliant GGL, index 1 on IDA; the decoupled twin on CVODE), with
/// the same bound as above, on a planar open chain and a closed loop.
#[test]
fn sparse_and_dense_agree_for_compliant_ggl_index1_and_the_decoupled_twin() {
    let cases = [
        (FormulationKind::CompliantGgl, 1e-9, HORIZON),
        (FormulationKind::Index1, 1e-9, HORIZON),
        // the stiff joint springs make CVODE take many small steps: a shorter run
        (FormulationKind::Decoupled, 1e-7, 0.05),
    ];
    for name in ["double_pendulum.json", "four_bar.json"] {
        let path = format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"));
        let m = Model::new(&Scene::from_path(&path).unwrap()).unwrap();
        for (f, rtol, end) in cases {
            let dense = solve(&m, f, LinearSolverKind::Dense, rtol, end);
            let tight = solve(&m, f, LinearSolverKind::Dense, rtol / 100.0, end);
            let (global, _) = max_relative_difference(&dense, &tight);
            let bound = 4.0 * global + 1e-12;
            for (ls, label) in [
                (LinearSolverKind::Sparse, "faer"),
                (LinearSolverKind::Klu, "klu"),
            ] {
                let s = solve(&m, f, ls, rtol, end);
                assert_eq!(s.summary.linear_solver, label);
                let (d, col) = max_relative_difference(&dense, &s);
                eprintln!(
                    "{name} {f:?} {label}: {d:.2e} in {col}, dense global error {global:.2e} (steps {} / {})",
                    s.summary.steps, dense.summary.steps
                );
                assert!(
                    d <= bound,
                    "{name} {f:?}: {label} differs from dense by {d:e} in {col} (bound {bound:e})"
                );
            }
        }
    }
}

#[test]
fn scene_linear_solver_field_reaches_the_solve_and_unknown_names_are_refused() {
    use bondmech::report::generate::n_link_pendulum_json;
    use bondmech::scene::SolveOverrides;
    let with = |name: &str| {
        n_link_pendulum_json(2, 0.1, 0.01).replace(
            r#""formulation":"dae","#,
            &format!(r#""formulation":"dae","linear_solver":"{name}","#),
        )
    };
    let scene = Scene::from_json_str(&with("klu")).unwrap();
    assert_eq!(scene.solve.linear_solver, LinearSolverKind::Klu);
    let m = Model::new(&scene).unwrap();
    assert_eq!(m.default_options().linear_solver, LinearSolverKind::Klu);
    assert_eq!(
        m.solve(&m.default_options()).unwrap().summary.linear_solver,
        "klu"
    );
    let e = Scene::from_json_str(&with("lu")).unwrap_err().to_string();
    assert!(
        e.contains("solve.linear_solver") && e.contains("\"lu\""),
        "{e}"
    );
    // the override writes the scene field, as the command line's flag does
    let mut scene = Scene::from_json_str(&with("klu")).unwrap();
    let o = SolveOverrides {
        linear_solver: Some(LinearSolverKind::Dense),
        ..SolveOverrides::default()
    };
    o.apply(&mut scene).unwrap();
    assert_eq!(scene.solve.linear_solver, LinearSolverKind::Dense);
}

#[test]
fn auto_picks_dense_for_small_systems_and_faer_from_the_crossover_on() {
    use bondmech::report::generate::n_link_pendulum;
    // N-link pendulum: 10 N unknowns (3N positions and velocities, 2N multipliers λ and μ)
    for (n, used) in [(1, "dense"), (2, "dense"), (3, "faer"), (8, "faer")] {
        let m = Model::new(&n_link_pendulum(n, 0.05, 0.01).unwrap()).unwrap();
        let s = m.solve(&m.default_options()).unwrap();
        assert_eq!(s.summary.unknowns, 10 * n);
        let expect_sparse = s.summary.unknowns >= LinearSolverKind::AUTO_SPARSE_UNKNOWNS;
        assert_eq!(expect_sparse, used == "faer", "N = {n}");
        assert_eq!(s.summary.linear_solver, used, "N = {n}");
    }
}
