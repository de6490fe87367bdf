//! bondmech: mechanisms as bond graphs, solved with SUNDIALS.
#![deny(unsafe_code)]
pub mod bond;
pub mod dae;
pub mod expr;
pub mod mech;
pub mod report;
pub mod scene;
#[allow(unsafe_code)]
pub mod sundials;
