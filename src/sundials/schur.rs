//! A direct linear solver for Newton matrices with a block-lower-triangular dependent part:
//! it eliminates the dependent unknowns block by block and factors only the Schur complement
//! on the remaining ones (the mechanism's degrees of freedom).
//!
//! With the unknowns split into `x` (the outer set of a [`SchurPartition`]: the degrees of
//! freedom) and `z` (its dependent blocks, in order), the matrix and its solution read
//!
//! ```text
//!   J = [A B; C D],   D = [D₁₁ 0 … 0; D₂₁ D₂₂ 0 …; …]  (block lower triangular),
//!   W = D⁻¹ C,   S = A − B W,
//!   J [x; z] = [b_x; b_z]:   z₀ = D⁻¹ b_z,   S x = b_x − B z₀,   z = z₀ − W x,
//! ```
//!
//! `D⁻¹` by forward substitution over the blocks (`z_k = D_kk⁻¹ (b_k − Σ_{l<k} D_kl z_l)`),
//! each diagonal block `D_kk` and `S` inverted by Gauss–Jordan elimination with partial pivoting. This
//! is exact (the same solution as an LU of `J`, up to rounding) whenever `J` and every `D_kk`
//! are regular; a singular `D_kk` or `S` is reported as a recoverable failure, as a zero pivot
//! of the dense LU is, so the integrator cuts its step (and its caller may change formulation).
//!
//! A block pairs a set of unknowns (columns) with a set of residual rows of the same size; the
//! rows need not be the unknowns' own ([`SchurPartition::with_row_blocks`]), so a saddle
//! `[M G_Dᵀ; G_D 0]` with square `G_D` splits into two triangular blocks: the constraint rows
//! against the first unknowns (`G_D`), then the first rows against the second unknowns
//! (`G_Dᵀ`), with `M` below the block diagonal.
//!
//! For the index-1 DAE of a mechanism (`crate::solve::formulation::index1`), `x` is the independent
//! coordinates and velocities, and the blocks are `G_qD` (the position rows in the dependent
//! coordinates), `G_vD` (the velocity rows in the dependent velocities), `G_D` (the
//! acceleration constraints in the dummy accelerations) and `G_Dᵀ` (the dependent inertias'
//! dynamics in the multipliers): the Newton step then costs four factorisations of the size of
//! the joint rows and one of the size of the degrees of freedom instead of one LU of the full
//! matrix. Only the structural non-zeros of `B`, `C` and the off-diagonal blocks of `D` are
//! visited.
//!
//! It reads the dense `SUNMatrix` the integrator fills with the user's Jacobian (so IDA keeps
//! its own decisions on when to re-evaluate and re-factor the Newton matrix).

use std::os::raw::c_int;

use super::context::Context;
use super::error::SolverError;
use super::linsol::{self, LinearSolver, Matrix, OwnLinearSolver};
use sundials_sys as sys;

/// Why a partition cannot serve the Schur solver.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PartitionError {
    /// The sets do not split `0..n` into disjoint parts.
    #[error("the outer set and the blocks must split the {n} unknowns into disjoint sets")]
    NotASplit {
        /// Number of unknowns.
        n: usize,
    },
    /// A structural non-zero lies above the block diagonal of the dependent part.
    #[error("the dependent part is not block lower triangular: entry ({row}, {col})")]
    NotLowerTriangular {
        /// Row of the offending entry.
        row: usize,
        /// Column of the offending entry.
        col: usize,
    },
}

/// Which unknowns a Schur elimination keeps (`outer`) and which it eliminates, block by block
/// (`blocks`, block lower triangular in that order), each block with the residual rows it is
/// solved from (`row_blocks`: the same sizes; the outer set keeps its own rows).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SchurSplit {
    /// The unknowns of the Schur complement (and their rows).
    pub outer: Vec<usize>,
    /// The eliminated unknowns, block by block.
    pub blocks: Vec<Vec<usize>>,
    /// The rows each block is solved from.
    pub row_blocks: Vec<Vec<usize>>,
}

impl SchurSplit {
    /// A split whose blocks are solved from their unknowns' own rows.
    pub fn symmetric(outer: Vec<usize>, blocks: Vec<Vec<usize>>) -> Self {
        SchurSplit {
            outer,
            row_blocks: blocks.clone(),
            blocks,
        }
    }
}

/// The split of the unknowns and rows and the structural non-zeros the solver visits.
#[derive(Clone, Debug)]
pub struct SchurPartition {
    n: usize,
    /// The unknowns kept by the Schur complement (`x`).
    outer: Vec<usize>,
    /// The unknowns of the dependent blocks (`z`), concatenated in block order.
    inner: Vec<usize>,
    /// The residual rows of the dependent blocks, in the same order (`inner` itself for a
    /// symmetric split).
    inner_rows: Vec<usize>,
    /// `inner[starts[k]..starts[k + 1]]`: block `k`.
    starts: Vec<usize>,
    /// `(local z row, local z column, dense index)` of `D` below the block diagonal, by row block:
    /// `lower[lower_at[k]..lower_at[k + 1]]` for row block `k`.
    lower: Vec<(usize, usize, usize)>,
    lower_at: Vec<usize>,
    /// `(local z row, dense index)` of `C`, by column of `x`: `c[c_at[j]..c_at[j + 1]]`.
    c: Vec<(usize, usize)>,
    c_at: Vec<usize>,
    /// `(local x row, local z column, dense index)` of `B`.
    b: Vec<(usize, usize, usize)>,
}

impl SchurPartition {
    /// The partition of `0..n` into `outer` and the ordered `blocks`, for a matrix whose
    /// structural non-zeros are `pattern` (`(row, column)`, repeats allowed); each block's rows
    /// are its unknowns' own.
    pub fn new(
        n: usize,
        outer: Vec<usize>,
        blocks: &[Vec<usize>],
        pattern: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<Self, PartitionError> {
        Self::with_row_blocks(n, outer, blocks, blocks, pattern)
    }

    /// The partition of [`SchurSplit`] `split` (see [`SchurPartition::with_row_blocks`]).
    pub fn from_split(
        n: usize,
        split: &SchurSplit,
        pattern: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<Self, PartitionError> {
        Self::with_row_blocks(
            n,
            split.outer.clone(),
            &split.blocks,
            &split.row_blocks,
            pattern,
        )
    }

    /// As [`SchurPartition::new`], with block `k`'s unknowns `blocks[k]` paired with the
    /// residual rows `row_blocks[k]` (the same size): `D_kk = J[row_blocks[k], blocks[k]]`. The
    /// outer set keeps its own rows; the row sets and the outer set must split `0..n` too.
    pub fn with_row_blocks(
        n: usize,
        outer: Vec<usize>,
        blocks: &[Vec<usize>],
        row_blocks: &[Vec<usize>],
        pattern: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<Self, PartitionError> {
        // where each unknown sits: Outer(local) or Inner(block, local)
        #[derive(Clone, Copy, PartialEq)]
        enum At {
            None,
            Outer(usize),
            Inner(usize, usize),
        }
        type Placed = (Vec<At>, Vec<usize>, Vec<usize>);
        // where each unknown (or row) sits, the sets concatenated, and where each set starts
        let place = |sets: &[Vec<usize>]| -> Result<Placed, PartitionError> {
            let mut at = vec![At::None; n];
            for (i, &u) in outer.iter().enumerate() {
                if u >= n || at[u] != At::None {
                    return Err(PartitionError::NotASplit { n });
                }
                at[u] = At::Outer(i);
            }
            let mut inner = Vec::new();
            let mut starts = vec![0];
            for (k, blk) in sets.iter().enumerate() {
                for &u in blk {
                    if u >= n || at[u] != At::None {
                        return Err(PartitionError::NotASplit { n });
                    }
                    at[u] = At::Inner(k, inner.len());
                    inner.push(u);
                }
                starts.push(inner.len());
            }
            if at.contains(&At::None) {
                return Err(PartitionError::NotASplit { n });
            }
            Ok((at, inner, starts))
        };
        if row_blocks.len() != blocks.len()
            || row_blocks
                .iter()
                .zip(blocks)
                .any(|(r, c)| r.len() != c.len())
        {
            return Err(PartitionError::NotASplit { n });
        }
        let (at, inner, starts) = place(blocks)?;
        let (at_row, inner_rows, _) = place(row_blocks)?;
        let mut entries: Vec<(usize, usize)> = pattern.into_iter().collect();
        entries.sort_unstable();
        entries.dedup();
        let nb = blocks.len();
        let mut lower_by: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); nb];
        let mut c_by: Vec<Vec<(usize, usize)>> = vec![Vec::new(); outer.len()];
        let mut b = Vec::new();
        for (row, col) in entries {
            if row >= n || col >= n {
                return Err(PartitionError::NotASplit { n });
            }
            let dense = col * n + row;
            match (at_row[row], at[col]) {
                (At::Inner(kr, r), At::Inner(kc, c)) => {
                    if kc > kr {
                        return Err(PartitionError::NotLowerTriangular { row, col });
                    }
                    if kc < kr {
                        lower_by[kr].push((r, c, dense));
                    }
                }
                (At::Inner(_, r), At::Outer(c)) => c_by[c].push((r, dense)),
                (At::Outer(r), At::Inner(_, c)) => b.push((r, c, dense)),
                _ => {}
            }
        }
        let (lower, lower_at) = flatten(lower_by);
        let (c, c_at) = flatten(c_by);
        Ok(SchurPartition {
            n,
            outer,
            inner,
            inner_rows,
            starts,
            lower,
            lower_at,
            c,
            c_at,
            b,
        })
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Size of the Schur complement (the outer set).
    pub fn outer_len(&self) -> usize {
        self.outer.len()
    }

    /// The structural non-zeros visited besides the diagonal blocks and `A`: those of `B`,
    /// of `C` and of `D` below its block diagonal.
    pub fn coupling_nonzeros(&self) -> (usize, usize, usize) {
        (self.b.len(), self.c.len(), self.lower.len())
    }
}

fn flatten<T>(groups: Vec<Vec<T>>) -> (Vec<T>, Vec<usize>) {
    let mut at = vec![0];
    let mut all = Vec::new();
    for g in groups {
        all.extend(g);
        at.push(all.len());
    }
    (all, at)
}

/// A singular diagonal block or Schur complement (zero or non-finite pivot).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("singular {what} in the Schur elimination")]
pub struct SingularSchur {
    /// `"dependent block"` or `"Schur complement"`.
    pub what: &'static str,
}

/// The factors of one Newton matrix, with all the scratch the solves need (nothing is
/// allocated after [`SchurLu::new`]).
#[derive(Clone, Debug)]
pub struct SchurLu {
    p: SchurPartition,
    /// Inverses of the diagonal blocks (column-major, concatenated) and the pivots of their LU.
    diag: Vec<f64>,
    diag_at: Vec<usize>,
    diag_piv: Vec<usize>,
    /// `W = D⁻¹ C`, `nz × nx` column-major.
    w: Vec<f64>,
    /// `S⁻¹` (`nx × nx`, column-major) and the pivots of its LU.
    s: Vec<f64>,
    s_piv: Vec<usize>,
    /// Values of `B`, `C`, the lower blocks, gathered at the factorisation.
    b_val: Vec<f64>,
    lower_val: Vec<f64>,
    /// Scratch of size `nz` and `nx`.
    z: Vec<f64>,
    x: Vec<f64>,
    /// Scratch of the largest block's size, and of its square (the inverses).
    tmp: Vec<f64>,
    work: Vec<f64>,
    factored: bool,
}

impl SchurLu {
    /// Storage for the factors of matrices with partition `p`.
    pub fn new(p: SchurPartition) -> Self {
        let nz = p.inner.len();
        let nx = p.outer.len();
        let mut diag_at = vec![0];
        for k in 0..p.starts.len() - 1 {
            let m = p.starts[k + 1] - p.starts[k];
            diag_at.push(diag_at[k] + m * m);
        }
        SchurLu {
            diag: vec![0.0; *diag_at.last().unwrap_or(&0)],
            diag_at,
            diag_piv: vec![0; nz],
            w: vec![0.0; nz * nx],
            s: vec![0.0; nx * nx],
            s_piv: vec![0; nx],
            b_val: vec![0.0; p.b.len()],
            lower_val: vec![0.0; p.lower.len()],
            z: vec![0.0; nz],
            x: vec![0.0; nx],
            tmp: vec![0.0; nz.max(nx)],
            work: vec![0.0; nz.max(nx).pow(2)],
            factored: false,
            p,
        }
    }

    /// The partition.
    pub fn partition(&self) -> &SchurPartition {
        &self.p
    }

    /// Factors the dense column-major `n × n` matrix `a` (see the module documentation).
    pub fn factor(&mut self, a: &[f64]) -> Result<(), SingularSchur> {
        self.factored = false;
        let p = &self.p;
        let n = p.n;
        let nx = p.outer.len();
        let nz = p.inner.len();
        // the diagonal blocks
        for k in 0..p.starts.len() - 1 {
            let (s0, s1) = (p.starts[k], p.starts[k + 1]);
            let m = s1 - s0;
            let blk = &mut self.diag[self.diag_at[k]..self.diag_at[k + 1]];
            for (jc, &cj) in p.inner[s0..s1].iter().enumerate() {
                for (ir, &ri) in p.inner_rows[s0..s1].iter().enumerate() {
                    blk[jc * m + ir] = a[cj * n + ri];
                }
            }
            if !invert(blk, m, &mut self.diag_piv[s0..s1], &mut self.work) {
                return Err(SingularSchur {
                    what: "dependent block",
                });
            }
        }
        for (v, &(_, _, d)) in self.lower_val.iter_mut().zip(&p.lower) {
            *v = a[d];
        }
        for (v, &(_, _, d)) in self.b_val.iter_mut().zip(&p.b) {
            *v = a[d];
        }
        // W = D⁻¹ C, column by column
        self.w.fill(0.0);
        for j in 0..nx {
            let col = &mut self.w[j * nz..(j + 1) * nz];
            for &(r, d) in &p.c[p.c_at[j]..p.c_at[j + 1]] {
                col[r] = a[d];
            }
            forward(
                p,
                &self.diag,
                &self.diag_at,
                &self.lower_val,
                col,
                &mut self.tmp,
            );
        }
        // S = A − B W
        for (jc, &cj) in p.outer.iter().enumerate() {
            for (ir, &ri) in p.outer.iter().enumerate() {
                self.s[jc * nx + ir] = a[cj * n + ri];
            }
        }
        for (&(r, c, _), &v) in p.b.iter().zip(&self.b_val) {
            for j in 0..nx {
                self.s[j * nx + r] -= v * self.w[j * nz + c];
            }
        }
        if !invert(&mut self.s, nx, &mut self.s_piv, &mut self.work) {
            return Err(SingularSchur {
                what: "Schur complement",
            });
        }
        self.factored = true;
        Ok(())
    }

    /// Whether the last [`Self::factor`] succeeded.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Overwrites `b` (length `n`) with the solution of `J x = b` for the factored `J`.
    pub fn solve(&mut self, b: &mut [f64]) {
        let p = &self.p;
        let nx = p.outer.len();
        let nz = p.inner.len();
        for (z, &u) in self.z.iter_mut().zip(&p.inner_rows) {
            *z = b[u];
        }
        forward(
            p,
            &self.diag,
            &self.diag_at,
            &self.lower_val,
            &mut self.z,
            &mut self.tmp,
        );
        for (x, &u) in self.x.iter_mut().zip(&p.outer) {
            *x = b[u];
        }
        for (&(r, c, _), &v) in p.b.iter().zip(&self.b_val) {
            self.x[r] -= v * self.z[c];
        }
        apply(&self.s, nx, &mut self.x, &mut self.tmp);
        for (j, &xj) in self.x.iter().enumerate() {
            if xj != 0.0 {
                let wj = &self.w[j * nz..(j + 1) * nz];
                for (z, w) in self.z.iter_mut().zip(wj) {
                    *z -= w * xj;
                }
            }
        }
        for (&x, &u) in self.x.iter().zip(&p.outer) {
            b[u] = x;
        }
        for (&z, &u) in self.z.iter().zip(&p.inner) {
            b[u] = z;
        }
    }
}

/// `z ← D⁻¹ z` by forward substitution over the blocks (`diag`: the blocks' inverses).
fn forward(
    p: &SchurPartition,
    diag: &[f64],
    diag_at: &[usize],
    lower_val: &[f64],
    z: &mut [f64],
    tmp: &mut [f64],
) {
    for k in 0..p.starts.len() - 1 {
        let (s0, s1) = (p.starts[k], p.starts[k + 1]);
        let range = p.lower_at[k]..p.lower_at[k + 1];
        for (&(r, c, _), &v) in p.lower[range.clone()].iter().zip(&lower_val[range]) {
            z[r] -= v * z[c];
        }
        apply(
            &diag[diag_at[k]..diag_at[k + 1]],
            s1 - s0,
            &mut z[s0..s1],
            tmp,
        );
    }
}

/// Replaces the column-major `m × m` matrix `a` by its inverse, by Gauss–Jordan elimination
/// with partial (row) pivoting in place: at pivot `k`, row `k` is divided by `a_kk` and
/// subtracted from every other row so column `k` becomes `e_k`, the elimination's multipliers
/// take its place (`a_ik ← −a_ik / a_kk`, `a_kk ← 1 / a_kk`); the row exchanges are undone as
/// column exchanges at the end, in reverse order (`A⁻¹ = (P A)⁻¹ P`). `m³` multiply-adds, where
/// an LU and `m` triangular solves of `e_j` cost `4m³/3` and their loop set-up per column.
/// `false` on a zero or non-finite pivot. The blocks are small and inverted once per Newton
/// matrix, while each of IDA's Newton iterations applies them: a product with the inverse is
/// one short loop per column, where the triangular solves of the factors cost their loop
/// set-up per row (measured with callgrind: 600 instructions per 4 × 4 solve).
fn invert(a: &mut [f64], m: usize, piv: &mut [usize], work: &mut [f64]) -> bool {
    let a = &mut a[..m * m];
    let col = &mut work[..m];
    for k in 0..m {
        let mut p = k;
        let mut big = a[k * m + k].abs();
        for i in k + 1..m {
            let v = a[k * m + i].abs();
            if v > big {
                big = v;
                p = i;
            }
        }
        piv[k] = p;
        if p != k {
            for j in 0..m {
                a.swap(j * m + k, j * m + p);
            }
        }
        let pivot = a[k * m + k];
        if pivot == 0.0 || !pivot.is_finite() {
            return false;
        }
        let inv = 1.0 / pivot;
        col.copy_from_slice(&a[k * m..(k + 1) * m]);
        for j in (0..m).filter(|&j| j != k) {
            let akj = a[j * m + k] * inv;
            a[j * m + k] = akj;
            if akj != 0.0 {
                let cj = &mut a[j * m..(j + 1) * m];
                for (x, &c) in cj[..k].iter_mut().zip(&col[..k]) {
                    *x -= c * akj;
                }
                for (x, &c) in cj[k + 1..].iter_mut().zip(&col[k + 1..]) {
                    *x -= c * akj;
                }
            }
        }
        for (i, x) in a[k * m..(k + 1) * m].iter_mut().enumerate() {
            *x = if i == k { inv } else { -col[i] * inv };
        }
    }
    for k in (0..m).rev() {
        let p = piv[k];
        if p != k {
            for i in 0..m {
                a.swap(k * m + i, p * m + i);
            }
        }
    }
    a.iter().all(|v| v.is_finite())
}

/// `v ← M v` for the column-major `m × m` matrix `minv` (`tmp`: scratch of length `m`).
#[inline]
fn apply(minv: &[f64], m: usize, v: &mut [f64], tmp: &mut [f64]) {
    if m == 0 {
        return;
    }
    let v = &mut v[..m];
    let t = &mut tmp[..m];
    t.copy_from_slice(v);
    // column by column, the first one assigning (0 + x = x: the same sums as from zero)
    let mut cols = minv[..m * m].chunks_exact(m);
    if let Some(first) = cols.next() {
        for (vi, &c) in v.iter_mut().zip(first) {
            *vi = c * t[0];
        }
    }
    for (col, &tj) in cols.zip(&t[1..]) {
        for (vi, &c) in v.iter_mut().zip(col) {
            *vi += c * tj;
        }
    }
}

impl OwnLinearSolver for SchurLu {
    const KIND: sys::SUNLinearSolver_Type = sys::SUNLinearSolver_Type_SUNLINEARSOLVER_DIRECT;

    fn reset(&mut self) {
        self.factored = false;
    }

    /// Factors the dense Newton matrix the integrator attached (only read).
    fn setup(&mut self, a: Option<Matrix<'_>>) -> c_int {
        match a {
            Some(Matrix::Dense { n, data }) if n == self.p.n => match self.factor(data) {
                Ok(()) => 0,
                // a singular block: recoverable (the integrator cuts the step), as a zero pivot
                Err(_) => sys::SUNLS_PACKAGE_FAIL_REC as c_int,
            },
            _ => -1,
        }
    }

    fn order(&self) -> Option<usize> {
        self.factored.then_some(self.p.n)
    }

    fn solve(&mut self, x: &mut [f64]) -> c_int {
        SchurLu::solve(self, x);
        linsol::finite_solution(x)
    }
}

/// A new Schur solver for the partition `p` (attached to an integrator with its dense matrix).
pub(crate) fn new(ctx: &Context, p: SchurPartition) -> Result<LinearSolver, SolverError> {
    linsol::own(ctx, SchurLu::new(p))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// A random matrix with the index-1 structure: `nx` outer unknowns scattered among the
    /// blocks, blocks of the given sizes, dense everywhere allowed, plus its pattern.
    fn structured(
        rng: &mut Rng,
        nx: usize,
        sizes: &[usize],
        saddle_zero: bool,
    ) -> (usize, Vec<usize>, Vec<Vec<usize>>, DMatrix<f64>) {
        let n = nx + sizes.iter().sum::<usize>();
        // a scrambled numbering
        let mut order: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = ((rng.next() + 0.5) * (i + 1) as f64) as usize % (i + 1);
            order.swap(i, j);
        }
        let outer = order[..nx].to_vec();
        let mut blocks = Vec::new();
        let mut at = nx;
        for &m in sizes {
            blocks.push(order[at..at + m].to_vec());
            at += m;
        }
        let block_of = |u: usize| blocks.iter().position(|b: &Vec<usize>| b.contains(&u));
        let mut a = DMatrix::zeros(n, n);
        for r in 0..n {
            for c in 0..n {
                let allowed = match (block_of(r), block_of(c)) {
                    (Some(kr), Some(kc)) => kc <= kr,
                    _ => true,
                };
                if allowed {
                    a[(r, c)] = rng.next();
                }
            }
        }
        // diagonally heavy blocks keep every D_kk regular; the last block gets a zero
        // lower-right corner, as the saddle [M G_Dᵀ; G_D 0] has
        for (k, b) in blocks.iter().enumerate() {
            for &u in b {
                a[(u, u)] += 3.0;
            }
            if saddle_zero && k == blocks.len() - 1 && b.len() >= 2 && b.len() % 2 == 0 {
                // [M Gᵀ; G 0]: M diagonal positive, G well conditioned
                let h = b.len() / 2;
                for i in 0..h {
                    for j in 0..h {
                        let g = rng.next() + if i == j { 3.0 } else { 0.0 };
                        a[(b[h + i], b[j])] = g;
                        a[(b[j], b[h + i])] = g;
                        a[(b[i], b[j])] = if i == j { 1.0 + rng.next() } else { 0.0 };
                        a[(b[h + i], b[h + j])] = 0.0;
                    }
                }
            }
        }
        (n, outer, blocks, a)
    }

    /// `a⁻¹ b` by nalgebra's dense LU (independent of the Schur elimination).
    fn lu_reference(a: &DMatrix<f64>, b: &[f64]) -> DVector<f64> {
        a.clone()
            .lu()
            .solve(&DVector::from_column_slice(b))
            .expect("regular")
    }

    fn pattern(a: &DMatrix<f64>) -> Vec<(usize, usize)> {
        let n = a.nrows();
        (0..n)
            .flat_map(|r| (0..n).map(move |c| (r, c)))
            .filter(|&(r, c)| a[(r, c)] != 0.0)
            .collect()
    }

    #[test]
    fn solves_as_the_full_lu_on_random_structured_matrices() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        for (nx, sizes) in [
            (1, vec![1, 1, 2]),
            (2, vec![4, 4, 8]),
            (2, vec![7, 7, 14]),
            (4, vec![6, 6, 12]),
            (3, vec![1]),
            (5, vec![]),
        ] {
            for trial in 0..5 {
                let (n, outer, blocks, a) = structured(&mut rng, nx, &sizes, trial % 2 == 0);
                let p = SchurPartition::new(n, outer, &blocks, pattern(&a)).expect("partition");
                let mut lu = SchurLu::new(p);
                lu.factor(a.as_slice()).expect("regular");
                let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
                let reference = lu_reference(&a, &b);
                let mut x = b.clone();
                lu.solve(&mut x);
                // forward error within what the conditioning allows (κ ε), and a backward
                // error (‖J x − b‖ / (‖J‖ ‖x‖)) at the rounding level
                let sv = a.clone().singular_values();
                let cond = |m: DMatrix<f64>| {
                    let s = m.singular_values();
                    s.max() / s.min()
                };
                // block elimination is as accurate as its pivot blocks are conditioned
                let sub = |r: &[usize], c: &[usize]| {
                    DMatrix::from_fn(r.len(), c.len(), |i, j| a[(r[i], c[j])])
                };
                let kappa_blocks = blocks
                    .iter()
                    .map(|b| cond(sub(b, b)))
                    .fold(1.0f64, f64::max);
                let kappa = (sv.max() / sv.min()).max(kappa_blocks);
                let xv = DVector::from_column_slice(&x);
                let forward = (&xv - &reference).amax() / reference.amax();
                assert!(
                    forward <= 1e-14 * kappa.max(1.0),
                    "nx {nx} sizes {sizes:?}: forward error {forward:.1e}, κ {kappa:.1e}"
                );
                let r = &a * &xv - DVector::from_column_slice(&b);
                let backward = r.norm() / (sv.max() * xv.norm());
                assert!(
                    backward < 1e-13,
                    "backward error {backward:.1e} (κ {kappa:.1e})"
                );
            }
        }
    }

    #[test]
    fn blocks_solved_from_other_rows_solve_as_the_full_lu() {
        // J' = P J with the blocks' rows exchanged among themselves: block k of J' is solved
        // from rows π(blocks[k]), and J' x = P b has J's solution x
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for (nx, sizes) in [
            (1, vec![2, 2, 2, 2]),
            (2, vec![7, 7, 7, 7]),
            (3, vec![1, 3]),
        ] {
            for trial in 0..4 {
                let (n, outer, blocks, a) = structured(&mut rng, nx, &sizes, trial % 2 == 0);
                let inner: Vec<usize> = blocks.concat();
                let mut shuffled = inner.clone();
                for i in (1..shuffled.len()).rev() {
                    let j = ((rng.next() + 0.5) * (i + 1) as f64) as usize % (i + 1);
                    shuffled.swap(i, j);
                }
                // π: inner[i] ↦ shuffled[i]; outer rows stay
                let mut pi: Vec<usize> = (0..n).collect();
                for (&from, &to) in inner.iter().zip(&shuffled) {
                    pi[from] = to;
                }
                let row_blocks: Vec<Vec<usize>> = blocks
                    .iter()
                    .map(|b| b.iter().map(|&u| pi[u]).collect())
                    .collect();
                let permuted = DMatrix::from_fn(n, n, |i, j| {
                    let src = pi.iter().position(|&t| t == i).unwrap();
                    a[(src, j)]
                });
                let p = SchurPartition::with_row_blocks(
                    n,
                    outer,
                    &blocks,
                    &row_blocks,
                    pattern(&permuted),
                )
                .expect("partition");
                let mut lu = SchurLu::new(p);
                lu.factor(permuted.as_slice()).expect("regular");
                let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
                let reference = lu_reference(&a, &b);
                let mut x = vec![0.0; n];
                for i in 0..n {
                    x[pi[i]] = b[i];
                }
                lu.solve(&mut x);
                let xv = DVector::from_column_slice(&x);
                let forward = (&xv - &reference).amax() / reference.amax();
                let s = a.clone().singular_values();
                assert!(
                    forward <= 1e-13 * (s.max() / s.min()).max(1.0),
                    "nx {nx} sizes {sizes:?}: forward error {forward:.1e}"
                );
            }
        }
    }

    #[test]
    fn row_blocks_of_other_sizes_are_refused() {
        let e = SchurPartition::with_row_blocks(3, vec![0], &[vec![1, 2]], &[vec![1]], [(0, 0)]);
        assert!(matches!(e, Err(PartitionError::NotASplit { n: 3 })));
    }

    #[test]
    fn an_entry_above_the_block_diagonal_is_refused() {
        // unknowns: outer {0}, blocks [{1}, {2}]; entry (1, 2) couples block 0 to block 1
        let e = SchurPartition::new(3, vec![0], &[vec![1], vec![2]], [(1, 1), (2, 2), (1, 2)]);
        assert_eq!(
            e.unwrap_err(),
            PartitionError::NotLowerTriangular { row: 1, col: 2 }
        );
    }

    #[test]
    fn overlapping_or_missing_unknowns_are_refused() {
        let dup = SchurPartition::new(3, vec![0, 1], &[vec![1, 2]], [(0, 0)]);
        assert!(matches!(dup, Err(PartitionError::NotASplit { n: 3 })));
        let missing = SchurPartition::new(3, vec![0], &[vec![1]], [(0, 0)]);
        assert!(matches!(missing, Err(PartitionError::NotASplit { n: 3 })));
    }

    #[test]
    fn a_singular_dependent_block_is_a_failure_not_a_wrong_answer() {
        // D₁₁ = [[1, 2], [2, 4]] is singular although J as a whole need not be
        let n = 3;
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 2.0, 4.0]);
        let p = SchurPartition::new(n, vec![0], &[vec![1, 2]], pattern(&a)).unwrap();
        let mut lu = SchurLu::new(p);
        assert_eq!(
            lu.factor(a.as_slice()),
            Err(SingularSchur {
                what: "dependent block"
            })
        );
        assert!(!lu.is_factored());
    }

    #[test]
    fn a_singular_schur_complement_is_a_failure() {
        // J = [[1, 1], [1, 1]] with D = [1]: S = 1 − 1·1 = 0
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let p = SchurPartition::new(2, vec![0], &[vec![1]], pattern(&a)).unwrap();
        let mut lu = SchurLu::new(p);
        assert_eq!(
            lu.factor(a.as_slice()),
            Err(SingularSchur {
                what: "Schur complement"
            })
        );
    }
}
