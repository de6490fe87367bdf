//! `bondmech animate`: the scene solved (or its motion read from `--csv`) and drawn.

use std::path::Path;

use bondmech::{Error, Model};

use super::args::{SolveArgs, ViewArg};
use super::output::{check_outputs, print_warnings, write};
use super::scene_input::{apply_flags, read_scene_with};

/// The flags of `bondmech animate` besides the solve flags.
pub(crate) struct AnimateFlags<'a> {
    pub(crate) fps: f64,
    pub(crate) speed: Option<f64>,
    pub(crate) view: Option<ViewArg>,
    pub(crate) csv: Option<&'a Path>,
    pub(crate) frames: Option<&'a Path>,
}

/// `bondmech animate`: solve the scene (or read `--csv`) and write the animation.
pub(crate) fn animate(args: &SolveArgs, out: &Path, flags: AnimateFlags) -> Result<(), Error> {
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
