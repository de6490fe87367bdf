//! Formulations of a multibody system as equations for SUNDIALS, one module each; the implicit
//! ones offer IDA's runner one interface, [`DaeFormulation`].
//!
//! * [`mechanics`]: the constraint calculus (`g`, `G_q`, `G_v`, `γ`) shared by all formulations.
//! * [`init`]: consistent initial values (projection onto the joints).
//! * [`ggl`]: stabilized index-2 DAE (Gear–Gupta–Leimkuhler), plain or compliant, for IDA.
//! * [`index1`]: index-1 with dummy derivatives (dependent velocities re-selected as needed).
//! * [`singular`]: conditioning of the joints (how near `G_v` is to losing rank).
//! * [`partitioned`]: the degrees of freedom as ODE states (dependent coordinates by Newton).
//! * [`decoupled`]: the stiff-spring twin (seed 16.6), an ODE for CVODE.
//! * [`raw_graph`]: the velocity-level index-2 and index-1 DAEs (or the ODE) of a raw bond graph.
//! * [`gram`]: sparse `G W Gᵀ` with its Cholesky factor (the consistent start of large mechanisms).
//! * [`compiled`]: residuals and right-hand sides compiled to tapes with exact Jacobians.

pub mod amplification;
pub mod block_lu;
pub mod compiled;
pub mod decoupled;
pub mod elimination;
pub mod formulation;
pub mod ggl;
pub mod gram;
pub mod index1;
pub mod init;
pub mod mechanics;
pub mod partition;
pub mod partitioned;
pub mod raw_graph;
pub mod singular;

pub use compiled::{ExplicitOde, ImplicitDae, Workspace};
pub use decoupled::DecoupledFormulation;
pub use formulation::{DaeFormulation, GglDae, IdDae};
pub use ggl::GglFormulation;
pub use index1::{
    block_condition_bound, dependent_condition, dependent_condition_bound,
    dependent_condition_bound_factors, independent_rows, independent_rows_of_stress,
    redundant_row_grip, select_dependent, EnergyInvariant, Index1Formulation, JointRows,
    SelfStress,
};
pub use init::{
    consistent_state, consistent_state_from, rank_loss_persists, ConsistentState, InitError,
};
pub use mechanics::{ConstraintExprs, MatrixTape, MechanicsTapes};
pub use partitioned::{Partition, PartitionError, PartitionedRhs, PartitionedSystem};
pub use singular::{
    dense_joint_condition_number, joint_condition_number, joint_conditioning,
    sparse_joint_condition_number, sparse_joint_condition_number_of, JointConditioning,
};
