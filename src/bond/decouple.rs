//! The decoupled twin as a transformation of the bond graph (seed 16.6, Fig. 17, 18 and 21).
//!
//! The chapter decouples a joint by opening it and putting a very stiff spring (and a damper)
//! where it was: the inertias that had differential causality get integral causality, and the
//! equations become an ODE with more degrees of freedom. [`decouple`] does exactly that to a
//! pinned mechanism's complete bond graph, junction by junction:
//!
//! * a **1-junction equating two flows** `f_a → J → f_b` (a pin's `V_A1 = V_A2`, Fig. 16)
//!   becomes a 0-junction forming the relative flow `f_a − f_b = G_k v`, on a new 1-junction
//!   `J.rel`;
//! * an **`Sf = 0`** holding a flow `f` (a pin to ground, a slider's row) becomes a 1-junction
//!   of that flow, oriented so that its flow is the row's `G_k v`;
//!
//! and on that flow a C `J.k` (compliance `1/k`) whose displacement is the joint's closure
//! `δ = g_k(x)` (so `δ' = G_k v`, checked by [`crate::bond::mechanics`]) and, when the damping
//! `c` is not zero, an R `J.c` in parallel. The junction's effort, `k g_k + c G_k v`, is the
//! spring-damper's force: the twin's counterpart of the multiplier `λ_k`. Read as a mechanism,
//! the graph gives
//!
//! ```text
//!   x' = K(x) v,   M v' = Q(t, x, v) − Σ_k (∂(G_k v)/∂v)ᵀ (k g_k(x) + c G_k v)
//! ```
//!
//! — the stiff-spring ODE CVODE solves, with nothing written beside the graph.
//!
//! ```
//! use bondmech::bond::decouple::decouple;
//! use bondmech::bond::model::{BondGraph, ConstraintJunction, Displacement, ElementKind, Parameter};
//! // a mass held at x = 0 by an Sf on its velocity junction
//! let mut g = BondGraph::new();
//! let v = g.add_junction("v", ElementKind::One);
//! let m = g.add_element("m", ElementKind::I, Some(Parameter::Const(1.0)));
//! g.add_bond(v, m);
//! let sf = g.add_element("pin.x", ElementKind::Sf, Some(Parameter::Const(0.0)));
//! g.add_bond(v, sf);
//! g.displacements.push(Displacement { element: v, name: "x".into(), initial: 0.0 });
//! g.constraint_junctions.push(ConstraintJunction {
//!     element: sf, joint: "pin".into(), direction: "x".into(), closure: Some("x_v".into()),
//! });
//! let twin = decouple(&g, 1e6, 0.0).unwrap();
//! assert!(twin.graph.constraint_junctions.is_empty());
//! let k = twin.graph.element(twin.springs[0].spring);
//! assert_eq!((k.name.as_str(), k.displacement.as_deref()), ("pin.x.k", Some("x_v")));
//! ```

use super::model::{BondGraph, ElementId, ElementKind, Parameter};

/// Why a graph has no decoupled twin.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DecoupleError {
    /// A flow source with a prescribed non-zero flow in a graph without annotated joints: it
    /// drives the graph rather than holding a joint, and has no spring to become.
    #[error("flow source '{source_name}' prescribes a flow that is not zero: only joints (Sf = 0 and two-bond 1-junctions) are opened by the decoupled twin")]
    DrivenFlow {
        /// The Sf's name.
        source_name: String,
    },
    /// A constraint junction that is neither a two-bond 1-junction nor an Sf.
    #[error("constraint junction '{junction}' must be a 1-junction with two bonds or an Sf to be opened")]
    Shape {
        /// Junction name.
        junction: String,
    },
    /// A stiffness that is not positive and finite, or a negative damping.
    #[error("joint stiffness {stiffness} must be positive and finite, joint damping {damping} finite and not negative")]
    Parameters {
        /// Joint stiffness `k`.
        stiffness: f64,
        /// Joint damping `c`.
        damping: f64,
    },
}

/// One opened joint row: the spring (and damper) put in its place.
#[derive(Debug, Clone, PartialEq)]
pub struct TwinSpring {
    /// The joint's name.
    pub joint: String,
    /// The row's direction.
    pub direction: String,
    /// The 1-junction carrying the row's flow `G_k v` (the spring's and damper's flow).
    pub junction: ElementId,
    /// The C of stiffness `k`, displacement `g_k(x)`.
    pub spring: ElementId,
    /// The R of damping `c` (absent when `c = 0`).
    pub damper: Option<ElementId>,
    /// `s = ±1`: the spring's displacement is `s g_k(x)` and its junction's flow `s G_k v`, so
    /// the row's force (the twin's `λ_k`) is `s` times the junction's effort. `−1` where the
    /// joint's Sf pointed at the body (`Sf → P`, a pin whose first body is the ground).
    pub sign: f64,
}

/// The decoupled twin of a pinned bond graph, with the springs in the order of the graph's
/// constraint junctions.
#[derive(Debug, Clone, PartialEq)]
pub struct DecoupledGraph {
    /// The graph with every constraint junction opened (no constraint junctions left).
    pub graph: BondGraph,
    /// The spring-damper of each former constraint row.
    pub springs: Vec<TwinSpring>,
}

/// Opens every constraint junction of `graph` and puts in a spring of stiffness `stiffness`
/// (and a damper of `damping`, when not zero) whose displacement is the joint's closure (see
/// the module documentation). A graph without annotated constraint junctions (the seed's own
/// form) has its joint rows opened as the causality reads them (every `Sf = 0` and every
/// two-bond 1-junction without storage), each spring a plain C whose displacement is the
/// integral of the row's flow from the start.
pub fn decouple(
    graph: &BondGraph,
    stiffness: f64,
    damping: f64,
) -> Result<DecoupledGraph, DecoupleError> {
    if !(stiffness.is_finite() && stiffness > 0.0 && damping.is_finite() && damping >= 0.0) {
        return Err(DecoupleError::Parameters { stiffness, damping });
    }
    let mut g = graph.clone();
    let mut junctions = std::mem::take(&mut g.constraint_junctions);
    if junctions.is_empty() && graph.displacements.is_empty() {
        // a graph without annotations (the seed's form; a mechanism's graph names its
        // coordinates and annotates every joint row, so one without joints has none): its
        // joint rows are its Sf and its two-bond 1-junctions (as the causality reads them),
        // without closures
        for e in super::causality::joint_row_elements(graph) {
            let el = graph.element(e);
            if el.kind == ElementKind::Sf && el.parameter != Some(Parameter::Const(0.0)) {
                return Err(DecoupleError::DrivenFlow {
                    source_name: el.name.clone(),
                });
            }
            junctions.push(super::model::ConstraintJunction {
                element: e,
                joint: el.name.clone(),
                direction: "flow".into(),
                closure: None,
            });
        }
    }
    let mut springs = Vec::with_capacity(junctions.len());
    for cj in junctions {
        let name = g.element(cj.element).name.clone();
        let closure = cj.closure.clone();
        let bonds = g.bonds_of(cj.element);
        let mut sign = 1.0;
        let rel = match g.element(cj.element).kind {
            // f_a → J → f_b: J becomes the 0-junction of f_a − f_b, carried by `J.rel`
            ElementKind::One if bonds.len() == 2 => {
                let into = bonds
                    .iter()
                    .filter(|&&b| g.bond(b).to == cj.element)
                    .count();
                if into != 1 {
                    if closure.is_some() {
                        return Err(DecoupleError::Shape { junction: name });
                    }
                    // both bonds into (or out of) J, as the seed draws a pin (Fig. 16: the
                    // pin forces equal and opposite): a TF of modulus −1 on the second bond
                    // turns its flow and effort, so that the 0-junction forms f_a − f_b and
                    // pushes both sides apart with the spring's one effort
                    let b = bonds[1];
                    let tf = g.add_element(
                        format!("{name}.turn"),
                        ElementKind::TF,
                        Some(Parameter::Const(-1.0)),
                    );
                    if g.bond(b).to == cj.element {
                        g.bonds[b.0].to = tf;
                        g.add_bond(tf, cj.element);
                    } else {
                        g.bonds[b.0].from = tf;
                        g.add_bond(cj.element, tf);
                    }
                }
                g.elements[cj.element.0].kind = ElementKind::Zero;
                let rel = g.add_junction(format!("{name}.rel"), ElementKind::One);
                g.add_bond(cj.element, rel);
                rel
            }
            // an Sf on the flow f becomes a 1-junction of f, the bond pointing into it (power
            // flows into the spring); its row was s f (s = −1 for `Sf → P`), so the spring's
            // displacement is s g_k: δ' = s (G_k v) = f
            ElementKind::Sf if bonds.len() == 1 => {
                let b = bonds[0];
                if g.bond(b).from == cj.element {
                    sign = -1.0;
                    let other = g.bond(b).to;
                    g.bonds[b.0].from = other;
                    g.bonds[b.0].to = cj.element;
                }
                let driven = !matches!(
                    g.element(cj.element).parameter,
                    Some(Parameter::Const(0.0)) | None
                );
                if driven {
                    // a driver stays a driver: its Sf(t) moves one end of the spring put in,
                    // `f_rel = f − Sf(t)` on a 0-junction, so the spring's displacement is the
                    // driver's closure `s(q) − s(t)` and its force the actuator's effort
                    let parameter = g.elements[cj.element.0].parameter.take();
                    let el = &mut g.elements[cj.element.0];
                    el.kind = ElementKind::Zero;
                    el.name = format!("{name}.twin");
                    let sf = g.add_element(name.clone(), ElementKind::Sf, parameter);
                    g.add_bond(cj.element, sf);
                    let rel = g.add_junction(format!("{name}.rel"), ElementKind::One);
                    g.add_bond(cj.element, rel);
                    rel
                } else {
                    let el = &mut g.elements[cj.element.0];
                    el.kind = ElementKind::One;
                    el.parameter = None;
                    cj.element
                }
            }
            _ => return Err(DecoupleError::Shape { junction: name }),
        };
        // without a closure the spring's displacement is its own state, the integral of the
        // row's flow from the start (zero there: the joint holds at the start)
        let spring_displacement = closure.map(|closure| {
            if sign < 0.0 {
                format!("-({closure})")
            } else {
                closure
            }
        });
        let spring = g.add_element(
            format!("{name}.k"),
            ElementKind::C,
            Some(Parameter::Const(1.0 / stiffness)),
        );
        g.add_bond(rel, spring);
        g.elements[spring.0].displacement = spring_displacement;
        let damper = (damping != 0.0).then(|| {
            let r = g.add_element(
                format!("{name}.c"),
                ElementKind::R,
                Some(Parameter::Const(damping)),
            );
            g.add_bond(rel, r);
            r
        });
        springs.push(TwinSpring {
            joint: cj.joint,
            direction: cj.direction,
            junction: rel,
            spring,
            damper,
            sign,
        });
    }
    Ok(DecoupledGraph { graph: g, springs })
}
