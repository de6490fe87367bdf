//! Weld: the points coincide and the relative rotation is fixed (planar: the relative angle,
//! `α_b − α_a − (α_b0 − α_a0) = 0`; spatial: the skew part of `R0ᵀ R_aᵀ R_b`). Bond graph:
//! the pin's 1-junctions plus one equating the angular velocities (`Sf = 0` on the point and
//! on ω when welded to the ground). Twin: a spring per axis on `P_a − P_b` and a torsional
//! one on the relative rotation.

use super::joint::{Drawing, Ends, Glyph, Joint, RowWriter, Rows};
use crate::bond::fragments::{pin_to_ground, weld, zero_flow};
use crate::mech::error::MechError;

/// Two bodies fixed together.
pub(super) struct Weld;

impl Joint for Weld {
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, _path: &str) -> Result<Rows, MechError> {
        Ok(w.weld(ends))
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

impl RowWriter<'_> {
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
}
