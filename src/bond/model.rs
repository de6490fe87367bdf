//! Bond graph data model: elements, bonds and a small builder.
//!
//! A bond carries effort `e` and flow `f`; its half arrow points from `from` to `to`
//! and marks the direction in which the power `P = e·f` is counted positive.
//!
//! Two-port convention (TF, GY, MTF, MGY): **port 1** is the bond whose half arrow points
//! *into* the two-port, **port 2** the bond whose half arrow points *out of* it.
//! - TF/MTF with modulus `m`: `e1 = m·e2`, `f2 = m·f1`.
//! - GY/MGY with modulus `r`: `e1 = r·f2`, `e2 = r·f1`.
//!
//! One-port parameters: Se effort, Sf flow, I inertia (`p = I·f`), C **compliance**
//! (`q = C·e`; a stiffness `k` given in JSON is stored as `1/k`), R resistance (`e = R·f`).

use serde::{Deserialize, Serialize};

/// Index of an element inside a [`BondGraph`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ElementId(pub usize);

/// Index of a bond inside a [`BondGraph`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BondId(pub usize);

/// The kind of a bond graph element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ElementKind {
    /// Effort source.
    Se,
    /// Flow source.
    Sf,
    /// Inertia (stores momentum `p`, `f = p/I`).
    I,
    /// Capacitor (stores displacement `q`, `e = q/C`).
    C,
    /// Resistor (`e = R·f`).
    R,
    /// Transformer, constant modulus.
    TF,
    /// Gyrator, constant modulus.
    GY,
    /// Modulated transformer (modulus an expression of states and time).
    MTF,
    /// Modulated gyrator (modulus an expression of states and time).
    MGY,
    /// 0-junction: common effort, flows sum to zero.
    #[serde(rename = "0")]
    Zero,
    /// 1-junction: common flow, efforts sum to zero.
    #[serde(rename = "1")]
    One,
}

impl ElementKind {
    /// The JSON spelling of the kind ("Se", …, "0", "1").
    pub fn as_str(self) -> &'static str {
        match self {
            ElementKind::Se => "Se",
            ElementKind::Sf => "Sf",
            ElementKind::I => "I",
            ElementKind::C => "C",
            ElementKind::R => "R",
            ElementKind::TF => "TF",
            ElementKind::GY => "GY",
            ElementKind::MTF => "MTF",
            ElementKind::MGY => "MGY",
            ElementKind::Zero => "0",
            ElementKind::One => "1",
        }
    }

    /// Parses the JSON spelling of a kind.
    pub fn parse(s: &str) -> Option<ElementKind> {
        Some(match s {
            "Se" => ElementKind::Se,
            "Sf" => ElementKind::Sf,
            "I" => ElementKind::I,
            "C" => ElementKind::C,
            "R" => ElementKind::R,
            "TF" => ElementKind::TF,
            "GY" => ElementKind::GY,
            "MTF" => ElementKind::MTF,
            "MGY" => ElementKind::MGY,
            "0" => ElementKind::Zero,
            "1" => ElementKind::One,
            _ => return None,
        })
    }

    /// Se, Sf, I, C or R: exactly one bond.
    pub fn is_one_port(self) -> bool {
        matches!(
            self,
            ElementKind::Se | ElementKind::Sf | ElementKind::I | ElementKind::C | ElementKind::R
        )
    }

    /// TF, GY, MTF or MGY: exactly two bonds, one in and one out.
    pub fn is_two_port(self) -> bool {
        matches!(
            self,
            ElementKind::TF | ElementKind::GY | ElementKind::MTF | ElementKind::MGY
        )
    }

    /// 0- or 1-junction.
    pub fn is_junction(self) -> bool {
        matches!(self, ElementKind::Zero | ElementKind::One)
    }

    /// I or C.
    pub fn is_storage(self) -> bool {
        matches!(self, ElementKind::I | ElementKind::C)
    }

    /// TF or MTF (transformer-like causality: one stroke in, one out).
    pub fn is_transformer(self) -> bool {
        matches!(self, ElementKind::TF | ElementKind::MTF)
    }

    /// GY or MGY (gyrator-like causality: both strokes in or both out).
    pub fn is_gyrator(self) -> bool {
        matches!(self, ElementKind::GY | ElementKind::MGY)
    }
}

/// The value of an element: source value, inertia, compliance, resistance or modulus.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Parameter {
    /// A constant.
    Const(f64),
    /// An expression in `t`, `p_<I>`, `x_<I or 1-junction>`, `q_<C>` and declared signals.
    Expr(String),
    /// A piecewise-linear table of time `t` (strictly increasing) against value `v`.
    Table {
        /// Sample times.
        t: Vec<f64>,
        /// Values at the sample times.
        v: Vec<f64>,
    },
}

/// A bond graph element.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Unique name (e.g. `bar1.I_m_x`).
    pub name: String,
    /// Kind of element.
    pub kind: ElementKind,
    /// Value/modulus (None for junctions). For C this is the compliance.
    pub parameter: Option<Parameter>,
    /// Display label (e.g. `-0.5·sin(α)`); the name is used when absent.
    pub label: Option<String>,
    /// Initial value of a storage element's state (momentum of I, displacement of C);
    /// `None` means 0. Ignored for storages in differential causality (their state follows
    /// from the constraint).
    pub initial: Option<f64>,
    /// Nonlinear constitutive law of an R element (instead of a resistance `parameter`).
    pub law: Option<ResistorLaw>,
    /// For a C: its displacement as an expression of the graph's displacement states and
    /// signals (`q_C = δ(x)`, e.g. a spring's stretch `L(x) − L₀`, or a decoupled joint's closure
    /// `g_k(x)`), instead of an integrated state of its own. Its time derivative is the C's
    /// flow, which [`crate::bond::mechanics`] checks at build time.
    pub displacement: Option<String>,
}

/// The constitutive law of a nonlinear resistor, `e = Φ(f)` and/or `f = Φ⁻¹(e)`, with `e` and
/// `f` counted *into* the resistor (so the power it dissipates is `e·f`).
///
/// Which form the equations use depends on the causality assignment gives the resistor: resistance
/// causality (its flow is imposed) needs `effort`, conductance causality (its effort is
/// imposed) needs `flow`. Both may be given. The expressions may also use time `t`, states
/// (`p_<I>`, `q_<C>`, `x_<I>`, `x_<1-junction>`) and signals, like any modulus.
///
/// ```
/// use bondmech::bond::model::ResistorLaw;
/// // quadratic drag, e = c·f·|f| with c = 0.3
/// let drag = ResistorLaw { effort: Some("0.3*f*abs(f)".into()), flow: None };
/// assert!(drag.flow.is_none());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ResistorLaw {
    /// `e = Φ(f, states, t)`: names the flow into the resistor `f`.
    pub effort: Option<String>,
    /// `f = Φ⁻¹(e, states, t)`: names the effort on the resistor `e`.
    pub flow: Option<String>,
}

/// A bond: half arrow from `from` to `to` (positive power direction).
#[derive(Debug, Clone, PartialEq)]
pub struct Bond {
    /// Unique name (`b<index>` by default).
    pub name: String,
    /// Element at the tail of the half arrow.
    pub from: ElementId,
    /// Element at the head of the half arrow.
    pub to: ElementId,
}

/// A bond graph: elements and bonds, addressed by typed ids.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BondGraph {
    /// Elements in insertion order (the order causality assignment follows).
    pub elements: Vec<Element>,
    /// Bonds in insertion order.
    pub bonds: Vec<Bond>,
    /// Names of externally supplied signals that expressions may reference
    /// (e.g. attitude matrix entries computed outside the bond graph).
    pub signals: Vec<String>,
    /// The junctions (1-junctions or Sf) that impose a joint's constraint rows, with the joint
    /// and direction they belong to (filled by the mechanism builder; empty for a raw graph).
    pub constraint_junctions: Vec<ConstraintJunction>,
    /// Displacement states `x_<element>` (∫ of a 1-junction's or an inertia's flow) that are
    /// coordinates of the mechanism, with their names and initial values. Moduli, closures
    /// and outputs use them.
    pub displacements: Vec<Displacement>,
    /// Names and initial flows of the inertias, for a graph read as a mechanism
    /// ([`crate::bond::mechanics`]); an inertia without an entry is named `f_<I>` and starts
    /// from its `initial` momentum divided by its inertia.
    pub flows: Vec<FlowState>,
    /// Signal states carried by the graph (e.g. a body's attitude quaternion `e' = ½ e ⊗ ω`).
    pub signal_states: Vec<SignalState>,
    /// Signals defined as expressions of the states (e.g. rotation matrix entries `R_ij(e)`).
    pub signal_definitions: Vec<SignalDefinition>,
    /// Named output columns of a graph read as a mechanism (e.g. a body point's position
    /// `bar2.A.x`), as expressions of the states (`x_<element>`, `f_<I>`, signals, `t`).
    pub outputs: Vec<GraphOutput>,
    /// The mechanical energy of a graph read as a mechanism, as an expression of the states.
    pub energy: Option<String>,
    /// Inertias the causality puts in differential causality first, where the junction
    /// structure leaves a choice ([`crate::bond::causality`]): the modeller's pick among the
    /// admissible assignments (seed 16.5: which inertias the joints make dependent is not
    /// unique). A mechanism's graph lists the body-frame angular inertias of each freely
    /// rotating spatial body, so that its centre's velocity is its states
    /// ([`crate::mech::annotate`]).
    pub prefer_differential: Vec<String>,
}

/// A named output column of a graph read as a mechanism.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphOutput {
    /// Column name.
    pub name: String,
    /// Its expression.
    pub expr: String,
    /// An angle to unwrap (continuous across ±π) after evaluation.
    pub unwrap: bool,
}

/// A displacement state `x_<element> = x₀ + ∫ f dt`, `f` the common flow of a 1-junction or
/// the flow of an inertia: one generalized coordinate of a mechanism (seed 16.3: the angle α
/// that modulates a body's MTFs is the displacement of its ω junction).
#[derive(Debug, Clone, PartialEq)]
pub struct Displacement {
    /// The 1-junction or I whose flow integrates to it.
    pub element: ElementId,
    /// Coordinate name (`bar1.x`, `bar1.angle`).
    pub name: String,
    /// Value at the start time.
    pub initial: f64,
}

/// The flow of an inertia as a named velocity unknown.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowState {
    /// The inertia.
    pub element: ElementId,
    /// Velocity name (`bar1.vx`, `bar1.omega`).
    pub name: String,
    /// Initial flow.
    pub initial: f64,
}

/// A state carried by the graph as a signal: `s' = rate(x, s, f_<junction>, t)`.
#[derive(Debug, Clone, PartialEq)]
pub struct SignalState {
    /// Signal name (usable in expressions).
    pub name: String,
    /// Value at the start time.
    pub initial: f64,
    /// Its time derivative; may use the common flow of a 1-junction as `f_<junction>`.
    pub rate: String,
}

/// A signal defined as an expression of states and other signals.
#[derive(Debug, Clone, PartialEq)]
pub struct SignalDefinition {
    /// Signal name (usable in expressions).
    pub name: String,
    /// Its definition.
    pub expr: String,
}

/// A junction that imposes one constraint row of a joint (seed 16.5, 16.7): the 1-junction
/// equating two bodies' flows along one direction, or the Sf = 0 on one body's flow.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintJunction {
    /// The junction (or Sf).
    pub element: ElementId,
    /// The joint's name in the scene.
    pub joint: String,
    /// The direction of the row (`x`, `y`, `axis1`, `w`, …).
    pub direction: String,
    /// The position-level closure `g_k(x)` whose time derivative is this junction's flow
    /// constraint (an expression of the displacement states and signals); `None` in a graph
    /// that only constrains velocities.
    pub closure: Option<String>,
}

impl BondGraph {
    /// Why the graph's stored energy `Σ p²/2m + Σ q²/2C` is not conserved: its first resistor
    /// or source that delivers power (a constant zero source does not); `None` when it is.
    pub fn energy_exchange(&self) -> Option<String> {
        self.elements
            .iter()
            .find_map(|e| match (e.kind, &e.parameter) {
                (ElementKind::R, _) => Some(format!("resistor '{}' dissipates energy", e.name)),
                (ElementKind::Se | ElementKind::Sf, Some(Parameter::Const(v))) if *v == 0.0 => None,
                (ElementKind::Se | ElementKind::Sf, _) => {
                    Some(format!("source '{}' delivers power", e.name))
                }
                _ => None,
            })
    }

    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends an element and returns its id (names are checked by validation).
    pub fn add_element(
        &mut self,
        name: impl Into<String>,
        kind: ElementKind,
        parameter: Option<Parameter>,
    ) -> ElementId {
        self.elements.push(Element {
            name: name.into(),
            kind,
            parameter,
            label: None,
            initial: None,
            law: None,
            displacement: None,
        });
        ElementId(self.elements.len() - 1)
    }

    /// Sets the initial state of a storage element (momentum of I, displacement of C).
    pub fn set_initial(&mut self, id: ElementId, value: f64) {
        if let Some(e) = self.elements.get_mut(id.0) {
            e.initial = Some(value);
        }
    }

    /// Appends a junction (no parameter).
    pub fn add_junction(&mut self, name: impl Into<String>, kind: ElementKind) -> ElementId {
        self.add_element(name, kind, None)
    }

    /// Sets the display label of an element.
    pub fn set_label(&mut self, id: ElementId, label: impl Into<String>) {
        if let Some(e) = self.elements.get_mut(id.0) {
            e.label = Some(label.into());
        }
    }

    /// Appends a bond `from → to` named `b<index>`.
    pub fn add_bond(&mut self, from: ElementId, to: ElementId) -> BondId {
        let name = format!("b{}", self.bonds.len());
        self.add_named_bond(name, from, to)
    }

    /// Appends a bond `from → to` with an explicit name.
    pub fn add_named_bond(
        &mut self,
        name: impl Into<String>,
        from: ElementId,
        to: ElementId,
    ) -> BondId {
        self.bonds.push(Bond {
            name: name.into(),
            from,
            to,
        });
        BondId(self.bonds.len() - 1)
    }

    /// Declares an external signal name usable in expressions.
    pub fn add_signal(&mut self, name: impl Into<String>) {
        let name = name.into();
        if !self.signals.contains(&name) {
            self.signals.push(name);
        }
    }

    /// The id of the (first) element with this name.
    pub fn element_by_name(&self, name: &str) -> Option<ElementId> {
        self.elements
            .iter()
            .position(|e| e.name == name)
            .map(ElementId)
    }

    /// The element with this id. Panics on a foreign id (ids come from this graph).
    pub fn element(&self, id: ElementId) -> &Element {
        &self.elements[id.0]
    }

    /// The bond with this id. Panics on a foreign id (ids come from this graph).
    pub fn bond(&self, id: BondId) -> &Bond {
        &self.bonds[id.0]
    }

    /// Ids of the bonds attached to `element`, in bond order.
    pub fn bonds_of(&self, element: ElementId) -> Vec<BondId> {
        self.bonds
            .iter()
            .enumerate()
            .filter(|(_, b)| b.from == element || b.to == element)
            .map(|(i, _)| BondId(i))
            .collect()
    }

    /// The element at the other end of `bond` seen from `element`.
    pub fn other_end(&self, bond: BondId, element: ElementId) -> ElementId {
        let b = self.bond(bond);
        if b.from == element {
            b.to
        } else {
            b.from
        }
    }

    /// The joint row an element imposes, if it is a constraint junction.
    pub fn constraint_junction(&self, e: ElementId) -> Option<&ConstraintJunction> {
        self.constraint_junctions.iter().find(|c| c.element == e)
    }

    /// Records the constraint junctions of the joints `joints`: every 1-junction or Sf named
    /// `<joint>.<direction>` (direction without a `.`), as the mechanism builder names them.
    pub fn annotate_joints<'a>(&mut self, joints: impl IntoIterator<Item = &'a str>) {
        let joints: std::collections::HashSet<&str> = joints.into_iter().collect();
        for (i, el) in self.elements.iter().enumerate() {
            if !matches!(el.kind, ElementKind::One | ElementKind::Sf) {
                continue;
            }
            let Some((joint, dir)) = el.name.rsplit_once('.') else {
                continue;
            };
            if joints.contains(&joint) {
                self.constraint_junctions.push(ConstraintJunction {
                    element: ElementId(i),
                    joint: joint.to_string(),
                    direction: dir.to_string(),
                    closure: None,
                });
            }
        }
    }

    /// Element ids in order.
    pub fn element_ids(&self) -> impl Iterator<Item = ElementId> {
        (0..self.elements.len()).map(ElementId)
    }
}
