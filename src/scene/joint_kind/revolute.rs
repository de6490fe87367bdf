//! `"revolute"`: a planar pin (no `axis`: the two points coincide) or, in a spatial scene, a
//! hinge about `axis` (the first body's frame, global for ground; docs/scene-format.md §5).

use super::own_fields::{direction, nums, KeyShape, OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A revolute joint: a planar pin without `axis`; a spatial hinge with one. A hinge has five
/// rows: the two points coincide (3) and the hinge axis `a = R_1 axis` stays perpendicular to
/// two body-2 vectors `R_2 c_1`, `R_2 c_2` (2), where `c_1, c_2` span the plane perpendicular to
/// the axis as seen in body 2 at the initial configuration (`R_2(0)ᵀ R_1(0) axis`).
#[derive(Debug, Clone, PartialEq)]
pub struct Revolute {
    /// The hinge axis in the frame of the first body (global for ground; non-zero); `None`
    /// for a planar pin.
    pub axis: Option<Vec<f64>>,
}

impl Revolute {
    /// A planar pin: the two points coincide; free rotation about Z.
    pub fn pin() -> Self {
        Revolute { axis: None }
    }

    /// A spatial hinge about `axis` (the first body's frame, global for ground).
    pub fn hinge(axis: Vec<f64>) -> Self {
        Revolute { axis: Some(axis) }
    }
}

impl OwnFields for Revolute {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, _bodies: &[String; 2]) {
        match (&self.axis, dim) {
            (None, Dimension::Spatial) => p.push(
                field(path, "axis"),
                "a revolute joint in a spatial scene is a hinge and needs an axis (the hinge axis in the frame of the first body, global for ground; body 2 keeps the relative orientation of the initial configuration about it); use spherical for a ball joint",
            ),
            (Some(_), Dimension::Planar) => p.push(
                field(path, "axis"),
                "only a prismatic joint has an axis in a planar scene (a planar revolute pins about z)",
            ),
            (Some(axis), dim) => direction(p, &field(path, "axis"), axis, dim.coords()),
            (None, Dimension::Planar) => {}
        }
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        if let Some(axis) = &self.axis {
            e.push(("axis", nums(axis)));
        }
    }
}

impl ReadOwnFields for Revolute {
    const TYPE: &'static str = "revolute";
    const KEYS: &'static [OwnKey] = &[OwnKey {
        name: "axis",
        shape: KeyShape::Vector,
        description: "Hinge axis (spatial revolute), first body's frame.",
    }];

    fn parse(_p: &mut Problems, f: &Fields<'_>, axis: Option<Vec<f64>>) -> Option<Self> {
        match axis {
            Some(axis) => Some(Revolute::hinge(axis)),
            None if f.get("axis").is_some() => None,
            None => Some(Revolute::pin()),
        }
    }
}
