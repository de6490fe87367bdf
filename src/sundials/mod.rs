//! Safe wrapper around SUNDIALS 6.4 (IDA for DAEs `F(t, y, y') = 0`, CVODE for
//! ODEs `y' = f(t, y)`), the only place in the crate that uses `unsafe`.
//!
//! Every solver owns its own `SUNContext`, so solvers are `Send` and nothing is
//! global. Callbacks are boxed Rust closures; panics and errors inside them are
//! caught and turned into [`SolverError`]s. Failing SUNDIALS return flags become
//! typed errors naming the function, flag and time reached.
//!
//! Table of contents:
//! - [`context`]: RAII `SUNContext`.
//! - [`vector`], [`matrix`], [`linsol`]: RAII serial `N_Vector`, dense `SUNMatrix`, dense `SUNLinearSolver`.
//! - [`dense_lu`]: the dense LU solver of the Newton iterations (compiled with the crate).
//! - [`schur`]: the Newton matrix by elimination of a block-lower-triangular dependent part
//!   and an LU of the Schur complement (the index-1 DAE's degrees of freedom).
//! - [`fast_ops`]: the serial vector kernels compiled with the crate (Debian builds SUNDIALS unoptimised).
//! - [`error`]: [`SolverError`], [`CallbackError`] and flag-name lookup.
//! - [`callback`]: panic-safe trampolines' shared state.
//! - [`options`]: [`IdaOptions`], [`CvodeOptions`], [`Step`], [`StepEvent`].
//! - [`stats`][]: [`SolverStats`].
//! - [`stepping`]: the `solve_to` loop of single internal steps with budgets and interpolation.
//! - [`ida`], [`cvode`]: the solvers; [`erk`]: ARKODE's explicit Runge–Kutta (ERKStep).
//! - [`sparse`]: [`CscPattern`], the CSC `SUNMatrix` and the sparse LU solvers (faer, KLU).
//! - [`custom_ls`]: [`IdaLinearSolver`], a user-supplied linear solver plugged into IDA.
//! - [`mod@version`]: linked library version.
//! - [`heap`]: bytes in use by `malloc`, for leak tests.

mod arkode_ffi;
pub mod callback;
mod calls;
pub mod context;
pub mod custom_ls;
pub mod cvode;
pub mod dense_lu;
pub mod erk;
pub mod error;
pub mod fast_ops;
pub mod heap;
pub mod ida;
pub mod linsol;
pub mod matrix;
pub mod options;
pub mod schur;
pub mod sparse;
pub mod stats;
pub mod stepping;
pub mod tables;
pub mod vector;
pub mod version;

pub use callback::{
    CvodeJacobianFn, CvodeRootFn, CvodeSparseJacobianFn, ErrorWeightFn, IdaJacobianFn, IdaRootFn,
    IdaSparseJacobianFn, ResidualFn, RhsFn,
};
pub use custom_ls::IdaLinearSolver;
pub use cvode::Cvode;
pub use erk::{Erk, ErkOptions};
pub use error::{CallbackError, CallbackResult, SolverError};
pub use ida::{Ida, SensResidualFn, SensStats};
pub use matrix::DenseMatrixMut;
pub use options::{CalcIc, CvodeOptions, IdaOptions, Multistep, Step, StepEvent};
pub use sparse::{
    solve_direct, solve_direct_ordered, solve_faer_sequence, ColumnOrdering, CscPattern,
    DirectSolver, FaerCounters, SparseMatrixMut, SparseSolver, REFACTOR_PIVOT_TOLERANCE,
};
pub use stats::{RecoveredFailure, SolverStats, MAX_LOGGED_FAILURES};
pub use version::{header_version, version};
