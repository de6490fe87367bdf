//! Reports: comparisons of the DAE with its decoupled twin, speed-against-error sweeps, their
//! SVG plots, and generated benchmark scenes.

pub mod animate;
pub mod compare;
pub mod generate;
pub mod plot;
pub mod reference;
pub mod sweep;
pub mod timeplot;

pub use compare::{column_kind, ColumnKind, Comparison, LargestDifference};
pub use sweep::{run_sweep, ExternalReference, SweepConfig, SweepReport};
