//! The singular-passage monitor's condition number `κ(G_v M⁺ G_vᵀ) = λ_max / λ_min` from the
//! sparse path (Lanczos on the sparse Gram matrix and, through its sparse Cholesky factor, on
//! its inverse; `partition::singular::sparse_joint_condition_number`) against all eigenvalues of the
//! dense Gram matrix computed here by nalgebra (an independent symmetric eigensolver), on every
//! bundled scene and on the 40-four-bar chain along its motion, up to and at its alignments;
//! and the κ `joint_conditioning` reports with the joints (faer's dense eigen-decomposition)
//! against the same reference on the bundled scenes.
//!
//! The bound: the Lanczos iterations stop at a relative residual of
//! `SPARSE_CONDITION_TOL = 1e-10` for each extreme eigenvalue; the dense reference has an
//! absolute error of about `n ε λ_max` in every eigenvalue, so a relative error of
//! `n ε κ` in `λ_min`. The two agree within `1e-6 + 1e3 ε κ` (relative), which is far below
//! what the monitor's decisions need (thresholds of 300 … 1e5, a peak among three outputs).

mod common;

use bondmech::dae::{ConstraintExprs, MechanicsTapes};
use bondmech::partition::thresholds::SPARSE_CONDITION_ROWS;
use bondmech::partition::{
    joint_condition_number, joint_conditioning, sparse_joint_condition_number,
};
use bondmech::{Model, Scene};
use common::four_bar_chain::chain_json_at;
use nalgebra::DMatrix;

/// `κ` from all eigenvalues of `G_v M⁺ G_vᵀ` (nalgebra), `∞` when `λ_min ≤ 0`.
fn reference_condition(gv: &DMatrix<f64>, mass: &[f64]) -> f64 {
    let mut a = gv.clone();
    for (j, &m) in mass.iter().enumerate() {
        let w = if m > 0.0 { 1.0 / m.sqrt() } else { 0.0 };
        a.column_mut(j).scale_mut(w);
    }
    let ev = (&a * a.transpose()).symmetric_eigenvalues();
    let (lmin, lmax) = (ev.min(), ev.max());
    if lmin > 0.0 && lmax > 0.0 {
        lmax / lmin
    } else {
        f64::INFINITY
    }
}

/// Above this κ the dense reference cannot tell a rank loss from a tiny `λ_min`
/// (`λ_min ≲ 1e-12 λ_max` is at the level of its rounding, `n ε λ_max`, for n ≤ 250).
const NUMERICALLY_SINGULAR: f64 = 1e12;

/// Checks the sparse κ of `gv` against the reference; returns `(reference κ, sparse κ)`.
fn check(what: &str, gv: &DMatrix<f64>, mass: &[f64]) -> (f64, Option<f64>) {
    let reference = reference_condition(gv, mass);
    let sparse = sparse_joint_condition_number(gv, mass);
    eprintln!(
        "{what}: rows {}, reference κ {reference:e}, sparse κ {sparse:?}",
        gv.nrows()
    );
    if reference > NUMERICALLY_SINGULAR {
        // the Cholesky factorisation may fail (None, then the dense path decides) or give a κ
        // that is just as large
        if let Some(k) = sparse {
            assert!(
                k > NUMERICALLY_SINGULAR / 10.0,
                "{what}: reference κ {reference:e}, sparse κ {k:e}"
            );
        }
    } else {
        let k = sparse.unwrap_or_else(|| {
            panic!("{what}: the sparse path gave up on a regular Gram matrix (κ {reference:e})")
        });
        let tol = 1e-6 + 1e3 * f64::EPSILON * reference;
        let rel = (k - reference).abs() / reference;
        assert!(
            rel <= tol,
            "{what}: sparse κ {k:e} against reference {reference:e}: relative difference {rel:e} > {tol:e}"
        );
    }
    (reference, sparse)
}

fn bundled_scenes() -> Vec<(String, Scene)> {
    common::bundled_scene_paths()
        .into_iter()
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, Scene::from_path(&p).unwrap())
        })
        .collect()
}

#[test]
fn sparse_condition_number_matches_dense_eigenvalues_on_every_bundled_scene() {
    let mut checked = 0;
    for (name, scene) in bundled_scenes() {
        let model = Model::new(&scene).unwrap();
        let Some(mech) = model.mechanism() else {
            continue; // a raw bond graph has no joints
        };
        let mut sys = mech.clone();
        let c = ConstraintExprs::derive(&mut sys);
        let tapes = MechanicsTapes::new(&mut sys, &c, None);
        let (nq, _, nc) = tapes.dims;
        if nc == 0 {
            continue;
        }
        let x0 = sys.initial_state();
        // the scene's initial configuration and three others, its coordinates moved by
        // 0.05 … 0.15 · sin(j + 1) (G_v is evaluated off the joint manifold there: a Gram matrix
        // of the same structure with other entries)
        for (k, amp) in [0.0, 0.05, 0.1, 0.15].into_iter().enumerate() {
            let mut x = x0.clone();
            for (j, q) in x[..nq].iter_mut().enumerate() {
                *q += amp * ((j + 1) as f64).sin();
            }
            let gv = tapes.gv.matrix(0.0, &x);
            let (reference, _) = check(&format!("{name}, state {k}"), &gv, &sys.mass);
            // the κ reported with the joints at a passage (faer's eigen-decomposition)
            let full = joint_conditioning(&gv, &sys.mass, &sys.rows).condition;
            if reference < NUMERICALLY_SINGULAR {
                let rel = (full - reference).abs() / reference;
                assert!(
                    rel <= 1e-6 + 1e3 * f64::EPSILON * reference,
                    "{name}, state {k}: joint_conditioning κ {full:e} against {reference:e}"
                );
            } else {
                assert!(
                    full > NUMERICALLY_SINGULAR / 10.0,
                    "{name}, state {k}: {full:e}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 40, "{checked} states checked");
}

#[test]
fn sparse_condition_number_matches_dense_eigenvalues_on_the_40_chain_up_to_its_alignment() {
    let n = 40;
    let mut kappas = Vec::new();
    // upright, on the way down, and ever nearer the alignment on the ground line (φ = 0)
    for phi in [
        std::f64::consts::FRAC_PI_2,
        1.0,
        0.3,
        0.1,
        0.03,
        1e-2,
        3e-3,
        1e-3,
        1e-4,
        -1e-3,
    ] {
        let model =
            Model::new(&Scene::from_json_str(&chain_json_at(n, phi, 1.0)).unwrap()).unwrap();
        let mut sys = model.system().clone();
        let c = ConstraintExprs::derive(&mut sys);
        let tapes = MechanicsTapes::new(&mut sys, &c, None);
        assert_eq!(tapes.dims.2, 242);
        assert!(
            tapes.dims.2 >= SPARSE_CONDITION_ROWS,
            "the sparse path is taken"
        );
        let gv = tapes.gv.matrix(0.0, &sys.initial_state());
        let (reference, sparse) = check(&format!("40-chain at φ = {phi}"), &gv, &sys.mass);
        // the solver's monitor takes the sparse value at this size
        assert_eq!(joint_condition_number(&gv, &sys.mass), sparse.unwrap());
        kappas.push(reference);
    }
    // the states span the monitor's range: from below SINGULAR_CONDITION (1e4) upright to
    // past every threshold (REGULAR_CONDITION 1e5, a peak of 6e11) at 1e-4 rad from the line
    assert!(kappas[0] < 1e4, "{kappas:?}");
    assert!(kappas[8] > 1e11, "{kappas:?}");
}
