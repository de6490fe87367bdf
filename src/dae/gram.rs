//! Sparse weighted Gram matrices `A = G W Gᵀ` of a constraint Jacobian `G` (`m × n`, few
//! entries per row) and a positive diagonal `W`, factored `A = L Lᵀ` by faer's sparse
//! Cholesky: the consistent start of large mechanisms solves with them instead of a dense SVD
//! (see [`super::init`]), in time and memory linear in the size of a chain-like mechanism.
//!
//! For a joint Jacobian `G_v`, `G_v G_vᵀ` is the matrix of the least-change velocity projection
//! `Δv = G_vᵀ (G_v G_vᵀ)⁻¹ G_v v` and `G_v M⁻¹ G_vᵀ` the one of the multipliers
//! `λ = (G_v M⁻¹ G_vᵀ)⁻¹ (G_v M⁻¹ Q + γ)`; both are SPD exactly when `G_v` has full row rank.

use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Side};
use nalgebra::DMatrix;

use crate::thresholds::ROUGH_STEPS;

/// `A = G W Gᵀ` in sparse form with its Cholesky factor.
pub struct SparseGram {
    m: usize,
    /// Lower triangle and diagonal of `A` as `(row, col, value)`, for products.
    entries: Vec<(usize, usize, f64)>,
    /// `A`'s lower triangle in compressed columns.
    a: SparseColMat<usize, f64>,
    symbolic: SymbolicLlt<usize>,
    llt: Llt<usize, f64>,
}

impl SparseGram {
    /// `A = G diag(w) Gᵀ` from the dense `g` (its zero entries are skipped), factored; `None`
    /// when `A` is not numerically positive definite (rank-deficient `G`) or the factorisation
    /// fails.
    pub fn new(g: &DMatrix<f64>, w: &[f64]) -> Option<SparseGram> {
        let (m, n) = g.shape();
        let mut entries = Vec::new();
        for j in 0..n {
            for i in 0..m {
                let v = g[(i, j)];
                if v != 0.0 {
                    entries.push((i, j, v));
                }
            }
        }
        Self::from_entries(m, n, &entries, w)
    }

    /// As [`SparseGram::new`], from the entries `(row, column, value)` of the `m × n` matrix
    /// `G` (each position at most once; zero values are skipped): linear in their number.
    pub fn from_entries(
        m: usize,
        n: usize,
        g: &[(usize, usize, f64)],
        w: &[f64],
    ) -> Option<SparseGram> {
        debug_assert_eq!(w.len(), n);
        // rows with an entry in each column of G
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &(i, j, v) in g {
            if v != 0.0 {
                cols[j].push((i, v));
            }
        }
        // A_ik = Σ_j G_ij w_j G_kj, lower triangle (i ≥ k), summed in a sorted list
        let mut pairs: Vec<((usize, usize), f64)> = Vec::new();
        for (j, col) in cols.iter().enumerate() {
            for &(i, a) in col {
                for &(k, b) in col {
                    if i >= k {
                        pairs.push(((k, i), a * w[j] * b));
                    }
                }
            }
        }
        pairs.sort_unstable_by_key(|p| p.0);
        let mut entries: Vec<(usize, usize, f64)> = Vec::with_capacity(pairs.len());
        for ((k, i), v) in pairs {
            match entries.last_mut() {
                Some(e) if (e.1, e.0) == (k, i) => e.2 += v,
                _ => entries.push((i, k, v)),
            }
        }
        let mut diagonal = vec![false; m];
        for e in entries.iter().filter(|e| e.0 == e.1) {
            diagonal[e.0] = true;
        }
        if diagonal.contains(&false) {
            return None; // an empty row of G
        }
        let triplets: Vec<Triplet<usize, usize, f64>> = entries
            .iter()
            .map(|&(i, k, v)| Triplet::new(i, k, v))
            .collect();
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &triplets).ok()?;
        let symbolic = SymbolicLlt::try_new(a.symbolic(), Side::Lower).ok()?;
        let llt = Llt::try_new_with_symbolic(symbolic.clone(), a.as_ref(), Side::Lower).ok()?;
        Some(SparseGram {
            m,
            entries,
            a,
            symbolic,
            llt,
        })
    }

    /// Dimension `m`.
    pub fn dim(&self) -> usize {
        self.m
    }

    /// `x ← A⁻¹ x`.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = x.len();
        self.llt
            .solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, n, 1));
    }

    /// `A x`.
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.m];
        self.apply_into(x, &mut y);
        y
    }

    /// `(λ_min, λ_max)` of `A` to the relative accuracy `rel_tol`, each from the largest
    /// eigenvalue of an operator by [`lanczos_largest`] (at most `max_iterations` steps each):
    ///
    /// * `1 / λ_min` of `A⁻¹` (solves with the Cholesky factor): the small eigenvalues of a
    ///   Gram matrix near a rank loss are well separated, a few steps suffice;
    /// * `λ_max` of `A` roughly ([`ROUGH_STEPS`] steps at most), which gives a shift `σ > λ_max`
    ///   (`σ = θ (1 + δ)`, δ = 1e-3, 1e-2, … until `σ I − A` has a Cholesky factor, which proves
    ///   it positive definite), then `1 / (σ − λ_max)` of `(σ I − A)⁻¹`: the top of a chain's
    ///   spectrum is clustered (plain Lanczos on `A` took 125 steps for 1e-10 on the 242 rows of
    ///   the 40-four-bar chain), the shift-and-invert separates it.
    ///
    /// `None` when an iteration does not converge or no shift up to `σ = 2 θ` is found.
    pub fn extreme_eigenvalues(&self, rel_tol: f64, max_iterations: usize) -> Option<(f64, f64)> {
        let lmin = self.smallest_eigenvalue(rel_tol, max_iterations)?;
        let v0 = start_vector(self.m);
        let rough = lanczos_largest(|x, y| self.apply_into(x, y), &v0, 1e-3, ROUGH_STEPS);
        let theta = rough.theta;
        if !(theta > 0.0 && theta.is_finite()) {
            return None;
        }
        let mut delta = 1e-3;
        let shifted = loop {
            if delta > 1.0 {
                return None;
            }
            if let Some(llt) = self.shifted_factor(theta * (1.0 + delta)) {
                break llt;
            }
            delta *= 10.0;
        };
        let sigma = theta * (1.0 + delta);
        let top = lanczos_largest(
            |x, y| {
                y.copy_from_slice(x);
                let n = y.len();
                shifted.solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(y, n, 1),
                );
            },
            &v0,
            rel_tol,
            max_iterations,
        );
        if !top.converged || top.theta <= 0.0 {
            return None;
        }
        Some((lmin, sigma - 1.0 / top.theta))
    }

    /// `λ_min` of `A` to the relative accuracy `rel_tol`: `1 / λ_min` is the largest
    /// eigenvalue of `A⁻¹` ([`lanczos_largest`] with solves by the Cholesky factor, at most
    /// `max_iterations` steps). `None` when the iteration does not converge.
    pub fn smallest_eigenvalue(&self, rel_tol: f64, max_iterations: usize) -> Option<f64> {
        self.smallest_eigenpair(rel_tol, max_iterations)
            .map(|(l, _)| l)
    }

    /// [`Self::smallest_eigenvalue`] and its eigenvector (the Ritz vector, unit).
    pub fn smallest_eigenpair(
        &self,
        rel_tol: f64,
        max_iterations: usize,
    ) -> Option<(f64, Vec<f64>)> {
        let v0 = start_vector(self.m);
        let (inv_lmin, u) = lanczos_largest_vector(
            |x, y| {
                y.copy_from_slice(x);
                self.solve_in_place(y);
            },
            &v0,
            rel_tol,
            max_iterations,
        );
        inv_lmin.converged.then(|| (1.0 / inv_lmin.theta, u))
    }

    /// The Cholesky factor of `σ I − A` (same pattern as `A`), `None` when it is not
    /// numerically positive definite (`σ ≤ λ_max`).
    fn shifted_factor(&self, sigma: f64) -> Option<Llt<usize, f64>> {
        let mut b = self.a.clone();
        let col_ptr: Vec<usize> = b.symbolic().col_ptr().to_vec();
        let row_idx: Vec<usize> = b.symbolic().row_idx().to_vec();
        let val = b.val_mut();
        for j in 0..self.m {
            for p in col_ptr[j]..col_ptr[j + 1] {
                val[p] = if row_idx[p] == j {
                    sigma - val[p]
                } else {
                    -val[p]
                };
            }
        }
        Llt::try_new_with_symbolic(self.symbolic.clone(), b.as_ref(), Side::Lower).ok()
    }

    /// `y ← A x`.
    fn apply_into(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for &(i, k, v) in &self.entries {
            y[i] += v * x[k];
            if i != k {
                y[k] += v * x[i];
            }
        }
    }

    /// An estimate of `κ(A) = λ_max / λ_min` from `iterations` steps each of the power method
    /// (on `A`) and inverse iteration (on `A⁻¹`), both from the all-ones vector; the Rayleigh
    /// quotients bound `λ_max` from below and `λ_min` from above, so the estimate never exceeds
    /// `κ(A)`, and it converges fastest exactly when `λ_min` is well separated (near a rank loss).
    pub fn condition_estimate(&self, iterations: usize) -> f64 {
        let unit = |v: &mut Vec<f64>| {
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 0.0 {
                v.iter_mut().for_each(|x| *x /= n);
            }
        };
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let mut v = vec![1.0; self.m];
        unit(&mut v);
        let mut lmax = 0.0;
        for _ in 0..iterations {
            let mut w = self.apply(&v);
            lmax = dot(&v, &w);
            unit(&mut w);
            v = w;
        }
        let mut v = vec![1.0; self.m];
        unit(&mut v);
        let mut inv_lmin = 0.0;
        for _ in 0..iterations {
            let mut w = v.clone();
            self.solve_in_place(&mut w);
            inv_lmin = dot(&v, &w);
            unit(&mut w);
            v = w;
        }
        if inv_lmin > 0.0 {
            lmax * inv_lmin
        } else {
            f64::INFINITY
        }
    }
}

/// A fixed start vector with no special structure (entries in `[0.5, 1.5)` from the
/// SplitMix64 sequence), so that it is not orthogonal to an extreme eigenvector of a symmetric
/// mechanism, as the all-ones vector can be; the same on every run.
pub(crate) fn start_vector(n: usize) -> Vec<f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..n)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            0.5 + (z >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The largest eigenvalue `θ` of the symmetric positive semi-definite operator `op`
/// (`op(x, y)`: `y ← Op x`, dimension `v0.len()`) by the Lanczos process from `v0` with full
/// reorthogonalisation (classical Gram–Schmidt, twice):
///
/// ```text
///   w = Op v_j − Σ_{i≤j} (v_iᵀ Op v_j) v_i,   β_j = ‖w‖,   v_{j+1} = w / β_j,
/// ```
///
/// `θ` the largest eigenvalue of the tridiagonal `T_j = V_jᵀ Op V_j`. It stops when the Ritz
/// residual `‖Op y − θ y‖ = β_j |s_j|` (`s_j` the last entry of `T_j`'s unit eigenvector)
/// is at most `rel_tol · θ` and `θ` changed by at most that since the step before — an
/// eigenvalue of `Op` then lies within `rel_tol · θ` of `θ` (Kahan–Parlett) — or when the
/// Krylov space is invariant (`β_j = 0`, or `j` = the dimension), where `θ` is exact; after
/// `max_iterations` steps it returns the last `θ`, not converged.
///
/// Written here rather than taken from faer's Krylov–Schur (`faer::matrix_free::eigen`),
/// which always builds a basis of at least 32 and restarts at 64 vectors: on the 242 joint
/// rows of the 40-four-bar chain that costs about as much as the dense eigenvalues, while
/// this loop stops after the few steps the extreme eigenvalue needs.
pub fn lanczos_largest(
    op: impl FnMut(&[f64], &mut [f64]),
    v0: &[f64],
    rel_tol: f64,
    max_iterations: usize,
) -> Lanczos {
    lanczos(op, v0, rel_tol, max_iterations, false).0
}

/// [`lanczos_largest`] and its Ritz vector `y = V_j s` (unit; `s` the unit eigenvector of
/// `T_j` for `θ`), the approximate eigenvector: empty where no `θ` was found.
pub fn lanczos_largest_vector(
    op: impl FnMut(&[f64], &mut [f64]),
    v0: &[f64],
    rel_tol: f64,
    max_iterations: usize,
) -> (Lanczos, Vec<f64>) {
    lanczos(op, v0, rel_tol, max_iterations, true)
}

fn lanczos(
    mut op: impl FnMut(&[f64], &mut [f64]),
    v0: &[f64],
    rel_tol: f64,
    max_iterations: usize,
    want_vector: bool,
) -> (Lanczos, Vec<f64>) {
    let n = v0.len();
    let mut result = Lanczos {
        theta: f64::NAN,
        residual: f64::INFINITY,
        iterations: 0,
        converged: false,
    };
    let norm0 = dot(v0, v0).sqrt();
    if n == 0 || norm0 == 0.0 || !norm0.is_finite() {
        return (result, Vec::new());
    }
    let mut v: Vec<f64> = v0.iter().map(|x| x / norm0).collect();
    let mut w = vec![0.0; n];
    let mut basis: Vec<f64> = Vec::with_capacity(n * max_iterations.min(n));
    let mut alpha: Vec<f64> = Vec::new();
    let mut beta: Vec<f64> = Vec::new();
    let mut previous = f64::NAN;
    // the Ritz vector V_j s of the last step's θ
    let ritz = |basis: &[f64], s: &[f64]| -> Vec<f64> {
        if !want_vector {
            return Vec::new();
        }
        let mut y = vec![0.0; n];
        for (col, &c) in basis.chunks_exact(n).zip(s) {
            y.iter_mut().zip(col).for_each(|(a, x)| *a += c * x);
        }
        y
    };
    let mut s_vec = Vec::new();
    for j in 0..max_iterations.min(n) {
        basis.extend_from_slice(&v);
        op(&v, &mut w);
        if !w.iter().all(|x| x.is_finite()) {
            let y = if s_vec.is_empty() {
                Vec::new()
            } else {
                ritz(&basis[..n * s_vec.len()], &s_vec)
            };
            return (result, y);
        }
        alpha.push(dot(&v, &w));
        for _ in 0..2 {
            for col in basis.chunks_exact(n) {
                let c = dot(col, &w);
                w.iter_mut().zip(col).for_each(|(y, x)| *y -= c * x);
            }
        }
        let b = dot(&w, &w).sqrt();
        let (theta, s) = tridiagonal_largest(&alpha, &beta, previous, rel_tol * 1e-3);
        let s_last = s.last().copied().unwrap_or(1.0);
        s_vec = s;
        let scale = theta.abs().max(f64::MIN_POSITIVE);
        let invariant = b <= f64::EPSILON * scale || j + 1 == n;
        result = Lanczos {
            theta,
            residual: if invariant {
                0.0
            } else {
                b * s_last.abs() / scale
            },
            iterations: j + 1,
            converged: false,
        };
        if invariant || (result.residual <= rel_tol && (theta - previous).abs() <= rel_tol * scale)
        {
            result.converged = true;
            return (result, ritz(&basis, &s_vec));
        }
        previous = theta;
        beta.push(b);
        v.iter_mut().zip(&w).for_each(|(x, y)| *x = y / b);
    }
    (result, ritz(&basis, &s_vec))
}

/// What [`lanczos_largest`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lanczos {
    /// The largest Ritz value (a lower bound of the largest eigenvalue).
    pub theta: f64,
    /// The Ritz residual relative to `θ` (0 on an invariant Krylov space).
    pub residual: f64,
    /// Lanczos steps taken.
    pub iterations: usize,
    /// Whether the residual reached the tolerance.
    pub converged: bool,
}

/// The largest eigenvalue `θ` of the symmetric tridiagonal `T` (diagonal `alpha`,
/// off-diagonal `beta`, `beta.len() + 1 = alpha.len()`) and its unit eigenvector (the
/// last unit vector where none is usable: the largest residual weight); `lower` is a lower bound of `θ` when finite (the previous step's Ritz value:
/// by Cauchy's interlacing theorem the largest eigenvalue of `T_j` is at least that of
/// `T_{j−1}`), `θ` is found to the relative accuracy `rel` (or rounding, if larger).
///
/// `θ` by bisection on the Sturm count `#{λ < x}` = the number of negative pivots of
/// `T − x I = L D Lᵀ` (`d_1 = α_1 − x`, `d_i = α_i − x − β_{i−1}² / d_{i−1}`) inside the
/// Gershgorin interval, to rounding; the eigenvector by two steps of inverse iteration with
/// `σ I − T` (`σ` just above `θ`, so it is positive definite and `L D Lᵀ` needs no pivoting).
fn tridiagonal_largest(alpha: &[f64], beta: &[f64], lower: f64, rel: f64) -> (f64, Vec<f64>) {
    let k = alpha.len();
    let off = |i: usize| if i < beta.len() { beta[i].abs() } else { 0.0 };
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for (i, &a) in alpha.iter().enumerate() {
        let r = off(i) + if i > 0 { off(i - 1) } else { 0.0 };
        lo = lo.min(a - r);
        hi = hi.max(a + r);
    }
    if lower.is_finite() && lower < hi {
        lo = lo.max(lower - f64::EPSILON * lower.abs());
    }
    let tiny = f64::MIN_POSITIVE / f64::EPSILON;
    let below = |x: f64| {
        let mut count = 0;
        let mut d = 1.0;
        for i in 0..k {
            d = alpha[i]
                - x
                - if i > 0 {
                    beta[i - 1] * beta[i - 1] / d
                } else {
                    0.0
                };
            if d == 0.0 {
                d = -tiny;
            }
            if d < 0.0 {
                count += 1;
            }
        }
        count
    };
    // λ_max ∈ (lo, hi]: below(x) = k ⇔ x > λ_max
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi || hi - lo <= rel.max(2.0 * f64::EPSILON) * hi.abs().max(lo.abs())
        {
            break;
        }
        if below(mid) == k {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let theta = 0.5 * (lo + hi);
    if k == 1 {
        return (theta, vec![1.0]);
    }
    let sigma = hi + 4.0 * f64::EPSILON * hi.abs().max(tiny);
    // σ I − T = L D Lᵀ: d_1 = σ − α_1, l_i = −β_i / d_i, d_{i+1} = σ − α_{i+1} − l_i (−β_i)
    let mut d = vec![0.0; k];
    let mut l = vec![0.0; k - 1];
    d[0] = (sigma - alpha[0]).max(tiny);
    for i in 0..k - 1 {
        l[i] = -beta[i] / d[i];
        d[i + 1] = (sigma - alpha[i + 1] + l[i] * beta[i]).max(tiny);
    }
    let mut x = vec![1.0; k];
    for _ in 0..2 {
        for i in 1..k {
            x[i] -= l[i - 1] * x[i - 1];
        }
        for i in 0..k {
            x[i] /= d[i];
        }
        for i in (0..k - 1).rev() {
            x[i] -= l[i] * x[i + 1];
        }
        let n = dot(&x, &x).sqrt();
        if n == 0.0 || !n.is_finite() {
            // no usable eigenvector: report the largest possible residual weight
            let mut e = vec![0.0; k];
            e[k - 1] = 1.0;
            return (theta, e);
        }
        x.iter_mut().for_each(|v| *v /= n);
    }
    (theta, x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `y = L x` for the path Laplacian `tridiag(−1, 2, −1)` of size `n`, whose eigenvalues are
    /// `2 − 2 cos(kπ/(n+1))`, `k = 1 … n`.
    fn laplacian(x: &[f64], y: &mut [f64]) {
        let n = x.len();
        for i in 0..n {
            y[i] = 2.0 * x[i]
                - if i > 0 { x[i - 1] } else { 0.0 }
                - if i + 1 < n { x[i + 1] } else { 0.0 };
        }
    }

    #[test]
    fn lanczos_finds_the_largest_eigenvalue_of_the_path_laplacian() {
        for n in [1usize, 2, 5, 50, 242] {
            let exact = 2.0 - 2.0 * (n as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos();
            let theta = lanczos_largest(laplacian, &start_vector(n), 1e-10, 400).theta;
            let rel = (theta - exact).abs() / exact;
            assert!(rel < 1e-10, "n {n}: {theta} against {exact}");
        }
    }
}
