//! CVODE: variable-order BDF (stiff) or Adams–Moulton (non-stiff) for ODEs
//! `y' = f(t, y)`, with Newton iteration on `M = I - γ ∂f/∂y` solved by the dense
//! linear solver (user Jacobian `∂f/∂y` or difference quotients) for both methods, or by a
//! sparse LU on a fixed CSC pattern ([`Cvode::new_sparse`]: faer or KLU, see
//! [`super::sparse`]).

use super::callback::{
    error_handler, finite_or_recoverable, CallbackStatus, CvodeJacobianFn, CvodeRootFn,
    CvodeSparseJacobianFn, RhsFn,
};
use super::calls::Calls;
use super::context::Context;
use super::error::{check, Package, SolverError};
use super::linsol::LinearSolver;
use super::matrix::{DenseMatrix, DenseMatrixMut};
use super::options::{check_tolerances, check_vector, CvodeOptions, Multistep, Step};
use super::sparse::{self, CscPattern, FaerCounters, SparseMatrix, SparseMatrixMut, SparseSolver};
use super::stats::SolverStats;
use super::stepping::{self, RawEvent, Stepper, SteppingState};
use super::vector::{slice_of, slice_of_mut, NVector};
use std::os::raw::{c_int, c_void};
use sundials_sys as sys;

const P: Package = Package::Cvode;

/// CVODE's entry points for the call sequences the integrator wrappers share
/// ([`super::calls`]).
static CALLS: Calls = Calls {
    package: P,
    user_function: "right-hand side",
    current_time: sys::CVodeGetCurrentTime,
    root_info: sys::CVodeGetRootInfo,
    set_stop_time: ("CVodeSetStopTime", sys::CVodeSetStopTime),
    dky: ("CVodeGetDky", sys::CVodeGetDky),
    last_step: sys::CVodeGetLastStep,
    last_order: Some(sys::CVodeGetLastOrder),
    counters: [
        Some(sys::CVodeGetNumSteps),
        Some(sys::CVodeGetNumRhsEvals),
        Some(sys::CVodeGetNumJacEvals),
        Some(sys::CVodeGetNumLinSolvSetups),
        Some(sys::CVodeGetNumNonlinSolvIters),
        Some(sys::CVodeGetNumNonlinSolvConvFails),
        Some(sys::CVodeGetNumErrTestFails),
        Some(sys::CVodeGetNumGEvals),
    ],
    returns: [sys::CV_SUCCESS, sys::CV_ROOT_RETURN, sys::CV_TSTOP_RETURN],
    too_much_work: sys::CV_TOO_MUCH_WORK,
};

/// Closures and callback status; boxed so SUNDIALS can hold its address as `user_data`.
struct CvodeData {
    status: CallbackStatus,
    n: usize,
    nroots: usize,
    rhs: RhsFn,
    jacobian: Option<CvodeJacobianFn>,
    sparse_jacobian: Option<(CvodeSparseJacobianFn, CscPattern)>,
    roots: Option<CvodeRootFn>,
}

/// Owned CVODE memory, freed with `CVodeFree`.
struct CvodeMem(*mut c_void);

impl Drop for CvodeMem {
    fn drop(&mut self) {
        // SAFETY: the pointer came from CVodeCreate and is freed exactly once.
        unsafe { sys::CVodeFree(&mut self.0) }
    }
}

/// A CVODE integrator with its own SUNDIALS context.
///
/// Field order is drop order: CVODE memory, linear solver, matrix, vectors,
/// closures, context last.
pub struct Cvode {
    mem: CvodeMem,
    #[allow(dead_code)] // owned: freed after `mem`
    ls: LinearSolver,
    #[allow(dead_code)] // owned: freed after `ls`
    mat: Option<DenseMatrix>,
    #[allow(dead_code)] // owned: freed after `ls`
    smat: Option<SparseMatrix>,
    y: NVector,
    tmp: NVector,
    data: Box<CvodeData>,
    stepping: SteppingState,
    /// Time of the last step the integrator accepted (what `last_step_time` returns).
    accepted: f64,
    #[allow(dead_code)] // owned: freed last
    ctx: Context,
}

// SAFETY: a Cvode exclusively owns its context, memory, vectors and closures (all
// `Send`); SUNDIALS keeps no global state across contexts, and nothing is shared.
unsafe impl Send for Cvode {}

unsafe extern "C" fn rhs_trampoline(
    t: f64,
    yy: sys::N_Vector,
    yd: sys::N_Vector,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: user_data is the Box<CvodeData> registered with CVodeSetUserData, alive
    // as long as the CVODE memory; yy and yd are distinct serial vectors of length n.
    let (data, y, ydot) = unsafe {
        let data = &mut *(user_data as *mut CvodeData);
        let n = data.n;
        (data, slice_of(yy, n), slice_of_mut(yd, n))
    };
    let CvodeData { status, rhs, .. } = data;
    let code = status.guard(t, || rhs(t, y, ydot));
    status.check_output("right-hand side", code, t, y, ydot)
}

unsafe extern "C" fn jacobian_trampoline(
    t: f64,
    yy: sys::N_Vector,
    fy: sys::N_Vector,
    jac: sys::SUNMatrix,
    user_data: *mut c_void,
    _t1: sys::N_Vector,
    _t2: sys::N_Vector,
    _t3: sys::N_Vector,
) -> c_int {
    // SAFETY: as in rhs_trampoline; jac is the dense n x n matrix we attached.
    let (data, y, f, mut j) = unsafe {
        let data = &mut *(user_data as *mut CvodeData);
        let n = data.n;
        (
            data,
            slice_of(yy, n),
            slice_of(fy, n),
            DenseMatrixMut::from_raw(jac),
        )
    };
    j.fill_zero();
    let CvodeData {
        status, jacobian, ..
    } = data;
    let Some(jacobian) = jacobian.as_mut() else {
        return -1;
    };
    let code = status.guard(t, || jacobian(t, y, f, &mut j));
    // a non-finite Newton matrix counts toward the solver being stuck, as a residual's does
    status.check_output("Jacobian", code, t, y, j.as_mut_slice())
}

#[allow(clippy::too_many_arguments)]
unsafe extern "C" fn sparse_jacobian_trampoline(
    t: f64,
    yy: sys::N_Vector,
    fy: sys::N_Vector,
    jac: sys::SUNMatrix,
    user_data: *mut c_void,
    _t1: sys::N_Vector,
    _t2: sys::N_Vector,
    _t3: sys::N_Vector,
) -> c_int {
    // SAFETY: as in rhs_trampoline; jac is the CSC matrix we attached, with room for the
    // pattern's entries (CVODE zeroes its index arrays, so the pattern is written back).
    let (data, y, f) = unsafe {
        let data = &mut *(user_data as *mut CvodeData);
        let n = data.n;
        (data, slice_of(yy, n), slice_of(fy, n))
    };
    let CvodeData {
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
    let code = status.guard(t, || jacobian(t, y, f, &mut j));
    status.check_output("Jacobian", code, t, y, j.values_mut())
}

unsafe extern "C" fn root_trampoline(
    t: f64,
    yy: sys::N_Vector,
    gout: *mut f64,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: as in rhs_trampoline; gout has room for the nroots registered.
    let (data, y, g) = unsafe {
        let data = &mut *(user_data as *mut CvodeData);
        let n = data.n;
        let g = std::slice::from_raw_parts_mut(gout, data.nroots);
        (data, slice_of(yy, n), g)
    };
    let CvodeData { status, roots, .. } = data;
    let Some(roots) = roots.as_mut() else {
        return -1;
    };
    let code = status.guard(t, || roots(t, y, g));
    if finite_or_recoverable(code, g) != 0 {
        -1
    } else {
        0
    }
}

impl Cvode {
    /// Create a CVODE solver for `y' = f(t, y)` from `(t0, y0)`.
    pub fn new(
        method: Multistep,
        t0: f64,
        y0: &[f64],
        rhs: RhsFn,
        jacobian: Option<CvodeJacobianFn>,
        opts: &CvodeOptions,
    ) -> Result<Cvode, SolverError> {
        Cvode::build(method, t0, y0, rhs, jacobian, None, opts)
    }

    /// Create a CVODE solver whose Jacobian `∂f/∂y` (and Newton matrix `I − γ ∂f/∂y`) is
    /// stored in the fixed sparsity `pattern` (CSC), filled by `jacobian` and factored by the
    /// sparse LU `solver`.
    #[allow(clippy::too_many_arguments)]
    pub fn new_sparse(
        method: Multistep,
        t0: f64,
        y0: &[f64],
        rhs: RhsFn,
        jacobian: CvodeSparseJacobianFn,
        pattern: CscPattern,
        solver: SparseSolver,
        opts: &CvodeOptions,
    ) -> Result<Cvode, SolverError> {
        if pattern.n() != y0.len() {
            return Err(SolverError::InvalidInput(format!(
                "sparsity pattern is {0} × {0} but y0 has length {1}",
                pattern.n(),
                y0.len()
            )));
        }
        Cvode::build(
            method,
            t0,
            y0,
            rhs,
            None,
            Some((jacobian, pattern, solver)),
            opts,
        )
    }

    fn build(
        method: Multistep,
        t0: f64,
        y0: &[f64],
        rhs: RhsFn,
        jacobian: Option<CvodeJacobianFn>,
        sparse_jac: Option<(CvodeSparseJacobianFn, CscPattern, SparseSolver)>,
        opts: &CvodeOptions,
    ) -> Result<Cvode, SolverError> {
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
        check_tolerances(opts.rtol, &opts.atol, n)?;
        // Locals drop in reverse order: memory first, context last.
        let ctx = Context::new()?;
        let y = NVector::from_slice(&ctx, y0)?;
        let tmp = NVector::from_slice(&ctx, y0)?;
        let has_jac = jacobian.is_some();
        let (mat, smat, ls) = match &sparse_jac {
            Some((_, p, kind)) => {
                let sm = SparseMatrix::new(&ctx, p)?;
                let ls = sparse::new_sparse_solver(&ctx, &y, &sm, *kind, Default::default())?;
                (None, Some(sm), ls)
            }
            None => {
                let m = DenseMatrix::square(&ctx, n)?;
                let ls = super::dense_lu::new(&ctx)?;
                (Some(m), None, ls)
            }
        };
        let mut data = Box::new(CvodeData {
            status: CallbackStatus::default(),
            n,
            nroots: 0,
            rhs,
            jacobian,
            sparse_jacobian: sparse_jac.map(|(j, p, _)| (j, p)),
            roots: None,
        });
        let a = match (&mat, &smat) {
            (Some(m), _) => m.raw(),
            (None, Some(m)) => m.raw(),
            (None, None) => std::ptr::null_mut(),
        };
        let lmm = match method {
            Multistep::Bdf => sys::CV_BDF,
            Multistep::Adams => sys::CV_ADAMS,
        };
        // SAFETY: valid context; NULL checked below.
        let raw = unsafe { sys::CVodeCreate(lmm, ctx.raw()) };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("CVodeCreate failed".into()));
        }
        let mem = CvodeMem(raw);
        let status_ptr = &mut data.status as *mut CallbackStatus as *mut c_void;
        let data_ptr = &mut *data as *mut CvodeData as *mut c_void;
        // SAFETY: mem, vectors, matrix and solver are live; user data and error-handler
        // data point into the Box `data`, kept alive (unmoved) by the returned Cvode.
        unsafe {
            check(
                P,
                "CVodeSetErrHandlerFn",
                sys::CVodeSetErrHandlerFn(raw, Some(error_handler), status_ptr),
                t0,
            )?;
            check(
                P,
                "CVodeInit",
                sys::CVodeInit(raw, Some(rhs_trampoline), t0, y.raw()),
                t0,
            )?;
            if opts.atol.len() == 1 {
                check(
                    P,
                    "CVodeSStolerances",
                    sys::CVodeSStolerances(raw, opts.rtol, opts.atol[0]),
                    t0,
                )?;
            } else {
                let atol = NVector::from_slice(&ctx, &opts.atol)?;
                check(
                    P,
                    "CVodeSVtolerances",
                    sys::CVodeSVtolerances(raw, opts.rtol, atol.raw()),
                    t0,
                )?;
            }
            check(
                P,
                "CVodeSetUserData",
                sys::CVodeSetUserData(raw, data_ptr),
                t0,
            )?;
            check(
                P,
                "CVodeSetLinearSolver",
                sys::CVodeSetLinearSolver(raw, ls.raw(), a),
                t0,
            )?;
            if has_jac {
                check(
                    P,
                    "CVodeSetJacFn",
                    sys::CVodeSetJacFn(raw, Some(jacobian_trampoline)),
                    t0,
                )?;
            }
            if smat.is_some() {
                check(
                    P,
                    "CVodeSetJacFn",
                    sys::CVodeSetJacFn(raw, Some(sparse_jacobian_trampoline)),
                    t0,
                )?;
            }
            if let Some(v) = opts.max_order {
                check(P, "CVodeSetMaxOrd", sys::CVodeSetMaxOrd(raw, v), t0)?;
            }
            if let Some(v) = opts.max_step {
                check(P, "CVodeSetMaxStep", sys::CVodeSetMaxStep(raw, v), t0)?;
            }
            if let Some(v) = opts.init_step {
                check(P, "CVodeSetInitStep", sys::CVodeSetInitStep(raw, v), t0)?;
            }
            if let Some(t) = opts.stop_time {
                check(P, "CVodeSetStopTime", sys::CVodeSetStopTime(raw, t), t0)?;
            }
            if opts.stab_lim_det {
                check(P, "CVodeSetStabLimDet", sys::CVodeSetStabLimDet(raw, 1), t0)?;
            }
        }
        Ok(Cvode {
            mem,
            ls,
            mat,
            smat,
            y,
            tmp,
            data,
            accepted: t0,
            stepping: SteppingState::new(
                t0,
                opts.max_steps,
                opts.max_wall_clock,
                opts.max_total_steps,
            ),
            ctx,
        })
    }

    fn raw(&self) -> *mut c_void {
        self.mem.0
    }

    /// Symbolic analyses and numeric factorisations of the faer sparse LU so far (`None`
    /// when CVODE does not use it).
    pub fn faer_counters(&self) -> Option<FaerCounters> {
        sparse::faer_counters(&self.ls)
    }

    /// Turn a failing flag into an error, preferring a callback's own error.
    fn fail(&mut self, function: &'static str, flag: c_int) -> SolverError {
        let t = self.current_time();
        let max_steps = self.stepping.max_steps;
        CALLS.failure(&mut self.data.status, (function, flag), t, max_steps)
    }

    /// Register `n` root functions `g(t, y)`; sign changes stop `solve_to`.
    pub fn set_roots(&mut self, n: usize, f: CvodeRootFn) -> Result<(), SolverError> {
        self.data.roots = Some(f);
        self.data.nroots = n;
        // SAFETY: live CVODE memory; the trampoline reads closures from the registered user data.
        let flag = unsafe { sys::CVodeRootInit(self.raw(), n as c_int, Some(root_trampoline)) };
        if flag < 0 {
            return Err(self.fail("CVodeRootInit", flag));
        }
        Ok(())
    }

    /// Integrate to `tout` (or an earlier root / stop time); `y()` then holds the state at `step.t`.
    pub fn solve_to(&mut self, tout: f64) -> Result<Step, SolverError> {
        stepping::solve_to(self, tout)
    }

    stepping::budget_methods!();

    /// Time CVODE's internal integration has reached (the last accepted step, at or after
    /// [`Self::t`]); [`Self::dky`] interpolates up to it.
    pub fn last_step_time(&self) -> f64 {
        self.accepted
    }

    /// Time of the state in `y()`.
    pub fn t(&self) -> f64 {
        self.stepping.t
    }

    /// State y at `t()`.
    pub fn y(&self) -> &[f64] {
        self.y.as_slice()
    }

    /// k-th derivative of the interpolating polynomial at `t` (within the last step).
    pub fn dky(&mut self, t: f64, k: i32, out: &mut [f64]) -> Result<(), SolverError> {
        super::calls::check_output("dky output", out, self.data.n)?;
        // SAFETY: live CVODE memory; tmp is an owned vector of length n.
        unsafe { CALLS.dky(self.raw(), t, k, self.tmp.raw()) }.map_err(|(f, c)| self.fail(f, c))?;
        out.copy_from_slice(self.tmp.as_slice());
        Ok(())
    }

    /// Restart from `(t0, y0)` keeping options and closures.
    pub fn reinit(&mut self, t0: f64, y0: &[f64]) -> Result<(), SolverError> {
        check_vector("y0", y0, self.data.n)?;
        self.y.as_mut_slice().copy_from_slice(y0);
        // SAFETY: live CVODE memory and an owned vector of length n.
        let flag = unsafe { sys::CVodeReInit(self.raw(), t0, self.y.raw()) };
        if flag < 0 {
            return Err(self.fail("CVodeReInit", flag));
        }
        self.stepping.restart(t0);
        self.accepted = t0;
        Ok(())
    }

    /// Do not step past `t`.
    pub fn set_stop_time(&mut self, t: f64) -> Result<(), SolverError> {
        // SAFETY: live CVODE memory.
        unsafe { CALLS.set_stop_time(self.raw(), t) }.map_err(|(f, c)| self.fail(f, c))
    }

    /// Last message SUNDIALS reported to the error handler (instead of printing it).
    pub fn last_error_message(&self) -> Option<&str> {
        self.data.status.last_message.as_deref()
    }

    /// Integrator counters (`residual_evals` counts right-hand-side evaluations).
    pub fn stats(&self) -> SolverStats {
        // SAFETY: live CVODE memory.
        unsafe { CALLS.stats(self.raw()) }
    }
}

impl Stepper for Cvode {
    fn stepping(&mut self) -> &mut SteppingState {
        &mut self.stepping
    }

    fn current_time(&self) -> f64 {
        // SAFETY: live CVODE memory.
        unsafe { CALLS.current_time(self.raw(), self.stepping.t) }
    }

    fn one_step(&mut self, tout: f64) -> Result<(f64, RawEvent), SolverError> {
        let r = self.one_step_raw(tout);
        if let Ok((t, _)) = &r {
            self.accepted = self.accepted.max(*t);
        }
        r
    }

    fn root_info(&mut self) -> Vec<i32> {
        self.root_info_raw()
    }

    fn interpolate(&mut self, t: f64) -> Result<(), SolverError> {
        self.interpolate_raw(t)
    }

    fn clear_status(&mut self) {
        self.data.status.clear();
    }

    fn state(&self) -> &[f64] {
        self.y()
    }
}

impl Cvode {
    fn one_step_raw(&mut self, tout: f64) -> Result<(f64, RawEvent), SolverError> {
        let mut tret = self.stepping.t;
        // SAFETY: live CVODE memory, an owned vector of length n, valid out-pointer.
        let flag =
            unsafe { sys::CVode(self.raw(), tout, self.y.raw(), &mut tret, sys::CV_ONE_STEP) };
        match CALLS.step_event(flag) {
            Some(event) => Ok((tret, event)),
            None => Err(self.fail("CVode", flag)),
        }
    }

    fn root_info_raw(&mut self) -> Vec<i32> {
        // SAFETY: live CVODE memory with nroots root functions.
        unsafe { CALLS.root_info(self.raw(), self.data.nroots) }
    }

    fn interpolate_raw(&mut self, t: f64) -> Result<(), SolverError> {
        // SAFETY: live CVODE memory and an owned vector of length n.
        unsafe { CALLS.dky(self.raw(), t, 0, self.y.raw()) }.map_err(|(f, c)| self.fail(f, c))
    }
}
