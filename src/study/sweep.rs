//! Running a speed-against-error sweep (`bondmech sweep`): the points, their accuracy runs in
//! parallel, their timing runs one at a time, the reference, the stiffness of the twin. The
//! data and its CSV, JSON and SVG are [`crate::report::sweep`]'s.

use std::io::IsTerminal;
use std::path::Path;

use nalgebra::DMatrix;
use rayon::prelude::*;

use crate::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::report::compare::{column_kind, ColumnKind};
use crate::report::sweep::*;
use crate::solve::formulation::DecoupledFormulation;
use crate::solve::{FormulationKind, Solution, SolveOptions};

/// The largest eigenvalue magnitude of the decoupled twin's Jacobian `∂f/∂y` at the start.
pub fn largest_eigenvalue(model: &Model, opts: &SolveOptions) -> Result<f64> {
    let mut sys = model.system().clone();
    let t0 = opts.output_times.first().copied().unwrap_or(0.0);
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, t0)?;
    let dec = DecoupledFormulation::build(&mut sys, opts.joint_stiffness, opts.joint_damping)?;
    let y0: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    let n = dec.ode.n;
    let mut jm = DMatrix::<f64>::zeros(n, n);
    let mut ws = dec.ode.workspace();
    dec.ode
        .jacobian(&mut ws, t0, &y0, |r, c, v| jm[(r, c)] += v);
    Ok(crate::analysis::linear_model::complex_eigenvalues(&jm)
        .iter()
        .fold(0.0f64, |a, z| a.max(z.norm())))
}

/// One point to run: options and its series label.
#[derive(Clone, Debug)]
struct Point {
    series: String,
    opts: SolveOptions,
}

fn point(
    base: &SolveOptions,
    f: FormulationKind,
    rtol: f64,
    k: Option<f64>,
    cfg: &SweepConfig,
) -> Point {
    let mut opts = base.clone();
    opts.formulation = f;
    opts.rtol = rtol;
    opts.atol = rtol * cfg.atol_per_rtol;
    if let Some(w) = cfg.point_wall_seconds {
        opts.max_wall_clock = Some(std::time::Duration::from_secs_f64(w));
    }
    let series = match k {
        Some(k) => {
            opts.joint_stiffness = k;
            format!("decoupled k={k:.0e}")
        }
        None => f.name().to_string(),
    };
    Point { series, opts }
}

fn failed(p: &Point, why: String) -> WorkPoint {
    WorkPoint {
        series: p.series.clone(),
        formulation: p.opts.formulation.name().into(),
        joint_stiffness: joint_stiffness(&p.opts),
        rtol: p.opts.rtol,
        atol: p.opts.atol,
        error: f64::NAN,
        cpu_seconds: f64::NAN,
        cpu_seconds_min: f64::NAN,
        steps: 0,
        residual_evals: 0,
        jacobian_evals: 0,
        error_test_failures: 0,
        max_constraint_error: f64::NAN,
        failure: Some(why),
    }
}

fn joint_stiffness(o: &SolveOptions) -> f64 {
    if o.formulation == FormulationKind::Decoupled {
        o.joint_stiffness
    } else {
        0.0
    }
}

fn measured(p: &Point, sol: &Solution, reference: Option<&Solution>) -> WorkPoint {
    let s = &sol.summary;
    WorkPoint {
        series: p.series.clone(),
        formulation: s.formulation.clone(),
        joint_stiffness: joint_stiffness(&p.opts),
        rtol: p.opts.rtol,
        atol: p.opts.atol,
        error: reference.map_or(0.0, |r| solution_error(sol, r)),
        cpu_seconds: s.cpu_seconds,
        cpu_seconds_min: s.cpu_seconds,
        steps: s.steps,
        residual_evals: s.residual_evals,
        jacobian_evals: s.jacobian_evals,
        error_test_failures: s.error_test_failures,
        max_constraint_error: s.max_constraint_error,
        failure: None,
    }
}

/// Re-runs a successful point `repeats` times (once if it is slow), one at a time, and stores
/// the median CPU time.
fn time_point(model: &Model, p: &Point, w: &mut WorkPoint, repeats: usize) {
    if w.failure.is_some() || repeats == 0 {
        return;
    }
    let repeats = if w.cpu_seconds > SLOW_RUN_SECONDS {
        1
    } else {
        repeats
    };
    let mut cpu: Vec<f64> = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        if crate::interrupt::requested().is_some() {
            // interrupted: the accuracy run's own CPU time stands
            return;
        }
        match model.solve(&p.opts) {
            // a timing run stopped by an interrupt: as above
            Err(_) if crate::interrupt::requested().is_some() => return,
            Ok(s) => cpu.push(s.summary.cpu_seconds),
            Err(e) => {
                w.failure = Some(format!("timing run failed: {e}"));
                return;
            }
        }
    }
    w.cpu_seconds_min = cpu.iter().copied().fold(f64::INFINITY, f64::min);
    w.cpu_seconds = median(&mut cpu);
}
/// Runs both sweeps on `model`; `tick` is called once per finished point (from any thread).
pub fn run_sweep(
    model: &Model,
    cfg: &SweepConfig,
    tick: &(dyn Fn(&str) + Sync),
) -> Result<SweepReport> {
    // a sweep measures errors row by row at the output times: event rows (and stops) would
    // misalign its runs, so the scene's events are left out (for every face: CLI and service)
    let without_events;
    let model = if model.scene().events.is_empty() {
        model
    } else {
        let mut scene = model.scene().clone();
        scene.events.clear();
        without_events = Model::new(&scene)?;
        &without_events
    };
    if cfg.rtols.is_empty() || cfg.rtols.iter().any(|r| !(*r > 0.0 && r.is_finite())) {
        return Err(Error::Options(format!(
            "sweep: tolerances must be positive and finite (got {:?})",
            cfg.rtols
        )));
    }
    if let Some(k) = cfg
        .stiffness_grid
        .iter()
        .chain(&cfg.decoupled_stiffnesses)
        .find(|k| !(**k > 0.0 && k.is_finite()))
    {
        return Err(Error::Options(format!(
            "sweep: joint stiffness must be > 0 (got {k})"
        )));
    }
    if cfg.accuracy.is_nan() || cfg.accuracy <= 0.0 {
        return Err(Error::Options(format!(
            "sweep: --accuracy must be > 0 (got {})",
            cfg.accuracy
        )));
    }
    let mut base = model.default_options();
    // no step cap unless the scene sets one: a sweep point runs to its end (issue 12)
    if let Some(t) = cfg.t_end {
        if !(t > 0.0 && t.is_finite()) {
            return Err(Error::Options(format!(
                "sweep: t_end must be > 0 (got {t})"
            )));
        }
        let step = model.scene().solve.output_step.unwrap_or(t / 100.0).min(t);
        base.output_times = SolveOptions::times(t, step);
    } else if let Some(cap) = cfg.t_end_cap {
        // the scene's own horizon, at most `cap`
        if base.output_times.last().is_some_and(|&t| t > cap) {
            base.output_times = model.output_times_until(cap)?;
        }
    }
    let external = match &cfg.reference {
        Some(r) => {
            let sol = crate::report::reference::truncate_reference(&r.solution, cfg.t_end);
            let t0 = base.output_times.first().copied().unwrap_or(0.0);
            if sol.times.len() < 2 || (sol.times[0] - t0).abs() > 1e-12 * (1.0 + t0.abs()) {
                return Err(Error::Options(format!(
                    "sweep: the reference {} must start at the scene's start t = {t0} and have at \
                     least two times up to t_end (it has {} from t = {})",
                    r.source,
                    sol.times.len(),
                    sol.times.first().copied().unwrap_or(f64::NAN)
                )));
            }
            base.output_times = sol.times.clone();
            Some(sol)
        }
        None => None,
    };

    // the reference (not stopped by the points' wall-clock budget)
    let mut ref_point = point(&base, FormulationKind::Ggl, cfg.reference_rtol, None, cfg);
    ref_point.opts.max_wall_clock = base.max_wall_clock;
    let mut stopped_note = None;
    let tight = match model.solve(&ref_point.opts) {
        Ok(sol) => sol,
        // a reference stopped part-way (a singular passage at a tight tolerance, say): the
        // sweep runs up to its last row, and the report says so
        Err(e)
            if external.is_none() && e.partial_solution().is_some_and(|p| p.times.len() >= 3) =>
        {
            let partial = e.partial_solution().expect("checked").clone();
            let t_last = partial.times[partial.times.len() - 1];
            base.output_times.retain(|&t| t <= t_last);
            ref_point.opts.output_times = base.output_times.clone();
            stopped_note = Some(format!(
                " (stopped part-way: {e}; the sweep runs to t = {t_last})"
            ));
            let mut sol = partial;
            let keep = sol.times.iter().filter(|&&t| t <= t_last).count();
            sol.times.truncate(keep);
            sol.rows.truncate(keep);
            sol
        }
        Err(e) => {
            return Err(Error::Options(format!(
                "sweep: the GGL reference at rtol {:e} failed: {e}",
                cfg.reference_rtol
            )))
        }
    };
    let t_end = base.output_times.last().copied().unwrap_or(0.0);
    tick("reference");
    let ref_run = measured(&ref_point, &tight, external.as_ref());
    if let (Some(ext), Some(r)) = (&external, &cfg.reference) {
        let shared: Vec<&String> = tight
            .columns
            .iter()
            .filter(|c| matches!(column_kind(c), ColumnKind::Position | ColumnKind::Angle))
            .filter(|c| ext.columns.contains(c))
            .collect();
        if shared.is_empty() {
            return Err(Error::Options(format!(
                "sweep: the reference {} shares no position or angle column with the scene's \
                 output (reference columns: {}; scene columns: {})",
                r.source,
                ext.columns.join(","),
                tight.columns.join(",")
            )));
        }
    }
    let reference = external.unwrap_or(tight);
    let reference_source = match &cfg.reference {
        Some(r) => r.source.clone(),
        None => format!(
            "GGL rtol {:e}{}",
            cfg.reference_rtol,
            stopped_note.unwrap_or_default()
        ),
    };

    // the points
    let mut wp_points = Vec::new();
    for &r in &cfg.rtols {
        wp_points.push(point(&base, FormulationKind::Ggl, r, None, cfg));
        wp_points.push(point(&base, FormulationKind::Index1, r, None, cfg));
        for &k in &cfg.decoupled_stiffnesses {
            wp_points.push(point(&base, FormulationKind::Decoupled, r, Some(k), cfg));
        }
    }
    let k_rtol = cfg.stiffness_rtol.unwrap_or(base.rtol);
    let baseline_point = point(&base, FormulationKind::Ggl, k_rtol, None, cfg);
    let k_points: Vec<Point> = cfg
        .stiffness_grid
        .iter()
        .map(|&k| point(&base, FormulationKind::Decoupled, k_rtol, Some(k), cfg))
        .collect();
    let mut all: Vec<Point> = wp_points.clone();
    all.push(baseline_point.clone());
    all.extend(k_points.iter().cloned());

    // accuracy runs, in parallel
    let mut runs: Vec<WorkPoint> = all
        .par_iter()
        .map(|p| {
            // after an interrupt (SIGINT, SIGTERM) the points not begun are not run; the
            // finished ones are kept
            let w = match crate::interrupt::requested() {
                Some(sig) => failed(
                    p,
                    format!(
                        "not run: interrupted by {}",
                        crate::interrupt::signal_name(sig)
                    ),
                ),
                None => match model.solve(&p.opts) {
                    Ok(sol) => measured(p, &sol, Some(&reference)),
                    Err(e) => failed(p, e.to_string()),
                },
            };
            tick(&p.series);
            w
        })
        .collect();
    // timing runs, one at a time
    for (p, w) in all.iter().zip(runs.iter_mut()) {
        time_point(model, p, w, cfg.repeats);
    }
    let k_runs = runs.split_off(wp_points.len() + 1);
    let dae_baseline = runs.pop().expect("the baseline point is in the list");
    let work_precision = runs;

    let m_min = model
        .scene()
        .bodies
        .iter()
        .map(|b| b.mass)
        .filter(|m| *m > 0.0)
        .fold(f64::INFINITY, f64::min);
    let mut stiffness = Vec::with_capacity(k_runs.len());
    for (p, run) in k_points.iter().zip(k_runs) {
        let largest = largest_eigenvalue(model, &p.opts).unwrap_or(f64::NAN);
        stiffness.push(StiffnessPoint {
            sqrt_k_over_m: (p.opts.joint_stiffness / m_min).sqrt(),
            largest_eigenvalue: largest,
            run,
        });
    }
    let sufficient_stiffness = stiffness
        .iter()
        .filter(|s| s.run.failure.is_none() && s.run.error <= cfg.accuracy)
        .min_by(|a, b| a.run.joint_stiffness.total_cmp(&b.run.joint_stiffness))
        .map(|s| SufficientStiffness {
            joint_stiffness: s.run.joint_stiffness,
            error: s.run.error,
            cpu_ratio_to_dae: s.run.cpu_seconds / dae_baseline.cpu_seconds,
            steps_ratio_to_dae: s.run.steps as f64 / dae_baseline.steps.max(1) as f64,
        });
    Ok(SweepReport {
        scene: model.scene().name.clone(),
        t_end,
        reference_source,
        reference: ref_run,
        work_precision,
        stiffness_rtol: k_rtol,
        dae_baseline,
        stiffness,
        accuracy: cfg.accuracy,
        sufficient_stiffness,
        repeats: cfg.repeats,
        machine: machine_description(),
    })
}

/// `bondmech sweep`: runs the sweep with a progress bar on a terminal (quiet otherwise), prints
/// the summary table and writes the data and plots into `out`.
pub fn sweep_command(model: &Model, cfg: &SweepConfig, out: &Path) -> Result<SweepReport> {
    let total = cfg.total_points() as u64;
    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(total);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} {msg}")
                .expect("template is valid"),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let report = run_sweep(model, cfg, &|label| {
        bar.set_message(label.to_string());
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    write_sweep(&report, out)?;
    Ok(report)
}

/// Writes `work_precision.csv`, `stiffness.csv`, `sweep.json`, `work_precision.svg` and
/// `stiffness.svg` into `dir` (created if missing).
pub fn write_sweep(report: &SweepReport, dir: &Path) -> Result<()> {
    let io = |p: &Path, source| Error::Io {
        path: p.display().to_string(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let json = serde_json::to_string_pretty(report).expect("report serialises");
    for (name, text) in [
        ("work_precision.csv", report.work_precision_csv()),
        ("stiffness.csv", report.stiffness_csv()),
        ("sweep.json", json),
    ] {
        let p = dir.join(name);
        crate::output::write_atomic(&p, text.as_bytes()).map_err(|e| io(&p, e))?;
    }
    crate::report::plot::work_precision_svg(report, &dir.join("work_precision.svg"))?;
    crate::report::plot::stiffness_svg(report, &dir.join("stiffness.svg"))?;
    Ok(())
}
