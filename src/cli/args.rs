//! The command line's grammar: the commands, their flags and their help (clap).

use std::path::PathBuf;

use bondmech::FormulationKind;
use clap::{Parser, Subcommand};

use super::fmu;

#[derive(Parser)]
#[command(
    name = "bondmech",
    version,
    about = "Mechanisms as bond graphs, solved with SUNDIALS (IDA DAE / CVODE decoupled twin)"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(clap::Args, Clone)]
pub(crate) struct SolveArgs {
    /// Scene file (JSON, see docs/scene-format.md); `-` reads it from standard input.
    pub(crate) scene: PathBuf,
    /// Formulation (the scene's solve.formulation by default).
    #[arg(long, value_enum)]
    pub(crate) formulation: Option<FormulationKind>,
    /// Relative tolerance (solve.rtol).
    #[arg(allow_negative_numbers = true, long)]
    pub(crate) rtol: Option<f64>,
    /// Absolute tolerance (solve.atol).
    #[arg(allow_negative_numbers = true, long)]
    pub(crate) atol: Option<f64>,
    /// End time in s (solve.t_end); the scene's output times after it are dropped.
    #[arg(allow_negative_numbers = true, long = "t-end")]
    pub(crate) t_end: Option<f64>,
    /// Joint stiffness of the decoupled twin in N/m (solve.joint_stiffness).
    #[arg(allow_negative_numbers = true, long = "joint-stiffness")]
    pub(crate) joint_stiffness: Option<f64>,
    /// Step budget of the whole run (solve.max_steps; none by default).
    #[arg(allow_negative_numbers = true, long = "max-steps")]
    pub(crate) max_steps: Option<u64>,
    /// Wall-clock budget of the whole run in s (solve.max_wall_seconds; none by default).
    #[arg(allow_negative_numbers = true, long = "max-wall-seconds")]
    pub(crate) max_wall_seconds: Option<f64>,
    /// Linear solver of the Newton iterations: auto, dense, sparse (faer) or klu
    /// (solve.linear_solver; auto by default: dense for small systems, sparse for large).
    #[arg(long = "linear-solver", value_parser = parse_linear_solver)]
    pub(crate) linear_solver: Option<bondmech::LinearSolverKind>,
    /// Change one scene field before solving: PATH=JSON, e.g. 'bodies[0].mass=2',
    /// 'gravity=[0,-1.62]', 'solve.formulation="index1"' (repeatable, applied in order).
    #[arg(long = "set", value_name = "PATH=JSON")]
    pub(crate) set: Vec<String>,
    /// Add every joint's reaction columns (`J.Fx, J.Fy[, J.Fz]`, and `J.Mz` or `J.Mx, J.My,
    /// J.Mz` for prismatic, weld and hinge joints): force and moment on the joint's second
    /// body, global frame, N and N·m; as `"outputs": ["reactions"]` in the scene.
    #[arg(long)]
    pub(crate) reactions: bool,
}

/// The orthographic views of `animate --view`.
#[derive(clap::ValueEnum, Clone, Copy)]
pub(crate) enum ViewArg {
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
pub(crate) enum Command {
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
    Graph(GraphArgs),
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
        #[arg(allow_negative_numbers = true, long, default_value_t = 30.0)]
        fps: f64,
        /// Seconds of motion per second of playback (0.5: slow motion). Default: 1, or slower
        /// (said on the page) when a body would turn more than 15° in one frame of playback.
        #[arg(allow_negative_numbers = true, long)]
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
    Sweep(SweepArgs),
    /// Combine the shards of a `sweep --vary ... --shard i/n` into the whole sweep's CSV/JSON/SVG.
    SweepMerge {
        /// The shards' output directories (all n of them, any order).
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory for the merged result (not one of the shards').
        #[arg(long)]
        out: PathBuf,
    },
    /// The run's columns and their forward sensitivities `d(<column>)/d(<PATH>)` to scene
    /// parameters (IDAS, exact ∂F/∂p; docs/scene-format.md §25), as CSV.
    Sensitivity {
        #[command(flatten)]
        args: SolveArgs,
        /// A scene path as `--set` takes it: `bodies[bar2].mass`, `springs[s1].stiffness`,
        /// `gravity[1]`, `bodies[block].position[0]`, … (repeatable).
        #[arg(long = "param", value_name = "PATH", required = true)]
        params: Vec<String>,
        /// CSV output file (default: standard output).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Identify scene parameters from measurements: Levenberg–Marquardt on the exact
    /// sensitivities, from the scene's values; a table on standard output, exit 1 when the
    /// fit does not converge.
    Fit {
        #[command(flatten)]
        args: SolveArgs,
        /// The measurements: CSV whose header names `t` and run columns.
        #[arg(long)]
        data: PathBuf,
        /// A scene path to fit (repeatable), as `sensitivity --param`.
        #[arg(long = "param", value_name = "PATH", required = true)]
        params: Vec<String>,
        /// The data's columns to fit (comma-separated; default all).
        #[arg(long, value_name = "COL,COL,...", value_delimiter = ',')]
        columns: Option<Vec<String>>,
        /// Write the fit as JSON to this file (converged, iterations, parameters, std_errors,
        /// covariance, residual_rms, correlation).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Write the scene with the fitted values to this file.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Largest number of Levenberg–Marquardt iterations (default 60).
        #[arg(long = "max-iterations")]
        max_iterations: Option<usize>,
    },
    /// Serve the HTTP/JSON API until SIGTERM or Ctrl-C (routes: docs/service.md).
    Serve(bondmech::service::ServeArgs),
    /// Export a scene as a co-simulation FMU (FMI 3.0, or 2.0 with --fmi 2; docs/fmu.md).
    Fmu(fmu::FmuArgs),
}

pub(crate) fn parse_linear_solver(s: &str) -> Result<bondmech::LinearSolverKind, String> {
    bondmech::LinearSolverKind::parse(s)
        .ok_or_else(|| format!("unknown linear solver '{s}' (expected auto, dense, sparse or klu)"))
}

// The flags of `bondmech graph` (the variant's doc comment is its help).
#[derive(clap::Args)]
pub(crate) struct GraphArgs {
    /// Scene file (JSON).
    pub(crate) scene: PathBuf,
    /// Print the causality report as JSON (dof, states, differential, conflicts, …).
    #[arg(long)]
    pub(crate) causality: bool,
    /// Draw the decoupled twin (joints replaced by stiff springs) instead.
    #[arg(long)]
    pub(crate) decoupled: bool,
    /// Draw one node per body or joint (the default above 200 elements).
    #[arg(long, conflicts_with = "expand")]
    pub(crate) collapse: bool,
    /// Draw every element, however large the graph.
    #[arg(long)]
    pub(crate) expand: bool,
    /// Print the mechanism's complete bond graph as a raw `bond_graph` scene (JSON, with
    /// its closures, coordinates, output columns, `solve` and `outputs`): `run` on it gives
    /// the mechanism's trajectories.
    #[arg(long, conflicts_with_all = ["causality", "decoupled"])]
    pub(crate) as_scene: bool,
    /// Write to this file instead of standard output; `.svg` runs Graphviz `dot`. With
    /// `--causality` the file gets the JSON report, so `.svg` and `.dot` are refused.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
}

// The flags of `bondmech sweep` (the variant's doc comment is its help).
#[derive(clap::Args)]
pub(crate) struct SweepArgs {
    /// Scene file (JSON).
    pub(crate) scene: PathBuf,
    /// Output directory for the CSV, JSON and SVG files.
    #[arg(long, default_value = "sweep-out")]
    pub(crate) out: PathBuf,
    /// A small sweep (3 tolerances, 3 stiffnesses, the scene's horizon up to 1 s, each point
    /// timed by its own run and stopped after 2 s of wall clock).
    #[arg(long)]
    pub(crate) quick: bool,
    /// Error the smallest sufficient joint stiffness must reach.
    #[arg(allow_negative_numbers = true, long)]
    pub(crate) accuracy: Option<f64>,
    /// Timed runs per point (median reported).
    #[arg(allow_negative_numbers = true, long)]
    pub(crate) repeats: Option<usize>,
    /// End time of every run (default: the scene's; --quick: the scene's, at most 1 s).
    #[arg(allow_negative_numbers = true, long = "t-end")]
    pub(crate) t_end: Option<f64>,
    /// An independent reference solution (CSV as `run` writes it: `t,<columns>`); errors are
    /// measured against it, at its times, instead of against GGL at a tight tolerance.
    #[arg(long)]
    pub(crate) reference: Option<PathBuf>,
    /// Sweep a scene parameter instead: PATH=[v1, v2, ...], e.g. 'bodies[1].mass=[1,2,4]' or
    /// 'gravity=[[0,-9.81],[0,-1.62]]'; several give the cartesian product (first slowest).
    #[arg(long = "vary", value_name = "PATH=[JSON,...]")]
    pub(crate) vary: Vec<String>,
    /// Change one scene field before sweeping: PATH=JSON (repeatable).
    #[arg(long = "set", value_name = "PATH=JSON")]
    pub(crate) set: Vec<String>,
    /// With --vary: run only the i-th of n slices (points k with k mod n = i-1) and write a
    /// partial result for `sweep-merge`.
    #[arg(long, value_name = "i/n")]
    pub(crate) shard: Option<String>,
    /// With --vary: the final-state columns to report (comma-separated; default all).
    #[arg(long, value_name = "COL,COL,...", value_delimiter = ',')]
    pub(crate) columns: Option<Vec<String>>,
}
