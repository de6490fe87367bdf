//! Scene errors: every problem names the JSON path of the offending field.
//!
//! A path is written the way a user would point at the field in the file:
//! `bodies[2].inertia`, `joints[0].points[1]`, `solve.rtol`. Document-level
//! problems (malformed JSON, a non-object scene) have an empty path.

use std::fmt;
use std::path::PathBuf;

/// One problem found in a scene: where it is and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// JSON path of the field, e.g. `bodies[2].inertia`; empty for the whole document.
    pub path: String,
    /// What is wrong, e.g. `must be >= 0 (got -1)`.
    pub message: String,
}

impl Problem {
    /// A problem at `path` with `message`.
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Problem {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.path.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.path, self.message)
        }
    }
}

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The scene text was read but is not a valid scene; every problem found is listed.
    #[error("{}", join_lines(problems))]
    Invalid {
        /// All problems found, in document order (structural problems first).
        problems: Vec<Problem>,
    },
    /// A `PATH=JSON` assignment (`--set`, `sweep --vary`) could not be parsed or applied.
    #[error("{0}")]
    Path(Box<super::path::PathError>),
    /// The scene file could not be read.
    #[error("cannot read scene file '{}': {source}", path.display())]
    Io {
        /// The file that could not be read.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
}

impl SceneError {
    /// The problems of an invalid scene (empty for an I/O error).
    pub fn problems(&self) -> &[Problem] {
        match self {
            SceneError::Invalid { problems } => problems,
            SceneError::Io { .. } | SceneError::Path(_) => &[],
        }
    }
}

fn join_lines(problems: &[Problem]) -> String {
    problems
        .iter()
        .map(Problem::to_string)
        .collect::<Vec<_>>()
        .join("\n")
}

/// Collects problems while walking a scene, keeping track of the current JSON path.
#[derive(Debug, Default)]
pub(crate) struct Problems {
    pub(crate) list: Vec<Problem>,
}

impl Problems {
    /// Records a problem at `path`.
    pub(crate) fn push(&mut self, path: impl Into<String>, message: impl Into<String>) {
        self.list.push(Problem::new(path, message));
    }
}

/// `parent.key`, or `key` when `parent` is the document root.
pub(crate) fn field(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// `parent[i]`.
pub(crate) fn index(parent: &str, i: usize) -> String {
    format!("{parent}[{i}]")
}

impl From<super::path::PathError> for SceneError {
    fn from(e: super::path::PathError) -> SceneError {
        SceneError::Path(Box::new(e))
    }
}
