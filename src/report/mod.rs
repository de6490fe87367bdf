//! Reports: comparisons of the DAE with its decoupled twin, the data of speed-against-error
//! sweeps and parameter sweeps (sharded and merged) with their CSV, JSON and SVG, plots and
//! animations of solutions, the tables the commands print (a run, the equilibrium, the linear model), and
//! generated benchmark scenes. Reports take solutions; the runs that produce a sweep's
//! solutions are [`crate::study`]'s.

pub mod animate;
pub mod bode;
pub mod compare;
pub mod error;
pub mod generate;
pub mod palette;
pub mod plot;
pub mod reference;
pub mod shard;
pub mod sweep;
pub mod tables;
pub mod timeplot;
pub mod vary;
pub mod view3d;

pub use compare::{column_kind, ColumnKind, Comparison, LargestDifference, Verdict};
pub use error::{ReferenceProblem, ReportError};
pub use sweep::{ExternalReference, SweepConfig, SweepReport};
