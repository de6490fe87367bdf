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
    /// Change one scene field before solving: PATH=JSON, e.g. 'bodies[0].mass=2',
    /// 'gravity=[0,-1.62]', 'solve.formulation="index1"' (repeatable, applied in order).
    #[arg(long = "set", value_name = "PATH=JSON")]
    set: Vec<String>,
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
    let model = Model::new(&bondmech::scene::path::scene_from_path_with(
        &args.scene,
        &args.set,
    )?)?;
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
            vary,
            set,
            shard,
            columns,
        } => {
            use bondmech::report::SweepConfig;
            if !vary.is_empty() {
                let flags = [
                    ("--quick", quick),
                    ("--accuracy", accuracy.is_some()),
                    ("--repeats", repeats.is_some()),
                ];
                if let Some((f, _)) = flags.iter().find(|(_, given)| *given) {
                    return Err(Error::Options(format!(
                        "{f} belongs to the tolerance/stiffness sweep, not to a --vary sweep"
                    )));
                }
                return vary_sweep(
                    &scene,
                    &out,
                    &set,
                    &vary,
                    shard.as_deref(),
                    t_end,
                    columns,
                    reference.as_deref(),
                );
            }
            if shard.is_some() || columns.is_some() {
                return Err(Error::Options(
                    "--shard and --columns need --vary (the tolerance/stiffness sweep is not sharded)"
                        .into(),
                ));
            }
            let mut inputs = vec![scene.as_path()];
            inputs.extend(reference.as_deref());
            bondmech::report::vary::check_out_dir(&out, &inputs)?;
            let model = Model::new(&bondmech::scene::path::scene_from_path_with(&scene, &set)?)?;
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
        Command::SweepMerge { dirs, out } => {
            let merged = bondmech::report::vary::merge_command(&dirs, &out)?;
            print!("{}", merged.table());
            println!("merged {} shards into {}", dirs.len(), out.display());
            Ok(())
        }
    }
}

/// `sweep --vary`: a parameter sweep (whole, or one shard of it).
#[allow(clippy::too_many_arguments)]
fn vary_sweep(
    scene: &Path,
    out: &Path,
    set: &[String],
    vary: &[String],
    shard: Option<&str>,
    t_end: Option<f64>,
    columns: Option<Vec<String>>,
    reference: Option<&Path>,
) -> Result<(), Error> {
    use bondmech::report::vary::{vary_command, Shard, VarySweep};
    let shard = shard.map(Shard::parse).transpose()?;
    let (text, stem) = bondmech::scene::path::read_scene_text(scene)?;
    let reference_path = reference;
    let reference = match reference {
        Some(path) => Some(bondmech::report::ExternalReference {
            source: path.display().to_string(),
            solution: bondmech::report::reference::reference_from_csv(path)?,
        }),
        None => None,
    };
    let sweep = VarySweep::new(&text, &stem, set, vary, t_end, columns, reference)?;
    let mut inputs = vec![scene];
    inputs.extend(reference_path);
    let report = vary_command(&sweep, shard, out, &inputs)?;
    print!("{}", report.table());
    println!("wrote {}", out.display());
    Ok(())
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
