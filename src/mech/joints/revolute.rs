//! Revolute joint, planar pin (seed 16.5 Fig. 16 and 16.7): the two points coincide,
//! `g = P_a − P_b = 0` per axis; in the bond graph, one 1-junction per axis equating the
//! points' velocities (or an `Sf = 0` on a point pinned to the ground). Twin: a spring per
//! axis on `P_a − P_b` (Fig. 17, 21). In a spatial scene a revolute needs an axis (a
//! [`super::hinge`]).

use super::joint::{Drawing, Ends, Glyph, Joint, RowWriter, Rows};
use crate::mech::error::MechError;

/// A planar pin.
pub(super) struct Revolute;

impl Joint for Revolute {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError> {
        if w.spatial {
            return Err(MechError::at(
                &format!("{path}.axis"),
                "a revolute joint in 3D is a hinge and needs an axis; use spherical for a ball joint",
            ));
        }
        Ok(w.coincident(ends))
    }

    fn locks(&self, spatial: bool) -> usize {
        if spatial {
            5
        } else {
            2
        }
    }

    fn transmits_moment(&self) -> bool {
        false
    }

    fn draw(&self, d: &mut Drawing<'_>) -> Result<(), MechError> {
        let e = d.ends(false, true)?;
        d.pin(&e);
        Ok(())
    }

    fn glyph(&self) -> Glyph {
        Glyph::Pin
    }
}
