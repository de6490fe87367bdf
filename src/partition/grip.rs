//! The dependent block's grip at scale: `G_v` read by its non-zeros ([`JointRows`]), the
//! block's sparse LU kept between steps ([`KeptBlockLu`]) and `σ_min(G_D)` by Lanczos
//! iterations ([`block_smallest_squared`]), so that the checks cost time linear in a chain.

use crate::partition::thresholds::{
    SPARSE_GRIP_ITERATIONS, SPARSE_GRIP_ROWS, SPARSE_GRIP_TOL, SPARSE_GRIP_TOP_STEPS,
    SPARSE_GRIP_TOP_TOL, SPARSE_GRIP_TOP_WARM_STEPS,
};
use nalgebra::DMatrix;

use super::condition::{block_condition_bound, dependent_condition};

/// Approximate eigenvectors of `G_v G_vᵀ` (each of length `nc`, or empty: unknown) carried
/// from one output to the next: `λ_max`'s, the dependent block's `σ_min(G_D)` left singular
/// vector, `λ_min`'s.
#[derive(Clone, Debug, Default)]
pub struct SpectralHints {
    top: Vec<f64>,
    block: Vec<f64>,
    smallest: Vec<f64>,
}

/// The velocity Jacobian `G_v` (`nc × nv`) at one state as the index-1 DAE's checks read it:
/// dense below [`SPARSE_GRIP_ROWS`] rows (the singular values of [`dependent_condition`] and
/// [`block_condition_bound`]), by its non-zeros from there on, where
///
/// ```text
///   σ_max(G_v)² = λ_max(G_v G_vᵀ),   σ_min(G_v)² = λ_min(G_v G_vᵀ),   σ_min(G_D)² = λ_min(G_D G_Dᵀ)
/// ```
///
/// come from Lanczos iterations ([`crate::dae::gram::lanczos_largest`]: on the inverse of the sparse
/// Gram matrix through its Cholesky factor for `λ_min`, [`crate::dae::gram::SparseGram`]; on the
/// products `G_v (G_vᵀ x)` for `λ_max`), so that `μ(D) = σ_max(G_v) / σ_min(G_D)`
/// and `κ(G_v)` cost time linear in the non-zeros of a chain-like mechanism. Where a sparse
/// factorisation fails (a rank loss: the Gram matrix not numerically positive definite) or an
/// iteration does not converge, the dense singular values decide. The dense `G_v` is built only
/// where a check needs it ([`JointRows::dense`]: a fresh selection of dependent velocities).
#[derive(Clone, Debug)]
pub struct JointRows {
    shape: (usize, usize),
    sparse: bool,
    /// Non-zeros `(row, column, value)` in row-major order (the sparse path only).
    entries: Vec<(usize, usize, f64)>,
    dense: Option<DMatrix<f64>>,
    /// `λ_max(G_v G_vᵀ)` once computed on the sparse path (`None` inside: failed).
    top: Option<Option<f64>>,
    /// `λ_min(G_v G_vᵀ)` once computed on the sparse path (`None` inside: failed).
    bottom: Option<Option<f64>>,
    /// Vectors whose Rayleigh quotients `‖G_vᵀ u‖² / ‖u‖²` bound `λ_min(G_v G_vᵀ)` from
    /// above (the sparse path): the dependent block's left singular vector for `σ_min(G_D)`,
    /// the caller's hint (`λ_min`'s eigenvector at an earlier state), and the eigenvector once
    /// `λ_min` is computed here.
    block_vector: Vec<f64>,
    hint: Vec<f64>,
    bottom_vector: Vec<f64>,
    /// `σ_min(G_D)²` of a block `D`, computed here or known to the caller
    /// ([`Self::with_block_smallest`]).
    block_known: Option<(Vec<usize>, f64)>,
    /// Start vectors for the Lanczos iterations, from an earlier state of the same rows
    /// ([`Self::with_hints`]): `λ_max(G_v G_vᵀ)`'s eigenvector and the dependent block's
    /// singular vector; replaced by this state's once computed.
    top_vector: Vec<f64>,
}

impl JointRows {
    /// `G_v` of `tape` at `(t, x)`, `x = [q, v]`.
    pub fn new(tape: &crate::dae::MatrixTape, t: f64, x: &[f64]) -> Self {
        if tape.rows >= SPARSE_GRIP_ROWS {
            Self::from_entries((tape.rows, tape.cols), tape.entries(t, x))
        } else {
            Self::from_dense(tape.matrix(t, x))
        }
    }

    /// The dense `gv` (the dense path whatever its size).
    pub fn from_dense(gv: DMatrix<f64>) -> Self {
        Self::unmeasured(gv.shape(), Vec::new(), Some(gv))
    }

    /// The `nc × nv` matrix of the non-zeros `entries` (row-major; the sparse path whatever
    /// its size).
    pub fn from_entries(shape: (usize, usize), entries: Vec<(usize, usize, f64)>) -> Self {
        Self::unmeasured(shape, entries, None)
    }

    /// The rows with nothing measured yet: sparse where `dense` is `None`.
    fn unmeasured(
        shape: (usize, usize),
        entries: Vec<(usize, usize, f64)>,
        dense: Option<DMatrix<f64>>,
    ) -> Self {
        JointRows {
            shape,
            sparse: dense.is_none(),
            entries,
            dense,
            top: None,
            bottom: None,
            block_vector: Vec::new(),
            hint: Vec::new(),
            bottom_vector: Vec::new(),
            block_known: None,
            top_vector: Vec::new(),
        }
    }

    /// Whether the measures come from the non-zeros.
    pub fn is_sparse(&self) -> bool {
        self.sparse
    }

    /// `(rows, columns)`.
    pub fn shape(&self) -> (usize, usize) {
        self.shape
    }

    /// The dense `G_v` (built from the non-zeros the first time on the sparse path).
    pub fn dense(&mut self) -> &DMatrix<f64> {
        let (shape, entries) = (self.shape, &self.entries);
        self.dense.get_or_insert_with(|| {
            let mut m = DMatrix::zeros(shape.0, shape.1);
            for &(i, j, v) in entries {
                m[(i, j)] = v;
            }
            m
        })
    }

    /// The non-zeros `(row, column, value)`, row-major (empty on the dense path).
    pub fn entries(&self) -> &[(usize, usize, f64)] {
        &self.entries
    }

    /// `λ_max(G_v G_vᵀ)` by Lanczos on the products `x ↦ G_v (G_vᵀ x)` from the non-zeros
    /// (no Gram matrix formed; computed once), at most [`SPARSE_GRIP_TOP_STEPS`] steps.
    fn top_eigenvalue(&mut self) -> Option<f64> {
        let (m, n) = self.shape;
        let entries = &self.entries;
        if let Some(top) = self.top {
            return top;
        }
        let (start, steps) = if self.top_vector.len() == m {
            (
                std::mem::take(&mut self.top_vector),
                SPARSE_GRIP_TOP_WARM_STEPS,
            )
        } else {
            (crate::dae::gram::start_vector(m), SPARSE_GRIP_TOP_STEPS)
        };
        let top_vector = &mut self.top_vector;
        *self.top.get_or_insert_with(|| {
            let mut w = vec![0.0; n];
            let (top, u) = crate::dae::gram::lanczos_largest_vector(
                |x, y| {
                    w.fill(0.0);
                    for &(i, j, v) in entries {
                        w[j] += v * x[i];
                    }
                    y.fill(0.0);
                    for &(i, j, v) in entries {
                        y[i] += v * w[j];
                    }
                },
                &start,
                SPARSE_GRIP_TOP_TOL,
                steps,
            );
            *top_vector = u;
            (top.theta.is_finite() && top.theta > 0.0).then_some(top.theta)
        })
    }

    /// `λ_min(G_v G_vᵀ)` from the sparse Gram matrix's Cholesky factor (computed once).
    fn bottom_eigenvalue(&mut self) -> Option<f64> {
        let (m, n) = self.shape;
        if self.bottom.is_none() {
            let pair =
                crate::dae::gram::SparseGram::from_entries(m, n, &self.entries, &vec![1.0; n])
                    .and_then(|g| g.smallest_eigenpair(SPARSE_GRIP_TOL, SPARSE_GRIP_ITERATIONS));
            self.bottom = Some(pair.map(|(l, u)| {
                self.bottom_vector = u;
                l
            }));
        }
        self.bottom.flatten()
    }

    /// The spectral vectors of an earlier state of the same rows ([`Self::hints`]): the
    /// Lanczos iterations start from them (a smooth motion then needs a few steps), and
    /// [`Self::no_block_much_better`] tries `λ_min`'s eigenvector's Rayleigh quotient before
    /// factoring the Gram matrix.
    pub fn with_hints(mut self, hints: SpectralHints) -> Self {
        self.top_vector = hints.top;
        self.block_vector = hints.block;
        self.hint = hints.smallest;
        self
    }

    /// `G_v` whose block `G_v[:, D]` (`D = dependent`) has `σ_min(G_D)² = smallest`, as the
    /// caller knows it from an earlier state with the very same block (bit for bit: a pinned
    /// chain's dependent translations): [`Self::dependent_condition_with`] then takes it
    /// instead of its Lanczos iteration on the block's LU.
    pub fn with_block_smallest(mut self, dependent: &[usize], smallest: f64) -> Self {
        self.block_known = Some((dependent.to_vec(), smallest));
        self
    }

    /// `σ_min(G_D)²` of the block `D` ([`Self::dependent_condition_with`] computed it, or it
    /// was given), if known.
    pub fn block_smallest(&self, dependent: &[usize]) -> Option<f64> {
        self.block_known
            .as_ref()
            .filter(|(d, _)| d[..] == dependent[..])
            .map(|k| k.1)
    }

    /// The best vectors known at this state, for the next state's [`Self::with_hints`]: each
    /// one computed here, or else the one given.
    pub fn hints(&mut self) -> SpectralHints {
        SpectralHints {
            top: std::mem::take(&mut self.top_vector),
            block: std::mem::take(&mut self.block_vector),
            smallest: if self.bottom_vector.is_empty() {
                std::mem::take(&mut self.hint)
            } else {
                std::mem::take(&mut self.bottom_vector)
            },
        }
    }

    /// The dependent block's grip `μ(D) = σ_max(G_v) / σ_min(G_D)` ([`dependent_condition`]).
    pub fn dependent_condition(&mut self, dependent: &[usize]) -> f64 {
        self.dependent_condition_with(dependent, None)
    }

    /// [`Self::dependent_condition`], on the sparse path with `lu`, the sparse LU of
    /// `G_D = G_v[:, D]` at this state where the caller has it (factored here otherwise):
    /// `σ_min(G_D)² = 1 / λ_max(G_D⁻ᵀ G_D⁻¹)` ([`block_smallest_squared`]).
    pub fn dependent_condition_with(
        &mut self,
        dependent: &[usize],
        lu: Option<&faer::sparse::linalg::solvers::Lu<usize, f64>>,
    ) -> f64 {
        let (m, _) = self.shape;
        if self.is_sparse() && m > 0 && dependent.len() == m {
            let lmax = self.top_eigenvalue();
            let known = self
                .block_known
                .as_ref()
                .filter(|(d, _)| d[..] == dependent[..])
                .map(|k| k.1);
            let lmin_d = match known {
                Some(l) => Some(l),
                None => {
                    let own = match lu {
                        Some(_) => None,
                        None => block_lu(self.shape, &self.entries, dependent, &mut None),
                    };
                    let start = std::mem::take(&mut self.block_vector);
                    let l = lu
                        .or(own.as_ref())
                        .and_then(|lu| block_smallest_squared(lu, m, &start))
                        .map(|(l, u)| {
                            self.block_vector = u;
                            l
                        });
                    if let Some(l) = l {
                        self.block_known = Some((dependent.to_vec(), l));
                    }
                    l
                }
            };
            if let Some((lmax, lmin_d)) = lmax.zip(lmin_d) {
                return if lmin_d <= 0.0 {
                    f64::INFINITY
                } else {
                    (lmax / lmin_d).sqrt()
                };
            }
        }
        dependent_condition(self.dense(), dependent)
    }

    /// Whether no block of dependent velocities can be `gain` times better gripped than
    /// `cond`, i.e. `cond ≤ gain · κ(G_v)` ([`Self::condition_bound`]: `κ(G_v)` bounds every
    /// block's grip from below).
    ///
    /// On the sparse path a lower bound of `κ(G_v)` decides first, at the cost of one product
    /// with `G_vᵀ`: `κ(G_v)² = λ_max / λ_min(G_v G_vᵀ) ≥ θ / ‖G_vᵀ u‖²`, with `θ` the Lanczos
    /// value of `λ_max` (a lower bound) and `u` any vector: the last dependent block's
    /// singular vector for `σ_min(G_D)` (`‖G_vᵀ u‖² = σ_min(G_D)² + ‖G_Iᵀ u‖²`), or the hint,
    /// `λ_min`'s eigenvector at an earlier output ([`Self::with_hints`]) — a Rayleigh quotient
    /// bounds `λ_min` from above. Where the motion is smooth the hint's bound is nearly sharp
    /// and no Gram matrix is factored; otherwise `κ(G_v)` itself decides.
    pub fn no_block_much_better(&mut self, cond: f64, gain: f64) -> bool {
        let within = |bound: f64| cond * (1.0 + 1e-9) <= gain * bound;
        let m = self.shape.0;
        if self.is_sparse() && (self.block_vector.len() == m || self.hint.len() == m) {
            if let Some(theta) = self.top_eigenvalue() {
                let mut w = vec![0.0; self.shape.1];
                let mut rq_min = f64::INFINITY;
                for u in [&self.block_vector, &self.hint] {
                    let uu = u.iter().map(|x| x * x).sum::<f64>();
                    if u.len() != m || uu.is_nan() || uu <= 0.0 {
                        continue;
                    }
                    w.fill(0.0);
                    for &(i, j, v) in &self.entries {
                        w[j] += v * u[i];
                    }
                    rq_min = rq_min.min(w.iter().map(|x| x * x).sum::<f64>() / uu);
                }
                if rq_min > 0.0 && rq_min.is_finite() && within((theta / rq_min).sqrt()) {
                    return true;
                }
            }
        }
        within(self.condition_bound())
    }

    /// The lower bound `κ(G_v)` of every block's grip ([`block_condition_bound`]).
    pub fn condition_bound(&mut self) -> f64 {
        let (m, n) = self.shape;
        if m == 0 || m > n {
            return 0.0;
        }
        if self.is_sparse() {
            if let Some((lmin, lmax)) = self.bottom_eigenvalue().zip(self.top_eigenvalue()) {
                return if lmin <= 0.0 {
                    f64::INFINITY
                } else {
                    (lmax / lmin).sqrt()
                };
            }
        }
        block_condition_bound(self.dense())
    }

    /// The joints' condition number `κ(G_v M⁺ G_vᵀ)` ([`super::joint_condition_number`], its
    /// sparse path from the non-zeros here).
    pub fn joint_condition_number(&mut self, mass: &[f64]) -> f64 {
        if self.is_sparse() {
            let kappa =
                super::singular::sparse_joint_condition_number_of(self.shape, &self.entries, mass);
            return kappa
                .unwrap_or_else(|| super::dense_joint_condition_number(self.dense(), mass));
        }
        super::joint_condition_number(self.dense(), mass)
    }
}

/// faer's sparse LU of the square block `G_v[:, D]` (`nc × nc`, `D` ordered as given) of the
/// `nc × nv` matrix with the non-zeros `entries`, with the symbolic factorisation `symbolic`
/// of its pattern (computed and kept there when `None`: the pattern of a partition's block is
/// fixed). `None` when `D` is not `nc` columns of the matrix or the factorisation fails (a
/// structurally or numerically singular block).
pub fn block_lu(
    (nc, nv): (usize, usize),
    entries: &[(usize, usize, f64)],
    dependent: &[usize],
    symbolic: &mut Option<faer::sparse::linalg::solvers::SymbolicLu<usize>>,
) -> Option<faer::sparse::linalg::solvers::Lu<usize, f64>> {
    if dependent.len() != nc {
        return None;
    }
    let mut local = vec![usize::MAX; nv];
    for (k, &j) in dependent.iter().enumerate() {
        *local.get_mut(j)? = k;
    }
    let block: Vec<(usize, usize, f64)> = entries
        .iter()
        .filter(|e| local[e.1] != usize::MAX)
        .map(|&(i, j, v)| (i, local[j], v))
        .collect();
    factor_block(nc, &block, symbolic)
}

/// faer's sparse LU of the `nc × nc` matrix with the non-zeros `block` (`(row, column, value)`),
/// the symbolic factorisation kept in `symbolic` as in [`block_lu`].
fn factor_block(
    nc: usize,
    block: &[(usize, usize, f64)],
    symbolic: &mut Option<faer::sparse::linalg::solvers::SymbolicLu<usize>>,
) -> Option<faer::sparse::linalg::solvers::Lu<usize, f64>> {
    use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
    use faer::sparse::{SparseColMat, Triplet};
    let triplets: Vec<Triplet<usize, usize, f64>> = block
        .iter()
        .map(|&(i, k, v)| Triplet::new(i, k, v))
        .collect();
    let b = SparseColMat::<usize, f64>::try_new_from_triplets(nc, nc, &triplets).ok()?;
    let symbolic = match symbolic {
        Some(s) => s.clone(),
        None => symbolic
            .insert(SymbolicLu::try_new(b.symbolic()).ok()?)
            .clone(),
    };
    Lu::try_new_with_symbolic(symbolic, b.as_ref()).ok()
}

/// [`block_lu`] for a partition's block, its factors kept with the block's entries they
/// factor: where the block's entries are the same again, bit for bit, the kept factors are the
/// block's (a pinned chain's dependent translations: rows of constant ±1, the same block at
/// every step), and nothing is factored. The symbolic factorisation is kept as [`block_lu`]
/// keeps it (the pattern of a partition's block is fixed).
#[derive(Default)]
pub struct KeptBlockLu {
    symbolic: Option<faer::sparse::linalg::solvers::SymbolicLu<usize>>,
    /// The dependent columns and each column's place in the block (`usize::MAX`: not in it).
    dependent: Vec<usize>,
    local: Vec<usize>,
    /// The block's entries `(row, place, value)` the kept factors are of.
    block: Vec<(usize, usize, f64)>,
    lu: Option<std::sync::Arc<faer::sparse::linalg::solvers::Lu<usize, f64>>>,
    /// Factorisations done.
    pub factored: u64,
    /// Calls the kept factors answered.
    pub kept: u64,
}

impl KeptBlockLu {
    /// The LU of `G[:, D]` ([`block_lu`]) for the `nc × nv` matrix with the non-zeros
    /// `entries` and `D = dependent`: the kept factors where the block's entries are those
    /// they factor.
    pub fn lu(
        &mut self,
        (nc, nv): (usize, usize),
        entries: &[(usize, usize, f64)],
        dependent: &[usize],
    ) -> Option<std::sync::Arc<faer::sparse::linalg::solvers::Lu<usize, f64>>> {
        if dependent.len() != nc || dependent.iter().any(|&j| j >= nv) {
            return None;
        }
        if self.dependent != dependent || self.local.len() != nv {
            *self = KeptBlockLu {
                factored: self.factored,
                kept: self.kept,
                ..KeptBlockLu::default()
            };
            self.dependent = dependent.to_vec();
            self.local = vec![usize::MAX; nv];
            for (k, &j) in dependent.iter().enumerate() {
                self.local[j] = k;
            }
        }
        let local = &self.local;
        let mut in_block = entries
            .iter()
            .filter(|e| local[e.1] != usize::MAX)
            .map(|&(i, j, v)| (i, local[j], v));
        let same = self.lu.is_some() && {
            let mut kept = self.block.iter();
            in_block.by_ref().all(|(i, k, v)| {
                kept.next()
                    .is_some_and(|&(i0, k0, v0)| i0 == i && k0 == k && v0.to_bits() == v.to_bits())
            }) && kept.next().is_none()
        };
        if same {
            self.kept += 1;
            return self.lu.clone();
        }
        self.block.clear();
        self.block.extend(
            entries
                .iter()
                .filter(|e| local[e.1] != usize::MAX)
                .map(|&(i, j, v)| (i, local[j], v)),
        );
        self.factored += 1;
        self.lu = factor_block(nc, &self.block, &mut self.symbolic).map(std::sync::Arc::new);
        if self.lu.is_none() {
            self.block.clear();
        }
        self.lu.clone()
    }
}

/// `σ_min(B)² = λ_min(B Bᵀ) = 1 / λ_max(B⁻ᵀ B⁻¹)` of the `n × n` matrix `B` factored as `lu`:
/// Lanczos ([`crate::dae::gram::lanczos_largest`], relative accuracy [`SPARSE_GRIP_TOL`]) on
/// `x ↦ B⁻ᵀ (B⁻¹ x)`, two triangular solve pairs per step, and its Ritz vector `u` (the left
/// singular vector for `σ_min(B)`: `B Bᵀ u ≈ σ_min² u`), from `start` (that vector at an
/// earlier state, or anything else of length `n`: a fixed start then). `None` when the
/// iteration does not converge or meets a non-finite value.
pub fn block_smallest_squared(
    lu: &faer::sparse::linalg::solvers::Lu<usize, f64>,
    n: usize,
    start: &[f64],
) -> Option<(f64, Vec<f64>)> {
    use faer::linalg::solvers::SolveCore;
    use faer::{Conj, MatMut};
    let (top, u) = crate::dae::gram::lanczos_largest_vector(
        |x, y| {
            y.copy_from_slice(x);
            lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(y, n, 1));
            lu.solve_transpose_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(y, n, 1),
            );
        },
        &if start.len() == n {
            start.to_vec()
        } else {
            crate::dae::gram::start_vector(n)
        },
        SPARSE_GRIP_TOL,
        SPARSE_GRIP_ITERATIONS,
    );
    (top.converged && top.theta > 0.0).then(|| (1.0 / top.theta, u))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::partition::{
        dependent_condition_bound, dependent_condition_bound_factors, select_dependent,
    };

    #[test]
    fn preferred_columns_are_taken_first_when_they_suffice() {
        // rows: a pin (x, y) on a bar with velocities (vx, vy, ω): G = [[1, 0, -s], [0, 1, c]]
        let g = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, -0.3, 0.0, 1.0, 0.4]);
        assert_eq!(select_dependent(&g, &[true, true, false]), Some(vec![0, 1]));
    }

    #[test]
    fn a_rotation_is_taken_when_the_translations_cannot_complete_the_set() {
        // the two rows only involve vx and ω: vy cannot help
        let g = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.5, 2.0, 0.0, -1.0]);
        assert_eq!(select_dependent(&g, &[true, true, false]), Some(vec![0, 2]));
    }

    #[test]
    fn rank_deficient_rows_have_no_dependent_set() {
        let g = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0]);
        assert_eq!(select_dependent(&g, &[true, true, true]), None);
    }

    /// Pseudo-random numbers in [−0.5, 0.5) (xorshift64) from `seed`.
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// `G_D x` for the block `D` of the matrix with the non-zeros `entries`.
    fn block_times(entries: &[(usize, usize, f64)], dependent: &[usize], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; dependent.len()];
        for &(i, j, v) in entries {
            if let Some(k) = dependent.iter().position(|&d| d == j) {
                y[i] += v * x[k];
            }
        }
        y
    }

    #[test]
    fn a_kept_block_lu_is_factored_again_only_when_the_blocks_entries_change() {
        use faer::linalg::solvers::SolveCore;
        use faer::{Conj, MatMut};
        // a 4 × 6 chain-like matrix: the block of columns 0, 2, 3, 5 is bidiagonal, columns
        // 1 and 4 change between the calls (as a pinned chain's rotations do)
        let at = |c1: f64, c4: f64| {
            vec![
                (0, 0, 1.0),
                (0, 1, c1),
                (1, 0, -1.0),
                (1, 2, 1.0),
                (1, 4, c4),
                (2, 2, -1.0),
                (2, 3, 2.0),
                (3, 3, -1.0),
                (3, 4, 0.5 * c4),
                (3, 5, 3.0),
            ]
        };
        let dependent = [0, 2, 3, 5];
        let b = [1.0, -2.0, 0.5, 4.0];
        let solve = |lu: &faer::sparse::linalg::solvers::Lu<usize, f64>| {
            let mut x = b.to_vec();
            lu.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut x, 4, 1),
            );
            x
        };
        let mut kept = KeptBlockLu::default();
        let first = kept.lu((4, 6), &at(0.3, -0.7), &dependent).unwrap();
        let again = kept.lu((4, 6), &at(1.9, 0.2), &dependent).unwrap();
        assert_eq!((kept.factored, kept.kept), (1, 1));
        assert!(std::sync::Arc::ptr_eq(&first, &again));
        // the block changes: factored again, and its solution solves the new block
        let mut changed = at(1.9, 0.2);
        changed[6].2 = 5.0;
        let fresh = kept.lu((4, 6), &changed, &dependent).unwrap();
        assert_eq!((kept.factored, kept.kept), (2, 1));
        for (entries, lu) in [(at(0.3, -0.7), &first), (changed, &fresh)] {
            let x = solve(lu);
            let r = block_times(&entries, &dependent, &x);
            for (ri, bi) in r.iter().zip(&b) {
                assert!((ri - bi).abs() < 1e-13, "G_D x = {r:?}, b = {b:?}");
            }
        }
        // another set of dependent columns is a new block
        let other = kept.lu((4, 6), &at(0.3, -0.7), &[0, 2, 4, 5]).unwrap();
        assert_eq!(kept.factored, 3);
        let x = solve(&other);
        let r = block_times(&at(0.3, -0.7), &[0, 2, 4, 5], &x);
        assert!(r.iter().zip(&b).all(|(ri, bi)| (ri - bi).abs() < 1e-13));
    }

    #[test]
    fn the_grip_bound_lies_between_the_grip_and_the_rows_eighth_root_times_it() {
        // μ(D) ≤ bound ≤ m^(1/8) μ(D), μ from the singular values (nalgebra's SVD), on
        // pseudo-random rows of every size up to 16 and blocks from well to badly gripped
        let mut next = uniform(0x2545_f491_4f6c_dd1d);
        for m in 1..=16 {
            for weak in [1.0, 1e-2, 1e-5] {
                let n = m + 1 + m % 3;
                let mut g = DMatrix::from_fn(m, n, |_, _| next());
                // the block's last column nearly a combination of the others
                for i in 0..m {
                    let c = if m > 1 { g[(i, 0)] } else { 0.0 };
                    g[(i, m - 1)] = c + weak * g[(i, m - 1)];
                }
                let d: Vec<usize> = (0..m).collect();
                let mu = dependent_condition(&g, &d);
                let bound = dependent_condition_bound(&g, &d);
                let top = (m as f64).powf(0.125) * mu;
                assert!(
                    bound >= mu * (1.0 - 1e-9) && bound <= top * (1.0 + 1e-9),
                    "m = {m}, weak {weak}: μ = {mu:e}, bound {bound:e}, at most {top:e}"
                );
            }
        }
        // a singular block, a block of the wrong size, no rows
        let g = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 0.0, 2.0, 4.0, 1.0]);
        assert_eq!(dependent_condition_bound(&g, &[0, 1]), f64::INFINITY);
        assert_eq!(dependent_condition_bound(&g, &[0]), f64::INFINITY);
        assert_eq!(dependent_condition_bound(&DMatrix::zeros(0, 3), &[]), 1.0);
    }

    #[test]
    fn the_grip_at_a_nearby_configuration_is_bounded_by_the_factors_and_the_move() {
        // μ(G + Δ) ≤ (a + ‖Δ‖_F) / (1/b − ‖Δ‖_F), μ from nalgebra's SVD, for moves up to
        // where the bound stops (‖Δ‖_F → 1/b)
        let mut next = uniform(0x9e37_79b9_7f4a_7c15);
        for m in [1, 2, 4, 7, 12] {
            let n = m + 2;
            let g = DMatrix::from_fn(m, n, |_, _| next());
            let d: Vec<usize> = (0..m).collect();
            let (a, b) = dependent_condition_bound_factors(&g, &d).expect("a regular block");
            for size in [1e-6, 1e-3, 0.1, 0.5, 0.9] {
                let mut delta = DMatrix::from_fn(m, n, |_, _| next());
                delta *= size / (b * delta.norm());
                let moved = delta.norm();
                let bound = (a + moved) / (1.0 / b - moved);
                let mu = dependent_condition(&(&g + &delta), &d);
                assert!(
                    mu <= bound * (1.0 + 1e-12),
                    "m = {m}, ‖Δ‖ b = {size}: μ = {mu:e} > {bound:e}"
                );
            }
        }
        assert_eq!(
            dependent_condition_bound_factors(&DMatrix::zeros(0, 3), &[]),
            None
        );
    }

    #[test]
    fn grip_of_the_dependent_block_is_the_rows_largest_over_the_blocks_smallest_singular_value() {
        // G_v = [[1, 0, 5], [0, 1e-3, 7]], block D = {0, 1} = diag(1, 1e-3): σ_min = 1e-3;
        // σ_max(G_v)² is the larger eigenvalue of G_v G_vᵀ = [[26, 35], [35, 49 + 1e-6]]
        let g = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 5.0, 0.0, 1e-3, 7.0]);
        let (a, b, d) = (26.0f64, 35.0f64, 49.0 + 1e-6);
        let lmax = 0.5 * (a + d + ((a - d).powi(2) + 4.0 * b * b).sqrt());
        let expected = lmax.sqrt() / 1e-3;
        let c = dependent_condition(&g, &[0, 1]);
        assert!((c / expected - 1.0).abs() < 1e-12, "{c} vs {expected}");
        // at least the block's own condition number, 1e3
        assert!(c >= 1e3);
    }
}
