//! What every joint kind's scene side is written with: the [`OwnFields`] a kind carries beyond
//! the generic `name`, `type`, `bodies` and `points` (their checks and their writing back), how
//! a kind is read ([`ReadOwnFields`]: its `"type"`, its keys with their schema, whether it has
//! points), and the checks several kinds share.
//!
//! This module sits below the kinds' files and below the dispatch ([`super::JointKind`]); it
//! knows no kind.

use crate::scene::error::{field, Problems};
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// The refusal of an `axis` on a kind that takes none (unless the kind says otherwise).
pub(crate) const AXIS_REFUSAL: &str =
    "only a prismatic, slot or rack_pinion joint or a spatial revolute (hinge) has an axis";

/// The JSON shape of a kind's own key, for the scene's schema.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum KeyShape {
    /// A number.
    Number,
    /// An array of numbers.
    Vector,
    /// Two arrays of numbers.
    Vectors,
}

/// One of a kind's own keys: its name, its JSON shape and what it means for the kind (the
/// schema's description).
#[derive(Clone, Copy, Debug)]
pub(crate) struct OwnKey {
    pub(crate) name: &'static str,
    pub(crate) shape: KeyShape,
    pub(crate) description: &'static str,
}

/// A kind's own fields once read: their meaning in a scene, and their writing back.
pub(crate) trait OwnFields {
    /// The kind's `"type"` in a scene.
    fn type_name(&self) -> &'static str;

    /// Checks what the kind's own fields mean in a scene of dimension `dim` (the generic
    /// `bodies` and `points` are checked by the caller); `path` is the joint's.
    fn validate(&self, p: &mut Problems, dim: Dimension, path: &str, bodies: &[String; 2]);

    /// The kind's own fields, as written after `"points"`.
    fn write(&self, e: &mut Vec<(&'static str, Json)>);
}

/// How a kind is read from a joint object.
pub(crate) trait ReadOwnFields: OwnFields + Sized {
    /// The kind's `"type"`.
    const TYPE: &'static str;
    /// The kind's own keys, in the order they are written.
    const KEYS: &'static [OwnKey];
    /// Whether the kind attaches at two points (`"points"` required); a kind without points
    /// acts at both bodies' centres.
    const HAS_POINTS: bool = true;
    /// The refusal of an `axis` when the kind has none among its [`Self::KEYS`].
    const AXIS_REFUSAL: &'static str = AXIS_REFUSAL;

    /// Reads the kind's own fields from `f`, reporting shape problems at their paths; `axis`
    /// is the object's `"axis"` already read as a vector (`None` when absent or malformed).
    fn parse(p: &mut Problems, f: &Fields<'_>, axis: Option<Vec<f64>>) -> Option<Self>;
}

/// Checks a direction field: `n` components, not all zero.
pub(crate) fn direction(p: &mut Problems, path: &str, v: &[f64], n: usize) {
    if v.len() != n {
        p.push(path, format!("expected {n} components, got {}", v.len()));
    }
    let norm2: f64 = v.iter().map(|x| x * x).sum();
    if norm2.is_finite() && norm2 == 0.0 {
        p.push(path, "must be a non-zero direction");
    }
}

/// Refuses a planar-only kind in space (at the joint's `type`, with `message`); whether it did.
pub(crate) fn refuse_space(p: &mut Problems, dim: Dimension, path: &str, message: &str) -> bool {
    if dim == Dimension::Spatial {
        p.push(field(path, "type"), message);
        return true;
    }
    false
}

/// Refuses the ground as body `k` of the joint at `path` with `message`.
pub(crate) fn refuse_ground(
    p: &mut Problems,
    path: &str,
    bodies: &[String; 2],
    ends: &[usize],
    message: &str,
) {
    for &k in ends {
        if bodies[k] == crate::scene::space::GROUND {
            p.push(
                crate::scene::error::index(&field(path, "bodies"), k),
                message,
            );
        }
    }
}

/// A vector as JSON.
pub(crate) fn nums(v: &[f64]) -> Json {
    Json::Array(v.iter().copied().map(Json::Number).collect())
}
