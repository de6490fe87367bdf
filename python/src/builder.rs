//! The builder (`bondmech::builder`) for Python: `Mechanism.planar().body(...).revolute(...)`.
//!
//! Each Python object holds the Rust builder value and every method returns a new object (the
//! Rust builder's by-value chaining), so a half-built mechanism can be reused. Joint and spring
//! ends are `("bar1", "O")` (named point), `("bar1", [0.1, 0.0])` (body-frame coordinates),
//! `"bar1"` (the centre of mass) or `Ground.at([x, y])`, as in Rust.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PySequence, PyString, PyTuple};

use bondmech::scene::{BodyFrame, EventAction, EventDirection, LoadValue, PointRef};
use bondmech::FormulationKind;

use crate::{type_error, IntoPyResult, Scene};

fn frame(name: &str) -> PyResult<BodyFrame> {
    match name {
        "inertial" => Ok(BodyFrame::Inertial),
        "body" => Ok(BodyFrame::BodyFixed),
        _ => Err(PyValueError::new_err(format!(
            "frame='{name}': expected 'inertial' or 'body'"
        ))),
    }
}

/// A planar rigid body (seed 16.3, 16.8): mass, moment of inertia about the centre of mass,
/// named points in body coordinates, and its initial state.
#[pyclass(module = "bondmech", name = "PlanarBody", frozen)]
#[derive(Clone)]
pub struct PlanarBody(bondmech::PlanarBody);

#[pymethods]
impl PlanarBody {
    /// A body of mass `mass` (kg) and moment of inertia `inertia` (kg m²), at the origin, at rest.
    #[new]
    fn new(name: &str, mass: f64, inertia: f64) -> Self {
        PlanarBody(bondmech::PlanarBody::new(name, mass, inertia))
    }

    /// A uniform bar of `length` along its x axis, points `O` (−ℓ/2, 0) and `A` (ℓ/2, 0).
    #[staticmethod]
    fn bar(name: &str, mass: f64, length: f64) -> Self {
        PlanarBody(bondmech::PlanarBody::bar(name, mass, length))
    }

    /// A point mass (inertia 0).
    #[staticmethod]
    fn point_mass(name: &str, mass: f64) -> Self {
        PlanarBody(bondmech::PlanarBody::point_mass(name, mass))
    }

    /// The same body with moment of inertia `inertia`.
    fn inertia(&self, inertia: f64) -> Self {
        PlanarBody(self.0.clone().inertia(inertia))
    }

    /// The same body with a named point at body coordinates `coords`.
    fn point(&self, name: &str, coords: [f64; 2]) -> Self {
        PlanarBody(self.0.clone().point(name, coords))
    }

    /// The same body with its centre of mass at `position` (global) and angle `angle` (rad).
    #[pyo3(signature = (position, angle = 0.0))]
    fn at(&self, position: [f64; 2], angle: f64) -> Self {
        PlanarBody(self.0.clone().at(position, angle))
    }

    /// Initial velocity of the centre of mass (global frame).
    fn velocity(&self, velocity: [f64; 2]) -> Self {
        PlanarBody(self.0.clone().velocity(velocity))
    }

    /// Initial angular velocity (rad/s).
    fn angular_velocity(&self, omega: f64) -> Self {
        PlanarBody(self.0.clone().angular_velocity(omega))
    }

    /// The frame its equations are written in: `"inertial"` (seed 16.8, default) or `"body"`.
    fn frame(&self, name: &str) -> PyResult<Self> {
        Ok(PlanarBody(self.0.clone().frame(frame(name)?)))
    }
}

/// A spatial rigid body (seed 16.1–16.2): mass, principal moments of inertia, named points,
/// initial position, Cardan angles and velocities.
#[pyclass(module = "bondmech", name = "SpatialBody", frozen)]
#[derive(Clone)]
pub struct SpatialBody(bondmech::SpatialBody);

#[pymethods]
impl SpatialBody {
    /// A body of mass `mass` and principal moments `principal_inertia` = [Jx, Jy, Jz].
    #[new]
    fn new(name: &str, mass: f64, principal_inertia: [f64; 3]) -> Self {
        SpatialBody(bondmech::SpatialBody::new(name, mass, principal_inertia))
    }

    /// The same body with a named point at body coordinates `coords`.
    fn point(&self, name: &str, coords: [f64; 3]) -> Self {
        SpatialBody(self.0.clone().point(name, coords))
    }

    /// Initial position (global) and Cardan angles [ψ, θ, φ] (rad).
    #[pyo3(signature = (position, cardan = [0.0, 0.0, 0.0]))]
    fn at(&self, position: [f64; 3], cardan: [f64; 3]) -> Self {
        SpatialBody(self.0.clone().at(position, cardan))
    }

    /// Initial velocity of the centre of mass (global frame).
    fn velocity(&self, velocity: [f64; 3]) -> Self {
        SpatialBody(self.0.clone().velocity(velocity))
    }

    /// Initial angular velocity (body frame).
    fn angular_velocity(&self, omega: [f64; 3]) -> Self {
        SpatialBody(self.0.clone().angular_velocity(omega))
    }

    /// `"inertial"` (default) or `"body"`.
    fn frame(&self, name: &str) -> PyResult<Self> {
        Ok(SpatialBody(self.0.clone().frame(frame(name)?)))
    }
}

/// One end of a joint, spring or force: a body and a point on it (see `Ground.at`).
#[pyclass(module = "bondmech", name = "Endpoint", frozen)]
#[derive(Clone)]
pub struct Endpoint(bondmech::Endpoint);

#[pymethods]
impl Endpoint {
    /// The body's name (`"ground"` for the fixed body).
    #[getter]
    fn body(&self) -> String {
        self.0.body.clone()
    }

    fn __repr__(&self) -> String {
        match &self.0.point {
            None => format!("Endpoint({:?})", self.0.body),
            Some(PointRef::Named(p)) => format!("Endpoint({:?}, {p:?})", self.0.body),
            Some(PointRef::Coords(c)) => format!("Endpoint({:?}, {c:?})", self.0.body),
        }
    }
}

/// The fixed body: `Ground.at([x, y])` is a ground point (global coordinates).
#[pyclass(module = "bondmech", name = "Ground", frozen)]
pub struct Ground;

#[pymethods]
impl Ground {
    /// The ground point at global coordinates `coords` (2 or 3 of them).
    #[staticmethod]
    fn at(coords: Vec<f64>) -> Endpoint {
        Endpoint(bondmech::Endpoint {
            body: bondmech::scene::GROUND.to_string(),
            point: Some(PointRef::Coords(coords)),
        })
    }
}

/// `("body", "P")`, `("body", [x, y])`, `"body"` or an `Endpoint`.
fn endpoint(obj: &Bound<'_, PyAny>) -> PyResult<bondmech::Endpoint> {
    if let Ok(e) = obj.cast::<Endpoint>() {
        return Ok(e.get().0.clone());
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(bondmech::Endpoint {
            body: s.extract::<String>()?,
            point: None,
        });
    }
    if let Ok(t) = obj.cast::<PyTuple>() {
        if t.len() == 2 {
            let body: String = t.get_item(0)?.extract()?;
            let p = t.get_item(1)?;
            let point = if let Ok(name) = p.extract::<String>() {
                PointRef::Named(name)
            } else {
                PointRef::Coords(p.extract::<Vec<f64>>()?)
            };
            return Ok(bondmech::Endpoint {
                body,
                point: Some(point),
            });
        }
    }
    Err(type_error(
        "an end is (\"body\", \"P\"), (\"body\", [x, y]), \"body\" or Ground.at([x, y])",
        obj,
    ))
}

/// A point-to-point spring-damper: `F = k (ℓ − ℓ₀) + c ℓ'` along the line between its ends.
#[pyclass(module = "bondmech", name = "SpringDamper", frozen)]
#[derive(Clone)]
pub struct SpringDamper(bondmech::SpringDamper);

#[pymethods]
impl SpringDamper {
    /// A spring of stiffness `stiffness` (N/m) between ends `a` and `b`; its rest length is the
    /// initial distance unless set.
    #[new]
    fn new(
        name: &str,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        stiffness: f64,
    ) -> PyResult<Self> {
        Ok(SpringDamper(bondmech::SpringDamper::new(
            name,
            endpoint(a)?,
            endpoint(b)?,
            stiffness,
        )))
    }

    /// The same spring with rest length `rest_length` (m).
    fn rest_length(&self, rest_length: f64) -> Self {
        SpringDamper(self.0.clone().rest_length(rest_length))
    }

    /// The same spring with damping `damping` (N s/m).
    fn damping(&self, damping: f64) -> Self {
        SpringDamper(self.0.clone().damping(damping))
    }
}

/// A load's value: a number or list of numbers (constant), an expression string or list of
/// them (in `t` and the scene's outputs), or `{"t": [...], "v": [...]}` (piecewise linear).
fn load_value(obj: &Bound<'_, PyAny>) -> PyResult<LoadValue> {
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(LoadValue::Const(vec![x]));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(LoadValue::Expr(vec![s.extract::<String>()?]));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let table = match d.get_item("table")? {
            Some(t) => t.cast_into::<PyDict>()?,
            None => d.clone(),
        };
        let (Some(t), Some(v)) = (table.get_item("t")?, table.get_item("v")?) else {
            return Err(PyValueError::new_err(
                "a table load is {\"t\": [...], \"v\": [...]}",
            ));
        };
        let t: Vec<f64> = t.extract()?;
        let mut rows = Vec::new();
        for item in v.try_iter()? {
            let item = item?;
            rows.push(match item.extract::<f64>() {
                Ok(x) => vec![x],
                Err(_) => item.extract::<Vec<f64>>()?,
            });
        }
        return Ok(LoadValue::table(t, rows));
    }
    if let Ok(seq) = obj.cast::<PySequence>() {
        if let Ok(c) = seq.extract::<Vec<f64>>() {
            return Ok(LoadValue::Const(c));
        }
        let mut parts = Vec::new();
        for item in obj.try_iter()? {
            let item = item?;
            parts.push(match item.extract::<f64>() {
                Ok(x) => format!("{x:?}"),
                Err(_) => item.extract::<String>()?,
            });
        }
        return Ok(LoadValue::Expr(parts));
    }
    Err(type_error(
        "a load value is a number, a list of numbers, an expression string (or a list of them) or {\"t\": [...], \"v\": [...]}",
        obj,
    ))
}

/// A mechanism built in code: bodies, joints, springs, loads and solver settings, turned into
/// a `Scene` by `build()` (validated like a scene file). Every method returns a new Mechanism.
///
/// ```python
/// scene = (Mechanism.planar().gravity([0, -9.81])
///          .body(PlanarBody.bar("bar1", 1.0, 1.0).at([0.5, 0.0]))
///          .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
///          .t_end(1.0).build())
/// ```
#[pyclass(module = "bondmech", name = "Mechanism", frozen)]
#[derive(Clone)]
pub struct Mechanism(bondmech::Mechanism);

impl Mechanism {
    fn with(&self, f: impl FnOnce(bondmech::Mechanism) -> bondmech::Mechanism) -> Self {
        Mechanism(f(self.0.clone()))
    }
}

#[pymethods]
impl Mechanism {
    /// An empty planar mechanism (dimension 2).
    #[staticmethod]
    fn planar() -> Self {
        Mechanism(bondmech::Mechanism::planar())
    }

    /// An empty spatial mechanism (dimension 3).
    #[staticmethod]
    fn spatial() -> Self {
        Mechanism(bondmech::Mechanism::spatial())
    }

    /// The scene's name.
    fn name(&self, name: &str) -> Self {
        self.with(|m| m.name(name))
    }

    /// The scene's description.
    fn description(&self, text: &str) -> Self {
        self.with(|m| m.description(text))
    }

    /// Gravity (m/s², 2 or 3 components).
    fn gravity(&self, g: Vec<f64>) -> PyResult<Self> {
        match g[..] {
            [x, y] => Ok(self.with(|m| m.gravity([x, y]))),
            [x, y, z] => Ok(self.with(|m| m.gravity([x, y, z]))),
            _ => Err(PyValueError::new_err(format!(
                "gravity: 2 or 3 components (got {})",
                g.len()
            ))),
        }
    }

    /// Adds a body (`PlanarBody` or `SpatialBody`).
    fn body(&self, body: &Bound<'_, PyAny>) -> PyResult<Self> {
        if let Ok(b) = body.cast::<PlanarBody>() {
            let b = b.get().0.clone();
            return Ok(self.with(|m| m.body(b)));
        }
        if let Ok(b) = body.cast::<SpatialBody>() {
            let b = b.get().0.clone();
            return Ok(self.with(|m| m.body(b)));
        }
        Err(type_error("body: a PlanarBody or a SpatialBody", body))
    }

    /// A revolute joint (planar pin) between ends `a` and `b`.
    fn revolute(&self, name: &str, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (a, b) = (endpoint(a)?, endpoint(b)?);
        Ok(self.with(|m| m.revolute(name, a, b)))
    }

    /// A prismatic joint (slider) along `axis` (in the first body's frame).
    fn prismatic(
        &self,
        name: &str,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        axis: Vec<f64>,
    ) -> PyResult<Self> {
        let (a, b) = (endpoint(a)?, endpoint(b)?);
        match axis[..] {
            [x, y] => Ok(self.with(|m| m.prismatic(name, a, b, [x, y]))),
            [x, y, z] => Ok(self.with(|m| m.prismatic(name, a, b, [x, y, z]))),
            _ => Err(PyValueError::new_err(format!(
                "prismatic axis: 2 or 3 components (got {})",
                axis.len()
            ))),
        }
    }

    /// A spherical joint (3D ball joint).
    fn spherical(&self, name: &str, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (a, b) = (endpoint(a)?, endpoint(b)?);
        Ok(self.with(|m| m.spherical(name, a, b)))
    }

    /// A hinge (3D revolute joint) about `axis` (in the first body's frame).
    fn hinge(
        &self,
        name: &str,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        axis: [f64; 3],
    ) -> PyResult<Self> {
        let (a, b) = (endpoint(a)?, endpoint(b)?);
        Ok(self.with(|m| m.hinge(name, a, b, axis)))
    }

    /// A weld (fixed joint).
    fn weld(&self, name: &str, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (a, b) = (endpoint(a)?, endpoint(b)?);
        Ok(self.with(|m| m.weld(name, a, b)))
    }

    /// Adds a spring-damper.
    fn spring(&self, spring: PyRef<'_, SpringDamper>) -> Self {
        let s = spring.0.clone();
        self.with(|m| m.spring(s))
    }

    /// A force applied at end `at` (global frame): a constant, an expression, or a table.
    fn force(&self, name: &str, at: &Bound<'_, PyAny>, value: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (at, value) = (endpoint(at)?, load_value(value)?);
        Ok(self.with(|m| m.force(name, at, value)))
    }

    /// A torque on `body`.
    fn torque(&self, name: &str, body: &str, value: &Bound<'_, PyAny>) -> PyResult<Self> {
        let value = load_value(value)?;
        Ok(self.with(|m| m.torque(name, body, value)))
    }

    /// Asks for an extra output column (`bar2.A`, `energy`, `reactions`, …).
    fn output(&self, output: &str) -> Self {
        self.with(|m| m.output(output))
    }

    /// An event: a zero crossing of `when` (`direction`: rising, falling or both; `action`:
    /// record or stop).
    #[pyo3(signature = (name, when, direction = "both", action = "record"))]
    fn event(&self, name: &str, when: &str, direction: &str, action: &str) -> PyResult<Self> {
        let direction = match direction {
            "rising" => EventDirection::Rising,
            "falling" => EventDirection::Falling,
            "both" => EventDirection::Both,
            d => {
                return Err(PyValueError::new_err(format!(
                    "direction='{d}': expected rising, falling or both"
                )))
            }
        };
        let action = match action {
            "stop" => EventAction::Stop,
            "record" => EventAction::Record,
            a => {
                return Err(PyValueError::new_err(format!(
                    "action='{a}': expected stop or record"
                )))
            }
        };
        Ok(self.with(|m| m.event(name, when, direction, action)))
    }

    /// End time (s); required.
    fn t_end(&self, t_end: f64) -> Self {
        self.with(|m| m.t_end(t_end))
    }

    /// Output step (s); default t_end / 100.
    fn output_step(&self, step: f64) -> Self {
        self.with(|m| m.output_step(step))
    }

    /// Relative and absolute tolerances.
    fn tolerances(&self, rtol: f64, atol: f64) -> Self {
        self.with(|m| m.tolerances(rtol, atol))
    }

    /// The default formulation (`dae`, `ggl`, `compliant_ggl`, `index1`, `partitioned`,
    /// `decoupled`).
    fn formulation(&self, name: &str) -> PyResult<Self> {
        let f = FormulationKind::parse(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "formulation='{name}': expected dae, ggl, compliant_ggl, index1, partitioned or decoupled"
            ))
        })?;
        Ok(self.with(|m| m.formulation(f)))
    }

    /// The scene, validated like a scene file (raises `SceneError` naming each bad element).
    fn build(&self, py: Python<'_>) -> PyResult<Scene> {
        let scene = self.0.clone().build().py(py)?;
        Ok(Scene::from_scene(scene))
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Mechanism>()?;
    m.add_class::<PlanarBody>()?;
    m.add_class::<SpatialBody>()?;
    m.add_class::<Endpoint>()?;
    m.add_class::<Ground>()?;
    m.add_class::<SpringDamper>()?;
    Ok(())
}
