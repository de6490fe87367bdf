//! A scene turned into a solvable model: the entry point of the library.
//!
//! A scene is either a mechanism (`bodies`, `joints`, …), expanded into a multibody system
//! (`q' = K(q) v`, `M v' = Q − G_vᵀλ`, `0 = g(q)`), or a raw `"bond_graph"`, whose equations
//! come from its causal assignment ([`crate::bond::equations`]). [`Model::new`] accepts both;
//! solving, streaming and inspecting the bond graph work on both, while the multibody
//! inspection ([`Model::equations`], [`Model::dof`]) and the decoupled twin
//! ([`Model::compare`]) need bodies and joints.

use std::ops::ControlFlow;

use cpu_time::ThreadTime;

use crate::bond::causality::CausalityReport;
use crate::bond::model::BondGraph;
use crate::error::{Error, Result};
use crate::expr::ExprGraph;
use crate::graph::SceneGraph;
use crate::mech::{MultibodySystem, Variant};
use crate::report::Comparison;
use crate::scene::Scene;
use crate::solve::bond_run::{
    raw_bond_graph_options, scene_bond_graph, solve_bond_graph_streaming,
};
use crate::solve::{solve_system, FormulationKind, Row, Solution, SolveOptions};

/// What a model solves: a multibody system, or a raw bond graph.
#[derive(Clone, Debug)]
enum Kind {
    /// Bodies and joints expanded into a multibody system.
    Mechanism(MultibodySystem),
    /// A scene's raw `"bond_graph"`, validated, with the empty multibody system that
    /// [`Model::system`] hands out for it.
    BondGraph(Box<BondGraph>, MultibodySystem),
}

/// A model ready to be solved: the scene and the multibody system (or raw bond graph) it
/// expands into.
///
/// ```
/// # fn main() -> bondmech::Result<()> {
/// let scene = bondmech::Scene::from_path("scenes/double_pendulum.json")?;
/// let model = bondmech::Model::new(&scene)?;
/// let mut options = model.default_options();
/// options.output_times = model.output_times_until(0.1)?;
/// let solution = model.solve(&options)?;
/// assert_eq!(solution.times.len(), 11); // the scene's output_step is 0.01 s
/// println!("{} steps", solution.summary.steps);
/// # Ok(()) }
/// ```
///
/// A raw bond graph scene is loaded the same way:
///
/// ```
/// # fn main() -> bondmech::Result<()> {
/// let scene = bondmech::Scene::from_path("scenes/bg_mass_spring_damper.json")?;
/// let model = bondmech::Model::new(&scene)?;
/// assert!(model.is_raw_bond_graph());
/// let causality = model.causality()?;
/// assert_eq!(causality.dof, 1); // one integral-causality inertia, p_m (seed 16.5)
/// assert_eq!(causality.state_count, 2); // p_m and q_k
/// let solution = model.solve(&model.default_options())?;
/// assert!(solution.column("q_k").is_some());
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct Model {
    scene: Scene,
    kind: Kind,
    build_cpu_seconds: f64,
}

/// The multibody system of a scene without bodies: no coordinates, no forces, zero energy.
fn empty_system() -> MultibodySystem {
    let mut graph = ExprGraph::new();
    let zero = graph.zero();
    MultibodySystem {
        graph,
        coords: Vec::new(),
        velocities: Vec::new(),
        given_velocities: Vec::new(),
        mass: Vec::new(),
        mass_symbols: Vec::new(),
        kinematics: Vec::new(),
        forces: Vec::new(),
        constraints: Vec::new(),
        rows: Vec::new(),
        energy: zero,
        kinetic: zero,
        outputs: Vec::new(),
        warnings: Vec::new(),
        load_terms: Vec::new(),
        body_size: 0.0,
        reactions: Vec::new(),
        reaction_outputs: false,
        events: Vec::new(),
        drivers: Vec::new(),
        energy_exchange: None,
        bodies: Vec::new(),
        names: Vec::new(),
        flow_rows: Vec::new(),
        source: crate::mech::EquationSource::Assembled("raw bond graph".into()),
        inertias: Vec::new(),
        bond_graph: None,
    }
}

impl Model {
    /// Builds the multibody system of `scene`, or reads and validates its raw `"bond_graph"`.
    ///
    /// Errors name the culprit: the JSON path of a bad body, joint or load, or the bond graph
    /// element or bond that is invalid. A model whose dense matrices would not fit in this
    /// machine's memory is refused before it is built ([`crate::mech::size`]).
    ///
    /// A scene's `"inputs"` are held at their start values ([`Scene::with_inputs_at_start`]);
    /// [`Model::scene`] is that scene.
    pub fn new(scene: &Scene) -> Result<Model> {
        let clock = ThreadTime::now();
        let scene = &scene.with_inputs_at_start();
        crate::mech::size::check_scene_memory(scene, scene.solve.formulation)?;
        let kind = if scene.bond_graph.is_some() {
            let graph = scene_bond_graph(scene)?;
            let warnings = crate::solve::bond_run::scene_bond_graph_warnings(scene, &graph);
            if graph.displacements.is_empty() {
                let mut sys = empty_system();
                sys.warnings = warnings;
                Kind::BondGraph(Box::new(graph), sys)
            } else {
                // a mechanism's graph (named coordinates, joint closures): solved as one
                let mut sys = crate::mech::annotate::system_from_graph(&graph)
                    .map_err(|e| Error::BondGraph(e.to_string()))?;
                sys.warnings.extend(warnings);
                for (i, o) in scene.outputs.iter().enumerate() {
                    let known = ["energy", "constraint_error"].contains(&o.as_str())
                        || sys
                            .outputs
                            .iter()
                            .any(|c| c.name == *o || c.name.starts_with(&format!("{o}.")));
                    if !known {
                        return Err(Error::BondGraph(format!(
                            "outputs[{i}]: '{o}' is not a column of the bond graph's `outputs`"
                        )));
                    }
                }
                Kind::Mechanism(sys)
            }
        } else {
            let mut sys = crate::mech::build(scene)?;
            if scene.solve.start_at_equilibrium {
                // "start": "equilibrium": at rest in the static equilibrium nearest the bodies'
                let eq = crate::analysis::equilibrium::equilibrium(&sys, scene.solve.t_start)?;
                for (c, (_, q)) in sys.coords.iter_mut().zip(&eq.coordinates) {
                    c.initial = *q;
                }
                for v in &mut sys.velocities {
                    v.initial = 0.0;
                }
            }
            Kind::Mechanism(sys)
        };
        Ok(Model {
            scene: scene.clone(),
            kind,
            build_cpu_seconds: clock.elapsed().as_secs_f64(),
        })
    }

    /// The static equilibrium nearest the scene's initial configuration, with its loads,
    /// drivers and inputs at `t_start` ([`crate::analysis::equilibrium`]): Newton with a line
    /// search on the effort balance with the joints held; `stable` from the tangent stiffness
    /// reduced to the degrees of freedom.
    ///
    /// ```
    /// use bondmech::{Model, Scene};
    /// // a bar pinned at its end O, held by a torsional-free spring to a point above: it rests
    /// // where the spring's moment balances the weight's
    /// let scene = Scene::from_json_str(r#"{
    ///   "gravity": [0, -9.81],
    ///   "bodies": [{ "name": "bar", "mass": 1, "inertia": 0.0833333333333333,
    ///                "points": { "O": [-0.5, 0], "A": [0.5, 0] }, "position": [0.5, 0] }],
    ///   "joints": [{ "name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
    ///                "points": [[0, 0], "O"] }],
    ///   "springs": [{ "bodies": ["ground", "bar"], "points": [[1, 1], "A"],
    ///                 "stiffness": 100, "rest_length": 0 }],
    ///   "solve": { "t_end": 1 } }"#).unwrap();
    /// let eq = Model::new(&scene).unwrap().equilibrium().unwrap();
    /// assert!(eq.converged && eq.stable);
    /// // the pivot carries the weight less the spring's vertical pull
    /// assert!(eq.residual < 1e-9);
    /// assert!(eq.coordinate("bar.angle").unwrap() > 0.0);
    /// ```
    pub fn equilibrium(&self) -> Result<crate::analysis::equilibrium::Equilibrium> {
        let sys = self
            .mechanism()
            .ok_or(crate::analysis::equilibrium::EquilibriumError::RawGraph)?;
        Ok(crate::analysis::equilibrium::equilibrium(
            sys,
            self.scene.solve.t_start,
        )?)
    }

    /// The scene this model was built from (its inputs, if any, at their start values).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether the scene is a raw `"bond_graph"` (no bodies or joints).
    pub fn is_raw_bond_graph(&self) -> bool {
        matches!(self.kind, Kind::BondGraph(..))
    }

    /// The symbolic multibody system (coordinates, masses, forces, constraint rows).
    ///
    /// For a raw bond graph scene this is the empty system (no coordinates, no rows); see
    /// [`Model::mechanism`] to tell the two apart.
    pub fn system(&self) -> &MultibodySystem {
        match &self.kind {
            Kind::Mechanism(s) | Kind::BondGraph(_, s) => s,
        }
    }

    /// The multibody system, or `None` for a raw bond graph scene.
    pub fn mechanism(&self) -> Option<&MultibodySystem> {
        match &self.kind {
            Kind::Mechanism(s) => Some(s),
            Kind::BondGraph(..) => None,
        }
    }

    /// The bond graph of the model: the chapter's fragments assembled for a mechanism (joints
    /// kept, seed 16.3–16.8), or the raw `"bond_graph"` as read.
    pub fn bond_graph(&self) -> Result<BondGraph> {
        Ok(self.scene_graph(Variant::Pinned)?.graph)
    }

    /// The bond graph of `variant` (for a mechanism: joints kept, or replaced by stiff
    /// springs; a raw bond graph has one variant only, and asking for its decoupled twin is an
    /// error) with its causal assignment (by matching).
    pub fn scene_graph(&self, variant: Variant) -> Result<SceneGraph> {
        match &self.kind {
            Kind::BondGraph(..) if variant == Variant::Decoupled => Err(Error::Options(
                "decoupled: a raw bond graph has no joints to decouple".into(),
            )),
            Kind::BondGraph(g, _) => SceneGraph::from_graph((**g).clone()),
            Kind::Mechanism(_) => SceneGraph::new(&self.scene, variant),
        }
    }

    /// The causality report of [`Model::bond_graph`]: DOF (integral storages), states,
    /// storages in differential causality, conflicts and algebraic loops. For a mechanism
    /// the inertias in integral causality number the mechanism's degrees of freedom
    /// (seed 16.5, 16.7).
    ///
    /// ```
    /// # fn main() -> bondmech::Result<()> {
    /// let scene = bondmech::Scene::from_path("scenes/double_pendulum.json")?;
    /// let report = bondmech::Model::new(&scene)?.causality()?;
    /// assert_eq!((report.integral_inertias, report.differential.len()), (2, 4)); // seed 16.7
    /// # Ok(()) }
    /// ```
    pub fn causality(&self) -> Result<CausalityReport> {
        Ok(self.scene_graph(Variant::Pinned)?.report())
    }

    /// Non-fatal remarks found while building the model.
    pub fn warnings(&self) -> &[String] {
        &self.system().warnings
    }

    /// The solve options written in the scene's `solve` section.
    ///
    /// For a raw bond graph, `decoupled` has no meaning and `index1` selects the index-1 DAE.
    pub fn default_options(&self) -> SolveOptions {
        if self.is_raw_bond_graph() {
            return raw_bond_graph_options(&self.scene);
        }
        let s = &self.scene.solve;
        SolveOptions {
            formulation: s.formulation,
            rtol: s.rtol,
            atol: s.atol,
            t_start: s.t_start,
            output_times: self.scene.output_times(),
            max_steps: s.max_steps,
            max_wall_clock: s
                .max_wall_seconds
                .and_then(|w| crate::scene::validate::wall_clock(w).ok()),
            joint_stiffness: s.joint_stiffness,
            joint_damping: s.joint_damping,
            linear_solver: s.linear_solver,
            integrator: s.integrator,
            switching_functions: s.switching_functions,
            energy_invariant: s.energy_invariant,
            ..SolveOptions::default()
        }
    }

    /// The scene's output times with the end time moved to `t_end` (the rule of the command
    /// line's `--t-end`): explicit `output_times` after `t_end` are dropped; otherwise the grid
    /// from `t_start` to `t_end` spaced by the scene's `output_step` (default
    /// `(t_end − t_start) / 100`).
    ///
    /// Fails unless `t_end > t_start` and finite, when no explicit output time is left, or when
    /// the grid would exceed [`crate::scene::validate::MAX_OUTPUT_TIMES`] rows.
    pub fn output_times_until(&self, t_end: f64) -> Result<Vec<f64>> {
        let s = &self.scene.solve;
        let t0 = s.t_start;
        if !(t_end.is_finite() && t_end > t0) {
            return Err(Error::Options(format!(
                "t_end: must be finite and > t_start = {t0} (got {t_end})"
            )));
        }
        if let Some(times) = &s.output_times {
            let kept: Vec<f64> = times.iter().copied().filter(|&t| t <= t_end).collect();
            if kept.is_empty() {
                return Err(Error::Options(format!(
                    "t_end = {t_end}: the scene's solve.output_times all lie after it (first {})",
                    times[0]
                )));
            }
            return Ok(kept);
        }
        let limit = crate::scene::validate::MAX_OUTPUT_TIMES;
        if let Some(h) = s.output_step {
            if (t_end - t0) / h > limit {
                return Err(Error::Options(format!(
                    "t_end = {t_end} with solve.output_step = {h} gives {:.1e} output rows, more than the limit {limit:e}; raise solve.output_step or lower t_end",
                    (t_end - t0) / h
                )));
            }
        }
        Ok(crate::scene::output_grid(t0, t_end, s.output_step))
    }

    /// The names of the columns of every row a solve produces (without `t`), in order — what
    /// a [`Model::solve_streaming`] observer needs to read its rows. `None` for a raw bond
    /// graph scene, whose columns come from its causal equations (see [`Solution::columns`]).
    pub fn columns(&self) -> Option<Vec<String>> {
        self.mechanism().map(crate::solve::run::output_columns)
    }

    /// The names of the columns of every row a solve with `opts` produces (without `t`), in
    /// order, for mechanisms and raw bond graphs alike (a raw graph's come from its causal
    /// equations, its decoupled twin's from the twin's).
    pub fn row_columns(&self, opts: &SolveOptions) -> Result<Vec<String>> {
        match &self.kind {
            Kind::Mechanism(sys) => Ok(crate::solve::run::output_columns(sys)),
            Kind::BondGraph(g, _) => Ok(crate::solve::bond_run::bond_graph_columns(g, opts)?),
        }
    }

    /// Solves with `opts`.
    pub fn solve(&self, opts: &SolveOptions) -> Result<Solution> {
        self.solve_streaming(opts, &mut |_| ControlFlow::Continue(()))
    }

    /// Solves with `opts`, handing each output row to `observer` as soon as it is computed;
    /// the observer returns `ControlFlow::Break(())` to stop early, and the solution then
    /// holds the rows up to and including the one that stopped it.
    ///
    /// For a raw bond graph the rows are handed over after the solve (the bond graph runner
    /// has no observer yet); an early stop still truncates the solution the same way.
    pub fn solve_streaming(
        &self,
        opts: &SolveOptions,
        observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    ) -> Result<Solution> {
        check_tolerances(opts)?;
        if opts.keep_rows {
            // every row is kept: refuse up front what cannot fit (a streaming solve keeps none)
            let columns = self.columns().map_or(16, |c| c.len());
            crate::mech::size::check_rows_memory(
                opts.output_times.len(),
                columns,
                crate::mech::size::memory_limit(),
            )?;
        }
        match &self.kind {
            Kind::Mechanism(sys) => {
                solve_system(sys.clone(), opts, self.build_cpu_seconds, observer)
                    .map_err(|e| Error::from(crate::solve::non_finite::name_in_mechanism(sys, e)))
            }
            Kind::BondGraph(g, sys) => {
                let mut sol = solve_bond_graph_streaming(g, opts, observer).map_err(|e| {
                    e.map_partial(|p| {
                        p.summary.build_cpu_seconds += self.build_cpu_seconds;
                        p.summary.warnings.extend(sys.warnings.iter().cloned());
                    })
                })?;
                sol.summary.build_cpu_seconds += self.build_cpu_seconds;
                sol.summary.warnings.extend(sys.warnings.iter().cloned());
                Ok(sol)
            }
        }
    }

    /// Solves the DAE (the options' formulation; `dae` where they ask for the twin) and the
    /// decoupled twin with the same options and compares them.
    ///
    /// Fails for a raw bond graph, which has no decoupled twin.
    pub fn compare(&self, opts: &SolveOptions) -> Result<(Comparison, Solution, Solution)> {
        if self.is_raw_bond_graph() {
            return Err(Error::Options(
                "compare needs bodies and joints (a raw bond graph has no decoupled twin)".into(),
            ));
        }
        let mut a = opts.clone();
        if a.formulation == FormulationKind::Decoupled {
            a.formulation = FormulationKind::Dae;
        }
        let mut b = opts.clone();
        b.formulation = FormulationKind::Decoupled;
        let dae = self.solve(&a)?;
        let dec = self.solve(&b)?;
        Ok((Comparison::judged(&dae, &dec, (a.rtol, a.atol)), dae, dec))
    }
}

/// Tolerances a solver can honour: positive, finite, `rtol` not below what double precision
/// can deliver.
fn check_tolerances(opts: &SolveOptions) -> Result<()> {
    if !(opts.rtol > 0.0 && opts.rtol.is_finite() && opts.atol > 0.0 && opts.atol.is_finite()) {
        return Err(Error::Options(format!(
            "rtol and atol must be positive and finite (got {}, {})",
            opts.rtol, opts.atol
        )));
    }
    Ok(())
}
