//! What a solve is asked to do.

use super::error::SolveError;
use std::time::Duration;

pub use crate::settings::{FormulationKind, Integrator, LinearSolverKind};

/// Options of one solve.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveOptions {
    /// Formulation.
    pub formulation: FormulationKind,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance of positions and velocities.
    pub atol: f64,
    /// Absolute tolerance of the multipliers λ, μ (used only in Newton's convergence test,
    /// since they are excluded from the error test). `None`: 1e-2 — measured: tighter values
    /// make the first Newton iterations fail at tight tolerances (the index-2 Newton matrix
    /// scales like 1/h²), looser ones change nothing.
    pub multiplier_atol: Option<f64>,
    /// Time of the initial state (s). The motion starts here whatever the output times are.
    pub t_start: f64,
    /// Times at which rows are written: strictly increasing, none before `t_start`; they need
    /// not contain `t_start` (a row is written there only if it is listed).
    pub output_times: Vec<f64>,
    /// Step budget of the whole run (all output intervals, restarts and re-selections
    /// together); `None` (the default): no cap, the run is bounded by `max_wall_clock` if
    /// given. When it runs out the solve fails with [`SolveError::Incomplete`], which keeps
    /// the rows computed so far.
    pub max_steps: Option<u64>,
    /// Wall-clock budget of the whole solve (all output intervals, IDA restarts and index-1
    /// re-selections together), checked between internal steps; when it runs out the solve
    /// fails with `SolverError::WallClock` carrying the time reached.
    pub max_wall_clock: Option<Duration>,
    /// Joint stiffness `k` of the decoupled twin.
    pub joint_stiffness: f64,
    /// Joint damping `c` of the decoupled twin.
    pub joint_damping: f64,
    /// Compliance ε of the compliant GGL; `None`: `1e-10 / m_ref` with `m_ref` the largest mass.
    pub compliance: Option<f64>,
    /// Largest BDF order CVODE may use for the decoupled twin (`None`, the default: CVODE's 5).
    /// The undamped joint springs put eigenvalues `±i√(k/m)` on the imaginary axis, where BDF
    /// orders 3–5 are unstable, so at those orders CVODE must resolve the spring oscillation
    /// (steps grow like `√k`); BDF2 is A-stable and damps the spring modes numerically.
    /// Measured (double pendulum, undamped, rtol 1e-8, 1 s): k = 1e8: order 5 57 367 steps,
    /// error against the minimal model 1.5e-6 (the twin's own 1/k error), order 2 19 875 steps,
    /// error 5.1e-6; k = 1e10: 581 661 steps / 1.5e-8 against 78 121 / 8.1e-6; k = 1e12: about
    /// 6 million steps against 902 071 / 3.0e-5. Order 2 is thus 3–7 times cheaper but adds an
    /// error of a few 1e-6 per second at rtol 1e-8, so it is opt-in (`Some(2)`) for very stiff
    /// twins where cost matters more than the last digits. Stability limit detection
    /// ([`Self::twin_stab_lim_det`]) did not help: 1 684 130 steps against 1 199 984 over 0.2 s
    /// at k = 1e12.
    pub twin_max_order: Option<i32>,
    /// BDF stability limit detection for the decoupled twin (`CVodeSetStabLimDet`).
    pub twin_stab_lim_det: bool,
    /// GGL: keep the *dependent* velocities (the index-2 components that `G_v v = 0` fixes,
    /// chosen as the index-1 formulation chooses them) in IDA's error test. Default `true`.
    /// `false` leaves them out (id 0 with suppressed algebraic error test), the set re-chosen
    /// at the output times when its block `G_v[:, D]` degrades, and every velocity put back in
    /// where no set is well conditioned and while the compliant GGL runs (see
    /// `solve::run::GGL_ERROR_TEST_SINGULAR`; `summary.ggl_error_test_reselections` counts the
    /// changes). Measured (`cargo bench --bench ggl_speed`, README): about half the steps at
    /// the same tolerance on the double pendulum and the slider-crank, and 1.7× less CPU at
    /// matched error. Not the default: plain GGL finds singular passages by failing near them,
    /// and without the dependent velocities in its error test it steps through a four-bar
    /// alignment without failing (tests/singular_fourbar_chain.rs: the first alignment, at
    /// 0.7 s, went unnoticed and the error grew to 4e-4), and the Andrews squeezer misses its
    /// 1e-7 reference at rtol 1e-10 (2e-7). Opt-in for smooth, regular mechanisms.
    pub ggl_dependent_velocity_error_test: bool,
    /// IDA formulations (GGL, index 1): the relative change of `c_j = α/h` (IDA's Newton
    /// matrix `∂F/∂y + c_j ∂F/∂y'`) beyond which IDA evaluates and factors a new Jacobian
    /// (`IDASetDeltaCjLSetup`); `None` takes bondmech's 0 (a new Jacobian at every change of
    /// `c_j`, see `solve::integrators::IDA_DELTA_CJ`; SUNDIALS' own default is 0.25).
    pub ida_delta_cj: Option<f64>,
    /// IDA formulations on faer's sparse LU: how it orders the Newton matrix's columns;
    /// `None` takes the formulation's own choice ([`crate::solve::formulation::DaeFormulation::sparse_ordering`]:
    /// the cheapest of three orders for the index-1 DAE, COLAMD for the others).
    pub sparse_ordering: Option<crate::sundials::ColumnOrdering>,
    /// Linear solver of the Newton iterations (default [`LinearSolverKind::Auto`]).
    pub linear_solver: LinearSolverKind,
    /// Integrator of the partitioned formulation (ignored by the others).
    pub integrator: Integrator,
    /// The partitioned formulation stops its integrator at the zeros of the loads'
    /// non-smooth operations (`max`, `min`, `abs`, `sign`, `select`) and restarts it on the
    /// other branch, instead of stepping across the kinks (`expr::switches`). Default true.
    pub switching_functions: bool,
    /// Keep every output row in the returned [`crate::Solution`] (the default). `false`: the
    /// rows only go to the observer of [`crate::Model::solve_streaming`] and the solution
    /// keeps just the latest one, so memory stays bounded whatever the number of rows (the
    /// command line streams `run`'s CSV so).
    pub keep_rows: bool,
    /// The default DAE (`dae`, `index1`) keeps a conservative mechanism's energy as an
    /// invariant of the DAE ([`crate::solve::formulation::EnergyInvariant`]): `None` (auto) and `Some(true)`
    /// where the mechanism conserves its energy and moves, `Some(false)` never.
    pub energy_invariant: Option<bool>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            formulation: FormulationKind::Dae,
            rtol: 1e-6,
            atol: 1e-8,
            multiplier_atol: None,
            t_start: 0.0,
            output_times: (0..=100).map(|i| i as f64 * 0.01).collect(),
            max_steps: None,
            max_wall_clock: None,
            joint_stiffness: 1e8,
            joint_damping: 0.0,
            compliance: None,
            twin_max_order: None,
            twin_stab_lim_det: false,
            ggl_dependent_velocity_error_test: true,
            ida_delta_cj: None,
            sparse_ordering: None,
            linear_solver: LinearSolverKind::Auto,
            integrator: Integrator::Auto,
            switching_functions: true,
            keep_rows: true,
            energy_invariant: None,
        }
    }
}

impl SolveOptions {
    /// The times a runner integrates over: `t_start`, then the output times after it; and
    /// whether the row at `t_start` is one the caller asked for (`output_times` lists it).
    ///
    /// ```
    /// use bondmech::SolveOptions;
    /// let o = SolveOptions { output_times: vec![0.5, 1.0], ..SolveOptions::default() };
    /// assert_eq!(o.integration_times().unwrap(), (vec![0.0, 0.5, 1.0], false));
    /// ```
    pub fn integration_times(&self) -> Result<(Vec<f64>, bool), SolveError> {
        let t0 = self.t_start;
        let bad = |m: String| Err(SolveError::Options(m));
        if !t0.is_finite() {
            return bad(format!("t_start must be finite (got {t0})"));
        }
        if self.output_times.is_empty() {
            return bad("output_times is empty".into());
        }
        if let Some(t) = self.output_times.iter().find(|t| !t.is_finite()) {
            return bad(format!("output_times must be finite (got {t})"));
        }
        if self.output_times.windows(2).any(|w| w[1] <= w[0]) {
            return bad("output_times must be strictly increasing".into());
        }
        if self.output_times[0] < t0 {
            return bad(format!(
                "output time {} is before t_start = {t0} (integration runs forward from the initial state)",
                self.output_times[0]
            ));
        }
        let listed = self.output_times[0] == t0;
        let mut times = Vec::with_capacity(self.output_times.len() + 1);
        times.push(t0);
        times.extend(self.output_times.iter().copied().filter(|&t| t > t0));
        Ok((times, listed))
    }

    /// `0, h, 2h, …, t_end` (the last one exactly `t_end`).
    pub fn times(t_end: f64, step: f64) -> Vec<f64> {
        let n = (t_end / step - 1e-9).ceil().max(1.0) as usize;
        let mut v: Vec<f64> = (0..n).map(|i| i as f64 * step).collect();
        v.push(t_end);
        v
    }
}
