//! The one public error type.
//!
//! Every fallible call of the library returns [`Result<T>`](Result), that is
//! `Result<T, bondmech::Error>`, except a few lower-level entry points that keep their own,
//! more detailed error type: [`Scene::from_json_str`](crate::scene::Scene::from_json_str),
//! [`Scene::from_path`](crate::scene::Scene::from_path) and `Scene::validate` return
//! [`SceneError`] (every problem with its JSON path), the [`sundials`](crate::sundials)
//! wrappers return [`SolverError`]. Each of these converts into [`Error`] through `From`,
//! so `?` works in a function returning `bondmech::Result`:
//!
//! ```
//! use bondmech::{Error, Model, Scene};
//!
//! fn steps(scene_json: &str) -> bondmech::Result<u64> {
//!     let scene = Scene::from_json_str(scene_json)?; // SceneError → Error::Scene
//!     let model = Model::new(&scene)?;
//!     Ok(model.solve(&model.default_options())?.summary.steps)
//! }
//!
//! let bad = r#"{"bodies": [{"name": "b", "mass": -1, "inertia": 1}], "solve": {"t_end": 1}}"#;
//! let Err(Error::Scene(e)) = steps(bad) else { panic!("a scene error") };
//! assert!(e.to_string().contains("bodies[0].mass"), "{e}"); // names the JSON path
//! ```

use crate::dae::InitError;
use crate::mech::MechError;
use crate::report::ReportError;
use crate::scene::SceneError;
use crate::solve::error::kept;
use crate::solve::SolveError;
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
    /// A load of the scene (or a parameter or law of a raw bond graph element) evaluates to NaN
    /// or ±∞ during the solve: which one (JSON path, name, expression) and when.
    #[error("{culprit}{}", if *stuck { "; the solver cannot step past it" } else { "" })]
    NonFinite {
        /// The culprit, its value and the time.
        culprit: Box<crate::mech::NonFiniteValue>,
        /// Whether the solver's steps piled up against it (rather than failing otherwise).
        stuck: bool,
        /// The solver's own error.
        #[source]
        solver: Box<SolverError>,
    },
    /// The model would not fit in this machine's memory (estimated before building it).
    #[error("{0}")]
    TooLarge(#[from] crate::mech::size::SizeError),
    /// Invalid solve options.
    #[error("invalid options: {0}")]
    Options(String),
    /// No static equilibrium was found (why in the message).
    #[error("{0}")]
    Equilibrium(#[from] crate::analysis::equilibrium::EquilibriumError),
    /// No linear model at the operating point, or a bad request for one (what in the message).
    #[error("{0}")]
    Linearize(#[from] crate::analysis::linear_model::LinearizeError),
    /// An output path refused before anything is computed (an input, given twice, not
    /// writable).
    #[error("{0}")]
    Output(#[from] crate::output::OutputError),
    /// A report (an animation, a plot, a reference table, a parameter sweep, one of its shards
    /// or their merge) was refused (what and where in the message).
    #[error("{0}")]
    Report(Box<ReportError>),
    /// A raw bond graph is invalid or cannot be turned into equations.
    #[error("bond graph: {0}")]
    BondGraph(String),
    /// A sensitivity run or a fit was refused or failed (the parameter's path or the data's
    /// column in the message).
    #[error("{0}")]
    Sensitivity(Box<crate::analysis::sensitivity::SensitivityError>),
    /// The solve stopped before its last output time — a budget (`max_steps`,
    /// `max_wall_seconds`) ran out or the solver failed — and kept what it had computed:
    /// `partial` holds the rows up to the time reached (its summary has `completed: false`,
    /// `t_reached` and `stopped_by`).
    #[error("{cause}; {}", kept(partial))]
    Incomplete {
        /// Why the solve stopped.
        cause: Box<Error>,
        /// The rows computed up to the time reached, and the statistics so far.
        partial: Box<crate::solve::Solution>,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}

/// A solve's error at the top: each variant of [`SolveError`] as the same variant here (same
/// message), the cause of a solve stopped part-way converted likewise.
impl From<SolveError> for Error {
    fn from(e: SolveError) -> Self {
        match e {
            SolveError::Init(e) => Error::Init(e),
            SolveError::Mechanism(e) => Error::Mechanism(e),
            SolveError::Solver(e) => Error::Solver(e),
            SolveError::NonFinite {
                culprit,
                stuck,
                solver,
            } => Error::NonFinite {
                culprit,
                stuck,
                solver,
            },
            SolveError::Options(m) => Error::Options(m),
            SolveError::BondGraph(m) => Error::BondGraph(m),
            SolveError::Incomplete { cause, partial } => Error::Incomplete {
                cause: Box::new(Error::from(*cause)),
                partial,
            },
        }
    }
}

impl Error {
    /// The rows computed before the solve stopped, when it stopped part-way.
    pub fn partial_solution(&self) -> Option<&crate::solve::Solution> {
        match self {
            Error::Incomplete { partial, .. } => Some(partial),
            _ => None,
        }
    }

    /// Applies `f` to the partial solution of an [`Error::Incomplete`]; other errors pass.
    pub fn map_partial(mut self, f: impl FnOnce(&mut crate::solve::Solution)) -> Self {
        if let Error::Incomplete { partial, .. } = &mut self {
            f(partial);
        }
        self
    }
}

impl From<ReportError> for Error {
    /// A report's file error stays an [`Error::Io`] (the caller's I/O class); the rest is
    /// [`Error::Report`].
    fn from(e: ReportError) -> Error {
        match e {
            ReportError::Io { path, source } => Error::Io { path, source },
            other => Error::Report(Box::new(other)),
        }
    }
}

impl From<crate::report::vary::VaryError> for Error {
    fn from(e: crate::report::vary::VaryError) -> Error {
        Error::Report(Box::new(e.into()))
    }
}

/// `Result` with bondmech's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl From<crate::analysis::sensitivity::SensitivityError> for Error {
    fn from(e: crate::analysis::sensitivity::SensitivityError) -> Self {
        Error::Sensitivity(Box::new(e))
    }
}
