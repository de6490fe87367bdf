//! The serial `N_Vector` operations the integrators call at every step, compiled with the
//! crate instead of taken from the system library.
//!
//! Debian's SUNDIALS 6.4 packages are built without optimisation: the serial vector kernels
//! spill every loop variable to the stack and cost about 20 instructions per element
//! (measured with callgrind: `N_VLinearSum_Serial` and its loops took 18 % of an index-1
//! double-pendulum solve on IDA, `SUNDlsMat_denseGETRS` 34 %). These kernels compute the same
//! expressions in the same order as `nvector_serial.c` (`z_i = a x_i + b y_i`,
//! `‖x‖_WRMS = sqrt(Σ (x_i w_i)² / n)`, …) and are installed into the ops table of every vector
//! `NVector` (`super::vector`) creates; SUNDIALS copies the table into each clone, so IDA's,
//! CVODE's and ARKODE's work vectors all use them.
//!
//! One kernel departs from `nvector_serial.c` on purpose: the masked WRMS norm of IDA's error test
//! averages over the components it measures (`wrms_norm_mask`).
//!
//! Every kernel reads the elements of its inputs at index `i` before writing element `i` of its
//! output, so an output that aliases an input (SUNDIALS calls `N_VLinearSum(a, x, b, y, x)`)
//! gives what the C loop gives.

use std::os::raw::c_int;
use sundials_sys as sys;

/// Length and data pointer of a serial vector.
///
/// # Safety
/// `v` must be a live serial `N_Vector` (content `_N_VectorContent_Serial`).
#[inline(always)]
unsafe fn parts(v: sys::N_Vector) -> (usize, *mut f64) {
    // SAFETY: guaranteed by the caller: the content of a serial vector is this struct.
    unsafe {
        let c = (*v).content as *const sys::_N_VectorContent_Serial;
        ((*c).length as usize, (*c).data)
    }
}

/// The `i`-th vector of a SUNDIALS vector array.
///
/// # Safety
/// `a` must point to at least `i + 1` live serial vectors.
#[inline(always)]
unsafe fn nth(a: *mut sys::N_Vector, i: usize) -> sys::N_Vector {
    // SAFETY: guaranteed by the caller.
    unsafe { *a.add(i) }
}

unsafe extern "C" fn linear_sum(
    a: f64,
    x: sys::N_Vector,
    b: f64,
    y: sys::N_Vector,
    z: sys::N_Vector,
) {
    // SAFETY: SUNDIALS passes live serial vectors of one length; each element is read before
    // the same element of z is written (aliasing as in the C loop).
    unsafe {
        let (n, xd) = parts(x);
        let (_, yd) = parts(y);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = a * *xd.add(i) + b * *yd.add(i);
        }
    }
}

unsafe extern "C" fn constant(c: f64, z: sys::N_Vector) {
    // SAFETY: a live serial vector.
    unsafe {
        let (n, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = c;
        }
    }
}

unsafe extern "C" fn prod(x: sys::N_Vector, y: sys::N_Vector, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, yd) = parts(y);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = *xd.add(i) * *yd.add(i);
        }
    }
}

unsafe extern "C" fn div(x: sys::N_Vector, y: sys::N_Vector, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, yd) = parts(y);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = *xd.add(i) / *yd.add(i);
        }
    }
}

unsafe extern "C" fn scale(c: f64, x: sys::N_Vector, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = c * *xd.add(i);
        }
    }
}

unsafe extern "C" fn abs(x: sys::N_Vector, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = (*xd.add(i)).abs();
        }
    }
}

unsafe extern "C" fn inv(x: sys::N_Vector, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = 1.0 / *xd.add(i);
        }
    }
}

unsafe extern "C" fn add_const(x: sys::N_Vector, b: f64, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = *xd.add(i) + b;
        }
    }
}

unsafe extern "C" fn dot_prod(x: sys::N_Vector, y: sys::N_Vector) -> f64 {
    // SAFETY: live serial vectors of one length, only read.
    unsafe {
        let (n, xd) = parts(x);
        let (_, yd) = parts(y);
        let mut s = 0.0;
        for i in 0..n {
            s += *xd.add(i) * *yd.add(i);
        }
        s
    }
}

unsafe extern "C" fn max_norm(x: sys::N_Vector) -> f64 {
    // SAFETY: a live serial vector, only read.
    unsafe {
        let (n, xd) = parts(x);
        let mut m = 0.0f64;
        for i in 0..n {
            let a = (*xd.add(i)).abs();
            if a > m {
                m = a;
            }
        }
        m
    }
}

/// `Σ (x_i w_i)²` over the elements with `id_i > 0` (all when `id` is `None`).
///
/// # Safety
/// Live serial vectors of one length.
#[inline(always)]
unsafe fn wsqr_sum(x: sys::N_Vector, w: sys::N_Vector, id: Option<sys::N_Vector>) -> f64 {
    // SAFETY: guaranteed by the caller; only reads.
    unsafe {
        let (n, xd) = parts(x);
        let (_, wd) = parts(w);
        let mut s = 0.0;
        match id {
            None => {
                for i in 0..n {
                    let p = *xd.add(i) * *wd.add(i);
                    s += p * p;
                }
            }
            Some(id) => {
                let (_, idd) = parts(id);
                for i in 0..n {
                    if *idd.add(i) > 0.0 {
                        let p = *xd.add(i) * *wd.add(i);
                        s += p * p;
                    }
                }
            }
        }
        s
    }
}

unsafe extern "C" fn wrms_norm(x: sys::N_Vector, w: sys::N_Vector) -> f64 {
    // SAFETY: live serial vectors of one length.
    unsafe {
        let n = parts(x).0 as f64;
        (wsqr_sum(x, w, None) / n).sqrt()
    }
}

/// The masked WRMS norm IDA's local error test takes with suppressed algebraic unknowns:
/// `sqrt(Σ_{id_i > 0} (x_i w_i)² / #{i : id_i > 0})`, the RMS over the components the test
/// measures.
///
/// `nvector_serial.c` (SUNDIALS 6.4) divides by the full length `n` instead, so a formulation
/// with `n_a` suppressed algebraic unknowns got an error test `sqrt(n / (n − n_a))` times looser
/// than its `rtol` says (√5 on the index-1 point-mass pendulum: 2 differential unknowns of 10;
/// √(19/7) on the index-1 heavy top), and the formulations' accuracies at one `rtol` differed by
/// their count of algebraic unknowns rather than by their method. Measured (rtol 1e-9, 2000 s
/// A01 pendulum, `dae`): 2.1e-2 m → 9.5e-3 m off the exact solution, 345k → 381k steps.
/// IDA takes it (with `IDASetSuppressAlg`) for the norms of its local error test.
unsafe extern "C" fn wrms_norm_mask(x: sys::N_Vector, w: sys::N_Vector, id: sys::N_Vector) -> f64 {
    // SAFETY: live serial vectors of one length.
    unsafe {
        let (n, idd) = parts(id);
        let tested = (0..n).filter(|&i| *idd.add(i) > 0.0).count().max(1) as f64;
        (wsqr_sum(x, w, Some(id)) / tested).sqrt()
    }
}

unsafe extern "C" fn wsqr_sum_local(x: sys::N_Vector, w: sys::N_Vector) -> f64 {
    // SAFETY: live serial vectors of one length.
    unsafe { wsqr_sum(x, w, None) }
}

unsafe extern "C" fn wsqr_sum_mask_local(
    x: sys::N_Vector,
    w: sys::N_Vector,
    id: sys::N_Vector,
) -> f64 {
    // SAFETY: live serial vectors of one length.
    unsafe { wsqr_sum(x, w, Some(id)) }
}

unsafe extern "C" fn min(x: sys::N_Vector) -> f64 {
    // SAFETY: a live serial vector of positive length, only read.
    unsafe {
        let (n, xd) = parts(x);
        let mut m = *xd;
        for i in 1..n {
            let v = *xd.add(i);
            if v < m {
                m = v;
            }
        }
        m
    }
}

unsafe extern "C" fn compare(c: f64, x: sys::N_Vector, z: sys::N_Vector) {
    // SAFETY: as in linear_sum.
    unsafe {
        let (n, xd) = parts(x);
        let (_, zd) = parts(z);
        for i in 0..n {
            *zd.add(i) = if (*xd.add(i)).abs() >= c { 1.0 } else { 0.0 };
        }
    }
}

unsafe extern "C" fn linear_combination(
    nvec: c_int,
    c: *mut f64,
    xs: *mut sys::N_Vector,
    z: sys::N_Vector,
) -> c_int {
    if nvec < 1 {
        return -1;
    }
    let nvec = nvec as usize;
    // the inputs' data pointers, looked up once (IDA and CVODE combine at most order + 2 ≤ 14)
    const MOST: usize = 16;
    if nvec > MOST {
        // more than any integrator here asks: z = Σ c_k X_k one input at a time
        // SAFETY: as below; z_i is written only after every input's element i was read.
        unsafe {
            let (n, zd) = parts(z);
            for i in 0..n {
                let mut s = 0.0;
                for k in 0..nvec {
                    s += *c.add(k) * *parts(nth(xs, k)).1.add(i);
                }
                *zd.add(i) = s;
            }
        }
        return 0;
    }
    let mut data = [std::ptr::null_mut::<f64>(); MOST];
    // SAFETY: SUNDIALS passes nvec coefficients and nvec live serial vectors of z's length;
    // z may be one of them: every element i of every input is read before z_i is written.
    unsafe {
        for (k, d) in data.iter_mut().enumerate().take(nvec) {
            *d = parts(nth(xs, k)).1;
        }
        let (n, zd) = parts(z);
        for i in 0..n {
            let mut s = *c * *data[0].add(i);
            for (k, d) in data.iter().enumerate().take(nvec).skip(1) {
                s += *c.add(k) * *d.add(i);
            }
            *zd.add(i) = s;
        }
    }
    0
}

unsafe extern "C" fn scale_add_multi(
    nvec: c_int,
    a: *mut f64,
    x: sys::N_Vector,
    ys: *mut sys::N_Vector,
    zs: *mut sys::N_Vector,
) -> c_int {
    if nvec < 1 {
        return -1;
    }
    // SAFETY: nvec coefficients and vectors of x's length; Z_k may alias Y_k (element-wise).
    unsafe {
        let (n, xd) = parts(x);
        for k in 0..nvec as usize {
            let ak = *a.add(k);
            let (_, yd) = parts(nth(ys, k));
            let (_, zd) = parts(nth(zs, k));
            for i in 0..n {
                *zd.add(i) = ak * *xd.add(i) + *yd.add(i);
            }
        }
    }
    0
}

unsafe extern "C" fn linear_sum_vector_array(
    nvec: c_int,
    a: f64,
    xs: *mut sys::N_Vector,
    b: f64,
    ys: *mut sys::N_Vector,
    zs: *mut sys::N_Vector,
) -> c_int {
    if nvec < 1 {
        return -1;
    }
    for k in 0..nvec as usize {
        // SAFETY: nvec live serial vectors in each array.
        unsafe { linear_sum(a, nth(xs, k), b, nth(ys, k), nth(zs, k)) };
    }
    0
}

unsafe extern "C" fn scale_vector_array(
    nvec: c_int,
    c: *mut f64,
    xs: *mut sys::N_Vector,
    zs: *mut sys::N_Vector,
) -> c_int {
    if nvec < 1 {
        return -1;
    }
    for k in 0..nvec as usize {
        // SAFETY: nvec coefficients and live serial vectors in each array.
        unsafe { scale(*c.add(k), nth(xs, k), nth(zs, k)) };
    }
    0
}

unsafe extern "C" fn const_vector_array(nvec: c_int, c: f64, zs: *mut sys::N_Vector) -> c_int {
    if nvec < 1 {
        return -1;
    }
    for k in 0..nvec as usize {
        // SAFETY: nvec live serial vectors.
        unsafe { constant(c, nth(zs, k)) };
    }
    0
}

unsafe extern "C" fn wrms_norm_vector_array(
    nvec: c_int,
    xs: *mut sys::N_Vector,
    ws: *mut sys::N_Vector,
    nrm: *mut f64,
) -> c_int {
    if nvec < 1 {
        return -1;
    }
    for k in 0..nvec as usize {
        // SAFETY: nvec live serial vectors in each array and nvec outputs.
        unsafe { *nrm.add(k) = wrms_norm(nth(xs, k), nth(ws, k)) };
    }
    0
}

unsafe extern "C" fn wrms_norm_mask_vector_array(
    nvec: c_int,
    xs: *mut sys::N_Vector,
    ws: *mut sys::N_Vector,
    id: sys::N_Vector,
    nrm: *mut f64,
) -> c_int {
    if nvec < 1 {
        return -1;
    }
    for k in 0..nvec as usize {
        // SAFETY: nvec live serial vectors in each array and nvec outputs.
        unsafe { *nrm.add(k) = wrms_norm_mask(nth(xs, k), nth(ws, k), id) };
    }
    0
}

/// Installs the kernels above into the ops table of `v`.
///
/// # Safety
/// `v` must be a live serial `N_Vector` whose ops table it owns (as `N_VNew_Serial` makes).
pub(crate) unsafe fn install(v: sys::N_Vector) {
    // SAFETY: guaranteed by the caller; the table is plain data owned by the vector.
    unsafe {
        let ops = &mut *(*v).ops;
        ops.nvlinearsum = Some(linear_sum);
        ops.nvconst = Some(constant);
        ops.nvprod = Some(prod);
        ops.nvdiv = Some(div);
        ops.nvscale = Some(scale);
        ops.nvabs = Some(abs);
        ops.nvinv = Some(inv);
        ops.nvaddconst = Some(add_const);
        ops.nvdotprod = Some(dot_prod);
        ops.nvmaxnorm = Some(max_norm);
        ops.nvwrmsnorm = Some(wrms_norm);
        ops.nvwrmsnormmask = Some(wrms_norm_mask);
        ops.nvmin = Some(min);
        ops.nvcompare = Some(compare);
        ops.nvwsqrsumlocal = Some(wsqr_sum_local);
        ops.nvwsqrsummasklocal = Some(wsqr_sum_mask_local);
        ops.nvlinearcombination = Some(linear_combination);
        ops.nvscaleaddmulti = Some(scale_add_multi);
        ops.nvlinearsumvectorarray = Some(linear_sum_vector_array);
        ops.nvscalevectorarray = Some(scale_vector_array);
        ops.nvconstvectorarray = Some(const_vector_array);
        ops.nvwrmsnormvectorarray = Some(wrms_norm_vector_array);
        ops.nvwrmsnormmaskvectorarray = Some(wrms_norm_mask_vector_array);
    }
}

#[cfg(test)]
mod tests {
    use super::super::context::Context;
    use super::super::vector::NVector;
    use sundials_sys as sys;

    /// Through SUNDIALS' dispatch (the ops table [`super::install`] fills): the masked WRMS norm
    /// is the RMS over the components with `id > 0` only, computed by hand here.
    #[test]
    fn masked_wrms_norm_averages_over_the_tested_components() {
        let ctx = Context::new().unwrap();
        let x = NVector::from_slice(&ctx, &[3.0, 100.0, -4.0, 7.0, 1e6]).unwrap();
        let w = NVector::from_slice(&ctx, &[2.0, 5.0, 0.5, 1.0, 3.0]).unwrap();
        let id = NVector::from_slice(&ctx, &[1.0, 0.0, 1.0, 1.0, 0.0]).unwrap();
        // SAFETY: three live serial vectors of one length.
        let masked = unsafe { sys::N_VWrmsNormMask(x.raw(), w.raw(), id.raw()) };
        let by_hand = ((6.0f64.powi(2) + 2.0f64.powi(2) + 7.0f64.powi(2)) / 3.0).sqrt();
        assert!(
            (masked - by_hand).abs() < 1e-14 * by_hand,
            "{masked} vs {by_hand}"
        );
        // SAFETY: as above.
        let full = unsafe { sys::N_VWrmsNorm(x.raw(), w.raw()) };
        let all = ((36.0 + 500.0f64.powi(2) + 4.0 + 49.0 + 3e6f64.powi(2)) / 5.0).sqrt();
        assert!((full - all).abs() < 1e-14 * all, "{full} vs {all}");
    }
}
