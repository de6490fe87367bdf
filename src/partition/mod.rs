//! The one owner of the partition: which velocities (and coordinates) are dependent, how well
//! the dependent block holds them, which joint rows are redundant, and every threshold that
//! decides a partition, a re-selection, a hand-over, a singular passage or the energy
//! invariant ([`thresholds`], asked through [`PartitionPolicy`]).
//!
//! * [`amplification`]: how the dependent blocks amplify the independent unknowns' error, as
//!   IDA's error weights.
//! * [`select`]: the choice of dependent columns (Gram–Schmidt with column pivoting, the
//!   causality's pivots first).
//! * [`condition`]: `μ(D) = σ_max(G_v) / σ_min(G_D)`, its bounds.
//! * [`grip`]: the same at scale (sparse LU of the block, Lanczos), kept between steps.
//! * [`redundancy`]: redundant joints — the self-stress, the independent rows, their grip.
//! * [`singular`]: the joints' conditioning `κ(G_v M⁻¹ G_vᵀ)` (how near `G_v` is to losing rank).
//! * [`coordinates`]: a partition of coordinates and velocities, and its Newton's limits.
//! * `causal`: the causality's partition at a configuration (what `graph --causality` draws).
//! * [`thresholds`]: every threshold, with the reason for its value, and [`PartitionPolicy`].

pub mod amplification;
pub(crate) mod causal;
pub mod condition;
pub mod coordinates;
pub mod grip;
pub mod redundancy;
pub mod select;
pub mod singular;
pub use crate::thresholds;

pub use condition::{
    block_condition_bound, dependent_condition, dependent_condition_bound,
    dependent_condition_bound_factors,
};
pub use coordinates::{
    always_measured_velocities, preferred_coordinates, Partition, PartitionError,
};
pub use grip::{block_lu, block_smallest_squared, JointRows, KeptBlockLu, SpectralHints};
pub use redundancy::{
    independent_rows, independent_rows_of_stress, redundant_row_grip, SelfStress,
};
pub use select::select_dependent;
pub use singular::{
    dense_joint_condition_number, joint_condition_number, joint_conditioning,
    sparse_joint_condition_number, sparse_joint_condition_number_of, JointConditioning,
};
pub use thresholds::{Decision, PartitionPolicy};
