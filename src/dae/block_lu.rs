//! The LU factorisation of the dependent block `G_D` of the joints' Jacobian, compiled once per
//! sparsity pattern and pivot order.
//!
//! The partitioned right-hand side factorises `G_D` (`nc × nc`) two or three times per call, and
//! `G_D` is sparse: a pin row mentions the two bodies' translations and angles, so most of its
//! entries are structural zeros, and its translation columns are the constants ±1. A dense LU
//! spends its time on those zeros and on the pivot search. Here the pivot order is chosen once
//! by partial pivoting at the current values ([`LuPlan::choose`]: row `p_k` of largest |a| in
//! column `k` of the partially eliminated matrix), the fill of `L + U` is found symbolically
//! along it, and each factorisation then runs only over that pattern:
//!
//! ```text
//!   P A = L U,   for k = 0 … n−1:  l_ik = a_ik / a_kk,  a_ij −= l_ik a_kj   (i ∈ L_k, j ∈ U_k)
//! ```
//!
//! with `L_k` the rows below `k` whose column `k` is structurally non-zero and `U_k` the columns
//! right of `k` in row `k`. The frozen pivot order stays stable while the values move as long
//! as no pivot shrinks: [`BlockLu::factor`] re-chooses it at the current values when the pivot
//! ratio `max |a_kk| / min |a_kk|` (the condition estimate the partition's re-choice reads)
//! grows past twice the planned one, or past the caller's limit, so the estimate it reports is
//! always that of a fresh partial pivoting where it matters.
//!
//! ```
//! use bondmech::dae::block_lu::BlockLu;
//! // A = [[0, 2], [1, 1]] given as its structural entries (row, column, index into `src`)
//! let mut lu = BlockLu::new(2, vec![(0, 1, 0), (1, 0, 1), (1, 1, 2)]);
//! lu.factor(&[2.0, 1.0, 1.0], f64::INFINITY).unwrap();
//! let mut b = [4.0, 3.0]; // A x = b for x = (1, 2)
//! lu.solve(&mut b);
//! assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] - 2.0).abs() < 1e-15);
//! ```

use crate::thresholds::REPLAN_GROWTH;

/// The matrix has a zero (or non-finite) pivot even with a fresh pivot order.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the block is singular (zero or non-finite pivot)")]
pub struct SingularBlock;

/// A pivot order and the pattern of `L + U` along it, for one sparsity pattern.
#[derive(Clone, Debug)]
pub struct LuPlan {
    n: usize,
    /// The row swapped with row `k` at step `k` (applied in order, `P b`).
    swap: Vec<usize>,
    /// For each original row, its permuted position.
    pos_of_row: Vec<usize>,
    /// `lower[lo[k]..lo[k + 1]]`: permuted rows `i > k` with `L[i][k]` structurally non-zero.
    lower: Vec<usize>,
    lo: Vec<usize>,
    /// `upper[up[k]..up[k + 1]]`: columns `j > k` with `U[k][j]` structurally non-zero.
    upper: Vec<usize>,
    up: Vec<usize>,
    /// Storage indices (permuted, row-major) of the fill: zero in `A`, non-zero in `L + U`.
    fill: Vec<usize>,
    /// Pivot ratio at the values the plan was chosen at.
    planned_ratio: f64,
}

impl LuPlan {
    /// Chooses the pivot order by partial pivoting on `values` (row-major `n × n`, original
    /// order) and the fill along it for the structural pattern `pattern` (same layout; the
    /// values' non-zeros must lie in it). `None` when a column has no non-zero pivot.
    pub fn choose(n: usize, pattern: &[bool], values: &[f64]) -> Option<LuPlan> {
        let mut a = values[..n * n].to_vec();
        let mut s = pattern[..n * n].to_vec();
        // perm[k]: original row at permuted position k (rows are swapped as they are chosen)
        let mut perm: Vec<usize> = (0..n).collect();
        let mut swap = vec![0; n];
        let (mut big, mut small) = (0.0f64, f64::INFINITY);
        for k in 0..n {
            let mut p = k;
            let mut best = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return None;
            }
            swap[k] = p;
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                    s.swap(k * n + j, p * n + j);
                }
                perm.swap(k, p);
            }
            big = big.max(best);
            small = small.min(best);
            let d = a[k * n + k];
            for i in k + 1..n {
                if !s[i * n + k] {
                    continue;
                }
                let f = a[i * n + k] / d;
                a[i * n + k] = f;
                for j in k + 1..n {
                    if s[k * n + j] {
                        a[i * n + j] -= f * a[k * n + j];
                        s[i * n + j] = true;
                    }
                }
            }
        }
        let mut pos_of_row = vec![0; n];
        for (k, &r) in perm.iter().enumerate() {
            pos_of_row[r] = k;
        }
        let (mut lower, mut lo) = (Vec::new(), vec![0]);
        let (mut upper, mut up) = (Vec::new(), vec![0]);
        for k in 0..n {
            lower.extend((k + 1..n).filter(|&i| s[i * n + k]));
            lo.push(lower.len());
            upper.extend((k + 1..n).filter(|&j| s[k * n + j]));
            up.push(upper.len());
        }
        let fill = (0..n * n)
            .filter(|&idx| s[idx] && !pattern[perm[idx / n] * n + idx % n])
            .collect();
        Some(LuPlan {
            n,
            swap,
            pos_of_row,
            lower,
            lo,
            upper,
            up,
            fill,
            planned_ratio: big / small,
        })
    }

    /// Number of multiply–adds of one factorisation along this plan.
    pub fn factor_flops(&self) -> usize {
        (0..self.n)
            .map(|k| (self.lo[k + 1] - self.lo[k]) * (1 + self.up[k + 1] - self.up[k]))
            .sum()
    }

    fn lower(&self, k: usize) -> &[usize] {
        &self.lower[self.lo[k]..self.lo[k + 1]]
    }

    fn upper(&self, k: usize) -> &[usize] {
        &self.upper[self.up[k]..self.up[k + 1]]
    }
}

/// The LU of one square sparse block, refactorised along a [`LuPlan`] from the values of its
/// structural entries.
#[derive(Clone, Debug)]
pub struct BlockLu {
    n: usize,
    /// Structural entries `(row, column, index into the caller's source slice)`.
    entries: Vec<(usize, usize, usize)>,
    plan: Option<LuPlan>,
    /// `(source index, storage index)` of each entry under the current plan.
    map: Vec<(usize, usize)>,
    /// Permuted row-major factors.
    a: Vec<f64>,
    /// Largest and smallest |pivot| of the last factorisation.
    pub pivots: (f64, f64),
    /// Pivot orders chosen so far (the first included).
    pub plans: u64,
}

impl BlockLu {
    /// A block of order `n` whose structural non-zeros are `entries` (`(row, column, index into
    /// the source slice that [`Self::factor`] reads)`; one entry per position: a repeated
    /// position keeps its last).
    pub fn new(n: usize, mut entries: Vec<(usize, usize, usize)>) -> BlockLu {
        let mut seen = std::collections::HashMap::new();
        for (k, &(r, c, _)) in entries.iter().enumerate() {
            seen.insert((r, c), k);
        }
        let mut keep: Vec<usize> = seen.into_values().collect();
        keep.sort_unstable();
        entries = keep.into_iter().map(|k| entries[k]).collect();
        BlockLu {
            n,
            entries,
            plan: None,
            map: Vec::new(),
            a: vec![0.0; n * n],
            pivots: (1.0, 1.0),
            plans: 0,
        }
    }

    /// Order of the block.
    pub fn order(&self) -> usize {
        self.n
    }

    /// The current plan (after the first [`Self::factor`]).
    pub fn plan(&self) -> Option<&LuPlan> {
        self.plan.as_ref()
    }

    /// Condition estimate of the last factorisation: largest over smallest |pivot|.
    pub fn ratio(&self) -> f64 {
        self.pivots.0 / self.pivots.1
    }

    /// Largest and smallest |pivot| of the last factorisation.
    pub fn pivots(&self) -> (f64, f64) {
        self.pivots
    }

    fn replan(&mut self, src: &[f64]) -> Result<(), SingularBlock> {
        let n = self.n;
        let mut pattern = vec![false; n * n];
        let mut values = vec![0.0; n * n];
        for &(r, c, s) in &self.entries {
            pattern[r * n + c] = true;
            values[r * n + c] = src[s];
        }
        let plan = LuPlan::choose(n, &pattern, &values).ok_or(SingularBlock)?;
        self.map = self
            .entries
            .iter()
            .map(|&(r, c, s)| (s, plan.pos_of_row[r] * n + c))
            .collect();
        // storage outside L + U is never read; zero it once
        self.a.fill(0.0);
        self.plan = Some(plan);
        self.plans += 1;
        Ok(())
    }

    /// Loads the block's values from `src` (each entry's source index) and factorises it,
    /// re-choosing the pivot order when there is none yet, when a pivot vanishes, or when the
    /// pivot ratio passes [`REPLAN_GROWTH`] times the planned one or `limit`. Returns the
    /// pivot ratio; `Err` when the block is singular under a fresh pivot order too.
    pub fn factor(&mut self, src: &[f64], limit: f64) -> Result<f64, SingularBlock> {
        if self.plan.is_none() {
            self.replan(src)?;
        }
        match self.factor_planned(src) {
            Some(r) => {
                let planned = self.plan.as_ref().map_or(1.0, |p| p.planned_ratio);
                if r <= REPLAN_GROWTH * planned && r <= limit {
                    return Ok(r);
                }
            }
            None if self.n == 0 => return Ok(1.0),
            None => {}
        }
        self.replan(src)?;
        self.factor_planned(src).ok_or(SingularBlock)
    }

    fn factor_planned(&mut self, src: &[f64]) -> Option<f64> {
        let n = self.n;
        let plan = self.plan.as_ref()?;
        let a = &mut self.a;
        for &i in &plan.fill {
            a[i] = 0.0;
        }
        for &(s, d) in &self.map {
            a[d] = src[s];
        }
        let (mut big, mut small) = (0.0f64, f64::INFINITY);
        for k in 0..n {
            let d = a[k * n + k];
            let m = d.abs();
            if m == 0.0 || !m.is_finite() {
                return None;
            }
            big = big.max(m);
            small = small.min(m);
            let up = plan.upper(k);
            for &i in plan.lower(k) {
                let f = a[i * n + k] / d;
                a[i * n + k] = f;
                if f != 0.0 {
                    for &j in up {
                        a[i * n + j] -= f * a[k * n + j];
                    }
                }
            }
        }
        if n == 0 {
            (big, small) = (1.0, 1.0);
        }
        self.pivots = (big, small);
        Some(big / small)
    }

    /// Solves `A x = b` in place with the last factorisation.
    pub fn solve(&self, b: &mut [f64]) {
        let Some(plan) = &self.plan else { return };
        let n = self.n;
        let a = &self.a;
        // c = P b (in place), then L c' = c (unit lower), then U x = c'
        let c = &mut b[..n];
        for (k, &p) in plan.swap.iter().enumerate() {
            c.swap(k, p);
        }
        for k in 0..n {
            let ck = c[k];
            if ck != 0.0 {
                for &i in plan.lower(k) {
                    c[i] -= a[i * n + k] * ck;
                }
            }
        }
        for k in (0..n).rev() {
            let mut s = c[k];
            for &j in plan.upper(k) {
                s -= a[k * n + j] * c[j];
            }
            c[k] = s / a[k * n + k];
        }
    }

    /// Solves `Aᵀ x = b` in place with the last factorisation (`Aᵀ = Uᵀ Lᵀ P`).
    pub fn solve_transposed(&self, b: &mut [f64]) {
        let Some(plan) = &self.plan else { return };
        let n = self.n;
        let a = &self.a;
        let c = &mut b[..n];
        for k in 0..n {
            c[k] /= a[k * n + k];
            let ck = c[k];
            for &j in plan.upper(k) {
                c[j] -= a[k * n + j] * ck;
            }
        }
        for k in (0..n).rev() {
            let mut s = c[k];
            for &i in plan.lower(k) {
                s -= a[i * n + k] * c[i];
            }
            c[k] = s;
        }
        for (k, &p) in plan.swap.iter().enumerate().rev() {
            c.swap(k, p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dense reference: `A x` for row-major `A`.
    fn mul(a: &[f64], n: usize, x: &[f64]) -> Vec<f64> {
        (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
            .collect()
    }

    fn block(a: &[f64], n: usize) -> (BlockLu, Vec<f64>) {
        let mut entries = Vec::new();
        let mut src = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if a[i * n + j] != 0.0 {
                    entries.push((i, j, src.len()));
                    src.push(a[i * n + j]);
                }
            }
        }
        (BlockLu::new(n, entries), src)
    }

    #[test]
    fn solves_a_sparse_system_that_needs_pivoting_and_fill_and_its_transpose() {
        // arrow matrix with a zero leading entry: pivoting and fill in the trailing block
        let n = 5;
        let a = [
            0.0, 1.0, 1.0, 1.0, 1.0, //
            1.0, 4.0, 0.0, 0.0, 0.0, //
            1.0, 0.0, 5.0, 0.0, 0.0, //
            1.0, 0.0, 0.0, 6.0, 0.0, //
            2.0, 0.0, 0.0, 0.0, 7.0,
        ];
        let (mut lu, src) = block(&a, n);
        lu.factor(&src, f64::INFINITY).unwrap();
        assert!(!lu.plan().unwrap().fill.is_empty(), "the pattern fills in");
        let x = [1.0, -2.0, 0.5, 3.0, -1.5];
        let mut b = mul(&a, n, &x);
        lu.solve(&mut b);
        let at: Vec<f64> = (0..n * n).map(|k| a[(k % n) * n + k / n]).collect();
        let mut bt = mul(&at, n, &x);
        lu.solve_transposed(&mut bt);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-14, "{b:?}");
            assert!((bt[i] - x[i]).abs() < 1e-14, "{bt:?}");
        }
    }

    #[test]
    fn pivot_order_is_rechosen_when_a_frozen_pivot_vanishes() {
        // planned at a = [[2, 1], [1, 1]] (pivot row 0), then row 0's leading entry goes to 0
        let (mut lu, mut src) = block(&[2.0, 1.0, 1.0, 1.0], 2);
        lu.factor(&src, f64::INFINITY).unwrap();
        assert_eq!(lu.plans, 1);
        src[0] = 0.0;
        lu.factor(&src, f64::INFINITY).unwrap();
        assert_eq!(lu.plans, 2, "a zero pivot asks for a new order");
        let mut b = [1.0, 3.0]; // [[0, 1], [1, 1]] x = b → x = (2, 1)
        lu.solve(&mut b);
        assert!(
            (b[0] - 2.0).abs() < 1e-15 && (b[1] - 1.0).abs() < 1e-15,
            "{b:?}"
        );
    }

    #[test]
    fn singular_block_is_an_error() {
        let (mut lu, src) = block(&[1.0, 2.0, 2.0, 4.0], 2);
        assert_eq!(lu.factor(&src, f64::INFINITY), Err(SingularBlock));
    }

    #[test]
    fn a_ratio_above_the_limit_is_always_that_of_a_fresh_partial_pivoting() {
        // a random walk of a 6×6 sparse matrix: whenever the reported ratio passes the limit it
        // is a fresh partial pivoting's (the partition's re-choice reads it), and the solution
        // stays exact along the walk
        let n = 6;
        let limit = 3.0;
        let mut a = vec![0.0; n * n];
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for i in 0..n {
            a[i * n + i] = 1.0 + rnd().abs();
            a[i * n + (i + 2) % n] = rnd();
            a[((i + 3) % n) * n + i] = rnd();
        }
        let pattern: Vec<bool> = a.iter().map(|&v| v != 0.0).collect();
        let (mut lu, mut src) = block(&a, n);
        let mut above = 0;
        for _ in 0..300 {
            for v in src.iter_mut() {
                *v += 0.1 * rnd();
            }
            let mut dense = vec![0.0; n * n];
            for &(r, c, s) in &lu.entries {
                dense[r * n + c] = src[s];
            }
            let Some(fresh) = LuPlan::choose(n, &pattern, &dense) else {
                continue;
            };
            let Ok(r) = lu.factor(&src, limit) else {
                continue;
            };
            if r > limit {
                above += 1;
                assert!(
                    (r / fresh.planned_ratio - 1.0).abs() < 1e-12,
                    "{r} vs {}",
                    fresh.planned_ratio
                );
            }
            let x: Vec<f64> = (0..n).map(|i| i as f64 - 2.5).collect();
            let mut b = mul(&dense, n, &x);
            lu.solve(&mut b);
            let err = b
                .iter()
                .zip(&x)
                .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            assert!(
                err < 1e-12 * r.max(1.0) * 100.0,
                "error {err:e} at ratio {r:e}"
            );
        }
        assert!(above > 10, "the walk passes the limit ({above} times)");
        assert!(lu.plans > 1, "and re-chooses the pivot order");
    }
}
