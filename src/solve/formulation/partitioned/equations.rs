//! The partitioned formulation: the seed's degrees of freedom as the ODE states.
//!
//! The chapter's causality assignment splits the inertias into integral-causality ones (the
//! degrees of freedom) and differential-causality ones (dependent: their flows are fixed by the
//! joints). Numerically the split is a choice of `nc` *dependent* columns of `G_q` (coordinates
//! `q_D`) and of `G_v` (velocities `v_D`) whose square blocks are well conditioned, made by a
//! column-pivoted Gram–Schmidt ([`select_dependent`], the rank-revealing QR of the joints'
//! Jacobian) at the current state. The ODE state is `y = [q_I, v_I]`, and each right-hand side
//!
//! ```text
//!   g(q_I, q_D) = 0                      Newton for q_D (warm-started, tolerance ≪ the integrator's)
//!   G_D v_D = −G_I v_I                   dependent velocities (G_v = [G_I G_D] at q)
//!   v' = R a_I + s,  R = [I; −G_D⁻¹G_I],  s = [0; −G_D⁻¹γ]
//!   (M_I + Bᵀ M_D B) a_I = Q_I − Bᵀ (Q_D + M_D c),   B = G_D⁻¹G_I,  c = G_D⁻¹γ
//!   y' = [(K(q) v)_I, a_I]
//! ```
//!
//! which are the reduced (Maggi/Kane) equations `Rᵀ(M v' − Q) = 0` with `G_v v' + γ = 0`; one LU
//! factorisation of `G_D` serves the velocities, `B`, `c` and the multipliers
//! `G_Dᵀ λ = Q_D − M_D a_D`. `G_D` is factorised along its sparsity pattern with a pivot order
//! kept between calls ([`crate::dae::block_lu`]), and so is the reduced mass matrix (`|v_I|`
//! square, dense pattern): no allocation per call, where nalgebra's decompositions take their
//! matrix by value.

// the dense kernels index row-major matrices and several vectors with the same loop variable
#![allow(clippy::needless_range_loop)]

use std::sync::Arc;

use nalgebra::DMatrix;

use super::elimination::{Elimination, EliminationInputs};
use crate::dae::block_lu::BlockLu;
use crate::dae::mechanics::{slots, ConstraintExprs, MatrixTape};
use crate::expr::{Expr, ExprGraph, StagedTape, Tape};
use crate::mech::MultibodySystem;
use crate::partition::coordinates::{left_branch, tangent_step, NewtonLimits};
pub use crate::partition::coordinates::{Partition, PartitionError};
use crate::partition::{dependent_condition, select_dependent};

/// The compiled pieces of a multibody system that every partition shares.
#[derive(Clone, Debug)]
pub struct PartitionedSystem {
    /// `(nq, nv, nc)`.
    pub dims: (usize, usize, usize),
    /// `[g, G_q's structural non-zeros]` over `[t, q, v]`.
    pos: Tape,
    /// `(row, coordinate)` of each compiled entry of `G_q` (they follow the `nc` values of `g`).
    gq_entries: Vec<(usize, usize)>,
    /// The variables (slots of `[t, q, v]`) each entry of `gq_entries` mentions.
    gq_vars: Vec<Vec<u32>>,
    /// `G_v` (its structural non-zeros), evaluated row-major `nc × nv`.
    gv: MatrixTape,
    /// `b = ∂g/∂t` of the rheonomic rows (drivers): `G_v v + b = 0`; `None` without them.
    bias: Option<Tape>,
    /// The expressions every partition's staged tape compiles: `[g, G_q's non-zeros]` then
    /// `[Q, γ, K(q) v]`, over the system's expression graph.
    graph: ExprGraph,
    all: Vec<Expr>,
    /// Diagonal of `M`.
    mass: Vec<f64>,
    /// The switching functions of the loads' non-smooth operations (`expr::switches`), over
    /// `[t, q, v, modes]`, and their tape.
    switching: Vec<Expr>,
    switch_tape: Tape,
    /// `q' = v` (then the dependent coordinates are the dependent velocities).
    identity_kinematics: bool,
    /// `q' = v` and the velocity rows are `G_q v` term by term (the same expressions: `G_v`
    /// is `G_q`, the velocity rows `d/dt g`): one factorisation of `G_q[:, D]` serves both
    /// levels. Flow rows written otherwise (e.g. in a body's axes, `T(q) G_q v`) have their own
    /// `G_v` and `γ`, and keep their own tape.
    gv_is_gq: bool,
    /// Coordinates preferred as dependent (translations, as the seed's causality picks them).
    preferred_q: Vec<bool>,
    /// Redundant joints: the rows kept (an independent set, [`crate::partition::independent_rows`]) and
    /// the number of all rows; the multipliers of the rows left out are reported as zero.
    kept_rows: Option<(Vec<usize>, usize)>,
}

impl PartitionedSystem {
    /// The system on the joint rows `kept` only, where the joints are redundant (`kept` an
    /// independent set of rows, [`crate::partition::independent_rows`]): the rows left out follow from
    /// the kept ones, so the dependent block is square on `kept`; the multipliers of the rows
    /// left out are zero in [`PartitionedRhs::full_with_multipliers`] (their reactions are not
    /// determined by the motion).
    pub fn on_rows(sys: &mut MultibodySystem, c: &ConstraintExprs, kept: Vec<usize>) -> Self {
        let full = c.g.len();
        let mut s = Self::new(sys, &c.keep_rows(&kept));
        s.kept_rows = Some((kept, full));
        s
    }

    /// The joint rows kept and the number of all rows, where the joints are redundant.
    pub fn kept_rows(&self) -> Option<&(Vec<usize>, usize)> {
        self.kept_rows.as_ref()
    }

    /// Compiles the tapes from the system and its constraint calculus.
    pub fn new(sys: &mut MultibodySystem, c: &ConstraintExprs) -> Self {
        let (nq, nv, nc) = (sys.nq(), sys.nv(), c.g.len());
        let identity_kinematics = nq == nv
            && (0..nq).all(|i| {
                let s = sys.v_slot(i);
                let v = sys.graph.var(s);
                sys.kinematics[i] == v
            });
        // a rheonomic row's velocity level is `G_v v + b`, not `G_q v`: no shared elimination
        let rheonomic = c.bias.iter().any(|&b| !sys.graph.is_zero(b));
        let gv_is_gq = identity_kinematics && c.gq == c.gv && !rheonomic;
        let mut pos: Vec<Expr> = c.g.clone();
        let mut gq_entries = Vec::new();
        let mut gq_vars = Vec::new();
        for (k, row) in c.gq.iter().enumerate() {
            for (i, &e) in row.iter().enumerate() {
                if !sys.graph.is_zero(e) {
                    gq_entries.push((k, i));
                    gq_vars.push(sys.graph.vars(e));
                    pos.push(e);
                }
            }
        }
        let mut all = pos.clone();
        // the loads' non-smooth operations held by mode variables after [t, q, v]
        let frozen = sys.graph.freeze_switches(&sys.forces, (1 + nq + nv) as u32);
        all.extend(&frozen.exprs);
        all.extend(&c.gamma);
        all.extend(&sys.kinematics);
        PartitionedSystem {
            dims: (nq, nv, nc),
            pos: sys.graph.compile(&pos),
            gq_entries,
            gq_vars,
            gv: MatrixTape::new(&sys.graph, &c.gv, nv),
            bias: rheonomic.then(|| sys.graph.compile(&c.bias)),
            switch_tape: sys.graph.compile(&frozen.switching),
            switching: frozen.switching.clone(),
            graph: sys.graph.clone(),
            all,
            mass: sys.mass.clone(),
            identity_kinematics,
            gv_is_gq,
            preferred_q: crate::partition::coordinates::preferred_coordinates(sys),
            kept_rows: None,
        }
    }

    /// What the symbolic elimination needs ([`super::elimination`]), where it applies: one
    /// factorisation serves both levels (`q' = v`, velocity rows `G_q v`).
    fn elimination_inputs(&self) -> Option<EliminationInputs<'_>> {
        let (_, nv, nc) = self.dims;
        let n_pos = self.pos.n_outputs();
        self.gv_is_gq.then(|| EliminationInputs {
            graph: &self.graph,
            g: &self.all[..nc],
            forces: &self.all[n_pos..n_pos + nv],
            mass: &self.mass,
            n_modes: self.switching.len(),
            switching: &self.switching,
        })
    }

    /// Number of switching functions (non-smooth operations in the loads).
    pub fn n_switches(&self) -> usize {
        self.switching.len()
    }

    /// `G_q` and `G_v` at `(t, x = [q, v])`.
    pub fn jacobians(&self, t: f64, x: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let (nq, _, nc) = self.dims;
        let vars = slots(t, x);
        let mut out = vec![0.0; self.pos.n_outputs()];
        self.pos.eval(&vars, &mut self.pos.workspace(), &mut out);
        let mut gq = DMatrix::zeros(nc, nq);
        for (&(k, i), &v) in self.gq_entries.iter().zip(&out[nc..]) {
            gq[(k, i)] = v;
        }
        (gq, self.gv.matrix(t, x))
    }

    /// The numeric causality choice at `(t, x)`: dependent columns of `G_q` and `G_v` by
    /// column-pivoted Gram–Schmidt (translations first, as the seed's differential causality
    /// picks them). `None` when `G_v` or `G_q` has lower rank than its number of rows (a
    /// singular configuration: no partition exists).
    pub fn choose(&self, t: f64, x: &[f64], preferred_v: &[bool]) -> Option<Partition> {
        let (nq, nv, _) = self.dims;
        let (gq, gv) = self.jacobians(t, x);
        let dep_v = select_dependent(&gv, preferred_v)?;
        let dep_q = if self.identity_kinematics {
            dep_v.clone()
        } else {
            select_dependent(&gq, &self.preferred_q)?
        };
        Some(Partition::of_dependent((nq, nv), dep_q, dep_v))
    }

    /// The partition whose dependent velocities are `dep_v` (the causality's differential
    /// inertias, [`crate::bond::causality`]): the dependent coordinates are the same indices
    /// where `q' = v`, else the numeric choice on `G_q`. `None` when `dep_v` is not one
    /// velocity per row or `G_q` has no regular block.
    pub fn with_dependent_velocities(
        &self,
        t: f64,
        x: &[f64],
        dep_v: Vec<usize>,
    ) -> Option<Partition> {
        let (nq, nv, nc) = self.dims;
        if dep_v.len() != nc || dep_v.iter().any(|&j| j >= nv) {
            return None;
        }
        let dep_q = if self.identity_kinematics {
            dep_v.clone()
        } else {
            let (gq, _) = self.jacobians(t, x);
            select_dependent(&gq, &self.preferred_q)?
        };
        Some(Partition::of_dependent((nq, nv), dep_q, dep_v))
    }

    /// Condition number (2-norm) of the dependent blocks of `G_q` and `G_v` (the larger) at
    /// `(t, x)`.
    pub fn condition(&self, p: &Partition, t: f64, x: &[f64]) -> f64 {
        let (gq, gv) = self.jacobians(t, x);
        dependent_condition(&gq, &p.dep_q).max(dependent_condition(&gv, &p.dep_v))
    }
}

/// Largest Newton iterations per right-hand side.
pub const MAX_NEWTON_ITERATIONS: usize = 8;

/// Newton iterations allowed when completing an output row (an output between two accepted
/// steps may lie further from the last evaluation than the integrator's stages do).
pub const OUTPUT_NEWTON_ITERATIONS: usize = 30;

/// The right-hand side of the partitioned ODE for one partition, with its workspace and the
/// warm start of the dependent coordinates.
#[derive(Clone, Debug)]
pub struct PartitionedRhs {
    sys: Arc<PartitionedSystem>,
    /// The partition.
    pub part: Partition,
    /// Newton's absolute tolerance on the dependent coordinates.
    pub newton_tol: f64,
    /// Condition estimate (largest over smallest |pivot| of `G_D`'s LU) above which the
    /// right-hand side fails with [`PartitionError::Repartition`]; infinite: never.
    pub repartition_above: f64,
    /// Newton iterations allowed per evaluation ([`MAX_NEWTON_ITERATIONS`] by default).
    pub max_newton: usize,
    /// `(t, y)` of the last completed evaluation (whose full state `vars` holds), when valid.
    last_t: f64,
    last_y: Vec<f64>,
    last_valid: bool,
    vars: Vec<f64>,
    /// `[g, G_q's non-zeros]` on one tape in two stages: `(t, q_I)` (fixed during a call: the
    /// independent angles' sines and cosines once), `q_D` (each Newton iteration); its
    /// outputs.
    staged: Arc<StagedTape>,
    w_st: Vec<f64>,
    o_st: Vec<f64>,
    /// `[Q, γ, K(q) v]`, evaluated once per call at the converged state (apart from Newton's
    /// tape: in 3D most of `γ` depends on the dependent angles, and re-running it with every
    /// Newton iteration made the spatial slider-crank's right-hand side 3× dearer); outputs.
    dynamics: Arc<Tape>,
    w_dyn: Vec<f64>,
    o_dyn: Vec<f64>,
    /// Stage 0 of `staged` is current for this call's `(t, q_I)`.
    stage0_valid: bool,
    w_gv: (Vec<f64>, Vec<f64>),
    /// LU of `G_q[:, D]` (its entries read from `o_pos`).
    jq: BlockLu,
    /// `G_q[:, I]` (row-major `nc × |q_I|`), gathered by `bq_map` (`(o_pos index, bq index)`).
    bq: Vec<f64>,
    bq_map: Vec<(usize, usize)>,
    /// LU of `G_v[:, D]` (its entries read from `G_v`'s non-zeros), unless `share`.
    jv: BlockLu,
    /// `G_v[:, I]` (gathered by `bv_map`), then overwritten by `B = G_D⁻¹ G_I`.
    bv: Vec<f64>,
    bv_map: Vec<(usize, usize)>,
    /// The velocity level uses `jq` (`G_v = G_q` and the same dependent columns).
    share: bool,
    /// The joints are affine in the dependent coordinates: `G_q[:, D]` is constant and
    /// `G_q[:, I]` does not mention `q_D` (translations dependent, as the seed's causality
    /// picks them, on pin joints). One Newton step from any point is then exact, and `G_D`
    /// is factorised once.
    linear: bool,
    /// `G_D⁻¹` (row-major) when `G_D` is constant and shared by both levels: its solves are
    /// then products (empty otherwise).
    dep_inverse: Vec<f64>,
    /// Scratch of `nc` values for the products.
    scratch: Vec<f64>,
    /// `b = ∂g/∂t` of the rheonomic rows at the last [`eval_bias`], and the
    /// workspace of its tape (empty without rheonomic rows): no allocation in the right-hand
    /// side.
    bias_out: Vec<f64>,
    bias_work: Vec<f64>,
    /// Workspace of the switching functions' tape.
    w_switch: Vec<f64>,
    /// `[q, v, λ]` of [`Self::full_with_multipliers`], and its right-hand side's buffer.
    with_multipliers: Vec<f64>,
    yd: Vec<f64>,
    /// `q_I` of the last converged call (for the tangent predictor).
    qi_prev: Vec<f64>,
    /// The time of `qi_prev` (the last converged position solve).
    t_prev: f64,
    have_prev: bool,
    /// `bv` holds `B = G_D⁻¹ G_I` of the last completed call (else the raw `G_v[:, I]`).
    b_ready: bool,
    /// `c = G_D⁻¹ γ` of the last right-hand side is there (kept through completions for
    /// outputs and events in between: the predictor's curvature term, a step away at most).
    c_ready: bool,
    /// Predicted dependent coordinates (the branch check's reference).
    pred: Vec<f64>,
    /// `M̂ = M_I + Bᵀ M_D B` (dense row-major) and its LU.
    mhat: Vec<f64>,
    mhat_lu: BlockLu,
    tmp: Vec<f64>,
    c: Vec<f64>,
    /// Accelerations `v'` of the last call (all velocities).
    pub acc: Vec<f64>,
    /// Newton iterations on the full block so far ([`Self::newton_iterations`] adds the
    /// elimination's).
    newton_iterations: u64,
    /// Condition estimate of the last `G_v[:, D]` factorised on the full block
    /// ([`Self::condition_estimate`] reads the elimination's when it runs).
    condition_estimate: f64,
    /// Condition estimate of the last `G_q[:, D]` factorised (Newton's last iteration).
    condition_q: f64,
    /// The dependent coordinates affine in their rows eliminated symbolically
    /// ([`super::elimination`]): the right-hand side then runs on the reduced coordinates, and
    /// the block path above only serves the multipliers.
    elim: Option<Box<Elimination>>,
}

impl PartitionedRhs {
    /// The right-hand side for partition `part`, warm-started at the full state `x = [q, v]`.
    pub fn new(sys: Arc<PartitionedSystem>, part: Partition, x: &[f64], newton_tol: f64) -> Self {
        let (nq, nv, nc) = sys.dims;
        let (niq, niv) = (part.ind_q.len(), part.ind_v.len());
        let ns = sys.n_switches();
        // [t, q, v, modes]: every mode 0 (the literal operations) until `set_modes`
        let mut vars = vec![0.0; 1 + nq + nv + ns];
        vars[1..=nq + nv].copy_from_slice(&x[..nq + nv]);
        // where each column sits in the dependent (Ok) or independent (Err) list
        let place = |n: usize, dep: &[usize], ind: &[usize]| {
            let mut at = vec![Ok(0); n];
            for (a, &i) in dep.iter().enumerate() {
                at[i] = Ok(a);
            }
            for (l, &i) in ind.iter().enumerate() {
                at[i] = Err(l);
            }
            at
        };
        let at_q = place(nq, &part.dep_q, &part.ind_q);
        let dep_slot: Vec<u32> = part.dep_q.iter().map(|&i| 1 + i as u32).collect();
        let stage_of = |v: u32| match v as usize {
            0 => 0,
            k if k <= nq => usize::from(at_q[k - 1].is_ok()),
            k if k <= nq + nv => 2,
            _ => 0,
        };
        let n_pos = sys.pos.n_outputs();
        let staged = Arc::new(sys.graph.compile_staged(&sys.all[..n_pos], &stage_of, 2));
        let dynamics = Arc::new(sys.graph.compile(&sys.all[n_pos..]));
        let linear = sys
            .gq_entries
            .iter()
            .zip(&sys.gq_vars)
            .all(|(&(_, i), vars)| match at_q[i] {
                Ok(_) => vars.is_empty(),
                Err(_) => !vars.iter().any(|v| dep_slot.contains(v)),
            });
        let (mut jq_entries, mut bq_map) = (Vec::new(), Vec::new());
        for (e, &(k, i)) in sys.gq_entries.iter().enumerate() {
            match at_q[i] {
                Ok(a) => jq_entries.push((k, a, nc + e)),
                Err(l) => bq_map.push((nc + e, k * niq + l)),
            }
        }
        let at_v = place(nv, &part.dep_v, &part.ind_v);
        let (mut jv_entries, mut bv_map) = (Vec::new(), Vec::new());
        for (e, &p) in sys.gv.positions().iter().enumerate() {
            let (k, j) = (p / nv, p % nv);
            match at_v[j] {
                Ok(a) => jv_entries.push((k, a, e)),
                Err(l) => bv_map.push((e, k * niv + l)),
            }
        }
        let elim = sys
            .elimination_inputs()
            .and_then(|inp| Elimination::new(&inp, &part, x))
            .map(Box::new);
        PartitionedRhs {
            elim,
            w_switch: sys.switch_tape.workspace(),
            w_st: staged.workspace(),
            o_st: vec![0.0; staged.tape().n_outputs()],
            stage0_valid: false,
            staged,
            w_dyn: dynamics.workspace(),
            o_dyn: vec![0.0; dynamics.n_outputs()],
            dynamics,
            w_gv: sys.gv.workspace(),
            jq: BlockLu::new(nc, jq_entries),
            bq: vec![0.0; nc * niq],
            bq_map,
            jv: BlockLu::new(nc, jv_entries),
            bv: vec![0.0; nc * niv],
            bv_map,
            share: sys.gv_is_gq && part.dep_q == part.dep_v,
            linear,
            dep_inverse: Vec::new(),
            scratch: vec![0.0; nc],
            bias_out: vec![0.0; if sys.bias.is_some() { nc } else { 0 }],
            bias_work: sys.bias.as_ref().map_or_else(Vec::new, |b| b.workspace()),
            with_multipliers: Vec::with_capacity(nq + nv + nc),
            yd: vec![0.0; niq + niv],
            qi_prev: vec![0.0; niq],
            t_prev: f64::NAN,
            have_prev: false,
            b_ready: false,
            c_ready: false,
            pred: vec![0.0; nc],
            mhat: vec![0.0; niv * niv],
            mhat_lu: BlockLu::new(niv, (0..niv * niv).map(|k| (k / niv, k % niv, k)).collect()),
            tmp: vec![0.0; nc.max(niv)],
            c: vec![0.0; nc],
            acc: vec![0.0; nv],
            newton_iterations: 0,
            condition_estimate: 1.0,
            condition_q: 1.0,
            repartition_above: f64::INFINITY,
            max_newton: MAX_NEWTON_ITERATIONS,
            last_t: f64::NAN,
            last_y: vec![0.0; niq + niv],
            last_valid: false,
            vars,
            part,
            newton_tol,
            sys,
        }
    }

    /// The full state `[q, v]` of the last evaluation.
    pub fn full_state(&self) -> &[f64] {
        let (nq, nv, _) = self.sys.dims;
        &self.vars[1..=nq + nv]
    }

    /// The modes of the switching functions (`expr::switches`: +1, −1, or 0 for the literal
    /// operation).
    pub fn modes(&self) -> &[f64] {
        let (nq, nv, _) = self.sys.dims;
        &self.vars[1 + nq + nv..]
    }

    /// Holds the loads' non-smooth operation `k` in `mode` (see [`Self::modes`]).
    pub fn set_mode(&mut self, k: usize, mode: f64) {
        let (nq, nv, _) = self.sys.dims;
        self.vars[1 + nq + nv + k] = mode;
        if let Some(e) = self.elim.as_deref_mut() {
            e.set_mode(k, mode);
        }
        self.stage0_valid = false;
        self.last_valid = false;
    }

    /// The switching functions at `(t, y)` (the root functions of the loads' switches): read
    /// from the last right-hand side when it was evaluated there (an explicit step's last
    /// stage), else from the completed state.
    pub fn switching_at(
        &mut self,
        t: f64,
        y: &[f64],
        out: &mut [f64],
    ) -> Result<(), PartitionError> {
        if let Some(e) = self.elim.as_deref() {
            if e.switching_at(t, y, out) {
                return Ok(());
            }
        }
        self.complete_for_output(t, y)?;
        self.switching_values(out);
        Ok(())
    }

    /// The switching functions at the last completed state and the current modes.
    pub fn switching_values(&mut self, out: &mut [f64]) {
        self.sys
            .switch_tape
            .eval(&self.vars, &mut self.w_switch, out);
    }

    /// Works on the full dependent block only (no symbolic elimination): the reference the
    /// elimination is checked against, and the `partitioned_elimination = false` option.
    pub fn without_elimination(mut self) -> Self {
        self.elim = None;
        self
    }

    /// `(|z|, |q_R|)`: the reduced coordinates and the loop closures left implicit, when the
    /// symbolic elimination applies ([`super::elimination`]).
    pub fn elimination(&self) -> Option<(usize, usize)> {
        self.elim.as_ref().map(|e| e.sizes())
    }

    fn limits(&self) -> NewtonLimits {
        NewtonLimits {
            tolerance: self.newton_tol,
            max_iterations: self.max_newton,
            repartition_above: self.repartition_above,
        }
    }

    /// Condition estimate of the last factorisation of the dependent block (largest over
    /// smallest pivot): the elimination's when it runs, else `G_v[:, D]`'s.
    pub fn condition_estimate(&self) -> f64 {
        self.elim
            .as_ref()
            .map_or(self.condition_estimate, |e| e.condition_estimate)
    }

    /// Newton iterations so far (on the full block and on the loop closures).
    pub fn newton_iterations(&self) -> u64 {
        self.newton_iterations + self.elim.as_ref().map_or(0, |e| e.newton_iterations)
    }

    /// Solves `g(q) = 0` for the dependent coordinates with `q_I = y[..|q_I|]`, from the warm
    /// start, and factorises `G_q[:, D]` (Newton with the exact Jacobian; a tangent predictor
    /// `Δq_D = −G_D⁻¹ G_I Δq_I` from the last converged call starts it).
    fn positions(&mut self, t: f64, y: &[f64]) -> Result<(), PartitionError> {
        let (nq, _, nc) = self.sys.dims;
        let (dq, iq) = (&self.part.dep_q, &self.part.ind_q);
        let niq = iq.len();
        self.vars[0] = t;
        self.stage0_valid = false;
        // size of the tangent prediction, and whether the Newton correction is checked against it
        let mut predicted = 0.0f64;
        let mut checked = false;
        if self.linear && nc > 0 {
            return self.linear_positions(t, y);
        }
        if self.have_prev && nc > 0 {
            // tangent predictor Δq_D = −G_D⁻¹ G_I Δq_I: with `B = G_D⁻¹ G_I` of the last call
            // when G_v = G_q (no solve), else with the last factorisation of G_q[:, D]
            if self.share && self.b_ready {
                let v = self.part.ind_v.iter().map(|&j| self.vars[1 + nq + j]);
                tangent_step(
                    &self.bv,
                    self.c_ready.then_some(&self.c[..]),
                    &y[..niq],
                    &self.qi_prev,
                    v,
                    &mut self.tmp[..nc],
                );
            } else {
                for k in 0..nc {
                    let mut s = 0.0;
                    for l in 0..niq {
                        s += self.bq[k * niq + l] * (y[l] - self.qi_prev[l]);
                    }
                    self.tmp[k] = s;
                }
                // rheonomic rows (drivers) move with time too: G_D Δq_D = −(G_I Δq_I + g_t Δt),
                // `g_t` at the last solve (with no DOF left, that is the whole prediction)
                if self.t_prev.is_finite() {
                    let dt = t - self.t_prev;
                    self.vars[0] = self.t_prev;
                    if eval_bias(
                        &self.sys,
                        &self.vars,
                        &mut self.bias_work,
                        &mut self.bias_out,
                    ) {
                        for k in 0..nc {
                            self.tmp[k] += self.bias_out[k] * dt;
                        }
                    }
                    self.vars[0] = t;
                }
                self.jq.solve(&mut self.tmp[..nc]);
            }
            for (k, &i) in dq.iter().enumerate() {
                self.vars[1 + i] -= self.tmp[k];
                predicted = predicted.max(self.tmp[k].abs());
            }
            for (k, &i) in dq.iter().enumerate() {
                self.pred[k] = self.vars[1 + i];
            }
            checked = true;
        }
        for (l, &i) in iq.iter().enumerate() {
            self.vars[1 + i] = y[l];
        }
        if nc == 0 {
            return Ok(());
        }
        let mut last = f64::INFINITY;
        for it in 0..self.max_newton {
            self.newton_iterations += 1;
            // (t, q_I) is fixed over the iterations: stage 0 once
            let first = if it == 0 { 0 } else { 1 };
            self.staged
                .eval_stages(&self.vars, &mut self.w_st, &mut self.o_st, first..2);
            self.stage0_valid = true;
            self.tmp[..nc].copy_from_slice(&self.o_st[..nc]);
            for &(s, d) in &self.bq_map {
                self.bq[d] = self.o_st[s];
            }
            let Ok(ratio) = self.jq.factor(&self.o_st, self.repartition_above) else {
                self.have_prev = false;
                return Err(PartitionError::SingularBlock { t });
            };
            self.condition_q = ratio;
            self.jq.solve(&mut self.tmp[..nc]);
            let mut step = 0.0f64;
            for (k, &i) in dq.iter().enumerate() {
                self.vars[1 + i] -= self.tmp[k];
                step = step.max(self.tmp[k].abs());
            }
            if !step.is_finite() {
                break;
            }
            last = step;
            // the correction cannot fall below the rounding of `g` amplified by the block:
            // `ratio` (its pivot ratio) ulp of the dependent coordinates. Regression: the
            // change-point four-bar at rtol 1e-10 stopped at t = 2.86 with a last correction
            // of 1.65e-14 against a tolerance of 1e-14, the block's ratio about 1e2 there.
            let size = dq
                .iter()
                .fold(0.0f64, |m, &i| m.max(self.vars[1 + i].abs()));
            if step <= self.newton_tol.max(4.0 * f64::EPSILON * ratio * size) {
                if checked {
                    // Newton must stay near the tangent prediction: a correction comparable to
                    // the prediction itself means the step crossed to another branch of the
                    // joints' solutions (near a bifurcation): retry with a smaller step
                    let corr = dq.iter().enumerate().fold(0.0f64, |a, (k, &i)| {
                        a.max((self.vars[1 + i] - self.pred[k]).abs())
                    });
                    let moved = y[..niq]
                        .iter()
                        .zip(&self.qi_prev)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    if left_branch(corr, predicted, moved, self.newton_tol) {
                        self.have_prev = false;
                        return Err(PartitionError::Branch {
                            t,
                            correction: corr,
                            predicted,
                        });
                    }
                }
                self.qi_prev.copy_from_slice(&y[..niq]);
                self.t_prev = t;
                self.have_prev = true;
                return Ok(());
            }
        }
        self.have_prev = false;
        Err(PartitionError::Newton {
            t,
            correction: last,
        })
    }

    /// [`Self::positions`] for joints affine in `q_D`: `g(q_I, q_D + Δ) = g + G_D Δ`, so one
    /// Newton step `Δ = −G_D⁻¹ g` from the last point is the solution (to rounding), and
    /// `G_q` there equals `G_q` at the last point (`G_D` constant, `G_I` free of `q_D`).
    fn linear_positions(&mut self, t: f64, y: &[f64]) -> Result<(), PartitionError> {
        let nc = self.sys.dims.2;
        let niq = self.part.ind_q.len();
        for (l, &i) in self.part.ind_q.iter().enumerate() {
            self.vars[1 + i] = y[l];
        }
        self.newton_iterations += 1;
        self.staged
            .eval_stages(&self.vars, &mut self.w_st, &mut self.o_st, 0..2);
        self.stage0_valid = true;
        self.tmp[..nc].copy_from_slice(&self.o_st[..nc]);
        for &(s, d) in &self.bq_map {
            self.bq[d] = self.o_st[s];
        }
        if self.jq.plan().is_none() {
            let Ok(ratio) = self.jq.factor(&self.o_st, f64::INFINITY) else {
                return Err(PartitionError::SingularBlock { t });
            };
            self.condition_q = ratio;
            if self.share {
                // the constant block's inverse, column by column
                let mut inv = vec![0.0; nc * nc];
                for j in 0..nc {
                    let e = &mut self.scratch;
                    e.fill(0.0);
                    e[j] = 1.0;
                    self.jq.solve(e);
                    for k in 0..nc {
                        inv[k * nc + j] = e[k];
                    }
                }
                self.dep_inverse = inv;
            }
        }
        dep_solve(
            &self.jq,
            &self.dep_inverse,
            &mut self.tmp[..nc],
            &mut self.scratch,
        );
        let mut step = 0.0f64;
        for (k, &i) in self.part.dep_q.iter().enumerate() {
            self.vars[1 + i] -= self.tmp[k];
            step = step.max(self.tmp[k].abs());
        }
        if !step.is_finite() {
            return Err(PartitionError::Newton {
                t,
                correction: step,
            });
        }
        self.qi_prev.copy_from_slice(&y[..niq]);
        self.have_prev = true;
        Ok(())
    }

    /// Evaluates `y' = f(t, y)` (see the module documentation); `y = [q_I, v_I]`.
    pub fn rhs(&mut self, t: f64, y: &[f64], yd: &mut [f64]) -> Result<(), PartitionError> {
        let lim = self.limits();
        if let Some(e) = self.elim.as_deref_mut() {
            self.last_valid = false;
            return e.rhs(t, y, yd, lim);
        }
        self.block_rhs(t, y, yd)
    }

    /// [`Self::rhs`] on the full dependent block.
    fn block_rhs(&mut self, t: f64, y: &[f64], yd: &mut [f64]) -> Result<(), PartitionError> {
        self.block_complete(t, y)?;
        let (nq, nv, nc) = self.sys.dims;
        let niq = self.part.ind_q.len();
        let niv = self.part.ind_v.len();
        // [Q, γ, Kv] at the full state
        self.dynamics
            .eval(&self.vars, &mut self.w_dyn, &mut self.o_dyn);
        let (qf, rest) = self.o_dyn.split_at(nv);
        let (gamma, kv) = rest.split_at(nc);
        let (dv, iv) = (&self.part.dep_v, &self.part.ind_v);
        let m = &self.sys.mass;
        // B = G_D⁻¹ G_I is ready (`complete`); c = G_D⁻¹ γ
        self.c.copy_from_slice(gamma);
        let lu = if self.share { &self.jq } else { &self.jv };
        dep_solve(lu, &self.dep_inverse, &mut self.c, &mut self.scratch);
        self.c_ready = true;
        // M̂ = M_I + Bᵀ M_D B,  r = Q_I − Bᵀ (Q_D + M_D c)
        for a in 0..niv {
            for b in 0..niv {
                let mut s = if a == b { m[iv[a]] } else { 0.0 };
                for (k, &j) in dv.iter().enumerate() {
                    s += self.bv[k * niv + a] * m[j] * self.bv[k * niv + b];
                }
                self.mhat[a * niv + b] = s;
            }
        }
        let (yq, ya) = yd.split_at_mut(niq);
        for (a, &j) in iv.iter().enumerate() {
            let mut s = qf[j];
            for (k, &d) in dv.iter().enumerate() {
                s -= self.bv[k * niv + a] * (qf[d] + m[d] * self.c[k]);
            }
            ya[a] = s;
        }
        if niv > 0 {
            if self.mhat_lu.factor(&self.mhat, f64::INFINITY).is_err() {
                return Err(PartitionError::SingularMass { t });
            }
            self.mhat_lu.solve(ya);
        }
        for (a, &j) in iv.iter().enumerate() {
            self.acc[j] = ya[a];
        }
        for (k, &d) in dv.iter().enumerate() {
            let mut s = -self.c[k];
            for a in 0..niv {
                s -= self.bv[k * niv + a] * ya[a];
            }
            self.acc[d] = s;
        }
        for (l, &i) in self.part.ind_q.iter().enumerate() {
            yq[l] = kv[i];
        }
        let _ = nq;
        Ok(())
    }

    /// Completes `y = [q_I, v_I]` to the full state `[q, v]` (Newton for `q_D`, then
    /// `G_D v_D = −G_I v_I`), left in [`Self::full_state`]; factorises `G_v[:, D]`.
    pub fn complete(&mut self, t: f64, y: &[f64]) -> Result<(), PartitionError> {
        let lim = self.limits();
        if let Some(e) = self.elim.as_deref_mut() {
            self.last_valid = false;
            let (nq, nv, _) = self.sys.dims;
            e.complete(t, y, &mut self.vars[1..=nq + nv], lim)?;
            // the block path starts from this exact state when it runs (multipliers)
            self.have_prev = false;
            self.stage0_valid = false;
            self.b_ready = false;
            self.c_ready = false;
            self.last_t = t;
            self.last_y.copy_from_slice(y);
            self.last_valid = true;
            return Ok(());
        }
        self.block_complete(t, y)
    }

    /// [`Self::complete`] on the full dependent block.
    fn block_complete(&mut self, t: f64, y: &[f64]) -> Result<(), PartitionError> {
        self.last_valid = false;
        self.positions(t, y)?;
        let (nq, _, nc) = self.sys.dims;
        let niq = self.part.ind_q.len();
        let niv = self.part.ind_v.len();
        let (dv, iv) = (&self.part.dep_v, &self.part.ind_v);
        for (l, &j) in iv.iter().enumerate() {
            self.vars[1 + nq + j] = y[niq + l];
        }
        if nc == 0 {
            return Ok(());
        }
        self.b_ready = false;
        if self.share {
            // G_v = G_q, and Newton's last factorisation of G_q[:, D] (at a point within the
            // Newton tolerance of the converged q) serves the velocity level too, without the
            // G_v tape and a second LU
            self.bv.copy_from_slice(&self.bq);
            self.condition_estimate = self.condition_q;
        } else {
            let vals = self.sys.gv.eval_nonzeros(&self.vars, &mut self.w_gv);
            self.bv.fill(0.0);
            for &(s, d) in &self.bv_map {
                self.bv[d] = vals[s];
            }
            let Ok(ratio) = self.jv.factor(vals, self.repartition_above) else {
                return Err(PartitionError::SingularBlock { t });
            };
            self.condition_estimate = ratio;
        }
        if self.condition_estimate > self.repartition_above {
            return Err(PartitionError::Repartition {
                t,
                condition: self.condition_estimate,
            });
        }
        // B = G_D⁻¹ G_I (column by column): the velocities v_D = −B v_I, the reduced equations
        // and the next call's tangent predictor
        let lu = if self.share { &self.jq } else { &self.jv };
        for l in 0..niv {
            for k in 0..nc {
                self.tmp[k] = self.bv[k * niv + l];
            }
            dep_solve(
                lu,
                &self.dep_inverse,
                &mut self.tmp[..nc],
                &mut self.scratch,
            );
            for k in 0..nc {
                self.bv[k * niv + l] = self.tmp[k];
            }
        }
        self.b_ready = true;
        for k in 0..nc {
            let mut s = 0.0;
            for (l, &j) in iv.iter().enumerate() {
                s += self.bv[k * niv + l] * self.vars[1 + nq + j];
            }
            self.tmp[k] = -s;
        }
        // v_D = −G_D⁻¹ (G_I v_I + b): a driver's prescribed rate
        if eval_bias(
            &self.sys,
            &self.vars,
            &mut self.bias_work,
            &mut self.bias_out,
        ) {
            let lu = if self.share { &self.jq } else { &self.jv };
            dep_solve(lu, &self.dep_inverse, &mut self.bias_out, &mut self.scratch);
            for k in 0..nc {
                self.tmp[k] -= self.bias_out[k];
            }
        }
        for (k, &j) in dv.iter().enumerate() {
            self.vars[1 + nq + j] = self.tmp[k];
        }
        self.last_t = t;
        self.last_y.copy_from_slice(y);
        self.last_valid = true;
        Ok(())
    }

    /// [`Self::complete`] for an output row (or an event function) at `(t, y)` between the
    /// integrator's evaluations: no partition re-choice, [`OUTPUT_NEWTON_ITERATIONS`] Newton
    /// iterations, and nothing to do when `(t, y)` is the last completed evaluation (an
    /// explicit Runge–Kutta step whose last stage is the step's end, landing on an output).
    pub fn complete_for_output(&mut self, t: f64, y: &[f64]) -> Result<(), PartitionError> {
        if self.last_valid && self.last_t == t && self.last_y == y {
            return Ok(());
        }
        self.relaxed(|s| s.complete(t, y))
    }

    /// [`Self::full_with_multipliers`] for an output row or an event function (see
    /// [`Self::complete_for_output`]).
    pub fn full_for_output(&mut self, t: f64, y: &[f64]) -> Result<&[f64], PartitionError> {
        self.relaxed(|s| s.full_with_multipliers(t, y).map(|_| ()))?;
        Ok(&self.with_multipliers)
    }

    fn relaxed<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> T {
        let (above, newton) = (self.repartition_above, self.max_newton);
        self.repartition_above = f64::INFINITY;
        self.max_newton = OUTPUT_NEWTON_ITERATIONS;
        let r = f(self);
        self.repartition_above = above;
        self.max_newton = newton;
        r
    }

    /// The full state with the multipliers, `[q, v, λ]`, at `(t, y)`: `λ` from
    /// `G_Dᵀ λ = Q_D − M_D a_D` with the accelerations of the reduced equations.
    /// (Written into a buffer of the right-hand side: no allocation, as event functions
    /// call it at every step.)
    pub fn full_with_multipliers(&mut self, t: f64, y: &[f64]) -> Result<&[f64], PartitionError> {
        let mut yd = std::mem::take(&mut self.yd);
        yd.resize(y.len(), 0.0);
        let r = if self.elim.is_some() {
            // the multipliers come from the full block, started at the reduced solution
            self.complete(t, y)
                .and_then(|()| self.block_rhs(t, y, &mut yd))
        } else {
            self.rhs(t, y, &mut yd)
        };
        self.yd = yd;
        r?;
        let (nq, nv, nc) = self.sys.dims;
        let out = &mut self.with_multipliers;
        out.clear();
        out.extend_from_slice(&self.vars[1..=nq + nv]);
        out.extend(
            self.part
                .dep_v
                .iter()
                .map(|&d| self.o_dyn[d] - self.sys.mass[d] * self.acc[d]),
        );
        if nc > 0 {
            let lu = if self.share { &self.jq } else { &self.jv };
            lu.solve_transposed(&mut out[nq + nv..]);
        }
        if let Some((kept, full)) = &self.sys.kept_rows {
            // every joint row's multiplier, zero on the rows left out: spread in place from the
            // back (`kept` ascends, so row `kept[k] ≥ k` is written after slot `k` is read)
            out.resize(nq + nv + full, 0.0);
            let lam = &mut out[nq + nv..];
            let mut next = *full;
            for (k, &r) in kept.iter().enumerate().rev() {
                lam[r + 1..next].fill(0.0);
                lam[r] = lam[k];
                next = r;
            }
            lam[..next].fill(0.0);
        }
        Ok(&self.with_multipliers)
    }
}

/// `b = ∂g/∂t` of the rheonomic rows at `vars` into `out` (with the tape's workspace `work`);
/// `false` without rheonomic rows.
fn eval_bias(sys: &PartitionedSystem, vars: &[f64], work: &mut [f64], out: &mut [f64]) -> bool {
    match &sys.bias {
        Some(bias) => {
            bias.eval(vars, work, out);
            true
        }
        None => false,
    }
}

/// `b ← G_D⁻¹ b`: the product with `inverse` when it is given (a constant block), else the
/// solve with the block's LU.
fn dep_solve(lu: &BlockLu, inverse: &[f64], b: &mut [f64], scratch: &mut [f64]) {
    if inverse.is_empty() {
        lu.solve(b);
        return;
    }
    let n = b.len();
    for (s, &x) in scratch.iter_mut().zip(b.iter()) {
        *s = x;
    }
    for (k, out) in b.iter_mut().enumerate() {
        *out = inverse[k * n..(k + 1) * n]
            .iter()
            .zip(&scratch[..n])
            .map(|(a, x)| a * x)
            .sum();
    }
}
