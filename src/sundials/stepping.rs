//! The stepping loop shared by IDA, CVODE and ARKODE (`solve_to`): single internal steps
//! (`*_ONE_STEP`) until the integrator passes `tout`, then interpolation of the
//! state at `tout` (`IDAGetDky`/`CVodeGetDky`). Between steps the step and
//! wall-clock budgets are checked: the step budget per `solve_to` call, the
//! wall-clock budget against the time spent in all `solve_to`/`step` calls of the
//! solver's life (reinit included), so it bounds a whole multi-output solve.
//! Roots and stop times found beyond `tout` are kept pending and returned by the
//! next call.

use super::error::SolverError;
use super::options::{Step, StepEvent};
use std::time::{Duration, Instant};

/// Step budget per `solve_to` call when none is given: SUNDIALS' own default
/// `mxstep`. Without a budget a step size shrinking toward a singularity would
/// loop forever.
pub const DEFAULT_MAX_STEPS: u64 = 500;

/// Outcome of one internal step.
pub(crate) enum RawEvent {
    Success,
    Root,
    StopTime,
}

/// Minimal integrator interface the loop needs.
pub(crate) trait Stepper {
    /// The stepping loop's bookkeeping of this solver.
    fn stepping(&mut self) -> &mut SteppingState;
    /// Time the integrator has reached internally (`tn`).
    fn current_time(&self) -> f64;
    /// One internal step toward `tout`; the state vectors then hold values at the returned time.
    fn one_step(&mut self, tout: f64) -> Result<(f64, RawEvent), SolverError>;
    /// Root directions after a root return.
    fn root_info(&mut self) -> Vec<i32>;
    /// Load the state vectors with the interpolant at `t` (within the last step).
    fn interpolate(&mut self, t: f64) -> Result<(), SolverError>;
    /// Forget callback errors from a previous call.
    fn clear_status(&mut self);
    /// The state vector as the last internal step left it (`y(t_n)` after a step in
    /// one-step mode).
    fn state(&self) -> &[f64];
}

/// A check of each internal step that lands at or before `tout` (its time `t_n` and state
/// `y(t_n)`): `true` stops the solve there.
pub type StepWatch<'w> = &'w mut dyn FnMut(f64, &[f64]) -> bool;

/// Bookkeeping of the loop: last returned time, pending event, budgets.
#[derive(Debug)]
pub(crate) struct SteppingState {
    pub(crate) t: f64,
    pub(crate) pending: Option<(f64, StepEvent)>,
    pub(crate) max_steps: Option<u64>,
    pub(crate) max_wall_clock: Option<Duration>,
    /// Internal steps allowed over the solver's whole life (all calls, `reinit` included).
    pub(crate) max_total_steps: Option<u64>,
    /// Wall-clock time spent inside `solve_to`/`step` so far (never reset).
    pub(crate) wall_used: Duration,
    /// Internal steps taken by `solve_to`/`step` so far (never reset).
    pub(crate) steps_used: u64,
    /// Consecutive internal steps that did not advance the time (`t + h == t`).
    pub(crate) stalled: u32,
    /// The time and step count where the current window of [`COLLAPSE_WINDOW`] steps began
    /// (`collapsed`).
    pub(crate) window: (f64, u32),
    /// The largest mean step of a window so far (`collapsed`).
    pub(crate) widest: f64,
}

/// Consecutive internal steps that leave the time where it was (`t + h == t` in floating
/// point: the step size is below the resolution of doubles at `t`, e.g. at `t = 1e300`)
/// after which the solve stops with [`SolverError::NoProgress`] instead of stepping forever.
/// Steps shrinking against a non-finite value stall too; the non-finite detection (25
/// evaluations) names the culprit before this count is reached.
pub const MAX_STALLED_STEPS: u32 = 100;

/// Steps over which the pace of a solve is measured (the collapse check of the stepping loop).
pub const COLLAPSE_WINDOW: u32 = 1000;

/// Steps still needed to reach the next output, at the pace of the last [`COLLAPSE_WINDOW`],
/// beyond which a step size that has shrunk by [`COLLAPSE_SHRINK`] has collapsed: 1e9 steps
/// are a quarter of an hour at the fastest (a microsecond each), hours on most models.
pub const COLLAPSED_STEPS_TO_GO: f64 = 1e9;

/// How far the mean step of a window must have fallen below the largest one of the run for a
/// slow pace to be a collapse: a run whose steps are small all along (a long
/// horizon with one output at its end) is slow, not collapsing; a model running away
/// (`exp(1e6*t)` as a torque: its steps halve each time their number doubles) shrinks its steps
/// by orders of magnitude within a fraction of a second.
pub const COLLAPSE_SHRINK: f64 = 1e-3;

/// Measures the pace over windows of [`COLLAPSE_WINDOW`] steps: `Some((h, steps_to_go))` when
/// the mean step `h` of the window just ended is below [`COLLAPSE_SHRINK`] times the largest
/// window mean of the run and, at that pace, reaching `tout` would take more than
/// [`COLLAPSED_STEPS_TO_GO`] steps. (Measured on a pendulum driven by `exp(1e6*t)`: the steps
/// fall from 3e-8 s to 1e-11 s within 1e5 steps, half a second; without this check the run
/// stepped for minutes before IDA gave up with `IDA_TOO_MUCH_ACC`.)
fn collapsed(d: &mut SteppingState, after: f64, tout: f64) -> Option<(f64, f64)> {
    d.window.1 += 1;
    if d.window.1 < COLLAPSE_WINDOW {
        return None;
    }
    let (t0, n) = d.window;
    d.window = (after, 0);
    let h = (after - t0) / f64::from(n);
    d.widest = d.widest.max(h);
    let to_go = (tout - after) / h;
    (h > 0.0 && h < COLLAPSE_SHRINK * d.widest && to_go > COLLAPSED_STEPS_TO_GO)
        .then_some((h, to_go))
}

/// The [`SolverError::StepCollapse`] at `t` (the state `y` there: its largest component is
/// named).
fn collapse_error(t: f64, (h, steps_to_go): (f64, f64), tout: f64, y: &[f64]) -> SolverError {
    let (index, value) = y
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap_or((0, 0.0));
    SolverError::StepCollapse {
        t,
        h,
        tout,
        steps_to_go,
        index,
        value,
    }
}

/// Counts a step from `before` to `after`: `Err(NoProgress)` after [`MAX_STALLED_STEPS`] in a
/// row that did not advance the time.
fn check_progress(d: &mut SteppingState, before: f64, after: f64) -> Result<(), SolverError> {
    if after > before {
        d.stalled = 0;
        return Ok(());
    }
    d.stalled += 1;
    if d.stalled >= MAX_STALLED_STEPS {
        return Err(SolverError::NoProgress {
            t: before,
            steps: d.stalled,
        });
    }
    Ok(())
}

impl SteppingState {
    pub(crate) fn new(
        t0: f64,
        max_steps: Option<u64>,
        max_wall_clock: Option<Duration>,
        max_total_steps: Option<u64>,
    ) -> Self {
        let max_steps = Some(max_steps.unwrap_or(DEFAULT_MAX_STEPS));
        SteppingState {
            t: t0,
            pending: None,
            max_steps,
            max_wall_clock,
            max_total_steps,
            wall_used: Duration::ZERO,
            steps_used: 0,
            stalled: 0,
            window: (t0, 0),
            widest: 0.0,
        }
    }

    pub(crate) fn restart(&mut self, t0: f64) {
        self.t = t0;
        self.pending = None;
        self.window = (t0, 0);
    }
}

fn check_tout(t: f64, tout: f64) -> Result<(), SolverError> {
    if !tout.is_finite() {
        return Err(SolverError::InvalidInput(format!(
            "tout must be finite, got {tout}"
        )));
    }
    if tout < t {
        return Err(SolverError::InvalidInput(format!(
            "tout = {tout} is before the current time {t} (integration is forward only)"
        )));
    }
    Ok(())
}

/// `Err(WallClock)` when the time already used plus the time since `start` exceeds the budget.
fn check_wall_clock(d: &SteppingState, start: Instant, t: f64) -> Result<(), SolverError> {
    match d.max_wall_clock {
        Some(limit) if d.wall_used + start.elapsed() > limit => {
            Err(SolverError::WallClock { t, limit })
        }
        _ => Ok(()),
    }
}

/// `Err(Interrupted)` when an interrupt (SIGINT, SIGTERM) was asked for since the solve began
/// ([`crate::interrupt::requested`]): the solve stops between two steps, as after a budget.
fn check_interrupt(t: f64) -> Result<(), SolverError> {
    match crate::interrupt::requested() {
        Some(signal) => Err(SolverError::Interrupted { t, signal }),
        None => Ok(()),
    }
}

/// `Err(StepBudget)` when the steps of the solver's whole life have used up its budget.
fn check_total_steps(d: &SteppingState, t: f64) -> Result<(), SolverError> {
    match d.max_total_steps {
        Some(max_steps) if d.steps_used >= max_steps => {
            Err(SolverError::StepBudget { t, max_steps })
        }
        _ => Ok(()),
    }
}

/// Advance to `tout` (or an earlier root / stop time), adding the time spent to the
/// solver's wall-clock account.
pub(crate) fn solve_to<S: Stepper>(s: &mut S, tout: f64) -> Result<Step, SolverError> {
    let start = Instant::now();
    let result = solve_to_inner(s, tout, start, None);
    s.stepping().wall_used += start.elapsed();
    result
}

/// [`solve_to`] with a check of every internal step: when `watch` returns `true` the solve
/// returns at that step, `Step { t: t_n, event: Reached }` with the state vectors holding the
/// step's own `y(t_n)` — at once where `t_n < tout`, after the output at `tout` otherwise (a
/// pending stop, its state interpolated at `t_n`), so that which steps the watch sees does
/// not depend on the output times.
pub(crate) fn solve_to_watched<S: Stepper>(
    s: &mut S,
    tout: f64,
    watch: StepWatch<'_>,
) -> Result<Step, SolverError> {
    let start = Instant::now();
    let result = solve_to_inner(s, tout, start, Some(watch));
    s.stepping().wall_used += start.elapsed();
    result
}

fn solve_to_inner<S: Stepper>(
    s: &mut S,
    tout: f64,
    start: Instant,
    mut watch: Option<StepWatch<'_>>,
) -> Result<Step, SolverError> {
    let t_last = s.stepping().t;
    check_tout(t_last, tout)?;
    s.clear_status();
    if tout == t_last && s.stepping().pending.is_none() {
        return Ok(Step {
            t: tout,
            event: StepEvent::Reached,
        });
    }
    let mut steps: u64 = 0;
    loop {
        if let Some((tp, _)) = &s.stepping().pending {
            if *tp <= tout {
                let (tp, event) = s.stepping().pending.take().expect("pending checked above");
                s.interpolate(tp)?;
                s.stepping().t = tp;
                return Ok(Step { t: tp, event });
            }
        }
        let tn = s.current_time();
        if tn >= tout {
            s.interpolate(tout)?;
            s.stepping().t = tout;
            return Ok(Step {
                t: tout,
                event: StepEvent::Reached,
            });
        }
        check_wall_clock(s.stepping(), start, tn)?;
        check_interrupt(tn)?;
        if let Some(max_steps) = s.stepping().max_steps {
            if steps >= max_steps {
                return Err(SolverError::TooMuchWork { t: tn, max_steps });
            }
        }
        check_total_steps(s.stepping(), tn)?;
        let (tret, raw) = s.one_step(tout)?;
        steps += 1;
        s.stepping().steps_used += 1;
        let after = s.current_time();
        check_progress(s.stepping(), tn, after)?;
        if after > tn {
            if let Some(pace) = collapsed(s.stepping(), after, tout) {
                return Err(collapse_error(after, pace, tout, s.state()));
            }
        }
        let event = match raw {
            RawEvent::Success => {
                // every accepted step is watched, the one that passes `tout` too (after the
                // output at `tout`, as a pending stop), so that what the watch sees does not
                // depend on the output times
                if let Some(w) = watch.as_deref_mut() {
                    if w(tret, s.state()) {
                        if tret < tout {
                            s.stepping().t = tret;
                            return Ok(Step {
                                t: tret,
                                event: StepEvent::Reached,
                            });
                        }
                        s.stepping().pending = Some((tret, StepEvent::Reached));
                    }
                }
                continue;
            }
            RawEvent::Root => StepEvent::Root(s.root_info()),
            RawEvent::StopTime => StepEvent::StopTime,
        };
        if tret > tout {
            s.stepping().pending = Some((tret, event));
            continue;
        }
        s.stepping().t = tret;
        return Ok(Step { t: tret, event });
    }
}

/// Take exactly one internal step (or return a pending event), adding the time
/// spent to the solver's wall-clock account.
pub(crate) fn step<S: Stepper>(s: &mut S, tout: f64) -> Result<Step, SolverError> {
    let start = Instant::now();
    let result = step_inner(s, tout, start);
    s.stepping().wall_used += start.elapsed();
    result
}

fn step_inner<S: Stepper>(s: &mut S, tout: f64, start: Instant) -> Result<Step, SolverError> {
    let t_last = s.stepping().t;
    if !tout.is_finite() || tout <= t_last {
        return Err(SolverError::InvalidInput(format!(
            "step: tout = {tout} must be finite and after the current time {t_last}"
        )));
    }
    s.clear_status();
    if let Some((tp, event)) = s.stepping().pending.take() {
        s.interpolate(tp)?;
        s.stepping().t = tp;
        return Ok(Step { t: tp, event });
    }
    let tn = s.current_time();
    check_wall_clock(s.stepping(), start, tn)?;
    check_interrupt(tn)?;
    check_total_steps(s.stepping(), tn)?;
    let (tret, raw) = s.one_step(tout)?;
    s.stepping().steps_used += 1;
    let after = s.current_time();
    check_progress(s.stepping(), tn, after)?;
    if after > tn {
        if let Some(pace) = collapsed(s.stepping(), after, tout) {
            return Err(collapse_error(after, pace, tout, s.state()));
        }
    }
    let event = match raw {
        RawEvent::Success => StepEvent::Reached,
        RawEvent::Root => StepEvent::Root(s.root_info()),
        RawEvent::StopTime => StepEvent::StopTime,
    };
    s.stepping().t = tret;
    Ok(Step { t: tret, event })
}

/// The budget methods every SUNDIALS wrapper exposes over its [`SteppingState`] (`self.stepping`),
/// written once: the wall-clock and total-step budgets a solve continued on a new solver
/// carries over from the earlier ones.
macro_rules! budget_methods {
    () => {
        /// Wall-clock time spent in `solve_to`/`step` since the solver was built; the
        /// `max_wall_clock` budget is checked against it.
        pub fn wall_clock_used(&self) -> std::time::Duration {
            self.stepping.wall_used
        }

        /// Count `spent` against the wall-clock budget as if it had been spent in this solver
        /// (for a solve that continues on a new solver after an earlier one).
        pub fn charge_wall_clock(&mut self, spent: std::time::Duration) {
            self.stepping.wall_used += spent;
        }

        /// Internal steps taken by `solve_to`/`step` since the solver was built; the
        /// `max_total_steps` budget is checked against it.
        pub fn steps_used(&self) -> u64 {
            self.stepping.steps_used
        }

        /// Count `steps` against the total step budget as if they had been taken by this
        /// solver (for a solve that continues on a new solver after an earlier one).
        pub fn charge_steps(&mut self, steps: u64) {
            self.stepping.steps_used += steps;
        }

        /// Take one internal step toward `tout`.
        pub fn step(&mut self, tout: f64) -> Result<Step, SolverError> {
            stepping::step(self, tout)
        }
    };
}
pub(crate) use budget_methods;
