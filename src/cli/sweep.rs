//! `bondmech sweep --vary`: a parameter sweep, whole or one shard of it.

use std::path::{Path, PathBuf};

use bondmech::Error;

use super::output::stdout_write;
use super::scene_input::read_scene_text;

/// Most timed runs per point of `sweep --repeats` (the median of more says nothing new).
pub(crate) const MAX_REPEATS: usize = 100;

/// The flags of a `sweep --vary`.
pub(crate) struct VaryArgs {
    pub(crate) set: Vec<String>,
    pub(crate) vary: Vec<String>,
    pub(crate) shard: Option<String>,
    pub(crate) t_end: Option<f64>,
    pub(crate) columns: Option<Vec<String>>,
    pub(crate) reference: Option<PathBuf>,
}

/// `sweep --vary`: a parameter sweep (whole, or one shard of it).
pub(crate) fn vary_sweep(scene: &Path, out: &Path, a: VaryArgs) -> Result<(), Error> {
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
