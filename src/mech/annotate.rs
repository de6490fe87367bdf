//! The mechanism's bond graph completed into the model the solver solves (seed 16.3–16.8).
//!
//! [`super::bondgraph`] draws the chapter's fragments. Here the pinned
//! graph of a planar mechanism gets what makes it simulatable:
//!
//! * **displacement states** `x_<junction>` with initial values: the body's `x`, `y` (∫ of the
//!   centre's `v_x`, `v_y` junctions) and angle `α` (∫ of the ω junction, which modulates the
//!   body's MTFs);
//! * **named flows** of the inertias, in the mechanism's velocity order;
//! * on every constraint junction, the joint's **closure** `g_k(x)` (its position-level row),
//!   whose time derivative the reader checks against the junction's flow constraint;
//! * the joints the seed draws no fragment for (a slider on any axis, a weld's angle) as a
//!   **modulated sum** `Σ_j (∂ġ_k/∂v_j) f_j` of the inertias' junction flows into an `Sf = 0`,
//!   and springs of non-zero rest length as a C on the length rate `L̇ = Σ_j (∂L̇/∂v_j) f_j`
//!   with displacement `L(x) − L₀` (and the damper's R on the same junction);
//! * the scene names a load expression uses (`crank.angle`) as signal definitions.
//!
//! Then [`crate::bond::mechanics`] reads `M`, `K(x) v`, `Q` and the rows `G_v v` off the graph,
//! and those are the equations every formulation solves.

use std::collections::HashMap;

use super::body::BodyKinematics;
use super::bondgraph::{planar_rest_length, scene_bond_graph_with};
use super::columns::Columns;
use super::coordinates::Geometry;
use super::error::MechError;
use super::system::{ConstraintRow, Coordinate, EquationSource, MultibodySystem, OutputColumn};
use crate::bond::fragments::modulated_sum;
use crate::bond::mechanics::{read_mechanics, read_mechanics_in, MechanicsError};
use crate::bond::model::{
    BondGraph, ConstraintJunction, Displacement, ElementId, ElementKind, FlowState, GraphOutput,
    Parameter, SignalDefinition,
};
use crate::expr::{Expr, ExprGraph};
use crate::scene::{BodyFrame, Dimension, LoadKind, PointRef, Scene};

/// Longest expression text written into the graph (beyond it the text holds `…` and the
/// reader refuses it by name).
const EXACT_TEXT_LIMIT: usize = 4_000_000;

/// Why a mechanism's bond graph cannot (yet) be the model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnnotateError {
    /// A kind of scene whose graph is not complete yet.
    #[error("{0}")]
    Unsupported(&'static str),
    /// The graph cannot be read.
    #[error(transparent)]
    Mechanics(#[from] MechanicsError),
    /// The scene is invalid.
    #[error(transparent)]
    Mech(#[from] MechError),
    /// The graph's states do not line up with the mechanism's coordinates.
    #[error("the bond graph's {what} '{graph}' does not match the mechanism's '{mechanism}'")]
    Layout {
        /// Coordinates or velocities.
        what: &'static str,
        /// The graph's name.
        graph: String,
        /// The mechanism's name.
        mechanism: String,
    },
    /// A name the mechanism uses has no element in the graph.
    #[error("the bond graph has no element '{0}'")]
    MissingElement(String),
}

/// The complete pinned bond graph of `scene`, annotated from the mechanism's geometry `sys`
/// (coordinates, joint closures, point positions).
pub fn mechanism_graph(scene: &Scene, sys: &MultibodySystem) -> Result<BondGraph, AnnotateError> {
    let spatial = matches!(scene.dimension, Dimension::Spatial);
    let (mut g, slot_names, velocity_junctions) = if spatial {
        spatial_bodies(scene, sys)?
    } else {
        planar_bodies(scene, sys)?
    };
    let mut eg = sys.graph.clone();
    let nq = sys.nq();
    let text = |eg: &ExprGraph, e: Expr| {
        eg.display_exact(e, &|s| quoted(&slot_names[s as usize]), EXACT_TEXT_LIMIT)
            .unwrap_or_else(|| "…".into())
    };
    // joints: closures on the drawn junctions, modulated sums for the others
    let drawn: HashMap<(String, String), usize> = g
        .constraint_junctions
        .iter()
        .enumerate()
        .map(|(i, c)| ((c.joint.clone(), c.direction.clone()), i))
        .collect();
    for (k, row) in sys.rows.iter().enumerate() {
        let closure = text(&eg, sys.constraints[k]);
        if let Some(&i) = drawn.get(&(row.joint.clone(), row.direction.clone())) {
            g.constraint_junctions[i].closure = Some(closure);
            continue;
        }
        let name = format!("{}.{}", row.joint, row.direction);
        let terms = rate_terms(
            &mut eg,
            sys,
            nq,
            sys.constraints[k],
            &velocity_junctions,
            &text,
        );
        // a driver: the joint's relative flow (the rate of its coordinate s(q)) on a
        // 1-junction, prescribed by the flow source `Sf <driver> = ṡ(t)`
        if let Some(d) = sys.drivers.iter().find(|d| d.row == k) {
            let sum = modulated_sum(&mut g, &name, &terms);
            let v = g.add_junction(format!("{}.rate", d.name), ElementKind::One);
            g.add_bond(sum, v);
            let rate = text(&eg, d.rate);
            let sf = g.add_element(d.name.clone(), ElementKind::Sf, Some(Parameter::Expr(rate)));
            g.add_bond(v, sf);
            g.constraint_junctions.push(ConstraintJunction {
                element: sf,
                joint: row.joint.clone(),
                direction: row.direction.clone(),
                closure: Some(closure),
            });
            continue;
        }
        // the row's flow on a 1-junction, held at zero by an Sf (like a pin's point, 16.7)
        let sum = modulated_sum(&mut g, &name, &terms);
        let v = g.add_junction(format!("{name}.v"), ElementKind::One);
        g.add_bond(sum, v);
        let sf = g.add_element(name, ElementKind::Sf, Some(Parameter::Const(0.0)));
        g.add_bond(v, sf);
        g.constraint_junctions.push(ConstraintJunction {
            element: sf,
            joint: row.joint.clone(),
            direction: row.direction.clone(),
            closure: Some(closure),
        });
    }
    // springs
    let mut index = ElementIndex::default();
    for (si, s) in scene.springs.iter().enumerate() {
        let pa = point(&mut eg, scene, sys, &s.bodies[0], &s.points[0])?;
        let pb = point(&mut eg, scene, sys, &s.bodies[1], &s.points[1])?;
        let dim = pa.len();
        let l0 = if !spatial {
            planar_rest_length(scene, si)
        } else {
            match s.rest_length {
                Some(l) => l,
                None => {
                    let d: Vec<Expr> = (0..dim).map(|i| eg.sub(pb[i], pa[i])).collect();
                    let dd = eg.dot(&d, &d);
                    let x0 = std::iter::once(0.0)
                        .chain(sys.coords.iter().map(|c| c.initial))
                        .chain(sys.velocities.iter().map(|c| c.initial))
                        .collect::<Vec<_>>();
                    eg.eval(dd, &x0).sqrt()
                }
            }
        };
        if spatial && l0 == 0.0 {
            // per axis: C on the rate of δ_k = P_first,k − P_other,k
            let (p1, p2) = if s.bodies[0] != "ground" {
                (&pa, &pb)
            } else {
                (&pb, &pa)
            };
            for k in 0..dim {
                let d = eg.sub(p1[k], p2[k]);
                let terms = rate_terms(&mut eg, sys, nq, d, &velocity_junctions, &text);
                let name = format!("{}.{}", s.name, ["x", "y", "z"][k]);
                let sum = modulated_sum(&mut g, &name, &terms);
                let rate = g.add_junction(format!("{name}.rel"), ElementKind::One);
                g.add_bond(sum, rate);
                let c = g.add_element(
                    format!("{name}.k"),
                    ElementKind::C,
                    Some(Parameter::Const(1.0 / s.stiffness)),
                );
                g.add_bond(rate, c);
                g.elements[c.0].displacement = Some(text(&eg, d));
                if s.damping > 0.0 {
                    let r = g.add_element(
                        format!("{name}.c"),
                        ElementKind::R,
                        Some(Parameter::Const(s.damping)),
                    );
                    g.add_bond(rate, r);
                }
            }
            continue;
        }
        if l0 == 0.0 {
            // the seed's per-axis springs: δ = P_first − P_other (the ground's point fixed)
            let (p1, p2) = if s.bodies[0] != "ground" {
                (pa, pb)
            } else {
                (pb, pa)
            };
            for (axis, (a, b)) in ["x", "y"].iter().zip(p1.iter().zip(&p2)) {
                let d = eg.sub(*a, *b);
                let c = index.get(&g, &format!("{}.{axis}.k", s.name))?;
                g.elements[c.0].displacement = Some(text(&eg, d));
            }
            continue;
        }
        let d: Vec<Expr> = (0..dim).map(|i| eg.sub(pb[i], pa[i])).collect();
        let dd = eg.dot(&d, &d);
        // F = −k (L − l₀) d/L has no direction where the points meet (d/L = 0/0 at L = 0)
        let x0 = std::iter::once(0.0)
            .chain(sys.coords.iter().map(|c| c.initial))
            .chain(sys.velocities.iter().map(|c| c.initial))
            .collect::<Vec<_>>();
        if eg.eval(dd, &x0) == 0.0 {
            return Err(MechError::at(
                &format!("springs[{si}].points"),
                format!(
                    "spring '{}': its two points coincide at the start, where a spring of rest_length {l0} has no direction (its force −k (L − l₀) d/L is 0/0 at L = 0); give rest_length 0 for a spring linear in the vector, or points apart",
                    s.name
                ),
            )
            .into());
        }
        let len = eg.sqrt(dd);
        let terms = rate_terms(&mut eg, sys, nq, len, &velocity_junctions, &text);
        let sum = modulated_sum(&mut g, &s.name, &terms);
        let rate = g.add_junction(format!("{}.rate", s.name), ElementKind::One);
        g.add_bond(sum, rate);
        let c = g.add_element(
            format!("{}.k", s.name),
            ElementKind::C,
            Some(Parameter::Const(1.0 / s.stiffness)),
        );
        g.add_bond(rate, c);
        let l0e = eg.constant(l0);
        let stretch = eg.sub(len, l0e);
        g.elements[c.0].displacement = Some(text(&eg, stretch));
        g.set_label(c, format!("1/{}", s.stiffness));
        if s.damping > 0.0 {
            let r = g.add_element(
                format!("{}.c", s.name),
                ElementKind::R,
                Some(Parameter::Const(s.damping)),
            );
            g.add_bond(rate, r);
        }
    }
    // scene names used by load expressions
    for name in g.signals.clone() {
        if let Some((_, e)) = sys.names.iter().find(|(n, _)| *n == name) {
            g.signal_definitions.push(SignalDefinition {
                name,
                expr: text(&eg, *e),
            });
        }
    }
    Ok(g)
}

/// The seed's planar graph (16.8) with its bodies' displacement states and named flows; the
/// slot names of the layout `[t, x, v]` and the junction of each velocity.
#[allow(clippy::type_complexity)]
fn planar_bodies(
    scene: &Scene,
    sys: &MultibodySystem,
) -> Result<(BondGraph, Vec<String>, Vec<ElementId>), AnnotateError> {
    let mut g = scene_bond_graph_with(scene, true)?;
    let mut index = ElementIndex::default();
    let mut find = |g: &BondGraph, n: &str| index.get(g, n);
    // a body-fixed bar (16.3) moves its centre along R(α)(u, w): the frame change of 16.4
    // brings the centre's velocity into the global axes, whose junctions integrate to x, y
    let fixed: Vec<&str> = scene
        .bodies
        .iter()
        .filter(|b| matches!(b.frame, BodyFrame::BodyFixed))
        .map(|b| b.name.as_str())
        .collect();
    for b in &fixed {
        let centre = crate::bond::fragments::PointJunctions {
            name: format!("{b}.cm"),
            vx: find(&g, &format!("{b}.v_x"))?,
            vy: find(&g, &format!("{b}.v_y"))?,
        };
        crate::bond::fragments::change_frame(
            &mut g,
            &format!("{b}.cm.in_global"),
            &centre,
            &format!("-x_{b}.omega"),
        );
    }
    let mut slot_names = vec!["t".to_string()];
    for c in &sys.coords {
        let (body, what) = c.name.rsplit_once('.').unwrap_or(("", ""));
        let global = fixed.contains(&body);
        let junction = match what {
            "x" if global => format!("{body}.cm.in_global.v_x"),
            "y" if global => format!("{body}.cm.in_global.v_y"),
            "x" => format!("{body}.v_x"),
            "y" => format!("{body}.v_y"),
            "angle" => format!("{body}.omega"),
            _ => return Err(AnnotateError::MissingElement(c.name.clone())),
        };
        let element = find(&g, &junction)?;
        g.displacements.push(Displacement {
            element,
            name: c.name.clone(),
            initial: c.initial,
        });
        slot_names.push(format!("x_{junction}"));
    }
    // the weight's global x component (the seed's fragments carry y) on the junction whose
    // displacement is the centre's x
    let gx = scene.gravity.first().copied().unwrap_or(0.0);
    if gx != 0.0 {
        for b in &scene.bodies {
            let junction = if fixed.contains(&b.name.as_str()) {
                format!("{}.cm.in_global.v_x", b.name)
            } else {
                format!("{}.v_x", b.name)
            };
            let j = find(&g, &junction)?;
            let se = g.add_element(
                format!("{}.weight_X", b.name),
                ElementKind::Se,
                Some(Parameter::Const(b.mass * gx)),
            );
            g.add_bond(se, j);
        }
    }
    let mut velocity_junctions = Vec::new();
    for v in &sys.velocities {
        let (body, what) = v.name.rsplit_once('.').unwrap_or(("", ""));
        let inertia = match what {
            "vx" | "u" => format!("{body}.I_m_x"),
            "vy" | "w" => format!("{body}.I_m_y"),
            "omega" => format!("{body}.I_J"),
            _ => return Err(AnnotateError::MissingElement(v.name.clone())),
        };
        let element = find(&g, &inertia)?;
        let bond = g.bonds_of(element)[0];
        velocity_junctions.push(g.other_end(bond, element));
        g.flows.push(FlowState {
            element,
            name: v.name.clone(),
            initial: v.initial,
        });
        slot_names.push(format!("f_{inertia}"));
    }
    Ok((g, slot_names, velocity_junctions))
}

/// The spatial graph of 16.1–16.2 in the layout of the mechanism: per body the 1-junctions of
/// the global centre velocity `V` with I:m and the weight, the body angular velocity `ω` with
/// I:J_k and the Euler junction structure (MGYs of modulus `h_k = J_k ω_k`), and the attitude
/// quaternion `e` as the displacements of four 1-junctions fed by MTFs from `ω` modulated by
/// `e` itself (`e' = ½ e ⊗ (0, ω)`, the rotation of 16.2 carried without the Cardan
/// singularity). Point masses carry `V` only.
#[allow(clippy::type_complexity)]
/// Whether the spatial body `name` rotates freely: none of its joints fixes a relative
/// rotation (a ball joint, a distance link, or no joint). Its graph then prefers its
/// body-frame angular inertias in differential causality
/// ([`crate::bond::model::BondGraph::prefer_differential`]), so that its centre's velocity `V` is
/// its states: a spinning body's transverse rotation, carried by the body-frame `ω_x, ω_y`,
/// turns in the body at about `(J_z/J_x − 1) ω_z` while the motion it describes (the axis's
/// nutation and precession) is slow in the world frame, where `V` carries it, and BDF's local
/// errors on the turning pair add up step after step. Measured on the heavy top
/// (`scenes/heavy_top.json`, 5 s, rtol 1e-9 / 1e-10 / 1e-11): 3050 / 557 / 6650 × rtol with `ω`
/// the states, 579 / 218 / 1919 × with `V` (at rtol 7e-10, 1.4e-9, 7e-11, 1.4e-10, 7e-12 and
/// 1.4e-11: 203–419 ×, 0.15–0.86 × the GGL's error; docs/performance.md, "The heavy top's
/// states").
fn rotates_freely(scene: &Scene, name: &str) -> bool {
    scene
        .joints
        .iter()
        .filter(|j| j.bodies.iter().any(|b| b == name))
        .all(|j| !crate::mech::joints::transmits_moment(&j.kind))
}

fn spatial_bodies(
    scene: &Scene,
    sys: &MultibodySystem,
) -> Result<(BondGraph, Vec<String>, Vec<ElementId>), AnnotateError> {
    let mut g = BondGraph::new();
    let ax = ["x", "y", "z"];
    let nq = sys.nq();
    // first pass: junctions and inertias, in the velocity order
    let mut velocity_junctions = vec![ElementId(0); sys.nv()];
    let mut coord_junctions = vec![None; nq];
    let mut flows = Vec::new();
    for (bi, (name, kin)) in sys.bodies.iter().enumerate() {
        let (r, v, w) = match kin {
            BodyKinematics::Spatial { r, v, w, .. } => (*r, *v, Some(*w)),
            BodyKinematics::Particle { r, v } => (*r, *v, None),
            _ => {
                return Err(AnnotateError::Unsupported(
                    "a planar body in a spatial scene",
                ))
            }
        };
        for k in 0..3 {
            let j = g.add_junction(format!("{name}.v_{}", ax[k]), ElementKind::One);
            let vi = (v[k] as usize) - 1 - nq;
            let i = g.add_element(
                format!("{name}.I_m_{}", ax[k]),
                ElementKind::I,
                Some(Parameter::Const(sys.mass[vi])),
            );
            g.add_bond(j, i);
            velocity_junctions[vi] = j;
            coord_junctions[(r[k] as usize) - 1] = Some(j);
            flows.push((vi, i));
            let gk = scene.gravity.get(k).copied().unwrap_or(0.0);
            if gk != 0.0 {
                let se = g.add_element(
                    format!("{name}.weight_{}", ax[k]),
                    ElementKind::Se,
                    Some(Parameter::Const(scene.bodies[bi].mass * gk)),
                );
                g.add_bond(se, j);
            }
        }
        if let Some(w) = w {
            let mut wj = [ElementId(0); 3];
            for k in 0..3 {
                wj[k] = g.add_junction(format!("{name}.w_{}", ax[k]), ElementKind::One);
                let vi = (w[k] as usize) - 1 - nq;
                let i = g.add_element(
                    format!("{name}.I_J_{}", ax[k]),
                    ElementKind::I,
                    Some(Parameter::Const(sys.mass[vi])),
                );
                g.add_bond(wj[k], i);
                velocity_junctions[vi] = wj[k];
                flows.push((vi, i));
            }
            for (a, b, k) in [(1, 2, 0), (2, 0, 1), (0, 1, 2)] {
                let e = g.add_element(
                    format!("{name}.mgy_w{}{}", ax[a], ax[b]),
                    ElementKind::MGY,
                    Some(Parameter::Expr(
                        crate::expr::quote_name(&format!("p_{name}.I_J_{}", ax[k])).into_owned(),
                    )),
                );
                g.set_label(e, format!("h_{}", ax[k]));
                g.add_bond(wj[a], e);
                g.add_bond(e, wj[b]);
            }
            if rotates_freely(scene, name) {
                g.prefer_differential
                    .extend(ax.iter().map(|a| format!("{name}.I_J_{a}")));
            }
        }
    }
    flows.sort_by_key(|(vi, _)| *vi);
    let mut slot_names = vec!["t".to_string()];
    // coordinate names: displacements of the V junctions now, quaternion junctions below
    let mut names_q = vec![String::new(); nq];
    for (k, j) in coord_junctions.iter().enumerate() {
        if let Some(j) = j {
            names_q[k] = format!("x_{}", g.element(*j).name);
        }
    }
    let quaternion_names: Vec<(usize, String)> = sys
        .coords
        .iter()
        .enumerate()
        .filter(|(k, _)| coord_junctions[*k].is_none())
        .map(|(k, c)| (k, format!("{}.rate", c.name)))
        .collect();
    for (k, n) in &quaternion_names {
        names_q[*k] = format!("x_{n}");
    }
    slot_names.extend(names_q);
    for (_, i) in &flows {
        slot_names.push(format!("f_{}", g.element(*i).name));
    }
    // the quaternion junctions: e_i' = Σ_k (∂e_i'/∂ω_k) ω_k
    let mut eg = sys.graph.clone();
    let text = |eg: &ExprGraph, e: Expr| {
        eg.display_exact(e, &|s| quoted(&slot_names[s as usize]), EXACT_TEXT_LIMIT)
            .unwrap_or_else(|| "…".into())
    };
    for (k, n) in &quaternion_names {
        let terms = velocity_terms(&mut eg, nq, sys.kinematics[*k], &velocity_junctions, &text);
        let sum = modulated_sum(&mut g, &sys.coords[*k].name, &terms);
        let j = g.add_junction(n.clone(), ElementKind::One);
        g.add_bond(sum, j);
        coord_junctions[*k] = Some(j);
    }
    for (k, c) in sys.coords.iter().enumerate() {
        g.displacements.push(Displacement {
            element: coord_junctions[k].expect("every coordinate has its junction"),
            name: c.name.clone(),
            initial: c.initial,
        });
    }
    for (vi, i) in flows {
        g.flows.push(FlowState {
            element: i,
            name: sys.velocities[vi].name.clone(),
            initial: sys.velocities[vi].initial,
        });
    }
    // force loads: Se on the point's velocity component, a modulated sum of the body's flows
    for l in &scene.loads {
        let params = super::bondgraph::load_parameters(&l.value);
        let p = l.point.clone().unwrap_or(PointRef::Coords(vec![0.0; 3]));
        let kin = sys
            .bodies
            .iter()
            .find(|(n, _)| *n == l.body)
            .map(|(_, k)| k.clone())
            .ok_or_else(|| AnnotateError::MissingElement(l.body.clone()))?;
        let coords: Vec<f64> = match &p {
            PointRef::Coords(c) => c.clone(),
            PointRef::Named(n) => scene
                .bodies
                .iter()
                .find(|b| b.name == l.body)
                .and_then(|b| b.points.iter().find(|(pn, _)| pn == n))
                .map(|(_, c)| c.clone())
                .unwrap_or_default(),
        };
        // a force acts on its point's velocity, a torque on the body's global angular
        // velocity `R ω` (the frame change of 16.2)
        let vel = match l.kind {
            LoadKind::Force => kin.point(&mut eg, &coords).velocity,
            LoadKind::Torque => match &kin {
                BodyKinematics::Spatial { w, .. } => {
                    let rot = kin.rotation3(&mut eg);
                    let we: Vec<Expr> = w.iter().map(|&s| eg.var(s)).collect();
                    (0..3).map(|i| eg.dot(&rot[i], &we)).collect()
                }
                _ => {
                    return Err(AnnotateError::Unsupported(
                        "a torque on a body without rotation",
                    ))
                }
            },
        };
        for (k, prm) in params.into_iter().enumerate().take(3) {
            let terms = velocity_terms(&mut eg, nq, vel[k], &velocity_junctions, &text);
            let name = format!("{}.{}", l.name, ax[k]);
            let sum = modulated_sum(&mut g, &name, &terms);
            let j = g.add_junction(format!("{name}.v"), ElementKind::One);
            g.add_bond(sum, j);
            if let Parameter::Expr(e) = &prm {
                for v in crate::bond::identifiers::variables(e).unwrap_or_default() {
                    if v != "t" {
                        g.add_signal(v);
                    }
                }
            }
            let se = g.add_element(name, ElementKind::Se, Some(prm));
            g.add_bond(se, j);
        }
    }
    Ok((g, slot_names, velocity_junctions))
}

/// `Σ_j (∂ḣ/∂v_j) f_j` for `h(x)`: the junction of each velocity it depends on, with the
/// modulus `∂ḣ/∂v_j(x)` as text (`ḣ = Σ_i ∂h/∂x_i · K_i(x) v`).
fn rate_terms(
    eg: &mut ExprGraph,
    sys: &MultibodySystem,
    nq: usize,
    h: Expr,
    junctions: &[ElementId],
    text: &dyn Fn(&ExprGraph, Expr) -> String,
) -> Vec<(ElementId, String)> {
    let rate = super::system::time_rate(eg, &sys.kinematics, h);
    velocity_terms(eg, nq, rate, junctions, text)
}

/// `rate = Σ_j m_j(x) v_j` as the junction of each velocity it depends on with the modulus
/// `m_j = ∂rate/∂v_j` as text (the MTFs of a modulated sum).
fn velocity_terms(
    eg: &mut ExprGraph,
    nq: usize,
    rate: Expr,
    junctions: &[ElementId],
    text: &dyn Fn(&ExprGraph, Expr) -> String,
) -> Vec<(ElementId, String)> {
    let mut out = Vec::new();
    // the velocities `rate` mentions, in slot order
    for s in eg.vars(rate) {
        let Some(j) = (s as usize).checked_sub(1 + nq) else {
            continue;
        };
        if let Some(&junction) = junctions.get(j) {
            let m = eg.diff(rate, s);
            out.push((junction, text(eg, m)));
        }
    }
    out
}

/// Element ids by name for a graph that only grows (a name lookup in the graph itself scans
/// every element: quadratic over a large mechanism's bodies).
#[derive(Default)]
struct ElementIndex {
    ids: HashMap<String, ElementId>,
    seen: usize,
}

impl ElementIndex {
    /// The first element named `name`, indexing the elements added since the last call.
    fn get(&mut self, g: &BondGraph, name: &str) -> Result<ElementId, AnnotateError> {
        for (i, e) in g.elements.iter().enumerate().skip(self.seen) {
            self.ids.entry(e.name.clone()).or_insert(ElementId(i));
        }
        self.seen = g.elements.len();
        self.ids
            .get(name)
            .copied()
            .ok_or_else(|| AnnotateError::MissingElement(name.to_string()))
    }
}

/// Position of a point of `body` (ground: global coordinates).
fn point(
    eg: &mut ExprGraph,
    scene: &Scene,
    sys: &MultibodySystem,
    body: &str,
    p: &PointRef,
) -> Result<Vec<Expr>, AnnotateError> {
    let coords: Vec<f64> = match p {
        PointRef::Coords(c) => c.clone(),
        PointRef::Named(n) => scene
            .bodies
            .iter()
            .find(|b| b.name == body)
            .and_then(|b| b.points.iter().find(|(pn, _)| pn == n))
            .map(|(_, c)| c.clone())
            .ok_or_else(|| AnnotateError::MissingElement(format!("{body}.{n}")))?,
    };
    let kin = if body == "ground" {
        BodyKinematics::Ground
    } else {
        sys.bodies
            .iter()
            .find(|(n, _)| n == body)
            .map(|(_, k)| k.clone())
            .ok_or_else(|| AnnotateError::MissingElement(body.to_string()))?
    };
    Ok(kin.point(eg, &coords).position)
}

/// Replaces the assembled inertias, forces and constraint rows of `sys` by the ones read off
/// the scene's bond graph; returns the graph it read.
pub fn read_into(scene: &Scene, sys: &mut MultibodySystem) -> Result<Expr, AnnotateError> {
    let g = mechanism_graph(scene, sys)?;
    let eqs = read_mechanics_in(&g, sys.graph.clone())?;
    for (what, ours, theirs) in [
        ("coordinate", &eqs.coords, &sys.coords),
        ("velocity", &eqs.velocities, &sys.velocities),
    ] {
        if ours.len() != theirs.len() {
            return Err(AnnotateError::Layout {
                what,
                graph: format!("{} states", ours.len()),
                mechanism: format!("{} states", theirs.len()),
            });
        }
        for (a, b) in ours.iter().zip(theirs.iter()) {
            if a.name != b.name {
                return Err(AnnotateError::Layout {
                    what,
                    graph: a.name.clone(),
                    mechanism: b.name.clone(),
                });
            }
        }
    }
    if eqs.rows.len() != sys.rows.len() {
        return Err(AnnotateError::Layout {
            what: "constraint rows",
            graph: eqs.rows.len().to_string(),
            mechanism: sys.rows.len().to_string(),
        });
    }
    let mut closures = Vec::with_capacity(sys.rows.len());
    let mut flows = Vec::with_capacity(sys.rows.len());
    for row in &sys.rows {
        let r = eqs
            .rows
            .iter()
            .find(|r| r.joint == row.joint && r.direction == row.direction)
            .ok_or_else(|| {
                AnnotateError::MissingElement(format!("{}.{}", row.joint, row.direction))
            })?;
        closures.push(r.closure.ok_or_else(|| {
            AnnotateError::MissingElement(format!("closure of {}.{}", row.joint, row.direction))
        })?);
        flows.push(r.flow);
    }
    sys.graph = eqs.graph;
    sys.mass = eqs.mass;
    sys.kinematics = eqs.kinematics;
    sys.forces = eqs.forces;
    sys.constraints = closures;
    sys.flow_rows = flows;
    sys.source = EquationSource::BondGraph;
    sys.inertias = eqs
        .inertias
        .iter()
        .map(|&e| g.element(e).name.clone())
        .collect();
    sys.bond_graph = Some(std::sync::Arc::new(g));
    Ok(eqs.stored)
}

/// The multibody system of a scene, its equations read off its bond graph where the graph is
/// complete (planar scenes in the non-rotating frame), assembled from the bodies otherwise
/// (the reason is kept in [`MultibodySystem::source`]).
pub fn build(scene: &Scene) -> Result<MultibodySystem, MechError> {
    let (mut sys, names) = Geometry::new(scene).system()?;
    let stored = match read_into(scene, &mut sys) {
        Ok(stored) => stored,
        Err(AnnotateError::Mech(e)) => return Err(e),
        Err(e) => {
            return Err(MechError::at(
                "bodies",
                format!("the mechanism's bond graph cannot be read as its equations: {e}"),
            ))
        }
    };
    let kin: Vec<BodyKinematics> = sys.bodies.iter().map(|(_, k)| k.clone()).collect();
    let (nq, nv) = (sys.nq(), sys.nv());
    sys.given_velocities = given_velocities(scene, &sys.bodies, (nq, nv));
    let reaction_columns = sys.reaction_columns();
    let mut columns = Columns {
        g: &mut sys.graph,
        scene,
        kin: &kin,
        nq,
        nv,
    };
    let (energy, kinetic) = columns.energy(&sys.mass, stored);
    sys.outputs = columns.outputs(&names, energy)?;
    sys.events = columns.events(&names, energy, &reaction_columns)?;
    sys.energy = energy;
    sys.kinetic = kinetic;
    Ok(sys)
}

/// Which of the `nv` velocities the scene gives: a body's translation where its `velocity` is
/// written, its rotation where its `angular_velocity` is (slots after the `nq` coordinates).
fn given_velocities(
    scene: &Scene,
    bodies: &[(String, BodyKinematics)],
    (nq, nv): (usize, usize),
) -> Vec<bool> {
    let mut given = vec![false; nv];
    let mut mark = |slots: &[u32]| {
        for &s in slots {
            if let Some(g) = (s as usize)
                .checked_sub(1 + nq)
                .and_then(|j| given.get_mut(j))
            {
                *g = true;
            }
        }
    };
    for b in &scene.bodies {
        let Some((_, kin)) = bodies.iter().find(|(name, _)| *name == b.name) else {
            continue;
        };
        let (translation, rotation): (Vec<u32>, Vec<u32>) = match kin {
            BodyKinematics::Ground => (vec![], vec![]),
            BodyKinematics::PlanarInertial { vx, vy, omega, .. } => {
                (vec![*vx, *vy], omega.iter().copied().collect())
            }
            BodyKinematics::PlanarBodyFixed { u, w, omega, .. } => (vec![*u, *w], vec![*omega]),
            BodyKinematics::Particle { v, .. } => (v.to_vec(), vec![]),
            BodyKinematics::Spatial { v, w, .. } => (v.to_vec(), w.to_vec()),
        };
        if b.velocity_given {
            mark(&translation);
        }
        if b.angular_velocity_given {
            mark(&rotation);
        }
    }
    given
}

/// The pinned bond graph of a mechanism scene, complete and self-contained: everything
/// [`mechanism_graph`] adds, plus the mechanism's output columns (`b.x`, `b.angle`,
/// `b.P.x`, …) and its energy as expressions of the graph's states, so that solving the graph
/// as a raw `"bond_graph"` scene ([`system_from_graph`]) gives the mechanism's run.
pub fn export_graph(scene: &Scene) -> Result<BondGraph, AnnotateError> {
    let sys = build(scene)?;
    let mut g = sys
        .bond_graph
        .as_deref()
        .cloned()
        .ok_or(AnnotateError::Unsupported(
            "a mechanism without its bond graph",
        ))?;
    let mut slot_names = vec!["t".to_string()];
    for d in &g.displacements {
        slot_names.push(format!("x_{}", g.element(d.element).name));
    }
    for f in &g.flows {
        slot_names.push(format!("f_{}", g.element(f.element).name));
    }
    let text = |e: Expr| {
        sys.graph
            .display_exact(e, &|s| quoted(&slot_names[s as usize]), EXACT_TEXT_LIMIT)
            .unwrap_or_else(|| "…".into())
    };
    g.outputs = sys
        .outputs
        .iter()
        .map(|o| GraphOutput {
            name: o.name.clone(),
            expr: text(o.expr),
            unwrap: o.unwrap,
        })
        .collect();
    g.energy = Some(text(sys.energy));
    Ok(g)
}

/// The multibody system of a bond graph that carries a mechanism's annotations (named
/// displacement states and flows, joint closures; see [`export_graph`]): every formulation
/// solves it like the mechanism it came from.
pub fn system_from_graph(g: &BondGraph) -> Result<MultibodySystem, AnnotateError> {
    let mut eqs = read_mechanics(g)?;
    let mut constraints = Vec::with_capacity(eqs.rows.len());
    let mut rows = Vec::with_capacity(eqs.rows.len());
    let mut flow_rows = Vec::with_capacity(eqs.rows.len());
    for r in &eqs.rows {
        let closure = r.closure.ok_or_else(|| {
            AnnotateError::MissingElement(format!(
                "closure of constraint junction '{}' (a graph solved as a mechanism needs every joint's closure)",
                g.element(r.junction).name
            ))
        })?;
        constraints.push(closure);
        flow_rows.push(r.flow);
        rows.push(ConstraintRow {
            joint: r.joint.clone(),
            direction: r.direction.clone(),
        });
    }
    let nq = eqs.nq();
    let mut kinetic_terms = Vec::new();
    for (j, &m) in eqs.mass.iter().enumerate() {
        if m != 0.0 {
            let v = eqs.graph.var((1 + nq + j) as u32);
            let v2 = eqs.graph.mul(v, v);
            kinetic_terms.push(eqs.graph.scale(0.5 * m, v2));
        }
    }
    let kinetic = eqs.graph.sum(&kinetic_terms);
    let energy = match &g.energy {
        Some(src) => eqs.parse("energy", src)?,
        None => eqs.graph.add(kinetic, eqs.stored),
    };
    let mut outputs = Vec::with_capacity(g.outputs.len());
    for o in &g.outputs {
        let expr = if o.name == "energy" {
            energy
        } else {
            eqs.parse(&o.name, &o.expr)?
        };
        outputs.push(OutputColumn {
            name: o.name.clone(),
            expr,
            unwrap: o.unwrap,
        });
    }
    let state = |v: &[crate::bond::mechanics::NamedState]| {
        v.iter()
            .map(|c| Coordinate {
                name: c.name.clone(),
                initial: c.initial,
            })
            .collect::<Vec<_>>()
    };
    Ok(MultibodySystem {
        coords: state(&eqs.coords),
        velocities: state(&eqs.velocities),
        given_velocities: Vec::new(),
        mass: eqs.mass.clone(),
        mass_symbols: Vec::new(),
        kinematics: eqs.kinematics.clone(),
        forces: eqs.forces.clone(),
        constraints,
        rows,
        energy,
        kinetic,
        outputs,
        warnings: Vec::new(),
        load_terms: Vec::new(),
        body_size: 0.0,
        reactions: Vec::new(),
        reaction_outputs: false,
        events: Vec::new(),
        drivers: Vec::new(),
        energy_exchange: g.energy_exchange(),
        bodies: Vec::new(),
        names: Vec::new(),
        flow_rows,
        source: EquationSource::BondGraph,
        inertias: eqs
            .inertias
            .iter()
            .map(|&e| g.element(e).name.clone())
            .collect(),
        bond_graph: Some(std::sync::Arc::new(g.clone())),
        graph: eqs.graph,
    })
}

/// A slot's name as expression text reads it back (`` `x_left-arm.omega` `` for a body called
/// `left-arm`, see [`crate::expr::quote_name`]).
fn quoted(name: &str) -> String {
    crate::expr::quote_name(name).into_owned()
}

/// Which variant of the mechanism to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// Joints kept: some inertias get differential causality (a DAE).
    Pinned,
    /// Joints replaced by stiff springs of this scene's `joint_stiffness` (an ODE).
    Decoupled,
}

/// Builds the bond graph of a scene: for [`Variant::Pinned`] its drawing (joints, springs and
/// loads in the seed's fragments; [`crate::mech::annotate`] completes it into the graph the
/// solver reads), for [`Variant::Decoupled`] the complete graph with its joints opened
/// ([`crate::bond::decouple`], the stiffness and damping of `scene.solve`).
pub fn scene_bond_graph(scene: &Scene, variant: Variant) -> Result<BondGraph, MechError> {
    match variant {
        // a spatial mechanism's graph is built whole by the completion (16.1–16.2: V and ω
        // junctions, the Euler junction structure, the quaternion's MTFs)
        Variant::Pinned if matches!(scene.dimension, Dimension::Spatial) => build(scene)?
            .bond_graph
            .as_deref()
            .cloned()
            .ok_or_else(|| MechError::at("bodies", "the mechanism has no bond graph")),
        Variant::Pinned => scene_bond_graph_with(scene, false),
        Variant::Decoupled => {
            let sys = build(scene)?;
            let pinned = sys.bond_graph.ok_or_else(|| {
                MechError::at("bodies", "the mechanism has no bond graph to decouple")
            })?;
            crate::bond::decouple::decouple(
                &pinned,
                scene.solve.joint_stiffness,
                scene.solve.joint_damping,
            )
            .map(|d| d.graph)
            .map_err(|e| MechError::at("solve.joint_stiffness", e.to_string()))
        }
    }
}
