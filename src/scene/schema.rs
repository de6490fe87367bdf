//! The JSON Schema of the scene format (docs/scene-format.md), generated with `schemars` from
//! the wire types below: the service's OpenAPI document carries it, so a client can validate a
//! scene before sending it. The parser ([`super::parse`]) stays the authority; a test checks
//! that every object here has exactly the keys the parser accepts.

use schemars::JsonSchema;

use super::joint_kind::own_fields::KeyShape;
use super::joint_kind::{kind_key_schemas, JOINT_TYPES};

/// A number, or an `[x, y]` / `[x, y, z]` vector.
#[derive(JsonSchema)]
#[schemars(untagged)]
#[allow(dead_code)]
enum NumberOrVector {
    Number(f64),
    Vector(Vec<f64>),
}

/// A point: a name of the body's points, or coordinates (body frame; global for ground).
#[derive(JsonSchema)]
#[schemars(untagged)]
#[allow(dead_code)]
enum PointRef {
    Named(String),
    Coords(Vec<f64>),
}

/// A load value: a constant (number or vector), a table, or an expression in `t` and the
/// scene's outputs (per component).
#[derive(JsonSchema)]
#[schemars(untagged)]
#[allow(dead_code)]
enum LoadValue {
    Number(f64),
    Vector(Vec<NumberOrExpr>),
    Table { table: Table },
    Expr(String),
}

/// A number or an expression.
#[derive(JsonSchema)]
#[schemars(untagged)]
#[allow(dead_code)]
enum NumberOrExpr {
    Number(f64),
    Expr(String),
}

/// A piecewise linear function of time.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Table {
    t: Vec<f64>,
    v: Vec<serde_json::Value>,
}

/// A rigid body.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Body {
    /// Unique name; not "ground", no `.`.
    name: String,
    /// Mass (kg, > 0).
    mass: f64,
    /// Planar: the inertia about the centre of mass (0: a point mass); spatial: principal
    /// moments `[Jx, Jy, Jz]`.
    inertia: NumberOrVector,
    /// Planar formulation frame: "inertial" (default) or "body".
    frame: Option<Frame>,
    /// Named points in body coordinates relative to the centre of mass.
    points: Option<std::collections::BTreeMap<String, Vec<f64>>>,
    /// Initial position of the centre of mass (global).
    position: Vec<f64>,
    /// Initial angle (planar, rad).
    angle: Option<f64>,
    /// Initial Cardan angles `[psi, theta, phi]` (spatial, rad).
    cardan: Option<[f64; 3]>,
    /// Initial velocity of the centre of mass (global).
    velocity: Option<Vec<f64>>,
    /// Initial angular velocity: planar a number, spatial `[wx, wy, wz]` (body frame).
    angular_velocity: Option<NumberOrVector>,
}

/// Formulation frame of a planar body.
#[derive(JsonSchema)]
#[schemars(rename_all = "snake_case")]
#[allow(dead_code)]
enum Frame {
    Inertial,
    Body,
}

/// Joint type.
#[derive(JsonSchema)]
#[schemars(rename_all = "snake_case")]
#[allow(dead_code)]
enum JointType {
    // the spellings are `crate::scene::JOINT_TYPES`, put in by `scene_schema`
    Revolute,
}

/// A joint between two bodies (either may be "ground").
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Joint {
    /// Unique name (default "joint<i>").
    name: Option<String>,
    /// revolute (planar pin, or a spatial hinge with `axis`), prismatic (needs `axis`),
    /// spherical, weld.
    #[schemars(rename = "type")]
    kind: JointType,
    /// The two bodies.
    bodies: [String; 2],
    /// The joint point on each body (required by every kind that attaches at points).
    points: Option<[PointRef; 2]>,
    // each kind's own keys are added by `scene_schema` from `crate::scene::joint_kind`
}

/// A point-to-point spring-damper.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Spring {
    name: Option<String>,
    bodies: [String; 2],
    points: [PointRef; 2],
    /// Stiffness (N/m).
    stiffness: f64,
    /// Rest length (m).
    rest_length: f64,
    /// Damping (N·s/m).
    damping: Option<f64>,
}

/// Load type.
#[derive(JsonSchema)]
#[schemars(rename_all = "snake_case")]
#[allow(dead_code)]
enum LoadType {
    Force,
    Torque,
}

/// A force (global frame) at a body point, or a torque on a body.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Load {
    name: Option<String>,
    #[schemars(rename = "type")]
    kind: LoadType,
    body: String,
    /// The point a force acts at (default: the centre of mass).
    point: Option<PointRef>,
    value: LoadValue,
}

/// Event direction.
#[derive(JsonSchema)]
#[schemars(rename_all = "snake_case")]
#[allow(dead_code)]
enum Direction {
    Rising,
    Falling,
    Both,
}

/// Event action.
#[derive(JsonSchema)]
#[schemars(rename_all = "snake_case")]
#[allow(dead_code)]
enum Action {
    Stop,
    Record,
}

/// A zero crossing of an expression: recorded, or stopping the run.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Event {
    name: Option<String>,
    /// An expression in `t` and the scene's outputs.
    when: String,
    direction: Option<Direction>,
    action: Option<Action>,
}

/// An input of the scene (an FMU input): a name load expressions may use, held at `start` by
/// the CLI.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Input {
    name: String,
    start: Option<f64>,
    unit: Option<String>,
}

/// A driver: prescribed motion of a revolute or prismatic joint (give exactly one of
/// `angle`, `angular_velocity`, `displacement`, `velocity`: a number or an expression of t).
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Driver {
    name: Option<String>,
    /// The driven joint's name.
    joint: String,
    /// Revolute: the relative angle (rad), a number or an expression of t.
    angle: Option<serde_json::Value>,
    /// Revolute: the relative angular velocity (rad/s), a constant.
    angular_velocity: Option<serde_json::Value>,
    /// Prismatic: the displacement along the axis (m), a number or an expression of t.
    displacement: Option<serde_json::Value>,
    /// Prismatic: the sliding velocity (m/s), a constant.
    velocity: Option<serde_json::Value>,
}

/// How to solve.
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields)]
#[allow(dead_code)]
struct Solve {
    formulation: Option<crate::settings::FormulationKind>,
    t_start: Option<f64>,
    /// End time (s).
    t_end: Option<f64>,
    output_step: Option<f64>,
    /// Times of the rows (strictly increasing), instead of `output_step`.
    output_times: Option<Vec<f64>>,
    rtol: Option<f64>,
    atol: Option<f64>,
    /// The decoupled twin's joint stiffness (N/m).
    joint_stiffness: Option<f64>,
    joint_damping: Option<f64>,
    max_steps: Option<u64>,
    max_wall_seconds: Option<f64>,
    /// auto, dense, sparse (faer) or klu.
    linear_solver: Option<String>,
    /// The decoupled twin's integrator.
    integrator: Option<String>,
    switching_functions: Option<bool>,
    /// auto (kept once the energy drifts), always or never: the default DAE's energy invariant.
    energy_invariant: Option<String>,
    /// "given" (the default: the bodies' configuration) or "equilibrium" (the static
    /// equilibrium nearest it, at rest).
    start: Option<String>,
}

/// A mechanism (bodies, joints, …) or a raw bond graph (`bond_graph`).
#[derive(JsonSchema)]
#[schemars(deny_unknown_fields, title = "bondmech scene")]
#[allow(dead_code)]
struct Scene {
    name: Option<String>,
    description: Option<String>,
    /// 2 (planar) or 3 (spatial).
    dimension: Option<u8>,
    /// Gravity (m/s²), `[gx, gy]` or `[gx, gy, gz]`.
    gravity: Option<Vec<f64>>,
    bodies: Option<Vec<Body>>,
    joints: Option<Vec<Joint>>,
    springs: Option<Vec<Spring>>,
    loads: Option<Vec<Load>>,
    solve: Option<Solve>,
    /// Extra columns: "body.point", "energy", "constraint_error", "reactions", expressions.
    outputs: Option<Vec<String>>,
    events: Option<Vec<Event>>,
    /// Inputs (`docs/fmu.md`): names usable in load expressions.
    inputs: Option<Vec<Input>>,
    /// Prescribed joint motion (docs/scene-format.md, drivers).
    drivers: Option<Vec<Driver>>,
    /// A raw bond graph: `{"elements": [...], "bonds": [...]}` (docs/scene-format.md).
    bond_graph: Option<serde_json::Map<String, serde_json::Value>>,
}

/// The JSON Schema (draft 2020-12) of a scene.
pub fn scene_schema() -> serde_json::Value {
    let mut s = serde_json::to_value(schemars::schema_for!(Scene)).expect("the schema serialises");
    // the joint kinds and their own keys, from the one list of kinds
    let types: Vec<serde_json::Value> = JOINT_TYPES.iter().map(|&t| t.into()).collect();
    s["$defs"]["JointType"] =
        serde_json::json!({ "description": "Joint type.", "type": "string", "enum": types });
    let props = &mut s["$defs"]["Joint"]["properties"];
    for (key, description, shape) in kind_key_schemas() {
        let schema = match shape {
            KeyShape::Vector => {
                serde_json::json!({ "type": "array", "items": { "type": "number" } })
            }
            KeyShape::Vectors => {
                serde_json::json!({ "type": "array", "items": { "type": "array", "items": { "type": "number" } }, "minItems": 2, "maxItems": 2 })
            }
            KeyShape::Number => serde_json::json!({ "type": "number" }),
        };
        props[key] = schema;
        props[key]["description"] = description.into();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse::{
        BODY_KEYS, EVENT_KEYS, INPUT_KEYS, JOINT_KEYS, LOAD_KEYS, SCENE_KEYS, SOLVE_KEYS,
        SPRING_KEYS,
    };

    fn keys(schema: &serde_json::Value, def: Option<&str>) -> Vec<String> {
        let obj = match def {
            None => schema,
            Some(d) => &schema["$defs"][d],
        };
        let mut k: Vec<String> = obj["properties"]
            .as_object()
            .unwrap_or_else(|| panic!("{def:?} has properties"))
            .keys()
            .cloned()
            .collect();
        k.sort();
        k
    }

    #[test]
    fn the_schema_has_exactly_the_keys_the_parser_accepts() {
        let s = scene_schema();
        for (def, accepted) in [
            (None, SCENE_KEYS),
            (Some("Body"), BODY_KEYS),
            (Some("Joint"), JOINT_KEYS.as_slice()),
            (Some("Spring"), SPRING_KEYS),
            (Some("Load"), LOAD_KEYS),
            (Some("Event"), EVENT_KEYS),
            (Some("Input"), INPUT_KEYS),
            (Some("Driver"), crate::scene::drivers::DRIVER_KEYS),
            (Some("Solve"), SOLVE_KEYS),
        ] {
            let mut want: Vec<String> = accepted.iter().map(|k| k.to_string()).collect();
            want.sort();
            assert_eq!(keys(&s, def), want, "{def:?}");
        }
        assert_eq!(s["additionalProperties"], false);
        assert_eq!(s["$defs"]["Body"]["additionalProperties"], false);
        let required: Vec<&str> = s["$defs"]["Body"]["required"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        for k in ["name", "mass", "inertia", "position"] {
            assert!(required.contains(&k), "{required:?}");
        }
    }
}
