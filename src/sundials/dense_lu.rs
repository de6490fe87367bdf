//! The dense direct linear solver of IDA's and CVODE's Newton iterations: LU with partial
//! pivoting, `P A = L U`, of the dense `SUNMatrix` the integrator attaches, compiled with the
//! crate.
//!
//! It replaces `SUNLinSol_Dense`, whose `SUNDlsMat_denseGETRF`/`denseGETRS` in Debian's
//! unoptimised SUNDIALS 6.4 build cost about 11 000 instructions per 20 × 20 solve (measured
//! with callgrind: a third of an index-1 double-pendulum solve on IDA). The algorithm is the
//! same (column-oriented elimination, the largest pivot of each column, the factors stored in
//! place of `A`, which the integrators rebuild before every setup), so the step sequences are
//! those of the SUNDIALS solver up to rounding.

use std::os::raw::c_int;
use std::ptr;

use super::context::Context;
use super::error::SolverError;
use super::linsol::{self, LinearSolver, Matrix, OwnLinearSolver};
use sundials_sys as sys;

/// The factorisation's state: the pivot rows, the size, and whether `A` holds valid factors.
struct DenseLu {
    n: usize,
    pivots: Vec<usize>,
    /// The factored matrix (borrowed from the integrator between setup and solve).
    factors: *mut f64,
    factored: bool,
}

/// Factors the column-major `n × n` matrix `a` in place (`P A = L U`, unit `L` below the
/// diagonal, `U` on and above it), writing the pivot row of each column to `pivots`.
/// Returns the 1-based column of a zero (or non-finite) pivot, or 0.
///
/// ```text
///   for k: p = argmax_{i ≥ k} |a_ik|; swap rows k, p; l_ik = a_ik / a_kk;
///          a_ij −= l_ik a_kj (i, j > k)
/// ```
pub fn factor(a: &mut [f64], n: usize, pivots: &mut [usize]) -> usize {
    for k in 0..n {
        let col = k * n;
        let mut p = k;
        let mut big = a[col + k].abs();
        for i in k + 1..n {
            let v = a[col + i].abs();
            if v > big {
                big = v;
                p = i;
            }
        }
        pivots[k] = p;
        let pivot = a[col + p];
        if pivot == 0.0 || !pivot.is_finite() {
            return k + 1;
        }
        if p != k {
            for j in 0..n {
                a.swap(j * n + k, j * n + p);
            }
        }
        let inv = 1.0 / a[col + k];
        for i in k + 1..n {
            a[col + i] *= inv;
        }
        for j in k + 1..n {
            let akj = a[j * n + k];
            if akj != 0.0 {
                let (left, right) = a.split_at_mut(j * n);
                let lk = &left[col + k + 1..col + n];
                let aj = &mut right[k + 1..n];
                for (x, l) in aj.iter_mut().zip(lk) {
                    *x -= l * akj;
                }
            }
        }
    }
    0
}

/// Solves `A x = b` in place with the factors of [`factor`].
pub fn solve(a: &[f64], n: usize, pivots: &[usize], b: &mut [f64]) {
    for (k, &p) in pivots.iter().enumerate().take(n) {
        if p != k {
            b.swap(k, p);
        }
    }
    for k in 0..n {
        let bk = b[k];
        if bk != 0.0 {
            let lk = &a[k * n + k + 1..k * n + n];
            for (x, l) in b[k + 1..].iter_mut().zip(lk) {
                *x -= l * bk;
            }
        }
    }
    for k in (0..n).rev() {
        b[k] /= a[k * n + k];
        let bk = b[k];
        if bk != 0.0 {
            let uk = &a[k * n..k * n + k];
            for (x, u) in b[..k].iter_mut().zip(uk) {
                *x -= u * bk;
            }
        }
    }
}

impl OwnLinearSolver for DenseLu {
    const KIND: sys::SUNLinearSolver_Type = sys::SUNLinearSolver_Type_SUNLINEARSOLVER_DIRECT;

    fn reset(&mut self) {
        self.factored = false;
    }

    /// Factors the dense matrix in place (the integrator rebuilds it before every setup and
    /// does not touch it until the next one; SUNDIALS' own dense solver factors it in place
    /// too).
    fn setup(&mut self, a: Option<Matrix<'_>>) -> c_int {
        let Some(Matrix::Dense { n, data }) = a else {
            return -1;
        };
        self.n = n;
        self.pivots.resize(n, 0);
        self.factors = data.as_mut_ptr();
        self.factored = false;
        match factor(data, n, &mut self.pivots) {
            0 => {
                self.factored = true;
                0
            }
            // a zero pivot: recoverable (IDA and CVODE cut the step), as SUNLinSol_Dense's
            k => k as c_int,
        }
    }

    fn order(&self) -> Option<usize> {
        (self.factored && !self.factors.is_null()).then_some(self.n)
    }

    fn solve(&mut self, x: &mut [f64]) -> c_int {
        let n = self.n;
        // SAFETY: `factors` is the matrix factored by `setup`, which the integrator still owns
        // unchanged until its next setup (`order` refuses a solve without one).
        let a = unsafe { std::slice::from_raw_parts(self.factors, n * n) };
        solve(a, n, &self.pivots, x);
        linsol::finite_solution(x)
    }
}

/// A new dense LU solver (attached to an integrator with its dense matrix).
pub(crate) fn new(ctx: &Context) -> Result<LinearSolver, SolverError> {
    linsol::own(
        ctx,
        DenseLu {
            n: 0,
            pivots: Vec::new(),
            factors: ptr::null_mut(),
            factored: false,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `A x` for a column-major `a`.
    fn mul(a: &[f64], n: usize, x: &[f64]) -> Vec<f64> {
        (0..n)
            .map(|i| (0..n).map(|j| a[j * n + i] * x[j]).sum())
            .collect()
    }

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        // a zero in the first pivot position: only row exchanges make it solvable
        let n = 3;
        let a = vec![0.0, 2.0, 1.0, 1.0, 1.0, 3.0, 4.0, -1.0, 2.0];
        let x = [1.0, -2.0, 0.5];
        let mut b = mul(&a, n, &x);
        let mut f = a.clone();
        let mut p = vec![0; n];
        assert_eq!(factor(&mut f, n, &mut p), 0);
        solve(&f, n, &p, &mut b);
        for (u, v) in b.iter().zip(x) {
            assert!((u - v).abs() < 1e-14, "{b:?}");
        }
    }

    #[test]
    fn reports_the_column_of_a_zero_pivot() {
        // the second column is twice the first: singular at column 2
        let a = vec![1.0, 2.0, 2.0, 4.0];
        let mut p = vec![0; 2];
        assert_eq!(factor(&mut a.clone(), 2, &mut p), 2);
    }

    #[test]
    fn a_nan_pivot_is_a_failed_factorisation() {
        let a = vec![f64::NAN, 1.0, 2.0, 3.0];
        let mut p = vec![0; 2];
        assert_eq!(factor(&mut a.clone(), 2, &mut p), 1);
    }

    #[test]
    fn agrees_with_nalgebra_on_random_systems() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for n in [1, 2, 3, 7, 20, 34] {
            let a: Vec<f64> = (0..n * n).map(|_| next()).collect();
            let b: Vec<f64> = (0..n).map(|_| next()).collect();
            let reference = nalgebra::DMatrix::from_column_slice(n, n, &a)
                .lu()
                .solve(&nalgebra::DVector::from_column_slice(&b))
                .expect("regular");
            let mut f = a.clone();
            let mut p = vec![0; n];
            assert_eq!(factor(&mut f, n, &mut p), 0);
            let mut x = b.clone();
            solve(&f, n, &p, &mut x);
            for (u, v) in x.iter().zip(reference.iter()) {
                assert!((u - v).abs() < 1e-9 * (1.0 + v.abs()), "n = {n}");
            }
        }
    }
}
