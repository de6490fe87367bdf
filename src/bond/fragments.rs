//! The seed chapter's constructions as builder functions appending to a [`BondGraph`].
//!
//! Orientation convention used throughout: power flows from a body's velocity junctions out
//! towards its points (`v_x → sum → P.v_x`), joints go from the first point to the second,
//! and external sources point into the junction they act on (`Se → P.v_x`). With this, an
//! effort source of value `F` at a point pushes the body with `+F`.
//!
//! Names are `<body>.<thing>`: `bar1.v_x`, `bar1.I_m_x`, `bar1.omega`, `bar1.A.v_x`, …
//! A body's angle is the expression variable `x_<body>.omega` (∫ of the ω junction's flow).

use super::model::{BondGraph, ElementId, ElementKind, Parameter};

/// A global (or body) axis of the plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// x direction.
    X,
    /// y direction.
    Y,
}

/// A point of a body: the 1-junctions whose common flows are its velocity components.
#[derive(Debug, Clone, PartialEq)]
pub struct PointJunctions {
    /// Full name (`bar1.A`).
    pub name: String,
    /// 1-junction of the x velocity.
    pub vx: ElementId,
    /// 1-junction of the y velocity.
    pub vy: ElementId,
}

impl PointJunctions {
    /// The junction of one axis.
    pub fn axis(&self, axis: Axis) -> ElementId {
        match axis {
            Axis::X => self.vx,
            Axis::Y => self.vy,
        }
    }
}

/// Parameters of a planar body.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarBodySpec {
    /// Body name (prefix of every element).
    pub name: String,
    /// Mass m.
    pub mass: f64,
    /// Moment of inertia J about the centre of mass (I:J omitted when 0 in the translating frame).
    pub inertia: f64,
    /// Gravity g (weight −m·g along global y); 0 for none.
    pub gravity: f64,
    /// Named points with body coordinates (a_x, a_y) from the centre of mass.
    pub points: Vec<(String, f64, f64)>,
    /// The rotation is modelled even where `J = 0` and every point is at the centre (a weld,
    /// a gear or a torque acts on it, or it starts spinning): the translating frame keeps
    /// I:J of value 0, its flow ω a velocity unknown fixed by the joints. Off-centre points
    /// imply it.
    pub rotation: bool,
}

/// Handles to a planar body's junctions.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarBody {
    /// Body name.
    pub name: String,
    /// 1-junction of v_x of the centre of mass.
    pub vx: ElementId,
    /// 1-junction of v_y of the centre of mass.
    pub vy: ElementId,
    /// 1-junction of the angular velocity ω.
    pub omega: ElementId,
    /// The inertias (I:m on v_x, I:m on v_y, I:J on ω when present).
    pub inertias: Vec<ElementId>,
    /// Expression variable of the body angle α.
    pub angle: String,
    /// The points, in the order given.
    pub points: Vec<PointJunctions>,
}

impl PlanarBody {
    /// The point with this (short) name.
    pub fn point(&self, name: &str) -> Option<&PointJunctions> {
        let full = format!("{}.{name}", self.name);
        self.points.iter().find(|p| p.name == full)
    }
}

/// Formats `Σ c_i·f_i` skipping zero coefficients; "0" when all vanish.
fn linear(terms: &[(f64, String)]) -> String {
    let mut s = String::new();
    for (c, f) in terms.iter().filter(|(c, _)| *c != 0.0) {
        if s.is_empty() {
            if *c < 0.0 {
                s.push('-');
            }
        } else if *c < 0.0 {
            s.push_str(" - ");
        } else {
            s.push_str(" + ");
        }
        s.push_str(&format!("{:?}*{f}", c.abs()));
    }
    if s.is_empty() {
        s.push('0');
    }
    s
}

fn label_of(expr: &str, angle: &str) -> String {
    expr.replace(angle, "α").replace('*', "·")
}

fn one_port(
    g: &mut BondGraph,
    name: String,
    kind: ElementKind,
    value: Parameter,
    junction: ElementId,
) -> ElementId {
    let e = g.add_element(name, kind, Some(value));
    if kind == ElementKind::Se || kind == ElementKind::Sf {
        g.add_bond(e, junction);
    } else {
        g.add_bond(junction, e);
    }
    e
}

fn body_core(g: &mut BondGraph, spec: &PlanarBodySpec, keep_zero_j: bool) -> PlanarBody {
    let n = &spec.name;
    let vx = g.add_junction(format!("{n}.v_x"), ElementKind::One);
    let mx = one_port(
        g,
        format!("{n}.I_m_x"),
        ElementKind::I,
        Parameter::Const(spec.mass),
        vx,
    );
    let vy = g.add_junction(format!("{n}.v_y"), ElementKind::One);
    let my = one_port(
        g,
        format!("{n}.I_m_y"),
        ElementKind::I,
        Parameter::Const(spec.mass),
        vy,
    );
    let omega = g.add_junction(format!("{n}.omega"), ElementKind::One);
    let mut inertias = vec![mx, my];
    if spec.inertia != 0.0 || keep_zero_j {
        inertias.push(one_port(
            g,
            format!("{n}.I_J"),
            ElementKind::I,
            Parameter::Const(spec.inertia),
            omega,
        ));
    }
    PlanarBody {
        name: n.clone(),
        vx,
        vy,
        omega,
        inertias,
        angle: crate::expr::quote_name(&format!("x_{n}.omega")).into_owned(),
        points: Vec::new(),
    }
}

/// Adds a point velocity `V_P = V_O + Σ (modulus_k · ω)` per axis: a 0-junction summing the
/// centre's flow and a (M)TF from ω, feeding the point's 1-junction.
fn add_point(
    g: &mut BondGraph,
    body: &mut PlanarBody,
    point: &str,
    moduli: [Option<Parameter>; 2],
    kind: ElementKind,
) {
    let n = format!("{}.{point}", body.name);
    let mut out = [ElementId(0); 2];
    for (k, (axis, centre)) in [("x", body.vx), ("y", body.vy)].into_iter().enumerate() {
        let sum = g.add_junction(format!("{n}.sum_{axis}"), ElementKind::Zero);
        g.add_bond(centre, sum);
        if let Some(m) = moduli[k].clone() {
            let label = match &m {
                Parameter::Expr(s) => Some(label_of(s, &body.angle)),
                _ => None,
            };
            let tf = g.add_element(format!("{n}.tf_{axis}"), kind, Some(m));
            if let Some(l) = label {
                g.set_label(tf, l);
            }
            g.add_bond(body.omega, tf);
            g.add_bond(tf, sum);
        }
        let v = g.add_junction(format!("{n}.v_{axis}"), ElementKind::One);
        g.add_bond(sum, v);
        out[k] = v;
    }
    body.points.push(PointJunctions {
        name: n,
        vx: out[0],
        vy: out[1],
    });
}

/// Planar body with a non-rotating frame at the centre of mass (seed 16.8, Fig. 22–25).
///
/// 1-junctions v_x, v_y, ω with I:m, I:m, I:J (I:J omitted when J = 0), the weight
/// Se = −m·g on v_y, and for each point P = (a_x, a_y) in body coordinates
/// `V_Px = V_Ox − ω·(a_x sinα + a_y cosα)`, `V_Py = V_Oy + ω·(a_x cosα − a_y sinα)`
/// through MTFs modulated by the body angle α = `x_<body>.omega`.
pub fn planar_body_translating(g: &mut BondGraph, spec: &PlanarBodySpec) -> PlanarBody {
    // a massless rotation still needs I:J (of value 0) when a point is off the centre or
    // something else acts on the rotation: its flow ω is then a velocity unknown fixed by the
    // joints
    let off_centre = spec
        .points
        .iter()
        .any(|(_, ax, ay)| *ax != 0.0 || *ay != 0.0);
    let mut body = body_core(g, spec, off_centre || spec.rotation);
    if spec.gravity != 0.0 {
        one_port(
            g,
            format!("{}.weight", spec.name),
            ElementKind::Se,
            Parameter::Const(-spec.mass * spec.gravity),
            body.vy,
        );
    }
    let a = body.angle.clone();
    let (s, c) = (format!("sin({a})"), format!("cos({a})"));
    for (p, ax, ay) in &spec.points {
        let moduli = if *ax == 0.0 && *ay == 0.0 {
            [None, None]
        } else {
            [
                Some(Parameter::Expr(linear(&[
                    (-ax, s.clone()),
                    (-ay, c.clone()),
                ]))),
                Some(Parameter::Expr(linear(&[
                    (*ax, c.clone()),
                    (-ay, s.clone()),
                ]))),
            ]
        };
        add_point(g, &mut body, p, moduli, ElementKind::MTF);
    }
    body
}

/// Planar body in its own body-fixed frame at the centre of mass (seed 16.3, Fig. 5–7).
///
/// I:m on v_x and v_y (body axes), I:J on ω, and the planar remnant of the Euler junction
/// structure: one MGY `v_y → v_x` with modulus m·ω = (m/J)·p_J, giving
/// `ṗ_x = F_x + m ω v_y`, `ṗ_y = F_y − m ω v_x`. The weight, when g ≠ 0, enters in body axes
/// as Se `−m g sinα` on v_x and `−m g cosα` on v_y. Points in body axes:
/// `V_Px = v_x − ω a_y`, `V_Py = v_y + ω a_x` (TFs, omitted when the arm is 0). Requires J > 0.
pub fn planar_body_fixed_frame(g: &mut BondGraph, spec: &PlanarBodySpec) -> PlanarBody {
    let mut body = body_core(g, spec, true);
    let n = &spec.name;
    let ratio = if spec.inertia != 0.0 {
        spec.mass / spec.inertia
    } else {
        f64::NAN
    };
    let mgy = g.add_element(
        format!("{n}.mgy"),
        ElementKind::MGY,
        Some(Parameter::Expr(format!(
            "{ratio:?}*{}",
            crate::expr::quote_name(&format!("p_{n}.I_J"))
        ))),
    );
    g.set_label(mgy, "m·ω");
    g.add_bond(body.vy, mgy);
    g.add_bond(mgy, body.vx);
    if spec.gravity != 0.0 {
        let w = spec.mass * spec.gravity;
        let a = body.angle.clone();
        one_port(
            g,
            format!("{n}.weight_x"),
            ElementKind::Se,
            Parameter::Expr(linear(&[(-w, format!("sin({a})"))])),
            body.vx,
        );
        one_port(
            g,
            format!("{n}.weight_y"),
            ElementKind::Se,
            Parameter::Expr(linear(&[(-w, format!("cos({a})"))])),
            body.vy,
        );
    }
    for (p, ax, ay) in &spec.points {
        let mx = (*ay != 0.0).then_some(Parameter::Const(-ay));
        let my = (*ax != 0.0).then_some(Parameter::Const(*ax));
        add_point(g, &mut body, p, [mx, my], ElementKind::TF);
    }
    body
}

/// A point mass (no rotation): 1-junctions v_x, v_y with I:m and the weight on v_y; e.g. the
/// piston of the slider-crank (Fig. 29). Its centre is its only point.
pub fn point_mass(g: &mut BondGraph, name: &str, mass: f64, gravity: f64) -> PointJunctions {
    let vx = g.add_junction(format!("{name}.v_x"), ElementKind::One);
    one_port(
        g,
        format!("{name}.I_m_x"),
        ElementKind::I,
        Parameter::Const(mass),
        vx,
    );
    let vy = g.add_junction(format!("{name}.v_y"), ElementKind::One);
    one_port(
        g,
        format!("{name}.I_m_y"),
        ElementKind::I,
        Parameter::Const(mass),
        vy,
    );
    if gravity != 0.0 {
        one_port(
            g,
            format!("{name}.weight"),
            ElementKind::Se,
            Parameter::Const(-mass * gravity),
            vy,
        );
    }
    PointJunctions {
        name: name.into(),
        vx,
        vy,
    }
}

/// Parameters of a 3D rigid body in principal axes at the centre of mass.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody3Spec {
    /// Body name.
    pub name: String,
    /// Mass m.
    pub mass: f64,
    /// Principal moments J_x, J_y, J_z.
    pub inertia: [f64; 3],
    /// Optional body→inertial rotation matrix entries `R[I][i]` as expressions (signals must be
    /// declared on the graph); when given, inertial-frame force/torque ports are built.
    pub rotation: Option<[[String; 3]; 3]>,
}

/// Handles to a 3D rigid body.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody3 {
    /// Body-frame 1-junctions v_x, v_y, v_z.
    pub v: [ElementId; 3],
    /// Body-frame 1-junctions ω_x, ω_y, ω_z.
    pub w: [ElementId; 3],
    /// I:m ×3 then I:J_x, I:J_y, I:J_z.
    pub inertias: [ElementId; 6],
    /// Inertial-frame velocity ports V_X, V_Y, V_Z (1-junctions; attach Se forces here).
    pub force_ports: Option<[ElementId; 3]>,
    /// Inertial-frame angular velocity ports (attach Se torques here).
    pub torque_ports: Option<[ElementId; 3]>,
}

/// 3D rigid body in body-fixed principal axes (seed 16.1, Fig. 2–3).
///
/// `F = dp/dt + ω × p`, `τ = dh/dt + ω × h` as six I's on 1-junctions and the Euler junction
/// structure of MGYs (two triangles): translational `v_y→v_x` (m ω_z), `v_z→v_y` (m ω_x),
/// `v_x→v_z` (m ω_y) with m ω_k = (m/J_k)·p_{J_k}; rotational `ω_y→ω_z` (h_x), `ω_z→ω_x`
/// (h_y), `ω_x→ω_y` (h_z) with h_k = p_{J_k}. Each MGY `a→b` with modulus r adds `+r f_a` to
/// ṗ_b and `−r f_b` to ṗ_a, which reproduces `−ω×p` and `−ω×h`.
/// Inertial ports: `V_I = Σ_i R[I][i] v_i` through MTFs into a 0-junction, whose effort
/// returns `Rᵀ F` to the body junctions.
pub fn rigid_body_3d(g: &mut BondGraph, spec: &RigidBody3Spec) -> RigidBody3 {
    let n = &spec.name;
    let ax = ["x", "y", "z"];
    let mut v = [ElementId(0); 3];
    let mut w = [ElementId(0); 3];
    let mut inertias = [ElementId(0); 6];
    for k in 0..3 {
        v[k] = g.add_junction(format!("{n}.v_{}", ax[k]), ElementKind::One);
        inertias[k] = one_port(
            g,
            format!("{n}.I_m_{}", ax[k]),
            ElementKind::I,
            Parameter::Const(spec.mass),
            v[k],
        );
    }
    for k in 0..3 {
        w[k] = g.add_junction(format!("{n}.w_{}", ax[k]), ElementKind::One);
        inertias[3 + k] = one_port(
            g,
            format!("{n}.I_J_{}", ax[k]),
            ElementKind::I,
            Parameter::Const(spec.inertia[k]),
            w[k],
        );
    }
    // (from, to, modulating axis k)
    for (a, b, k) in [(1, 0, 2), (2, 1, 0), (0, 2, 1)] {
        let ratio = spec.mass / spec.inertia[k];
        let e = g.add_element(
            format!("{n}.mgy_v{}{}", ax[a], ax[b]),
            ElementKind::MGY,
            Some(Parameter::Expr(format!(
                "{ratio:?}*{}",
                crate::expr::quote_name(&format!("p_{n}.I_J_{}", ax[k]))
            ))),
        );
        g.set_label(e, format!("m·ω_{}", ax[k]));
        g.add_bond(v[a], e);
        g.add_bond(e, v[b]);
    }
    for (a, b, k) in [(1, 2, 0), (2, 0, 1), (0, 1, 2)] {
        let e = g.add_element(
            format!("{n}.mgy_w{}{}", ax[a], ax[b]),
            ElementKind::MGY,
            Some(Parameter::Expr(
                crate::expr::quote_name(&format!("p_{n}.I_J_{}", ax[k])).into_owned(),
            )),
        );
        g.set_label(e, format!("h_{}", ax[k]));
        g.add_bond(w[a], e);
        g.add_bond(e, w[b]);
    }
    let (mut force_ports, mut torque_ports) = (None, None);
    if let Some(r) = &spec.rotation {
        let big = ["X", "Y", "Z"];
        for (tag, body, slot) in [("V", v, &mut force_ports), ("W", w, &mut torque_ports)] {
            let mut ports = [ElementId(0); 3];
            for (i, port) in ports.iter_mut().enumerate() {
                let sum = g.add_junction(format!("{n}.{tag}_{}.sum", big[i]), ElementKind::Zero);
                for (k, &jb) in body.iter().enumerate() {
                    let m = g.add_element(
                        format!("{n}.{tag}_{}.mtf_{}", big[i], ax[k]),
                        ElementKind::MTF,
                        Some(Parameter::Expr(r[i][k].clone())),
                    );
                    g.add_bond(jb, m);
                    g.add_bond(m, sum);
                }
                *port = g.add_junction(format!("{n}.{tag}_{}", big[i]), ElementKind::One);
                g.add_bond(sum, *port);
            }
            *slot = Some(ports);
        }
    }
    RigidBody3 {
        v,
        w,
        inertias,
        force_ports,
        torque_ports,
    }
}

fn axis_name(axis: Axis) -> &'static str {
    match axis {
        Axis::X => "x",
        Axis::Y => "y",
    }
}

/// Equates two flows with a 1-junction `name`: `a → name → b` (seed Fig. 16).
pub fn equate_flows(g: &mut BondGraph, name: String, a: ElementId, b: ElementId) -> ElementId {
    let j = g.add_junction(name, ElementKind::One);
    g.add_bond(a, j);
    g.add_bond(j, b);
    j
}

/// Revolute joint between two points in the same (global) axes (seed 16.5, Fig. 16): one
/// 1-junction per axis imposing `V_A1 = V_A2`; its effort is the joint force.
pub fn revolute(g: &mut BondGraph, name: &str, a: &PointJunctions, b: &PointJunctions) {
    for axis in [Axis::X, Axis::Y] {
        equate_flows(
            g,
            format!("{name}.{}", axis_name(axis)),
            a.axis(axis),
            b.axis(axis),
        );
    }
}

/// Pin to ground (seed 16.7): Sf = 0 on both velocity components of the point. The half
/// arrow follows the joint's order (from the first point to the second): `Sf → P` when the
/// ground is the joint's first body, `P → Sf` when it is the second, so that the junction's
/// flow constraint is the rate of the joint's closure `g = P_first − P_second`.
pub fn pin_to_ground(g: &mut BondGraph, name: &str, p: &PointJunctions, ground_first: bool) {
    for axis in [Axis::X, Axis::Y] {
        let sf = g.add_element(
            format!("{name}.{}", axis_name(axis)),
            ElementKind::Sf,
            Some(Parameter::Const(0.0)),
        );
        if ground_first {
            g.add_bond(sf, p.axis(axis));
        } else {
            g.add_bond(p.axis(axis), sf);
        }
    }
}

/// A flow constraint read off any joint closure `g(x)` (seed 16.5 generalised): the
/// modulated flows `Σ_j m_j(x) f_j` of the given 1-junctions summed at a 0-junction
/// `<name>.sum`, whose outflow is the rate of the closure; returns the 0-junction. A modulus
/// `"1"` is a plain bond, a constant one a TF, any other an MTF.
pub fn modulated_sum(g: &mut BondGraph, name: &str, terms: &[(ElementId, String)]) -> ElementId {
    let sum = g.add_junction(format!("{name}.sum"), ElementKind::Zero);
    for (k, (j, m)) in terms.iter().enumerate() {
        if m == "1" {
            g.add_bond(*j, sum);
            continue;
        }
        let (kind, p) = match m.parse::<f64>() {
            Ok(c) => (ElementKind::TF, Parameter::Const(c)),
            Err(_) => (ElementKind::MTF, Parameter::Expr(m.clone())),
        };
        let tf = g.add_element(format!("{name}.m{k}"), kind, Some(p));
        g.add_bond(*j, tf);
        g.add_bond(tf, sum);
    }
    sum
}

/// Weld: revolute plus equal angular velocities.
pub fn weld(
    g: &mut BondGraph,
    name: &str,
    a: (&PointJunctions, ElementId),
    b: (&PointJunctions, ElementId),
) {
    revolute(g, name, a.0, b.0);
    equate_flows(g, format!("{name}.w"), a.1, b.1);
}

/// Prismatic joint along a global axis (piston in cylinder, seed Fig. 29): free along
/// `axis`, equal velocities across it, no relative rotation. `b = None` is the ground
/// (fixed cylinder): Sf = 0 on the perpendicular velocity and on ω (when the slider rotates).
pub fn prismatic(
    g: &mut BondGraph,
    name: &str,
    a: (&PointJunctions, Option<ElementId>),
    b: Option<(&PointJunctions, Option<ElementId>)>,
    axis: Axis,
) {
    let across = match axis {
        Axis::X => Axis::Y,
        Axis::Y => Axis::X,
    };
    match b {
        None => {
            one_port(
                g,
                format!("{name}.{}", axis_name(across)),
                ElementKind::Sf,
                Parameter::Const(0.0),
                a.0.axis(across),
            );
            if let Some(w) = a.1 {
                one_port(
                    g,
                    format!("{name}.w"),
                    ElementKind::Sf,
                    Parameter::Const(0.0),
                    w,
                );
            }
        }
        Some(b) => {
            equate_flows(
                g,
                format!("{name}.{}", axis_name(across)),
                a.0.axis(across),
                b.0.axis(across),
            );
            match (a.1, b.1) {
                (Some(wa), Some(wb)) => {
                    equate_flows(g, format!("{name}.w"), wa, wb);
                }
                (Some(w), None) | (None, Some(w)) => {
                    one_port(
                        g,
                        format!("{name}.w"),
                        ElementKind::Sf,
                        Parameter::Const(0.0),
                        w,
                    );
                }
                (None, None) => {}
            }
        }
    }
}

/// Spring (C, stiffness k, stored as compliance 1/k) and/or damper (R) along one axis between
/// points `a` and `b` (`None` = ground). Between two points a 0-junction forms the relative
/// velocity `v_a − v_b`; spring and damper act in parallel on a 1-junction of that velocity.
pub fn spring_damper(
    g: &mut BondGraph,
    name: &str,
    a: &PointJunctions,
    b: Option<&PointJunctions>,
    axis: Axis,
    stiffness: Option<f64>,
    damping: Option<f64>,
) {
    let ax = axis_name(axis);
    coupling(
        g,
        &format!("{name}.{ax}"),
        a.axis(axis),
        b.map(|b| b.axis(axis)),
        stiffness,
        damping,
    );
}

/// Spring (C, compliance 1/k) and/or damper (R) on the difference of two flows `f_a − f_b`
/// (`b = None`: on `f_a` itself, i.e. to ground): a 0-junction `name` forms `f_a − f_b`, a
/// 1-junction `name.rel` carries it, `name.k` and `name.c` act on it in parallel; so the
/// effort `k ∫(f_a − f_b) + c (f_a − f_b)` acts against `a` and for `b`.
pub fn coupling(
    g: &mut BondGraph,
    name: &str,
    a: ElementId,
    b: Option<ElementId>,
    stiffness: Option<f64>,
    damping: Option<f64>,
) {
    let rel = match b {
        None => a,
        Some(b) => {
            let z = g.add_junction(name.to_string(), ElementKind::Zero);
            g.add_bond(a, z);
            g.add_bond(z, b);
            let rel = g.add_junction(format!("{name}.rel"), ElementKind::One);
            g.add_bond(z, rel);
            rel
        }
    };
    if let Some(k) = stiffness {
        one_port(
            g,
            format!("{name}.k"),
            ElementKind::C,
            Parameter::Const(1.0 / k),
            rel,
        );
    }
    if let Some(c) = damping {
        one_port(
            g,
            format!("{name}.c"),
            ElementKind::R,
            Parameter::Const(c),
            rel,
        );
    }
}

/// Decoupled joint (seed 16.6–16.7, Fig. 17–18, 21): each constrained direction of a revolute
/// joint (or of a pin to ground, `b = None`) replaced by a stiff spring, optionally damped.
pub fn decoupled_revolute(
    g: &mut BondGraph,
    name: &str,
    a: &PointJunctions,
    b: Option<&PointJunctions>,
    stiffness: f64,
    damping: Option<f64>,
) {
    for axis in [Axis::X, Axis::Y] {
        spring_damper(g, name, a, b, axis, Some(stiffness), damping);
    }
}

/// A force load: Se on one velocity component of a point (e.g. the gas force Se:Eg).
pub fn force(
    g: &mut BondGraph,
    name: &str,
    p: &PointJunctions,
    axis: Axis,
    value: Parameter,
) -> ElementId {
    one_port(g, name.into(), ElementKind::Se, value, p.axis(axis))
}

/// A torque load: Se on a body's ω junction.
pub fn torque(g: &mut BondGraph, name: &str, omega: ElementId, value: Parameter) -> ElementId {
    one_port(g, name.into(), ElementKind::Se, value, omega)
}

/// Change of reference frame of a point velocity (seed 16.4, Fig. 9–10): with `theta` the angle
/// of the target frame relative to the source frame (an expression, e.g.
/// `x_bar2.omega - x_bar1.omega`), `u' = cosθ·u + sinθ·v`, `v' = −sinθ·u + cosθ·v`, built from
/// four MTFs into two 0-junctions; the efforts go back as `Rᵀ F`. Returns the point's
/// velocity junctions in the target frame.
pub fn change_frame(
    g: &mut BondGraph,
    name: &str,
    p: &PointJunctions,
    theta: &str,
) -> PointJunctions {
    let (c, s) = (format!("cos({theta})"), format!("sin({theta})"));
    let rows = [("x", [c.clone(), s.clone()]), ("y", [format!("-{s}"), c])];
    let mut out = [ElementId(0); 2];
    for (k, (axis, moduli)) in rows.into_iter().enumerate() {
        let sum = g.add_junction(format!("{name}.sum_{axis}"), ElementKind::Zero);
        for ((src, from), m) in [("x", p.vx), ("y", p.vy)].into_iter().zip(moduli) {
            let tf = g.add_element(
                format!("{name}.mtf_{axis}{src}"),
                ElementKind::MTF,
                Some(Parameter::Expr(m.clone())),
            );
            g.set_label(tf, m.replace('*', "·"));
            g.add_bond(from, tf);
            g.add_bond(tf, sum);
        }
        out[k] = g.add_junction(format!("{name}.v_{axis}"), ElementKind::One);
        g.add_bond(sum, out[k]);
    }
    PointJunctions {
        name: name.into(),
        vx: out[0],
        vy: out[1],
    }
}

/// A point of a 3D body: the 1-junctions whose common flows are its global velocity
/// components `V_X, V_Y, V_Z`.
#[derive(Debug, Clone, PartialEq)]
pub struct Point3 {
    /// Full name (`bar1.A`).
    pub name: String,
    /// 1-junctions of the global velocity components X, Y, Z.
    pub v: [ElementId; 3],
}

/// A spatial point mass (translation only): three 1-junctions `<name>.V_X`, `.V_Y`, `.V_Z` of
/// the global velocity, each with I:m (`<name>.I_m_X`, …): `ṗ_I = F_I`. Its centre is its only
/// point.
pub fn point_mass_3d(g: &mut BondGraph, name: &str, mass: f64) -> Point3 {
    let v = ["X", "Y", "Z"].map(|ax| {
        let j = g.add_junction(format!("{name}.V_{ax}"), ElementKind::One);
        one_port(
            g,
            format!("{name}.I_m_{ax}"),
            ElementKind::I,
            Parameter::Const(mass),
            j,
        );
        j
    });
    Point3 {
        name: name.into(),
        v,
    }
}

/// Global velocity of a point of a 3D body, `V_P = V_O + Ω × r` (seed 16.1–16.2 in the
/// inertial frame): `centre` are the body's inertial velocity ports `V_O` (see
/// [`rigid_body_3d`] with a rotation), `omega` its inertial angular velocity ports `Ω`, and
/// `r` the global components of the arm `r = R r_body` as expressions of the attitude. Per
/// axis I (with (I, J, K) cyclic) a 0-junction `<name>.sum_I` adds `V_OI`, `r_K·Ω_J` and
/// `−r_J·Ω_K` (MTFs `<name>.mtf_IJ`, `<name>.mtf_IK`) into the 1-junction `<name>.V_I`; the
/// efforts return `F` to the centre and `r × F` to the rotation.
pub fn spatial_point(
    g: &mut BondGraph,
    name: &str,
    centre: [ElementId; 3],
    omega: [ElementId; 3],
    r: &[String; 3],
) -> Point3 {
    let ax = ["X", "Y", "Z"];
    let mut v = [ElementId(0); 3];
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let sum = g.add_junction(format!("{name}.sum_{}", ax[i]), ElementKind::Zero);
        g.add_bond(centre[i], sum);
        for (from, m) in [(j, r[k].clone()), (k, format!("-({})", r[j]))] {
            let tf = g.add_element(
                format!("{name}.mtf_{}{}", ax[i], ax[from]),
                ElementKind::MTF,
                Some(Parameter::Expr(m.clone())),
            );
            g.set_label(tf, m.replace('*', "·"));
            g.add_bond(omega[from], tf);
            g.add_bond(tf, sum);
        }
        v[i] = g.add_junction(format!("{name}.V_{}", ax[i]), ElementKind::One);
        g.add_bond(sum, v[i]);
    }
    Point3 {
        name: name.into(),
        v,
    }
}

/// Projection of flows on a direction, `f = Σ_k c_k f_k`: a (M)TF per source (TF for a
/// constant modulus, MTF for an expression) into a 0-junction `<name>.sum`, feeding the
/// 1-junction `name`, whose flow is the projection (e.g. a component of an angular velocity
/// across a hinge axis); the effort returns as `c_k e` to each source.
pub fn projection(g: &mut BondGraph, name: &str, sources: &[(ElementId, Parameter)]) -> ElementId {
    let sum = g.add_junction(format!("{name}.sum"), ElementKind::Zero);
    for (k, (from, m)) in sources.iter().enumerate() {
        let kind = match m {
            Parameter::Const(_) => ElementKind::TF,
            _ => ElementKind::MTF,
        };
        let tf = g.add_element(format!("{name}.tf{k}"), kind, Some(m.clone()));
        if let Parameter::Expr(e) = m {
            g.set_label(tf, e.replace('*', "·"));
        }
        g.add_bond(*from, tf);
        g.add_bond(tf, sum);
    }
    let out = g.add_junction(name.to_string(), ElementKind::One);
    g.add_bond(sum, out);
    out
}

/// A zero flow source `Sf = 0` named `name` on `junction` (a constrained direction to ground,
/// seed 16.7); its effort is the reaction.
pub fn zero_flow(g: &mut BondGraph, name: &str, junction: ElementId) -> ElementId {
    one_port(
        g,
        name.into(),
        ElementKind::Sf,
        Parameter::Const(0.0),
        junction,
    )
}

/// `Σ c_i·x_i` as an expression string (`"0"` when every coefficient vanishes).
pub fn linear_expression(terms: &[(f64, String)]) -> String {
    linear(terms)
}
