//! Stabilized index-2 formulation (Gear–Gupta–Leimkuhler), optionally compliant.
//!
//! Unknowns `y = [q, v, λ, μ]`; residual
//!
//! ```text
//!   F_q = q' − K(q) v + G_qᵀ μ          (μ keeps q on g = 0; it is zero on the exact solution)
//!   F_v = M v' − Q(t, q, v) + G_vᵀ λ − α M v   (λ: the efforts at the differential-causality inertias)
//!   F_g = g(q) − ε μ
//!   F_w = G_v(q) v − ε λ
//! ```
//!
//! With `ε = 0` this is plain GGL (`α = 0`). A small `ε > 0` (the *compliant* GGL) keeps the
//! Newton matrix regular where `G` loses rank for an instant (aligned four-bar chains, an
//! isosceles slider-crank at its bifurcation): the joints then give a little exactly there,
//! and are rigid elsewhere. `λ, μ` are algebraic (id 0), excluded from IDA's error test.
//!
//! **The compliant joints give back what they absorb.** With `E = T + V`, `T = ½ vᵀ M v`, the
//! residual gives `dE/dt = P − λᵀ G_v v − ∂E/∂q · G_qᵀ μ + α vᵀ M v`, `P` the power of the
//! scene's own forces. Rigid joints do no work (`G_v v = 0`, `μ = 0`); compliant ones absorb
//! `p = ε |λ|² + ∂E/∂q · G_qᵀ μ` — the velocity rows act as a damper of rate `1/ε`, the
//! position multipliers' slip `q' − K v` moves the potential. Near a singular configuration
//! `|λ|` grows to `~1/√ε` for a time `~√ε`, and a change-point four-bar lost 1.75e-5 J
//! (3e-6 of its energy) at each passage whatever the tolerance (the trial's F3). The rate
//!
//! ```text
//!   α = p / (vᵀ M v + |p| τ)
//! ```
//!
//! gives `p` back along the momentum, where it changes no joint row to first order (`G_v v ≈ 0`)
//! — the counterpart of the energy invariant's `−μ M v` in the index-1 formulation. It is on
//! where the compliance carries a singular passage ([`crate::solve::formulation::GglDae::set_restoring`]: the GGL's
//! switch, the partitioned formulation's passage), not where the compliance is there from the
//! start (`compliant_ggl`, redundant joints): `μ` is an algebraic unknown held to IDA's
//! multiplier tolerance, and `∂E/∂q · G_qᵀ μ` carries that error `∂E/∂q · G_qᵀ` times over
//! the whole run (Bricard's mechanism at rtol 1e-9 went from seconds to more than ten
//! minutes with the rate on from the start). At rest
//! both parts of `p` cancel (`Q = G_vᵀ λ`, so the slip power is `−ε |λ|²`), and `τ`
//! ([`RESTORING_TIME`]) bounds `α` where the mechanism slows. The Newton matrix holds the
//! rate's diagonal `−α M`; its rank-one couplings through `p` and `vᵀ M v` (relative size
//! `|α| h` at a step `h`) are left to IDA's modified Newton iteration.
//!
//! ε is applied at evaluation time ([`GglFormulation::residual`], [`GglFormulation::jacobian`]),
//! not compiled into the tapes, so one compiled residual serves both forms and the solver can
//! switch between them (`src/solve/formulation/ggl/runner.rs` does so at singular passages) by a
//! re-initialisation.

use crate::dae::compiled::{CompanionScalar, ImplicitDae, Workspace};
use crate::dae::mechanics::ConstraintExprs;
use crate::expr::Expr;
use crate::mech::MultibodySystem;

/// The time `τ` that bounds the restoring rate, `|α| ≤ 1/τ`: where the mechanism nearly rests
/// (`vᵀ M v < |p| τ`) the power is given back only in part, and the diagonal `−α M` the rate
/// puts into the Newton matrix stays small against `c_j M` at any step IDA takes there. At a
/// passage the part not given back is `|p| τ / vᵀ M v` of the power: 1e-5 on the
/// change-point four-bar (`p` ≈ 0.1 W, `vᵀ M v` ≈ 10 J).
pub const RESTORING_TIME: f64 = 1e-3;

/// The GGL residual of a multibody system, compiled with its exact Jacobian.
#[derive(Clone, Debug)]
pub struct GglFormulation {
    /// The compiled residual.
    pub dae: ImplicitDae,
    /// Compliance ε asked for at build time (0 for plain GGL); the evaluation functions take
    /// the ε to use as an argument.
    pub compliance: f64,
    /// `(nq, nv, nc)`: `λ_k` is unknown `nq + nv + k`, `μ_k` is `nq + nv + nc + k`.
    pub dims: (usize, usize, usize),
    /// 1 for differential unknowns (q, v), 0 for algebraic (λ, μ).
    pub id: Vec<f64>,
    /// Names of the unknowns.
    pub names: Vec<String>,
    /// The diagonal mass matrix `M` (the velocities' inertias).
    pub mass: Vec<f64>,
    /// `∂E/∂q · G_qᵀ μ`, the power the position multipliers' slip takes from the energy.
    slip_power: CompanionScalar,
}

impl GglFormulation {
    /// Builds `F(t, y, y')` as in the module documentation (`compliance` is recorded; the
    /// compiled tapes hold the ε = 0 residual and ε is added by the evaluation functions).
    ///
    /// Slots: `y = [q, v, λ, μ]` at `1..=n`, `y'` at `n+1..=2n`; the first `1 + nq + nv` slots
    /// coincide with the state layout of the multibody system.
    pub fn build(sys: &mut MultibodySystem, c: &ConstraintExprs, compliance: f64) -> Self {
        let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
        let n = nq + nv + 2 * nc;
        let mu = |k: usize| (1 + nq + nv + nc + k) as u32;
        let res = Self::residual_rows(sys, c);
        let energy = sys.energy;
        let g = &mut sys.graph;
        // the slip power ∂E/∂q · G_qᵀ μ (what the position multipliers' slip q' − K v takes
        // from the energy)
        let q_slots: Vec<u32> = (0..nq).map(|i| (1 + i) as u32).collect();
        let de_dq = g.gradient(energy, &q_slots);
        let mut slip_terms = Vec::new();
        for (i, &d) in de_dq.iter().enumerate() {
            if g.is_zero(d) {
                continue;
            }
            let mut inner = Vec::new();
            for k in 0..nc {
                if !g.is_zero(c.gq[k][i]) {
                    let m = g.var(mu(k));
                    inner.push(g.mul(c.gq[k][i], m));
                }
            }
            if !inner.is_empty() {
                let sum = g.sum(&inner);
                slip_terms.push(g.mul(d, sum));
            }
        }
        let slip = g.sum(&slip_terms);
        let slip_power = CompanionScalar::build(g, slip);
        let mut id = vec![1.0; nq + nv];
        id.extend(std::iter::repeat_n(0.0, 2 * nc));
        let mut names: Vec<String> = sys.coords.iter().map(|c| c.name.clone()).collect();
        names.extend(sys.velocities.iter().map(|c| c.name.clone()));
        for tag in ["lambda", "mu"] {
            for r in &sys.rows {
                names.push(format!("{}.{}.{}", r.joint, r.direction, tag));
            }
        }
        GglFormulation {
            dae: ImplicitDae::build(g, &res, n),
            compliance,
            dims: (nq, nv, nc),
            id,
            names,
            mass: sys.mass.clone(),
            slip_power,
        }
    }

    /// `∂F/∂p_k` of the GGL residual at `ε = 0`, one list of rows (over `[t, y, y']`) per
    /// parameter of `sym`: the residual rows built from the mechanism with its parameters as
    /// symbols, differentiated ([`crate::sensitivity`]); `ε` and the restoring rate do not
    /// depend on the parameters. Also the hidden constraints `G_v v' + γ = 0` (over `[t, y,
    /// y']` and the symbols), which determine the multipliers' sensitivities at the start.
    pub fn parameter_rows(
        sym: &mut dyn crate::solve::formulation::ParameterSymbols,
    ) -> (Vec<Vec<Expr>>, Vec<Expr>) {
        let sys = sym.system();
        let c = ConstraintExprs::derive(sys);
        let rows = Self::residual_rows(sys, &c);
        let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
        let n = nq + nv + 2 * nc;
        let hidden: Vec<Expr> = (0..nc)
            .map(|k| c.acceleration_row(&mut sys.graph, k, |j| (1 + n + nq + j) as u32))
            .collect();
        (sym.derivatives(&rows), hidden)
    }

    /// `F(t, y, y')` at `ε = 0` (the rows of the module documentation) as expressions over
    /// `[t, y, y']`.
    pub fn residual_rows(sys: &mut MultibodySystem, c: &ConstraintExprs) -> Vec<Expr> {
        let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
        let n = nq + nv + 2 * nc;
        let lam = |k: usize| (1 + nq + nv + k) as u32;
        let mu = |k: usize| (1 + nq + nv + nc + k) as u32;
        let qp = |i: usize| (1 + n + i) as u32;
        let vp = |j: usize| (1 + n + nq + j) as u32;
        let g = &mut sys.graph;
        let mut res: Vec<Expr> = Vec::with_capacity(n);
        for i in 0..nq {
            let mut terms = vec![g.var(qp(i))];
            terms.push(g.neg(sys.kinematics[i]));
            for k in 0..nc {
                if !g.is_zero(c.gq[k][i]) {
                    let m = g.var(mu(k));
                    terms.push(g.mul(c.gq[k][i], m));
                }
            }
            res.push(g.sum(&terms));
        }
        for j in 0..nv {
            let a = g.var(vp(j));
            // M_j v_j' (a sensitivity run's system may hold M_j as an expression of a parameter)
            let ma = match sys.mass_symbols.get(j) {
                Some(&m) => g.mul(m, a),
                None => g.scale(sys.mass[j], a),
            };
            res.push(c.effort_row(g, (j, sys.forces[j]), &[ma], lam));
        }
        res.extend(c.g.iter().copied());
        res.extend(c.gvv.iter().copied());
        res
    }

    /// The structural non-zeros of `∂F/∂y + cj ∂F/∂y'` for any compliance: the compiled
    /// tapes' entries and the `(λ_k, μ_k)`, `(μ_k, λ_k)` pairs where `−ε` enters, so one
    /// sparsity pattern serves plain and compliant GGL alike.
    pub fn structure(&self) -> Vec<(usize, usize)> {
        let (nq, nv, nc) = self.dims;
        let (lam, mu) = (nq + nv, nq + nv + nc);
        let mut s: Vec<(usize, usize)> = self.dae.structure().collect();
        for k in 0..nc {
            s.push((lam + k, mu + k));
            s.push((mu + k, lam + k));
        }
        s
    }

    /// `F(t, y, y')` with compliance `eps`: the compiled ε = 0 residual minus `ε μ` in the
    /// position rows and `ε λ` in the velocity rows, and where `restore` the restoring rate's
    /// `α M v` in the dynamics rows.
    pub fn residual(
        &self,
        ws: &mut Workspace,
        (eps, restore): (f64, bool),
        t: f64,
        y: &[f64],
        yp: &[f64],
        r: &mut [f64],
    ) {
        self.dae.residual(ws, t, y, yp, r);
        if eps != 0.0 {
            let (nq, nv, nc) = self.dims;
            let (lam, mu) = (nq + nv, nq + nv + nc);
            for k in 0..nc {
                r[lam + k] -= eps * y[mu + k];
                r[mu + k] -= eps * y[lam + k];
            }
            if restore {
                let alpha = self.restoring_rate(ws, eps, y);
                for (j, m) in self.mass.iter().enumerate() {
                    r[nq + j] -= alpha * m * y[nq + j];
                }
            }
        }
    }

    /// The rate `α` at which the compliant joints' absorbed power is given back along the
    /// momentum: `α = p / (vᵀ M v + p τ)`, `p = ε |λ|²` (see the module documentation).
    fn restoring_rate(&self, ws: &mut Workspace, eps: f64, y: &[f64]) -> f64 {
        let (nq, nv, nc) = self.dims;
        let lam = &y[nq + nv..nq + nv + nc];
        let p = eps * lam.iter().map(|l| l * l).sum::<f64>() + self.slip_power.eval_loaded(ws);
        if p == 0.0 {
            return 0.0;
        }
        let t2: f64 = (self.mass.iter().zip(&y[nq..nq + nv]))
            .map(|(m, v)| m * v * v)
            .sum();
        p / (t2 + p.abs() * RESTORING_TIME)
    }

    /// Calls `put(row, col, value)` for every entry of `∂F/∂y + cj ∂F/∂y'` with compliance
    /// `eps` (entries may repeat: the caller adds them).
    #[allow(clippy::too_many_arguments)]
    pub fn jacobian(
        &self,
        ws: &mut Workspace,
        (eps, restore): (f64, bool),
        t: f64,
        cj: f64,
        y: &[f64],
        yp: &[f64],
        mut put: impl FnMut(usize, usize, f64),
    ) {
        self.dae.jacobian(ws, t, cj, y, yp, &mut put);
        if eps != 0.0 {
            let (nq, nv, nc) = self.dims;
            let (lam, mu) = (nq + nv, nq + nv + nc);
            for k in 0..nc {
                put(lam + k, mu + k, -eps);
                put(mu + k, lam + k, -eps);
            }
            if restore {
                let alpha = self.restoring_rate(ws, eps, y);
                for (j, m) in self.mass.iter().enumerate() {
                    put(nq + j, nq + j, -alpha * m);
                }
            }
        }
    }
}
