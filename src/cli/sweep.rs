//! `bondmech sweep`: the tolerance/stiffness sweep of a scene, or with `--vary` a parameter
//! sweep, whole or one shard of it.

use std::path::{Path, PathBuf};

use bondmech::report::SweepConfig;
use bondmech::scene::SolveOverrides;
use bondmech::{Error, Model};

use super::args::SweepArgs;
use super::failure::{options_error, CliError};
use super::output::stdout_write;
use super::scene_input::{apply_overrides, read_scene_text, read_scene_with};

/// Most timed runs per point of `sweep --repeats` (the median of more says nothing new).
const MAX_REPEATS: usize = 100;

/// The flags of a `sweep --vary`.
struct VaryArgs {
    pub(crate) set: Vec<String>,
    pub(crate) vary: Vec<String>,
    pub(crate) shard: Option<String>,
    pub(crate) t_end: Option<f64>,
    pub(crate) columns: Option<Vec<String>>,
    pub(crate) reference: Option<PathBuf>,
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

/// `bondmech sweep`: the tolerance/stiffness sweep, or with `--vary` a parameter sweep.
pub(crate) fn sweep(args: SweepArgs) -> Result<(), CliError> {
    let SweepArgs {
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
    } = args;
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
