//! Explicit elimination of the dependent coordinates that the joints give in closed form: the
//! seed's differential-causality inertias whose flows follow from one bond each.
//!
//! A pin joint's row `x_B + R(θ_B) s_B − x_A − R(θ_A) s_A = 0` is affine in the translation
//! `x_B` with coefficient 1: the seed's causality makes `x_B` dependent and reads it off the
//! row. So do a prismatic joint's rows and a weld's. Applied in cascade (substituting each
//! eliminated coordinate into the remaining rows) this solves every row of a tree
//! symbolically; what stays implicit are the loop closures (one per independent loop, e.g. the
//! slider-crank's `r cos φ + l cos ψ = 0`). With `z = [q_I, q_R]` (independent coordinates and
//! the dependent ones left implicit) and the eliminated ones `q_E = h(z)`:
//!
//! ```text
//!   q = Φ(z),  J = ∂Φ/∂z,  q̇ = J ż,  q̈ = J z̈ + J̇ ż
//!   M̃ = Jᵀ M J,  Q̃ = Jᵀ (Q(t, Φ, J ż) − M J̇ ż)              (the eliminated rows' forces drop out)
//!   g̃(z) = 0,  G̃ = ∂g̃/∂z = [G̃_I G̃_R],  γ̃ = (∂(G̃ ż)/∂z) ż     (the loop closures)
//!   B = G̃_R⁻¹ G̃_I,  c = G̃_R⁻¹ γ̃,  ż_R = −B ż_I,  z̈ = [I; −B] a_I + [0; −c]
//!   (M̃_II − M̃_IR B − Bᵀ M̃_RI + Bᵀ M̃_RR B) a_I = Q̃_I + M̃_IR c − Bᵀ (Q̃_R + M̃_RR c)
//! ```
//!
//! the same reduced (Maggi) equations as [`super::equations`]'s, with the algebra of the
//! eliminated rows done once, symbolically, instead of in every call: Newton runs on the loop
//! closures only (none for a tree: the double pendulum's right-hand side is its Lagrange
//! equations), and `M̃`, `Q̃` come from one compiled tape. The condition estimate the partition's
//! re-choice reads is that of the block LU in the elimination order: the eliminated rows'
//! constant pivots with the pivots of `G̃_R` (its Schur complement).
//!
//! It applies where the partitioned formulation shares one factorisation between the two
//! levels (`q' = v`, the velocity rows `G_q v`), and to small systems (the symbolic `Jᵀ M J`
//! is dense in `z`); elsewhere the partitioned right-hand side works on the full block.

// the dense kernels index row-major matrices and several vectors with the same loop variable
#![allow(clippy::needless_range_loop)]

use std::sync::Arc;

use crate::dae::block_lu::BlockLu;
use crate::expr::{Expr, ExprGraph, StagedTape, Tape};
use crate::partition::coordinates::{
    left_branch, tangent_step, NewtonLimits, Partition, PartitionError,
};

/// Largest number of reduced coordinates `|z| = |q_I| + |q_R|` eliminated symbolically
/// (`Jᵀ M J` has `|z|²` entries, each a sum over the eliminated coordinates).
pub const MAX_REDUCED_COORDINATES: usize = 12;

/// Largest number of coordinates of a system eliminated symbolically.
pub const MAX_ELIMINATED_SYSTEM: usize = 60;

/// What [`Elimination::new`] needs of the multibody system (all over the slots `[t, q, v]`).
pub(crate) struct EliminationInputs<'a> {
    /// The system's expression graph (cloned: the elimination adds its own expressions).
    pub graph: &'a ExprGraph,
    /// `g(q)`.
    pub g: &'a [Expr],
    /// `Q(t, q, v)`, one per coordinate (`q' = v`).
    pub forces: &'a [Expr],
    /// Diagonal of `M`.
    pub mass: &'a [f64],
    /// Mode variables after `[t, q, v]` (`expr::switches`).
    pub n_modes: usize,
    /// The switching functions of the loads (over `[t, q, v, modes]`), evaluated with every
    /// right-hand side so that root functions at its point cost nothing more.
    pub switching: &'a [Expr],
}

/// The partitioned right-hand side with the dependent coordinates affine in their rows
/// eliminated symbolically (see the module documentation).
#[derive(Clone, Debug)]
pub(crate) struct Elimination {
    nq: usize,
    /// `z = [q_I, q_R]` (coordinate indices) and `|q_I|`.
    z: Vec<usize>,
    ni: usize,
    /// Eliminated coordinates `q_E`, in the order of the `full` tape's outputs.
    elim: Vec<usize>,
    /// Largest and smallest |coefficient| of the eliminated coordinates in their rows.
    elim_pivots: (f64, f64),
    /// `[g̃_R, G̃ (|R| × |z| row-major)]` in two stages, `(t, q_I)` and `q_R` (Newton).
    newton: Arc<StagedTape>,
    w_n: Vec<f64>,
    o_n: Vec<f64>,
    /// `[M̃ (|z| × |z|), Q̃ (|z|), γ̃ (|R|), switching functions]` over `[t, z, ż, modes]`.
    tape: Arc<Tape>,
    w: Vec<f64>,
    o: Vec<f64>,
    /// `(t, y)` of the last right-hand side (whose outputs `o` holds), when valid.
    last_t: f64,
    last_y: Vec<f64>,
    last_valid: bool,
    /// `[q_E, q̇_E]` over `[t, z, ż]` (output rows only).
    full: Arc<Tape>,
    w_full: Vec<f64>,
    o_full: Vec<f64>,
    /// `[t, q, v, modes]` (only `t`, `z`, `ż` and the modes are read by the tapes).
    vars: Vec<f64>,
    /// LU of `G̃_R` (entries read from the tape's outputs).
    lu: BlockLu,
    /// `G̃_I`, then `B = G̃_R⁻¹ G̃_I` (row-major `|R| × |q_I|`).
    b: Vec<f64>,
    b_ready: bool,
    c: Vec<f64>,
    c_ready: bool,
    /// `q_I` of the last converged call (tangent predictor).
    qi_prev: Vec<f64>,
    have_prev: bool,
    pred: Vec<f64>,
    tmp: Vec<f64>,
    mhat: Vec<f64>,
    mhat_lu: BlockLu,
    /// Newton iterations so far.
    pub newton_iterations: u64,
    /// Condition estimate of the last factorisation (see the module documentation).
    pub condition_estimate: f64,
}

/// Offsets of the tape's output blocks.
#[derive(Clone, Copy)]
struct Layout {
    nr: usize,
    nz: usize,
}

impl Layout {
    /// `G̃` in the Newton tape's outputs.
    fn gq(&self) -> usize {
        self.nr
    }
    /// `Q̃` in the dynamics tape's outputs (after `M̃`).
    fn forces(&self) -> usize {
        self.nz * self.nz
    }
    fn gamma(&self) -> usize {
        self.forces() + self.nz
    }
    fn switching(&self) -> usize {
        self.gamma() + self.nr
    }
}

/// `Σ_a (∂e/∂z_a) ż_a`: the derivative of `e` along the motion with `z̈ = 0` (`e` linear in
/// `ż` gives `J̇ ż` and `γ̃`); `z` are coordinate indices, `zv` their velocity variables.
fn along(g: &mut ExprGraph, e: Expr, z: &[usize], zv: &[Expr]) -> Expr {
    let terms: Vec<Expr> = z
        .iter()
        .zip(zv)
        .map(|(&a, &va)| {
            let d = g.diff(e, (1 + a) as u32);
            g.mul(d, va)
        })
        .collect();
    g.sum(&terms)
}

impl Elimination {
    /// The elimination for partition `part` (with `dep_q = dep_v` and `q' = v`), warm-started
    /// at the full state `x = [q, v]`; `None` when no dependent coordinate is affine in a row
    /// with a constant coefficient, or the system is too large (see
    /// [`MAX_REDUCED_COORDINATES`]).
    pub(crate) fn new(inp: &EliminationInputs<'_>, part: &Partition, x: &[f64]) -> Option<Self> {
        let nq = inp.mass.len();
        let nc = inp.g.len();
        if nq > MAX_ELIMINATED_SYSTEM || part.dep_q != part.dep_v || part.dep_q.len() != nc {
            return None;
        }
        let mut g = inp.graph.clone();
        let qs = |i: usize| (1 + i) as u32;
        let vs = |i: usize| (1 + nq + i) as u32;
        let mut dep = vec![false; nq];
        for &d in &part.dep_q {
            dep[d] = true;
        }
        // the cascade: h[i] = q_i's expression, free of every eliminated coordinate
        let mut h: Vec<Option<Expr>> = vec![None; nq];
        let mut order = Vec::new();
        let mut rows: Vec<Expr> = inp.g.to_vec();
        let mut used = vec![false; nc];
        let (mut cmax, mut cmin) = (0.0f64, f64::INFINITY);
        loop {
            let mut progress = false;
            for k in 0..nc {
                if used[k] {
                    continue;
                }
                let row = rows[k];
                let found = g.vars(row).into_iter().find_map(|v| {
                    let i = (v as usize).checked_sub(1).filter(|&i| i < nq)?;
                    if !dep[i] || h[i].is_some() {
                        return None;
                    }
                    let c = g.diff(row, v);
                    g.as_const(c)
                        .filter(|c| *c != 0.0 && c.is_finite())
                        .map(|c| (i, c))
                });
                let Some((i, c)) = found else { continue };
                let zero = g.zero();
                let rest = g.substitute(row, &[(qs(i), zero)]);
                let hi = g.scale(-1.0 / c, rest);
                // keep every expression free of eliminated coordinates
                let map = [(qs(i), hi)];
                for e in h.iter_mut().flatten() {
                    *e = g.substitute(*e, &map);
                }
                for (r, u) in rows.iter_mut().zip(&used) {
                    if !u {
                        *r = g.substitute(*r, &map);
                    }
                }
                h[i] = Some(hi);
                order.push(i);
                used[k] = true;
                cmax = cmax.max(c.abs());
                cmin = cmin.min(c.abs());
                progress = true;
            }
            if !progress {
                break;
            }
        }
        if order.is_empty() {
            return None;
        }
        let rdep: Vec<usize> = part
            .dep_q
            .iter()
            .copied()
            .filter(|&d| h[d].is_none())
            .collect();
        let rrows: Vec<Expr> = (0..nc).filter(|&k| !used[k]).map(|k| rows[k]).collect();
        let z: Vec<usize> = part.ind_q.iter().chain(&rdep).copied().collect();
        let (ni, nr, nz) = (part.ind_q.len(), rdep.len(), z.len());
        if nz > MAX_REDUCED_COORDINATES || rrows.len() != nr {
            return None;
        }
        let zv: Vec<Expr> = z.iter().map(|&i| g.var(vs(i))).collect();
        // J = ∂Φ/∂z (rows: coordinates), q̇_E = J_E ż, J̇ ż
        let mut jac: Vec<Vec<Expr>> = Vec::with_capacity(nq);
        let mut qdot: Vec<Expr> = Vec::with_capacity(nq);
        let mut conv: Vec<Expr> = Vec::with_capacity(nq);
        for i in 0..nq {
            match h[i] {
                Some(hi) => {
                    let row: Vec<Expr> = z.iter().map(|&a| g.diff(hi, qs(a))).collect();
                    let qd = g.dot(&row, &zv);
                    let cv = along(&mut g, qd, &z, &zv);
                    jac.push(row);
                    qdot.push(qd);
                    conv.push(cv);
                }
                None => {
                    let row: Vec<Expr> = z
                        .iter()
                        .map(|&a| if a == i { g.one() } else { g.zero() })
                        .collect();
                    jac.push(row);
                    let vi = g.var(vs(i));
                    qdot.push(vi);
                    conv.push(g.zero());
                }
            }
        }
        let mut map: Vec<(u32, Expr)> = Vec::new();
        for &i in &order {
            map.push((qs(i), h[i].expect("eliminated")));
            map.push((vs(i), qdot[i]));
        }
        let forces = g.substitute_all(inp.forces, &map);
        // Newton: g̃_R, G̃; dynamics: M̃, Q̃, γ̃, switching functions
        let mut newton_outs: Vec<Expr> = rrows.clone();
        let mut gt: Vec<Expr> = Vec::with_capacity(nr * nz);
        for &r in &rrows {
            for &a in &z {
                gt.push(g.diff(r, qs(a)));
            }
        }
        newton_outs.extend(&gt);
        let mut outs: Vec<Expr> = Vec::new();
        for a in 0..nz {
            for b in 0..nz {
                let rows: Vec<usize> = (0..nq)
                    .filter(|&i| !g.is_zero(jac[i][a]) && !g.is_zero(jac[i][b]))
                    .collect();
                let terms: Vec<Expr> = rows
                    .into_iter()
                    .map(|i| {
                        let p = g.mul(jac[i][a], jac[i][b]);
                        g.scale(inp.mass[i], p)
                    })
                    .collect();
                outs.push(g.sum(&terms));
            }
        }
        for a in 0..nz {
            let rows: Vec<usize> = (0..nq).filter(|&i| !g.is_zero(jac[i][a])).collect();
            let terms: Vec<Expr> = rows
                .into_iter()
                .map(|i| {
                    let inertial = g.scale(inp.mass[i], conv[i]);
                    let f = g.sub(forces[i], inertial);
                    g.mul(jac[i][a], f)
                })
                .collect();
            outs.push(g.sum(&terms));
        }
        for k in 0..nr {
            let gv = g.dot(&gt[k * nz..(k + 1) * nz], &zv);
            let gamma = along(&mut g, gv, &z, &zv);
            outs.push(gamma);
        }
        let switching = g.substitute_all(inp.switching, &map);
        outs.extend(&switching);
        // Newton's stages: t and q_I (0), q_R (1)
        let mut at = vec![2usize; 1 + 2 * nq];
        at[0] = 0;
        for &i in &part.ind_q {
            at[qs(i) as usize] = 0;
        }
        for &i in &part.dep_q {
            at[qs(i) as usize] = 1;
        }
        let stage_of = |v: u32| at.get(v as usize).copied().unwrap_or(0);
        let newton = Arc::new(g.compile_staged(&newton_outs, &stage_of, 2));
        let tape = Arc::new(g.compile(&outs));
        let full_outs: Vec<Expr> = order
            .iter()
            .map(|&i| h[i].expect("eliminated"))
            .chain(order.iter().map(|&i| qdot[i]))
            .collect();
        let full = Arc::new(g.compile(&full_outs));
        let lay = Layout { nr, nz };
        let entries = (0..nr)
            .flat_map(|k| (0..nr).map(move |l| (k, l, lay.gq() + k * nz + ni + l)))
            .collect();
        let mut vars = vec![0.0; 1 + 2 * nq + inp.n_modes];
        vars[1..=2 * nq].copy_from_slice(&x[..2 * nq]);
        Some(Elimination {
            nq,
            w_n: newton.workspace(),
            o_n: vec![0.0; newton.tape().n_outputs()],
            newton,
            w: tape.workspace(),
            o: vec![0.0; tape.n_outputs()],
            tape,
            last_t: f64::NAN,
            last_y: vec![0.0; 2 * ni],
            last_valid: false,
            w_full: full.workspace(),
            o_full: vec![0.0; full.n_outputs()],
            full,
            vars,
            lu: BlockLu::new(nr, entries),
            b: vec![0.0; nr * ni],
            b_ready: false,
            c: vec![0.0; nr],
            c_ready: false,
            qi_prev: vec![0.0; ni],
            have_prev: false,
            pred: vec![0.0; nr],
            tmp: vec![0.0; nz.max(1)],
            mhat: vec![0.0; ni * ni],
            mhat_lu: BlockLu::new(ni, (0..ni * ni).map(|k| (k / ni, k % ni, k)).collect()),
            newton_iterations: 0,
            condition_estimate: if cmin > 0.0 { cmax / cmin } else { 1.0 },
            elim_pivots: (cmax, cmin),
            elim: order,
            z,
            ni,
        })
    }

    fn layout(&self) -> Layout {
        Layout {
            nr: self.z.len() - self.ni,
            nz: self.z.len(),
        }
    }

    /// Newton on the loop closures `g̃(q_I, q_R) = 0` for `q_R` from the warm start and a
    /// tangent predictor, then `ż_R = −B ż_I`; `y = [q_I, v_I]`.
    fn complete_z(&mut self, t: f64, y: &[f64], lim: NewtonLimits) -> Result<(), PartitionError> {
        let (ni, nq) = (self.ni, self.nq);
        let lay = self.layout();
        let nr = lay.nr;
        self.vars[0] = t;
        self.last_valid = false;
        let mut predicted = 0.0f64;
        let mut checked = false;
        if nr > 0 && self.have_prev && self.b_ready {
            // Δq_R = −B Δq_I − ½ δ² c, as the full block's predictor
            let v = (0..ni).map(|l| self.vars[1 + nq + self.z[l]]);
            tangent_step(
                &self.b,
                self.c_ready.then_some(&self.c[..]),
                &y[..ni],
                &self.qi_prev,
                v,
                &mut self.tmp[..nr],
            );
            for k in 0..nr {
                let s = 1 + self.z[ni + k];
                self.vars[s] -= self.tmp[k];
                self.pred[k] = self.vars[s];
                predicted = predicted.max(self.tmp[k].abs());
            }
            checked = true;
        }
        for l in 0..ni {
            self.vars[1 + self.z[l]] = y[l];
        }
        self.b_ready = false;
        if nr > 0 {
            let mut converged = false;
            let mut last = f64::INFINITY;
            for it in 0..lim.max_iterations {
                self.newton_iterations += 1;
                let first = if it == 0 { 0 } else { 1 };
                self.newton
                    .eval_stages(&self.vars, &mut self.w_n, &mut self.o_n, first..2);
                if self.lu.factor(&self.o_n, lim.repartition_above).is_err() {
                    self.have_prev = false;
                    return Err(PartitionError::SingularBlock { t });
                }
                self.tmp[..nr].copy_from_slice(&self.o_n[..nr]);
                self.lu.solve(&mut self.tmp[..nr]);
                let mut step = 0.0f64;
                for k in 0..nr {
                    self.vars[1 + self.z[ni + k]] -= self.tmp[k];
                    step = step.max(self.tmp[k].abs());
                }
                if !step.is_finite() {
                    break;
                }
                last = step;
                if step <= lim.tolerance {
                    converged = true;
                    break;
                }
            }
            if !converged {
                self.have_prev = false;
                return Err(PartitionError::Newton {
                    t,
                    correction: last,
                });
            }
            if checked {
                let corr = (0..nr).fold(0.0f64, |a, k| {
                    a.max((self.vars[1 + self.z[ni + k]] - self.pred[k]).abs())
                });
                let moved = (0..ni).fold(0.0f64, |m, l| m.max((y[l] - self.qi_prev[l]).abs()));
                if left_branch(corr, predicted, moved, lim.tolerance) {
                    self.have_prev = false;
                    return Err(PartitionError::Branch {
                        t,
                        correction: corr,
                        predicted,
                    });
                }
            }
            let (big, small) = self.lu.pivots();
            let (cmax, cmin) = self.elim_pivots;
            self.condition_estimate = big.max(cmax) / small.min(cmin);
            if self.condition_estimate > lim.repartition_above {
                return Err(PartitionError::Repartition {
                    t,
                    condition: self.condition_estimate,
                });
            }
            // B = G̃_R⁻¹ G̃_I, column by column
            for l in 0..ni {
                for k in 0..nr {
                    self.tmp[k] = self.o_n[lay.gq() + k * lay.nz + l];
                }
                self.lu.solve(&mut self.tmp[..nr]);
                for k in 0..nr {
                    self.b[k * ni + l] = self.tmp[k];
                }
            }
            self.b_ready = true;
        }
        for l in 0..ni {
            self.vars[1 + nq + self.z[l]] = y[ni + l];
        }
        for k in 0..nr {
            let s: f64 = (0..ni).map(|l| self.b[k * ni + l] * y[ni + l]).sum();
            self.vars[1 + nq + self.z[ni + k]] = -s;
        }
        self.qi_prev.copy_from_slice(&y[..ni]);
        self.have_prev = true;
        Ok(())
    }

    /// `y' = f(t, y)`, `y = [q_I, v_I]` (see the module documentation).
    pub(crate) fn rhs(
        &mut self,
        t: f64,
        y: &[f64],
        yd: &mut [f64],
        lim: NewtonLimits,
    ) -> Result<(), PartitionError> {
        self.complete_z(t, y, lim)?;
        let (ni, lay) = (self.ni, self.layout());
        let (nr, nz) = (lay.nr, lay.nz);
        self.tape.eval(&self.vars, &mut self.w, &mut self.o);
        self.last_t = t;
        self.last_y.copy_from_slice(y);
        self.last_valid = true;
        let m = &self.o[..lay.forces()];
        let q = &self.o[lay.forces()..lay.gamma()];
        // c = G̃_R⁻¹ γ̃
        if nr > 0 {
            self.c
                .copy_from_slice(&self.o[lay.gamma()..lay.gamma() + nr]);
            self.lu.solve(&mut self.c);
            self.c_ready = true;
        }
        let (b, c) = (&self.b, &self.c);
        // M̂ = M̃_II − M̃_IR B − Bᵀ M̃_RI + Bᵀ M̃_RR B
        for a in 0..ni {
            for bb in 0..ni {
                let mut s = m[a * nz + bb];
                for k in 0..nr {
                    s -=
                        m[a * nz + ni + k] * b[k * ni + bb] + b[k * ni + a] * m[(ni + k) * nz + bb];
                    for l in 0..nr {
                        s += b[k * ni + a] * m[(ni + k) * nz + ni + l] * b[l * ni + bb];
                    }
                }
                self.mhat[a * ni + bb] = s;
            }
        }
        // r = Q̃_I + M̃_IR c − Bᵀ (Q̃_R + M̃_RR c)
        let (yq, ya) = yd.split_at_mut(ni);
        yq.copy_from_slice(&y[ni..2 * ni]);
        for k in 0..nr {
            let mut s = q[ni + k];
            for l in 0..nr {
                s += m[(ni + k) * nz + ni + l] * c[l];
            }
            self.tmp[k] = s;
        }
        for a in 0..ni {
            let mut s = q[a];
            for k in 0..nr {
                s += m[a * nz + ni + k] * c[k] - b[k * ni + a] * self.tmp[k];
            }
            ya[a] = s;
        }
        if ni > 0 {
            if self.mhat_lu.factor(&self.mhat, f64::INFINITY).is_err() {
                return Err(PartitionError::SingularMass { t });
            }
            self.mhat_lu.solve(ya);
        }
        Ok(())
    }

    /// Completes `y = [q_I, v_I]` to the full state `[q, v]`, written into `x`.
    pub(crate) fn complete(
        &mut self,
        t: f64,
        y: &[f64],
        x: &mut [f64],
        lim: NewtonLimits,
    ) -> Result<(), PartitionError> {
        self.complete_z(t, y, lim)?;
        self.full
            .eval(&self.vars, &mut self.w_full, &mut self.o_full);
        let (nq, ne) = (self.nq, self.elim.len());
        for (k, &i) in self.elim.iter().enumerate() {
            self.vars[1 + i] = self.o_full[k];
            self.vars[1 + nq + i] = self.o_full[ne + k];
        }
        x.copy_from_slice(&self.vars[1..1 + 2 * nq]);
        Ok(())
    }

    /// Holds the loads' switch `k` in `mode` (`expr::switches`).
    pub(crate) fn set_mode(&mut self, k: usize, mode: f64) {
        self.vars[1 + 2 * self.nq + k] = mode;
        self.last_valid = false;
    }

    /// The switching functions at `(t, y)` if that was the last right-hand side's point.
    pub(crate) fn switching_at(&self, t: f64, y: &[f64], out: &mut [f64]) -> bool {
        if !(self.last_valid && self.last_t == t && self.last_y == y) {
            return false;
        }
        let at = self.layout().switching();
        out.copy_from_slice(&self.o[at..at + out.len()]);
        true
    }

    /// The number of reduced coordinates `|z|` and of loop closures `|q_R|`.
    pub(crate) fn sizes(&self) -> (usize, usize) {
        (self.z.len(), self.z.len() - self.ni)
    }
}
