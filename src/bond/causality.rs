//! Sequential causality assignment procedure (SCAP).
//!
//! Each bond gets a causal stroke at the end that *receives* the effort (the other end
//! imposes it). Rules: Se imposes effort, Sf imposes flow; at a 0-junction exactly one bond
//! imposes the common effort, at a 1-junction exactly one bond imposes the common flow;
//! TF/MTF pass the stroke through (one in, one out), GY/MGY have both strokes in or both out.
//!
//! Order (deterministic, element order throughout):
//! 1. sources, then propagate;
//! 2. inertias, then capacitors, one at a time with **integral** causality (I receives effort,
//!    C receives flow), propagating after each; a storage already fixed by propagation the other
//!    way is **differential** (a dependent variable / constraint of the seed, 16.5), and the
//!    junction and bonds that forced it are reported: following the variable the storage
//!    receives back through the final causal graph, the first junction that computes it as a
//!    balance of two or more bonds (the junction where the constraint closes, e.g. where a
//!    pin's velocity meets the bar's own), whichever step of SCAP fixed it. An integral
//!    choice is kept only if the rest of the graph can still be completed without a conflict
//!    (a depth-first look-ahead with propagation over the free bonds, bounded by
//!    [`SEARCH_BUDGET`]); otherwise the storage is made differential.
//!    This catches constraints that close kinematic loops (slider-crank, four-bar), which
//!    purely local propagation cannot see;
//! 3. resistors (R imposes effort, an arbitrary choice), propagating; every other R whose
//!    causality that choice forces lies on a zero-order causal path with it: an **algebraic loop**;
//! 4. any bond still free, arbitrarily, propagating.
//!
//! Over-determined junctions and two-ports are **conflicts**; they are recorded with the
//! elements whose choices clash, and the assignment still completes.
//! The number of degrees of freedom reported is `dof = #integral I` (seed 16.5: "solo las
//! inercias con causalidad integral … corresponden con grados de libertad"): the displacements
//! of integral capacitors are states but not degrees of freedom (the decoupled double pendulum
//! of Fig. 21 has 6 DOF and 10 states). `state_count = #integral I + #integral C` is the number
//! of states of the resulting ODE/DAE, listed in `states`.

use super::model::{BondGraph, BondId, ElementId, ElementKind};
use super::validate::{validate, ValidationErrors};
use serde::Serialize;
use std::collections::{HashSet, VecDeque};

/// Maximum number of tentative bond orientations tried by one look-ahead search.
pub const SEARCH_BUDGET: usize = 20_000;

/// Which step of the procedure fixed a bond.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Stage {
    /// Required by a source.
    Source,
    /// Chosen for a storage element (integral causality).
    Storage,
    /// Chosen for a resistor.
    Resistor,
    /// Chosen arbitrarily for a leftover bond.
    Arbitrary,
    /// Forced by propagation through a junction or two-port.
    Propagated,
}

/// The causal assignment of one bond (ids).
#[derive(Debug, Clone, PartialEq)]
pub struct BondAssignment {
    /// The element that receives the effort (the causal stroke's end).
    pub effort_receiver: ElementId,
    /// The element that imposes the effort (the other end).
    pub effort_source: ElementId,
    /// The element whose choice started the propagation that fixed this bond.
    pub origin: ElementId,
    /// The step that fixed it.
    pub stage: Stage,
    /// The junction/two-port that propagated it (None for a direct choice).
    pub via: Option<ElementId>,
    /// The bonds at `via` whose causality forced this one.
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
    /// The element whose choice started the propagation (e.g. an inertia made integral earlier).
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
}

struct Scap<'g> {
    g: &'g BondGraph,
    adj: Vec<Vec<BondId>>,
    state: Vec<Option<BondAssignment>>,
    seq: Vec<usize>,
    counter: usize,
    queue: VecDeque<ElementId>,
    conflicts: Vec<Conflict>,
    conflicted: HashSet<ElementId>,
    /// Undo log: bonds in the order they were fixed, conflicted elements in order.
    trail: Vec<BondId>,
    conflicted_trail: Vec<ElementId>,
    /// Receivers of the last conflict-free completion found by the look-ahead.
    witness: Option<Vec<ElementId>>,
}

/// A point of the undo log to roll back to.
#[derive(Clone, Copy)]
struct Mark {
    trail: usize,
    conflicts: usize,
    conflicted: usize,
}

impl<'g> Scap<'g> {
    fn new(g: &'g BondGraph) -> Self {
        let mut adj = vec![Vec::new(); g.elements.len()];
        for (i, b) in g.bonds.iter().enumerate() {
            adj[b.from.0].push(BondId(i));
            adj[b.to.0].push(BondId(i));
        }
        Scap {
            g,
            adj,
            state: vec![None; g.bonds.len()],
            seq: vec![0; g.bonds.len()],
            counter: 0,
            queue: VecDeque::new(),
            conflicts: Vec::new(),
            conflicted: HashSet::new(),
            trail: Vec::new(),
            conflicted_trail: Vec::new(),
            witness: None,
        }
    }

    fn name(&self, e: ElementId) -> String {
        self.g.element(e).name.clone()
    }

    fn receiver(&self, b: BondId) -> Option<ElementId> {
        self.state[b.0].as_ref().map(|a| a.effort_receiver)
    }

    fn set(
        &mut self,
        b: BondId,
        receiver: ElementId,
        origin: ElementId,
        stage: Stage,
        via: Option<ElementId>,
        causes: Vec<BondId>,
    ) {
        if self.state[b.0].is_some() {
            return;
        }
        let bond = self.g.bond(b);
        let source = if bond.from == receiver {
            bond.to
        } else {
            bond.from
        };
        self.counter += 1;
        self.seq[b.0] = self.counter;
        self.state[b.0] = Some(BondAssignment {
            effort_receiver: receiver,
            effort_source: source,
            origin,
            stage,
            via,
            causes,
        });
        self.trail.push(b);
        self.queue.push_back(bond.from);
        self.queue.push_back(bond.to);
    }

    fn mark(&self) -> Mark {
        Mark {
            trail: self.trail.len(),
            conflicts: self.conflicts.len(),
            conflicted: self.conflicted_trail.len(),
        }
    }

    /// Undoes every assignment and conflict recorded after `m` (the queue is empty at marks).
    fn rollback(&mut self, m: Mark) {
        for b in self.trail.drain(m.trail..) {
            self.state[b.0] = None;
        }
        self.conflicts.truncate(m.conflicts);
        for e in self.conflicted_trail.drain(m.conflicted..) {
            self.conflicted.remove(&e);
        }
        self.queue.clear();
    }

    /// Fixes `b` and propagates.
    fn choose(
        &mut self,
        b: BondId,
        receiver: ElementId,
        origin: ElementId,
        stage: Stage,
        via: Option<ElementId>,
    ) {
        self.set(b, receiver, origin, stage, via, vec![]);
        self.propagate();
    }

    /// Would completing the graph from here create a conflict? (Leaves the state unchanged.)
    /// Returns the junction of an unavoidable conflict, or None when some conflict-free
    /// completion exists (a depth-first search with propagation, bounded by [`SEARCH_BUDGET`]
    /// choices; when the budget runs out the completion is assumed possible).
    fn look_ahead(&mut self) -> Option<String> {
        // a previous conflict-free completion that agrees with every fixed bond still is one
        // (propagated bonds are forced consequences), so no search is needed
        if let Some(w) = &self.witness {
            if self
                .state
                .iter()
                .zip(w)
                .all(|(a, r)| a.as_ref().is_none_or(|a| a.effort_receiver == *r))
            {
                return None;
            }
        }
        let m = self.mark();
        let mut budget = SEARCH_BUDGET;
        let ok = self.search(0, &mut budget);
        self.witness = if ok && self.state.iter().all(|a| a.is_some()) {
            Some(
                self.state
                    .iter()
                    .flatten()
                    .map(|a| a.effort_receiver)
                    .collect(),
            )
        } else {
            None
        };
        self.rollback(m);
        if ok {
            return None;
        }
        let r = self.complete();
        self.rollback(m);
        r.or_else(|| Some(String::new()))
    }

    /// Depth-first search for a conflict-free assignment of the free bonds from index `start`;
    /// on success the assignment is left in place.
    fn search(&mut self, start: usize, budget: &mut usize) -> bool {
        let Some(i) = (start..self.g.bonds.len()).find(|&i| self.state[i].is_none()) else {
            return true;
        };
        let (from, to) = (self.g.bonds[i].from, self.g.bonds[i].to);
        for receiver in [to, from] {
            if *budget == 0 {
                return true;
            }
            *budget -= 1;
            let m = self.mark();
            self.choose(BondId(i), receiver, from, Stage::Arbitrary, None);
            if self.conflicts.len() == m.conflicts && self.search(i + 1, budget) {
                return true;
            }
            self.rollback(m);
        }
        false
    }

    fn origin(&self, b: BondId) -> ElementId {
        self.state[b.0]
            .as_ref()
            .map(|a| a.origin)
            .unwrap_or(ElementId(0))
    }

    /// Origin of the most recently fixed of `causes`.
    fn latest_origin(&self, causes: &[BondId]) -> ElementId {
        causes
            .iter()
            .max_by_key(|b| self.seq[b.0])
            .map(|&b| self.origin(b))
            .unwrap_or(ElementId(0))
    }

    fn conflict(&mut self, at: ElementId, bonds: &[BondId], description: String) {
        if !self.conflicted.insert(at) {
            return;
        }
        self.conflicted_trail.push(at);
        let mut elements: Vec<ElementId> = bonds.iter().map(|&b| self.origin(b)).collect();
        elements.sort();
        elements.dedup();
        self.conflicts.push(Conflict {
            junction: self.name(at),
            elements: elements.into_iter().map(|e| self.name(e)).collect(),
            description,
        });
    }

    fn propagate(&mut self) {
        while let Some(el) = self.queue.pop_front() {
            self.process(el);
        }
    }

    fn process(&mut self, el: ElementId) {
        let kind = self.g.element(el).kind;
        let bonds = self.adj[el.0].clone();
        match kind {
            ElementKind::Zero | ElementKind::One => self.junction(el, kind, &bonds),
            k if k.is_two_port() && bonds.len() == 2 => self.two_port(el, k, &bonds),
            _ => {}
        }
    }

    fn junction(&mut self, el: ElementId, kind: ElementKind, bonds: &[BondId]) {
        let zero = kind == ElementKind::Zero;
        // a bond "determines" the junction when it imposes the common variable on it
        let determines = |r: ElementId| if zero { r == el } else { r != el };
        let det: Vec<BondId> = bonds
            .iter()
            .copied()
            .filter(|&b| self.receiver(b).is_some_and(determines))
            .collect();
        let free: Vec<BondId> = bonds
            .iter()
            .copied()
            .filter(|&b| self.receiver(b).is_none())
            .collect();
        let (what, var) = if zero {
            ("0-junction", "effort")
        } else {
            ("1-junction", "flow")
        };
        let non_det_receiver = |s: &Self, b: BondId| {
            if zero {
                s.g.other_end(b, el)
            } else {
                el
            }
        };
        let det_receiver = |s: &Self, b: BondId| {
            if zero {
                el
            } else {
                s.g.other_end(b, el)
            }
        };
        if det.len() >= 2 {
            let names: Vec<String> = det.iter().map(|&b| self.g.bond(b).name.clone()).collect();
            self.conflict(
                el,
                &det,
                format!(
                    "{what} '{}' has its common {var} imposed by {} bonds ({})",
                    self.name(el),
                    det.len(),
                    names.join(", ")
                ),
            );
        }
        if !det.is_empty() {
            let origin = self.latest_origin(&det);
            for b in free {
                let r = non_det_receiver(self, b);
                self.set(b, r, origin, Stage::Propagated, Some(el), det.clone());
            }
        } else if free.len() == 1 {
            let causes: Vec<BondId> = bonds.iter().copied().filter(|&b| b != free[0]).collect();
            let origin = self.latest_origin(&causes);
            let r = det_receiver(self, free[0]);
            self.set(free[0], r, origin, Stage::Propagated, Some(el), causes);
        } else if free.is_empty() && !bonds.is_empty() {
            self.conflict(
                el,
                bonds,
                format!(
                    "{what} '{}': no bond imposes the common {var}, every bond imposes the other variable",
                    self.name(el)
                ),
            );
        }
    }

    /// Assigns every free bond, choosing for each the orientation that creates no new conflict
    /// when one exists. Returns the junction of the first unavoidable conflict, if any.
    fn complete(&mut self) -> Option<String> {
        let base = self.conflicts.len();
        for i in 0..self.g.bonds.len() {
            if self.state[i].is_some() {
                continue;
            }
            let (from, to) = (self.g.bonds[i].from, self.g.bonds[i].to);
            let m = self.mark();
            self.choose(BondId(i), to, from, Stage::Arbitrary, None);
            if self.conflicts.len() > m.conflicts {
                self.rollback(m);
                self.choose(BondId(i), from, from, Stage::Arbitrary, None);
                if self.conflicts.len() > m.conflicts {
                    self.rollback(m);
                    self.choose(BondId(i), to, from, Stage::Arbitrary, None);
                }
            }
        }
        (self.conflicts.len() > base).then(|| self.conflicts[base].junction.clone())
    }

    fn two_port(&mut self, el: ElementId, kind: ElementKind, bonds: &[BondId]) {
        let (a, b) = (bonds[0], bonds[1]);
        let ra = self.receiver(a).map(|r| r == el);
        let rb = self.receiver(b).map(|r| r == el);
        // gyrator: both strokes at the element or both away; transformer: exactly one
        let same = kind.is_gyrator();
        match (ra, rb) {
            (Some(x), None) => {
                let at_el = if same { x } else { !x };
                let r = if at_el { el } else { self.g.other_end(b, el) };
                let o = self.origin(a);
                self.set(b, r, o, Stage::Propagated, Some(el), vec![a]);
            }
            (None, Some(y)) => {
                let at_el = if same { y } else { !y };
                let r = if at_el { el } else { self.g.other_end(a, el) };
                let o = self.origin(b);
                self.set(a, r, o, Stage::Propagated, Some(el), vec![b]);
            }
            (Some(x), Some(y)) if (x == y) != same => {
                let rule = if same {
                    "needs both causal strokes at it or both away"
                } else {
                    "needs one causal stroke at it and one away"
                };
                self.conflict(
                    el,
                    &[a, b],
                    format!("{} '{}' {rule}", kind.as_str(), self.name(el)),
                );
            }
            _ => {}
        }
    }
}

/// Assigns causality to a valid graph (validation errors are returned otherwise).
pub fn assign_causality(graph: &BondGraph) -> Result<Causality, ValidationErrors> {
    validate(graph)?;
    let mut s = Scap::new(graph);
    let ids: Vec<ElementId> = graph.element_ids().collect();
    let kind = |e: ElementId| graph.element(e).kind;

    // 1. sources
    for &e in &ids {
        let k = kind(e);
        if k != ElementKind::Se && k != ElementKind::Sf {
            continue;
        }
        let b = s.adj[e.0][0];
        let want = if k == ElementKind::Sf {
            e
        } else {
            graph.other_end(b, e)
        };
        match s.receiver(b) {
            None => s.set(b, want, e, Stage::Source, None, vec![]),
            Some(r) if r != want => s.conflict(
                e,
                &[b],
                format!(
                    "source '{}' is bonded directly to another source with the same causality",
                    graph.element(e).name
                ),
            ),
            _ => {}
        }
    }
    // junctions with a single bond and the like are decided from the start
    s.queue.extend(ids.iter().copied());
    s.propagate();

    // 2. storage: inertias first, then capacitors, integral causality preferred. A choice is
    //    kept only if the rest of the graph can still be completed without a conflict (greedy
    //    look-ahead); otherwise the storage is made differential: this catches constraints
    //    that close kinematic loops, which plain local propagation cannot see.
    for wanted in [ElementKind::I, ElementKind::C] {
        for &e in &ids {
            if kind(e) != wanted {
                continue;
            }
            let b = s.adj[e.0][0];
            if s.receiver(b).is_some() {
                continue;
            }
            let other = graph.other_end(b, e);
            let (integral, differential) = if wanted == ElementKind::I {
                (e, other)
            } else {
                (other, e)
            };
            let m = s.mark();
            s.choose(b, integral, e, Stage::Storage, None);
            let culprit = if s.conflicts.len() > m.conflicts {
                Some(s.conflicts[m.conflicts].junction.clone())
            } else {
                s.look_ahead()
            };
            let Some(culprit) = culprit else {
                continue;
            };
            s.rollback(m);
            let via = graph.element_by_name(&culprit);
            // the bonds at the over-determined junction already fixed before this choice
            // (all of its bonds when the clash only appears deeper in the completion)
            let causes: Vec<BondId> = match via {
                Some(j) => {
                    let fixed: Vec<BondId> = s.adj[j.0]
                        .iter()
                        .copied()
                        .filter(|&x| x != b && s.receiver(x).is_some())
                        .collect();
                    if fixed.is_empty() {
                        s.adj[j.0].iter().copied().filter(|&x| x != b).collect()
                    } else {
                        fixed
                    }
                }
                None => vec![],
            };
            s.set(b, differential, e, Stage::Storage, via, causes);
            s.propagate();
            let alt_ok = s.conflicts.len() == m.conflicts && s.look_ahead().is_none();
            if !alt_ok {
                s.rollback(m);
                s.choose(b, integral, e, Stage::Storage, None);
            }
        }
    }

    // 3. resistors, detecting algebraic loops
    let mut loops: Vec<Vec<ElementId>> = Vec::new();
    for &e in &ids {
        if kind(e) != ElementKind::R {
            continue;
        }
        let b = s.adj[e.0][0];
        if s.receiver(b).is_some() {
            continue;
        }
        let r = graph.other_end(b, e);
        s.set(b, r, e, Stage::Resistor, None, vec![]);
        s.propagate();
        let mut group: Vec<ElementId> = ids
            .iter()
            .copied()
            .filter(|&o| {
                o != e
                    && kind(o) == ElementKind::R
                    && s.state[s.adj[o.0][0].0]
                        .as_ref()
                        .is_some_and(|a| a.origin == e && a.stage == Stage::Propagated)
            })
            .collect();
        if !group.is_empty() {
            group.push(e);
            group.sort();
            loops.push(group);
        }
    }

    // 4. leftovers, preferring the orientation that creates no conflict
    let mut budget = SEARCH_BUDGET;
    let m = s.mark();
    if !s.search(0, &mut budget) {
        s.rollback(m);
    }
    s.complete();

    let bonds: Vec<BondAssignment> = s
        .state
        .into_iter()
        .map(|a| a.expect("all bonds assigned"))
        .collect();
    let mut storage = Vec::new();
    for wanted in [ElementKind::I, ElementKind::C] {
        for &e in &ids {
            if kind(e) != wanted {
                continue;
            }
            let a = &bonds[s.adj[e.0][0].0];
            let receives_effort = a.effort_receiver == e;
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
    Ok(Causality {
        bonds,
        storage,
        conflicts: s.conflicts,
        algebraic_loops: loops,
    })
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
                    let a = &self.bonds[b.0];
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
                        origin: name(a.origin),
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
        }
    }
}
