//! Solver options and step results.

use std::time::Duration;

/// Options for [`super::Ida`].
#[derive(Clone, Debug)]
pub struct IdaOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance: length 1 (scalar) or length n.
    pub atol: Vec<f64>,
    /// Internal steps allowed per `solve_to` call (`None`: [`super::stepping::DEFAULT_MAX_STEPS`] = 500).
    pub max_steps: Option<u64>,
    /// Wall-clock time allowed for the whole integration: the time spent in all
    /// `solve_to`/`step` calls since the solver was built (`reinit` does not reset it),
    /// checked before each internal step.
    pub max_wall_clock: Option<Duration>,
    /// Internal steps allowed over the whole integration: all `solve_to`/`step` calls since the
    /// solver was built (`reinit` does not reset it; see also `charge_steps`). `None`: no cap.
    pub max_total_steps: Option<u64>,
    /// Maximum BDF order (1..=5).
    pub max_order: Option<i32>,
    /// Maximum |step|.
    pub max_step: Option<f64>,
    /// Initial step size.
    pub init_step: Option<f64>,
    /// 1.0 for differential, 0.0 for algebraic components (needed by `calc_ic` and `suppress_alg`).
    pub id: Option<Vec<f64>>,
    /// Exclude algebraic components from the local error test.
    pub suppress_alg: bool,
    /// SUNDIALS constraints (0, ±1, ±2 per component).
    pub constraints: Option<Vec<f64>>,
    /// Do not integrate past this time.
    pub stop_time: Option<f64>,
    /// Maximum Newton iterations per step.
    pub max_nonlin_iters: Option<i32>,
    /// Maximum nonlinear convergence failures per step.
    pub max_conv_fails: Option<i32>,
    /// Maximum error test failures per step.
    pub max_err_test_fails: Option<i32>,
    /// `IDASetDeltaCjLSetup`: IDA calls the linear solver setup (a new Jacobian and its
    /// factorisation) when `|c_j/c_j,old − 1|` exceeds this (SUNDIALS default 0.25); between
    /// setups the Newton iteration runs on the old matrix, its steps scaled by
    /// `2/(1 + c_j/c_j,old)` (linear solution scaling).
    pub delta_cj_lsetup: Option<f64>,
    /// `IDASetNonlinConvCoef`: the Newton iteration stops when its WRMS error estimate is below
    /// this fraction of the local error test's bound (SUNDIALS default 0.33).
    pub nonlin_conv_coef: Option<f64>,
    /// How faer's sparse LU orders the Newton matrix's columns (with a sparse Jacobian and
    /// [`super::SparseSolver::Faer`]).
    pub sparse_ordering: super::ColumnOrdering,
}

impl Default for IdaOptions {
    fn default() -> Self {
        IdaOptions {
            rtol: 1e-6,
            atol: vec![1e-8],
            max_steps: None,
            max_wall_clock: None,
            max_total_steps: None,
            max_order: None,
            max_step: None,
            init_step: None,
            id: None,
            suppress_alg: false,
            constraints: None,
            stop_time: None,
            max_nonlin_iters: None,
            max_conv_fails: None,
            max_err_test_fails: None,
            delta_cj_lsetup: None,
            nonlin_conv_coef: None,
            sparse_ordering: super::ColumnOrdering::Colamd,
        }
    }
}

/// Options for [`super::Cvode`].
#[derive(Clone, Debug)]
pub struct CvodeOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance: length 1 (scalar) or length n.
    pub atol: Vec<f64>,
    /// Internal steps allowed per `solve_to` call (`None`: [`super::stepping::DEFAULT_MAX_STEPS`] = 500).
    pub max_steps: Option<u64>,
    /// Wall-clock time allowed for the whole integration: the time spent in all
    /// `solve_to`/`step` calls since the solver was built (`reinit` does not reset it),
    /// checked before each internal step.
    pub max_wall_clock: Option<Duration>,
    /// Internal steps allowed over the whole integration: all `solve_to`/`step` calls since the
    /// solver was built (`reinit` does not reset it; see also `charge_steps`). `None`: no cap.
    pub max_total_steps: Option<u64>,
    /// Maximum order (BDF ≤ 5, Adams ≤ 12).
    pub max_order: Option<i32>,
    /// Maximum |step|.
    pub max_step: Option<f64>,
    /// Initial step size.
    pub init_step: Option<f64>,
    /// Do not integrate past this time.
    pub stop_time: Option<f64>,
    /// BDF stability limit detection (`CVodeSetStabLimDet`): CVODE lowers the order when it
    /// detects that BDF orders 3–5 are unstable for eigenvalues near the imaginary axis.
    pub stab_lim_det: bool,
}

impl Default for CvodeOptions {
    fn default() -> Self {
        CvodeOptions {
            rtol: 1e-6,
            atol: vec![1e-8],
            max_steps: None,
            max_wall_clock: None,
            max_total_steps: None,
            max_order: None,
            max_step: None,
            init_step: None,
            stop_time: None,
            stab_lim_det: false,
        }
    }
}

/// Linear multistep family for CVODE.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Multistep {
    /// Backward differentiation formulas (stiff problems).
    Bdf,
    /// Adams–Moulton (non-stiff problems).
    Adams,
}

/// What `IDACalcIC` computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalcIc {
    /// Algebraic y and differential y' from the differential y (`IDA_YA_YDP_INIT`; needs `id`).
    AlgebraicAndDerivatives,
    /// All of y from the given y' (`IDA_Y_INIT`).
    AllY,
}

/// Why a solve call returned.
#[derive(Clone, Debug, PartialEq)]
pub enum StepEvent {
    /// The requested time (or one internal step) was reached.
    Reached,
    /// Root functions changed sign; entries are ±1 for roots found (direction), 0 otherwise.
    Root(Vec<i32>),
    /// The stop time was reached.
    StopTime,
}

/// Result of a solve call.
#[derive(Clone, Debug)]
pub struct Step {
    /// Time of the returned state.
    pub t: f64,
    /// Why the call returned.
    pub event: StepEvent,
}

pub(crate) fn check_tolerances(
    rtol: f64,
    atol: &[f64],
    n: usize,
) -> Result<(), super::SolverError> {
    use super::SolverError::InvalidInput;
    if !(rtol.is_finite() && rtol >= 0.0) {
        return Err(InvalidInput(format!(
            "rtol must be finite and >= 0, got {rtol}"
        )));
    }
    if atol.len() != 1 && atol.len() != n {
        return Err(InvalidInput(format!(
            "atol must have length 1 or {n}, got {}",
            atol.len()
        )));
    }
    if let Some(a) = atol.iter().find(|a| !(a.is_finite() && **a >= 0.0)) {
        return Err(InvalidInput(format!(
            "atol entries must be finite and >= 0, got {a}"
        )));
    }
    Ok(())
}

pub(crate) fn check_vector(name: &str, v: &[f64], n: usize) -> Result<(), super::SolverError> {
    use super::SolverError::InvalidInput;
    if v.len() != n {
        return Err(InvalidInput(format!(
            "{name} has length {}, expected {n}",
            v.len()
        )));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(InvalidInput(format!(
            "{name}[{i}] is not finite ({})",
            v[i]
        )));
    }
    Ok(())
}
