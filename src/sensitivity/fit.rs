//! Parameters identified from measurements: the values `p` that minimise
//! `½ Σ_{c, i} (y_c(t_i; p) − d_c(t_i))²` over the data's columns `c` and times `t_i`, by
//! Levenberg–Marquardt on the run's exact sensitivities `J = ∂y_c(t_i)/∂p` ([`super::run`]):
//!
//! ```text
//!   (JᵀJ + λ diag(JᵀJ)) δ = −Jᵀ r,     p ← p + δ   (λ shrinks after a step that lowers the
//!                                                     sum of squares, grows otherwise)
//! ```
//!
//! from the scene's values, a mass, inertia, stiffness, damping or length kept positive. At
//! the minimum the covariance of the estimate is the Gauss–Newton one scaled by the residual
//! variance, `C = s² (JᵀJ)⁻¹` with `s² = Σ r² / (m − n_p)`; the standard errors are `√C_kk`
//! and the correlations `C_kl / √(C_kk C_ll)`. A singular `JᵀJ` (the data do not tell two
//! parameters apart) is refused naming the correlated pair.

use nalgebra::{DMatrix, DVector};

use super::run::{sensitivity, SensitivityRequest};
use super::{SceneParameter, SensitivityError};
use crate::scene::Scene;

/// Largest number of Levenberg–Marquardt iterations.
pub const MAX_ITERATIONS: usize = 60;
/// Relative step size under which the fit has converged.
pub const STEP_TOLERANCE: f64 = 1e-9;
/// Correlation beyond which two parameters are not identifiable from the data.
pub const CORRELATION_LIMIT: f64 = 0.99999;

/// Measured data: times and columns (named as the run's).
#[derive(Clone, Debug, PartialEq)]
pub struct FitData {
    /// Sample times (strictly increasing).
    pub times: Vec<f64>,
    /// Column names (the run's).
    pub columns: Vec<String>,
    /// `values[i][c]`: column `c` at `times[i]`.
    pub values: Vec<Vec<f64>>,
}

impl FitData {
    /// Reads CSV text whose header names `t` and run columns; every value a finite number.
    pub fn from_csv(text: &str) -> Result<Self, SensitivityError> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| SensitivityError::Data(format!("cannot read the header: {e}")))?
            .iter()
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (i, rec) in reader.records().enumerate() {
            let rec = rec.map_err(|e| SensitivityError::Data(format!("row {}: {e}", i + 1)))?;
            let mut row = Vec::with_capacity(rec.len());
            for (c, field) in rec.iter().enumerate() {
                let name = header.get(c).map(String::as_str).unwrap_or("?");
                let v: f64 = field.parse().map_err(|_| {
                    SensitivityError::Data(format!(
                        "column '{name}', row {}: '{field}' is not a number",
                        i + 1
                    ))
                })?;
                row.push(v);
            }
            rows.push(row);
        }
        Self::from_table(header, rows)
    }

    /// Data from a header (with `t`) and rows of the same length.
    pub fn from_table(header: Vec<String>, rows: Vec<Vec<f64>>) -> Result<Self, SensitivityError> {
        let Some(ti) = header.iter().position(|h| h == "t") else {
            return Err(SensitivityError::Data(format!(
                "no column 't' (the header names: {})",
                header.join(", ")
            )));
        };
        if header.len() < 2 {
            return Err(SensitivityError::Data("no column besides 't'".into()));
        }
        for (i, h) in header.iter().enumerate() {
            if header[..i].contains(h) {
                return Err(SensitivityError::Data(format!(
                    "column '{h}' is given twice"
                )));
            }
        }
        if rows.is_empty() {
            return Err(SensitivityError::Data("no rows".into()));
        }
        let mut times = Vec::with_capacity(rows.len());
        let mut values = Vec::with_capacity(rows.len());
        for (i, r) in rows.iter().enumerate() {
            if r.len() != header.len() {
                return Err(SensitivityError::Data(format!(
                    "row {} has {} values for {} columns",
                    i + 1,
                    r.len(),
                    header.len()
                )));
            }
            for (c, v) in r.iter().enumerate() {
                if !v.is_finite() {
                    return Err(SensitivityError::Data(format!(
                        "column '{}', row {}: {v} is not a finite number",
                        header[c],
                        i + 1
                    )));
                }
            }
            if let Some(&last) = times.last() {
                if r[ti] <= last {
                    return Err(SensitivityError::Data(format!(
                        "column 't', row {}: the times must increase ({} after {last})",
                        i + 1,
                        r[ti]
                    )));
                }
            }
            times.push(r[ti]);
            values.push(
                r.iter()
                    .enumerate()
                    .filter(|&(c, _)| c != ti)
                    .map(|(_, v)| *v)
                    .collect(),
            );
        }
        let columns = header.into_iter().filter(|h| h != "t").collect();
        Ok(FitData {
            times,
            columns,
            values,
        })
    }
}

/// What to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitRequest {
    /// Scene paths of the parameters.
    pub params: Vec<String>,
    /// The data's columns to fit (`None`: all of them).
    pub columns: Option<Vec<String>>,
    /// Largest number of iterations (`None`: [`MAX_ITERATIONS`]).
    pub max_iterations: Option<usize>,
}

/// The fit's outcome (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// Whether the iteration met its tolerance.
    pub converged: bool,
    /// Why it stopped.
    pub reason: String,
    /// Levenberg–Marquardt iterations (accepted steps and rejected trials).
    pub iterations: usize,
    /// Runs with sensitivities made.
    pub runs: usize,
    /// Parameter paths, in order.
    pub paths: Vec<String>,
    /// The scene's values (the start).
    pub start: Vec<f64>,
    /// The fitted values.
    pub values: Vec<f64>,
    /// Their standard errors.
    pub std_errors: Vec<f64>,
    /// The covariance matrix.
    pub covariance: Vec<Vec<f64>>,
    /// The correlation matrix.
    pub correlation: Vec<Vec<f64>>,
    /// `√(Σ r² / m)` at the fitted values.
    pub residual_rms: f64,
    /// The data's columns fitted.
    pub columns: Vec<String>,
    /// Data points fitted (`m`).
    pub points: usize,
}

impl FitReport {
    /// The JSON of the fit: `converged`, `iterations`, `parameters`, `std_errors`,
    /// `covariance`, `residual_rms`, `correlation` (and `reason`, `start`, `columns`).
    pub fn to_json(&self) -> serde_json::Value {
        let map = |v: &[f64]| {
            serde_json::Value::Object(
                self.paths
                    .iter()
                    .zip(v)
                    .map(|(p, x)| (p.clone(), json_number(*x)))
                    .collect(),
            )
        };
        let matrix = |m: &[Vec<f64>]| {
            serde_json::Value::Array(
                m.iter()
                    .map(|r| serde_json::Value::Array(r.iter().map(|x| json_number(*x)).collect()))
                    .collect(),
            )
        };
        serde_json::json!({
            "converged": self.converged,
            "reason": self.reason,
            "iterations": self.iterations,
            "parameters": map(&self.values),
            "start": map(&self.start),
            "std_errors": map(&self.std_errors),
            "covariance": matrix(&self.covariance),
            "correlation": matrix(&self.correlation),
            "residual_rms": json_number(self.residual_rms),
            "columns": self.columns,
            "points": self.points,
        })
    }

    /// A table of the parameters: path, start, fitted value, standard error.
    pub fn table(&self) -> String {
        let w = self.paths.iter().map(|p| p.len()).max().unwrap_or(9).max(9);
        let mut out = format!(
            "{:w$}  {:>14}  {:>14}  {:>12}\n",
            "parameter", "start", "fitted", "std. error"
        );
        for (k, p) in self.paths.iter().enumerate() {
            out.push_str(&format!(
                "{p:w$}  {:>14.8e}  {:>14.8e}  {:>12.3e}\n",
                self.start[k], self.values[k], self.std_errors[k]
            ));
        }
        out.push_str(&format!(
            "residual rms {:.3e} over {} points of [{}]; {} after {} iterations: {}\n",
            self.residual_rms,
            self.points,
            self.columns.join(", "),
            if self.converged {
                "converged"
            } else {
                "NOT converged"
            },
            self.iterations,
            self.reason
        ));
        out
    }
}

fn json_number(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x)
        .map(serde_json::Value::Number)
        .unwrap_or(serde_json::Value::Null)
}

/// The residuals `r = y − d` (column-major over the fitted columns) and `J = ∂y/∂p` at `values`.
struct Evaluation {
    r: DVector<f64>,
    j: DMatrix<f64>,
}

impl Evaluation {
    fn cost(&self) -> f64 {
        0.5 * self.r.norm_squared()
    }
}

/// Fits the parameters of `req` to `data` starting from the scene's values (see the module
/// documentation). A fit that does not converge returns its last iterate with
/// `converged: false` and the reason; unusable data, or parameters the data cannot tell apart,
/// are refused naming the column or the parameters.
pub fn fit(scene: &Scene, data: &FitData, req: &FitRequest) -> Result<FitReport, SensitivityError> {
    let params: Vec<SceneParameter> = req
        .params
        .iter()
        .map(|p| SceneParameter::new(scene, p))
        .collect::<Result<_, _>>()?;
    if params.is_empty() {
        return Err(SensitivityError::Scene("give at least one --param".into()));
    }
    let columns: Vec<String> = match &req.columns {
        Some(c) => {
            for name in c {
                if !data.columns.contains(name) {
                    return Err(SensitivityError::Data(format!(
                        "--columns names '{name}', which the data do not have (they have: {})",
                        data.columns.join(", ")
                    )));
                }
            }
            c.clone()
        }
        None => data.columns.clone(),
    };
    let data_index: Vec<usize> = columns
        .iter()
        .map(|c| data.columns.iter().position(|d| d == c).unwrap_or(0))
        .collect();
    // the run's output times: the scene's start, then the data's times
    let t_start = scene.solve.t_start;
    let t_end = scene.solve.t_end;
    let (first, last) = (data.times[0], *data.times.last().unwrap_or(&data.times[0]));
    if first < t_start || last > t_end {
        return Err(SensitivityError::Data(format!(
            "column 't': the data's times [{first}, {last}] lie outside the scene's span [{t_start}, {t_end}]"
        )));
    }
    let skip = usize::from(first > t_start);
    let mut times = Vec::with_capacity(data.times.len() + 1);
    if skip == 1 {
        times.push(t_start);
    }
    times.extend_from_slice(&data.times);
    let np = params.len();
    let m = columns.len() * data.times.len();
    if m <= np {
        return Err(SensitivityError::Data(format!(
            "{m} data points for {np} parameters: the fit needs more points than parameters"
        )));
    }
    let mut runs = 0;
    let mut evaluate = |values: &[f64]| -> Result<Evaluation, SensitivityError> {
        runs += 1;
        let s = SceneParameter::scene_with(scene, &params, values)?;
        let mut sreq = SensitivityRequest::new(&[]);
        sreq.params = req.params.clone();
        sreq.output_times = Some(times.clone());
        let sol = sensitivity(&s, &sreq)?;
        let mut r = DVector::zeros(m);
        let mut j = DMatrix::zeros(m, np);
        for (ci, name) in columns.iter().enumerate() {
            let Some(col) = sol.columns.iter().position(|c| c == name) else {
                return Err(SensitivityError::Data(format!(
                    "column '{name}' is not a column of the run (its columns: {})",
                    sol.columns.join(", ")
                )));
            };
            for k in 0..np {
                let Some(d) = sol.derivative(name, k) else {
                    return Err(SensitivityError::Data(format!(
                        "column '{name}' depends on --param {} explicitly; fit other columns",
                        req.params[k]
                    )));
                };
                for i in 0..data.times.len() {
                    j[(ci * data.times.len() + i, k)] = d[i + skip];
                }
            }
            for i in 0..data.times.len() {
                r[ci * data.times.len() + i] =
                    sol.rows[i + skip][col] - data.values[i][data_index[ci]];
            }
        }
        Ok(Evaluation { r, j })
    };
    let start: Vec<f64> = params.iter().map(|p| p.value).collect();
    let positive: Vec<bool> = params.iter().map(SceneParameter::positive).collect();
    let scale: Vec<f64> = start
        .iter()
        .map(|v| if *v != 0.0 { v.abs() } else { 1.0 })
        .collect();
    let mut p = start.clone();
    let mut ev = evaluate(&p)?;
    for k in 0..np {
        if ev.j.column(k).iter().all(|&x| x == 0.0) {
            return Err(SensitivityError::Fit(format!(
                "the fitted columns do not depend on --param {}: it cannot be identified from them",
                req.params[k]
            )));
        }
    }
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let mut converged = false;
    let max_iterations = req.max_iterations.unwrap_or(MAX_ITERATIONS);
    let mut reason = format!("{max_iterations} iterations reached without meeting the tolerance");
    while iterations < max_iterations {
        iterations += 1;
        // scaled unknowns u = p / scale: J_u = J diag(scale)
        let ju = DMatrix::from_fn(m, np, |i, k| ev.j[(i, k)] * scale[k]);
        let jtj = ju.transpose() * &ju;
        let g = ju.transpose() * &ev.r;
        let mut a = jtj.clone();
        for k in 0..np {
            a[(k, k)] += lambda * jtj[(k, k)].max(1e-300);
        }
        let Some(du) = a.clone().cholesky().map(|c| c.solve(&(-&g))) else {
            lambda *= 10.0;
            continue;
        };
        let mut trial: Vec<f64> = (0..np).map(|k| p[k] + du[k] * scale[k]).collect();
        for k in 0..np {
            if positive[k] && trial[k] <= 0.0 {
                // keep it positive: at most a tenth of the way to zero
                trial[k] = p[k] * 0.1;
            }
        }
        let step = (0..np)
            .map(|k| ((trial[k] - p[k]) / scale[k]).abs())
            .fold(0.0, f64::max);
        let next = match evaluate(&trial) {
            Ok(e) => Some(e),
            Err(SensitivityError::Solver(_)) | Err(SensitivityError::Solve(_)) => None,
            Err(e) => return Err(e),
        };
        match next {
            Some(e) if e.cost() <= ev.cost() => {
                let gain = ev.cost() - e.cost();
                p = trial;
                ev = e;
                lambda = (lambda / 3.0).max(1e-12);
                if step < STEP_TOLERANCE || gain <= 1e-14 * ev.cost().max(f64::MIN_POSITIVE) {
                    converged = true;
                    reason = format!("the step {step:.1e} (relative) met the tolerance");
                    break;
                }
            }
            _ => {
                lambda *= 4.0;
                if lambda > 1e12 {
                    reason = "no step lowers the sum of squares (λ beyond 1e12)".into();
                    break;
                }
            }
        }
        if step < STEP_TOLERANCE * 1e-3 {
            converged = true;
            reason = format!("the step {step:.1e} (relative) met the tolerance");
            break;
        }
    }
    // covariance at the last iterate
    let jtj = ev.j.transpose() * &ev.j;
    let dof = (m - np) as f64;
    let s2 = ev.r.norm_squared() / dof;
    let d: Vec<f64> = (0..np).map(|k| jtj[(k, k)].sqrt()).collect();
    let scaled = DMatrix::from_fn(np, np, |a, b| jtj[(a, b)] / (d[a] * d[b]));
    let svd = scaled.clone().svd(false, false);
    let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
    let inverse = scaled.clone().try_inverse();
    let singular = smin <= 1e-12 * smax || inverse.is_none();
    let cov = inverse
        .map(|inv| DMatrix::from_fn(np, np, |a, b| s2 * inv[(a, b)] / (d[a] * d[b])))
        .unwrap_or_else(|| DMatrix::from_element(np, np, f64::INFINITY));
    let se: Vec<f64> = (0..np).map(|k| cov[(k, k)].sqrt()).collect();
    let corr = DMatrix::from_fn(np, np, |a, b| cov[(a, b)] / (se[a] * se[b]));
    let mut worst: Option<(usize, usize, f64)> = None;
    for a in 0..np {
        for b in a + 1..np {
            let c = if singular {
                jtj[(a, b)] / (d[a] * d[b])
            } else {
                corr[(a, b)]
            };
            if c.abs() > worst.map_or(0.0, |w| w.2.abs()) {
                worst = Some((a, b, c));
            }
        }
    }
    if singular || worst.is_some_and(|w| w.2.abs() > CORRELATION_LIMIT) {
        let pair = worst
            .map(|(a, b, c)| {
                format!(
                    "--param {} and --param {} (correlation {c:.6})",
                    req.params[a], req.params[b]
                )
            })
            .unwrap_or_else(|| "the parameters".into());
        return Err(SensitivityError::Fit(format!(
            "not identifiable from these data: {pair} change the fitted columns alike (the Gauss–Newton matrix is singular); fix one of them or measure more columns"
        )));
    }
    let to_rows = |m: &DMatrix<f64>| -> Vec<Vec<f64>> {
        (0..m.nrows())
            .map(|i| m.row(i).iter().copied().collect())
            .collect()
    };
    Ok(FitReport {
        converged,
        reason,
        iterations,
        runs,
        paths: req.params.clone(),
        start,
        values: p,
        std_errors: se,
        covariance: to_rows(&cov),
        correlation: to_rows(&corr),
        residual_rms: (ev.r.norm_squared() / m as f64).sqrt(),
        columns,
        points: m,
    })
}
