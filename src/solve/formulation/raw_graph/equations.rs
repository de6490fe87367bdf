//! The DAEs of a raw bond graph (seed 16.5–16.7 written as a graph by hand), for IDA and
//! CVODE: the causal equations [`BondEquations`] of [`crate::bond::equations`] (integral
//! states, differential storages with their velocity-level constraint rows, algebraic loops)
//! formed into
//!
//! ```text
//!   index 2 (velocity level):  [x' − f,  p_d' − λ,  φ_d − p_d/m_d,  z − h] = 0
//!   index 1:                   [x' − f,  p_d' − λ,  d/dt(φ_d − p_d/m_d),  z − h] = 0
//! ```
//!
//! over the unknowns `y = [x, p_d, λ, z]` (`λ`, `z` algebraic), or the ODE `x' = f(t, x)` when
//! no storage is in differential causality and no loop is algebraic.

use nalgebra::{DMatrix, DVector};

use crate::bond::equations::{BondEquations, EquationError, VariableKind};
use crate::dae::compiled::{ExplicitOde, ImplicitDae};
use crate::expr::Expr;

impl BondEquations {
    /// Is it a plain ODE (no differential storage, no algebraic loop)?
    pub fn is_ode(&self) -> bool {
        self.n_dependent == 0 && self.n_loops == 0
    }

    /// `1` for differential unknowns (`x`, `p_d`), `0` for algebraic ones (`λ`, `z`).
    pub fn id(&self) -> Vec<f64> {
        self.kinds
            .iter()
            .map(|k| match k {
                VariableKind::Multiplier | VariableKind::Loop => 0.0,
                _ => 1.0,
            })
            .collect()
    }

    /// The explicit ODE `ẋ = f(t, x)` for CVODE, when [`Self::is_ode`].
    pub fn ode(&self) -> Option<ExplicitOde> {
        if !self.is_ode() {
            return None;
        }
        let mut g = self.graph.clone();
        Some(ExplicitOde::build(&mut g, &self.rhs))
    }

    fn yp(&mut self, i: usize) -> Expr {
        self.graph.var((self.n + 1 + i) as u32)
    }

    fn y(&mut self, i: usize) -> Expr {
        self.graph.var((1 + i) as u32)
    }

    /// Rows common to both formulations, with `constraint(row)` supplying the constraint rows.
    fn residual_with(&mut self, index1: bool) -> Vec<Expr> {
        let (nx, nd) = (self.n_states, self.n_dependent);
        let mut r = Vec::with_capacity(self.n);
        for i in 0..nx {
            let d = self.yp(i);
            r.push(self.graph.sub(d, self.rhs[i]));
        }
        for j in 0..nd {
            let d = self.yp(nx + j);
            let l = self.y(nx + nd + j);
            r.push(self.graph.sub(d, l));
        }
        for j in 0..nd {
            let c = self.constraints[j];
            if index1 {
                r.push(self.total_derivative(c));
            } else {
                r.push(c);
            }
        }
        r.extend(self.loop_rows.iter().copied());
        r
    }

    /// `Σⱼ ∂c/∂yⱼ·y'ⱼ + ∂c/∂t`.
    fn total_derivative(&mut self, c: Expr) -> Expr {
        let mut acc = self.graph.diff(c, 0);
        for v in self.graph.vars(c) {
            let v = v as usize;
            if v == 0 || v > self.n {
                continue;
            }
            let d = self.graph.diff(c, v as u32);
            let yp = self.yp(v - 1);
            let t = self.graph.mul(d, yp);
            acc = self.graph.add(acc, t);
        }
        acc
    }

    /// The index-2 residual rows `[x' − f, p_d' − λ, φ_d − p_d/m_d, z − h]` (slots `[t, y, y']`).
    pub fn residual_index2(&mut self) -> Vec<Expr> {
        self.residual_with(false)
    }

    /// The index-1 residual rows: as [`Self::residual_index2`] with each constraint row
    /// replaced by its total time derivative.
    pub fn residual_index1(&mut self) -> Vec<Expr> {
        self.residual_with(true)
    }

    /// The velocity-level index-2 DAE for IDA (`λ`, `z` algebraic: use [`Self::id`] and
    /// suppress them from the error test).
    pub fn velocity_index2(&self) -> ImplicitDae {
        let mut me = self.clone();
        let r = me.residual_index2();
        ImplicitDae::build(&mut me.graph, &r, self.n)
    }

    /// The index-1 DAE (constraint rows differentiated once; the constraints may drift).
    pub fn index1(&self) -> ImplicitDae {
        let mut me = self.clone();
        let r = me.residual_index1();
        ImplicitDae::build(&mut me.graph, &r, self.n)
    }

    /// Structural non-zeros `(row, col)` of `∂F/∂y + ∂F/∂y'` of the index-2 residual, sorted.
    pub fn sparsity(&self) -> Vec<(usize, usize)> {
        let mut me = self.clone();
        let rows = me.residual_index2();
        let mut out = Vec::new();
        for (i, &r) in rows.iter().enumerate() {
            for v in me.graph.vars(r) {
                let v = v as usize;
                if v >= 1 && v <= 2 * self.n {
                    out.push((i, (v - 1) % self.n));
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Consistent `(y, y')` at `t0` starting from `y_guess` (its integral states are kept):
    /// the dependent momenta are projected onto the constraints (Newton on `φ_d − p_d/m_d = 0`),
    /// then `y'` of the differential unknowns and the algebraic `λ`, `z` solve the index-1
    /// system (Newton with the exact Jacobian).
    pub fn consistent_start(
        &self,
        t0: f64,
        y_guess: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), EquationError> {
        let n = self.n;
        let (nx, nd) = (self.n_states, self.n_dependent);
        let ndiff = nx + nd;
        let dae2 = self.velocity_index2();
        let dae1 = self.index1();
        let mut ws2 = dae2.workspace();
        let mut ws1 = dae1.workspace();
        let mut y = y_guess.to_vec();
        let mut yp = vec![0.0; n];
        let mut r = vec![0.0; n];
        let jac =
            |dae: &ImplicitDae, ws: &mut crate::dae::Workspace, cj: f64, y: &[f64], yp: &[f64]| {
                let mut m = DMatrix::<f64>::zeros(n, n);
                dae.jacobian(ws, t0, cj, y, yp, |i, j, v| m[(i, j)] += v);
                m
            };
        let fail = |what: &str| EquationError::Initialisation(what.to_string());
        for _outer in 0..4 {
            // 1. dependent momenta onto the velocity constraints
            for _ in 0..20 {
                dae2.residual(&mut ws2, t0, &y, &yp, &mut r);
                let c = DVector::from_iterator(nd, r[ndiff..ndiff + nd].iter().copied());
                if c.amax() <= 1e-14 * (1.0 + y.iter().fold(0.0f64, |a, b| a.max(b.abs()))) {
                    break;
                }
                let j0 = jac(&dae2, &mut ws2, 0.0, &y, &yp);
                let a = j0.view((ndiff, nx), (nd, nd)).into_owned();
                let dx = a.lu().solve(&c).ok_or_else(|| {
                    fail("the constraint rows do not depend on the dependent momenta")
                })?;
                for k in 0..nd {
                    y[nx + k] -= dx[k];
                }
            }
            // 2. y' of the differential unknowns and the algebraic unknowns (index-1 system)
            let mut converged = false;
            for _ in 0..30 {
                dae1.residual(&mut ws1, t0, &y, &yp, &mut r);
                let scale = 1.0 + y.iter().chain(&yp).fold(0.0f64, |a, b| a.max(b.abs()));
                if r.iter().fold(0.0f64, |a, b| a.max(b.abs())) <= 1e-13 * scale {
                    converged = true;
                    break;
                }
                let j0 = jac(&dae1, &mut ws1, 0.0, &y, &yp);
                let j1 = jac(&dae1, &mut ws1, 1.0, &y, &yp);
                let mut a = DMatrix::<f64>::zeros(n, n);
                for col in 0..n {
                    for row in 0..n {
                        a[(row, col)] = if col < ndiff {
                            j1[(row, col)] - j0[(row, col)]
                        } else {
                            j0[(row, col)]
                        };
                    }
                }
                let rv = DVector::from_column_slice(&r);
                let du = a.lu().solve(&rv).ok_or_else(|| {
                    fail("the index-1 system is singular at the start (λ or loop variables undetermined)")
                })?;
                for col in 0..n {
                    if col < ndiff {
                        yp[col] -= du[col];
                    } else {
                        y[col] -= du[col];
                    }
                }
            }
            if !converged {
                return Err(fail("Newton did not converge on the index-1 system"));
            }
            dae2.residual(&mut ws2, t0, &y, &yp, &mut r);
            if r[ndiff..ndiff + nd].iter().all(|c| c.abs() <= 1e-12) {
                return Ok((y, yp));
            }
        }
        Ok((y, yp))
    }
}
