//! The bond graph of a scene, its causality report and its drawing.
//!
//! A scene with `bodies`/`joints` is expanded with the chapter's fragments
//! ([`crate::mech::bondgraph`]); a scene with a raw `"bond_graph"` is read as it is.

use crate::bond::causality::{assign_causality, Causality, CausalityReport};
use crate::bond::dot::to_dot;
use crate::bond::json::RawBondGraph;
use crate::bond::model::BondGraph;
use crate::mech::{scene_bond_graph, Variant};
use crate::scene::Scene;
use crate::{Error, Result};

/// A scene's bond graph with its causal assignment.
#[derive(Clone, Debug)]
pub struct SceneGraph {
    /// The bond graph.
    pub graph: BondGraph,
    /// The SCAP causal assignment.
    pub causality: Causality,
}

impl SceneGraph {
    /// Builds (or reads) the bond graph of `scene` and assigns causality.
    ///
    /// ```
    /// let scene = bondmech::Scene::from_path("scenes/double_pendulum.json").unwrap();
    /// let g = bondmech::graph::SceneGraph::new(&scene, bondmech::mech::Variant::Pinned).unwrap();
    /// let r = g.report();
    /// assert_eq!((r.integral_inertias, r.differential.len()), (2, 4)); // seed 16.7
    /// ```
    pub fn new(scene: &Scene, variant: Variant) -> Result<SceneGraph> {
        let graph = match &scene.bond_graph {
            Some(raw) => {
                let raw: RawBondGraph = serde_json::from_value(raw.clone())
                    .map_err(|e| Error::BondGraph(format!("bond_graph: {e}")))?;
                raw.to_graph()
                    .map_err(|e| Error::BondGraph(e.to_string().replace('\n', "; ")))?
            }
            None => scene_bond_graph(scene, variant)?,
        };
        SceneGraph::from_graph(graph)
    }

    /// Assigns causality to a bond graph already built (for example a model's raw graph).
    pub fn from_graph(graph: BondGraph) -> Result<SceneGraph> {
        let causality = assign_causality(&graph)
            .map_err(|e| Error::BondGraph(e.to_string().replace('\n', "; ")))?;
        Ok(SceneGraph { graph, causality })
    }

    /// The causality report: DOF, states, differential storages, conflicts, algebraic loops.
    pub fn report(&self) -> CausalityReport {
        self.causality.report(&self.graph)
    }

    /// Graphviz DOT with half arrows, causal strokes and differential storages in red.
    pub fn dot(&self) -> String {
        to_dot(&self.graph, Some(&self.causality))
    }
}
