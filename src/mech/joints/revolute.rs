//! Revolute joint, planar pin (seed 16.5 Fig. 16 and 16.7): the two points coincide,
//! `g = P_a − P_b = 0` per axis; in the bond graph, one 1-junction per axis equating the
//! points' velocities (or an `Sf = 0` on a point pinned to the ground). Twin: a spring per
//! axis on `P_a − P_b` (Fig. 17, 21). In a spatial scene a revolute needs an axis (a
//! [`super::hinge`]).

use super::joint::{
    Drawing, Driven, DrivenCoordinate, DriverSite, Ends, Glyph, Joint, RowWriter, Rows,
};
use crate::mech::body::{AngleSlot, BodyKinematics};
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

    /// The relative angle `α_b − α_a`; refused where a body's rotation is not modelled.
    fn driven_coordinate(&self, w: &mut RowWriter<'_>, site: &DriverSite<'_>) -> Driven {
        let ends = site.ends;
        let modelled = |k: &BodyKinematics| {
            !matches!(
                k,
                BodyKinematics::PlanarInertial {
                    angle: AngleSlot::Fixed(_),
                    ..
                }
            )
        };
        for (b, k) in site.bodies.iter().zip([&ends.ka, &ends.kb]) {
            if !modelled(k) {
                return Err(MechError::at(
                    &format!("{}.joint", site.path),
                    format!("joint '{}': body '{b}' has no modelled rotation (inertia 0 and nothing turns it), so its angle cannot be driven", site.joint),
                ));
            }
        }
        let aa = ends.ka.planar_angle(w.g);
        let ab = ends.kb.planar_angle(w.g);
        Ok(Some(DrivenCoordinate::Linear(w.g.sub(ab, aa))))
    }
}
