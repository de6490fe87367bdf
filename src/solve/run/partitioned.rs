//! Running the partitioned formulation ([`crate::dae::partitioned`]): the degrees of freedom
//! `[q_I, v_I]` on CVODE (Adams or BDF) or ARKODE (explicit Runge–Kutta), the partition
//! re-chosen when its dependent block degrades, and singular passages (no well-conditioned
//! partition) handed to the compliant GGL on IDA and taken back after them.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use cpu_time::ThreadTime;

use super::{
    budget_row_ida, emit, event_eval, events_fired, fill_stats, is_budget, joint_conditioning,
    make_ggl_ida, multiplier_atol, restart_state, set_completed, set_energy, set_ida_events,
    stopped, OutputEval, Row, SingularPassage, Solution, Summary,
};
use crate::dae::{
    consistent_state_from, ConsistentState, ConstraintExprs, GglFormulation, MechanicsTapes,
    Partition, PartitionError, PartitionedRhs, PartitionedSystem,
};
use crate::mech::MultibodySystem;
use crate::solve::options::{Integrator, SolveOptions};
use crate::solve::partition::CausalPartition;
use crate::solve::reactions::Multipliers;
use crate::sundials::{
    CallbackError, Cvode, CvodeOptions, Erk, ErkOptions, Multistep, SolverError, SolverStats, Step,
    StepEvent,
};
use crate::Error;

/// Condition estimate of the dependent block `G_v[:, D]` (largest over smallest pivot of its
/// LU) above which the right-hand side asks for a new partition (or [`REPARTITION_GROWTH`] times the
/// estimate at the start of the segment, if larger).
pub const REPARTITION_CONDITION: f64 = 20.0;

/// Growth of the re-choice threshold over the segment's starting estimate (and over the
/// last threshold when a re-choice kept the partition).
pub const REPARTITION_GROWTH: f64 = 3.0;

/// Condition number of the best partition's dependent blocks above which no partition is
/// taken as well conditioned: the compliant GGL carries the mechanism through. Relative to a
/// mechanism whose best partition starts at [`TYPICAL_CONDITION`]; the thresholds scale with
/// the starting condition where it is larger (units: the Andrews squeezer, in metres and
/// radians over millimetre levers, starts at 7e2 and is regular).
pub const SINGULAR_PARTITION: f64 = 60.0;

/// The compliant GGL hands the mechanism back at the first output where the best partition's
/// condition number is below this (scaled like [`SINGULAR_PARTITION`]).
pub const REGULAR_PARTITION: f64 = 30.0;

/// The starting condition number below which [`SINGULAR_PARTITION`] and
/// [`REGULAR_PARTITION`] apply as they are (measured: planar pendulums, four-bars and
/// slider-cranks start between 1 and 5).
pub const TYPICAL_CONDITION: f64 = 5.0;

/// `Integrator::Auto` takes BDF when `ρ̂ · Δt_out` exceeds this, where `ρ̂` is the infinity
/// norm of the reduced ODE's Jacobian at the start (an upper bound of its spectral radius, by
/// difference quotients) and `Δt_out` the mean output interval: an explicit method would then
/// need more than about this many steps per output interval for stability alone.
pub const STIFFNESS_LIMIT: f64 = 500.0;

/// Failed segments from the same output after which the compliant GGL takes the passage.
const MAX_RETRIES: usize = 2;

/// One integrator of the independent states.
enum Integ {
    Cvode(Cvode),
    Erk(Erk),
}

impl Integ {
    fn solve_to(&mut self, t: f64) -> Result<Step, SolverError> {
        match self {
            Integ::Cvode(c) => c.solve_to(t),
            Integ::Erk(e) => e.solve_to(t),
        }
    }
    fn y(&self) -> &[f64] {
        match self {
            Integ::Cvode(c) => c.y(),
            Integ::Erk(e) => e.y(),
        }
    }
    fn last_step_time(&self) -> f64 {
        match self {
            Integ::Cvode(c) => c.last_step_time(),
            Integ::Erk(e) => e.last_step_time(),
        }
    }
    fn dky(&mut self, t: f64, out: &mut [f64]) -> Result<(), SolverError> {
        match self {
            Integ::Cvode(c) => c.dky(t, 0, out),
            Integ::Erk(e) => e.dky(t, 0, out),
        }
    }
    /// Restarts at `(t, y)`; an explicit method starts with its last step size (a restart
    /// at a switching function's zero changes the right-hand side's derivatives, not the
    /// time scale of the motion).
    fn reinit(&mut self, t: f64, y: &[f64], h: f64) -> Result<(), SolverError> {
        match self {
            Integ::Cvode(c) => c.reinit(t, y),
            Integ::Erk(e) => {
                e.reinit(t, y)?;
                e.set_init_step(if h.is_finite() { h.abs() } else { 0.0 })
            }
        }
    }
    fn last_step(&self) -> f64 {
        self.stats().last_step
    }
    fn stats(&self) -> SolverStats {
        match self {
            Integ::Cvode(c) => c.stats(),
            Integ::Erk(e) => e.stats(),
        }
    }
    fn charge(&mut self, wall: std::time::Duration, steps: u64) {
        match self {
            Integ::Cvode(c) => {
                c.charge_wall_clock(wall);
                c.charge_steps(steps);
            }
            Integ::Erk(e) => {
                e.charge_wall_clock(wall);
                e.charge_steps(steps);
            }
        }
    }
}

type RootFn = Box<dyn FnMut(f64, &[f64], &mut [f64]) -> crate::sundials::CallbackResult + Send>;

/// The right-hand side shared by the integrator and the output rows and event functions, which
/// complete their states from its last evaluation (its Newton warm start and tangent
/// predictor are then at most a step away).
type SharedRhs = Arc<Mutex<PartitionedRhs>>;

/// The shared right-hand side (a panic caught in an earlier callback leaves it usable: every
/// evaluation starts from its own inputs).
fn lock(core: &SharedRhs) -> MutexGuard<'_, PartitionedRhs> {
    core.lock().unwrap_or_else(|e| e.into_inner())
}

/// Builds the integrator of one segment.
fn make_integ(
    kind: Integrator,
    core: &SharedRhs,
    flag: &Arc<AtomicBool>,
    t0: f64,
    y0: &[f64],
    opts: &SolveOptions,
    roots: Option<(usize, RootFn, bool)>,
) -> Result<Integ, Error> {
    let c1 = core.clone();
    let f1 = flag.clone();
    let rhs = Box::new(
        move |t: f64, y: &[f64], yd: &mut [f64]| match lock(&c1).rhs(t, y, yd) {
            Ok(()) => Ok(()),
            Err(e @ PartitionError::Repartition { .. }) => {
                f1.store(true, Ordering::Relaxed);
                Err(CallbackError::Fatal(e.to_string()))
            }
            Err(e) => Err(CallbackError::Recoverable(e.to_string())),
        },
    );
    let stop_time = opts.output_times.last().copied();
    let integ = match kind {
        Integrator::Erk => {
            let eo = ErkOptions {
                rtol: opts.rtol,
                atol: opts.atol,
                max_steps: Some(u64::MAX),
                max_total_steps: opts.max_steps,
                max_wall_clock: opts.max_wall_clock,
                stop_time,
            };
            let mut e = Erk::new(t0, y0, rhs, &eo)?;
            if let Some((n, f, events)) = roots {
                e.set_roots(n, f)?;
                if events {
                    // event times to the step's accuracy; the switching functions' zeros are
                    // integrated to again from the last exact point (the cubic interpolant,
                    // which takes no right-hand side beyond the step's own, only places them)
                    e.set_interpolant_degree(crate::sundials::erk::MAX_INTERPOLANT_DEGREE)?;
                }
            }
            Integ::Erk(e)
        }
        _ => {
            let method = if kind == Integrator::Bdf {
                Multistep::Bdf
            } else {
                Multistep::Adams
            };
            let co = CvodeOptions {
                rtol: opts.rtol,
                atol: vec![opts.atol],
                max_steps: Some(u64::MAX),
                max_total_steps: opts.max_steps,
                max_wall_clock: opts.max_wall_clock,
                stop_time,
                ..CvodeOptions::default()
            };
            // Newton (both methods) with CVODE's difference-quotient Jacobian of the reduced
            // ODE: |q_I| + |v_I| right-hand sides per Jacobian, a handful of states.
            let mut c = Cvode::new(method, t0, y0, rhs, None, &co)?;
            if let Some((n, f, _)) = roots {
                c.set_roots(n, f)?;
            }
            Integ::Cvode(c)
        }
    };
    Ok(integ)
}

/// `Integrator::Auto`: BDF when the reduced ODE is stiff at the start (see
/// [`STIFFNESS_LIMIT`]), else explicit Runge–Kutta.
fn stiffness_choice(core: &PartitionedRhs, t0: f64, y0: &[f64], opts: &SolveOptions) -> Integrator {
    let mut c = core.clone();
    let n = y0.len();
    let mut f0 = vec![0.0; n];
    if n == 0 || c.rhs(t0, y0, &mut f0).is_err() {
        return Integrator::Bdf;
    }
    let mut rows = vec![0.0f64; n];
    let mut y = y0.to_vec();
    let mut f = vec![0.0; n];
    for j in 0..n {
        let d = 1e-7 * (1.0 + y0[j].abs());
        y[j] = y0[j] + d;
        if c.rhs(t0, &y, &mut f).is_err() {
            return Integrator::Bdf;
        }
        for i in 0..n {
            rows[i] += ((f[i] - f0[i]) / d).abs();
        }
        y[j] = y0[j];
    }
    let rho = rows.iter().fold(0.0f64, |a, &b| a.max(b));
    let times = &opts.output_times;
    let dt = (times[times.len() - 1] - times[0]) / (times.len() - 1).max(1) as f64;
    if rho * dt > STIFFNESS_LIMIT {
        Integrator::Bdf
    } else {
        Integrator::Erk
    }
}

/// The Newton tolerance on the dependent coordinates: a thousandth of the integrator's
/// tolerance on a coordinate of size `qscale`, and at least 16 ulp of it.
fn newton_tolerance(opts: &SolveOptions, qscale: f64) -> f64 {
    (1e-3 * opts.rtol * qscale)
        .min(1e-2 * opts.atol.max(1e-300))
        .max(16.0 * f64::EPSILON * qscale)
}

/// How much better conditioned the numeric partition must be at the start for the causality's
/// to be set aside there.
const CAUSALITY_KEPT_GAIN: f64 = 10.0;

/// Runs the partitioned formulation (see the module documentation).
#[allow(clippy::too_many_arguments)]
pub(super) fn run_partitioned(
    mut sys: MultibodySystem,
    c: &ConstraintExprs,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    opts: &SolveOptions,
    summary: &mut Summary,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let t0 = opts.output_times[0];
    if !init.redundant_joints.is_empty() {
        // redundant everywhere: no partition exists at any time; the compliant GGL solves it
        // (the caller has named the joints in a warning)
        let eps = super::default_compliance(&sys, opts);
        let ggl = GglFormulation::build(&mut sys, c, eps);
        // the summary names what runs: no formulation silently becomes another
        summary.formulation = "compliant_ggl".into();
        return super::run_ggl(&sys, ggl, tapes, init, eps, eps, opts, summary, observer);
    }
    let psys = Arc::new(PartitionedSystem::new(&mut sys, c));
    let mut x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    let qscale = 1.0 + init.q.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let newton_tol = newton_tolerance(opts, qscale);
    let multipliers = Multipliers::Unknowns(nq + nv);
    let mut out = OutputEval::new(&sys, tapes.clone(), &multipliers);
    // output rows read the multipliers only for the reaction columns
    let with_multipliers = sys.reaction_outputs;
    let events = event_eval(&sys, &tapes, &multipliers);
    // room for every output row up front (no reallocation inside the timed integration)
    let mut sol = Solution {
        columns: out.columns.clone(),
        times: Vec::with_capacity(opts.output_times.len()),
        rows: Vec::with_capacity(opts.output_times.len()),
        summary: Summary::default(),
    };
    summary.solver = "CVODE".into();
    let clock = ThreadTime::now();
    let wall_start = std::time::Instant::now();
    let mut total = SolverStats::default();
    // the completed state of each output row (one buffer for the whole run)
    let mut full: Vec<f64> = Vec::with_capacity(nq + nv + nc);
    let mut first = x.clone();
    first.extend(&init.lambda);
    let row = out.row(t0, &first);
    let finish =
        |summary: &mut Summary, out: &OutputEval, total: &SolverStats, compliant_time: f64| {
            summary.cpu_seconds = clock.elapsed().as_secs_f64();
            fill_stats(summary, total);
            summary.max_constraint_error = out.max_g;
            summary.compliant_time = compliant_time;
            summary.compliance_used = compliant_time > 0.0 || !summary.singular_passages.is_empty();
            set_energy(summary, out.energy_drift(), out.energy_exchange.as_deref());
        };
    if emit(&mut sol, observer, t0, row, opts.keep_rows) {
        finish(summary, &out, &total, 0.0);
        set_completed(summary, &sol);
        sol.summary = summary.clone();
        return Ok(sol);
    }
    let n_out = opts.output_times.len();
    let mut k_next = 1;
    let mut t_start = t0;
    let mut kind = opts.integrator;
    let mut rechoices = 0u64;
    let mut compliant_time = 0.0;
    let mut ggl: Option<Arc<GglFormulation>> = None;
    let mut last_part: Option<Partition> = None;
    // the threshold of the partition kept after a re-choice found nothing better
    let mut keep_threshold = REPARTITION_CONDITION;
    let mut stalls = 0;
    // the chapter's partition at the start: the differential-causality inertias' flows as the
    // dependent velocities (kept unless its block is ill-conditioned there and the numeric
    // choice is much better conditioned)
    let causal = CausalPartition::new(&sys, t0);
    // the numeric choice at (t, x) takes the inertias the causality puts in differential
    // causality there first
    let choose = |t: f64, x: &[f64]| psys.choose(t, x, &causal.preferred_at(t, &x[..nq]));
    // the thresholds' scale: the best partition's condition at the start
    let scale = choose(t0, &x).map_or(1.0, |p| {
        (psys.condition(&p, t0, &x) / TYPICAL_CONDITION).max(1.0)
    });
    let mut from_causality = causal
        .dependent()
        .and_then(|d| psys.with_dependent_velocities(t0, &x, d))
        .filter(|p| {
            let k = psys.condition(p, t0, &x);
            k <= REPARTITION_CONDITION
                || choose(t0, &x)
                    .is_none_or(|b| psys.condition(&b, t0, &x) * CAUSALITY_KEPT_GAIN >= k)
        });
    if from_causality.is_none() && nc > 0 && !sys.inertias.is_empty() {
        summary.warnings.push(format!(
            "partitioned: the causality's dependent inertias are not a regular block of the joint rows at t = {t0}; chosen numerically"
        ));
    }
    'segment: while k_next < n_out {
        let choice = from_causality
            .take()
            .or_else(|| choose(t_start, &x))
            .map(|p| {
                let k = psys.condition(&p, t_start, &x);
                (p, k)
            })
            .filter(|(_, k)| *k <= SINGULAR_PARTITION * scale && stalls < MAX_RETRIES);
        let Some((part, _)) = choice else {
            // no well-conditioned partition: the compliant GGL carries the passage
            let eps = super::default_compliance(&sys, opts);
            let ggl = match &ggl {
                Some(g) => g.clone(),
                None => {
                    let g = Arc::new(GglFormulation::build(&mut sys, c, eps));
                    ggl = Some(g.clone());
                    g
                }
            };
            let gv = tapes.gv.matrix(t_start, &x);
            let cond = joint_conditioning(&gv, &sys.mass, &sys.rows);
            summary.warnings.push(format!(
                "partitioned: no well-conditioned partition at t = {t_start:.6} (joints [{}], κ = {:.1e}); the compliant GGL (ε = {eps:.1e}) carries the passage",
                cond.joints.join(", "),
                cond.condition
            ));
            summary.singular_passages.push(SingularPassage {
                t: t_start,
                joints: cond.joints,
                condition: cond.condition,
                restarted_at: t_start,
                plain_again_at: None,
                failure: "no well-conditioned partition".into(),
            });
            let (y, yp) = restart_state(&sys, &tapes, eps, t_start, &x)?;
            let mut atol = vec![opts.atol; nq + nv];
            atol.extend(std::iter::repeat_n(multiplier_atol(opts), 2 * nc));
            let mut solver = make_ggl_ida(&ggl, atol, eps, t_start, &y, &yp, opts)?;
            set_ida_events(&mut solver.ida, &events)?;
            solver.ida.charge_wall_clock(wall_start.elapsed());
            solver.ida.charge_steps(total.steps);
            let t_in = t_start;
            let mut t_back = None;
            while k_next < n_out {
                let step = match solver.ida.solve_to(opts.output_times[k_next]) {
                    Ok(s) => s,
                    Err(e) => {
                        total.accumulate(&solver.ida.stats());
                        let last = budget_row_ida(&e, &mut solver.ida, &mut out);
                        finish(summary, &out, &total, compliant_time);
                        summary.partition_rechoices = rechoices;
                        return Err(stopped(e, sol, summary.clone(), last));
                    }
                };
                if let StepEvent::Root(info) = &step.event {
                    let Some(stop) = events_fired(&sys.events, info, step.t, summary) else {
                        continue;
                    };
                    let row = out.row(step.t, solver.ida.y());
                    if emit(&mut sol, observer, step.t, row, opts.keep_rows) || stop {
                        total.accumulate(&solver.ida.stats());
                        compliant_time += step.t - t_in;
                        break 'segment;
                    }
                    continue;
                }
                k_next += 1;
                let row = out.row(step.t, solver.ida.y());
                if emit(&mut sol, observer, step.t, row, opts.keep_rows) {
                    total.accumulate(&solver.ida.stats());
                    compliant_time += step.t - t_in;
                    break 'segment;
                }
                let xr = solver.ida.y()[..nq + nv].to_vec();
                let back = choose(step.t, &xr)
                    .is_some_and(|p| psys.condition(&p, step.t, &xr) < REGULAR_PARTITION * scale);
                if back && k_next < n_out {
                    let st = consistent_state_from(&sys, &tapes, step.t, &xr)?;
                    x = st.q.iter().chain(&st.v).copied().collect();
                    t_start = step.t;
                    if let Some(p) = summary.singular_passages.last_mut() {
                        p.plain_again_at = Some(step.t);
                    }
                    t_back = Some(step.t);
                    break;
                }
            }
            total.accumulate(&solver.ida.stats());
            compliant_time += t_back.unwrap_or(opts.output_times[n_out - 1]) - t_in;
            stalls = 0;
            last_part = None;
            continue 'segment;
        };
        if last_part.is_none() && rechoices == 0 && summary.dependent.is_empty() {
            (summary.states, summary.dependent) = causal.names(&part.dep_v);
        }
        if let Some(lp) = &last_part {
            if *lp != part {
                rechoices += 1;
                summary.warnings.push(format!(
                    "partitioned: partition re-chosen at t = {t_start:.6}"
                ));
            }
        }
        let threshold = if last_part.as_ref() == Some(&part) {
            keep_threshold
        } else {
            REPARTITION_CONDITION
        };
        let mut core = PartitionedRhs::new(psys.clone(), part.clone(), &x, newton_tol);
        let y0 = part.states_of(nq, &x);
        core.complete(t_start, &y0).map_err(|e| {
            Error::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: e.to_string(),
            })
        })?;
        core.repartition_above = threshold.max(REPARTITION_GROWTH * core.condition_estimate());
        keep_threshold = REPARTITION_GROWTH * core.repartition_above;
        last_part = Some(part.clone());
        if kind == Integrator::Auto {
            kind = stiffness_choice(&core, t_start, &y0, opts);
        }
        summary.integrator = kind.name().into();
        summary.solver = if kind == Integrator::Erk {
            "ARKODE".into()
        } else {
            "CVODE".into()
        };
        summary.unknowns = y0.len();
        let flag = Arc::new(AtomicBool::new(false));
        let oc: SharedRhs = Arc::new(Mutex::new(core));
        let n_ev = events.len();
        let n_sw = if opts.switching_functions {
            psys.n_switches()
        } else {
            0
        };
        let mut switches = Switches::new(n_sw);
        if n_sw > 0 {
            let mut rhs = lock(&oc);
            switches.start(&mut rhs);
        }
        // roots are muted while a segment is integrated again up to a switching function's zero
        let mute = Arc::new(AtomicBool::new(false));
        let roots = (n_ev + n_sw > 0).then(|| {
            let mut ev = events.clone();
            let rc = oc.clone();
            let muted = mute.clone();
            let f: RootFn = Box::new(move |t: f64, y: &[f64], g: &mut [f64]| {
                if muted.load(Ordering::Relaxed) {
                    g.fill(1.0);
                    return Ok(());
                }
                let mut rhs = lock(&rc);
                let recoverable = |e: PartitionError| CallbackError::Recoverable(e.to_string());
                let (ge, gs) = g.split_at_mut(n_ev);
                if n_ev > 0 {
                    // the multipliers (a right-hand side on the full block and a transposed
                    // solve, at every step) only for events that read reaction columns
                    if ev.uses_reactions() {
                        let full = rhs.full_for_output(t, y).map_err(recoverable)?;
                        ev.roots(t, full, ge)?;
                    } else {
                        rhs.complete_for_output(t, y).map_err(recoverable)?;
                        ev.roots(t, rhs.full_state(), ge)?;
                    }
                }
                if n_sw > 0 {
                    rhs.switching_at(t, y, gs).map_err(recoverable)?;
                    // a released switch (evaluated literally) reports no zero
                    for (v, &m) in gs.iter_mut().zip(rhs.modes()) {
                        if m == 0.0 {
                            *v = 1.0;
                        }
                    }
                }
                Ok(())
            });
            (n_ev + n_sw, f, n_ev > 0)
        });
        let mut integ = make_integ(kind, &oc, &flag, t_start, &y0, opts, roots)?;
        integ.charge(wall_start.elapsed(), total.steps);
        // the last point where the integrator was started or stopped exactly (an output, a
        // switch): a zero of a switching function is integrated to again from there
        let mut good = (t_start, y0.clone());
        while k_next < n_out {
            let step = match integ.solve_to(opts.output_times[k_next]) {
                Ok(s) => s,
                Err(e) => {
                    if !is_budget(&e) && nc > 0 {
                        // a partition failure (the block degraded, or Newton or the steps
                        // failed near a singular configuration): choose again from the last
                        // output, where the state is known good (the steps accepted just
                        // before the failure may already be degraded), and after two
                        // failures from the same output hand the passage to the GGL
                        total.accumulate(&integ.stats());
                        if flag.load(Ordering::Relaxed) {
                            summary.warnings.push(format!(
                                "partitioned: dependent block degraded at t = {:.6} ({e})",
                                integ.last_step_time()
                            ));
                        }
                        stalls += 1;
                        continue 'segment;
                    }
                    total.accumulate(&integ.stats());
                    let last = e.time().filter(|_| is_budget(&e)).and_then(|tr| {
                        let mut y = vec![0.0; y0.len()];
                        integ.dky(tr, &mut y).ok()?;
                        let mut rhs = lock(&oc);
                        let full = rhs.full_for_output(tr, &y).ok()?;
                        Some((tr, out.row(tr, full)))
                    });
                    finish(summary, &out, &total, compliant_time);
                    summary.partition_rechoices = rechoices;
                    return Err(stopped(e, sol, summary.clone(), last));
                }
            };
            // the multipliers (a full right-hand side and a transposed solve) only where the
            // rows show them (reaction columns); otherwise positions and velocities suffice
            let completed = {
                let mut oc = lock(&oc);
                let state = if with_multipliers {
                    oc.full_for_output(step.t, integ.y())
                } else {
                    oc.complete_for_output(step.t, integ.y())
                        .map(|()| oc.full_state())
                };
                state.map(|s| {
                    full.clear();
                    full.extend_from_slice(s);
                })
            };
            completed.map_err(|e| {
                Error::Solver(SolverError::InvalidInput(format!(
                    "partitioned: completing the output row: {e}"
                )))
            })?;
            if let StepEvent::Root(info) = &step.event {
                let (user, sw) = info.split_at(n_ev);
                let fired = events_fired(&sys.events, user, step.t, summary);
                if let Some(stop) = fired {
                    let row = out.row(step.t, &full);
                    if emit(&mut sol, observer, step.t, row, opts.keep_rows) || stop {
                        total.accumulate(&integ.stats());
                        break 'segment;
                    }
                }
                if Switches::would_change(&lock(&oc), sw) {
                    // the state at the zero from the integrator's own steps, not from its
                    // interpolant over a step that crossed the zero: integrate again from
                    // the last exact point to the zero with the old modes, then restart with
                    // the new ones (the counters restart with the integrator)
                    let h = integ.last_step();
                    total.accumulate(&integ.stats());
                    integ.reinit(good.0, &good.1, h)?;
                    mute.store(true, Ordering::Relaxed);
                    let reached = loop {
                        match integ.solve_to(step.t) {
                            Ok(s) if s.t >= step.t => break Ok(()),
                            Ok(_) => continue,
                            Err(e) => break Err(e),
                        }
                    };
                    mute.store(false, Ordering::Relaxed);
                    reached?;
                    total.accumulate(&integ.stats());
                    {
                        let mut rhs = lock(&oc);
                        switches.crossed(&mut rhs, sw, step.t, summary);
                    }
                    good = (step.t, integ.y().to_vec());
                    integ.reinit(good.0, &good.1, h)?;
                }
                continue;
            }
            if n_sw > 0 {
                // a zero the root finder could not see (a switching function starting at
                // zero, or two zeros within one step): the modes are checked at every output
                let changed = {
                    let mut rhs = lock(&oc);
                    switches.check(&mut rhs, step.t, summary)
                };
                if changed {
                    let h = integ.last_step();
                    total.accumulate(&integ.stats());
                    let y = integ.y().to_vec();
                    integ.reinit(step.t, &y, h)?;
                }
            }
            good.0 = step.t;
            good.1.copy_from_slice(integ.y());
            k_next += 1;
            stalls = 0;
            // (t_start, x): the last point reached on the mechanism, where a failure restarts
            x.copy_from_slice(&full[..nq + nv]);
            t_start = step.t;
            let row = out.row(step.t, &full);
            if emit(&mut sol, observer, step.t, row, opts.keep_rows) {
                total.accumulate(&integ.stats());
                break 'segment;
            }
        }
        total.accumulate(&integ.stats());
        break;
    }
    finish(summary, &out, &total, compliant_time);
    summary.partition_rechoices = rechoices;
    set_completed(summary, &sol);
    sol.summary = summary.clone();
    Ok(sol)
}

/// Crossings of one switching function between two outputs after which it is released to
/// the literal operation (a sliding mode, e.g. Coulomb friction at rest: each mode pushes the
/// state back across the zero).
pub const MAX_SWITCHINGS_PER_OUTPUT: u32 = 50;

/// The modes of the loads' switching functions over a segment (`expr::switches`): set from the
/// functions' signs at its start, flipped at their zeros (the root finder's direction), checked
/// at every output, and released when they chatter.
struct Switches {
    /// The switching functions' values (scratch).
    values: Vec<f64>,
    /// Crossings of each function since the last output.
    recent: Vec<u32>,
    /// Time of each function's last zero (an output there keeps the mode the zero set, whatever
    /// the sign of the function's rounding-level value).
    zero_at: Vec<f64>,
}

/// The mode a zero crossing in direction `d` (+1 rising, −1 falling) leaves its function in.
fn mode_after(d: i32) -> f64 {
    if d > 0 {
        1.0
    } else {
        -1.0
    }
}

impl Switches {
    fn new(n: usize) -> Self {
        Switches {
            values: vec![0.0; n],
            recent: vec![0; n],
            zero_at: vec![f64::NAN; n],
        }
    }

    /// Modes (held by `rhs`) from the signs of the switching functions at the completed start
    /// state, evaluated with the literal operations, which the modes then reproduce.
    fn start(&mut self, rhs: &mut PartitionedRhs) {
        for k in 0..self.values.len() {
            rhs.set_mode(k, 0.0);
        }
        rhs.switching_values(&mut self.values);
        for (k, &v) in self.values.iter().enumerate() {
            rhs.set_mode(k, if v > 0.0 { 1.0 } else { -1.0 });
        }
    }

    /// Whether zeros found by the root finder (`dirs`) change a mode (a released one, 0, stays).
    fn would_change(rhs: &PartitionedRhs, dirs: &[i32]) -> bool {
        dirs.iter()
            .zip(rhs.modes())
            .any(|(&d, &m)| d != 0 && m != 0.0 && m != mode_after(d))
    }

    /// Zeros found by the root finder (`dirs`: +1 rising, −1 falling, 0 none) set the modes.
    fn crossed(&mut self, rhs: &mut PartitionedRhs, dirs: &[i32], t: f64, summary: &mut Summary) {
        for (k, &d) in dirs.iter().enumerate() {
            if d == 0 || rhs.modes()[k] == 0.0 {
                continue;
            }
            self.zero_at[k] = t;
            if rhs.modes()[k] != mode_after(d) {
                self.flip(rhs, k, mode_after(d), t, summary);
            }
        }
    }

    /// At an output (the completed state in `rhs`): modes whose function has the other sign
    /// are set to it; the chattering counters restart. Whether a mode changed.
    fn check(&mut self, rhs: &mut PartitionedRhs, t: f64, summary: &mut Summary) -> bool {
        rhs.switching_values(&mut self.values);
        let mut changed = false;
        for k in 0..self.values.len() {
            let (m, v) = (rhs.modes()[k], self.values[k]);
            if m != 0.0 && v != 0.0 && (v > 0.0) != (m > 0.0) && self.zero_at[k] != t {
                self.flip(rhs, k, -m, t, summary);
                changed = true;
            }
        }
        self.recent.fill(0);
        changed
    }

    /// Sets mode `k` to `m`, or releases it (0: the literal operation) past
    /// [`MAX_SWITCHINGS_PER_OUTPUT`] changes since the last output.
    fn flip(&mut self, rhs: &mut PartitionedRhs, k: usize, m: f64, t: f64, summary: &mut Summary) {
        summary.switchings += 1;
        self.recent[k] += 1;
        if self.recent[k] > MAX_SWITCHINGS_PER_OUTPUT {
            rhs.set_mode(k, 0.0);
            summary.warnings.push(format!(
                "partitioned: switching function {k} of the loads changed sign more than {MAX_SWITCHINGS_PER_OUTPUT} times before t = {t:.6}; its operation is evaluated as written from there (the integrator steps across its zeros)"
            ));
        } else {
            rhs.set_mode(k, m);
        }
    }
}
