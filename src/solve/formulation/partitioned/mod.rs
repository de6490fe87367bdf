//! The partitioned formulation: the degrees of freedom as ODE states, the dependent coordinates
//! by Newton ([`equations`]) or by symbolic elimination where they are affine in their rows
//! ([`elimination`]), and its runner (re-partition, singular partitions, stiffness switch).

pub mod elimination;
pub mod equations;
pub(crate) mod runner;

pub use equations::*;
