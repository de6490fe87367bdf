//! Output files: checked before any work is done, written atomically, CSV by the `csv` crate.
//!
//! * [`check_outputs`] and [`check_output_dir`] refuse, before a solve, an output that is an
//!   input (the same file by device and inode, so a hard link or a symbolic link of the scene
//!   is caught as well as its path), an output given twice, and a file or directory that
//!   cannot be written or made — naming the flag.
//! * [`AtomicFile`] writes a regular file (or a path that does not exist yet) beside the target
//!   (a temporary file in the same directory) and renames it into place when complete: a run
//!   killed mid-write leaves the previous file (or no file), never a file cut mid-row. Writing
//!   through a symbolic link replaces the file it points to and keeps the link. Anything else
//!   — a device such as `/dev/null`, a FIFO, a socket — is written in place, streaming, and is
//!   never renamed over: replacing `/dev/null` with a regular file would break every program
//!   on the machine. Every write, the final flush and the sync are checked: a full device or
//!   disk is an error naming the file, never a success with a truncated file.
//! * [`CsvRows`] writes a trajectory (`t`, then the columns) row by row through the `csv`
//!   crate, so names holding a comma or a quote are quoted per RFC 4180 and memory stays
//!   bounded whatever the number of rows.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Why an output path is refused before anything is computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The output is one of the command's inputs (same path, hard link or symbolic link).
    #[error("{flag} {}: is an input of this command ({}, {how}); refusing to overwrite it", .path.display(), .input.display())]
    IsInput {
        /// The flag (`--out`, `--summary`, …).
        flag: String,
        /// The output path as given.
        path: PathBuf,
        /// The input it is.
        input: PathBuf,
        /// `the same path`, `the same file: a hard or symbolic link`.
        how: &'static str,
    },
    /// Two outputs are the same file.
    #[error("{flag} {}: is also given to {other}; give each output its own file", .path.display())]
    Repeated {
        /// The flag.
        flag: String,
        /// The path.
        path: PathBuf,
        /// The other flag.
        other: String,
    },
    /// The output cannot be written (missing directory, a directory in place of a file, no
    /// permission, a file in place of a directory).
    #[error("{flag} {}: {why}", .path.display())]
    NotWritable {
        /// The flag.
        flag: String,
        /// The path.
        path: PathBuf,
        /// What is in the way.
        why: String,
    },
}

/// Device and inode of the file at `path` (following symbolic links), if it exists.
pub fn file_id(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

/// Whether `a` and `b` name the same file: the same device and inode when both exist (a hard
/// link, a symbolic link, another spelling of the path), else the same absolute path.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (file_id(a), file_id(b)) {
        (Some(x), Some(y)) => x == y,
        (None, None) => resolved(a) == resolved(b),
        _ => false,
    }
}

/// `path` made absolute without requiring it to exist (its parent is resolved when it exists).
pub fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match (parent.canonicalize(), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

/// Refuses an output file equal to an input (by device and inode, or by path when it does not
/// exist yet) or to another output, and one that cannot be written (a missing directory, a
/// directory in place of a file, no permission) — before anything is solved, so that no result
/// is computed only to be lost. `-` (standard input) is not a file.
pub fn check_outputs(
    inputs: &[&Path],
    outputs: &[(&str, Option<&Path>)],
) -> Result<(), OutputError> {
    let inputs: Vec<&Path> = inputs
        .iter()
        .copied()
        .filter(|p| *p != Path::new("-"))
        .collect();
    let mut seen: Vec<(&str, &Path)> = Vec::new();
    for (flag, path) in outputs {
        let Some(path) = path else { continue };
        for input in &inputs {
            if same_file(path, input) {
                let link =
                    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
                let how = if link {
                    "the same file: a symbolic link to it"
                } else if resolved(path) == resolved(input) {
                    "the same path"
                } else {
                    "the same file: a hard link to it"
                };
                return Err(OutputError::IsInput {
                    flag: flag.to_string(),
                    path: path.to_path_buf(),
                    input: input.to_path_buf(),
                    how,
                });
            }
        }
        if let Some((other, _)) = seen.iter().find(|(_, q)| same_file(path, q)) {
            return Err(OutputError::Repeated {
                flag: flag.to_string(),
                path: path.to_path_buf(),
                other: other.to_string(),
            });
        }
        writable(flag, path)?;
        seen.push((flag, path));
    }
    Ok(())
}

/// Whether a file can be written at `path` (beside it, then renamed: [`AtomicFile`]) without
/// creating or changing it now.
fn writable(flag: &str, path: &Path) -> Result<(), OutputError> {
    let refuse = |why: String| {
        Err(OutputError::NotWritable {
            flag: flag.to_string(),
            path: path.to_path_buf(),
            why,
        })
    };
    if path.is_dir() {
        return refuse("is a directory".into());
    }
    let target = write_target(path);
    match std::fs::metadata(&target) {
        // a FIFO: opening it for writing waits for its reader, so it is not opened now
        Ok(m) if is_fifo(&m) => return Ok(()),
        // a device or socket is written in place: only the node itself must be writable
        Ok(m) if !m.is_file() => {
            return match std::fs::OpenOptions::new().write(true).open(&target) {
                Ok(_) => Ok(()),
                Err(e) => refuse(format!("cannot be written ({e})")),
            }
        }
        _ => {}
    }
    if target.exists() {
        if let Err(e) = std::fs::OpenOptions::new().append(true).open(&target) {
            return refuse(format!("cannot be written ({e})"));
        }
    }
    let dir = parent_dir(&target);
    if !dir.is_dir() {
        return refuse(format!("directory {} does not exist", dir.display()));
    }
    probe_dir(&dir).or_else(|e| {
        refuse(format!(
            "directory {} cannot be written ({e}); the file is written beside its target and renamed into place",
            dir.display()
        ))
    })
}

/// Refuses an output directory (`--plot DIR`, a sweep's `--out DIR`) that cannot be made or
/// written, or that is an input — before anything is solved. A missing directory is fine when
/// its nearest existing ancestor is a writable directory (it is created when written to).
pub fn check_output_dir(flag: &str, dir: &Path, inputs: &[&Path]) -> Result<(), OutputError> {
    let refuse = |why: String| {
        Err(OutputError::NotWritable {
            flag: flag.to_string(),
            path: dir.to_path_buf(),
            why,
        })
    };
    for input in inputs.iter().filter(|p| **p != Path::new("-")) {
        if same_file(dir, input) {
            return Err(OutputError::IsInput {
                flag: flag.to_string(),
                path: dir.to_path_buf(),
                input: input.to_path_buf(),
                how: "the same file",
            });
        }
    }
    // the nearest ancestor that exists must be a directory we can write into
    let mut existing = dir;
    while !existing.as_os_str().is_empty() && std::fs::symlink_metadata(existing).is_err() {
        match existing.parent() {
            Some(p) => existing = p,
            None => break,
        }
    }
    let existing = if existing.as_os_str().is_empty() {
        Path::new(".")
    } else {
        existing
    };
    if !existing.is_dir() {
        return refuse(if existing == dir {
            "is a file, not a directory".into()
        } else {
            format!(
                "cannot be made: {} is a file, not a directory",
                existing.display()
            )
        });
    }
    probe_dir(existing)
        .or_else(|e| refuse(format!("{} cannot be written ({e})", existing.display())))
}

/// Creates and removes a temporary file in `dir`.
fn probe_dir(dir: &Path) -> io::Result<()> {
    tempfile::Builder::new()
        .prefix(".bondmech-probe-")
        .tempfile_in(dir)
        .map(drop)
}

/// The directory of `path` (`.` for a bare file name).
fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Where writing `path` lands: the file a symbolic link points to (so the link is kept),
/// else `path` itself.
fn write_target(path: &Path) -> PathBuf {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => path.canonicalize().unwrap_or_else(|_| {
            // a dangling link: write where it points
            std::fs::read_link(path)
                .map(|t| parent_dir(path).join(t))
                .unwrap_or_else(|_| path.to_path_buf())
        }),
        _ => path.to_path_buf(),
    }
}

/// Whether `m` is a FIFO (named pipe).
fn is_fifo(m: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    m.file_type().is_fifo()
}

/// Where an [`AtomicFile`]'s bytes go.
enum Sink {
    /// A temporary file beside a regular target, renamed over it by the commit.
    Temp(tempfile::NamedTempFile),
    /// The target itself, opened for writing: a device, a FIFO or a socket (never renamed over).
    InPlace(std::fs::File),
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Sink::Temp(f) => f.write(buf),
            Sink::InPlace(f) => f.write(buf),
        }
    }
    fn flush(&mut self) -> io::Result<()> {
        match self {
            Sink::Temp(f) => f.flush(),
            Sink::InPlace(f) => f.flush(),
        }
    }
}

/// The temporary files of the [`AtomicFile`]s being written, for [`remove_temporaries`].
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn temporaries() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes the temporary files of every [`AtomicFile`] still being written, leaving their
/// targets as they were: for a program about to exit at once (a second Ctrl-C), which runs no
/// destructor. Returns how many were removed.
pub fn remove_temporaries() -> usize {
    temporaries()
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// A temporary file listed for [`remove_temporaries`] while it lives.
struct Listed(Option<PathBuf>);

impl Listed {
    fn new(path: Option<&Path>) -> Listed {
        if let Some(p) = path {
            temporaries().push(p.to_path_buf());
        }
        Listed(path.map(Path::to_path_buf))
    }
}

impl Drop for Listed {
    fn drop(&mut self) {
        if let Some(p) = &self.0 {
            let mut list = temporaries();
            if let Some(i) = list.iter().position(|q| q == p) {
                list.swap_remove(i);
            }
        }
    }
}

/// An output file: a regular file written beside its target and renamed into place by
/// [`AtomicFile::commit`] (dropped without a commit, on an error or a panic, the temporary file
/// is removed and the target is left as it was), or a device, FIFO or socket written in place.
/// Its temporary file is listed for [`remove_temporaries`] until it is renamed or removed.
pub struct AtomicFile {
    target: PathBuf,
    file: io::BufWriter<Sink>,
    listed: Listed,
}

impl AtomicFile {
    /// Starts writing `path`: for a regular file (or a new one), a temporary file
    /// `.NAME.XXXXXX.tmp` in the same directory, with the permissions of the file it replaces
    /// (or the usual ones, umask applied); for a device, FIFO or socket, the node itself
    /// (a FIFO's open waits for its reader, as a shell's `>` does).
    pub fn create(path: &Path) -> io::Result<AtomicFile> {
        use std::os::unix::fs::PermissionsExt;
        let target = write_target(path);
        let meta = std::fs::metadata(&target).ok();
        if meta.as_ref().is_some_and(|m| !m.is_file() && !m.is_dir()) {
            let file = std::fs::OpenOptions::new().write(true).open(&target)?;
            return Ok(AtomicFile {
                target,
                file: io::BufWriter::with_capacity(1 << 16, Sink::InPlace(file)),
                listed: Listed::new(None),
            });
        }
        let dir = parent_dir(&target);
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "output".into());
        let mode = meta.map_or(0o666, |m| m.permissions().mode() & 0o7777);
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .permissions(std::fs::Permissions::from_mode(mode))
            .tempfile_in(&dir)?;
        Ok(AtomicFile {
            target,
            listed: Listed::new(Some(tmp.path())),
            file: io::BufWriter::with_capacity(1 << 16, Sink::Temp(tmp)),
        })
    }

    /// Flushes and syncs the bytes, then renames a temporary file into place. A write error
    /// (a full disk or device) is returned, and the temporary file removed.
    pub fn commit(self) -> io::Result<()> {
        let AtomicFile {
            target,
            file,
            listed,
        } = self;
        match file.into_inner().map_err(|e| e.into_error())? {
            Sink::Temp(tmp) => {
                tmp.as_file().sync_all()?;
                tmp.persist(&target).map_err(|e| e.error)?;
                drop(listed);
            }
            Sink::InPlace(f) => match f.sync_all() {
                // a character device, FIFO or socket has nothing to sync (EINVAL)
                Err(e) if e.raw_os_error() == Some(22) => {}
                other => other?,
            },
        }
        Ok(())
    }

    /// The file this writes (the target of a symbolic link).
    pub fn target(&self) -> &Path {
        &self.target
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

/// Writes `bytes` to `path` atomically ([`AtomicFile`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes)?;
    f.commit()
}

/// A trajectory CSV written row by row: header `t,<columns>` (names quoted per RFC 4180 when
/// they hold a comma, a quote or a line break), then `t` as the shortest decimal that reads
/// back exactly and every value with 17 significant digits.
pub struct CsvRows<W: Write> {
    csv: csv::Writer<W>,
    columns: usize,
}

impl<W: Write> CsvRows<W> {
    /// Writes the header.
    pub fn new(w: W, columns: &[String]) -> io::Result<CsvRows<W>> {
        let mut csv = csv::WriterBuilder::new()
            .flexible(false)
            .buffer_capacity(1 << 16)
            .from_writer(w);
        csv.write_field("t").map_err(csv_io)?;
        for c in columns {
            csv.write_field(c).map_err(csv_io)?;
        }
        csv.write_record(None::<&[u8]>).map_err(csv_io)?;
        Ok(CsvRows {
            csv,
            columns: columns.len(),
        })
    }

    /// Writes one row (`values` in the header's order).
    pub fn row(&mut self, t: f64, values: &[f64]) -> io::Result<()> {
        if values.len() != self.columns {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "a row of {} values for {} columns",
                    values.len(),
                    self.columns
                ),
            ));
        }
        let mut buf = String::with_capacity(32);
        use std::fmt::Write as _;
        let _ = write!(buf, "{t}");
        self.csv.write_field(&buf).map_err(csv_io)?;
        for v in values {
            buf.clear();
            let _ = write!(buf, "{v:.17e}");
            self.csv.write_field(&buf).map_err(csv_io)?;
        }
        self.csv.write_record(None::<&[u8]>).map_err(csv_io)
    }

    /// Flushes and returns the writer.
    pub fn finish(self) -> io::Result<W> {
        self.csv.into_inner().map_err(|e| e.into_error())
    }
}

/// The I/O error inside a `csv` error (the writer only fails on I/O).
fn csv_io(e: csv::Error) -> io::Error {
    match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => io::Error::other(format!("{other:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_with_a_comma_is_quoted() {
        let mut w = CsvRows::new(Vec::new(), &["b.P,1.x".into(), "e".into()]).unwrap();
        w.row(0.5, &[1.0, 2.0]).unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        assert_eq!(
            text,
            "t,\"b.P,1.x\",e\n0.5,1.00000000000000000e0,2.00000000000000000e0\n"
        );
    }
}
