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
//! outputs and inside the output intervals, when the dependent block `G_v[:, D]` (or
//! `G_q[:, D_q]`) has degraded and a fresh choice is [`INDEX1_RESELECT_GAIN`] times better
//! conditioned, the run restarts with the fresh choice (counted in
//! `summary.index1_reselections`). Between outputs a step watch ([`BlockGrip`]) estimates the
//! block's condition at every internal step of IDA from the LU pivots of `G_v[:, D]`; where it
//! has grown the step is examined as an output is, and the run restarts at that step (the bead
//! of a slot through a pivot passes the pivot between two outputs, and the block that held at
//! the last output is singular there). When IDA fails, the choice is made again at its last
//! accepted step before anything else. The `dae` formulation hands the rest of the run to the
//! GGL only where no regular dependent block exists (the joints approach a singular
//! configuration); `index1` then stops with the block, the joints and the time named.

use crate::solve::formulation::shared::joints_in_words;
use std::sync::Arc;

use cpu_time::ThreadTime;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::Lu;
use faer::{Conj, MatMut};
use nalgebra::DMatrix;

use crate::dae::{
    consistent_state_from, rank_loss_persists, ConsistentState, ConstraintExprs, MechanicsTapes,
};
use crate::mech::MultibodySystem;
use crate::partition::causal::CausalPartition;
use crate::partition::thresholds::{
    AT_REST, BUILT_KEPT, COMPLETION_TOLERANCE, ENERGY_DRIFT_TRIGGER, ENERGY_READS,
    ENERGY_TREND_FRACTION, EXAMINE_MOTION, GRIP_ALERT, GRIP_EVERY_STEP_ROWS, GRIP_GROWTH,
    GRIP_RECHECK, INDEX1_CHECK_CONDITION, INDEX1_RESELECT_GAIN, MOOT_MARGIN, SPARSE_GRIP_ROWS,
};
use crate::partition::{
    dependent_condition_bound, dependent_condition_bound_factors, independent_rows,
    joint_conditioning, select_dependent, JointRows,
};
use crate::partition::{Decision, PartitionPolicy};
use crate::partition::{KeptBlockLu, SpectralHints};
use crate::solve::formulation::shared::JobStart;
use crate::solve::formulation::Job;
use crate::solve::formulation::{DaeFormulation, GglFormulation, Index1Formulation};
use crate::solve::formulation::{
    Ending, Formulation, HandOver, ImplicitProblem, Next, Problem, Start,
};
use crate::solve::options::SolveOptions;
use crate::solve::reactions::Multipliers;
use crate::solve::rows::OutputEval;
use crate::solve::solution::Summary;
use crate::solve::solver::Solver;
use crate::solve::SolveError;
use crate::sundials::SolverError;

mod checks;

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
    (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
    t: f64,
    y: &mut [f64],
    lus: &mut BlockLus,
) {
    let (nq, nv, _) = tapes.dims;
    let nc = rows.len();
    if nc == 0 || dependent.len() != nc || coordinates.len() != nc {
        return;
    }
    // (every row: a subset, where the joints are redundant, takes the dense path)
    if nc >= SPARSE_GRIP_ROWS && nc == tapes.dims.2 {
        complete_dependent_sparse(tapes, (dependent, coordinates), t, y, lus);
        return;
    }
    let b = &mut lus.scratch;
    if b.g_work.len() != tapes.g.workspace_len() {
        *b = CompletionScratch {
            g_work: tapes.g.workspace(),
            g: vec![0.0; tapes.g.n_outputs()],
            gq_work: tapes.gq.workspace(),
            gv_work: tapes.gv.workspace(),
            bias_work: tapes
                .bias
                .as_ref()
                .map(|t| t.workspace())
                .unwrap_or_default(),
            bias: vec![0.0; tapes.dims.2],
            ..CompletionScratch::default()
        };
    }
    let scale = y[..nq].iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for _ in 0..4 {
        b.vars.clear();
        b.vars.push(t);
        b.vars.extend_from_slice(&y[..nq + nv]);
        tapes.g.eval(&b.vars, &mut b.g_work, &mut b.g);
        if rows
            .iter()
            .all(|&k| b.g[k].abs() <= COMPLETION_TOLERANCE * scale)
        {
            break;
        }
        tapes
            .gq
            .matrix_into(t, &y[..nq + nv], (&mut b.vars, &mut b.gq_work), &mut b.gq);
        let block = DMatrix::from_fn(nc, nc, |r, k| b.gq[(rows[r], coordinates[k])]);
        let Some(dq) = block.lu().solve(&nalgebra::DVector::from_iterator(
            nc,
            rows.iter().map(|&k| -b.g[k]),
        )) else {
            return;
        };
        for (k, &i) in coordinates.iter().enumerate() {
            y[i] += dq[k];
        }
    }
    tapes
        .gv
        .matrix_into(t, &y[..nq + nv], (&mut b.vars, &mut b.gv_work), &mut b.gv);
    let gv = &b.gv;
    let block = DMatrix::from_fn(nc, nc, |r, k| gv[(rows[r], dependent[k])]);
    // G_D v_D = −(G_I v_I + b), b = ∂g/∂t (a driver's prescribed rate)
    if let Some(bias) = &tapes.bias {
        bias.eval(&b.vars, &mut b.bias_work, &mut b.bias);
    }
    let rhs = nalgebra::DVector::from_fn(nc, |r, _| {
        -(0..nv)
            .filter(|j| !dependent.contains(j))
            .map(|j| gv[(rows[r], j)] * y[nq + j])
            .sum::<f64>()
            - b.bias[rows[r]]
    });
    if let Some(vd) = block.lu().solve(&rhs) {
        for (k, &j) in dependent.iter().enumerate() {
            y[nq + j] = vd[k];
        }
    }
}

/// The buffers of [`complete_dependent`]'s dense path (kept: it runs at every output row and
/// examined step; allocating the tapes' workspaces there was a quarter of a spherical
/// pendulum's run).
#[derive(Default)]
struct CompletionScratch {
    vars: Vec<f64>,
    g_work: Vec<f64>,
    g: Vec<f64>,
    gq_work: (Vec<f64>, Vec<f64>),
    gv_work: (Vec<f64>, Vec<f64>),
    bias_work: Vec<f64>,
    bias: Vec<f64>,
    gq: DMatrix<f64>,
    gv: DMatrix<f64>,
}

/// The rows `rows` of `m` (all of them when `rows` lists every row).
fn rows_of(m: &DMatrix<f64>, rows: &[usize]) -> DMatrix<f64> {
    if rows.len() == m.nrows() {
        return m.clone();
    }
    DMatrix::from_fn(rows.len(), m.ncols(), |r, j| m[(rows[r], j)])
}

/// Whether the joints' loss of rank at the start, `init.rank` with the independent rows `kept`,
/// is that of a singular configuration the mechanism leaves as it moves (a four-bar started on
/// its aligned configuration) rather than redundant joints ([`rank_loss_persists`]); where it is,
/// `summary` gets a warning naming the joints. The formulations then keep every joint row and
/// pass the start as any singular passage.
pub(crate) fn starts_singular(
    formulation: &str,
    tapes: &MechanicsTapes,
    (t0, x): (f64, &[f64]),
    kept: &[usize],
    init: &ConsistentState,
    summary: &mut Summary,
) -> bool {
    if init.redundant_joints.is_empty() || rank_loss_persists(tapes, t0, x, kept, init.rank) {
        return false;
    }
    summary.warnings.push(format!(
        "{formulation}: the joints [{}] lose rank at t = {t0} but regain it as the mechanism moves: a singular configuration, not redundant joints",
        joints_in_words(&init.redundant_joints)
    ));
    true
}

/// The warning of a formulation that solves redundant joints from the independent rows `kept`:
/// which rows are left out, and that the joints' reactions are not unique.
pub(crate) fn redundant_rows_warning(
    formulation: &str,
    sys: &MultibodySystem,
    kept: &[usize],
    t0: f64,
    init: &ConsistentState,
) -> String {
    let left: Vec<String> = (0..sys.rows.len())
        .filter(|k| !kept.contains(k))
        .map(|k| format!("{}.{}", sys.rows[k].joint, sys.rows[k].direction))
        .collect();
    format!(
        "{formulation}: the joint rows [{}] are redundant at t = {t0} (a combination of the others); the motion is solved from the other {} rows, and the reactions of joints [{}] are not unique: those reported take the redundant rows' forces as zero",
        joints_in_words(&left),
        kept.len(),
        joints_in_words(&init.redundant_joints)
    )
}

/// The multipliers of the independent rows `rows` that exert the same generalized forces as
/// `λ` (a least-squares solution over all rows, as the consistent start gives it), with the
/// other rows' held at zero: `λ_R = (G_R G_Rᵀ)⁻¹ G_R (G_vᵀ λ)`, exact where `G_R` spans the row
/// space of `G_v`. `λ` itself when every row is independent.
pub(crate) fn multipliers_on_rows(gv: &DMatrix<f64>, lambda: &[f64], rows: &[usize]) -> Vec<f64> {
    if rows.len() == gv.nrows() {
        return lambda.to_vec();
    }
    let force = gv.transpose() * nalgebra::DVector::from_column_slice(lambda);
    let gr = rows_of(gv, rows);
    let normal = &gr * gr.transpose();
    let rhs = &gr * force;
    let lr = normal
        .cholesky()
        .map(|c| c.solve(&rhs))
        .unwrap_or_else(|| nalgebra::DVector::zeros(rows.len()));
    let mut out = vec![0.0; gv.nrows()];
    for (k, &row) in rows.iter().enumerate() {
        out[row] = lr[k];
    }
    out
}

/// `(t, [q, v])` of a row and the LU of `G_v[:, D]` there.
type FactoredRow = (f64, Vec<f64>, Arc<Lu<usize, f64>>);

/// The buffers [`Index1::examination_moot`] evaluates `G_v` and `G_q` with: the slots, the
/// tapes' work and the dense matrices, sized at the first check and kept.
#[derive(Debug)]
struct MootBuffers {
    vars: Vec<f64>,
    gv_work: (Vec<f64>, Vec<f64>),
    gq_work: (Vec<f64>, Vec<f64>),
    gv: DMatrix<f64>,
    gq: DMatrix<f64>,
}

impl Default for MootBuffers {
    fn default() -> Self {
        MootBuffers {
            vars: Vec::new(),
            gv_work: (Vec::new(), Vec::new()),
            gq_work: (Vec::new(), Vec::new()),
            gv: DMatrix::zeros(0, 0),
            gq: DMatrix::zeros(0, 0),
        }
    }
}

/// At scale: faer's LUs of the blocks `G_q[:, D_q]` and `G_v[:, D]`, symbolic (their patterns
/// are fixed while the partition is) and numeric, kept with the entries they factor
/// ([`KeptBlockLu`]: a pinned chain's blocks, rows of constant ±1, are factored once per
/// segment; a fresh LU at every output and examined step was 9 % of the 128-link pendulum's
/// run), and the LU of `G_v[:, D]` at the last completed row, which the output's grip check
/// ([`JointRows::dependent_condition_with`]) reuses.
#[derive(Default)]
struct BlockLus {
    q: KeptBlockLu,
    v: KeptBlockLu,
    /// `(t, [q, v])` of the completed row and the LU of `G_v[:, D]` there.
    last: Option<FactoredRow>,
    /// `G_v`'s non-zeros at `last`'s state where the step watch's examination evaluated them
    /// (the examination reads them instead of evaluating them again).
    last_gv: Option<Vec<(usize, usize, f64)>>,
    /// `σ_min(G_D)²` of the block `v` factored in its factorisation number `.0`
    /// (`KeptBlockLu::factored`): while the kept factors answer, the block is the same and so
    /// is its smallest singular value (the pinned chain's, at every examination).
    smallest: Option<(u64, f64)>,
    /// The dense path's buffers.
    scratch: CompletionScratch,
}

/// `b ← B⁻¹ b` with a dependent block's sparse LU `lu`; whether every entry came out finite.
fn solved_finite(lu: &Lu<usize, f64>, b: &mut [f64]) -> bool {
    let n = b.len();
    lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(b, n, 1));
    b.iter().all(|v| v.is_finite())
}

/// [`complete_dependent`] with the blocks `G_q[:, D_q]` and `G_v[:, D]` read by their
/// non-zeros ([`crate::dae::MatrixTape::entries`]) and solved by faer's sparse LU
/// ([`KeptBlockLu`], the factors kept in `lus`):
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
    lus.last_gv = None;
    let scale = y[..nq].iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for _ in 0..4 {
        let g = MechanicsTapes::eval(&tapes.g, t, &y[..nq + nv]);
        if g.iter().all(|v| v.abs() <= COMPLETION_TOLERANCE * scale) {
            break;
        }
        let gq = tapes.gq.entries(t, &y[..nq + nv]);
        let Some(lu) = lus.q.lu((nc, nq), &gq, coordinates) else {
            return;
        };
        let mut dq: Vec<f64> = g.iter().map(|v| -v).collect();
        if !solved_finite(&lu, &mut dq) {
            return;
        }
        for (k, &i) in coordinates.iter().enumerate() {
            y[i] += dq[k];
        }
    }
    let gv = tapes.gv.entries(t, &y[..nq + nv]);
    let Some(lu) = lus.v.lu((nc, nv), &gv, dependent) else {
        return;
    };
    let mut in_d = vec![false; nv];
    for &j in dependent {
        in_d[j] = true;
    }
    let mut vd: Vec<f64> = tapes
        .bias_at(t, &y[..nq + nv])
        .into_iter()
        .map(|b| -b)
        .collect();
    for &(r, c, v) in &gv {
        if !in_d[c] {
            vd[r] -= v * y[nq + c];
        }
    }
    if !solved_finite(&lu, &mut vd) {
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
    (t, x): (f64, &[f64]),
    dependent: &[usize],
    rows: &[usize],
) -> Option<Vec<usize>> {
    if q_rates_are_v(sys) {
        return Some(dependent.to_vec());
    }
    let gq = rows_of(&tapes.gq.matrix(t, x), rows);
    select_dependent(&gq, &crate::partition::preferred_coordinates(sys))
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

/// The step watch's estimate of the dependent block's condition: `G_v` at IDA's step, the
/// block `G_v[:, D]`, its LU with partial pivoting and the ratio of its largest to its
/// smallest pivot, `ρ = max|u_kk| / min|u_kk|` (`ρ ≤ κ(G_v[:, D])`, and `ρ → ∞` as the block
/// becomes singular). Buffers are kept so that a check allocates nothing. A block whose
/// entries are all constant expressions (the translations of a pinned chain) is not watched.
struct BlockGrip {
    /// Tape slots `[t, q, v]`.
    vars: Vec<f64>,
    work: (Vec<f64>, Vec<f64>),
    /// `G_v`, row-major `nc × nv`.
    gv: Vec<f64>,
    /// `G_v[:, D]`, column-major `nc × nc`, factored in place.
    block: Vec<f64>,
    /// The estimate above which a step is examined.
    alert: f64,
    /// Steps between two checks at most rows (1 up to [`GRIP_EVERY_STEP_ROWS`]), steps until
    /// the next check (that, times 4 while the estimate is below half the alert, times 2 below
    /// 80 % of it), and steps since the last one.
    every: u64,
    next: u64,
    since: u64,
    /// Whether every entry of the running block `G_v[:, D]` is a constant expression (a
    /// pinned chain's dependent translations: rows of ±1): its condition cannot change and
    /// the watch is off.
    constant: bool,
}

impl BlockGrip {
    fn new(tapes: &MechanicsTapes) -> BlockGrip {
        let (nq, nv, nc) = tapes.dims;
        let ratio = nc.div_ceil(GRIP_EVERY_STEP_ROWS) as u64;
        BlockGrip {
            vars: vec![0.0; 1 + nq + nv],
            work: tapes.gv.workspace(),
            gv: vec![0.0; nc * nv],
            block: vec![0.0; nc * nc],
            alert: f64::INFINITY,
            every: (ratio * ratio).max(1),
            next: 1,
            since: 0,
            constant: false,
        }
    }

    /// `ρ(G_v[R, D])` at `(t, y)`, `y = [q, v, …]`, over the joint rows `R` the segment solves
    /// from (∞ for a singular block).
    fn estimate(
        &mut self,
        tapes: &MechanicsTapes,
        (dependent, rows): (&[usize], &[usize]),
        t: f64,
        y: &[f64],
    ) -> f64 {
        let (nq, nv, _) = tapes.dims;
        let m = rows.len();
        if m == 0 || dependent.len() != m {
            return 1.0;
        }
        self.vars[0] = t;
        self.vars[1..].copy_from_slice(&y[..nq + nv]);
        tapes.gv.eval_into(&self.vars, &mut self.work, &mut self.gv);
        for (k, &j) in dependent.iter().enumerate() {
            for (i, &r) in rows.iter().enumerate() {
                self.block[k * m + i] = self.gv[r * nv + j];
            }
        }
        // the whole rows' largest entry: a block that loses its grip uniformly (a 1 × 1 block,
        // a point mass on a distance link passing under its pivot) has pivots of one size
        let whole = rows
            .iter()
            .flat_map(|&r| self.gv[r * nv..(r + 1) * nv].iter())
            .fold(0.0f64, |a, v| a.max(v.abs()));
        pivot_ratio(&mut self.block[..m * m], m, whole)
    }
}

/// The largest of `whole` (the largest entry of the block's rows) and the largest pivot, over
/// the smallest pivot magnitude of the LU with partial pivoting of the column-major `m × m`
/// matrix `a` (factored in place); ∞ when a pivot is zero. Like `μ(D)`
/// ([`crate::partition::dependent_condition`]) it sees a block that loses its grip against the whole
/// rows: `G_v = [x  y]`, `D = {x}` gives `max(|x|, |y|) / |x|`, where the pivots alone give 1.
fn pivot_ratio(a: &mut [f64], m: usize, whole: f64) -> f64 {
    let (mut largest, mut smallest) = (0.0f64, f64::INFINITY);
    for k in 0..m {
        let (p, pv) = (k..m)
            .map(|r| (r, a[k * m + r].abs()))
            .fold((k, -1.0), |b, c| if c.1 > b.1 { c } else { b });
        if pv == 0.0 {
            return f64::INFINITY;
        }
        (largest, smallest) = (largest.max(pv), smallest.min(pv));
        if p != k {
            for c in k..m {
                a.swap(c * m + k, c * m + p);
            }
        }
        let d = a[k * m + k];
        for r in k + 1..m {
            let l = a[k * m + r] / d;
            if l != 0.0 {
                for c in k + 1..m {
                    a[c * m + r] -= l * a[c * m + k];
                }
            }
        }
    }
    largest.max(whole) / smallest
}

/// The index-1 DAE with its re-selections and (for `dae`) its hand-over to the GGL.
struct Index1<'a> {
    /// `G_v G_vᵀ`'s approximate eigenvectors at the last output: the next output's Lanczos
    /// iterations start from them and its check bounds `κ(G_v)` by a Rayleigh quotient before
    /// factoring the Gram matrix ([`JointRows::no_block_much_better`]).
    hints: SpectralHints,
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
    /// The joint rows the running segment solves its dependent block from: every row, or a
    /// maximal independent set where the joints are redundant ([`independent_rows`]).
    rows: Vec<usize>,
    /// Redundant joints: how many rows are redundant, and the rows the causality names
    /// redundant (left out first where they can be).
    redundant: Option<(usize, Vec<usize>)>,
    /// The causality's dependent inertias, for the first segment.
    from_causality: Option<Vec<usize>>,
    watch: HandoverWatch,
    /// `dae`: hands the rest of the run to the GGL near a singular configuration.
    hands_over: bool,
    reselections: u64,
    y_first: Vec<f64>,
    /// The step watch of the running segment.
    grip: BlockGrip,
    /// The time of the last restart at a step (a failure there again is not answered by
    /// another restart at the same time).
    restarted_at: Option<f64>,
    /// The configuration `q` at the last examination of the partition ([`EXAMINE_MOTION`]).
    examined_q: Vec<f64>,
    /// The IDA step the watch asked to examine: its time, whether the configuration has moved
    /// [`EXAMINE_MOTION`] since the last examination, whether the block's grip alert fired.
    watched: Option<(f64, bool, bool)>,
    /// The grip `μ` of the running dependent velocities' and coordinates' blocks at the last
    /// examination that looked for a better choice and kept them: the search (a causality
    /// assignment and a greedy selection) is made again only once the block has degraded
    /// [`GRIP_RECHECK`] times further (0: not yet searched in this segment).
    /// `G_v` where [`Index1::examination_moot`] last bounded the velocities' block in full, and
    /// that bound's factors `(a, b)` ([`dependent_condition_bound_factors`]); cleared at each
    /// segment's start (a new block).
    moot_reference: Option<(DMatrix<f64>, f64, f64)>,
    /// Buffers of [`Index1::examination_moot`] (kept: the check runs at every other step).
    moot_buffers: MootBuffers,
    kept_grip: (f64, f64),
    /// The blocks' sparse LUs at scale (reset with the partition).
    block_lus: BlockLus,
    /// The energy kept as an invariant, where the run keeps it
    /// ([`crate::solve::formulation::EnergyInvariant`]); the same `E₀` across restarts.
    energy_e0: Option<f64>,
    /// Where the mechanism conserves its energy and the invariant is not kept from the start:
    /// the watch that switches it on once the energy has drifted ([`EnergyWatch`]).
    energy_watch: Option<EnergyWatch>,
    /// The IDA step at which the energy watch reads the energy next (set by the step watch).
    energy_due: Option<f64>,
    /// The formulations built for earlier segments, by `(dependent, rows)`
    /// (without the energy invariant): a mechanism that swings back and forth returns to the
    /// partitions it had, and compiling one is most of a restart's cost (Bricard's).
    built: Vec<(PartitionKey, Index1Formulation)>,
}

/// The kind of the index-1 DAE's re-selection warnings ([`Summary::routine_warning`]),
/// labelled with the formulation that ran (`dae: partition re-selected` under the default,
/// `index1: …` under `index1`).
fn reselection_warning(formulation: &str) -> String {
    format!("{formulation}: partition re-selected")
}

/// `(dependent velocities, joint rows)` of a segment: the formulation built for them serves
/// every choice of dependent coordinates ([`Index1Formulation::with_coordinates`]).
type PartitionKey = (Vec<usize>, Vec<usize>);

/// The energy at the outputs of a run that may keep it as an invariant later.
#[derive(Clone, Debug)]
struct EnergyWatch {
    /// `[E, kinetic]`.
    tape: crate::expr::Tape,
    /// The energy at the start, and the time.
    e_start: f64,
    t_start: f64,
    /// The largest kinetic energy met.
    kinetic_max: f64,
    /// The largest `Σ |∂E/∂x_i|` met (`x = [q, v]`): the energy error the absolute tolerance
    /// allows per unit of atol.
    gradient_max: f64,
    /// The time from which the next IDA step reads the energy, and the spacing of the reads
    /// ([`ENERGY_READS`] over the run): a schedule of the integrator's own, so that the
    /// decision does not depend on the output times asked for.
    next_read: f64,
    spacing: f64,
    /// The trigger has fired at a step where the mechanism barely moves: the watch reads at
    /// every step until it moves well enough to take its energy back.
    pending: bool,
    /// The tape's workspace and outputs, reused by every read.
    work: Vec<f64>,
    out: Vec<f64>,
}

impl EnergyWatch {
    /// `[E, kinetic, ∂E/∂x…]` at `(t, x)`, `x = [q, v]`, into `self.out` (no allocation), the
    /// largest kinetic energy and gradient met updated; returns `(E, kinetic)`.
    fn read(&mut self, t: f64, x: &[f64]) -> (f64, f64) {
        self.tape
            .eval_parts(&[&[t], x], &mut self.work, &mut self.out);
        let (e, kinetic) = (self.out[0], self.out[1]);
        self.kinetic_max = self.kinetic_max.max(kinetic);
        self.gradient_max = self
            .gradient_max
            .max(self.out[2..].iter().map(|d| d.abs()).sum());
        (e, kinetic)
    }
}

impl<'a> Index1<'a> {
    /// `G_v` over the running segment's rows at `(t, x)` as the checks read it (dense, or by
    /// its non-zeros at scale; a subset of the rows, where the joints are redundant, dense).
    fn gv_at(&self, t: f64, x: &[f64]) -> JointRows {
        if self.rows.len() == self.tapes.dims.2 {
            JointRows::new(&self.tapes.gv, t, x)
        } else {
            JointRows::from_dense(rows_of(&self.tapes.gv.matrix(t, x), &self.rows))
        }
    }

    fn nq(&self) -> usize {
        self.tapes.dims.0
    }

    /// The rest of the run from the last output `(t_h, x)` on the GGL (plain, compliant at
    /// singular passages).
    fn hand_over(&mut self, t_h: f64, why: &str) -> Result<Box<HandOver<'a>>, SolveError> {
        let x = self.x.clone();
        self.hand_over_from(t_h, &x, why)
    }

    /// The rest of the run from `(t_h, x)`, `x = [q, v]` (an output row or an IDA step), on the
    /// GGL (plain, compliant at singular passages).
    fn hand_over_from(
        &mut self,
        t_h: f64,
        x: &[f64],
        why: &str,
    ) -> Result<Box<HandOver<'a>>, SolveError> {
        let init = self.restart_state(t_h, x)?;
        let eps_default =
            crate::solve::formulation::shared::default_compliance(&self.sys, &self.opts);
        let tb = ThreadTime::now();
        let mut sys = self.sys.clone();
        // redundant joints need the compliant form throughout
        let eps = if self.redundant.is_some() {
            eps_default
        } else {
            0.0
        };
        let ggl = GglFormulation::build(&mut sys, self.c, eps);
        let build_seconds = tb.elapsed().as_secs_f64();
        let job = crate::solve::formulation::ggl::runner::job(
            sys,
            ggl,
            self.tapes.clone(),
            &init,
            (eps, eps_default),
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
    fn parameter_rows(
        &mut self,
        sym: &mut dyn crate::solve::formulation::ParameterSymbols,
    ) -> Option<Result<super::super::ParameterRows, SolveError>> {
        let partition = (&self.dependent[..], &self.coordinates[..], &self.rows[..]);
        Some(
            Index1Formulation::parameter_rows(sym, partition, self.energy_e0.is_some())
                .map(|rows| super::super::ParameterRows {
                    rows,
                    hidden: Vec::new(),
                    pinned: Vec::new(),
                })
                .map_err(SolveError::from),
        )
    }

    fn first_row_state(&self) -> Vec<f64> {
        self.y_first.clone()
    }

    fn segment(&mut self, t_start: f64, summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        let (nq, nv, nc) = self.tapes.dims;
        if let Some((d, hint)) = &self.redundant {
            // the causality's choice at the start, the best-held rows at a re-selection
            let hint: &[usize] = if self.reselections == 0 { hint } else { &[] };
            let full = self.tapes.gv.matrix(t_start, &self.x);
            // a restart for another cause (the dependent coordinates or velocities) keeps the
            // running rows while they hold the rank within REDUNDANT_ROWS_GAIN of the best set,
            // as the outputs' check does ([`Self::fresher_rows`]): the rows are then the same
            // from segment to segment, and a partition met before is taken from `built`
            // (Bricard re-chooses its coordinates twice a period; a fresh set of rows at every
            // restart made every segment's partition new)
            let stress = crate::partition::SelfStress::new(&full, *d);
            let fresh = stress.as_ref().and_then(|s| s.independent_rows(hint));
            let keep = self.reselections > 0
                && self.rows.len() + *d == nc
                && stress.as_ref().zip(fresh.as_ref()).is_some_and(|(s, f)| {
                    PartitionPolicy::rows_hold(s.grip(&self.rows), s.grip(f))
                });
            match fresh {
                _ if keep => {}
                Some(rows) => self.rows = rows,
                None if self.hands_over => {
                    let h = self.hand_over(t_start, "no regular set of independent joint rows")?;
                    return Ok(Start::HandOver(h));
                }
                None => {}
            }
        } else {
            self.rows = (0..nc).collect();
        }
        let r = self.rows.len();
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
            let full = self.tapes.gv.matrix(t_start, &self.x);
            let c = joint_conditioning(&full, &self.sys.mass, &self.sys.rows);
            SolveError::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: format!(
                    "joints [{}] lose rank (κ = {:.1e}): no set of dependent velocities exists; use the ggl formulation",
                    joints_in_words(&c.joints),
                    c.condition
                ),
            })
        })?;
        if self.reselections == 0 {
            (summary.states, summary.dependent) = self.causal.names(&dependent);
        }
        let Some(coordinates) = dependent_coordinates(
            &self.sys,
            &self.tapes,
            (t_start, &self.x),
            &dependent,
            &self.rows,
        ) else {
            if self.hands_over {
                let h = self.hand_over(t_start, "no regular set of dependent coordinates")?;
                return Ok(Start::HandOver(h));
            }
            return Err(SolveError::Init(crate::dae::InitError::Singular {
                t: t_start,
                what: "the joints' position rows lose rank: no set of dependent coordinates exists; use the ggl formulation".into(),
            }));
        };
        // the invariant restarts at the energy of the state it restarts from: that state's
        // dependent coordinates and velocities are completed from the independent ones (to
        // rounding), IDA's were within its Newton tolerance, and the energies differ by about
        // that much; a row violated by it at the start would kick the first step by it
        if self.energy_e0.is_some() {
            let x_start: Vec<f64> = self.state.q.iter().chain(&self.state.v).copied().collect();
            let e = MechanicsTapes::eval(&self.tapes.outputs, t_start, &x_start);
            self.energy_e0 = Some(e[e.len() - 2]);
        }
        // a partition met before, or one that differs from it in the dependent coordinates
        // only (their rows are selected among the compiled candidates)
        let key = (dependent.clone(), self.rows.clone());
        let cached = self
            .energy_e0
            .is_none()
            .then(|| self.built.iter().find(|(k, _)| *k == key))
            .flatten()
            .and_then(|(_, f)| f.with_coordinates(nq, &coordinates));
        let f = match cached {
            Some(f) => f,
            None => {
                let f = Index1Formulation::build_with_energy(
                    &mut self.sys,
                    self.c,
                    (&dependent, &coordinates, &self.rows),
                    self.energy_e0,
                )?;
                if self.energy_e0.is_none() {
                    if self.built.len() == BUILT_KEPT {
                        self.built.remove(0);
                    }
                    self.built.push((key, f.clone()));
                }
                f
            }
        };
        summary.unknowns = f.dae.n;
        let split = f.schur_split(nq);
        let state = &self.state;
        let mut y0 = state.q.clone();
        y0.extend(&state.v);
        y0.extend(dependent.iter().map(|&j| state.vdot[j]));
        if self.redundant.is_some() {
            let full = self.tapes.gv.matrix(t_start, &self.x);
            y0.extend(multipliers_on_rows(&full, &state.lambda, &self.rows));
        } else {
            y0.extend(&state.lambda);
        }
        // q' = K(q) v
        let x_start: Vec<f64> = state.q.iter().chain(&state.v).copied().collect();
        let mut yp0 = MechanicsTapes::eval(&self.tapes.kinematics, t_start, &x_start);
        yp0.extend(&state.vdot);
        yp0.extend(std::iter::repeat_n(0.0, r + nc));
        let mut atol = vec![self.opts.atol; nq + nv];
        atol.extend(std::iter::repeat_n(self.opts.atol, r));
        atol.extend(std::iter::repeat_n(
            crate::solve::formulation::shared::multiplier_atol(&self.opts),
            nc,
        ));
        if f.energy.is_some() {
            // η, κ (the reduced gradient's multipliers) and μ, then their rates
            y0.extend(energy_multipliers(
                &mut self.sys,
                self.c,
                (t_start, &x_start),
                (&dependent, &coordinates, &self.rows),
            ));
            y0.push(0.0);
            yp0.extend(std::iter::repeat_n(0.0, 2 * r + 1));
            // multipliers, as λ (measured: μ at the coordinates' atol made Newton's test
            // unreachable on the heavy top, every step cut to nothing)
            atol.extend(std::iter::repeat_n(
                crate::solve::formulation::shared::multiplier_atol(&self.opts),
                2 * r + 1,
            ));
        }
        let dae: Arc<dyn DaeFormulation> = Arc::new(f);
        let weights = crate::partition::amplification::DependentAmplification::new(
            (&self.tapes.gq, &self.tapes.gv),
            (&dependent, &coordinates, &self.rows),
            (nq, nv),
            dae.id(),
            q_rates_are_v(&self.sys),
        )
        .map(|mut a| {
            Box::new(move |t: f64, y: &[f64], w: &mut [f64]| {
                a.raise(t, y, w);
                Ok(())
            }) as crate::sundials::ErrorWeightFn
        });
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
        // the step watch's alert: GRIP_GROWTH times the block's estimate at the start, at least
        // GRIP_ALERT
        let start = self.grip.estimate(
            &self.tapes,
            (&self.dependent, &self.rows),
            t_start,
            &x_start,
        );
        self.grip.alert = (GRIP_GROWTH * start).max(GRIP_ALERT);
        self.examined_q.clear();
        self.examined_q.extend_from_slice(&x_start[..nq]);
        self.watched = None;
        self.kept_grip = (0.0, 0.0);
        self.moot_reference = None;
        self.grip.since = 0;
        self.grip.next = self.grip.every;
        self.grip.constant = self.c.gv.iter().all(|row| {
            self.dependent
                .iter()
                .all(|&j| self.sys.graph.as_const(row[j]).is_some())
        });
        self.block_lus = BlockLus::default();
        Ok(Start::Run(Problem::Implicit(ImplicitProblem {
            dae,
            atol,
            y0,
            yp0,
            schur,
            weights,
        })))
    }

    fn row_state(&mut self, t: f64, y: &[f64], x: &mut Vec<f64>) -> Result<(), SolveError> {
        x.clear();
        x.extend_from_slice(y);
        complete_dependent(
            &self.tapes,
            (&self.dependent, &self.coordinates, &self.rows),
            t,
            x,
            &mut self.block_lus,
        );
        Ok(())
    }

    fn watches_steps(&self) -> bool {
        self.tapes.dims.2 > 0 || self.energy_watch.is_some()
    }

    fn watch_step(&mut self, t: f64, y: &[f64]) -> bool {
        // no re-choice at or after the last output
        if self.opts.output_times.last().is_none_or(|&end| t >= end) {
            return false;
        }
        if let Some(w) = self.energy_watch.as_mut() {
            if w.pending || t >= w.next_read {
                while w.next_read <= t {
                    w.next_read += w.spacing;
                }
                self.energy_due = Some(t);
            }
        }
        if self.tapes.dims.2 == 0 {
            return self.energy_due.is_some();
        }
        let nq = self.nq();
        let scheduled = self.examined_q.len() == nq
            && y[..nq]
                .iter()
                .zip(&self.examined_q)
                .any(|(a, b)| (a - b).abs() > EXAMINE_MOTION);
        let alert = self.grip_alert(t, y);
        if scheduled || alert {
            self.watched = Some((t, scheduled, alert));
        }
        scheduled || alert || self.energy_due.is_some()
    }

    fn at_step(
        &mut self,
        t: f64,
        y: &[f64],
        _solver: &mut Solver,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        if self.energy_due.take() == Some(t) {
            if let Some(next) = self.energy_check(t, y, summary)? {
                self.watched = None;
                return Ok(next);
            }
        }
        let Some((_, scheduled, alert)) = self.watched.take() else {
            return Ok(Next::Continue);
        };
        if scheduled && !alert && self.examination_moot(t, y) {
            let nq = self.nq();
            self.examined_q.clear();
            self.examined_q.extend_from_slice(&y[..nq]);
            return Ok(Next::Continue);
        }
        let x = if self.at_scale() {
            // the checks read IDA's step as it is (its dependent coordinates and velocities
            // hold the joints to the Newton tolerance), with the LU of G_v[:, D] there; a
            // restart or hand-over completes the row first ([`Self::restart_state`])
            let (nq, nv, nc) = self.tapes.dims;
            let x = y[..nq + nv].to_vec();
            let gv = self.tapes.gv.entries(t, &x);
            let lu = self.block_lus.v.lu((nc, nv), &gv, &self.dependent);
            self.block_lus.last = lu.map(|lu| (t, x.clone(), lu));
            self.block_lus.last_gv = Some(gv);
            x
        } else {
            self.completed(t, y)
        };
        Ok(self
            .examine_step(t, &x, (scheduled, alert), summary)?
            .unwrap_or(Next::Continue))
    }

    fn recover(
        &mut self,
        e: &SolverError,
        solver: &mut Solver,
        _last: (f64, &[f64]),
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let stalled = matches!(e, SolverError::NoProgress { .. })
            || crate::solve::formulation::ggl::runner::is_convergence_failure(e).is_some();
        if !stalled || self.tapes.dims.2 == 0 {
            return Ok(Next::Fail);
        }
        // IDA's last accepted step: choose the partition again there first
        let Some(ida) = solver.ida() else {
            return Ok(Next::Fail);
        };
        let t_n = ida.last_accepted_time();
        let y_n = ida.y().to_vec();
        let x_n = self.completed(t_n, &y_n);
        if self.restarted_at != Some(t_n) && x_n.iter().all(|v| v.is_finite()) {
            let why = format!("IDA failed: {e}");
            if let Some(next) = self.rechoose_at_step(t_n, &x_n, &why, summary)? {
                return Ok(next);
            }
        }
        if self.hands_over {
            let h = self.hand_over(self.t_last, &format!("IDA failed at t = {t_n:.6}: {e}"))?;
            return Ok(Next::HandOver(h));
        }
        Ok(Next::FailWith(SolverError::Stalled {
            t: t_n,
            cause: self.stall_cause(t_n, &x_n, e),
        }))
    }

    fn at_output(
        &mut self,
        t: f64,
        full: &[f64],
        _solver: &mut Solver,
        more: bool,
        summary: &mut Summary,
    ) -> Result<Next<'a>, SolveError> {
        let n = self.x.len();
        self.x.copy_from_slice(&full[..n]);
        self.t_last = t;
        // the step the watch asked to examine ended exactly on this output
        if let Some((_, scheduled, alert)) = self.watched.filter(|w| w.0 == t && more) {
            self.watched = None;
            let x = self.x.clone();
            if let Some(next) = self.examine_step(t, &x, (scheduled, alert), summary)? {
                return Ok(next);
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

/// The energy the run keeps as an invariant ([`crate::solve::formulation::EnergyInvariant`]): `E(q₀, v₀)`
/// where the mechanism conserves its energy (no load does work, no spring damps, `E` does not
/// depend on time) and moves (it is not at rest in an equilibrium, where `dE/dμ = 0`), unless
/// the options switch it off; `None` otherwise.
fn kept_energy(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    (t0, x): (f64, &[f64]),
    init: &ConsistentState,
    opts: &SolveOptions,
) -> Option<f64> {
    if opts.energy_invariant == Some(false)
        || sys.energy_exchange.is_some()
        || sys.graph.depends_on(sys.energy, 0)
    {
        return None;
    }
    // at rest in an equilibrium nothing moves and the multiplier has no grip
    let moving = init
        .v
        .iter()
        .chain(&init.vdot)
        .zip(sys.mass.iter().chain(&sys.mass))
        .any(|(a, &m)| m != 0.0 && a.abs() > AT_REST);
    if !moving {
        return None;
    }
    let outputs = MechanicsTapes::eval(&tapes.outputs, t0, x);
    let e0 = outputs[outputs.len() - 2];
    e0.is_finite().then_some(e0)
}

/// `(η, κ)` of the energy invariant at `(t, x)` ([`crate::solve::formulation::EnergyInvariant`]):
/// `G_v[R, D]ᵀ η = ∂E/∂v_D`, then `G_q[R, D_q]ᵀ κ = h_D` with `h = ∂E/∂q − (∂(G_v v)/∂q)ᵀ η`
/// (zeros where a block is singular: IDA's first Newton iteration then finds them).
fn energy_multipliers(
    sys: &mut MultibodySystem,
    c: &ConstraintExprs,
    (t, x): (f64, &[f64]),
    (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
) -> Vec<f64> {
    let r = rows.len();
    let energy = sys.energy;
    let nq = sys.nq();
    let v_slots: Vec<u32> = dependent.iter().map(|&j| sys.v_slot(j)).collect();
    let g = &mut sys.graph;
    // outputs: ∂E/∂v_D (r), ∂E/∂q_D (r), G_v[R, D] (r×r), G_q[R, D_q] (r×r),
    // ∂(G_v v)_R/∂q_D (r×r), row-major
    let mut exprs = Vec::with_capacity(2 * r + 3 * r * r);
    // ∂E/∂v_D and ∂E/∂q_D in one reverse sweep
    let slots: Vec<u32> = v_slots
        .iter()
        .copied()
        .chain(coordinates.iter().map(|&i| (1 + i) as u32))
        .collect();
    exprs.extend(g.gradient(energy, &slots));
    for &rk in rows {
        exprs.extend(dependent.iter().map(|&j| c.gv[rk][j]));
    }
    for &rk in rows {
        exprs.extend(coordinates.iter().map(|&i| c.gq[rk][i]));
    }
    for &rk in rows {
        for &i in coordinates {
            exprs.push(g.diff(c.gvv[rk], (1 + i) as u32));
        }
    }
    let vals = MechanicsTapes::eval(&g.compile(&exprs), t, x);
    debug_assert_eq!(vals.len(), 2 * r + 3 * r * r);
    let _ = nq;
    let at = |base: usize, k: usize, a: usize| vals[base + k * r + a];
    let (dv, dq) = (&vals[..r], &vals[r..2 * r]);
    let (b_gv, b_gq, b_dq) = (2 * r, 2 * r + r * r, 2 * r + 2 * r * r);
    // (G_v[R, D])ᵀ η = ∂E/∂v_D
    let gvt = DMatrix::from_fn(r, r, |a, k| at(b_gv, k, a));
    let eta = gvt
        .lu()
        .solve(&nalgebra::DVector::from_column_slice(dv))
        .unwrap_or_else(|| nalgebra::DVector::zeros(r));
    // h_D = ∂E/∂q_D − (∂(G_v v)_R/∂q_D)ᵀ η;  (G_q[R, D_q])ᵀ κ = h_D
    let h = nalgebra::DVector::from_fn(r, |a, _| {
        dq[a] - (0..r).map(|k| at(b_dq, k, a) * eta[k]).sum::<f64>()
    });
    let gqt = DMatrix::from_fn(r, r, |a, k| at(b_gq, k, a));
    let kappa = gqt
        .lu()
        .solve(&h)
        .unwrap_or_else(|| nalgebra::DVector::zeros(r));
    eta.iter().chain(kappa.iter()).copied().collect()
}

/// The index-1 DAE of `sys` from the consistent start `init` (`summary.formulation`: `index1`,
/// or `dae`, which hands over to the GGL), with its rows and events. The causality's partition
/// is the first choice of the dependent velocities, unless its block is ill-conditioned at the
/// start and a numeric choice is much better.
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
    summary.solver = "IDA".into();
    let causal = CausalPartition::new(&sys, t0);
    // redundant joints: the rows the causality names redundant are left out of the dependent
    // block (the others, a maximal independent set, determine the motion)
    let mut redundant = (!init.redundant_joints.is_empty())
        .then(|| (nc - init.rank.min(nc), causal.redundant_rows(&sys.rows)));
    let mut full = redundant.as_ref().map(|_| tapes.gv.matrix(t0, &x));
    let mut joint_rows: Vec<usize> = match (&redundant, &full) {
        (Some((d, hint)), Some(full)) => {
            independent_rows(full, *d, hint).unwrap_or_else(|| (0..nc).collect())
        }
        _ => (0..nc).collect(),
    };
    // a loss of rank at the start's configuration only (a four-bar started on its aligned
    // configuration) is a singular configuration, not redundant joints: the rows left out
    // would be violated as soon as the mechanism moves (issue 34: 0.31 m on such a four-bar)
    let singular_start = redundant.is_some()
        && starts_singular(
            &summary.formulation.clone(),
            &tapes,
            (t0, &x),
            &joint_rows,
            init,
            summary,
        );
    if singular_start {
        (redundant, full, joint_rows) = (None, None, (0..nc).collect());
    }
    let r = joint_rows.len();
    if redundant.is_some() {
        let w = redundant_rows_warning(&summary.formulation, &sys, &joint_rows, t0, init);
        summary.warnings.push(w);
    }
    // y = [q, v, a_D, λ]
    let multipliers = Multipliers::Unknowns(nq + nv + r);
    let rows = OutputEval::new(sys.clone(), tapes.clone(), &multipliers);
    let events = crate::solve::formulation::shared::events(
        &sys,
        &tapes,
        &crate::solve::formulation::shared::solved_multipliers(&sys, &tapes),
    );
    let mut y_first = x.clone();
    y_first.extend(std::iter::repeat_n(0.0, r));
    match &full {
        Some(full) => y_first.extend(multipliers_on_rows(full, &init.lambda, &joint_rows)),
        None => y_first.extend(&init.lambda),
    }
    let hands_over = summary.formulation == "dae";
    let mut gv = match &full {
        Some(full) => JointRows::from_dense(rows_of(full, &joint_rows)),
        None => JointRows::new(&tapes.gv, t0, &x),
    };
    // the chapter's partition at the start: the differential-causality inertias' flows
    // (kept unless its block is ill-conditioned there and a numeric choice is much better;
    // no choice can be INDEX1_RESELECT_GAIN times better when the causality's block is within
    // that factor of the bound κ(G_v) ≤ μ(D) of every block: then no numeric choice is made)
    let causality_block = causal.dependent().filter(|_| !singular_start).map(|d| {
        let cond = gv.dependent_condition(&d);
        (d, cond)
    });
    let from_causality = causality_block.as_ref().and_then(|(d, cond)| {
        let keep = PartitionPolicy::well_conditioned(*cond)
            || gv.no_block_much_better(*cond, INDEX1_RESELECT_GAIN)
            || select_dependent(gv.dense(), &causal.preferred_at(t0, &x[..nq]))
                .is_none_or(|b| PartitionPolicy::keeps_against(gv.dependent_condition(&b), *cond));
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
    if from_causality.is_none() && !sys.inertias.is_empty() && !singular_start {
        let w = crate::partition::causal::not_regular_warning(&summary.formulation, t0);
        summary.warnings.push(w);
    }
    let grip = BlockGrip::new(&tapes);
    let (energy_e0, energy_watch) = match kept_energy(&sys, &tapes, (t0, &x), init, opts) {
        Some(e0) if opts.energy_invariant == Some(true) => (Some(e0), None),
        Some(e0) => {
            let mut exprs = vec![sys.energy, sys.kinetic];
            let slots: Vec<u32> = (1..=(nq + nv) as u32).collect();
            exprs.extend(sys.graph.gradient(sys.energy, &slots));
            let tape = sys.graph.compile(&exprs);
            let ek = MechanicsTapes::eval(&tape, t0, &x);
            let t_end = opts.output_times.last().copied().unwrap_or(t0);
            let spacing = (t_end - t0) / ENERGY_READS;
            (
                None,
                (spacing > 0.0).then(|| EnergyWatch {
                    work: tape.workspace(),
                    out: vec![0.0; tape.n_outputs()],
                    tape,
                    e_start: e0,
                    t_start: t0,
                    kinetic_max: ek[1],
                    gradient_max: ek[2..].iter().map(|d| d.abs()).sum(),
                    next_read: t0 + spacing,
                    pending: false,
                    spacing,
                }),
            )
        }
        None => (None, None),
    };
    summary.energy_invariant = energy_e0.is_some();
    Job {
        formulation: Box::new(Index1 {
            hints: SpectralHints::default(),
            built: Vec::new(),
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
            rows: joint_rows,
            redundant,
            from_causality: from_causality.map(|(d, _)| d),
            watch,
            hands_over,
            reselections: 0,
            y_first,
            grip,
            restarted_at: None,
            examined_q: Vec::new(),
            watched: None,
            kept_grip: (0.0, 0.0),
            moot_reference: None,
            moot_buffers: MootBuffers::default(),
            block_lus: BlockLus::default(),
            energy_e0,
            energy_watch,
            energy_due: None,
        }),
        rows: Box::new(rows),
        events,
    }
}
