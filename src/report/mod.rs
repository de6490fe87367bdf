//! Reports: comparisons of the DAE with its decoupled twin (and, later, sweeps and plots).

pub mod compare;

pub use compare::{column_kind, ColumnKind, Comparison, LargestDifference};
