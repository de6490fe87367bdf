//! Slot (planar pin-in-slot): the second body's point `P_b` stays on the line through the
//! first body's point `P_a` along `axis` (fixed in the first body); sliding along the slot and
//! the relative rotation are free. One row, `g = n · (P_b − P_a) = 0` with
//! `n = R(α_a) perp(û)`, `perp(u) = (−u_y, u_x)`, `û` the unit axis (row `normal`).
//!
//! Bond graph: the row's rate `ṅ·(P_b − P_a) + n·(V_b − V_a)` as a modulated sum of the
//! inertias' junction flows into an `Sf = 0` ([`crate::mech::annotate`] draws it from the
//! closure). Twin: a spring `k g` across the slot. Reaction: the normal force on the second
//! body (no moment: the pin turns freely).

use super::joint::{unit_axis, Ends, Glyph, Joint, RowWriter, Rows};
use crate::mech::body::BodyKinematics;
use crate::mech::error::MechError;

/// A pin sliding in a slot along `axis` (the first body's frame).
pub(super) struct Slot<'a> {
    pub(super) axis: &'a [f64],
}

impl Joint for Slot<'_> {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        if w.spatial || self.axis.len() != 2 {
            return Err(MechError::at(
                &format!("{path}.axis"),
                "a slot joint is planar and needs a 2D direction",
            ));
        }
        let u = unit_axis(&[self.axis[0], self.axis[1], 0.0], path)?;
        let perp = [-u[1], u[0]];
        let g = &mut *w.g;
        // n = R(α_a) perp(û): the first body's point at `perp` minus its origin
        let n = match &ends.ka {
            BodyKinematics::Ground => [g.constant(perp[0]), g.constant(perp[1])],
            ka => {
                let tip = ka.point(g, &perp);
                let origin = ka.point(g, &[0.0, 0.0]);
                [
                    g.sub(tip.position[0], origin.position[0]),
                    g.sub(tip.position[1], origin.position[1]),
                ]
            }
        };
        let d = [
            g.sub(ends.pb.position[0], ends.pa.position[0]),
            g.sub(ends.pb.position[1], ends.pa.position[1]),
        ];
        Ok(vec![("normal", g.dot(&n, &d))])
    }

    fn locks(&self, _spatial: bool) -> usize {
        1
    }

    fn transmits_moment(&self) -> bool {
        false
    }

    fn needs_rotation(&self, end: usize, _spatial: bool) -> bool {
        // the slot turns with the first body
        end == 0
    }

    fn glyph(&self) -> Glyph {
        Glyph::Slider {
            axis: self.axis.to_vec(),
        }
    }
}
