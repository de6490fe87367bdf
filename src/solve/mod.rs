//! Running a mechanism or a raw bond graph: each formulation implements the one `Formulation`
//! trait (`formulation.rs`: residual or right-hand side with Jacobian and sparsity, id vector,
//! consistent start, row state, recovery hook), in a runner of its own (`runners/`: GGL
//! plain and compliant, index 1 and `dae`, partitioned, decoupled twin, raw bond graph; the
//! equations each runs are built in `crate::dae`, e.g. `dae/ggl.rs` and `runners/ggl.rs`), and
//! the one executor (`executor.rs`) runs any of them on IDA, CVODE or ARKODE (`solver.rs`): output times,
//! events, budgets, partial rows, statistics, energy drift, streaming. Errors: [`SolveError`].

pub mod bond_run;
pub mod error;
pub(crate) mod executor;
pub mod formulation;
mod integrators;
pub(crate) mod kinematic;
pub(crate) mod non_finite;
pub mod options;
pub(crate) mod reactions;
mod rows;
pub mod run;
mod solution;
pub(crate) mod solver;

pub use error::SolveError;
pub use options::{FormulationKind, Integrator, LinearSolverKind, SolveOptions};
pub use run::{solve_system, EventRecord, Row, SingularPassage, Solution, Summary};
