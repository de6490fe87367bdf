//! Joints as types: each kind is one file holding a type that implements `Joint` (the trait
//! and what the kinds share are in `joint.rs`, below them), and `joint_type` is the one
//! dispatch from the scene's [`JointKind`] to it.
//!
//! A kind owns, in its file: its closure rows `g_k(q) = 0` over the bodies' coordinates (seed
//! 16.5, 16.7), its planar bond-graph fragment (the chapter's, when it draws one; otherwise
//! [`crate::mech::annotate`] draws the closure's rate as a modulated sum `Σ_j (∂ġ_k/∂v_j) f_j`
//! of the inertias' junction flows into an `Sf = 0`), how many rows it locks, which of its
//! bodies need a modelled rotation, whether its reaction carries a moment, and the glyph it is
//! drawn with. The scene side of a kind (its
//! `"type"` and own fields) is [`crate::scene::joint_kind`].
//!
//! The closure of a row is what its constraint junction in the bond graph integrates: the
//! junction's flow constraint is `d/dt g_k = G_k v`, which [`crate::bond::mechanics`] checks
//! at build time. The twin ([`crate::bond::decouple`]) opens every constraint junction and puts
//! in a C of compliance `1/k` whose displacement is the row's closure `g_k`, so each kind's
//! twin spring is `k·g_k` along its own rows.
//!
//! Each joint's reaction (its force and moment on the second body) is read from the
//! multipliers of its rows ([`crate::mech::JointReaction`]).

mod distance;
mod gear;
mod hinge;
pub(crate) mod joint;
mod prismatic;
mod rack_pinion;
mod revolute;
mod slot;
mod spherical;
mod universal;
mod weld;

use crate::mech::error::MechError;
use crate::scene::JointKind;
pub use joint::Glyph;
pub(crate) use joint::{
    common_frame, Drawing, DrivenCoordinate, DriverSite, Ends, Joint, RowWriter,
};

/// The one dispatch from a scene's joint kind to its type.
pub(super) fn joint_type(kind: &JointKind) -> Box<dyn Joint + '_> {
    match kind {
        JointKind::Revolute(k) => match &k.axis {
            None => Box::new(revolute::Revolute),
            Some(axis) => Box::new(hinge::Hinge { axis }),
        },
        JointKind::Spherical(_) => Box::new(spherical::Spherical),
        JointKind::Prismatic(k) => Box::new(prismatic::Prismatic { axis: &k.axis }),
        JointKind::Weld(_) => Box::new(weld::Weld),
        JointKind::Universal(k) => Box::new(universal::Universal { axes: &k.axes }),
        JointKind::Gear(k) => Box::new(gear::Gear { ratio: k.ratio }),
        JointKind::Slot(k) => Box::new(slot::Slot { axis: &k.axis }),
        JointKind::Distance(k) => Box::new(distance::Distance { length: k.length }),
        JointKind::RackPinion(k) => Box::new(rack_pinion::RackPinion {
            radius: k.radius,
            axis: &k.axis,
        }),
    }
}

/// How a joint of kind `kind` is drawn.
pub fn glyph(kind: &JointKind) -> Glyph {
    joint_type(kind).glyph()
}

/// Rows a joint of kind `kind` locks (at most), planar or `spatial`.
pub(super) fn locks(kind: &JointKind, spatial: bool) -> usize {
    joint_type(kind).locks(spatial)
}

/// Whether a joint of kind `kind` fixes a relative rotation (its reaction carries a moment):
/// a body whose every joint does not rotates freely ([`crate::mech::annotate`]).
pub(crate) fn transmits_moment(kind: &JointKind) -> bool {
    joint_type(kind).transmits_moment()
}

/// Whether a joint of kind `kind` needs body `end`'s rotation modelled.
pub(super) fn needs_rotation(kind: &JointKind, end: usize, spatial: bool) -> bool {
    joint_type(kind).needs_rotation(end, spatial)
}

impl Drawing<'_> {
    /// The joint draws itself: [`Joint::draw`] of its kind.
    pub(crate) fn draw(&mut self, kind: &JointKind) -> Result<(), MechError> {
        joint_type(kind).draw(self)
    }
}
