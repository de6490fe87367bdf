//! Mechanisms built in code: the vocabulary of the scene format as Rust builders.
//!
//! A [`Mechanism`] collects bodies ([`PlanarBody`], [`SpatialBody`]), joints, springs
//! ([`SpringDamper`]), loads and solver settings and turns them into a [`Scene`] with
//! [`Mechanism::build`], checked by the same validator as a JSON scene file
//! ([`Scene::validate`]). A scene built here and the same scene read from JSON are equal
//! (`==`) and solve to identical results.
//!
//! Joint and spring ends are [`Endpoint`]s: `("bar1", "O")` is the named point `O` of `bar1`,
//! `("bar1", [0.1, 0.0])` a point given by body-frame coordinates, `"bar1"` alone its centre
//! of mass, and [`Ground`]`.at([x, y])` a fixed point of the ground (global frame).
//!
//! ```
//! use bondmech::{Ground, Mechanism, PlanarBody};
//! // Simple pendulum (seed 16.8, Fig. 26): a point mass on a massless rod of 1 m.
//! let scene = Mechanism::planar()
//!     .gravity([0.0, -9.81])
//!     .body(PlanarBody::point_mass("bob", 1.0).point("O", [-1.0, 0.0]).at([1.0, 0.0], 0.0))
//!     .revolute("pivot", Ground.at([0.0, 0.0]), ("bob", "O"))
//!     .t_end(2.0)
//!     .build()?;
//! assert_eq!(scene.joints[0].bodies, ["ground".to_string(), "bob".to_string()]);
//! # Ok::<(), bondmech::Error>(())
//! ```
//!
//! Errors name the element and keep its JSON path:
//!
//! ```
//! use bondmech::{Mechanism, PlanarBody};
//! let err = Mechanism::planar()
//!     .body(PlanarBody::point_mass("bob", -1.0))
//!     .t_end(1.0)
//!     .build()
//!     .unwrap_err();
//! assert_eq!(err.to_string(), "body 'bob' (bodies[0]).mass: must be > 0 and finite (got -1)");
//! ```

use crate::error::{Error, Result};
use crate::scene::joint_kind::{Prismatic, Revolute, Spherical, Weld};
use crate::scene::{
    Body, BodyFrame, Dimension, Inertia, Joint, JointKind, Load, LoadKind, LoadValue, PointRef,
    Problem, Scene, SceneError, SolveSettings, Spring, GROUND,
};
use crate::settings::FormulationKind;

/// A planar rigid body (seed 16.3, 16.8): mass, moment of inertia about the centre of mass,
/// named points in body coordinates, and its initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarBody(Body);

impl PlanarBody {
    /// A body of mass `mass` (kg) and moment of inertia `inertia` (kg m², about the centre of
    /// mass), at the origin, at rest, with no named points.
    pub fn new(name: &str, mass: f64, inertia: f64) -> Self {
        PlanarBody(Body {
            name: name.to_string(),
            mass,
            inertia: Inertia::Planar(inertia),
            frame: BodyFrame::Inertial,
            points: Vec::new(),
            position: vec![0.0, 0.0],
            angle: 0.0,
            cardan: [0.0; 3],
            velocity: vec![0.0, 0.0],
            angular_velocity: vec![0.0],
            velocity_given: false,
            angular_velocity_given: false,
        })
    }

    /// A uniform bar of length `length` along its body x axis: inertia `m L²/12`, points `O`
    /// at `[−L/2, 0]` and `A` at `[L/2, 0]` (the seed's bar, Fig. 14).
    pub fn bar(name: &str, mass: f64, length: f64) -> Self {
        PlanarBody::new(name, mass, mass * length * length / 12.0)
            .point("O", [-0.5 * length, 0.0])
            .point("A", [0.5 * length, 0.0])
    }

    /// A point mass (inertia 0): its angle is modelled only if some point lies away from the
    /// centre of mass (a bob on a massless rod).
    pub fn point_mass(name: &str, mass: f64) -> Self {
        PlanarBody::new(name, mass, 0.0)
    }

    /// Replaces the moment of inertia about the centre of mass.
    pub fn inertia(mut self, inertia: f64) -> Self {
        self.0.inertia = Inertia::Planar(inertia);
        self
    }

    /// Adds (or moves) the named point `name` at body coordinates `coords` relative to the
    /// centre of mass.
    pub fn point(mut self, name: &str, coords: [f64; 2]) -> Self {
        set_point(&mut self.0, name, coords.to_vec());
        self
    }

    /// Initial position of the centre of mass (global frame) and angle (rad).
    pub fn at(mut self, position: [f64; 2], angle: f64) -> Self {
        self.0.position = position.to_vec();
        self.0.angle = angle;
        self
    }

    /// Initial velocity of the centre of mass (global frame).
    pub fn velocity(mut self, velocity: [f64; 2]) -> Self {
        self.0.velocity = velocity.to_vec();
        self.0.velocity_given = true;
        self
    }

    /// Initial angular velocity ω (rad/s).
    pub fn angular_velocity(mut self, omega: f64) -> Self {
        self.0.angular_velocity = vec![omega];
        self.0.angular_velocity_given = true;
        self
    }

    /// The frame its equations are written in: [`BodyFrame::Inertial`] (seed 16.8, the
    /// default) or [`BodyFrame::BodyFixed`] (seed 16.3).
    pub fn frame(mut self, frame: BodyFrame) -> Self {
        self.0.frame = frame;
        self
    }
}

impl From<PlanarBody> for Body {
    fn from(b: PlanarBody) -> Body {
        b.0
    }
}

/// A rigid body in space (seed 16.1–16.2): mass, principal moments of inertia, named points,
/// and its initial state (position, Cardan angles, velocities).
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialBody(Body);

impl SpatialBody {
    /// A body of mass `mass` with principal moments `[Jx, Jy, Jz]` (body frame), at the origin,
    /// unrotated, at rest, with no named points.
    pub fn new(name: &str, mass: f64, principal_inertia: [f64; 3]) -> Self {
        SpatialBody(Body {
            name: name.to_string(),
            mass,
            inertia: Inertia::Principal(principal_inertia),
            frame: BodyFrame::Inertial,
            points: Vec::new(),
            position: vec![0.0; 3],
            angle: 0.0,
            cardan: [0.0; 3],
            velocity: vec![0.0; 3],
            angular_velocity: vec![0.0; 3],
            velocity_given: false,
            angular_velocity_given: false,
        })
    }

    /// Adds (or moves) the named point `name` at body coordinates `coords`.
    pub fn point(mut self, name: &str, coords: [f64; 3]) -> Self {
        set_point(&mut self.0, name, coords.to_vec());
        self
    }

    /// Initial position of the centre of mass and Cardan angles `[ψ, θ, φ]`
    /// (`R = Ψ(ψ about Z) Θ(θ about y') Φ(φ about x'')`, seed 16.2).
    pub fn at(mut self, position: [f64; 3], cardan: [f64; 3]) -> Self {
        self.0.position = position.to_vec();
        self.0.cardan = cardan;
        self
    }

    /// Initial velocity of the centre of mass (global frame).
    pub fn velocity(mut self, velocity: [f64; 3]) -> Self {
        self.0.velocity = velocity.to_vec();
        self.0.velocity_given = true;
        self
    }

    /// Initial angular velocity `[ωx, ωy, ωz]` in the body frame.
    pub fn angular_velocity(mut self, omega: [f64; 3]) -> Self {
        self.0.angular_velocity = omega.to_vec();
        self.0.angular_velocity_given = true;
        self
    }

    /// The formulation frame ([`BodyFrame::Inertial`] by default, as in the scene format).
    pub fn frame(mut self, frame: BodyFrame) -> Self {
        self.0.frame = frame;
        self
    }
}

impl From<SpatialBody> for Body {
    fn from(b: SpatialBody) -> Body {
        b.0
    }
}

fn set_point(body: &mut Body, name: &str, coords: Vec<f64>) {
    match body.points.iter_mut().find(|(n, _)| n == name) {
        Some((_, c)) => *c = coords,
        None => body.points.push((name.to_string(), coords)),
    }
}

/// The fixed body. `Ground.at([x, y])` is a ground point for a joint, spring or load end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ground;

impl Ground {
    /// The ground point at global coordinates `coords` (2 or 3 of them).
    pub fn at<const N: usize>(self, coords: [f64; N]) -> Endpoint {
        Endpoint {
            body: GROUND.to_string(),
            point: Some(PointRef::Coords(coords.to_vec())),
        }
    }
}

/// One end of a joint, spring or force: a body and a point on it.
///
/// Built from `("body", "P")` (named point), `("body", [x, y])` (body-frame coordinates),
/// `"body"` (the centre of mass) or [`Ground::at`].
#[derive(Clone, Debug, PartialEq)]
pub struct Endpoint {
    /// The body's name (`"ground"` for the fixed body).
    pub body: String,
    /// The point; `None` is the centre of mass.
    pub point: Option<PointRef>,
}

impl From<(&str, &str)> for Endpoint {
    fn from((body, point): (&str, &str)) -> Self {
        Endpoint {
            body: body.to_string(),
            point: Some(PointRef::Named(point.to_string())),
        }
    }
}

impl<const N: usize> From<(&str, [f64; N])> for Endpoint {
    fn from((body, coords): (&str, [f64; N])) -> Self {
        Endpoint {
            body: body.to_string(),
            point: Some(PointRef::Coords(coords.to_vec())),
        }
    }
}

impl From<&str> for Endpoint {
    fn from(body: &str) -> Self {
        Endpoint {
            body: body.to_string(),
            point: None,
        }
    }
}

impl Endpoint {
    /// The point, with the centre of mass written as zero coordinates.
    fn point_or_centre(&self, dim: usize) -> PointRef {
        self.point
            .clone()
            .unwrap_or_else(|| PointRef::Coords(vec![0.0; dim]))
    }
}

/// A point-to-point spring-damper: `F = k (ℓ − ℓ₀) + c ℓ'` along the line between its ends.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringDamper {
    name: String,
    ends: [Endpoint; 2],
    stiffness: f64,
    rest_length: Option<f64>,
    damping: f64,
}

impl SpringDamper {
    /// A spring of stiffness `stiffness` (N/m) between `a` and `b`, rest length = the initial
    /// distance, no damping.
    pub fn new(name: &str, a: impl Into<Endpoint>, b: impl Into<Endpoint>, stiffness: f64) -> Self {
        SpringDamper {
            name: name.to_string(),
            ends: [a.into(), b.into()],
            stiffness,
            rest_length: None,
            damping: 0.0,
        }
    }

    /// Rest length ℓ₀ (m).
    pub fn rest_length(mut self, rest_length: f64) -> Self {
        self.rest_length = Some(rest_length);
        self
    }

    /// Damping c (N s/m).
    pub fn damping(mut self, damping: f64) -> Self {
        self.damping = damping;
        self
    }
}

impl LoadValue {
    /// One expression per component in `t` and the scene's outputs, e.g. a gas force
    /// `LoadValue::expr(["0", "-50*max(0, cos(crank.angle))"])`.
    pub fn expr<S: AsRef<str>>(components: impl IntoIterator<Item = S>) -> Self {
        LoadValue::Expr(
            components
                .into_iter()
                .map(|s| s.as_ref().to_string())
                .collect(),
        )
    }

    /// Piecewise linear in time: `values[k]` (all components) at `times[k]`.
    pub fn table(times: Vec<f64>, values: Vec<Vec<f64>>) -> Self {
        LoadValue::Table {
            t: times,
            v: values,
        }
    }
}

impl From<f64> for LoadValue {
    /// A constant scalar (a planar torque).
    fn from(c: f64) -> Self {
        LoadValue::Const(vec![c])
    }
}

impl<const N: usize> From<[f64; N]> for LoadValue {
    /// Constant components (a force, or a spatial torque).
    fn from(c: [f64; N]) -> Self {
        LoadValue::Const(c.to_vec())
    }
}

impl From<&str> for LoadValue {
    /// A scalar expression (a planar torque), e.g. `"-0.1*crank.omega"`.
    fn from(e: &str) -> Self {
        LoadValue::Expr(vec![e.to_string()])
    }
}

impl<const N: usize> From<[&str; N]> for LoadValue {
    /// One expression per component.
    fn from(e: [&str; N]) -> Self {
        LoadValue::expr(e)
    }
}

impl<const N: usize> From<[String; N]> for LoadValue {
    /// One expression per component, built at run time (e.g. with `format!`).
    fn from(e: [String; N]) -> Self {
        LoadValue::Expr(e.to_vec())
    }
}

/// A mechanism under construction; [`Mechanism::build`] turns it into a validated [`Scene`].
///
/// Elements keep the order they are added in, which is the order of the scene's lists (and
/// hence of the coordinates and output columns).
#[derive(Clone, Debug, PartialEq)]
pub struct Mechanism {
    scene: Scene,
    t_end_set: bool,
}

impl Mechanism {
    fn new(dimension: Dimension) -> Self {
        Mechanism {
            scene: Scene {
                name: "scene".to_string(),
                dimension,
                gravity: vec![0.0; dimension.coords()],
                bodies: Vec::new(),
                joints: Vec::new(),
                springs: Vec::new(),
                loads: Vec::new(),
                solve: SolveSettings::with_t_end(1.0),
                outputs: Vec::new(),
                events: Vec::new(),
                drivers: Vec::new(),
                inputs: Vec::new(),
                bond_graph: None,
                description: None,
            },
            t_end_set: false,
        }
    }

    /// A planar mechanism (`"dimension": 2`), no gravity.
    pub fn planar() -> Self {
        Mechanism::new(Dimension::Planar)
    }

    /// A spatial mechanism (`"dimension": 3`), no gravity.
    pub fn spatial() -> Self {
        Mechanism::new(Dimension::Spatial)
    }

    /// The scene name (default `"scene"`).
    pub fn name(mut self, name: &str) -> Self {
        self.scene.name = name.to_string();
        self
    }

    /// Free text kept with the scene (e.g. the seed figure it follows).
    pub fn description(mut self, text: &str) -> Self {
        self.scene.description = Some(text.to_string());
        self
    }

    /// Gravitational acceleration in the global frame (`[gx, gy]` or `[gx, gy, gz]`).
    pub fn gravity<const N: usize>(mut self, g: [f64; N]) -> Self {
        self.scene.gravity = g.to_vec();
        self
    }

    /// Adds a body ([`PlanarBody`] or [`SpatialBody`]).
    pub fn body(mut self, body: impl Into<Body>) -> Self {
        self.scene.bodies.push(body.into());
        self
    }

    fn joint(mut self, name: &str, kind: JointKind, a: Endpoint, b: Endpoint) -> Self {
        let dim = self.scene.dimension.coords();
        self.scene.joints.push(Joint {
            name: name.to_string(),
            kind,
            points: [a.point_or_centre(dim), b.point_or_centre(dim)],
            bodies: [a.body, b.body],
        });
        self
    }

    /// A revolute joint (planar pin): the points `a` and `b` coincide.
    pub fn revolute(self, name: &str, a: impl Into<Endpoint>, b: impl Into<Endpoint>) -> Self {
        self.joint(name, Revolute::pin().into(), a.into(), b.into())
    }

    /// A prismatic joint (slider): `b` moves along `axis` (frame of `a`'s body) through `a`,
    /// and the relative angle stays fixed.
    pub fn prismatic<const N: usize>(
        self,
        name: &str,
        a: impl Into<Endpoint>,
        b: impl Into<Endpoint>,
        axis: [f64; N],
    ) -> Self {
        let kind = Prismatic {
            axis: axis.to_vec(),
        }
        .into();
        self.joint(name, kind, a.into(), b.into())
    }

    /// A spherical (ball) joint in space: the points `a` and `b` coincide.
    pub fn spherical(self, name: &str, a: impl Into<Endpoint>, b: impl Into<Endpoint>) -> Self {
        self.joint(name, Spherical.into(), a.into(), b.into())
    }

    /// A hinge (spatial revolute joint, `"type": "revolute"` with an `"axis"` in a 3D scene):
    /// the points `a` and `b` coincide (three rows, `P_a = P_b`) and body b turns relative to
    /// body a about `axis` only (two rows, `(R_a axis) · (R_b c_k) = 0` with `c_1, c_2`
    /// perpendicular to the axis as body b sees it initially). `axis` is in the frame of `a`'s
    /// body (global when `a` is the ground).
    ///
    /// ```
    /// use bondmech::{Ground, Mechanism, Model, SpatialBody};
    /// // A bar of 1 m hinged at one end about the global Y axis: one degree of freedom
    /// // (6 velocities, 5 independent hinge rows).
    /// let scene = Mechanism::spatial()
    ///     .gravity([0.0, 0.0, -9.81])
    ///     .body(
    ///         SpatialBody::new("bar", 1.0, [0.02, 1.0 / 12.0, 1.0 / 12.0])
    ///             .point("O", [-0.5, 0.0, 0.0])
    ///             .at([0.5, 0.0, 0.0], [0.0, 0.0, 0.0]),
    ///     )
    ///     .hinge("pivot", Ground.at([0.0, 0.0, 0.0]), ("bar", "O"), [0.0, 1.0, 0.0])
    ///     .t_end(1.0)
    ///     .build()?;
    /// let dof = Model::new(&scene)?.dof()?;
    /// assert_eq!((dof.velocities, dof.rank, dof.dof), (6, 5, 1));
    /// # Ok::<(), bondmech::Error>(())
    /// ```
    pub fn hinge(
        self,
        name: &str,
        a: impl Into<Endpoint>,
        b: impl Into<Endpoint>,
        axis: [f64; 3],
    ) -> Self {
        let kind = Revolute::hinge(axis.to_vec()).into();
        self.joint(name, kind, a.into(), b.into())
    }

    /// A weld: the two bodies are fixed together at their current relative pose.
    pub fn weld(self, name: &str, a: impl Into<Endpoint>, b: impl Into<Endpoint>) -> Self {
        self.joint(name, Weld.into(), a.into(), b.into())
    }

    /// Adds a point-to-point spring-damper.
    pub fn spring(mut self, spring: SpringDamper) -> Self {
        let dim = self.scene.dimension.coords();
        let [a, b] = spring.ends;
        self.scene.springs.push(Spring {
            name: spring.name,
            points: [a.point_or_centre(dim), b.point_or_centre(dim)],
            bodies: [a.body, b.body],
            stiffness: spring.stiffness,
            rest_length: spring.rest_length,
            damping: spring.damping,
        });
        self
    }

    /// A force (global frame) on a body at a point (`"body"` alone: its centre of mass): a
    /// constant `[fx, fy]`, a [`LoadValue::table`], or expressions (`["0", "-50*cos(crank.angle)"]`).
    pub fn force(
        mut self,
        name: &str,
        at: impl Into<Endpoint>,
        value: impl Into<LoadValue>,
    ) -> Self {
        let at = at.into();
        self.scene.loads.push(Load {
            name: name.to_string(),
            kind: LoadKind::Force,
            body: at.body,
            point: at.point,
            value: value.into(),
        });
        self
    }

    /// A torque on a body: a scalar in the plane (`1.0`, `"-0.1*crank.omega"`), `[tx, ty, tz]`
    /// (global frame) in space, or a [`LoadValue::table`].
    pub fn torque(mut self, name: &str, body: &str, value: impl Into<LoadValue>) -> Self {
        self.scene.loads.push(Load {
            name: name.to_string(),
            kind: LoadKind::Torque,
            body: body.to_string(),
            point: None,
            value: value.into(),
        });
        self
    }

    /// Requests an extra output column: `"bar2.A"` (a point), `"energy"`, `"constraint_error"`,
    /// or `"reactions"` (every joint's force and moment on its second body).
    pub fn output(mut self, output: &str) -> Self {
        self.scene.outputs.push(output.to_string());
        self
    }

    /// Adds an event: a zero crossing of `when` (an expression in `t` and the output columns)
    /// in `direction`, which records a row or stops the run (`action`).
    pub fn event(
        mut self,
        name: &str,
        when: &str,
        direction: crate::scene::EventDirection,
        action: crate::scene::EventAction,
    ) -> Self {
        self.scene.events.push(crate::scene::Event {
            name: name.to_string(),
            when: when.to_string(),
            direction,
            action,
        });
        self
    }

    /// End time of the solve (s); required.
    pub fn t_end(mut self, t_end: f64) -> Self {
        self.scene.solve.t_end = t_end;
        self.t_end_set = true;
        self
    }

    /// Output interval (default `t_end / 100`).
    pub fn output_step(mut self, step: f64) -> Self {
        self.scene.solve.output_step = Some(step);
        self
    }

    /// Relative and absolute tolerances (defaults 1e-6, 1e-8).
    pub fn tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.scene.solve.rtol = rtol;
        self.scene.solve.atol = atol;
        self
    }

    /// The formulation the scene asks for (default [`FormulationKind::Dae`]).
    pub fn formulation(mut self, formulation: FormulationKind) -> Self {
        self.scene.solve.formulation = formulation;
        self
    }

    /// Replaces all solver settings at once.
    pub fn solve_settings(mut self, settings: SolveSettings) -> Self {
        self.t_end_set = true;
        self.scene.solve = settings;
        self
    }

    /// The scene, checked by [`Scene::validate`] (the JSON validator); every problem is
    /// reported with the name of its body, joint, spring or load and its JSON path.
    pub fn build(self) -> Result<Scene> {
        let scene = self.scene;
        let mut problems = Vec::new();
        if !self.t_end_set {
            problems.push(Problem::new(
                "solve.t_end",
                "not set (call Mechanism::t_end)",
            ));
        }
        if let Err(SceneError::Invalid { problems: found }) = scene.validate() {
            problems.extend(found);
        }
        if problems.is_empty() {
            Ok(scene)
        } else {
            let problems = problems
                .into_iter()
                .map(|p| name_element(&scene, p))
                .collect();
            Err(Error::Scene(SceneError::Invalid { problems }))
        }
    }
}

impl From<Scene> for Mechanism {
    /// Continues building from an existing scene (e.g. one read from JSON): elements added
    /// afterwards are appended to its lists.
    fn from(scene: Scene) -> Self {
        Mechanism {
            scene,
            t_end_set: true,
        }
    }
}

/// Rewrites a path `bodies[1].mass` as `body 'bar2' (bodies[1]).mass`.
fn name_element(scene: &Scene, p: Problem) -> Problem {
    let lists: [(&str, &str, Vec<&str>); 4] = [
        (
            "bodies",
            "body",
            scene.bodies.iter().map(|b| b.name.as_str()).collect(),
        ),
        (
            "joints",
            "joint",
            scene.joints.iter().map(|j| j.name.as_str()).collect(),
        ),
        (
            "springs",
            "spring",
            scene.springs.iter().map(|s| s.name.as_str()).collect(),
        ),
        (
            "loads",
            "load",
            scene.loads.iter().map(|l| l.name.as_str()).collect(),
        ),
    ];
    for (list, what, names) in lists {
        let Some(rest) = p.path.strip_prefix(list).and_then(|r| r.strip_prefix('[')) else {
            continue;
        };
        let Some((i, tail)) = rest.split_once(']') else {
            continue;
        };
        if let Some(name) = i.parse::<usize>().ok().and_then(|i| names.get(i)) {
            let path = format!("{what} '{name}' ({list}[{i}]){tail}");
            return Problem::new(path, p.message);
        }
    }
    p
}
