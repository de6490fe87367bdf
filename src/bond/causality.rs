//! Causality by matching: structural assignment from a bipartite matching, true DOF from the
//! numeric rank of the constraint rows.
//!
//! Each bond gets a causal stroke at the end that *receives* the effort (the other end
//! imposes it). Rules: Se imposes effort, Sf imposes flow; at a 0-junction exactly one bond
//! imposes the common effort, at a 1-junction exactly one bond imposes the common flow;
//! TF/MTF pass the stroke through (one in, one out), GY/MGY have both strokes away.
//!
//! 1. **Which inertias are dependent** ([`super::rank`]): the junction structure's flow
//!    equations are eliminated down to the constraint rows `G v_I = 0` on the inertia flows, and
//!    `G` is factorised with complete pivoting. Its rank `r` is the number of inertias in
//!    differential causality (seed 16.5: one per independent constraint); the pivot columns are
//!    those inertias, chosen by the size of their pivots at the state (never one whose flow would
//!    be found by dividing by a modulus that vanishes there); rows left without a pivot are the
//!    **redundant junctions**. [`assign_causality`] takes `r` as the generic rank (moduli at
//!    generic values: the structural count, what a graph drawn without a geometry means) and
//!    prefers the inertias well conditioned at the graph's initial state;
//!    [`assign_causality_at`] takes the rank at a given state (a mechanism's initial
//!    configuration), so a geometrically special mechanism (Bricard's loop: generically rigid,
//!    one DOF from its geometry) gets its true DOF and its redundant joint rows named. Where
//!    the rows leave a choice, the inertias the graph lists in
//!    [`BondGraph::prefer_differential`] are pivoted on first (a freely rotating spatial
//!    body's angular inertias, so that its centre's velocity is integral: the chapter's freedom
//!    among admissible assignments, used for accuracy).
//! 2. **The strokes** ([`super::orient`]): with those inertias differential and the others
//!    integral, capacitors integral, the causal strokes are a degree-constrained orientation of
//!    the bonds, solved as a bipartite matching (max flow). When the rules cannot all hold,
//!    storages change causality before a junction is over-determined; an element left outside
//!    its rule is a **conflict** (the redundant junctions are over-determined by design and
//!    appear there too).
//! 3. **Algebraic loops**: resistors on a cycle of the variable dependency graph (strongly
//!    connected components of "bond variable computed from bond variable"), i.e. zero-order
//!    causal paths.
//!
//! Everything is built in the canonical (name) order, so the assignment does not depend on the
//! order of elements or bonds in the file. The cost is that of the sparse elimination (linear
//! in the size of chains and trees of bodies), Dinic's max flow (`O(E √V)`) and Tarjan's
//! algorithm (linear). `dof = #integral I` (seed 16.5: "solo las inercias con causalidad
//! integral … corresponden con grados de libertad"); `state_count = #integral I + #integral C`.

use super::model::{BondGraph, BondId, ElementId, ElementKind, Parameter};
use super::orient::Network;
use super::rank::{
    canonical_bonds, canonical_elements, constraint_rank, ConstraintRank, Valuation,
};
use super::validate::{validate, ValidationErrors};
use serde::Serialize;

/// What kind of bond this is for the assignment (the matching fixes all bonds at once).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Stage {
    /// The bond of a source (its causality is required).
    Source,
    /// The bond of a storage element (its causality chosen from the constraint rows' pivots).
    Storage,
    /// The bond of a resistor.
    Resistor,
    /// Not produced by the matching (kept so that reports of older versions still parse).
    Arbitrary,
    /// A bond of the junction structure (junctions and two-ports only).
    Propagated,
}

/// The causal assignment of one bond (ids).
#[derive(Debug, Clone, PartialEq)]
pub struct BondAssignment {
    /// The element that receives the effort (the causal stroke's end).
    pub effort_receiver: ElementId,
    /// The element that imposes the effort (the other end).
    pub effort_source: ElementId,
    /// The element that imposes the effort (the matching has no propagation order to record).
    pub origin: ElementId,
    /// What kind of bond it is.
    pub stage: Stage,
    /// None: the matching fixes every bond at once (see [`DifferentialStorage`] for what forced
    /// a differential storage, read from the final causal graph).
    pub via: Option<ElementId>,
    /// Empty, as `via`.
    pub causes: Vec<BondId>,
}

/// Integral or differential causality of a storage element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StorageCausality {
    /// I receives effort / C receives flow: a state.
    Integral,
    /// Forced the other way: a dependent variable.
    Differential,
}

/// A storage element with differential causality and what forced it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DifferentialStorage {
    /// Storage element name.
    pub element: String,
    /// Its bond.
    pub bond: String,
    /// The junction where the constraint closes: following the variable the storage receives
    /// (flow for I, effort for C) back through the causal graph, the first junction computing
    /// it as a balance of two or more other bonds; when the chain ends at a state or source
    /// instead, the last junction on it.
    pub forced_by_junction: String,
    /// The bonds at that junction that determined it (never empty).
    pub via_bonds: Vec<String>,
    /// The elements at the other ends of `via_bonds` (e.g. the pin's 1-junction).
    pub via_elements: Vec<String>,
    /// Junctions and two-ports from the storage back to `forced_by_junction`, in that order.
    pub path: Vec<String>,
    /// The constraint junction whose row was solved for this storage (the pivot row of the
    /// rank-revealing factorisation, e.g. `knee.y`); the forcing junction otherwise.
    pub origin: String,
}

/// An over-determined junction or two-port.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Conflict {
    /// The junction (or two-port/source) where the clash shows.
    pub junction: String,
    /// The elements whose requirements clash.
    pub elements: Vec<String>,
    /// Human-readable explanation.
    pub description: String,
}

/// Causality of one bond, by name.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BondCausality {
    /// Bond name.
    pub bond: String,
    /// Tail of the half arrow.
    pub from: String,
    /// Head of the half arrow.
    pub to: String,
    /// Element imposing the effort.
    pub effort_by: String,
    /// Element receiving the effort (causal stroke end).
    pub stroke_at: String,
    /// Step that fixed it.
    pub stage: Stage,
}

/// Causality of one storage element, by name.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StorageInfo {
    /// Element name.
    pub element: String,
    /// "I" or "C".
    pub kind: String,
    /// Integral or differential.
    pub causality: StorageCausality,
}

/// The result of causality assignment with ids, for the equation builder.
#[derive(Debug, Clone, PartialEq)]
pub struct Causality {
    /// Per bond, in bond order.
    pub bonds: Vec<BondAssignment>,
    /// Per storage element, in element order.
    pub storage: Vec<(ElementId, StorageCausality)>,
    /// Over-determined junctions.
    pub conflicts: Vec<Conflict>,
    /// Resistor groups on zero-order causal loops (ids, element order).
    pub algebraic_loops: Vec<Vec<ElementId>>,
    /// The constraint rows and their rank (see [`super::rank`]).
    pub constraints: ConstraintSummary,
}

/// What the numeric factorisation of the constraint rows found.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintSummary {
    /// Number of flow rows of the junction structure.
    pub rows: usize,
    /// Rank of the constraint rows on the inertia flows at generic moduli (structural count).
    pub generic_rank: usize,
    /// Rank at the state the assignment was made for (the graph's initial values, or the state
    /// given to [`assign_causality_at`]).
    pub numeric_rank: usize,
    /// The rank the assignment follows (`generic_rank` for [`assign_causality`],
    /// `numeric_rank` for [`assign_causality_at`]).
    pub rank: usize,
    /// Junctions (or Sf, TF) whose rows were left without a pivot: redundant at that rank.
    pub redundant: Vec<ElementId>,
    /// For each inertia put in differential causality by a pivot, the junction of its row.
    pub pivot_rows: Vec<(ElementId, ElementId)>,
}

/// A redundant constraint junction: its row is a combination of the others.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RedundantJunction {
    /// The junction (1-junction of a joint row, Sf of a row to ground, 0-junction or TF).
    pub junction: String,
    /// The joint: the junction name up to its last `.` (`hinge3` of `hinge3.axis2`).
    pub joint: String,
    /// The direction: the junction name after its last `.` (`axis2`; empty without a `.`).
    pub direction: String,
}

/// The serializable causality report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CausalityReport {
    /// Degrees of freedom: the number of inertias with integral causality (seed 16.5).
    pub dof: usize,
    /// Number of integral storages (I and C), `= states.len()`: the states of the ODE/DAE.
    pub state_count: usize,
    /// Integral storage element names (I first, then C, each in element order).
    pub states: Vec<String>,
    /// State variable names: `p_<I>`, `q_<C>`.
    pub state_variables: Vec<String>,
    /// Number of inertias with integral causality (equal to `dof`; kept for compatibility).
    pub integral_inertias: usize,
    /// Storages with differential causality.
    pub differential: Vec<DifferentialStorage>,
    /// Over-determined junctions.
    pub conflicts: Vec<Conflict>,
    /// Groups of resistors on algebraic loops.
    pub algebraic_loops: Vec<Vec<String>>,
    /// Causality of every storage.
    pub storages: Vec<StorageInfo>,
    /// Causality of every bond.
    pub bond_causality: Vec<BondCausality>,
    /// Number of flow constraint rows of the junction structure (joint rows, pins, sums).
    pub constraint_rows: usize,
    /// Rank of the constraint rows on the inertia flows with generic moduli (the structural
    /// count: what the graph's shape alone allows).
    pub generic_rank: usize,
    /// Rank at the state of the assignment (a mechanism's initial configuration): lower than
    /// `generic_rank` on a geometrically special mechanism (Bricard: 29 of 30).
    pub numeric_rank: usize,
    /// Constraint junctions whose rows are redundant (a combination of the others), named by
    /// joint and direction; empty when every constraint is independent.
    pub redundant: Vec<RedundantJunction>,
}

/// A deterministic generic value for a variable (`0.3 … 1.3`, from a hash of its name), used
/// for the generic rank and for names a valuation does not know.
pub fn generic_value(name: &str) -> f64 {
    // FNV-1a, then mixed
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    // splitmix64 finaliser: names differing in their last letter get unrelated values
    h ^= h >> 30;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 31;
    0.3 + (h >> 11) as f64 / (1u64 << 53) as f64
}

/// The graph's own initial values: `p_<I>`, `q_<C>` from `initial` (0 when absent; an
/// inertia with a named flow starts at `I·f₀`), a displacement `x_…` from its annotation (0
/// when it has none); anything else (signals) is unknown.
fn initial_value(graph: &BondGraph, name: &str) -> Option<f64> {
    if let Some(rest) = name.strip_prefix("x_") {
        // an annotated displacement state starts from its initial value
        let annotated = graph
            .displacements
            .iter()
            .find(|d| graph.element(d.element).name == rest);
        return Some(annotated.map_or(0.0, |d| d.initial));
    }
    if let Some(rest) = name.strip_prefix("p_") {
        if let Some(f) = graph
            .flows
            .iter()
            .find(|f| graph.element(f.element).name == rest)
        {
            if let Some(Parameter::Const(m)) = graph.element(f.element).parameter {
                return Some(m * f.initial);
            }
        }
    }
    for prefix in ["p_", "q_"] {
        if let Some(rest) = name.strip_prefix(prefix) {
            if let Some(e) = graph.element_by_name(rest) {
                return Some(graph.element(e).initial.unwrap_or(0.0));
            }
        }
    }
    None
}

/// Assigns causality to a valid graph (validation errors are returned otherwise), with the
/// **generic** rank of the constraint rows (the structural count) and, among the choices it
/// leaves, the inertias best conditioned at the graph's initial values (see the module docs).
pub fn assign_causality(graph: &BondGraph) -> Result<Causality, ValidationErrors> {
    let state = |n: &str| initial_value(graph, n).or_else(|| Some(generic_value(n)));
    assign(graph, 0.0, &state, false)
}

/// Assigns causality with the rank of the constraint rows **at a state**: `values` gives the
/// variables the moduli reference (`x_<body>.omega` angles, rotation-entry signals, …) at time
/// `t`; names it does not know take the graph's initial values, then generic values. A
/// mechanism's scene graph uses its initial configuration, so the DOF is the true one there
/// and the redundant junctions are named.
pub fn assign_causality_at(
    graph: &BondGraph,
    t: f64,
    values: Valuation,
) -> Result<Causality, ValidationErrors> {
    let state = |n: &str| {
        values(n)
            .or_else(|| initial_value(graph, n))
            .or_else(|| Some(generic_value(n)))
    };
    assign(graph, t, &state, true)
}

/// The storages that [`assign_causality_at`] puts in differential causality (its report's
/// `differential`, as element ids), on a graph already known to be valid (a mechanism's graph
/// that was assigned once): the validation (whose messages cost more than the assignment
/// itself), the generic rank (only reported) and the report's names are skipped. What a
/// formulation's re-choice at run time calls.
pub fn reassign_differential_at(graph: &BondGraph, t: f64, values: Valuation) -> Vec<ElementId> {
    let state = |n: &str| {
        values(n)
            .or_else(|| initial_value(graph, n))
            .or_else(|| Some(generic_value(n)))
    };
    assign_ranked(graph, t, &state, true, false)
        .storage
        .iter()
        .filter(|(_, c)| *c == StorageCausality::Differential)
        .map(|&(e, _)| e)
        .collect()
}

fn assign(
    graph: &BondGraph,
    t: f64,
    values: Valuation,
    at_state: bool,
) -> Result<Causality, ValidationErrors> {
    validate(graph)?;
    Ok(assign_valid(graph, t, values, at_state))
}

fn assign_valid(graph: &BondGraph, t: f64, values: Valuation, at_state: bool) -> Causality {
    assign_ranked(graph, t, values, at_state, true)
}

/// [`assign_valid`]; without `generic_rank` (at the state only), the generic rank is not
/// computed and `constraints.generic_rank` holds the numeric rank.
fn assign_ranked(
    graph: &BondGraph,
    t: f64,
    values: Valuation,
    at_state: bool,
    generic_rank: bool,
) -> Causality {
    let deferred = joint_rows(graph);
    let preferred = preferred_differential(graph);
    let at = constraint_rank(graph, t, values, &preferred, &deferred);
    let generic_values = |n: &str| Some(generic_value(n));
    let mut generic = if generic_rank || !at_state {
        constraint_rank(graph, t, &generic_values, &preferred, &deferred)
    } else {
        at.clone()
    };
    if !at_state && generic.rank > at.rank {
        // singular at the state: keep its well-conditioned pivots, complete them generically
        let first: Vec<ElementId> = at.pivots.iter().map(|p| p.1).collect();
        generic = constraint_rank(graph, t, &generic_values, &first, &deferred);
    }
    // at full generic rank the state's own pivots are the choice (best conditioned there)
    let generic_choice = if generic.rank == at.rank {
        &at
    } else {
        &generic
    };
    let chosen: &ConstraintRank = if at_state { &at } else { generic_choice };
    let differential: Vec<ElementId> = chosen.pivots.iter().map(|p| p.1).collect();
    let constraints = ConstraintSummary {
        rows: at.rows,
        generic_rank: generic.rank,
        numeric_rank: at.rank,
        rank: chosen.rank,
        redundant: chosen.redundant.clone(),
        pivot_rows: chosen.pivots.iter().map(|&(r, i)| (i, r)).collect(),
    };
    // a gyrator first has both strokes away (efforts from flows); one left outside its rule is
    // given the other gyrator causality (both strokes at it) and the matching is solved again
    let mut gy_in = vec![false; graph.elements.len()];
    let mut sources;
    loop {
        sources = orient(
            graph,
            &differential,
            &chosen.redundant,
            &at.zero_moduli,
            &gy_in,
        );
        let mut changed = false;
        for e in graph.element_ids() {
            if graph.element(e).kind.is_gyrator() && !gy_in[e.0] {
                let n = graph
                    .bonds
                    .iter()
                    .enumerate()
                    .filter(|(i, b)| (b.from == e || b.to == e) && sources[*i] == e);
                if n.count() != 2 {
                    gy_in[e.0] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    finish(graph, sources, constraints)
}

/// The inertias the graph prefers in differential causality ([`BondGraph::prefer_differential`]),
/// in canonical (name) order: the pivoting takes each first where its column still has an
/// entry in an open row, so the choice does not depend on the order they are listed in.
fn preferred_differential(graph: &BondGraph) -> Vec<ElementId> {
    let mut names: Vec<&str> = graph
        .prefer_differential
        .iter()
        .map(String::as_str)
        .collect();
    names.sort_unstable();
    names.dedup();
    names
        .into_iter()
        .filter_map(|n| graph.element_ids().find(|&e| graph.element(e).name == n))
        .filter(|&e| graph.element(e).kind == ElementKind::I)
        .collect()
}

/// The elements whose rows are joint constraints: the graph's annotated constraint junctions,
/// or, in a graph without annotations, every Sf and every 1-junction of two bonds with no
/// storage on it (a junction that only equates two flows, seed Fig. 16).
fn joint_rows(graph: &BondGraph) -> Vec<bool> {
    let mut d = vec![false; graph.elements.len()];
    if !graph.constraint_junctions.is_empty() {
        for c in &graph.constraint_junctions {
            d[c.element.0] = true;
        }
        return d;
    }
    let adj = adjacency(graph);
    for e in graph.element_ids() {
        d[e.0] = match graph.element(e).kind {
            ElementKind::Sf => true,
            ElementKind::One => {
                adj[e.0].len() == 2
                    && adj[e.0]
                        .iter()
                        .all(|&b| !graph.element(graph.other_end(b, e)).kind.is_storage())
            }
            _ => false,
        };
    }
    d
}

/// The elements whose rows are joint constraints (see `joint_rows`): the graph's annotated
/// constraint junctions, or, in a graph without annotations, every Sf and every 1-junction of
/// two bonds with no storage on it — what the decoupled twin opens
/// ([`crate::bond::decouple::decouple`]).
pub fn joint_row_elements(graph: &BondGraph) -> Vec<ElementId> {
    joint_rows(graph)
        .iter()
        .enumerate()
        .filter(|(_, &d)| d)
        .map(|(i, _)| ElementId(i))
        .collect()
}

/// Adjacency in canonical bond order.
fn adjacency(graph: &BondGraph) -> Vec<Vec<BondId>> {
    let mut adj = vec![Vec::new(); graph.elements.len()];
    for b in canonical_bonds(graph) {
        let bd = graph.bond(b);
        adj[bd.from.0].push(b);
        adj[bd.to.0].push(b);
    }
    adj
}

/// The structural rule `[lo, hi]` on how many of its bonds an element is the effort source of
/// (storages: both causalities allowed).
fn rule(kind: ElementKind, degree: i64) -> (i64, i64) {
    match kind {
        ElementKind::Se => (1, 1),
        ElementKind::Sf => (0, 0),
        ElementKind::I | ElementKind::C | ElementKind::R => (0, 1),
        ElementKind::Zero => ((degree - 1).max(0), (degree - 1).max(0)),
        ElementKind::One => (degree.min(1), degree.min(1)),
        ElementKind::TF | ElementKind::MTF => (1, 1),
        ElementKind::GY | ElementKind::MGY => (2, 2),
    }
}

/// The effort source of every bond (see [`super::orient`]).
fn orient(
    graph: &BondGraph,
    differential: &[ElementId],
    redundant: &[ElementId],
    zero_moduli: &[ElementId],
    gy_in: &[bool],
) -> Vec<ElementId> {
    let adj = adjacency(graph);
    let bonds = canonical_bonds(graph);
    let elements = canonical_elements(graph);
    let nb = bonds.len();
    let mut is_zero = vec![false; graph.elements.len()];
    for &z in zero_moduli {
        is_zero[z.0] = true;
    }
    let mut is_differential = vec![false; graph.elements.len()];
    for &d in differential {
        is_differential[d.0] = true;
    }
    let mut node_of = vec![0usize; graph.elements.len()];
    for (k, e) in elements.iter().enumerate() {
        node_of[e.0] = 2 + nb + k;
    }
    let mut net = Network::new(2 + nb + elements.len());
    // bond → element arcs, the ones that would divide by a vanishing modulus held back
    let mut arcs: Vec<(BondId, ElementId, usize)> = Vec::new();
    let mut held: Vec<(usize, usize, usize)> = Vec::new();
    for (k, &b) in bonds.iter().enumerate() {
        net.arc(0, 2 + k, 1);
        let bd = graph.bond(b);
        for e in [bd.from, bd.to] {
            // a TF is the effort source of its outward bond when it computes f₁ = f₂/m
            let divides = is_zero[e.0] && bd.from == e;
            if divides {
                held.push((arcs.len(), 2 + k, node_of[e.0]));
                arcs.push((b, e, usize::MAX));
            } else {
                let i = net.arc(2 + k, node_of[e.0], 1);
                arcs.push((b, e, i));
            }
        }
    }
    let mut sink = vec![0usize; graph.elements.len()];
    let mut cap = vec![0i64; graph.elements.len()];
    for &e in &elements {
        sink[e.0] = net.arc(node_of[e.0], 1, 0);
    }
    let kind = |e: ElementId| graph.element(e).kind;
    let degree = |e: ElementId| adj[e.0].len() as i64;
    let mut relax = vec![0i64; graph.elements.len()];
    for &r in redundant {
        // an Sf row over-determines the junction it feeds
        let at = if kind(r) == ElementKind::Sf {
            adj[r.0]
                .first()
                .map(|&b| graph.other_end(b, r))
                .unwrap_or(r)
        } else {
            r
        };
        relax[at.0] += 1;
    }
    // the wanted count of a storage: I integral 0 / differential 1; C integral 1
    let wanted = |e: ElementId| -> i64 {
        match kind(e) {
            ElementKind::I => i64::from(is_differential[e.0]),
            _ => 1,
        }
    };
    let set = |net: &mut Network, cap: &mut Vec<i64>, e: ElementId, c: i64| {
        if c > cap[e.0] {
            net.raise(sink[e.0], c - cap[e.0]);
            cap[e.0] = c;
        }
    };
    let storage = |e: ElementId| kind(e).is_storage();
    // 1. structural lower bounds of junctions, two-ports and sources
    for &e in &elements {
        if !storage(e) && kind(e) != ElementKind::R {
            let lo = if gy_in[e.0] {
                0
            } else {
                rule(kind(e), degree(e)).0
            };
            set(&mut net, &mut cap, e, lo);
        }
    }
    net.augment();
    // 2. the storages' wanted causality
    for &e in &elements {
        if storage(e) {
            set(&mut net, &mut cap, e, wanted(e));
        }
    }
    net.augment();
    // 3. upper bounds (redundant junctions may be over-determined)
    for &e in &elements {
        let c = if storage(e) {
            wanted(e)
        } else {
            let hi = if gy_in[e.0] {
                0
            } else {
                rule(kind(e), degree(e)).1
            };
            hi + relax[e.0]
        };
        set(&mut net, &mut cap, e, c);
    }
    net.augment();
    // 4. storages may change causality
    for &e in &elements {
        if storage(e) {
            set(&mut net, &mut cap, e, 1);
        }
    }
    net.augment();
    // 5. a transformer may divide by a vanishing modulus
    for (k, bond_node, el_node) in held {
        arcs[k].2 = net.arc(bond_node, el_node, 1);
    }
    net.augment();
    // 6. anything left: the elements outside their rule are the conflicts
    for &e in &elements {
        set(&mut net, &mut cap, e, degree(e));
    }
    net.augment();
    let mut source = vec![ElementId(usize::MAX); graph.bonds.len()];
    for &(b, e, i) in &arcs {
        if i != usize::MAX && net.flow(i) > 0 {
            source[b.0] = e;
        }
    }
    source
}

/// Builds the assignment from the effort source of every bond.
fn finish(graph: &BondGraph, source: Vec<ElementId>, constraints: ConstraintSummary) -> Causality {
    let adj = adjacency(graph);
    let kind = |e: ElementId| graph.element(e).kind;
    let bonds: Vec<BondAssignment> = graph
        .bonds
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let src = source[i];
            let receiver = if src == b.from { b.to } else { b.from };
            let stage = match (kind(b.from), kind(b.to)) {
                (k, _) | (_, k) if matches!(k, ElementKind::Se | ElementKind::Sf) => Stage::Source,
                (k, _) | (_, k) if k.is_storage() => Stage::Storage,
                (ElementKind::R, _) | (_, ElementKind::R) => Stage::Resistor,
                _ => Stage::Propagated,
            };
            BondAssignment {
                effort_receiver: receiver,
                effort_source: src,
                origin: src,
                stage,
                via: None,
                causes: vec![],
            }
        })
        .collect();
    let count = |e: ElementId| -> i64 {
        adj[e.0]
            .iter()
            .filter(|b| bonds[b.0].effort_source == e)
            .count() as i64
    };
    // conflicts, in name order
    let mut conflicts = Vec::new();
    for e in canonical_elements(graph) {
        let k = kind(e);
        if k.is_storage() || k == ElementKind::R {
            continue;
        }
        let (lo, hi) = rule(k, adj[e.0].len() as i64);
        let n = count(e);
        if (lo..=hi).contains(&n) || (k.is_gyrator() && n == 0) {
            continue;
        }
        let name = &graph.element(e).name;
        let neighbours = |bs: &[BondId]| -> Vec<String> {
            let mut v: Vec<String> = bs
                .iter()
                .map(|&b| graph.element(graph.other_end(b, e)).name.clone())
                .collect();
            v.sort();
            v.dedup();
            v
        };
        let (elements, description) = match k {
            ElementKind::Zero | ElementKind::One => {
                let zero = k == ElementKind::Zero;
                let det: Vec<BondId> = adj[e.0]
                    .iter()
                    .copied()
                    .filter(|b| (bonds[b.0].effort_receiver == e) == zero)
                    .collect();
                let (what, var) = if zero {
                    ("0-junction", "effort")
                } else {
                    ("1-junction", "flow")
                };
                if det.is_empty() {
                    (
                        neighbours(&adj[e.0]),
                        format!("{what} '{name}': no bond imposes the common {var}, every bond imposes the other variable"),
                    )
                } else {
                    let names: Vec<String> =
                        det.iter().map(|&b| graph.bond(b).name.clone()).collect();
                    (
                        neighbours(&det),
                        format!(
                            "{what} '{name}' has its common {var} imposed by {} bonds ({})",
                            det.len(),
                            names.join(", ")
                        ),
                    )
                }
            }
            k if k.is_two_port() => {
                let rule = if k.is_gyrator() {
                    "needs both causal strokes at it or both away"
                } else {
                    "needs one causal stroke at it and one away"
                };
                (
                    neighbours(&adj[e.0]),
                    format!("{} '{name}' {rule}", k.as_str()),
                )
            }
            _ => (
                neighbours(&adj[e.0]),
                format!(
                    "source '{name}' is bonded directly to another source with the same causality"
                ),
            ),
        };
        conflicts.push(Conflict {
            junction: name.clone(),
            elements,
            description,
        });
    }
    let mut storage = Vec::new();
    for wanted in [ElementKind::I, ElementKind::C] {
        for e in graph.element_ids() {
            if kind(e) != wanted {
                continue;
            }
            let Some(&b) = adj[e.0].first() else { continue };
            let receives_effort = bonds[b.0].effort_receiver == e;
            let integral = (wanted == ElementKind::I) == receives_effort;
            storage.push((
                e,
                if integral {
                    StorageCausality::Integral
                } else {
                    StorageCausality::Differential
                },
            ));
        }
    }
    let mut c = Causality {
        bonds,
        storage,
        conflicts,
        algebraic_loops: Vec::new(),
        constraints,
    };
    c.algebraic_loops = algebraic_loops(graph, &c, &adj);
    c
}

/// Resistors on zero-order causal loops: the strongly connected components (Tarjan,
/// iterative) of the graph "bond variable ← bond variables its computing element reads",
/// grouped by component; each group sorted by name, groups by their first name.
fn algebraic_loops(graph: &BondGraph, c: &Causality, adj: &[Vec<BondId>]) -> Vec<Vec<ElementId>> {
    let nb = graph.bonds.len();
    let kind = |e: ElementId| graph.element(e).kind;
    // node 2b: effort of bond b, 2b+1: its flow
    let deps = |v: usize| -> Vec<usize> {
        let b = BondId(v / 2);
        let effort = v.is_multiple_of(2);
        let a = &c.bonds[b.0];
        let x = if effort {
            a.effort_source
        } else {
            a.effort_receiver
        };
        let others = || adj[x.0].iter().copied().filter(move |&o| o != b);
        let e = |o: BondId| 2 * o.0;
        let f = |o: BondId| 2 * o.0 + 1;
        match (kind(x), effort) {
            (ElementKind::R, true) => vec![f(b)],
            (ElementKind::R, false) => vec![e(b)],
            (ElementKind::One, true) | (ElementKind::Zero, false) => {
                others().map(|o| if effort { e(o) } else { f(o) }).collect()
            }
            (ElementKind::Zero, true) => others()
                .find(|o| c.bonds[o.0].effort_receiver == x)
                .map(e)
                .into_iter()
                .collect(),
            (ElementKind::One, false) => others()
                .find(|o| c.bonds[o.0].effort_source == x)
                .map(f)
                .into_iter()
                .collect(),
            (k, true) if k.is_transformer() => others().map(e).collect(),
            (k, false) if k.is_transformer() => others().map(f).collect(),
            (k, true) if k.is_gyrator() => others().map(f).collect(),
            (k, false) if k.is_gyrator() => others().map(e).collect(),
            _ => vec![],
        }
    };
    let n = 2 * nb;
    let succ: Vec<Vec<usize>> = (0..n).map(deps).collect();
    let mut index = vec![usize::MAX; n];
    let mut low = vec![0usize; n];
    let mut on = vec![false; n];
    let mut stack = Vec::new();
    let mut next = 0;
    let mut groups: Vec<Vec<ElementId>> = Vec::new();
    for root in 0..n {
        if index[root] != usize::MAX {
            continue;
        }
        let mut call: Vec<(usize, usize)> = vec![(root, 0)];
        index[root] = next;
        low[root] = next;
        next += 1;
        stack.push(root);
        on[root] = true;
        while let Some(&mut (v, ref mut k)) = call.last_mut() {
            if *k < succ[v].len() {
                let w = succ[v][*k];
                *k += 1;
                if index[w] == usize::MAX {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on[w] = true;
                    call.push((w, 0));
                } else if on[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            call.pop();
            if let Some(&(u, _)) = call.last() {
                low[u] = low[u].min(low[v]);
            }
            if low[v] == index[v] {
                let mut comp = Vec::new();
                loop {
                    let w = stack.pop().expect("Tarjan stack");
                    on[w] = false;
                    comp.push(w);
                    if w == v {
                        break;
                    }
                }
                let cyclic = comp.len() > 1 || succ[v].contains(&v);
                if cyclic {
                    let mut rs: Vec<ElementId> = comp
                        .iter()
                        .flat_map(|&w| {
                            let bd = graph.bond(BondId(w / 2));
                            [bd.from, bd.to]
                        })
                        .filter(|&e| kind(e) == ElementKind::R)
                        .collect();
                    rs.sort_by(|a, b| graph.element(*a).name.cmp(&graph.element(*b).name));
                    rs.dedup();
                    if !rs.is_empty() {
                        groups.push(rs);
                    }
                }
            }
        }
    }
    groups.sort_by(|a, b| graph.element(a[0]).name.cmp(&graph.element(b[0]).name));
    groups
}

impl Causality {
    /// The bond of a one-port (graphs passed validation, so it exists).
    fn port_bond(graph: &BondGraph, e: ElementId) -> BondId {
        graph.bonds_of(e)[0]
    }

    /// Where the constraint on a differential storage closes, read from the final causal
    /// graph (so it does not depend on the order in which SCAP or its look-ahead fixed the
    /// bonds): follow the variable the storage receives (flow for I, effort for C) back to the
    /// element computing it, as the equations do. A junction passing on its common variable
    /// from the bond that imposes it, a TF/MTF (same variable) and a GY/MGY (flow ↔ effort) are
    /// passed through; the first junction that computes the variable as a balance of two or
    /// more other bonds (a 0-junction's flow, a 1-junction's effort) is where the constraint
    /// closes, and those bonds are returned. When the chain ends at a state or a source instead,
    /// the last junction passed and the bond towards that element are returned.
    fn closing_junction(
        &self,
        graph: &BondGraph,
        storage: ElementId,
        b0: BondId,
    ) -> (ElementId, Vec<BondId>, Vec<ElementId>) {
        let mut flow = graph.element(storage).kind == ElementKind::I;
        let (mut b, mut x) = (b0, graph.other_end(b0, storage));
        let mut path = Vec::new();
        let mut last: Option<(ElementId, BondId)> = None;
        for _ in 0..=self.bonds.len() {
            let kind = graph.element(x).kind;
            let others: Vec<BondId> = graph.bonds_of(x).into_iter().filter(|&o| o != b).collect();
            let next = match kind {
                ElementKind::Zero | ElementKind::One => {
                    path.push(x);
                    let zero = kind == ElementKind::Zero;
                    if zero == flow {
                        // the variable is a balance of the other bonds
                        if others.len() >= 2 {
                            return (x, others, path);
                        }
                        others.first().copied()
                    } else {
                        // the common variable, imposed by one bond
                        others.iter().copied().find(|o| {
                            let r = self.bonds[o.0].effort_receiver;
                            if zero {
                                r == x
                            } else {
                                r != x
                            }
                        })
                    }
                }
                k if k.is_two_port() => {
                    path.push(x);
                    if k.is_gyrator() {
                        flow = !flow;
                    }
                    others.first().copied()
                }
                _ => None,
            };
            let Some(n) = next else {
                break;
            };
            if kind.is_junction() {
                last = Some((x, n));
            }
            b = n;
            x = graph.other_end(n, x);
        }
        match last {
            Some((j, via)) => {
                while path.last().is_some_and(|&p| p != j) {
                    path.pop();
                }
                (j, vec![via], path)
            }
            None => (x, vec![b], path),
        }
    }

    /// Causality of a storage element, if it is one.
    pub fn storage_causality(&self, e: ElementId) -> Option<StorageCausality> {
        self.storage
            .iter()
            .find(|(id, _)| *id == e)
            .map(|(_, c)| *c)
    }

    /// Is this storage element differential?
    pub fn is_differential(&self, e: ElementId) -> bool {
        self.storage_causality(e) == Some(StorageCausality::Differential)
    }

    /// The report with element names.
    pub fn report(&self, graph: &BondGraph) -> CausalityReport {
        let name = |e: ElementId| graph.element(e).name.clone();
        let mut states = Vec::new();
        let mut state_variables = Vec::new();
        let mut differential = Vec::new();
        let mut storages = Vec::new();
        let mut integral_inertias = 0;
        for &(e, c) in &self.storage {
            let el = graph.element(e);
            storages.push(StorageInfo {
                element: el.name.clone(),
                kind: el.kind.as_str().into(),
                causality: c,
            });
            let b = Self::port_bond(graph, e);
            match c {
                StorageCausality::Integral => {
                    states.push(el.name.clone());
                    let prefix = if el.kind == ElementKind::I {
                        "p_"
                    } else {
                        "q_"
                    };
                    state_variables.push(format!("{prefix}{}", el.name));
                    if el.kind == ElementKind::I {
                        integral_inertias += 1;
                    }
                }
                StorageCausality::Differential => {
                    let (at, causes, path) = self.closing_junction(graph, e, b);
                    differential.push(DifferentialStorage {
                        element: el.name.clone(),
                        bond: graph.bond(b).name.clone(),
                        forced_by_junction: name(at),
                        via_bonds: causes.iter().map(|c| graph.bond(*c).name.clone()).collect(),
                        via_elements: causes
                            .iter()
                            .map(|&c| name(graph.other_end(c, at)))
                            .collect(),
                        path: path.into_iter().map(name).collect(),
                        origin: self
                            .constraints
                            .pivot_rows
                            .iter()
                            .find(|p| p.0 == e)
                            .map(|p| name(p.1))
                            .unwrap_or_else(|| name(at)),
                    });
                }
            }
        }
        let bond_causality = self
            .bonds
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let b = graph.bond(BondId(i));
                BondCausality {
                    bond: b.name.clone(),
                    from: name(b.from),
                    to: name(b.to),
                    effort_by: name(a.effort_source),
                    stroke_at: name(a.effort_receiver),
                    stage: a.stage,
                }
            })
            .collect();
        CausalityReport {
            dof: integral_inertias,
            state_count: states.len(),
            states,
            state_variables,
            integral_inertias,
            differential,
            conflicts: self.conflicts.clone(),
            algebraic_loops: self
                .algebraic_loops
                .iter()
                .map(|l| l.iter().map(|&e| name(e)).collect())
                .collect(),
            storages,
            bond_causality,
            constraint_rows: self.constraints.rows,
            generic_rank: self.constraints.generic_rank,
            numeric_rank: self.constraints.numeric_rank,
            redundant: self
                .constraints
                .redundant
                .iter()
                .map(|&r| {
                    let junction = name(r);
                    if let Some(c) = graph.constraint_junction(r) {
                        return RedundantJunction {
                            junction,
                            joint: c.joint.clone(),
                            direction: c.direction.clone(),
                        };
                    }
                    let (joint, direction) = match junction.rsplit_once('.') {
                        Some((j, d)) => (j.to_string(), d.to_string()),
                        None => (junction.clone(), String::new()),
                    };
                    RedundantJunction {
                        junction,
                        joint,
                        direction,
                    }
                })
                .collect(),
        }
    }
}
