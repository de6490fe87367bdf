//! Sparse Newton matrices: a compressed-sparse-column pattern fixed once per problem, the
//! SUNDIALS CSC `SUNMatrix` the Jacobian callbacks fill, and two sparse direct solvers for it.
//!
//! IDA's iteration matrix `J = ∂F/∂y + cj ∂F/∂y'` (and CVODE's `M = I − γ ∂f/∂y`) of a
//! mechanism has a few entries per row, so it is stored as CSC (`colptr`, `rowidx`, values)
//! and factored `P J Q = L U` by a sparse LU:
//!
//! * [`SparseSolver::Faer`]: faer's sparse LU (COLAMD column ordering, or the cheapest of
//!   three orders, [`ColumnOrdering`]; partial pivoting by rows), wrapped here as a custom
//!   *matrix-direct* `SUNLinearSolver`: the symbolic analysis runs once per pattern (again
//!   only if the pattern seen at a setup differs), and every `setup` refactors numerically
//!   with the current values;
//! * [`SparseSolver::Klu`]: SUNDIALS' own `SUNLinSol_KLU` (SuiteSparse KLU, from Debian's
//!   `libsundials-dev`), which likewise analyses once and refactors.
//!
//! Both are *matrix-based* solvers, so the integrators keep their usual Jacobian reuse
//! (IDA re-evaluates `J` only when `cj` changed enough or Newton failed; CVODE reuses
//! `∂f/∂y` across steps and re-forms `I − γJ`) exactly as with the dense solver.
//!
//! The pattern always contains the diagonal: CVODE's `SUNMatScaleAddI` then adds `I` in
//! place (it would otherwise re-allocate with a new pattern), and an explicit zero on the
//! diagonal costs nothing.

use super::context::Context;
use super::error::SolverError;
use super::linsol::{self, LinearSolver, Matrix, OwnLinearSolver};
use super::vector::NVector;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::simplicial::{
    self, factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch, SimplicialLu,
};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use std::os::raw::c_int;
use sundials_sys as sys;

/// How faer's sparse LU orders the columns of the Newton matrix ([`SparseSolver::Faer`]; KLU
/// keeps its own).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColumnOrdering {
    /// COLAMD, faer's own choice: it minimises the fill of the Cholesky factor of `AᵀA`, a
    /// bound on the fill of `L` and `U` under any row pivoting.
    #[default]
    Colamd,
    /// The cheapest of COLAMD, Cuthill–McKee and reverse Cuthill–McKee on the pattern of
    /// `A + Aᵀ` ([`cuthill_mckee`]), by the multiply–adds of each one's numeric factorisation of
    /// the first matrix after a symbolic analysis ([`lu_flops`]; the row pivoting, and so the
    /// fill, depends on the values). The factorisation is then faer's simplicial LU
    /// (left-looking, partial pivoting by rows) in that column order.
    ///
    /// Bound on COLAMD's, which does not see the pivoting: for the index-1 DAE of a chain
    /// (`crate::solve::formulation::index1`), whose acceleration rows have no entry in their multipliers'
    /// columns, COLAMD's order costs 1.6 times the multiply–adds of Cuthill–McKee's (N-link
    /// pendulum, N = 256: 98 600 against 52 000), while for the GGL DAE of the same chain
    /// COLAMD's is already the cheapest of the three.
    Cheapest,
}

/// Which sparse LU factors the Newton matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SparseSolver {
    /// faer's sparse LU through our custom `SUNLinearSolver`.
    Faer,
    /// SUNDIALS' `SUNLinSol_KLU` (SuiteSparse KLU).
    Klu,
}

/// A square sparsity pattern in compressed sparse column form: the row indices of column `j`
/// are `rowidx[colptr[j]..colptr[j+1]]`, sorted and unique. Always holds the diagonal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CscPattern {
    n: usize,
    colptr: Vec<usize>,
    rowidx: Vec<usize>,
}

impl CscPattern {
    /// The pattern of an `n × n` matrix with the given `(row, col)` entries (repeats allowed)
    /// and the diagonal. An entry outside `n × n` is an [`SolverError::InvalidInput`].
    pub fn new(
        n: usize,
        entries: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<CscPattern, SolverError> {
        let mut cols: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
        for (r, c) in entries {
            if r >= n || c >= n {
                return Err(SolverError::InvalidInput(format!(
                    "sparsity pattern entry ({r}, {c}) lies outside the {n} × {n} matrix"
                )));
            }
            cols[c].push(r);
        }
        let mut colptr = Vec::with_capacity(n + 1);
        let mut rowidx = Vec::new();
        colptr.push(0);
        for mut col in cols {
            col.sort_unstable();
            col.dedup();
            rowidx.extend(col);
            colptr.push(rowidx.len());
        }
        Ok(CscPattern { n, colptr, rowidx })
    }

    /// Matrix dimension.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.rowidx.len()
    }

    /// Column pointers (`n + 1` of them).
    pub fn colptr(&self) -> &[usize] {
        &self.colptr
    }

    /// Row indices, column after column.
    pub fn rowidx(&self) -> &[usize] {
        &self.rowidx
    }

    /// Index into the values of entry `(row, col)`, if it is in the pattern.
    pub fn position(&self, row: usize, col: usize) -> Option<usize> {
        if col >= self.n {
            return None;
        }
        let (a, b) = (self.colptr[col], self.colptr[col + 1]);
        self.rowidx[a..b].binary_search(&row).ok().map(|k| a + k)
    }
}

/// Mutable view of the values of a sparse matrix with a [`CscPattern`].
pub struct SparseMatrixMut<'a> {
    pattern: &'a CscPattern,
    data: &'a mut [f64],
}

impl<'a> SparseMatrixMut<'a> {
    /// View of `data` (one value per pattern entry); `None` if the lengths differ.
    pub fn from_slice(pattern: &'a CscPattern, data: &'a mut [f64]) -> Option<Self> {
        (data.len() == pattern.nnz()).then_some(SparseMatrixMut { pattern, data })
    }

    /// The pattern.
    pub fn pattern(&self) -> &CscPattern {
        self.pattern
    }

    /// `A[i, j] += v`. Panics if `(i, j)` is not in the pattern (inside a Jacobian callback
    /// the panic is caught and stops the solve with an error naming the entry).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        match self.pattern.position(i, j) {
            Some(k) => self.data[k] += v,
            None => panic!("Jacobian entry ({i}, {j}) is not in the sparsity pattern"),
        }
    }

    /// `A[i, j] += v` for the entry stored at `slot` of the values ([`CscPattern::position`]
    /// of `(i, j)`, looked up once: no search). Panics if `slot` is not below the pattern's
    /// number of entries.
    pub fn add_at(&mut self, slot: usize, v: f64) {
        self.data[slot] += v;
    }

    /// `A[i, j]` (0 outside the pattern).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.pattern.position(i, j).map_or(0.0, |k| self.data[k])
    }

    /// Set every stored value to zero.
    pub fn fill_zero(&mut self) {
        self.data.fill(0.0);
    }

    /// The stored values, in pattern order.
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.data
    }
}

/// Owned CSC `SUNSparseMatrix` holding a [`CscPattern`], destroyed on drop.
pub(crate) struct SparseMatrix {
    raw: sys::SUNMatrix,
}

impl SparseMatrix {
    pub(crate) fn new(ctx: &Context, pattern: &CscPattern) -> Result<SparseMatrix, SolverError> {
        let n = pattern.n() as sys::sunindextype;
        // SAFETY: valid context, positive dimensions; NULL is checked below.
        let raw = unsafe {
            sys::SUNSparseMatrix(
                n,
                n,
                pattern.nnz().max(1) as sys::sunindextype,
                sys::CSC_MAT as c_int,
                ctx.raw(),
            )
        };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("SUNSparseMatrix failed".into()));
        }
        let m = SparseMatrix { raw };
        // SAFETY: `raw` is a live CSC matrix with room for the pattern's nnz entries.
        unsafe { write_pattern(raw, pattern) };
        Ok(m)
    }

    pub(crate) fn raw(&self) -> sys::SUNMatrix {
        self.raw
    }
}

impl Drop for SparseMatrix {
    fn drop(&mut self) {
        // SAFETY: `raw` came from SUNSparseMatrix and is destroyed exactly once.
        unsafe { sys::SUNMatDestroy(self.raw) }
    }
}

/// Writes `pattern`'s column pointers and row indices into a CSC `SUNMatrix`
/// (`SUNMatZero` clears them, so a Jacobian callback writes them back every time).
///
/// # Safety
/// `m` must be a live CSC sparse matrix with `n = pattern.n()` columns and capacity for at
/// least `pattern.nnz()` entries, not accessed elsewhere meanwhile.
pub(crate) unsafe fn write_pattern(m: sys::SUNMatrix, pattern: &CscPattern) {
    // SAFETY: guaranteed by the caller.
    unsafe {
        let n = pattern.n();
        let ptrs = std::slice::from_raw_parts_mut(sys::SUNSparseMatrix_IndexPointers(m), n + 1);
        for (d, s) in ptrs.iter_mut().zip(pattern.colptr()) {
            *d = *s as sys::sunindextype;
        }
        let nnz = pattern.nnz();
        if nnz > 0 {
            let rows = std::slice::from_raw_parts_mut(sys::SUNSparseMatrix_IndexValues(m), nnz);
            for (d, s) in rows.iter_mut().zip(pattern.rowidx()) {
                *d = *s as sys::sunindextype;
            }
        }
    }
}

/// View of the values of a CSC `SUNMatrix` holding `pattern`.
///
/// # Safety
/// As for [`write_pattern`]; the view must not outlive `m`.
pub(crate) unsafe fn values_of<'a>(m: sys::SUNMatrix, pattern: &CscPattern) -> &'a mut [f64] {
    // SAFETY: guaranteed by the caller.
    unsafe {
        let nnz = pattern.nnz();
        if nnz == 0 {
            return &mut [];
        }
        std::slice::from_raw_parts_mut(sys::SUNSparseMatrix_Data(m), nnz)
    }
}

// --- KLU -----------------------------------------------------------------------------------

// sundials-sys 0.6 binds `SUNLinSol_KLU` only with its `klu` feature, which pulls
// `suitesparse_sys` and makes sundials-sys build SUNDIALS from source with cmake (refused by
// this project, see build.rs). Debian's libsundials-dev ships the KLU solver as its own
// library, so we declare its one constructor here and link it from build.rs.
extern "C" {
    fn SUNLinSol_KLU(
        y: sys::N_Vector,
        a: sys::SUNMatrix,
        sunctx: sys::SUNContext,
    ) -> sys::SUNLinearSolver;
}

/// The sparse direct solver `kind` for the CSC matrix `a` (template vector `y`), faer's
/// ordering its columns by `ordering`.
pub(crate) fn new_sparse_solver(
    ctx: &Context,
    y: &NVector,
    a: &SparseMatrix,
    kind: SparseSolver,
    ordering: ColumnOrdering,
) -> Result<LinearSolver, SolverError> {
    match kind {
        SparseSolver::Klu => {
            // SAFETY: live serial vector, CSC matrix and context of matching size.
            let raw = unsafe { SUNLinSol_KLU(y.raw(), a.raw(), ctx.raw()) };
            if raw.is_null() {
                return Err(SolverError::InvalidInput("SUNLinSol_KLU failed".into()));
            }
            // SAFETY: built by SUNDIALS; its free op releases the KLU data.
            Ok(unsafe { LinearSolver::from_raw(raw) })
        }
        SparseSolver::Faer => new_faer_solver(ctx, ordering),
    }
}

// --- faer sparse LU as a SUNLinearSolver ---------------------------------------------------

/// Counters of the faer solver (for tests: the symbolic analysis runs once per pattern).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaerCounters {
    /// Symbolic analyses (column ordering, elimination structure).
    pub symbolic: u64,
    /// Numeric factorisations.
    pub numeric: u64,
    /// Of the numeric factorisations, those that kept the row pivot order of the last full one
    /// ([`ColumnOrdering::Cheapest`]: `StaticLu::refactor`, no pivot search).
    pub refactored: u64,
    /// Refactorisations given up on a pivot below [`REFACTOR_PIVOT_TOLERANCE`] times its
    /// column (a full factorisation with row pivoting followed).
    pub repivoted: u64,
}

/// State of the faer LU: the pattern it was analysed for, the symbolic and numeric factors.
struct FaerLu {
    colptr: Vec<usize>,
    rowidx: Vec<usize>,
    symbolic: Option<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    factored: bool,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    counters: FaerCounters,
    ordering: ColumnOrdering,
    /// [`ColumnOrdering::Cheapest`]: the simplicial LU in a column order of our choosing.
    ordered: Option<OrderedLu>,
}

/// faer's simplicial LU in a column order chosen among `candidates` at the first numeric
/// factorisation after a symbolic analysis ([`ColumnOrdering::Cheapest`]).
struct OrderedLu {
    /// Column orders still to compare (all of them until the first factorisation succeeds).
    candidates: Vec<Vec<usize>>,
    /// The column order kept, forward and inverse.
    col_fwd: Vec<usize>,
    col_inv: Vec<usize>,
    row_fwd: Vec<usize>,
    row_inv: Vec<usize>,
    lu: SimplicialLu<usize, f64>,
    /// The factors of the last factorisation with their patterns fixed (copied from `lu` after
    /// a full factorisation): later factorisations refactor into them in the same row and
    /// column orders, and the solves read them.
    fixed: Option<StaticLu>,
}

/// Smallest ratio `|u_jj| / max_{i>j} |l̃_ij|` (the pivot against the entries below it in its
/// column before division) a refactorisation in a kept row order accepts: threshold partial
/// pivoting's test (UMFPACK's default 0.1), which bounds each elimination step's growth by
/// `1 + 1/τ` as partial pivoting bounds it by 2. Below it the matrix is factored again with
/// row pivoting (KLU's `klu_refactor` keeps the order unchecked; SUNDIALS' KLU wrapper then
/// tests the reciprocal pivot growth).
pub const REFACTOR_PIVOT_TOLERANCE: f64 = 0.1;

/// An LU factorisation `P A Q = L U` whose patterns and row order `P` are those of a first
/// factorisation with partial pivoting, refactored numerically for new values of `A` (same
/// pattern) without a pivot search or a reach computation — the left-looking refactorisation
/// of Gilbert–Peierls with the reach known (KLU's `klu_refactor`):
///
/// ```text
///   x = (P A Q)[:, j];   for k ∈ U[:, j], k < j, increasing:  u_kj = x_k,  x_{i>k} −= l_ik u_kj
///   u_jj = x_j;   l_ij = x_i / u_jj  (i ∈ L[:, j])
/// ```
///
/// With `P` fixed, the structural reach of every column is the same as in the first
/// factorisation (it depends on the patterns of `A` and `L` only), so `L` and `U` keep their
/// patterns. Row indices are in the permuted numbering; `L` is unit lower triangular (its
/// diagonal not stored), `U`'s diagonal is `diag`.
#[derive(Clone, Debug)]
struct StaticLu {
    l_colptr: Vec<usize>,
    l_rows: Vec<usize>,
    l_vals: Vec<f64>,
    u_colptr: Vec<usize>,
    u_rows: Vec<usize>,
    u_vals: Vec<f64>,
    diag: Vec<f64>,
    work: Vec<f64>,
}

impl StaticLu {
    /// The factors of faer's simplicial LU (row indices already in the permuted numbering, the
    /// unit diagonal of `L` first in its column, `U`'s diagonal last in its column), `U`'s
    /// columns sorted by row.
    fn from_simplicial(lu: &SimplicialLu<usize, f64>, n: usize) -> StaticLu {
        let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
        let mut s = StaticLu {
            l_colptr: Vec::with_capacity(n + 1),
            l_rows: Vec::new(),
            l_vals: Vec::new(),
            u_colptr: Vec::with_capacity(n + 1),
            u_rows: Vec::new(),
            u_vals: Vec::new(),
            diag: vec![0.0; n],
            work: vec![0.0; n],
        };
        s.l_colptr.push(0);
        s.u_colptr.push(0);
        let mut col: Vec<(usize, f64)> = Vec::new();
        for j in 0..n {
            for (&i, &v) in l.row_idx_of_col_raw(j).iter().zip(l.val_of_col(j)) {
                if i != j {
                    s.l_rows.push(i);
                    s.l_vals.push(v);
                }
            }
            s.l_colptr.push(s.l_rows.len());
            col.clear();
            for (&i, &v) in u.row_idx_of_col_raw(j).iter().zip(u.val_of_col(j)) {
                if i == j {
                    s.diag[j] = v;
                } else {
                    col.push((i, v));
                }
            }
            col.sort_unstable_by_key(|e| e.0);
            s.u_rows.extend(col.iter().map(|e| e.0));
            s.u_vals.extend(col.iter().map(|e| e.1));
            s.u_colptr.push(s.u_rows.len());
        }
        // the solves and refactorisations index their work vector of n entries by these rows
        // unchecked: a factor of an n × n matrix has none beyond it
        assert!(
            s.l_rows.iter().chain(&s.u_rows).all(|&i| i < n),
            "faer's LU factors of an {n} x {n} matrix have a row index beyond it"
        );
        s
    }

    /// Refactors `a` (the pattern the factors were made for) in the column order `col_fwd` and
    /// the row order `row_inv` (original row → pivot position). `false` where a pivot fails
    /// [`REFACTOR_PIVOT_TOLERANCE`] (or is zero or not finite): the factors are then unusable.
    fn refactor(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        col_fwd: &[usize],
        row_inv: &[usize],
    ) -> bool {
        let n = self.diag.len();
        let x = &mut self.work[..n];
        for j in 0..n {
            let c = col_fwd[j];
            for (&i, &v) in a.row_idx_of_col_raw(c).iter().zip(a.val_of_col(c)) {
                x[row_inv[i]] += v;
            }
            let (u0, u1) = (self.u_colptr[j], self.u_colptr[j + 1]);
            for p in u0..u1 {
                let k = self.u_rows[p];
                let ukj = x[k];
                x[k] = 0.0;
                self.u_vals[p] = ukj;
                if ukj != 0.0 {
                    let (l0, l1) = (self.l_colptr[k], self.l_colptr[k + 1]);
                    for (&i, &l) in self.l_rows[l0..l1].iter().zip(&self.l_vals[l0..l1]) {
                        x[i] -= l * ukj;
                    }
                }
            }
            let pivot = x[j];
            x[j] = 0.0;
            self.diag[j] = pivot;
            let (l0, l1) = (self.l_colptr[j], self.l_colptr[j + 1]);
            let below = self.l_rows[l0..l1]
                .iter()
                .fold(0.0f64, |m, &i| m.max(x[i].abs()));
            if !(pivot.is_finite() && pivot != 0.0)
                || pivot.abs() < REFACTOR_PIVOT_TOLERANCE * below
            {
                x.fill(0.0);
                return false;
            }
            let inv = pivot.recip();
            for (&i, l) in self.l_rows[l0..l1].iter().zip(&mut self.l_vals[l0..l1]) {
                *l = x[i] * inv;
                x[i] = 0.0;
            }
        }
        true
    }

    /// Solves `A x = b` in place (`b` in, `x` out): `z = L⁻¹ P b`, `z = U⁻¹ z`, `x = Q z`.
    fn solve_in_place(&mut self, b: &mut [f64], row_fwd: &[usize], col_fwd: &[usize]) {
        let n = self.diag.len();
        let z = &mut self.work;
        for k in 0..n {
            z[k] = b[row_fwd[k]];
        }
        let z = &mut z[..n];
        for j in 0..n {
            let zj = z[j];
            if zj != 0.0 {
                let (l0, l1) = (self.l_colptr[j], self.l_colptr[j + 1]);
                for (&i, &l) in self.l_rows[l0..l1].iter().zip(&self.l_vals[l0..l1]) {
                    z[i] -= l * zj;
                }
            }
        }
        for j in (0..n).rev() {
            let zj = z[j] / self.diag[j];
            z[j] = zj;
            if zj != 0.0 {
                let (u0, u1) = (self.u_colptr[j], self.u_colptr[j + 1]);
                for (&k, &u) in self.u_rows[u0..u1].iter().zip(&self.u_vals[u0..u1]) {
                    z[k] -= u * zj;
                }
            }
        }
        for k in 0..n {
            b[col_fwd[k]] = z[k];
            z[k] = 0.0;
        }
    }
}

/// Cuthill–McKee order of the `n × n` pattern `(colptr, rowidx)` symmetrised, `A + Aᵀ`:
/// breadth first from a vertex of least degree, the neighbours of each vertex taken by
/// increasing degree (again from a least-degree vertex for each further component). On a
/// chain-like mechanism it numbers the unknowns along the chain, so that `L` and `U` stay
/// within a band of a few bodies' unknowns. Reversed when `reverse` (RCM).
pub fn cuthill_mckee(n: usize, colptr: &[usize], rowidx: &[usize], reverse: bool) -> Vec<usize> {
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
    for j in 0..n {
        for &i in &rowidx[colptr[j]..colptr[j + 1]] {
            if i != j {
                adj[i].push(j);
                adj[j].push(i);
            }
        }
    }
    for a in adj.iter_mut() {
        a.sort_unstable();
        a.dedup();
    }
    let deg: Vec<usize> = adj.iter().map(Vec::len).collect();
    for a in adj.iter_mut() {
        a.sort_by_key(|&w| (deg[w], w));
    }
    let mut by_degree: Vec<usize> = (0..n).collect();
    by_degree.sort_by_key(|&j| (deg[j], j));
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for &start in &by_degree {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let mut head = order.len();
        order.push(start);
        while head < order.len() {
            let v = order[head];
            head += 1;
            for &w in &adj[v] {
                if !seen[w] {
                    seen[w] = true;
                    order.push(w);
                }
            }
        }
    }
    if reverse {
        order.reverse();
    }
    order
}

/// Multiply–adds of a left-looking LU with the factors `L` and `U`: for each column `j` and
/// each `k ≠ j` in `U[:, j]`, the entries of `L[:, k]`.
pub fn lu_flops(
    n: usize,
    l: SparseColMatRef<'_, usize, f64>,
    u: SparseColMatRef<'_, usize, f64>,
) -> usize {
    (0..n)
        .map(|j| {
            u.row_idx_of_col_raw(j)
                .iter()
                .filter(|&&k| k != j)
                .map(|&k| l.row_idx_of_col_raw(k).len())
                .sum::<usize>()
        })
        .sum()
}

/// COLAMD's column order of the `n × n` pattern with faer's default controls (the order
/// `factorize_symbolic_lu` takes); `None` where it fails (out of memory).
fn colamd_order(n: usize, pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Vec<usize>> {
    use faer::sparse::linalg::colamd;
    let mut mem =
        MemBuffer::try_new(colamd::order_scratch::<usize>(n, n, pattern.compute_nnz())).ok()?;
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    colamd::order(
        &mut fwd,
        &mut inv,
        pattern,
        colamd::Control::default(),
        MemStack::new(&mut mem),
    )
    .ok()?;
    Some(fwd)
}

/// Factors `a` in the column order `fwd` into `ordered` (its row permutation and LU).
fn factor_ordered(
    ordered: &mut OrderedLu,
    a: SparseColMatRef<'_, usize, f64>,
    fwd: &[usize],
    inv: &[usize],
    mem: &mut MemBuffer,
) -> bool {
    let n = fwd.len();
    let perm = PermRef::new_checked(fwd, inv, n);
    let stack = MemStack::new(mem);
    factorize_simplicial_numeric_lu(
        &mut ordered.row_fwd,
        &mut ordered.row_inv,
        &mut ordered.lu,
        a,
        perm,
        stack,
    )
    .is_ok()
}

fn inverse(fwd: &[usize]) -> Vec<usize> {
    let mut inv = vec![0; fwd.len()];
    for (k, &p) in fwd.iter().enumerate() {
        inv[p] = k;
    }
    inv
}

/// [`faer_setup`] for [`ColumnOrdering::Cheapest`], the pattern current in `lu`.
fn faer_setup_ordered(lu: &mut FaerLu, n: usize, vals: &[f64]) -> c_int {
    let pattern = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &lu.colptr, None, &lu.rowidx);
    let a = SparseColMatRef::new(pattern, vals);
    let Some(ordered) = lu.ordered.as_mut() else {
        return -1;
    };
    lu.counters.numeric += 1;
    if ordered.candidates.is_empty() {
        // the row order of the last full factorisation, while its pivots hold
        if let Some(fixed) = ordered.fixed.as_mut() {
            if fixed.refactor(a, &ordered.col_fwd, &ordered.row_inv) {
                lu.counters.refactored += 1;
                lu.factored = true;
                return 0;
            }
            lu.counters.repivoted += 1;
        }
        let (fwd, inv) = (
            std::mem::take(&mut ordered.col_fwd),
            std::mem::take(&mut ordered.col_inv),
        );
        let ok = factor_ordered(ordered, a, &fwd, &inv, &mut lu.factor_mem);
        (ordered.col_fwd, ordered.col_inv) = (fwd, inv);
        ordered.fixed = ok.then(|| StaticLu::from_simplicial(&ordered.lu, n));
        lu.factored = ok;
        return if ok {
            0
        } else {
            sys::SUNLS_LUFACT_FAIL as c_int
        };
    }
    // the first factorisation: each candidate order, the one of fewest multiply-adds kept
    // (its factors are this setup's: the same factorisation done once more gave the same)
    type Probe = (
        usize,
        usize,
        Vec<usize>,
        Vec<usize>,
        SimplicialLu<usize, f64>,
    );
    let mut best: Option<Probe> = None;
    for (k, fwd) in ordered.candidates.iter().enumerate() {
        let inv = inverse(fwd);
        let (mut probe_fwd, mut probe_inv) = (vec![0; n], vec![0; n]);
        let mut probe = SimplicialLu::new();
        let stack = MemStack::new(&mut lu.factor_mem);
        let perm = PermRef::new_checked(fwd, &inv, n);
        if factorize_simplicial_numeric_lu(
            &mut probe_fwd,
            &mut probe_inv,
            &mut probe,
            a,
            perm,
            stack,
        )
        .is_ok()
        {
            let flops = lu_flops(n, probe.l_factor_unsorted(), probe.u_factor_unsorted());
            if best.as_ref().is_none_or(|b| flops < b.1) {
                best = Some((k, flops, probe_fwd, probe_inv, probe));
            }
        }
    }
    let Some((k, _, row_fwd, row_inv, probe)) = best else {
        lu.factored = false;
        return sys::SUNLS_LUFACT_FAIL as c_int;
    };
    let fwd = ordered.candidates.swap_remove(k);
    ordered.candidates.clear();
    let inv = inverse(&fwd);
    (ordered.col_fwd, ordered.col_inv) = (fwd, inv);
    (ordered.row_fwd, ordered.row_inv) = (row_fwd, row_inv);
    ordered.fixed = Some(StaticLu::from_simplicial(&probe, n));
    ordered.lu = probe;
    lu.factored = true;
    0
}

/// Reads the pattern of the CSC matrix `a` into `lu`, redoing the symbolic analysis if it
/// changed, then factors `a` numerically. Returns 0, or a positive (recoverable) code when
/// the matrix is singular, or -1 on an internal failure.
fn faer_setup(lu: &mut FaerLu, n: usize, ptrs: &[i64], rows: &[i64], vals: &[f64]) -> c_int {
    let same = lu.colptr.len() == ptrs.len()
        && lu.rowidx.len() == rows.len()
        && lu.colptr.iter().zip(ptrs).all(|(a, b)| *a as i64 == *b)
        && lu.rowidx.iter().zip(rows).all(|(a, b)| *a as i64 == *b);
    let analysed = match lu.ordering {
        ColumnOrdering::Colamd => lu.symbolic.is_some(),
        ColumnOrdering::Cheapest => lu.ordered.is_some(),
    };
    if !same || !analysed {
        lu.colptr = ptrs.iter().map(|&p| p as usize).collect();
        lu.rowidx = rows.iter().map(|&r| r as usize).collect();
        let pattern =
            SymbolicSparseColMatRef::new_unsorted_checked(n, n, &lu.colptr, None, &lu.rowidx);
        lu.counters.symbolic += 1;
        lu.factored = false;
        if lu.ordering == ColumnOrdering::Cheapest {
            // COLAMD's order alone (faer's symbolic LU, which starts with the same call with
            // the same defaults, also analyses the supernodes: a quarter of the first setup's
            // cost at N = 256, unused here); Cuthill–McKee's once, reversed for RCM
            let Some(colamd) = colamd_order(n, pattern) else {
                return -1;
            };
            let cm = cuthill_mckee(n, &lu.colptr, &lu.rowidx, false);
            let rcm: Vec<usize> = cm.iter().rev().copied().collect();
            lu.factor_mem =
                MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n));
            lu.solve_mem = MemBuffer::new(simplicial::solve_in_place_scratch::<usize, f64>(
                n,
                1,
                Par::Seq,
            ));
            lu.ordered = Some(OrderedLu {
                candidates: vec![colamd, cm, rcm],
                col_fwd: Vec::new(),
                col_inv: Vec::new(),
                row_fwd: vec![0; n],
                row_inv: vec![0; n],
                lu: SimplicialLu::new(),
                fixed: None,
            });
        } else {
            let symbolic = match factorize_symbolic_lu(pattern, Default::default()) {
                Ok(s) => s,
                Err(_) => return -1,
            };
            lu.factor_mem = MemBuffer::new(
                symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            );
            lu.solve_mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            lu.symbolic = Some(symbolic);
            lu.numeric = NumericLu::new();
        }
    }
    if lu.ordering == ColumnOrdering::Cheapest {
        return faer_setup_ordered(lu, n, vals);
    }
    let Some(symbolic) = lu.symbolic.as_ref() else {
        return -1;
    };
    let pattern = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &lu.colptr, None, &lu.rowidx);
    let a = SparseColMatRef::new(pattern, vals);
    lu.counters.numeric += 1;
    let stack = MemStack::new(&mut lu.factor_mem);
    match symbolic.factorize_numeric_lu(&mut lu.numeric, a, Par::Seq, stack, Default::default()) {
        Ok(_) => {
            lu.factored = true;
            0
        }
        Err(_) => {
            lu.factored = false;
            // SUNLS_LUFACT_FAIL: recoverable, the integrator retries with a smaller step
            sys::SUNLS_LUFACT_FAIL as c_int
        }
    }
}

fn faer_solve(lu: &mut FaerLu, x: &mut [f64]) -> c_int {
    if let Some(ordered) = lu.ordered.as_mut() {
        if !lu.factored {
            return -1;
        }
        let n = x.len();
        if let Some(fixed) = ordered.fixed.as_mut() {
            if ordered.row_fwd.len() != n || ordered.col_fwd.len() != n || fixed.diag.len() != n {
                return -1;
            }
            fixed.solve_in_place(x, &ordered.row_fwd, &ordered.col_fwd);
            return if x.iter().all(|v| v.is_finite()) {
                0
            } else {
                sys::SUNLS_PACKAGE_FAIL_REC as c_int
            };
        }
        // (every successful factorisation leaves its factors in `fixed`)
        return -1;
    }
    let (Some(symbolic), true) = (lu.symbolic.as_ref(), lu.factored) else {
        return -1;
    };
    let n = x.len();
    let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
    let stack = MemStack::new(&mut lu.solve_mem);
    LuRef::new_unchecked(symbolic, &lu.numeric).solve_in_place_with_conj(
        Conj::No,
        rhs,
        Par::Seq,
        stack,
    );
    if x.iter().all(|v| v.is_finite()) {
        0
    } else {
        // a numerically singular factor: recoverable, as the dense solver's zero pivot is
        sys::SUNLS_PACKAGE_FAIL_REC as c_int
    }
}

impl OwnLinearSolver for FaerLu {
    const KIND: sys::SUNLinearSolver_Type = sys::SUNLinearSolver_Type_SUNLINEARSOLVER_DIRECT;

    fn reset(&mut self) {
        self.factored = false;
    }

    /// Refactors the CSC matrix the integrator attached.
    fn setup(&mut self, a: Option<Matrix<'_>>) -> c_int {
        let Some(Matrix::Sparse {
            n,
            ptrs,
            rows,
            vals,
        }) = a
        else {
            return -1;
        };
        faer_setup(self, n, ptrs, rows, vals)
    }

    fn order(&self) -> Option<usize> {
        Some(self.colptr.len().saturating_sub(1))
    }

    fn solve(&mut self, x: &mut [f64]) -> c_int {
        faer_solve(self, x)
    }
}

fn new_faer_solver(ctx: &Context, ordering: ColumnOrdering) -> Result<LinearSolver, SolverError> {
    let content = FaerLu {
        colptr: Vec::new(),
        rowidx: Vec::new(),
        symbolic: None,
        numeric: NumericLu::new(),
        factored: false,
        factor_mem: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
        solve_mem: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
        counters: FaerCounters::default(),
        ordering,
        ordered: None,
    };
    linsol::own(ctx, content)
}

/// The counters of a faer solver built by [`new_sparse_solver`] (`None` for KLU).
pub(crate) fn faer_counters(ls: &LinearSolver) -> Option<FaerCounters> {
    ls.content::<FaerLu>().map(|lu| lu.counters)
}

// --- one-off solves -------------------------------------------------------------------------

/// A direct solver for [`solve_direct`]: SUNDIALS' dense LU, or one of the sparse LUs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectSolver {
    /// `SUNLinSol_Dense` (LAPACK-style partial-pivoting LU on the full `n × n` matrix).
    Dense,
    /// A sparse LU on the CSC matrix.
    Sparse(SparseSolver),
}

/// `Err` naming `function` for a non-zero `SUNLinearSolver` return `flag`.
fn ls_call(function: &'static str, flag: c_int) -> Result<(), SolverError> {
    if flag == 0 {
        Ok(())
    } else {
        Err(SolverError::Flag {
            function,
            flag,
            name: format!("SUNLS flag {flag}"),
            t: f64::NAN,
        })
    }
}

/// `SUNLinSolSetup` on `a`, then `SUNLinSolSolve` of `a x = rhs`, as the integrators call them.
///
/// # Safety
/// `solver` is initialised, `a` is a live matrix of the solver's kind and size, `x` and `rhs`
/// are distinct live vectors of that size, all built on one context.
unsafe fn setup_and_solve(
    solver: &LinearSolver,
    a: sys::SUNMatrix,
    x: &NVector,
    rhs: &NVector,
) -> Result<(), SolverError> {
    // SAFETY: guaranteed by the caller.
    unsafe {
        ls_call("SUNLinSolSetup", sys::SUNLinSolSetup(solver.raw(), a))?;
        ls_call(
            "SUNLinSolSolve",
            sys::SUNLinSolSolve(solver.raw(), a, x.raw(), rhs.raw(), 0.0),
        )
    }
}

/// Solves `A x = b` once with the same `SUNLinearSolver` the integrators use for `kind`
/// (`SUNLinSol_Dense`, our faer wrapper or `SUNLinSol_KLU`), calling its `initialize`,
/// `setup` (the factorisation `P A Q = L U`) and `solve` ops as IDA and CVODE do. `A` has the
/// sparsity `pattern` and the entries `values` (in pattern order); the dense solver receives
/// the same entries scattered into a zeroed `n × n` matrix. Used by the tests to compare the
/// three factorisations of one Newton matrix.
pub fn solve_direct(
    kind: DirectSolver,
    pattern: &CscPattern,
    values: &[f64],
    b: &[f64],
) -> Result<Vec<f64>, SolverError> {
    solve_direct_ordered(kind, ColumnOrdering::Colamd, pattern, values, b)
}

/// [`solve_direct`] with faer ordering the columns by `ordering` (the other solvers ignore it).
pub fn solve_direct_ordered(
    kind: DirectSolver,
    ordering: ColumnOrdering,
    pattern: &CscPattern,
    values: &[f64],
    b: &[f64],
) -> Result<Vec<f64>, SolverError> {
    let n = pattern.n();
    if values.len() != pattern.nnz() || b.len() != n || n == 0 {
        return Err(SolverError::InvalidInput(format!(
            "solve_direct: {} values and {} right-hand sides for a {n} × {n} pattern with {} entries",
            values.len(),
            b.len(),
            pattern.nnz()
        )));
    }
    // Drop order (reverse of declaration): solver, matrix, vectors, then the context.
    let ctx = Context::new()?;
    let rhs = NVector::from_slice(&ctx, b)?;
    let mut x = NVector::from_slice(&ctx, b)?;
    let (matrix, solver): (Box<dyn AsRawMatrix>, LinearSolver) = match kind {
        DirectSolver::Dense => {
            let a = super::matrix::DenseMatrix::square(&ctx, n)?;
            // SAFETY: `a` is a live n × n dense matrix owned here; the view ends in this block.
            let mut view = unsafe { super::matrix::DenseMatrixMut::from_raw(a.raw()) };
            view.fill_zero();
            for j in 0..n {
                let (a, b) = (pattern.colptr()[j], pattern.colptr()[j + 1]);
                for (&r, &v) in pattern.rowidx()[a..b].iter().zip(&values[a..b]) {
                    view.add(r, j, v);
                }
            }
            let ls = super::dense_lu::new(&ctx)?;
            (Box::new(a), ls)
        }
        DirectSolver::Sparse(s) => {
            let a = SparseMatrix::new(&ctx, pattern)?;
            // SAFETY: `a` is a live CSC matrix holding `pattern`; the view ends in this block.
            unsafe { values_of(a.raw(), pattern) }.copy_from_slice(values);
            let ls = new_sparse_solver(&ctx, &rhs, &a, s, ordering)?;
            (Box::new(a), ls)
        }
    };
    // SAFETY: solver, matrix and vectors are live, of size n and built on `ctx`; `x` and
    // `rhs` are distinct vectors; the ops are called in the order the integrators use.
    unsafe {
        ls_call(
            "SUNLinSolInitialize",
            sys::SUNLinSolInitialize(solver.raw()),
        )?;
        setup_and_solve(&solver, matrix.raw_matrix(), &x, &rhs)?;
    }
    let out = x.as_mut_slice().to_vec();
    drop(solver);
    drop(matrix);
    Ok(out)
}

/// Solves `A_k x_k = b` for a sequence of matrices `A_k` of one `pattern` (`values[k]`, in
/// pattern order) with one faer solver ordering its columns by `ordering`, its `setup` called
/// for each as the integrators call it at each Jacobian update (the symbolic analysis once,
/// then a numeric factorisation — with [`ColumnOrdering::Cheapest`], a refactorisation in the
/// row order of the last full one while its pivots hold). Returns the solutions and the
/// solver's counters. Used by the tests to compare the refactorisations with the dense LU.
pub fn solve_faer_sequence(
    ordering: ColumnOrdering,
    pattern: &CscPattern,
    values: &[Vec<f64>],
    b: &[f64],
) -> Result<(Vec<Vec<f64>>, FaerCounters), SolverError> {
    let n = pattern.n();
    if values.iter().any(|v| v.len() != pattern.nnz()) || b.len() != n || n == 0 {
        return Err(SolverError::InvalidInput(format!(
            "solve_faer_sequence: values of a wrong length or {} right-hand sides for a {n} × {n} pattern with {} entries",
            b.len(),
            pattern.nnz()
        )));
    }
    // Drop order (reverse of declaration): solver, matrix, vectors, then the context.
    let ctx = Context::new()?;
    let rhs = NVector::from_slice(&ctx, b)?;
    let mut x = NVector::from_slice(&ctx, b)?;
    let a = SparseMatrix::new(&ctx, pattern)?;
    let solver = new_sparse_solver(&ctx, &rhs, &a, SparseSolver::Faer, ordering)?;
    let mut out = Vec::with_capacity(values.len());
    // SAFETY: solver, matrix and vectors are live, of size n and built on `ctx`; `x` and
    // `rhs` are distinct vectors; the values view of `a` ends before the ops read `a`.
    unsafe {
        ls_call(
            "SUNLinSolInitialize",
            sys::SUNLinSolInitialize(solver.raw()),
        )?;
        for v in values {
            values_of(a.raw(), pattern).copy_from_slice(v);
            setup_and_solve(&solver, a.raw(), &x, &rhs)?;
            out.push(x.as_mut_slice().to_vec());
        }
    }
    let counters = faer_counters(&solver).unwrap_or_default();
    drop(solver);
    drop(a);
    Ok((out, counters))
}

/// The raw `SUNMatrix` of an owned dense or sparse matrix.
trait AsRawMatrix {
    fn raw_matrix(&self) -> sys::SUNMatrix;
}

impl AsRawMatrix for SparseMatrix {
    fn raw_matrix(&self) -> sys::SUNMatrix {
        self.raw
    }
}

impl AsRawMatrix for super::matrix::DenseMatrix {
    fn raw_matrix(&self) -> sys::SUNMatrix {
        self.raw()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pattern (diagonal included) of the path `p[0] – p[1] – … – p[n-1]`.
    fn path(p: &[usize]) -> CscPattern {
        let edges = p.windows(2).flat_map(|w| [(w[0], w[1]), (w[1], w[0])]);
        CscPattern::new(p.len(), edges).unwrap()
    }

    #[test]
    fn cuthill_mckee_numbers_a_scrambled_path_from_one_end_to_the_other() {
        // the path's vertices labelled out of order
        let p = [5, 2, 7, 0, 3, 6, 1, 4];
        let pat = path(&p);
        for reverse in [false, true] {
            let order = cuthill_mckee(8, pat.colptr(), pat.rowidx(), reverse);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..8).collect::<Vec<_>>(), "a permutation");
            // along the path: each vertex next to the one before it, starting at an end
            let at = |v: usize| p.iter().position(|&w| w == v).unwrap();
            for w in order.windows(2) {
                assert_eq!(at(w[0]).abs_diff(at(w[1])), 1, "{order:?}");
            }
            assert!([0, 7].contains(&at(order[0])), "{order:?}");
        }
    }

    /// The saddle chain of [`the_cheapest_order_solves_a_saddle_system_as_the_dense_lu_does`]
    /// with its entries scaled by `s(k, e)` (block `k`, entry `e` of the block's list).
    fn saddle_chain(n: usize, s: impl Fn(usize, usize) -> f64) -> Vec<(usize, usize, f64)> {
        let mut entries = Vec::new();
        for k in 0..n {
            let (a, v, l) = (3 * k, 3 * k + 1, 3 * k + 2);
            let block = [
                (a, a, 2.0 + k as f64 * 0.01),
                (a, l, 1.0),
                (l, a, 1.0),
                (v, v, 50.0),
                (v, l, -0.7),
                (l, v, 0.3),
                (l, l, 0.0),
            ];
            entries.extend(
                block
                    .iter()
                    .enumerate()
                    .map(|(e, &(i, j, x))| (i, j, x * s(k, e))),
            );
            if k + 1 < n {
                entries.extend([(l, 3 * (k + 1), -1.0), (3 * (k + 1), l, -1.0)]);
            }
        }
        entries
    }

    /// Each matrix of `seq` (one pattern) solved by one faer solver in the cheapest order,
    /// refactoring from one to the next, against SUNDIALS' dense LU of each, to rounding;
    /// returns the solver's counters.
    fn refactored_against_dense(seq: &[Vec<(usize, usize, f64)>]) -> FaerCounters {
        let n = 1 + seq[0].iter().map(|e| e.0.max(e.1)).max().unwrap();
        let pat = CscPattern::new(n, seq[0].iter().map(|e| (e.0, e.1))).unwrap();
        let values: Vec<Vec<f64>> = seq
            .iter()
            .map(|entries| {
                let mut v = vec![0.0; pat.nnz()];
                for &(i, j, x) in entries {
                    v[pat.position(i, j).unwrap()] += x;
                }
                v
            })
            .collect();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let (xs, counters) =
            solve_faer_sequence(ColumnOrdering::Cheapest, &pat, &values, &b).unwrap();
        for (k, (x, v)) in xs.iter().zip(&values).enumerate() {
            let dense = solve_direct(DirectSolver::Dense, &pat, v, &b).unwrap();
            let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, d) in x.iter().zip(&dense) {
                assert!((a - d).abs() <= 1e-11 * scale, "matrix {k}: {a} vs {d}");
            }
            // and it solves its own system: A x − b to rounding
            let mut r = b.iter().map(|v| -v).collect::<Vec<_>>();
            for &(i, j, a) in &seq[k] {
                r[i] += a * x[j];
            }
            assert!(r.iter().all(|v| v.abs() < 1e-11), "matrix {k}: {r:?}");
        }
        counters
    }

    #[test]
    fn refactorisations_in_the_kept_row_order_solve_as_the_dense_lu_does() {
        // the entries drift from matrix to matrix, as a Newton matrix's do along a run
        let seq: Vec<_> = (0..6)
            .map(|m| {
                saddle_chain(40, |k, e| {
                    1.0 + 0.05 * m as f64 * ((k + 3 * e) as f64).sin()
                })
            })
            .collect();
        let c = refactored_against_dense(&seq);
        assert_eq!(c.symbolic, 1, "{c:?}");
        assert_eq!(c.numeric, 6, "{c:?}");
        // the first is factored with pivoting, the others in its row order
        assert_eq!((c.refactored, c.repivoted), (5, 0), "{c:?}");
    }

    #[test]
    fn a_refactorisation_whose_pivot_fails_the_threshold_pivots_again() {
        // a chain of 2 × 2 blocks [d o; o d], weakly coupled: with d = 4, o = 1 the first
        // factorisation pivots on the diagonal; with d = 1e-9, o = 4 that row order would
        // divide by 1e-9 against 4 below it (the threshold test fails at the first column
        // of the first block met), so that factorisation pivots again; the third matrix is
        // the first again (refactored in the new order or pivoted again: either solves)
        let chain = |d: f64, o: f64| {
            let mut e = Vec::new();
            for k in 0..15 {
                let (a, b) = (2 * k, 2 * k + 1);
                e.extend([(a, a, d), (a, b, o), (b, a, o), (b, b, d)]);
                if k + 1 < 15 {
                    e.extend([(b, b + 1, 0.01), (b + 1, b, 0.02)]);
                }
            }
            e
        };
        let seq = vec![chain(4.0, 1.0), chain(1e-9, 4.0), chain(4.0, 1.0)];
        let c = refactored_against_dense(&seq);
        assert!(c.repivoted >= 1, "{c:?}");
        assert_eq!(c.numeric, 3, "{c:?}");
        assert_eq!(c.refactored + c.repivoted, 2, "{c:?}");
    }

    #[test]
    fn the_cheapest_order_solves_a_saddle_system_as_the_dense_lu_does() {
        // a chain of n blocks [m 0 gᵀ; 0 c −1; g 1 0]-like couplings with zeros on the
        // multipliers' diagonal, as the index-1 DAE's acceleration rows have
        let n = 60;
        let entries = saddle_chain(n, |_, _| 1.0);
        let pat = CscPattern::new(3 * n, entries.iter().map(|e| (e.0, e.1))).unwrap();
        let mut values = vec![0.0; pat.nnz()];
        for &(i, j, v) in &entries {
            values[pat.position(i, j).unwrap()] += v;
        }
        let b: Vec<f64> = (0..3 * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let dense = solve_direct(DirectSolver::Dense, &pat, &values, &b).unwrap();
        let ordered = solve_direct_ordered(
            DirectSolver::Sparse(SparseSolver::Faer),
            ColumnOrdering::Cheapest,
            &pat,
            &values,
            &b,
        )
        .unwrap();
        let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in ordered.iter().zip(&dense) {
            assert!((x - y).abs() <= 1e-12 * scale, "{x} vs {y}");
        }
        // and it solves the system: residual A x − b to rounding
        let mut r = b.iter().map(|v| -v).collect::<Vec<_>>();
        for &(i, j, v) in &entries {
            r[i] += v * ordered[j];
        }
        assert!(r.iter().all(|v| v.abs() < 1e-12), "{r:?}");
    }
}
