//! Running a mechanism or a raw bond graph: each formulation implements the one `Formulation`
//! trait ([`formulation`]: residual or right-hand side with Jacobian and sparsity, id vector,
//! consistent start, row state, recovery hook) in one folder of its own under `formulation/`
//! (`ggl`, `index1` with the chapter's `dae`, `partitioned`, `decoupled`, `raw_graph`: each its
//! `equations.rs` and its `runner.rs`), and the one executor (`executor.rs`) runs any of them on
//! IDA, CVODE or ARKODE (`solver.rs`): output times, events, budgets, partial rows, statistics,
//! energy drift, streaming. Which velocities are dependent, and when to choose again, is asked
//! of [`crate::partition`]. Errors: [`SolveError`].

pub mod bond_run;
pub mod error;
pub(crate) mod executor;
pub mod formulation;
pub(crate) mod integrators;
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
