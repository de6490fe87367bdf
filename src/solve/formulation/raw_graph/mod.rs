//! A raw bond graph's own equations (the velocity-level index-2 and index-1 DAEs, or the ODE)
//! ([`equations`]) and its runner.

pub mod equations;
pub(crate) mod runner;
