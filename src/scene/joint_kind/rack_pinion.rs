//! `"rack_pinion"` (planar): `bodies: [pinion, rack]`, `points: [C, P]` (the pinion's centre,
//! a point of the rack), `radius`, `axis` (the rack's direction in the rack's frame;
//! docs/scene-format.md §5).

use super::own_fields::{
    direction, nums, refuse_ground, refuse_space, KeyShape, OwnFields, OwnKey, ReadOwnFields,
};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A rack and pinion: `(P − C)·(R_rack û) − s(0) = ρ ((θ_p − θ_r) − (θ_p(0) − θ_r(0)))`.
#[derive(Debug, Clone, PartialEq)]
pub struct RackPinion {
    /// The pinion's pitch radius ρ (> 0).
    pub radius: f64,
    /// The rack's direction in the rack's frame (non-zero); the pinion lies on its left.
    pub axis: Vec<f64>,
}

impl OwnFields for RackPinion {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, bodies: &[String; 2]) {
        if refuse_space(p, dim, path, "a rack_pinion joint is planar (dimension 2)") {
            return;
        }
        direction(p, &field(path, "axis"), &self.axis, 2);
        if !self.radius.is_finite() || self.radius <= 0.0 {
            p.push(field(path, "radius"), "must be a finite pitch radius > 0");
        }
        refuse_ground(
            p,
            path,
            bodies,
            &[0],
            "the pinion (first body) cannot be the ground: a fixed pinion locks the rack; the rack (second body) may be",
        );
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        e.push(("radius", Json::Number(self.radius)));
        e.push(("axis", nums(&self.axis)));
    }
}

impl ReadOwnFields for RackPinion {
    const TYPE: &'static str = "rack_pinion";
    const KEYS: &'static [OwnKey] = &[
        OwnKey {
            name: "radius",
            shape: KeyShape::Number,
            description: "Pitch radius of the pinion (rack_pinion), > 0.",
        },
        OwnKey {
            name: "axis",
            shape: KeyShape::Vector,
            description: "The rack's direction (rack_pinion), rack's frame.",
        },
    ];

    fn parse(p: &mut Problems, f: &Fields<'_>, axis: Option<Vec<f64>>) -> Option<Self> {
        let radius = f.required_number(p, "radius");
        if f.get("axis").is_none() {
            p.push(
                f.path("axis"),
                "a rack_pinion joint needs an axis (the rack's direction in the rack's frame)",
            );
        }
        Some(RackPinion {
            radius: radius?,
            axis: axis?,
        })
    }
}
