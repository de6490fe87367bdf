//! What a report refuses, typed: the animation's and the plots' inputs, a reference table's
//! lines, the sweep shards ([`VaryError`]) and the files written. The crate's top-level
//! [`Error`](crate::error::Error) wraps it; reports import nothing above themselves.
//!
//! ```
//! use bondmech::report::{ReferenceProblem, ReportError};
//! let e = ReportError::Reference {
//!     origin: "ref.csv".into(),
//!     line: 3,
//!     problem: ReferenceProblem::TimesNotIncreasing { t: 0.1, prev: 0.2 },
//! };
//! assert_eq!(e.to_string(), "ref.csv line 3: times must increase (t = 0.1 after 0.2)");
//! ```

use super::shard::Shard;
use crate::scene::SceneError;

/// A report's refusal (the message names the input, the option or the line).
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A body's position or angle column is missing from the rows to animate.
    #[error(
        "{origin}: no column `{body}.{column}` for body `{body}` (a CSV written by `bondmech run` for this scene has it)"
    )]
    MissingColumn {
        /// Where the rows came from.
        origin: String,
        /// The body.
        body: String,
        /// The missing column's suffix (`x`, `y`, `z`, `angle`).
        column: &'static str,
    },
    /// A spatial body has neither quaternion nor Cardan-angle columns.
    #[error(
        "{origin}: no attitude columns for body `{body}` (`{body}.qw,{body}.qx,{body}.qy,{body}.qz` or `{body}.psi,{body}.theta,{body}.phi`)"
    )]
    MissingAttitude {
        /// Where the rows came from.
        origin: String,
        /// The body.
        body: String,
    },
    /// A joint or an output names a point the body does not have.
    #[error("body `{body}` has no point `{point}`")]
    MissingPoint {
        /// The body.
        body: String,
        /// The point's name.
        point: String,
    },
    /// Nothing to animate or plot.
    #[error("{origin}: no rows {purpose}")]
    NoRows {
        /// Where the rows came from.
        origin: String,
        /// What the rows were for (`to plot`, `to animate`, `at finite times to animate`).
        purpose: &'static str,
    },
    /// `--fps` and `--speed` ask for more frames than an animation holds.
    #[error(
        "--fps {fps} at --speed {speed} gives {frames} frames for {span} s of motion (at most {max}): lower --fps or raise --speed"
    )]
    TooManyFrames {
        /// Frames per second of playback.
        fps: f64,
        /// Playback speed.
        speed: f64,
        /// The frames asked for.
        frames: f64,
        /// The motion's duration (s).
        span: f64,
        /// The most frames an animation holds.
        max: usize,
    },
    /// The motion turns a body so fast that the frames it needs exceed the limit.
    #[error(
        "{origin}: the motion needs {frames} frames (at most {max}) so that no body turns more than {max_turn_degrees}° between frames: animate a shorter time (--t-end)"
    )]
    TooFastToAnimate {
        /// Where the rows came from.
        origin: String,
        /// The frames needed.
        frames: usize,
        /// The most frames an animation holds.
        max: usize,
        /// The most a body may turn between frames (degrees).
        max_turn_degrees: f64,
    },
    /// A raw bond graph has no geometry to draw.
    #[error("animate needs a scene with bodies (a raw bond graph has no geometry to draw)")]
    NoGeometry,
    /// A spatial scene without bodies or rows.
    #[error("animate needs a scene with bodies and rows to draw")]
    NothingToDraw,
    /// The 3D view got no frames.
    #[error("no frames to draw")]
    NoFrames,
    /// An option that must be positive is not.
    #[error("{option}: must be > 0 (got {value})")]
    NotPositive {
        /// The option (`--fps`, `--speed`).
        option: &'static str,
        /// Its value.
        value: f64,
    },
    /// The 3D view was asked for a planar scene.
    #[error("the 3D view needs a spatial scene (\"dimension\": 3); a planar scene is drawn in its xy view (SVG)")]
    NotSpatial,
    /// A planar scene asked for a view other than `xy`.
    #[error("--view {view}: a planar scene has only the xy view")]
    PlanarView {
        /// The view asked for.
        view: &'static str,
    },
    /// `--columns` names a column the solution does not have.
    #[error("--columns: no column `{pattern}` (the columns are {shown})")]
    UnknownColumn {
        /// The pattern that picked nothing.
        pattern: String,
        /// The first columns, for the message.
        shown: String,
    },
    /// A plot would be written over its own input.
    #[error("{path}: would overwrite the input; choose another --out directory")]
    WouldOverwrite {
        /// The file.
        path: String,
    },
    /// A reference table's line is wrong.
    #[error("{origin} line {line}: {problem}")]
    Reference {
        /// The table's name.
        origin: String,
        /// The file's own line number.
        line: u64,
        /// What is wrong with it.
        problem: ReferenceProblem,
    },
    /// A reference table has no header.
    #[error("{origin}: empty reference file")]
    EmptyReference {
        /// The table's name.
        origin: String,
    },
    /// A reference table has a header but no rows.
    #[error("{origin}: the reference has no rows")]
    NoReferenceRows {
        /// The table's name.
        origin: String,
    },
    /// The CSV reader refused a reference table.
    #[error("{origin}: {cause}")]
    Csv {
        /// The table's name.
        origin: String,
        /// The reader's error.
        cause: csv::Error,
    },
    /// A sweep, one of its shards or their merge was refused.
    #[error("{0}")]
    Vary(#[from] VaryError),
    /// A variation's scene path is wrong.
    #[error("{0}")]
    Scene(#[from] SceneError),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}

/// What is wrong with a line of a reference table.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceProblem {
    /// The first header name is neither `t` nor `time`.
    #[error("the header must start with `t` or `time` (got `{got}`)")]
    HeaderStart {
        /// The first name.
        got: String,
    },
    /// The header has only the time column.
    #[error("the header names no column after `t`")]
    NoColumns,
    /// A column name appears twice.
    #[error("column `{name}` appears twice")]
    DuplicateColumn {
        /// The name.
        name: String,
    },
    /// A row's length differs from the header's.
    #[error("{values} values for {columns} columns")]
    RowLength {
        /// The row's values.
        values: usize,
        /// The header's names.
        columns: usize,
    },
    /// A cell is not a number.
    #[error("column {column} (`{name}`): `{cell}` is not a number")]
    NotANumber {
        /// 1-based column.
        column: usize,
        /// The column's name.
        name: String,
        /// The cell.
        cell: String,
    },
    /// A cell is infinite or NaN.
    #[error("column {column} (`{name}`): {value} is not finite")]
    NotFinite {
        /// 1-based column.
        column: usize,
        /// The column's name.
        name: String,
        /// The value.
        value: f64,
    },
    /// Times do not increase.
    #[error("times must increase (t = {t} after {prev})")]
    TimesNotIncreasing {
        /// This row's time.
        t: f64,
        /// The previous row's.
        prev: f64,
    },
}

/// Why a parameter sweep, a shard or a merge was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum VaryError {
    /// `--shard` is not `i/n` with `1 <= i <= n`.
    #[error("--shard '{text}': {why} (expected i/n with 1 <= i <= n, e.g. 3/8)")]
    BadShard {
        /// The flag's value.
        text: String,
        /// What is wrong.
        why: String,
    },
    /// A point's values make an invalid scene.
    #[error("sweep point {index} ({values}): {message}")]
    BadPoint {
        /// Point number (from 0).
        index: usize,
        /// Its values, `PATH=VALUE, …`.
        values: String,
        /// The scene's problems, with their paths.
        message: String,
    },
    /// `--columns` names a column the runs do not write.
    #[error("--columns: no column '{column}' (the runs write: {available})")]
    UnknownColumn {
        /// The column asked for.
        column: String,
        /// The columns there are, comma-separated.
        available: String,
    },
    /// The reference cannot be used for this scene.
    #[error("sweep: the reference {source_name} {message}")]
    Reference {
        /// Where the reference came from.
        source_name: String,
        /// What is wrong.
        message: String,
    },
    /// A directory given to `sweep-merge` holds no readable result.
    #[error("{dir}: {message}")]
    NotAResult {
        /// The directory (or file).
        dir: String,
        /// What is wrong.
        message: String,
    },
    /// A directory given to `sweep-merge` holds a whole sweep.
    #[error("sweep-merge: {dir} holds a whole sweep, not a shard (written without --shard)")]
    WholeSweep {
        /// The directory.
        dir: String,
    },
    /// Two shards come from different sweeps.
    #[error("sweep-merge: {first} (fingerprint {first_fingerprint}) and {other} (fingerprint {other_fingerprint}) are shards of different sweeps: {difference}")]
    DifferentSweeps {
        /// The first directory.
        first: String,
        /// Its fingerprint.
        first_fingerprint: String,
        /// The other directory.
        other: String,
        /// Its fingerprint.
        other_fingerprint: String,
        /// What differs.
        difference: String,
    },
    /// A shard's fingerprint does not match its spec.
    #[error("sweep-merge: {dir}: the fingerprint does not match its spec (edited by hand?)")]
    FingerprintMismatch {
        /// The directory.
        dir: String,
    },
    /// Shards of different splits (`1/3` and `2/4`).
    #[error("sweep-merge: {dir} is shard {shard} but {first} is a shard of {count}: every shard must come from the same --shard i/n split")]
    ShardCountMismatch {
        /// The directory.
        dir: String,
        /// Its shard.
        shard: Shard,
        /// The first directory.
        first: String,
        /// The first directory's shard count.
        count: usize,
    },
    /// The same shard twice.
    #[error("sweep-merge: shard {shard} given twice: {first} and {second}")]
    DuplicateShard {
        /// The shard.
        shard: Shard,
        /// One directory holding it.
        first: String,
        /// The other.
        second: String,
    },
    /// A shard whose points are not its slice of the sweep.
    #[error("sweep-merge: {dir}: its points are not those of shard {shard} of a {total}-point sweep (incomplete or edited result)")]
    WrongPoints {
        /// The directory.
        dir: String,
        /// Its shard.
        shard: Shard,
        /// Points in the whole sweep.
        total: usize,
    },
    /// Shards missing.
    #[error("sweep-merge: missing shard{} {} (given {given} of {count})", if missing.len() == 1 { "" } else { "s" }, missing.join(", "))]
    MissingShards {
        /// The missing shards, `i/n`.
        missing: Vec<String>,
        /// How many were given.
        given: usize,
        /// How many there should be.
        count: usize,
    },
    /// The cartesian product is larger than the sweep's limit (`report::vary::MAX_POINTS`).
    #[error("--vary: {sizes} values make more than {max} points; split the sweep into several")]
    TooManyPoints {
        /// The limit.
        max: usize,
        /// The number of values of each `--vary`.
        sizes: String,
    },
    /// Two `--vary` of the same field.
    #[error("--vary {first} and --vary {second} both vary {field}")]
    DuplicateVary {
        /// The first path as written.
        first: String,
        /// The second.
        second: String,
        /// The field (indices resolved).
        field: String,
    },
    /// `sweep-merge` without directories.
    #[error("sweep-merge: give the shards' directories")]
    NoShards,
    /// The output directory cannot be used.
    #[error("--out {dir}: {message}")]
    OutDir {
        /// The directory.
        dir: String,
        /// Why.
        message: String,
    },
}

/// `Result` with a [`ReportError`].
pub type Result<T, E = ReportError> = std::result::Result<T, E>;

/// The I/O error of `path`, as a [`ReportError::Io`].
pub(crate) fn io_error(path: &std::path::Path, source: std::io::Error) -> ReportError {
    ReportError::Io {
        path: path.display().to_string(),
        source,
    }
}
