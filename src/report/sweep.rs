//! Speed against error: the work-precision and stiffness-vs-rigidity sweeps of `bondmech sweep`.
//!
//! **Error.** Every run is compared with a reference solution at the scene's output times:
//! `e = max_k max_c |x_c(t_k) − x_c^ref(t_k)|` over the position columns (m) and angle columns
//! (rad) that both solutions write (`b.x`, `b.y`, `b.angle`, points). The reference is the GGL
//! DAE at [`SweepConfig::reference_rtol`] (tighter than every swept tolerance), or, when the
//! user hands one in ([`SweepConfig::reference`], `bondmech sweep --reference REF.csv`), an
//! independent reference table: then every run — the tight GGL run included — is measured
//! against it, at its times.
//!
//! **Work-precision.** For each relative tolerance `rtol` (absolute tolerance
//! `atol = rtol · atol_per_rtol`) and each formulation — GGL DAE, index-1 DAE, and the decoupled
//! twin at a few joint stiffnesses `k` — the error, the median CPU seconds of
//! [`SweepConfig::repeats`] runs (integration only; model building excluded), steps, residual
//! and Jacobian evaluations.
//!
//! **Stiffness vs rigidity.** The decoupled twin `M v' = Q − G_vᵀ k g(q)` at one tolerance over a
//! grid of `k`: error against the DAE reference, constraint violation (the largest spring stretch
//! `max |g(q)|`), cost, and the stiffness itself — the largest eigenvalue magnitude `|λ|max` of
//! the ODE Jacobian `∂f/∂y` at the start, and `sqrt(k/m_min)` with `m_min` the smallest body
//! mass. The smallest `k` whose error reaches [`SweepConfig::accuracy`] is reported with its
//! CPU time relative to the GGL DAE at the same tolerance.
//!
//! The accuracy runs of all points go in parallel (`rayon`); the timing runs one at a time
//! (a point whose accuracy run took over [`SLOW_RUN_SECONDS`] is timed once).

use serde::Serialize;

use super::compare::{column_kind, ColumnKind};
use crate::solve::Solution;

/// What to sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepConfig {
    /// Relative tolerances of the work-precision sweep.
    pub rtols: Vec<f64>,
    /// Joint stiffnesses of the decoupled series in the work-precision sweep (N/m).
    pub decoupled_stiffnesses: Vec<f64>,
    /// Joint stiffnesses of the stiffness-vs-rigidity sweep (N/m).
    pub stiffness_grid: Vec<f64>,
    /// Relative tolerance of the stiffness sweep; `None`: the scene's `rtol`.
    pub stiffness_rtol: Option<f64>,
    /// The accuracy (error, see the module docs) the smallest sufficient `k` must reach.
    pub accuracy: f64,
    /// Timed runs per point (their median is reported).
    pub repeats: usize,
    /// Relative tolerance of the GGL reference solution.
    pub reference_rtol: f64,
    /// `atol = rtol · atol_per_rtol` for every run.
    pub atol_per_rtol: f64,
    /// End time; `None`: the scene's.
    pub t_end: Option<f64>,
    /// With `t_end` `None`: at most this end time (the scene's own when shorter).
    pub t_end_cap: Option<f64>,
    /// Wall-clock budget of each point's run (s); a point stopped by it is reported as failed
    /// and left out of the plots. `None`: the scene's own limits.
    pub point_wall_seconds: Option<f64>,
    /// An independent reference solution (e.g. a published one, read with
    /// [`super::reference::reference_from_csv`]); `None`: the tight GGL run is the reference.
    pub reference: Option<ExternalReference>,
}

/// An independent reference solution handed to the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalReference {
    /// Where it came from (a file name), for the report.
    pub source: String,
    /// The reference table: times from the scene's start, columns named as `bondmech run` names
    /// them.
    pub solution: Solution,
}

fn decades(from: i32, to: i32, step: i32) -> Vec<f64> {
    let mut v = Vec::new();
    let mut e = from;
    while (step > 0 && e <= to) || (step < 0 && e >= to) {
        v.push(10f64.powi(e));
        e += step;
    }
    v
}

impl SweepConfig {
    /// The full sweep: rtol 1e-3 … 1e-12, decoupled at k = 1e4, 1e6, 1e8, k = 1e2 … 1e12,
    /// five timed runs per point, reference GGL at rtol 1e-13.
    pub fn full() -> Self {
        SweepConfig {
            rtols: decades(-3, -12, -1),
            decoupled_stiffnesses: vec![1e4, 1e6, 1e8],
            stiffness_grid: decades(2, 12, 1),
            stiffness_rtol: None,
            accuracy: 1e-4,
            repeats: 5,
            reference_rtol: 1e-13,
            atol_per_rtol: 1e-2,
            t_end: None,
            t_end_cap: None,
            point_wall_seconds: None,
            reference: None,
        }
    }

    /// A quick sweep for tests and a first look: rtol 1e-4, 1e-6, 1e-8; decoupled at k = 1e6
    /// in the work-precision sweep, k = 1e4, 1e6, 1e8 in the stiffness sweep; the scene's own
    /// horizon up to 1 s; no separate timing runs (`repeats` 0: each point's CPU time is that
    /// of its accuracy run); every run stopped after 2 s of wall clock (reported as failed).
    pub fn quick() -> Self {
        SweepConfig {
            rtols: vec![1e-4, 1e-6, 1e-8],
            decoupled_stiffnesses: vec![1e6],
            stiffness_grid: vec![1e4, 1e6, 1e8],
            stiffness_rtol: Some(1e-8),
            accuracy: 1e-4,
            repeats: 0,
            reference_rtol: 1e-11,
            atol_per_rtol: 1e-2,
            t_end: None,
            t_end_cap: Some(1.0),
            point_wall_seconds: Some(2.0),
            reference: None,
        }
    }

    /// Number of sweep points (for a progress bar): work-precision runs plus stiffness runs
    /// plus the DAE baseline of the stiffness sweep and the reference.
    pub fn total_points(&self) -> usize {
        self.rtols.len() * (2 + self.decoupled_stiffnesses.len()) + self.stiffness_grid.len() + 2
    }
}

/// One run of the work-precision sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorkPoint {
    /// Series label: `ggl`, `index1`, `decoupled k=1e6`.
    pub series: String,
    /// Formulation name.
    pub formulation: String,
    /// Joint stiffness of the decoupled twin (N/m); 0 for the DAEs.
    pub joint_stiffness: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Error against the reference (see the module docs); NaN when the run failed.
    pub error: f64,
    /// Median CPU seconds of the timed runs (integration only).
    pub cpu_seconds: f64,
    /// Fastest of the timed runs.
    pub cpu_seconds_min: f64,
    /// Internal steps.
    pub steps: u64,
    /// Residual (IDA) or right-hand-side (CVODE) evaluations.
    pub residual_evals: u64,
    /// Jacobian evaluations.
    pub jacobian_evals: u64,
    /// Error test failures.
    pub error_test_failures: u64,
    /// Largest |g(q)| at the output times (the spring stretch for the decoupled twin).
    pub max_constraint_error: f64,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// One run of the stiffness-vs-rigidity sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StiffnessPoint {
    /// The run (series `decoupled k=…`).
    #[serde(flatten)]
    pub run: WorkPoint,
    /// Largest eigenvalue magnitude of the twin's Jacobian ∂f/∂y at the start (1/s).
    pub largest_eigenvalue: f64,
    /// `sqrt(k / m_min)`, `m_min` the smallest body mass (rad/s).
    pub sqrt_k_over_m: f64,
}

/// The smallest joint stiffness that reaches the requested accuracy.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SufficientStiffness {
    /// k (N/m).
    pub joint_stiffness: f64,
    /// Its error.
    pub error: f64,
    /// Its median CPU seconds divided by the GGL DAE's at the same tolerance.
    pub cpu_ratio_to_dae: f64,
    /// Its steps divided by the GGL DAE's.
    pub steps_ratio_to_dae: f64,
}

/// Everything `bondmech sweep` measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepReport {
    /// Scene name.
    pub scene: String,
    /// End time of every run (s).
    pub t_end: f64,
    /// What the errors are measured against: `GGL rtol …` or the independent reference's source.
    pub reference_source: String,
    /// The tight GGL run (its error is 0 by definition, or its error against the independent
    /// reference when there is one).
    pub reference: WorkPoint,
    /// The work-precision points.
    pub work_precision: Vec<WorkPoint>,
    /// Relative tolerance of the stiffness sweep.
    pub stiffness_rtol: f64,
    /// The GGL DAE at the stiffness sweep's tolerance (the cost baseline).
    pub dae_baseline: WorkPoint,
    /// The stiffness sweep.
    pub stiffness: Vec<StiffnessPoint>,
    /// Requested accuracy.
    pub accuracy: f64,
    /// The smallest swept k that reaches `accuracy`, if any.
    pub sufficient_stiffness: Option<SufficientStiffness>,
    /// Timed runs per point.
    pub repeats: usize,
    /// CPU model and core count of the machine that ran the sweep.
    pub machine: String,
}

/// Largest absolute difference over the position and angle columns the two solutions share,
/// over all output times (the solutions must have the same output times).
pub fn solution_error(sol: &Solution, reference: &Solution) -> f64 {
    let mut worst = 0.0f64;
    for (ci, name) in sol.columns.iter().enumerate() {
        if !matches!(column_kind(name), ColumnKind::Position | ColumnKind::Angle) {
            continue;
        }
        let Some(cr) = reference.columns.iter().position(|n| n == name) else {
            continue;
        };
        for (a, b) in sol.rows.iter().zip(&reference.rows) {
            let d = (a[ci] - b[cr]).abs();
            if d.is_nan() {
                return f64::NAN;
            }
            worst = worst.max(d);
        }
    }
    if sol.rows.len() < reference.rows.len() {
        return f64::NAN;
    }
    worst
}

/// Median of a non-empty slice (sorted in place).
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// An accuracy run slower than this (CPU seconds) is timed once, not [`SweepConfig::repeats`]
/// times: a stiff twin at k = 1e12 takes minutes per run, and its median would change nothing.
pub const SLOW_RUN_SECONDS: f64 = 1.0;

/// CPU model and core count, from `/proc/cpuinfo` where there is one.
pub fn machine_description() -> String {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    format!("{cpu}, {cores} cores")
}

const RUN_HEADER: &str = "series,formulation,joint_stiffness,rtol,atol,error,cpu_seconds,cpu_seconds_min,steps,residual_evals,jacobian_evals,error_test_failures,max_constraint_error,failure";

fn run_csv(w: &WorkPoint) -> String {
    format!(
        "{},{},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{},{:e},{}",
        w.series,
        w.formulation,
        w.joint_stiffness,
        w.rtol,
        w.atol,
        w.error,
        w.cpu_seconds,
        w.cpu_seconds_min,
        w.steps,
        w.residual_evals,
        w.jacobian_evals,
        w.error_test_failures,
        w.max_constraint_error,
        w.failure
            .as_deref()
            .unwrap_or("")
            .replace([',', '\n', '"'], ";")
    )
}

impl SweepReport {
    /// The work-precision points as CSV (one row per run).
    pub fn work_precision_csv(&self) -> String {
        let mut s = format!("{RUN_HEADER}\n");
        for w in &self.work_precision {
            s.push_str(&run_csv(w));
            s.push('\n');
        }
        s
    }

    /// The stiffness sweep as CSV, with the DAE baseline as its first row.
    pub fn stiffness_csv(&self) -> String {
        let mut s = format!("{RUN_HEADER},largest_eigenvalue,sqrt_k_over_m\n");
        s.push_str(&format!("{},,\n", run_csv(&self.dae_baseline)));
        for p in &self.stiffness {
            s.push_str(&format!(
                "{},{:e},{:e}\n",
                run_csv(&p.run),
                p.largest_eigenvalue,
                p.sqrt_k_over_m
            ));
        }
        s
    }

    /// A short text summary for the terminal.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{}: t_end = {} s, errors against {} (GGL rtol {:e}: {} steps, error {:.2e})\n\nwork-precision\n{:<20} {:>8} {:>10} {:>11} {:>7} {:>7} {:>6}\n",
            self.scene, self.t_end, self.reference_source, self.reference.rtol, self.reference.steps, self.reference.error,
            "series", "rtol", "error", "CPU (s)", "steps", "res", "jac"
        );
        for w in &self.work_precision {
            s.push_str(&format!(
                "{:<20} {:>8.0e} {:>10.2e} {:>11.3e} {:>7} {:>7} {:>6}{}\n",
                w.series,
                w.rtol,
                w.error,
                w.cpu_seconds,
                w.steps,
                w.residual_evals,
                w.jacobian_evals,
                w.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!("  FAILED: {f}"))
            ));
        }
        s.push_str(&format!(
            "\nstiffness vs rigidity at rtol {:e} (GGL DAE: error {:.2e}, CPU {:.3e} s, {} steps)\n{:>8} {:>10} {:>10} {:>11} {:>7} {:>6} {:>10} {:>10}\n",
            self.stiffness_rtol, self.dae_baseline.error, self.dae_baseline.cpu_seconds,
            self.dae_baseline.steps, "k", "error", "stretch", "CPU (s)", "steps", "jac", "|λ|max", "√(k/m)"
        ));
        for p in &self.stiffness {
            let w = &p.run;
            s.push_str(&format!(
                "{:>8.0e} {:>10.2e} {:>10.2e} {:>11.3e} {:>7} {:>6} {:>10.3e} {:>10.3e}{}\n",
                w.joint_stiffness,
                w.error,
                w.max_constraint_error,
                w.cpu_seconds,
                w.steps,
                w.jacobian_evals,
                p.largest_eigenvalue,
                p.sqrt_k_over_m,
                w.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!("  FAILED: {f}"))
            ));
        }
        match &self.sufficient_stiffness {
            Some(k) => s.push_str(&format!(
                "\nsmallest k with error <= {:e}: {:e} N/m (error {:.2e}), CPU {:.2}x and steps {:.2}x the GGL DAE\n",
                self.accuracy, k.joint_stiffness, k.error, k.cpu_ratio_to_dae, k.steps_ratio_to_dae
            )),
            None => s.push_str(&format!(
                "\nno swept k reaches error <= {:e}\n",
                self.accuracy
            )),
        }
        s
    }
}
