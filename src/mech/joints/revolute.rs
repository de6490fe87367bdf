//! Revolute (planar pin, seed 16.5 Fig. 16 and 16.7) and spherical joints: the two points
//! coincide, `g = P_a − P_b = 0` per axis; in the bond graph, one 1-junction per axis equating
//! the points' velocities (or an `Sf = 0` on a point pinned to the ground).

use super::{Ends, Rows};
use crate::mech::geometry::Geometry;
use crate::mech::MechError;
use crate::scene::JointKind;

impl Geometry<'_> {
    /// The rows of a revolute or spherical joint.
    pub(super) fn revolute(
        &mut self,
        ends: &Ends,
        kind: &JointKind,
        path: &str,
    ) -> Result<Rows, MechError> {
        if self.spatial && matches!(kind, JointKind::Revolute) {
            return Err(MechError::at(
                &format!("{path}.axis"),
                "a revolute joint in 3D is a hinge and needs an axis; use spherical for a ball joint",
            ));
        }
        Ok(self.coincident(ends))
    }
}
