//! The exact Jacobians of the mechanism formulations (GGL with its runtime −ε compliance
//! blocks, index 1, decoupled twin) against central finite differences of their own residuals
//! at random states — the finite differences being the independent reference.

use bondmech::dae::{ConstraintExprs, MechanicsTapes};
use bondmech::mech::build;
use bondmech::partition::select_dependent;
use bondmech::solve::formulation::{DecoupledFormulation, GglFormulation, Index1Formulation};
use bondmech::Scene;
use nalgebra::DMatrix;

fn scene(name: &str) -> Scene {
    Scene::from_path(format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// A small deterministic pseudo-random sequence in [−1, 1].
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
    fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.next()).collect()
    }
}

/// Central difference of `f` with respect to component `j` of `x`.
fn fd_column(f: &mut dyn FnMut(&[f64]) -> Vec<f64>, x: &[f64], j: usize) -> Vec<f64> {
    let h = 1e-6 * x[j].abs().max(1.0);
    let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
    xp[j] += h;
    xm[j] -= h;
    let (a, b) = (f(&xp), f(&xm));
    a.iter().zip(&b).map(|(p, m)| (p - m) / (2.0 * h)).collect()
}

/// Compares `exact` (n × n) with finite differences of `f`, relative to the entry and to the
/// matrix scale (round-off of the differences grows with |F|/h).
fn check(what: &str, exact: &DMatrix<f64>, f: &mut dyn FnMut(&[f64]) -> Vec<f64>, x: &[f64]) {
    let scale = exact.amax().max(1.0);
    for j in 0..x.len() {
        let col = fd_column(f, x, j);
        for (i, fd) in col.iter().enumerate() {
            let e = exact[(i, j)];
            assert!(
                (e - fd).abs() <= 1e-6 * (e.abs() + 1e-3 * scale + 1.0),
                "{what}: entry ({i}, {j}) exact {e} vs finite difference {fd}"
            );
        }
    }
}

fn dense(n: usize, fill: impl FnOnce(&mut dyn FnMut(usize, usize, f64))) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(n, n);
    fill(&mut |r, c, v| m[(r, c)] += v);
    m
}

fn check_scene(name: &str, seed: u64) {
    let mut rng = Rng(seed);
    for _ in 0..3 {
        // GGL, plain and compliant (ε large enough for its blocks to show in the differences)
        for eps in [0.0, 0.3] {
            let mut sys = build(&scene(name)).unwrap();
            let c = ConstraintExprs::derive(&mut sys);
            let f = GglFormulation::build(&mut sys, &c, eps);
            let n = f.dae.n;
            let (y, yp) = (rng.vec(n), rng.vec(n));
            let mut ws = f.dae.workspace();
            let dfdy = dense(n, |put| {
                f.jacobian(&mut ws, (eps, false), 0.3, 0.0, &y, &yp, put)
            });
            let with_cj = dense(n, |put| {
                f.jacobian(&mut ws, (eps, false), 0.3, 1.0, &y, &yp, put)
            });
            let dfdyp = &with_cj - &dfdy;
            let mut r = vec![0.0; n];
            check(
                &format!("{name} GGL ε = {eps} ∂F/∂y"),
                &dfdy,
                &mut |yy| {
                    f.residual(&mut ws, (eps, false), 0.3, yy, &yp, &mut r);
                    r.clone()
                },
                &y,
            );
            let mut r = vec![0.0; n];
            check(
                &format!("{name} GGL ε = {eps} ∂F/∂y'"),
                &dfdyp,
                &mut |pp| {
                    f.residual(&mut ws, (eps, false), 0.3, &y, pp, &mut r);
                    r.clone()
                },
                &yp,
            );
        }
        // index 1 with the dependent set chosen at a random configuration
        {
            let mut sys = build(&scene(name)).unwrap();
            let c = ConstraintExprs::derive(&mut sys);
            let tapes = MechanicsTapes::new(&mut sys, &c, None);
            let (nq, nv, _) = tapes.dims;
            let x = rng.vec(nq + nv);
            let gv = tapes.gv.matrix(0.0, &x);
            let dep = select_dependent(&gv, &vec![false; nv]).expect("full rank here");
            let f = Index1Formulation::build(&mut sys, &c, &dep).unwrap();
            let n = f.dae.n;
            let (y, yp) = (rng.vec(n), rng.vec(n));
            let mut ws = f.dae.workspace();
            let dfdy = dense(n, |put| f.dae.jacobian(&mut ws, 0.3, 0.0, &y, &yp, put));
            let with_cj = dense(n, |put| f.dae.jacobian(&mut ws, 0.3, 1.0, &y, &yp, put));
            let dfdyp = &with_cj - &dfdy;
            let mut r = vec![0.0; n];
            check(
                &format!("{name} index-1 ∂F/∂y"),
                &dfdy,
                &mut |yy| {
                    f.dae.residual(&mut ws, 0.3, yy, &yp, &mut r);
                    r.clone()
                },
                &y,
            );
            let mut r = vec![0.0; n];
            check(
                &format!("{name} index-1 ∂F/∂y'"),
                &dfdyp,
                &mut |pp| {
                    f.dae.residual(&mut ws, 0.3, &y, pp, &mut r);
                    r.clone()
                },
                &yp,
            );
        }
        // decoupled twin (stiffness and damping moderate so the differences keep their digits)
        {
            let mut sys = bondmech::mech::build(&scene(name)).unwrap();
            let d = DecoupledFormulation::build(&mut sys, 1e3, 7.0).unwrap();
            let n = d.ode.n;
            let y = rng.vec(n);
            let mut ws = d.ode.workspace();
            let jac = dense(n, |put| d.ode.jacobian(&mut ws, 0.3, &y, put));
            let mut r = vec![0.0; n];
            check(
                &format!("{name} decoupled ∂f/∂y"),
                &jac,
                &mut |yy| {
                    d.ode.rhs(&mut ws, 0.3, yy, &mut r);
                    r.clone()
                },
                &y,
            );
        }
    }
}

#[test]
fn double_pendulum_jacobians_match_finite_differences() {
    check_scene("double_pendulum.json", 7);
}

#[test]
fn slider_crank_jacobians_match_finite_differences() {
    check_scene("slider_crank.json", 11);
}

/// The index-1 DAE with its dependent coordinates re-chosen as data
/// ([`Index1Formulation::with_coordinates`]: the coordinates' rows selected among compiled
/// candidates) is the DAE built afresh for those coordinates: the same residual and Jacobian,
/// bit for bit, at random states — and its Jacobian agrees with finite differences of its own
/// residual. Bricard's mechanism (quaternion coordinates, `q' = K(q) v`, a redundant row left
/// out) and the spatial slider-crank.
#[test]
fn index1_with_other_dependent_coordinates_is_the_dae_built_for_them() {
    for (name, seed) in [("bricard.json", 11u64), ("spatial_slider_crank.json", 12)] {
        let mut rng = Rng(seed);
        let mut sys = build(&scene(name)).unwrap();
        let c = ConstraintExprs::derive(&mut sys);
        let tapes = MechanicsTapes::new(&mut sys, &c, None);
        let (nq, nv, nc) = tapes.dims;
        let x = rng.vec(nq + nv);
        let gv = tapes.gv.matrix(0.0, &x);
        // the rows: every row, or (Bricard) all but one, as where its redundant row is left out
        let left_out = usize::from(name == "bricard.json");
        let rows: Vec<usize> = (0..nc - left_out).collect();
        let sub = DMatrix::from_fn(rows.len(), nv, |r, j| gv[(rows[r], j)]);
        let dep = select_dependent(&sub, &vec![false; nv]).expect("full rank here");
        let r = rows.len();
        // two choices of r dependent coordinates: the first r, the last r
        let first: Vec<usize> = (0..r).collect();
        let last: Vec<usize> = (nq - r..nq).collect();
        let built =
            Index1Formulation::build_partitioned(&mut sys, &c, &dep, &first, &rows).unwrap();
        let selected = built.with_coordinates(nq, &last).expect("selectable");
        let fresh = Index1Formulation::build_partitioned(&mut sys, &c, &dep, &last, &rows).unwrap();
        assert_eq!(selected.id, fresh.id, "{name}");
        assert_eq!(selected.coordinates, last, "{name}");
        let n = fresh.dae.n;
        assert_eq!(selected.dae.n, n, "{name}");
        for _ in 0..3 {
            let (y, yp) = (rng.vec(n), rng.vec(n));
            let (mut wa, mut wb) = (selected.dae.workspace(), fresh.dae.workspace());
            let (mut ra, mut rb) = (vec![0.0; n], vec![0.0; n]);
            selected.dae.residual(&mut wa, 0.3, &y, &yp, &mut ra);
            fresh.dae.residual(&mut wb, 0.3, &y, &yp, &mut rb);
            assert_eq!(ra, rb, "{name}: residuals");
            for cj in [0.0, 1.0, 7.5] {
                let ja = dense(n, |put| {
                    selected.dae.jacobian(&mut wa, 0.3, cj, &y, &yp, put)
                });
                let jb = dense(n, |put| fresh.dae.jacobian(&mut wb, 0.3, cj, &y, &yp, put));
                assert_eq!(ja, jb, "{name}: Jacobians at cj = {cj}");
            }
            let mut pattern_a: Vec<_> = selected.dae.structure().collect();
            let mut pattern_b: Vec<_> = fresh.dae.structure().collect();
            pattern_a.sort_unstable();
            pattern_b.sort_unstable();
            assert_eq!(pattern_a, pattern_b, "{name}: sparsity patterns");
            let dfdy = dense(n, |put| {
                selected.dae.jacobian(&mut wa, 0.3, 0.0, &y, &yp, put)
            });
            let mut r = vec![0.0; n];
            check(
                &format!("{name} index-1, coordinates as data, ∂F/∂y"),
                &dfdy,
                &mut |yy| {
                    selected.dae.residual(&mut wa, 0.3, yy, &yp, &mut r);
                    r.clone()
                },
                &y,
            );
        }
    }
}
