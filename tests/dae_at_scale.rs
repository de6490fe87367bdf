//! The default (`dae`, the chapter's index-1 DAE) at scale: the N-link pendulum of issue 34
//! (uniform 1 m, 1 kg bars pinned end to end, the first to the ground, released horizontal at
//! rest, gravity −y, rtol 1e-6) on the paths large mechanisms take — faer's sparse LU for the
//! Newton matrix (from `LinearSolverKind::AUTO_SCHUR_UNKNOWNS` unknowns) and the output checks
//! and row completion on the non-zeros of the joint Jacobians (from `SPARSE_GRIP_ROWS` rows) —
//! checked against references that owe nothing to bondmech:
//!
//! * the absolute angles against the minimal-coordinate model of `tests/common/n_link.rs`
//!   (Lagrange's equations in θ₁ … θ_N, integrated by the reference RK45 at 1e-13);
//! * the joints from the output rows by the scene's geometry: bar k's end O at
//!   `c_k − ½ e_k` on bar k−1's end A at `c_{k−1} + ½ e_{k−1}` (the first at the origin);
//! * the mechanical energy from the output rows (`Σ ½ m |v|² + ½ I ω² + m g y`), conserved.

mod common;

use bondmech::partition::thresholds::SPARSE_GRIP_ROWS;
use bondmech::report::generate::n_link_pendulum;
use bondmech::{LinearSolverKind, Model, Solution};
use common::n_link::{simulate_n_link, NLinkPendulum};

/// The tolerance of the problem.
const RTOL: f64 = 1e-6;
const ATOL: f64 = 1e-8;
const G: f64 = 9.81;

/// The N-link pendulum on the default, `t_end` s, outputs every 0.01 s.
fn solve(n: usize, t_end: f64) -> Solution {
    let scene = n_link_pendulum(n, t_end, 0.01).expect("generated scene is valid");
    let model = Model::new(&scene).expect("model builds");
    let mut o = model.default_options();
    o.rtol = RTOL;
    o.atol = ATOL;
    model
        .solve(&o)
        .expect("the N-link pendulum solves on the default")
}

fn col(s: &Solution, name: &str) -> Vec<f64> {
    s.column(name).unwrap_or_else(|| panic!("column {name}"))
}

/// The pins' bound for `n` links (m): the rows are completed onto the joints by Newton to
/// `1e-15` of the coordinates' scale (`n` m, the chain's reach), so they coincide to a hundred
/// times that (measured: 2.7e-15 m at N = 32, 1.4e-14 m at N = 128).
fn pin_bound(n: usize) -> f64 {
    100.0 * 1e-15 * n as f64
}

/// Largest distance between the pinned ends over all rows and joints (m).
fn joint_error(s: &Solution, n: usize) -> f64 {
    let mut worst = 0.0f64;
    for k in 0..s.times.len() {
        let mut a_prev = [0.0, 0.0];
        for b in 1..=n {
            let x = s.value(k, &format!("bar{b}.x")).unwrap();
            let y = s.value(k, &format!("bar{b}.y")).unwrap();
            let (sn, cs) = s.value(k, &format!("bar{b}.angle")).unwrap().sin_cos();
            let o = [x - 0.5 * cs, y - 0.5 * sn];
            worst = worst.max((o[0] - a_prev[0]).hypot(o[1] - a_prev[1]));
            a_prev = [x + 0.5 * cs, y + 0.5 * sn];
        }
    }
    worst
}

/// Mechanical energy of row `k` from its positions and velocities (m = 1 kg, I = 1/12 kg m²).
fn energy(s: &Solution, k: usize, n: usize) -> f64 {
    (1..=n)
        .map(|b| {
            let v = |c: &str| s.value(k, &format!("bar{b}.{c}")).unwrap();
            0.5 * (v("vx").powi(2) + v("vy").powi(2)) + 0.5 / 12.0 * v("omega").powi(2) + G * v("y")
        })
        .sum()
}

#[test]
fn a_32_link_pendulum_on_the_default_takes_the_sparse_paths_and_matches_the_minimal_model() {
    let n = 32;
    let t_end = 0.3;
    let s = solve(n, t_end);
    assert_eq!(s.summary.formulation, "dae");
    assert_eq!(
        s.summary.linear_solver, "faer",
        "{} unknowns: the sparse LU",
        s.summary.unknowns
    );
    assert!(s.summary.unknowns >= LinearSolverKind::AUTO_SCHUR_UNKNOWNS);
    assert!(2 * n >= SPARSE_GRIP_ROWS, "the output checks' sparse path");
    assert_eq!(s.summary.index1_reselections, 0);
    assert!(s.summary.warnings.is_empty(), "{:?}", s.summary.warnings);
    // the minimal-coordinate model from rest, horizontal
    let p = NLinkPendulum {
        masses: vec![1.0; n],
        lengths: vec![1.0; n],
        g: G,
    };
    let reference = simulate_n_link(&p, &vec![0.0; n], &vec![0.0; n], &s.times);
    let mut worst = 0.0f64;
    for (k, r) in reference.iter().enumerate() {
        for b in 0..n {
            let a = s.value(k, &format!("bar{}.angle", b + 1)).unwrap();
            worst = worst.max((a - r.theta[b]).abs());
        }
    }
    eprintln!("32 links, {t_end} s: worst angle error {worst:.2e} rad");
    // a global error of the order of the tolerance (the angles are O(1) rad): 10 rtol
    // (measured 2.0e-7 rad)
    assert!(
        worst < 10.0 * RTOL,
        "angles off the minimal model by {worst:e} rad"
    );
    let joints = joint_error(&s, n);
    eprintln!("32 links: joint error {joints:.2e} m");
    assert!(joints < pin_bound(n), "pins apart by {joints:e} m");
}

#[test]
fn a_128_link_pendulum_on_the_default_keeps_its_joints_and_its_energy() {
    let n = 128;
    let s = solve(n, 1.0);
    assert_eq!(s.summary.formulation, "dae");
    assert_eq!(s.summary.linear_solver, "faer");
    assert!(s.summary.warnings.is_empty(), "{:?}", s.summary.warnings);
    let joints = joint_error(&s, n);
    let e0 = energy(&s, 0, n);
    let last = s.times.len() - 1;
    // the energy's scale: the potential energy released by the end (m g Σ −y_k, from y = 0)
    let y_drop: f64 = (1..=n)
        .map(|b| -col(&s, &format!("bar{b}.y"))[last])
        .sum::<f64>()
        * G;
    let drift = (0..=last)
        .map(|k| (energy(&s, k, n) - e0).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "128 links: joint error {joints:.2e} m, energy drift {drift:.2e} J of {y_drop:.1} J released"
    );
    assert!(joints < pin_bound(n), "pins apart by {joints:e} m");
    assert!(y_drop > 0.0);
    // conserved to the tolerance: the drift at most rtol of the energy released (measured
    // 5.9e-4 J of 5853 J, 1e-7 of it)
    assert!(
        drift < RTOL * y_drop,
        "energy drift {drift:e} J against {y_drop:e} J released"
    );
}
