//! JSON form of a raw bond graph (the scene's `"bond_graph"` field).
//!
//! ```json
//! {"elements": [{"name": "m1", "kind": "I", "value": 1.0},
//!               {"name": "Eg", "kind": "Se", "value": "100*sin(t)"},
//!               {"name": "F",  "kind": "Se", "value": {"table": {"t": [0, 1], "v": [0, 5]}}},
//!               {"name": "k",  "kind": "C",  "stiffness": 1000.0},
//!               {"name": "tf1","kind": "MTF","modulus": "0.5*cos(x_J)"},
//!               {"name": "j1", "kind": "1"}],
//!  "bonds": [{"name": "b1", "from": "Eg", "to": "j1"}]}
//! ```
//! One-ports take `value` (C takes `stiffness` or `compliance` instead and stores the
//! compliance), two-ports take `modulus`, junctions nothing. Bond names default to `b<index>`.
//! Storage elements may give `"initial"`: the initial momentum of an I, the initial
//! displacement of a C (default 0; a finite number; not allowed on other kinds).
//! A nonlinear R gives its constitutive law instead of a `value`: `"effort_law"`, `e = Φ(f)`
//! in the flow `f` into the resistor (used under resistance causality), and/or
//! `"flow_law"`, `f = Φ⁻¹(e)` in its effort `e` (under conductance causality), e.g.
//! `{"name": "drag", "kind": "R", "effort_law": "0.3*f*abs(f)"}`.

use super::model::{BondGraph, ElementId, ElementKind, Parameter, ResistorLaw};
use super::validate::{
    bond_path, check_parameter, check_single_bond_junctions, collect_errors, element_path,
    known_variables, BondError, ValidationErrors, ROOT,
};
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};

/// A parameter as written in JSON: a number, an expression string or `{"table": {t, v}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RawParameter {
    /// A constant.
    Number(f64),
    /// An expression.
    Expr(String),
    /// A time table.
    Table {
        /// The table.
        table: RawTable,
    },
}

/// A time table `{"t": [...], "v": [...]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTable {
    /// Sample times.
    pub t: Vec<f64>,
    /// Values.
    pub v: Vec<f64>,
}

/// An element as written in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawElement {
    /// Unique name.
    pub name: String,
    /// "Se", "Sf", "I", "C", "R", "TF", "GY", "MTF", "MGY", "0" or "1".
    pub kind: String,
    /// Value of Se, Sf, I, R.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<RawParameter>,
    /// Modulus of TF, GY, MTF, MGY.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modulus: Option<RawParameter>,
    /// Stiffness of C (stored as compliance 1/k).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<RawParameter>,
    /// Compliance of C.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<RawParameter>,
    /// Display label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Initial state of a storage element: momentum of I, displacement of C (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<f64>,
    /// Nonlinear R: `e = Φ(f)`, an expression in the flow `f` into the resistor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effort_law: Option<String>,
    /// Nonlinear R: `f = Φ⁻¹(e)`, an expression in the effort `e` on the resistor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flow_law: Option<String>,
    /// C: its displacement as an expression of the displacement states (instead of a state
    /// of its own), e.g. a spring's stretch `L(x) − L₀`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<String>,
}

/// A displacement state `x_<element>` named as a coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDisplacement {
    /// The 1-junction or I whose flow it integrates.
    pub element: String,
    /// Coordinate name (a CSV column), e.g. `bar1.angle`.
    pub name: String,
    /// Initial value (default 0).
    #[serde(default)]
    pub initial: f64,
}

/// An inertia's flow named as a velocity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFlow {
    /// The inertia.
    pub element: String,
    /// Velocity name (a CSV column), e.g. `bar1.omega`.
    pub name: String,
    /// Initial flow (default 0).
    #[serde(default)]
    pub initial: f64,
}

/// A joint's constraint junction with its closure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConstraint {
    /// The 1-junction (two bonds) or Sf that imposes the row.
    pub element: String,
    /// Joint name.
    pub joint: String,
    /// Direction of the row.
    pub direction: String,
    /// `g_k(x)`, whose time derivative is the junction's flow constraint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closure: Option<String>,
}

/// A named expression (a signal definition or an output column).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawNamedExpr {
    /// Name.
    pub name: String,
    /// Expression.
    pub expr: String,
    /// For an output column: an angle to unwrap after evaluation.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub unwrap: bool,
}

/// A bond as written in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBond {
    /// Optional name (default `b<index>`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Name of the element at the tail of the half arrow.
    pub from: String,
    /// Name of the element at the head of the half arrow.
    pub to: String,
}

/// A raw bond graph as written in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBondGraph {
    /// Elements.
    pub elements: Vec<RawElement>,
    /// Bonds.
    #[serde(default)]
    pub bonds: Vec<RawBond>,
    /// External signal names expressions may use.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub signals: Vec<String>,
    /// Displacement states named as coordinates (a graph read as a mechanism).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub displacements: Vec<RawDisplacement>,
    /// Inertias' flows named as velocities.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flows: Vec<RawFlow>,
    /// Joints' constraint junctions with their closures.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub constraints: Vec<RawConstraint>,
    /// Signals defined as expressions of the states.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub signal_definitions: Vec<RawNamedExpr>,
    /// Output columns of a graph read as a mechanism.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<RawNamedExpr>,
    /// Mechanical energy of a graph read as a mechanism.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy: Option<String>,
    /// Inertias put in differential causality first where the junction structure leaves a
    /// choice ([`BondGraph::prefer_differential`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub prefer_differential: Vec<String>,
}

/// Failure to read a bond graph from JSON text.
#[derive(Debug, thiserror::Error)]
pub enum BondJsonError {
    /// The text is not a bond graph document.
    #[error("bond_graph: {0}")]
    Parse(#[from] serde_json::Error),
    /// The document describes an invalid graph.
    #[error("{0}")]
    Invalid(#[from] ValidationErrors),
}

impl From<&RawParameter> for Parameter {
    fn from(p: &RawParameter) -> Self {
        match p {
            RawParameter::Number(v) => Parameter::Const(*v),
            RawParameter::Expr(s) => Parameter::Expr(s.clone()),
            RawParameter::Table { table } => Parameter::Table {
                t: table.t.clone(),
                v: table.v.clone(),
            },
        }
    }
}

impl From<&Parameter> for RawParameter {
    fn from(p: &Parameter) -> Self {
        match p {
            Parameter::Const(v) => RawParameter::Number(*v),
            Parameter::Expr(s) => RawParameter::Expr(s.clone()),
            Parameter::Table { t, v } => RawParameter::Table {
                table: RawTable {
                    t: t.clone(),
                    v: v.clone(),
                },
            },
        }
    }
}

/// Compliance from a stiffness parameter (constants and tables inverted, expressions wrapped).
fn compliance_from_stiffness(k: &Parameter) -> Parameter {
    match k {
        Parameter::Const(v) => Parameter::Const(1.0 / v),
        Parameter::Expr(s) => Parameter::Expr(format!("1/({s})")),
        Parameter::Table { t, v } => Parameter::Table {
            t: t.clone(),
            v: v.iter().map(|x| 1.0 / x).collect(),
        },
    }
}

impl RawBondGraph {
    /// Copies the mechanism annotations (displacements, flows, constraints, signal
    /// definitions, outputs, energy) into `graph`, naming unknown elements by JSON path.
    fn annotations(
        &self,
        graph: &mut BondGraph,
        by_name: &HashMap<&str, ElementId>,
        errors: &mut Vec<BondError>,
    ) {
        let lookup = |field: &str, i: usize, name: &str, errors: &mut Vec<BondError>| {
            let id = by_name.get(name).copied();
            if id.is_none() {
                errors.push(BondError::BadParameter {
                    path: format!("{ROOT}.{field}[{i}].element"),
                    element: name.to_string(),
                    reason: "no element of this name".into(),
                });
            }
            id
        };
        for (i, d) in self.displacements.iter().enumerate() {
            if let Some(element) = lookup("displacements", i, &d.element, errors) {
                graph.displacements.push(super::model::Displacement {
                    element,
                    name: d.name.clone(),
                    initial: d.initial,
                });
            }
        }
        for (i, f) in self.flows.iter().enumerate() {
            if let Some(element) = lookup("flows", i, &f.element, errors) {
                graph.flows.push(super::model::FlowState {
                    element,
                    name: f.name.clone(),
                    initial: f.initial,
                });
            }
        }
        for (i, c) in self.constraints.iter().enumerate() {
            if let Some(element) = lookup("constraints", i, &c.element, errors) {
                graph
                    .constraint_junctions
                    .push(super::model::ConstraintJunction {
                        element,
                        joint: c.joint.clone(),
                        direction: c.direction.clone(),
                        closure: c.closure.clone(),
                    });
            }
        }
        graph.signal_definitions = self
            .signal_definitions
            .iter()
            .map(|d| super::model::SignalDefinition {
                name: d.name.clone(),
                expr: d.expr.clone(),
            })
            .collect();
        graph.outputs = self
            .outputs
            .iter()
            .map(|o| super::model::GraphOutput {
                name: o.name.clone(),
                expr: o.expr.clone(),
                unwrap: o.unwrap,
            })
            .collect();
        graph.energy = self.energy.clone();
        for (i, name) in self.prefer_differential.iter().enumerate() {
            match by_name.get(name.as_str()) {
                Some(&id) if graph.element(id).kind == ElementKind::I => {
                    graph.prefer_differential.push(name.clone())
                }
                Some(_) => errors.push(BondError::BadParameter {
                    path: format!("{ROOT}.prefer_differential[{i}]"),
                    element: name.clone(),
                    reason: "not an inertia (I): only an inertia can be preferred in differential causality".into(),
                }),
                None => errors.push(BondError::BadParameter {
                    path: format!("{ROOT}.prefer_differential[{i}]"),
                    element: name.clone(),
                    reason: "no element of this name".into(),
                }),
            }
        }
    }

    /// Parses JSON text (the value of `"bond_graph"`).
    pub fn from_json_str(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// Builds and validates the graph, collecting every error with its JSON path.
    pub fn to_graph(&self) -> Result<BondGraph, ValidationErrors> {
        let mut errors: Vec<BondError> = Vec::new();
        let mut graph = BondGraph::new();
        graph.signals = self.signals.clone();
        let mut by_name: HashMap<&str, ElementId> = HashMap::new();
        let mut stiffness_checks: Vec<(usize, Parameter)> = Vec::new();
        for (i, raw) in self.elements.iter().enumerate() {
            let path = element_path(i);
            let Some(kind) = ElementKind::parse(&raw.kind) else {
                errors.push(BondError::UnknownKind {
                    path: format!("{path}.kind"),
                    element: raw.name.clone(),
                    kind: raw.kind.clone(),
                });
                // keep a placeholder junction so that indices and bond ends still resolve
                let id = graph.add_junction(raw.name.clone(), ElementKind::One);
                by_name.entry(raw.name.as_str()).or_insert(id);
                continue;
            };
            let has_law = raw.effort_law.is_some() || raw.flow_law.is_some();
            let parameter = if has_law && kind == ElementKind::R && raw.value.is_none() {
                None
            } else {
                element_parameter(raw, kind, &path, &mut errors, &mut stiffness_checks, i)
            };
            let id = graph.add_element(raw.name.clone(), kind, parameter);
            if has_law {
                let field = if raw.effort_law.is_some() {
                    "effort_law"
                } else {
                    "flow_law"
                };
                if kind != ElementKind::R {
                    errors.push(BondError::BadParameter {
                        path: format!("{path}.{field}"),
                        element: raw.name.clone(),
                        reason: format!(
                            "a constitutive law applies to R elements only, not to {}",
                            kind.as_str()
                        ),
                    });
                } else if raw.value.is_some() {
                    errors.push(BondError::BadParameter {
                        path: format!("{path}.{field}"),
                        element: raw.name.clone(),
                        reason: "give either `value` (linear, e = R·f) or a law, not both".into(),
                    });
                } else {
                    graph.elements[id.0].law = Some(ResistorLaw {
                        effort: raw.effort_law.clone(),
                        flow: raw.flow_law.clone(),
                    });
                }
            }
            if let Some(l) = &raw.label {
                graph.set_label(id, l.clone());
            }
            if let Some(x0) = raw.initial {
                if !kind.is_storage() {
                    errors.push(BondError::BadParameter {
                        path: format!("{path}.initial"),
                        element: raw.name.clone(),
                        reason: format!(
                            "`initial` applies to storage elements (I, C) only, not to {}",
                            kind.as_str()
                        ),
                    });
                } else if !x0.is_finite() {
                    errors.push(BondError::NonFinite {
                        path: format!("{path}.initial"),
                        element: raw.name.clone(),
                        value: x0,
                    });
                } else if x0.abs() > super::validate::MAX_PARAMETER {
                    errors.push(BondError::TooLarge {
                        path: format!("{path}.initial"),
                        element: raw.name.clone(),
                        value: x0,
                        max: super::validate::MAX_PARAMETER,
                    });
                } else {
                    graph.set_initial(id, x0);
                }
            }
            by_name.entry(raw.name.as_str()).or_insert(id);
        }
        let mut skip: HashSet<ElementId> = HashSet::new();
        for (i, raw) in self.bonds.iter().enumerate() {
            let name = raw.name.clone().unwrap_or_else(|| format!("b{i}"));
            let from = by_name.get(raw.from.as_str()).copied();
            let to = by_name.get(raw.to.as_str()).copied();
            for (end, id, n) in [("from", from, &raw.from), ("to", to, &raw.to)] {
                if id.is_none() {
                    errors.push(BondError::UnknownElement {
                        path: format!("{}.{end}", bond_path(i)),
                        bond: name.clone(),
                        name: n.clone(),
                    });
                }
            }
            match (from, to) {
                (Some(f), Some(t)) => {
                    graph.add_named_bond(name, f, t);
                }
                (f, t) => {
                    skip.extend(f);
                    skip.extend(t);
                }
            }
        }
        for (i, raw) in self.elements.iter().enumerate() {
            if let Some(d) = &raw.displacement {
                if raw.kind != "C" {
                    errors.push(BondError::BadParameter {
                        path: format!("{}.displacement", element_path(i)),
                        element: raw.name.clone(),
                        reason: "`displacement` applies to C elements only".into(),
                    });
                } else {
                    graph.elements[i].displacement = Some(d.clone());
                }
            }
        }
        self.annotations(&mut graph, &by_name, &mut errors);
        // Stiffness is checked as stiffness (positive), before inversion.
        let known = known_variables(&graph);
        for (i, k) in &stiffness_checks {
            let e = &graph.elements[*i];
            let mut errs = Vec::new();
            check_parameter(
                &e.name,
                ElementKind::C,
                Some(k),
                &format!("{}.stiffness", element_path(*i)),
                &element_path(*i),
                &known,
                &mut errs,
            );
            for err in errs {
                errors.push(match err {
                    BondError::NonPositive {
                        path,
                        element,
                        value,
                        ..
                    } => BondError::NonPositive {
                        path,
                        element,
                        what: "stiffness".into(),
                        value,
                    },
                    other => other,
                });
            }
        }
        let stiffness_elements: HashSet<usize> = stiffness_checks.iter().map(|(i, _)| *i).collect();
        for err in collect_errors(&graph, &skip) {
            // parameters given as stiffness were already checked above
            let skip_err = stiffness_elements.iter().any(|i| {
                matches!(&err, BondError::NonPositive { path, .. } | BondError::NonFinite { path, .. } | BondError::TooLarge { path, .. } | BondError::UnknownVariable { path, .. } | BondError::BadExpression { path, .. } | BondError::BadParameter { path, .. }
                    if path.starts_with(&format!("{}.compliance", element_path(*i))))
            });
            if !skip_err {
                errors.push(err);
            }
        }
        // a junction left with one bond is often the consequence of another error (a bond
        // with a misspelt end): reported only when the graph has no other problem
        if errors.is_empty() {
            check_single_bond_junctions(&graph, &skip, &mut errors);
        }
        if errors.is_empty() {
            Ok(graph)
        } else {
            Err(ValidationErrors(errors))
        }
    }

    /// Reads the JSON value of a scene's `"bond_graph"`; an element or bond that cannot be read
    /// (unknown field, wrong type, missing field) is named by its index and name, e.g.
    /// `bond_graph.elements[3] (name "R1"): unknown field "resistence" (an R element takes
    /// "value"; …)`, the closest known field suggested when one is close.
    pub fn from_value(v: &serde_json::Value) -> Result<Self, ValidationErrors> {
        let whole = match serde_json::from_value::<RawBondGraph>(v.clone()) {
            Ok(g) => return Ok(g),
            Err(e) => e,
        };
        let mut errors = Vec::new();
        if let Some(obj) = v.as_object() {
            for key in obj.keys() {
                if !GRAPH_FIELDS.contains(&key.as_str()) {
                    errors.push(BondError::Field {
                        path: ROOT.into(),
                        element: None,
                        message: unknown_field(key, GRAPH_FIELDS),
                    });
                }
            }
        }
        for (list, fields) in [("elements", ELEMENT_FIELDS), ("bonds", BOND_FIELDS)] {
            let Some(items) = v.get(list).and_then(|a| a.as_array()) else {
                continue;
            };
            for (i, item) in items.iter().enumerate() {
                let path = format!("{ROOT}.{list}[{i}]");
                let element = item.get("name").and_then(|n| n.as_str()).map(String::from);
                let mut push = |message: String| {
                    errors.push(BondError::Field {
                        path: path.clone(),
                        element: element.clone(),
                        message,
                    })
                };
                let unknown: Vec<&String> = item
                    .as_object()
                    .map(|o| o.keys().filter(|k| !fields.contains(&k.as_str())).collect())
                    .unwrap_or_default();
                if !unknown.is_empty() {
                    for k in unknown {
                        push(unknown_field(k, fields));
                    }
                    continue;
                }
                let err = if list == "elements" {
                    serde_json::from_value::<RawElement>(item.clone()).err()
                } else {
                    serde_json::from_value::<RawBond>(item.clone()).err()
                };
                if let Some(e) = err {
                    push(e.to_string());
                }
            }
        }
        if errors.is_empty() {
            errors.push(BondError::Field {
                path: ROOT.into(),
                element: None,
                message: whole.to_string(),
            });
        }
        Err(ValidationErrors(errors))
    }
}

/// Fields of a `"bond_graph"` object.
const GRAPH_FIELDS: &[&str] = &["elements", "bonds", "signals"];
/// Fields of an element.
const ELEMENT_FIELDS: &[&str] = &[
    "name",
    "kind",
    "value",
    "modulus",
    "stiffness",
    "compliance",
    "label",
    "initial",
    "effort_law",
    "flow_law",
];
/// Fields of a bond.
const BOND_FIELDS: &[&str] = &["name", "from", "to"];

/// `unknown field "x"`, with the closest known field when one is close (edit distance at most
/// a third of the longer name, or a parameter word such as `resistance` → `value`), and the
/// known fields.
fn unknown_field(key: &str, known: &[&str]) -> String {
    let lower = key.to_lowercase();
    let best = known
        .iter()
        .map(|k| (edit_distance(&lower, k), *k))
        .min()
        .filter(|(d, k)| {
            let longer = k.len().max(lower.len());
            *d <= (longer / 3).max(if longer >= 5 { 2 } else { 1 })
        })
        .map(|(_, k)| k);
    // names of element parameters that bond graph texts use for `value`
    let parameter_words = [
        "resist", "induct", "inert", "mass", "capac", "effort", "flow", "source", "damp", "param",
    ];
    let best = best.or_else(|| {
        (known.contains(&"value") && parameter_words.iter().any(|w| lower.contains(w)))
            .then_some("value")
    });
    let list = known
        .iter()
        .map(|k| format!("\"{k}\""))
        .collect::<Vec<_>>()
        .join(", ");
    match best {
        Some(b) => format!("unknown field \"{key}\" (did you mean \"{b}\"? known fields: {list})"),
        None => format!("unknown field \"{key}\" (known fields: {list})"),
    }
}

/// Levenshtein distance between two short strings.
pub(crate) fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

fn element_parameter(
    raw: &RawElement,
    kind: ElementKind,
    path: &str,
    errors: &mut Vec<BondError>,
    stiffness_checks: &mut Vec<(usize, Parameter)>,
    index: usize,
) -> Option<Parameter> {
    let misplaced = |field: &str, errors: &mut Vec<BondError>| {
        let allowed = match kind {
            ElementKind::C => "`stiffness` or `compliance`",
            k if k.is_two_port() => "`modulus`",
            k if k.is_junction() => "no parameter",
            _ => "`value`",
        };
        errors.push(BondError::BadParameter {
            path: format!("{path}.{field}"),
            element: raw.name.clone(),
            reason: format!(
                "field `{field}` does not apply to a {} element (it takes {allowed})",
                kind.as_str()
            ),
        });
    };
    let fields = [
        ("value", &raw.value),
        ("modulus", &raw.modulus),
        ("stiffness", &raw.stiffness),
        ("compliance", &raw.compliance),
    ];
    let wanted: &[&str] = match kind {
        ElementKind::C => &["stiffness", "compliance"],
        k if k.is_two_port() => &["modulus"],
        k if k.is_junction() => &[],
        _ => &["value"],
    };
    for (field, v) in fields {
        if v.is_some() && !wanted.contains(&field) {
            misplaced(field, errors);
        }
    }
    match kind {
        ElementKind::C => match (&raw.stiffness, &raw.compliance) {
            (Some(_), Some(_)) => {
                errors.push(BondError::BadParameter {
                    path: format!("{path}.stiffness"),
                    element: raw.name.clone(),
                    reason: "give either `stiffness` or `compliance`, not both".into(),
                });
                None
            }
            (Some(k), None) => {
                let k = Parameter::from(k);
                stiffness_checks.push((index, k.clone()));
                Some(compliance_from_stiffness(&k))
            }
            (None, Some(c)) => Some(Parameter::from(c)),
            (None, None) => None,
        },
        k if k.is_two_port() => raw.modulus.as_ref().map(Parameter::from),
        k if k.is_junction() => None,
        _ => raw.value.as_ref().map(Parameter::from),
    }
}

impl BondGraph {
    /// Reads and validates a graph from the JSON text of a `"bond_graph"` value.
    pub fn from_json_str(text: &str) -> Result<BondGraph, BondJsonError> {
        Ok(RawBondGraph::from_json_str(text)?.to_graph()?)
    }

    /// The JSON form of this graph (C written as `compliance`).
    pub fn to_raw(&self) -> RawBondGraph {
        let elements = self
            .elements
            .iter()
            .map(|e| {
                let p = e.parameter.as_ref().map(RawParameter::from);
                let mut raw = RawElement {
                    name: e.name.clone(),
                    kind: e.kind.as_str().into(),
                    value: None,
                    modulus: None,
                    stiffness: None,
                    compliance: None,
                    label: e.label.clone(),
                    initial: e.initial,
                    effort_law: e.law.as_ref().and_then(|l| l.effort.clone()),
                    flow_law: e.law.as_ref().and_then(|l| l.flow.clone()),
                    displacement: e.displacement.clone(),
                };
                match e.kind {
                    ElementKind::C => raw.compliance = p,
                    k if k.is_two_port() => raw.modulus = p,
                    _ => raw.value = p,
                }
                raw
            })
            .collect();
        let bonds = self
            .bonds
            .iter()
            .map(|b| RawBond {
                name: Some(b.name.clone()),
                from: self.elements[b.from.0].name.clone(),
                to: self.elements[b.to.0].name.clone(),
            })
            .collect();
        let name = |id: ElementId| self.elements[id.0].name.clone();
        RawBondGraph {
            elements,
            bonds,
            signals: self.signals.clone(),
            displacements: self
                .displacements
                .iter()
                .map(|d| RawDisplacement {
                    element: name(d.element),
                    name: d.name.clone(),
                    initial: d.initial,
                })
                .collect(),
            flows: self
                .flows
                .iter()
                .map(|f| RawFlow {
                    element: name(f.element),
                    name: f.name.clone(),
                    initial: f.initial,
                })
                .collect(),
            constraints: self
                .constraint_junctions
                .iter()
                .map(|c| RawConstraint {
                    element: name(c.element),
                    joint: c.joint.clone(),
                    direction: c.direction.clone(),
                    closure: c.closure.clone(),
                })
                .collect(),
            signal_definitions: self
                .signal_definitions
                .iter()
                .map(|d| RawNamedExpr {
                    name: d.name.clone(),
                    expr: d.expr.clone(),
                    unwrap: false,
                })
                .collect(),
            outputs: self
                .outputs
                .iter()
                .map(|o| RawNamedExpr {
                    name: o.name.clone(),
                    expr: o.expr.clone(),
                    unwrap: o.unwrap,
                })
                .collect(),
            energy: self.energy.clone(),
            prefer_differential: self.prefer_differential.clone(),
        }
    }
}
