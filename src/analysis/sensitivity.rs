//! [`SensitivityError`]: every refusal of a sensitivity run or a fit names the parameter's path
//! or the data's column.

use crate::scene::SceneError;
use crate::solve::SolveError;
use crate::sundials::SolverError;

/// Why a sensitivity run or a fit cannot be done.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SensitivityError {
    /// The path names nothing in the scene, or not a number.
    #[error("--param {path}: {reason}")]
    Path {
        /// The path as given.
        path: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The parameter enters the equations in a way sensitivities are not computed for.
    #[error("--param {path}: {reason}")]
    Unsupported {
        /// The path.
        path: String,
        /// Why.
        reason: String,
    },
    /// The scene or its solve options cannot be run with sensitivities.
    #[error("{0}")]
    Scene(String),
    /// The scene with a parameter changed is not a valid scene.
    #[error("--param {path}: {source}")]
    Perturbed {
        /// The path.
        path: String,
        /// The scene's refusal.
        #[source]
        source: SceneError,
    },
    /// The mechanism cannot be built or solved.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The integrator failed.
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// The measured data are unusable (names the column or the row).
    #[error("data: {0}")]
    Data(String),
    /// The fit did not converge or its parameters are not identifiable.
    #[error("fit: {0}")]
    Fit(String),
}

impl From<crate::mech::MechError> for SensitivityError {
    fn from(e: crate::mech::MechError) -> Self {
        SensitivityError::Solve(SolveError::from(e))
    }
}
