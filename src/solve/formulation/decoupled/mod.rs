//! The decoupled stiff-spring twin (seed 16.6), an ODE for CVODE: its equations
//! ([`equations`]) and its runner.

pub mod equations;
pub(crate) mod runner;

pub use equations::*;
