//! The index-1 DAE (acceleration level) with dependent coordinates and velocities — the
//! chapter's partition: the differential-causality inertias' flows `v_D` are the dependent
//! velocities (dummy derivatives), their accelerations `a_D` algebraic unknowns:
//!
//! ```text
//! q' = K(q) v,   v_I' = a_I,   M a − Q(q, v, t) + G_vᵀ λ = 0,   G_v a + (G_v)' v = 0
//! ```
//!
//! on IDA, the Newton matrix solved by eliminating the dependent blocks (a Schur complement of
//! the size of the degrees of freedom) when the linear solver is `auto`. Recoveries: at the
//! outputs, when the dependent block `G_v[:, D]` (or `G_q[:, D_q]`) has degraded and a fresh
//! choice is [`INDEX1_RESELECT_GAIN`] times better conditioned, the run restarts with the
//! fresh choice (counted in `summary.index1_reselections`). The `dae` formulation hands the
//! rest of the run to the GGL where the joints approach a singular configuration (no regular
//! dependent block exists) or IDA fails.

use std::sync::Arc;

use cpu_time::ThreadTime;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::{Conj, MatMut};
use nalgebra::DMatrix;

use crate::dae::index1::{block_lu, SPARSE_GRIP_ROWS};
use crate::dae::{
    consistent_state_from, joint_conditioning, select_dependent, ConsistentState, ConstraintExprs,
    DaeFormulation, GglFormulation, Index1Formulation, JointRows, MechanicsTapes,
};
use crate::mech::MultibodySystem;
use crate::solve::formulation::Job;
use crate::solve::formulation::{
    Ending, Formulation, HandOver, ImplicitProblem, Next, Problem, Start,
};
use crate::solve::options::SolveOptions;
use crate::solve::partition::CausalPartition;
use crate::solve::partition::{INDEX1_CHECK_CONDITION, INDEX1_RESELECT_GAIN};
use crate::solve::reactions::Multipliers;
use crate::solve::rows::OutputEval;
use crate::solve::solution::Summary;
use crate::solve::solver::Solver;
use crate::solve::SolveError;
use crate::sundials::SolverError;

/// Completes the dependent coordinates and velocities of an output row `y = [q, v, …]` of the
/// index-1 DAE (dependent coordinates `coordinates`, dependent velocities `dependent`) from the
/// independent ones: Newton on `g(q_I, q_D) = 0` for `q_D` (with `G_q[:, D_q]`), then
/// `G_v[:, D] v_D = −G_v[:, I] v_I`.
///
/// IDA interpolates an output between its steps, and the algebraic unknowns, out of its error
/// test, are interpolated by a polynomial that satisfies the joints only at the steps (measured:
/// a pinned point moving at 1e-5 m/s at outputs of the double pendulum); the completed row lies
/// on the joints to the Newton tolerance, as the steps do.
///
/// From [`SPARSE_GRIP_ROWS`] joint rows on, the blocks are read by their non-zeros and solved
/// by faer's sparse LU ([`complete_dependent_sparse`]: linear in the size of a chain, where the
/// dense LU is cubic).
fn complete_dependent(
    tapes: &MechanicsTapes,
    (dependent, coordinates): (&[usize], &[usize]),
    t: f64,
    y: &mut [f64],
    lus: &mut BlockLus,
) {
    let (nq, nv, nc) = tapes.dims;
    if nc == 0 || dependent.len() != nc || coordinates.len() != nc {
        return;
    }
    if nc >= SPARSE_GRIP_ROWS {
        complete_dependent_sparse(tapes, (dependent, coordinates), t, y, lus);
        return;
    }
    let scale = y[..nq].iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for _ in 0..4 {
        let g = MechanicsTapes::eval(&tapes.g, t, &y[..nq + nv]);
        if g.iter().all(|v| v.abs() <= 1e-15 * scale) {
            break;
        }
        let gq = tapes.gq.matrix(t, &y[..nq + nv]);
        let block = DMatrix::from_fn(nc, nc, |r, k| gq[(r, coordinates[k])]);
        let Some(dq) = block
            .lu()
            .solve(&nalgebra::DVector::from_iterator(nc, g.iter().map(|v| -v)))
        else {
            return;
        };
        for (k, &i) in coordinates.iter().enumerate() {
            y[i] += dq[k];
        }
    }
    let gv = tapes.gv.matrix(t, &y[..nq + nv]);
    let block = DMatrix::from_fn(nc, nc, |r, k| gv[(r, dependent[k])]);
    let rhs = nalgebra::DVector::from_fn(nc, |r, _| {
        -(0..nv)
            .filter(|j| !dependent.contains(j))
            .map(|j| gv[(r, j)] * y[nq + j])
            .sum::<f64>()
    });
    if let Some(vd) = block.lu().solve(&rhs) {
        for (k, &j) in dependent.iter().enumerate() {
            y[nq + j] = vd[k];
        }
    }
}

/// At scale: faer's symbolic LUs of the blocks `G_q[:, D_q]` and `G_v[:, D]` (their patterns
/// are fixed while the partition is), and the numeric LU of `G_v[:, D]` at the last completed
/// row, which the output's grip check ([`JointRows::dependent_condition_with`]) reuses.
#[derive(Default)]
struct BlockLus {
    q: Option<SymbolicLu<usize>>,
    v: Option<SymbolicLu<usize>>,
    /// `(t, [q, v])` of the completed row and the LU of `G_v[:, D]` there.
    last: Option<(f64, Vec<f64>, Lu<usize, f64>)>,
}

/// [`complete_dependent`] with the blocks `G_q[:, D_q]` and `G_v[:, D]` read by their
/// non-zeros ([`crate::dae::MatrixTape::entries`]) and solved by faer's sparse LU
/// ([`crate::dae::index1::block_lu`], the symbolic factorisations kept in `lus`):
/// `G_q[:, D_q] Δq_D = −g` (up to four Newton steps), then
/// `G_v[:, D] v_D = −Σ_{j ∉ D} G_v[:, j] v_j`. A singular block leaves the row as it is.
fn complete_dependent_sparse(
    tapes: &MechanicsTapes,
    (dependent, coordinates): (&[usize], &[usize]),
    t: f64,
    y: &mut [f64],
    lus: &mut BlockLus,
) {
    let (nq, nv, nc) = tapes.dims;
    lus.last = None;
    let scale = y[..nq].iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for _ in 0..4 {
        let g = MechanicsTapes::eval(&tapes.g, t, &y[..nq + nv]);
        if g.iter().all(|v| v.abs() <= 1e-15 * scale) {
            break;
        }
        let gq = tapes.gq.entries(t, &y[..nq + nv]);
        let Some(lu) = block_lu((nc, nq), &gq, coordinates, &mut lus.q) else {
            return;
        };
        let mut dq: Vec<f64> = g.iter().map(|v| -v).collect();
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut dq, nc, 1),
        );
        if !dq.iter().all(|v| v.is_finite()) {
            return;
        }
        for (k, &i) in coordinates.iter().enumerate() {
            y[i] += dq[k];
        }
    }
    let gv = tapes.gv.entries(t, &y[..nq + nv]);
    let Some(lu) = block_lu((nc, nv), &gv, dependent, &mut lus.v) else {
        return;
    };
    let mut in_d = vec![false; nv];
    for &j in dependent {
        in_d[j] = true;
    }
    let mut vd = vec![0.0; nc];
    for &(r, c, v) in &gv {
        if !in_d[c] {
            vd[r] -= v * y[nq + c];
        }
    }
    lu.solve_in_place_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(&mut vd, nc, 1),
    );
    if !vd.iter().all(|v| v.is_finite()) {
        return;
    }
    for (k, &j) in dependent.iter().enumerate() {
        y[nq + j] = vd[k];
    }
    lus.last = Some((t, y[..nq + nv].to_vec(), lu));
}

/// The dependent coordinates of the index-1 DAE for the dependent velocities `dependent`: the
/// same indices where `q' = v`; otherwise `nc` columns of `G_q` chosen as
/// [`select_dependent`] chooses velocities, the translations first (a 3D body's position, not
/// its quaternion). `None` when `G_q` has lower rank than its rows.
fn dependent_coordinates(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t: f64,
    x: &[f64],
    dependent: &[usize],
) -> Option<Vec<usize>> {
    if q_rates_are_v(sys) {
        return Some(dependent.to_vec());
    }
    let gq = tapes.gq.matrix(t, x);
    select_dependent(&gq, &crate::dae::partition::preferred_coordinates(sys))
}

/// Whether every coordinate's rate is its velocity (`q' = v`: planar bodies in the seed's
/// non-rotating frame, 16.8): then the index-1 DAE's dependent coordinates are its dependent
/// velocities' own.
fn q_rates_are_v(sys: &MultibodySystem) -> bool {
    if sys.nq() != sys.nv() {
        return false;
    }
    let mut g = sys.graph.clone();
    (0..sys.nq()).all(|i| sys.kinematics[i] == g.var(sys.v_slot(i)))
}

/// The joints' and the partition's conditioning at the start of a `dae` run.
struct HandoverWatch {
    /// `κ(G_v M⁺ G_vᵀ)`.
    joints: f64,
    /// `κ(G_v[:, D])` (at least half the re-selection threshold).
    block: f64,
    /// The start.
    t0: f64,
}

/// The rise of the joints' condition number `κ(G_v M⁺ G_vᵀ)` over its value at the start above
/// which the `dae` formulation hands the rest of the run to the GGL (checked at the outputs
/// where the dependent block's condition has doubled). Measured on the bundled scenes: the
/// slider-crank's κ varies by 1.9× over its turns, Andrews' by 1.6×, the four-bar's by 2.9×;
/// the three-four-bar chain's rises 18× an output step before its alignment (κ peak 8e3).
const DAE_HANDOVER_RISE: f64 = 10.0;

/// The condition number of the best-conditioned dependent block `G_v[:, D]` above which the
/// `dae` formulation hands the rest of the run to the GGL (which passes singular configurations
/// with its compliant form and reports them): every partition is then degrading, as near a
/// singular configuration of the joints (a four-bar chain's alignment; a slider-crank's dead
/// centre is not one: the crank angle stays a regular state there).
const DAE_HANDOVER_CONDITION: f64 = 1e3;

/// The index-1 DAE with its re-selections and (for `dae`) its hand-over to the GGL.
struct Index1<'a> {
    sys: MultibodySystem,
    c: &'a ConstraintExprs,
    tapes: MechanicsTapes,
    causal: CausalPartition,
    opts: SolveOptions,
    /// `[q, v]` of the last output row (completed), where a restart starts.
    x: Vec<f64>,
    /// Time of the last output row.
    t_last: f64,
    /// The consistent state a segment starts from.
    state: ConsistentState,
    /// The dependent velocities and coordinates of the running segment.
    dependent: Vec<usize>,
    coordinates: Vec<usize>,
    /// The causality's dependent inertias, for the first segment.
    from_causality: Option<Vec<usize>>,
    watch: HandoverWatch,
    /// `dae`: hands the rest of the run to the GGL near a singular configuration.
    hands_over: bool,
    reselections: u64,
    y_first: Vec<f64>,
    /// The blocks' sparse LUs at scale (reset with the partition).
    block_lus: BlockLus,
}

impl<'a> Index1<'a> {
    /// `G_v` at `(t, x)` as the checks read it (dense, or by its non-zeros at scale).
    fn gv_at(&self, t: f64, x: &[f64]) -> JointRows {
        JointRows::new(&self.tapes.gv, t, x)
    }

    fn nq(&self) -> usize {
        self.tapes.dims.0
    }

    /// The rest of the run from the last output `(t_h, x)` on the GGL (plain, compliant at
    /// singular passages).
    fn hand_over(&mut self, t_h: f64, why: &str) -> Result<Box<HandOver<'a>>, SolveError> {
        let init = consistent_state_from(&self.sys, &self.tapes, t_h, &self.x)?;
        let eps_default = super::default_compliance(&self.sys, &self.opts);
        let tb = ThreadTime::now();
        let mut sys = self.sys.clone();
        let ggl = GglFormulation::build(&mut sys, self.c, 0.0);
        let build_seconds = tb.elapsed().as_secs_f64();
        let job = super::ggl::job(
            sys,
            ggl,
            self.tapes.clone(),
            &init,
            (0.0, eps_default),
            t_h,
            &self.opts,
        );
        Ok(Box::new(HandOver {
            job,
            t: t_h,
            warning: format!(
                "dae: the rest of the run from t = {t_h:.6} is solved by the GGL ({why})"
            ),
            build_seconds,
        }))
    }
}

impl<'a> Formulation<'a> for Index1<'a> {
    fn first_row_state(&self) -> Vec<f64> {
        self.y_first.clone()
    }

    fn segment(&mut self, t_start: f64, summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        let (nq, nv, nc) = self.tapes.dims;
        // G_v only where the causality's choice is not taken (a restart)
        let mut gv: Option<JointRows> = None;
        let chosen = self.from_causality.take().or_else(|| {
            let preferred = self.causal.preferred_at(t_start, &self.x[..nq]);
            select_dependent(gv.insert(self.gv_at(t_start, &self.x)).dense(), &preferred)
        });
        if chosen.is_none() && self.hands_over {
            let h = self.hand_over(t_start, "no regular set of dependent velocities")?;
            return Ok(Start::HandOver(h));
        }
        let dependent = chosen.ok_or_else(|| {
            let gv = gv.get_or_insert_with(|| self.gv_at(t_start, &self.x));
            let c = joint_conditioning(gv.dense(), &self.sys.mass, &self.sys.rows);
            SolveError::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: format!(
                    "joints [{}] lose rank (κ = {:.1e}): no set of dependent velocities exists; use the ggl formulation",
                    c.joints.join(", "),
                    c.condition
                ),
            })
        })?;
        if self.reselections == 0 {
            (summary.states, summary.dependent) = self.causal.names(&dependent);
        }
        let Some(coordinates) =
            dependent_coordinates(&self.sys, &self.tapes, t_start, &self.x, &dependent)
        else {
            if self.hands_over {
                let h = self.hand_over(t_start, "no regular set of dependent coordinates")?;
                return Ok(Start::HandOver(h));
            }
            return Err(SolveError::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: "the joints' position rows lose rank: no set of dependent coordinates exists; use the ggl formulation".into(),
            }));
        };
        let f =
            Index1Formulation::build_partitioned(&mut self.sys, self.c, &dependent, &coordinates)?;
        summary.unknowns = f.dae.n;
        let split = f.schur_split(nq);
        let state = &self.state;
        let mut y0 = state.q.clone();
        y0.extend(&state.v);
        y0.extend(dependent.iter().map(|&j| state.vdot[j]));
        y0.extend(&state.lambda);
        // q' = K(q) v
        let x_start: Vec<f64> = state.q.iter().chain(&state.v).copied().collect();
        let mut yp0 = MechanicsTapes::eval(&self.tapes.kinematics, t_start, &x_start);
        yp0.extend(&state.vdot);
        yp0.extend(std::iter::repeat_n(0.0, 2 * nc));
        let mut atol = vec![self.opts.atol; nq + nv];
        atol.extend(std::iter::repeat_n(self.opts.atol, nc));
        atol.extend(std::iter::repeat_n(super::multiplier_atol(&self.opts), nc));
        let dae: Arc<dyn DaeFormulation> = Arc::new(f);
        // `auto`: the Newton matrix by elimination of the dependent blocks (Schur complement)
        // below AUTO_SCHUR_UNKNOWNS, faer's sparse LU from there on (make_ida resolves `auto`)
        let schur = self
            .opts
            .linear_solver
            .index1_schur(dae.len())
            .then_some(split);
        if schur.is_none() {
            summary.linear_solver = self.opts.linear_solver.resolved_name(dae.len()).into();
        }
        self.dependent = dependent;
        self.coordinates = coordinates;
        self.block_lus = BlockLus::default();
        Ok(Start::Run(Problem::Implicit(ImplicitProblem {
            dae,
            atol,
            y0,
            yp0,
            schur,
        })))
    }

    fn row_state(&mut self, t: f64, y: &[f64], x: &mut Vec<f64>) -> Result<(), SolveError> {
        x.clear();
        x.extend_from_slice(y);
        complete_dependent(
            &self.tapes,
            (&self.dependent, &self.coordinates),
            t,
            x,
            &mut self.block_lus,
        );
        Ok(())
    }

    fn recover(
        &mut self,
        e: &SolverError,
        solver: &mut Solver,
        _last: (f64, &[f64]),
        _summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        if self.hands_over && super::ggl::is_convergence_failure(e).is_some() {
            let t_fail = solver.ida().map_or(f64::NAN, |i| i.t());
            let h = self.hand_over(self.t_last, &format!("IDA failed at t = {t_fail:.6}: {e}"))?;
            return Ok(Next::HandOver(h));
        }
        Ok(Next::Fail)
    }

    fn at_output(
        &mut self,
        t: f64,
        full: &[f64],
        _solver: &mut Solver,
        more: bool,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let nq = self.nq();
        let n = self.x.len();
        self.x.copy_from_slice(&full[..n]);
        self.t_last = t;
        // G_v at this output, evaluated once for every check below (dense, or by its
        // non-zeros at scale: every measure then linear in the size of a chain)
        let mut gv = self.gv_at(t, &self.x);
        // (at scale, with the LU of G_v[:, D] the completion of this row factored)
        let lu = self
            .block_lus
            .last
            .take()
            .filter(|(tl, xl, _)| *tl == t && xl[..] == self.x[..]);
        let cond = gv.dependent_condition_with(&self.dependent, lu.as_ref().map(|l| &l.2));
        // the causality's preference at this output (a graph assignment), assigned at most once
        let mut preferred: Option<Vec<bool>> = None;
        if self.hands_over && cond > 2.0 * self.watch.block && more {
            // the partition degrades: are the joints approaching a singular configuration?
            let kappa = gv.joint_condition_number(&self.sys.mass);
            // best ≤ cond: a fresh choice only matters above the hand-over's threshold
            let best = if cond > DAE_HANDOVER_CONDITION {
                let p = preferred.get_or_insert_with(|| self.causal.preferred_at(t, &self.x[..nq]));
                select_dependent(gv.dense(), p)
                    .map_or(f64::INFINITY, |b| gv.dependent_condition(&b))
                    .min(cond)
            } else {
                cond
            };
            if kappa > DAE_HANDOVER_RISE * self.watch.joints || best > DAE_HANDOVER_CONDITION {
                let why = format!(
                    "the joints approach a singular configuration: κ(G_v M⁺ G_vᵀ) = {kappa:.1e} ({:.1e} at t = {}), the best dependent block's condition {best:.1e}",
                    self.watch.joints, self.watch.t0
                );
                return Ok(Next::HandOver(self.hand_over(t, &why)?));
            }
        }
        if cond > INDEX1_CHECK_CONDITION && more {
            // when no block can be INDEX1_RESELECT_GAIN times better conditioned than the bound
            // allows, no fresh choice (a causality assignment) can replace this one
            let possible = cond * (1.0 + 1e-9) > INDEX1_RESELECT_GAIN * gv.condition_bound();
            let better = possible
                .then(|| {
                    let p =
                        preferred.get_or_insert_with(|| self.causal.preferred_at(t, &self.x[..nq]));
                    select_dependent(gv.dense(), p)
                })
                .flatten();
            if let Some(b) = better {
                if b != self.dependent && gv.dependent_condition(&b) * INDEX1_RESELECT_GAIN < cond {
                    self.reselections += 1;
                    self.state = consistent_state_from(&self.sys, &self.tapes, t, &self.x)?;
                    summary.warnings.push(format!(
                        "index1: dependent velocities re-selected at t = {t:.6} (condition {cond:.1e})"
                    ));
                    return Ok(Next::Restart(t));
                }
            }
        }
        // the dependent coordinates, where they are chosen apart from the velocities
        if self.coordinates != self.dependent && more {
            let mut gq = JointRows::new(&self.tapes.gq, t, &self.x);
            let cond_q = gq.dependent_condition(&self.coordinates);
            let better = (cond_q > INDEX1_CHECK_CONDITION)
                .then(|| {
                    select_dependent(
                        gq.dense(),
                        &crate::dae::partition::preferred_coordinates(&self.sys),
                    )
                })
                .flatten()
                .filter(|b| gq.dependent_condition(b) * INDEX1_RESELECT_GAIN < cond_q);
            if better.is_some() {
                self.reselections += 1;
                self.state = consistent_state_from(&self.sys, &self.tapes, t, &self.x)?;
                summary.warnings.push(format!(
                    "index1: dependent coordinates re-selected at t = {t:.6} (condition {cond_q:.1e})"
                ));
                return Ok(Next::Restart(t));
            }
        }
        Ok(Next::Continue)
    }

    fn finish(
        &mut self,
        summary: &mut Summary,
        _solver: Option<&Solver>,
        _t_last: Option<f64>,
        _ending: Ending,
    ) {
        summary.index1_reselections = self.reselections;
    }
}

/// The index-1 DAE of `sys` from the consistent start `init` (`summary.formulation`: `index1`,
/// or `dae`, which hands over to the GGL), with its rows and events. The causality's partition
/// is the first choice of the dependent velocities, unless its block is ill-conditioned at the
/// start and a numeric choice is much better.
pub(crate) fn job<'a>(
    sys: MultibodySystem,
    c: &'a ConstraintExprs,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    opts: &SolveOptions,
    summary: &mut Summary,
) -> Job<'a> {
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let t0 = opts.output_times[0];
    let x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
    summary.solver = "IDA".into();
    let causal = CausalPartition::new(&sys, t0);
    // y = [q, v, a_D, λ]
    let multipliers = Multipliers::Unknowns(nq + nv + nc);
    let rows = OutputEval::new(sys.clone(), tapes.clone(), &multipliers);
    let events = super::events(&sys, &tapes, &super::solved_multipliers(&sys, &tapes));
    let mut y_first = x.clone();
    y_first.extend(std::iter::repeat_n(0.0, nc));
    y_first.extend(&init.lambda);
    let hands_over = summary.formulation == "dae";
    let mut gv = JointRows::new(&tapes.gv, t0, &x);
    // the chapter's partition at the start: the differential-causality inertias' flows
    // (kept unless its block is ill-conditioned there and a numeric choice is much better;
    // no choice can be INDEX1_RESELECT_GAIN times better when the causality's block is within
    // that factor of the bound κ(G_v) ≤ μ(D) of every block: then no numeric choice is made)
    let causality_block = causal.dependent().map(|d| {
        let cond = gv.dependent_condition(&d);
        (d, cond)
    });
    let from_causality = causality_block.as_ref().and_then(|(d, cond)| {
        let keep = *cond <= INDEX1_CHECK_CONDITION
            || *cond * (1.0 + 1e-9) <= INDEX1_RESELECT_GAIN * gv.condition_bound()
            || select_dependent(gv.dense(), &causal.preferred_at(t0, &x[..nq]))
                .is_none_or(|b| gv.dependent_condition(&b) * INDEX1_RESELECT_GAIN >= *cond);
        keep.then(|| (d.clone(), *cond))
    });
    // what the hand-over compares with: the joints' and the partition's conditioning at the start
    let watch = {
        // (the causality's preference, a graph assignment, only where the causality's block fails)
        let block = match &from_causality {
            Some((_, cond)) => *cond,
            None => select_dependent(gv.dense(), &causal.preferred_at(t0, &x[..nq]))
                .map_or(f64::INFINITY, |d| gv.dependent_condition(&d)),
        };
        HandoverWatch {
            joints: if hands_over {
                gv.joint_condition_number(&sys.mass)
            } else {
                f64::INFINITY
            },
            block: block.max(INDEX1_CHECK_CONDITION / 2.0),
            t0,
        }
    };
    if from_causality.is_none() && !sys.inertias.is_empty() {
        summary.warnings.push(format!(
            "{}: the causality's dependent inertias are not a regular block of the joint rows at t = {t0}; chosen numerically",
            summary.formulation
        ));
    }
    Job {
        formulation: Box::new(Index1 {
            sys,
            c,
            tapes,
            causal,
            opts: opts.clone(),
            x,
            t_last: t0,
            state: init.clone(),
            dependent: Vec::new(),
            coordinates: Vec::new(),
            from_causality: from_causality.map(|(d, _)| d),
            watch,
            hands_over,
            reselections: 0,
            y_first,
            block_lus: BlockLus::default(),
        }),
        rows: Box::new(rows),
        events,
    }
}
