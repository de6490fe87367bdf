//! The one executor: runs any [`Formulation`] on IDA, CVODE or ARKODE and owns everything
//! around the integration — the output times, the scene's events, the step and wall-clock
//! budgets (carried over from segment to segment), the partial rows of a budget stop, the
//! statistics in the [`Summary`], the energy drift and constraint error of the rows, and the
//! streaming of every row to the observer. The formulations keep only their mathematics and
//! their recoveries ([`super::formulation`]).

use std::ops::ControlFlow;
use std::sync::Arc;
use std::time::Instant;

use cpu_time::ThreadTime;

use super::formulation::{
    Ending, Events, Formulation, HandOver, Job, Next, Problem, RowEval, Start,
};
use super::integrators::{make_cvode, make_ida, make_ida_schur};
use super::options::SolveOptions;
use super::solution::{EventRecord, Row, Solution, Summary};
use super::solver::{Integ, Solver};
use crate::mech::EventFunction;
use crate::scene::EventAction;
use crate::settings::Integrator;
use crate::solve::SolveError;
use crate::sundials::{Cvode, CvodeOptions, Erk, ErkOptions, Multistep, SolverError, SolverStats};

/// Builds the integrator of `problem` from `t`, carrying `earlier` counters and charging
/// the budgets with the steps and wall-clock time already spent.
fn build_solver(
    problem: Problem,
    t: f64,
    opts: &SolveOptions,
    events: Option<&Events>,
    (earlier, wall): (SolverStats, std::time::Duration),
    summary: &mut Summary,
) -> Result<Solver, SolveError> {
    let integ = match problem {
        Problem::Implicit(p) => {
            let wants_schur = p.schur.is_some();
            let weights = p.weights.map(|w| (p.atol.clone(), w));
            let schur = p.schur.and_then(|split| {
                make_ida_schur(
                    p.dae.clone(),
                    split,
                    p.atol.clone(),
                    t,
                    (&p.y0, &p.yp0),
                    opts,
                )
            });
            let mut ida = match schur {
                Some(ida) => {
                    summary.linear_solver = "schur".into();
                    ida?
                }
                None => {
                    let n = p.dae.len();
                    let ida = make_ida(p.dae, p.atol, t, &p.y0, &p.yp0, opts)?;
                    if wants_schur {
                        summary.linear_solver = opts.linear_solver.resolved_name(n).into();
                    }
                    ida
                }
            };
            if let Some((atol, w)) = weights {
                ida.set_error_weights(opts.rtol, atol, w)?;
            }
            if let Some(ev) = events.filter(|e| e.eval.len() > 0) {
                let mut ev = ev.eval.clone();
                ida.set_roots(ev.len(), Box::new(move |t, y, _yp, g| ev.roots(t, y, g)))?;
            }
            Integ::Ida(ida)
        }
        Problem::Explicit(p) => {
            let cv_opts = CvodeOptions {
                max_order: p.max_order,
                stab_lim_det: p.stab_lim_det,
                ..cvode_options(opts)
            };
            let mut cv = make_cvode(Arc::clone(&p.ode), t, &p.y0, &cv_opts, opts)?;
            if let Some(ev) = events.filter(|e| e.eval.len() > 0) {
                let mut ev = ev.eval.clone();
                cv.set_roots(ev.len(), Box::new(move |t, y, g| ev.roots(t, y, g)))?;
            }
            Integ::Cvode(cv)
        }
        Problem::Reduced(p) => reduced_integrator(p, t, opts)?,
    };
    Ok(Solver::new(integ, (earlier, wall)))
}

/// CVODE's options from the solve's: tolerances, the budgets (no per-output step limit; the
/// total steps and wall clock of the whole run) and the stop time at the last output.
fn cvode_options(opts: &SolveOptions) -> CvodeOptions {
    CvodeOptions {
        rtol: opts.rtol,
        atol: vec![opts.atol],
        max_steps: Some(u64::MAX),
        max_total_steps: opts.max_steps,
        max_wall_clock: opts.max_wall_clock,
        stop_time: opts.output_times.last().copied(),
        ..CvodeOptions::default()
    }
}

/// CVODE (Adams or BDF, Newton on CVODE's difference-quotient Jacobian: the reduced ODE has a
/// handful of states) or ARKODE's explicit Runge–Kutta on a reduced problem.
fn reduced_integrator(
    p: super::formulation::ReducedProblem,
    t: f64,
    opts: &SolveOptions,
) -> Result<Integ, SolveError> {
    let stop_time = opts.output_times.last().copied();
    if p.y0.is_empty() {
        // DOF 0: a kinematic analysis, nothing to integrate
        let roots = p.roots.map(|(n, f, _)| (n, f));
        return Ok(Integ::Kinematic(super::kinematic::KinematicSteps::new(
            t, roots,
        )?));
    }
    if p.integrator == Integrator::Erk {
        let eo = ErkOptions {
            rtol: opts.rtol,
            atol: opts.atol,
            max_steps: Some(u64::MAX),
            max_total_steps: opts.max_steps,
            max_wall_clock: opts.max_wall_clock,
            stop_time,
        };
        let mut e = Erk::new(t, &p.y0, p.rhs, &eo)?;
        if let Some((n, f, events)) = p.roots {
            e.set_roots(n, f)?;
            if events {
                // event times to the step's accuracy; the switching functions' zeros are
                // integrated to again from the last exact point (the cubic interpolant,
                // which takes no right-hand side beyond the step's own, only places them)
                e.set_interpolant_degree(crate::sundials::erk::MAX_INTERPOLANT_DEGREE)?;
            }
        }
        if let Some(h) = p.init_step {
            e.set_init_step(h)?;
        }
        return Ok(Integ::Erk(e));
    }
    let method = if p.integrator == Integrator::Bdf {
        Multistep::Bdf
    } else {
        Multistep::Adams
    };
    let mut c = Cvode::new(method, t, &p.y0, p.rhs, None, &cvode_options(opts))?;
    if let Some((n, f, _)) = p.roots {
        c.set_roots(n, f)?;
    }
    Ok(Integ::Cvode(c))
}

/// The run's bookkeeping between segments.
struct Run<'r> {
    opts: &'r SolveOptions,
    rows: Box<dyn RowEval + 'r>,
    events: Option<Events>,
    sol: Solution,
    clock: ThreadTime,
    wall_start: Instant,
    /// CPU seconds spent building segments (model building, not integration).
    build: f64,
    /// The row state of the last row.
    x: Vec<f64>,
    /// Time of the last row.
    t_last: f64,
    /// The row state at a root return.
    x_root: Vec<f64>,
}

/// Runs `job` over the output times of `opts` (the first one is the start), streaming every
/// row to `observer` (`ControlFlow::Break(())` stops; the rows so far are returned), and
/// writes the statistics into `summary` (which the caller has filled with what it knows
/// before the integration: corrections, warnings, names).
pub(crate) fn execute<'a>(
    job: Job<'a>,
    opts: &SolveOptions,
    summary: &mut Summary,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, SolveError> {
    let Job {
        mut formulation,
        rows,
        events,
    } = job;
    let times = &opts.output_times;
    let t0 = times[0];
    let mut run = Run {
        opts,
        sol: Solution {
            columns: rows.columns(),
            times: Vec::with_capacity(times.len()),
            rows: Vec::with_capacity(times.len()),
            summary: Summary::default(),
        },
        rows,
        events,
        clock: ThreadTime::now(),
        wall_start: Instant::now(),
        build: 0.0,
        x: formulation.first_row_state(),
        t_last: t0,
        x_root: Vec::new(),
    };
    let first = run.rows.row(t0, &run.x);
    let mut solver: Option<Solver> = None;
    if emit(&mut run.sol, observer, t0, first, opts.keep_rows) {
        return Ok(run.complete(&mut *formulation, solver.as_ref(), summary));
    }
    let n_ev = run.events.as_ref().map_or(0, |e| e.eval.len());
    let mut k = 1;
    let mut t_start = t0;
    'segments: while k < times.len() {
        let tb = ThreadTime::now();
        let start = formulation.segment(t_start, summary);
        run.build += tb.elapsed().as_secs_f64();
        let problem = match start? {
            Start::Run(p) => p,
            Start::HandOver(h) => {
                // its build is counted by the hand-over
                run.build -= h.build_seconds;
                return run.hand_over(&mut *formulation, solver.as_ref(), h, k, summary, observer);
            }
        };
        let earlier = solver.take().map(|s| s.stats()).unwrap_or_default();
        let wall = run.wall_start.elapsed();
        let s = solver.insert(build_solver(
            problem,
            t_start,
            opts,
            run.events.as_ref(),
            (earlier, wall),
            summary,
        )?);
        let watching = formulation.watches_steps();
        // the wall-clock budget bounds the whole run: the time between two calls of the
        // integrator (the formulation's examinations at steps and outputs, the rows written)
        // is charged to it too (examined at every step, a run spent most of its time there
        // and outlived its budget several times over)
        let mut outside: Option<Instant> = None;
        while k < times.len() {
            if let Some(since) = outside.take() {
                s.charge_wall_clock(since.elapsed());
            }
            let result = if watching {
                let f = &mut *formulation;
                s.solve_to_watched(times[k], &mut |t, y| f.watch_step(t, y))
            } else {
                s.solve_to(times[k])
            };
            outside = Some(Instant::now());
            let step = match result {
                Ok(step) => step,
                Err(e) => {
                    let next = if is_budget(&e) {
                        Next::Fail
                    } else {
                        formulation.recover(&e, s, (run.t_last, &run.x), summary)?
                    };
                    match next {
                        Next::Continue => continue,
                        Next::Restart(t) => {
                            t_start = t;
                            continue 'segments;
                        }
                        Next::HandOver(h) => {
                            return run.hand_over(
                                &mut *formulation,
                                Some(&*s),
                                h,
                                k,
                                summary,
                                observer,
                            )
                        }
                        Next::Fail => return Err(run.stop(e, &mut *formulation, s, summary)),
                        Next::FailWith(named) => {
                            return Err(run.stop(named, &mut *formulation, s, summary))
                        }
                    }
                }
            };
            if watching && step.t < times[k] && step.event == crate::sundials::StepEvent::Reached {
                // the formulation's watch stopped at an internal step
                let y = s.y().to_vec();
                match formulation.at_step(step.t, &y, s, summary)? {
                    Next::Continue => continue,
                    Next::Fail => {
                        let e = refused(step.t, "at an internal step");
                        return Err(run.stop(e, &mut *formulation, s, summary));
                    }
                    Next::Restart(t) => {
                        t_start = t;
                        continue 'segments;
                    }
                    Next::HandOver(h) => {
                        return run.hand_over(&mut *formulation, Some(&*s), h, k, summary, observer)
                    }
                    Next::FailWith(named) => {
                        return Err(run.stop(named, &mut *formulation, s, summary))
                    }
                }
            }
            if let crate::sundials::StepEvent::Root(info) = &step.event {
                let (user, rest) = info.split_at(n_ev.min(info.len()));
                let defs = run.events.as_ref().map_or(&[][..], |e| &e.defs[..]);
                // the row state at every root return (a formulation that completes its state
                // warm-starts its next completion from it)
                formulation.row_state(step.t, s.y(), &mut run.x_root)?;
                if let Some(stop) = events_fired(defs, user, step.t, summary) {
                    std::mem::swap(&mut run.x, &mut run.x_root);
                    run.t_last = step.t;
                    let row = run.rows.row(step.t, &run.x);
                    if emit(&mut run.sol, observer, step.t, row, opts.keep_rows) || stop {
                        break 'segments;
                    }
                }
                if rest.iter().any(|&d| d != 0) {
                    formulation.at_switch(step.t, rest, s, summary)?;
                }
                continue;
            }
            k += 1;
            formulation.row_state(step.t, s.y(), &mut run.x)?;
            run.t_last = step.t;
            let row = run.rows.row(step.t, &run.x);
            if emit(&mut run.sol, observer, step.t, row, opts.keep_rows) {
                break 'segments;
            }
            match formulation.at_output(step.t, &run.x, s, k < times.len(), summary)? {
                Next::Continue => {}
                Next::Fail => {
                    let e = refused(step.t, "at an output");
                    return Err(run.stop(e, &mut *formulation, s, summary));
                }
                Next::FailWith(named) => {
                    return Err(run.stop(named, &mut *formulation, s, summary))
                }
                Next::Restart(t) => {
                    t_start = t;
                    continue 'segments;
                }
                Next::HandOver(h) => {
                    return run.hand_over(&mut *formulation, Some(&*s), h, k, summary, observer)
                }
            }
        }
        break;
    }
    Ok(run.complete(&mut *formulation, solver.as_ref(), summary))
}

/// The error of a [`Next::Fail`] from the formulation's examination `at` a step or an output
/// at `t`, where no integrator error is at hand: the formulation cannot go on there.
fn refused(t: f64, at: &str) -> SolverError {
    SolverError::Stalled {
        t,
        cause: format!("its examination {at} stopped the run"),
    }
}

impl Run<'_> {
    /// The counters, CPU time, constraint error and energy of the run so far, then the
    /// formulation's own figures.
    fn figures(
        &self,
        f: &mut dyn Formulation<'_>,
        solver: Option<&Solver>,
        summary: &mut Summary,
        ending: Ending,
    ) {
        summary.cpu_seconds = self.clock.elapsed().as_secs_f64() - self.build;
        summary.build_cpu_seconds += self.build;
        fill_stats(summary, &solver.map(Solver::stats).unwrap_or_default());
        summary.max_constraint_error = self.rows.max_constraint_error();
        set_energy(
            summary,
            self.rows.energy_drift(),
            self.rows.energy_exchange().as_deref(),
        );
        summary.driver_work = self.rows.driver_work();
        summary.driver_work_note = self.rows.driver_work_note();
        f.finish(summary, solver, self.sol.times.last().copied(), ending);
    }

    fn complete(
        mut self,
        f: &mut dyn Formulation<'_>,
        solver: Option<&Solver>,
        summary: &mut Summary,
    ) -> Solution {
        self.figures(f, solver, summary, Ending::Completed);
        set_completed(summary, &self.sol);
        self.sol.summary = summary.clone();
        self.sol
    }

    /// The [`SolveError::Incomplete`] of a run stopped by `e`, with the row at the time reached
    /// after a budget stop.
    fn stop(
        mut self,
        e: SolverError,
        f: &mut dyn Formulation<'_>,
        solver: &mut Solver,
        summary: &mut Summary,
    ) -> SolveError {
        let last = e.time().filter(|_| is_budget(&e)).and_then(|tr| {
            let mut y = vec![0.0; solver.y().len()];
            solver.dky(tr, &mut y).ok()?;
            let mut x = Vec::new();
            f.row_state(tr, &y, &mut x).ok()?;
            Some((tr, self.rows.row(tr, &x)))
        });
        if let Some(hint) = tolerance_hint(&e, self.opts) {
            summary.warnings.push(hint);
        }
        let defs = self.events.as_ref().map_or(&[][..], |ev| &ev.defs[..]);
        if let Some(hint) = events_hint(&e, defs, &summary.events) {
            summary.warnings.push(hint);
        }
        self.figures(f, Some(solver), summary, Ending::Stopped);
        stopped(e, self.sol, summary.clone(), last)
    }

    /// The rest of the run from the last row (at `h.t`) on the formulation of `h`: its rows
    /// after `h.t` appended, the counters of both parts added, the hand-over named in the
    /// warnings.
    fn hand_over(
        self,
        f: &mut dyn Formulation<'_>,
        solver: Option<&Solver>,
        h: Box<HandOver<'_>>,
        k_next: usize,
        summary: &mut Summary,
        observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        let h = *h;
        self.figures(f, solver, summary, Ending::HandedOver);
        let before = summary.clone();
        summary.warnings.push(h.warning);
        let times = &self.opts.output_times;
        let o = SolveOptions {
            output_times: std::iter::once(h.t)
                .chain(times[k_next.min(times.len())..].iter().copied())
                .collect(),
            ..self.opts.clone()
        };
        summary.build_cpu_seconds += h.build_seconds;
        // the row at h.t is this part's last one
        let mut first = true;
        let mut rest = |r: Row<'_>| {
            if std::mem::take(&mut first) {
                ControlFlow::Continue(())
            } else {
                observer(r)
            }
        };
        let sol = &self.sol;
        let merge = |part: &mut Solution| merge_parts(sol, &before, part);
        match execute(h.job, &o, summary, &mut rest) {
            Ok(mut part) => {
                merge(&mut part);
                *summary = part.summary.clone();
                Ok(part)
            }
            Err(e) => Err(e.map_partial(merge)),
        }
    }
}

/// `part` (a run handed over at its first row, the last of `first`) after the rows of `first`,
/// its counters and CPU time added to those of `before` (the summary of `first`), its name.
fn merge_parts(first: &Solution, before: &Summary, part: &mut Solution) {
    let mut times = first.times.clone();
    let mut rows = first.rows.clone();
    times.extend(part.times.iter().skip(1));
    rows.extend(part.rows.iter().skip(1).cloned());
    part.times = times;
    part.rows = rows;
    let s = &mut part.summary;
    s.formulation.clone_from(&before.formulation);
    let mut counters = counters_of(before);
    counters.accumulate(&counters_of(s));
    fill_stats(s, &counters);
    s.cpu_seconds += before.cpu_seconds;
    s.index1_reselections = before.index1_reselections;
    s.max_constraint_error = s.max_constraint_error.max(before.max_constraint_error);
    if let (Some(a), Some(b)) = (s.energy_drift, before.energy_drift) {
        s.energy_drift = Some(a + b);
    }
}

/// Tolerances at or below which repeated error-test failures are most likely the tolerance's
/// fault: `rtol <= 1e-10` or `atol <= 1e-13` ask for digits that rounding (about 2.2e-16 times
/// each state, amplified by a stiff problem's Newton iterations) does not leave.
const TIGHT_RTOL: f64 = 1e-10;
const TIGHT_ATOL: f64 = 1e-13;

/// The advice for a solve stopped by repeated error-test failures (`IDA_ERR_FAIL`,
/// `CV_ERR_FAILURE`) at tight tolerances: the error test cannot be met in double precision
/// there; loosen them (issue 38: a stiff double pendulum at rtol 1e-12, atol 1e-14 failed at
/// t = 0 with nothing saying why, and atol 1e-13 works).
fn tolerance_hint(e: &SolverError, opts: &SolveOptions) -> Option<String> {
    let SolverError::Flag { name, t, .. } = e else {
        return None;
    };
    if !(name == "IDA_ERR_FAIL" || name == "CV_ERR_FAILURE") {
        return None;
    }
    if !(opts.rtol <= TIGHT_RTOL || opts.atol <= TIGHT_ATOL) {
        return None;
    }
    // one decade looser in atol (at least 1e-13), two in rtol (at least 1e-10)
    let decade = |x: f64| x.log10().round() as i32;
    let atol = (decade(opts.atol) + 1).max(-13);
    let rtol = (decade(opts.rtol) + 2).clamp(-10, -6);
    Some(format!(
        "the error test failed repeatedly at t = {t} at rtol = {:e}, atol = {:e}: tolerances this tight ask for more digits than double precision leaves in a stiff problem's states; loosen them (solve.rtol, solve.atol or --rtol, --atol: e.g. atol 1e{atol} or rtol 1e{rtol})",
        opts.rtol, opts.atol,
    ))
}

/// Event crossings met within this span before a failure (relative to `|t|`, at least
/// [`EVENT_PILE_FLOOR`] s) that name the events as its likely cause.
const EVENT_PILE_SPAN: f64 = 1e-3;
/// Smallest span of [`EVENT_PILE_SPAN`] (s).
const EVENT_PILE_FLOOR: f64 = 1e-9;
/// Crossings within that span that make a pile.
const EVENT_PILE_COUNT: usize = 10;

/// The events piled up before a solver failure (issue 38: 10 000 events whose crossings lie
/// 1e-9 s apart collapsed IDA's step at t = 0.50000625, and the message named no event): when
/// at least [`EVENT_PILE_COUNT`] crossings were met within `max(1e-3 |t|, 1e-9 s)` before the
/// failure at `t`, a warning naming how many, their span and the events (`events[i]` and
/// name, at most five), with what to do.
fn events_hint(e: &SolverError, defs: &[EventFunction], met: &[EventRecord]) -> Option<String> {
    if is_budget(e) || defs.is_empty() {
        return None;
    }
    let t = e.time()?;
    let span = (EVENT_PILE_SPAN * t.abs()).max(EVENT_PILE_FLOOR);
    let recent: Vec<&EventRecord> = met.iter().filter(|r| r.t >= t - span).collect();
    if recent.len() < EVENT_PILE_COUNT {
        return None;
    }
    let mut names: Vec<&str> = Vec::new();
    for r in &recent {
        if !names.contains(&r.name.as_str()) {
            names.push(&r.name);
        }
    }
    let shown: Vec<String> = names
        .iter()
        .take(5)
        .map(|n| match defs.iter().position(|d| d.name == *n) {
            Some(i) => format!("events[{i}] '{n}'"),
            None => format!("'{n}'"),
        })
        .collect();
    let more = if names.len() > 5 {
        format!(" and {} more", names.len() - 5)
    } else {
        String::new()
    };
    let first = recent.first().map_or(t, |r| r.t);
    Some(format!(
        "the solver failed at t = {t} after {} event crossings within {:e} s (from t = {first}) of {} event{} ({}{more}): crossings this close together make the solver stop and restart at each, and its step collapses; space the events' thresholds apart, merge them into fewer events, or count one direction only (events[i].direction)",
        recent.len(),
        t - first,
        names.len(),
        if names.len() == 1 { "" } else { "s" },
        shown.join(", "),
    ))
}

pub(crate) fn stop_reason(e: &SolverError) -> &'static str {
    match e {
        SolverError::StepBudget { .. } | SolverError::TooMuchWork { .. } => "max_steps",
        SolverError::WallClock { .. } => "max_wall_seconds",
        SolverError::Interrupted { .. } => "interrupt",
        _ => "solver_error",
    }
}

/// Whether `e` is a budget running out or an interrupt (the state at the time reached is sound).
pub(crate) fn is_budget(e: &SolverError) -> bool {
    stop_reason(e) != "solver_error"
}

/// The [`SolveError::Incomplete`] of a solve stopped by `e`: the rows so far, plus `last_row` (the
/// state at the time reached, after a budget stop) when it lies beyond them.
pub(crate) fn stopped(
    e: SolverError,
    mut sol: Solution,
    mut summary: Summary,
    last_row: Option<(f64, Vec<f64>)>,
) -> SolveError {
    let t_last = sol.times.last().copied().unwrap_or(f64::NEG_INFINITY);
    summary.completed = false;
    summary.t_reached = e.time().unwrap_or(t_last).max(t_last);
    summary.stopped_by = Some(stop_reason(&e).into());
    if let Some((t, row)) = last_row {
        if t > t_last {
            sol.times.push(t);
            sol.rows.push(row);
            summary.t_reached = t;
        }
    }
    sol.summary = summary;
    SolveError::Incomplete {
        cause: Box::new(SolveError::Solver(e)),
        partial: Box::new(sol),
    }
}

/// Records the energy figures: the drift where energy is conserved (`exchange` is `None`),
/// else `not_conserved` with the reason.
pub(crate) fn set_energy(summary: &mut Summary, drift: f64, exchange: Option<&str>) {
    match exchange {
        None => {
            summary.energy_check = "conserved".into();
            summary.energy_drift = Some(drift);
            summary.energy_note.clear();
        }
        Some(why) => {
            summary.energy_check = "not_conserved".into();
            summary.energy_drift = None;
            summary.energy_note = why.into();
        }
    }
}

/// Marks a solve that reached its last row.
pub(crate) fn set_completed(summary: &mut Summary, sol: &Solution) {
    summary.completed = true;
    summary.t_reached = sol.times.last().copied().unwrap_or(0.0);
    summary.stopped_by = None;
}

/// Runs `solve` over the integration times of `opts` (`t_start`, then the output times after
/// it), and removes the row at `t_start` from the solution (and from the stream) unless the
/// caller listed it among the output times.
pub(crate) fn from_t_start(
    opts: &SolveOptions,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    solve: impl FnOnce(
        &SolveOptions,
        &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError>,
) -> Result<Solution, SolveError> {
    let (times, listed) = opts.integration_times()?;
    let inner = SolveOptions {
        output_times: times,
        ..opts.clone()
    };
    let mut skip = !listed;
    let mut filtered = |row: Row<'_>| {
        if std::mem::take(&mut skip) {
            ControlFlow::Continue(())
        } else {
            observer(row)
        }
    };
    let t0 = opts.t_start;
    // the row at t_start is the first one, if it is still there (a solve that keeps only its
    // latest row may have dropped it already)
    let drop_first = |sol: &mut Solution| {
        if !listed && sol.times.first() == Some(&t0) && !sol.rows.is_empty() {
            sol.times.remove(0);
            sol.rows.remove(0);
        }
    };
    match solve(&inner, &mut filtered) {
        Ok(mut sol) => {
            drop_first(&mut sol);
            Ok(sol)
        }
        Err(e) => Err(e.map_partial(drop_first)),
    }
}

/// The counters [`fill_stats`] wrote into a summary (the inverse of it).
fn counters_of(summary: &Summary) -> SolverStats {
    SolverStats {
        steps: summary.steps,
        residual_evals: summary.residual_evals,
        jacobian_evals: summary.jacobian_evals,
        linear_setups: summary.linear_setups,
        error_test_failures: summary.error_test_failures,
        nonlinear_iterations: summary.nonlinear_iterations,
        nonlinear_conv_failures: summary.nonlinear_conv_failures,
        last_step: summary.last_step,
        ..SolverStats::default()
    }
}

fn fill_stats(summary: &mut Summary, s: &SolverStats) {
    summary.steps = s.steps;
    summary.residual_evals = s.residual_evals;
    summary.jacobian_evals = s.jacobian_evals;
    summary.linear_setups = s.linear_setups;
    summary.error_test_failures = s.error_test_failures;
    summary.nonlinear_iterations = s.nonlinear_iterations;
    summary.nonlinear_conv_failures = s.nonlinear_conv_failures;
    summary.last_step = s.last_step;
}

/// Hands a row to the observer and appends it to the solution (with `keep` false, the
/// solution keeps only its latest row: [`SolveOptions::keep_rows`]); `true` when the observer
/// asks to stop.
pub(crate) fn emit(
    sol: &mut Solution,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
    t: f64,
    row: Vec<f64>,
    keep: bool,
) -> bool {
    let brk = observer(Row { t, values: &row }).is_break();
    if !keep {
        sol.times.clear();
        sol.rows.clear();
    }
    sol.times.push(t);
    sol.rows.push(row);
    brk
}
/// The events that count at a root return at `t` (`info[i]`: +1 rising, −1 falling, 0 not
/// crossing), recorded in the summary; `None` when none counts (a crossing in a direction the
/// event ignores), else whether one of them stops the run.
fn events_fired(
    events: &[EventFunction],
    info: &[i32],
    t: f64,
    summary: &mut Summary,
) -> Option<bool> {
    let mut stop = None;
    for (e, &sign) in events.iter().zip(info) {
        if e.direction.accepts(sign) {
            summary.events.push(EventRecord {
                name: e.name.clone(),
                t,
            });
            stop = Some(stop.unwrap_or(false) || e.action == EventAction::Stop);
        }
    }
    stop
}

#[cfg(test)]
mod tests {
    //! The executor on a formulation that is only a trait implementation: the harmonic
    //! oscillator `x' = v, v' = −x` (`x = cos t`, `v = −sin t` from `(1, 0)`, energy
    //! `(x² + v²)/2` conserved) as a reduced problem, with a recovery hook.

    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::Arc;

    use super::*;
    use crate::sundials::CallbackError;

    /// Rows `[x, v]` and the energy `(x² + v²)/2`.
    struct Identity {
        e0: Option<f64>,
        dev: f64,
    }

    impl RowEval for Identity {
        fn columns(&self) -> Vec<String> {
            vec!["x".into(), "v".into()]
        }
        fn row(&mut self, _t: f64, x: &[f64]) -> Vec<f64> {
            let e = 0.5 * (x[0] * x[0] + x[1] * x[1]);
            let e0 = *self.e0.get_or_insert(e);
            self.dev = self.dev.max((e - e0).abs());
            x.to_vec()
        }
        fn max_constraint_error(&self) -> f64 {
            0.0
        }
        fn energy_drift(&self) -> f64 {
            self.dev / self.e0.unwrap_or(1.0)
        }
        fn energy_exchange(&self) -> Option<String> {
            None
        }
    }

    /// The oscillator; its right-hand side fails once past `fail_after` (a fatal callback
    /// error), which the recovery hook answers with a restart from the last row.
    struct Oscillator {
        integrator: Integrator,
        start: (f64, Vec<f64>),
        fail_after: f64,
        failed: Arc<AtomicBool>,
        recoveries: Arc<AtomicUsize>,
        /// Outputs after this time answer [`Next::Fail`].
        refuse_after: f64,
    }

    impl<'a> Formulation<'a> for Oscillator {
        fn first_row_state(&self) -> Vec<f64> {
            self.start.1.clone()
        }
        fn segment(&mut self, _t: f64, _s: &mut Summary) -> Result<Start<'a>, SolveError> {
            let (fail_after, failed) = (self.fail_after, self.failed.clone());
            let rhs: crate::sundials::RhsFn = Box::new(move |t, y, yd| {
                if t > fail_after && !failed.swap(true, Ordering::Relaxed) {
                    return Err(CallbackError::Fatal("a partition degraded".into()));
                }
                yd[0] = y[1];
                yd[1] = -y[0];
                Ok(())
            });
            Ok(Start::Run(Problem::Reduced(
                super::super::formulation::ReducedProblem {
                    integrator: self.integrator,
                    rhs,
                    y0: self.start.1.clone(),
                    roots: None,
                    init_step: None,
                },
            )))
        }
        fn at_output(
            &mut self,
            t: f64,
            x: &[f64],
            _solver: &mut Solver,
            _more: bool,
            _s: &mut Summary,
        ) -> Result<Next<'a>, SolveError> {
            self.start = (t, x.to_vec());
            Ok(if t > self.refuse_after {
                Next::Fail
            } else {
                Next::Continue
            })
        }
        fn recover(
            &mut self,
            _e: &SolverError,
            _solver: &mut Solver,
            (t, x): (f64, &[f64]),
            _s: &mut Summary,
        ) -> Result<Next<'a>, SolveError> {
            self.recoveries.fetch_add(1, Ordering::Relaxed);
            assert_eq!(self.start, (t, x.to_vec()), "the hook gets the last row");
            Ok(Next::Restart(t))
        }
    }

    fn run(
        integrator: Integrator,
        fail_after: f64,
        max_steps: Option<u64>,
    ) -> (Result<Solution, SolveError>, usize) {
        run_refusing(integrator, fail_after, max_steps, f64::INFINITY)
    }

    fn run_refusing(
        integrator: Integrator,
        fail_after: f64,
        max_steps: Option<u64>,
        refuse_after: f64,
    ) -> (Result<Solution, SolveError>, usize) {
        let recoveries = Arc::new(AtomicUsize::new(0));
        let job = Job {
            formulation: Box::new(Oscillator {
                integrator,
                start: (0.0, vec![1.0, 0.0]),
                fail_after,
                failed: Arc::new(AtomicBool::new(false)),
                recoveries: recoveries.clone(),
                refuse_after,
            }),
            rows: Box::new(Identity { e0: None, dev: 0.0 }),
            events: None,
        };
        let opts = SolveOptions {
            rtol: 1e-10,
            atol: 1e-12,
            output_times: (0..=40).map(|k| 0.1 * k as f64).collect(),
            max_steps,
            ..SolveOptions::default()
        };
        let mut summary = Summary::default();
        let r = execute(job, &opts, &mut summary, &mut |_| ControlFlow::Continue(()));
        (r, recoveries.load(Ordering::Relaxed))
    }

    fn assert_on_cosine(sol: &Solution) {
        for (t, r) in sol.times.iter().zip(&sol.rows) {
            assert!((r[0] - t.cos()).abs() < 1e-7, "x({t}) = {}", r[0]);
            assert!((r[1] + t.sin()).abs() < 1e-7, "v({t}) = {}", r[1]);
        }
    }

    #[test]
    fn any_integrator_runs_a_formulation_and_the_executor_fills_the_summary() {
        for integrator in [Integrator::Erk, Integrator::Adams, Integrator::Bdf] {
            let (r, recoveries) = run(integrator, f64::INFINITY, None);
            let sol = r.unwrap();
            assert_eq!((sol.times.len(), recoveries), (41, 0), "{integrator:?}");
            assert_on_cosine(&sol);
            let s = &sol.summary;
            assert!(
                s.completed && s.steps > 0 && s.residual_evals > s.steps,
                "{s:?}"
            );
            assert_eq!((s.t_reached, s.energy_check.as_str()), (4.0, "conserved"));
            assert!(s.energy_drift.unwrap() < 1e-7, "{s:?}");
        }
    }

    #[test]
    fn a_failure_goes_to_the_recovery_hook_and_the_run_restarts_from_the_last_row() {
        let (r, recoveries) = run(Integrator::Adams, 1.05, None);
        let sol = r.unwrap();
        assert_eq!((sol.times.len(), recoveries), (41, 1));
        assert_on_cosine(&sol);
    }

    #[test]
    fn a_step_budget_stops_with_the_rows_so_far_and_the_row_at_the_time_reached() {
        let (r, _) = run(Integrator::Erk, f64::INFINITY, Some(30));
        let Err(SolveError::Incomplete { cause, partial }) = r else {
            panic!("a budget stop keeps its rows")
        };
        assert!(matches!(
            *cause,
            SolveError::Solver(SolverError::StepBudget { .. })
        ));
        let s = &partial.summary;
        assert_eq!(
            (s.completed, s.stopped_by.as_deref()),
            (false, Some("max_steps"))
        );
        assert_eq!(s.steps, 30);
        // the rows at the outputs reached, then the row at the time reached
        let n = partial.times.len();
        assert!(
            n >= 2 && partial.times[n - 1] == s.t_reached,
            "{:?}",
            partial.times
        );
        assert!(partial.times[n - 1] > partial.times[n - 2]);
        assert!(s.t_reached > 0.0 && s.t_reached < 4.0);
        assert_on_cosine(&partial);
    }

    #[test]
    fn regression_next_fail_at_an_output_stops_the_run_with_the_rows_so_far() {
        // `Next::Fail` from `at_output` used to be continued silently (issue 47)
        let (r, recoveries) = run_refusing(Integrator::Adams, f64::INFINITY, None, 1.05);
        let Err(SolveError::Incomplete { cause, partial }) = r else {
            panic!("a refused output stops the run and keeps its rows")
        };
        let SolveError::Solver(SolverError::Stalled { t, .. }) = *cause else {
            panic!("stopped by the formulation: {cause:?}")
        };
        assert_eq!(recoveries, 0);
        // the rows up to and including the refused output at t = 1.1, no further
        assert_eq!(partial.times.len(), 12, "{:?}", partial.times);
        assert!((t - 1.1).abs() < 1e-12 && partial.times[11] == t, "{t}");
        let s = &partial.summary;
        assert_eq!(
            (s.completed, s.stopped_by.as_deref(), s.t_reached),
            (false, Some("solver_error"), t)
        );
        assert_on_cosine(&partial);
    }
}
