//! Scene → bond graph, with the chapter's fragments (`crate::bond::fragments`).
//!
//! The drawing and the causality report of a mechanism: planar bodies in the frame the scene
//! asks for (16.3 or 16.8), joints as the 1-junctions that equate point velocities (16.5) or as
//! zero flow sources to ground (16.7), the piston's slider (Fig. 29), springs and dampers along
//! the global axes, loads as effort sources. Joints, springs and forces meet body-fixed bars
//! (16.3) through the frame change of 16.4 (an MTF pair modulated by the relative angle
//! between two body-fixed bars, or by −α towards the global frame), so their 1-junctions
//! always equate components along the same axes. The *decoupled* variant (16.6, Fig. 17–18, 21)
//! is not drawn here: it is the complete pinned graph with every constraint junction opened
//! and a spring put in ([`crate::bond::decouple`]), exactly what CVODE solves.
//!
//! A spatial scene's graph is not drawn here: [`crate::mech::annotate`] builds it whole (the
//! global `V` and body `ω` junctions of 16.1 with the Euler junction structure, the attitude
//! quaternion carried by MTFs, one modulated sum per constraint row), and
//! [`crate::mech::scene_bond_graph`] returns that complete graph.
//!
//! The inertias that causality assignment forces into differential causality here are the ones whose flows
//! the joints impose: one per independent constraint row of the multibody system.

use std::collections::HashMap;

use crate::bond::fragments::{
    change_frame, force, planar_body_fixed_frame, planar_body_translating, spring_damper, torque,
    Axis, PlanarBody, PlanarBodySpec, PointJunctions,
};
use crate::bond::model::{BondGraph, Parameter};
use crate::scene::{BodyFrame, Inertia, LoadKind, LoadValue, PointRef, Scene};

use super::error::MechError;
use super::joints::{common_frame, Drawing};

/// [`super::scene_bond_graph`]'s drawing; with `open` the planar pinned graph leaves out what
/// [`crate::mech::annotate`] adds from the joints' closures: prismatic joints, a weld's
/// angle row and springs of non-zero rest length.
pub(crate) fn scene_bond_graph_with(scene: &Scene, open: bool) -> Result<BondGraph, MechError> {
    let mut g = planar(scene, open)?;
    g.annotate_joints(scene.joints.iter().map(|j| j.name.as_str()));
    Ok(g)
}

/// Rest length of a planar spring: its `rest_length`, or its initial length.
pub(crate) fn planar_rest_length(scene: &Scene, si: usize) -> f64 {
    let s = &scene.springs[si];
    if let Some(l) = s.rest_length {
        return l;
    }
    let at = |k: usize| -> [f64; 2] {
        let c: Vec<f64> = match &s.points[k] {
            PointRef::Coords(c) => c.clone(),
            PointRef::Named(n) => scene
                .bodies
                .iter()
                .find(|b| b.name == s.bodies[k])
                .and_then(|b| b.points.iter().find(|(pn, _)| pn == n))
                .map(|(_, c)| c.clone())
                .unwrap_or_default(),
        };
        let (cx, cy) = (
            c.first().copied().unwrap_or(0.0),
            c.get(1).copied().unwrap_or(0.0),
        );
        match scene.bodies.iter().find(|b| b.name == s.bodies[k]) {
            None => [cx, cy],
            Some(b) => {
                let (sn, cs) = b.angle.sin_cos();
                let p = |i: usize| b.position.get(i).copied().unwrap_or(0.0);
                [p(0) + cs * cx - sn * cy, p(1) + sn * cx + cs * cy]
            }
        }
    };
    let (a, b) = (at(0), at(1));
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
}

/// The bond graph of a planar scene (seed 16.3–16.8).
fn planar(scene: &Scene, open: bool) -> Result<BondGraph, MechError> {
    let mut g = BondGraph::default();
    let gy = -scene.gravity.get(1).copied().unwrap_or(0.0);
    // points each body needs: its named points plus coordinate points used by joints, springs
    // and loads (named `<joint>.<k>` etc.)
    let mut extra: HashMap<String, Vec<(String, f64, f64)>> = HashMap::new();
    let mut refname = |body: &str, p: &PointRef, tag: String| -> String {
        match p {
            PointRef::Named(n) => n.clone(),
            PointRef::Coords(c) => {
                if body != "ground" {
                    extra.entry(body.to_string()).or_default().push((
                        tag.clone(),
                        c[0],
                        c.get(1).copied().unwrap_or(0.0),
                    ));
                }
                tag
            }
        }
    };
    let joint_points: Vec<[String; 2]> = scene
        .joints
        .iter()
        .map(|j| [0, 1].map(|k| refname(&j.bodies[k], &j.points[k], format!("{}_{k}", j.name))))
        .collect();
    let spring_points: Vec<[String; 2]> = scene
        .springs
        .iter()
        .map(|s| [0, 1].map(|k| refname(&s.bodies[k], &s.points[k], format!("{}_{k}", s.name))))
        .collect();
    let load_points: Vec<Option<String>> = scene
        .loads
        .iter()
        .map(|l| {
            l.point
                .as_ref()
                .map(|p| refname(&l.body, p, format!("{}_p", l.name)))
        })
        .collect();
    // which bodies' rotations are modelled: decided once, by the layout that gives them their
    // coordinates (an angle for a spinning or welded point mass too)
    let plans = super::coordinates::Geometry::new(scene).plan()?;
    let rotates: HashMap<&str, bool> = scene
        .bodies
        .iter()
        .zip(&plans)
        .map(|(b, plan)| {
            let angle = matches!(plan, super::layout::Plan::Planar { angle: true, .. });
            (b.name.as_str(), angle)
        })
        .collect();
    let mut bodies: HashMap<String, PlanarBody> = HashMap::new();
    for b in &scene.bodies {
        let j = match b.inertia {
            Inertia::Planar(j) => j,
            Inertia::Principal(j) => j[2],
        };
        let mut points: Vec<(String, f64, f64)> = b
            .points
            .iter()
            .map(|(n, c)| (n.clone(), c[0], c.get(1).copied().unwrap_or(0.0)))
            .collect();
        let centre_load = scene
            .loads
            .iter()
            .any(|l| l.body == b.name && l.point.is_none() && matches!(l.kind, LoadKind::Force));
        if centre_load {
            points.push(("cm".into(), 0.0, 0.0));
        }
        points.extend(extra.get(&b.name).cloned().unwrap_or_default());
        let spec = PlanarBodySpec {
            name: b.name.clone(),
            mass: b.mass,
            inertia: j,
            gravity: gy,
            points,
            rotation: rotates.get(b.name.as_str()).copied().unwrap_or(false),
        };
        let pb = match b.frame {
            BodyFrame::BodyFixed => planar_body_fixed_frame(&mut g, &spec),
            BodyFrame::Inertial => planar_body_translating(&mut g, &spec),
        };
        bodies.insert(b.name.clone(), pb);
    }
    let point = |body: &str, name: &str, path: &str| -> Result<Option<PointJunctions>, MechError> {
        if body == "ground" {
            return Ok(None);
        }
        let b = bodies
            .get(body)
            .ok_or_else(|| MechError::at(path, format!("unknown body '{body}'")))?;
        b.point(name)
            .cloned()
            .map(Some)
            .ok_or_else(|| MechError::at(path, format!("body '{body}' has no point '{name}'")))
    };
    let omega = |body: &str| {
        bodies
            .get(body)
            .filter(|_| rotates.get(body).copied().unwrap_or(false))
            .map(|b| b.omega)
    };
    // the solver's graph writes the joints of body-fixed bars as modulated sums of the bodies'
    // flows in the global axes (crate::mech::annotate), where their closures live
    let body_fixed = scene
        .bodies
        .iter()
        .any(|b| matches!(b.frame, BodyFrame::BodyFixed));
    for (ji, j) in scene.joints.iter().enumerate() {
        if open && body_fixed {
            continue;
        }
        let path = format!("joints[{ji}]");
        let points = [
            point(&j.bodies[0], &joint_points[ji][0], &path)?,
            point(&j.bodies[1], &joint_points[ji][1], &path)?,
        ];
        let mut d = Drawing {
            g: &mut g,
            name: &j.name,
            path: &path,
            bodies: [&j.bodies[0], &j.bodies[1]],
            points,
            frames: [0, 1].map(|k| body_fixed_angle(scene, &j.bodies[k])),
            omegas: [0, 1].map(|k| omega(&j.bodies[k])),
            open,
        };
        d.draw(&j.kind)?;
    }
    // drivers: the joint's relative flow on a 1-junction `<driver>.rate`, prescribed by the
    // flow source `Sf <driver> = ṡ(t)` (the solver's graph gets it from
    // crate::mech::annotate, with the driver's closure)
    for (di, d) in scene.drivers.iter().enumerate() {
        if open {
            break;
        }
        let (ji, j) = super::geometry::driven_joint(scene, di)?;
        let terms: Vec<(crate::bond::model::ElementId, String)> = if d.kind.is_rotation() {
            [(1, "1"), (0, "-1")]
                .into_iter()
                .filter_map(|(k, m)| omega(&j.bodies[k]).map(|w| (w, m.to_string())))
                .collect()
        } else {
            let axis =
                match &j.kind {
                    crate::scene::JointKind::Prismatic(k) if k.axis[0].abs() < 1e-12 => Axis::Y,
                    crate::scene::JointKind::Prismatic(k) if k.axis[1].abs() < 1e-12 => Axis::X,
                    _ => return Err(MechError::at(
                        &format!("joints[{ji}].axis"),
                        "the bond graph drawing supports driven sliders along a global axis only",
                    )),
                };
            let jp = format!("joints[{ji}]");
            let pa = point(&j.bodies[0], &joint_points[ji][0], &jp)?;
            let pb = point(&j.bodies[1], &joint_points[ji][1], &jp)?;
            let (pa, pb) = common_frame(
                &mut g,
                &d.name,
                [&j.bodies[0], &j.bodies[1]],
                [pa, pb],
                [0, 1].map(|k| body_fixed_angle(scene, &j.bodies[k])),
                true,
            );
            [(pb, "1"), (pa, "-1")]
                .into_iter()
                .filter_map(|(p, m)| p.map(|p| (p.axis(axis), m.to_string())))
                .collect()
        };
        let sum =
            crate::bond::fragments::modulated_sum(&mut g, &format!("{}.{}", d.name, "rel"), &terms);
        let v = g.add_junction(
            format!("{}.rate", d.name),
            crate::bond::model::ElementKind::One,
        );
        g.add_bond(sum, v);
        let sf = g.add_element(
            d.name.clone(),
            crate::bond::model::ElementKind::Sf,
            Some(Parameter::Expr(driver_rate_text(d))),
        );
        g.add_bond(v, sf);
    }
    for (si, s) in scene.springs.iter().enumerate() {
        if open && planar_rest_length(scene, si) != 0.0 {
            continue;
        }
        let path = format!("springs[{si}]");
        let pa = point(&s.bodies[0], &spring_points[si][0], &path)?;
        let pb = point(&s.bodies[1], &spring_points[si][1], &path)?;
        // springs act along the global axes
        let (pa, pb) = common_frame(
            &mut g,
            &s.name,
            [&s.bodies[0], &s.bodies[1]],
            [pa, pb],
            [0, 1].map(|k| body_fixed_angle(scene, &s.bodies[k])),
            true,
        );
        let (p1, p2) = match (&pa, &pb) {
            (Some(a), b) => (a, b.as_ref()),
            (None, Some(b)) => (b, None),
            (None, None) => continue,
        };
        let damp = (s.damping > 0.0).then_some(s.damping);
        // `<spring>.x.k`, `<spring>.x.c`, … (spring_damper names the axis)
        for ax in [Axis::X, Axis::Y] {
            spring_damper(&mut g, &s.name, p1, p2, ax, Some(s.stiffness), damp);
        }
    }
    for (li, l) in scene.loads.iter().enumerate() {
        let path = format!("loads[{li}]");
        let params = load_parameters(&l.value);
        // scene outputs used by a load expression (e.g. the gas force's `crank.angle`) are
        // external signals of the bond graph
        for p in &params {
            if let Parameter::Expr(e) = p {
                for v in crate::bond::identifiers::variables(e).unwrap_or_default() {
                    if v != "t" {
                        g.add_signal(v);
                    }
                }
            }
        }
        match l.kind {
            LoadKind::Force => {
                let name = load_points[li].clone().unwrap_or_else(|| "cm".into());
                let Some(p) = point(&l.body, &name, &path)? else {
                    continue;
                };
                // forces are given in the global frame
                let p = match body_fixed_angle(scene, &l.body) {
                    Some(a) => change_frame(
                        &mut g,
                        &format!("{}.{}.in_global", l.name, p.name),
                        &p,
                        &format!("-{a}"),
                    ),
                    None => p,
                };
                for (ax, prm) in [Axis::X, Axis::Y].into_iter().zip(params) {
                    let n = format!("{}.{}", l.name, if ax == Axis::X { "x" } else { "y" });
                    force(&mut g, &n, &p, ax, prm);
                }
            }
            LoadKind::Torque => {
                if let Some(w) = omega(&l.body) {
                    let prm = params.into_iter().next().unwrap_or(Parameter::Const(0.0));
                    torque(&mut g, &l.name, w, prm);
                }
            }
        }
    }
    Ok(g)
}

/// The prescribed rate `ṡ(t)` of a driver as expression text: its value for a rate driver,
/// the value's time derivative for an angle or displacement.
fn driver_rate_text(d: &crate::scene::Driver) -> String {
    if d.kind.is_rate() {
        return d.value.clone();
    }
    let mut eg = crate::expr::ExprGraph::new();
    let tv = eg.var(0);
    match eg.parse(&d.value, &mut |n: &str| (n == "t").then_some(tv)) {
        Ok(e) => {
            let r = eg.diff(e, 0);
            eg.display_exact(r, &|_| "t".to_string(), 100_000)
                .unwrap_or_else(|| format!("d/dt({})", d.value))
        }
        Err(_) => format!("d/dt({})", d.value),
    }
}

/// The angle variable `x_<body>.omega` of a planar body written in its body-fixed frame
/// (seed 16.3), None for a body in the non-rotating frame (16.8) or ground.
fn body_fixed_angle(scene: &Scene, body: &str) -> Option<String> {
    scene
        .bodies
        .iter()
        .find(|b| b.name == body && matches!(b.frame, BodyFrame::BodyFixed))
        .map(|b| crate::expr::quote_name(&format!("x_{}.omega", b.name)).into_owned())
}

pub(crate) fn load_parameters(v: &LoadValue) -> Vec<Parameter> {
    match v {
        LoadValue::Const(c) => c.iter().map(|&x| Parameter::Const(x)).collect(),
        LoadValue::Expr(e) => e.iter().map(|s| Parameter::Expr(s.clone())).collect(),
        LoadValue::Table { t, v } => {
            let n = v.first().map(|r| r.len()).unwrap_or(0);
            (0..n)
                .map(|k| Parameter::Table {
                    t: t.clone(),
                    v: v.iter().map(|r| r[k]).collect(),
                })
                .collect()
        }
    }
}
