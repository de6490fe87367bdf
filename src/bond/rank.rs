//! Numeric rank of a bond graph's kinematic (flow) constraints at a state.
//!
//! The junction structure's homogeneous flow equations, one row each:
//! - 1-junction with bonds `b₀ … b_d` (b₀ the first by canonical key): `f_bk − f_b0 = 0`;
//! - 0-junction: `Σ s_b f_b = 0` (`s_b = +1` when the half arrow points into the junction);
//! - TF/MTF (port 1 inward, port 2 outward, modulus `m` at the state): `f₂ − m f₁ = 0`;
//! - Sf: `f = 0` (its value is a known input; only the homogeneous part constrains).
//!
//! GY/MGY, R, C, Se and I impose no flow relation. With `A = [A_I A_O]` (columns the flows of
//! the inertias' bonds and of every other bond), the admissible inertia flows are the projection
//! of `ker A` on the `I` columns, of dimension `n_I − (rank A − rank A_O)`: the degrees of
//! freedom. bondmech computes it by sparse Gaussian elimination: first every non-inertia column
//! is eliminated (minimum-degree column order, largest pivot in the column, entries below the
//! tolerance treated as zero), which leaves the constraint rows `G v_I = 0` expressed on the
//! inertia flows alone — each row still named after the junction (or Sf, or TF) it started
//! from; then `G` is factorised with complete pivoting (largest remaining entry first), which
//! reveals its rank `r`. The pivot columns are the dependent inertias (the best-conditioned
//! choice at that state: each pivot is the largest available), the rows left without a pivot
//! are the redundant constraints. For a mechanism `G` is the joint Jacobian `G_v` written on the
//! bond graph's inertia flows. Work and fill stay proportional to the graph for chains and
//! trees of bodies (every elimination touches a few neighbouring rows).

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};

use super::model::{BondGraph, BondId, ElementId, ElementKind, Parameter};
use crate::expr::ExprGraph;

/// Entries below `TOLERANCE × (largest entry of the matrix)` count as zero: the causality's
/// numeric rank tolerance, defined with the other thresholds that decide a partition
/// ([`crate::thresholds::CAUSALITY_RANK_TOLERANCE`]).
pub use crate::thresholds::CAUSALITY_RANK_TOLERANCE as TOLERANCE;

/// Values of the variables a modulus may reference (`t`, states, displacements, signals).
pub type Valuation<'a> = &'a dyn Fn(&str) -> Option<f64>;

/// One flow-constraint row and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct RowOrigin {
    /// The junction, TF/MTF or Sf that wrote the row.
    pub element: ElementId,
}

/// The result of [`constraint_rank`].
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintRank {
    /// Number of flow rows of the junction structure.
    pub rows: usize,
    /// Rank of the constraint rows on the inertia flows (`rank A − rank A_O`).
    pub rank: usize,
    /// Pivots in the order they were taken: (row origin, inertia element). The inertias are
    /// the dependent ones (differential causality).
    pub pivots: Vec<(ElementId, ElementId)>,
    /// Origins of the constraint rows left without a pivot (redundant at this state).
    pub redundant: Vec<ElementId>,
    /// Elements whose modulus vanishes at this state (TF/MTF with `|m|` below the tolerance).
    pub zero_moduli: Vec<ElementId>,
}

/// The value of a two-port modulus at a state (`None` when it cannot be evaluated).
pub fn modulus_value(graph: &BondGraph, e: ElementId, t: f64, values: Valuation) -> Option<f64> {
    match graph.element(e).parameter.as_ref()? {
        Parameter::Const(c) => Some(*c),
        Parameter::Table { t: ts, v } => {
            let mut eg = ExprGraph::new();
            let time = eg.var(0);
            let x = eg.table(ts, v, time);
            Some(eg.eval(x, &[t]))
        }
        Parameter::Expr(s) => PARSED_MODULI.with(|cache| {
            let mut cache = cache.borrow_mut();
            if cache.len() >= PARSED_MODULI_KEPT && !cache.contains_key(s) {
                cache.clear();
            }
            let parsed = cache
                .entry(s.clone())
                .or_insert_with(|| ParsedModulus::parse(s))
                .as_ref()?;
            let mut vars = Vec::with_capacity(1 + parsed.names.len());
            vars.push(t);
            for n in &parsed.names {
                vars.push(values(n)?);
            }
            Some(parsed.graph.eval(parsed.root, &vars))
        }),
    }
}

/// A modulus expression parsed once, its variables (other than `t`) as the graph's variables
/// `1, 2, …` in the order of `names` (`t` is variable 0).
struct ParsedModulus {
    graph: ExprGraph,
    root: crate::expr::Expr,
    names: Vec<String>,
}

impl ParsedModulus {
    fn parse(s: &str) -> Option<ParsedModulus> {
        let mut graph = ExprGraph::new();
        let time = graph.var(0);
        let mut nodes: BTreeMap<String, crate::expr::Expr> = BTreeMap::new();
        let mut names = Vec::new();
        for n in crate::bond::identifiers::variables(s).ok()? {
            if n != "t" && !nodes.contains_key(&n) {
                nodes.insert(n.clone(), graph.var((1 + names.len()) as u32));
                names.push(n);
            }
        }
        let root = graph
            .parse(s, &mut |n| {
                if n == "t" {
                    Some(time)
                } else {
                    nodes.get(n).copied()
                }
            })
            .ok()?;
        Some(ParsedModulus { graph, root, names })
    }
}

/// Modulus expressions parsed so far on this thread, by their text: the causality's ranked
/// assignment evaluates every modulated transformer's modulus at each configuration it is
/// asked about (at every restart of the index-1 DAE, at every examination of its partition),
/// and lexing and parsing them again each time was 8 % of Bricard's run (perf).
const PARSED_MODULI_KEPT: usize = 4096;

thread_local! {
    static PARSED_MODULI: std::cell::RefCell<std::collections::HashMap<String, Option<ParsedModulus>>> =
        std::cell::RefCell::new(std::collections::HashMap::new());
}

/// Canonical order of bonds: by (tail name, head name, bond name), independent of file order.
pub fn canonical_bonds(graph: &BondGraph) -> Vec<BondId> {
    let mut ids: Vec<BondId> = (0..graph.bonds.len()).map(BondId).collect();
    ids.sort_by(|&a, &b| {
        let (x, y) = (graph.bond(a), graph.bond(b));
        (
            &graph.element(x.from).name,
            &graph.element(x.to).name,
            &x.name,
        )
            .cmp(&(
                &graph.element(y.from).name,
                &graph.element(y.to).name,
                &y.name,
            ))
    });
    ids
}

/// Canonical order of elements: by name.
pub fn canonical_elements(graph: &BondGraph) -> Vec<ElementId> {
    let mut ids: Vec<ElementId> = graph.element_ids().collect();
    ids.sort_by(|&a, &b| graph.element(a).name.cmp(&graph.element(b).name));
    ids
}

type Row = BTreeMap<usize, f64>;

/// Rank of the flow constraints on the inertia flows at a state (see the module docs).
///
/// `first` lists inertias to pivot on first, in that order, when their columns allow it (used to
/// keep a choice made at another state). Columns and rows are numbered in the canonical orders
/// ([`canonical_bonds`], [`canonical_elements`]), so the result does not depend on the order of
/// elements or bonds in the file.
pub fn constraint_rank(
    graph: &BondGraph,
    t: f64,
    values: Valuation,
    first: &[ElementId],
    deferred: &[bool],
) -> ConstraintRank {
    let bonds = canonical_bonds(graph);
    let mut col_of = vec![0usize; graph.bonds.len()];
    for (c, b) in bonds.iter().enumerate() {
        col_of[b.0] = c;
    }
    let mut adj: Vec<Vec<BondId>> = vec![Vec::new(); graph.elements.len()];
    for &b in &bonds {
        let bd = graph.bond(b);
        adj[bd.from.0].push(b);
        adj[bd.to.0].push(b);
    }
    // inertia of each column (None: not an inertia bond)
    let mut inertia_of: Vec<Option<ElementId>> = vec![None; bonds.len()];
    for e in graph.element_ids() {
        if graph.element(e).kind == ElementKind::I {
            if let Some(&b) = adj[e.0].first() {
                inertia_of[col_of[b.0]] = Some(e);
            }
        }
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut origin: Vec<ElementId> = Vec::new();
    let mut zero_moduli = Vec::new();
    let sign = |b: BondId, e: ElementId| if graph.bond(b).to == e { 1.0 } else { -1.0 };
    for e in canonical_elements(graph) {
        let bs = &adj[e.0];
        match graph.element(e).kind {
            ElementKind::One => {
                for &b in bs.iter().skip(1) {
                    let mut r = Row::new();
                    r.insert(col_of[b.0], 1.0);
                    r.insert(col_of[bs[0].0], -1.0);
                    rows.push(r);
                    origin.push(e);
                }
            }
            ElementKind::Zero if !bs.is_empty() => {
                let mut r = Row::new();
                for &b in bs {
                    *r.entry(col_of[b.0]).or_insert(0.0) += sign(b, e);
                }
                rows.push(r);
                origin.push(e);
            }
            k if k.is_transformer() && bs.len() == 2 => {
                let (p1, p2) = if graph.bond(bs[0]).to == e {
                    (bs[0], bs[1])
                } else {
                    (bs[1], bs[0])
                };
                let m = modulus_value(graph, e, t, values).unwrap_or(f64::NAN);
                let m = if m.is_finite() { m } else { 1.0 };
                if m.abs() <= TOLERANCE {
                    zero_moduli.push(e);
                }
                let mut r = Row::new();
                r.insert(col_of[p2.0], 1.0);
                if m != 0.0 {
                    *r.entry(col_of[p1.0]).or_insert(0.0) -= m;
                }
                rows.push(r);
                origin.push(e);
            }
            ElementKind::Sf if !bs.is_empty() => {
                let mut r = Row::new();
                r.insert(col_of[bs[0].0], 1.0);
                rows.push(r);
                origin.push(e);
            }
            _ => {}
        }
    }
    let n_rows = rows.len();
    let scale = rows
        .iter()
        .flat_map(|r| r.values())
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(1.0);
    let tol = TOLERANCE * scale;
    let mut col_rows: Vec<std::collections::BTreeSet<usize>> =
        vec![Default::default(); bonds.len()];
    for (i, r) in rows.iter().enumerate() {
        for &c in r.keys() {
            col_rows[c].insert(i);
        }
    }
    let mut active = vec![true; n_rows];

    // row_i -= (a_ic / a_pc) row_p, keeping the column index up to date
    // (only active rows: the pivot rows are not updated, as in LU, so no fill accumulates)
    let eliminate = |rows: &mut Vec<Row>,
                     col_rows: &mut Vec<std::collections::BTreeSet<usize>>,
                     active: &[bool],
                     p: usize,
                     c: usize,
                     touched: &mut Vec<usize>| {
        let pivot_row = rows[p].clone();
        let a = pivot_row[&c];
        let others: Vec<usize> = col_rows[c]
            .iter()
            .copied()
            .filter(|&i| i != p && active[i])
            .collect();
        for i in others {
            let f = rows[i].get(&c).copied().unwrap_or(0.0) / a;
            for (&k, &v) in &pivot_row {
                let x = rows[i].entry(k).or_insert(0.0);
                *x -= f * v;
                if k == c || x.abs() <= tol * 1e-6 {
                    rows[i].remove(&k);
                    col_rows[k].remove(&i);
                } else {
                    col_rows[k].insert(i);
                }
                touched.push(k);
            }
        }
    };

    // phase 1: eliminate the non-inertia columns, minimum degree first
    let mut heap: BinaryHeap<Reverse<(usize, usize)>> = (0..bonds.len())
        .filter(|&c| inertia_of[c].is_none())
        .map(|c| Reverse((col_rows[c].len(), c)))
        .collect();
    let mut done = vec![false; bonds.len()];
    while let Some(Reverse((count, c))) = heap.pop() {
        if done[c] {
            continue;
        }
        let now = col_rows[c].iter().filter(|&&i| active[i]).count();
        if now != count {
            heap.push(Reverse((now, c)));
            continue;
        }
        done[c] = true;
        // threshold partial pivoting: among entries within 1/100 of the column's largest,
        // a row that is not a joint's constraint row first (the joint rows stay as the
        // constraints of phase 2, so a redundancy is named after a joint), then the largest
        let top = col_rows[c]
            .iter()
            .filter(|&&i| active[i])
            .fold(0.0f64, |m, &i| m.max(rows[i][&c].abs()));
        let best = col_rows[c]
            .iter()
            .copied()
            .filter(|&i| active[i] && rows[i][&c].abs() >= 0.01 * top)
            .map(|i| {
                (
                    !deferred[origin[i].0],
                    rows[i][&c].abs(),
                    Reverse(rows[i].len()),
                    Reverse(i),
                    i,
                )
            })
            .max_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        let Some((_, mag, _, _, p)) = best else {
            continue;
        };
        if mag <= tol {
            // numerically zero at this state: drop the entries
            for i in col_rows[c].clone() {
                rows[i].remove(&c);
            }
            col_rows[c].clear();
            continue;
        }
        active[p] = false;
        let mut touched = Vec::new();
        eliminate(&mut rows, &mut col_rows, &active, p, c, &mut touched);
        touched.sort_unstable();
        touched.dedup();
        for k in touched {
            if !done[k] && inertia_of[k].is_none() {
                let n = col_rows[k].iter().filter(|&&i| active[i]).count();
                heap.push(Reverse((n, k)));
            }
        }
    }
    // what is left of non-inertia columns is below the tolerance
    for (i, r) in rows.iter_mut().enumerate() {
        if active[i] {
            r.retain(|&k, v| inertia_of[k].is_some() && v.abs() > tol);
        }
    }
    for (c, set) in col_rows.iter_mut().enumerate() {
        set.retain(|&i| active[i] && rows[i].contains_key(&c));
    }

    // phase 2: pivoting on the constraint rows G (inertia columns), causal order first
    let mut pivots = Vec::new();
    let mut frozen = vec![false; bonds.len()];
    let mut pivot_on = |p: usize,
                        c: usize,
                        rows: &mut Vec<Row>,
                        col_rows: &mut Vec<std::collections::BTreeSet<usize>>,
                        active: &mut Vec<bool>,
                        frozen: &mut Vec<bool>| {
        active[p] = false;
        // the row's other inertias are read, not solved for, by this row: they stay integral
        for &k in rows[p].keys() {
            if k != c {
                frozen[k] = true;
            }
        }
        pivots.push((origin[p], inertia_of[c].expect("inertia column")));
        let mut touched = Vec::new();
        eliminate(rows, col_rows, active, p, c, &mut touched);
        for k in touched {
            col_rows[k].retain(|&i| active[i] && rows[i].contains_key(&k));
        }
        col_rows[c].clear();
    };
    for &e in first {
        let Some(&b) = adj[e.0].first() else { continue };
        let c = col_of[b.0];
        let best = col_rows[c]
            .iter()
            .copied()
            .filter(|&i| active[i])
            .map(|i| (rows[i].get(&c).copied().unwrap_or(0.0).abs(), Reverse(i), i))
            .max_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        if let Some((mag, _, p)) = best {
            if mag > tol {
                pivot_on(p, c, &mut rows, &mut col_rows, &mut active, &mut frozen);
            }
        }
    }
    loop {
        // (1) causal pivots: an inertia not read by an earlier pivot row, in a row with the
        // fewest such inertias (a row that names one inertia determines it), at least 1/10 of
        // the row's largest entry (never a vanishing modulus); a non-joint row before a joint
        // row (so joint rows are what is left over); then the largest entry; ties to the
        // later name.
        // (2) when no causal pivot is left, complete pivoting over every entry: the rows that
        // still carry an entry are independent, and solving them couples inertias (an
        // algebraic loop of the junction structure); what is left below the tolerance is
        // redundant.
        type Key = (Reverse<usize>, bool, f64, usize, Reverse<usize>);
        let mut causal: Option<(Key, usize, usize)> = None;
        let mut any: Option<(f64, usize, usize)> = None;
        for (i, r) in rows.iter().enumerate() {
            if !active[i] {
                continue;
            }
            let row_max = r.values().fold(0.0f64, |m, v| m.max(v.abs()));
            let free = r.keys().filter(|&&k| !frozen[k]).count();
            for (&c, &v) in r {
                let m = v.abs();
                if m <= tol {
                    continue;
                }
                if any.is_none_or(|(bm, bc, bi)| {
                    m > bm * (1.0 + 1e-12) || (m >= bm * (1.0 - 1e-12) && (c, i) > (bc, bi))
                }) {
                    any = Some((m, c, i));
                }
                if frozen[c] || m < 0.1 * row_max {
                    continue;
                }
                let key: Key = (Reverse(free), !deferred[origin[i].0], m, c, Reverse(i));
                let better = match &causal {
                    None => true,
                    Some((k, _, _)) => {
                        (key.0, key.1) > (k.0, k.1)
                            || ((key.0, key.1) == (k.0, k.1)
                                && (m > k.2 * (1.0 + 1e-12)
                                    || (m >= k.2 * (1.0 - 1e-12) && (c, Reverse(i)) > (k.3, k.4))))
                    }
                };
                if better {
                    causal = Some((key, c, i));
                }
            }
        }
        if let Some((_, c, p)) = causal {
            pivot_on(p, c, &mut rows, &mut col_rows, &mut active, &mut frozen);
        } else if let Some((_, c, p)) = any {
            pivot_on(p, c, &mut rows, &mut col_rows, &mut active, &mut frozen);
        } else {
            break;
        }
    }
    let redundant = (0..n_rows)
        .filter(|&i| active[i])
        .map(|i| origin[i])
        .collect();
    ConstraintRank {
        rows: n_rows,
        rank: pivots.len(),
        pivots,
        redundant,
        zero_moduli,
    }
}
