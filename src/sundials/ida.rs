//! IDA: variable-order BDF for implicit DAEs `F(t, y, y') = 0`.
//!
//! Newton's method on the BDF corrector solves `F(t, y, α y + β) = 0` with the
//! iteration matrix `J = ∂F/∂y + cj ∂F/∂y'` (user-supplied or difference quotients),
//! factored by the dense linear solver, by a sparse LU on a fixed CSC pattern
//! ([`Ida::new_sparse`]: faer or KLU, see [`super::sparse`]) or by a user [`IdaLinearSolver`].

use super::callback::{
    error_handler, finite_or_recoverable, CallbackStatus, ErrorWeightFn, IdaJacobianFn, IdaRootFn,
    IdaSparseJacobianFn, ResidualFn,
};
use super::calls::Calls;
use super::context::Context;
use super::custom_ls::{self, IdaLinearSolver};
use super::error::{check, Package, SolverError};
use super::linsol::LinearSolver;
use super::matrix::{DenseMatrix, DenseMatrixMut};
use super::options::{check_tolerances, check_vector, CalcIc, IdaOptions, Step};
use super::schur::SchurPartition;
use super::sparse::{self, CscPattern, FaerCounters, SparseMatrix, SparseMatrixMut, SparseSolver};
use super::stats::{RecoveredFailure, SolverStats, MAX_LOGGED_FAILURES};
use super::stepping::{self, RawEvent, Stepper, SteppingState};
use super::vector::{slice_of, slice_of_mut, NVector};
use std::os::raw::{c_int, c_long, c_void};
use std::ptr;
use sundials_sys as sys;

mod sens;
pub use sens::{SensResidualFn, SensStats};

const P: Package = Package::Ida;

/// IDA's entry points for the call sequences the integrator wrappers share
/// ([`super::calls`]).
static CALLS: Calls = Calls {
    package: P,
    user_function: "residual",
    current_time: sys::IDAGetCurrentTime,
    root_info: sys::IDAGetRootInfo,
    set_stop_time: ("IDASetStopTime", sys::IDASetStopTime),
    dky: ("IDAGetDky", sys::IDAGetDky),
    last_step: sys::IDAGetLastStep,
    last_order: Some(sys::IDAGetLastOrder),
    counters: [
        Some(sys::IDAGetNumSteps),
        Some(sys::IDAGetNumResEvals),
        Some(sys::IDAGetNumJacEvals),
        Some(sys::IDAGetNumLinSolvSetups),
        Some(sys::IDAGetNumNonlinSolvIters),
        Some(sys::IDAGetNumNonlinSolvConvFails),
        Some(sys::IDAGetNumErrTestFails),
        Some(sys::IDAGetNumGEvals),
    ],
    returns: [
        sys::IDA_SUCCESS,
        sys::IDA_ROOT_RETURN,
        sys::IDA_TSTOP_RETURN,
    ],
    too_much_work: sys::IDA_TOO_MUCH_WORK,
};

/// Closures and callback status; boxed so SUNDIALS can hold its address as `user_data`.
pub(crate) struct IdaData {
    pub(crate) status: CallbackStatus,
    pub(crate) n: usize,
    nroots: usize,
    residual: ResidualFn,
    jacobian: Option<IdaJacobianFn>,
    sparse_jacobian: Option<(IdaSparseJacobianFn, CscPattern)>,
    roots: Option<IdaRootFn>,
    /// The time of the last residual evaluation (the error weights' `t`).
    last_t: f64,
    /// User error weights ([`Ida::set_error_weights`]).
    weights: Option<ErrorWeights>,
    /// The sensitivity residual ([`Ida::enable_sensitivities`]).
    sens: Option<sens::SensData>,
}

/// The tolerances and closure behind `IDAWFtolerances` ([`Ida::set_error_weights`]).
struct ErrorWeights {
    rtol: f64,
    atol: Vec<f64>,
    raise: ErrorWeightFn,
}

/// Owned IDA memory, freed with `IDAFree`.
struct IdaMem(*mut c_void);

impl Drop for IdaMem {
    fn drop(&mut self) {
        // SAFETY: the pointer came from IDACreate and is freed exactly once.
        unsafe { sys::IDAFree(&mut self.0) }
    }
}

/// An IDA integrator with its own SUNDIALS context.
///
/// Field order is drop order: IDA memory, then linear solver, matrix, vectors,
/// closures, and the context last, as SUNDIALS requires.
pub struct Ida {
    mem: IdaMem,
    #[allow(dead_code)] // owned: freed after `mem`
    ls: LinearSolver,
    #[allow(dead_code)] // owned: freed after `ls`
    mat: Option<DenseMatrix>,
    #[allow(dead_code)] // owned: freed after `ls`
    smat: Option<SparseMatrix>,
    y: NVector,
    yp: NVector,
    tmp: NVector,
    data: Box<IdaData>,
    /// The sensitivities' start and output vectors (freed after `mem`).
    sens: Option<sens::SensVectors>,
    stepping: SteppingState,
    /// Steps accepted after recovered failures, and the failure counters seen so far.
    failures: FailureLog,
    #[allow(dead_code)] // owned: freed last
    ctx: Context,
}

/// The [`RecoveredFailure`] log of one IDA: counters are compared after every step.
#[derive(Debug, Default)]
struct FailureLog {
    log: Vec<RecoveredFailure>,
    conv: u64,
    etf: u64,
}

// SAFETY: an Ida exclusively owns its context, memory, vectors and closures (all
// `Send`); SUNDIALS keeps no global state across contexts, and nothing is shared.
unsafe impl Send for Ida {}

unsafe extern "C" fn residual_trampoline(
    t: f64,
    yy: sys::N_Vector,
    yp: sys::N_Vector,
    rr: sys::N_Vector,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: user_data is the Box<IdaData> registered with IDASetUserData, alive as
    // long as the IDA memory; yy, yp, rr are distinct serial vectors of length n.
    let (data, y, yp, r) = unsafe {
        let data = &mut *(user_data as *mut IdaData);
        let n = data.n;
        (data, slice_of(yy, n), slice_of(yp, n), slice_of_mut(rr, n))
    };
    data.last_t = t;
    let IdaData {
        status, residual, ..
    } = data;
    let code = status.guard(t, || residual(t, y, yp, r));
    status.check_output("residual", code, t, y, r)
}

#[allow(clippy::too_many_arguments)]
unsafe extern "C" fn jacobian_trampoline(
    t: f64,
    cj: f64,
    yy: sys::N_Vector,
    yp: sys::N_Vector,
    _rr: sys::N_Vector,
    jac: sys::SUNMatrix,
    user_data: *mut c_void,
    _t1: sys::N_Vector,
    _t2: sys::N_Vector,
    _t3: sys::N_Vector,
) -> c_int {
    // SAFETY: as in residual_trampoline; jac is the dense n x n matrix we attached.
    let (data, y, yp, mut j) = unsafe {
        let data = &mut *(user_data as *mut IdaData);
        let n = data.n;
        (
            data,
            slice_of(yy, n),
            slice_of(yp, n),
            DenseMatrixMut::from_raw(jac),
        )
    };
    // IDA zeroes the matrix before it calls this function (idaLsSetup: SUNMatZero, then jac)
    let IdaData {
        status, jacobian, ..
    } = data;
    let Some(jacobian) = jacobian.as_mut() else {
        return -1;
    };
    let code = status.guard(t, || jacobian(t, cj, y, yp, &mut j));
    // a non-finite Newton matrix counts toward the solver being stuck, as a residual's does
    status.check_output("Jacobian", code, t, y, j.as_mut_slice())
}

#[allow(clippy::too_many_arguments)]
unsafe extern "C" fn sparse_jacobian_trampoline(
    t: f64,
    cj: f64,
    yy: sys::N_Vector,
    yp: sys::N_Vector,
    _rr: sys::N_Vector,
    jac: sys::SUNMatrix,
    user_data: *mut c_void,
    _t1: sys::N_Vector,
    _t2: sys::N_Vector,
    _t3: sys::N_Vector,
) -> c_int {
    // SAFETY: as in residual_trampoline; jac is the CSC matrix we attached, built with room
    // for the pattern's entries (IDA zeroes its index arrays, so the pattern is written back).
    let (data, y, yp) = unsafe {
        let data = &mut *(user_data as *mut IdaData);
        let n = data.n;
        (data, slice_of(yy, n), slice_of(yp, n))
    };
    let IdaData {
        status,
        sparse_jacobian,
        ..
    } = data;
    let Some((jacobian, pattern)) = sparse_jacobian.as_mut() else {
        return -1;
    };
    // SAFETY: as above.
    let values = unsafe {
        sparse::write_pattern(jac, pattern);
        sparse::values_of(jac, pattern)
    };
    values.fill(0.0);
    let Some(mut j) = SparseMatrixMut::from_slice(pattern, values) else {
        return -1;
    };
    let code = status.guard(t, || jacobian(t, cj, y, yp, &mut j));
    status.check_output("Jacobian", code, t, y, j.values_mut())
}

unsafe extern "C" fn root_trampoline(
    t: f64,
    yy: sys::N_Vector,
    yp: sys::N_Vector,
    gout: *mut f64,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: as in residual_trampoline; gout has room for the nroots registered.
    let (data, y, yp, g) = unsafe {
        let data = &mut *(user_data as *mut IdaData);
        let n = data.n;
        let g = std::slice::from_raw_parts_mut(gout, data.nroots);
        (data, slice_of(yy, n), slice_of(yp, n), g)
    };
    let IdaData { status, roots, .. } = data;
    let Some(roots) = roots.as_mut() else {
        return -1;
    };
    let code = status.guard(t, || roots(t, y, yp, g));
    // Root functions may not return "recoverable": treat non-finite output as fatal.
    if finite_or_recoverable(code, g) != 0 {
        -1
    } else {
        0
    }
}

unsafe extern "C" fn weights_trampoline(
    yy: sys::N_Vector,
    ewt: sys::N_Vector,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: as in residual_trampoline; yy and ewt are distinct serial vectors of length n.
    let (data, y, w) = unsafe {
        let data = &mut *(user_data as *mut IdaData);
        let n = data.n;
        (data, slice_of(yy, n), slice_of_mut(ewt, n))
    };
    let t = data.last_t;
    let IdaData {
        status, weights, ..
    } = data;
    let Some(ErrorWeights { rtol, atol, raise }) = weights.as_mut() else {
        return -1;
    };
    for (i, (wi, yi)) in w.iter_mut().zip(y).enumerate() {
        let tol = *rtol * yi.abs() + atol[if atol.len() == 1 { 0 } else { i }];
        if tol.is_nan() || tol <= 0.0 {
            return -1;
        }
        *wi = 1.0 / tol;
    }
    match status.guard(t, || raise(t, y, w)) {
        0 if w.iter().all(|v| v.is_finite() && *v > 0.0) => 0,
        _ => -1,
    }
}

enum Linear {
    Dense(Option<IdaJacobianFn>),
    Schur(IdaJacobianFn, SchurPartition),
    Custom(Box<dyn IdaLinearSolver>),
    Sparse(IdaSparseJacobianFn, CscPattern, SparseSolver),
}

impl Ida {
    /// Create an IDA solver for `F(t, y, y') = 0` from `(t0, y0, yp0)` with the dense
    /// linear solver (difference-quotient Jacobian if `jacobian` is `None`).
    pub fn new(
        t0: f64,
        y0: &[f64],
        yp0: &[f64],
        residual: ResidualFn,
        jacobian: Option<IdaJacobianFn>,
        opts: &IdaOptions,
    ) -> Result<Ida, SolverError> {
        Ida::build(t0, y0, yp0, residual, Linear::Dense(jacobian), opts)
    }

    /// Create an IDA solver whose dense Newton matrix `J = ∂F/∂y + cj ∂F/∂y'` (filled by
    /// `jacobian`) is solved by eliminating the dependent blocks of `partition` and factoring
    /// the Schur complement ([`super::schur`]).
    pub fn new_schur(
        t0: f64,
        y0: &[f64],
        yp0: &[f64],
        residual: ResidualFn,
        jacobian: IdaJacobianFn,
        partition: SchurPartition,
        opts: &IdaOptions,
    ) -> Result<Ida, SolverError> {
        if partition.len() != y0.len() {
            return Err(SolverError::InvalidInput(format!(
                "the Schur partition has {} unknowns but y0 has length {}",
                partition.len(),
                y0.len()
            )));
        }
        Ida::build(
            t0,
            y0,
            yp0,
            residual,
            Linear::Schur(jacobian, partition),
            opts,
        )
    }

    /// Create an IDA solver that solves its Newton systems with a user linear solver.
    pub fn new_with_linear_solver(
        t0: f64,
        y0: &[f64],
        yp0: &[f64],
        residual: ResidualFn,
        linear_solver: Box<dyn IdaLinearSolver>,
        opts: &IdaOptions,
    ) -> Result<Ida, SolverError> {
        Ida::build(t0, y0, yp0, residual, Linear::Custom(linear_solver), opts)
    }

    /// Create an IDA solver whose Newton matrix `J = ∂F/∂y + cj ∂F/∂y'` is stored in the
    /// fixed sparsity `pattern` (CSC), filled by `jacobian` and factored by the sparse LU
    /// `solver`.
    #[allow(clippy::too_many_arguments)]
    pub fn new_sparse(
        t0: f64,
        y0: &[f64],
        yp0: &[f64],
        residual: ResidualFn,
        jacobian: IdaSparseJacobianFn,
        pattern: CscPattern,
        solver: SparseSolver,
        opts: &IdaOptions,
    ) -> Result<Ida, SolverError> {
        if pattern.n() != y0.len() {
            return Err(SolverError::InvalidInput(format!(
                "sparsity pattern is {0} × {0} but y0 has length {1}",
                pattern.n(),
                y0.len()
            )));
        }
        Ida::build(
            t0,
            y0,
            yp0,
            residual,
            Linear::Sparse(jacobian, pattern, solver),
            opts,
        )
    }

    fn build(
        t0: f64,
        y0: &[f64],
        yp0: &[f64],
        residual: ResidualFn,
        linear: Linear,
        opts: &IdaOptions,
    ) -> Result<Ida, SolverError> {
        let n = y0.len();
        if n == 0 {
            return Err(SolverError::InvalidInput("y0 is empty".into()));
        }
        if !t0.is_finite() {
            return Err(SolverError::InvalidInput(format!(
                "t0 must be finite, got {t0}"
            )));
        }
        check_vector("y0", y0, n)?;
        check_vector("yp0", yp0, n)?;
        check_tolerances(opts.rtol, &opts.atol, n)?;
        if let Some(id) = &opts.id {
            check_vector("id", id, n)?;
        }
        if let Some(c) = &opts.constraints {
            check_vector("constraints", c, n)?;
        }
        // Locals drop in reverse order: memory first, context last.
        let ctx = Context::new()?;
        let y = NVector::from_slice(&ctx, y0)?;
        let yp = NVector::from_slice(&ctx, yp0)?;
        let tmp = NVector::from_slice(&ctx, y0)?;
        let (jacobian, custom, sparse_jac, schur) = match linear {
            Linear::Dense(j) => (j, None, None, None),
            Linear::Schur(j, p) => (Some(j), None, None, Some(p)),
            Linear::Custom(c) => (None, Some(c), None, None),
            Linear::Sparse(j, p, s) => (None, None, Some((j, p, s)), None),
        };
        let has_jac = jacobian.is_some();
        let sparse_kind = sparse_jac.as_ref().map(|(_, _, s)| *s);
        let smat = match &sparse_jac {
            Some((_, p, _)) => Some(SparseMatrix::new(&ctx, p)?),
            None => None,
        };
        let mut data = Box::new(IdaData {
            status: CallbackStatus::default(),
            n,
            nroots: 0,
            residual,
            jacobian,
            sparse_jacobian: sparse_jac.map(|(j, p, _)| (j, p)),
            roots: None,
            last_t: t0,
            weights: None,
            sens: None,
        });
        let (mat, mut ls) = match (custom, &smat, sparse_kind) {
            (_, Some(sm), Some(kind)) => (
                None,
                sparse::new_sparse_solver(&ctx, &y, sm, kind, opts.sparse_ordering)?,
            ),
            (None, _, _) => {
                let mat = DenseMatrix::square(&ctx, n)?;
                let ls = match schur {
                    Some(p) => super::schur::new(&ctx, p)?,
                    None => super::dense_lu::new(&ctx)?,
                };
                (Some(mat), ls)
            }
            (Some(c), _, _) => (None, custom_ls::new_linear_solver(&ctx, c, n)?),
        };
        // SAFETY: valid context; NULL checked below.
        let raw = unsafe { sys::IDACreate(ctx.raw()) };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("IDACreate failed".into()));
        }
        let mem = IdaMem(raw);
        let status_ptr = &mut data.status as *mut CallbackStatus as *mut c_void;
        let data_ptr = &mut *data as *mut IdaData as *mut c_void;
        // SAFETY: mem, vectors, matrix and solver are live; the user data and error
        // handler data point into the Box `data`, which the returned Ida keeps alive
        // (and does not move) for as long as the IDA memory.
        unsafe {
            check(
                P,
                "IDASetErrHandlerFn",
                sys::IDASetErrHandlerFn(raw, Some(error_handler), status_ptr),
                t0,
            )?;
            check(
                P,
                "IDAInit",
                sys::IDAInit(raw, Some(residual_trampoline), t0, y.raw(), yp.raw()),
                t0,
            )?;
            if opts.atol.len() == 1 {
                check(
                    P,
                    "IDASStolerances",
                    sys::IDASStolerances(raw, opts.rtol, opts.atol[0]),
                    t0,
                )?;
            } else {
                let atol = NVector::from_slice(&ctx, &opts.atol)?;
                check(
                    P,
                    "IDASVtolerances",
                    sys::IDASVtolerances(raw, opts.rtol, atol.raw()),
                    t0,
                )?;
            }
            check(P, "IDASetUserData", sys::IDASetUserData(raw, data_ptr), t0)?;
            let a = match (&mat, &smat) {
                (Some(m), _) => m.raw(),
                (None, Some(m)) => m.raw(),
                (None, None) => ptr::null_mut(),
            };
            check(
                P,
                "IDASetLinearSolver",
                sys::IDASetLinearSolver(raw, ls.raw(), a),
                t0,
            )?;
            if has_jac {
                check(
                    P,
                    "IDASetJacFn",
                    sys::IDASetJacFn(raw, Some(jacobian_trampoline)),
                    t0,
                )?;
            }
            if smat.is_some() {
                check(
                    P,
                    "IDASetJacFn",
                    sys::IDASetJacFn(raw, Some(sparse_jacobian_trampoline)),
                    t0,
                )?;
            }
            if mat.is_none() && smat.is_none() {
                custom_ls::attach(&mut ls, raw, status_ptr as *mut CallbackStatus);
            }
            if let Some(v) = opts.max_order {
                check(P, "IDASetMaxOrd", sys::IDASetMaxOrd(raw, v), t0)?;
            }
            if let Some(v) = opts.max_step {
                check(P, "IDASetMaxStep", sys::IDASetMaxStep(raw, v), t0)?;
            }
            if let Some(v) = opts.init_step {
                check(P, "IDASetInitStep", sys::IDASetInitStep(raw, v), t0)?;
            }
            if let Some(id) = &opts.id {
                let v = NVector::from_slice(&ctx, id)?;
                check(P, "IDASetId", sys::IDASetId(raw, v.raw()), t0)?;
            }
            if opts.suppress_alg {
                check(P, "IDASetSuppressAlg", sys::IDASetSuppressAlg(raw, 1), t0)?;
            }
            if let Some(c) = &opts.constraints {
                let v = NVector::from_slice(&ctx, c)?;
                check(
                    P,
                    "IDASetConstraints",
                    sys::IDASetConstraints(raw, v.raw()),
                    t0,
                )?;
            }
            if let Some(t) = opts.stop_time {
                check(P, "IDASetStopTime", sys::IDASetStopTime(raw, t), t0)?;
            }
            if let Some(v) = opts.max_nonlin_iters {
                check(
                    P,
                    "IDASetMaxNonlinIters",
                    sys::IDASetMaxNonlinIters(raw, v),
                    t0,
                )?;
            }
            if let Some(v) = opts.max_conv_fails {
                check(P, "IDASetMaxConvFails", sys::IDASetMaxConvFails(raw, v), t0)?;
            }
            if let Some(v) = opts.max_err_test_fails {
                check(
                    P,
                    "IDASetMaxErrTestFails",
                    sys::IDASetMaxErrTestFails(raw, v),
                    t0,
                )?;
            }
            if let Some(v) = opts.delta_cj_lsetup {
                check(
                    P,
                    "IDASetDeltaCjLSetup",
                    sys::IDASetDeltaCjLSetup(raw, v),
                    t0,
                )?;
            }
            if let Some(v) = opts.nonlin_conv_coef {
                check(
                    P,
                    "IDASetNonlinConvCoef",
                    sys::IDASetNonlinConvCoef(raw, v),
                    t0,
                )?;
            }
        }
        Ok(Ida {
            mem,
            ls,
            mat,
            smat,
            y,
            yp,
            tmp,
            data,
            sens: None,
            stepping: SteppingState::new(
                t0,
                opts.max_steps,
                opts.max_wall_clock,
                opts.max_total_steps,
            ),
            failures: FailureLog::default(),
            ctx,
        })
    }

    fn raw(&self) -> *mut c_void {
        self.mem.0
    }

    /// Symbolic analyses and numeric factorisations of the faer sparse LU so far (`None`
    /// when IDA does not use it).
    pub fn faer_counters(&self) -> Option<FaerCounters> {
        sparse::faer_counters(&self.ls)
    }

    /// Steps accepted after Newton convergence or error test failures, in order, since the
    /// solver was created (across `reinit`; at most [`MAX_LOGGED_FAILURES`]).
    pub fn recovered_failures(&self) -> &[RecoveredFailure] {
        &self.failures.log
    }

    /// Logs the step that just reached `t` if the failure counters moved.
    fn log_failures(&mut self, t: f64) {
        let (mut conv, mut etf): (c_long, c_long) = (0, 0);
        // SAFETY: live IDA memory and valid out-pointers.
        unsafe {
            sys::IDAGetNumNonlinSolvConvFails(self.raw(), &mut conv);
            sys::IDAGetNumErrTestFails(self.raw(), &mut etf);
        }
        let (conv, etf) = (conv.max(0) as u64, etf.max(0) as u64);
        let f = &mut self.failures;
        if (conv > f.conv || etf > f.etf) && f.log.len() < MAX_LOGGED_FAILURES {
            f.log.push(RecoveredFailure {
                t,
                convergence_failures: (conv - f.conv.min(conv)) as u32,
                error_test_failures: (etf - f.etf.min(etf)) as u32,
            });
        }
        f.conv = conv;
        f.etf = etf;
    }

    /// Turn a failing flag into an error, preferring a callback's own error.
    fn fail(&mut self, function: &'static str, flag: c_int) -> SolverError {
        let t = self.current_time();
        let max_steps = self.stepping.max_steps;
        CALLS.failure(&mut self.data.status, (function, flag), t, max_steps)
    }

    /// Register `n` root functions `g(t, y, y')`; sign changes stop `solve_to`.
    pub fn set_roots(&mut self, n: usize, f: IdaRootFn) -> Result<(), SolverError> {
        self.data.roots = Some(f);
        self.data.nroots = n;
        // SAFETY: live IDA memory; the trampoline reads closures from the registered user data.
        let flag = unsafe { sys::IDARootInit(self.raw(), n as c_int, Some(root_trampoline)) };
        if flag < 0 {
            return Err(self.fail("IDARootInit", flag));
        }
        Ok(())
    }

    /// Compute consistent initial conditions (`IDACalcIC`); `y()`/`yp()` then hold them.
    pub fn calc_ic(&mut self, mode: CalcIc, tout1: f64) -> Result<(), SolverError> {
        self.data.status.clear();
        let icopt = match mode {
            CalcIc::AlgebraicAndDerivatives => sys::IDA_YA_YDP_INIT,
            CalcIc::AllY => sys::IDA_Y_INIT,
        };
        // SAFETY: live IDA memory and owned vectors of length n.
        let flag = unsafe { sys::IDACalcIC(self.raw(), icopt, tout1) };
        if flag < 0 {
            return Err(self.fail("IDACalcIC", flag));
        }
        // SAFETY: as above.
        let flag = unsafe { sys::IDAGetConsistentIC(self.raw(), self.y.raw(), self.yp.raw()) };
        if flag < 0 {
            return Err(self.fail("IDAGetConsistentIC", flag));
        }
        Ok(())
    }

    /// Integrate to `tout` (or an earlier root / stop time); `y()`/`yp()` then hold the state at `step.t`.
    pub fn solve_to(&mut self, tout: f64) -> Result<Step, SolverError> {
        stepping::solve_to(self, tout)
    }

    /// [`Ida::solve_to`] that also returns early at the first internal step before `tout`
    /// for which `watch(t_n, y(t_n))` is `true` (`step.t < tout`; `y()` holds the step's own
    /// `y(t_n)`).
    pub fn solve_to_watched(
        &mut self,
        tout: f64,
        watch: &mut dyn FnMut(f64, &[f64]) -> bool,
    ) -> Result<Step, SolverError> {
        stepping::solve_to_watched(self, tout, watch)
    }

    /// Time of IDA's last accepted internal step `t_n` (after a failed solve call, the state
    /// `y()` holds `y(t_n)`: IDA returns its last accepted step on a failure).
    pub fn last_accepted_time(&self) -> f64 {
        self.current_time()
    }

    stepping::budget_methods!();

    /// Time of the state in `y()`/`yp()`.
    pub fn t(&self) -> f64 {
        self.stepping.t
    }

    /// State y at `t()`.
    pub fn y(&self) -> &[f64] {
        self.y.as_slice()
    }

    /// Derivative y' at `t()`.
    pub fn yp(&self) -> &[f64] {
        self.yp.as_slice()
    }

    /// k-th derivative of the interpolating polynomial at `t` (within the last step).
    pub fn dky(&mut self, t: f64, k: i32, out: &mut [f64]) -> Result<(), SolverError> {
        super::calls::check_output("dky output", out, self.data.n)?;
        // SAFETY: live IDA memory; tmp is an owned vector of length n.
        unsafe { CALLS.dky(self.raw(), t, k, self.tmp.raw()) }.map_err(|(f, c)| self.fail(f, c))?;
        out.copy_from_slice(self.tmp.as_slice());
        Ok(())
    }

    /// Restart from `(t0, y0, yp0)` keeping options, closures and linear solver.
    pub fn reinit(&mut self, t0: f64, y0: &[f64], yp0: &[f64]) -> Result<(), SolverError> {
        let n = self.data.n;
        check_vector("y0", y0, n)?;
        check_vector("yp0", yp0, n)?;
        self.y.as_mut_slice().copy_from_slice(y0);
        self.yp.as_mut_slice().copy_from_slice(yp0);
        // SAFETY: live IDA memory and owned vectors of length n.
        let flag = unsafe { sys::IDAReInit(self.raw(), t0, self.y.raw(), self.yp.raw()) };
        if flag < 0 {
            return Err(self.fail("IDAReInit", flag));
        }
        if self.sens.take().is_some() {
            // the sensitivities started at the old start: a restart turns them off
            // SAFETY: live IDA memory with sensitivities.
            unsafe { sys::IDASensToggleOff(self.raw()) };
            self.data.sens = None;
        }
        self.stepping.restart(t0);
        // IDAReInit zeroes SUNDIALS' counters
        self.failures.conv = 0;
        self.failures.etf = 0;
        Ok(())
    }

    /// Replaces the differential/algebraic marks `id` (1 differential, 0 algebraic) between
    /// steps, without a restart: with `suppress_alg` set, IDA's local error test is the
    /// weighted RMS norm masked by `id`, so this changes which components the next steps'
    /// error test sees (IDA copies the vector).
    pub fn set_id(&mut self, id: &[f64]) -> Result<(), SolverError> {
        check_vector("id", id, self.data.n)?;
        self.tmp.as_mut_slice().copy_from_slice(id);
        // SAFETY: live IDA memory; `tmp` is an owned vector of length n, which IDASetId copies
        // into IDA's own id vector (cloned on first use) before returning.
        let flag = unsafe { sys::IDASetId(self.raw(), self.tmp.raw()) };
        if flag < 0 {
            return Err(self.fail("IDASetId", flag));
        }
        Ok(())
    }

    /// Error weights `w_i = 1 / (rtol |y_i| + atol_i)` raised by `raise` (`IDAWFtolerances`):
    /// IDA's local error test and Newton convergence test measure `‖W e‖` with these weights,
    /// so raising a component's weight tightens the test on it. Replaces the tolerances given
    /// at construction; kept across [`Ida::reinit`].
    pub fn set_error_weights(
        &mut self,
        rtol: f64,
        atol: Vec<f64>,
        raise: ErrorWeightFn,
    ) -> Result<(), SolverError> {
        check_tolerances(rtol, &atol, self.data.n)?;
        self.data.weights = Some(ErrorWeights { rtol, atol, raise });
        // SAFETY: live IDA memory; the trampoline reads the closure from the boxed `IdaData`
        // registered as user data, which outlives the IDA memory.
        let flag = unsafe { sys::IDAWFtolerances(self.raw(), Some(weights_trampoline)) };
        if flag < 0 {
            return Err(self.fail("IDAWFtolerances", flag));
        }
        Ok(())
    }

    /// Do not step past `t`.
    pub fn set_stop_time(&mut self, t: f64) -> Result<(), SolverError> {
        // SAFETY: live IDA memory.
        unsafe { CALLS.set_stop_time(self.raw(), t) }.map_err(|(f, c)| self.fail(f, c))
    }

    /// Last message SUNDIALS reported to the error handler (instead of printing it).
    pub fn last_error_message(&self) -> Option<&str> {
        self.data.status.last_message.as_deref()
    }

    /// Integrator counters.
    pub fn stats(&self) -> SolverStats {
        // SAFETY: live IDA memory.
        unsafe { CALLS.stats(self.raw()) }
    }
}

impl Stepper for Ida {
    fn stepping(&mut self) -> &mut SteppingState {
        &mut self.stepping
    }

    fn current_time(&self) -> f64 {
        // SAFETY: live IDA memory.
        unsafe { CALLS.current_time(self.raw(), self.stepping.t) }
    }

    fn one_step(&mut self, tout: f64) -> Result<(f64, RawEvent), SolverError> {
        let mut tret = self.stepping.t;
        // SAFETY: live IDA memory, owned vectors of length n, valid out-pointer.
        let flag = unsafe {
            sys::IDASolve(
                self.raw(),
                tout,
                &mut tret,
                self.y.raw(),
                self.yp.raw(),
                sys::IDA_ONE_STEP,
            )
        };
        if flag >= 0 {
            self.log_failures(tret);
        }
        match CALLS.step_event(flag) {
            Some(event) => Ok((tret, event)),
            None => Err(self.fail("IDASolve", flag)),
        }
    }

    fn root_info(&mut self) -> Vec<i32> {
        // SAFETY: live IDA memory with nroots root functions.
        unsafe { CALLS.root_info(self.raw(), self.data.nroots) }
    }

    fn interpolate(&mut self, t: f64) -> Result<(), SolverError> {
        // SAFETY: live IDA memory and owned vectors of length n.
        unsafe { CALLS.dky(self.raw(), t, 0, self.y.raw()) }.map_err(|(f, c)| self.fail(f, c))?;
        // SAFETY: as above.
        unsafe { CALLS.dky(self.raw(), t, 1, self.yp.raw()) }.map_err(|(f, c)| self.fail(f, c))
    }

    fn clear_status(&mut self) {
        self.data.status.clear();
    }

    fn state(&self) -> &[f64] {
        self.y()
    }
}
