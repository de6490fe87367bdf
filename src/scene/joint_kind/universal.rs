//! `"universal"` (spatial Hooke's joint): `"points": [pa, pb]`, `"axes": [a1, a2]` (a1 in the
//! first body's frame, a2 in the second's; docs/scene-format.md §5).

use super::own_fields::{
    direction, nums, refuse_ground, KeyShape, OwnFields, OwnKey, ReadOwnFields,
};
use crate::scene::error::{field, index, Problems};
use crate::scene::fields::{vector, Fields};
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A Hooke's joint: the points coincide and the fork axes stay perpendicular,
/// `(R_a a1)·(R_b a2) = 0` (four rows).
#[derive(Debug, Clone, PartialEq)]
pub struct Universal {
    /// `[a1, a2]`: a1 in the first body's frame, a2 in the second's (non-zero, 3D).
    pub axes: [Vec<f64>; 2],
}

impl OwnFields for Universal {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, bodies: &[String; 2]) {
        if dim == Dimension::Planar {
            p.push(
                field(path, "type"),
                "a universal (Hooke's) joint needs a spatial scene (dimension 3)",
            );
            return;
        }
        for (k, a) in self.axes.iter().enumerate() {
            direction(p, &index(&field(path, "axes"), k), a, 3);
        }
        refuse_ground(
            p,
            path,
            bodies,
            &[0, 1],
            "a universal joint connects two moving shafts; hinge a shaft to the ground with a revolute joint instead",
        );
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        e.push((
            "axes",
            Json::Array(self.axes.iter().map(|a| nums(a)).collect()),
        ));
    }
}

impl ReadOwnFields for Universal {
    const TYPE: &'static str = "universal";
    const KEYS: &'static [OwnKey] = &[OwnKey {
        name: "axes",
        shape: KeyShape::Vectors,
        description: "The two fork axes of a universal joint: [a1 in the first body's frame, a2 in the second's].",
    }];
    const AXIS_REFUSAL: &'static str =
        "a universal joint has two fork axes: use \"axes\": [a1, a2]";

    fn parse(p: &mut Problems, f: &Fields<'_>, _axis: Option<Vec<f64>>) -> Option<Self> {
        let j = f.required(p, "axes")?;
        let path = f.path("axes");
        match j {
            Json::Array(items) if items.len() == 2 => {
                let a1 = vector(p, &index(&path, 0), &items[0]);
                let a2 = vector(p, &index(&path, 1), &items[1]);
                Some(Universal { axes: [a1?, a2?] })
            }
            _ => {
                p.push(
                    path,
                    "expected [a1, a2]: the fork axis in each body's frame",
                );
                None
            }
        }
    }
}
