//! Graphviz DOT export.
//!
//! Conventions:
//! - every bond is an edge `from -> to` drawn with a half arrow (`lnormal`) at the head: the
//!   positive power direction;
//! - with causality, a causal stroke (`tee`) is drawn at the end that **receives the effort**
//!   (the other end imposes it): `arrowhead=teelnormal` when the stroke is at the head,
//!   `arrowtail=tee` when it is at the tail;
//! - node labels are `KIND:label-or-name` (`I:bar1.I_m_x`, `Se:Eg`, `MTF:-0.5·sin(α_bar1)`; for
//!   MTF/MGY without a label the modulus expression is shown; an angle `α` in a label is named
//!   after the body whose angle it is, `α_bar1`, when the modulus depends on one body angle
//!   `x_bar1.omega`); junctions show `0`/`1` with the name as an external label;
//! - storages with differential causality are red, conflicting junctions orange; with
//!   causality, a legend node explains the colours and strokes;
//! - a graph of more than [`CLUSTER_ABOVE`] elements is grouped into Graphviz clusters by the
//!   first part of the element names — one cluster per body (`bar1.v_x`, `bar1.O.sum_x`, …) and
//!   per joint (`hip.x`, …).

use super::causality::Causality;
use super::model::{BondGraph, ElementId, ElementKind, Parameter};
use std::collections::HashSet;
use std::fmt::Write;

fn escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}

/// Graphs with more elements than this are drawn grouped by body (Graphviz clusters).
pub const CLUSTER_ABOVE: usize = 30;

/// The body angle a modulus depends on: `bar1` for an expression in `x_bar1.omega` alone.
fn angle_body(expr: &str) -> Option<&str> {
    let mut found: Option<&str> = None;
    let mut rest = expr;
    while let Some(i) = rest.find("x_") {
        let tail = &rest[i + 2..];
        if let Some(j) = tail.find(".omega") {
            let name = &tail[..j];
            let plain = !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_alphanumeric() || c == '_' || c == '-');
            if plain {
                match found {
                    Some(f) if f != name => return None,
                    _ => found = Some(name),
                }
            }
        }
        rest = tail;
    }
    found
}

/// The display label of an element.
pub fn node_label(graph: &BondGraph, id: ElementId) -> String {
    let e = graph.element(id);
    if e.kind.is_junction() {
        return e.kind.as_str().into();
    }
    let mut text = match (&e.label, &e.parameter, e.kind) {
        (Some(l), _, _) => l.clone(),
        (None, Some(Parameter::Expr(s)), ElementKind::MTF | ElementKind::MGY) => s.clone(),
        _ => e.name.clone(),
    };
    if let (Some(Parameter::Expr(s)), ElementKind::MTF | ElementKind::MGY) = (&e.parameter, e.kind)
    {
        if let Some(body) = angle_body(s) {
            text = text
                .replace('α', &format!("α_{body}"))
                .replace(&format!("x_{body}.omega"), &format!("α_{body}"));
        }
    }
    format!("{}:{}", e.kind.as_str(), text)
}

/// The legend of the colours and strokes (an HTML-like Graphviz label on one node).
const LEGEND: &str = "  legend [shape=plaintext, fontsize=11, label=<<table border=\"1\" cellborder=\"0\" cellspacing=\"2\" cellpadding=\"2\">\
<tr><td colspan=\"2\"><b>legend</b></td></tr>\
<tr><td>I:name</td><td align=\"left\">storage in integral causality (a state)</td></tr>\
<tr><td border=\"1\"><font color=\"red\">I:name</font></td><td align=\"left\">inertia in differential causality (a constraint row of the DAE)</td></tr>\
<tr><td border=\"1\"><font color=\"orange\">0 / 1</font></td><td align=\"left\">junction with a causal conflict</td></tr>\
<tr><td>half arrow</td><td align=\"left\">positive power direction</td></tr>\
<tr><td>bar (stroke)</td><td align=\"left\">at the end that receives the effort</td></tr>\
<tr><td>MTF:…α_b</td><td align=\"left\">modulus depending on the angle α of body b</td></tr>\
</table>>];\n";

/// Renders the graph as DOT, with causal strokes and colours when `causality` is given.
pub fn to_dot(graph: &BondGraph, causality: Option<&Causality>) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph bond_graph {{");
    let _ = writeln!(out, "  rankdir=LR;");
    let _ = writeln!(out, "  node [shape=plaintext, fontname=\"Helvetica\"];");
    let _ = writeln!(out, "  edge [arrowhead=lnormal];");
    let differential: HashSet<ElementId> = causality
        .map(|c| {
            graph
                .element_ids()
                .filter(|&e| c.is_differential(e))
                .collect()
        })
        .unwrap_or_default();
    let conflicted: HashSet<String> = causality
        .map(|c| c.conflicts.iter().map(|k| k.junction.clone()).collect())
        .unwrap_or_default();
    let node = |id: ElementId| {
        let e = graph.element(id);
        let mut attrs = format!("label=\"{}\"", escape(&node_label(graph, id)));
        if e.kind.is_junction() {
            let _ = write!(attrs, ", xlabel=\"{}\"", escape(&e.name));
        }
        if differential.contains(&id) {
            attrs.push_str(", fontcolor=red, color=red, shape=box");
        } else if conflicted.contains(&e.name) {
            attrs.push_str(", fontcolor=orange, color=orange, shape=box");
        }
        format!("n{} [{attrs}];", id.0)
    };
    let ids: Vec<ElementId> = graph.element_ids().collect();
    if ids.len() > CLUSTER_ABOVE {
        // one cluster per body or joint: the first part of the element names
        let mut groups: Vec<(String, Vec<ElementId>)> = Vec::new();
        for &id in &ids {
            let name = &graph.element(id).name;
            let key = name.split('.').next().unwrap_or(name).to_string();
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, v)) => v.push(id),
                None => groups.push((key, vec![id])),
            }
        }
        for (i, (key, members)) in groups.iter().enumerate() {
            if members.len() < 2 {
                let _ = writeln!(out, "  {}", node(members[0]));
                continue;
            }
            let _ = writeln!(out, "  subgraph cluster_{i} {{");
            let _ = writeln!(
                out,
                "    label=\"{}\"; style=rounded; color=gray60; fontcolor=gray30;",
                escape(key)
            );
            for &id in members {
                let _ = writeln!(out, "    {}", node(id));
            }
            let _ = writeln!(out, "  }}");
        }
    } else {
        for &id in &ids {
            let _ = writeln!(out, "  {}", node(id));
        }
    }
    if causality.is_some() {
        out.push_str(LEGEND);
    }
    for (i, b) in graph.bonds.iter().enumerate() {
        let mut attrs = format!("label=\"{}\"", escape(&b.name));
        if let Some(c) = causality {
            let a = &c.bonds[i];
            if a.effort_receiver == b.to {
                attrs.push_str(", arrowhead=teelnormal");
            } else {
                attrs.push_str(", dir=both, arrowtail=tee");
            }
            let hot = |e: ElementId| {
                differential.contains(&e) || conflicted.contains(&graph.element(e).name)
            };
            if differential.contains(&b.from) || differential.contains(&b.to) {
                attrs.push_str(", color=red");
            } else if hot(b.from) || hot(b.to) {
                attrs.push_str(", color=orange");
            }
        }
        let _ = writeln!(out, "  n{} -> n{} [{attrs}];", b.from.0, b.to.0);
    }
    out.push_str("}\n");
    out
}
