//! The one public error type.

use crate::dae::InitError;
use crate::mech::MechError;
use crate::scene::SceneError;
use crate::sundials::SolverError;

/// Everything that can go wrong in bondmech, each variant saying what and where.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The scene file is malformed or invalid (JSON paths in the message).
    #[error("{0}")]
    Scene(#[from] SceneError),
    /// The mechanism cannot be built (JSON path of the culprit).
    #[error("{0}")]
    Mechanism(#[from] MechError),
    /// No consistent initial state.
    #[error("initialisation: {0}")]
    Init(#[from] InitError),
    /// The solver failed (function, flag and time in the message).
    #[error("{0}")]
    Solver(#[from] SolverError),
    /// Invalid solve options.
    #[error("invalid options: {0}")]
    Options(String),
    /// A raw bond graph is invalid or cannot be turned into equations.
    #[error("bond graph: {0}")]
    BondGraph(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}

/// `Result` with bondmech's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
