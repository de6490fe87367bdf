//! Independent reference solutions read from CSV, for `bondmech sweep --reference`.
//!
//! A reference is a table in the format `bondmech run` writes: a header `t,<col>,<col>,…` and one
//! row of numbers per time. Its columns keep the scene contract's names (`bar2.x`,
//! `crank.angle`, `rod.B.y`, …), so a published reference solution — or one computed by another
//! tool — can be compared with every formulation of a sweep without trusting bondmech for the
//! reference itself. The sweep's output times become the reference's times (no interpolation
//! error enters the comparison).
//!
//! ```
//! use bondmech::report::reference::reference_from_csv_str;
//!
//! let r = reference_from_csv_str("t,bar1.x\n0,0.5\n0.5,0.25\n", "ref.csv")?;
//! assert_eq!(r.times, vec![0.0, 0.5]);
//! assert_eq!(r.column("bar1.x"), Some(vec![0.5, 0.25]));
//! # Ok::<(), bondmech::Error>(())
//! ```

use std::path::Path;

use crate::solve::{Solution, Summary};
use crate::{Error, Result};

/// Parses a reference table (`t` first, then named columns) from CSV text; `origin` names the
/// source in error messages (`ref.csv line 3, column 2: …`).
///
/// Times must be finite and strictly increasing; every row has as many numbers as the header
/// has names; at least one row.
pub fn reference_from_csv_str(text: &str, origin: &str) -> Result<Solution> {
    let bad = |line: usize, what: String| Error::Options(format!("{origin} line {line}: {what}"));
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines
        .next()
        .ok_or_else(|| Error::Options(format!("{origin}: empty reference file")))?;
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    if names.first().map(String::as_str) != Some("t") {
        return Err(bad(
            1,
            format!(
                "the header must start with `t` (got `{}`)",
                names.first().map_or("", String::as_str)
            ),
        ));
    }
    if names.len() < 2 {
        return Err(bad(1, "the header names no column after `t`".into()));
    }
    if let Some(dup) = names
        .iter()
        .enumerate()
        .find(|(i, n)| names[..*i].contains(n))
    {
        return Err(bad(1, format!("column `{}` appears twice", dup.1)));
    }
    let mut times = Vec::new();
    let mut rows = Vec::new();
    for (i, line) in lines {
        let line_no = i + 1;
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != names.len() {
            return Err(bad(
                line_no,
                format!("{} values for {} columns", cells.len(), names.len()),
            ));
        }
        let mut values = Vec::with_capacity(cells.len());
        for (c, cell) in cells.iter().enumerate() {
            let v: f64 = cell.trim().parse().map_err(|_| {
                bad(
                    line_no,
                    format!(
                        "column {} (`{}`): `{}` is not a number",
                        c + 1,
                        names[c],
                        cell.trim()
                    ),
                )
            })?;
            if !v.is_finite() {
                return Err(bad(
                    line_no,
                    format!("column {} (`{}`): {v} is not finite", c + 1, names[c]),
                ));
            }
            values.push(v);
        }
        let t = values.remove(0);
        if let Some(&prev) = times.last() {
            if t <= prev {
                return Err(bad(
                    line_no,
                    format!("times must increase (t = {t} after {prev})"),
                ));
            }
        }
        times.push(t);
        rows.push(values);
    }
    if times.is_empty() {
        return Err(Error::Options(format!(
            "{origin}: the reference has no rows"
        )));
    }
    Ok(Solution {
        columns: names[1..].to_vec(),
        times,
        rows,
        summary: Summary {
            formulation: "reference".into(),
            ..Summary::default()
        },
    })
}

/// Reads a reference table from a CSV file (see [`reference_from_csv_str`]).
pub fn reference_from_csv(path: &Path) -> Result<Solution> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Options(format!("{}: {e}", path.display())))?;
    reference_from_csv_str(&text, &path.display().to_string())
}

/// The reference restricted to `t ≤ t_end` (all of it when `t_end` is `None`).
pub fn truncate_reference(reference: &Solution, t_end: Option<f64>) -> Solution {
    let keep = match t_end {
        Some(t) => reference
            .times
            .iter()
            .take_while(|&&s| s <= t * (1.0 + 1e-12))
            .count(),
        None => reference.times.len(),
    };
    Solution {
        columns: reference.columns.clone(),
        times: reference.times[..keep].to_vec(),
        rows: reference.rows[..keep].to_vec(),
        summary: reference.summary.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_errors_name_file_line_and_column() {
        let e = reference_from_csv_str("t,a\n0,1\n1,x\n", "r.csv").unwrap_err();
        assert!(e.to_string().contains("r.csv line 3"), "{e}");
        assert!(e.to_string().contains("`a`"), "{e}");
        let e = reference_from_csv_str("x,a\n0,1\n", "r.csv").unwrap_err();
        assert!(e.to_string().contains("start with `t`"), "{e}");
        let e = reference_from_csv_str("t,a\n1,1\n0.5,1\n", "r.csv").unwrap_err();
        assert!(e.to_string().contains("times must increase"), "{e}");
        let e = reference_from_csv_str("t,a\n0,1,2\n", "r.csv").unwrap_err();
        assert!(e.to_string().contains("3 values for 2 columns"), "{e}");
        let e = reference_from_csv_str("t,a,a\n0,1,2\n", "r.csv").unwrap_err();
        assert!(e.to_string().contains("appears twice"), "{e}");
        let e = reference_from_csv_str("t,a\n", "r.csv").unwrap_err();
        assert!(e.to_string().contains("no rows"), "{e}");
    }

    #[test]
    fn truncation_keeps_times_up_to_t_end() {
        let r = reference_from_csv_str("t,a\n0,1\n0.5,2\n1,3\n", "r").unwrap();
        let t = truncate_reference(&r, Some(0.5));
        assert_eq!(t.times, vec![0.0, 0.5]);
        assert_eq!(t.rows, vec![vec![1.0], vec![2.0]]);
    }
}
