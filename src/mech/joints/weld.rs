//! Weld: the points coincide and the relative rotation is fixed (planar: the relative angle,
//! `α_b − α_a − (α_b0 − α_a0) = 0`; spatial: the skew part of `R0ᵀ R_aᵀ R_b`). Bond graph:
//! the pin's 1-junctions plus one equating the angular velocities (`Sf = 0` on the point and
//! on ω when welded to the ground). Twin: a spring per axis on `P_a − P_b` and a torsional
//! one on the relative rotation.

use super::{Drawing, Ends, Glyph, Joint, Rows};
use crate::bond::fragments::{pin_to_ground, weld, zero_flow};
use crate::expr::Expr;
use crate::mech::body::{AngleSlot, BodyKinematics};
use crate::mech::geometry::Geometry;
use crate::mech::MechError;

/// Two bodies fixed together.
pub(super) struct Weld;

impl Joint for Weld {
    fn rows(&self, geo: &mut Geometry<'_>, ends: &Ends, _path: &str) -> Result<Rows, MechError> {
        Ok(geo.weld(ends))
    }

    fn locks(&self, spatial: bool) -> usize {
        if spatial {
            6
        } else {
            3
        }
    }

    fn transmits_moment(&self) -> bool {
        true
    }

    fn needs_rotation(&self, _end: usize, _spatial: bool) -> bool {
        true
    }

    fn draw(&self, d: &mut Drawing<'_>) -> Result<(), MechError> {
        let e = d.ends(false, true)?;
        if d.open {
            // the angle row is completed from its closure
            d.pin(&e);
            return Ok(());
        }
        let b1 = d.bodies[e.b1];
        let w1 = d.omegas[e.b1].ok_or_else(|| {
            MechError::at(
                d.path,
                format!("weld: body '{b1}' has no modelled rotation"),
            )
        })?;
        match (&e.p2, e.b2) {
            (Some(p2), Some(b2)) => {
                let w2 = d.omegas[b2].ok_or_else(|| {
                    MechError::at(
                        d.path,
                        format!("weld: body '{}' has no modelled rotation", d.bodies[b2]),
                    )
                })?;
                weld(d.g, d.name, (&e.p1, w1), (p2, w2));
            }
            _ => {
                // fixed to ground: Sf = 0 on both components and on ω
                pin_to_ground(d.g, d.name, &e.p1, e.ground_first);
                zero_flow(d.g, &format!("{}.w", d.name), w1);
            }
        }
        Ok(())
    }

    fn glyph(&self) -> Glyph {
        Glyph::Weld
    }
}

impl Geometry<'_> {
    /// The rows of a weld.
    fn weld(&mut self, ends: &Ends) -> Rows {
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
