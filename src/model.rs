//! A scene turned into a solvable model: the entry point of the library.

use std::ops::ControlFlow;

use cpu_time::ThreadTime;

use crate::mech::{assemble, MultibodySystem};
use crate::report::Comparison;
use crate::scene::{Formulation, Scene};
use crate::solve::{solve_system, FormulationKind, Row, Solution, SolveOptions};
use crate::{Error, Result};

/// A mechanism ready to be solved: the scene and the multibody system it expands into.
///
/// ```no_run
/// # fn main() -> Result<(), bondmech::Error> {
/// let scene = bondmech::Scene::from_path("scenes/double_pendulum.json")?;
/// let model = bondmech::Model::new(&scene)?;
/// let solution = model.solve(&model.default_options())?;
/// println!("{} steps", solution.summary.steps);
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct Model {
    scene: Scene,
    system: MultibodySystem,
    build_cpu_seconds: f64,
}

impl Model {
    /// Builds the multibody system of `scene`.
    pub fn new(scene: &Scene) -> Result<Model> {
        let clock = ThreadTime::now();
        let system = assemble(scene)?;
        Ok(Model {
            scene: scene.clone(),
            system,
            build_cpu_seconds: clock.elapsed().as_secs_f64(),
        })
    }

    /// The scene this model was built from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The symbolic multibody system (coordinates, masses, forces, constraint rows).
    pub fn system(&self) -> &MultibodySystem {
        &self.system
    }

    /// Non-fatal remarks found while building the model.
    pub fn warnings(&self) -> &[String] {
        &self.system.warnings
    }

    /// The solve options written in the scene's `solve` section.
    pub fn default_options(&self) -> SolveOptions {
        let s = &self.scene.solve;
        let formulation = match s.formulation {
            Formulation::Decoupled => FormulationKind::Decoupled,
            Formulation::CompliantGgl => FormulationKind::CompliantGgl,
            Formulation::Index1 => FormulationKind::Index1,
            _ => FormulationKind::Ggl,
        };
        SolveOptions {
            formulation,
            rtol: s.rtol,
            atol: s.atol,
            output_times: self.scene.output_times(),
            max_steps: s.max_steps.or(Some(100_000)),
            max_wall_clock: s.max_wall_seconds.map(std::time::Duration::from_secs_f64),
            joint_stiffness: s.joint_stiffness,
            joint_damping: s.joint_damping,
            ..SolveOptions::default()
        }
    }

    /// Solves with `opts`.
    pub fn solve(&self, opts: &SolveOptions) -> Result<Solution> {
        self.solve_streaming(opts, &mut |_| ControlFlow::Continue(()))
    }

    /// Solves with `opts`, handing each output row to `observer` as soon as it is computed;
    /// the observer returns `ControlFlow::Break(())` to stop early.
    pub fn solve_streaming(
        &self,
        opts: &SolveOptions,
        observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    ) -> Result<Solution> {
        if opts.output_times.is_empty() {
            return Err(Error::Options("output_times is empty".into()));
        }
        if !(opts.rtol > 0.0 && opts.rtol.is_finite() && opts.atol > 0.0 && opts.atol.is_finite()) {
            return Err(Error::Options(format!(
                "rtol and atol must be positive and finite (got {}, {})",
                opts.rtol, opts.atol
            )));
        }
        if opts.output_times.windows(2).any(|w| w[1] <= w[0]) {
            return Err(Error::Options(
                "output_times must be strictly increasing".into(),
            ));
        }
        solve_system(self.system.clone(), opts, self.build_cpu_seconds, observer)
    }

    /// Solves the DAE (GGL) and the decoupled twin with the same options and compares them.
    pub fn compare(&self, opts: &SolveOptions) -> Result<(Comparison, Solution, Solution)> {
        let mut a = opts.clone();
        if a.formulation == FormulationKind::Decoupled {
            a.formulation = FormulationKind::Ggl;
        }
        let mut b = opts.clone();
        b.formulation = FormulationKind::Decoupled;
        let dae = self.solve(&a)?;
        let dec = self.solve(&b)?;
        Ok((Comparison::new(&dae, &dec), dae, dec))
    }
}
