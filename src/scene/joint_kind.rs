//! The joint kinds a scene can name: the one list of kinds on the scene side, and the one
//! dispatch from a joint object's `"type"` to its kind.
//!
//! Each kind's scene side — its own fields beyond the generic `name`, `bodies` and `points`,
//! how they are read, checked (with their JSON paths) and written back, and their schema
//! entries — is one file under `scene/joint_kind/` implementing `OwnFields` and
//! `ReadOwnFields` (`own_fields.rs`) (`docs/scene-format.md` §5). What a kind *does* — its
//! bond-graph fragment, its closure rows `g_k(q)`, what it locks, its twin's springs, its
//! reaction and its glyph — lives in one file per kind under `crate::mech::joints`, which
//! dispatches on [`JointKind`] once. A new kind adds its file here and its line in
//! `joint_kinds!`'s list below, and its file and dispatch line there.

mod distance;
mod gear;
pub(crate) mod own_fields;
mod prismatic;
mod rack_pinion;
mod revolute;
mod slot;
mod spherical;
mod universal;
mod weld;

pub use distance::Distance;
pub use gear::Gear;
pub use prismatic::Prismatic;
pub use rack_pinion::RackPinion;
pub use revolute::Revolute;
pub use slot::Slot;
pub use spherical::Spherical;
pub use universal::Universal;
pub use weld::Weld;

use std::sync::LazyLock;

use own_fields::{KeyShape, OwnFields, OwnKey, ReadOwnFields, AXIS_REFUSAL};

use super::error::Problems;
use super::fields::Fields;
use super::space::Dimension;
use super::tree::Json;

/// Declares [`JointKind`] (one variant per kind, carrying the kind's own fields), the one
/// match from a kind to its own fields, the conversions from each kind's type, and the table
/// of kinds the reader dispatches on — all from one list.
macro_rules! joint_kinds {
    ($($(#[$doc:meta])* $variant:ident($kind:ty),)*) => {
        /// The kind of a joint, with its own fields.
        #[derive(Debug, Clone, PartialEq)]
        pub enum JointKind {
            $($(#[$doc])* $variant($kind),)*
        }

        impl JointKind {
            /// The kind's own fields: the one match on the scene side.
            fn own(&self) -> &dyn OwnFields {
                match self {
                    $(JointKind::$variant(k) => k,)*
                }
            }
        }

        $(impl From<$kind> for JointKind {
            fn from(k: $kind) -> Self {
                JointKind::$variant(k)
            }
        })*

        /// Every kind's `"type"` spelling, in the order the documentation lists them.
        pub const JOINT_TYPES: &[&str] = &[$(<$kind as ReadOwnFields>::TYPE,)*];

        /// How each kind is read, in the order of [`JOINT_TYPES`].
        const KINDS: &[KindReader] = &[$(KindReader::of::<$kind>(),)*];
    };
}

joint_kinds! {
    /// `"revolute"`: a planar pin, or a spatial hinge about its `axis`.
    Revolute(Revolute),
    /// `"prismatic"`: a slider along `axis`.
    Prismatic(Prismatic),
    /// `"spherical"`: a 3D ball joint.
    Spherical(Spherical),
    /// `"weld"`: the two bodies are fixed together.
    Weld(Weld),
    /// `"gear"` (planar): an external mesh of ratio `r`; no `points`.
    Gear(Gear),
    /// `"slot"` (planar): a pin in a slot along `axis`.
    Slot(Slot),
    /// `"rack_pinion"` (planar): a rack and pinion of pitch radius `radius`.
    RackPinion(RackPinion),
    /// `"universal"` (spatial): a Hooke's joint with fork axes `axes`.
    Universal(Universal),
    /// `"distance"`: a massless rigid link of `length` between the two points.
    Distance(Distance),
}

/// How one kind is read: its spelling, its own keys, whether it has points, its refusal of an
/// `axis` it does not take, and its reader.
struct KindReader {
    type_name: &'static str,
    keys: &'static [OwnKey],
    has_points: bool,
    axis_refusal: &'static str,
    parse: fn(&mut Problems, &Fields<'_>, Option<Vec<f64>>) -> Option<JointKind>,
}

impl KindReader {
    const fn of<K: ReadOwnFields + Into<JointKind>>() -> Self {
        KindReader {
            type_name: K::TYPE,
            keys: K::KEYS,
            has_points: K::HAS_POINTS,
            axis_refusal: K::AXIS_REFUSAL,
            parse: read_as::<K>,
        }
    }

    fn owns(&self, key: &str) -> bool {
        self.keys.iter().any(|k| k.name == key)
    }
}

fn read_as<K: ReadOwnFields + Into<JointKind>>(
    p: &mut Problems,
    f: &Fields<'_>,
    axis: Option<Vec<f64>>,
) -> Option<JointKind> {
    K::parse(p, f, axis).map(Into::into)
}

fn reader(type_name: &str) -> Option<&'static KindReader> {
    KINDS.iter().find(|k| k.type_name == type_name)
}

/// The kinds' own keys, each once, in the order the kinds list them first.
fn own_keys() -> Vec<&'static str> {
    let mut keys: Vec<&'static str> = Vec::new();
    for k in KINDS.iter().flat_map(|k| k.keys) {
        if !keys.contains(&k.name) {
            keys.push(k.name);
        }
    }
    keys
}

/// The keys a joint object may carry (the generic ones and every kind's own).
pub(crate) static JOINT_KEYS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    let mut keys = vec!["name", "type", "bodies", "points"];
    keys.extend(own_keys());
    keys
});

/// The JSON schema of each kind-specific key (`(key, description, shape)`; the description
/// joins each owner's), for [`super::schema::scene_schema`].
pub(crate) fn kind_key_schemas() -> Vec<(&'static str, String, KeyShape)> {
    own_keys()
        .into_iter()
        .map(|key| {
            let owned: Vec<&OwnKey> = KINDS
                .iter()
                .flat_map(|k| k.keys)
                .filter(|k| k.name == key)
                .collect();
            let description: Vec<&str> = owned.iter().map(|k| k.description).collect();
            (key, description.join(" "), owned[0].shape)
        })
        .collect()
}

impl JointKind {
    /// The kind's `"type"` in a scene.
    pub fn type_name(&self) -> &'static str {
        self.own().type_name()
    }

    /// The kind's own fields, as written after `"points"`.
    pub(super) fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        self.own().write(e)
    }

    /// Checks what the kind's own fields mean in a scene of dimension `dim` (the generic
    /// `bodies` and `points` are checked by the caller); `path` is the joint's.
    pub(super) fn validate(
        &self,
        p: &mut Problems,
        dim: Dimension,
        path: &str,
        bodies: &[String; 2],
    ) {
        self.own().validate(p, dim, path, bodies)
    }
}

/// Whether the kind attaches at two points (`"points"` required); a kind without points
/// gets both bodies' centres.
pub fn has_points(type_name: &str) -> bool {
    reader(type_name).is_none_or(|k| k.has_points)
}

/// Reads the kind `type_name` and its own fields from a joint object (`f`), reporting
/// shape problems at their paths; `None` when it cannot be read.
pub(super) fn parse(p: &mut Problems, f: &Fields<'_>, type_name: &str) -> Option<JointKind> {
    let kind = reader(type_name);
    for key in own_keys().into_iter().filter(|&k| k != "axis") {
        if f.get(key).is_some() && !kind.is_some_and(|k| k.owns(key)) {
            let owners: Vec<&str> = KINDS
                .iter()
                .filter(|k| k.owns(key))
                .map(|k| k.type_name)
                .collect();
            p.push(
                f.path(key),
                format!("only a {} joint has a {key}", owners.join(" or ")),
            );
        }
    }
    let axis = f.vector(p, "axis");
    if f.get("axis").is_some() && !kind.is_some_and(|k| k.owns("axis")) {
        p.push(
            f.path("axis"),
            kind.map_or(AXIS_REFUSAL, |k| k.axis_refusal),
        );
    }
    match kind {
        Some(k) => (k.parse)(p, f, axis),
        None => {
            p.push(
                f.path("type"),
                format!(
                    "unknown joint type \"{type_name}\" (expected {})",
                    JOINT_TYPES.join(", ")
                ),
            );
            None
        }
    }
}
