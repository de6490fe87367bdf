//! The Schur solver of the index-1 DAE's Newton matrix (issue 25) against a dense LU of the same
//! matrix, on the two problems of `../shared/docs/peers.md`: at the consistent initial state and
//! along a motion, for step coefficients `c_j` from 1 to 1e6 (IDA's `α/h` over the steps it
//! takes on these problems).

use bondmech::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use bondmech::partition::select_dependent;
use bondmech::solve::formulation::{DaeFormulation, Index1Formulation};
use bondmech::sundials::dense_lu;
use bondmech::sundials::schur::{SchurLu, SchurPartition};
use bondmech::Scene;

fn check_scene(path: &str) {
    let scene = Scene::from_path(path).expect("scene");
    let mut sys = bondmech::mech::build(&scene).expect("system");
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, 0.0).expect("consistent");
    let (nq, nv) = (sys.nq(), sys.nv());
    let x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    let gv = tapes.gv.matrix(0.0, &x);
    let preferred: Vec<bool> = (0..nv).map(|j| j % 3 != 2).collect();
    let dependent = select_dependent(&gv, &preferred).expect("a dependent set");
    let f = Index1Formulation::build(&mut sys, &c, &dependent).expect("index-1");
    let n = f.len();
    let split = f.schur_split(nq);
    let blocks = split.blocks.clone();
    assert_eq!(
        split.outer.len(),
        2 * (nv - dependent.len()),
        "{path}: the DOF block"
    );
    let partition = SchurPartition::from_split(n, &split, f.structure()).expect("structure");
    eprintln!(
        "{path}: n = {n}, blocks {:?}, non-zeros of B, C, D below its diagonal {:?}",
        blocks.iter().map(Vec::len).collect::<Vec<_>>(),
        partition.coupling_nonzeros()
    );
    let mut lu = SchurLu::new(partition);
    let mut ws = f.workspace();
    // states: the consistent start, then perturbed ones (the Newton iterates are not on the
    // constraint manifold)
    let mut y0 = init.q.clone();
    y0.extend(&init.v);
    y0.extend(dependent.iter().map(|&j| init.vdot[j]));
    y0.extend(&init.lambda);
    let mut yp0 = init.v.clone();
    yp0.extend(&init.vdot);
    yp0.extend(std::iter::repeat_n(0.0, n - nq - nv));
    let mut worst = 0.0f64;
    for (k, cj) in [1.0, 1e2, 1e4, 1e6].into_iter().enumerate() {
        let y: Vec<f64> = y0
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.05 * k as f64 * ((i as f64 * 1.3).sin()))
            .collect();
        let mut a = vec![0.0; n * n];
        f.jacobian(&mut ws, 0.1, cj, &y, &yp0, &mut |r, col, v| {
            a[col * n + r] += v
        });
        lu.factor(&a).expect("regular blocks");
        let b: Vec<f64> = (0..n).map(|i| ((i * 7 + 3) as f64).cos()).collect();
        let mut x = b.clone();
        lu.solve(&mut x);
        let mut f_lu = a.clone();
        let mut piv = vec![0; n];
        assert_eq!(dense_lu::factor(&mut f_lu, n, &mut piv), 0);
        let mut reference = b.clone();
        dense_lu::solve(&f_lu, n, &piv, &mut reference);
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = x
            .iter()
            .zip(&reference)
            .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()))
            / scale;
        worst = worst.max(err);
        assert!(
            err < 1e-12,
            "{path}, c_j = {cj:e}: relative difference {err:.1e}"
        );
    }
    eprintln!("{path}: largest relative difference to the dense LU {worst:.1e}");
}

#[test]
fn the_double_pendulum_newton_matrix_solves_as_the_dense_lu() {
    check_scene("benches/scenes/peers_double_pendulum.json");
}

#[test]
fn the_slider_crank_newton_matrix_solves_as_the_dense_lu() {
    check_scene("benches/scenes/peers_slider_crank.json");
}
