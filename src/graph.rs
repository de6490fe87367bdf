//! The bond graph of a scene, its causality report and its drawing.
//!
//! A scene with `bodies`/`joints` gets the complete graph its equations are read from
//! ([`crate::mech::build`]: the chapter's fragments completed with closures and displacements),
//! or that graph's decoupled twin ([`crate::bond::decouple`]); a scene with a raw
//! `"bond_graph"` is read as it is.

use crate::bond::causality::{assign_causality, assign_causality_at, Causality, CausalityReport};
use crate::bond::dot::to_dot;
use crate::bond::json::RawBondGraph;
use crate::bond::model::BondGraph;
use crate::error::{Error, Result};
use crate::mech::{scene_bond_graph, Variant};
use crate::scene::Scene;
use std::collections::HashMap;

/// A scene's bond graph with its causal assignment.
#[derive(Clone, Debug)]
pub struct SceneGraph {
    /// The bond graph.
    pub graph: BondGraph,
    /// The causal assignment (by matching, see [`crate::bond::causality`]).
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
    ///
    /// A mechanism's causality follows the rank of its constraint rows at the scene's initial
    /// configuration ([`assign_causality_at`] with [`initial_values`]): the true DOF of a
    /// geometrically special mechanism, with its redundant joint rows named. A raw graph gets
    /// the generic (structural) count ([`assign_causality`]).
    pub fn new(scene: &Scene, variant: Variant) -> Result<SceneGraph> {
        let scene = &scene.with_inputs_at_start();
        match &scene.bond_graph {
            Some(raw) => {
                let raw: RawBondGraph = serde_json::from_value(raw.clone())
                    .map_err(|e| Error::BondGraph(format!("bond_graph: {e}")))?;
                let graph = raw
                    .to_graph()
                    .map_err(|e| Error::BondGraph(e.to_string().replace('\n', "; ")))?;
                SceneGraph::from_graph(graph)
            }
            None => {
                // the graph the solver reads: the complete pinned graph (closures, sliders,
                // springs), or its decoupled twin (each constraint junction opened, a spring
                // put in)
                let graph = match variant {
                    Variant::Pinned => crate::mech::build(scene)?
                        .bond_graph
                        .as_deref()
                        .cloned()
                        .ok_or_else(|| {
                            Error::BondGraph("the mechanism has no bond graph".into())
                        })?,
                    Variant::Decoupled => scene_bond_graph(scene, variant)?,
                };
                let values = initial_values(scene);
                let causality =
                    assign_causality_at(&graph, scene.solve.t_start, &|n| values.get(n).copied())
                        .map_err(|e| Error::BondGraph(e.to_string().replace('\n', "; ")))?;
                Ok(SceneGraph { graph, causality })
            }
        }
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

    /// Graphviz DOT with half arrows, causal strokes and differential storages in red
    /// (collapsed to one node per body or joint above [`crate::bond::dot::COLLAPSE_ABOVE`]
    /// elements).
    pub fn dot(&self) -> String {
        to_dot(&self.graph, Some(&self.causality))
    }

    /// [`SceneGraph::dot`], collapsed (one node per body or joint) or expanded as asked.
    pub fn dot_with(&self, collapse: bool) -> String {
        crate::bond::dot::to_dot_with(&self.graph, Some(&self.causality), collapse)
    }
}

/// The values the moduli of a mechanism's bond graph reference, at the scene's initial state:
/// `x_<body>.omega` the planar angle α of each body, `<body>.R_<I><i>` the entries of each
/// spatial body's rotation `R = R_Z(ψ) R_y(θ) R_x(φ)` (seed 16.2, Cardan angles `[ψ, θ, φ]`).
pub fn initial_values(scene: &Scene) -> HashMap<String, f64> {
    let mut v = HashMap::new();
    for b in &scene.bodies {
        v.insert(format!("x_{}.omega", b.name), b.angle);
        let [psi, theta, phi] = b.cardan;
        let (cs, ss) = (psi.cos(), psi.sin());
        let (ct, st) = (theta.cos(), theta.sin());
        let (cf, sf) = (phi.cos(), phi.sin());
        let r = [
            [ct * cs, sf * st * cs - cf * ss, cf * st * cs + sf * ss],
            [ct * ss, sf * st * ss + cf * cs, cf * st * ss - sf * cs],
            [-st, sf * ct, cf * ct],
        ];
        for (i, big) in ["X", "Y", "Z"].iter().enumerate() {
            for (k, small) in ["x", "y", "z"].iter().enumerate() {
                v.insert(format!("{}.R_{big}{small}", b.name), r[i][k]);
            }
        }
    }
    v
}

/// A mechanism scene's bond graph written as a raw `"bond_graph"` scene (JSON): the complete
/// pinned graph with its displacement states, named flows, joint closures, output columns
/// and energy ([`crate::mech::annotate::export_graph`]), with the scene's `name`,
/// `description`, `solve` and `outputs`. Solving it gives the mechanism's trajectories and
/// columns; it can be edited like any raw graph (an R at a joint, a C, a source).
///
/// ```
/// let scene = bondmech::Scene::from_path("scenes/double_pendulum.json").unwrap();
/// let raw = bondmech::graph::bond_graph_scene(&scene).unwrap();
/// let back = bondmech::Scene::from_json_str(&raw.to_string()).unwrap();
/// assert!(back.bond_graph.is_some() && back.bodies.is_empty());
/// ```
pub fn bond_graph_scene(scene: &Scene) -> Result<serde_json::Value> {
    if scene.bond_graph.is_some() {
        return Err(Error::Options(
            "--as-scene: the scene is already a raw bond graph".into(),
        ));
    }
    let graph = crate::mech::annotate::export_graph(scene).map_err(|e| match e {
        crate::mech::annotate::AnnotateError::Mech(e) => Error::from(e),
        other => Error::Options(format!(
            "--as-scene: this scene's bond graph cannot be written as a scene yet: {other}"
        )),
    })?;
    let mut v: serde_json::Value =
        serde_json::from_str(&scene.to_json_string()).map_err(|e| Error::Options(e.to_string()))?;
    let obj = v
        .as_object_mut()
        .ok_or_else(|| Error::Options("scene is not a JSON object".into()))?;
    for key in [
        "bodies",
        "joints",
        "springs",
        "loads",
        "events",
        "drivers",
        "gravity",
        "dimension",
    ] {
        obj.remove(key);
    }
    if let Some(outputs) = obj.get_mut("outputs").and_then(|o| o.as_array_mut()) {
        outputs.retain(|o| o != "reactions");
    }
    obj.insert(
        "bond_graph".into(),
        serde_json::to_value(graph.to_raw()).map_err(|e| Error::Options(e.to_string()))?,
    );
    Ok(v)
}
