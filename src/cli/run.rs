//! `bondmech run`: the rows streamed to their sink as they are computed, the summary, the
//! table and plots.

use std::io::Write;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use bondmech::Error;

use super::args::SolveArgs;
use super::failure::CliError;
use super::output::{check_outputs, io_error, print_warnings, stdout_write, write};
use super::scene_input::load;

/// Where `run` streams its rows: a file written atomically, or standard output.
pub(crate) enum RowSink {
    File(
        bondmech::output::CsvRows<bondmech::output::AtomicFile>,
        PathBuf,
    ),
    Stdout(bondmech::output::CsvRows<std::io::Stdout>),
}

impl RowSink {
    fn new(out: Option<&Path>, columns: &[String]) -> Result<RowSink, Error> {
        use bondmech::output::{AtomicFile, CsvRows};
        Ok(match out {
            Some(p) => RowSink::File(
                AtomicFile::create(p)
                    .and_then(|f| CsvRows::new(f, columns))
                    .map_err(io_error(p))?,
                p.to_path_buf(),
            ),
            None => RowSink::Stdout(
                CsvRows::new(std::io::stdout(), columns)
                    .map_err(io_error(Path::new("standard output")))?,
            ),
        })
    }

    fn path(&self) -> &Path {
        match self {
            RowSink::File(_, p) => p,
            RowSink::Stdout(_) => Path::new("standard output"),
        }
    }

    fn row(&mut self, t: f64, values: &[f64]) -> std::io::Result<()> {
        match self {
            RowSink::File(w, _) => w.row(t, values),
            RowSink::Stdout(w) => w.row(t, values),
        }
    }

    /// Flushes the rows; a file is renamed into place only now.
    fn finish(self) -> Result<(), Error> {
        let path = self.path().to_path_buf();
        match self {
            RowSink::File(w, _) => w.finish().and_then(|f| f.commit()),
            RowSink::Stdout(w) => w.finish().and_then(|mut o| o.flush()),
        }
        .map_err(io_error(&path))
    }
}

/// Output rows from which `run` says up front what the run will write and how long that takes
/// (issue 51: 1e7 rows, the most a scene may ask for, took minutes without a word, which a
/// user cannot tell from a hang).
pub(crate) const MANY_ROWS: usize = 1_000_000;

/// Bytes of one CSV value (17 significant digits, exponent, separator).
const CSV_VALUE_BYTES: usize = 25;

/// The warning for a run of `rows` output rows of `columns` columns (with `t`), from
/// [`MANY_ROWS`] on: the rows, the CSV's size, the time per row, and how to ask for fewer.
pub(crate) fn many_rows_warning(rows: usize, columns: usize) -> Option<String> {
    if rows < MANY_ROWS {
        return None;
    }
    let gb = (rows * columns * CSV_VALUE_BYTES) as f64 / 1e9;
    Some(format!(
        "{rows} output rows of {columns} columns (about {gb:.1} GB of CSV): each row costs a few microseconds to compute and write besides the solve itself, so this run takes minutes; the rows stream to the output as they are computed (Ctrl-C keeps those written). For fewer rows raise solve.output_step (--set solve.output_step=…); to bound the run, --max-wall-seconds"
    ))
}

/// Events `--table` lists by name and time (the rest are counted).
const TABLE_EVENTS: usize = 20;

/// Writes the summary JSON atomically.
pub(crate) fn write_summary(path: &Path, summary: &bondmech::Summary) -> Result<(), Error> {
    let j = serde_json::to_string_pretty(summary).expect("summary serialises");
    write(path, &j)
}

/// `bondmech run`: the rows stream to `--out` (or standard output) as they are computed, so
/// memory stays bounded whatever their number; they are kept in memory only for `--table`
/// and `--plot`. A run stopped by a budget writes the rows it computed, then fails.
pub(crate) fn run_command(
    args: &SolveArgs,
    out: Option<&Path>,
    summary: Option<&Path>,
    (table, no_csv): (bool, bool),
    plot: Option<&Path>,
) -> Result<(), CliError> {
    check_outputs(&[&args.scene], &[("--out", out), ("--summary", summary)])?;
    if let Some(dir) = plot {
        let inputs: Vec<&Path> = std::iter::once(args.scene.as_path()).chain(out).collect();
        bondmech::output::check_output_dir("--plot", dir, &inputs).map_err(Error::from)?;
    }
    let (model, mut opts) = load(args)?;
    opts.keep_rows = table || plot.is_some();
    let columns = model.row_columns(&opts)?;
    if let Some(w) = many_rows_warning(opts.output_times.len(), columns.len() + 1) {
        print_warnings(&[w]);
    }
    let mut sink = match (out, no_csv) {
        (None, true) => None,
        (out, _) => Some(RowSink::new(out, &columns)?),
    };
    let mut failed: Option<std::io::Error> = None;
    let mut last_t = f64::NEG_INFINITY;
    let mut written = 0usize;
    let result = model.solve_streaming(&opts, &mut |row| {
        if let Some(s) = sink.as_mut() {
            if let Err(e) = s.row(row.t, row.values) {
                failed = Some(e);
                return ControlFlow::Break(());
            }
        }
        last_t = row.t;
        written += 1;
        ControlFlow::Continue(())
    });
    if let Some(e) = failed {
        let path = sink
            .as_ref()
            .map_or(PathBuf::new(), |s| s.path().to_path_buf());
        return Err(io_error(&path)(e).into());
    }
    let sol = match result {
        Ok(sol) => sol,
        Err(e) => {
            // a run stopped part-way keeps its rows: those streamed, plus the state at the time
            // reached, then fails
            let Some(partial) = e.partial_solution() else {
                return Err(e.into());
            };
            print_warnings(&partial.summary.warnings);
            if let Some(mut s) = sink.take() {
                for (t, r) in partial.times.iter().zip(&partial.rows) {
                    if *t > last_t {
                        s.row(*t, r)
                            .map_err(io_error(out.unwrap_or(Path::new("-"))))?;
                        last_t = *t;
                        written += 1;
                    }
                }
                s.finish()?;
            }
            if let Some(p) = summary {
                write_summary(p, &partial.summary)?;
            }
            let written_to = out.map(|p| format!("written to {}", p.display()));
            if opts.keep_rows {
                return Err(CliError {
                    error: e,
                    note: written_to,
                });
            }
            // the rows went to their sink as they came and the partial solution holds the
            // last ones only: the count is the sink's
            let s = &partial.summary;
            let hint = bondmech::solve::error::budget_hint(s.stopped_by.as_deref());
            let mut note = format!(
                "stopped at t = {}{hint}; the {written} rows up to t = {last_t} are kept",
                s.t_reached
            );
            if let Some(w) = written_to {
                note = format!("{note}; {w}");
            }
            let Error::Incomplete { cause, .. } = e else {
                unreachable!("a partial solution comes with Error::Incomplete")
            };
            return Err(CliError {
                error: *cause,
                note: Some(note),
            });
        }
    };
    // the rows are in place before anything else can fail
    if let Some(s) = sink.take() {
        s.finish()?;
    }
    // the model's own warnings, redundant joints, singular passages, re-selections
    print_warnings(&sol.summary.warnings);
    if let Some(p) = summary {
        write_summary(p, &sol.summary)?;
    }
    if let Some(dir) = plot {
        let source = out.unwrap_or(&args.scene).display().to_string();
        let popts = bondmech::report::timeplot::PlotOptions {
            title: model.scene().name.clone(),
            columns: None,
        };
        bondmech::report::timeplot::plot_solution_with(&sol, &source, dir, &popts)?;
    }
    if table {
        let mut text = bondmech::report::tables::short_table(&sol, 11);
        let s = &sol.summary;
        let drift = match s.energy_drift {
            Some(d) => format!("energy drift {d:.2e}"),
            None => format!("energy not conserved ({})", s.energy_note),
        };
        text.push_str(&format!(
            "{}: {} steps, {} residual evals, {} Jacobians, CPU {:.3e} s, max constraint error {:.2e}, {drift}\n",
            s.formulation, s.steps, s.residual_evals, s.jacobian_evals, s.cpu_seconds,
            s.max_constraint_error
        ));
        if let Some(w) = s.driver_work {
            text.push_str(&format!("driver work {w:.6e} J ({})\n", s.driver_work_note));
        }
        // a short table lists a few events; the summary (`--summary`) has them all
        for e in s.events.iter().take(TABLE_EVENTS) {
            text.push_str(&format!("event {} at t = {}\n", e.name, e.t));
        }
        if s.events.len() > TABLE_EVENTS {
            text.push_str(&format!(
                "… and {} more events (summary.events lists all {}: --summary FILE.json)\n",
                s.events.len() - TABLE_EVENTS,
                s.events.len()
            ));
        }
        stdout_write(&text)?;
    }
    Ok(())
}
