//! `dae::block_condition_bound`: a lower bound on the condition number of every square block of
//! columns of a wide matrix, checked against every block by brute force (the 2-norm condition
//! of each column subset from nalgebra's singular values), on deterministic pseudo-random
//! matrices of 1 … 4 rows and up to 7 columns with columns of very different scales.

use bondmech::partition::{block_condition_bound, dependent_condition};
use nalgebra::DMatrix;

/// A deterministic pseudo-random stream in [-1, 1) (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// Every `k`-subset of `0..n`.
fn subsets(n: usize, k: usize) -> Vec<Vec<usize>> {
    if k == 0 {
        return vec![Vec::new()];
    }
    if n < k {
        return Vec::new();
    }
    let mut out = subsets(n - 1, k);
    for mut s in subsets(n - 1, k - 1) {
        s.push(n - 1);
        out.push(s);
    }
    out
}

#[test]
fn bound_is_below_every_block_condition() {
    let mut rng = Lcg(20261126);
    let mut tight = 0.0f64;
    for m in 1..=4 {
        for n in m..=7 {
            for _ in 0..40 {
                // columns scaled over three decades, as translations and lever arms are
                let scales: Vec<f64> = (0..n).map(|_| 10f64.powf(1.5 * rng.next())).collect();
                let g = DMatrix::from_fn(m, n, |_, j| scales[j] * rng.next());
                let bound = block_condition_bound(&g);
                assert!(bound.is_finite() && bound > 0.0, "bound {bound} of {g}");
                for d in subsets(n, m) {
                    let k = dependent_condition(&g, &d);
                    assert!(
                        k >= bound * (1.0 - 1e-12),
                        "block {d:?} has condition {k} below the bound {bound} ({g})"
                    );
                    tight = tight.max(bound / k);
                }
            }
        }
    }
    // the bound is not vacuous: some block comes within a factor 2 of it
    assert!(
        tight > 0.5,
        "the bound is never within 2x of a block: {tight}"
    );
}

#[test]
fn square_matrix_bound_is_its_condition_or_less() {
    let g = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1e-3]);
    let b = block_condition_bound(&g);
    assert!(b <= dependent_condition(&g, &[0, 1]) * (1.0 + 1e-12));
    assert!((b - 1e3).abs() < 1e-9, "{b}");
}

#[test]
fn rank_deficient_and_empty() {
    let g = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0]);
    // rank one: σ_min(G) is zero up to rounding
    assert!(block_condition_bound(&g) > 1e12);
    assert_eq!(block_condition_bound(&DMatrix::<f64>::zeros(0, 3)), 0.0);
    assert_eq!(block_condition_bound(&DMatrix::<f64>::zeros(3, 2)), 0.0);
}
