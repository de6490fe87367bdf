//! Joint reactions: the force and moment a joint exerts on its second body, from the joint's
//! constraint forces.
//!
//! The joint's rows `g_J(q) = 0` act on the mechanism through the generalized forces
//! `f = −G_{v,J}ᵀ λ_J` (`M v' = Q − G_vᵀ λ`; for the decoupled twin `λ = k g + c G_v v`, the
//! forces of its joint springs). On the *carrier* body (the joint's second body, or its first
//! when the second is ground) with velocities `v_b`, the wrench `(F, M)` applied at the joint
//! point `P` (global frame, moment about `P`) has the same virtual power as `f`:
//!
//! ```text
//!   F · V_P + M · ω = f_b · v_b   for every v_b,   i.e.   Bᵀ (F, M) = f_b,   B = ∂(V_P, ω)/∂v_b
//! ```
//!
//! `B` is square (planar body: `(v_x, v_y, ω)` or `(u, w, ω)` against `(V_Px, V_Py, ω)`; spatial
//! body: `(V, ω_body)` against `(V_P, ω_global)`; a body without a modelled rotation: `V` against
//! `V_P`) and regular, so the wrench is unique. When the second body is ground the wrench on
//! the first body is computed and moved to the ground by action and reaction, about the
//! ground's joint point: `F_2 = −F_1`, `M_2 = −M_1 − (P_1 − P_2) × F_1`.
//!
//! This one mapping serves every joint kind (the rows say what the joint fixes); the kind only
//! decides which columns are written (whether it transmits a moment). It is the only place where
//! multipliers become forces.

use nalgebra::{DMatrix, DVector};

use crate::expr::Expr;

/// How to read one joint's reaction from its constraint forces (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct JointReaction {
    /// Joint name (as in the scene).
    pub joint: String,
    /// Indices of the joint's constraint rows.
    pub rows: Vec<usize>,
    /// Velocity indices of the carrier body.
    pub velocities: Vec<usize>,
    /// Number of force components: 2 (plane) or 3 (space).
    pub dim: usize,
    /// Rotational velocity components of the carrier (0 without a modelled rotation).
    pub rotations: usize,
    /// The carrier is the first body (the second is ground): apply action and reaction.
    pub flip: bool,
    /// The joint transmits moments: `M` columns are written.
    pub moment: bool,
    /// `B = ∂(V_P, ω)/∂v_b`, `(dim + rotations) × velocities.len()`, row-major.
    pub basis: Vec<Expr>,
    /// `P_1 − P_2` (global), `dim` components: the lever of the action-reaction move.
    pub lever: Vec<Expr>,
}

impl JointReaction {
    /// Column names: `J.Fx, J.Fy[, J.Fz]`, then `J.Mz` (plane) or `J.Mx, J.My, J.Mz` (space)
    /// when the joint transmits moments.
    pub fn columns(&self) -> Vec<String> {
        let mut c: Vec<String> = ["Fx", "Fy", "Fz"][..self.dim]
            .iter()
            .map(|a| format!("{}.{a}", self.joint))
            .collect();
        if self.moment {
            let m: &[&str] = if self.dim == 2 {
                &["Mz"]
            } else {
                &["Mx", "My", "Mz"]
            };
            c.extend(m.iter().map(|a| format!("{}.{a}", self.joint)));
        }
        c
    }

    /// Number of columns.
    pub fn n_columns(&self) -> usize {
        self.dim + if self.moment { 2 * self.dim - 3 } else { 0 }
    }

    /// The reaction columns from the values of [`Self::basis`] and [`Self::lever`], the full
    /// `G_v` (row-major `nc × nv`) and the constraint forces `lambda` of every row; writes
    /// [`Self::n_columns`] values to `out` (NaN if `B` is singular, which a valid body never is).
    pub fn wrench(
        &self,
        basis: &[f64],
        lever: &[f64],
        gv: &[f64],
        nv: usize,
        lambda: &[f64],
        out: &mut [f64],
    ) {
        let nb = self.velocities.len();
        let n = self.dim + self.rotations;
        // f_b = −G_{v,J}ᵀ λ_J restricted to the carrier's velocities
        let f = DVector::from_iterator(
            nb,
            self.velocities.iter().map(|&j| {
                -self
                    .rows
                    .iter()
                    .map(|&k| gv[k * nv + j] * lambda[k])
                    .sum::<f64>()
            }),
        );
        let b = DMatrix::from_row_slice(n, nb, basis);
        let w = b
            .transpose()
            .lu()
            .solve(&f)
            .unwrap_or_else(|| DVector::from_element(n, f64::NAN));
        let mut force: Vec<f64> = w.iter().take(self.dim).copied().collect();
        // moment about P: 2D scalar or 3D vector (zero without a modelled rotation)
        let mut moment = [0.0; 3];
        let mdim = if self.dim == 2 { 1 } else { 3 };
        for k in 0..self.rotations.min(mdim) {
            moment[k] = w[self.dim + k];
        }
        if self.flip {
            let d = lever;
            let lxf: [f64; 3] = if self.dim == 2 {
                [d[0] * force[1] - d[1] * force[0], 0.0, 0.0]
            } else {
                [
                    d[1] * force[2] - d[2] * force[1],
                    d[2] * force[0] - d[0] * force[2],
                    d[0] * force[1] - d[1] * force[0],
                ]
            };
            for k in 0..mdim {
                moment[k] = -moment[k] - lxf[k];
            }
            for x in &mut force {
                *x = -*x;
            }
        }
        out[..self.dim].copy_from_slice(&force);
        if self.moment {
            out[self.dim..self.dim + mdim].copy_from_slice(&moment[..mdim]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::ExprGraph;

    /// A joint whose second body is ground, in 3D, with `B = I` and `G_v = I` (six rows on the
    /// first body's six velocities): the wrench on the first body is `−λ = (F₁, M₁)` about P₁,
    /// and the columns are the ground's: `F = −F₁ = λ_F`, `M = −M₁ − (P₁ − P₂) × F₁`.
    #[test]
    fn ground_second_body_in_3d_moves_the_moment_by_the_lever() {
        let mut g = ExprGraph::new();
        let z = g.zero();
        let r = JointReaction {
            joint: "j".into(),
            rows: (0..6).collect(),
            velocities: (0..6).collect(),
            dim: 3,
            rotations: 3,
            flip: true,
            moment: true,
            basis: vec![z; 36],
            lever: vec![z; 3],
        };
        let mut basis = vec![0.0; 36];
        let mut gv = vec![0.0; 36];
        for i in 0..6 {
            basis[i * 6 + i] = 1.0;
            gv[i * 6 + i] = 1.0;
        }
        let lambda = [1.0, -2.0, 3.0, 0.5, -0.25, 2.0];
        let lever = [0.1, 0.2, -0.3];
        let mut out = [0.0; 6];
        r.wrench(&basis, &lever, &gv, 6, &lambda, &mut out);
        // F₁ = (−1, 2, −3), M₁ = (−0.5, 0.25, −2); d × F₁ with d = (0.1, 0.2, −0.3):
        // (0.2·(−3) − (−0.3)·2, (−0.3)·(−1) − 0.1·(−3), 0.1·2 − 0.2·(−1)) = (0, 0.6, 0.4)
        let expected = [1.0, -2.0, 3.0, 0.5, -0.25 - 0.6, 2.0 - 0.4];
        for (a, b) in out.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15, "{out:?} against {expected:?}");
        }
        assert_eq!(
            r.columns(),
            ["j.Fx", "j.Fy", "j.Fz", "j.Mx", "j.My", "j.Mz"]
        );
    }
}
