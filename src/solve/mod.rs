//! Running a mechanism or a raw bond graph: a [`formulation::Formulation`] per formulation
//! (one module each in [`formulations`]), run by the one [`executor`] on IDA, CVODE or ARKODE
//! (output times, events, budgets, partial rows, statistics, energy drift, streaming).

pub mod bond_run;
pub mod error;
pub(crate) mod executor;
pub(crate) mod formulation;
pub(crate) mod formulations;
mod integrators;
pub(crate) mod non_finite;
pub mod options;
mod partition;
mod reactions;
mod rows;
pub mod run;
mod solution;

pub use error::SolveError;
pub use options::{FormulationKind, Integrator, LinearSolverKind, SolveOptions};
pub use run::{solve_system, EventRecord, Row, SingularPassage, Solution, Summary};
