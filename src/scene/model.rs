//! Scene data: plain `pub` types that the mechanism layer consumes.
//!
//! A `Scene` is what a valid scene file says, with every default filled in:
//! vectors have the scene's dimension (2 or 3 components), omitted initial
//! velocities are zero, omitted solver settings take the defaults listed on
//! [`SolveSettings`]. The fixed body is the reserved name [`GROUND`]; it is
//! never listed in [`Scene::bodies`].

pub use super::drivers::{Driver, DriverKind};
pub use super::joint_kind::JointKind;
pub use super::space::{Dimension, GROUND};
use crate::settings::{FormulationKind, Integrator, LinearSolverKind};

/// Outputs that are not tied to a body (`"energy"`, `"constraint_error"`, ...).
pub const SCALAR_OUTPUTS: &[&str] = &[
    "energy",
    "kinetic_energy",
    "potential_energy",
    "constraint_error",
    "reactions",
];

/// Standard per-body columns a `b.<column>` output or expression may name.
pub const BODY_COLUMNS: &[&str] = &[
    "x", "y", "z", "angle", "vx", "vy", "vz", "omega", "wx", "wy", "wz", "wX", "wY", "wZ", "psi",
    "theta", "phi", "qw", "qx", "qy", "qz",
];

/// A mechanism scene (scene format v1).
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Scene name (default: the file stem, or `"scene"`).
    pub name: String,
    /// Planar (`"dimension": 2`, the default) or spatial (`3`).
    pub dimension: Dimension,
    /// Gravitational acceleration, global frame, one component per dimension (default zero).
    pub gravity: Vec<f64>,
    /// The moving bodies (ground excluded).
    pub bodies: Vec<Body>,
    /// Joints between bodies (or a body and ground).
    pub joints: Vec<Joint>,
    /// Point-to-point spring-dampers.
    pub springs: Vec<Spring>,
    /// Applied forces and torques.
    pub loads: Vec<Load>,
    /// Solver settings.
    pub solve: SolveSettings,
    /// Extra output columns (`"bar2.A"`, `"energy"`, `"constraint_error"`, `"reactions"`).
    pub outputs: Vec<String>,
    /// Events found by root finding while solving (`"events"`).
    pub events: Vec<Event>,
    /// Named inputs load expressions may use (`"inputs"`), set from outside (an FMU's
    /// importer); a run holds each at its start value ([`Scene::with_inputs_at_start`]).
    pub inputs: Vec<Input>,
    /// Prescribed joint motions (`"drivers"`, [`super::drivers`]).
    pub drivers: Vec<Driver>,
    /// A raw bond graph given instead of bodies and joints (validated by `bond`).
    pub bond_graph: Option<serde_json::Value>,
    /// Free text, e.g. the seed figure the scene follows.
    pub description: Option<String>,
}

/// Rotational inertia about the centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Inertia {
    /// Planar moment of inertia about the z axis (`"inertia": J`); 0 is a point mass.
    Planar(f64),
    /// Principal moments `[Jx, Jy, Jz]` in the body frame (`"inertia": [Jx, Jy, Jz]`).
    Principal([f64; 3]),
}

/// The frame in which a planar body's equations are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BodyFrame {
    /// `"inertial"`: non-rotating frame at the centre of mass (seed 16.8); the default.
    #[default]
    Inertial,
    /// `"body"`: body-fixed frame (seed 16.3, 16.1).
    BodyFixed,
}

/// A rigid body and its initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Unique name; not `"ground"`, no `.` in it.
    pub name: String,
    /// Mass in kg (> 0).
    pub mass: f64,
    /// Inertia about the centre of mass.
    pub inertia: Inertia,
    /// Formulation frame (planar bodies).
    pub frame: BodyFrame,
    /// Named points in body coordinates relative to the centre of mass, in the user's order.
    pub points: Vec<(String, Vec<f64>)>,
    /// Initial position of the centre of mass (global frame).
    pub position: Vec<f64>,
    /// Initial angle (planar scenes; 0 in spatial scenes).
    pub angle: f64,
    /// Initial Cardan angles `[psi, theta, phi]` (spatial scenes; zeros in planar scenes).
    pub cardan: [f64; 3],
    /// Initial velocity of the centre of mass (global frame).
    pub velocity: Vec<f64>,
    /// Initial angular velocity: `[omega]` in the plane, `[wx, wy, wz]` (body frame) in space.
    pub angular_velocity: Vec<f64>,
    /// Whether the scene writes `velocity` (absent: zeros, which the initial projection may
    /// change first to close the joints).
    pub velocity_given: bool,
    /// Whether the scene writes `angular_velocity` (as `velocity_given`).
    pub angular_velocity_given: bool,
}

impl Body {
    /// Coordinates (body frame) of the named point, if the body has it.
    pub fn point(&self, name: &str) -> Option<&[f64]> {
        self.points
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, c)| c.as_slice())
    }

    /// The point names, in the user's order.
    pub fn point_names(&self) -> impl Iterator<Item = &str> {
        self.points.iter().map(|(n, _)| n.as_str())
    }
}

/// A point on a body: by name, or by coordinates (body frame; global for ground).
#[derive(Debug, Clone, PartialEq)]
pub enum PointRef {
    /// A named point of the body.
    Named(String),
    /// Coordinates in the body frame (global frame for ground).
    Coords(Vec<f64>),
}

/// A joint between two bodies (either may be ground).
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Unique name (default `"joint<i>"`).
    pub name: String,
    /// The kind, with its own fields (`docs/scene-format.md` §5).
    pub kind: JointKind,
    /// The two bodies, by name.
    pub bodies: [String; 2],
    /// The joint point on each body.
    pub points: [PointRef; 2],
}

/// A point-to-point spring-damper.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// Name (default `"spring<i>"`).
    pub name: String,
    /// The two bodies, by name.
    pub bodies: [String; 2],
    /// The attachment point on each body.
    pub points: [PointRef; 2],
    /// Stiffness k in N/m (>= 0).
    pub stiffness: f64,
    /// Rest length l0 in m; `None` = the initial distance between the points.
    pub rest_length: Option<f64>,
    /// Damping c in N·s/m (>= 0, default 0).
    pub damping: f64,
}

/// Force or torque.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadKind {
    /// A force (global frame) applied at a point.
    Force,
    /// A torque (scalar in the plane; global `[tx, ty, tz]` in space).
    Torque,
}

/// The value of a load as a function of time.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadValue {
    /// Constant components (a planar torque has one component).
    Const(Vec<f64>),
    /// Piecewise linear in time: `v[k]` is the value (all components) at `t[k]`.
    Table {
        /// Strictly increasing sample times.
        t: Vec<f64>,
        /// One value per sample time, each with the load's number of components.
        v: Vec<Vec<f64>>,
    },
    /// One expression per component, in `t` and the scene's outputs (e.g. `crank.angle`).
    Expr(Vec<String>),
}

/// An applied force or torque.
#[derive(Debug, Clone, PartialEq)]
pub struct Load {
    /// Name (default `"load<i>"`).
    pub name: String,
    /// Force or torque.
    pub kind: LoadKind,
    /// The loaded body (not ground).
    pub body: String,
    /// Point of application of a force (`None` = centre of mass); always `None` for a torque.
    pub point: Option<PointRef>,
    /// The value.
    pub value: LoadValue,
}

impl Load {
    /// Number of components of the value: force = dimension, torque = 1 (plane) or 3 (space).
    pub fn components(&self, dimension: Dimension) -> usize {
        match self.kind {
            LoadKind::Force => dimension.coords(),
            LoadKind::Torque => dimension.rotations(),
        }
    }
}

/// An input of the scene (`"inputs"`): a name the load expressions may use, whose value is
/// set from outside (the importer of an FMU, `bondmech fmu`); a run holds it at `start`.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// The name used in load expressions (letters, digits and `_`, not starting with a digit;
    /// not `t`, `pi`, a function or a scalar output).
    pub name: String,
    /// The value a run uses, and the FMU's start value.
    pub start: f64,
    /// Unit, as written in an FMU's model description (`"N.m"`), if given.
    pub unit: Option<String>,
}

/// Which zero crossings of an event's `when` expression count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EventDirection {
    /// `"rising"`: `when` passes zero from below.
    Rising,
    /// `"falling"`: `when` passes zero from above.
    Falling,
    /// `"both"` (the default): either way.
    #[default]
    Both,
}

impl EventDirection {
    /// The JSON name.
    pub fn as_str(self) -> &'static str {
        match self {
            EventDirection::Rising => "rising",
            EventDirection::Falling => "falling",
            EventDirection::Both => "both",
        }
    }

    /// Whether a crossing in direction `sign` (+1 rising, −1 falling, as SUNDIALS reports it)
    /// counts.
    pub fn accepts(self, sign: i32) -> bool {
        match self {
            EventDirection::Rising => sign > 0,
            EventDirection::Falling => sign < 0,
            EventDirection::Both => sign != 0,
        }
    }
}

/// What happens when an event fires.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EventAction {
    /// `"stop"`: the run ends there, successfully; the event row is the last row.
    Stop,
    /// `"record"` (the default): a row is written at the event time and the run goes on.
    #[default]
    Record,
}

impl EventAction {
    /// The JSON name.
    pub fn as_str(self) -> &'static str {
        match self {
            EventAction::Stop => "stop",
            EventAction::Record => "record",
        }
    }
}

/// An event: a zero crossing of `when`, located by the integrator's root finding.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Name (default `"event<i>"`), reported in the summary's `events`.
    pub name: String,
    /// Expression in `t` and the output columns (standard body columns, point coordinates
    /// and velocities `b.P.x`, `energy`, reaction columns `J.Fx`, …); the event fires where
    /// it crosses zero.
    pub when: String,
    /// Which crossings count.
    pub direction: EventDirection,
    /// Stop the run or record a row.
    pub action: EventAction,
}

/// Solver settings (`"solve"`).
#[derive(Debug, Clone, PartialEq)]
pub struct SolveSettings {
    /// Formulation (default `dae`).
    pub formulation: FormulationKind,
    /// Time of the initial state given by the bodies, in s (default 0).
    pub t_start: f64,
    /// End time in s (> `t_start`, required).
    pub t_end: f64,
    /// Output interval (default `t_end / 100` when neither this nor `output_times` is given).
    pub output_step: Option<f64>,
    /// Explicit output times, strictly increasing in `[t_start, t_end]`: when rows are written
    /// (the motion always starts at `t_start`; the list need not contain it).
    pub output_times: Option<Vec<f64>>,
    /// Relative tolerance (default 1e-6).
    pub rtol: f64,
    /// Absolute tolerance (default 1e-8).
    pub atol: f64,
    /// Stiffness of the decoupling springs in N/m (default 1e8).
    pub joint_stiffness: f64,
    /// Damping of the decoupling springs in N·s/m (default 0).
    pub joint_damping: f64,
    /// Step budget over the whole run (none by default).
    pub max_steps: Option<u64>,
    /// Wall-clock budget in s (none by default).
    pub max_wall_seconds: Option<f64>,
    /// Linear solver of the Newton iterations (default `auto`).
    pub linear_solver: LinearSolverKind,
    /// Integrator of the partitioned formulation (default `auto`).
    pub integrator: Integrator,
    /// The partitioned formulation stops at the zeros of the loads' non-smooth operations
    /// (default true; the solve options' `switching_functions`).
    pub switching_functions: bool,
    /// The default DAE keeps a conservative mechanism's energy as an invariant: `None` (`"auto"`,
    /// the default) once its drift exceeds what the tolerance promises, `Some(true)`
    /// (`"always"`) from the start, `Some(false)` (`"never"`) not at all.
    pub energy_invariant: Option<bool>,
    /// `"start": "equilibrium"`: the motion starts at rest from the static equilibrium nearest
    /// the bodies' configuration ([`crate::Model::equilibrium`]); `false` (`"given"`, the
    /// default): from the bodies' configuration.
    pub start_at_equilibrium: bool,
}

impl SolveSettings {
    /// Default relative tolerance.
    pub const DEFAULT_RTOL: f64 = 1e-6;
    /// Default absolute tolerance.
    pub const DEFAULT_ATOL: f64 = 1e-8;
    /// Default decoupling spring stiffness.
    pub const DEFAULT_JOINT_STIFFNESS: f64 = 1e8;
    /// Default number of output intervals when no output step or times are given.
    pub const DEFAULT_OUTPUT_INTERVALS: usize = 100;

    /// Settings with all defaults and the given end time.
    pub fn with_t_end(t_end: f64) -> Self {
        SolveSettings {
            formulation: FormulationKind::Dae,
            t_start: 0.0,
            t_end,
            output_step: None,
            output_times: None,
            rtol: Self::DEFAULT_RTOL,
            atol: Self::DEFAULT_ATOL,
            joint_stiffness: Self::DEFAULT_JOINT_STIFFNESS,
            joint_damping: 0.0,
            max_steps: None,
            max_wall_seconds: None,
            linear_solver: LinearSolverKind::Auto,
            integrator: Integrator::Auto,
            switching_functions: true,
            energy_invariant: None,
            start_at_equilibrium: false,
        }
    }
}

impl Scene {
    /// Index of the named body in `bodies` (`None` for ground or an unknown name).
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The output times: `output_times` if given, else `t_start, t_start + h, …` up to and
    /// including `t_end` (the last interval may be shorter), with `h = output_step` or
    /// `(t_end − t_start) / 100`. The motion starts at `t_start` whether or not it is listed.
    pub fn output_times(&self) -> Vec<f64> {
        let s = &self.solve;
        if let Some(times) = &s.output_times {
            return times.clone();
        }
        output_grid(s.t_start, s.t_end, s.output_step)
    }
}

/// `t_start, t_start + h, …, t_end` (the last one exactly `t_end`, the last interval possibly
/// shorter), with `h = step` or `(t_end − t_start) / 100` when `step` is `None`; at most 10⁷
/// intervals (validation refuses more), so it never hangs. `[t_start]` when the span is empty.
///
/// ```
/// assert_eq!(bondmech::scene::output_grid(0.5, 1.5, Some(0.5)), vec![0.5, 1.0, 1.5]);
/// ```
pub fn output_grid(t_start: f64, t_end: f64, step: Option<f64>) -> Vec<f64> {
    let span = t_end - t_start;
    if !(span > 0.0 && span.is_finite() && t_start.is_finite()) {
        return vec![t_start];
    }
    let h = match step {
        Some(h) if h > 0.0 && h.is_finite() => h.min(span),
        _ => span / SolveSettings::DEFAULT_OUTPUT_INTERVALS as f64,
    };
    let tol = 1e-9 * span;
    let n = ((span + tol) / h).floor().min(1e7) as usize;
    let mut times: Vec<f64> = (0..=n).map(|k| t_start + k as f64 * h).collect();
    match times.last_mut() {
        Some(last) if (t_end - *last).abs() <= tol => *last = t_end,
        _ => times.push(t_end),
    }
    times
}
