//! `bondmech fmu`: a scene as a co-simulation FMU (see `docs/fmu.md`).
//!
//! The FMU's shared library is `libbondmech_fmu.so`, the `bondmech-fmu` crate of this
//! workspace, built by `cargo build` next to the `bondmech` executable (by `cargo test` in
//! `deps/` beside it); the command copies it into the archive. `--library` (or
//! `BONDMECH_FMU_LIBRARY`) names another copy.

use std::path::{Path, PathBuf};

use bondmech::fmu::{describe, ExportOptions, FmiVersion, FmuError};
use bondmech::Error;

/// The file name cargo gives the FMU's shared library.
const LIBRARY: &str = "libbondmech_fmu.so";

/// The flags of `bondmech fmu`.
#[derive(clap::Args)]
pub struct FmuArgs {
    /// Scene file.
    scene: PathBuf,
    /// The FMU to write (`NAME.fmu`).
    #[arg(long)]
    out: PathBuf,
    /// FMI version: 3 (the default) or 2.
    #[arg(long, default_value = "3", value_parser = ["2", "3"])]
    fmi: String,
    /// A numeric scene field the importer may set before initialisation, by its `--set` path
    /// (`bodies[bar2].mass`, `gravity[1]`, `solve.rtol`); repeatable.
    #[arg(long = "parameter", value_name = "PATH")]
    parameters: Vec<String>,
    /// A scene input to expose (default: all of the scene's `inputs`); repeatable.
    #[arg(long = "input", value_name = "NAME")]
    inputs: Vec<String>,
    /// An output column (default: every body's position and angle, the requested points and
    /// the drivers' effort and power); repeatable.
    #[arg(long = "output", value_name = "COLUMN")]
    outputs: Vec<String>,
    /// The FMU's shared library (default: `BONDMECH_FMU_LIBRARY`, else `libbondmech_fmu.so`
    /// next to this executable).
    #[arg(long, value_name = "FILE.so")]
    library: Option<PathBuf>,
}

fn io(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Where the shared library is: `--library`, `BONDMECH_FMU_LIBRARY`, or next to this
/// executable: the newer of cargo's `target/<profile>/libbondmech_fmu.so` (`cargo build`) and
/// `target/<profile>/deps/libbondmech_fmu.so` (`cargo test` builds only that one).
fn library_path(given: Option<&Path>) -> Result<PathBuf, Error> {
    if let Some(p) = given {
        return Ok(p.to_path_buf());
    }
    if let Some(p) = std::env::var_os("BONDMECH_FMU_LIBRARY") {
        return Ok(PathBuf::from(p));
    }
    let exe = std::env::current_exe().map_err(|e| io(Path::new("bondmech"), e))?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    let candidates = [
        dir.join(LIBRARY),
        dir.join("deps").join(LIBRARY),
        dir.join("..").join(LIBRARY),
    ];
    candidates
        .iter()
        .filter_map(|p| Some((std::fs::metadata(p).ok()?.modified().ok()?, p)))
        .max_by_key(|(modified, _)| *modified)
        .map(|(_, p)| p.clone())
        .ok_or_else(|| {
            Error::Options(format!(
                "the FMU's shared library {LIBRARY} is not next to {} (build it with `cargo build -p bondmech-fmu`, or give --library FILE.so)",
                exe.display()
            ))
        })
}

fn to_error(e: FmuError) -> Error {
    match e {
        FmuError::Scene(e) => e.into(),
        FmuError::Model(e) => e,
        other => Error::Options(other.to_string()),
    }
}

/// Writes the FMU and prints what it holds.
pub fn export(args: &FmuArgs) -> Result<(), Error> {
    // the FMU never replaces the scene it is made from, nor the shared library it packs (nor a
    // link to either), checked before work
    let mut inputs = vec![args.scene.as_path()];
    inputs.extend(args.library.as_deref());
    bondmech::output::check_outputs(&inputs, &[("--out", Some(&args.out))])?;
    let (text, stem) = bondmech::scene::path::read_scene_text(&args.scene)?;
    let options = ExportOptions {
        fmi: if args.fmi == "2" {
            FmiVersion::V2
        } else {
            FmiVersion::V3
        },
        parameters: args.parameters.clone(),
        inputs: (!args.inputs.is_empty()).then(|| args.inputs.clone()),
        outputs: (!args.outputs.is_empty()).then(|| args.outputs.clone()),
    };
    let config = describe(&text, &stem, &options).map_err(to_error)?;
    let lib_path = library_path(args.library.as_deref())?;
    let library = std::fs::read(&lib_path).map_err(|e| io(&lib_path, e))?;
    let bytes = config.archive(&text, &library).map_err(to_error)?;
    bondmech::output::write_atomic(&args.out, &bytes).map_err(|e| io(&args.out, e))?;
    let count = |k| config.of_kind(k).count();
    use bondmech::fmu::VariableKind::*;
    println!(
        "wrote {} (FMI {} co-simulation, {} parameters, {} inputs, {} outputs)",
        args.out.display(),
        config.fmi_version.as_str(),
        count(Parameter),
        count(Input),
        count(Output)
    );
    Ok(())
}
