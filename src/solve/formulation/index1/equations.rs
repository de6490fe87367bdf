//! Index-1 formulation with dummy derivatives (Mattsson–Söderlind), acceleration level.
//!
//! The velocities split into independent `I` and dependent `D` ones (`|D|` = number of
//! constraint rows, `G_v[:, D]` nonsingular) — the dependent ones are those the bond graph gives
//! differential causality. The derivatives of the dependent quantities become algebraic
//! "dummy" unknowns `a_D`, and the position and velocity constraints are kept, so nothing drifts:
//!
//! ```text
//!   q_I' = v_I                        (differential)
//!   0 = g(q)                          (determines q_D)
//!   M_I v_I' = Q_I − G_Iᵀ λ           (differential)
//!   0 = G_v v                         (determines v_D)
//!   M_D a_D = Q_D − G_Dᵀ λ            (dummy derivatives a_D = v_D')
//!   0 = G_I v_I' + G_D a_D + γ        (acceleration-level constraint, determines λ)
//! ```
//!
//! Valid where `G_D` is well conditioned; the runner watches its condition number and re-selects
//! `D` (restarting IDA) when it degrades. Where the coordinates' rates are not the velocities
//! (`q' = K(q) v`: a 3D body's quaternion, a body-fixed planar frame), the dependent coordinates
//! `D_q` (`G_q[:, D_q]` nonsingular) are chosen apart from the dependent velocities and the
//! independent ones keep `q_I' = K_I(q) v` ([`Index1Formulation::build_partitioned`]).

use crate::dae::compiled::ImplicitDae;
use crate::dae::mechanics::ConstraintExprs;
use crate::expr::Expr;
use crate::mech::{MechError, MultibodySystem};
use crate::sundials::schur::SchurSplit;

/// The compiled index-1 residual for one choice of dependent velocities.
#[derive(Clone, Debug)]
pub struct Index1Formulation {
    /// The compiled residual.
    pub dae: ImplicitDae,
    /// Dependent velocity indices (sorted).
    pub dependent: Vec<usize>,
    /// Dependent coordinate indices (sorted; the velocity indices when `q' = v`).
    pub coordinates: Vec<usize>,
    /// The joint rows the dependent block is solved from (sorted): every row, or, where the
    /// joints are redundant, a maximal independent set ([`independent_rows`](crate::partition::independent_rows)); the other rows'
    /// multipliers are held at zero.
    pub rows: Vec<usize>,
    /// Multipliers `λ`: one per joint row, redundant rows included.
    pub multipliers: usize,
    /// The energy invariant's unknowns `(κ, μ)` after `λ`, where the run keeps the energy
    /// ([`EnergyInvariant`]); `None` otherwise.
    pub energy: Option<EnergyInvariant>,
    /// IDA's error-test mask ([`error_test_mask`]): 1 for the independent coordinates and
    /// velocities; 0 for the dependent ones, the dummy accelerations, the multipliers and the
    /// energy invariant's unknowns.
    pub id: Vec<f64>,
}

/// IDA's error-test mask of the index-1 DAE `y = [q, v, a_D, λ, …]` (`(nq, nv, n)`: coordinates,
/// velocities, unknowns; `coordinates` the dependent coordinates, `dependent` the dependent
/// velocities): the independent coordinates and velocities are measured; the dependent ones,
/// the dummy accelerations, the multipliers and the energy invariant's unknowns are not (IDA's
/// `id` with `IDASetSuppressAlg`; bondmech never calls `IDACalcIC`, so the mask is all `id`
/// means here).
///
/// Measuring the dependent velocities too was tried (issue 46) and is not the default: their
/// error is the independent ones' amplified by the dependent block, and with them in the test a
/// five-bar whose couplers' block degrades to μ ≈ 10–100 before a re-selection went from 12×,
/// 8.6×, 4.1× the GGL's error at rtol 1e-7 / 1e-8 / 1e-9 to 1.7×, 0.52×, 0.61×. But IDA's local
/// error estimate of an algebraic unknown is its predictor's miss, and `v_D = −G_v[R, D]⁻¹ G_v[R, I]
/// v_I` varies on the time scale of the block's smallest singular value: a bead in a slot beside
/// its pivot (rtol 1e-9) took 10 162 error-test failures in 15 345 steps and ended 1.6e-6 off
/// (3.5e-8 before), a spherical pendulum stayed at order 1 with h ≈ 9e-6 for 700 steps and lost
/// 1.6e-4 J. What the five-bar needs is the independent velocities weighted by the block's
/// amplification, not the dependent ones' predictor (docs/performance.md, "The default's error
/// test"). The exception, `measured`: the velocities of a freely rotating spatial body stay in
/// the test when dependent ([`crate::partition::coordinates::always_measured_velocities`]).
///
/// ```
/// use bondmech::solve::formulation::index1::error_test_mask;
/// // a pendulum bob: q = (x, y), v = (vx, vy), y and vy dependent; then a_D and λ
/// let none = [false, false];
/// assert_eq!(error_test_mask((2, 2, 6), &[1], &[1], &none), vec![1.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
/// ```
pub fn error_test_mask(
    (nq, nv, n): (usize, usize, usize),
    coordinates: &[usize],
    dependent: &[usize],
    measured: &[bool],
) -> Vec<f64> {
    let mut id = vec![1.0; nq + nv];
    for &i in coordinates {
        id[i] = 0.0;
    }
    for &j in dependent {
        if !measured.get(j).copied().unwrap_or(false) {
            id[nq + j] = 0.0;
        }
    }
    id.resize(n, 0.0);
    id
}

/// The energy of a conservative mechanism kept as an invariant of the index-1 DAE, `E(q, v) =
/// E₀`, with one multiplier `μ` acting along the energy's gradient on the joints' manifold
/// (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, IV.4: projection onto the
/// invariant; here as a row of the DAE, so IDA keeps it at every step instead of a projection
/// after the step):
///
/// ```text
///   q_I' = K_I(q) v − μ ĝ_I,        ĝ_I = h_I − G_q[R, I]ᵀ κ       (the reduced gradient)
///   h = ∂E/∂q − (∂(G_v v)/∂q)ᵀ η                                   (v_D moves with q)
///   0 = G_v[R, D]ᵀ η − ∂E/∂v_D                                     (determines η)
///   0 = G_q[R, D_q]ᵀ κ − h_D                                       (determines κ)
///   M v' = Q − G_vᵀ λ − μ M v                                      (independent and dummy rows)
///   0 = E(q, v) − E₀                                               (determines μ)
/// ```
///
/// `ĝ_I` is the gradient of `E` along the manifold in the independent coordinates at fixed
/// independent velocities (the dependent coordinates and velocities follow the joints), and `−μ M v` removes kinetic energy
/// along the velocity itself (tangent: `G_v v = 0`), so `dE/dμ = −(|ĝ_I|² + vᵀ M v)`, which
/// vanishes only at rest in an equilibrium: the row holds wherever the mechanism moves. In the
/// exact solution `μ = 0`; numerically `μ` absorbs the integrator's energy error, which BDF's
/// numerical damping makes one-signed and which, over hundreds of periods of an undamped
/// oscillation, becomes a phase error (the IFToMM A01 pendulum). `η`, `κ` and `μ` are algebraic
/// and left out of the local error test (`μ` is an index-2 unknown, as the GGL's position
/// multipliers are).
#[derive(Clone, Debug, PartialEq)]
pub struct EnergyInvariant {
    /// The energy kept, `E₀` (J).
    pub e0: f64,
    /// Offset of `η` in `y` (`r` entries, one per independent joint row), then `κ` (`r`),
    /// then `μ`.
    pub offset: usize,
}

impl Index1Formulation {
    /// The split of `y = [q, v, a_D, λ]` (`nq` coordinates) for the Schur solver of the Newton matrix
    /// ([`crate::sundials::schur`]): the independent coordinates and velocities `(q_I, v_I)`,
    /// and the dependent blocks in the order that makes them block lower triangular — `q_D`
    /// (rows `g = 0`, block `G_qD`), `v_D` (rows `G_v v = 0`, block `G_vD`), then the saddle
    /// of the dummy accelerations and the multipliers,
    ///
    /// ```text
    ///   [M_D  G_Dᵀ] [a_D]     (the dependent inertias' dynamics)
    ///   [G_D  0   ] [λ  ]     (the acceleration constraints, rows R; λ_k = 0 for k ∉ R)
    /// ```
    ///
    /// as two triangular blocks: `a_D` from the acceleration constraints (`G_D = G_v[R, D]`,
    /// square), then `λ` from the dynamics rows and the redundant rows' `λ_k = 0`
    /// (`[G_Dᵀ G_{R̄,D}ᵀ; 0 I]`), `M_D` below the block diagonal. Two inversions of the joint
    /// rows' size instead of one of twice it: a quarter of the saddle's work.
    pub fn schur_split(&self, nq: usize) -> SchurSplit {
        let r = self.dependent.len();
        let extra = if self.energy.is_some() { 2 * r + 1 } else { 0 };
        let nv = self.dae.n - nq - r - self.multipliers - extra;
        let mut outer: Vec<usize> = (0..nq)
            .filter(|i| !self.coordinates.contains(i))
            .chain(
                (0..nv)
                    .filter(|j| !self.dependent.contains(j))
                    .map(|j| nq + j),
            )
            .collect();
        // rows nq + nv .. + r: the dependent inertias' dynamics; then one row per joint row k:
        // its acceleration constraint (k ∈ R) or λ_k = 0
        let (a0, l0) = (nq + nv, nq + nv + r);
        let mut blocks = vec![
            self.coordinates.clone(),
            self.dependent.iter().map(|&j| nq + j).collect(),
            (a0..l0).collect(),
            (l0..l0 + self.multipliers).collect(),
        ];
        let mut row_blocks = blocks.clone();
        row_blocks[2] = self.rows.iter().map(|&k| l0 + k).collect();
        row_blocks[3] = (a0..l0)
            .chain(
                (0..self.multipliers)
                    .filter(|k| !self.rows.contains(k))
                    .map(|k| l0 + k),
            )
            .collect();
        if let Some(inv) = &self.energy {
            // η after λ (its rows read q, v), κ after it (its rows read q, v, η), μ with the
            // degrees of freedom (its row reads every coordinate and velocity)
            for b in [
                inv.offset..inv.offset + r,
                inv.offset + r..inv.offset + 2 * r,
            ] {
                blocks.push(b.clone().collect());
                row_blocks.push(b.collect());
            }
            outer.push(inv.offset + 2 * r);
        }
        SchurSplit {
            outer,
            blocks,
            row_blocks,
        }
    }

    /// Builds the residual for the dependent set `dependent` (velocity indices), with the same
    /// indices as the dependent coordinates: needs `q' = v` (planar bodies in the seed's
    /// non-rotating frame, 16.8). [`Index1Formulation::build_partitioned`] takes both sets.
    ///
    /// Slots: `y = [q, v, a_D, λ]` at `1..=n`, `y'` at `n+1..=2n`.
    pub fn build(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        dependent: &[usize],
    ) -> Result<Self, MechError> {
        let (nq, nv) = (sys.nq(), sys.nv());
        let identity = nq == nv
            && (0..nq).all(|i| {
                let s = sys.v_slot(i);
                let v = sys.graph.var(s);
                sys.kinematics[i] == v
            });
        if !identity {
            return Err(MechError::at(
                "solve.formulation",
                "the index-1 formulation with one dependent set needs q' = v (planar bodies in the default non-rotating frame); give the dependent coordinates too",
            ));
        }
        let rows: Vec<usize> = (0..sys.nc()).collect();
        Self::build_partitioned(sys, c, dependent, dependent, &rows)
    }

    /// Builds the residual for dependent velocities `dependent` and dependent coordinates
    /// `coordinates` (each `r` indices, `r` = `rows.len()`, the independent joint rows `R`:
    /// every row unless the joints are redundant; `G_v[R, D]` and `G_q[R, D_q]` nonsingular) of a
    /// mechanism whose coordinates move as `q' = K(q) v` (quaternions of 3D bodies, body-fixed
    /// planar frames, or `K = I`):
    ///
    /// ```text
    ///   q_I' = K_I(q) v                   (differential: the coordinates not in D_q)
    ///   0 = g(q)                          (determines q_D)
    ///   M_I v_I' = Q_I − G_Iᵀ λ           (differential)
    ///   0 = G_v v                         (determines v_D)
    ///   M_D a_D = Q_D − G_Dᵀ λ            (a_D = v_D')
    ///   0 = G_I v_I' + G_D a_D + γ        (determines λ)
    /// ```
    ///
    /// with `g`, `G_v v` and the acceleration rows taken over the rows `R` only, and `λ_k = 0`
    /// for a row `k` outside `R` (a redundant row: its force is not determined by the motion,
    /// and the reactions reported take it as zero).
    ///
    /// Slots: `y = [q, v, a_D, λ]` at `1..=n` (`a_D` of length `r`, `λ` one per row), `y'` at
    /// `n+1..=2n`.
    pub fn build_partitioned(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        dependent: &[usize],
        coordinates: &[usize],
        rows: &[usize],
    ) -> Result<Self, MechError> {
        Self::build_with_energy(sys, c, (dependent, coordinates, rows), None)
    }

    /// The same formulation (dependent velocities, joint rows, compiled tapes) with the
    /// dependent coordinates `coordinates` (`r` sorted indices, `G_q[R, D_q]` nonsingular): the
    /// coordinates' rows are selected again among the candidates the tapes compute (the
    /// kinematic row of each coordinate, each position row), nothing is compiled. `None` for a
    /// formulation that keeps the energy invariant (its rows depend on `D_q` otherwise).
    pub fn with_coordinates(&self, nq: usize, coordinates: &[usize]) -> Option<Self> {
        let r = self.rows.len();
        if self.energy.is_some()
            || coordinates.len() != r
            || coordinates.iter().any(|&i| i >= nq)
            || self.dae.candidates() != self.dae.n + r
        {
            return None;
        }
        // the velocities' and the other unknowns' entries of the mask do not depend on the
        // coordinates chosen ([`error_test_mask`])
        let mut id = self.id.clone();
        for (i, d) in id.iter_mut().enumerate().take(nq) {
            *d = if coordinates.contains(&i) { 0.0 } else { 1.0 };
        }
        Some(Index1Formulation {
            dae: self
                .dae
                .with_selection(coordinate_rows(nq, self.dae.n, coordinates)),
            dependent: self.dependent.clone(),
            coordinates: coordinates.to_vec(),
            rows: self.rows.clone(),
            multipliers: self.multipliers,
            energy: None,
            id,
        })
    }

    /// [`Index1Formulation::build_partitioned`] with, where `e0` is given, the system's energy
    /// kept at `e0` as an invariant ([`EnergyInvariant`]): `y = [q, v, a_D, λ, η, κ, μ]`.
    pub fn build_with_energy(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
        e0: Option<f64>,
    ) -> Result<Self, MechError> {
        let (res, n, id) = Self::residual_rows(sys, c, (dependent, coordinates, rows), e0)?;
        let (nq, nc) = (sys.nq(), sys.nc());
        let g = &mut sys.graph;
        let dae = if e0.is_none() {
            ImplicitDae::build_selected(g, &res, n, Some(coordinate_rows(nq, n, coordinates)))
        } else {
            ImplicitDae::build(g, &res, n)
        };
        Ok(Index1Formulation {
            dae,
            dependent: dependent.to_vec(),
            coordinates: coordinates.to_vec(),
            rows: rows.to_vec(),
            multipliers: nc,
            energy: e0.map(|e0| EnergyInvariant {
                e0,
                offset: nq + sys.nv() + rows.len() + nc,
            }),
            id,
        })
    }

    /// The residual's rows `R` of [`Index1Formulation::build_with_energy`] as expressions over
    /// `[t, y, y']` (without the invariant: the `n + r` candidate rows, the DAE's rows a
    /// selection of them, [`Index1Formulation::dae_rows`]), the number of unknowns `n` and the
    /// error-test mask. The sensitivity run differentiates them with respect to a parameter
    /// ([`crate::sensitivity`]).
    pub fn residual_rows(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
        e0: Option<f64>,
    ) -> Result<(Vec<Expr>, usize, Vec<f64>), MechError> {
        let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
        let r = rows.len();
        if dependent.len() != r || coordinates.len() != r || rows.iter().any(|&k| k >= nc) {
            return Err(MechError::at(
                "solve.formulation",
                format!(
                    "index-1 needs {r} dependent velocities and coordinates for its {r} independent rows of {nc}, got {} and {}",
                    dependent.len(),
                    coordinates.len()
                ),
            ));
        }
        let n = nq + nv + r + nc + if e0.is_some() { 2 * r + 1 } else { 0 };
        let eta = |k: usize| (1 + nq + nv + r + nc + k) as u32;
        let kappa = |k: usize| (1 + nq + nv + r + nc + r + k) as u32;
        let mu_slot = (1 + nq + nv + r + nc + 2 * r) as u32;
        let a_slot = |k: usize| (1 + nq + nv + k) as u32;
        let lam = |k: usize| (1 + nq + nv + r + k) as u32;
        let qp = |i: usize| (1 + n + i) as u32;
        let vp = |j: usize| (1 + n + nq + j) as u32;
        let dpos = |j: usize| dependent.iter().position(|&d| d == j);
        let qpos = |i: usize| coordinates.iter().position(|&d| d == i);
        let energy = sys.energy;
        let v_slots: Vec<u32> = (0..nv).map(|j| sys.v_slot(j)).collect();
        let measured = crate::partition::coordinates::always_measured_velocities(sys);
        let g = &mut sys.graph;
        // ∂E/∂q and ∂E/∂v in one reverse sweep (linear in the energy's size)
        let (de_dq, de_dv) = if e0.is_some() {
            let slots: Vec<u32> = (0..nq)
                .map(|i| (1 + i) as u32)
                .chain(v_slots.iter().copied())
                .collect();
            let mut d = g.gradient(energy, &slots);
            let dv = d.split_off(nq);
            (d, dv)
        } else {
            (Vec::new(), Vec::new())
        };
        // h = ∂E/∂q − (∂(G_v v)/∂q)ᵀ η: the energy's gradient in the coordinates with the
        // dependent velocities' dependence on them (G_v[R, D]ᵀ η = ∂E/∂v_D)
        let grad: Vec<Expr> = if e0.is_some() {
            (0..nq)
                .map(|i| {
                    let mut terms = vec![de_dq[i]];
                    for (k, &rk) in rows.iter().enumerate() {
                        if g.depends_on(c.gvv[rk], (1 + i) as u32) {
                            let d = g.diff(c.gvv[rk], (1 + i) as u32);
                            let e = g.var(eta(k));
                            let t = g.mul(d, e);
                            terms.push(g.neg(t));
                        }
                    }
                    g.sum(&terms)
                })
                .collect()
        } else {
            Vec::new()
        };
        let mu = g.var(mu_slot);
        let mut res: Vec<Expr> = Vec::with_capacity(n);
        // without the invariant, every coordinate's kinematic row and every position row are
        // candidates, the dependent coordinates' choice a selection among them
        // ([`Index1Formulation::with_coordinates`]): q_i' − K_i v for i ∉ D_q, g_{R_k} for the
        // k-th dependent coordinate
        let selectable = e0.is_none();
        if selectable {
            for i in 0..nq {
                let a = g.var(qp(i));
                res.push(g.sub(a, sys.kinematics[i]));
            }
            res.extend(rows.iter().map(|&k| c.g[k]));
        }
        // q rows
        for i in (0..nq).filter(|_| !selectable) {
            match qpos(i) {
                Some(k) => res.push(c.g[rows[k]]),
                None => {
                    let a = g.var(qp(i));
                    let mut row = g.sub(a, sys.kinematics[i]);
                    if let Some(&h) = grad.get(i) {
                        // + μ ĝ_i, ĝ_i = h_i − Σ_k G_q[R_k, i] κ_k
                        let mut terms = vec![h];
                        for (k, &rk) in rows.iter().enumerate() {
                            if !g.is_zero(c.gq[rk][i]) {
                                let kk = g.var(kappa(k));
                                let t = g.mul(c.gq[rk][i], kk);
                                terms.push(g.neg(t));
                            }
                        }
                        let gi = g.sum(&terms);
                        let push = g.mul(mu, gi);
                        row = g.add(row, push);
                    }
                    res.push(row);
                }
            }
        }
        // dynamics with the multipliers, for v_j' (independent) or a_j (dependent)
        let keep = e0.is_some();
        let dyn_row = |g: &mut crate::expr::ExprGraph, j: usize, acc: Expr| {
            // M_j a_j (a sensitivity run's system may hold M_j as an expression of a parameter)
            let mut inertia = vec![match sys.mass_symbols.get(j) {
                Some(&m) => g.mul(m, acc),
                None => g.scale(sys.mass[j], acc),
            }];
            if keep && sys.mass[j] != 0.0 {
                // + μ M_j v_j
                let v = g.var(v_slots[j]);
                let mv = g.scale(sys.mass[j], v);
                inertia.push(g.mul(mu, mv));
            }
            c.effort_row(g, (j, sys.forces[j]), &inertia, lam)
        };
        for j in 0..nv {
            match dpos(j) {
                Some(k) => res.push(c.gvv[rows[k]]),
                None => {
                    let a = g.var(vp(j));
                    res.push(dyn_row(g, j, a));
                }
            }
        }
        for (k, &j) in dependent.iter().enumerate() {
            let a = g.var(a_slot(k));
            res.push(dyn_row(g, j, a));
        }
        for k in 0..nc {
            if !rows.contains(&k) {
                // a redundant row: its multiplier is held at zero
                res.push(g.var(lam(k)));
                continue;
            }
            res.push(c.acceleration_row(g, k, |j| match dpos(j) {
                Some(kk) => a_slot(kk),
                None => vp(j),
            }));
        }
        if let Some(e0) = e0 {
            // η: G_v[R, D]ᵀ η − ∂E/∂v_D = 0, one row per dependent velocity
            for &j in dependent {
                let mut terms = vec![];
                terms.push(g.neg(de_dv[j]));
                for (k, &rk) in rows.iter().enumerate() {
                    if !g.is_zero(c.gv[rk][j]) {
                        let e = g.var(eta(k));
                        terms.push(g.mul(c.gv[rk][j], e));
                    }
                }
                res.push(g.sum(&terms));
            }
            // κ: G_q[R, D_q]ᵀ κ − h_D = 0, one row per dependent coordinate
            for &i in coordinates {
                let mut terms = vec![g.neg(grad[i])];
                for (k, &rk) in rows.iter().enumerate() {
                    if !g.is_zero(c.gq[rk][i]) {
                        let kk = g.var(kappa(k));
                        terms.push(g.mul(c.gq[rk][i], kk));
                    }
                }
                res.push(g.sum(&terms));
            }
            // μ: E(q, v) − E₀ = 0
            let e = g.constant(e0);
            res.push(g.sub(energy, e));
        }
        let id = error_test_mask((nq, nv, n), coordinates, dependent, &measured);
        Ok((res, n, id))
    }

    /// The DAE's rows among [`Index1Formulation::residual_rows`]'s (the candidate row of each
    /// row, in order) for the dependent coordinates `coordinates`, without the invariant.
    pub fn dae_rows(nq: usize, n: usize, coordinates: &[usize]) -> Vec<usize> {
        coordinate_rows(nq, n, coordinates)
    }
}

/// The candidate row of each row of the index-1 DAE without the energy invariant (`n` rows,
/// the candidates `[q_i' − K_i v (nq), g_{R_k} (r), the other n − nq rows]`): coordinate `i`'s
/// row is its kinematic row, or the `k`-th position row where `i` is the `k`-th dependent
/// coordinate; the other rows follow in order.
fn coordinate_rows(nq: usize, n: usize, coordinates: &[usize]) -> Vec<usize> {
    let r = coordinates.len();
    (0..nq)
        .map(|i| match coordinates.iter().position(|&d| d == i) {
            Some(k) => nq + k,
            None => i,
        })
        .chain((nq..n).map(|j| j + r))
        .collect()
}
