//! `bondmech sensitivity` and `bondmech fit`: the library's [`bondmech::sensitivity`] with the
//! scene read and the solve flags applied as `run` does.

use std::path::{Path, PathBuf};

use bondmech::sensitivity::{FitData, FitRequest, SceneParameter, SensitivityRequest};
use bondmech::Error;

use super::args::SolveArgs;
use super::failure::CliError;
use super::output::{check_outputs, io_error, print_warnings, stdout_write, write};
use super::scene_input::{apply_flags, read_scene_with};

/// The scene of `args` with its `--set` and solve flags applied.
fn scene(args: &SolveArgs) -> Result<bondmech::Scene, Error> {
    let mut scene = read_scene_with(&args.scene, &args.set)?;
    apply_flags(&mut scene, args)?;
    Ok(scene)
}

/// `bondmech sensitivity`: the CSV of the run's columns and their sensitivities.
pub(crate) fn sensitivity(
    args: &SolveArgs,
    params: &[String],
    out: Option<&Path>,
) -> Result<(), CliError> {
    check_outputs(&[&args.scene], &[("--out", out)])?;
    let scene = scene(args)?;
    let mut req = SensitivityRequest::new(&[]);
    req.params = params.to_vec();
    let s = bondmech::sensitivity::sensitivity(&scene, &req).map_err(Error::from)?;
    print_warnings(&s.warnings);
    let csv = s.to_csv();
    match out {
        Some(p) => Ok(write(p, &csv)?),
        None => Ok(stdout_write(&csv)?),
    }
}

/// `bondmech fit`: the fitted values as a table, `--json`, `--out` (the fitted scene); exit 1
/// when the fit does not converge (its last iterate is still reported).
pub(crate) fn fit(
    args: &SolveArgs,
    (data, params, columns, max_iterations): (
        &PathBuf,
        &[String],
        Option<Vec<String>>,
        Option<usize>,
    ),
    (json, out): (Option<&Path>, Option<&Path>),
) -> Result<(), CliError> {
    check_outputs(&[&args.scene, data], &[("--json", json), ("--out", out)])?;
    let scene = scene(args)?;
    let text = std::fs::read_to_string(data).map_err(io_error(data))?;
    let data = FitData::from_csv(&text).map_err(Error::from)?;
    let req = FitRequest {
        params: params.to_vec(),
        columns,
        max_iterations,
    };
    let report = bondmech::sensitivity::fit(&scene, &data, &req).map_err(Error::from)?;
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&report.to_json())
            .map_err(|e| super::failure::options_error(e.to_string()))?;
        write(path, &(text + "\n"))?;
    }
    if let Some(path) = out {
        let ps: Vec<SceneParameter> = params
            .iter()
            .map(|p| SceneParameter::new(&scene, p))
            .collect::<Result<_, _>>()
            .map_err(Error::from)?;
        let fitted =
            SceneParameter::scene_with(&scene, &ps, &report.values).map_err(Error::from)?;
        write(path, &(fitted.to_json_string() + "\n"))?;
    }
    stdout_write(&report.table())?;
    if !report.converged {
        return Err(CliError {
            error: Error::from(bondmech::sensitivity::SensitivityError::Fit(format!(
                "did not converge: {} (the last iterate is above)",
                report.reason
            ))),
            note: None,
        });
    }
    Ok(())
}
