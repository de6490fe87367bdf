//! `"prismatic"`: a slider along `axis` (the first body's frame, global for ground;
//! docs/scene-format.md §5).

use super::own_fields::{direction, nums, KeyShape, OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A slider along `axis` (frame of the first body); relative rotation fixed (planar: one
/// normal row and the relative angle; spatial: two normal rows and three rotation rows, the
/// latter left out when the second body is a point mass).
#[derive(Debug, Clone, PartialEq)]
pub struct Prismatic {
    /// Sliding direction in the frame of the first body (non-zero; not normalised).
    pub axis: Vec<f64>,
}

impl OwnFields for Prismatic {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, _bodies: &[String; 2]) {
        direction(p, &field(path, "axis"), &self.axis, dim.coords());
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        e.push(("axis", nums(&self.axis)));
    }
}

impl ReadOwnFields for Prismatic {
    const TYPE: &'static str = "prismatic";
    const KEYS: &'static [OwnKey] = &[OwnKey {
        name: "axis",
        shape: KeyShape::Vector,
        description: "Sliding direction (prismatic), first body's frame.",
    }];

    fn parse(p: &mut Problems, f: &Fields<'_>, axis: Option<Vec<f64>>) -> Option<Self> {
        if axis.is_none() && f.get("axis").is_none() {
            p.push(
                f.path("axis"),
                "a prismatic joint needs an axis (the sliding direction in the frame of the first body)",
            );
        }
        axis.map(|axis| Prismatic { axis })
    }
}
