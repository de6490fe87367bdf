//! Writing a command's outputs: files atomically, standard output (a closed pipe comes back as
//! an error the command line ends on quietly), warnings to standard error, Graphviz drawings;
//! outputs checked before anything is solved.

use std::io::Write;
use std::path::Path;

use bondmech::Error;

/// Prints non-fatal remarks to standard error, one line each.
pub(crate) fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("bondmech: warning: {}", w.replace('\n', "; "));
    }
}

pub(crate) fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Writes `text` to `path` atomically (beside it, then renamed into place).
pub(crate) fn write(path: &Path, text: &str) -> Result<(), Error> {
    bondmech::output::write_atomic(path, text.as_bytes()).map_err(io_error(path))
}

/// Writes to standard output; a closed pipe comes back as a `BrokenPipe` I/O error.
pub(crate) fn stdout_write(text: &str) -> Result<(), Error> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(io_error(Path::new("standard output")))
}

/// Refuses an output that is an input (same path, hard or symbolic link), given twice, or
/// not writable — before anything is solved ([`bondmech::output::check_outputs`]).
pub(crate) fn check_outputs(
    inputs: &[&Path],
    outputs: &[(&str, Option<&Path>)],
) -> Result<(), Error> {
    Ok(bondmech::output::check_outputs(inputs, outputs)?)
}

/// Renders DOT to SVG with Graphviz, written atomically to `path`.
pub(crate) fn svg(dot: &str, path: &Path) -> Result<(), Error> {
    use std::io::Write;
    let mut child = std::process::Command::new("dot")
        .arg("-Tsvg")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| {
            Error::Options(format!(
                "cannot run Graphviz 'dot' ({e}): apt-get install graphviz, or write .dot"
            ))
        })?;
    let mut stdin = child.stdin.take().expect("piped stdin");
    let text = dot.to_string();
    // written from another thread: dot may fill its output pipe before reading all its input
    let feeder = std::thread::spawn(move || stdin.write_all(text.as_bytes()));
    let output = child.wait_with_output().map_err(|source| Error::Io {
        path: "dot".into(),
        source,
    })?;
    let fed = feeder.join().unwrap_or_else(|_| {
        Err(std::io::Error::other(
            "the thread writing to Graphviz 'dot' panicked",
        ))
    });
    if !output.status.success() {
        return Err(Error::Options(format!(
            "Graphviz 'dot' failed ({})",
            output.status
        )));
    }
    fed.map_err(|source| Error::Io {
        path: "dot".into(),
        source,
    })?;
    bondmech::output::write_atomic(path, &output.stdout).map_err(io_error(path))
}
