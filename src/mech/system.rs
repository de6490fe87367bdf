//! The symbolic multibody system a mechanism expands into.
//!
//! Every mechanism, planar or spatial, becomes
//!
//! ```text
//!   q' = K(q) v                      (kinematics: identity for the seed's non-rotating frame, 16.8)
//!   M v' = Q(t, q, v) − G_v(q)ᵀ λ    (the inertias: M is diagonal, one entry per I element)
//!   0 = g(q)                         (one row per differential-causality inertia: the joints)
//! ```
//!
//! with `G_v = (∂g/∂q)·K` the velocity-constraint Jacobian. The rows of `g` are the algebraic
//! constraint rows that the chapter's differential-causality inertias stand for (16.5, 16.7); the
//! forces `Q` collect gravity, springs, dampers, loads and the gyroscopic (MGY) terms.
//!
//! Expressions live in one [`ExprGraph`] whose variable slots follow the *state layout*
//! `[t, q_0 … q_{nq−1}, v_0 … v_{nv−1}]`; formulations append their own unknowns after it.

use super::reactions::JointReaction;
use crate::expr::{Expr, ExprGraph};
use crate::scene::{EventAction, EventDirection};

/// What a generalized coordinate stands for (used for names, diagnostics and outputs).
#[derive(Clone, Debug, PartialEq)]
pub struct Coordinate {
    /// Readable name, e.g. `bar1.x` or `bar1.angle`.
    pub name: String,
    /// Initial value given by the user (before projection onto the constraints).
    pub initial: f64,
}

/// One scalar position-level constraint row `g_i(q) = 0`, and the joint it comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintRow {
    /// Name of the joint (as in the scene).
    pub joint: String,
    /// Which direction of the joint this row fixes (`x`, `y`, `z`, `normal`, `angle`, …).
    pub direction: String,
}

/// A named scalar output (a CSV column) as an expression of the state `[t, q, v]`.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputColumn {
    /// Column name, e.g. `bar2.A.x`.
    pub name: String,
    /// Its expression.
    pub expr: Expr,
    /// Angles whose continuous (unwrapped) value must be restored after evaluation
    /// (Cardan angles computed with `atan2`).
    pub unwrap: bool,
}

/// A scene event ready for root finding: its `when` as an expression over the *event layout*
/// `[t, q, v, r]`, where `r` are the reaction columns of every joint in order
/// ([`MultibodySystem::reactions`]), so an event may watch a joint force.
#[derive(Clone, Debug, PartialEq)]
pub struct EventFunction {
    /// Event name (as in the scene).
    pub name: String,
    /// The `when` expression as written (for messages).
    pub when: String,
    /// The function whose zero crossings are the event.
    pub expr: Expr,
    /// Which crossings count.
    pub direction: EventDirection,
    /// Stop the run, or record a row.
    pub action: EventAction,
    /// Whether `expr` depends on reaction columns (then the runner computes them).
    pub uses_reactions: bool,
}

/// A driver's row and columns: the driver prescribes a joint's coordinate `s(q) = s(t)`
/// (its constraint row `g = s(q) − s(t)`, row [`DriverOutput::row`] of the system); its
/// effort on the joint's second body is `−λ_row` (`M v' = Q − G_vᵀ λ` and `∂g/∂s = 1`), the
/// torque (revolute) or force (prismatic) the actuator gives, and its power is that effort
/// times the prescribed rate `ṡ(t)`.
#[derive(Clone, Debug, PartialEq)]
pub struct DriverOutput {
    /// The driver's name (as in the scene).
    pub name: String,
    /// Index of the driver in the scene's `drivers`.
    pub index: usize,
    /// The driven joint's name.
    pub joint: String,
    /// Index of its constraint row.
    pub row: usize,
    /// `torque` (a revolute joint) or `force` (a prismatic joint).
    pub effort: &'static str,
    /// The prescribed rate `ṡ(t)`.
    pub rate: Expr,
}

impl DriverOutput {
    /// Its columns: `<name>.torque` or `<name>.force`, then `<name>.power`.
    pub fn columns(&self) -> [String; 2] {
        [
            format!("{}.{}", self.name, self.effort),
            format!("{}.power", self.name),
        ]
    }
}

/// How far the user's initial configuration is from satisfying one joint.
#[derive(Clone, Debug, PartialEq)]
pub struct JointViolation {
    /// Name of the joint (as in the scene).
    pub joint: String,
    /// Index of the joint in the scene's `joints` array.
    pub index: usize,
    /// The joint's rows `g_i(q₀)` at the initial coordinates, with their directions
    /// (`x`, `y`, `z` in metres: the gap between the two joint points; `normal*` in metres;
    /// `angle` in radians; `axis*`, `r*` dimensionless, about the misalignment angle).
    pub rows: Vec<(String, f64)>,
    /// Euclidean norm of `rows` (for a pin: the distance between the two joint points).
    pub norm: f64,
}

/// One component of a load whose value is an expression, kept so that a non-finite generalized
/// force can be traced back to the load that produced it.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadTerm {
    /// JSON path of the value, e.g. `loads[2].value` or `loads[0].value[1]`.
    pub path: String,
    /// Name of the load (as in the scene, `load<i>` by default).
    pub load: String,
    /// The expression text as written in the scene.
    pub source: String,
    /// The expression, in the state layout `[t, q, v]`.
    pub expr: Expr,
}

/// A load of time above this magnitude and growing is a runaway where the steps collapse
/// ([`MultibodySystem::load_runaway`]).
pub const RUNAWAY_VALUE: f64 = 1e12;

/// A value of the model that evaluates to NaN or ±∞, named after the scene field that
/// produced it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path} ({what}) evaluates to {value} at t = {t}")]
pub struct NonFiniteValue {
    /// JSON path of the culprit (`loads[2].value`), or the equation (`forces[bar.omega]`) when no
    /// single scene field is to blame.
    pub path: String,
    /// What it is, e.g. `load 'gas', "1/t"`.
    pub what: String,
    /// Time of the evaluation.
    pub t: f64,
    /// The value (NaN or ±∞).
    pub value: f64,
}

/// The symbolic multibody system: see the module documentation for the equations.
#[derive(Clone, Debug)]
pub struct MultibodySystem {
    /// Expression arena holding every expression below.
    pub graph: ExprGraph,
    /// Generalized coordinates `q`.
    pub coords: Vec<Coordinate>,
    /// Velocity unknowns `v` (names), initial values.
    pub velocities: Vec<Coordinate>,
    /// Which velocities the scene gives (a body's `velocity` or `angular_velocity`), one per
    /// velocity (empty: none): the initial projection changes the others, where they can
    /// close the joints ([`crate::dae::consistent_state`]).
    pub given_velocities: Vec<bool>,
    /// Diagonal of the mass matrix `M` (one entry per velocity; 0 for a massless rotation).
    pub mass: Vec<f64>,
    /// The inertias `M_j` as expressions where they depend on a sensitivity run's parameter
    /// symbols ([`crate::sensitivity`]); empty otherwise (then `mass` is all there is).
    pub mass_symbols: Vec<Expr>,
    /// `K(q) v`, one expression per coordinate.
    pub kinematics: Vec<Expr>,
    /// Generalized forces `Q(t, q, v)`, one per velocity.
    pub forces: Vec<Expr>,
    /// Position constraints `g(q)`.
    pub constraints: Vec<Expr>,
    /// Where each constraint row comes from.
    pub rows: Vec<ConstraintRow>,
    /// Total mechanical energy (kinetic + gravity + springs).
    pub energy: Expr,
    /// Kinetic energy alone (used to scale the energy drift).
    pub kinetic: Expr,
    /// Standard and requested output columns.
    pub outputs: Vec<OutputColumn>,
    /// Non-fatal remarks found while building (unconnected bodies, unmodelled rotations, …).
    pub warnings: Vec<String>,
    /// The loads given as expressions, one term per component (to name a non-finite force).
    pub load_terms: Vec<LoadTerm>,
    /// Size of the bodies (m): the largest distance of a body point from its centre of mass,
    /// or the scene's [`length_scale`](crate::scene::validate::length_scale) when no body has
    /// points away from its centre; 0 when neither exists.
    pub body_size: f64,
    /// How each joint's reaction is read from its constraint forces, in the scene's order.
    pub reactions: Vec<JointReaction>,
    /// Whether the reaction columns are written (`"outputs": ["reactions"]`).
    pub reaction_outputs: bool,
    /// The scene's events.
    pub events: Vec<EventFunction>,
    /// The scene's drivers (prescribed joint motion), in the scene's order.
    pub drivers: Vec<DriverOutput>,
    /// Why the mechanical energy is not conserved (the first damper or load that exchanges
    /// energy with the mechanism, e.g. `loads[0] ('gas') does work`); `None` when it is.
    pub energy_exchange: Option<String>,
    /// How each scene body is represented (its slots), in the scene's order.
    pub bodies: Vec<(String, super::body::BodyKinematics)>,
    /// The scene's expression vocabulary (`t`, `bar.angle`, `bar.A.x`, …), sorted by name.
    pub names: Vec<(String, Expr)>,
    /// The velocity-level constraint rows `G_v v` read off the bond graph's constraint
    /// junctions (one per row of `constraints`); empty when they are to be derived from `g`.
    pub flow_rows: Vec<Expr>,
    /// Where the equations come from.
    pub source: EquationSource,
    /// The inertia (I element of [`MultibodySystem::bond_graph`]) whose flow each velocity is,
    /// by element name (the names `graph --causality` reports); empty for equations assembled
    /// beside the graph.
    pub inertias: Vec<String>,
    /// The complete bond graph the equations were read from (the decoupled twin is read from
    /// its transformation, [`crate::bond::decouple`]); `None` for equations assembled beside it.
    pub bond_graph: Option<std::sync::Arc<crate::bond::model::BondGraph>>,
}

/// Where a [`MultibodySystem`]'s inertias, forces and constraint rows come from.
#[derive(Clone, Debug, PartialEq)]
pub enum EquationSource {
    /// Read off the mechanism's bond graph ([`crate::bond::mechanics`]).
    BondGraph,
    /// Assembled from the bodies directly, because the bond graph of this scene cannot be read
    /// yet (the reason).
    Assembled(String),
}

impl MultibodySystem {
    /// Number of coordinates.
    pub fn nq(&self) -> usize {
        self.coords.len()
    }
    /// Number of velocities.
    pub fn nv(&self) -> usize {
        self.velocities.len()
    }
    /// Number of constraint rows.
    pub fn nc(&self) -> usize {
        self.constraints.len()
    }
    /// Number of variable slots of the state layout `[t, q, v]`.
    pub fn n_state_slots(&self) -> usize {
        1 + self.nq() + self.nv()
    }
    /// Slot of coordinate `i` in the state layout.
    pub fn q_slot(&self, i: usize) -> u32 {
        (1 + i) as u32
    }
    /// Slot of velocity `j` in the state layout.
    pub fn v_slot(&self, j: usize) -> u32 {
        (1 + self.nq() + j) as u32
    }
    /// Initial state vector `[q0, v0]` as given by the user.
    pub fn initial_state(&self) -> Vec<f64> {
        self.coords
            .iter()
            .chain(self.velocities.iter())
            .map(|c| c.initial)
            .collect()
    }

    /// `G_v(q) v` — the velocity-level constraints, built as `Σ_k ∂g_i/∂q_k · (K v)_k`.
    pub fn velocity_constraints(&mut self) -> Vec<Expr> {
        (0..self.nc())
            .map(|i| time_rate(&mut self.graph, &self.kinematics, self.constraints[i]))
            .collect()
    }

    /// Rows of `G_v` as expressions: `G_v[i][j] = ∂(G_v v)_i / ∂v_j` (exact, since it is linear in `v`).
    pub fn velocity_jacobian(&mut self, gv: &[Expr]) -> Vec<Vec<Expr>> {
        let nv = self.nv();
        let mut rows = Vec::with_capacity(gv.len());
        for &e in gv {
            // zero except at the velocities the row mentions
            let mut row = vec![self.graph.zero(); nv];
            for slot in self.graph.vars(e) {
                let Some(j) = (slot as usize).checked_sub(1 + self.nq()) else {
                    continue;
                };
                if j < nv {
                    row[j] = self.graph.diff(e, slot);
                }
            }
            rows.push(row);
        }
        rows
    }

    /// The constraint violation of every joint at the user's initial coordinates `q₀` (before
    /// the projection onto `g(q) = 0` that the solvers do), in the order of the scene's joints;
    /// `joints` are the scene's joint names (to number them). Joints without rows are absent.
    pub fn initial_violation(&self, joints: &[String]) -> Vec<JointViolation> {
        self.initial_violation_at(0.0, joints)
    }

    /// [`Self::initial_violation`] at time `t` (a driver's row depends on it).
    pub fn initial_violation_at(&self, t: f64, joints: &[String]) -> Vec<JointViolation> {
        let mut x = vec![t];
        x.extend(self.initial_state());
        let mut out: Vec<JointViolation> = Vec::new();
        for (row, &g) in self.rows.iter().zip(&self.constraints) {
            let val = self.graph.eval(g, &x);
            match out.last_mut() {
                Some(v) if v.joint == row.joint => v.rows.push((row.direction.clone(), val)),
                _ => out.push(JointViolation {
                    joint: row.joint.clone(),
                    index: joints.iter().position(|j| *j == row.joint).unwrap_or(0),
                    rows: vec![(row.direction.clone(), val)],
                    norm: 0.0,
                }),
            }
        }
        for v in &mut out {
            v.norm = v.rows.iter().map(|(_, r)| r * r).sum::<f64>().sqrt();
        }
        out
    }

    /// The first scene quantity that is not finite at time `t` and state `x = [q, v]`: a load
    /// expression (its JSON path, name and text), a load whose derivative along a coordinate or
    /// velocity is not (it makes the Newton matrix non-finite), or else a generalized force (the
    /// velocity it acts on). `None` when every load and force is finite there.
    pub fn non_finite_source(&self, t: f64, x: &[f64]) -> Option<NonFiniteValue> {
        let mut vars = Vec::with_capacity(1 + x.len());
        vars.push(t);
        vars.extend_from_slice(x);
        for l in &self.load_terms {
            let value = self.graph.eval(l.expr, &vars);
            if !value.is_finite() {
                return Some(NonFiniteValue {
                    path: l.path.clone(),
                    what: format!("load '{}', {}", l.load, crate::expr::excerpt(&l.source, 0)),
                    t,
                    value,
                });
            }
        }
        // a finite load whose rate of change is not (sqrt at 0): the Newton matrix is not finite
        let mut g = self.graph.clone();
        for l in &self.load_terms {
            for slot in 1..vars.len() as u32 {
                let d = g.diff(l.expr, slot);
                let value = g.eval(d, &vars);
                if !value.is_finite() {
                    return Some(NonFiniteValue {
                        path: l.path.clone(),
                        what: format!(
                            "the derivative of load '{}', {}",
                            l.load,
                            crate::expr::excerpt(&l.source, 0)
                        ),
                        t,
                        value,
                    });
                }
            }
        }
        for (j, &f) in self.forces.iter().enumerate() {
            let value = self.graph.eval(f, &vars);
            if !value.is_finite() {
                // the body whose velocity it is (`bar.vx` of `bodies[0]`)
                let velocity = &self.velocities[j].name;
                let body = velocity
                    .rsplit_once('.')
                    .and_then(|(b, _)| self.bodies.iter().position(|(n, _)| n == b))
                    .map(|i| format!(" of bodies[{i}] '{}'", self.bodies[i].0))
                    .unwrap_or_default();
                return Some(NonFiniteValue {
                    path: format!("the generalized force on '{velocity}'{body}"),
                    what: "the gravity, springs, dampers and loads acting on it; a spring with a rest_length > 0 whose two points meet has no direction there (d/L = 0/0)".into(),
                    t,
                    value,
                });
            }
        }
        None
    }

    /// A load that depends on time alone and changes by its own size within 1 ns at `t`, its
    /// rate `|v'|` above 1e9 per second and `|v|` above 1e6 (or that is not finite there): a
    /// pole of its expression (`1/(t - 0.1)` near 0.1) that collapses the solver's step before
    /// the value overflows. The load (JSON path, name, expression, the time scale `|v/v'|`)
    /// with its value, or `None`.
    pub fn load_pole(&self, t: f64) -> Option<NonFiniteValue> {
        /// `|v'/v|` (1/s) above which a load changes by its own size within 1 ns.
        const POLE_RATE: f64 = 1e9;
        let mut g = self.graph.clone();
        let mut vars = vec![0.0; 1 + self.coords.len() + self.velocities.len()];
        vars[0] = t;
        for l in &self.load_terms {
            if g.vars(l.expr).iter().any(|&s| s != 0) {
                continue;
            }
            let value = g.eval(l.expr, &vars);
            let d = g.diff(l.expr, 0);
            let rate = g.eval(d, &vars);
            let relative = (rate / value).abs();
            if !value.is_finite()
                || !rate.is_finite()
                || (relative > POLE_RATE && rate.abs() > POLE_RATE && value.abs() > 1e6)
            {
                return Some(NonFiniteValue {
                    path: l.path.clone(),
                    what: format!(
                        "load '{}', {}, a pole: it changes by its own size within {:.1e} s",
                        l.load,
                        crate::expr::excerpt(&l.source, 0),
                        1.0 / relative,
                    ),
                    t,
                    value,
                });
            }
        }
        None
    }

    /// A load of time alone that grows without bound at `t` (`exp(1e6*t)`): its magnitude
    /// above [`RUNAWAY_VALUE`] and growing, named with the time it doubles in and, at that
    /// exponential pace, the time it overflows a double. The culprit of a collapsed step
    /// ([`crate::sundials::SolverError::StepCollapse`]).
    pub fn load_runaway(&self, t: f64) -> Option<NonFiniteValue> {
        let mut g = self.graph.clone();
        let mut vars = vec![0.0; 1 + self.coords.len() + self.velocities.len()];
        vars[0] = t;
        let of_time: Vec<&LoadTerm> = self
            .load_terms
            .iter()
            .filter(|l| g.vars(l.expr).iter().all(|&s| s == 0))
            .collect();
        of_time
            .into_iter()
            .map(|l| {
                let value = g.eval(l.expr, &vars);
                let d = g.diff(l.expr, 0);
                (l, value, g.eval(d, &vars))
            })
            .filter(|(_, value, rate)| {
                value.is_finite() && value.abs() > RUNAWAY_VALUE && value * rate > 0.0
            })
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .map(|(l, value, rate)| {
                let relative = (rate / value).abs();
                let overflow = t + (f64::MAX / value.abs()).ln() / relative;
                NonFiniteValue {
                    path: l.path.clone(),
                    what: format!(
                        "load '{}', {}, grows without bound: it doubles every {:.1e} s and at that pace overflows by t ≈ {overflow:.2e}",
                        l.load,
                        crate::expr::excerpt(&l.source, 0),
                        std::f64::consts::LN_2 / relative,
                    ),
                    t,
                    value,
                }
            })
    }

    /// Names of every joint's reaction columns, in order, then every driver's columns (the
    /// `r` part of the event layout).
    pub fn reaction_columns(&self) -> Vec<String> {
        self.reactions
            .iter()
            .flat_map(|r| r.columns())
            .chain(self.drivers.iter().flat_map(|d| d.columns()))
            .collect()
    }

    /// Names of the driver columns alone (written whether or not reactions are asked for).
    pub fn driver_columns(&self) -> Vec<String> {
        self.drivers.iter().flat_map(|d| d.columns()).collect()
    }

    /// Index of the output column called `name`.
    pub fn output_index(&self, name: &str) -> Option<usize> {
        self.outputs.iter().position(|c| c.name == name)
    }
}

/// The rate of a function of the coordinates along the motion, `ḣ = Σ_k ∂h/∂q_k · (K(q) v)_k`
/// (`kinematics` the expressions `K(q) v`, one per coordinate, slots `1..=nq`), over the
/// coordinates `h` mentions, in slot order (linear in the mechanism's size).
pub fn time_rate(graph: &mut ExprGraph, kinematics: &[Expr], h: Expr) -> Expr {
    let nq = kinematics.len();
    let mut terms = Vec::new();
    for slot in graph.vars(h) {
        let k = slot as usize;
        if (1..=nq).contains(&k) {
            let d = graph.diff(h, slot);
            terms.push(graph.mul(d, kinematics[k - 1]));
        }
    }
    graph.sum(&terms)
}
