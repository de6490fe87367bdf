//! The `bondmech` command line: a thin layer over the library.
//!
//! Every flag that changes the scene (`--rtol`, `--atol`, `--t-end`, `--joint-stiffness`,
//! `--formulation`, `--max-steps`, `--max-wall-seconds`) is written into the scene's `solve`
//! section and the scene is validated again, so a flag obeys exactly the scene's rules and a
//! refusal names the flag. Output paths are checked before anything is solved; a closed
//! standard output (`| head`) ends the program quietly.

use std::io::{Read, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod fmu_cmd;

use bondmech::scene::SolveOverrides;
use bondmech::FormulationKind;
use bondmech::{Error, Model, Scene, SolveOptions};
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "bondmech",
    version,
    about = "Mechanisms as bond graphs, solved with SUNDIALS (IDA DAE / CVODE decoupled twin)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct SolveArgs {
    /// Scene file (JSON, see docs/scene-format.md); `-` reads it from standard input.
    scene: PathBuf,
    /// Formulation (the scene's solve.formulation by default).
    #[arg(long, value_enum)]
    formulation: Option<FormulationKind>,
    /// Relative tolerance (solve.rtol).
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance (solve.atol).
    #[arg(long)]
    atol: Option<f64>,
    /// End time in s (solve.t_end); the scene's output times after it are dropped.
    #[arg(long = "t-end")]
    t_end: Option<f64>,
    /// Joint stiffness of the decoupled twin in N/m (solve.joint_stiffness).
    #[arg(long = "joint-stiffness")]
    joint_stiffness: Option<f64>,
    /// Step budget of the whole run (solve.max_steps; none by default).
    #[arg(long = "max-steps")]
    max_steps: Option<u64>,
    /// Wall-clock budget of the whole run in s (solve.max_wall_seconds; none by default).
    #[arg(long = "max-wall-seconds")]
    max_wall_seconds: Option<f64>,
    /// Linear solver of the Newton iterations: auto, dense, sparse (faer) or klu
    /// (solve.linear_solver; auto by default: dense for small systems, sparse for large).
    #[arg(long = "linear-solver", value_parser = parse_linear_solver)]
    linear_solver: Option<bondmech::LinearSolverKind>,
    /// Change one scene field before solving: PATH=JSON, e.g. 'bodies[0].mass=2',
    /// 'gravity=[0,-1.62]', 'solve.formulation="index1"' (repeatable, applied in order).
    #[arg(long = "set", value_name = "PATH=JSON")]
    set: Vec<String>,
    /// Add every joint's reaction columns (`J.Fx, J.Fy[, J.Fz]`, and `J.Mz` or `J.Mx, J.My,
    /// J.Mz` for prismatic, weld and hinge joints): force and moment on the joint's second
    /// body, global frame, N and N·m; as `"outputs": ["reactions"]` in the scene.
    #[arg(long)]
    reactions: bool,
}

/// The orthographic views of `animate --view`.
#[derive(clap::ValueEnum, Clone, Copy)]
enum ViewArg {
    /// x right, y up (planar scenes).
    Xy,
    /// x right, z up.
    Xz,
    /// y right, z up.
    Yz,
    /// Isometric: x to the lower left, y to the lower right, z up.
    Iso,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene and write its trajectory as CSV.
    Run {
        #[command(flatten)]
        args: SolveArgs,
        /// CSV output file (default: standard output).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the solver summary as JSON to this file.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Print a short table instead of the CSV on standard output.
        #[arg(long)]
        table: bool,
        /// Also write SVG plots against time of the columns into this directory (the CSV then
        /// goes to standard output only when asked: `--out -`).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// The bond graph of a scene: DOT (or SVG through Graphviz), or its causality report.
    Graph {
        /// Scene file (JSON).
        scene: PathBuf,
        /// Print the causality report as JSON (dof, states, differential, conflicts, …).
        #[arg(long)]
        causality: bool,
        /// Draw the decoupled twin (joints replaced by stiff springs) instead.
        #[arg(long)]
        decoupled: bool,
        /// Draw one node per body or joint (the default above 200 elements).
        #[arg(long, conflicts_with = "expand")]
        collapse: bool,
        /// Draw every element, however large the graph.
        #[arg(long)]
        expand: bool,
        /// Print the mechanism's complete bond graph as a raw `bond_graph` scene (JSON, with
        /// its closures, coordinates, output columns, `solve` and `outputs`): `run` on it gives
        /// the mechanism's trajectories.
        #[arg(long, conflicts_with_all = ["causality", "decoupled"])]
        as_scene: bool,
        /// Write to this file instead of standard output; `.svg` runs Graphviz `dot`. With
        /// `--causality` the file gets the JSON report, so `.svg` and `.dot` are refused.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// The equations a scene is solved with, named after the bond graph: kinematics,
    /// dynamics, each constraint row with its joint, junction and differential inertia, and the
    /// flow constraint each junction imposes.
    Equations {
        /// Scene file (JSON; `-` reads standard input).
        scene: PathBuf,
    },
    /// The static equilibrium nearest the scene's configuration (loads, drivers and inputs at
    /// t_start): Newton with a line search, the joints held; its stability from the tangent
    /// stiffness reduced to the degrees of freedom. Exit 1 when none is found.
    Equilibrium {
        /// Scene file (JSON; `-` reads standard input).
        scene: PathBuf,
        /// Change one scene field first: PATH=JSON (as `run --set`).
        #[arg(long = "set", value_name = "PATH=JSON")]
        set: Vec<String>,
        /// Write the result as JSON to this file (converged, iterations, residual,
        /// coordinates, reactions, drivers, stable, stiffness_eigenvalues).
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// The linear model about an operating point, x' = A x + B u, y = C x + D u, in the
    /// chapter's states (the integral-causality inertias' displacements and flows), with its
    /// modes (eigenvalues of A: natural frequency, damping ratio, shape) and, with --bode,
    /// its frequency response.
    Linearize {
        /// Scene file (JSON; `-` reads standard input).
        scene: PathBuf,
        /// Change one scene field first: PATH=JSON (as `run --set`).
        #[arg(long = "set", value_name = "PATH=JSON")]
        set: Vec<String>,
        /// The operating point: `equilibrium` (the static equilibrium nearest the scene's
        /// configuration) or `t=T` (the solved state at time T, s).
        #[arg(long, default_value = "equilibrium")]
        at: String,
        /// An output column y (a run CSV column of the bodies' motion, or a state); repeat for
        /// several. Default: the states.
        #[arg(long = "output", value_name = "COLUMN")]
        output: Vec<String>,
        /// The independent coordinates (and velocities) by name, comma-separated, instead of
        /// the causality's choice (e.g. `bar1.x,bar2.x`).
        #[arg(long, value_delimiter = ',')]
        states: Option<Vec<String>>,
        /// Write the linear model as JSON to this file (at, operating_point, states, inputs,
        /// outputs, A, B, C, D, modes).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Draw the Bode plot (magnitude and phase of every input → output pair) to this SVG.
        #[arg(long)]
        bode: Option<PathBuf>,
    },
    /// Solve the DAE (IDA) and the decoupled twin (CVODE) side by side.
    Compare {
        #[command(flatten)]
        args: SolveArgs,
        /// Write the comparison as JSON to this file.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Animate the solved motion: one self-contained SVG (SMIL) or HTML file.
    Animate {
        #[command(flatten)]
        args: SolveArgs,
        /// Output file: `.svg` (animated with SMIL) or `.html` (with play/pause and a slider).
        #[arg(long, default_value = "motion.svg")]
        out: PathBuf,
        /// Frames per second of playback.
        #[arg(long, default_value_t = 30.0)]
        fps: f64,
        /// Seconds of motion per second of playback (0.5: slow motion). Default: 1, or slower
        /// (said on the page) when a body would turn more than 15° in one frame of playback.
        #[arg(long)]
        speed: Option<f64>,
        /// Orthographic view (default: xy for a planar scene, iso for a spatial one).
        #[arg(long, value_enum)]
        view: Option<ViewArg>,
        /// Animate the motion in this CSV (as `bondmech run` writes it, or another tool's with
        /// the same column names) instead of solving the scene.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Also write the frames exactly as drawn to this JSON file:
        /// `{"frames": [{"t": …, "points": {"body.point": [x, y(, z)], …}}, …]}`.
        #[arg(long)]
        frames: Option<PathBuf>,
    },
    /// SVG plots against time of a run's CSV: coordinates, velocities, energy, constraint error.
    Plot {
        /// The CSV that `bondmech run` wrote (or another tool's, `t` or `time` first).
        csv: PathBuf,
        /// Output directory (one SVG per group of columns).
        #[arg(long, default_value = "plots")]
        out: PathBuf,
        /// The columns to draw (comma-separated names, or prefixes ending in `*`: `bar2.*`).
        #[arg(long, value_name = "COL,COL,...", value_delimiter = ',')]
        columns: Option<Vec<String>>,
        /// The plots' title (default: the CSV's file name without extension).
        #[arg(long)]
        title: Option<String>,
    },
    /// Speed against error: tolerance (work-precision) and joint-stiffness sweeps, CSV/JSON/SVG.
    Sweep {
        /// Scene file (JSON).
        scene: PathBuf,
        /// Output directory for the CSV, JSON and SVG files.
        #[arg(long, default_value = "sweep-out")]
        out: PathBuf,
        /// A small sweep (3 tolerances, 3 stiffnesses, the scene's horizon up to 1 s, each point
        /// timed by its own run and stopped after 2 s of wall clock).
        #[arg(long)]
        quick: bool,
        /// Error the smallest sufficient joint stiffness must reach.
        #[arg(long)]
        accuracy: Option<f64>,
        /// Timed runs per point (median reported).
        #[arg(long)]
        repeats: Option<usize>,
        /// End time of every run (default: the scene's; --quick: the scene's, at most 1 s).
        #[arg(long = "t-end")]
        t_end: Option<f64>,
        /// An independent reference solution (CSV as `run` writes it: `t,<columns>`); errors are
        /// measured against it, at its times, instead of against GGL at a tight tolerance.
        #[arg(long)]
        reference: Option<PathBuf>,
        /// Sweep a scene parameter instead: PATH=[v1, v2, ...], e.g. 'bodies[1].mass=[1,2,4]' or
        /// 'gravity=[[0,-9.81],[0,-1.62]]'; several give the cartesian product (first slowest).
        #[arg(long = "vary", value_name = "PATH=[JSON,...]")]
        vary: Vec<String>,
        /// Change one scene field before sweeping: PATH=JSON (repeatable).
        #[arg(long = "set", value_name = "PATH=JSON")]
        set: Vec<String>,
        /// With --vary: run only the i-th of n slices (points k with k mod n = i-1) and write a
        /// partial result for `sweep-merge`.
        #[arg(long, value_name = "i/n")]
        shard: Option<String>,
        /// With --vary: the final-state columns to report (comma-separated; default all).
        #[arg(long, value_name = "COL,COL,...", value_delimiter = ',')]
        columns: Option<Vec<String>>,
    },
    /// Combine the shards of a `sweep --vary ... --shard i/n` into the whole sweep's CSV/JSON/SVG.
    SweepMerge {
        /// The shards' output directories (all n of them, any order).
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory for the merged result (not one of the shards').
        #[arg(long)]
        out: PathBuf,
    },
    /// Serve the HTTP/JSON API until SIGTERM or Ctrl-C (routes: docs/service.md).
    Serve(bondmech::service::ServeArgs),
    /// Export a scene as a co-simulation FMU (FMI 3.0, or 2.0 with --fmi 2; docs/fmu.md).
    Fmu(fmu_cmd::FmuArgs),
}

/// A failure of a command, with what the command still managed to do (e.g. where the rows of
/// a run stopped part-way were written).
struct CliError {
    error: Error,
    note: Option<String>,
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    // the commands that solve stop at the next step on SIGINT or SIGTERM and keep their rows;
    // the others (and `serve`, which drains its requests itself) keep the default
    if matches!(
        cli.command,
        Command::Run { .. }
            | Command::Compare { .. }
            | Command::Animate { .. }
            | Command::Sweep { .. }
    ) {
        watch_interrupts();
    }
    let result = run(cli);
    let interrupted = bondmech::interrupt::requested();
    match result {
        Ok(()) => match interrupted {
            // the interrupt came after the work was done: the outputs are complete, and the
            // exit status says the command was interrupted all the same
            Some(signal) => exit_status_of(signal),
            None => ExitCode::SUCCESS,
        },
        // the reader of standard output went away (`| head`): nothing left to tell anyone
        Err(e) if is_broken_pipe(&e.error) => ExitCode::SUCCESS,
        Err(CliError { error, note }) => {
            let mut msg = error.to_string().replace('\n', "; ");
            if let Some(n) = note {
                msg = format!("{msg}; {n}");
            }
            eprintln!("bondmech: {msg}");
            match interrupted {
                Some(signal) => exit_status_of(signal),
                None => ExitCode::FAILURE,
            }
        }
    }
}

/// Whether `signal` was ignored when the program started (its bit in `SigIgn` of
/// `/proc/self/status`; `false` where that cannot be read).
fn ignored_at_start(signal: i32) -> bool {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else {
        return false;
    };
    status
        .lines()
        .find_map(|l| l.strip_prefix("SigIgn:"))
        .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
        .is_some_and(|mask| mask & (1 << (signal - 1)) != 0)
}

/// The shell's exit status of a command ended by `signal`: `128 + signal` (130 for SIGINT,
/// 143 for SIGTERM).
fn exit_status_of(signal: i32) -> ExitCode {
    ExitCode::from(u8::try_from(128 + signal).unwrap_or(u8::MAX))
}

/// Handles SIGINT and SIGTERM on a thread of their own (tokio's signal handling, which installs
/// the handlers safely and wakes the thread): the first asks the solve to stop at its next step
/// ([`bondmech::interrupt::request`]: the rows so far are written as after a budget stop, the
/// summary says `stopped_by: "interrupt"`, the exit status is 128 + signal); a second one exits
/// at once with 128 + its number, after removing the temporary files of the outputs being
/// written (their targets are left as they were). Returns once the handlers are in place.
fn watch_interrupts() {
    use bondmech::interrupt::{request, signal_name, SIGINT, SIGTERM};
    let (ready, wait_ready) = std::sync::mpsc::channel::<()>();
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let Ok(rt) = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
            else {
                let _ = ready.send(());
                return;
            };
            rt.block_on(async move {
                use tokio::signal::unix::{signal, Signal, SignalKind};
                // a signal ignored when the program started (`nohup`, `cmd &` in a script) stays
                // ignored, as it would without a handler
                let listen = |sig: i32, kind: SignalKind| -> Result<Option<Signal>, ()> {
                    if ignored_at_start(sig) {
                        return Ok(None);
                    }
                    signal(kind).map(Some).map_err(drop)
                };
                let (Ok(mut int), Ok(mut term)) = (
                    listen(SIGINT, SignalKind::interrupt()),
                    listen(SIGTERM, SignalKind::terminate()),
                ) else {
                    let _ = ready.send(());
                    return;
                };
                let _ = ready.send(());
                async fn next(s: &mut Option<Signal>) -> Option<()> {
                    match s {
                        Some(s) => s.recv().await,
                        None => std::future::pending().await,
                    }
                }
                loop {
                    let sig = tokio::select! {
                        Some(()) = next(&mut int) => SIGINT,
                        Some(()) = next(&mut term) => SIGTERM,
                        else => return,
                    };
                    if request(sig) {
                        eprintln!(
                            "bondmech: {} received: stopping at the next step, the rows so far are kept (again to quit at once)",
                            signal_name(sig)
                        );
                    } else {
                        bondmech::output::remove_temporaries();
                        std::process::exit(128 + sig);
                    }
                }
            });
        });
    if spawned.is_ok() {
        let _ = wait_ready.recv();
    }
}

fn options_error(message: String) -> CliError {
    Error::Options(message).into()
}

fn is_broken_pipe(e: &Error) -> bool {
    matches!(e, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe)
}

/// Reads a scene file, or standard input for `-`.
fn read_scene(path: &Path) -> Result<Scene, Error> {
    if path == Path::new("-") {
        let mut text = String::new();
        std::io::stdin()
            .read_to_string(&mut text)
            .map_err(|source| Error::Io {
                path: "standard input".into(),
                source,
            })?;
        return Ok(Scene::from_json_str(&text)?);
    }
    Ok(Scene::from_path(path)?)
}

/// Reads the text of a scene file, or of standard input for `-`, and its default name.
fn read_scene_text(path: &Path) -> Result<(String, String), Error> {
    if path == Path::new("-") {
        let mut text = String::new();
        std::io::stdin()
            .read_to_string(&mut text)
            .map_err(|source| Error::Io {
                path: "standard input".into(),
                source,
            })?;
        return Ok((text, "scene".into()));
    }
    Ok(bondmech::scene::path::read_scene_text(path)?)
}

/// [`read_scene`] with `--set PATH=JSON` assignments applied (in order) before validation.
fn read_scene_with(path: &Path, sets: &[String]) -> Result<Scene, Error> {
    if sets.is_empty() {
        return read_scene(path);
    }
    let (text, name) = read_scene_text(path)?;
    Ok(bondmech::scene::path::scene_from_json_with_sets(
        &text, &name, sets,
    )?)
}

/// Writes the flags into the scene's `solve` section and validates the scene again, so that a
/// flag obeys the scene's own rules; a refusal names the flag and the field.
fn apply_flags(scene: &mut Scene, args: &SolveArgs) -> Result<(), Error> {
    apply_overrides(
        scene,
        &SolveOverrides {
            formulation: args.formulation,
            rtol: args.rtol,
            atol: args.atol,
            t_end: args.t_end,
            joint_stiffness: args.joint_stiffness,
            max_steps: args.max_steps,
            max_wall_seconds: args.max_wall_seconds,
            linear_solver: args.linear_solver,
        },
    )
}

fn parse_linear_solver(s: &str) -> Result<bondmech::LinearSolverKind, String> {
    bondmech::LinearSolverKind::parse(s)
        .ok_or_else(|| format!("unknown linear solver '{s}' (expected auto, dense, sparse or klu)"))
}

/// [`SolveOverrides::apply`], each refusal naming its flag (`--t-end: solve.output_step: …`).
fn apply_overrides(scene: &mut Scene, overrides: &SolveOverrides) -> Result<(), Error> {
    overrides.apply(scene).map_err(|problems| {
        let lines: Vec<String> = problems
            .iter()
            .map(|p| match p.overridden {
                Some(field) => format!("--{}: {}", field.replace('_', "-"), p.problem),
                None => p.problem.to_string(),
            })
            .collect();
        Error::Options(lines.join("\n"))
    })
}

/// Loads a scene (a mechanism or a raw bond graph) and its options, with the flags applied.
fn load(args: &SolveArgs) -> Result<(Model, SolveOptions), Error> {
    let mut scene = read_scene_with(&args.scene, &args.set)?;
    if args.reactions && !scene.outputs.iter().any(|o| o == "reactions") {
        scene.outputs.push("reactions".into());
    }
    apply_flags(&mut scene, args)?;
    let model = Model::new(&scene)?;
    let opts = model.default_options();
    Ok((model, opts))
}

/// Prints non-fatal remarks to standard error, one line each.
fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("bondmech: warning: {}", w.replace('\n', "; "));
    }
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Writes `text` to `path` atomically (beside it, then renamed into place).
fn write(path: &Path, text: &str) -> Result<(), Error> {
    bondmech::output::write_atomic(path, text.as_bytes()).map_err(io_error(path))
}

/// Writes to standard output; a closed pipe comes back as a `BrokenPipe` I/O error.
fn stdout_write(text: &str) -> Result<(), Error> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(io_error(Path::new("standard output")))
}

/// Refuses an output that is an input (same path, hard or symbolic link), given twice, or
/// not writable — before anything is solved ([`bondmech::output::check_outputs`]).
fn check_outputs(inputs: &[&Path], outputs: &[(&str, Option<&Path>)]) -> Result<(), Error> {
    Ok(bondmech::output::check_outputs(inputs, outputs)?)
}

/// Where `run` streams its rows: a file written atomically, or standard output.
enum RowSink {
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

/// Writes the summary JSON atomically.
fn write_summary(path: &Path, summary: &bondmech::Summary) -> Result<(), Error> {
    let j = serde_json::to_string_pretty(summary).expect("summary serialises");
    write(path, &j)
}

/// `bondmech run`: the rows stream to `--out` (or standard output) as they are computed, so
/// memory stays bounded whatever their number; they are kept in memory only for `--table`
/// and `--plot`. A run stopped by a budget writes the rows it computed, then fails.
fn run_command(
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
        let mut text = short_table(&sol, 11);
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
        for e in &s.events {
            text.push_str(&format!("event {} at t = {}\n", e.name, e.t));
        }
        stdout_write(&text)?;
    }
    Ok(())
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Run {
            args,
            out,
            summary,
            table,
            plot,
        } => {
            // `--out -`: the CSV on standard output, asked for explicitly
            let dash = out.as_deref() == Some(Path::new("-"));
            let out = if dash { None } else { out };
            // with --plot, the CSV goes to the terminal only when asked
            let no_csv = table || (plot.is_some() && out.is_none() && !dash);
            run_command(
                &args,
                out.as_deref(),
                summary.as_deref(),
                (table, no_csv),
                plot.as_deref(),
            )
        }
        Command::Equilibrium { scene, set, json } => {
            let model = Model::new(&read_scene_with(&scene, &set)?)?;
            let eq = model.equilibrium()?;
            if let Some(path) = json {
                let text = serde_json::to_string_pretty(&eq.to_json())
                    .map_err(|e| options_error(e.to_string()))?;
                std::fs::write(&path, text + "\n")
                    .map_err(|e| options_error(format!("cannot write {}: {e}", path.display())))?;
            }
            let mut t = format!(
                "equilibrium: {} after {} iterations (residual {:.3e}), {}\n",
                if eq.converged {
                    "converged"
                } else {
                    "not converged"
                },
                eq.iterations,
                eq.residual,
                if eq.stable { "stable" } else { "unstable" }
            );
            for (what, list) in [
                ("coordinates", &eq.coordinates),
                ("reactions", &eq.reactions),
                ("drivers", &eq.drivers),
            ] {
                if !list.is_empty() {
                    t.push_str(&format!("{what}:\n"));
                    for (k, v) in list {
                        t.push_str(&format!("  {k:<24} {v:>22.15e}\n"));
                    }
                }
            }
            t.push_str(&format!(
                "stiffness eigenvalues: {:?}\n",
                eq.stiffness_eigenvalues
            ));
            Ok(stdout_write(&t)?)
        }
        Command::Linearize {
            scene,
            set,
            at,
            output,
            states,
            json,
            bode,
        } => {
            let at: bondmech::OperatingPoint = at.parse().map_err(Error::from)?;
            if let Some(p) = &bode {
                let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
                if !ext.eq_ignore_ascii_case("svg") {
                    return Err(options_error(format!(
                        "--bode {}: the Bode plot is an SVG file (give a .svg path)",
                        p.display()
                    )));
                }
            }
            let scene = read_scene_with(&scene, &set)?;
            let options = bondmech::LinearizeOptions {
                at,
                outputs: output,
                states,
            };
            let lm = bondmech::linearize(&scene, &options)?;
            if let Some(path) = json {
                let text = serde_json::to_string_pretty(&lm.to_json())
                    .map_err(|e| options_error(e.to_string()))?;
                std::fs::write(&path, text + "\n")
                    .map_err(|e| options_error(format!("cannot write {}: {e}", path.display())))?;
            }
            if let Some(path) = bode {
                bondmech::report::bode::bode_svg(&lm, &scene.name, &path)
                    .map_err(|e| Error::Report(Box::new(e)))?;
            }
            Ok(stdout_write(&lm.table())?)
        }
        Command::Equations { scene } => {
            let model = Model::new(&read_scene(&scene)?)?;
            if model.is_raw_bond_graph() {
                return Err(options_error(
                    "equations: a raw bond graph scene is solved from its causal equations; `graph --causality` shows them".into(),
                ));
            }
            Ok(stdout_write(&model.equations().to_string())?)
        }
        Command::Graph {
            scene,
            causality,
            decoupled,
            as_scene,
            out,
            collapse,
            expand,
        } => {
            if as_scene {
                if let Some(p) = out.as_ref() {
                    let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
                    if !ext.eq_ignore_ascii_case("json") {
                        return Err(options_error(format!(
                            "--out {}: --as-scene writes a JSON scene; give --out a .json file",
                            p.display()
                        )));
                    }
                }
                check_outputs(&[&scene], &[("--out", out.as_deref())])?;
                let v = bondmech::graph::bond_graph_scene(&read_scene(&scene)?)?;
                let text = serde_json::to_string_pretty(&v).expect("scene serialises") + "\n";
                return match out {
                    Some(p) => Ok(write(&p, &text)?),
                    None => Ok(stdout_write(&text)?),
                };
            }
            // the causality report is JSON: refuse to write it into a drawing's file
            if let Some(p) = out.as_ref().filter(|_| causality) {
                let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
                if ext.eq_ignore_ascii_case("svg") || ext.eq_ignore_ascii_case("dot") {
                    return Err(options_error(format!(
                        "--out {}: --causality writes the causality report as JSON; give --out a .json file (or draw the graph without --causality)",
                        p.display()
                    )));
                }
            }
            check_outputs(&[&scene], &[("--out", out.as_deref())])?;
            let model = Model::new(&read_scene(&scene)?)?;
            if decoupled && model.is_raw_bond_graph() {
                return Err(options_error(
                    "--decoupled: a raw bond graph has no joints to decouple".into(),
                ));
            }
            // the scene's own `solve.formulation: "decoupled"` draws the twin too
            let decoupled = decoupled
                || (!model.is_raw_bond_graph()
                    && model.scene().solve.formulation == bondmech::FormulationKind::Decoupled);
            let variant = if decoupled {
                bondmech::mech::Variant::Decoupled
            } else {
                bondmech::mech::Variant::Pinned
            };
            let g = model.scene_graph(variant)?;
            let text = if causality {
                serde_json::to_string_pretty(&g.report()).expect("report serialises") + "\n"
            } else if collapse || expand {
                g.dot_with(collapse)
            } else {
                g.dot()
            };
            match out {
                Some(p) if p.extension().is_some_and(|e| e == "svg") => Ok(svg(&text, &p)?),
                Some(p) => Ok(write(&p, &text)?),
                None => Ok(stdout_write(&text)?),
            }
        }
        Command::Animate {
            args,
            out,
            fps,
            speed,
            view,
            csv,
            frames,
        } => Ok(animate(
            &args,
            &out,
            AnimateFlags {
                fps,
                speed,
                view,
                csv: csv.as_deref(),
                frames: frames.as_deref(),
            },
        )?),
        Command::Plot {
            csv,
            out,
            columns,
            title,
        } => {
            bondmech::output::check_output_dir("--out", &out, &[&csv]).map_err(Error::from)?;
            let sol = bondmech::report::reference::reference_from_csv(&csv)?;
            let opts = bondmech::report::timeplot::PlotOptions {
                title: title.unwrap_or_default(),
                columns,
            };
            let files = bondmech::report::timeplot::plot_solution_with(
                &sol,
                &csv.display().to_string(),
                &out,
                &opts,
            )?;
            for f in files {
                println!("wrote {}", f.display());
            }
            Ok(())
        }
        Command::Compare { args, json } => {
            if args.formulation == Some(FormulationKind::Decoupled) {
                return Err(options_error(
                    "--formulation decoupled: compare always solves the decoupled twin as its second run; --formulation chooses the DAE side (dae, compliant_ggl or index1)".into(),
                ));
            }
            check_outputs(&[&args.scene], &[("--json", json.as_deref())])?;
            let (model, opts) = load(&args)?;
            let (cmp, dae, twin) = model.compare(&opts)?;
            let mut warnings = dae.summary.warnings.clone();
            for w in &twin.summary.warnings {
                if !warnings.contains(w) {
                    warnings.push(w.clone());
                }
            }
            print_warnings(&warnings);
            stdout_write(&cmp.table())?;
            if let Some(p) = &json {
                let j = serde_json::to_string_pretty(&cmp).expect("comparison serialises");
                write(p, &j)?;
            }
            Ok(())
        }
        Command::Sweep {
            scene,
            out,
            quick,
            accuracy,
            repeats,
            t_end,
            reference,
            vary,
            set,
            shard,
            columns,
        } => {
            use bondmech::report::SweepConfig;
            if out.exists() && !out.is_dir() {
                return Err(options_error(format!(
                    "--out {}: is a file; sweep writes a directory of CSV, JSON and SVG files",
                    out.display()
                )));
            }
            if let Some(r) = &reference {
                if bondmech::output::resolved(r).starts_with(bondmech::output::resolved(&out)) {
                    return Err(options_error(format!(
                        "--out {}: contains the reference {}; the sweep's files could overwrite it",
                        out.display(),
                        r.display()
                    )));
                }
            }
            if !vary.is_empty() {
                let flags = [
                    ("--quick", quick),
                    ("--accuracy", accuracy.is_some()),
                    ("--repeats", repeats.is_some()),
                ];
                if let Some((f, _)) = flags.iter().find(|(_, given)| *given) {
                    return Err(options_error(format!(
                        "{f} belongs to the tolerance/stiffness sweep, not to a --vary sweep"
                    )));
                }
                let spec = VaryArgs {
                    set,
                    vary,
                    shard,
                    t_end,
                    columns,
                    reference,
                };
                return Ok(vary_sweep(&scene, &out, spec)?);
            }
            if shard.is_some() || columns.is_some() {
                return Err(options_error(
                    "--shard and --columns need --vary (the tolerance/stiffness sweep is not sharded)"
                        .into(),
                ));
            }
            let mut inputs = vec![scene.as_path()];
            inputs.extend(reference.as_deref());
            bondmech::report::vary::check_out_dir(&out, &inputs)?;
            let mut scene_data = read_scene_with(&scene, &set)?;
            if let Some(t) = t_end {
                let t_end = SolveOverrides {
                    t_end: Some(t),
                    ..SolveOverrides::default()
                };
                apply_overrides(&mut scene_data, &t_end)?;
            }
            let model = Model::new(&scene_data)?;
            if model.is_raw_bond_graph() {
                return Err(options_error(
                    "sweep needs bodies and joints (a raw bond graph has no decoupled twin)".into(),
                ));
            }
            let mut cfg = if quick {
                SweepConfig::quick()
            } else {
                SweepConfig::full()
            };
            cfg.accuracy = accuracy.unwrap_or(cfg.accuracy);
            if let Some(r) = repeats {
                if !(1..=MAX_REPEATS).contains(&r) {
                    return Err(options_error(format!(
                        "--repeats: must be between 1 and {MAX_REPEATS} (got {r})"
                    )));
                }
            }
            if let Some(a) = accuracy {
                if !(a.is_finite() && a > 0.0) {
                    return Err(options_error(format!(
                        "--accuracy: must be > 0 and finite (got {a})"
                    )));
                }
            }
            cfg.repeats = repeats.unwrap_or(cfg.repeats);
            if let Some(t) = t_end {
                cfg.t_end = Some(t);
            }
            if let Some(path) = reference {
                cfg.reference = Some(bondmech::report::ExternalReference {
                    source: path.display().to_string(),
                    solution: bondmech::report::reference::reference_from_csv(&path)?,
                });
            }
            let report = bondmech::study::sweep::sweep_command(&model, &cfg, &out)?;
            Ok(stdout_write(&format!(
                "{}wrote {}\n",
                report.table(),
                out.display()
            ))?)
        }
        Command::SweepMerge { dirs, out } => {
            let merged = bondmech::report::vary::merge_command(&dirs, &out)?;
            Ok(stdout_write(&format!(
                "{}merged {} shards into {}\n",
                merged.table(),
                dirs.len(),
                out.display()
            ))?)
        }
        Command::Fmu(args) => Ok(fmu_cmd::export(&args)?),
        Command::Serve(args) => {
            let config = args.config().map_err(Error::Options)?;
            let addr = config.addr.to_string();
            Ok(
                bondmech::service::run(config)
                    .map_err(|source| Error::Io { path: addr, source })?,
            )
        }
    }
}

/// Most timed runs per point of `sweep --repeats` (the median of more says nothing new).
const MAX_REPEATS: usize = 100;

/// The flags of a `sweep --vary`.
struct VaryArgs {
    set: Vec<String>,
    vary: Vec<String>,
    shard: Option<String>,
    t_end: Option<f64>,
    columns: Option<Vec<String>>,
    reference: Option<PathBuf>,
}

/// `sweep --vary`: a parameter sweep (whole, or one shard of it).
fn vary_sweep(scene: &Path, out: &Path, a: VaryArgs) -> Result<(), Error> {
    use bondmech::report::vary::Shard;
    use bondmech::study::vary::{vary_command, VarySweep};
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    let (text, name) = read_scene_text(scene)?;
    let reference = match &a.reference {
        Some(path) => Some(bondmech::report::ExternalReference {
            source: path.display().to_string(),
            solution: bondmech::report::reference::reference_from_csv(path)?,
        }),
        None => None,
    };
    let sweep = VarySweep::new(&text, &name, &a.set, &a.vary, a.t_end, a.columns, reference)?;
    let mut inputs = vec![scene];
    inputs.extend(a.reference.as_deref());
    let report = vary_command(&sweep, shard, out, &inputs)?;
    stdout_write(&format!("{}wrote {}\n", report.table(), out.display()))
}

/// The flags of `bondmech animate` besides the solve flags.
struct AnimateFlags<'a> {
    fps: f64,
    speed: Option<f64>,
    view: Option<ViewArg>,
    csv: Option<&'a Path>,
    frames: Option<&'a Path>,
}

/// `bondmech animate`: solve the scene (or read `--csv`) and write the animation.
fn animate(args: &SolveArgs, out: &Path, flags: AnimateFlags) -> Result<(), Error> {
    use bondmech::report::animate::{
        animation, denser_output_times, frames_json, AnimationFormat, AnimationOptions, View,
    };
    let AnimateFlags {
        fps,
        speed,
        view,
        csv,
        frames,
    } = flags;
    let inputs: Vec<&Path> = std::iter::once(args.scene.as_path()).chain(csv).collect();
    check_outputs(&inputs, &[("--out", Some(out)), ("--frames", frames)])?;
    if let Some(f) = frames {
        if f.extension().and_then(|e| e.to_str()) != Some("json") {
            return Err(Error::Options(format!(
                "--frames {}: give a .json file",
                f.display()
            )));
        }
    }
    let format = match out.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("svg") => AnimationFormat::Svg,
        Some(e) if e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm") => {
            AnimationFormat::Html
        }
        _ => {
            return Err(Error::Options(format!(
                "--out {}: give a .svg or .html file",
                out.display()
            )))
        }
    };
    let mut scene = read_scene_with(&args.scene, &args.set)?;
    if scene.bodies.is_empty() {
        return Err(Error::Options(format!(
            "{}: animate needs a scene with bodies (a raw bond graph has no geometry to draw)",
            args.scene.display()
        )));
    }
    let (sol, source) = match csv {
        Some(path) => {
            let solve_flags = args.formulation.is_some()
                || args.rtol.is_some()
                || args.atol.is_some()
                || args.t_end.is_some()
                || args.joint_stiffness.is_some()
                || args.max_steps.is_some()
                || args.max_wall_seconds.is_some()
                || args.linear_solver.is_some();
            if solve_flags {
                return Err(Error::Options(format!(
                    "--csv {}: the motion comes from the CSV; the solve flags (--formulation, --rtol, --atol, --t-end, --joint-stiffness, --max-steps, --max-wall-seconds, --linear-solver) apply only when animate solves the scene",
                    path.display()
                )));
            }
            (
                bondmech::report::reference::reference_from_csv(path)?,
                path.display().to_string(),
            )
        }
        None => {
            apply_flags(&mut scene, args)?;
            let model = Model::new(&scene)?;
            let mut opts = model.default_options();
            let mut sol = model.solve(&opts)?;
            // rows close enough that every frame is a row: no body turning more than 15°
            // (a refinement cut from coarse rows may still miss, hence a few rounds)
            for _ in 0..4 {
                let Some(times) = denser_output_times(&scene, &sol)? else {
                    break;
                };
                opts.output_times = times.into_iter().filter(|&t| t >= opts.t_start).collect();
                sol = model.solve(&opts)?;
            }
            print_warnings(&sol.summary.warnings);
            (sol, format!("the solution of {}", args.scene.display()))
        }
    };
    let opts = AnimationOptions {
        fps,
        speed,
        view: view.map(|v| match v {
            ViewArg::Xy => View::Xy,
            ViewArg::Xz => View::Xz,
            ViewArg::Yz => View::Yz,
            ViewArg::Iso => View::Iso,
        }),
        source,
        ..AnimationOptions::default()
    };
    let text = animation(&scene, &sol, &opts, format)?;
    write(out, &text)?;
    println!("wrote {}", out.display());
    if let Some(f) = frames {
        write(f, &frames_json(&scene, &sol, &opts)?)?;
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// Renders DOT to SVG with Graphviz, written atomically to `path`.
fn svg(dot: &str, path: &Path) -> Result<(), Error> {
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

/// About `rows` evenly spaced rows of the first few columns.
fn short_table(sol: &bondmech::Solution, rows: usize) -> String {
    let cols: Vec<usize> = (0..sol.columns.len().min(6)).collect();
    let mut s = format!("{:>8}", "t");
    for &c in &cols {
        s.push_str(&format!(" {:>14}", sol.columns[c]));
    }
    s.push('\n');
    let n = sol.times.len();
    let stride = (n.max(2) - 1).div_ceil(rows.max(2) - 1).max(1);
    for k in (0..n).step_by(stride).chain(std::iter::once(n - 1)) {
        if k % stride != 0 && k != n - 1 {
            continue;
        }
        s.push_str(&format!("{:>8.3}", sol.times[k]));
        for &c in &cols {
            s.push_str(&format!(" {:>14.6}", sol.rows[k][c]));
        }
        s.push('\n');
        if k == n - 1 {
            break;
        }
    }
    s
}
