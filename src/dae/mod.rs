//! What every formulation of a multibody system shares, below the partition
//! ([`crate::partition`]) and the formulations themselves ([`crate::solve::formulation`]):
//!
//! * [`mechanics`]: the constraint calculus (`g`, `G_q`, `G_v`, `γ`) and the mechanics rows
//!   `M a − Q + G_vᵀ λ` and `G_v a + γ`, written once for every formulation and analysis.
//! * [`init`]: consistent initial values (projection onto the joints).
//! * [`gram`]: sparse `G W Gᵀ` with its Cholesky factor (the consistent start of large mechanisms).
//! * [`block_lu`]: the dependent block's dense LU, planned once per partition.
//! * [`compiled`]: residuals and right-hand sides compiled to tapes with exact Jacobians.

pub mod block_lu;
pub mod compiled;
pub mod gram;
pub mod init;
pub mod mechanics;

pub use compiled::{ExplicitOde, ImplicitDae, Workspace};
pub use init::{
    consistent_state, consistent_state_from, rank_loss_persists, ConsistentState, InitError,
};
pub use mechanics::{ConstraintExprs, MatrixTape, MechanicsTapes};
