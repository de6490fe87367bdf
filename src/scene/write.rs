//! Writing a scene back to JSON (format v1), keeping the order of named points.
//!
//! `Scene` implements `serde::Serialize` through an order-preserving tree, so
//! parse → serialize → parse gives back an equal `Scene`. Every setting is
//! written explicitly (defaults included); optional settings that are absent
//! stay absent.

use super::model::*;
use super::tree::Json;
use serde::{Serialize, Serializer};

fn num(x: f64) -> Json {
    Json::Number(x)
}

fn nums(v: &[f64]) -> Json {
    Json::Array(v.iter().copied().map(num).collect())
}

fn text(s: &str) -> Json {
    Json::String(s.to_string())
}

fn obj(entries: Vec<(&str, Json)>) -> Json {
    Json::Object(
        entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
    )
}

fn point_ref(p: &PointRef) -> Json {
    match p {
        PointRef::Named(n) => text(n),
        PointRef::Coords(c) => nums(c),
    }
}

fn body(b: &Body, dim: Dimension) -> Json {
    let mut e = vec![
        ("name", text(&b.name)),
        ("mass", num(b.mass)),
        (
            "inertia",
            match b.inertia {
                Inertia::Planar(j) => num(j),
                Inertia::Principal(js) => nums(&js),
            },
        ),
        (
            "frame",
            text(match b.frame {
                BodyFrame::Inertial => "inertial",
                BodyFrame::BodyFixed => "body",
            }),
        ),
        (
            "points",
            Json::Object(b.points.iter().map(|(n, c)| (n.clone(), nums(c))).collect()),
        ),
        ("position", nums(&b.position)),
    ];
    match dim {
        Dimension::Planar => e.push(("angle", num(b.angle))),
        Dimension::Spatial => e.push(("cardan", nums(&b.cardan))),
    }
    // what the scene left out stays out (the initial projection treats a given velocity as
    // the user's and changes the others first)
    if b.velocity_given {
        e.push(("velocity", nums(&b.velocity)));
    }
    if b.angular_velocity_given {
        let w = match (dim, b.angular_velocity.as_slice()) {
            (Dimension::Planar, [w]) => num(*w),
            (_, w) => nums(w),
        };
        e.push(("angular_velocity", w));
    }
    obj(e)
}

fn joint(j: &Joint) -> Json {
    let mut e = vec![("name", text(&j.name))];
    e.push(("type", text(j.kind.type_name())));
    e.push((
        "bodies",
        Json::Array(j.bodies.iter().map(|b| text(b)).collect()),
    ));
    if super::joint_kind::has_points(j.kind.type_name()) {
        e.push((
            "points",
            Json::Array(j.points.iter().map(point_ref).collect()),
        ));
    }
    j.kind.write(&mut e);
    obj(e)
}

fn spring(s: &Spring) -> Json {
    let mut e = vec![
        ("name", text(&s.name)),
        (
            "bodies",
            Json::Array(s.bodies.iter().map(|b| text(b)).collect()),
        ),
        (
            "points",
            Json::Array(s.points.iter().map(point_ref).collect()),
        ),
        ("stiffness", num(s.stiffness)),
    ];
    if let Some(l0) = s.rest_length {
        e.push(("rest_length", num(l0)));
    }
    e.push(("damping", num(s.damping)));
    obj(e)
}

/// A value with one component is written as a scalar.
fn components(v: &[f64]) -> Json {
    match v {
        [x] => num(*x),
        _ => nums(v),
    }
}

fn load(l: &Load) -> Json {
    let mut e = vec![
        ("name", text(&l.name)),
        (
            "type",
            text(match l.kind {
                LoadKind::Force => "force",
                LoadKind::Torque => "torque",
            }),
        ),
        ("body", text(&l.body)),
    ];
    if let Some(p) = &l.point {
        e.push(("point", point_ref(p)));
    }
    let value = match &l.value {
        LoadValue::Const(v) if l.kind == LoadKind::Torque => components(v),
        LoadValue::Const(v) => nums(v),
        LoadValue::Expr(x) if x.len() == 1 && l.kind == LoadKind::Torque => text(&x[0]),
        LoadValue::Expr(x) => Json::Array(x.iter().map(|s| text(s)).collect()),
        LoadValue::Table { t, v } => obj(vec![(
            "table",
            obj(vec![
                ("t", nums(t)),
                (
                    "v",
                    Json::Array(v.iter().map(|row| components(row)).collect()),
                ),
            ]),
        )]),
    };
    e.push(("value", value));
    obj(e)
}

fn solve(s: &SolveSettings) -> Json {
    let mut e = vec![
        ("formulation", text(s.formulation.name())),
        ("t_end", num(s.t_end)),
    ];
    if s.t_start != 0.0 {
        e.insert(1, ("t_start", num(s.t_start)));
    }
    if let Some(h) = s.output_step {
        e.push(("output_step", num(h)));
    }
    if let Some(t) = &s.output_times {
        e.push(("output_times", nums(t)));
    }
    e.push(("rtol", num(s.rtol)));
    e.push(("atol", num(s.atol)));
    e.push(("joint_stiffness", num(s.joint_stiffness)));
    e.push(("joint_damping", num(s.joint_damping)));
    if let Some(n) = s.max_steps {
        e.push(("max_steps", num(n as f64)));
    }
    if let Some(w) = s.max_wall_seconds {
        e.push(("max_wall_seconds", num(w)));
    }
    if s.linear_solver != crate::settings::LinearSolverKind::Auto {
        e.push(("linear_solver", text(s.linear_solver.name())));
    }
    if s.integrator != crate::settings::Integrator::Auto {
        e.push(("integrator", text(s.integrator.name())));
    }
    if !s.switching_functions {
        e.push(("switching_functions", Json::Bool(false)));
    }
    if s.start_at_equilibrium {
        e.push(("start", text("equilibrium")));
    }
    if let Some(k) = s.energy_invariant {
        e.push(("energy_invariant", text(if k { "always" } else { "never" })));
    }
    obj(e)
}

/// The scene as an order-preserving JSON tree.
pub(crate) fn scene_tree(s: &Scene) -> Json {
    let dim = s.dimension;
    let mut e = vec![("name", text(&s.name))];
    if let Some(d) = &s.description {
        e.push(("description", text(d)));
    }
    e.push(("dimension", num(dim.coords() as f64)));
    e.push(("gravity", nums(&s.gravity)));
    e.push((
        "bodies",
        Json::Array(s.bodies.iter().map(|b| body(b, dim)).collect()),
    ));
    e.push(("joints", Json::Array(s.joints.iter().map(joint).collect())));
    e.push((
        "springs",
        Json::Array(s.springs.iter().map(spring).collect()),
    ));
    e.push(("loads", Json::Array(s.loads.iter().map(load).collect())));
    e.push(("solve", solve(&s.solve)));
    e.push((
        "outputs",
        Json::Array(s.outputs.iter().map(|o| text(o)).collect()),
    ));
    if !s.inputs.is_empty() {
        e.push((
            "inputs",
            Json::Array(
                s.inputs
                    .iter()
                    .map(|u| {
                        let mut fields = vec![("name", text(&u.name)), ("start", num(u.start))];
                        if let Some(unit) = &u.unit {
                            fields.push(("unit", text(unit)));
                        }
                        obj(fields)
                    })
                    .collect(),
            ),
        ));
    }
    if !s.events.is_empty() {
        e.push((
            "events",
            Json::Array(
                s.events
                    .iter()
                    .map(|ev| {
                        obj(vec![
                            ("name", text(&ev.name)),
                            ("when", text(&ev.when)),
                            ("direction", text(ev.direction.as_str())),
                            ("action", text(ev.action.as_str())),
                        ])
                    })
                    .collect(),
            ),
        ));
    }
    if !s.drivers.is_empty() {
        e.push((
            "drivers",
            Json::Array(
                s.drivers
                    .iter()
                    .map(|d| {
                        obj(vec![
                            ("name", text(&d.name)),
                            ("joint", text(&d.joint)),
                            (d.kind.key(), text(&d.value)),
                        ])
                    })
                    .collect(),
            ),
        ));
    }
    if let Some(g) = &s.bond_graph {
        e.push(("bond_graph", Json::from_value(g)));
    }
    obj(e)
}

impl Serialize for Scene {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        scene_tree(self).serialize(serializer)
    }
}
