//! The `bondmech` command line: a thin layer over the library.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bondmech::{Error, FormulationKind, Model, Scene, SolveOptions};
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
    /// Scene file (JSON, see docs/scene-format).
    scene: PathBuf,
    /// dae (GGL, IDA), compliant_ggl, index1, or decoupled (stiff springs, CVODE).
    #[arg(long)]
    formulation: Option<String>,
    /// Relative tolerance.
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance.
    #[arg(long)]
    atol: Option<f64>,
    /// End time (s).
    #[arg(long = "t-end")]
    t_end: Option<f64>,
    /// Joint stiffness of the decoupled twin (N/m).
    #[arg(long = "joint-stiffness")]
    joint_stiffness: Option<f64>,
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
        /// Write to this file instead of standard output; `.svg` runs Graphviz `dot`. With
        /// `--causality` the file gets the JSON report, so `.svg` and `.dot` are refused.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Solve the DAE (IDA) and the decoupled twin (CVODE) side by side.
    Compare {
        #[command(flatten)]
        args: SolveArgs,
        /// Write the comparison as JSON to this file.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Speed against error: tolerance (work-precision) and joint-stiffness sweeps, CSV/JSON/SVG.
    Sweep {
        /// Scene file (JSON).
        scene: PathBuf,
        /// Output directory for the CSV, JSON and SVG files.
        #[arg(long, default_value = "sweep-out")]
        out: PathBuf,
        /// A small sweep (3 tolerances, 3 stiffnesses, 1 s, one timed run per point).
        #[arg(long)]
        quick: bool,
        /// Error the smallest sufficient joint stiffness must reach.
        #[arg(long)]
        accuracy: Option<f64>,
        /// Timed runs per point (median reported).
        #[arg(long)]
        repeats: Option<usize>,
        /// End time of every run (default: the scene's; --quick: 1 s).
        #[arg(long = "t-end")]
        t_end: Option<f64>,
        /// An independent reference solution (CSV as `run` writes it: `t,<columns>`); errors are
        /// measured against it, at its times, instead of against GGL at a tight tolerance.
        #[arg(long)]
        reference: Option<PathBuf>,
    },
    /// Serve the HTTP/JSON API until SIGTERM or Ctrl-C (routes: docs/service.md).
    Serve(bondmech::service::ServeArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg = e.to_string().replace('\n', "; ");
            eprintln!("bondmech: {msg}");
            ExitCode::FAILURE
        }
    }
}

/// Loads a scene (a mechanism or a raw bond graph) and its options, with the flags applied.
fn load(args: &SolveArgs) -> Result<(Model, SolveOptions), Error> {
    let model = Model::new(&Scene::from_path(&args.scene)?)?;
    let mut opts = model.default_options();
    if let Some(f) = &args.formulation {
        opts.formulation = FormulationKind::parse(f).ok_or_else(|| {
            Error::Options(format!(
                "--formulation: unknown '{f}' (expected dae, ggl, compliant_ggl, index1 or decoupled)"
            ))
        })?;
    }
    if let Some(r) = args.rtol {
        opts.rtol = r;
    }
    if let Some(a) = args.atol {
        opts.atol = a;
    }
    if let Some(k) = args.joint_stiffness {
        if !(k > 0.0 && k.is_finite()) {
            return Err(Error::Options(format!(
                "--joint-stiffness: must be > 0 (got {k})"
            )));
        }
        opts.joint_stiffness = k;
    }
    if let Some(t) = args.t_end {
        if !(t > 0.0 && t.is_finite()) {
            return Err(Error::Options(format!("--t-end: must be > 0 (got {t})")));
        }
        opts.output_times = model.output_times_until(t)?;
    }
    Ok((model, opts))
}

/// Prints non-fatal remarks to standard error, one line each.
fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("bondmech: warning: {}", w.replace('\n', "; "));
    }
}

fn write(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|source| Error::Io {
        path: path.display().to_string(),
        source,
    })
}

fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Run {
            args,
            out,
            summary,
            table,
        } => {
            let (model, opts) = load(&args)?;
            let sol = model.solve(&opts)?;
            // the model's own warnings, redundant joints, singular passages, re-selections
            print_warnings(&sol.summary.warnings);
            let csv = sol.to_csv();
            match &out {
                Some(p) => write(p, &csv)?,
                None if !table => print!("{csv}"),
                None => {}
            }
            if table {
                print!("{}", short_table(&sol, 11));
                let s = &sol.summary;
                println!(
                    "{}: {} steps, {} residual evals, {} Jacobians, CPU {:.3e} s, max constraint error {:.2e}, energy drift {:.2e}",
                    s.formulation, s.steps, s.residual_evals, s.jacobian_evals, s.cpu_seconds,
                    s.max_constraint_error, s.energy_drift
                );
            }
            if let Some(p) = &summary {
                let j = serde_json::to_string_pretty(&sol.summary).expect("summary serialises");
                write(p, &j)?;
            }
            Ok(())
        }
        Command::Graph {
            scene,
            causality,
            decoupled,
            out,
        } => {
            // the causality report is JSON: refuse to write it into a drawing's file
            if let Some(p) = out.as_ref().filter(|_| causality) {
                let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
                if ext.eq_ignore_ascii_case("svg") || ext.eq_ignore_ascii_case("dot") {
                    return Err(Error::Options(format!(
                        "--out {}: --causality writes the causality report as JSON; give --out a .json file (or draw the graph without --causality)",
                        p.display()
                    )));
                }
            }
            let model = Model::new(&Scene::from_path(&scene)?)?;
            let variant = if decoupled {
                bondmech::mech::Variant::Decoupled
            } else {
                bondmech::mech::Variant::Pinned
            };
            let g = model.scene_graph(variant)?;
            let text = if causality {
                serde_json::to_string_pretty(&g.report()).expect("report serialises") + "\n"
            } else {
                g.dot()
            };
            match out {
                Some(p) if p.extension().is_some_and(|e| e == "svg") => svg(&text, &p),
                Some(p) => write(&p, &text),
                None => {
                    print!("{text}");
                    Ok(())
                }
            }
        }
        Command::Compare { args, json } => {
            let (model, opts) = load(&args)?;
            let (cmp, dae, twin) = model.compare(&opts)?;
            let mut warnings = dae.summary.warnings.clone();
            for w in &twin.summary.warnings {
                if !warnings.contains(w) {
                    warnings.push(w.clone());
                }
            }
            print_warnings(&warnings);
            print!("{}", cmp.table());
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
        } => {
            use bondmech::report::SweepConfig;
            let model = Model::new(&Scene::from_path(&scene)?)?;
            if model.is_raw_bond_graph() {
                return Err(Error::Options(
                    "sweep needs bodies and joints (a raw bond graph has no decoupled twin)".into(),
                ));
            }
            let mut cfg = if quick {
                SweepConfig::quick()
            } else {
                SweepConfig::full()
            };
            cfg.accuracy = accuracy.unwrap_or(cfg.accuracy);
            cfg.repeats = repeats.unwrap_or(cfg.repeats);
            if let Some(t) = t_end {
                if !(t > 0.0 && t.is_finite()) {
                    return Err(Error::Options(format!("--t-end: must be > 0 (got {t})")));
                }
                cfg.t_end = Some(t);
            }
            if let Some(path) = reference {
                cfg.reference = Some(bondmech::report::ExternalReference {
                    source: path.display().to_string(),
                    solution: bondmech::report::reference::reference_from_csv(&path)?,
                });
            }
            let report = bondmech::report::sweep::sweep_command(&model, &cfg, &out)?;
            print!("{}", report.table());
            println!("wrote {}", out.display());
            Ok(())
        }
        Command::Serve(args) => {
            let config = args.config().map_err(Error::Options)?;
            let addr = config.addr.to_string();
            bondmech::service::run(config).map_err(|source| Error::Io { path: addr, source })
        }
    }
}

/// Renders DOT to SVG with Graphviz.
fn svg(dot: &str, path: &Path) -> Result<(), Error> {
    use std::io::Write;
    let mut child = std::process::Command::new("dot")
        .arg("-Tsvg")
        .arg("-o")
        .arg(path)
        .stdin(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| {
            Error::Options(format!(
                "cannot run Graphviz 'dot' ({e}): apt-get install graphviz, or write .dot"
            ))
        })?;
    child
        .stdin
        .take()
        .expect("piped stdin")
        .write_all(dot.as_bytes())
        .map_err(|source| Error::Io {
            path: "dot".into(),
            source,
        })?;
    let status = child.wait().map_err(|source| Error::Io {
        path: "dot".into(),
        source,
    })?;
    if status.success() {
        Ok(())
    } else {
        Err(Error::Options(format!("Graphviz 'dot' failed ({status})")))
    }
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
