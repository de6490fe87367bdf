//! The partition of the velocities into states and dependent unknowns, as the chapter's
//! causality gives it (seed 16.5, 16.7): the inertias the joints force into differential
//! causality are the dependent unknowns, the integral ones the states.
//!
//! [`CausalPartition`] runs the causality assignment of the mechanism's own bond graph
//! ([`crate::bond::causality::assign_causality_at`]) at the start, and again at the current
//! configuration when a formulation re-chooses its partition: the assignment's pivots are the
//! inertias best conditioned *at that state*, which the numeric choice
//! ([`super::select_dependent`]) then takes first. No name heuristics: what
//! `graph --causality` draws is the partition the solvers start from.

use std::sync::Arc;

use crate::bond::causality::{assign_causality_at, reassign_differential_at, CausalityReport};
use crate::bond::model::BondGraph;
use crate::mech::MultibodySystem;

/// One answer of [`CausalPartition::preferred_at`]: the time, the displacement variables'
/// values, and the preference.
type PreferenceAt = (f64, Vec<f64>, Vec<bool>);

/// The causality of a mechanism's bond graph, evaluated at its configurations.
pub(crate) struct CausalPartition {
    /// The assignment at the start time (what `graph --causality` reports).
    pub start: Option<CausalityReport>,
    /// `(x_<junction>, coordinate index)`: the graph's displacement variables that the
    /// moduli reference, and the coordinate each is.
    displacement_vars: Vec<(String, usize)>,
    /// The mechanism's bond graph.
    graph: Option<Arc<BondGraph>>,
    /// The inertia of each velocity (empty when the equations were not read off a graph).
    inertias: Vec<String>,
    /// Each velocity's name (for velocities without an inertia).
    velocities: Vec<String>,
    /// Constraint rows.
    nc: usize,
    /// The start time, each displacement variable's value there (the graph's initial value
    /// that [`Self::start`] was assigned with, by `displacement_vars`), and the preference that
    /// assignment gives: [`Self::preferred_at`] at the start state is the same assignment.
    start_t: f64,
    start_values: Vec<f64>,
    start_mask: Vec<bool>,
    /// The last query of [`Self::preferred_at`] away from the start: its time, displacement
    /// values and answer (a re-choice asks at its step, and the segment it restarts asks again
    /// at the same state: one graph assignment, not two).
    last: std::sync::Mutex<Option<PreferenceAt>>,
}

impl CausalPartition {
    /// The causality of `sys`'s bond graph at its configuration at `t0` (`None` inside when the
    /// equations were not read off a graph or the assignment fails).
    pub fn new(sys: &MultibodySystem, t0: f64) -> Self {
        let displacement_vars = sys
            .bond_graph
            .as_deref()
            .map(|g| {
                g.displacements
                    .iter()
                    .filter_map(|d| {
                        let i = sys.coords.iter().position(|c| c.name == d.name)?;
                        Some((format!("x_{}", g.element(d.element).name), i))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let mut cp = CausalPartition {
            start: None,
            displacement_vars,
            graph: sys.bond_graph.clone(),
            inertias: if sys.inertias.len() == sys.nv() {
                sys.inertias.clone()
            } else {
                Vec::new()
            },
            velocities: sys.velocities.iter().map(|v| v.name.clone()).collect(),
            nc: sys.nc(),
            start_t: t0,
            start_values: Vec::new(),
            start_mask: Vec::new(),
            last: std::sync::Mutex::new(None),
        };
        cp.start = cp.report(t0);
        if let (Some(g), Some(r)) = (cp.graph.as_deref(), cp.start.as_ref()) {
            // the value the start's assignment read for each displacement variable (the first
            // annotated displacement of that element, as the assignment looks it up)
            cp.start_values = cp
                .displacement_vars
                .iter()
                .map(|(name, _)| {
                    g.displacements
                        .iter()
                        .find(|d| name.strip_prefix("x_") == Some(&g.element(d.element).name))
                        .map_or(0.0, |d| d.initial)
                })
                .collect();
            let mut mask = vec![false; cp.velocities.len()];
            for d in &r.differential {
                if let Some(j) = cp.inertias.iter().position(|n| *n == d.element) {
                    mask[j] = true;
                }
            }
            cp.start_mask = mask;
        }
        cp
    }

    /// The assignment at the start time (the graph's initial values; validates the graph).
    fn report(&self, t: f64) -> Option<CausalityReport> {
        let graph = self.graph.as_deref()?;
        let causality = assign_causality_at(graph, t, &|_| None).ok()?;
        Some(causality.report(graph))
    }

    /// The velocities whose inertias the assignment at the start puts in differential causality
    /// (the `differential[].element` of `graph --causality`), sorted; `None` when the
    /// velocities are not one inertia each or the assignment does not give one dependent
    /// velocity per independent constraint row (the rows less the redundant ones it names).
    pub fn dependent(&self) -> Option<Vec<usize>> {
        let report = self.start.as_ref()?;
        if self.inertias.is_empty() {
            return None;
        }
        let mut dependent: Vec<usize> = report
            .differential
            .iter()
            .filter_map(|d| self.inertias.iter().position(|n| *n == d.element))
            .collect();
        dependent.sort_unstable();
        dependent.dedup();
        let rank = self.nc - report.redundant.len().min(self.nc);
        (dependent.len() == rank).then_some(dependent)
    }

    /// The joint rows (indices into `rows`) that the assignment at the start names redundant
    /// (`redundant[]` of `graph --causality`: a junction `joint.direction`), sorted.
    pub fn redundant_rows(&self, rows: &[crate::mech::ConstraintRow]) -> Vec<usize> {
        let Some(report) = self.start.as_ref() else {
            return Vec::new();
        };
        let mut out: Vec<usize> = report
            .redundant
            .iter()
            .filter_map(|r| {
                rows.iter()
                    .position(|row| row.joint == r.joint && row.direction == r.direction)
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Which velocities the assignment at the configuration `q` at `t` puts in differential
    /// causality: the preference of a re-choice there ([`super::select_dependent`] takes
    /// them first and completes the set by pivoting where they are not enough). All `false`
    /// when no assignment exists.
    pub fn preferred_at(&self, t: f64, q: &[f64]) -> Vec<bool> {
        let mut mask = vec![false; self.velocities.len()];
        let (Some(graph), Some(_)) = (self.graph.as_deref(), self.start.as_ref()) else {
            return mask;
        };
        // at the start state the assignment is the start's (same graph, time and values)
        if t == self.start_t
            && self
                .displacement_vars
                .iter()
                .zip(&self.start_values)
                .all(|(&(_, i), &v)| q[i] == v)
        {
            return self.start_mask.clone();
        }
        let key: Vec<f64> = self.displacement_vars.iter().map(|&(_, i)| q[i]).collect();
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((lt, lv, lm)) = last.as_ref() {
            if *lt == t && *lv == key {
                return lm.clone();
            }
        }
        let values = |name: &str| {
            self.displacement_vars
                .iter()
                .find(|(n, _)| n == name)
                .map(|&(_, i)| q[i])
        };
        for e in reassign_differential_at(graph, t, &values) {
            let name = &graph.element(e).name;
            if let Some(j) = self.inertias.iter().position(|n| n == name) {
                mask[j] = true;
            }
        }
        *last = Some((t, key, mask.clone()));
        mask
    }

    /// The summary's names of a partition (`summary.states`, `summary.dependent`): the
    /// dependent velocities' inertias; and the states, the other inertias followed by the
    /// storages the causality keeps integral that are not inertias (the springs' capacitors)
    /// — the `states` of `graph --causality` when the partition is the causality's.
    pub fn names(&self, dependent: &[usize]) -> (Vec<String>, Vec<String>) {
        let name = |j: usize| {
            self.inertias
                .get(j)
                .cloned()
                .unwrap_or_else(|| self.velocities[j].clone())
        };
        let mut states: Vec<String> = (0..self.velocities.len())
            .filter(|j| !dependent.contains(j))
            .map(name)
            .collect();
        if let Some(r) = &self.start {
            states.extend(
                r.states
                    .iter()
                    .filter(|s| !self.inertias.contains(s))
                    .cloned(),
            );
        }
        (states, dependent.iter().map(|&j| name(j)).collect())
    }
}

/// The warning where the causality's dependent inertias are no regular block of the joint rows
/// at the start `t0` (the `formulation` then chooses its dependent velocities numerically).
pub(crate) fn not_regular_warning(formulation: &str, t0: f64) -> String {
    format!(
        "{formulation}: the causality's dependent inertias are not a regular block of the joint rows at t = {t0}; chosen numerically"
    )
}
