//! Spherical (ball) joint, spatial: the two points coincide, `g = P_a − P_b = 0` per axis
//! (three rows; the 3D form of the pin's 1-junctions `V_A1 = V_A2`, 16.5). Twin: a spring
//! per axis on `P_a − P_b`.

use super::joint::{Drawing, Ends, Glyph, Joint, RowWriter, Rows};
use crate::mech::error::MechError;

/// A ball joint.
pub(super) struct Spherical;

impl Joint for Spherical {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, _path: &str) -> Result<Rows, MechError> {
        Ok(w.coincident(ends))
    }

    fn locks(&self, _spatial: bool) -> usize {
        3
    }

    fn transmits_moment(&self) -> bool {
        false
    }

    fn draw(&self, d: &mut Drawing<'_>) -> Result<(), MechError> {
        // the planar drawing: a ball joint has no planar fragment
        d.ends(false, false)?;
        Err(MechError::at(
            &format!("{}.type", d.path),
            "spherical joints exist only in 3D scenes",
        ))
    }

    fn glyph(&self) -> Glyph {
        Glyph::Ball
    }
}
