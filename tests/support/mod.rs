//! Helpers shared by tests that drive bondmech itself: running the CLI, building raw bond graphs
//! and evaluating their equations. (Unlike `tests/common`, whose reference models must stay
//! independent of bondmech, these use it.)
#![allow(dead_code)]

pub mod bond;
pub mod cli;
pub mod nodes;
pub mod signals;
pub mod solve;
