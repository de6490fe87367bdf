//! # bondmech
//!
//! Mechanisms as bond graphs, solved with SUNDIALS: the pinned mechanism as a true DAE on IDA
//! (its differential-causality inertias kept as algebraic constraint rows, index-reduced by
//! Gear–Gupta–Leimkuhler stabilisation, exact Jacobians), and its *decoupled* stiff-spring twin
//! as an ODE on CVODE, so the price of replacing a joint by a spring can be measured.
//!
//! | module | owns |
//! |---|---|
//! | [`sundials`] | the only `unsafe`: safe RAII wrappers of IDA and CVODE |
//! | [`expr`] | expression DAG, symbolic derivatives, evaluation tapes |
//! | [`bond`] | bond graphs: data model, validation, causality (SCAP), DOT drawings |
//! | [`graph`] | a scene's bond graph, causality report and drawing |
//! | [`scene`] | the JSON scene format, validated with paths to the bad field |
//! | [`mech`] | bodies, joints, springs, loads → the multibody system |
//! | [`dae`] | GGL and decoupled formulations, consistent initialisation |
//! | [`solve`] | running a formulation: outputs, statistics |
//! | [`report`] | DAE vs decoupled comparisons |
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod bond;
pub mod dae;
pub mod error;
pub mod expr;
pub mod graph;
pub mod mech;
pub mod model;
pub mod report;
pub mod scene;
pub mod solve;
#[allow(unsafe_code)]
pub mod sundials;

pub use error::{Error, Result};
pub use model::Model;
pub use report::Comparison;
pub use scene::Scene;
pub use solve::{FormulationKind, Solution, SolveOptions, Summary};
