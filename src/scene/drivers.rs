//! Drivers (`"drivers"`): prescribed joint motion.
//!
//! ```json
//! "drivers": [
//!   {"name": "motor", "joint": "crank_pivot", "angle": "10*t"},
//!   {"name": "feed",  "joint": "cart_slide",  "velocity": "0.2"}
//! ]
//! ```
//!
//! A driver prescribes the coordinate `s` of one `revolute` joint (planar pin or spatial hinge:
//! the rotation of the second body relative to the first) or `prismatic` joint (the position of
//! the second point along the axis, from the first point): `angle` / `displacement` give
//! `s(t)`, `angular_velocity` / `velocity` give `ṡ(t)` (then `s(t) = s(t_start) + ∫ṡ`). In the
//! bond graph it is a flow source `Sf(t) = ṡ(t)` on the joint's relative-flow junction; its
//! effort is the actuator's torque or force. The mechanism side is
//! [`crate::mech::geometry`]; the scene side (reading and checking) is here.

use super::error::{comma_in_name, field, index, Problems};
use super::fields::{number, Fields};
use super::model::Scene;
use super::tree::Json;
use super::JointKind;

/// What a driver prescribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriverKind {
    /// The angle of a revolute joint (rad), `s(t)`.
    Angle,
    /// The angular velocity of a revolute joint (rad/s), `ṡ(t)`.
    AngularVelocity,
    /// The displacement of a prismatic joint (m), `s(t)`.
    Displacement,
    /// The sliding velocity of a prismatic joint (m/s), `ṡ(t)`.
    Velocity,
}

impl DriverKind {
    /// The JSON key of this kind.
    pub fn key(self) -> &'static str {
        match self {
            DriverKind::Angle => "angle",
            DriverKind::AngularVelocity => "angular_velocity",
            DriverKind::Displacement => "displacement",
            DriverKind::Velocity => "velocity",
        }
    }

    /// Whether the value is a rate (`ṡ`) rather than the coordinate (`s`).
    pub fn is_rate(self) -> bool {
        matches!(self, DriverKind::AngularVelocity | DriverKind::Velocity)
    }

    /// Whether it drives a rotation (a revolute joint) rather than a slide.
    pub fn is_rotation(self) -> bool {
        matches!(self, DriverKind::Angle | DriverKind::AngularVelocity)
    }

    /// The effort column's suffix: `torque` (rotation) or `force` (slide).
    pub fn effort(self) -> &'static str {
        if self.is_rotation() {
            "torque"
        } else {
            "force"
        }
    }
}

/// A driver of the scene (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Driver {
    /// Name (default `driver<i>`): its columns are `<name>.torque|force` and `<name>.power`.
    pub name: String,
    /// The driven joint's name.
    pub joint: String,
    /// What is prescribed.
    pub kind: DriverKind,
    /// The value: an expression of `t` (and the scene's inputs); a number is written as text.
    pub value: String,
}

/// The keys of a driver.
pub(crate) const DRIVER_KEYS: &[&str] = &[
    "name",
    "joint",
    "angle",
    "angular_velocity",
    "displacement",
    "velocity",
];

const KINDS: [DriverKind; 4] = [
    DriverKind::Angle,
    DriverKind::AngularVelocity,
    DriverKind::Displacement,
    DriverKind::Velocity,
];

/// Reads `drivers[i]`.
pub(crate) fn driver(p: &mut Problems, i: usize, j: &Json) -> Option<Driver> {
    let path = index("drivers", i);
    let f = Fields::new(p, &path, j, DRIVER_KEYS)?;
    let name = f.string(p, "name").unwrap_or_else(|| format!("driver{i}"));
    let joint = f.required(p, "joint").and_then(|j| match j {
        Json::String(s) => Some(s.clone()),
        other => {
            p.push(
                f.path("joint"),
                format!("expected a joint's name, got {}", other.kind()),
            );
            None
        }
    });
    let given: Vec<DriverKind> = KINDS
        .into_iter()
        .filter(|k| f.get(k.key()).is_some())
        .collect();
    let kind = match given.as_slice() {
        [k] => Some(*k),
        [] => {
            p.push(
                &path,
                "needs one of \"angle\", \"angular_velocity\" (revolute) or \"displacement\", \"velocity\" (prismatic)",
            );
            None
        }
        [_, second, ..] => {
            p.push(
                f.path(second.key()),
                format!(
                    "a driver prescribes one thing: give only one of {}",
                    given
                        .iter()
                        .map(|k| format!("\"{}\"", k.key()))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
            None
        }
    };
    let value = kind.and_then(|k| {
        let vp = f.path(k.key());
        match f.get(k.key())? {
            Json::String(s) => Some(s.clone()),
            j @ Json::Number(_) => number(p, &vp, j).map(|x| format!("{x}")),
            other => {
                p.push(
                    vp,
                    format!(
                        "expected a number or an expression of t, got {}",
                        other.kind()
                    ),
                );
                None
            }
        }
    });
    Some(Driver {
        name,
        joint: joint?,
        kind: kind?,
        value: value?,
    })
}

/// The checks of `"drivers"`: names unique (and not a joint's), the joint exists and is a
/// revolute or prismatic joint, the value fits the joint, one driver per joint, a non-empty
/// expression; not in a raw bond graph.
pub(crate) fn validate(p: &mut Problems, scene: &Scene) {
    let mut names: Vec<&str> = Vec::new();
    let mut driven: Vec<(&str, usize)> = Vec::new();
    for (i, d) in scene.drivers.iter().enumerate() {
        let path = index("drivers", i);
        if scene.bond_graph.is_some() {
            p.push(
                &path,
                "drivers need bodies and joints (a raw bond graph prescribes a flow with an Sf)",
            );
            continue;
        }
        let np = field(&path, "name");
        if d.name.is_empty() || d.name.contains('`') {
            p.push(&np, "must be a non-empty name without '`'");
        } else if d.name.contains(',') {
            p.push(&np, comma_in_name(&d.name));
        } else if names.contains(&d.name.as_str()) {
            p.push(&np, format!("duplicate driver name '{}'", d.name));
        } else if scene.joints.iter().any(|j| j.name == d.name) {
            p.push(
                &np,
                format!(
                    "'{}' is a joint's name: a driver's columns need a name of their own",
                    d.name
                ),
            );
        }
        names.push(&d.name);
        let jp = field(&path, "joint");
        let vp = field(&path, d.kind.key());
        match scene.joints.iter().find(|j| j.name == d.joint) {
            None => p.push(
                &jp,
                format!(
                    "no joint named '{}'{} (joints: {})",
                    d.joint,
                    super::fields::did_you_mean_note(
                        &d.joint,
                        scene.joints.iter().map(|j| j.name.as_str())
                    ),
                    scene
                        .joints
                        .iter()
                        .map(|j| format!("'{}'", j.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
            Some(j) => {
                match (&j.kind, d.kind.is_rotation()) {
                    (JointKind::Revolute(_), true) | (JointKind::Prismatic(_), false) => {}
                    (JointKind::Revolute(_), false) => p.push(
                        &vp,
                        format!(
                            "joint '{}' is revolute: a revolute joint is driven by angle or angular_velocity",
                            j.name
                        ),
                    ),
                    (JointKind::Prismatic(_), true) => p.push(
                        &vp,
                        format!(
                            "joint '{}' is prismatic: a prismatic joint is driven by displacement or velocity",
                            j.name
                        ),
                    ),
                    (other, _) => p.push(
                        &jp,
                        format!(
                            "joint '{}' is a {} joint, which has no free motion to drive: only revolute and prismatic joints take a driver",
                            j.name,
                            other.type_name()
                        ),
                    ),
                }
                if let Some((_, k)) = driven.iter().find(|(n, _)| *n == d.joint) {
                    p.push(
                        &jp,
                        format!(
                            "joint '{}' is already driven by drivers[{k}] ('{}'): a joint's motion is prescribed once",
                            d.joint, scene.drivers[*k].name
                        ),
                    );
                } else {
                    driven.push((&d.joint, i));
                }
            }
        }
        if d.value.trim().is_empty() {
            p.push(&vp, "expression must not be empty");
        }
    }
}
