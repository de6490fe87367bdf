//! Parameter sweeps: `bondmech sweep --vary 'PATH=[v1, v2, …]'`, sharded with `--shard i/n` and
//! put back together with `bondmech sweep-merge`.
//!
//! **Points.** Each `--vary` is a [scene path](crate::scene::path) and a list of JSON values;
//! several give their cartesian product, the first varying slowest (nested loops in the order
//! given): point `k` (from 0) of `--vary a=[a0,a1] --vary b=[b0,b1,b2]` is
//! `(a[k / 3], b[k % 3])`. Every point is the scene with fixed `--set` assignments and then its
//! values applied, re-parsed and validated (a bad value is an error naming its path and the point
//! before anything is solved), and solved with the scene's own settings (its formulation and
//! tolerances; `--t-end` or the reference's times replace its output times).
//!
//! **What a point reports.** The run's summary — formulation, steps, residual and Jacobian
//! evaluations, error test failures, CPU seconds (integration only), the largest constraint
//! error, the energy drift — then the time of the last row and the final value of every output
//! column (or only the chosen ones, `--columns`), and, with a reference, the error against it:
//! the largest difference over position and angle columns at the reference's times, as
//! [`super::sweep::solution_error`] measures it. A run that fails is a row with its failure and
//! empty numbers; the sweep goes on.
//!
//! **Parallel and sharded.** Points run on all cores (rayon); each point is an independent solve
//! and results are collected in point order, so a parallel run equals a serial one except for
//! CPU times. `--shard i/n` runs the points `k` with `k mod n = i − 1` (round robin, which
//! spreads expensive corners of the grid over the shards) and writes a partial result;
//! [`merge`] checks that the shards belong to the same sweep (the [`VarySpec::fingerprint`] of
//! the scene, the assignments, the variations, the end time, the columns and the reference) and
//! that each of `1/n … n/n` is there exactly once, and gives the report an unsharded run gives.

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use super::error::VaryError;
use super::error::{ReportError, Result};
pub use super::shard::Shard;
use crate::scene::path::parse_variation;
use crate::scene::SceneError;
use crate::solve::Solution;

/// File name of a sweep's (or a shard's) JSON result in its output directory.
pub const JSON_FILE: &str = "vary.json";
/// File name of the CSV table.
pub const CSV_FILE: &str = "vary.csv";
/// File name of the plot (one numeric `--vary` only).
pub const SVG_FILE: &str = "vary.svg";
/// The largest number of points one sweep may have (every point's scene is checked first).
pub const MAX_POINTS: usize = 10_000_000;
/// Format tag stored in every result, checked by [`merge`].
pub const FORMAT: &str = "bondmech-vary-1";

/// One `--vary`: a scene path and its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variation {
    /// The scene path as written (`bodies[1].mass`).
    pub path: String,
    /// The values, in order.
    pub values: Vec<serde_json::Value>,
}

impl Variation {
    /// Parses `PATH=[v1, v2, …]`.
    pub fn parse(text: &str) -> Result<Variation> {
        let (path, values) = parse_variation(text).map_err(SceneError::from)?;
        Ok(Variation {
            path: path.as_str().to_string(),
            values,
        })
    }
}

impl Shard {
    /// Parses `i/n` with `1 <= i <= n`.
    pub fn parse(text: &str) -> Result<Shard, VaryError> {
        let bad = |why: &str| VaryError::BadShard {
            text: text.to_string(),
            why: why.to_string(),
        };
        let (i, n) = text.split_once('/').ok_or_else(|| bad("no '/'"))?;
        let i: usize = i
            .trim()
            .parse()
            .map_err(|_| bad("i is not a whole number"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("n is not a whole number"))?;
        if n == 0 {
            return Err(bad("n must be at least 1"));
        }
        if i == 0 || i > n {
            return Err(bad(&format!("i must be between 1 and {n}")));
        }
        Ok(Shard { index: i, count: n })
    }
}

/// Everything that defines a parameter sweep's results; shards of one sweep have equal specs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VarySpec {
    /// Scene name.
    pub scene: String,
    /// FNV-1a 64 of the scene as bondmech writes it back (after the fixed assignments), hex.
    pub scene_hash: String,
    /// Fixed assignments (`--set`), applied before the variations.
    pub sets: Vec<String>,
    /// The variations (`--vary`), first varying slowest.
    pub vary: Vec<Variation>,
    /// End time (`--t-end`); `None`: the scene's (or the reference's).
    pub t_end: Option<f64>,
    /// Final-state columns chosen with `--columns`; `None`: all of them.
    pub columns: Option<Vec<String>>,
    /// Where the reference came from, if there is one.
    pub reference: Option<String>,
    /// FNV-1a 64 of the reference table (columns, times, values), hex.
    pub reference_hash: Option<String>,
}

impl VarySpec {
    /// Number of points (the product of the variations' lengths).
    pub fn total_points(&self) -> usize {
        self.vary.iter().map(|v| v.values.len()).product()
    }

    /// The values of point `k` (first variation slowest).
    pub fn point_values(&self, mut k: usize) -> Vec<serde_json::Value> {
        let mut out = vec![serde_json::Value::Null; self.vary.len()];
        for (slot, v) in out.iter_mut().zip(&self.vary).rev() {
            let n = v.values.len();
            *slot = v.values[k % n].clone();
            k /= n;
        }
        out
    }

    /// A hash of the spec (hex): equal for shards of one sweep. The reference counts by its
    /// content (`reference_hash`), not by where it was read from.
    pub fn fingerprint(&self) -> String {
        let mut s = self.clone();
        s.reference = None;
        fnv_hex(
            serde_json::to_string(&s)
                .expect("spec serialises")
                .as_bytes(),
        )
    }
}

fn fnv1a(bytes: &[u8], mut h: u64) -> u64 {
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

pub(crate) fn fnv_hex(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a(bytes, FNV_OFFSET))
}

pub(crate) fn solution_hash(s: &Solution) -> String {
    let mut h = FNV_OFFSET;
    for c in &s.columns {
        h = fnv1a(c.as_bytes(), h);
        h = fnv1a(b",", h);
    }
    for (t, row) in s.times.iter().zip(&s.rows) {
        h = fnv1a(&t.to_bits().to_le_bytes(), h);
        for x in row {
            h = fnv1a(&x.to_bits().to_le_bytes(), h);
        }
    }
    format!("{h:016x}")
}

/// `NaN` and infinities are written as JSON `null` and read back as `NaN`.
mod nan_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}

pub(crate) fn finite_or_nan(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        f64::NAN
    }
}

/// The final value of one output column.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FinalValue {
    /// Column name (as in `run`'s CSV).
    pub column: String,
    /// Its value in the last row (`NaN`/`null` if not finite).
    #[serde(with = "nan_null")]
    pub value: f64,
}

/// One point of a parameter sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VaryPoint {
    /// Point number (from 0) in the whole sweep.
    pub index: usize,
    /// Its values, one per variation.
    pub values: Vec<serde_json::Value>,
    /// Why the run failed, if it did (the numbers below are then `null`).
    pub failure: Option<String>,
    /// Formulation that ran (`ggl`, `index1`, `decoupled`, …).
    pub formulation: String,
    /// Internal steps.
    pub steps: u64,
    /// Residual or right-hand-side evaluations.
    pub residual_evals: u64,
    /// Jacobian evaluations.
    pub jacobian_evals: u64,
    /// Error test failures.
    pub error_test_failures: u64,
    /// CPU seconds of the integration (the only field that differs between runs).
    #[serde(with = "nan_null")]
    pub cpu_seconds: f64,
    /// Largest |g(q)| at the output times.
    #[serde(with = "nan_null")]
    pub max_constraint_error: f64,
    /// Relative energy drift (see [`crate::solve::Summary::energy_drift`]); `NaN`/`null` when the
    /// scene does not conserve energy.
    #[serde(with = "nan_null")]
    pub energy_drift: f64,
    /// Error against the reference (with a reference only).
    #[serde(with = "nan_null")]
    pub error: f64,
    /// Time of the last row.
    #[serde(with = "nan_null")]
    pub t_final: f64,
    /// The last row's values.
    pub final_values: Vec<FinalValue>,
}

/// A parameter sweep's result, whole or one shard of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VaryReport {
    /// [`FORMAT`].
    pub format: String,
    /// [`VarySpec::fingerprint`] of `spec`.
    pub fingerprint: String,
    /// What was swept.
    pub spec: VarySpec,
    /// Points in the whole sweep.
    pub total_points: usize,
    /// The shard this result holds; `None` for a whole (or merged) sweep.
    pub shard: Option<Shard>,
    /// The points run, in order.
    pub points: Vec<VaryPoint>,
}

/// Quotes a CSV field when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        String::new()
    }
}

impl VaryReport {
    /// The final-value columns of all points, in order of first appearance.
    pub fn final_columns(&self) -> Vec<String> {
        let mut cols: Vec<String> = Vec::new();
        for p in &self.points {
            for f in &p.final_values {
                if !cols.contains(&f.column) {
                    cols.push(f.column.clone());
                }
            }
        }
        cols
    }

    /// One row per point: `index`, the varied values (JSON), `failure`, the summary, `error`
    /// (with a reference), `t_final`, then `final.<column>` for every output column.
    pub fn csv(&self) -> String {
        let cols = self.final_columns();
        let with_error = self.spec.reference.is_some();
        let mut head = vec!["index".to_string()];
        head.extend(self.spec.vary.iter().map(|v| csv_field(&v.path)));
        for h in [
            "failure",
            "formulation",
            "steps",
            "residual_evals",
            "jacobian_evals",
            "error_test_failures",
            "cpu_seconds",
            "max_constraint_error",
            "energy_drift",
        ] {
            head.push(h.into());
        }
        if with_error {
            head.push("error".into());
        }
        head.push("t_final".into());
        head.extend(cols.iter().map(|c| csv_field(&format!("final.{c}"))));
        let mut s = head.join(",");
        s.push('\n');
        for p in &self.points {
            let mut row = vec![p.index.to_string()];
            row.extend(p.values.iter().map(|v| csv_field(&v.to_string())));
            row.push(csv_field(p.failure.as_deref().unwrap_or("")));
            row.push(csv_field(&p.formulation));
            for n in [
                p.steps,
                p.residual_evals,
                p.jacobian_evals,
                p.error_test_failures,
            ] {
                row.push(n.to_string());
            }
            row.push(num(p.cpu_seconds));
            row.push(num(p.max_constraint_error));
            row.push(num(p.energy_drift));
            if with_error {
                row.push(num(p.error));
            }
            row.push(num(p.t_final));
            for c in &cols {
                let v = p.final_values.iter().find(|f| &f.column == c);
                row.push(v.map_or(String::new(), |f| num(f.value)));
            }
            s.push_str(&row.join(","));
            s.push('\n');
        }
        s
    }

    /// A short text summary for the terminal (the first few final columns).
    pub fn table(&self) -> String {
        let cols: Vec<String> = self.final_columns().into_iter().take(3).collect();
        let mut s = format!(
            "{}: {} of {} points{}\n",
            self.spec.scene,
            self.points.len(),
            self.total_points,
            self.shard
                .map_or(String::new(), |sh| format!(" (shard {sh})"))
        );
        let mut head = format!("{:>6}", "point");
        for v in &self.spec.vary {
            let _ = write!(head, " {:>18}", v.path);
        }
        let _ = write!(head, " {:>8} {:>10} {:>10}", "steps", "CPU (s)", "max |g|");
        if self.spec.reference.is_some() {
            let _ = write!(head, " {:>10}", "error");
        }
        for c in &cols {
            let _ = write!(head, " {c:>14}");
        }
        s.push_str(&head);
        s.push('\n');
        for p in &self.points {
            let _ = write!(s, "{:>6}", p.index);
            for v in &p.values {
                let _ = write!(s, " {:>18}", v.to_string());
            }
            if let Some(f) = &p.failure {
                let _ = writeln!(s, "  FAILED: {f}");
                continue;
            }
            let _ = write!(
                s,
                " {:>8} {:>10.3e} {:>10.2e}",
                p.steps, p.cpu_seconds, p.max_constraint_error
            );
            if self.spec.reference.is_some() {
                let _ = write!(s, " {:>10.2e}", p.error);
            }
            for c in &cols {
                let v = p.final_values.iter().find(|f| &f.column == c);
                let _ = write!(s, " {:>14.6}", v.map_or(f64::NAN, |f| f.value));
            }
            s.push('\n');
        }
        s
    }

    /// Writes `vary.json` and `vary.csv` into `dir`, and `vary.svg` for a whole sweep over one
    /// numeric parameter. The directory should have been checked with [`check_out_dir`].
    pub fn write_all(&self, dir: &Path) -> Result<()> {
        let io = |p: &Path, source| ReportError::Io {
            path: p.display().to_string(),
            source,
        };
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let json = serde_json::to_string_pretty(self).expect("report serialises") + "\n";
        for (name, text) in [(JSON_FILE, json), (CSV_FILE, self.csv())] {
            let p = dir.join(name);
            crate::output::write_atomic(&p, text.as_bytes()).map_err(|e| io(&p, e))?;
        }
        if self.shard.is_none() {
            vary_svg(self, &dir.join(SVG_FILE))?;
        }
        Ok(())
    }

    /// Reads a result written by [`VaryReport::write_all`] from `dir`.
    pub fn read(dir: &Path) -> Result<VaryReport> {
        let p = dir.join(JSON_FILE);
        let text = std::fs::read_to_string(&p).map_err(|e| VaryError::NotAResult {
            dir: dir.display().to_string(),
            message: format!(
                "cannot read {JSON_FILE} ({e}); is it the --out directory of a `bondmech \
                     sweep --vary ... --shard i/n`?"
            ),
        })?;
        let r: VaryReport = serde_json::from_str(&text).map_err(|e| VaryError::NotAResult {
            dir: p.display().to_string(),
            message: format!("not a bondmech parameter sweep result: {e}"),
        })?;
        if r.format != FORMAT {
            return Err(VaryError::NotAResult {
                dir: p.display().to_string(),
                message: format!("format '{}', expected '{FORMAT}'", r.format),
            }
            .into());
        }
        Ok(r)
    }
}

/// What differs between two specs, for the merge error.
fn spec_difference(a: &VarySpec, b: &VarySpec) -> String {
    let mut d = Vec::new();
    if a.scene != b.scene || a.scene_hash != b.scene_hash {
        d.push(format!("scene ({} vs {})", a.scene, b.scene));
    }
    if a.sets != b.sets {
        d.push(format!("--set ({:?} vs {:?})", a.sets, b.sets));
    }
    if a.vary != b.vary {
        d.push("--vary".to_string());
    }
    if a.t_end != b.t_end {
        d.push(format!("--t-end ({:?} vs {:?})", a.t_end, b.t_end));
    }
    if a.columns != b.columns {
        d.push("--columns".to_string());
    }
    if a.reference_hash != b.reference_hash {
        d.push("--reference".to_string());
    }
    if d.is_empty() {
        "the fingerprints differ".into()
    } else {
        format!("they differ in {}", d.join(", "))
    }
}

/// Combines the shards `1/n … n/n` of one sweep (each read from its directory) into the report
/// an unsharded run gives. Refuses shards of different sweeps, a missing or repeated shard, a
/// whole sweep among the shards, and a shard whose points are not its slice.
pub fn merge(parts: &[(PathBuf, VaryReport)]) -> Result<VaryReport> {
    let Some((first_dir, first)) = parts.first() else {
        return Err(VaryError::NoShards.into());
    };
    let mut have: Vec<Option<&Path>> = Vec::new();
    let mut count = None;
    for (dir, r) in parts {
        let Some(shard) = r.shard else {
            return Err(VaryError::WholeSweep {
                dir: dir.display().to_string(),
            }
            .into());
        };
        if r.fingerprint != first.fingerprint || r.spec.fingerprint() != first.spec.fingerprint() {
            return Err(VaryError::DifferentSweeps {
                first: first_dir.display().to_string(),
                first_fingerprint: first.fingerprint.clone(),
                other: dir.display().to_string(),
                other_fingerprint: r.fingerprint.clone(),
                difference: spec_difference(&first.spec, &r.spec),
            }
            .into());
        }
        if r.fingerprint != r.spec.fingerprint() {
            return Err(VaryError::FingerprintMismatch {
                dir: dir.display().to_string(),
            }
            .into());
        }
        match count {
            None => {
                count = Some(shard.count);
                have = vec![None; shard.count];
            }
            Some(n) if n != shard.count => {
                return Err(VaryError::ShardCountMismatch {
                    dir: dir.display().to_string(),
                    shard,
                    first: first_dir.display().to_string(),
                    count: n,
                }
                .into())
            }
            Some(_) => {}
        }
        if shard.index == 0 || shard.index > shard.count {
            return Err(VaryError::WrongPoints {
                dir: dir.display().to_string(),
                shard,
                total: r.total_points,
            }
            .into());
        }
        if let Some(prev) = have[shard.index - 1] {
            return Err(VaryError::DuplicateShard {
                shard,
                first: prev.display().to_string(),
                second: dir.display().to_string(),
            }
            .into());
        }
        have[shard.index - 1] = Some(dir);
        let expected: Vec<usize> = (0..r.total_points).filter(|&k| shard.owns(k)).collect();
        let got: Vec<usize> = r.points.iter().map(|p| p.index).collect();
        if r.total_points != r.spec.total_points() || got != expected {
            return Err(VaryError::WrongPoints {
                dir: dir.display().to_string(),
                shard,
                total: r.spec.total_points(),
            }
            .into());
        }
    }
    let n = count.unwrap_or(0);
    let missing: Vec<String> = have
        .iter()
        .enumerate()
        .filter(|(_, d)| d.is_none())
        .map(|(i, _)| format!("{}/{n}", i + 1))
        .collect();
    if !missing.is_empty() {
        return Err(VaryError::MissingShards {
            given: n - missing.len(),
            missing,
            count: n,
        }
        .into());
    }
    let mut points: Vec<VaryPoint> = parts
        .iter()
        .flat_map(|(_, r)| r.points.iter().cloned())
        .collect();
    points.sort_by_key(|p| p.index);
    Ok(VaryReport {
        format: FORMAT.into(),
        fingerprint: first.fingerprint.clone(),
        spec: first.spec.clone(),
        total_points: first.total_points,
        shard: None,
        points,
    })
}

/// Checks, before anything is computed, that `dir` can be created and written, and that none of
/// the files a sweep writes there is one of `inputs` (the scene, the reference, the shards).
pub fn check_out_dir(dir: &Path, inputs: &[&Path]) -> Result<()> {
    let io = |p: &Path, source| ReportError::Io {
        path: p.display().to_string(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(|e| VaryError::OutDir {
        dir: dir.display().to_string(),
        // a file (or a FIFO, a device) in the way: say so, not "File exists (os error 17)"
        message: match std::fs::metadata(dir) {
            Ok(m) if !m.is_dir() => "is a file, not a directory: give a directory for the merged CSV, JSON and SVG files".into(),
            _ => format!("cannot create it ({e})"),
        },
    })?;
    let probe = dir.join(format!(".bondmech-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| VaryError::OutDir {
        dir: dir.display().to_string(),
        message: format!("not writable ({e})"),
    })?;
    let _ = std::fs::remove_file(&probe);
    let canon_dir = dir.canonicalize().map_err(|e| io(dir, e))?;
    for input in inputs {
        let Ok(c) = input.canonicalize() else {
            continue;
        };
        if c == canon_dir {
            return Err(VaryError::OutDir {
                dir: dir.display().to_string(),
                message: "is an input directory; write the merged result elsewhere".into(),
            }
            .into());
        }
        for name in [
            JSON_FILE,
            CSV_FILE,
            SVG_FILE,
            "work_precision.csv",
            "stiffness.csv",
            "sweep.json",
            "work_precision.svg",
            "stiffness.svg",
        ] {
            if canon_dir.join(name) == c || crate::output::same_file(&canon_dir.join(name), input) {
                return Err(VaryError::OutDir {
                    dir: dir.display().to_string(),
                    message: format!("would overwrite the input {}", input.display()),
                }
                .into());
            }
        }
    }
    Ok(())
}

/// A progress bar with the ETA on a terminal, hidden otherwise.
pub fn progress_bar(total: u64) -> indicatif::ProgressBar {
    if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(total);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} points, {elapsed} elapsed, ETA {eta}",
            )
            .expect("template is valid"),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    }
}

/// `bondmech sweep-merge DIR… --out DIR`: reads the shards, merges them and writes the whole
/// sweep's CSV, JSON and SVG into `out`.
pub fn merge_command(dirs: &[PathBuf], out: &Path) -> Result<VaryReport> {
    if dirs.is_empty() {
        return Err(VaryError::NoShards.into());
    }
    let inputs: Vec<&Path> = dirs.iter().map(PathBuf::as_path).collect();
    let mut parts = Vec::with_capacity(dirs.len());
    for d in dirs {
        parts.push((d.clone(), VaryReport::read(d)?));
    }
    let merged = merge(&parts)?;
    check_out_dir(out, &inputs)?;
    merged.write_all(out)?;
    Ok(merged)
}

/// `[lo, hi]` of the positive finite values, widened a little (log axes need lo > 0).
fn log_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return None;
    }
    let hi = if hi <= lo { lo * 10.0 } else { hi };
    Some((lo / 2.0, hi * 2.0))
}

/// For a sweep over one numeric parameter: the error against the reference (or, without one,
/// the largest constraint error) at each value, log scale on y, and on x when every value is
/// positive and they span more than a decade. Nothing is drawn otherwise (and no file written).
pub fn vary_svg(report: &VaryReport, path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| ReportError::Io {
        path: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    };
    if report.spec.vary.len() != 1 {
        return Ok(());
    }
    let with_ref = report.spec.reference.is_some();
    let pts: Vec<(f64, f64)> = report
        .points
        .iter()
        .filter(|p| p.failure.is_none())
        .filter_map(|p| {
            let x = p.values.first()?.as_f64()?;
            let y = if with_ref {
                p.error
            } else {
                p.max_constraint_error
            };
            (x.is_finite() && y.is_finite() && y > 0.0).then_some((x, y))
        })
        .collect();
    if pts.len() < 2 {
        return Ok(());
    }
    let Some((y0, y1)) = log_range(pts.iter().map(|p| p.1)) else {
        return Ok(());
    };
    let (xmin, xmax) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let log_x = xmin > 0.0 && xmax / xmin > 10.0;
    let name = &report.spec.vary[0].path;
    let y_desc = if with_ref {
        "max error vs reference (m, rad)"
    } else {
        "max constraint error |g(q)|"
    };
    let root = SVGBackend::new(path, (800, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let caption = format!("{}: sweep over {name}", report.spec.scene);
    let colour = RGBColor(31, 119, 180);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(|e| err(&e))?;
            chart
                .configure_mesh()
                .light_line_style(TRANSPARENT)
                .x_desc(name.as_str())
                .y_desc(y_desc)
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()
                .map_err(|e| err(&e))?;
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), &colour))
                .map_err(|e| err(&e))?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|&(x, y)| Circle::new((x, y), 4, colour.filled())),
                )
                .map_err(|e| err(&e))?;
        }};
    }
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70);
    if log_x {
        draw!(
            builder.build_cartesian_2d((xmin / 1.5..xmax * 1.5).log_scale(), (y0..y1).log_scale())
        );
    } else {
        let pad = if xmax > xmin {
            0.05 * (xmax - xmin)
        } else {
            0.5 * xmin.abs().max(1.0)
        };
        draw!(builder.build_cartesian_2d(xmin - pad..xmax + pad, (y0..y1).log_scale()));
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_points() {
        for n in 1..=7 {
            for total in [0usize, 1, 5, 12] {
                let mut seen = vec![0; total];
                for i in 1..=n {
                    let s = Shard::parse(&format!("{i}/{n}")).unwrap();
                    for (k, c) in seen.iter_mut().enumerate() {
                        if s.owns(k) {
                            *c += 1;
                        }
                    }
                }
                assert!(seen.iter().all(|&c| c == 1), "n = {n}, total = {total}");
            }
        }
        for bad in ["0/3", "4/3", "1/0", "3", "a/3", "1/b", "-1/3", ""] {
            let e = Shard::parse(bad).unwrap_err().to_string();
            assert!(e.starts_with(&format!("--shard '{bad}'")), "{e}");
        }
        assert_eq!(
            Shard::parse(" 2 / 5 ").unwrap(),
            Shard { index: 2, count: 5 }
        );
    }

    #[test]
    fn points_are_the_cartesian_product_first_slowest() {
        let spec = VarySpec {
            scene: "s".into(),
            scene_hash: String::new(),
            sets: vec![],
            vary: vec![
                Variation::parse("a=[1,2]").unwrap(),
                Variation::parse("b=[\"x\",\"y\",\"z\"]").unwrap(),
            ],
            t_end: None,
            columns: None,
            reference: None,
            reference_hash: None,
        };
        assert_eq!(spec.total_points(), 6);
        let all: Vec<String> = (0..6)
            .map(|k| {
                let v = spec.point_values(k);
                format!("{}{}", v[0], v[1].as_str().unwrap())
            })
            .collect();
        assert_eq!(all, ["1x", "1y", "1z", "2x", "2y", "2z"]);
        // the fingerprint follows the spec, not where the reference was read from
        let mut other = spec.clone();
        other.reference = Some("elsewhere/ref.csv".into());
        assert_eq!(spec.fingerprint(), other.fingerprint());
        other.vary[1].values.pop();
        assert_ne!(spec.fingerprint(), other.fingerprint());
    }
}
