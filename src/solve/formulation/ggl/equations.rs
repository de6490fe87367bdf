//! Stabilized index-2 formulation (Gear–Gupta–Leimkuhler), optionally compliant.
//!
//! Unknowns `y = [q, v, λ, μ]`; residual
//!
//! ```text
//!   F_q = q' − K(q) v + G_qᵀ μ          (μ keeps q on g = 0; it is zero on the exact solution)
//!   F_v = M v' − Q(t, q, v) + G_vᵀ λ    (λ: the efforts at the differential-causality inertias)
//!   F_g = g(q) − ε μ
//!   F_w = G_v(q) v − ε λ
//! ```
//!
//! With `ε = 0` this is plain GGL. A small `ε > 0` (the *compliant* GGL) keeps the Newton
//! matrix regular where `G` loses rank for an instant (aligned four-bar chains, an isosceles
//! slider-crank at its bifurcation): the joints then behave as extremely stiff springs of
//! compliance ε exactly there, and as rigid joints elsewhere. `λ, μ` are algebraic (id 0),
//! excluded from IDA's error test.
//!
//! ε is applied at evaluation time ([`GglFormulation::residual`], [`GglFormulation::jacobian`]),
//! not compiled into the tapes, so one compiled residual serves both forms and the solver can
//! switch between them (`src/solve/formulation/ggl/runner.rs` does so at singular passages) by a
//! re-initialisation.

use crate::dae::compiled::{ImplicitDae, Workspace};
use crate::dae::mechanics::ConstraintExprs;
use crate::expr::Expr;
use crate::mech::MultibodySystem;

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
            let ma = g.scale(sys.mass[j], a);
            res.push(c.effort_row(g, (j, sys.forces[j]), &[ma], lam));
        }
        res.extend(c.g.iter().copied());
        res.extend(c.gvv.iter().copied());
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
        }
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
    /// position rows and `ε λ` in the velocity rows.
    pub fn residual(
        &self,
        ws: &mut Workspace,
        eps: f64,
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
        }
    }

    /// Calls `put(row, col, value)` for every entry of `∂F/∂y + cj ∂F/∂y'` with compliance
    /// `eps` (entries may repeat: the caller adds them).
    #[allow(clippy::too_many_arguments)]
    pub fn jacobian(
        &self,
        ws: &mut Workspace,
        eps: f64,
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
        }
    }
}
