//! Running a parameter sweep (`bondmech sweep --vary`, `--shard`): every point's scene built
//! and solved (in parallel, results identical to a serial run). The spec, the shards, the
//! report and its CSV, JSON and SVG are [`crate::report::vary`]'s.

use std::path::Path;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::model::Model;
use crate::report::compare::{column_kind, ColumnKind};
use crate::report::sweep::{solution_error, ExternalReference};
use crate::report::vary::*;
use crate::scene::path::{
    apply_tree, parse_assignment, parse_variation_tree, scene_from_tree_with, Assignment, ScenePath,
};
use crate::scene::{parse, tree::Json, Scene, SceneError};
use crate::solve::Solution;

/// A parameter sweep ready to run: the base scene tree, the assignments and the spec.
pub struct VarySweep {
    base: Json,
    default_name: String,
    sets: Vec<Assignment>,
    paths: Vec<ScenePath>,
    /// The values of each variation as order-preserving trees.
    trees: Vec<Vec<Json>>,
    spec: VarySpec,
    reference: Option<Solution>,
}

impl VarySweep {
    /// Prepares a sweep of scene text `text` (its `name` defaults to `default_name`): parses
    /// `sets` (`PATH=JSON`) and `vary` (`PATH=[…]`), checks the base scene and every point's
    /// scene (the first bad one is an error naming the point and the path), reads the reference.
    pub fn new(
        text: &str,
        default_name: &str,
        sets: &[String],
        vary: &[String],
        t_end: Option<f64>,
        columns: Option<Vec<String>>,
        reference: Option<ExternalReference>,
    ) -> Result<VarySweep> {
        if vary.is_empty() {
            return Err(Error::Options(
                "a parameter sweep needs at least one --vary PATH=[v1, v2, ...]".into(),
            ));
        }
        if let Some(t) = t_end {
            if !(t > 0.0 && t.is_finite()) {
                return Err(Error::Options(format!("--t-end: must be > 0 (got {t})")));
            }
        }
        let sets: Vec<Assignment> = sets
            .iter()
            .map(|s| parse_assignment(s))
            .collect::<std::result::Result<_, _>>()
            .map_err(SceneError::from)?;
        let variations: Vec<Variation> = vary
            .iter()
            .map(|v| Variation::parse(v))
            .collect::<std::result::Result<_, _>>()?;
        let total = variations
            .iter()
            .try_fold(1usize, |n, v| n.checked_mul(v.values.len()))
            .filter(|n| *n <= MAX_POINTS);
        if total.is_none() {
            let sizes: Vec<String> = variations
                .iter()
                .map(|v| v.values.len().to_string())
                .collect();
            return Err(VaryError::TooManyPoints {
                max: MAX_POINTS,
                sizes: sizes.join(" × "),
            }
            .into());
        }
        let mut paths: Vec<ScenePath> = Vec::with_capacity(vary.len());
        let mut trees: Vec<Vec<Json>> = Vec::with_capacity(vary.len());
        for v in vary {
            let (p, t) = parse_variation_tree(v).map_err(SceneError::from)?;
            paths.push(p);
            trees.push(t);
        }
        let base = parse::parse_tree(text).map_err(|problems| SceneError::Invalid { problems })?;
        let scene = scene_from_tree_with(base.clone(), default_name, &sets)?;
        // two --vary of one field (by index and by name, say) would make equal points
        let mut with_sets = base.clone();
        for a in &sets {
            apply_tree(&mut with_sets, a.path(), a.tree_value().clone())
                .map_err(SceneError::from)?;
        }
        let mut resolved: Vec<(String, &str)> = Vec::new();
        for (p, v) in paths.iter().zip(&variations) {
            let mut t = with_sets.clone();
            let at = apply_tree(&mut t, p, Json::Null).map_err(SceneError::from)?;
            if let Some((_, first)) = resolved.iter().find(|(r, _)| *r == at) {
                return Err(VaryError::DuplicateVary {
                    first: first.to_string(),
                    second: v.path.clone(),
                    field: at,
                }
                .into());
            }
            resolved.push((at, &v.path));
        }
        let reference = reference.map(|r| {
            let sol = crate::report::reference::truncate_reference(&r.solution, t_end);
            (r.source, sol)
        });
        let spec = VarySpec {
            scene: scene.name.clone(),
            scene_hash: fnv_hex(scene.to_json_string().as_bytes()),
            sets: sets.iter().map(|a| a.as_str().to_string()).collect(),
            vary: variations,
            t_end,
            columns,
            reference: reference.as_ref().map(|(s, _)| s.clone()),
            reference_hash: reference.as_ref().map(|(_, sol)| solution_hash(sol)),
        };
        let sweep = VarySweep {
            base,
            default_name: default_name.to_string(),
            sets,
            paths,
            trees,
            spec,
            reference: reference.map(|(_, sol)| sol),
        };
        if let Some(t) = t_end {
            // a bad --t-end is refused once, not as a failed run at every point
            Model::new(&scene)?
                .output_times_until(t)
                .map_err(|e| match e {
                    Error::Options(m) => Error::Options(format!("--t-end: {m}")),
                    other => other,
                })?;
        }
        if let Some(r) = &sweep.reference {
            let t0 = Model::new(&scene)?
                .default_options()
                .output_times
                .first()
                .copied()
                .unwrap_or(0.0);
            if r.times.len() < 2 || (r.times[0] - t0).abs() > 1e-12 * (1.0 + t0.abs()) {
                return Err(VaryError::Reference {
                    source_name: sweep.spec.reference.clone().unwrap_or_default(),
                    message: format!(
                        "must start at the scene's start t = {t0} and have at least two times up \
                         to t_end (it has {} from t = {})",
                        r.times.len(),
                        r.times.first().copied().unwrap_or(f64::NAN)
                    ),
                }
                .into());
            }
        }
        // every point's scene, before anything is solved
        for k in 0..sweep.spec.total_points() {
            sweep.scene(k)?;
        }
        Ok(sweep)
    }

    /// What is swept.
    pub fn spec(&self) -> &VarySpec {
        &self.spec
    }

    /// The scene of point `k`; an error names the point, its values and the path.
    pub fn scene(&self, k: usize) -> Result<Scene> {
        let values = self.spec.point_values(k);
        let mut sets = self.sets.clone();
        let mut rest = k;
        let mut picked = vec![0; self.trees.len()];
        for (slot, t) in picked.iter_mut().zip(&self.trees).rev() {
            *slot = rest % t.len();
            rest /= t.len();
        }
        for ((p, t), (i, v)) in self
            .paths
            .iter()
            .zip(&self.trees)
            .zip(picked.into_iter().zip(&values))
        {
            let text = format!("{p}={v}");
            sets.push(Assignment::from_tree(p.clone(), t[i].clone(), text).labelled("--vary"));
        }
        scene_from_tree_with(self.base.clone(), &self.default_name, &sets).map_err(|e| {
            let what: Vec<String> = self
                .spec
                .vary
                .iter()
                .zip(&values)
                .map(|(v, x)| format!("{}={x}", v.path))
                .collect();
            Error::from(VaryError::BadPoint {
                index: k,
                values: what.join(", "),
                message: e.to_string().replace('\n', "; "),
            })
        })
    }

    /// Runs the points of `shard` (all when `None`) on rayon's pool; `tick` is called after
    /// each point (from any thread).
    pub fn run(&self, shard: Option<Shard>, tick: &(dyn Fn() + Sync)) -> Result<VaryReport> {
        let ks: Vec<usize> = (0..self.spec.total_points())
            .filter(|&k| shard.is_none_or(|s| s.owns(k)))
            .collect();
        // the first point alone: a misspelt --columns or an unusable reference is refused after
        // one solve, not after the whole slice
        let mut runs: Vec<(VaryPoint, Vec<String>)> = Vec::with_capacity(ks.len());
        if let Some(&k0) = ks.first() {
            runs.push(self.run_point(k0)?);
            tick();
            if runs[0].0.failure.is_none() {
                self.check_columns(&runs[0].1)?;
            }
        }
        let rest: Vec<(VaryPoint, Vec<String>)> = ks
            .get(1..)
            .unwrap_or_default()
            .par_iter()
            .map(|&k| {
                let p = self.run_point(k);
                tick();
                p
            })
            .collect::<Result<_>>()?;
        runs.extend(rest);
        if let Some((_, columns)) = runs.iter().find(|(p, _)| p.failure.is_none()) {
            self.check_columns(columns)?;
        }
        let points = runs.into_iter().map(|(p, _)| p).collect();
        Ok(VaryReport {
            format: FORMAT.into(),
            fingerprint: self.spec.fingerprint(),
            spec: self.spec.clone(),
            total_points: self.spec.total_points(),
            shard,
            points,
        })
    }

    /// The indices of the points `shard` runs.
    pub fn shard_len(&self, shard: Option<Shard>) -> usize {
        (0..self.spec.total_points())
            .filter(|&k| shard.is_none_or(|s| s.owns(k)))
            .count()
    }

    /// Runs point `k`: its record and all the columns its run wrote.
    fn run_point(&self, k: usize) -> Result<(VaryPoint, Vec<String>)> {
        let values = self.spec.point_values(k);
        let mut point = VaryPoint {
            index: k,
            values,
            failure: None,
            formulation: String::new(),
            steps: 0,
            residual_evals: 0,
            jacobian_evals: 0,
            error_test_failures: 0,
            cpu_seconds: f64::NAN,
            max_constraint_error: f64::NAN,
            energy_drift: f64::NAN,
            error: f64::NAN,
            t_final: f64::NAN,
            final_values: Vec::new(),
        };
        // after an interrupt (SIGINT, SIGTERM) the points not begun are not run; the finished
        // ones are kept
        if let Some(sig) = crate::interrupt::requested() {
            point.failure = Some(format!(
                "not run: interrupted by {}",
                crate::interrupt::signal_name(sig)
            ));
            return Ok((point, Vec::new()));
        }
        let mut scene = self.scene(k)?;
        if self.reference.is_some() {
            // errors are measured row by row at the reference's times: event rows would
            // misalign them (as in the tolerance sweep); without a reference a `stop` event
            // ends the run and its row is the final state
            scene.events.clear();
        }
        let solved = Model::new(&scene).and_then(|model| {
            let mut opts = model.default_options();
            point.formulation = opts.formulation.name().to_string();
            if let Some(r) = &self.reference {
                opts.output_times = r.times.clone();
            } else if let Some(t) = self.spec.t_end {
                opts.output_times = model.output_times_until(t)?;
            }
            model.solve(&opts)
        });
        let sol = match solved {
            Ok(s) => s,
            Err(e) => {
                point.failure = Some(e.to_string().replace('\n', "; "));
                return Ok((point, Vec::new()));
            }
        };
        let s = &sol.summary;
        point.formulation = s.formulation.clone();
        point.steps = s.steps;
        point.residual_evals = s.residual_evals;
        point.jacobian_evals = s.jacobian_evals;
        point.error_test_failures = s.error_test_failures;
        point.cpu_seconds = finite_or_nan(s.cpu_seconds);
        point.max_constraint_error = finite_or_nan(s.max_constraint_error);
        point.energy_drift = finite_or_nan(s.energy_drift.unwrap_or(f64::NAN));
        if let Some(r) = &self.reference {
            point.error = finite_or_nan(solution_error(&sol, r));
        }
        if let (Some(t), Some(row)) = (sol.times.last(), sol.rows.last()) {
            point.t_final = finite_or_nan(*t);
            let all: Vec<(&String, f64)> = sol.columns.iter().zip(row.iter().copied()).collect();
            let chosen: Vec<(&String, f64)> = match &self.spec.columns {
                None => all,
                // in the order asked for
                Some(want) => want
                    .iter()
                    .filter_map(|w| all.iter().find(|(c, _)| *c == w).copied())
                    .collect(),
            };
            point.final_values = chosen
                .into_iter()
                .map(|(c, x)| FinalValue {
                    column: c.clone(),
                    value: finite_or_nan(x),
                })
                .collect();
        }
        Ok((point, sol.columns))
    }

    /// A chosen column the runs do not write, or a reference sharing no position or angle
    /// column with them, is an error naming what there is (`columns`: a successful run's).
    fn check_columns(&self, columns: &[String]) -> Result<()> {
        if let Some(want) = &self.spec.columns {
            if let Some(c) = want.iter().find(|c| !columns.contains(c)) {
                return Err(VaryError::UnknownColumn {
                    column: c.clone(),
                    available: columns.join(", "),
                }
                .into());
            }
        }
        if let Some(r) = &self.reference {
            let shared = r.columns.iter().any(|c| {
                matches!(column_kind(c), ColumnKind::Position | ColumnKind::Angle)
                    && columns.contains(c)
            });
            if !shared {
                return Err(VaryError::Reference {
                    source_name: self.spec.reference.clone().unwrap_or_default(),
                    message: format!(
                        "shares no position or angle column with the scene's output (reference \
                         columns: {}; scene columns: {})",
                        r.columns.join(","),
                        columns.join(",")
                    ),
                }
                .into());
            }
        }
        Ok(())
    }
}

/// `bondmech sweep --vary`: runs `sweep`'s points (of `shard`) with a progress bar and writes
/// the result into `out` (checked before computing).
pub fn vary_command(
    sweep: &VarySweep,
    shard: Option<Shard>,
    out: &Path,
    inputs: &[&Path],
) -> Result<VaryReport> {
    check_out_dir(out, inputs)?;
    let bar = progress_bar(sweep.shard_len(shard) as u64);
    let report = sweep.run(shard, &|| bar.inc(1))?;
    bar.finish_and_clear();
    report.write_all(out)?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn too_many_points_are_refused_before_anything_runs() {
        let big = format!(
            "bodies[0].mass=[{}]",
            (1..=4000)
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(",")
        );
        let text = r#"{"bodies": [{"name": "b", "mass": 1, "inertia": 1}], "solve": {"t_end": 1}}"#;
        let vary = [big.clone(), big.replace("mass", "inertia")];
        let Err(e) = VarySweep::new(text, "s", &[], &vary, None, None, None) else {
            panic!("refused")
        };
        assert!(
            e.to_string().contains("4000 × 4000 values make more than"),
            "{e}"
        );
    }
}
