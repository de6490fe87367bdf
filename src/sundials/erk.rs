//! ARKODE's explicit Runge–Kutta stepper (ERKStep) for non-stiff ODEs `y' = f(t, y)`.
//!
//! `sundials-sys` 0.6 generates no ARKODE bindings (its `wrapper.h` leaves the ARKODE headers
//! out; its `arkode` feature only links `libsundials_arkode`), so the few ERKStep functions
//! used here are declared by hand in the private `ffi` module, copied from Debian's SUNDIALS 6.4
//! `arkode/arkode_erkstep.h`.
//!
//! Output times are reached exactly: `solve_to(tout)` sets ERKStep's stop time to `tout`, so the
//! last step lands on it (an explicit method's own dense output is of lower order than the
//! method; landing costs at most one short step per output).

use super::callback::{error_handler, finite_or_recoverable, CallbackStatus, CvodeRootFn, RhsFn};
use super::calls::Calls;
use super::context::Context;
use super::error::{check, Package, SolverError};
use super::options::{check_tolerances, check_vector, Step};
use super::stats::SolverStats;
use super::stepping::{self, RawEvent, Stepper, SteppingState};
use super::tables::ButcherTable;
use super::vector::{slice_of, slice_of_mut, NVector};
use std::os::raw::{c_int, c_void};
use sundials_sys as sys;

const P: Package = Package::Arkode;

use super::arkode_ffi as ffi;

/// ARKODE's entry points for the call sequences the integrator wrappers share
/// ([`super::calls`]).
static CALLS: Calls = Calls {
    package: P,
    user_function: "right-hand side",
    current_time: ffi::ERKStepGetCurrentTime,
    root_info: ffi::ERKStepGetRootInfo,
    set_stop_time: ("ERKStepSetStopTime", ffi::ERKStepSetStopTime),
    dky: ("ERKStepGetDky", ffi::ERKStepGetDky),
    last_step: ffi::ERKStepGetLastStep,
    last_order: None,
    counters: [
        Some(ffi::ERKStepGetNumSteps),
        Some(ffi::ERKStepGetNumRhsEvals),
        None,
        None,
        None,
        None,
        Some(ffi::ERKStepGetNumErrTestFails),
        Some(ffi::ERKStepGetNumGEvals),
    ],
    returns: [
        ffi::ARK_SUCCESS,
        ffi::ARK_ROOT_RETURN,
        ffi::ARK_TSTOP_RETURN,
    ],
    too_much_work: ffi::ARK_TOO_MUCH_WORK,
};

/// Options for [`Erk`].
#[derive(Clone, Debug)]
pub struct ErkOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (scalar).
    pub atol: f64,
    /// Internal steps allowed per `solve_to` call (`None`: the stepping loop's default 500).
    pub max_steps: Option<u64>,
    /// Internal steps allowed over the whole integration (`None`: no cap).
    pub max_total_steps: Option<u64>,
    /// Wall-clock time allowed for the whole integration.
    pub max_wall_clock: Option<std::time::Duration>,
    /// Do not integrate past this time.
    pub stop_time: Option<f64>,
}

/// Degree of the Hermite interpolant by default.
const CUBIC: c_int = 3;

/// ARKODE's most accurate Hermite interpolant (its default: degree `q − 1` up to 5).
pub const MAX_INTERPOLANT_DEGREE: i32 = ffi::ARK_INTERP_MAX_DEGREE;

/// The explicit Runge–Kutta method of an [`Erk`].
#[derive(Clone, Debug, PartialEq)]
pub enum ErkTable {
    /// One of ARKODE's built-in tables (`ARKODE_ERKTableID`) and its name.
    Builtin(c_int, &'static str),
    /// A table handed to ARKODE ([`super::tables`]).
    Custom(ButcherTable),
}

impl ErkTable {
    /// The method's name.
    pub fn name(&self) -> &'static str {
        match self {
            ErkTable::Builtin(_, n) => n,
            ErkTable::Custom(t) => t.name,
        }
    }
}

/// The Butcher table for a relative tolerance: Tsitouras 5(4) down to 1e-7, Fehlberg 8(7)
/// below (the high order pays where the steps are accuracy-bound).
///
/// Tsitouras 5(4) rather than ARKODE's Dormand–Prince 5(4): the same six right-hand sides per
/// step, smaller errors (slider-crank, partitioned, rtol 1e-7: see the README's partitioned
/// section). Not Verner 6(5) (`ARKODE_VERNER_8_5_6`) nor `ARK5(4)8L[2]SA-ERK`: in Debian's
/// SUNDIALS 6.4 both fall short of their order — on `y'' = −y` over 50 s with a step of
/// 0.01 s Verner ends 3.8e-7 off (Dormand–Prince 1.4e-12, Fehlberg 4.7e-14), and at rtol 1e-9
/// it took 2593 steps to end 3e-6 off where Fehlberg took 406 to end 3e-10 off
/// (`tests/sundials_erk.rs`).
pub fn table_for(rtol: f64) -> ErkTable {
    if rtol >= 1e-7 {
        ErkTable::Custom(ButcherTable::tsitouras5())
    } else {
        ErkTable::Builtin(ffi::FEHLBERG_13_7_8, "Fehlberg 8(7)")
    }
}

struct ErkData {
    status: CallbackStatus,
    n: usize,
    nroots: usize,
    rhs: RhsFn,
    roots: Option<CvodeRootFn>,
}

struct ErkMem(*mut c_void);

impl Drop for ErkMem {
    fn drop(&mut self) {
        // SAFETY: the pointer came from ERKStepCreate and is freed exactly once.
        unsafe { ffi::ERKStepFree(&mut self.0) }
    }
}

/// An ERKStep integrator with its own SUNDIALS context (field order is drop order).
pub struct Erk {
    mem: ErkMem,
    y: NVector,
    tmp: NVector,
    data: Box<ErkData>,
    stepping: SteppingState,
    /// Time of the last step the integrator accepted (what `last_step_time` returns).
    accepted: f64,
    stop_time: Option<f64>,
    #[allow(dead_code)] // owned: freed last
    ctx: Context,
}

// SAFETY: an Erk exclusively owns its context, memory, vectors and closures (all `Send`);
// SUNDIALS keeps no global state across contexts.
unsafe impl Send for Erk {}

unsafe extern "C" fn rhs_trampoline(
    t: f64,
    yy: sys::N_Vector,
    yd: sys::N_Vector,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: user_data is the Box<ErkData> registered with ERKStepSetUserData, alive as long
    // as the ARKODE memory; yy and yd are distinct serial vectors of length n.
    let (data, y, ydot) = unsafe {
        let data = &mut *(user_data as *mut ErkData);
        let n = data.n;
        (data, slice_of(yy, n), slice_of_mut(yd, n))
    };
    let ErkData { status, rhs, .. } = data;
    let code = status.guard(t, || rhs(t, y, ydot));
    status.check_output("right-hand side", code, t, y, ydot)
}

unsafe extern "C" fn root_trampoline(
    t: f64,
    yy: sys::N_Vector,
    gout: *mut f64,
    user_data: *mut c_void,
) -> c_int {
    // SAFETY: as in rhs_trampoline; gout has room for the nroots registered.
    let (data, y, g) = unsafe {
        let data = &mut *(user_data as *mut ErkData);
        let n = data.n;
        let g = std::slice::from_raw_parts_mut(gout, data.nroots);
        (data, slice_of(yy, n), g)
    };
    let ErkData { status, roots, .. } = data;
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

impl Erk {
    /// Creates an explicit Runge–Kutta solver for `y' = f(t, y)` from `(t0, y0)`, with the
    /// Butcher table of [`table_for`] the relative tolerance.
    pub fn new(t0: f64, y0: &[f64], rhs: RhsFn, opts: &ErkOptions) -> Result<Erk, SolverError> {
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
        check_tolerances(opts.rtol, &[opts.atol], n)?;
        let ctx = Context::new()?;
        let y = NVector::from_slice(&ctx, y0)?;
        let tmp = NVector::from_slice(&ctx, y0)?;
        let mut data = Box::new(ErkData {
            status: CallbackStatus::default(),
            n,
            nroots: 0,
            rhs,
            roots: None,
        });
        // SAFETY: valid context and vector; NULL checked below.
        let raw = unsafe { ffi::ERKStepCreate(Some(rhs_trampoline), t0, y.raw(), ctx.raw()) };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("ERKStepCreate failed".into()));
        }
        let mem = ErkMem(raw);
        let status_ptr = &mut data.status as *mut CallbackStatus as *mut c_void;
        let data_ptr = &mut *data as *mut ErkData as *mut c_void;
        // SAFETY: live ARKODE memory; user data and error-handler data point into the Box
        // `data`, kept alive (unmoved) by the returned Erk; a custom table's arrays are live
        // for the call that copies them into a table ARKODE copies in turn, and that table is
        // freed once, right after.
        unsafe {
            check(
                P,
                "ERKStepSetErrHandlerFn",
                ffi::ERKStepSetErrHandlerFn(raw, Some(error_handler), status_ptr),
                t0,
            )?;
            check(
                P,
                "ERKStepSStolerances",
                ffi::ERKStepSStolerances(raw, opts.rtol, opts.atol),
                t0,
            )?;
            check(
                P,
                "ERKStepSetUserData",
                ffi::ERKStepSetUserData(raw, data_ptr),
                t0,
            )?;
            match table_for(opts.rtol) {
                ErkTable::Builtin(id, _) => check(
                    P,
                    "ERKStepSetTableNum",
                    ffi::ERKStepSetTableNum(raw, id),
                    t0,
                )?,
                ErkTable::Custom(mut tb) => {
                    // ARKODE copies the table (ERKStepSetTable), so it is freed right after
                    let table = ffi::ARKodeButcherTable_Create(
                        tb.stages() as c_int,
                        tb.q,
                        tb.p,
                        tb.c.as_mut_ptr(),
                        tb.a.as_mut_ptr(),
                        tb.b.as_mut_ptr(),
                        tb.d.as_mut_ptr(),
                    );
                    if table.is_null() {
                        return Err(SolverError::InvalidInput(
                            "ARKodeButcherTable_Create failed".into(),
                        ));
                    }
                    let flag = ffi::ERKStepSetTable(raw, table);
                    ffi::ARKodeButcherTable_Free(table);
                    check(P, "ERKStepSetTable", flag, t0)?;
                }
            }
            // outputs are reached exactly (stop times), so the interpolant only serves root
            // finding and `dky`: a cubic Hermite needs no right-hand side beyond the step's
            // own, where ARKODE's default (degree q − 1, quartic for a fifth-order table)
            // spends one more per step
            check(
                P,
                "ERKStepSetInterpolantDegree",
                ffi::ERKStepSetInterpolantDegree(raw, CUBIC),
                t0,
            )?;
            // the stepping loop counts steps; ARKODE's own per-call limit is one step in ONE_STEP mode
            check(
                P,
                "ERKStepSetMaxNumSteps",
                ffi::ERKStepSetMaxNumSteps(raw, -1),
                t0,
            )?;
        }
        Ok(Erk {
            mem,
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
            stop_time: opts.stop_time,
            ctx,
        })
    }

    fn raw(&self) -> *mut c_void {
        self.mem.0
    }

    fn fail(&mut self, function: &'static str, flag: c_int) -> SolverError {
        let t = self.current_time();
        let max_steps = self.stepping.max_steps;
        CALLS.failure(&mut self.data.status, (function, flag), t, max_steps)
    }

    /// Registers `n` root functions `g(t, y)`; sign changes stop `solve_to`. Root finding
    /// interpolates within the step with the cubic interpolant unless
    /// [`Self::set_interpolant_degree`] asks for more ([`MAX_INTERPOLANT_DEGREE`]: event times
    /// to the step's accuracy).
    pub fn set_roots(&mut self, n: usize, f: CvodeRootFn) -> Result<(), SolverError> {
        self.data.roots = Some(f);
        self.data.nroots = n;
        // SAFETY: live ARKODE memory; the trampoline reads closures from the user data.
        let flag = unsafe { ffi::ERKStepRootInit(self.raw(), n as c_int, Some(root_trampoline)) };
        if flag < 0 {
            return Err(self.fail("ERKStepRootInit", flag));
        }
        Ok(())
    }

    /// Integrates to `tout` exactly (or an earlier root); `y()` then holds the state at `step.t`.
    pub fn solve_to(&mut self, tout: f64) -> Result<Step, SolverError> {
        let stop = self.stop_time.map_or(tout, |s| s.min(tout));
        if stop > self.stepping.t {
            // SAFETY: live ARKODE memory.
            unsafe { CALLS.set_stop_time(self.raw(), stop) }.map_err(|(f, c)| self.fail(f, c))?;
        }
        stepping::solve_to(self, tout)
    }

    stepping::budget_methods!();

    /// Time of the last accepted step (at or after [`Self::t`]).
    pub fn last_step_time(&self) -> f64 {
        self.accepted
    }

    /// Time of the state in `y()`.
    pub fn t(&self) -> f64 {
        self.stepping.t
    }

    /// State at `t()`.
    pub fn y(&self) -> &[f64] {
        self.y.as_slice()
    }

    /// k-th derivative of ARKODE's interpolant at `t` (within the last step).
    pub fn dky(&mut self, t: f64, k: i32, out: &mut [f64]) -> Result<(), SolverError> {
        super::calls::check_output("dky output", out, self.data.n)?;
        // SAFETY: live ARKODE memory; tmp is an owned vector of length n.
        unsafe { CALLS.dky(self.raw(), t, k, self.tmp.raw()) }.map_err(|(f, c)| self.fail(f, c))?;
        out.copy_from_slice(self.tmp.as_slice());
        Ok(())
    }

    /// The first step after the next (re)start (0: ARKODE's estimate, the default).
    pub fn set_init_step(&mut self, h: f64) -> Result<(), SolverError> {
        // SAFETY: live ARKODE memory.
        let flag = unsafe { ffi::ERKStepSetInitStep(self.raw(), h) };
        if flag < 0 {
            return Err(self.fail("ERKStepSetInitStep", flag));
        }
        Ok(())
    }

    /// Sets the Hermite interpolant's degree (`dky` and root finding; cubic by default).
    pub fn set_interpolant_degree(&mut self, degree: i32) -> Result<(), SolverError> {
        // SAFETY: live ARKODE memory.
        let flag = unsafe { ffi::ERKStepSetInterpolantDegree(self.raw(), degree as c_int) };
        if flag < 0 {
            return Err(self.fail("ERKStepSetInterpolantDegree", flag));
        }
        Ok(())
    }

    /// Restarts from `(t0, y0)` keeping options and closures.
    pub fn reinit(&mut self, t0: f64, y0: &[f64]) -> Result<(), SolverError> {
        check_vector("y0", y0, self.data.n)?;
        self.y.as_mut_slice().copy_from_slice(y0);
        // SAFETY: live ARKODE memory and an owned vector of length n.
        let flag =
            unsafe { ffi::ERKStepReInit(self.raw(), Some(rhs_trampoline), t0, self.y.raw()) };
        if flag < 0 {
            return Err(self.fail("ERKStepReInit", flag));
        }
        self.stepping.restart(t0);
        self.accepted = t0;
        Ok(())
    }

    /// Integrator counters (`residual_evals` counts right-hand-side evaluations).
    pub fn stats(&self) -> SolverStats {
        // SAFETY: live ARKODE memory.
        unsafe { CALLS.stats(self.raw()) }
    }
}

impl Stepper for Erk {
    fn stepping(&mut self) -> &mut SteppingState {
        &mut self.stepping
    }

    fn current_time(&self) -> f64 {
        // SAFETY: live ARKODE memory.
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

impl Erk {
    fn one_step_raw(&mut self, tout: f64) -> Result<(f64, RawEvent), SolverError> {
        let mut tret = self.stepping.t;
        // SAFETY: live ARKODE memory, an owned vector of length n, valid out-pointer.
        let flag = unsafe {
            ffi::ERKStepEvolve(self.raw(), tout, self.y.raw(), &mut tret, ffi::ARK_ONE_STEP)
        };
        match CALLS.step_event(flag) {
            Some(event) => Ok((tret, event)),
            None => Err(self.fail("ERKStepEvolve", flag)),
        }
    }

    fn root_info_raw(&mut self) -> Vec<i32> {
        // SAFETY: live ARKODE memory with nroots root functions.
        unsafe { CALLS.root_info(self.raw(), self.data.nroots) }
    }

    fn interpolate_raw(&mut self, t: f64) -> Result<(), SolverError> {
        // SAFETY: live ARKODE memory and an owned vector of length n.
        unsafe { CALLS.dky(self.raw(), t, 0, self.y.raw()) }.map_err(|(f, c)| self.fail(f, c))
    }
}
