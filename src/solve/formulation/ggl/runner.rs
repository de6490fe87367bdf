//! The stabilized index-2 GGL (Gear–Gupta–Leimkuhler) on IDA, plain or compliant:
//!
//! ```text
//! q' = K(q) v − G_qᵀ μ,   M v' = Q(q, v, t) − G_vᵀ λ,   0 = g(q) − ε μ,   0 = G_v v − ε λ
//! ```
//!
//! with `λ, μ` algebraic (id 0, out of the error test). The recovery hook handles singular
//! configurations: when plain GGL (ε = 0) fails with a collapsing step (`IDA_CONV_FAIL`,
//! `IDA_ERR_FAIL`, `IDA_LSETUP_FAIL`) and `κ(G_v M⁺ G_vᵀ)` at its last accepted step exceeds
//! [`SINGULAR_CONDITION`], IDA restarts from the last output with the compliant GGL
//! (ε = `1e-10 / m_ref` unless given) and a [`SingularPassage`] is recorded (time, joints, κ).
//! Joints redundant everywhere use the compliant GGL from the start.

use crate::solve::formulation::shared::joints_in_words;
use std::sync::Arc;

use nalgebra::DMatrix;

use crate::dae::{consistent_state_from, ConsistentState, MechanicsTapes};
use crate::mech::MultibodySystem;
use crate::partition::causal::CausalPartition;
use crate::partition::thresholds::{MAX_SINGULAR_PASSAGES, PASSAGE_CONDITION, RESUME_PLAIN_GGL};
use crate::partition::{
    dependent_condition, joint_condition_number, joint_conditioning, select_dependent,
};
use crate::partition::{Decision, PartitionPolicy};
use crate::solve::formulation::Job;
use crate::solve::formulation::{Ending, Formulation, ImplicitProblem, Next, Problem, Start};
use crate::solve::formulation::{GglDae, GglFormulation};
use crate::solve::options::SolveOptions;
use crate::solve::reactions::Multipliers;
use crate::solve::rows::OutputEval;
use crate::solve::solution::{SingularPassage, Summary};
use crate::solve::solver::Solver;
use crate::solve::SolveError;
use crate::sundials::SolverError;

/// Which velocities the GGL leaves out of IDA's local error test
/// (`SolveOptions::ggl_dependent_velocity_error_test = false`).
///
/// The velocity rows `G_v(q) v = 0` fix the dependent velocities `v_D` in terms of the others,
/// `v_D = −G_v[:, D]⁻¹ G_v[:, I] v_I`: they are index-2 components, whose BDF error estimate
/// measures the constraint's differentiation rather than the dynamics, so the error test
/// weights them with 0 (IDA's `id` mask with suppressed algebraic error test). `D` is chosen as
/// the index-1 formulation chooses it ([`select_dependent`]), and re-chosen at output times
/// when `μ(D)` ([`dependent_condition`]) exceeds [`INDEX1_CHECK_CONDITION`] and a fresh
/// choice is [`INDEX1_RESELECT_GAIN`] times better conditioned. Where no set is well
/// conditioned (`κ(G_v[:, D]) >` [`GGL_ERROR_TEST_SINGULAR`], or no set exists), and while the
/// compliant GGL runs (there `G_v v = ε λ`: the velocities are no longer fixed by the joints
/// alone), every velocity is kept in the error test.
struct DependentErrorTest {
    /// Whether the exclusion was asked for.
    active: bool,
    /// The `id` of the formulation with every velocity in the error test.
    base_id: Vec<f64>,
    nq: usize,
    preferred: Vec<bool>,
    /// The velocities out of the error test (`None`: all in).
    dependent: Option<Vec<usize>>,
    /// Changes of the set after the first choice.
    reselections: u64,
    chosen_once: bool,
}

impl DependentErrorTest {
    fn new(active: bool, base_id: Vec<f64>, nq: usize, preferred: Vec<bool>) -> Self {
        DependentErrorTest {
            active,
            base_id,
            nq,
            preferred,
            dependent: None,
            reselections: 0,
            chosen_once: false,
        }
    }

    /// The `id` vector for the current set.
    fn id(&self) -> Vec<f64> {
        let mut id = self.base_id.clone();
        for &j in self.dependent.iter().flatten() {
            id[self.nq + j] = 0.0;
        }
        id
    }

    /// A fresh choice at `G_v` with compliance `eps`; returns whether the set changed.
    fn choose(&mut self, gv: &DMatrix<f64>, eps: f64) -> bool {
        let fresh = if eps > 0.0 {
            None
        } else {
            select_dependent(gv, &self.preferred)
                .filter(|d| PartitionPolicy::error_test_regular(dependent_condition(gv, d)))
        };
        self.set(fresh)
    }

    fn set(&mut self, fresh: Option<Vec<usize>>) -> bool {
        let changed = fresh != self.dependent;
        if changed && self.chosen_once {
            self.reselections += 1;
        }
        self.chosen_once = true;
        self.dependent = fresh;
        changed
    }

    /// The check at an output time: re-chooses when the current set has degraded (or is empty
    /// and a set may exist again); returns whether the set changed.
    fn check(&mut self, gv: &DMatrix<f64>, eps: f64) -> bool {
        if eps > 0.0 {
            return self.set(None);
        }
        match &self.dependent {
            Some(d) => {
                let cond = dependent_condition(gv, d);
                let mut fresh = None;
                let decision = PartitionPolicy::error_test_block(cond, || {
                    let b = select_dependent(gv, &self.preferred).filter(|b| b != d)?;
                    let cb = dependent_condition(gv, &b);
                    fresh = Some(b);
                    Some(cb)
                });
                match decision {
                    Decision::Rechoose => self.set(fresh),
                    Decision::Singular => self.set(None),
                    _ => false,
                }
            }
            None => self.choose(gv, eps),
        }
    }
}

/// Whether an IDA failure is the kind a singular passage causes (Newton or error test failing
/// with a collapsing step).
pub(crate) fn is_convergence_failure(e: &SolverError) -> Option<(f64, String)> {
    match e {
        SolverError::Flag { name, t, .. }
            if name == "IDA_CONV_FAIL" || name == "IDA_ERR_FAIL" || name == "IDA_LSETUP_FAIL" =>
        {
            Some((*t, name.clone()))
        }
        _ => None,
    }
}

/// Velocities that satisfy the velocity rows `G_v v = ε λ` of the (compliant, if `ε > 0`) GGL
/// with the least change, so that a (re)start does not begin with a jump IDA's error test sees.
fn compliant_velocities(
    tapes: &MechanicsTapes,
    nq: usize,
    nv: usize,
    eps: f64,
    t: f64,
    y: &mut [f64],
) {
    let nc = tapes.dims.2;
    if nc == 0 {
        return;
    }
    let gv = tapes.gv.matrix(t, &y[..nq + nv]);
    let v = nalgebra::DVector::from_column_slice(&y[nq..nq + nv]);
    let lam = nalgebra::DVector::from_column_slice(&y[nq + nv..nq + nv + nc]);
    let mut defect = &lam * eps - &gv * &v;
    if tapes.bias.is_some() {
        defect -= nalgebra::DVector::from_vec(tapes.bias_at(t, &y[..nq + nv]));
    }
    let svd = gv.svd(true, true);
    // directions of (nearly) lost rank are left alone: there the row residual is small anyway
    let tol = 1e-6 * svd.singular_values.max().max(1e-300);
    if let Ok(dv) = svd.solve(&defect, tol) {
        for j in 0..nv {
            y[nq + j] += dv[j];
        }
    }
}

/// A consistent GGL state `(y, y')` at `(t, x = [q, v])` for compliance `eps`: positions and
/// velocities projected onto the joints, accelerations and (least-norm) multipliers from the
/// mass–constraint system, then velocities adjusted to `G_v v = ε λ`. The multipliers of the
/// failed plain-GGL step are not reused: near the singular configuration they grow without bound.
pub(crate) fn restart_state(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    eps: f64,
    t: f64,
    x: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), SolveError> {
    let (nq, nv, nc) = tapes.dims;
    let st = consistent_state_from(sys, tapes, t, x)?;
    let mut y = st.q.clone();
    y.extend(&st.v);
    y.extend(&st.lambda);
    y.extend(std::iter::repeat_n(0.0, nc));
    compliant_velocities(tapes, nq, nv, eps, t, &mut y);
    let mut yp = MechanicsTapes::eval(&tapes.kinematics, t, &y[..nq + nv]);
    yp.extend(&st.vdot);
    yp.extend(std::iter::repeat_n(0.0, 2 * nc));
    Ok((y, yp))
}

/// Finds the peaks of κ over the output times (one output of delay) and locates each peak
/// between the outputs: near a rank loss `s = κ^{-1/2}` (the ratio of the smallest to the
/// largest singular value of `M^{-1/2} G_vᵀ`) falls linearly to zero, `s ≈ a |t − t*|`, so
/// `t*` follows from the steeper of the two one-sided slopes at the smallest sample.
#[derive(Default)]
struct PeakFinder {
    /// `(t, κ, G_v)` of the last three outputs.
    samples: Vec<(f64, f64, DMatrix<f64>)>,
}

impl PeakFinder {
    /// Output spacing seen last (0 before two samples).
    fn spacing(&self) -> f64 {
        match self.samples.as_slice() {
            [.., a, b] => b.0 - a.0,
            _ => 0.0,
        }
    }

    /// Adds the sample `κ(t)` with the `G_v` it came from; returns a passage when the previous
    /// sample was a peak, naming the joints `joints_of` finds in that sample's `G_v`.
    fn push(
        &mut self,
        t: f64,
        kappa: f64,
        gv: DMatrix<f64>,
        joints_of: impl Fn(&DMatrix<f64>) -> Vec<String>,
    ) -> Option<SingularPassage> {
        self.samples.push((t, kappa, gv));
        if self.samples.len() > 3 {
            self.samples.remove(0);
        }
        let [(t0, k0, _), (t1, k1, gv1), (t2, k2, _)] = self.samples.as_slice() else {
            return None;
        };
        let (k0, k1, k2) = (*k0, *k1, *k2);
        if !(k1 > PASSAGE_CONDITION && k1 >= k0 && k1 > k2 && k1.is_finite()) {
            return None;
        }
        let s = |k: f64| 1.0 / k.sqrt();
        let (sl, sm, sr) = (s(k0), s(k1), s(k2));
        let left = (sl - sm) / (t1 - t0);
        let right = (sr - sm) / (t2 - t1);
        let t_peak = if left >= right {
            (t1 + sm / left).min(*t2)
        } else {
            (t1 - sm / right).max(*t0)
        };
        Some(SingularPassage {
            t: t_peak,
            joints: joints_of(gv1),
            condition: k1,
            restarted_at: t_peak,
            plain_again_at: None,
            failure: "conditioning peak".into(),
        })
    }
}

/// The GGL on IDA with its compliant switch (see the module documentation).
struct Ggl {
    sys: MultibodySystem,
    tapes: MechanicsTapes,
    dae: Arc<GglDae>,
    y0: Vec<f64>,
    yp0: Vec<f64>,
    atol: Vec<f64>,
    eps_start: f64,
    eps_switch: f64,
    error_test: DependentErrorTest,
    /// Joints redundant everywhere have κ = ∞ throughout: no passages to find there.
    monitor: bool,
    peaks: PeakFinder,
    compliant_since: Option<f64>,
    compliant_time: f64,
    linear_solver: crate::settings::LinearSolverKind,
}

impl Ggl {
    fn gv_at(&self, t: f64, y: &[f64]) -> DMatrix<f64> {
        let (nq, nv, _) = self.tapes.dims;
        self.tapes.gv.matrix(t, &y[..nq + nv])
    }

    /// Why IDA's Newton iteration failed at `t` (error `e`) where the GGL does not take it as a
    /// singular passage: the joints' conditioning there `c`, and what passes instead. Regression
    /// (the trial's F2): a change-point four-bar at rtol 1e-12, atol 1e-14 stopped with
    /// `IDA_CONV_FAIL` and nothing else, where the partitioned formulation completes.
    fn convergence_cause(
        &self,
        t: f64,
        c: &crate::partition::JointConditioning,
        e: &SolverError,
        summary: &Summary,
    ) -> String {
        let compliant = self.dae.compliance() > 0.0;
        let joints = if PartitionPolicy::names_singular(c.condition) {
            format!(
                "near a singular configuration of the joints [{}] (κ(G_v M⁺ G_vᵀ) = {:.1e})",
                joints_in_words(&c.joints),
                c.condition
            )
        } else {
            format!(
                "with the joints regularly placed (κ(G_v M⁺ G_vᵀ) = {:.1e})",
                c.condition
            )
        };
        let passages = if summary.singular_passages.len() >= MAX_SINGULAR_PASSAGES {
            format!(
                "; {MAX_SINGULAR_PASSAGES} singular passages were already taken, the most a run takes"
            )
        } else {
            String::new()
        };
        format!(
            "ggl{}: IDA's Newton iteration failed at t = {t:.6} ({e}) {joints}{passages}: the GGL's Newton matrix, whose multiplier rows scale as 1/h², cannot resolve the corrections these tolerances ask for at the step size they need; a looser rtol or atol, or the partitioned formulation (an ODE in the degrees of freedom), may pass",
            if compliant { " (compliant)" } else { "" },
        )
    }
}

/// IDA's id vector after a change of the dependent velocities out of the error test.
fn set_id(solver: &mut Solver, id: &[f64]) -> Result<(), SolveError> {
    if let Some(ida) = solver.ida() {
        ida.set_id(id)?;
    }
    Ok(())
}

impl<'a> Formulation<'a> for Ggl {
    fn parameter_rows(
        &mut self,
        sym: &mut dyn crate::solve::formulation::ParameterSymbols,
    ) -> Option<Result<crate::solve::formulation::ParameterRows, SolveError>> {
        let (rows, hidden) = GglFormulation::parameter_rows(sym);
        let (nq, nv, nc) = self.dae.formulation.dims;
        Some(Ok(crate::solve::formulation::ParameterRows {
            rows,
            hidden,
            // μ vanishes on the solution
            pinned: (nq + nv + nc..nq + nv + 2 * nc).collect(),
        }))
    }

    fn first_row_state(&self) -> Vec<f64> {
        self.y0.clone()
    }

    fn segment(&mut self, _t: f64, summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        let n = self.dae.formulation.dae.n;
        summary.solver = "IDA".into();
        summary.unknowns = n;
        summary.linear_solver = self.sys_linear_solver(n);
        Ok(Start::Run(Problem::Implicit(ImplicitProblem {
            dae: self.dae.clone(),
            atol: self.atol.clone(),
            y0: self.y0.clone(),
            yp0: self.yp0.clone(),
            schur: None,
            weights: None,
        })))
    }

    fn recover(
        &mut self,
        e: &SolverError,
        solver: &mut Solver,
        (tr, xr): (f64, &[f64]),
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let (nq, nv, _) = self.tapes.dims;
        let eps_switch = self.eps_switch;
        let failure = is_convergence_failure(e);
        // the joints' conditioning where IDA failed (the interpolated state at its time)
        let conditioning = match &failure {
            Some((tf, _)) => {
                let mut y = vec![0.0; self.y0.len()];
                solver.dky(*tf, &mut y)?;
                Some(joint_conditioning(
                    &self.gv_at(*tf, &y),
                    &self.sys.mass,
                    &self.sys.rows,
                ))
            }
            None => None,
        };
        // a singular passage: plain GGL failed to converge near a rank-deficient G_v
        let passage = match (&failure, &conditioning) {
            (Some((tf, name)), Some(c))
                if self.dae.compliance() == 0.0
                    && eps_switch > 0.0
                    && PartitionPolicy::is_singular(c.condition)
                    && summary.singular_passages.len() < MAX_SINGULAR_PASSAGES =>
            {
                Some((*tf, name.clone(), c.clone()))
            }
            _ => None,
        };
        let Some((tf, name, c)) = passage else {
            // (the error test's failures keep their own hint: the executor's tolerance hint)
            return Ok(match (failure, conditioning) {
                (Some((tf, name)), Some(c)) if name == "IDA_CONV_FAIL" => {
                    Next::FailWith(SolverError::Stalled {
                        t: tf,
                        cause: self.convergence_cause(tf, &c, e, summary),
                    })
                }
                _ => Next::Fail,
            });
        };
        // restart from the last output: the steps plain GGL accepted just before failing are
        // already degraded by the ill-conditioned Newton matrix (measured on the isosceles
        // slider-crank: restarting from the last accepted step left a crank-angle error 60
        // times that of the compliant GGL throughout)
        let (y, yp) = restart_state(&self.sys, &self.tapes, eps_switch, tr, &xr[..nq + nv])?;
        self.dae.set_compliance(eps_switch);
        self.dae.set_restoring(true);
        solver.reinit_ida(tr, &y, &yp)?;
        if self.error_test.active && self.error_test.choose(&self.gv_at(tr, &y), eps_switch) {
            set_id(solver, &self.error_test.id())?;
        }
        self.compliant_since = Some(tr);
        summary.warnings.push(format!(
            "singular configuration at t = {tf:.6}: joints [{}] lose independence (κ = {:.1e}, {name}); continued with the compliant GGL (ε = {eps_switch:.1e}) from t = {tr}",
            joints_in_words(&c.joints),
            c.condition
        ));
        (summary.singular_passages).push(SingularPassage::begun(tf, c, tr, name));
        Ok(Next::Continue)
    }

    fn at_output(
        &mut self,
        t: f64,
        y: &[f64],
        solver: &mut Solver,
        more: bool,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let eps = self.dae.compliance();
        if self.error_test.active && self.error_test.check(&self.gv_at(t, y), eps) {
            set_id(solver, &self.error_test.id())?;
        }
        // while compliant, every further singular passage shows as a peak of κ. κ alone at
        // every output (eigenvalues only, `joint_condition_number`); the joints involved
        // (eigenvectors, `joint_conditioning`) only where they are reported: at a failure
        // taken as a passage, and at a peak of κ (the PeakFinder keeps `G_v` of its samples
        // for that). Measured on the 40-four-bar chain (242 joint rows, κ above
        // PASSAGE_CONDITION at most outputs): full eigen-decompositions at the 400 outputs
        // took 40 % of the solve.
        if self.monitor && eps > 0.0 {
            let gv = self.gv_at(t, y);
            let kappa = joint_condition_number(&gv, &self.sys.mass);
            let sys = &self.sys;
            let joints_of = |gv: &DMatrix<f64>| joint_conditioning(gv, &sys.mass, &sys.rows).joints;
            if let Some(p) = self.peaks.push(t, kappa, gv, joints_of) {
                let near_switch = summary
                    .singular_passages
                    .last()
                    .is_some_and(|q| (q.t - p.t).abs() < 2.0 * self.peaks.spacing());
                if !near_switch {
                    summary.warnings.push(format!(
                        "singular configuration at t = {:.6}: joints [{}] lose independence (κ peak {:.1e}); carried through by the compliant GGL (ε = {:.1e})",
                        p.t,
                        joints_in_words(&p.joints),
                        p.condition,
                        eps
                    ));
                    summary.singular_passages.push(p);
                }
            }
        }
        // back to plain GGL once the joints are well-conditioned again
        let switched = summary
            .singular_passages
            .last()
            .is_some_and(|p| p.plain_again_at.is_none());
        if RESUME_PLAIN_GGL && switched && eps > 0.0 && more {
            let kappa = joint_condition_number(&self.gv_at(t, y), &self.sys.mass);
            if PartitionPolicy::is_regular(kappa) {
                let (nq, nv, _) = self.tapes.dims;
                let mut y = y.to_vec();
                let yp = solver.ida().map(|i| i.yp().to_vec()).unwrap_or_default();
                compliant_velocities(&self.tapes, nq, nv, 0.0, t, &mut y);
                self.dae.set_compliance(0.0);
                self.dae.set_restoring(false);
                solver.reinit_ida(t, &y, &yp)?;
                if let Some(ts) = self.compliant_since.take() {
                    self.compliant_time += t - ts;
                }
                if let Some(p) = summary.singular_passages.last_mut() {
                    p.plain_again_at = Some(t);
                }
            }
        }
        Ok(Next::Continue)
    }

    fn finish(
        &mut self,
        summary: &mut Summary,
        solver: Option<&Solver>,
        t_last: Option<f64>,
        ending: Ending,
    ) {
        if ending == Ending::Completed {
            if let Some(ts) = self.compliant_since {
                self.compliant_time += t_last.unwrap_or(ts) - ts;
            }
            summary.recovered_failures = solver.map(Solver::recovered_failures).unwrap_or_default();
            summary.ggl_error_test_reselections = self.error_test.reselections;
        }
        summary.compliance_used = self.eps_start > 0.0 || !summary.singular_passages.is_empty();
        summary.compliance = if summary.compliance_used {
            self.eps_start.max(self.eps_switch)
        } else {
            0.0
        };
        summary.compliant_time = self.compliant_time;
    }
}

impl Ggl {
    fn sys_linear_solver(&self, n: usize) -> String {
        self.linear_solver.resolved_name(n).into()
    }
}

/// The GGL of `sys` (built at compliance `eps_start`) from the consistent start `init` at `t0`,
/// switching to the compliance `eps_switch` at singular passages (0: never), with its rows and
/// events.
#[allow(clippy::too_many_arguments)]
pub(crate) fn job<'a>(
    sys: MultibodySystem,
    ggl: GglFormulation,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    (eps_start, eps_switch): (f64, f64),
    t0: f64,
    opts: &SolveOptions,
) -> Job<'a> {
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let mut y0 = init.q.clone();
    y0.extend(&init.v);
    y0.extend(&init.lambda);
    y0.extend(std::iter::repeat_n(0.0, nc));
    compliant_velocities(&tapes, nq, nv, eps_start, t0, &mut y0);
    let mut yp0 = MechanicsTapes::eval(&tapes.kinematics, t0, &y0[..nq + nv]);
    yp0.extend(&init.vdot);
    yp0.extend(std::iter::repeat_n(0.0, 2 * nc));
    let mut atol = vec![opts.atol; nq + nv];
    atol.extend(std::iter::repeat_n(
        crate::solve::formulation::shared::multiplier_atol(opts),
        2 * nc,
    ));
    let mut error_test = DependentErrorTest::new(
        !opts.ggl_dependent_velocity_error_test && nc > 0,
        ggl.id.clone(),
        nq,
        CausalPartition::new(&sys, t0).preferred_at(t0, &y0[..nq]),
    );
    let mut ggl = ggl;
    if error_test.active {
        let gv = tapes.gv.matrix(t0, &y0[..nq + nv]);
        error_test.choose(&gv, eps_start);
        ggl.id = error_test.id();
    }
    let dae = Arc::new(GglDae::shared(Arc::new(ggl), eps_start));
    let multipliers = Multipliers::Unknowns(nq + nv);
    let rows = OutputEval::new(&sys, tapes.clone(), &multipliers);
    let events = crate::solve::formulation::shared::events(
        &sys,
        &tapes,
        &crate::solve::formulation::shared::solved_multipliers(&sys, &tapes),
    );
    Job {
        formulation: Box::new(Ggl {
            monitor: init.redundant_joints.is_empty(),
            linear_solver: opts.linear_solver,
            sys,
            tapes,
            dae,
            y0,
            yp0,
            atol,
            eps_start,
            eps_switch,
            error_test,
            peaks: PeakFinder::default(),
            compliant_since: (eps_start > 0.0).then_some(t0),
            compliant_time: 0.0,
        }),
        rows: Box::new(rows),
        events,
    }
}
