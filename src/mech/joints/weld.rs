//! Weld: the points coincide and the relative rotation is fixed (planar: the relative angle,
//! `α_b − α_a − (α_b0 − α_a0) = 0`; spatial: the skew part of `R0ᵀ R_aᵀ R_b`).

use super::{Ends, Rows};
use crate::expr::Expr;
use crate::mech::body::{AngleSlot, BodyKinematics};
use crate::mech::geometry::Geometry;

impl Geometry<'_> {
    /// The rows of a weld.
    pub(super) fn weld(&mut self, ends: &Ends) -> Rows {
        let mut rows = self.coincident(ends);
        if self.spatial {
            rows.extend(self.relative_rotation_rows(&ends.ka, &ends.kb));
        } else if let Some(e) = self.relative_angle_row(&ends.ka, &ends.kb) {
            rows.push(("angle", e));
        }
        rows
    }

    /// `α_b − α_a − (α_b0 − α_a0)`, when both angles are modelled (or ground).
    pub(super) fn relative_angle_row(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
    ) -> Option<Expr> {
        let modelled = |k: &BodyKinematics| {
            matches!(
                k,
                BodyKinematics::Ground
                    | BodyKinematics::PlanarBodyFixed { .. }
                    | BodyKinematics::PlanarInertial {
                        angle: AngleSlot::Coordinate(_),
                        ..
                    }
            )
        };
        if !modelled(ka) || !modelled(kb) {
            return None;
        }
        let aa = ka.planar_angle(&mut self.g);
        let ab = kb.planar_angle(&mut self.g);
        let x0 = self.initial_slots();
        let rel0 = self.g.eval(ab, &x0) - self.g.eval(aa, &x0);
        let d = self.g.sub(ab, aa);
        let c = self.g.constant(rel0);
        Some(self.g.sub(d, c))
    }

    /// Orientation rows of a spatial weld: the skew part of `C = R0ᵀ R_aᵀ R_b`.
    pub(super) fn relative_rotation_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
    ) -> Vec<(&'static str, Expr)> {
        let ra = ka.rotation3(&mut self.g);
        let rb = kb.rotation3(&mut self.g);
        let x0 = self.initial_slots();
        let mut rel = [[self.g.zero(); 3]; 3];
        let mut rel0 = [[0.0; 3]; 3];
        for i in 0..3 {
            for k in 0..3 {
                let ca: Vec<Expr> = (0..3).map(|m| ra[m][i]).collect();
                let cb: Vec<Expr> = (0..3).map(|m| rb[m][k]).collect();
                rel[i][k] = self.g.dot(&ca, &cb);
                rel0[i][k] = self.g.eval(rel[i][k], &x0);
            }
        }
        // C = rel0ᵀ rel
        let mut c = [[self.g.zero(); 3]; 3];
        for i in 0..3 {
            for k in 0..3 {
                let terms: Vec<Expr> = (0..3)
                    .map(|m| self.g.scale(rel0[m][i], rel[m][k]))
                    .collect();
                c[i][k] = self.g.sum(&terms);
            }
        }
        let mut out = Vec::new();
        for (dir, (a0, a1), (p, q)) in [
            ("rx", (2, 1), (1, 2)),
            ("ry", (0, 2), (2, 0)),
            ("rz", (1, 0), (0, 1)),
        ] {
            let d = self.g.sub(c[a0][a1], c[p][q]);
            out.push((dir, self.g.scale(0.5, d)));
        }
        out
    }
}
