//! Spatial hinge: the points coincide (`P_a − P_b = 0`, three rows) and the bodies share the
//! hinge axis (two rows). Twin: a spring on each of the five rows (three per axis on
//! `P_a − P_b`, two torsional ones on the axis rows).

use super::joint::{
    perpendicular_pair, unit_axis, Drawing, Driven, DrivenCoordinate, DriverSite, Ends, Glyph,
    Joint, RowWriter, Rows,
};
use crate::expr::{Expr, ExprGraph};
use crate::mech::body::BodyKinematics;
use crate::mech::error::MechError;

/// A spatial hinge about `axis` (body a's frame).
pub(super) struct Hinge<'a> {
    pub(super) axis: &'a [f64],
}

impl Joint for Hinge<'_> {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        w.hinge(ends, self.axis, path)
    }

    fn locks(&self, _spatial: bool) -> usize {
        5
    }

    fn transmits_moment(&self) -> bool {
        true
    }

    fn needs_rotation(&self, _end: usize, spatial: bool) -> bool {
        spatial
    }

    fn draw(&self, d: &mut Drawing<'_>) -> Result<(), MechError> {
        d.ends(false, false)?;
        Err(MechError::at(
            &format!("{}.axis", d.path),
            "a revolute joint with an axis (hinge) exists only in 3D scenes",
        ))
    }

    fn glyph(&self) -> Glyph {
        Glyph::Hinge {
            axis: self.axis.to_vec(),
        }
    }

    /// The rotation `φ` about the axis from the initial relative pose: `cos φ = (R_a c_1)·(R_b
    /// u)`, `sin φ = (R_a c_2)·(R_b u)`, with `c_1, c_2` perpendicular to the unit axis `â`
    /// and `u = R_b(0)ᵀ R_a(0) c_1` (`c_1` as body b sees it initially).
    fn driven_coordinate(&self, w: &mut RowWriter<'_>, site: &DriverSite<'_>) -> Driven {
        let ends = site.ends;
        let f = w.hinge_frame(&ends.ka, &ends.kb, self.axis, site.joint_path)?;
        let (c1, c2) = perpendicular_pair(f.u);
        let a0c1: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|k| f.ra0[i][k] * c1[k]).sum())
            .collect();
        let uu: Vec<f64> = (0..3)
            .map(|k| (0..3).map(|i| f.rb0[i][k] * a0c1[i]).sum())
            .collect();
        let g = &mut *w.g;
        let times = |g: &mut ExprGraph, r: &[[Expr; 3]; 3], c: &[f64]| -> Vec<Expr> {
            let ce: Vec<Expr> = c.iter().map(|&x| g.constant(x)).collect();
            (0..3).map(|i| g.dot(&r[i], &ce)).collect()
        };
        let bu = times(g, &f.rb, &uu);
        let ac1 = times(g, &f.ra, &c1);
        let ac2 = times(g, &f.ra, &c2);
        let cos = g.dot(&ac1, &bu);
        let sin = g.dot(&ac2, &bu);
        Ok(Some(DrivenCoordinate::Turn { cos, sin }))
    }
}

/// A hinge's frame: the unit axis `â` (body a's frame), the bodies' rotations `R_a`, `R_b` and
/// their initial values.
struct HingeFrame {
    u: [f64; 3],
    ra: [[Expr; 3]; 3],
    rb: [[Expr; 3]; 3],
    ra0: [[f64; 3]; 3],
    rb0: [[f64; 3]; 3],
}

impl RowWriter<'_> {
    /// The five rows of a spatial hinge about `axis` (body a's frame).
    fn hinge(&mut self, ends: &Ends, axis: &[f64], path: &str) -> Result<Rows, MechError> {
        if !self.spatial {
            return Err(MechError::at(
                &format!("{path}.axis"),
                "a planar revolute pins about z and takes no axis",
            ));
        }
        let mut rows = self.coincident(ends);
        rows.extend(self.hinge_rows(&ends.ka, &ends.kb, axis, path)?);
        Ok(rows)
    }

    /// The frame of a hinge about `axis` (body a's frame) between bodies `ka` and `kb`.
    fn hinge_frame(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
        axis: &[f64],
        path: &str,
    ) -> Result<HingeFrame, MechError> {
        let u = unit_axis(axis, path)?;
        let ra = ka.rotation3(self.g);
        let rb = kb.rotation3(self.g);
        let x0 = self.x0;
        let ev = |g: &ExprGraph, r: &[[Expr; 3]; 3]| -> [[f64; 3]; 3] {
            let mut m = [[0.0; 3]; 3];
            for i in 0..3 {
                for k in 0..3 {
                    m[i][k] = g.eval(r[i][k], x0);
                }
            }
            m
        };
        let (ra0, rb0) = (ev(self.g, &ra), ev(self.g, &rb));
        Ok(HingeFrame {
            u,
            ra,
            rb,
            ra0,
            rb0,
        })
    }

    /// The two orientation rows of a spatial hinge: with `a = R_a â` the hinge axis (`â` the
    /// unit `axis` in body a's frame) and `c_1, c_2` an orthonormal pair perpendicular to the
    /// axis as body b sees it initially (`R_b(0)ᵀ R_a(0) â`), the rows are `a · (R_b c_1) = 0`
    /// and `a · (R_b c_2) = 0` (dimensionless: about the small relative rotation angles).
    fn hinge_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
        axis: &[f64],
        path: &str,
    ) -> Result<Vec<(&'static str, Expr)>, MechError> {
        let HingeFrame {
            u,
            ra,
            rb,
            ra0,
            rb0,
        } = self.hinge_frame(ka, kb, axis, path)?;
        // global axis at t = 0, then seen from body b
        let ag: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|k| ra0[i][k] * u[k]).sum())
            .collect();
        let ab: [f64; 3] = std::array::from_fn(|k| (0..3).map(|i| rb0[i][k] * ag[i]).sum::<f64>());
        let (c1, c2) = perpendicular_pair(ab);
        let ue: Vec<Expr> = u.iter().map(|&c| self.g.constant(c)).collect();
        let a: Vec<Expr> = (0..3).map(|i| self.g.dot(&ra[i], &ue)).collect();
        let mut out = Vec::with_capacity(2);
        for (dir, c) in [("axis1", c1), ("axis2", c2)] {
            let ce: Vec<Expr> = c.iter().map(|&x| self.g.constant(x)).collect();
            let bc: Vec<Expr> = (0..3).map(|i| self.g.dot(&rb[i], &ce)).collect();
            out.push((dir, self.g.dot(&a, &bc)));
        }
        Ok(out)
    }
}
