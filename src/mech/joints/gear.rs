//! Gear (planar): an external mesh between two gears on axles fixed to the ground,
//! `g = (θ_b − θ_b(0)) + r (θ_a − θ_a(0)) = 0` (one row, `mesh`), so `ω_b = −r ω_a`.
//!
//! Bond graph: the row's rate `ω_b + r ω_a` is the sum at a 0-junction of body b's ω junction
//! and body a's ω junction through a TF of modulus `r`, held at zero by an `Sf = 0`
//! ([`crate::mech::annotate`] draws it from the closure): the seed's TF between the two
//! angular-velocity 1-junctions. Twin: a torsional spring `k g` on the mesh. Reaction: the
//! mesh's moment on body b (no force: the tooth force is carried by the axles' own joints).
//! The axles are not part of the gear: each gear is pinned to the ground by its own revolute.

use super::joint::{Ends, Glyph, Joint, RowWriter, Rows};
use crate::mech::body::BodyKinematics;
use crate::mech::error::MechError;

/// A gear pair of ratio `r`: body b turns `−r` times body a's rotation.
pub(super) struct Gear {
    pub(super) ratio: f64,
}

impl Joint for Gear {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        for (k, kin) in [&ends.ka, &ends.kb].into_iter().enumerate() {
            if matches!(kin, BodyKinematics::Ground) {
                return Err(MechError::at(
                    &format!("{path}.bodies[{k}]"),
                    "a gear meshes two moving gears; the ground cannot be one of them",
                ));
            }
        }
        if w.spatial {
            return Err(MechError::at(
                &format!("{path}.type"),
                "a gear joint is planar (dimension 2)",
            ));
        }
        let x0 = w.x0;
        let g = &mut *w.g;
        let ta = ends.ka.planar_angle(g);
        let tb = ends.kb.planar_angle(g);
        // (θ_b + r θ_a) − (θ_b(0) + r θ_a(0))
        let rta = g.scale(self.ratio, ta);
        let sum = g.add(tb, rta);
        let c = g.eval(sum, x0);
        let c = g.constant(c);
        Ok(vec![("mesh", g.sub(sum, c))])
    }

    fn locks(&self, _spatial: bool) -> usize {
        1
    }

    fn transmits_moment(&self) -> bool {
        true
    }

    fn needs_rotation(&self, _end: usize, _spatial: bool) -> bool {
        true
    }

    fn glyph(&self) -> Glyph {
        Glyph::Pin
    }
}
