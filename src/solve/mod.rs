//! Running a mechanism: the formulation chosen in [`SolveOptions`] on IDA (GGL DAE) or CVODE
//! (decoupled twin), with consistent initial values, output rows, energy and constraint error.

pub mod bond_run;
mod integrators;
pub(crate) mod non_finite;
pub mod options;
mod partition;
mod reactions;
pub mod run;

pub use options::{FormulationKind, Integrator, LinearSolverKind, SolveOptions};
pub use run::{solve_system, EventRecord, Row, SingularPassage, Solution, Summary};
