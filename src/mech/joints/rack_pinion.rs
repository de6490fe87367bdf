//! Rack and pinion (planar): `bodies: [pinion, rack]`, `points: [C, P]` (the pinion's centre; a
//! point of the rack), pitch radius ρ and the rack's direction `û` in the rack's frame. The
//! rack's travel along its axis relative to the pinion's centre equals ρ times the pinion's
//! rotation relative to the rack (row `mesh`):
//!
//! `g = (P − C)·(R(θ_r) û) − s(0) − ρ ((θ_p − θ_r) − (θ_p(0) − θ_r(0))) = 0`,
//!
//! `s(0)` the initial value of `(P − C)·(R(θ_r) û)`. Sign: the pinion lies on the left of the
//! rack's axis (axis +X, pinion above the rack), so a counter-clockwise pinion drives the rack
//! along `+û`. The rack keeps its own (prismatic) joint; this row only couples.
//!
//! Bond graph: the row's rate (`ρ` times the pinion's ω against the rack's velocity along its
//! axis: a TF between ω and v when the rack does not turn, MTFs when it does) as a modulated sum
//! of the inertias' junction flows into an `Sf = 0` ([`crate::mech::annotate`] draws it from
//! the closure). Twin: a spring `k g` along the rack. Reaction: the tooth force on the rack
//! (and its moment about P).

use super::joint::{unit_axis, Ends, Glyph, Joint, RowWriter, Rows};
use crate::mech::error::MechError;

/// A pinion of pitch radius `radius` on a rack along `axis` (the rack's frame).
pub(super) struct RackPinion<'a> {
    pub(super) radius: f64,
    pub(super) axis: &'a [f64],
}

impl Joint for RackPinion<'_> {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        if w.spatial || self.axis.len() != 2 {
            return Err(MechError::at(
                &format!("{path}.axis"),
                "a rack_pinion joint is planar and needs a 2D direction",
            ));
        }
        let u = unit_axis(&[self.axis[0], self.axis[1], 0.0], path)?;
        let x0 = w.x0;
        let g = &mut *w.g;
        // R(θ_r) û: the rack's point at û minus its origin
        let tip = ends.kb.point(g, &[u[0], u[1]]);
        let origin = ends.kb.point(g, &[0.0, 0.0]);
        let dir = [
            g.sub(tip.position[0], origin.position[0]),
            g.sub(tip.position[1], origin.position[1]),
        ];
        let d = [
            g.sub(ends.pb.position[0], ends.pa.position[0]),
            g.sub(ends.pb.position[1], ends.pa.position[1]),
        ];
        let s = g.dot(&d, &dir);
        let tp = ends.ka.planar_angle(g);
        let tr = ends.kb.planar_angle(g);
        let rel = g.sub(tp, tr);
        let turn = g.scale(self.radius, rel);
        // s − ρ (θ_p − θ_r) − [its initial value]
        let e = g.sub(s, turn);
        let e0 = g.eval(e, x0);
        let c = g.constant(e0);
        Ok(vec![("mesh", g.sub(e, c))])
    }

    fn locks(&self, _spatial: bool) -> usize {
        1
    }

    fn transmits_moment(&self) -> bool {
        true
    }

    fn needs_rotation(&self, end: usize, _spatial: bool) -> bool {
        // the pinion turns; the rack's angle enters as far as it is modelled
        end == 0
    }

    fn glyph(&self) -> Glyph {
        Glyph::Pin
    }
}
