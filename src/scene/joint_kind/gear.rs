//! `"gear"` (planar): an external mesh between two gears on axles fixed to the ground, no
//! `points` (docs/scene-format.md §5).

use super::own_fields::{refuse_ground, refuse_space, KeyShape, OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// An external mesh, `θ_b − θ_b(0) = −r (θ_a − θ_a(0))`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gear {
    /// The ratio `r` (non-zero, finite): body b turns `−r` times body a's rotation.
    pub ratio: f64,
}

impl OwnFields for Gear {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, bodies: &[String; 2]) {
        if refuse_space(
            p,
            dim,
            path,
            "a gear joint is planar (dimension 2): it meshes two rotations about Z",
        ) {
            return;
        }
        if !self.ratio.is_finite() || self.ratio == 0.0 {
            p.push(field(path, "ratio"), "must be a finite, non-zero number");
        }
        refuse_ground(
            p,
            path,
            bodies,
            &[0, 1],
            "a gear meshes two moving gears (on axles fixed to the ground by their own revolute joints); the ground cannot be one of them",
        );
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        e.push(("ratio", Json::Number(self.ratio)));
    }
}

impl ReadOwnFields for Gear {
    const TYPE: &'static str = "gear";
    const KEYS: &'static [OwnKey] = &[OwnKey {
        name: "ratio",
        shape: KeyShape::Number,
        description: "Gear ratio r (gear): θ_b − θ_b(0) = −r (θ_a − θ_a(0)).",
    }];
    const HAS_POINTS: bool = false;

    fn parse(p: &mut Problems, f: &Fields<'_>, _axis: Option<Vec<f64>>) -> Option<Self> {
        f.required_number(p, "ratio").map(|ratio| Gear { ratio })
    }
}
