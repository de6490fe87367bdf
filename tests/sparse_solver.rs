//! The sparse Newton solves (faer's sparse LU, SUNDIALS' KLU) against the dense LU on every
//! bundled mechanism scene, and the scene/option plumbing of `solve.linear_solver`.
//!
//! Two things are checked, because they are the two things that can be said:
//!
//! 1. **One Newton system, three factorisations, agreement to rounding.** At the consistent
//!    initial state and at three states along a dense GGL run of every bundled mechanism
//!    scene, the Newton matrix of each formulation (GGL, compliant GGL, index 1 where the
//!    scene has `q' = v`, the decoupled twin's `I − γ ∂f/∂y` where every coordinate has an
//!    inertia) is assembled once from its tapes and `A x = b` is solved by the very
//!    `SUNLinearSolver`s the integrators use (`SUNLinSol_Dense`, our faer wrapper,
//!    `SUNLinSol_KLU`; [`bondmech::sundials::solve_direct`]). The bound is derived, not fitted:
//!    * each solve is backward stable: its normwise backward error (Rigal–Gaches)
//!      `η = ‖b − A x̂‖∞ / (‖A‖∞ ‖x̂‖∞ + ‖b‖∞)` is at most `η_max = 1e-12` (LU with partial or
//!      threshold pivoting: `η ≲ γ_3n ρ`, with `u = 1.1e-16`, `n ≤ 200` and a growth factor
//!      `ρ` up to ~15; the residual is computed in floating point, so `(n + 2) u` is added to
//!      the measured `η`, the rounding of that computation);
//!    * a solve with backward error `η` has relative forward error at most
//!      `f = 2 η κ / (1 − η κ)` when `η κ < 1` (Higham, *Accuracy and Stability of Numerical
//!      Algorithms*, 2nd ed., Thm 7.2), with `κ = ‖A‖∞ ‖A⁻¹‖∞` computed from nalgebra's inverse
//!      (an independent LU); and, componentwise, with `ω = maxᵢ |r_i| / (|A| |x̂| + |b|)_i`, at
//!      most `ω ‖ |A⁻¹| (|A| |x| + |b|) ‖ / ‖x‖ / (1 − ω ‖ |A⁻¹| |A| ‖)` (Thm 7.4), which does
//!      not see the row scaling (the decoupled twin's rows of Andrews' squeezer have a normwise
//!      `κ` of 6e14 at `γ = 1e-4`, their Skeel condition is small). Both are bounds; the
//!      smaller is used;
//!    * so two solves differ by at most `(f_a + f_b) ‖x‖ ≤ (f_a + f_b) ‖x̂_dense‖ / (1 − f_dense)`.
//!
//!    Nothing here is tuned: a sparse solver that dropped an entry, mis-ordered a permutation
//!    or pivoted unstably fails the backward-error assertion or the difference bound.
//!
//! 2. **Whole runs agree within a bound derived from the tolerance, the same for all three.**
//!    Whole trajectories cannot agree to rounding: GGL's index-2 Newton matrix has a condition
//!    growing like `1/h²`, the rounding differences above reach the Newton corrections of the
//!    multipliers and, within the first steps, flip a marginal step-size decision, and from
//!    then on the step sequences differ (measured: pendulum at rtol 1e-10, 621 steps with
//!    faer, 601 with KLU, 696 dense). What must hold is that each run is as accurate as the
//!    tolerance asks: each of dense, faer and KLU is within `K · rtol` (relative to each
//!    column's largest magnitude, at least 1) of a dense run at a 100× tighter tolerance, with
//!    one `K` for all three solvers — never looser for the sparse ones.

mod common;

use bondmech::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use bondmech::partition::select_dependent;
use bondmech::solve::formulation::{DecoupledFormulation, GglFormulation, Index1Formulation};
use bondmech::sundials::{
    solve_direct, solve_faer_sequence, CscPattern, DirectSolver, Ida, IdaOptions, SparseSolver,
};
use bondmech::{FormulationKind, LinearSolverKind, Model, Scene, Solution, SolveOptions};
use nalgebra::DMatrix;

/// Largest normwise backward error allowed of a backward-stable LU (see the module docs).
const ETA_MAX: f64 = 1e-12;
/// Unit roundoff of f64.
const U: f64 = f64::EPSILON / 2.0;

fn mechanism_scenes() -> Vec<(String, Scene)> {
    common::bundled_scene_paths()
        .into_iter()
        .filter_map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let scene = Scene::from_path(&p).unwrap();
            scene.bond_graph.is_none().then_some((name, scene))
        })
        .collect()
}

/// A Newton matrix in CSC form, named by formulation and state.
struct NewtonMatrix {
    label: String,
    pattern: CscPattern,
    values: Vec<f64>,
}

impl NewtonMatrix {
    /// From the structural pattern `structure` and the entries `put` (repeats are summed).
    fn new(
        label: String,
        n: usize,
        structure: impl IntoIterator<Item = (usize, usize)>,
        fill: impl FnOnce(&mut dyn FnMut(usize, usize, f64)),
    ) -> Self {
        let pattern = CscPattern::new(n, structure).unwrap();
        let mut values = vec![0.0; pattern.nnz()];
        fill(&mut |r, c, v| {
            let k = pattern
                .position(r, c)
                .unwrap_or_else(|| panic!("{label}: entry ({r}, {c}) outside the pattern"));
            values[k] += v;
        });
        NewtonMatrix {
            label,
            pattern,
            values,
        }
    }

    fn dense(&self) -> DMatrix<f64> {
        let n = self.pattern.n();
        let mut a = DMatrix::zeros(n, n);
        for j in 0..n {
            for k in self.pattern.colptr()[j]..self.pattern.colptr()[j + 1] {
                a[(self.pattern.rowidx()[k], j)] += self.values[k];
            }
        }
        a
    }
}

fn inf_norm_vec(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

fn inf_norm_mat(a: &DMatrix<f64>) -> f64 {
    (0..a.nrows())
        .map(|i| a.row(i).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Solves one Newton system with the dense LU, faer and KLU and checks the bounds of the
/// module documentation. Returns the largest `‖x̂_s − x̂_dense‖ / bound` seen (≤ 1).
fn check_system(scene: &str, m: &NewtonMatrix) -> f64 {
    check_system_with(scene, m, None)
}

/// [`check_system`], and where `refactored` is given (the solution of `A x = b`, `b` as
/// [`rhs_of`] makes it, by faer's LU in the cheapest column order refactored in an earlier
/// matrix's row order: [`bondmech::sundials::solve_faer_sequence`]), that solution checked by
/// the same bounds.
fn check_system_with(scene: &str, m: &NewtonMatrix, refactored: Option<&[f64]>) -> f64 {
    let n = m.pattern.n();
    let a = m.dense();
    let abs_a = a.abs();
    let norm_a = inf_norm_mat(&a);
    let inv = a
        .clone()
        .try_inverse()
        .unwrap_or_else(|| panic!("{scene} {}: singular Newton matrix", m.label));
    let abs_inv = inv.abs();
    let kappa = norm_a * inf_norm_mat(&inv);
    // Skeel's condition ‖ |A⁻¹| |A| ‖∞, invariant under row scaling (the Newton matrices mix
    // units: metres, radians, newtons, and cj or γ k scale rows by many orders of magnitude)
    let skeel = inf_norm_mat(&(&abs_inv * &abs_a));
    let b = rhs_of(&a);
    let norm_b = inf_norm_vec(&b);
    // (x̂, normwise η, componentwise ω, relative forward-error bound f)
    let solve = |kind: Option<DirectSolver>| -> (Vec<f64>, f64, f64, f64) {
        let x = match (kind, refactored) {
            (Some(kind), _) => solve_direct(kind, &m.pattern, &m.values, &b)
                .unwrap_or_else(|e| panic!("{scene} {} {kind:?}: {e}", m.label)),
            (None, Some(x)) => x.to_vec(),
            (None, None) => unreachable!("a solver or a solution"),
        };
        let r: Vec<f64> = (0..n)
            .map(|i| b[i] - (0..n).map(|j| a[(i, j)] * x[j]).sum::<f64>())
            .collect();
        // the residual's own rounding, γ_{n+2} ≈ (n + 2) u, is added to both backward errors
        let rounding = (n as f64 + 2.0) * U;
        let eta = inf_norm_vec(&r) / (norm_a * inf_norm_vec(&x) + norm_b) + rounding;
        let omega = (0..n)
            .map(|i| {
                let scale = (0..n).map(|j| abs_a[(i, j)] * x[j].abs()).sum::<f64>() + b[i].abs();
                if scale > 0.0 {
                    r[i].abs() / scale
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
            + rounding;
        // Higham Thm 7.2 (normwise) and 7.4 (componentwise, E = |A|, f = |b|): both bound
        // the relative forward error; the smaller one is used
        let normwise = if eta * kappa < 0.5 {
            2.0 * eta * kappa / (1.0 - eta * kappa)
        } else {
            f64::INFINITY
        };
        let componentwise = if omega * skeel < 0.5 {
            let xn = inf_norm_vec(&x);
            let ax_b: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| abs_a[(i, j)] * x[j].abs()).sum::<f64>() + b[i].abs())
                .collect();
            let num = (0..n)
                .map(|i| (0..n).map(|j| abs_inv[(i, j)] * ax_b[j]).sum::<f64>())
                .fold(0.0, f64::max);
            // with ‖x̂‖ for ‖x‖: (1 + 2 ω skeel) covers the difference to first order
            omega * num / xn / (1.0 - omega * skeel) * (1.0 + 2.0 * omega * skeel)
        } else {
            f64::INFINITY
        };
        let f = normwise.min(componentwise);
        assert!(
            f < 0.5,
            "{scene} {}: {kind:?} too ill-conditioned for a bound: κ = {kappa:.2e}, η = {eta:.2e}, Skeel {skeel:.2e}, ω = {omega:.2e}",
            m.label
        );
        (x, eta, omega, f)
    };
    let (xd, eta_d, _, f_d) = solve(Some(DirectSolver::Dense));
    assert!(
        eta_d <= ETA_MAX,
        "{scene} {}: dense backward error {eta_d:.2e}",
        m.label
    );
    let mut worst = 0.0f64;
    let kinds = [
        Some(DirectSolver::Sparse(SparseSolver::Faer)),
        Some(DirectSolver::Sparse(SparseSolver::Klu)),
        None,
    ];
    for s in kinds
        .into_iter()
        .filter(|k| k.is_some() || refactored.is_some())
    {
        let (x, eta, omega, f) = solve(s);
        let s = s.map_or("faer refactored".to_string(), |k| format!("{k:?}"));
        assert!(
            eta <= ETA_MAX,
            "{scene} {} {s}: backward error {eta:.2e} > {ETA_MAX:e} (dense {eta_d:.2e})",
            m.label
        );
        let bound = (f + f_d) / (1.0 - f_d) * inf_norm_vec(&xd);
        let diff = inf_norm_vec(&x.iter().zip(&xd).map(|(p, q)| p - q).collect::<Vec<_>>());
        assert!(
            diff <= bound,
            "{scene} {} {s}: ‖x − x_dense‖ = {diff:.2e} > {bound:.2e} (κ = {kappa:.2e}, Skeel {skeel:.2e}, η = {eta:.2e}, ω = {omega:.2e})",
            m.label
        );
        worst = worst.max(diff / bound);
    }
    worst
}

/// A right-hand side with every unknown in play: `b = A x*`, `x*_i = cos(i) + 2`.
fn rhs_of(a: &DMatrix<f64>) -> Vec<f64> {
    let n = a.nrows();
    let xs: Vec<f64> = (0..n).map(|i| (i as f64).cos() + 2.0).collect();
    (0..n)
        .map(|i| (0..n).map(|j| a[(i, j)] * xs[j]).sum())
        .collect()
}

/// `(t, y, y', h)` of the GGL unknowns at the consistent start and at three times along a
/// dense GGL run (rtol 1e-8), `h` the step last taken (the start: IDA's first step, 1e-4 s).
fn ggl_states(
    scene: &str,
    ggl: &GglFormulation,
    dependent: &[usize],
    eps: f64,
    y0: Vec<f64>,
    yp0: Vec<f64>,
) -> Vec<(f64, Vec<f64>, Vec<f64>, f64)> {
    let (nq, nv, nc) = ggl.dims;
    let mut out = vec![(0.0, y0.clone(), yp0.clone(), 1e-4)];
    let (d1, d2) = (ggl.clone(), ggl.clone());
    let (mut w1, mut w2) = (d1.dae.workspace(), d2.dae.workspace());
    let residual = Box::new(move |t: f64, y: &[f64], yp: &[f64], r: &mut [f64]| {
        d1.residual(&mut w1, (eps, false), t, y, yp, r);
        Ok(())
    });
    let jacobian = Box::new(
        move |t: f64,
              cj: f64,
              y: &[f64],
              yp: &[f64],
              j: &mut bondmech::sundials::DenseMatrixMut<'_>| {
            j.fill_zero();
            d2.jacobian(&mut w2, (eps, false), t, cj, y, yp, |r, c, v| {
                j.add(r, c, v)
            });
            Ok(())
        },
    );
    let mut atol = vec![1e-10; nq + nv];
    atol.extend(std::iter::repeat_n(1e-2, 2 * nc));
    // as the solver does: the dependent velocities (index-2 components) out of the error test
    let mut id = ggl.id.clone();
    for j in dependent {
        id[nq + j] = 0.0;
    }
    let opts = IdaOptions {
        rtol: 1e-8,
        atol,
        id: Some(id),
        suppress_alg: true,
        init_step: Some(1e-4),
        max_steps: Some(100_000),
        ..IdaOptions::default()
    };
    let mut ida = Ida::new(0.0, &y0, &yp0, residual, Some(jacobian), &opts).unwrap();
    for t in [0.1, 0.2, 0.3] {
        ida.solve_to(t)
            .unwrap_or_else(|e| panic!("{scene}: dense GGL run: {e}"));
        out.push((
            t,
            ida.y().to_vec(),
            ida.yp().to_vec(),
            ida.stats().last_step,
        ));
    }
    out
}

/// Every formulation's Newton matrix of `model` at the states of [`ggl_states`].
fn newton_matrices(scene: &str, model: &Model) -> Vec<NewtonMatrix> {
    let mut sys = model.system().clone();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, 0.0).unwrap();
    let (nq, nv, nc) = tapes.dims;
    let mref = sys.mass.iter().fold(0.0f64, |a, &b| a.max(b));
    let compliance = 1e-10 / mref;
    // plain GGL unless the joints are redundant (then the solver runs compliant GGL too)
    let eps = if init.redundant_joints.is_empty() {
        0.0
    } else {
        compliance
    };
    let ggl = GglFormulation::build(&mut sys, &c, eps);
    let mut x0 = init.q.clone();
    x0.extend(&init.v);
    let mut y0 = x0.clone();
    y0.extend(&init.lambda);
    y0.extend(std::iter::repeat_n(0.0, nc));
    if eps > 0.0 {
        // compliant GGL: velocities with G_v v = ε λ (least change), as the solver starts
        let gv = tapes.gv.matrix(0.0, &x0);
        let v = nalgebra::DVector::from_column_slice(&init.v);
        let lam = nalgebra::DVector::from_column_slice(&init.lambda);
        let defect = &lam * eps - &gv * &v;
        let svd = gv.svd(true, true);
        let tol = 1e-6 * svd.singular_values.max();
        let dv = svd.solve(&defect, tol).unwrap();
        for j in 0..nv {
            x0[nq + j] += dv[j];
            y0[nq + j] += dv[j];
        }
    }
    let mut yp0 = MechanicsTapes::eval(&tapes.kinematics, 0.0, &x0);
    yp0.extend(&init.vdot);
    yp0.extend(std::iter::repeat_n(0.0, 2 * nc));
    let gv = tapes.gv.matrix(0.0, &x0);
    let dependent = select_dependent(&gv, &vec![false; nv]);
    let states = ggl_states(
        scene,
        &ggl,
        dependent.as_deref().unwrap_or(&[]),
        eps,
        y0,
        yp0,
    );
    let index1 = dependent.and_then(|d| {
        Index1Formulation::build(&mut sys, &c, &d)
            .ok()
            .map(|f| (d, f))
    });
    let opts = model.default_options();
    let twin = DecoupledFormulation::build(&mut sys, opts.joint_stiffness, 0.0).ok();
    let mut out = Vec::new();
    for (t, y, yp, h) in &states {
        let cj = 1.0 / h;
        for (name, e) in [("ggl", eps), ("compliant ggl", compliance)] {
            let mut ws = ggl.dae.workspace();
            out.push(NewtonMatrix::new(
                format!("{name} at t = {t} (cj = {cj:.1e})"),
                ggl.dae.n,
                ggl.structure(),
                |put| ggl.jacobian(&mut ws, (e, false), *t, cj, y, yp, put),
            ));
        }
        if let Some((dependent, f)) = &index1 {
            // y = [q, v, a_D, λ], y' = [v, v', 0, 0]
            let mut y1 = y[..nq + nv].to_vec();
            y1.extend(dependent.iter().map(|&j| yp[nq + j]));
            y1.extend(&y[nq + nv..nq + nv + nc]);
            let mut yp1 = yp[..nq + nv].to_vec();
            yp1.extend(std::iter::repeat_n(0.0, 2 * nc));
            let mut ws = f.dae.workspace();
            out.push(NewtonMatrix::new(
                format!("index1 at t = {t} (cj = {cj:.1e})"),
                f.dae.n,
                f.dae.structure(),
                |put| f.dae.jacobian(&mut ws, *t, cj, &y1, &yp1, put),
            ));
        }
        if let Some(d) = &twin {
            // CVODE's M = I − γ ∂f/∂y, γ = h (BDF order 1)
            let mut ws = d.ode.workspace();
            out.push(NewtonMatrix::new(
                format!("decoupled at t = {t} (γ = {h:.1e})"),
                d.ode.n,
                d.ode.structure(),
                |put| {
                    for i in 0..d.ode.n {
                        put(i, i, 1.0);
                    }
                    d.ode
                        .jacobian(&mut ws, *t, &y[..nq + nv], |r, c, v| put(r, c, -h * v))
                },
            ));
        }
    }
    out
}

#[test]
fn dense_faer_and_klu_solve_every_bundled_scenes_newton_systems_alike_to_rounding() {
    let mut scenes = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for (name, scene) in mechanism_scenes() {
        let model = Model::new(&scene).unwrap();
        let matrices = newton_matrices(&name, &model);
        let mut worst = 0.0f64;
        for m in &matrices {
            kinds.insert(m.label.split(" at ").next().unwrap().to_string());
            worst = worst.max(check_system(&name, m));
        }
        eprintln!(
            "{name}: {} Newton systems, largest difference {:.2} of its bound",
            matrices.len(),
            worst
        );
        scenes += 1;
    }
    assert!(scenes >= 10, "only {scenes} mechanism scenes");
    let kinds: Vec<_> = kinds.into_iter().collect();
    assert_eq!(kinds, ["compliant ggl", "decoupled", "ggl", "index1"]);
}

/// The index-1 DAE's Newton matrices of each scene at its four states (one pattern) factored
/// in sequence by one faer solver in the cheapest column order, as IDA's setups do along a run:
/// the first with row pivoting, the later ones refactored in its row order while their pivots
/// pass the threshold test. Each solution meets the bounds of the module documentation against
/// SUNDIALS' dense LU of the same matrix.
#[test]
fn refactored_index1_newton_systems_solve_as_the_dense_lu_does() {
    let mut refactored = 0;
    for (name, scene) in mechanism_scenes() {
        let model = Model::new(&scene).unwrap();
        let matrices: Vec<NewtonMatrix> = newton_matrices(&name, &model)
            .into_iter()
            .filter(|m| m.label.starts_with("index1 "))
            .collect();
        let Some(first) = matrices.first() else {
            continue;
        };
        assert!(
            matrices.iter().all(|m| m.pattern == first.pattern),
            "{name}: one pattern"
        );
        // one right-hand side per matrix, as check_system makes it: solve each matrix's own
        // system with a solver that has factored the earlier ones
        let mut xs = Vec::new();
        for k in 0..matrices.len() {
            let values: Vec<Vec<f64>> = matrices[..=k].iter().map(|m| m.values.clone()).collect();
            let b = rhs_of(&matrices[k].dense());
            let (x, counters) = solve_faer_sequence(
                bondmech::sundials::ColumnOrdering::Cheapest,
                &first.pattern,
                &values,
                &b,
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(counters.numeric as usize, k + 1, "{name}");
            assert_eq!(
                counters.refactored + counters.repivoted,
                k as u64,
                "{name}: every factorisation after the first tries the kept row order"
            );
            refactored += counters.refactored;
            xs.push(x[k].clone());
        }
        for (m, x) in matrices.iter().zip(&xs) {
            check_system_with(&name, m, Some(x));
        }
    }
    assert!(refactored > 0, "no refactorisation was exercised");
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

/// Runs `model` with formulation `f` at `rtol` with dense, faer and KLU and checks each
/// against a dense run at `rtol / 100`: error at most `k · rtol`, the same `k` for all three.
fn runs_within_tolerance_bound(
    name: &str,
    model: &Model,
    f: FormulationKind,
    rtol: f64,
    end: f64,
    k: f64,
) {
    let reference = solve(model, f, LinearSolverKind::Dense, rtol / 100.0, end);
    for (ls, label) in [
        (LinearSolverKind::Dense, "dense"),
        (LinearSolverKind::Sparse, "faer"),
        (LinearSolverKind::Klu, "klu"),
    ] {
        let s = solve(model, f, ls, rtol, end);
        assert_eq!(s.summary.linear_solver, label);
        let (d, col) = max_relative_difference(&reference, &s);
        eprintln!(
            "{name} {f:?} {label}: error {:.1} rtol in {col} ({} steps)",
            d / rtol,
            s.summary.steps
        );
        assert!(
            d <= k * rtol,
            "{name} {f:?} {label}: error {d:.2e} in {col} exceeds {k} rtol"
        );
    }
}

/// GGL on every bundled mechanism scene, 0.5 s at rtol 1e-9. A BDF run's global error is the
/// local errors (each ≲ rtol per step, relative to the state) carried by the motion; over half
/// a second of these mechanisms the dense runs measured 2.5 (two bars) … 605 rtol (the
/// slider-crank, 4800 steps). `K` is three times the worst dense run, rounded: 2000 rtol, the
/// same for dense, faer and KLU (the sparse runs measured 2.5 … 772 rtol).
#[test]
fn dense_faer_and_klu_ggl_runs_of_every_bundled_scene_are_within_the_same_tolerance_bound() {
    let mut compared = 0;
    for (name, scene) in mechanism_scenes() {
        let m = Model::new(&scene).unwrap();
        runs_within_tolerance_bound(&name, &m, FormulationKind::Ggl, 1e-9, 0.5, 2000.0);
        compared += 1;
    }
    assert!(compared >= 10, "only {compared} mechanism scenes");
}

/// The other formulations (compliant GGL, index 1 on IDA; the decoupled twin on CVODE) on a
/// planar open chain and a closed loop. `K` as above, three times the worst dense run: the
/// twin's stiff joint springs (k = 1e8) make its dense runs the least accurate (207 and 943
/// rtol; compliant GGL 49 and 126, index 1 85 and 181), so `K` = 3000 rtol, again one bound
/// for dense, faer and KLU.
#[test]
fn dense_faer_and_klu_runs_of_compliant_ggl_index1_and_the_twin_are_within_the_same_tolerance_bound(
) {
    let cases = [
        (FormulationKind::CompliantGgl, 1e-9, 0.5),
        (FormulationKind::Index1, 1e-9, 0.5),
        // the stiff joint springs make CVODE take many small steps: a shorter run
        (FormulationKind::Decoupled, 1e-7, 0.05),
    ];
    for name in ["double_pendulum.json", "four_bar.json"] {
        let path = format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"));
        let m = Model::new(&Scene::from_path(&path).unwrap()).unwrap();
        for (f, rtol, end) in cases {
            runs_within_tolerance_bound(name, &m, f, rtol, end, 3000.0);
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
        // the GGL's Newton matrix (the default dae's has its own Schur solver under auto)
        let mut o = m.default_options();
        o.formulation = bondmech::FormulationKind::Ggl;
        let s = m.solve(&o).unwrap();
        assert_eq!(s.summary.unknowns, 10 * n);
        let expect_sparse = s.summary.unknowns >= LinearSolverKind::AUTO_SPARSE_UNKNOWNS;
        assert_eq!(expect_sparse, used == "faer", "N = {n}");
        assert_eq!(s.summary.linear_solver, used, "N = {n}");
    }
}
