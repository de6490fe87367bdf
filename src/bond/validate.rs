//! Structural and parameter validation of a bond graph.
//!
//! Every error names the JSON path (`bond_graph.elements[2]`, `bond_graph.bonds[3].to`) and the
//! element or bond concerned; validation collects **all** errors instead of stopping at the first.

use super::identifiers::{variables, ScanError};
use super::model::{BondGraph, ElementId, ElementKind, Parameter};
use crate::expr::{excerpt, Expr, ExprGraph};
use std::collections::{HashMap, HashSet};

/// The JSON path prefix of a raw bond graph inside a scene.
pub const ROOT: &str = "bond_graph";

/// One problem in a bond graph; every message starts with the JSON path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BondError {
    /// The graph has no elements.
    #[error("{path}: empty bond graph (no elements)")]
    EmptyGraph {
        /// JSON path.
        path: String,
    },
    /// A kind that is not one of Se, Sf, I, C, R, TF, GY, MTF, MGY, 0, 1.
    #[error("{path}: unknown element kind '{kind}' for '{element}' (expected Se, Sf, I, C, R, TF, GY, MTF, MGY, 0 or 1)")]
    UnknownKind {
        /// JSON path.
        path: String,
        /// Element name.
        element: String,
        /// The kind given.
        kind: String,
    },
    /// Two elements (or two bonds) share a name.
    #[error("{path}: duplicate name '{name}' (already used at {first})")]
    DuplicateName {
        /// JSON path of the second use.
        path: String,
        /// The name.
        name: String,
        /// JSON path of the first use.
        first: String,
    },
    /// A bond end names no element.
    #[error("{path}: unknown element '{name}' in bond '{bond}'")]
    UnknownElement {
        /// JSON path of the bond end.
        path: String,
        /// Bond name.
        bond: String,
        /// The missing element name.
        name: String,
    },
    /// A bond from an element to itself.
    #[error("{path}: bond '{bond}' connects element '{element}' to itself")]
    SelfBond {
        /// JSON path of the bond.
        path: String,
        /// Bond name.
        bond: String,
        /// Element name.
        element: String,
    },
    /// A one-port or two-port with the wrong number of bonds.
    #[error("{path}: {kind} element '{element}' needs exactly {expected} bond(s), has {found}")]
    WrongBondCount {
        /// JSON path of the element.
        path: String,
        /// Element name.
        element: String,
        /// Kind spelled as in JSON.
        kind: String,
        /// Required number of bonds.
        expected: usize,
        /// Number found.
        found: usize,
    },
    /// A two-port whose bonds are both inward or both outward.
    #[error("{path}: two-port '{element}' needs one bond pointing in (port 1) and one pointing out (port 2), has {inward} in and {outward} out")]
    TwoPortDirection {
        /// JSON path of the element.
        path: String,
        /// Element name.
        element: String,
        /// Bonds pointing in.
        inward: usize,
        /// Bonds pointing out.
        outward: usize,
    },
    /// A junction without bonds.
    #[error("{path}: junction '{element}' has no bonds")]
    IsolatedJunction {
        /// JSON path of the element.
        path: String,
        /// Element name.
        element: String,
    },
    /// A 0-junction with a single bond: it does not connect anything, and it forces its one
    /// bond's flow to zero, silently changing the physics (a 0-junction on the rotor of a DC
    /// motor locks it). A 1-junction with one bond is accepted: it is a point velocity with
    /// nothing attached, whose zero effort is exactly a free end's.
    #[error("{path}: {kind}-junction '{element}' has a single bond ({bond}): it connects nothing and forces that bond's {forced} to zero; connect it to two bonds or more, or remove it and bond its neighbour directly")]
    SingleBondJunction {
        /// JSON path of the element.
        path: String,
        /// Element name.
        element: String,
        /// `0` or `1`.
        kind: String,
        /// Name of the one bond.
        bond: String,
        /// `flow` (0-junction) or `effort` (1-junction).
        forced: String,
    },
    /// A field of an element or bond that cannot be read (unknown field, wrong type, missing
    /// field), with the element's index and name.
    #[error("{path}{}: {message}", element.as_ref().map(|n| format!(" (name \"{n}\")")).unwrap_or_default())]
    Field {
        /// JSON path of the element or bond, e.g. `bond_graph.elements[3]`.
        path: String,
        /// Name of the element or bond, when it has one.
        element: Option<String>,
        /// What is wrong, e.g. `unknown field "resistence" (did you mean "resistance"?)`.
        message: String,
    },
    /// An expression refers to a variable that is not `t`, a state of the graph or a signal.
    #[error("{path}: expression {} of '{element}' refers to unknown variable '{variable}' (known: t, p_<I>, x_<I or 1-junction>, q_<C>, declared signals)", excerpt(expr, expr.find(variable.as_str()).unwrap_or(0)))]
    UnknownVariable {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// The expression.
        expr: String,
        /// The unknown identifier.
        variable: String,
    },
    /// An expression that does not scan.
    #[error("{path}: expression {} of '{element}' is malformed: {reason}", excerpt(expr, *pos))]
    BadExpression {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// The expression.
        expr: String,
        /// What is wrong.
        reason: String,
        /// Byte offset of the problem in `expr` (0 when it has no single place).
        pos: usize,
    },
    /// A NaN or infinite number.
    #[error("{path}: parameter of '{element}' is not finite ({value})")]
    NonFinite {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// The value.
        value: f64,
    },
    /// A number beyond [`MAX_PARAMETER`] in magnitude (a parameter, a table value, an initial
    /// momentum or displacement): its products with the state overflow.
    #[error("{path}: '{element}': {value:e} is beyond ±{max:e}: its products with the state overflow in the equations (rule: |value| <= {max:e})")]
    TooLarge {
        /// JSON path of the number.
        path: String,
        /// Element name.
        element: String,
        /// The value.
        value: f64,
        /// The bound ([`MAX_PARAMETER`]).
        max: f64,
    },
    /// A negative inertia, or a capacitor (or stiffness) that is zero or negative. (A zero
    /// inertia is a massless flow fixed by the constraints: accepted, and read as such when the
    /// graph is solved as a mechanism.)
    #[error("{path}: {what} of '{element}' must be positive, got {value}")]
    NonPositive {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// "inertia", "compliance" or "stiffness".
        what: String,
        /// The value.
        value: f64,
    },
    /// A negative resistance.
    #[error("{path}: resistance of '{element}' must be non-negative, got {value}")]
    NegativeResistance {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// The value.
        value: f64,
    },
    /// A required parameter is missing.
    #[error("{path}: {kind} element '{element}' needs a parameter (`{field}`)")]
    MissingParameter {
        /// JSON path of the element.
        path: String,
        /// Element name.
        element: String,
        /// Kind spelled as in JSON.
        kind: String,
        /// The JSON field(s) expected.
        field: String,
    },
    /// A parameter in the wrong place or a malformed table.
    #[error("{path}: '{element}': {reason}")]
    BadParameter {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// What is wrong.
        reason: String,
    },
    /// An expression-valued parameter whose value at the start breaks the rule numbers obey
    /// (finite; inertia >= 0, compliance > 0, resistance >= 0).
    #[error("{path}: '{element}': {expr} evaluates to {value} at t_start = {t}: {rule}")]
    ExpressionValue {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// The expression (cut when long).
        expr: String,
        /// The start time it was evaluated at.
        t: f64,
        /// Its value there.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
    /// An expression-valued parameter (or a resistor's law) whose value at time `t` of the run
    /// breaks its rule ([`crate::bond::parameter_span::check_over_span`]).
    #[error("{path}: '{element}': {expr} evaluates to {value} at t = {t}: {rule}")]
    ValueInRun {
        /// JSON path of the parameter.
        path: String,
        /// Element name.
        element: String,
        /// The expression (cut when long).
        expr: String,
        /// The time it was evaluated at.
        t: f64,
        /// Its value there.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
    /// A TF/GY/MTF/MGY modulus that is identically zero (a constant 0 or an expression that
    /// simplifies to 0): the equations divide by it (`e₂ = e₁/m`, `f₁ = f₂/m`, `f = e/r`).
    #[error("{path}: {kind} element '{element}': modulus is identically zero (the equations divide by it)")]
    ZeroModulus {
        /// JSON path of the modulus.
        path: String,
        /// Element name.
        element: String,
        /// Kind spelled as in JSON.
        kind: String,
    },
}

/// Largest magnitude of a raw bond graph's numbers (parameters, table values, initial values),
/// as the masses of a mechanism scene (`crate::scene::validate::MAX_MASS`): beyond it their
/// products with the state (`e = q/C`, `f = p/I`, `e = R f`) overflow (issue 38: a C stiffness
/// of 1e308 failed as "CVode failed with CV_REPTD_RHSFUNC_ERR").
pub const MAX_PARAMETER: f64 = 1e100;

/// All the errors found in one bond graph.
#[derive(Debug, Clone, PartialEq)]
pub struct ValidationErrors(pub Vec<BondError>);

impl std::fmt::Display for ValidationErrors {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} error(s) in bond graph:", self.0.len())?;
        for e in &self.0 {
            write!(f, "\n  {e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ValidationErrors {}

/// Path of element `i`.
pub(crate) fn element_path(i: usize) -> String {
    format!("{ROOT}.elements[{i}]")
}

/// Path of bond `i`.
pub(crate) fn bond_path(i: usize) -> String {
    format!("{ROOT}.bonds[{i}]")
}

/// The JSON field a parameter of this kind lives in.
pub(crate) fn parameter_field(kind: ElementKind) -> &'static str {
    match kind {
        ElementKind::C => "compliance",
        k if k.is_two_port() => "modulus",
        _ => "value",
    }
}

/// Validates a bond graph; `Ok(())` or every error found.
pub fn validate(graph: &BondGraph) -> Result<(), ValidationErrors> {
    let errors = collect_errors(graph, &HashSet::new());
    if errors.is_empty() {
        Ok(())
    } else {
        Err(ValidationErrors(errors))
    }
}

/// Collects the errors of `graph`; bond counts are not checked for elements in `skip_counts`
/// (elements touched by bonds that could not be resolved while reading JSON).
pub(crate) fn collect_errors(
    graph: &BondGraph,
    skip_counts: &HashSet<ElementId>,
) -> Vec<BondError> {
    let mut errors = Vec::new();
    if graph.elements.is_empty() {
        errors.push(BondError::EmptyGraph {
            path: format!("{ROOT}.elements"),
        });
    }
    check_names(graph, &mut errors);
    check_bonds(graph, &mut errors);
    check_ports(graph, skip_counts, &mut errors);
    let known = known_variables(graph);
    for (i, e) in graph.elements.iter().enumerate() {
        if let Some(law) = &e.law {
            for (field, own, expr) in [
                ("effort_law", "f", &law.effort),
                ("flow_law", "e", &law.flow),
            ] {
                let Some(expr) = expr else { continue };
                let mut with_own = known.clone();
                with_own.insert(own.into());
                check_parameter(
                    &e.name,
                    e.kind,
                    Some(&Parameter::Expr(expr.clone())),
                    &format!("{}.{field}", element_path(i)),
                    &element_path(i),
                    &with_own,
                    &mut errors,
                );
            }
            continue;
        }
        let path = format!("{}.{}", element_path(i), parameter_field(e.kind));
        check_parameter(
            &e.name,
            e.kind,
            e.parameter.as_ref(),
            &path,
            &element_path(i),
            &known,
            &mut errors,
        );
    }
    errors
}

fn check_names(graph: &BondGraph, errors: &mut Vec<BondError>) {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, e) in graph.elements.iter().enumerate() {
        if let Some(&first) = seen.get(e.name.as_str()) {
            errors.push(BondError::DuplicateName {
                path: format!("{}.name", element_path(i)),
                name: e.name.clone(),
                first: element_path(first),
            });
        } else {
            seen.insert(&e.name, i);
        }
    }
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, b) in graph.bonds.iter().enumerate() {
        if let Some(&first) = seen.get(b.name.as_str()) {
            errors.push(BondError::DuplicateName {
                path: format!("{}.name", bond_path(i)),
                name: b.name.clone(),
                first: bond_path(first),
            });
        } else {
            seen.insert(&b.name, i);
        }
    }
}

fn check_bonds(graph: &BondGraph, errors: &mut Vec<BondError>) {
    let n = graph.elements.len();
    for (i, b) in graph.bonds.iter().enumerate() {
        for (end, id) in [("from", b.from), ("to", b.to)] {
            if id.0 >= n {
                errors.push(BondError::UnknownElement {
                    path: format!("{}.{end}", bond_path(i)),
                    bond: b.name.clone(),
                    name: format!("#{}", id.0),
                });
            }
        }
        if b.from == b.to && b.from.0 < n {
            errors.push(BondError::SelfBond {
                path: bond_path(i),
                bond: b.name.clone(),
                element: graph.elements[b.from.0].name.clone(),
            });
        }
    }
}

fn check_ports(graph: &BondGraph, skip: &HashSet<ElementId>, errors: &mut Vec<BondError>) {
    // bond counts per element in one pass (linear in the graph)
    let mut inward_of = vec![0usize; graph.elements.len()];
    let mut outward_of = vec![0usize; graph.elements.len()];
    for b in &graph.bonds {
        if let Some(n) = inward_of.get_mut(b.to.0) {
            *n += 1;
        }
        if let Some(n) = outward_of.get_mut(b.from.0) {
            *n += 1;
        }
    }
    for (i, e) in graph.elements.iter().enumerate() {
        let id = ElementId(i);
        if skip.contains(&id) {
            continue;
        }
        let (inward, outward) = (inward_of[i], outward_of[i]);
        let found = inward + outward;
        let path = element_path(i);
        if e.kind.is_one_port() && found != 1 {
            errors.push(BondError::WrongBondCount {
                path,
                element: e.name.clone(),
                kind: e.kind.as_str().into(),
                expected: 1,
                found,
            });
        } else if e.kind.is_two_port() {
            if found != 2 {
                errors.push(BondError::WrongBondCount {
                    path,
                    element: e.name.clone(),
                    kind: e.kind.as_str().into(),
                    expected: 2,
                    found,
                });
            } else if inward != 1 {
                errors.push(BondError::TwoPortDirection {
                    path,
                    element: e.name.clone(),
                    inward,
                    outward,
                });
            }
        } else if e.kind.is_junction() && found == 0 && graph.displacements.is_empty() {
            // in a mechanism's graph (it names its coordinates) a junction without bonds is the
            // ω junction of a massless body that nothing turns (a bead, a piston with its point
            // at its centre): it carries no variable and is no mistake
            errors.push(BondError::IsolatedJunction {
                path,
                element: e.name.clone(),
            });
        }
    }
}

/// 0-junctions with exactly one bond (raw bond graphs only: see
/// [`BondError::SingleBondJunction`]); a 1-junction with one bond is a free point velocity.
pub(crate) fn check_single_bond_junctions(
    graph: &BondGraph,
    skip: &HashSet<ElementId>,
    errors: &mut Vec<BondError>,
) {
    for (i, e) in graph.elements.iter().enumerate() {
        let id = ElementId(i);
        if !e.kind.is_junction() || skip.contains(&id) {
            continue;
        }
        let bonds: Vec<_> = graph
            .bonds
            .iter()
            .filter(|b| b.to == id || b.from == id)
            .collect();
        // a 1-junction with one bond is a point velocity with nothing attached (the free end
        // A of a bar in the seed's figures): its zero effort is the physics, a free end
        // carries no force. A 0-junction with one bond instead forces a flow to zero: a lock.
        if e.kind == ElementKind::One {
            continue;
        }
        if let [b] = bonds.as_slice() {
            let zero = e.kind == ElementKind::Zero;
            errors.push(BondError::SingleBondJunction {
                path: element_path(i),
                element: e.name.clone(),
                kind: if zero { "0" } else { "1" }.into(),
                bond: b.name.clone(),
                forced: if zero { "flow" } else { "effort" }.into(),
            });
        }
    }
}

/// Variables an expression of this graph may use.
pub fn known_variables(graph: &BondGraph) -> HashSet<String> {
    let mut known: HashSet<String> = HashSet::new();
    known.insert("t".into());
    for s in &graph.signals {
        known.insert(s.clone());
    }
    for s in &graph.signal_states {
        known.insert(s.name.clone());
    }
    for s in &graph.signal_definitions {
        known.insert(s.name.clone());
    }
    for e in &graph.elements {
        match e.kind {
            ElementKind::I => {
                known.insert(format!("p_{}", e.name));
                known.insert(format!("x_{}", e.name));
                known.insert(format!("f_{}", e.name));
            }
            ElementKind::One => {
                known.insert(format!("x_{}", e.name));
            }
            ElementKind::C => {
                known.insert(format!("q_{}", e.name));
            }
            _ => {}
        }
    }
    known
}

/// The variables referenced by the graph's expressions, in element order without repeats
/// (e.g. the displacements `x_<1-junction>` an equation builder must integrate). Expressions
/// that do not scan are skipped (validation reports them).
pub fn referenced_variables(graph: &BondGraph) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for e in &graph.elements {
        if let Some(Parameter::Expr(s)) = &e.parameter {
            for v in variables(s).unwrap_or_default() {
                if !out.contains(&v) {
                    out.push(v);
                }
            }
        }
    }
    out
}

/// Checks one parameter; `path` points at the parameter field, `element_path` at the element.
pub(crate) fn check_parameter(
    name: &str,
    kind: ElementKind,
    parameter: Option<&Parameter>,
    path: &str,
    element_path: &str,
    known: &HashSet<String>,
    errors: &mut Vec<BondError>,
) {
    let Some(p) = parameter else {
        if !kind.is_junction() {
            let field = match kind {
                ElementKind::C => "stiffness` or `compliance",
                k => parameter_field(k),
            };
            errors.push(BondError::MissingParameter {
                path: element_path.into(),
                element: name.into(),
                kind: kind.as_str().into(),
                field: field.into(),
            });
        }
        return;
    };
    if kind.is_junction() {
        errors.push(BondError::BadParameter {
            path: path.into(),
            element: name.into(),
            reason: "junctions take no value".into(),
        });
        return;
    }
    let check_number = |v: f64, errors: &mut Vec<BondError>| {
        if !v.is_finite() {
            errors.push(BondError::NonFinite {
                path: path.into(),
                element: name.into(),
                value: v,
            });
        } else if v.abs() > MAX_PARAMETER {
            errors.push(BondError::TooLarge {
                path: path.into(),
                element: name.into(),
                value: v,
                max: MAX_PARAMETER,
            });
        } else if (kind == ElementKind::C && v <= 0.0) || (kind == ElementKind::I && v < 0.0) {
            errors.push(BondError::NonPositive {
                path: path.into(),
                element: name.into(),
                what: if kind == ElementKind::I {
                    "inertia".into()
                } else {
                    "compliance".into()
                },
                value: v,
            });
        } else if kind == ElementKind::R && v < 0.0 {
            errors.push(BondError::NegativeResistance {
                path: path.into(),
                element: name.into(),
                value: v,
            });
        }
    };
    let zero_modulus = |errors: &mut Vec<BondError>| {
        errors.push(BondError::ZeroModulus {
            path: path.into(),
            element: name.into(),
            kind: kind.as_str().into(),
        })
    };
    match p {
        Parameter::Const(v) => {
            check_number(*v, errors);
            if kind.is_two_port() && *v == 0.0 {
                zero_modulus(errors);
            }
        }
        Parameter::Expr(s) => {
            let before = errors.len();
            check_expression(name, s, path, known, errors);
            if kind.is_two_port() && errors.len() == before && is_constant_zero(s) {
                zero_modulus(errors);
            }
        }
        Parameter::Table { t, v } => {
            if t.is_empty() || t.len() != v.len() {
                errors.push(BondError::BadParameter {
                    path: path.into(),
                    element: name.into(),
                    reason: format!(
                        "table needs as many times as values and at least one (t: {}, v: {})",
                        t.len(),
                        v.len()
                    ),
                });
                return;
            }
            if t.iter().any(|x| !x.is_finite()) || t.windows(2).any(|w| w[1] <= w[0]) {
                errors.push(BondError::BadParameter {
                    path: format!("{path}.table.t"),
                    element: name.into(),
                    reason: "table times must be finite and strictly increasing".into(),
                });
            }
            for &x in v {
                check_number(x, errors);
            }
        }
    }
}

/// The rule a value of an element of `kind` breaks, if any: the rules numbers are held to
/// (finite; inertia >= 0, compliance > 0, resistance >= 0).
fn value_rule(kind: ElementKind, v: f64) -> Option<&'static str> {
    if !v.is_finite() {
        Some("the value must be finite")
    } else if kind == ElementKind::I && v < 0.0 {
        Some("an inertia must be >= 0")
    } else if kind == ElementKind::C && v <= 0.0 {
        Some("a compliance must be > 0")
    } else if kind == ElementKind::R && v < 0.0 {
        Some("a resistance must be >= 0")
    } else {
        None
    }
}

/// Expression-valued parameters that depend on nothing but `t` (a constant written as a
/// string, `"-1.5"`, or a function of time), evaluated at `t_start` and held to the sign rules
/// numbers obey: a value given as an expression must not slip past the sign checks. A
/// non-finite value, and expressions of the state, are refused by the solve's check at their
/// first evaluation, which names the element and the time.
pub fn check_expression_values(graph: &BondGraph, t_start: f64) -> Vec<BondError> {
    let mut errors = Vec::new();
    for (i, e) in graph.elements.iter().enumerate() {
        let Some(Parameter::Expr(expr)) = &e.parameter else {
            continue;
        };
        if e.law.is_some() || e.kind.is_junction() {
            continue;
        }
        let Ok(vars) = variables(expr) else { continue };
        if vars.iter().any(|v| v != "t") {
            continue;
        }
        let mut g = ExprGraph::new();
        let t = g.var(0);
        let Ok(x) = g.parse(expr, &mut |n| (n == "t").then_some(t)) else {
            continue;
        };
        let value = g.eval(x, &[t_start]);
        // a non-finite value is named by the solve's own check at its first evaluation
        // (`bond_graph.elements[0] (Se 'F', value "1/t") evaluates to inf at t = 0`)
        if !value.is_finite() {
            continue;
        }
        if let Some(rule) = value_rule(e.kind, value) {
            errors.push(BondError::ExpressionValue {
                path: format!("{}.{}", element_path(i), parameter_field(e.kind)),
                element: e.name.clone(),
                expr: crate::expr::excerpt(expr, 0),
                t: t_start,
                value,
                rule,
            });
        }
    }
    errors
}

/// Does `expr` simplify to the constant 0 (every name taken as an independent variable)?
fn is_constant_zero(expr: &str) -> bool {
    let mut g = ExprGraph::new();
    let slots: HashMap<String, Expr> = variables(expr)
        .unwrap_or_default()
        .into_iter()
        .enumerate()
        .map(|(i, n)| (n, g.var(i as u32)))
        .collect();
    g.parse(expr, &mut |n| slots.get(n).copied())
        .ok()
        .is_some_and(|e| g.as_const(e) == Some(0.0))
}

fn check_expression(
    name: &str,
    expr: &str,
    path: &str,
    known: &HashSet<String>,
    errors: &mut Vec<BondError>,
) {
    match variables(expr) {
        Ok(vars) => {
            for v in vars {
                if !known.contains(&v) {
                    errors.push(BondError::UnknownVariable {
                        path: path.into(),
                        element: name.into(),
                        expr: expr.into(),
                        variable: v,
                    });
                }
            }
        }
        Err(e) => errors.push(BondError::BadExpression {
            path: path.into(),
            element: name.into(),
            expr: expr.into(),
            reason: scan_reason(&e),
            pos: scan_pos(expr, &e),
        }),
    }
}

fn scan_reason(e: &ScanError) -> String {
    e.to_string()
}

/// Byte offset in `expr` of the problem `e` describes (0 when it has no single place).
fn scan_pos(expr: &str, e: &ScanError) -> usize {
    match e {
        ScanError::BadCharacter(_, i) => expr.char_indices().nth(*i).map_or(0, |(b, _)| b),
        ScanError::UnknownFunction(n) => expr.find(n.as_str()).unwrap_or(0),
        ScanError::Unbalanced | ScanError::Empty | ScanError::TooLong(_) => 0,
    }
}
