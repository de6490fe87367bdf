//! The error of a mechanism that cannot be built, with the JSON path of the culprit.

/// A mechanism that cannot be built, with the JSON path of the culprit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct MechError {
    /// JSON path of the offending field, e.g. `joints[1].points[0]`.
    pub path: String,
    /// What is wrong.
    pub message: String,
}

impl MechError {
    /// An error at `path`.
    pub fn at(path: &str, message: impl Into<String>) -> Self {
        MechError {
            path: path.to_string(),
            message: message.into(),
        }
    }
}
