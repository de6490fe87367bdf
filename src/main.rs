//! The `bondmech` command line: a thin layer over the library.
//!
//! Every flag that changes the scene (`--rtol`, `--atol`, `--t-end`, `--joint-stiffness`,
//! `--formulation`, `--max-steps`, `--max-wall-seconds`) is written into the scene's `solve`
//! section and the scene is validated again, so a flag obeys exactly the scene's rules and a
//! refusal names the flag. Output paths are checked before anything is solved; a closed
//! standard output (`| head`) ends the program quietly.

use std::path::Path;
use std::process::ExitCode;

mod cli;

use bondmech::FormulationKind;
use bondmech::{Error, Model};
use clap::Parser;

use cli::animate::{animate, AnimateFlags};
use cli::args::{Cli, Command};
use cli::failure::{is_broken_pipe, options_error, CliError};
use cli::fmu;
use cli::output::{check_outputs, print_warnings, stdout_write, write};
use cli::run::run_command;
use cli::scene_input::{load, read_scene, read_scene_with};
use cli::signals::{exit_status_of, watch_interrupts};

fn main() -> ExitCode {
    let cli = Cli::parse();
    // the commands that solve stop at the next step on SIGINT or SIGTERM and keep their rows;
    // the others (and `serve`, which drains its requests itself) keep the default
    if matches!(
        cli.command,
        Command::Run { .. } | Command::Compare { .. } | Command::Animate { .. } | Command::Sweep(_)
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
            // never onto the scene (nor a link to it), checked before any work
            check_outputs(&[&scene], &[("--json", json.as_deref())])?;
            let model = Model::new(&read_scene_with(&scene, &set)?)?;
            let eq = model.equilibrium()?;
            if let Some(path) = json {
                let text = serde_json::to_string_pretty(&eq.to_json())
                    .map_err(|e| options_error(e.to_string()))?;
                write(&path, &(text + "\n"))?;
            }
            Ok(stdout_write(&eq.table())?)
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
            // never onto the scene (nor a link to it), nor both outputs onto one file
            check_outputs(
                &[&scene],
                &[("--json", json.as_deref()), ("--bode", bode.as_deref())],
            )?;
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
                write(&path, &(text + "\n"))?;
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
        Command::Graph(args) => cli::graph::graph(args),
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
        Command::Sweep(args) => cli::sweep::sweep(args),
        Command::SweepMerge { dirs, out } => {
            let merged = bondmech::report::vary::merge_command(&dirs, &out)?;
            Ok(stdout_write(&format!(
                "{}merged {} shards into {}\n",
                merged.table(),
                dirs.len(),
                out.display()
            ))?)
        }
        Command::Fmu(args) => Ok(fmu::export(&args)?),
        Command::Sensitivity { args, params, out } => {
            cli::sensitivity::sensitivity(&args, &params, out.as_deref())
        }
        Command::Fit {
            args,
            data,
            params,
            columns,
            json,
            out,
            max_iterations,
        } => cli::sensitivity::fit(
            &args,
            (&data, &params, columns, max_iterations),
            (json.as_deref(), out.as_deref()),
        ),
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
