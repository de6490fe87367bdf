//! `"spherical"`: a ball joint in a spatial scene, the two points coincide
//! (docs/scene-format.md §5).

use super::own_fields::{OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A 3D ball joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Spherical;

impl OwnFields for Spherical {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, _bodies: &[String; 2]) {
        if dim == Dimension::Planar {
            p.push(
                field(path, "type"),
                "a spherical joint needs a spatial scene (dimension 3); use revolute in the plane",
            );
        }
    }

    fn write(&self, _e: &mut Vec<(&'static str, Json)>) {}
}

impl ReadOwnFields for Spherical {
    const TYPE: &'static str = "spherical";
    const KEYS: &'static [OwnKey] = &[];

    fn parse(_p: &mut Problems, _f: &Fields<'_>, _axis: Option<Vec<f64>>) -> Option<Self> {
        Some(Spherical)
    }
}
