//! The partitioned formulation ([`crate::solve::formulation::partitioned`]): the chapter's degrees of freedom
//! as states, the ODE `[q_I, v_I]' = f(t, q_I, v_I)` whose right-hand side recovers the
//! dependent coordinates by Newton on `g(q_I, q_D) = 0` and the dependent velocities from
//! `G_v v = 0`, on CVODE (Adams or BDF) or ARKODE (explicit Runge–Kutta). Recoveries: the
//! partition is re-chosen when its dependent block degrades (a restart from the last output),
//! and singular passages (no well-conditioned partition) are handed to the compliant GGL on IDA
//! and taken back after them. The loads' switching functions (`max`, `min`, `abs`, `sign`,
//! `select`) are root functions: at a zero the segment is integrated again to it with the old
//! modes and restarted with the new ones.

use crate::solve::formulation::shared::joints_in_words;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use crate::dae::{consistent_state_from, ConstraintExprs, MechanicsTapes};
use crate::mech::MultibodySystem;
use crate::partition::causal::CausalPartition;
use crate::partition::thresholds::{
    MAX_RETRIES, MAX_SWITCHINGS_PER_OUTPUT, REPARTITION_CONDITION, REPARTITION_GROWTH,
    STIFFNESS_LIMIT, TYPICAL_CONDITION,
};
use crate::partition::PartitionPolicy;
use crate::partition::{joint_conditioning, Partition, PartitionError};
use crate::settings::Integrator;
use crate::solve::formulation::shared::JobStart;
use crate::solve::formulation::{
    Ending, Formulation, ImplicitProblem, Next, Problem, ReducedProblem, Start,
};
use crate::solve::formulation::{Events, Job};
use crate::solve::formulation::{GglDae, GglFormulation, PartitionedRhs, PartitionedSystem};
use crate::solve::options::SolveOptions;
use crate::solve::reactions::Multipliers;
use crate::solve::rows::OutputEval;
use crate::solve::solution::{SingularPassage, Summary};
use crate::solve::solver::Solver;
use crate::solve::SolveError;
use crate::sundials::{CallbackError, CvodeRootFn, SolverError};

/// The right-hand side shared by the integrator and the output rows and event functions, which
/// complete their states from its last evaluation (its Newton warm start and tangent
/// predictor are then at most a step away).
type SharedRhs = Arc<Mutex<PartitionedRhs>>;

/// The shared right-hand side (a panic caught in an earlier callback leaves it usable: every
/// evaluation starts from its own inputs).
fn lock(core: &SharedRhs) -> MutexGuard<'_, PartitionedRhs> {
    core.lock().unwrap_or_else(|e| e.into_inner())
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

/// What the running segment integrates.
enum Mode {
    /// The degrees of freedom of a partition, on CVODE or ARKODE.
    Partition {
        /// The right-hand side shared with the root functions and the rows.
        rhs: SharedRhs,
        /// Set by the right-hand side when its dependent block asks for a new partition.
        degraded: Arc<AtomicBool>,
        /// Roots muted while a segment is integrated again up to a switching function's zero.
        mute: Arc<AtomicBool>,
        switches: Switches,
        /// The last point where the integrator was started or stopped exactly (an output, a
        /// switch): a zero of a switching function is integrated to again from there.
        good: (f64, Vec<f64>),
    },
    /// A singular passage on the compliant GGL, entered at `t_in`.
    Passage { t_in: f64 },
    /// Before the first segment and after the end.
    Idle,
}

/// The partitioned formulation (see the module documentation).
struct Partitioned<'a> {
    sys: MultibodySystem,
    c: &'a ConstraintExprs,
    tapes: MechanicsTapes,
    psys: Arc<PartitionedSystem>,
    causal: CausalPartition,
    opts: SolveOptions,
    events: Option<Events>,
    mode: Mode,
    /// `[q, v]` of the last output, where a segment starts.
    x: Vec<f64>,
    /// Time of the last output.
    t_start: f64,
    newton_tol: f64,
    with_multipliers: bool,
    /// The thresholds' scale: the best partition's condition at the start.
    scale: f64,
    kind: Integrator,
    rechoices: u64,
    compliant_time: f64,
    ggl: Option<Arc<GglFormulation>>,
    last_part: Option<Partition>,
    /// The threshold of the partition kept after a re-choice found nothing better.
    keep_threshold: f64,
    stalls: usize,
    from_causality: Option<Partition>,
    first: Vec<f64>,
}

impl<'a> Partitioned<'a> {
    /// The numeric choice at `(t, x)`: the inertias the causality puts in differential
    /// causality there first.
    fn choose(&self, t: f64, x: &[f64]) -> Option<Partition> {
        let nq = self.tapes.dims.0;
        self.psys
            .choose(t, x, &self.causal.preferred_at(t, &x[..nq]))
    }

    /// Redundant joints whose kept rows lose their grip (the self-stress turns with the
    /// mechanism): another independent set of rows at the last output, when one exists and
    /// differs (the system is compiled again on it, as the index-1 DAE re-selects its rows).
    fn fresh_rows(&mut self, summary: &mut Summary) -> Option<()> {
        let (kept, full) = self.psys.kept_rows()?.clone();
        let t = self.t_start;
        let gv = self.tapes.gv.matrix(t, &self.x);
        let redundant = full - kept.len();
        let fresh =
            crate::partition::independent_rows(&gv, redundant, &[]).filter(|f| *f != kept)?;
        summary.warnings.push(format!(
            "partitioned: independent joint rows re-selected at t = {t:.6} (left out: {})",
            (0..full)
                .filter(|k| !fresh.contains(k))
                .map(|k| format!("{}.{}", self.sys.rows[k].joint, self.sys.rows[k].direction))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        self.psys = Arc::new(PartitionedSystem::on_rows(&mut self.sys, self.c, fresh));
        self.last_part = None;
        self.stalls = 0;
        Some(())
    }

    /// A singular passage from `t_start`: the compliant GGL carries it.
    fn passage(&mut self, summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        let (nq, nv, nc) = self.tapes.dims;
        let t_start = self.t_start;
        let eps = crate::solve::formulation::shared::default_compliance(&self.sys, &self.opts);
        let ggl = match &self.ggl {
            Some(g) => g.clone(),
            None => {
                let g = Arc::new(GglFormulation::build(&mut self.sys, self.c, eps));
                self.ggl = Some(g.clone());
                g
            }
        };
        let gv = self.tapes.gv.matrix(t_start, &self.x);
        let cond = joint_conditioning(&gv, &self.sys.mass, &self.sys.rows);
        summary.warnings.push(format!(
            "partitioned: no well-conditioned partition at t = {t_start:.6} (joints [{}], κ = {:.1e}); the compliant GGL (ε = {eps:.1e}) carries the passage",
            joints_in_words(&cond.joints),
            cond.condition
        ));
        let failure = "no well-conditioned partition".to_string();
        (summary.singular_passages).push(SingularPassage::begun(t_start, cond, t_start, failure));
        let (y0, yp0) = crate::solve::formulation::ggl::runner::restart_state(
            &self.sys,
            &self.tapes,
            eps,
            t_start,
            &self.x,
        )?;
        let mut atol = vec![self.opts.atol; nq + nv];
        atol.extend(std::iter::repeat_n(
            crate::solve::formulation::shared::multiplier_atol(&self.opts),
            2 * nc,
        ));
        self.mode = Mode::Passage { t_in: t_start };
        self.stalls = 0;
        self.last_part = None;
        let dae = Arc::new(GglDae::shared(ggl, eps));
        dae.set_restoring(true);
        Ok(Start::Run(Problem::Implicit(ImplicitProblem {
            dae,
            atol,
            y0,
            yp0,
            schur: None,
            weights: None,
        })))
    }
}

impl<'a> Formulation<'a> for Partitioned<'a> {
    fn first_row_state(&self) -> Vec<f64> {
        self.first.clone()
    }

    fn segment(&mut self, _t: f64, summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        let nq = self.tapes.dims.0;
        let t_start = self.t_start;
        let choice = self
            .from_causality
            .take()
            .or_else(|| self.choose(t_start, &self.x))
            .map(|p| {
                let k = self.psys.condition(&p, t_start, &self.x);
                (p, k)
            })
            .filter(|(_, k)| {
                PartitionPolicy::partition_usable(*k, self.scale) && self.stalls < MAX_RETRIES
            });
        let choice = match choice {
            None => self.fresh_rows(summary).and_then(|()| {
                self.choose(t_start, &self.x).and_then(|p| {
                    let k = self.psys.condition(&p, t_start, &self.x);
                    PartitionPolicy::partition_usable(k, self.scale).then_some((p, k))
                })
            }),
            some => some,
        };
        let Some((part, _)) = choice else {
            return self.passage(summary);
        };
        if self.last_part.is_none() && self.rechoices == 0 && summary.dependent.is_empty() {
            (summary.states, summary.dependent) = self.causal.names(&part.dep_v);
        }
        if let Some(lp) = &self.last_part {
            if *lp != part {
                self.rechoices += 1;
                summary.routine_warning(
                    "partitioned: partition re-chosen",
                    format!("partitioned: partition re-chosen at t = {t_start:.6}"),
                );
            }
        }
        let threshold = if self.last_part.as_ref() == Some(&part) {
            self.keep_threshold
        } else {
            REPARTITION_CONDITION
        };
        let mut core =
            PartitionedRhs::new(self.psys.clone(), part.clone(), &self.x, self.newton_tol);
        let y0 = part.states_of(nq, &self.x);
        core.complete(t_start, &y0).map_err(|e| {
            SolveError::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: e.to_string(),
            })
        })?;
        core.repartition_above = threshold.max(REPARTITION_GROWTH * core.condition_estimate());
        self.keep_threshold = REPARTITION_GROWTH * core.repartition_above;
        self.last_part = Some(part);
        if self.kind == Integrator::Auto {
            self.kind = stiffness_choice(&core, t_start, &y0, &self.opts);
        }
        summary.integrator = self.kind.name().into();
        summary.solver = if self.kind == Integrator::Erk {
            "ARKODE".into()
        } else {
            "CVODE".into()
        };
        if y0.is_empty() {
            // DOF 0: nothing to integrate; each row is the dependent block's Newton solve
            // (solve::kinematic steps to the output times)
            summary.integrator = "none".into();
            summary.solver = "none (kinematic analysis)".into();
        }
        summary.unknowns = y0.len();
        let degraded = Arc::new(AtomicBool::new(false));
        let oc: SharedRhs = Arc::new(Mutex::new(core));
        let n_ev = self.events.as_ref().map_or(0, |e| e.eval.len());
        let n_sw = if self.opts.switching_functions {
            self.psys.n_switches()
        } else {
            0
        };
        let mut switches = Switches::new(n_sw);
        if n_sw > 0 {
            let mut rhs = lock(&oc);
            switches.start(&mut rhs);
        }
        let mute = Arc::new(AtomicBool::new(false));
        let roots = (n_ev + n_sw > 0).then(|| {
            let mut ev = self.events.as_ref().map(|e| e.eval.clone());
            let rc = oc.clone();
            let muted = mute.clone();
            let f: CvodeRootFn = Box::new(move |t: f64, y: &[f64], g: &mut [f64]| {
                if muted.load(Ordering::Relaxed) {
                    g.fill(1.0);
                    return Ok(());
                }
                let mut rhs = lock(&rc);
                let recoverable = |e: PartitionError| CallbackError::Recoverable(e.to_string());
                let (ge, gs) = g.split_at_mut(n_ev);
                if let Some(ev) = &mut ev {
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
        let (c1, f1) = (oc.clone(), degraded.clone());
        let rhs =
            Box::new(
                move |t: f64, y: &[f64], yd: &mut [f64]| match lock(&c1).rhs(t, y, yd) {
                    Ok(()) => Ok(()),
                    Err(e @ PartitionError::Repartition { .. }) => {
                        f1.store(true, Ordering::Relaxed);
                        Err(CallbackError::Fatal(e.to_string()))
                    }
                    Err(e) => Err(CallbackError::Recoverable(e.to_string())),
                },
            );
        self.mode = Mode::Partition {
            rhs: oc,
            degraded,
            mute,
            switches,
            good: (t_start, y0.clone()),
        };
        Ok(Start::Run(Problem::Reduced(ReducedProblem {
            integrator: self.kind,
            rhs,
            y0,
            roots,
            init_step: None,
        })))
    }

    fn row_state(&mut self, t: f64, y: &[f64], x: &mut Vec<f64>) -> Result<(), SolveError> {
        let Mode::Partition { rhs, .. } = &self.mode else {
            x.clear();
            x.extend_from_slice(y);
            return Ok(());
        };
        // the multipliers (a full right-hand side and a transposed solve) only where the rows
        // show them (reaction columns); otherwise positions and velocities suffice
        let mut oc = lock(rhs);
        let state = if self.with_multipliers {
            oc.full_for_output(t, y)
        } else {
            oc.complete_for_output(t, y).map(|()| oc.full_state())
        };
        match state {
            Ok(s) => {
                x.clear();
                x.extend_from_slice(s);
                Ok(())
            }
            // not the input's fault: the solve stops at t with its rows so far
            Err(e) => Err(SolveError::Solver(SolverError::Stalled {
                t,
                cause: format!("partitioned: completing the output row: {e}"),
            })),
        }
    }

    fn recover(
        &mut self,
        e: &SolverError,
        solver: &mut Solver,
        _last: (f64, &[f64]),
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let Mode::Partition { degraded, .. } = &self.mode else {
            return Ok(Next::Fail);
        };
        if self.tapes.dims.2 == 0 {
            return Ok(Next::Fail);
        }
        // a partition failure (the block degraded, or Newton or the steps failed near a
        // singular configuration): choose again from the last output, where the state is
        // known good (the steps accepted just before the failure may already be degraded),
        // and after two failures from the same output hand the passage to the GGL
        if degraded.load(Ordering::Relaxed) {
            summary.warnings.push(format!(
                "partitioned: dependent block degraded at t = {:.6} ({e})",
                solver.last_step_time()
            ));
        }
        self.stalls += 1;
        Ok(Next::Restart(self.t_start))
    }

    fn at_switch(
        &mut self,
        t: f64,
        sw: &[i32],
        solver: &mut Solver,
        summary: &mut Summary,
    ) -> Result<(), SolveError> {
        let Mode::Partition {
            rhs,
            mute,
            switches,
            good,
            ..
        } = &mut self.mode
        else {
            return Ok(());
        };
        if !Switches::would_change(&lock(rhs), sw) {
            return Ok(());
        }
        // the state at the zero from the integrator's own steps, not from its interpolant
        // over a step that crossed the zero: integrate again from the last exact point to the
        // zero with the old modes, then restart with the new ones (the counters restart with
        // the integrator)
        let h = solver.last_step();
        solver.reinit_ode(good.0, &good.1, h)?;
        mute.store(true, Ordering::Relaxed);
        let reached = solver.advance_to(t);
        mute.store(false, Ordering::Relaxed);
        reached?;
        switches.crossed(&mut lock(rhs), sw, t, summary);
        *good = (t, solver.y().to_vec());
        solver.reinit_ode(good.0, &good.1, h)?;
        Ok(())
    }

    fn at_output(
        &mut self,
        t: f64,
        full: &[f64],
        solver: &mut Solver,
        more: bool,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let (nq, nv, _) = self.tapes.dims;
        match &mut self.mode {
            Mode::Partition {
                rhs,
                switches,
                good,
                ..
            } => {
                if !switches.values.is_empty() {
                    // a zero the root finder could not see (a switching function starting
                    // at zero, or two zeros within one step): the modes are checked at every
                    // output
                    let changed = switches.check(&mut lock(rhs), t, summary);
                    if changed {
                        let h = solver.last_step();
                        let y = solver.y().to_vec();
                        solver.reinit_ode(t, &y, h)?;
                    }
                }
                good.0 = t;
                good.1.copy_from_slice(solver.y());
                self.stalls = 0;
                // (t_start, x): the last point reached on the mechanism, where a failure
                // restarts
                self.x.copy_from_slice(&full[..nq + nv]);
                self.t_start = t;
                Ok(Next::Continue)
            }
            Mode::Idle => Ok(Next::Continue),
            Mode::Passage { t_in } => {
                let t_in = *t_in;
                let xr = &full[..nq + nv];
                let back = self.choose(t, xr).is_some_and(|p| {
                    PartitionPolicy::partition_regular(self.psys.condition(&p, t, xr), self.scale)
                });
                if !(back && more) {
                    return Ok(Next::Continue);
                }
                let st = consistent_state_from(&self.sys, &self.tapes, t, xr)?;
                self.x = st.q.iter().chain(&st.v).copied().collect();
                self.t_start = t;
                if let Some(p) = summary.singular_passages.last_mut() {
                    p.plain_again_at = Some(t);
                }
                self.compliant_time += t - t_in;
                self.stalls = 0;
                self.last_part = None;
                Ok(Next::Restart(t))
            }
        }
    }

    fn finish(
        &mut self,
        summary: &mut Summary,
        _solver: Option<&Solver>,
        t_last: Option<f64>,
        ending: Ending,
    ) {
        if let (Mode::Passage { t_in }, Ending::Completed) = (&self.mode, ending) {
            self.compliant_time += t_last.unwrap_or(*t_in) - t_in;
            self.mode = Mode::Idle;
        }
        summary.compliant_time = self.compliant_time;
        summary.compliance_used =
            self.compliant_time > 0.0 || !summary.singular_passages.is_empty();
        summary.partition_rechoices = self.rechoices;
    }
}

/// The partitioned formulation of `sys` from the consistent start `init`, with its rows and
/// events; a mechanism with joints redundant everywhere (no partition exists at any time) is
/// solved by the compliant GGL, and `summary.formulation` says so.
pub(crate) fn job<'a>(start: JobStart<'a, '_>, summary: &mut Summary) -> Job<'a> {
    let JobStart {
        mut sys,
        c,
        tapes,
        init,
        opts,
        t0,
        x,
    } = start;
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let causal = CausalPartition::new(&sys, t0);
    // redundant joints: the partition of the chapter's causality on an independent set of the
    // joint rows, the one the index-1 DAE takes (the causality's redundant junctions left out
    // first); the rows left out follow from the others
    let mut first_lambda = init.lambda.clone();
    let full = (!init.redundant_joints.is_empty()).then(|| tapes.gv.matrix(t0, &x));
    let hint = causal.redundant_rows(&sys.rows);
    let kept = full
        .as_ref()
        .and_then(|full| crate::partition::independent_rows(full, nc - init.rank.min(nc), &hint));
    // a loss of rank at the start's configuration only (a four-bar started on its aligned
    // configuration): a singular configuration, passed as every other (the rows left out would
    // be violated as soon as the mechanism moves: 3.0 m on such a four-bar, issue 34)
    let singular_start = kept.as_ref().is_some_and(|k| {
        crate::solve::formulation::index1::runner::starts_singular(
            "partitioned",
            &tapes,
            (t0, &x),
            k,
            init,
            summary,
        )
    });
    let psys = if init.redundant_joints.is_empty() || singular_start {
        PartitionedSystem::new(&mut sys, c)
    } else {
        let full = full.expect("G_v where the joints are redundant");
        let Some(kept) = kept else {
            // no regular set of rows at the start: the compliant GGL solves it (the summary
            // names what runs: no formulation silently becomes another)
            let eps = crate::solve::formulation::shared::default_compliance(&sys, opts);
            let ggl = GglFormulation::build(&mut sys, c, eps);
            summary.formulation = "compliant_ggl".into();
            summary.warnings.push(format!(
                "partitioned: redundant joints [{}] with no regular set of independent rows at t = {t0}; solved with the compliant GGL",
                joints_in_words(&init.redundant_joints)
            ));
            return crate::solve::formulation::ggl::runner::job(
                sys,
                ggl,
                tapes,
                init,
                (eps, eps),
                t0,
                opts,
            );
        };
        summary.warnings.push(
            crate::solve::formulation::index1::runner::redundant_rows_warning(
                "partitioned",
                &sys,
                &kept,
                t0,
                init,
            ),
        );
        let on_kept = crate::solve::formulation::index1::runner::multipliers_on_rows(
            &full,
            &init.lambda,
            &kept,
        );
        first_lambda = vec![0.0; nc];
        for (&r, l) in kept.iter().zip(on_kept) {
            first_lambda[r] = l;
        }
        PartitionedSystem::on_rows(&mut sys, c, kept)
    };
    let psys = Arc::new(psys);
    let x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    let qscale = 1.0 + init.q.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let multipliers = Multipliers::Unknowns(nq + nv);
    let rows = OutputEval::new(&sys, tapes.clone(), &multipliers);
    let events = crate::solve::formulation::shared::events(&sys, &tapes, &multipliers);
    summary.solver = "CVODE".into();
    let mut first = x.clone();
    first.extend(&first_lambda);
    // the chapter's partition at the start: the differential-causality inertias' flows as the
    // dependent velocities (kept unless its block is ill-conditioned there and the numeric
    // choice is much better conditioned)
    let choose = |t: f64, x: &[f64]| psys.choose(t, x, &causal.preferred_at(t, &x[..nq]));
    let scale = choose(t0, &x).map_or(1.0, |p| {
        (psys.condition(&p, t0, &x) / TYPICAL_CONDITION).max(1.0)
    });
    let from_causality = causal
        .dependent()
        .and_then(|d| psys.with_dependent_velocities(t0, &x, d))
        .filter(|p| {
            let k = psys.condition(p, t0, &x);
            PartitionPolicy::causality_kept(k, || {
                choose(t0, &x).map(|b| psys.condition(&b, t0, &x))
            })
        });
    if from_causality.is_none() && nc > 0 && !sys.inertias.is_empty() && !singular_start {
        let w = crate::partition::causal::not_regular_warning("partitioned", t0);
        summary.warnings.push(w);
    }
    Job {
        formulation: Box::new(Partitioned {
            with_multipliers: sys.reaction_outputs || !sys.drivers.is_empty(),
            newton_tol: newton_tolerance(opts, qscale),
            sys,
            c,
            tapes,
            psys,
            causal,
            kind: opts.integrator,
            opts: opts.clone(),
            events: events.clone(),
            mode: Mode::Idle,
            x,
            t_start: t0,
            scale,
            rechoices: 0,
            compliant_time: 0.0,
            ggl: None,
            last_part: None,
            keep_threshold: REPARTITION_CONDITION,
            stalls: 0,
            from_causality,
            first,
        }),
        rows: Box::new(rows),
        events,
    }
}
