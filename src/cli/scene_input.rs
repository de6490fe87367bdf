//! Reading a scene (a file or standard input, `--set` applied) and writing the solve flags into
//! its `solve` section, so that a flag obeys the scene's own rules.

use std::path::Path;

use bondmech::scene::SolveOverrides;
use bondmech::{Error, Model, Scene, SolveOptions};

use super::args::SolveArgs;

/// Reads a scene file, or standard input for `-`.
pub(crate) fn read_scene(path: &Path) -> Result<Scene, Error> {
    if path == Path::new("-") {
        let text = read_stdin()?;
        return Ok(Scene::from_json_str(&text)?);
    }
    Ok(Scene::from_path(path)?)
}

/// Reads the text of a scene file, or of standard input for `-`, and its default name.
pub(crate) fn read_scene_text(path: &Path) -> Result<(String, String), Error> {
    if path == Path::new("-") {
        let text = read_stdin()?;
        return Ok((text, "scene".into()));
    }
    Ok(bondmech::scene::path::read_scene_text(path)?)
}

/// [`read_scene`] with `--set PATH=JSON` assignments applied (in order) before validation.
pub(crate) fn read_scene_with(path: &Path, sets: &[String]) -> Result<Scene, Error> {
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
pub(crate) fn apply_flags(scene: &mut Scene, args: &SolveArgs) -> Result<(), Error> {
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

/// [`SolveOverrides::apply`], each refusal naming its flag (`--t-end: solve.output_step: …`).
pub(crate) fn apply_overrides(scene: &mut Scene, overrides: &SolveOverrides) -> Result<(), Error> {
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
pub(crate) fn load(args: &SolveArgs) -> Result<(Model, SolveOptions), Error> {
    let mut scene = read_scene_with(&args.scene, &args.set)?;
    if args.reactions && !scene.outputs.iter().any(|o| o == "reactions") {
        scene.outputs.push("reactions".into());
    }
    apply_flags(&mut scene, args)?;
    let model = Model::new(&scene)?;
    let opts = model.default_options();
    Ok((model, opts))
}

/// The whole of standard input, with a scene file's checks ([`bondmech::scene::read_text_from`]:
/// size, binary data, UTF-8); an empty one — closed (`<&-`: the process starts with
/// `/dev/null` there) or empty — is refused saying how to give a scene.
fn read_stdin() -> Result<String, Error> {
    let name = Path::new("standard input");
    bondmech::scene::read_text_from(std::io::stdin().lock(), name).map_err(|e| match e {
        bondmech::scene::SceneError::Empty { .. } => Error::Io {
            path: "standard input".into(),
            source: std::io::Error::other(
                "is empty (closed, or /dev/null): pipe a scene into `bondmech run -` (`cat scene.json | bondmech run -`), or give the scene's file instead of '-'",
            ),
        },
        e => Error::from(e),
    })
}
