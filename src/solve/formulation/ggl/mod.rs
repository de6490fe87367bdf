//! The GGL formulation (Gear–Gupta–Leimkuhler, stabilized index 2, plain or compliant): its
//! equations ([`equations`]) and its runner (restarts, the compliant switch at singular
//! passages, statistics).

pub mod equations;
pub(crate) mod runner;

pub use equations::*;
