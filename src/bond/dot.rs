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

/// Text for a Graphviz HTML-like label.
fn html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// One node per fragment (body or joint), labelled with its element counts; one edge per pair
/// of fragments that bonds join, labelled with their number.
fn collapsed_dot(graph: &BondGraph, causality: Option<&Causality>) -> String {
    use std::collections::BTreeMap;
    let mut groups: Vec<(String, Vec<ElementId>)> = Vec::new();
    for id in graph.element_ids() {
        let key = fragment(&graph.element(id).name).to_string();
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(id),
            None => groups.push((key, vec![id])),
        }
    }
    let group_of: BTreeMap<usize, usize> = groups
        .iter()
        .enumerate()
        .flat_map(|(g, (_, ids))| ids.iter().map(move |id| (id.0, g)))
        .collect();
    let mut out = String::new();
    let _ = writeln!(out, "digraph bond_graph {{");
    let _ = writeln!(
        out,
        "  rankdir=LR; size=\"{MAX_INCHES},{MAX_INCHES}\"; label=\"one node per body or joint (--expand: every element)\"; fontsize=11;"
    );
    let _ = writeln!(
        out,
        "  node [shape=box, style=rounded, fontname=\"Helvetica\"];"
    );
    for (g, (key, ids)) in groups.iter().enumerate() {
        let mut kinds: BTreeMap<&str, usize> = BTreeMap::new();
        for id in ids {
            *kinds.entry(graph.element(*id).kind.as_str()).or_default() += 1;
        }
        let counts: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} {k}")).collect();
        let differential = causality
            .map(|c| ids.iter().filter(|&&e| c.is_differential(e)).count())
            .unwrap_or(0);
        // DOT's `\n` between escaped lines
        let mut label = format!(
            "{}\\n{}",
            escape(&shorten(key, 40)),
            escape(&shorten(&counts.join(", "), 56))
        );
        let mut colour = "";
        if differential > 0 {
            label.push_str(&format!("\\n{differential} differential"));
            colour = ", color=red, fontcolor=red";
        }
        let _ = writeln!(out, "  g{g} [label=\"{label}\"{colour}];");
    }
    let mut edges: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    for b in &graph.bonds {
        let (a, c) = (group_of[&b.from.0], group_of[&b.to.0]);
        if a != c {
            *edges.entry((a.min(c), a.max(c))).or_default() += 1;
        }
    }
    for ((a, c), n) in edges {
        let _ = writeln!(
            out,
            "  g{a} -> g{c} [dir=none, label=\"{n} bond{}\"];",
            if n == 1 { "" } else { "s" }
        );
    }
    out.push_str("}\n");
    out
}

/// Graphs with more elements than this are drawn grouped by body (Graphviz clusters).
pub const CLUSTER_ABOVE: usize = 30;

/// Graphs with more elements than this are drawn collapsed by default: one node per body's or
/// joint's fragment ([`to_dot_with`]).
pub const COLLAPSE_ABOVE: usize = 200;

/// The longest node label drawn in full; a longer modulus is drawn by the element's name and
/// listed (shortened) in the legend.
pub const MAX_LABEL: usize = 40;

/// The drawing's largest side in inches (Graphviz `size`, scaled down to fit): 55 in = 3960 pt.
pub const MAX_INCHES: u32 = 55;

/// Numbers in `text` with float noise (`0.0007400000000000011`) written in the shortest form
/// that rounds to the same 12 significant digits (`0.00074`).
pub fn tidy_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            && (i == 0
                || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'));
        if !starts {
            let ch = text[i..].chars().next().unwrap_or(' ');
            out.push(ch);
            i += ch.len_utf8();
            continue;
        }
        let mut j = i;
        while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.') {
            j += 1;
        }
        if j < b.len() && (b[j] == b'e' || b[j] == b'E') {
            let mut k = j + 1;
            if k < b.len() && (b[k] == b'-' || b[k] == b'+') {
                k += 1;
            }
            if k < b.len() && b[k].is_ascii_digit() {
                j = k;
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
            }
        }
        let lit = &text[i..j];
        match lit.parse::<f64>() {
            Ok(v) if lit.len() > 12 && v.is_finite() && v != 0.0 => {
                let rounded: f64 = format!("{v:.11e}").parse().unwrap_or(v);
                out.push_str(&format!("{rounded}"));
            }
            _ => out.push_str(lit),
        }
        i = j;
    }
    out
}

/// A label at most `max` characters long (`…` at the cut).
fn shorten(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        return s.to_string();
    }
    let mut t: String = s.chars().take(max.saturating_sub(1)).collect();
    t.push('…');
    t
}

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
    format!("{}:{}", e.kind.as_str(), tidy_numbers(&text))
}

/// The legend of the colours and strokes (an HTML-like Graphviz label on one node).
const LEGEND: &str = "  legend [shape=plaintext, fontsize=11, label=<<table border=\"1\" cellborder=\"0\" cellspacing=\"2\" cellpadding=\"2\">\
<tr><td colspan=\"2\"><b>legend</b></td></tr>\
<tr><td>I:name</td><td align=\"left\">storage in integral causality (a state)</td></tr>\
<tr><td border=\"1\"><font color=\"red\">I:name</font></td><td align=\"left\">inertia in differential causality (a DAE row)</td></tr>\
<tr><td border=\"1\"><font color=\"orange\">0 / 1</font></td><td align=\"left\">junction with a causal conflict</td></tr>\
<tr><td>half arrow</td><td align=\"left\">positive power direction</td></tr>\
<tr><td>bar (stroke)</td><td align=\"left\">at the end that receives the effort</td></tr>\
<tr><td>MTF:…α_b</td><td align=\"left\">modulus depending on the angle α of body b</td></tr>\
</table>>];\n";

/// Renders the graph as DOT, with causal strokes and colours when `causality` is given;
/// collapsed ([`to_dot_with`]) when it has more than [`COLLAPSE_ABOVE`] elements.
pub fn to_dot(graph: &BondGraph, causality: Option<&Causality>) -> String {
    let collapse = graph.element_ids().count() > COLLAPSE_ABOVE;
    to_dot_with(graph, causality, collapse)
}

/// The fragment an element belongs to: the first part of its name (a body or a joint).
fn fragment(name: &str) -> &str {
    name.split('.').next().unwrap_or(name)
}

/// Renders the graph as DOT: every element (`collapse` false; long moduli drawn by the
/// element's name and listed in a legend) or one node per body's or joint's fragment
/// (`collapse` true, its elements counted by kind, the bonds between fragments counted).
/// Either way the drawing is at most [`MAX_INCHES`] on its longer side.
pub fn to_dot_with(graph: &BondGraph, causality: Option<&Causality>, collapse: bool) -> String {
    if collapse {
        return collapsed_dot(graph, causality);
    }
    let mut out = String::new();
    let _ = writeln!(out, "digraph bond_graph {{");
    let _ = writeln!(out, "  rankdir=LR; size=\"{MAX_INCHES},{MAX_INCHES}\";");
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
    // long moduli: the element's name in the node, the modulus (shortened) in a legend
    let mut moduli: Vec<String> = Vec::new();
    let labels: Vec<String> = graph
        .element_ids()
        .map(|id| {
            let full = node_label(graph, id);
            if full.chars().count() <= MAX_LABEL {
                return full;
            }
            let e = graph.element(id);
            let short = shorten(&format!("{}:{}", e.kind.as_str(), e.name), MAX_LABEL);
            let text = full.split_once(':').map_or(full.as_str(), |x| x.1);
            moduli.push(shorten(&format!("{} = {text}", shorten(&e.name, 20)), 58));
            short
        })
        .collect();
    let node = |id: ElementId| {
        let e = graph.element(id);
        let mut attrs = format!("label=\"{}\"", escape(&labels[id.0]));
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
    if !moduli.is_empty() {
        let rows: String = moduli
            .iter()
            .map(|m| format!("<tr><td align=\"left\">{}</td></tr>", html(m)))
            .collect();
        let _ = writeln!(
            out,
            "  moduli [shape=plaintext, fontsize=11, label=<<table border=\"1\" cellborder=\"0\" cellspacing=\"1\" cellpadding=\"1\"><tr><td><b>long moduli (in full: bondmech equations)</b></td></tr>{rows}</table>>];"
        );
    }
    for (i, b) in graph.bonds.iter().enumerate() {
        let mut attrs = format!("label=\"{}\"", escape(&shorten(&b.name, MAX_LABEL)));
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
