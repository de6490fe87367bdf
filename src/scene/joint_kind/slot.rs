//! `"slot"` (planar pin-in-slot): the second body's point stays on the line through the first
//! body's point along `axis` (docs/scene-format.md §5).

use super::own_fields::{direction, nums, KeyShape, OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A pin in a slot along `axis` (fixed in the first body); sliding and rotation free.
#[derive(Debug, Clone, PartialEq)]
pub struct Slot {
    /// The slot's direction in the first body's frame (global for ground; non-zero).
    pub axis: Vec<f64>,
}

impl OwnFields for Slot {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, _bodies: &[String; 2]) {
        match dim {
            Dimension::Spatial => p.push(
                field(path, "type"),
                "a slot joint is planar (dimension 2); in space use a prismatic joint with a point mass",
            ),
            Dimension::Planar => direction(p, &field(path, "axis"), &self.axis, 2),
        }
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        e.push(("axis", nums(&self.axis)));
    }
}

impl ReadOwnFields for Slot {
    const TYPE: &'static str = "slot";
    const KEYS: &'static [OwnKey] = &[OwnKey {
        name: "axis",
        shape: KeyShape::Vector,
        description: "The slot's direction (slot), first body's frame.",
    }];

    fn parse(p: &mut Problems, f: &Fields<'_>, axis: Option<Vec<f64>>) -> Option<Self> {
        if axis.is_none() && f.get("axis").is_none() {
            p.push(
                f.path("axis"),
                "a slot joint needs an axis (the slot's direction in the frame of the first body)",
            );
        }
        axis.map(|axis| Slot { axis })
    }
}
