//! A command's failure: the library's error with what the command still managed to do, and
//! the failures the command line names itself.

use bondmech::Error;

/// A failure of a command, with what the command still managed to do (e.g. where the rows of
/// a run stopped part-way were written).
pub(crate) struct CliError {
    pub(crate) error: Error,
    pub(crate) note: Option<String>,
}

impl From<Error> for CliError {
    fn from(error: Error) -> Self {
        CliError { error, note: None }
    }
}

impl From<bondmech::report::ReportError> for CliError {
    fn from(e: bondmech::report::ReportError) -> Self {
        Error::from(e).into()
    }
}

impl From<bondmech::scene::SceneError> for CliError {
    fn from(e: bondmech::scene::SceneError) -> Self {
        Error::from(e).into()
    }
}

pub(crate) fn options_error(message: String) -> CliError {
    Error::Options(message).into()
}

pub(crate) fn is_broken_pipe(e: &Error) -> bool {
    matches!(e, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe)
}
