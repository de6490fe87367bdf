//! A bond graph read as a multibody system: the equations every mechanism formulation is built
//! from, taken from the graph itself (seed 16.5–16.8).
//!
//! Every inertia contributes one velocity unknown `v_j` (its flow) and every displacement state
//! `x_<element>` one coordinate. The joints' constraint junctions are *opened*: no flow passes
//! through them, so, starting from the inertias' flows, every other bond's flow follows from the
//! junction structure —
//!
//! * 1-junction: all flows equal; 0-junction: `Σ s_b f_b = 0` (`s_b = +1` for a bond pointing
//!   into it); TF/MTF: `f₂ = m f₁`,
//!
//! — as an expression `f_b(t, x, v)`, linear in `v`. Then
//!
//! * **kinematics**: `x' = f` of the displacement's element (the coordinate rates `K(x) v`);
//! * **constraint rows**: each constraint junction `k` compares the two flows that meet there,
//!   `G_k v = f_in − f_out` for a 1-junction (first body's point minus second's), and
//!   `G_k v = s (f − F)` for a flow source (`s = +1` when the bond points into the Sf);
//!   the junction's effort is the row's multiplier `λ_k` (the joint force);
//! * **generalized forces** by virtual power through the junction structure (power
//!   conserving, so the efforts reflected onto the inertias are its transpose):
//!   `Q_j = Σ_E −s_E e_E ∂f_E/∂v_j` over the sources, capacitors, resistors and the ports of
//!   gyrators (`e₁ = r f₂`, `e₂ = r f₁`), `s_E = +1` when the bond points into `E`;
//! * **closures** `g_k(x)` given on the constraint junctions, with the check
//!   `d/dt g_k = Σ_i ∂g_k/∂x_i x_i' = G_k v` at random states (likewise `d/dt δ = s f` for a
//!   capacitor whose displacement `δ(x)` is given as an expression).
//!
//! Unknown layout of every expression: slot 0 is `t`, then the coordinates (displacements,
//! then capacitor states, then signal states), then the velocities.
//!
//! ```
//! use bondmech::bond::model::{BondGraph, ElementKind, Parameter, Displacement, FlowState};
//! use bondmech::bond::mechanics::read_mechanics;
//! // a mass on a spring: I and C on one 1-junction, the C's displacement the junction's
//! let mut g = BondGraph::new();
//! let j = g.add_junction("v", ElementKind::One);
//! let m = g.add_element("m", ElementKind::I, Some(Parameter::Const(2.0)));
//! let k = g.add_element("k", ElementKind::C, Some(Parameter::Const(0.25)));
//! g.add_bond(j, m);
//! g.add_bond(j, k);
//! g.elements[k.0].displacement = Some("x_v".into());
//! g.displacements.push(Displacement { element: j, name: "x".into(), initial: 0.1 });
//! g.flows.push(FlowState { element: m, name: "v".into(), initial: 0.0 });
//! let eqs = read_mechanics(&g).unwrap();
//! // Q = −x/C = −4·x at x = 0.1
//! let q = eqs.graph.eval(eqs.forces[0], &[0.0, 0.1, 0.0]);
//! assert!((q + 0.4).abs() < 1e-15);
//! ```

use std::collections::HashMap;

use super::model::{BondGraph, BondId, ElementId, ElementKind, Parameter};
use crate::expr::{Expr, ExprGraph, ParseError};

/// Why a bond graph cannot be read as a mechanism.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MechanicsError {
    /// An element's value is missing or of the wrong kind.
    #[error("element '{element}': {what}")]
    Parameter {
        /// Element name.
        element: String,
        /// What is wrong.
        what: &'static str,
    },
    /// An expression does not parse against the graph's states and signals.
    #[error("element '{element}': expression {}: {source}", crate::expr::excerpt(expr, source.pos()))]
    Expression {
        /// Element (or signal) name.
        element: String,
        /// The expression.
        expr: String,
        /// Parser error.
        source: ParseError,
    },
    /// The inertias do not fix the flow an element needs.
    #[error("the flow at '{element}' is not fixed by the inertias' flows (it is needed {needed})")]
    UndeterminedFlow {
        /// Element name.
        element: String,
        /// What needs it.
        needed: &'static str,
    },
    /// A 1-junction equates two independent flows without being a joint's constraint junction.
    #[error("1-junction '{junction}' equates two independent flows but is not a joint's constraint junction (name it in `constraints`, or open it)")]
    HiddenConstraint {
        /// Junction name.
        junction: String,
    },
    /// A constraint junction that is not a two-bond 1-junction or a flow source.
    #[error("constraint junction '{junction}' must be a 1-junction with two bonds or an Sf")]
    ConstraintShape {
        /// Junction name.
        junction: String,
    },
    /// A closure whose time derivative is not the junction's flow constraint.
    #[error("joint '{joint}' ({direction}, junction '{junction}'): d/dt of the closure differs from the junction's flow constraint by {mismatch:.3e} at a test state (closure {closure})")]
    ClosureMismatch {
        /// Joint name.
        joint: String,
        /// Direction of the row.
        direction: String,
        /// Junction name.
        junction: String,
        /// The closure as written.
        closure: String,
        /// Largest difference found.
        mismatch: f64,
    },
    /// A C whose displacement expression does not integrate its flow.
    #[error("element '{element}': d/dt of its displacement {displacement} differs from its flow by {mismatch:.3e} at a test state")]
    DisplacementMismatch {
        /// Element name.
        element: String,
        /// The displacement as written.
        displacement: String,
        /// Largest difference found.
        mismatch: f64,
    },
}

/// One constraint row read off a constraint junction.
#[derive(Debug, Clone, PartialEq)]
pub struct MechanicalRow {
    /// The junction (1-junction or Sf).
    pub junction: ElementId,
    /// The joint's name (the Sf's or junction's own name in a graph without joints).
    pub joint: String,
    /// Direction of the row.
    pub direction: String,
    /// `G_k v`: the flow constraint at the junction.
    pub flow: Expr,
    /// `g_k(x)`, when the junction carries a closure.
    pub closure: Option<Expr>,
}

/// A named state with its initial value.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedState {
    /// Name (`bar1.x`, `bar1.vx`, `q_spring.k`).
    pub name: String,
    /// Initial value.
    pub initial: f64,
}

/// The multibody equations of a bond graph (see the module documentation).
#[derive(Debug, Clone)]
pub struct MechanicalEquations {
    /// Expression arena (slots `[t, x, v]`).
    pub graph: ExprGraph,
    /// Coordinates: displacements, capacitor states, signal states.
    pub coords: Vec<NamedState>,
    /// Velocities: the inertias' flows.
    pub velocities: Vec<NamedState>,
    /// The inertia of each velocity.
    pub inertias: Vec<ElementId>,
    /// `M`: the inertias' constant values.
    pub mass: Vec<f64>,
    /// Coordinate rates `x' = K(x) v`.
    pub kinematics: Vec<Expr>,
    /// Generalized forces `Q(t, x, v)` (without the joints' forces).
    pub forces: Vec<Expr>,
    /// Constraint rows, one per constraint junction.
    pub rows: Vec<MechanicalRow>,
    /// Flow of every bond (`None` where nothing fixes it).
    pub bond_flows: Vec<Option<Expr>>,
    /// Energy stored in the capacitors, `Σ ½ δ²/C`.
    pub stored: Expr,
    /// Capacitors given by a displacement expression: `(C, δ(x), s f)`, `s f` its flow in.
    pub capacitors: Vec<(ElementId, Expr, Expr)>,
    /// The names expressions of the graph may use (`t`, `x_…`, `q_…`, `p_…`, `f_…`, signals),
    /// for parsing further expressions over the same layout.
    pub names: HashMap<String, Expr>,
}

impl MechanicalEquations {
    /// Parses `src` over the graph's names (`owner` names it in errors).
    pub fn parse(&mut self, owner: &str, src: &str) -> Result<Expr, MechanicsError> {
        let names = &self.names;
        self.graph
            .parse(src, &mut |n| names.get(n).copied())
            .map_err(|source| MechanicsError::Expression {
                element: owner.to_string(),
                expr: src.to_string(),
                source,
            })
    }
}

impl MechanicalEquations {
    /// Number of coordinates.
    pub fn nq(&self) -> usize {
        self.coords.len()
    }
    /// Number of velocities.
    pub fn nv(&self) -> usize {
        self.velocities.len()
    }
    /// Initial slot vector `[0, x₀, v₀]`.
    pub fn initial_slots(&self) -> Vec<f64> {
        std::iter::once(0.0)
            .chain(self.coords.iter().map(|c| c.initial))
            .chain(self.velocities.iter().map(|v| v.initial))
            .collect()
    }
}

type Res<T> = Result<T, MechanicsError>;

struct Reader<'a> {
    g: &'a BondGraph,
    eg: ExprGraph,
    names: HashMap<String, Expr>,
    flows: Vec<Option<Expr>>,
    bonds_of: Vec<Vec<BondId>>,
    opened: Vec<bool>,
    /// Flow sources whose flow is prescribed into the graph (not a constraint row).
    sources: Vec<bool>,
    /// Extra symbols' slots and values ([`read_mechanics_with_names`]).
    symbols: Vec<(u32, f64)>,
}

/// Reads the multibody equations of a bond graph (see the module documentation).
pub fn read_mechanics(graph: &BondGraph) -> Result<MechanicalEquations, MechanicsError> {
    read_mechanics_in(graph, ExprGraph::new())
}

/// [`read_mechanics`], appending to an existing expression arena whose variable slots follow
/// the same layout `[t, x, v]` (so expressions built beside the graph, such as a mechanism's
/// output columns, stay valid).
pub fn read_mechanics_in(
    graph: &BondGraph,
    arena: ExprGraph,
) -> Result<MechanicalEquations, MechanicsError> {
    read_mechanics_with_names(graph, arena, &[])
}

/// [`read_mechanics_in`] where the parameters' expressions may also name `extra` symbols
/// (`(name, variable slot, value)`: a sensitivity run's parameters, [`crate::sensitivity`]);
/// the build-time checks evaluate them at their values.
pub fn read_mechanics_with_names(
    graph: &BondGraph,
    arena: ExprGraph,
    extra: &[(String, u32, f64)],
) -> Result<MechanicalEquations, MechanicsError> {
    let mut arena = arena;
    let names: HashMap<String, Expr> = extra
        .iter()
        .map(|(n, slot, _)| (n.clone(), arena.var(*slot)))
        .collect();
    let values: Vec<(u32, f64)> = extra.iter().map(|(_, s, v)| (*s, *v)).collect();
    let n_el = graph.elements.len();
    let mut bonds_of = vec![Vec::new(); n_el];
    for (i, b) in graph.bonds.iter().enumerate() {
        bonds_of[b.from.0].push(BondId(i));
        bonds_of[b.to.0].push(BondId(i));
    }
    let mut opened = vec![false; n_el];
    for c in &graph.constraint_junctions {
        opened[c.element.0] = true;
    }
    for (i, el) in graph.elements.iter().enumerate() {
        if el.kind == ElementKind::Sf {
            opened[i] = true;
        }
    }
    let r = Reader {
        g: graph,
        eg: arena,
        names,
        symbols: values,
        flows: vec![None; graph.bonds.len()],
        bonds_of,
        opened,
        sources: vec![false; n_el],
    };
    r.read()
}

impl Reader<'_> {
    fn name(&self, e: ElementId) -> String {
        self.g.element(e).name.clone()
    }

    /// `+1` when bond `b` points into element `e`.
    fn sign_into(&self, b: BondId, e: ElementId) -> f64 {
        if self.g.bond(b).to == e {
            1.0
        } else {
            -1.0
        }
    }

    fn parse(&mut self, owner: &str, src: &str) -> Res<Expr> {
        let names = &self.names;
        self.eg
            .parse(src, &mut |n| names.get(n).copied())
            .map_err(|source| MechanicsError::Expression {
                element: owner.to_string(),
                expr: src.to_string(),
                source,
            })
    }

    fn parameter(&mut self, e: ElementId, what: &'static str) -> Res<Expr> {
        let el = self.g.element(e);
        let name = el.name.clone();
        match el.parameter.clone() {
            None => Err(MechanicsError::Parameter {
                element: name,
                what,
            }),
            Some(Parameter::Const(c)) => Ok(self.eg.constant(c)),
            Some(Parameter::Expr(s)) => self.parse(&name, &s),
            Some(Parameter::Table { t, v }) => {
                let time = self.eg.var(0);
                Ok(self.eg.table(&t, &v, time))
            }
        }
    }

    fn read(mut self) -> Res<MechanicalEquations> {
        let g = self.g;
        // --- layout -------------------------------------------------------------------------
        let mut coords: Vec<NamedState> = g
            .displacements
            .iter()
            .map(|d| NamedState {
                name: d.name.clone(),
                initial: d.initial,
            })
            .collect();
        // integrated capacitor states (C without a displacement expression)
        let c_states: Vec<ElementId> = g
            .element_ids()
            .filter(|&e| {
                let el = g.element(e);
                el.kind == ElementKind::C && el.displacement.is_none()
            })
            .collect();
        for &c in &c_states {
            coords.push(NamedState {
                name: format!("q_{}", self.name(c)),
                initial: g.element(c).initial.unwrap_or(0.0),
            });
        }
        for s in &g.signal_states {
            coords.push(NamedState {
                name: s.name.clone(),
                initial: s.initial,
            });
        }
        let nq = coords.len();
        let inertias: Vec<ElementId> = g
            .element_ids()
            .filter(|&e| g.element(e).kind == ElementKind::I)
            .collect();
        let mut mass = Vec::with_capacity(inertias.len());
        for &i in &inertias {
            match g.element(i).parameter {
                Some(Parameter::Const(m)) => mass.push(m),
                _ => {
                    return Err(MechanicsError::Parameter {
                        element: self.name(i),
                        what: "an inertia read as a mechanism needs a constant value",
                    })
                }
            }
        }
        let velocities: Vec<NamedState> = inertias
            .iter()
            .zip(&mass)
            .map(|(&i, &m)| match g.flows.iter().find(|f| f.element == i) {
                Some(f) => NamedState {
                    name: f.name.clone(),
                    initial: f.initial,
                },
                None => NamedState {
                    name: format!("f_{}", self.name(i)),
                    initial: if m != 0.0 {
                        g.element(i).initial.unwrap_or(0.0) / m
                    } else {
                        0.0
                    },
                },
            })
            .collect();
        let q_slot = |k: usize| (1 + k) as u32;
        let v_slot = |j: usize| (1 + nq + j) as u32;
        // --- names: t, x_<element>, q_<C>, signal states, p_<I>, f_<I> ---------------------------
        let t = self.eg.var(0);
        self.names.insert("t".into(), t);
        for (k, d) in g.displacements.iter().enumerate() {
            let x = self.eg.var(q_slot(k));
            self.names.insert(format!("x_{}", self.name(d.element)), x);
        }
        for (k, &c) in c_states.iter().enumerate() {
            let x = self.eg.var(q_slot(g.displacements.len() + k));
            self.names.insert(format!("q_{}", self.name(c)), x);
        }
        let first_signal = g.displacements.len() + c_states.len();
        for (k, s) in g.signal_states.iter().enumerate() {
            let x = self.eg.var(q_slot(first_signal + k));
            self.names.insert(s.name.clone(), x);
        }
        for (j, (&i, &m)) in inertias.iter().zip(&mass).enumerate() {
            let v = self.eg.var(v_slot(j));
            let p = self.eg.scale(m, v);
            let n = self.name(i);
            self.names.insert(format!("p_{n}"), p);
            self.names.insert(format!("f_{n}"), v);
        }
        for d in &g.signal_definitions {
            let e = self.parse(&d.name, &d.expr)?;
            self.names.insert(d.name.clone(), e);
        }
        // --- flows --------------------------------------------------------------------------
        for (j, &i) in inertias.iter().enumerate() {
            let v = self.eg.var(v_slot(j));
            for &b in &self.bonds_of[i.0].clone() {
                self.flows[b.0] = Some(v);
            }
        }
        self.propagate()?;
        self.check_hidden_constraints()?;
        for e in g.element_ids() {
            if g.element(e).kind == ElementKind::One && !self.opened[e.0] {
                if let Some(f) = self.junction_flow(e) {
                    self.names.insert(format!("f_{}", self.name(e)), f);
                }
            }
        }
        // --- kinematics ---------------------------------------------------------------------
        let mut kinematics = Vec::with_capacity(nq);
        for d in &g.displacements {
            let f = self.element_flow(d.element, "for its displacement state")?;
            kinematics.push(f);
        }
        for &c in &c_states {
            let b = self.bonds_of[c.0][0];
            let f = self.flow(b, c, "for the capacitor's state")?;
            let s = self.sign_into(b, c);
            kinematics.push(self.eg.scale(s, f));
        }
        for s in &g.signal_states {
            let e = self.parse(&s.name, &s.rate)?;
            kinematics.push(e);
        }
        // --- forces -------------------------------------------------------------------------
        let nv = inertias.len();
        let mut terms: Vec<Vec<Expr>> = vec![Vec::new(); nv];
        let mut stored = Vec::new();
        let mut capacitors = Vec::new();
        let v_slots: Vec<u32> = (0..nv).map(v_slot).collect();
        for e in g.element_ids() {
            let el = g.element(e);
            let mut efforts: Vec<(BondId, f64, Expr)> = Vec::new();
            match el.kind {
                ElementKind::Se => {
                    let b = self.bonds_of[e.0][0];
                    let v = self.parameter(e, "an effort source needs a value")?;
                    efforts.push((b, self.sign_into(b, e), v));
                }
                ElementKind::C => {
                    let b = self.bonds_of[e.0][0];
                    let delta = match &el.displacement {
                        Some(src) => self.parse(&el.name, src)?,
                        None => self.names[&format!("q_{}", el.name)],
                    };
                    let c = self.parameter(e, "a capacitor needs its compliance")?;
                    if el.displacement.is_some() {
                        let f = self.flow(b, e, "for its displacement")?;
                        let f_in = self.eg.scale(self.sign_into(b, e), f);
                        capacitors.push((e, delta, f_in));
                    }
                    let eff = self.eg.div(delta, c);
                    let d2 = self.eg.mul(delta, eff);
                    stored.push(self.eg.scale(0.5, d2));
                    efforts.push((b, self.sign_into(b, e), eff));
                }
                ElementKind::R => {
                    let b = self.bonds_of[e.0][0];
                    let s = self.sign_into(b, e);
                    let f = self.flow(b, e, "for the resistor's effort")?;
                    let f_in = self.eg.scale(s, f);
                    let eff = match &el.law {
                        Some(law) => {
                            let Some(src) = &law.effort else {
                                return Err(MechanicsError::Parameter {
                                    element: el.name.clone(),
                                    what: "a resistor read as a mechanism needs `effort_law` (its flow is imposed)",
                                });
                            };
                            let names = &self.names;
                            self.eg
                                .parse(src, &mut |n| {
                                    if n == "f" {
                                        Some(f_in)
                                    } else {
                                        names.get(n).copied()
                                    }
                                })
                                .map_err(|source| MechanicsError::Expression {
                                    element: el.name.clone(),
                                    expr: src.clone(),
                                    source,
                                })?
                        }
                        None => {
                            let r = self.parameter(e, "a resistor needs its resistance")?;
                            self.eg.mul(r, f_in)
                        }
                    };
                    efforts.push((b, s, eff));
                }
                ElementKind::GY | ElementKind::MGY => {
                    let bs = self.bonds_of[e.0].clone();
                    let (b1, b2) = if self.g.bond(bs[0]).to == e {
                        (bs[0], bs[1])
                    } else {
                        (bs[1], bs[0])
                    };
                    let r = self.parameter(e, "a gyrator needs its modulus")?;
                    let f1 = self.flow(b1, e, "for the gyrator's efforts")?;
                    let f2 = self.flow(b2, e, "for the gyrator's efforts")?;
                    let e1 = self.eg.mul(r, f2);
                    let e2 = self.eg.mul(r, f1);
                    efforts.push((b1, 1.0, e1));
                    efforts.push((b2, -1.0, e2));
                }
                _ => {}
            }
            for (b, s, eff) in efforts {
                let f = self.flow(b, e, "for the effort it applies")?;
                for (j, &slot) in v_slots.iter().enumerate() {
                    if self.eg.depends_on(f, slot) {
                        let d = self.eg.diff(f, slot);
                        let w = self.eg.mul(d, eff);
                        terms[j].push(self.eg.scale(-s, w));
                    }
                }
            }
        }
        let forces: Vec<Expr> = terms.iter().map(|t| self.eg.sum(t)).collect();
        let stored = self.eg.sum(&stored);
        // --- constraint rows ----------------------------------------------------------------
        let mut rows = Vec::new();
        let mut seen = vec![false; g.elements.len()];
        let annotated: Vec<(ElementId, String, String, Option<String>)> = g
            .constraint_junctions
            .iter()
            .map(|c| {
                (
                    c.element,
                    c.joint.clone(),
                    c.direction.clone(),
                    c.closure.clone(),
                )
            })
            .collect();
        let bare: Vec<(ElementId, String, String, Option<String>)> = g
            .element_ids()
            .filter(|&e| g.element(e).kind == ElementKind::Sf)
            .filter(|e| !g.constraint_junctions.iter().any(|c| c.element == *e))
            .filter(|e| !self.sources[e.0])
            .map(|e| (e, self.name(e), String::new(), None))
            .collect();
        for (e, joint, direction, closure) in annotated.into_iter().chain(bare) {
            if std::mem::replace(&mut seen[e.0], true) {
                continue;
            }
            let flow = self.row(e)?;
            let closure = match closure {
                Some(src) => Some(self.parse(&format!("{joint}.{direction}"), &src)?),
                None => None,
            };
            rows.push(MechanicalRow {
                junction: e,
                joint,
                direction,
                flow,
                closure,
            });
        }
        let eqs = MechanicalEquations {
            graph: self.eg,
            coords,
            velocities,
            inertias,
            mass,
            kinematics,
            forces,
            rows,
            bond_flows: self.flows,
            stored,
            capacitors,
            names: self.names,
        };
        check_integrals(g, &eqs, &self.symbols)?;
        Ok(eqs)
    }

    /// Sets flows until nothing changes.
    fn propagate(&mut self) -> Res<()> {
        loop {
            let mut changed = false;
            for e in self.g.element_ids() {
                let kind = self.g.element(e).kind;
                if self.opened[e.0] {
                    continue;
                }
                let bs = self.bonds_of[e.0].clone();
                match kind {
                    ElementKind::One => {
                        if let Some(f) = bs.iter().find_map(|b| self.flows[b.0]) {
                            for b in &bs {
                                if self.flows[b.0].is_none() {
                                    self.flows[b.0] = Some(f);
                                    changed = true;
                                }
                            }
                        }
                    }
                    ElementKind::Zero => {
                        let unknown: Vec<BondId> = bs
                            .iter()
                            .copied()
                            .filter(|b| self.flows[b.0].is_none())
                            .collect();
                        if unknown.len() == 1 {
                            let u = unknown[0];
                            let mut acc = Vec::new();
                            for &b in &bs {
                                if b != u {
                                    let f = self.flows[b.0].expect("known");
                                    acc.push(self.eg.scale(self.sign_into(b, e), f));
                                }
                            }
                            let sum = self.eg.sum(&acc);
                            let f = self.eg.scale(-self.sign_into(u, e), sum);
                            self.flows[u.0] = Some(f);
                            changed = true;
                        }
                    }
                    ElementKind::TF | ElementKind::MTF => {
                        let (b1, b2) = if self.g.bond(bs[0]).to == e {
                            (bs[0], bs[1])
                        } else {
                            (bs[1], bs[0])
                        };
                        match (self.flows[b1.0], self.flows[b2.0]) {
                            (Some(f1), None) => {
                                let m = self.parameter(e, "a transformer needs its modulus")?;
                                self.flows[b2.0] = Some(self.eg.mul(m, f1));
                                changed = true;
                            }
                            (None, Some(f2)) => {
                                let m = self.parameter(e, "a transformer needs its modulus")?;
                                self.flows[b1.0] = Some(self.eg.div(f2, m));
                                changed = true;
                            }
                            _ => {}
                        }
                    }
                    _ => {}
                }
            }
            if !changed {
                // a flow source the inertias' flows leave undetermined (on a 0-junction
                // beside another unknown flow: a driver's Sf(t) moving one end of the twin's
                // spring) is a prescribed flow, not a row: its bond carries its value
                let sources: Vec<ElementId> = self
                    .g
                    .element_ids()
                    .filter(|&e| {
                        self.g.element(e).kind == ElementKind::Sf
                            && self.bonds_of[e.0].len() == 1
                            && self.flows[self.bonds_of[e.0][0].0].is_none()
                            && !self.g.constraint_junctions.iter().any(|c| c.element == e)
                            && !self.g.displacements.is_empty()
                    })
                    .collect();
                if sources.is_empty() {
                    return Ok(());
                }
                for e in sources {
                    let b = self.bonds_of[e.0][0];
                    let f = self.parameter(e, "a flow source needs a value")?;
                    self.flows[b.0] = Some(f);
                    self.sources[e.0] = true;
                }
            }
        }
    }

    /// A non-opened 1-junction whose bonds got different flows equates two independent flows.
    fn check_hidden_constraints(&mut self) -> Res<()> {
        let probe = probe_states(self.g, 1);
        for e in self.g.element_ids() {
            if self.g.element(e).kind != ElementKind::One || self.opened[e.0] {
                continue;
            }
            let fs: Vec<Expr> = self.bonds_of[e.0]
                .iter()
                .filter_map(|b| self.flows[b.0])
                .collect();
            for w in fs.windows(2) {
                if w[0] != w[1] {
                    let d = self.eg.sub(w[0], w[1]);
                    if probe.iter().any(|x| self.eg.eval(d, x).abs() > 1e-12) {
                        return Err(MechanicsError::HiddenConstraint {
                            junction: self.name(e),
                        });
                    }
                }
            }
        }
        Ok(())
    }

    fn junction_flow(&self, e: ElementId) -> Option<Expr> {
        self.bonds_of[e.0].iter().find_map(|b| self.flows[b.0])
    }

    fn flow(&self, b: BondId, owner: ElementId, needed: &'static str) -> Res<Expr> {
        self.flows[b.0].ok_or_else(|| MechanicsError::UndeterminedFlow {
            element: self.name(owner),
            needed,
        })
    }

    fn element_flow(&self, e: ElementId, needed: &'static str) -> Res<Expr> {
        self.junction_flow(e)
            .ok_or_else(|| MechanicsError::UndeterminedFlow {
                element: self.name(e),
                needed,
            })
    }

    /// `G_k v` at constraint junction `e` (see the module documentation).
    fn row(&mut self, e: ElementId) -> Res<Expr> {
        let bs = self.bonds_of[e.0].clone();
        match self.g.element(e).kind {
            ElementKind::Sf if bs.len() == 1 => {
                let b = bs[0];
                let f = self.flow(b, e, "for its constraint row")?;
                let src = self.parameter(e, "a flow source needs a value")?;
                let d = self.eg.sub(f, src);
                Ok(self.eg.scale(self.sign_into(b, e), d))
            }
            ElementKind::One if bs.len() == 2 => {
                let (bi, bo) = if self.g.bond(bs[0]).to == e || self.g.bond(bs[1]).to != e {
                    (bs[0], bs[1])
                } else {
                    (bs[1], bs[0])
                };
                let fi = self.flow(bi, e, "for its constraint row")?;
                let fo = self.flow(bo, e, "for its constraint row")?;
                Ok(self.eg.sub(fi, fo))
            }
            _ => Err(MechanicsError::ConstraintShape {
                junction: self.name(e),
            }),
        }
    }
}

/// Deterministic pseudo-random states `[t, x, v]` near the initial one (for the build-time
/// checks), `n` of them.
fn probe_states(g: &BondGraph, n: usize) -> Vec<Vec<f64>> {
    let n_slots = 1
        + g.displacements.len()
        + g.elements
            .iter()
            .filter(|e| e.kind == ElementKind::C && e.displacement.is_none())
            .count()
        + g.signal_states.len()
        + g.elements
            .iter()
            .filter(|e| e.kind == ElementKind::I)
            .count();
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n)
        .map(|_| (0..n_slots).map(|_| 0.5 + next()).collect())
        .collect()
}

/// Checks `d/dt g_k = G_k v` for every closure and `d/dt δ = s f` for every capacitor given by
/// its displacement, at random states near the initial one.
fn check_integrals(g: &BondGraph, eqs: &MechanicalEquations, symbols: &[(u32, f64)]) -> Res<()> {
    let mut eg = eqs.graph.clone();
    // extra symbols at their values
    let values: Vec<(u32, Expr)> = symbols.iter().map(|&(s, v)| (s, eg.constant(v))).collect();
    let at_values = |eg: &mut ExprGraph, e: Expr| -> Expr {
        if values.is_empty() {
            e
        } else {
            eg.substitute(e, &values)
        }
    };
    let nq = eqs.nq();
    let x0 = eqs.initial_slots();
    let mut probes = probe_states(g, 3);
    for p in &mut probes {
        for (k, v) in p.iter_mut().enumerate() {
            *v = x0[k] + 0.3 * (*v - 0.5);
        }
    }
    let rate = |eg: &mut ExprGraph, e: Expr| -> Expr {
        let mut terms = Vec::new();
        let t = eg.diff(e, 0);
        terms.push(t);
        // only the coordinates the expression mentions (linear in the mechanism's size)
        for s in eg.vars(e) {
            let k = s as usize;
            if (1..=nq).contains(&k) {
                let d = eg.diff(e, s);
                terms.push(eg.mul(d, eqs.kinematics[k - 1]));
            }
        }
        eg.sum(&terms)
    };
    let mismatch = |eg: &ExprGraph, a: Expr, b: Expr| -> f64 {
        probes
            .iter()
            .map(|x| {
                let (u, w) = (eg.eval(a, x), eg.eval(b, x));
                let m = (u - w).abs() / (1.0 + u.abs().max(w.abs()));
                if m.is_nan() {
                    f64::INFINITY
                } else {
                    m
                }
            })
            .fold(0.0, f64::max)
    };
    for r in &eqs.rows {
        let Some(c) = r.closure else { continue };
        let d = rate(&mut eg, c);
        let (d, flow) = (at_values(&mut eg, d), at_values(&mut eg, r.flow));
        let m = mismatch(&eg, d, flow);
        if m > 1e-9 {
            let closure = g
                .constraint_junctions
                .iter()
                .find(|cj| cj.element == r.junction)
                .and_then(|cj| cj.closure.clone())
                .unwrap_or_default();
            return Err(MechanicsError::ClosureMismatch {
                joint: r.joint.clone(),
                direction: r.direction.clone(),
                junction: g.element(r.junction).name.clone(),
                closure,
                mismatch: m,
            });
        }
    }
    for &(c, delta, f_in) in &eqs.capacitors {
        let d = rate(&mut eg, delta);
        let (d, f_in) = (at_values(&mut eg, d), at_values(&mut eg, f_in));
        let m = mismatch(&eg, d, f_in);
        if m > 1e-9 {
            let el = g.element(c);
            return Err(MechanicsError::DisplacementMismatch {
                element: el.name.clone(),
                displacement: el.displacement.clone().unwrap_or_default(),
                mismatch: m,
            });
        }
    }
    Ok(())
}
