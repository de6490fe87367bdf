//! Conditioning of the joints at one state: how close `G_v` is to losing rank.
//!
//! The matrix that must be inverted to find the constraint forces is the mass-weighted Gram
//! matrix `A = G_v M⁺ G_vᵀ` (λ from `A λ = G_v M⁺ Q + γ`; `M⁺` skips massless coordinates).
//! Its spectral condition `κ = λ_max / λ_min` measures how near the joints are to a singular
//! configuration (four-bar chains aligned on the ground line, an isosceles slider-crank at its
//! bifurcation): there `λ_min → 0` and the plain GGL Newton matrix becomes singular. The
//! eigenvectors of `A` whose eigenvalues are (relatively) small say which joint rows lose
//! independence.

use nalgebra::DMatrix;

use crate::mech::ConstraintRow;

/// The conditioning of the joints at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct JointConditioning {
    /// `κ(G_v M⁺ G_vᵀ) = λ_max / λ_min` (infinite when `λ_min ≤ 0`).
    pub condition: f64,
    /// Joints whose rows take part in the near-dependency (the eigenvectors of the eigenvalues
    /// within [`NEAR_NULL_RATIO`] of the smallest one), in row order.
    pub joints: Vec<String>,
}

/// Eigenvalues up to this multiple of the smallest one span the near-null space.
pub const NEAR_NULL_RATIO: f64 = 100.0;

/// Share of an eigenvector's largest entry above which a row counts as involved.
const INVOLVED_SHARE: f64 = 0.05;

/// Conditioning of `G_v M⁺ G_vᵀ` for `gv` (`nc × nv`) and the diagonal mass matrix `mass`.
pub fn joint_conditioning(
    gv: &DMatrix<f64>,
    mass: &[f64],
    rows: &[ConstraintRow],
) -> JointConditioning {
    let nc = gv.nrows();
    if nc == 0 {
        return JointConditioning {
            condition: 1.0,
            joints: vec![],
        };
    }
    let eig = mass_weighted_gram(gv, mass).symmetric_eigen();
    let lmax = eig.eigenvalues.max();
    let lmin = eig.eigenvalues.min();
    let condition = if lmin > 0.0 && lmax > 0.0 {
        lmax / lmin
    } else {
        f64::INFINITY
    };
    let floor = lmin.max(lmax * f64::EPSILON) * NEAR_NULL_RATIO;
    let mut involved = vec![false; nc];
    for (k, &l) in eig.eigenvalues.iter().enumerate() {
        if l > floor {
            continue;
        }
        let col = eig.eigenvectors.column(k);
        let big = col.amax();
        for (i, &c) in col.iter().enumerate() {
            if c.abs() > INVOLVED_SHARE * big {
                involved[i] = true;
            }
        }
    }
    let mut joints: Vec<String> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        if involved[i] && !joints.contains(&r.joint) {
            joints.push(r.joint.clone());
        }
    }
    JointConditioning { condition, joints }
}

/// `A = G_v M⁺ G_vᵀ`, formed as `(G_v M^{-1/2}) (G_v M^{-1/2})ᵀ`.
fn mass_weighted_gram(gv: &DMatrix<f64>, mass: &[f64]) -> DMatrix<f64> {
    let mut a = gv.clone();
    for (j, &m) in mass.iter().enumerate() {
        let w = if m > 0.0 { 1.0 / m.sqrt() } else { 0.0 };
        a.column_mut(j).scale_mut(w);
    }
    &a * a.transpose()
}

/// `κ(G_v M⁺ G_vᵀ) = λ_max / λ_min` alone, from the eigenvalues without the eigenvectors
/// (several times cheaper than [`joint_conditioning`] for many joint rows: the solver
/// monitors it at every output and asks for the joints only where κ is large).
pub fn joint_condition_number(gv: &DMatrix<f64>, mass: &[f64]) -> f64 {
    if gv.nrows() == 0 {
        return 1.0;
    }
    let ev = mass_weighted_gram(gv, mass).symmetric_eigenvalues();
    let (lmax, lmin) = (ev.max(), ev.min());
    if lmin > 0.0 && lmax > 0.0 {
        lmax / lmin
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(j: &str) -> ConstraintRow {
        ConstraintRow {
            joint: j.into(),
            direction: "x".into(),
        }
    }

    #[test]
    fn well_conditioned_rows_have_condition_of_their_mass_ratio() {
        // two independent rows on two coordinates of masses 1 and 4: A = diag(1, 1/4), κ = 4
        let gv = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let c = joint_conditioning(&gv, &[1.0, 4.0], &[row("a"), row("b")]);
        assert!((c.condition - 4.0).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn nearly_parallel_rows_name_their_joints_and_not_the_others() {
        // rows a and b nearly parallel (angle δ), row c independent: λ_min ≈ δ²/2
        let d: f64 = 1e-5;
        let gv =
            DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, d.cos(), d.sin(), 0.0, 0.0, 0.0, 1.0]);
        let c = joint_conditioning(&gv, &[1.0, 1.0, 1.0], &[row("a"), row("b"), row("c")]);
        assert!(c.condition > 1e9 && c.condition < 1e11, "{c:?}");
        assert_eq!(c.joints, vec!["a".to_string(), "b".to_string()]);
        let k = joint_condition_number(&gv, &[1.0, 1.0, 1.0]);
        assert!(
            (k / c.condition - 1.0).abs() < 1e-6,
            "{k:e} against {:e}",
            c.condition
        );
    }
}
