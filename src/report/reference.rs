//! Independent reference solutions read from CSV, for `bondmech sweep --reference`.
//!
//! A reference is a table in the format `bondmech run` writes: a header `t,<col>,<col>,…` and one
//! row of numbers per time (other tools' CSV is accepted too: quoted names, a `time` column,
//! comment lines; see [`reference_from_csv_str`]). `bondmech animate --csv` reads its run
//! tables with the same reader. Its columns keep the scene contract's names (`bar2.x`,
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

use super::error::{io_error, ReferenceProblem, ReportError, Result};
use crate::solve::{Solution, Summary};

/// Parses a reference table (`t` first, then named columns) from CSV text; `origin` names the
/// source in error messages (`ref.csv line 3, column 2: …`).
///
/// The text is read with the `csv` crate, so other tools' tables work too: quoted header names
/// (`"bar1.x"`), spaces around cells, blank lines, `#` comment lines, a UTF-8 byte order mark,
/// and a first column named `time` (any case) instead of `t`. Times must be finite and strictly
/// increasing; every row has as many numbers as the header has names; at least one row.
pub fn reference_from_csv_str(text: &str, origin: &str) -> Result<Solution> {
    let bad = |line: u64, problem: ReferenceProblem| ReportError::Reference {
        origin: origin.to_string(),
        line,
        problem,
    };
    let csv_error = |cause| ReportError::Csv {
        origin: origin.to_string(),
        cause,
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header = reader.headers().map_err(csv_error)?.clone();
    // the file's own line numbers (the csv crate's skip comment lines)
    let line_at = |pos: Option<&csv::Position>| {
        pos.map_or(0, |p| {
            let bytes = text.as_bytes();
            let mut byte = (p.byte() as usize).min(bytes.len());
            // the position may be that of the blank or comment lines before the record
            loop {
                let rest = &text[byte..];
                let line_end = rest.find('\n').map_or(rest.len(), |i| i + 1);
                let line = rest[..line_end].trim();
                if line_end == 0 || !(line.is_empty() || line.starts_with('#')) {
                    break;
                }
                byte += line_end;
            }
            1 + bytes[..byte].iter().filter(|&&b| b == b'\n').count() as u64
        })
    };
    let header_line = line_at(header.position());
    let names: Vec<String> = header.iter().map(|s| unquote(s).to_string()).collect();
    if names.iter().all(|n| n.is_empty()) {
        return Err(ReportError::EmptyReference {
            origin: origin.to_string(),
        });
    }
    let first = names.first().map_or("", String::as_str);
    if first != "t" && !first.eq_ignore_ascii_case("time") {
        return Err(bad(
            header_line,
            ReferenceProblem::HeaderStart {
                got: first.to_string(),
            },
        ));
    }
    if names.len() < 2 {
        return Err(bad(header_line, ReferenceProblem::NoColumns));
    }
    if let Some((_, dup)) = names
        .iter()
        .enumerate()
        .find(|(i, n)| names[..*i].contains(n))
    {
        return Err(bad(
            header_line,
            ReferenceProblem::DuplicateColumn { name: dup.clone() },
        ));
    }
    let mut times = Vec::new();
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(csv_error)?;
        let line_no = line_at(record.position());
        if record.iter().all(str::is_empty) {
            continue;
        }
        if record.len() != names.len() {
            return Err(bad(
                line_no,
                ReferenceProblem::RowLength {
                    values: record.len(),
                    columns: names.len(),
                },
            ));
        }
        let mut values = Vec::with_capacity(record.len());
        for (c, cell) in record.iter().map(unquote).enumerate() {
            let v: f64 = cell.parse().map_err(|_| {
                bad(
                    line_no,
                    ReferenceProblem::NotANumber {
                        column: c + 1,
                        name: names[c].clone(),
                        cell: cell.to_string(),
                    },
                )
            })?;
            if !v.is_finite() {
                return Err(bad(
                    line_no,
                    ReferenceProblem::NotFinite {
                        column: c + 1,
                        name: names[c].clone(),
                        value: v,
                    },
                ));
            }
            values.push(v);
        }
        let t = values.remove(0);
        if let Some(&prev) = times.last() {
            if t <= prev {
                return Err(bad(
                    line_no,
                    ReferenceProblem::TimesNotIncreasing { t, prev },
                ));
            }
        }
        times.push(t);
        rows.push(values);
    }
    if times.is_empty() {
        return Err(ReportError::NoReferenceRows {
            origin: origin.to_string(),
        });
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

/// A cell without the quotes that survive when a tool writes a space before them (`a, "b"`).
fn unquote(cell: &str) -> &str {
    let c = cell.trim();
    c.strip_prefix('"')
        .and_then(|c| c.strip_suffix('"'))
        .map_or(c, str::trim)
}

/// Reads a reference table from a CSV file (see [`reference_from_csv_str`]).
pub fn reference_from_csv(path: &Path) -> Result<Solution> {
    let text = std::fs::read_to_string(path).map_err(|e| io_error(path, e))?;
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
    fn other_tools_csv_quoted_headers_time_column_comments() {
        let text = "\u{feff}# exported by another tool\n\"Time\", \"bar1.x\" ,\"bar1.angle\"\n\n0, 0.5, 0\n\"0.5\",0.25,1e-1\n";
        let r = reference_from_csv_str(text, "other.csv").unwrap();
        assert_eq!(
            r.columns,
            vec!["bar1.x".to_string(), "bar1.angle".to_string()]
        );
        assert_eq!(r.times, vec![0.0, 0.5]);
        assert_eq!(r.column("bar1.angle"), Some(vec![0.0, 0.1]));
        // line numbers count the comment and blank lines of the file
        let e = reference_from_csv_str("# c\ntime,a\n0,1\n\n1,oops\n", "o.csv").unwrap_err();
        assert!(e.to_string().contains("o.csv line 5"), "{e}");
        assert!(e.to_string().contains("`oops` is not a number"), "{e}");
    }

    #[test]
    fn truncation_keeps_times_up_to_t_end() {
        let r = reference_from_csv_str("t,a\n0,1\n0.5,2\n1,3\n", "r").unwrap();
        let t = truncate_reference(&r, Some(0.5));
        assert_eq!(t.times, vec![0.0, 0.5]);
        assert_eq!(t.rows, vec![vec![1.0], vec![2.0]]);
    }
}
