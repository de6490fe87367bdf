//! Sparse weighted Gram matrices `A = G W Gᵀ` of a constraint Jacobian `G` (`m × n`, few
//! entries per row) and a positive diagonal `W`, factored `A = L Lᵀ` by faer's sparse
//! Cholesky: the consistent start of large mechanisms solves with them instead of a dense SVD
//! (see [`super::init`]), in time and memory linear in the size of a chain-like mechanism.
//!
//! For a joint Jacobian `G_v`, `G_v G_vᵀ` is the matrix of the least-change velocity projection
//! `Δv = G_vᵀ (G_v G_vᵀ)⁻¹ G_v v` and `G_v M⁻¹ G_vᵀ` the one of the multipliers
//! `λ = (G_v M⁻¹ G_vᵀ)⁻¹ (G_v M⁻¹ Q + γ)`; both are SPD exactly when `G_v` has full row rank.

use faer::linalg::solvers::SolveCore;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Side};
use nalgebra::DMatrix;

/// `A = G W Gᵀ` in sparse form with its Cholesky factor.
pub struct SparseGram {
    m: usize,
    /// Lower triangle and diagonal of `A` as `(row, col, value)`, for products.
    entries: Vec<(usize, usize, f64)>,
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
}

impl SparseGram {
    /// `A = G diag(w) Gᵀ` from the dense `g` (its zero entries are skipped), factored; `None`
    /// when `A` is not numerically positive definite (rank-deficient `G`) or the factorisation
    /// fails.
    pub fn new(g: &DMatrix<f64>, w: &[f64]) -> Option<SparseGram> {
        let (m, n) = g.shape();
        debug_assert_eq!(w.len(), n);
        // rows with an entry in each column of G
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for j in 0..n {
            for i in 0..m {
                let v = g[(i, j)];
                if v != 0.0 {
                    cols[j].push((i, v));
                }
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
        let llt = a.sp_cholesky(Side::Lower).ok()?;
        Some(SparseGram { m, entries, llt })
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
        for &(i, k, v) in &self.entries {
            y[i] += v * x[k];
            if i != k {
                y[k] += v * x[i];
            }
        }
        y
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
