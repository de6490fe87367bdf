//! `"distance"` (planar and spatial): a massless rigid link between `"points": [pa, pb]`,
//! `"length": L` optional (default: the points' initial distance; docs/scene-format.md §5).

use super::own_fields::{KeyShape, OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// A massless rigid link: `|P_b − P_a| = L`.
#[derive(Debug, Clone, PartialEq)]
pub struct Distance {
    /// The link's length `L` (finite, > 0); `None`: the points' distance at the start.
    pub length: Option<f64>,
}

impl OwnFields for Distance {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, p: &mut Problems, _dim: Dimension, path: &str, _bodies: &[String; 2]) {
        if let Some(l) = self.length {
            if !l.is_finite() || l <= 0.0 {
                p.push(field(path, "length"), "must be a finite link length > 0");
            }
        }
    }

    fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        if let Some(l) = self.length {
            e.push(("length", Json::Number(l)));
        }
    }
}

impl ReadOwnFields for Distance {
    const TYPE: &'static str = "distance";
    const KEYS: &'static [OwnKey] = &[OwnKey {
        name: "length",
        shape: KeyShape::Number,
        description: "Link length L (distance), > 0; default: the points' initial distance.",
    }];

    fn parse(p: &mut Problems, f: &Fields<'_>, _axis: Option<Vec<f64>>) -> Option<Self> {
        match f.get("length") {
            None => Some(Distance { length: None }),
            Some(_) => f.number(p, "length").map(|l| Distance { length: Some(l) }),
        }
    }
}
