//! The index-1 formulation with dummy derivatives (`index1` and the chapter's default `dae`):
//! its equations ([`equations`]) and its runner (re-selection of the dependent velocities, the
//! energy invariant, the hand-over to the GGL at a singular passage). Which velocities are
//! dependent, and when to choose again, is the partition's ([`crate::partition`]).

pub mod equations;
pub(crate) mod runner;
mod sensitivity;

pub use equations::*;
