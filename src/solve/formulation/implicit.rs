//! The one interface IDA's runner sees: a formulation as a fully implicit DAE
//! `F(t, y, y') = 0` with its exact iteration matrix `J = ∂F/∂y + c_j ∂F/∂y'` and the id vector
//! (differential or algebraic unknowns). The GGL DAE (plain or compliant), the index-1 DAE and
//! a raw bond graph's DAEs implement it; the solver set-up ([`crate::solve`]) is written once
//! against it.
//!
//! ```
//! use bondmech::dae::ConstraintExprs;
//! use bondmech::solve::formulation::{DaeFormulation, GglDae, GglFormulation};
//! let scene = bondmech::Scene::from_path("scenes/pendulum.json").unwrap();
//! let mut sys = bondmech::mech::build(&scene).unwrap();
//! let c = ConstraintExprs::derive(&mut sys);
//! let ggl = GglDae::new(GglFormulation::build(&mut sys, &c, 0.0), 0.0);
//! let f: &dyn DaeFormulation = &ggl;
//! // q, v, λ, μ: the pendulum's 3 coordinates and velocities, 2 rows
//! assert_eq!((f.len(), f.id().iter().filter(|&&d| d == 0.0).count()), (10, 4));
//! ```

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use super::GglFormulation;
use super::Index1Formulation;
use crate::dae::compiled::{ImplicitDae, Workspace};
use crate::sundials::ColumnOrdering;

/// A formulation as a fully implicit DAE for IDA (see the module documentation).
pub trait DaeFormulation: Send + Sync {
    /// Number of unknowns `n` (and of equations).
    fn len(&self) -> usize;
    /// Whether it has no unknowns.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// IDA's id vector: 1 for a differential unknown, 0 for an algebraic one.
    fn id(&self) -> &[f64];
    /// Fresh evaluation buffers.
    fn workspace(&self) -> Workspace;
    /// `r = F(t, y, y')`.
    fn residual(&self, ws: &mut Workspace, t: f64, y: &[f64], yp: &[f64], r: &mut [f64]);
    /// Calls `put(row, col, value)` for every entry of `J = ∂F/∂y + c_j ∂F/∂y'` (entries may
    /// repeat: values add).
    #[allow(clippy::too_many_arguments)]
    fn jacobian(
        &self,
        ws: &mut Workspace,
        t: f64,
        cj: f64,
        y: &[f64],
        yp: &[f64],
        put: &mut dyn FnMut(usize, usize, f64),
    );
    /// `values[slots[k]] += J_k` for the `k`-th entry `J_k` of `J` in the order of
    /// [`Self::structure`] at `(t, c_j)` and `(y, y')` (`into = (slots, values)`, `slots`: each
    /// entry's place among a sparse matrix's values, one per entry), without a call per entry; `false` (nothing written) where the formulation does
    /// not do so, and the caller puts the entries one by one ([`Self::jacobian`]).
    fn jacobian_into_slots(
        &self,
        _ws: &mut Workspace,
        _at: (f64, f64),
        _state: (&[f64], &[f64]),
        _into: (&[usize], &mut [f64]),
    ) -> bool {
        false
    }
    /// The structural non-zeros `(row, col)` of `J` (the sparsity pattern of the Newton matrix).
    fn structure(&self) -> Vec<(usize, usize)>;
    /// `∂F/∂y` into `dy` and `∂F/∂y'` into `dyp` as `(row, col, value)` at `(t, y, y')` (values
    /// of repeated entries add), for the sensitivity residual `F_y s + F_y' s' + ∂F/∂p`;
    /// `false` where the formulation does not give them apart.
    fn jacobian_parts(
        &self,
        _ws: &mut Workspace,
        _t: f64,
        _state: (&[f64], &[f64]),
        _dy: &mut Vec<(usize, usize, f64)>,
        _dyp: &mut Vec<(usize, usize, f64)>,
    ) -> bool {
        false
    }
    /// How faer's sparse LU orders the columns of `J` (where the Newton matrix is sparse):
    /// COLAMD unless the formulation knows better.
    fn sparse_ordering(&self) -> ColumnOrdering {
        ColumnOrdering::Colamd
    }
}

/// The GGL DAE at a compliance `ε` that can change between steps (the runner switches to the
/// compliant GGL at a singular passage and restarts IDA): `F` and `J` of [`GglFormulation`]
/// evaluated at the current `ε`.
#[derive(Debug)]
pub struct GglDae {
    /// The compiled GGL residual.
    pub formulation: Arc<GglFormulation>,
    compliance: AtomicU64,
    restoring: AtomicBool,
}

impl GglDae {
    /// The GGL DAE at compliance `eps` (0: plain GGL).
    pub fn new(formulation: GglFormulation, eps: f64) -> Self {
        Self::shared(Arc::new(formulation), eps)
    }
    /// The GGL DAE of a shared formulation at compliance `eps`.
    pub fn shared(formulation: Arc<GglFormulation>, eps: f64) -> Self {
        GglDae {
            formulation,
            compliance: AtomicU64::new(eps.to_bits()),
            restoring: AtomicBool::new(false),
        }
    }
    /// The current compliance `ε`.
    pub fn compliance(&self) -> f64 {
        f64::from_bits(self.compliance.load(Ordering::Relaxed))
    }
    /// Sets the compliance used by later evaluations.
    pub fn set_compliance(&self, eps: f64) {
        self.compliance.store(eps.to_bits(), Ordering::Relaxed);
    }
    /// Whether the compliant joints give back the power they absorb
    /// ([`GglFormulation::residual`]): set where the compliance carries a singular passage.
    pub fn set_restoring(&self, on: bool) {
        self.restoring.store(on, Ordering::Relaxed);
    }
    fn restoring(&self) -> bool {
        self.restoring.load(Ordering::Relaxed)
    }
}

impl DaeFormulation for GglDae {
    fn len(&self) -> usize {
        self.formulation.dae.n
    }
    fn id(&self) -> &[f64] {
        &self.formulation.id
    }
    fn workspace(&self) -> Workspace {
        self.formulation.dae.workspace()
    }
    fn residual(&self, ws: &mut Workspace, t: f64, y: &[f64], yp: &[f64], r: &mut [f64]) {
        self.formulation
            .residual(ws, (self.compliance(), self.restoring()), t, y, yp, r);
    }
    fn jacobian(
        &self,
        ws: &mut Workspace,
        t: f64,
        cj: f64,
        y: &[f64],
        yp: &[f64],
        put: &mut dyn FnMut(usize, usize, f64),
    ) {
        self.formulation
            .jacobian(ws, (self.compliance(), self.restoring()), t, cj, y, yp, put);
    }
    fn structure(&self) -> Vec<(usize, usize)> {
        self.formulation.structure()
    }
    fn jacobian_parts(
        &self,
        ws: &mut Workspace,
        t: f64,
        state: (&[f64], &[f64]),
        dy: &mut Vec<(usize, usize, f64)>,
        dyp: &mut Vec<(usize, usize, f64)>,
    ) -> bool {
        // the restoring rate's couplings through `p` are not in the matrix (left to Newton)
        if self.restoring() {
            return false;
        }
        self.formulation.dae.jacobian_parts(ws, t, state, dy, dyp);
        let eps = self.compliance();
        if eps != 0.0 {
            let (nq, nv, nc) = self.formulation.dims;
            let (lam, mu) = (nq + nv, nq + nv + nc);
            for k in 0..nc {
                dy.push((lam + k, mu + k, -eps));
                dy.push((mu + k, lam + k, -eps));
            }
        }
        true
    }
}

/// `DaeFormulation` for a type holding a compiled residual `dae: ImplicitDae` and its id vector
/// `id: Vec<f64>`.
macro_rules! compiled_with_id {
    ($t:ty, $ordering:expr) => {
        impl DaeFormulation for $t {
            fn len(&self) -> usize {
                self.dae.n
            }
            fn id(&self) -> &[f64] {
                &self.id
            }
            fn workspace(&self) -> Workspace {
                self.dae.workspace()
            }
            fn residual(&self, ws: &mut Workspace, t: f64, y: &[f64], yp: &[f64], r: &mut [f64]) {
                self.dae.residual(ws, t, y, yp, r);
            }
            fn jacobian(
                &self,
                ws: &mut Workspace,
                t: f64,
                cj: f64,
                y: &[f64],
                yp: &[f64],
                put: &mut dyn FnMut(usize, usize, f64),
            ) {
                self.dae.jacobian(ws, t, cj, y, yp, put);
            }
            fn jacobian_into_slots(
                &self,
                ws: &mut Workspace,
                at: (f64, f64),
                state: (&[f64], &[f64]),
                into: (&[usize], &mut [f64]),
            ) -> bool {
                self.dae.jacobian_into_slots(ws, at, state, into)
            }
            fn structure(&self) -> Vec<(usize, usize)> {
                self.dae.structure().collect()
            }
            fn jacobian_parts(
                &self,
                ws: &mut Workspace,
                t: f64,
                state: (&[f64], &[f64]),
                dy: &mut Vec<(usize, usize, f64)>,
                dyp: &mut Vec<(usize, usize, f64)>,
            ) -> bool {
                self.dae.jacobian_parts(ws, t, state, dy, dyp);
                true
            }
            fn sparse_ordering(&self) -> ColumnOrdering {
                $ordering
            }
        }
    };
}

// The index-1 DAE's acceleration rows have no entry in their multipliers' columns, and COLAMD,
// which bounds the fill of any row pivoting, orders it poorly: the cheapest of three orders
// (ColumnOrdering::Cheapest: on the N-link pendulum at N = 256, Cuthill–McKee's, 0.53 times
// COLAMD's multiply–adds).
compiled_with_id!(Index1Formulation, ColumnOrdering::Cheapest);
compiled_with_id!(IdDae, ColumnOrdering::Colamd);

/// A compiled DAE with its id vector (a raw bond graph's velocity-level or index-1 DAE).
#[derive(Clone, Debug)]
pub struct IdDae {
    /// The compiled residual.
    pub dae: ImplicitDae,
    /// 1 for differential unknowns, 0 for algebraic.
    pub id: Vec<f64>,
}
