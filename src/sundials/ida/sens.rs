//! IDAS forward sensitivities of an [`Ida`]: `s_i = ∂y/∂p_i` for `N_s` parameters, integrated
//! with the solution by the staggered corrector (the state's Newton iteration converges first,
//! then one linear Newton iteration per step solves all sensitivity systems with the same
//! factored iteration matrix `J = ∂F/∂y + c_j ∂F/∂y'`).
//!
//! The sensitivity residual is the user's
//!
//! ```text
//!   F_y(t, y, y') s_i + F_y'(t, y, y') s_i' + ∂F/∂p_i(t, y, y') = 0,   i = 1 … N_s
//! ```
//!
//! (`IDASetSensResFn` through `IDASensInit`), and the sensitivities take part in IDAS's local
//! error test (`IDASetSensErrCon`), so the steps control their error as the state's.

use super::{Ida, IdaData, P};
use crate::sundials::error::{check, CallbackResult, SolverError};
use crate::sundials::vector::{slice_of, slice_of_mut};
use std::os::raw::{c_int, c_long, c_void};
use sundials_sys as sys;

/// The sensitivity residual `(t, y, y', s, s', r)`: for every parameter `i`, write
/// `r[i] = F_y s[i] + F_y' s'[i] + ∂F/∂p_i` (all slices of length `n`).
pub type SensResidualFn = Box<
    dyn FnMut(f64, &[f64], &[f64], &[&[f64]], &[&[f64]], &mut [&mut [f64]]) -> CallbackResult
        + Send,
>;

/// The sensitivity closure and its vector count, inside [`IdaData`].
pub(crate) struct SensData {
    ns: usize,
    residual: SensResidualFn,
}

/// An owned array of `N_s` serial vectors (`N_VCloneVectorArray`), destroyed on drop.
pub(crate) struct VectorArray {
    raw: *mut sys::N_Vector,
    count: usize,
    len: usize,
}

impl VectorArray {
    /// `count` clones of `template`'s layout holding `values[k]` (each of the template's length).
    fn new(template: sys::N_Vector, len: usize, values: &[Vec<f64>]) -> Result<Self, SolverError> {
        // SAFETY: template is a live serial vector; NULL is checked below.
        let raw = unsafe { sys::N_VCloneVectorArray(values.len() as c_int, template) };
        if raw.is_null() {
            return Err(SolverError::InvalidInput(
                "N_VCloneVectorArray failed".into(),
            ));
        }
        let mut a = VectorArray {
            raw,
            count: values.len(),
            len,
        };
        for (k, v) in values.iter().enumerate() {
            a.slice_mut(k).copy_from_slice(v);
        }
        Ok(a)
    }

    fn slice(&self, k: usize) -> &[f64] {
        // SAFETY: k < count; each entry is a live serial vector of length `len` owned by self.
        unsafe { slice_of(*self.raw.add(k), self.len) }
    }

    fn slice_mut(&mut self, k: usize) -> &mut [f64] {
        // SAFETY: as in `slice`, and `&mut self` gives exclusive access.
        unsafe { slice_of_mut(*self.raw.add(k), self.len) }
    }
}

impl Drop for VectorArray {
    fn drop(&mut self) {
        // SAFETY: raw came from N_VCloneVectorArray with `count` vectors, destroyed once.
        unsafe { sys::N_VDestroyVectorArray(self.raw, self.count as c_int) }
    }
}

/// Sensitivity state of an [`Ida`]: the vectors IDAS reads its start from and writes
/// [`Ida::sensitivities`] into.
pub(crate) struct SensVectors {
    s: VectorArray,
    #[allow(dead_code)] // owned: IDAS copied it at IDASensInit
    sp: VectorArray,
}

#[allow(clippy::too_many_arguments)]
unsafe extern "C" fn sens_trampoline(
    ns: c_int,
    t: f64,
    yy: sys::N_Vector,
    yp: sys::N_Vector,
    _rr: sys::N_Vector,
    ys: *mut sys::N_Vector,
    yps: *mut sys::N_Vector,
    rs: *mut sys::N_Vector,
    user_data: *mut c_void,
    _t1: sys::N_Vector,
    _t2: sys::N_Vector,
    _t3: sys::N_Vector,
) -> c_int {
    // SAFETY: user_data is the Box<IdaData> registered with IDASetUserData, alive as long as
    // the IDA memory; yy, yp and the `ns` vectors of ys, yps, rs are distinct serial vectors
    // of length n owned by IDAS for the duration of the call.
    let (data, y, yp, s, sp, mut r) = unsafe {
        let data = &mut *(user_data as *mut IdaData);
        let n = data.n;
        let ns = ns.max(0) as usize;
        let s: Vec<&[f64]> = (0..ns).map(|k| slice_of(*ys.add(k), n)).collect();
        let sp: Vec<&[f64]> = (0..ns).map(|k| slice_of(*yps.add(k), n)).collect();
        let r: Vec<&mut [f64]> = (0..ns).map(|k| slice_of_mut(*rs.add(k), n)).collect();
        (data, slice_of(yy, n), slice_of(yp, n), s, sp, r)
    };
    let IdaData { status, sens, .. } = data;
    let Some(sens) = sens.as_mut() else {
        return -1;
    };
    if s.len() != sens.ns {
        return -1;
    }
    let code = status.guard(t, || (sens.residual)(t, y, yp, &s, &sp, &mut r));
    let finite = r.iter().all(|v| v.iter().all(|x| x.is_finite()));
    match code {
        0 if !finite => 1,
        c => c,
    }
}

/// Sensitivity counters of an IDAS run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SensStats {
    /// Sensitivity residual evaluations.
    pub residual_evals: u64,
    /// Error test failures caused by the sensitivities.
    pub error_test_fails: u64,
    /// Sensitivity nonlinear (linear-in-s) iterations.
    pub nonlinear_iters: u64,
}

impl Ida {
    /// Turns on forward sensitivities for `s0.len()` parameters from the start `(s0, sp0)`
    /// (each of length `n`, consistent with the sensitivity residual at the current time),
    /// with the residual `residual` ([`SensResidualFn`]), the staggered corrector, the
    /// tolerances `rtol` and `atol[i]` (per parameter, one value per unknown), and the
    /// sensitivities in the error test. Call before the first step.
    pub fn enable_sensitivities(
        &mut self,
        s0: &[Vec<f64>],
        sp0: &[Vec<f64>],
        residual: SensResidualFn,
        rtol: f64,
        atol: &[Vec<f64>],
    ) -> Result<(), SolverError> {
        let n = self.data.n;
        let ns = s0.len();
        if ns == 0
            || sp0.len() != ns
            || atol.len() != ns
            || s0.iter().chain(sp0).chain(atol).any(|v| v.len() != n)
        {
            return Err(SolverError::InvalidInput(format!(
                "sensitivities need {ns} start vectors, rates and tolerances of length {n}"
            )));
        }
        if atol.iter().flatten().any(|a| !(a.is_finite() && *a > 0.0))
            || rtol.is_nan()
            || rtol <= 0.0
        {
            return Err(SolverError::InvalidInput(
                "sensitivity tolerances must be positive and finite".into(),
            ));
        }
        let t = self.t();
        let s = VectorArray::new(self.y.raw(), n, s0)?;
        let sp = VectorArray::new(self.y.raw(), n, sp0)?;
        let tol = VectorArray::new(self.y.raw(), n, atol)?;
        self.data.sens = Some(SensData { ns, residual });
        let raw = self.raw();
        // SAFETY: live IDA memory; the arrays hold `ns` live vectors of length n (IDAS copies
        // the start and the tolerances); the trampoline reads the closure from the boxed
        // IdaData registered as user data, which outlives the IDA memory.
        unsafe {
            check(
                P,
                "IDASensInit",
                sys::IDASensInit(
                    raw,
                    ns as c_int,
                    sys::IDA_STAGGERED as c_int,
                    Some(sens_trampoline),
                    s.raw,
                    sp.raw,
                ),
                t,
            )?;
            check(
                P,
                "IDASensSVtolerances",
                sys::IDASensSVtolerances(raw, rtol, tol.raw),
                t,
            )?;
            check(P, "IDASetSensErrCon", sys::IDASetSensErrCon(raw, 1), t)?;
        }
        self.sens = Some(SensVectors { s, sp });
        Ok(())
    }

    /// The sensitivities `s_i(t)` at `t` within the last step (after [`Ida::solve_to`]: its
    /// time), one vector of length `n` per parameter.
    pub fn sensitivities(&mut self, t: f64) -> Result<Vec<Vec<f64>>, SolverError> {
        let raw = self.raw();
        let Some(v) = self.sens.as_mut() else {
            return Err(SolverError::InvalidInput(
                "sensitivities were not enabled".into(),
            ));
        };
        // SAFETY: live IDA memory with sensitivities; `s` holds `ns` live vectors of length n.
        let flag = unsafe { sys::IDAGetSensDky(raw, t, 0, v.s.raw) };
        if flag < 0 {
            return Err(self.fail("IDAGetSensDky", flag));
        }
        let v = self.sens.as_ref().expect("checked above");
        Ok((0..v.s.count).map(|k| v.s.slice(k).to_vec()).collect())
    }

    /// Sensitivity counters (zero without sensitivities).
    pub fn sens_stats(&self) -> SensStats {
        if self.sens.is_none() {
            return SensStats::default();
        }
        let (mut re, mut etf, mut nni): (c_long, c_long, c_long) = (0, 0, 0);
        // SAFETY: live IDA memory with sensitivities and valid out-pointers.
        unsafe {
            sys::IDAGetSensNumResEvals(self.raw(), &mut re);
            sys::IDAGetSensNumErrTestFails(self.raw(), &mut etf);
            sys::IDAGetSensNumNonlinSolvIters(self.raw(), &mut nni);
        }
        SensStats {
            residual_evals: re.max(0) as u64,
            error_test_fails: etf.max(0) as u64,
            nonlinear_iters: nni.max(0) as u64,
        }
    }
}
