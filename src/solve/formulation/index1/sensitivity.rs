//! `∂F/∂p` of the index-1 DAE for a sensitivity run: the same residual rows
//! ([`Index1Formulation::residual_rows`]) built from the mechanism with its parameters as
//! symbols ([`SymbolicSystem`]), differentiated with respect to each symbol and evaluated at
//! the parameters' values. For the rows of `F`:
//!
//! ```text
//!   ∂/∂p (q_I' − K_I v)                = −∂K_I/∂p v
//!   ∂/∂p g_R(q)                        = ∂g_R/∂p
//!   ∂/∂p (M_j a_j − Q_j + G_jᵀ λ)       = ∂M_j/∂p a_j − ∂Q_j/∂p + ∂G_jᵀ/∂p λ
//!   ∂/∂p (G_v v)_R, (G_I v_I' + G_D a_D + γ)_R  likewise
//! ```

use super::Index1Formulation;
use crate::dae::ConstraintExprs;
use crate::expr::Expr;
use crate::mech::MechError;
use crate::solve::formulation::ParameterSymbols;

impl Index1Formulation {
    /// `∂F/∂p_k` of the index-1 DAE with the dependent velocities, coordinates and joint rows
    /// `partition`, one list of `n` rows (in the DAE's row order, over `[t, y, y']`) per
    /// parameter of `sym`. Refused with the energy invariant (its rows hold the energy `E₀` of
    /// the start).
    pub fn parameter_rows(
        sym: &mut dyn ParameterSymbols,
        partition: (&[usize], &[usize], &[usize]),
        energy: bool,
    ) -> Result<Vec<Vec<Expr>>, MechError> {
        if energy {
            return Err(MechError::at(
                "solve.energy_invariant",
                "sensitivities are not computed with the energy invariant (its rows hold the start's energy)",
            ));
        }
        let sys = sym.system();
        let c = ConstraintExprs::derive(sys);
        let (res, n, _) = Self::residual_rows(sys, &c, partition, None)?;
        let rows: Vec<Expr> = Self::dae_rows(sys.nq(), n, partition.1)
            .iter()
            .map(|&i| res[i])
            .collect();
        Ok(sym.derivatives(&rows))
    }
}
