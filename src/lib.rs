//! # bondmech
//!
//! Mechanisms as bond graphs, solved with SUNDIALS: the pinned mechanism as a true DAE on IDA
//! (its differential-causality inertias kept as algebraic constraint rows, index-reduced by
//! default to index 1 in the causality's partition, singular passages handed to
//! Gear–Gupta–Leimkuhler stabilisation, exact Jacobians), and its *decoupled* stiff-spring twin
//! as an ODE on CVODE, so the price of replacing a joint by a spring can be measured.
//!
//! ```
//! use bondmech::{FormulationKind, Ground, Mechanism, Model, PlanarBody};
//!
//! // Double pendulum of two hinged uniform bars, 1 kg and 1 m each (seed 16.7, Fig. 19),
//! // released horizontal at rest.
//! let scene = Mechanism::planar()
//!     .gravity([0.0, -9.81])
//!     .body(PlanarBody::bar("bar1", 1.0, 1.0).at([0.5, 0.0], 0.0))
//!     .body(PlanarBody::bar("bar2", 1.0, 1.0).at([1.5, 0.0], 0.0))
//!     .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
//!     .revolute("knee", ("bar1", "A"), ("bar2", "O"))
//!     .output("energy")
//!     .t_end(1.0)
//!     .build()?;
//!
//! let model = Model::new(&scene)?;
//! assert_eq!(model.dof()?.dof, 2); // 6 velocities, 4 independent pin rows
//!
//! let mut options = model.default_options(); // from the scene: t_end 1, 100 intervals
//! options.rtol = 1e-6;
//! let dae = model.solve(&options)?; // the default `dae`: index 1 in the causality's partition, on IDA
//! let energy = dae.column("energy").unwrap();
//! assert!((energy[100] - energy[0]).abs() < 1e-3 * 9.81); // conservative: energy kept
//! assert!(dae.summary.max_constraint_error < 1e-6); // the pins hold
//!
//! options.formulation = FormulationKind::Decoupled; // pins → stiff springs, ODE on CVODE
//! let twin = model.solve(&options)?;
//! let (a, b) = (dae.value(100, "bar2.y").unwrap(), twin.value(100, "bar2.y").unwrap());
//! assert!((a - b).abs() < 1e-2);
//! # Ok::<(), bondmech::Error>(())
//! ```
//!
//! Scenes also come from JSON ([`Scene::from_path`], [`Scene::from_json_str`]), including raw
//! bond graph scenes (`"bond_graph"`, solved by the same [`Model`]); a model can be looked at
//! before solving ([`Model::equations`], [`Model::dof`], [`Model::constraint_rows`], its bond
//! graph [`Model::bond_graph`] and causality report [`Model::causality`]),
//! solved with a callback that may stop early ([`Model::solve_streaming`]) and compared with
//! its decoupled twin ([`Model::compare`]). Every call fails with the one error type
//! [`Error`]; scene loading returns the more detailed [`scene::SceneError`], which `?`
//! converts into [`Error`] (see [`error`] for an example). [`Model`] is `Send + Sync`: independent solves can
//! run on several threads at once.
//!
//! | module | owns |
//! |---|---|
//! | [`builder`] | mechanisms built in code: [`Mechanism`], [`PlanarBody`], [`SpatialBody`] |
//! | [`model`] | [`Model`]: scene → solvable model; solve, stream, compare, inspect |
//! | [`sundials`] | the only `unsafe`: safe RAII wrappers of IDA and CVODE |
//! | [`expr`] | expression DAG, symbolic derivatives, evaluation tapes |
//! | [`bond`] | bond graphs: data model, validation, causality (matching + numeric rank), the equations read off a graph ([`bond::mechanics`]), the decoupled twin as a transformation ([`bond::decouple`]), DOT drawings |
//! | [`graph`] | a scene's bond graph, causality report and drawing |
//! | [`fmu`] | a scene as a co-simulation FMU (FMI 2.0, 3.0): the archive and its variables |
//! | [`scene`] | the JSON scene format, validated with paths to the bad field; [`scene::path`] changes one field (`--set`) |
//! | [`mech`] | bodies, joints, springs, loads → the mechanism's complete bond graph, read as the multibody system |
//! | [`dae`] | what every formulation shares: the constraint calculus, the mechanics rows `M a − Q + G_vᵀ λ` and `G_v a + γ` written once, consistent initialisation, compiled tapes |
//! | [`partition`] | the one owner of the partition: dependent velocities and coordinates, conditioning, redundant rows, [`partition::PartitionPolicy`] |
//! | [`thresholds`] | every threshold that decides a partition, a re-selection, a hand-over, the energy invariant or a rank under them, each with the reason for its value |
//! | [`solve`] | one `Formulation` trait, one folder per formulation ([`solve::formulation`]: GGL, index 1, partitioned, twin, raw graph; equations and runner), one executor on IDA, CVODE or ARKODE: outputs, events, budgets, statistics; its own `SolveError` |
//! | [`analysis`] | what the analyses find: the static equilibrium (and its search), the linear model about an operating point and its modes ([`linearize`] computes it) |
//! | [`report`] | DAE vs decoupled comparisons, the data, CSV, JSON and SVG of tolerance, stiffness and parameter sweeps ([`report::vary`]), plots, animations |
//! | [`study`] | running sweeps: many solves of one scene, in parallel and in shards |
//! | [`service`] | `bondmech serve`: the HTTP/JSON service over [`Model`] |
//! | [`trajectory`] | typed views of a [`Solution`]: bodies, points, energy, constraint error |
#![deny(unsafe_code)]
#![deny(missing_docs)]

pub mod analysis;
pub mod bond;
pub mod builder;
pub mod dae;
pub mod error;
pub mod expr;
pub mod fmu;
pub mod graph;
pub mod interrupt;
pub mod mech;
pub mod model;
mod model_inspect;
mod model_linearize;
pub mod output;
pub mod partition;
pub mod report;
pub mod scene;
pub mod sensitivity;
pub mod service;
pub mod settings;
pub mod solve;
pub mod study;
#[allow(unsafe_code)]
pub mod sundials;
pub mod thresholds;
pub mod trajectory;

pub use analysis::linear_model::{LinearModel, LinearizeOptions, OperatingPoint};
pub use builder::{Endpoint, Ground, Mechanism, PlanarBody, SpatialBody, SpringDamper};
pub use error::{Error, Result};
pub use model::Model;
pub use model_inspect::{DofReport, Equations};
pub use model_linearize::linearize;
pub use report::Comparison;
pub use scene::Scene;
pub use solve::{FormulationKind, Integrator, LinearSolverKind, Solution, SolveOptions, Summary};
pub use trajectory::{BodyTrajectory, PlanarTrajectory, PointTrajectory, SpatialTrajectory};
