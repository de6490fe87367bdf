//! Graphviz DOT export.
//!
//! Conventions:
//! - every bond is an edge `from -> to` drawn with a half arrow (`lnormal`) at the head: the
//!   positive power direction;
//! - with causality, a causal stroke (`tee`) is drawn at the end that **receives the effort**
//!   (the other end imposes it): `arrowhead=teelnormal` when the stroke is at the head,
//!   `arrowtail=tee` when it is at the tail;
//! - node labels are `KIND:label-or-name` (`I:bar1.I_m_x`, `Se:Eg`, `MTF:-0.5·sin(α)`; for
//!   MTF/MGY without a label the modulus expression is shown); junctions show `0`/`1` with the
//!   name as an external label;
//! - storages with differential causality are red, conflicting junctions orange.

use super::causality::Causality;
use super::model::{BondGraph, ElementId, ElementKind, Parameter};
use std::collections::HashSet;
use std::fmt::Write;

fn escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}

/// The display label of an element.
pub fn node_label(graph: &BondGraph, id: ElementId) -> String {
    let e = graph.element(id);
    if e.kind.is_junction() {
        return e.kind.as_str().into();
    }
    let text = match (&e.label, &e.parameter, e.kind) {
        (Some(l), _, _) => l.clone(),
        (None, Some(Parameter::Expr(s)), ElementKind::MTF | ElementKind::MGY) => s.clone(),
        _ => e.name.clone(),
    };
    format!("{}:{}", e.kind.as_str(), text)
}

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
    for id in graph.element_ids() {
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
        let _ = writeln!(out, "  n{} [{attrs}];", id.0);
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
