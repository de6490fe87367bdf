//! Equations of a causal bond graph: state derivatives, velocity-level constraint rows of the
//! differential storages, and algebraic-loop rows, as expressions with exact derivatives.
//!
//! Every bond's effort and flow is expressed by following the causal strokes: the element
//! that imposes the effort on a bond computes `e`, the element that receives it computes `f`.
//! Sign convention: `s = +1` when the half arrow points into the element, `−1` otherwise.
//! - Se: `e = E(t, …)`; Sf: `f = F(t, …)`.
//! - I (momentum `p`, inertia `m`): `ṗ = s·e`, `f = p/m`. Integral: `f` is imposed.
//!   Differential: the effort it imposes is the unknown `e = s·λ` with `ṗ_d = λ`, and the
//!   **constraint row** `φ_d(x, t) − p_d/m_d = 0`, `φ_d` the flow the junction structure imposes.
//! - C (displacement `q`, compliance `C`): `q̇ = s·f`, `e = q/C`. Differential: the flow it
//!   imposes is the unknown `f = s·μ`, `q̇_d = μ`, row `ε_d(x, t) − q_d/C_d = 0`.
//! - R: `e = s·R·f` or `f = s·e/R` (power `R f² ≥ 0` into the resistor either way).
//! - 0-junction: common effort; the bond imposing the flow gets `f_d = −s_d Σ_{b≠d} s_b f_b`
//!   (`Σ s_b f_b = 0`). 1-junction: common flow; `e_d = −s_d Σ_{b≠d} s_b e_b`.
//! - TF/MTF (`e₁ = m e₂`, `f₂ = m f₁`), GY/MGY (`e₁ = r f₂`, `e₂ = r f₁`), port 1 the inward bond.
//!
//! **Algebraic loops** (zero-order causal paths, e.g. through two resistors) show up as a
//! bond variable needed while it is being computed. That variable becomes an algebraic
//! unknown `z` with the row `z − h(x, z, t) = 0`, solved by the DAE (IDA, index 1). They are not
//! eliminated symbolically, linear or not: one mechanism for all cases; the solver's Newton
//! iteration solves a linear loop in one step.
//!
//! Displacements referenced by a modulus (`x_<I>` = ∫ flow of the inertia's bond,
//! `x_<1-junction>` = ∫ its common flow) are extra states.
//!
//! Unknown vector `y = [x, p_d, λ, z]`: `x` the integral states (`p_<I>` of integral inertias,
//! then `q_<C>` of integral capacitors, element order, then the referenced displacements `x_…`),
//! `p_d` the momenta/displacements of the differential storages, `λ` one multiplier per
//! differential storage (`lambda_<name>`), `z` the loop variables (`z_e_<bond>`, `z_f_<bond>`).
//! Expression slots as in [`ImplicitDae`](crate::dae::ImplicitDae): `0 = t`, `1..=n` is `y`,
//! `n+1..=2n` is `y'`; declared signals come after, at `2n+1+k`.
//!
//! Velocity-level index-2 residual (raw bond graphs carry no position constraint):
//! `x' − f(x, λ, z, t) = 0`, `p_d' − λ = 0`, `φ_d(x, t) − p_d/m_d = 0`, `z − h = 0`;
//! `λ`, `z` algebraic. The index-1 variant replaces each constraint row `c(y, t)` by its total
//! derivative `Σⱼ ∂c/∂yⱼ·y'ⱼ + ∂c/∂t`.

use std::collections::HashMap;

use super::causality::{Causality, StorageCausality};
use super::model::{BondGraph, BondId, ElementId, ElementKind, Parameter};
use super::validate::referenced_variables;
use crate::expr::{Expr, ExprGraph, ParseError};

/// Why equations cannot be generated from a bond graph.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EquationError {
    /// The causal assignment over-determines a junction or two-port.
    #[error("causal conflict at '{junction}': {description} (the graph has redundant constraints; equations are not generated)")]
    Conflict {
        /// Junction or two-port where the clash shows.
        junction: String,
        /// What clashes.
        description: String,
    },
    /// An element that needs a parameter has none.
    #[error("element '{element}': missing {what}")]
    MissingParameter {
        /// Element name.
        element: String,
        /// The parameter it needs.
        what: String,
    },
    /// An expression does not parse against the graph's variables.
    #[error("element '{element}': expression {}: {source}", crate::expr::excerpt(expr, source.pos()))]
    Expression {
        /// Element name.
        element: String,
        /// The expression.
        expr: String,
        /// Parser error.
        source: ParseError,
    },
    /// An element asked to compute a variable its causality does not give it.
    #[error(
        "element '{element}' cannot impose the {what} on bond '{bond}' (causality is inconsistent)"
    )]
    Causality {
        /// Element name.
        element: String,
        /// Bond name.
        bond: String,
        /// "effort" or "flow".
        what: String,
    },
    /// Consistent initial values could not be found.
    #[error("consistent initial values: {0}")]
    Initialisation(String),
}

/// What one unknown of `y` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VariableKind {
    /// Momentum of an integral inertia.
    Momentum,
    /// Displacement of an integral capacitor.
    Displacement,
    /// Integrated flow of an inertia or 1-junction (`x_…`), referenced by a modulus.
    Position,
    /// Momentum (I) or displacement (C) of a differential storage.
    Dependent,
    /// The effort (I) or flow (C) a differential storage imposes: `λ = ṗ_d` (algebraic).
    Multiplier,
    /// A bond variable on an algebraic loop (algebraic).
    Loop,
}

/// The equations of a causal bond graph (see the module docs for the layout).
#[derive(Debug, Clone)]
pub struct BondEquations {
    /// Expression arena holding every row.
    pub graph: ExprGraph,
    /// Number of unknowns `n = nx + 2·nd + nz`.
    pub n: usize,
    /// Names of the unknowns `y` (`p_m1`, `q_k`, `x_j1`, `p_m2`, `lambda_m2`, `z_e_b3`).
    pub names: Vec<String>,
    /// Kind of each unknown.
    pub kinds: Vec<VariableKind>,
    /// Number of integral states `nx` (including referenced displacements).
    pub n_states: usize,
    /// Number of differential storages `nd`.
    pub n_dependent: usize,
    /// Number of loop variables `nz`.
    pub n_loops: usize,
    /// `ẋ = f(t, y)`, one per integral state (slots `[t, y]`, may involve `λ`, `z`).
    pub rhs: Vec<Expr>,
    /// Velocity-level constraint rows `φ_d − p_d/m_d` (or `ε_d − q_d/C_d`), one per differential storage.
    pub constraints: Vec<Expr>,
    /// Loop rows `z − h`, one per loop variable.
    pub loop_rows: Vec<Expr>,
    /// The element of each differential storage, in `p_d` order.
    pub dependent_elements: Vec<ElementId>,
    /// Initial values of `y` as given in the graph (`initial` of integral storages, else 0;
    /// `p_d`, `λ`, `z` are 0 here; see [`BondEquations::consistent_start`]).
    pub initial: Vec<f64>,
    /// Declared signals, at slots `2n+1+k`.
    pub signals: Vec<String>,
    /// Useful outputs over `[t, y]`: `f_<I>` (flow `p/m`), `e_<C>` (effort `q/C`), `energy`
    /// (`Σ p²/2m + Σ q²/2C` over every storage).
    pub outputs: Vec<(String, Expr)>,
    /// Every element parameter and law, in the slots `[t, y, y']` (to name a non-finite one).
    pub terms: Vec<ElementTerm>,
}

#[derive(Clone, Copy)]
enum Memo {
    Todo,
    Busy,
    Done(Expr),
}

#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Var {
    Effort(BondId),
    Flow(BondId),
}

struct Builder<'a> {
    g: &'a BondGraph,
    c: &'a Causality,
    eg: ExprGraph,
    names: HashMap<String, Expr>,
    params: HashMap<ElementId, Expr>,
    memo: HashMap<Var, Memo>,
    loops: Vec<(Var, Expr, Option<Expr>)>,
    loop_base: usize,
    state_var: HashMap<ElementId, Expr>,
    multiplier: HashMap<ElementId, Expr>,
    /// Every parameter and law expression built, to name an element whose value is not finite.
    terms: Vec<ElementTerm>,
}

/// A parameter (`value`, `modulus`, `compliance`) or law (`effort_law`, `flow_law`) of an
/// element as an expression of the equations' slots `[t, y, y']`.
#[derive(Clone, Debug)]
pub struct ElementTerm {
    /// The element.
    pub element: ElementId,
    /// Which of its fields: `value`, `modulus`, `compliance`, `effort_law` or `flow_law`.
    pub field: &'static str,
    /// The expression.
    pub expr: Expr,
}

type Res<T> = Result<T, EquationError>;

impl Builder<'_> {
    fn element_name(&self, e: ElementId) -> String {
        self.g.element(e).name.clone()
    }

    /// The constitutive law of a nonlinear R: `e = Φ(f)` (`effort` true, `own` = the flow into
    /// the resistor) or `f = Φ⁻¹(e)` (`own` = its effort).
    fn law(&mut self, x: ElementId, effort: bool, own: Expr) -> Res<Expr> {
        let el = self.g.element(x);
        let law = el.law.as_ref().expect("called for R elements with a law");
        let (src, var, field, causality) = if effort {
            (
                &law.effort,
                "f",
                "effort_law",
                "resistance causality (its flow is imposed)",
            )
        } else {
            (
                &law.flow,
                "e",
                "flow_law",
                "conductance causality (its effort is imposed)",
            )
        };
        let Some(src) = src else {
            return Err(EquationError::MissingParameter {
                element: el.name.clone(),
                what: format!(
                    "`{field}` (the resistor has {causality} in this graph, and only the other \
                     form of its law is given)"
                ),
            });
        };
        let names = &self.names;
        let e = self
            .eg
            .parse(src, &mut |n| {
                if n == var {
                    Some(own)
                } else {
                    names.get(n).copied()
                }
            })
            .map_err(|source| EquationError::Expression {
                element: el.name.clone(),
                expr: src.clone(),
                source,
            })?;
        self.terms.push(ElementTerm {
            element: x,
            field,
            expr: e,
        });
        Ok(e)
    }

    fn param(&mut self, e: ElementId, what: &str) -> Res<Expr> {
        if let Some(&p) = self.params.get(&e) {
            return Ok(p);
        }
        let el = self.g.element(e);
        let p = match &el.parameter {
            None => {
                return Err(EquationError::MissingParameter {
                    element: el.name.clone(),
                    what: what.into(),
                })
            }
            Some(Parameter::Const(v)) => self.eg.constant(*v),
            Some(Parameter::Table { t, v }) => {
                let time = self.eg.var(0);
                self.eg.table(t, v, time)
            }
            Some(Parameter::Expr(s)) => {
                let names = &self.names;
                self.eg
                    .parse(s, &mut |n| names.get(n).copied())
                    .map_err(|source| EquationError::Expression {
                        element: el.name.clone(),
                        expr: s.clone(),
                        source,
                    })?
            }
        };
        self.params.insert(e, p);
        self.terms.push(ElementTerm {
            element: e,
            field: super::validate::parameter_field(el.kind),
            expr: p,
        });
        Ok(p)
    }

    /// +1 when bond `b` points into `e`.
    fn sign(&self, b: BondId, e: ElementId) -> f64 {
        if self.g.bond(b).to == e {
            1.0
        } else {
            -1.0
        }
    }

    fn get(&mut self, v: Var) -> Res<Expr> {
        match self.memo.get(&v).copied().unwrap_or(Memo::Todo) {
            Memo::Done(e) => return Ok(e),
            Memo::Busy => {
                if let Some(l) = self.loops.iter().find(|l| l.0 == v) {
                    return Ok(l.1);
                }
                let slot = 1 + self.loop_base + self.loops.len();
                let z = self.eg.var(slot as u32);
                self.loops.push((v, z, None));
                return Ok(z);
            }
            Memo::Todo => {}
        }
        self.memo.insert(v, Memo::Busy);
        let h = match v {
            Var::Effort(b) => {
                let src = self.c.bonds[b.0].effort_source;
                self.out_effort(src, b)?
            }
            Var::Flow(b) => {
                let rcv = self.c.bonds[b.0].effort_receiver;
                self.out_flow(rcv, b)?
            }
        };
        let e = match self.loops.iter_mut().find(|l| l.0 == v) {
            Some(l) => {
                l.2 = Some(h);
                l.1
            }
            None => h,
        };
        self.memo.insert(v, Memo::Done(e));
        Ok(e)
    }

    fn effort(&mut self, b: BondId) -> Res<Expr> {
        self.get(Var::Effort(b))
    }

    fn flow(&mut self, b: BondId) -> Res<Expr> {
        self.get(Var::Flow(b))
    }

    fn bad(&self, e: ElementId, b: BondId, what: &str) -> EquationError {
        EquationError::Causality {
            element: self.element_name(e),
            bond: self.g.bond(b).name.clone(),
            what: what.into(),
        }
    }

    /// The other bond of a two-port and whether `b` is port 1 (inward).
    fn ports(&self, x: ElementId, b: BondId) -> (BondId, bool) {
        let other = self
            .g
            .bonds_of(x)
            .into_iter()
            .find(|&o| o != b)
            .unwrap_or(b);
        (other, self.g.bond(b).to == x)
    }

    /// Signed sum `−s_d Σ_{b≠d} s_b v_b` of a junction balance.
    fn balance(&mut self, j: ElementId, d: BondId, efforts: bool) -> Res<Expr> {
        let sd = self.sign(d, j);
        let mut acc = self.eg.zero();
        for b in self.g.bonds_of(j) {
            if b == d {
                continue;
            }
            let v = if efforts {
                self.effort(b)?
            } else {
                self.flow(b)?
            };
            let t = self.eg.scale(-sd * self.sign(b, j), v);
            acc = self.eg.add(acc, t);
        }
        Ok(acc)
    }

    /// The bond at junction `j` that imposes its common variable.
    fn determining(&self, j: ElementId, zero: bool) -> Option<BondId> {
        self.g.bonds_of(j).into_iter().find(|b| {
            let r = self.c.bonds[b.0].effort_receiver;
            if zero {
                r == j
            } else {
                r != j
            }
        })
    }

    fn out_effort(&mut self, x: ElementId, b: BondId) -> Res<Expr> {
        let kind = self.g.element(x).kind;
        let s = self.sign(b, x);
        Ok(match kind {
            ElementKind::Se => self.param(x, "effort value")?,
            ElementKind::I => {
                let l = *self
                    .multiplier
                    .get(&x)
                    .ok_or_else(|| self.bad(x, b, "effort"))?;
                self.eg.scale(s, l)
            }
            ElementKind::C => {
                if self.c.storage_causality(x) != Some(StorageCausality::Integral) {
                    return Err(self.bad(x, b, "effort"));
                }
                let q = self.state_var[&x];
                let cc = self.param(x, "compliance")?;
                self.eg.div(q, cc)
            }
            ElementKind::R => {
                let f = self.flow(b)?;
                if self.g.element(x).law.is_some() {
                    // e = Φ(f_in), f_in = s·f the flow into the resistor
                    let f_in = self.eg.scale(s, f);
                    return self.law(x, true, f_in);
                }
                let r = self.param(x, "resistance")?;
                let rf = self.eg.mul(r, f);
                self.eg.scale(s, rf)
            }
            ElementKind::One => self.balance(x, b, true)?,
            ElementKind::Zero => {
                let d = self
                    .determining(x, true)
                    .ok_or_else(|| self.bad(x, b, "effort"))?;
                self.effort(d)?
            }
            k if k.is_transformer() => {
                let m = self.param(x, "modulus")?;
                let (o, port1) = self.ports(x, b);
                let e = self.effort(o)?;
                if port1 {
                    self.eg.mul(m, e)
                } else {
                    self.eg.div(e, m)
                }
            }
            k if k.is_gyrator() => {
                let r = self.param(x, "modulus")?;
                let (o, _) = self.ports(x, b);
                let f = self.flow(o)?;
                self.eg.mul(r, f)
            }
            _ => return Err(self.bad(x, b, "effort")),
        })
    }

    fn out_flow(&mut self, x: ElementId, b: BondId) -> Res<Expr> {
        let kind = self.g.element(x).kind;
        let s = self.sign(b, x);
        Ok(match kind {
            ElementKind::Sf => self.param(x, "flow value")?,
            ElementKind::I => {
                if self.c.storage_causality(x) != Some(StorageCausality::Integral) {
                    return Err(self.bad(x, b, "flow"));
                }
                let p = self.state_var[&x];
                let m = self.param(x, "inertia")?;
                if self.eg.is_zero(m) {
                    return Err(EquationError::MissingParameter {
                        element: self.element_name(x),
                        what: "a nonzero inertia (a massless flow is fixed only by joint closures: give the graph its closures)".into(),
                    });
                }
                self.eg.div(p, m)
            }
            ElementKind::C => {
                let mu = *self
                    .multiplier
                    .get(&x)
                    .ok_or_else(|| self.bad(x, b, "flow"))?;
                self.eg.scale(s, mu)
            }
            ElementKind::R => {
                let e = self.effort(b)?;
                if self.g.element(x).law.is_some() {
                    // f = s·Φ⁻¹(e): the law gives the flow into the resistor
                    let f_in = self.law(x, false, e)?;
                    return Ok(self.eg.scale(s, f_in));
                }
                let r = self.param(x, "resistance")?;
                let er = self.eg.div(e, r);
                self.eg.scale(s, er)
            }
            ElementKind::Zero => self.balance(x, b, false)?,
            ElementKind::One => {
                let d = self
                    .determining(x, false)
                    .ok_or_else(|| self.bad(x, b, "flow"))?;
                self.flow(d)?
            }
            k if k.is_transformer() => {
                let m = self.param(x, "modulus")?;
                let (o, port1) = self.ports(x, b);
                let f = self.flow(o)?;
                if port1 {
                    self.eg.div(f, m)
                } else {
                    self.eg.mul(m, f)
                }
            }
            k if k.is_gyrator() => {
                let r = self.param(x, "modulus")?;
                let (o, _) = self.ports(x, b);
                let e = self.effort(o)?;
                self.eg.div(e, r)
            }
            _ => return Err(self.bad(x, b, "flow")),
        })
    }
}

/// Unknowns known before the traversal: integral states, displacements, dependents, multipliers.
struct Layout {
    names: Vec<String>,
    kinds: Vec<VariableKind>,
    elements: Vec<Option<ElementId>>,
    n_states: usize,
    dependent: Vec<ElementId>,
    positions: Vec<(String, ElementId)>,
}

fn layout(g: &BondGraph, c: &Causality) -> Layout {
    let mut names = Vec::new();
    let mut kinds = Vec::new();
    let mut elements = Vec::new();
    let mut dependent = Vec::new();
    for &(e, sc) in &c.storage {
        let el = g.element(e);
        let prefix = if el.kind == ElementKind::I { "p" } else { "q" };
        match sc {
            StorageCausality::Integral => {
                names.push(format!("{prefix}_{}", el.name));
                kinds.push(if el.kind == ElementKind::I {
                    VariableKind::Momentum
                } else {
                    VariableKind::Displacement
                });
                elements.push(Some(e));
            }
            StorageCausality::Differential => dependent.push(e),
        }
    }
    let mut positions = Vec::new();
    for v in referenced_variables(g) {
        if let Some(rest) = v.strip_prefix("x_") {
            if let Some(e) = g.element_by_name(rest) {
                if matches!(g.element(e).kind, ElementKind::I | ElementKind::One) {
                    names.push(v.clone());
                    kinds.push(VariableKind::Position);
                    elements.push(Some(e));
                    positions.push((v, e));
                }
            }
        }
    }
    let n_states = names.len();
    for &e in &dependent {
        let el = g.element(e);
        let prefix = if el.kind == ElementKind::I { "p" } else { "q" };
        names.push(format!("{prefix}_{}", el.name));
        kinds.push(VariableKind::Dependent);
        elements.push(Some(e));
    }
    for &e in &dependent {
        names.push(format!("lambda_{}", g.element(e).name));
        kinds.push(VariableKind::Multiplier);
        elements.push(Some(e));
    }
    Layout {
        names,
        kinds,
        elements,
        n_states,
        dependent,
        positions,
    }
}

struct Built {
    eg: ExprGraph,
    rhs: Vec<Expr>,
    constraints: Vec<Expr>,
    loops: Vec<(Var, Expr, Option<Expr>)>,
    outputs: Vec<(String, Expr)>,
    terms: Vec<ElementTerm>,
}

fn run(g: &BondGraph, c: &Causality, lay: &Layout, n_loops: usize) -> Res<Built> {
    let n_known = lay.names.len();
    let n = n_known + n_loops;
    let mut eg = ExprGraph::new();
    let mut names: HashMap<String, Expr> = HashMap::new();
    names.insert("t".into(), eg.var(0));
    let mut state_var = HashMap::new();
    let mut multiplier = HashMap::new();
    for (i, name) in lay.names.iter().enumerate() {
        let v = eg.var((1 + i) as u32);
        match lay.kinds[i] {
            VariableKind::Multiplier => {
                if let Some(e) = lay.elements[i] {
                    multiplier.insert(e, v);
                }
            }
            VariableKind::Position => {
                names.insert(name.clone(), v);
            }
            _ => {
                names.insert(name.clone(), v);
                if let Some(e) = lay.elements[i] {
                    state_var.insert(e, v);
                }
            }
        }
    }
    for (k, s) in g.signals.iter().enumerate() {
        let v = eg.var((2 * n + 1 + k) as u32);
        names.insert(s.clone(), v);
    }
    let mut b = Builder {
        g,
        c,
        eg,
        names,
        params: HashMap::new(),
        memo: HashMap::new(),
        loops: Vec::new(),
        loop_base: n_known,
        state_var,
        multiplier,
        terms: Vec::new(),
    };
    let mut rhs = Vec::new();
    // integral storages
    for &(e, sc) in &c.storage {
        if sc != StorageCausality::Integral {
            continue;
        }
        let bond = g.bonds_of(e)[0];
        let s = b.sign(bond, e);
        let v = if g.element(e).kind == ElementKind::I {
            b.effort(bond)?
        } else {
            b.flow(bond)?
        };
        rhs.push(b.eg.scale(s, v));
    }
    // displacements
    for (_, e) in &lay.positions {
        let bond = match g.element(*e).kind {
            ElementKind::One => b
                .determining(*e, false)
                .unwrap_or_else(|| g.bonds_of(*e)[0]),
            _ => g.bonds_of(*e)[0],
        };
        rhs.push(b.flow(bond)?);
    }
    // constraint rows of differential storages
    let mut constraints = Vec::new();
    for &e in &lay.dependent {
        let bond = g.bonds_of(e)[0];
        let own = b.state_var[&e];
        let row = if g.element(e).kind == ElementKind::I {
            let phi = b.flow(bond)?;
            let m = b.param(e, "inertia")?;
            if b.eg.is_zero(m) {
                return Err(EquationError::MissingParameter {
                    element: b.element_name(e),
                    what: "a nonzero inertia (a massless flow is fixed only by joint closures: give the graph its closures)".into(),
                });
            }
            let pm = b.eg.div(own, m);
            b.eg.sub(phi, pm)
        } else {
            let eps = b.effort(bond)?;
            let cc = b.param(e, "compliance")?;
            let qc = b.eg.div(own, cc);
            b.eg.sub(eps, qc)
        };
        constraints.push(row);
    }
    // outputs: storage flows/efforts and energy
    let mut outputs = Vec::new();
    let mut energy = b.eg.zero();
    for &(e, _) in &c.storage {
        let el = g.element(e);
        let v = b.state_var[&e];
        let (prefix, par) = if el.kind == ElementKind::I {
            ("f", "inertia")
        } else {
            ("e", "compliance")
        };
        let p = b.param(e, par)?;
        let ratio = b.eg.div(v, p);
        outputs.push((format!("{prefix}_{}", el.name), ratio));
        let half = b.eg.scale(0.5, ratio);
        let w = b.eg.mul(half, v);
        energy = b.eg.add(energy, w);
    }
    outputs.push(("energy".into(), energy));
    Ok(Built {
        eg: b.eg,
        rhs,
        constraints,
        loops: b.loops,
        outputs,
        terms: b.terms,
    })
}

impl BondEquations {
    /// Generates the equations of `graph` with its causal assignment `causality`.
    ///
    /// ```
    /// use bondmech::bond::{assign_causality, equations::BondEquations, BondGraph};
    /// let g = BondGraph::from_json_str(r#"{"elements": [
    ///   {"name": "F", "kind": "Se", "value": 2.0}, {"name": "m", "kind": "I", "value": 4.0},
    ///   {"name": "j", "kind": "1"}],
    ///   "bonds": [{"from": "F", "to": "j"}, {"from": "j", "to": "m"}]}"#).unwrap();
    /// let eq = BondEquations::new(&g, &assign_causality(&g).unwrap()).unwrap();
    /// assert_eq!(eq.names, vec!["p_m"]);
    /// assert_eq!(eq.graph.eval(eq.rhs[0], &[0.0, 1.0]), 2.0); // ṗ = F
    /// ```
    pub fn new(graph: &BondGraph, causality: &Causality) -> Result<Self, EquationError> {
        if let Some(c) = causality.conflicts.first() {
            return Err(EquationError::Conflict {
                junction: c.junction.clone(),
                description: c.description.clone(),
            });
        }
        if let Some(el) = graph.elements.iter().find(|e| {
            e.kind == ElementKind::I && matches!(e.parameter, Some(Parameter::Const(m)) if m == 0.0)
        }) {
            return Err(EquationError::MissingParameter {
                element: el.name.clone(),
                what: "a nonzero inertia (a massless flow is fixed only by joint closures: give the graph its closures)".into(),
            });
        }
        let lay = layout(graph, causality);
        // the loop variables are found during the traversal; a first pass counts them so that
        // the y' and signal slots are right in the second
        let n_loops = run(graph, causality, &lay, 0)?.loops.len();
        let built = run(graph, causality, &lay, n_loops)?;
        let mut names = lay.names.clone();
        let mut kinds = lay.kinds.clone();
        let mut loop_rows = Vec::new();
        let mut eg = built.eg;
        for (v, z, h) in &built.loops {
            names.push(match v {
                Var::Effort(b) => format!("z_e_{}", graph.bond(*b).name),
                Var::Flow(b) => format!("z_f_{}", graph.bond(*b).name),
            });
            kinds.push(VariableKind::Loop);
            let h = h.unwrap_or(*z);
            loop_rows.push(eg.sub(*z, h));
        }
        let n = names.len();
        let mut initial = vec![0.0; n];
        for (i, k) in kinds.iter().enumerate() {
            if matches!(k, VariableKind::Momentum | VariableKind::Displacement) {
                if let Some(e) = lay.elements[i] {
                    initial[i] = graph.element(e).initial.unwrap_or(0.0);
                }
            }
        }
        for (j, &e) in lay.dependent.iter().enumerate() {
            initial[lay.n_states + j] = graph.element(e).initial.unwrap_or(0.0);
        }
        Ok(BondEquations {
            graph: eg,
            n,
            names,
            kinds,
            n_states: lay.n_states,
            n_dependent: lay.dependent.len(),
            n_loops: built.loops.len(),
            rhs: built.rhs,
            constraints: built.constraints,
            loop_rows,
            dependent_elements: lay.dependent,
            initial,
            signals: graph.signals.clone(),
            outputs: built.outputs,
            terms: built.terms,
        })
    }

    /// Names of the integral states `x`.
    pub fn state_names(&self) -> &[String] {
        &self.names[..self.n_states]
    }

    /// Names of the algebraic unknowns (multipliers `λ`, loop variables `z`).
    pub fn algebraic_names(&self) -> Vec<String> {
        self.names
            .iter()
            .zip(&self.kinds)
            .filter(|(_, k)| matches!(k, VariableKind::Multiplier | VariableKind::Loop))
            .map(|(n, _)| n.clone())
            .collect()
    }
}

/// Equations straight from a graph: assigns causality, then [`BondEquations::new`].
pub fn equations(graph: &BondGraph) -> Result<BondEquations, String> {
    let c = super::assign_causality(graph).map_err(|e| e.to_string())?;
    BondEquations::new(graph, &c).map_err(|e| e.to_string())
}
