//! The joint kinds a scene can name, as data: each kind's `"type"`, the fields it carries
//! beyond the generic `name`, `bodies` and `points`, and the checks and writing of those fields.
//!
//! This is the scene side of a joint kind (`docs/scene-format.md` §5). What a kind *does* —
//! its bond-graph fragment, its closure rows `g_k(q)`, what it locks, its twin's springs, its
//! reaction and its glyph — lives in one file per kind under `crate::mech::joints`, which
//! dispatches on [`JointKind`] once. A new kind adds its variant and its arms here (one file)
//! and its dispatch line and file there.

use super::error::{field, Problems};
use super::model::Dimension;
use super::parse::Fields;
use super::tree::Json;

/// The keys a joint object may carry (the generic ones and every kind's own).
pub(crate) const JOINT_KEYS: &[&str] = &[
    "name", "type", "bodies", "points", "axis", "ratio", "radius", "axes",
];

/// Every kind's `"type"` spelling, in the order the documentation lists them.
pub const JOINT_TYPES: &[&str] = &[
    "revolute",
    "prismatic",
    "spherical",
    "weld",
    "gear",
    "slot",
    "rack_pinion",
];

/// The JSON schema of each kind-specific key (`(key, description, schema type)`), for
/// [`super::schema::scene_schema`].
pub(crate) const KIND_KEY_SCHEMAS: &[(&str, &str, &str)] = &[
    (
        "axis",
        "Sliding direction (prismatic) or hinge axis (spatial revolute), first body's frame.",
        "vector",
    ),
    (
        "ratio",
        "Gear ratio r (gear): θ_b − θ_b(0) = −r (θ_a − θ_a(0)).",
        "number",
    ),
    (
        "radius",
        "Pitch radius of the pinion (rack_pinion), > 0.",
        "number",
    ),
    (
        "axes",
        "The two fork axes of a universal joint: [a1 in the first body's frame, a2 in the second's].",
        "vectors",
    ),
];

/// The kinds that may carry each kind-specific key other than `axis` (whose refusal has its
/// own message); a key given to another kind is refused.
const KEY_OWNERS: &[(&str, &[&str])] = &[
    ("ratio", &["gear"]),
    ("radius", &["rack_pinion"]),
    ("axes", &["universal"]),
];

/// The kind of a joint.
#[derive(Debug, Clone, PartialEq)]
pub enum JointKind {
    /// `"revolute"` without `axis`: planar pin (the two points coincide).
    Revolute,
    /// `"prismatic"`: slider along `axis` (frame of the first body); relative rotation fixed
    /// (planar: one normal row and the relative angle; spatial: two normal rows and three
    /// rotation rows, the latter left out when the second body is a point mass).
    Prismatic {
        /// Sliding direction in the frame of the first body (non-zero; not normalised).
        axis: Vec<f64>,
    },
    /// `"revolute"` with an `axis` in a spatial scene: a hinge. Five rows: the two points
    /// coincide (3) and the hinge axis `a = R_1 axis` stays perpendicular to two body-2 vectors
    /// `R_2 c_1`, `R_2 c_2` (2), where `c_1, c_2` span the plane perpendicular to the axis as seen
    /// in body 2 at the initial configuration (`R_2(0)ᵀ R_1(0) axis`).
    Hinge {
        /// Hinge axis in the frame of the first body (global for ground; non-zero).
        axis: Vec<f64>,
    },
    /// `"spherical"`: 3D ball joint.
    Spherical,
    /// `"weld"`: the two bodies are fixed together.
    Weld,
    /// `"slot"` (planar pin-in-slot): the second body's point stays on the line through the
    /// first body's point along `axis` (fixed in the first body); sliding and rotation free.
    Slot {
        /// The slot's direction in the first body's frame (global for ground; non-zero).
        axis: Vec<f64>,
    },
    /// `"rack_pinion"` (planar): `bodies: [pinion, rack]`, `points: [C, P]` (the pinion's
    /// centre, a point of the rack): `(P − C)·(R_rack û) − s(0) = ρ ((θ_p − θ_r) − (θ_p(0) − θ_r(0)))`.
    RackPinion {
        /// The pinion's pitch radius ρ (> 0).
        radius: f64,
        /// The rack's direction in the rack's frame (non-zero); the pinion lies on its left.
        axis: Vec<f64>,
    },
    /// `"universal"` (spatial Hooke's joint): the points coincide and the fork axes stay
    /// perpendicular, `(R_a a1)·(R_b a2) = 0` (four rows).
    Universal {
        /// `[a1, a2]`: a1 in the first body's frame, a2 in the second's (non-zero, 3D).
        axes: [Vec<f64>; 2],
    },
    /// `"gear"` (planar): an external mesh between two gears on axles fixed to the ground,
    /// `θ_b − θ_b(0) = −r (θ_a − θ_a(0))`; no `points`.
    Gear {
        /// The ratio `r` (non-zero, finite): body b turns `−r` times body a's rotation.
        ratio: f64,
    },
}

impl JointKind {
    /// The kind's `"type"` in a scene.
    pub fn type_name(&self) -> &'static str {
        match self {
            JointKind::Revolute | JointKind::Hinge { .. } => "revolute",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Spherical => "spherical",
            JointKind::Weld => "weld",
            JointKind::Gear { .. } => "gear",
            JointKind::Slot { .. } => "slot",
            JointKind::RackPinion { .. } => "rack_pinion",
            JointKind::Universal { .. } => "universal",
        }
    }

    /// The kind's own fields, as written after `"points"`.
    pub(super) fn write(&self, e: &mut Vec<(&'static str, Json)>) {
        if let JointKind::Prismatic { axis }
        | JointKind::Hinge { axis }
        | JointKind::Slot { axis } = self
        {
            e.push(("axis", nums(axis)));
        }
        if let JointKind::RackPinion { radius, axis } = self {
            e.push(("radius", Json::Number(*radius)));
            e.push(("axis", nums(axis)));
        }
        if let JointKind::Universal { axes } = self {
            e.push(("axes", Json::Array(axes.iter().map(|a| nums(a)).collect())));
        }
        if let JointKind::Gear { ratio } = self {
            e.push(("ratio", Json::Number(*ratio)));
        }
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
        let tp = field(path, "type");
        match (self, dim) {
            (JointKind::Spherical, Dimension::Planar) => p.push(
                tp,
                "a spherical joint needs a spatial scene (dimension 3); use revolute in the plane",
            ),
            (JointKind::Revolute, Dimension::Spatial) => p.push(
                field(path, "axis"),
                "a revolute joint in a spatial scene is a hinge and needs an axis (the hinge axis in the frame of the first body, global for ground; body 2 keeps the relative orientation of the initial configuration about it); use spherical for a ball joint",
            ),
            (JointKind::Hinge { .. }, Dimension::Planar) => p.push(
                field(path, "axis"),
                "only a prismatic joint has an axis in a planar scene (a planar revolute pins about z)",
            ),
            (JointKind::Prismatic { axis } | JointKind::Hinge { axis }, dim) => {
                direction(p, &field(path, "axis"), axis, dim.coords());
            }
            (JointKind::Slot { .. }, Dimension::Spatial) => p.push(
                tp,
                "a slot joint is planar (dimension 2); in space use a prismatic joint with a point mass",
            ),
            (JointKind::Slot { axis }, Dimension::Planar) => {
                direction(p, &field(path, "axis"), axis, 2);
            }
            (JointKind::RackPinion { .. }, Dimension::Spatial) => p.push(
                tp,
                "a rack_pinion joint is planar (dimension 2)",
            ),
            (JointKind::RackPinion { radius, axis }, Dimension::Planar) => {
                direction(p, &field(path, "axis"), axis, 2);
                if !radius.is_finite() || *radius <= 0.0 {
                    p.push(field(path, "radius"), "must be a finite pitch radius > 0");
                }
                if bodies[0] == super::model::GROUND {
                    p.push(
                        super::error::index(&field(path, "bodies"), 0),
                        "the pinion (first body) cannot be the ground: a fixed pinion locks the rack; the rack (second body) may be",
                    );
                }
            }
            (JointKind::Universal { .. }, Dimension::Planar) => p.push(
                tp,
                "a universal (Hooke's) joint needs a spatial scene (dimension 3)",
            ),
            (JointKind::Universal { axes }, Dimension::Spatial) => {
                for (k, a) in axes.iter().enumerate() {
                    direction(p, &super::error::index(&field(path, "axes"), k), a, 3);
                }
                for (k, b) in bodies.iter().enumerate() {
                    if b == super::model::GROUND {
                        p.push(
                            super::error::index(&field(path, "bodies"), k),
                            "a universal joint connects two moving shafts; hinge a shaft to the ground with a revolute joint instead",
                        );
                    }
                }
            }
            (JointKind::Gear { .. }, Dimension::Spatial) => p.push(
                tp,
                "a gear joint is planar (dimension 2): it meshes two rotations about Z",
            ),
            (JointKind::Gear { ratio }, Dimension::Planar) => {
                if !ratio.is_finite() || *ratio == 0.0 {
                    p.push(field(path, "ratio"), "must be a finite, non-zero number");
                }
                for (k, b) in bodies.iter().enumerate() {
                    if b == super::model::GROUND {
                        p.push(
                            super::error::index(&field(path, "bodies"), k),
                            "a gear meshes two moving gears (on axles fixed to the ground by their own revolute joints); the ground cannot be one of them",
                        );
                    }
                }
            }
            _ => {}
        }
    }
}

/// Checks a direction field: `n` components, not all zero.
pub(super) fn direction(p: &mut Problems, path: &str, v: &[f64], n: usize) {
    if v.len() != n {
        p.push(path, format!("expected {n} components, got {}", v.len()));
    }
    let norm2: f64 = v.iter().map(|x| x * x).sum();
    if norm2.is_finite() && norm2 == 0.0 {
        p.push(path, "must be a non-zero direction");
    }
}

fn nums(v: &[f64]) -> Json {
    Json::Array(v.iter().copied().map(Json::Number).collect())
}

/// Whether the kind attaches at two points (`"points"` required); a kind without points
/// gets both bodies' centres.
pub fn has_points(type_name: &str) -> bool {
    type_name != "gear"
}

/// Reads the kind `type_name` and its own fields from a joint object (`f`), reporting
/// shape problems at their paths; `None` when it cannot be read.
pub(super) fn parse(
    p: &mut Problems,
    f: &Fields<'_>,
    type_name: &str,
    dim: Dimension,
) -> Option<JointKind> {
    let _ = dim;
    for &(key, owners) in KEY_OWNERS {
        if f.get(key).is_some() && !owners.contains(&type_name) {
            p.push(
                f.path(key),
                format!("only a {} joint has a {key}", owners.join(" or ")),
            );
        }
    }
    let axis = f.vector(p, "axis");
    match type_name {
        "prismatic" => match axis {
            Some(axis) => Some(JointKind::Prismatic { axis }),
            None => {
                if f.get("axis").is_none() {
                    p.push(f.path("axis"), "a prismatic joint needs an axis (the sliding direction in the frame of the first body)");
                }
                None
            }
        },
        "revolute" => match axis {
            Some(axis) => Some(JointKind::Hinge { axis }),
            None if f.get("axis").is_some() => None,
            None => Some(JointKind::Revolute),
        },
        "rack_pinion" => {
            let radius = f.required_number(p, "radius");
            if f.get("axis").is_none() {
                p.push(
                    f.path("axis"),
                    "a rack_pinion joint needs an axis (the rack's direction in the rack's frame)",
                );
            }
            Some(JointKind::RackPinion {
                radius: radius?,
                axis: axis?,
            })
        }
        "universal" => {
            if f.get("axis").is_some() {
                p.push(
                    f.path("axis"),
                    "a universal joint has two fork axes: use \"axes\": [a1, a2]",
                );
            }
            let j = f.required(p, "axes")?;
            let path = f.path("axes");
            match j {
                Json::Array(items) if items.len() == 2 => {
                    let a1 = super::parse::vector(p, &super::error::index(&path, 0), &items[0]);
                    let a2 = super::parse::vector(p, &super::error::index(&path, 1), &items[1]);
                    Some(JointKind::Universal { axes: [a1?, a2?] })
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
        "slot" => match axis {
            Some(axis) => Some(JointKind::Slot { axis }),
            None => {
                if f.get("axis").is_none() {
                    p.push(f.path("axis"), "a slot joint needs an axis (the slot's direction in the frame of the first body)");
                }
                None
            }
        },
        k => {
            if f.get("axis").is_some() {
                p.push(
                    f.path("axis"),
                    "only a prismatic, slot or rack_pinion joint or a spatial revolute (hinge) has an axis",
                );
            }
            match k {
                "spherical" => Some(JointKind::Spherical),
                "gear" => f
                    .required_number(p, "ratio")
                    .map(|ratio| JointKind::Gear { ratio }),
                "weld" => Some(JointKind::Weld),
                other => {
                    p.push(
                        f.path("type"),
                        format!(
                            "unknown joint type \"{other}\" (expected {})",
                            JOINT_TYPES.join(", ")
                        ),
                    );
                    None
                }
            }
        }
    }
}
