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
    Path(Box<PathError>),
    /// The scene file could not be read.
    #[error("cannot read scene file '{}': {source}", path.display())]
    Io {
        /// The file that could not be read.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The scene text is empty: an empty file, or standard input closed or empty.
    #[error("'{}' is empty: a scene is a JSON object ({{\"bodies\": [...], ...}} or {{\"bond_graph\": {{...}}}}, docs/scene-format.md)", path.display())]
    Empty {
        /// The file (or `standard input`).
        path: PathBuf,
    },
    /// The bytes read are not JSON text: a NUL byte (binary data, a device such as
    /// `/dev/zero`, refused as soon as it is read) or bytes that are not UTF-8.
    #[error("'{}': byte {offset} {why}", path.display())]
    NotText {
        /// The file (or `standard input`).
        path: PathBuf,
        /// Offset of the first offending byte.
        offset: usize,
        /// What the byte says about the data.
        why: &'static str,
    },
}

impl SceneError {
    /// The problems of an invalid scene (empty for an I/O error).
    pub fn problems(&self) -> &[Problem] {
        match self {
            SceneError::Invalid { problems } => problems,
            SceneError::Io { .. }
            | SceneError::Path(_)
            | SceneError::Empty { .. }
            | SceneError::NotText { .. } => &[],
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
    /// Problems reported after the meaning stage has run (a subnormal number: the field's own
    /// range check, when it has one, speaks instead).
    pub(crate) deferred: Vec<Problem>,
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

impl From<PathError> for SceneError {
    fn from(e: PathError) -> SceneError {
        SceneError::Path(Box::new(e))
    }
}

/// Why a path or an assignment could not be parsed or applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PathError {
    /// The path text is malformed.
    #[error("bad scene path '{path}': {message}")]
    Syntax {
        /// The path as given.
        path: String,
        /// What is wrong (with the character position).
        message: String,
    },
    /// An assignment is not `PATH=JSON`, or its value is not JSON.
    #[error("bad assignment '{assignment}': {message}")]
    Assignment {
        /// The assignment as given.
        assignment: String,
        /// What is wrong.
        message: String,
    },
    /// A key is not there (and could not be added, because an index follows it).
    #[error(
        "{path}: no key '{key}' in {} (keys there: {})",
        where_(at),
        list(available)
    )]
    UnknownKey {
        /// The whole path.
        path: String,
        /// The path of the object searched (empty: the scene).
        at: String,
        /// The missing key.
        key: String,
        /// The keys the object has.
        available: Vec<String>,
    },
    /// An index past the end of an array.
    #[error("{path}: index {index} out of range: {} has {len} entries", where_(at))]
    IndexOutOfRange {
        /// The whole path.
        path: String,
        /// The path of the array.
        at: String,
        /// The index asked for.
        index: usize,
        /// The array's length.
        len: usize,
    },
    /// No entry of an array has this `"name"`.
    #[error(
        "{path}: no entry named '{name}' in {} (names there: {})",
        where_(at),
        list(names)
    )]
    UnknownName {
        /// The whole path.
        path: String,
        /// The path of the array.
        at: String,
        /// The name asked for.
        name: String,
        /// The names present.
        names: Vec<String>,
    },
    /// A key or index applied to something that has none (a number, a string, …).
    #[error("{path}: {} is {found}, it has no {wanted}", where_(at))]
    NotContainer {
        /// The whole path.
        path: String,
        /// The path of the value.
        at: String,
        /// Its JSON type (`a number`, `an array`, …).
        found: String,
        /// What the segment needs (`key 'mass'`, `index 1`, `entry named 'bar2'`).
        wanted: String,
    },
}

fn where_(at: &str) -> String {
    if at.is_empty() {
        "the scene".into()
    } else {
        format!("'{at}'")
    }
}

fn list(v: &[String]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

/// Why a name that becomes part of an output column (a body, point, joint or driver name)
/// may not hold a comma: column lists (`--columns`, `outputs`, the service's `output=`) are
/// comma-separated, and a CSV header cell holding one must be quoted, which tools reading the
/// header by splitting it on commas get wrong.
pub fn comma_in_name(name: &str) -> String {
    format!(
        "'{name}' must not contain ',' (it names output columns, and column lists and CSV headers are comma-separated)"
    )
}
