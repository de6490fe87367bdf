//! The ARKODE ERKStep C API that `sundials-sys` does not bind (Debian's SUNDIALS 6.4 ships
//! the library; its headers are declared here), used by [`super::erk`] and by the flag names
//! of [`super::error`].

use std::os::raw::{c_char, c_int, c_long, c_void};
use sundials_sys as sys;

/// `ARKRhsFn`.
pub type ArkRhsFn = Option<
    unsafe extern "C" fn(t: f64, y: sys::N_Vector, yd: sys::N_Vector, ud: *mut c_void) -> c_int,
>;
/// `ARKRootFn`.
pub type ArkRootFn =
    Option<unsafe extern "C" fn(t: f64, y: sys::N_Vector, g: *mut f64, ud: *mut c_void) -> c_int>;
/// `ARKErrHandlerFn`.
pub type ArkErrHandlerFn =
    Option<unsafe extern "C" fn(c_int, *const c_char, *const c_char, *mut c_char, *mut c_void)>;

/// `ARK_ONE_STEP`.
pub const ARK_ONE_STEP: c_int = 2;
/// `ARK_SUCCESS`.
pub const ARK_SUCCESS: c_int = 0;
/// `ARK_TSTOP_RETURN`.
pub const ARK_TSTOP_RETURN: c_int = 1;
/// `ARK_ROOT_RETURN`.
pub const ARK_ROOT_RETURN: c_int = 2;
/// `ARK_TOO_MUCH_WORK`.
pub const ARK_TOO_MUCH_WORK: c_int = -1;
/// `ARKODE_FEHLBERG_13_7_8`.
pub const FEHLBERG_13_7_8: c_int = 11;
/// `ARK_INTERP_MAX_DEGREE` (ERKStep lowers it to the method's order − 1).
pub const ARK_INTERP_MAX_DEGREE: c_int = 5;

#[link(name = "sundials_arkode")]
extern "C" {
    pub fn ERKStepCreate(
        f: ArkRhsFn,
        t0: f64,
        y0: sys::N_Vector,
        ctx: sys::SUNContext,
    ) -> *mut c_void;
    pub fn ERKStepReInit(mem: *mut c_void, f: ArkRhsFn, t0: f64, y0: sys::N_Vector) -> c_int;
    pub fn ERKStepSStolerances(mem: *mut c_void, rtol: f64, atol: f64) -> c_int;
    pub fn ERKStepSetUserData(mem: *mut c_void, ud: *mut c_void) -> c_int;
    pub fn ERKStepSetTableNum(mem: *mut c_void, table: c_int) -> c_int;
    pub fn ERKStepSetInterpolantDegree(mem: *mut c_void, degree: c_int) -> c_int;
    pub fn ERKStepSetMaxNumSteps(mem: *mut c_void, mxsteps: c_long) -> c_int;
    pub fn ERKStepSetInitStep(mem: *mut c_void, hin: f64) -> c_int;
    pub fn ERKStepSetTable(mem: *mut c_void, b: *mut c_void) -> c_int;
    pub fn ARKodeButcherTable_Create(
        s: c_int,
        q: c_int,
        p: c_int,
        c: *mut f64,
        a: *mut f64,
        b: *mut f64,
        d: *mut f64,
    ) -> *mut c_void;
    pub fn ARKodeButcherTable_Free(b: *mut c_void);
    pub fn ERKStepSetStopTime(mem: *mut c_void, tstop: f64) -> c_int;
    pub fn ERKStepSetErrHandlerFn(mem: *mut c_void, f: ArkErrHandlerFn, d: *mut c_void) -> c_int;
    pub fn ERKStepRootInit(mem: *mut c_void, n: c_int, g: ArkRootFn) -> c_int;
    pub fn ERKStepEvolve(
        mem: *mut c_void,
        tout: f64,
        yout: sys::N_Vector,
        tret: *mut f64,
        itask: c_int,
    ) -> c_int;
    pub fn ERKStepGetDky(mem: *mut c_void, t: f64, k: c_int, dky: sys::N_Vector) -> c_int;
    pub fn ERKStepGetNumSteps(mem: *mut c_void, n: *mut c_long) -> c_int;
    pub fn ERKStepGetNumRhsEvals(mem: *mut c_void, n: *mut c_long) -> c_int;
    pub fn ERKStepGetNumErrTestFails(mem: *mut c_void, n: *mut c_long) -> c_int;
    pub fn ERKStepGetNumGEvals(mem: *mut c_void, n: *mut c_long) -> c_int;
    pub fn ERKStepGetLastStep(mem: *mut c_void, h: *mut f64) -> c_int;
    pub fn ERKStepGetCurrentTime(mem: *mut c_void, t: *mut f64) -> c_int;
    pub fn ERKStepGetRootInfo(mem: *mut c_void, info: *mut c_int) -> c_int;
    pub fn ERKStepFree(mem: *mut *mut c_void);
    pub fn ERKStepGetReturnFlagName(flag: c_long) -> *mut c_char;
}
