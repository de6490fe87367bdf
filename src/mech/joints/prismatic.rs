//! Prismatic joint (a slider, seed Fig. 29): the second body's point stays on the line
//! through the first body's point along `axis` (body a's frame), and the relative rotation is
//! fixed. Planar: `n·(P_b − P_a) = 0` with `n = R(α_a) perp(axis)`, plus the relative angle;
//! spatial: two normal rows and the three rotation rows of a weld. Bond graph: the seed's
//! slider fragment along a global axis (Fig. 29). Twin: a spring on each row (across the
//! rail, and torsional on the relative rotation).

use super::joint::{
    perpendicular_pair, unit_axis, Drawing, Driven, DrivenCoordinate, DriverSite, Ends, Glyph,
    Joint, RowWriter, Rows,
};
use crate::bond::fragments::{prismatic, Axis};
use crate::expr::Expr;
use crate::mech::body::BodyKinematics;
use crate::mech::body::PointKinematics;
use crate::mech::error::MechError;

/// A slider along `axis` (body a's frame).
pub(super) struct Prismatic<'a> {
    pub(super) axis: &'a [f64],
}

impl Joint for Prismatic<'_> {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        w.prismatic(ends, self.axis, path)
    }

    fn locks(&self, spatial: bool) -> usize {
        if spatial {
            5
        } else {
            2
        }
    }

    fn transmits_moment(&self) -> bool {
        true
    }

    fn needs_rotation(&self, end: usize, spatial: bool) -> bool {
        // the rail turns with the first body
        !spatial && end == 0
    }

    fn draw(&self, d: &mut Drawing<'_>) -> Result<(), MechError> {
        let e = d.ends(true, false)?;
        if d.open {
            return Ok(());
        }
        let axis = self.axis;
        let ax = if axis[0].abs() < 1e-12 {
            Axis::Y
        } else if axis[1].abs() < 1e-12 {
            Axis::X
        } else {
            return Err(MechError::at(
                &format!("{}.axis", d.path),
                "the bond graph drawing supports sliders along a global axis only",
            ));
        };
        let w1 = d.omegas[e.b1];
        let other = match (&e.p2, e.b2) {
            (Some(p2), Some(b2)) => Some((p2, d.omegas[b2])),
            _ => None,
        };
        prismatic(d.g, d.name, (&e.p1, w1), other, ax);
        Ok(())
    }

    fn glyph(&self) -> Glyph {
        Glyph::Slider {
            axis: self.axis.to_vec(),
        }
    }

    /// The displacement along the rail, `(P_b − P_a)·(R_a â)`.
    fn driven_coordinate(&self, w: &mut RowWriter<'_>, site: &DriverSite<'_>) -> Driven {
        let ends = site.ends;
        let g = &mut *w.g;
        let dim = ends.pa.position.len();
        let axis: Vec<Expr> = if w.spatial {
            let u = unit_axis(self.axis, site.joint_path)?;
            let ra = ends.ka.rotation3(g);
            let ue: Vec<Expr> = u.iter().map(|&x| g.constant(x)).collect();
            (0..3).map(|i| g.dot(&ra[i], &ue)).collect()
        } else {
            let k = self.axis;
            let n = (k[0] * k[0] + k[1] * k[1]).sqrt();
            let u = [k[0] / n, k[1] / n];
            if matches!(ends.ka, BodyKinematics::Ground) {
                vec![g.constant(u[0]), g.constant(u[1])]
            } else {
                let p = ends.ka.point(g, &u);
                let o = ends.ka.point(g, &[0.0, 0.0]);
                (0..2)
                    .map(|i| g.sub(p.position[i], o.position[i]))
                    .collect()
            }
        };
        let dvec: Vec<Expr> = (0..dim)
            .map(|i| g.sub(ends.pb.position[i], ends.pa.position[i]))
            .collect();
        Ok(Some(DrivenCoordinate::Linear(g.dot(&axis, &dvec))))
    }
}

impl RowWriter<'_> {
    /// The rows of a prismatic joint along `axis`.
    fn prismatic(&mut self, ends: &Ends, axis: &[f64], path: &str) -> Result<Rows, MechError> {
        if self.spatial {
            return self.spatial_prismatic_rows(&ends.ka, &ends.kb, &ends.pa, &ends.pb, axis, path);
        }
        let (ka, kb, pa, pb) = (&ends.ka, &ends.kb, &ends.pa, &ends.pb);
        let mut rows: Rows = Vec::with_capacity(2);
        // n = R(α_a)·perp(u); n·(P_b − P_a) = 0
        let norm = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
        let perp = [-axis[1] / norm, axis[0] / norm];
        let n = ka.point(self.g, &perp);
        let origin = ka.point(self.g, &[0.0, 0.0]);
        let g = &mut *self.g;
        let nx = if matches!(ka, BodyKinematics::Ground) {
            [g.constant(perp[0]), g.constant(perp[1])]
        } else {
            [
                g.sub(n.position[0], origin.position[0]),
                g.sub(n.position[1], origin.position[1]),
            ]
        };
        let d = [
            g.sub(pb.position[0], pa.position[0]),
            g.sub(pb.position[1], pa.position[1]),
        ];
        rows.push(("normal", g.dot(&nx, &d)));
        if let Some(e) = self.relative_angle_row(ka, kb) {
            rows.push(("angle", e));
        }
        Ok(rows)
    }

    /// Rows of a spatial prismatic joint: with `d = P_b − P_a` and `c_1, c_2` an orthonormal pair
    /// perpendicular to `axis` in body a's frame, `(R_a c_1)·d = 0` and `(R_a c_2)·d = 0` (body b's
    /// point stays on the line through `P_a` along `R_a axis`), plus the three rows of a weld
    /// fixing the relative rotation (left out when body b is a point mass, which has none).
    fn spatial_prismatic_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
        pa: &PointKinematics,
        pb: &PointKinematics,
        axis: &[f64],
        path: &str,
    ) -> Result<Vec<(&'static str, Expr)>, MechError> {
        let axis = unit_axis(axis, path)?;
        if matches!(ka, BodyKinematics::Particle { .. }) {
            return Err(MechError::at(
                &format!("{path}.bodies[0]"),
                "the first body of a prismatic joint carries the axis and needs a rotation; a point mass (inertia [0, 0, 0]) has none (list it second)",
            ));
        }
        let (c1, c2) = perpendicular_pair(axis);
        let ra = ka.rotation3(self.g);
        let d: Vec<Expr> = (0..3)
            .map(|k| self.g.sub(pb.position[k], pa.position[k]))
            .collect();
        let mut out = Vec::with_capacity(5);
        for (dir, c) in [("normal1", c1), ("normal2", c2)] {
            let ce: Vec<Expr> = c.iter().map(|&x| self.g.constant(x)).collect();
            let n: Vec<Expr> = (0..3).map(|i| self.g.dot(&ra[i], &ce)).collect();
            out.push((dir, self.g.dot(&n, &d)));
        }
        if !matches!(kb, BodyKinematics::Particle { .. }) {
            out.extend(self.relative_rotation_rows(ka, kb));
        }
        Ok(out)
    }
}
