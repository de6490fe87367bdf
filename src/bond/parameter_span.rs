//! A raw bond graph's expression parameters checked over the whole run before it starts, and
//! the remarks worth a warning (issue 51).
//!
//! [`crate::bond::validate::check_expression_values`] holds an expression of `t` to the sign
//! rules numbers obey at `t_start` only, so `"-5*t"` as a resistance (0 at the start, negative
//! after) or `"t"` as a stiffness (0 at the start) ran without a word. Here:
//!
//! - an expression of `t` alone is evaluated at the start and at [`SPAN_SAMPLES`] times evenly
//!   spread over `[t_start, t_end]`; an expression of `t` and the storages' states (`p_<I>`,
//!   `q_<C>`) at the start, with the states' initial values. The first time a value breaks
//!   its rule is refused, naming the element's JSON path, the expression, the time and the
//!   rule: a resistance `< 0` (a negative resistance gives energy to the motion), an inertia
//!   `< 0`, a stiffness or compliance that is not finite and `> 0`;
//! - a nonlinear resistor's law of its own flow (`effort_law`, in `f`) or effort (`flow_law`,
//!   in `e`) is evaluated at the start for flows or efforts of ±1e-3, ±1 and ±1e3: a law with
//!   `e·f < 0` there is a negative resistance, refused;
//! - warnings (not refusals): a modulus (`TF`, `GY`, `MTF`, `MGY`) of time alone that is 0 at
//!   the start (the element transmits nothing there, and where the causality divides by it the
//!   first evaluation fails; a modulus of the state, such as a body-frame bar's gyrator, is 0
//!   at rest by design), and a parameter written as a string holding a plain number
//!   (`"stiffness": "100"`: read as the expression `100`, legal, but most likely meant as a
//!   number).

use serde_json::Value;

use super::identifiers::variables;
use super::model::{BondGraph, ElementKind, Parameter};
use super::validate::{element_path, BondError};
use crate::expr::{excerpt, ExprGraph};

/// Times (besides `t_start`) at which an expression of `t` alone is checked, evenly spread
/// over the run.
pub const SPAN_SAMPLES: usize = 200;

/// Flows (or efforts) at which a nonlinear resistor's law is checked for dissipation.
const LAW_PROBES: [f64; 6] = [1e-3, -1e-3, 1.0, -1.0, 1e3, -1e3];

/// Whether element `i` of the raw scene gave its parameter as `stiffness` (a C given by its
/// stiffness is stored as the compliance `1/(k)`).
fn given_as_stiffness(raw: Option<&Value>, i: usize) -> bool {
    raw.and_then(|r| r.get("elements"))
        .and_then(|e| e.get(i))
        .is_some_and(|e| e.get("stiffness").is_some())
}

/// An expression compiled with its variables in slots: `t` in slot 0, then the names in
/// `names` order.
struct Compiled {
    graph: ExprGraph,
    expr: crate::expr::Expr,
    names: Vec<String>,
}

fn compile(source: &str) -> Option<Compiled> {
    let mut names: Vec<String> = variables(source).ok()?;
    names.retain(|n| n != "t");
    let mut graph = ExprGraph::new();
    let slots: Vec<(String, crate::expr::Expr)> = std::iter::once("t".to_string())
        .chain(names.iter().cloned())
        .enumerate()
        .map(|(k, n)| (n, graph.var(k as u32)))
        .collect();
    let expr = graph
        .parse(source, &mut |n| {
            slots.iter().find(|(m, _)| m == n).map(|(_, e)| *e)
        })
        .ok()?;
    Some(Compiled { graph, expr, names })
}

/// The initial value of a storage state `p_<I>` or `q_<C>` (the element's `initial`, 0 when
/// not given); `None` for any other name.
fn initial_state(graph: &BondGraph, name: &str) -> Option<f64> {
    let (kind, element) = if let Some(e) = name.strip_prefix("p_") {
        (ElementKind::I, e)
    } else if let Some(e) = name.strip_prefix("q_") {
        (ElementKind::C, e)
    } else {
        return None;
    };
    graph
        .elements
        .iter()
        .find(|el| el.kind == kind && el.name == element)
        .map(|el| el.initial.unwrap_or(0.0))
}

/// The rule a value of an element of `kind` breaks, if any. `stiffness`: a C given by its
/// stiffness (the value is then the compliance `1/k`).
fn rule(kind: ElementKind, value: f64, stiffness: bool) -> Option<&'static str> {
    match kind {
        ElementKind::R if value < 0.0 => {
            Some("a resistance must be >= 0 (a negative resistance gives energy to the motion, which then grows without bound)")
        }
        ElementKind::I if value < 0.0 => Some("an inertia must be >= 0"),
        ElementKind::C if stiffness && !(value.is_finite() && value > 0.0) => {
            Some("a stiffness must be > 0 and finite")
        }
        ElementKind::C if !(value.is_finite() && value > 0.0) => {
            Some("a compliance must be > 0 and finite")
        }
        _ => None,
    }
}

/// The times an expression of `t` alone is checked at: `t_start`, then [`SPAN_SAMPLES`]
/// evenly spread up to `t_end`.
fn span_times(t_start: f64, t_end: f64) -> Vec<f64> {
    let mut v = vec![t_start];
    if t_end.is_finite() && t_end > t_start {
        let n = SPAN_SAMPLES as f64;
        v.extend((1..=SPAN_SAMPLES).map(|k| t_start + (t_end - t_start) * k as f64 / n));
    }
    v
}

/// Every expression parameter of `graph` that breaks its rule somewhere in `[t_start, t_end]`
/// (an expression of `t`) or at the start (an expression of the states), and every resistor
/// law that gives energy at the start; `raw` is the scene's `"bond_graph"` JSON (which says
/// whether a C was given by its stiffness).
pub fn check_over_span(
    graph: &BondGraph,
    raw: Option<&Value>,
    t_start: f64,
    t_end: f64,
) -> Vec<BondError> {
    let mut errors = Vec::new();
    let times = span_times(t_start, t_end);
    for (i, e) in graph.elements.iter().enumerate() {
        if e.kind.is_junction() {
            continue;
        }
        if let Some(law) = &e.law {
            errors.extend(check_law(i, &e.name, law, t_start));
            continue;
        }
        let Some(Parameter::Expr(source)) = &e.parameter else {
            continue;
        };
        if !matches!(e.kind, ElementKind::R | ElementKind::I | ElementKind::C) {
            continue;
        }
        let Some(c) = compile(source) else { continue };
        let stiffness = e.kind == ElementKind::C && given_as_stiffness(raw, i);
        let field = match e.kind {
            ElementKind::C if stiffness => "stiffness",
            ElementKind::C => "compliance",
            _ => "value",
        };
        // the states at their initial values; an expression of anything else is left to the
        // solve's own checks
        let Some(states) = c
            .names
            .iter()
            .map(|n| initial_state(graph, n))
            .collect::<Option<Vec<f64>>>()
        else {
            continue;
        };
        let at: &[f64] = if states.is_empty() {
            &times
        } else {
            &times[..1]
        };
        let mut vars = vec![0.0; 1 + states.len()];
        vars[1..].copy_from_slice(&states);
        for &t in at {
            vars[0] = t;
            let value = c.graph.eval(c.expr, &vars);
            // a non-finite resistance or inertia is named by the solve's own check at its
            // first evaluation; a C's compliance is not (its equations use 1/C)
            if !value.is_finite() && e.kind != ElementKind::C {
                break;
            }
            if let Some(rule) = rule(e.kind, value, stiffness) {
                let (shown, text) = if stiffness {
                    // the stored compliance is 1/(k): the user wrote k
                    let k = source
                        .strip_prefix("1/(")
                        .and_then(|s| s.strip_suffix(')'))
                        .unwrap_or(source);
                    (1.0 / value, k)
                } else {
                    (value, source.as_str())
                };
                errors.push(BondError::ValueInRun {
                    path: format!("{}.{field}", element_path(i)),
                    element: e.name.clone(),
                    expr: excerpt(text, 0),
                    t,
                    value: shown,
                    rule,
                });
                break;
            }
        }
    }
    errors
}

/// A law `e = Φ(f)` (`effort_law`) or `f = Φ⁻¹(e)` (`flow_law`) of the resistor's own flow or
/// effort and `t` alone, refused when `e·f < 0` at the start for a probe value.
fn check_law(
    i: usize,
    name: &str,
    law: &super::model::ResistorLaw,
    t_start: f64,
) -> Option<BondError> {
    for (field, source, own) in [
        ("effort_law", law.effort.as_ref(), "f"),
        ("flow_law", law.flow.as_ref(), "e"),
    ] {
        let Some(source) = source else { continue };
        let Some(c) = compile(source) else { continue };
        if c.names.iter().any(|n| n != own) {
            continue;
        }
        for x in LAW_PROBES {
            let mut vars = vec![t_start];
            vars.extend(c.names.iter().map(|_| x));
            let y = c.graph.eval(c.expr, &vars);
            if y.is_finite() && y * x < 0.0 {
                return Some(BondError::ValueInRun {
                    path: format!("{}.{field}", element_path(i)),
                    element: name.to_string(),
                    expr: excerpt(source, 0),
                    t: t_start,
                    value: y,
                    rule: if own == "f" {
                        "a resistor's law must dissipate, e·f >= 0; here e has the sign opposite to f (a negative resistance gives energy to the motion)"
                    } else {
                        "a resistor's law must dissipate, e·f >= 0; here f has the sign opposite to e (a negative resistance gives energy to the motion)"
                    },
                });
            }
        }
    }
    None
}

/// Warnings about a raw bond graph's parameters, each starting with its JSON path: a modulus
/// of time alone that is 0 at `t_start`, and a parameter written as a string holding a plain number.
pub fn warnings(graph: &BondGraph, raw: Option<&Value>, t_start: f64) -> Vec<String> {
    let mut out = Vec::new();
    for (i, e) in graph.elements.iter().enumerate() {
        if !matches!(
            e.kind,
            ElementKind::TF | ElementKind::GY | ElementKind::MTF | ElementKind::MGY
        ) {
            continue;
        }
        // a modulus of time alone (one of the state is the model's own coupling: a body-frame
        // bar's gyrator `12*p_J` is 0 at rest, as it should be)
        let value = match &e.parameter {
            Some(Parameter::Const(v)) => Some((*v, None)),
            Some(Parameter::Expr(s)) => compile(s)
                .filter(|c| c.names.is_empty())
                .map(|c| (c.graph.eval(c.expr, &[t_start]), Some(s.as_str()))),
            _ => None,
        };
        if let Some((0.0, source)) = value {
            out.push(format!(
                "{}.modulus: {} '{}'{} is 0 at t_start = {t_start}: the element transmits nothing there, and where its causality divides by the modulus the first evaluation fails",
                element_path(i),
                e.kind.as_str(),
                e.name,
                source.map_or(String::new(), |s| format!(", modulus {}", excerpt(s, 0)))
            ));
        }
    }
    let elements = raw
        .and_then(|r| r.get("elements"))
        .and_then(Value::as_array);
    for (i, el) in elements.into_iter().flatten().enumerate() {
        for field in ["value", "stiffness", "compliance", "modulus"] {
            if let Some(Value::String(s)) = el.get(field) {
                if s.trim().parse::<f64>().is_ok() {
                    out.push(format!(
                        "{}.{field}: \"{}\" is a string holding a number: it is read as the expression {}; write a number without quotes (a string is for an expression such as \"100*(1 + t)\")",
                        element_path(i),
                        excerpt(s, 0),
                        s.trim()
                    ));
                }
            }
        }
    }
    out
}
