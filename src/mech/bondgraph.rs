//! Scene → bond graph, with the chapter's fragments (`crate::bond::fragments`).
//!
//! The drawing and the causality report of a mechanism: planar bodies in the frame the scene
//! asks for (16.3 or 16.8), joints as the 1-junctions that equate point velocities (16.5) or as
//! zero flow sources to ground (16.7), the piston's slider (Fig. 29), springs and dampers along
//! the global axes, loads as effort sources. The *decoupled* variant replaces every joint by the
//! springs of 16.6 (Fig. 17–18, 21), so every inertia gets integral causality.
//!
//! The inertias that SCAP forces into differential causality here are the ones whose flows
//! the joints impose: one per independent constraint row of the multibody system.

use std::collections::HashMap;

use crate::bond::fragments::{
    decoupled_revolute, force, pin_to_ground, planar_body_fixed_frame, planar_body_translating,
    prismatic, revolute, rigid_body_3d, spring_damper, torque, weld, Axis, PlanarBody,
    PlanarBodySpec, PointJunctions, RigidBody3Spec,
};
use crate::bond::model::{BondGraph, Parameter};
use crate::scene::{
    BodyFrame, Dimension, Inertia, JointKind, LoadKind, LoadValue, PointRef, Scene,
};

use super::MechError;

/// Which variant of the mechanism to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// Joints kept: some inertias get differential causality (a DAE).
    Pinned,
    /// Joints replaced by stiff springs of this scene's `joint_stiffness` (an ODE).
    Decoupled,
}

/// Builds the bond graph of a scene.
pub fn scene_bond_graph(scene: &Scene, variant: Variant) -> Result<BondGraph, MechError> {
    if matches!(scene.dimension, Dimension::Spatial) {
        return spatial(scene);
    }
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
            .filter(|_| has_rotation(scene, body))
            .map(|b| b.omega)
    };
    let k = scene.solve.joint_stiffness;
    let c = (scene.solve.joint_damping > 0.0).then_some(scene.solve.joint_damping);
    for (ji, j) in scene.joints.iter().enumerate() {
        let path = format!("joints[{ji}]");
        let pa = point(&j.bodies[0], &joint_points[ji][0], &path)?;
        let pb = point(&j.bodies[1], &joint_points[ji][1], &path)?;
        // ground first, or second
        let (p1, p2, b1, b2) = match (&pa, &pb) {
            (None, Some(p)) => (p, None, &j.bodies[1], None),
            (Some(p), None) => (p, None, &j.bodies[0], None),
            (Some(a), Some(b)) => (a, Some(b), &j.bodies[0], Some(&j.bodies[1])),
            (None, None) => return Err(MechError::at(&path, "a joint between ground and ground")),
        };
        match (&j.kind, variant) {
            (JointKind::Revolute, Variant::Pinned) => match p2 {
                None => pin_to_ground(&mut g, &j.name, p1),
                Some(p2) => revolute(&mut g, &j.name, p1, p2),
            },
            (JointKind::Revolute, Variant::Decoupled)
            | (JointKind::Weld, Variant::Decoupled)
            | (JointKind::Prismatic { .. }, Variant::Decoupled) => {
                decoupled_revolute(&mut g, &j.name, p1, p2, k, c);
            }
            (JointKind::Weld, Variant::Pinned) => {
                let w1 = omega(b1).ok_or_else(|| {
                    MechError::at(&path, format!("weld: body '{b1}' has no modelled rotation"))
                })?;
                match (p2, b2) {
                    (Some(p2), Some(b2)) => {
                        let w2 = omega(b2).ok_or_else(|| {
                            MechError::at(
                                &path,
                                format!("weld: body '{b2}' has no modelled rotation"),
                            )
                        })?;
                        weld(&mut g, &j.name, (p1, w1), (p2, w2));
                    }
                    _ => {
                        pin_to_ground(&mut g, &j.name, p1);
                        prismatic(
                            &mut g,
                            &format!("{}.rot", j.name),
                            (p1, Some(w1)),
                            None,
                            Axis::X,
                        );
                    }
                }
            }
            (JointKind::Prismatic { axis }, Variant::Pinned) => {
                let ax = if axis[0].abs() < 1e-12 {
                    Axis::Y
                } else if axis[1].abs() < 1e-12 {
                    Axis::X
                } else {
                    return Err(MechError::at(
                        &format!("{path}.axis"),
                        "the bond graph drawing supports sliders along a global axis only",
                    ));
                };
                let w1 = omega(b1);
                let other = match (p2, b2) {
                    (Some(p2), Some(b2)) => Some((p2, omega(b2))),
                    _ => None,
                };
                prismatic(&mut g, &j.name, (p1, w1), other, ax);
            }
            (JointKind::Hinge { .. }, _) => {
                return Err(MechError::at(
                    &format!("{path}.axis"),
                    "a revolute joint with an axis (hinge) exists only in 3D scenes",
                ))
            }
            (JointKind::Spherical, _) => {
                return Err(MechError::at(
                    &format!("{path}.type"),
                    "spherical joints exist only in 3D scenes",
                ))
            }
        }
    }
    for (si, s) in scene.springs.iter().enumerate() {
        let path = format!("springs[{si}]");
        let pa = point(&s.bodies[0], &spring_points[si][0], &path)?;
        let pb = point(&s.bodies[1], &spring_points[si][1], &path)?;
        let (p1, p2) = match (&pa, &pb) {
            (Some(a), b) => (a, b.as_ref()),
            (None, Some(b)) => (b, None),
            (None, None) => continue,
        };
        let damp = (s.damping > 0.0).then_some(s.damping);
        for ax in [Axis::X, Axis::Y] {
            let n = format!("{}.{}", s.name, if ax == Axis::X { "x" } else { "y" });
            spring_damper(&mut g, &n, p1, p2, ax, Some(s.stiffness), damp);
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

fn has_rotation(scene: &Scene, body: &str) -> bool {
    scene.bodies.iter().any(|b| {
        b.name == body
            && (matches!(b.frame, BodyFrame::BodyFixed)
                || matches!(b.inertia, Inertia::Planar(j) if j > 0.0))
    })
}

fn load_parameters(v: &LoadValue) -> Vec<Parameter> {
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

fn spatial(scene: &Scene) -> Result<BondGraph, MechError> {
    if let Some((ji, _)) = scene.joints.iter().enumerate().next() {
        return Err(MechError::at(
            &format!("joints[{ji}]"),
            "the bond graph of jointed 3D mechanisms is not drawn yet (free 3D bodies are)",
        ));
    }
    let mut g = BondGraph::default();
    for b in &scene.bodies {
        let inertia = match b.inertia {
            Inertia::Principal(j) => j,
            Inertia::Planar(j) => [j; 3],
        };
        rigid_body_3d(
            &mut g,
            &RigidBody3Spec {
                name: b.name.clone(),
                mass: b.mass,
                inertia,
                rotation: None,
            },
        );
    }
    Ok(g)
}
