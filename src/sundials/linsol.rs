//! RAII owner of a `SUNLinearSolver`, and the one callback table of the linear solvers of ours
//! (the dense LU of [`super::dense_lu`], the Schur complement of [`super::schur`], faer's sparse
//! LU of [`super::sparse`], IDA's user-supplied solver of [`super::custom_ls`]): each implements
//! the trait `OwnLinearSolver` in safe Rust, and `own` hands SUNDIALS the `initialize`, `setup`
//! and `solve` operations that call it, every panic caught before it could unwind into C.

use super::context::Context;
use super::error::SolverError;
use super::vector::{slice_of, slice_of_mut};
use std::any::TypeId;
use std::os::raw::{c_int, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};
use sundials_sys as sys;

/// Owned `SUNLinearSolver`, freed with `SUNLinSolFree` on drop.
pub(crate) struct LinearSolver {
    raw: sys::SUNLinearSolver,
    /// The type of its content, for a solver built by [`own`].
    content: Option<TypeId>,
}

impl LinearSolver {
    /// Take ownership of an already-built solver.
    ///
    /// # Safety
    /// `raw` must be a valid solver whose `free` op releases everything it owns.
    pub(crate) unsafe fn from_raw(raw: sys::SUNLinearSolver) -> LinearSolver {
        LinearSolver { raw, content: None }
    }

    pub(crate) fn raw(&self) -> sys::SUNLinearSolver {
        self.raw
    }

    /// The content of a solver built by [`own`] with content `T`; `None` for another solver
    /// (SUNDIALS' own, or one of ours of another type).
    fn tagged<T: OwnLinearSolver>(&self) -> Option<*mut T> {
        if self.content != Some(TypeId::of::<T>()) {
            return None;
        }
        // SAFETY: a live solver built by `own::<T>`: its content is our Box<T>.
        let content = unsafe { (*self.raw).content };
        (!content.is_null()).then_some(content as *mut T)
    }

    /// The solver of type `T` inside, read ([`own`]).
    pub(crate) fn content<T: OwnLinearSolver>(&self) -> Option<&T> {
        // SAFETY: a pointer into the content this solver owns, borrowed with it.
        self.tagged::<T>().map(|p| unsafe { &*p })
    }

    /// The solver of type `T` inside, to change ([`own`]).
    pub(crate) fn content_mut<T: OwnLinearSolver>(&mut self) -> Option<&mut T> {
        // SAFETY: a pointer into the content this solver owns, borrowed mutably with it.
        self.tagged::<T>().map(|p| unsafe { &mut *p })
    }
}

impl Drop for LinearSolver {
    fn drop(&mut self) {
        // SAFETY: `raw` is owned and freed exactly once, after the integrator memory.
        unsafe {
            sys::SUNLinSolFree(self.raw);
        }
    }
}

/// The matrix a linear solver's `setup` receives, as the integrator holds it.
pub(crate) enum Matrix<'a> {
    /// Square dense, column-major `n × n`; rebuilt by the integrator before every setup and
    /// not accessed elsewhere until the next one, so a solver may factor it in place.
    Dense {
        /// The order.
        n: usize,
        /// The entries, column by column.
        data: &'a mut [f64],
    },
    /// Compressed sparse columns (`n` columns, `ptrs[n]` stored entries).
    Sparse {
        /// The number of columns.
        n: usize,
        /// Where each column starts in `rows` and `vals` (`n + 1` entries).
        ptrs: &'a [i64],
        /// The row of each stored entry.
        rows: &'a [i64],
        /// The value of each stored entry.
        vals: &'a [f64],
    },
}

/// A linear solver of ours, as the one callback table ([`own`]) calls it. The return codes
/// are SUNDIALS': 0 success, positive a recoverable failure (the integrator cuts the step),
/// negative an unrecoverable one.
pub(crate) trait OwnLinearSolver: 'static {
    /// `DIRECT` (matrix-based) or `MATRIX_EMBEDDED` (it forms its own matrix).
    const KIND: sys::SUNLinearSolver_Type;

    /// `initialize`: forget the last factorisation (default: nothing to forget).
    fn reset(&mut self) {}

    /// `setup`: factor `a` (`None`: no matrix, or not a kind SUNDIALS documents). Default:
    /// nothing to do (a matrix-embedded solver sets itself up in `solve`).
    fn setup(&mut self, a: Option<Matrix<'_>>) -> c_int {
        let _ = a;
        0
    }

    /// The order of the systems `solve` takes now; `None` while it cannot solve.
    fn order(&self) -> Option<usize>;

    /// `solve`: overwrite `x`, which holds `b`, with the solution of the system.
    fn solve(&mut self, x: &mut [f64]) -> c_int;
}

/// The solver inside `s`.
///
/// # Safety
/// `s` must be a live solver built by [`own::<T>`], not otherwise borrowed.
unsafe fn content<'a, T>(s: sys::SUNLinearSolver) -> &'a mut T {
    // SAFETY: the caller's contract: the content is our Box<T>.
    unsafe { &mut *((*s).content as *mut T) }
}

/// The matrix `a`, when it is square dense or sparse CSC.
///
/// # Safety
/// `a` must be null or a live `SUNMatrix`, not accessed elsewhere while the result lives.
unsafe fn matrix<'a>(a: sys::SUNMatrix) -> Option<Matrix<'a>> {
    // SAFETY: the caller's contract; the type is checked before the accessors, and the
    // slices have the lengths the matrix states (CSC: `n + 1` pointers, `ptrs[n]` entries).
    unsafe {
        if let Some((n, data)) = super::matrix::square_dense(a) {
            let data = std::slice::from_raw_parts_mut(data, n * n);
            return Some(Matrix::Dense { n, data });
        }
        if a.is_null() || sys::SUNMatGetID(a) != sys::SUNMatrix_ID_SUNMATRIX_SPARSE {
            return None;
        }
        let n = sys::SUNSparseMatrix_Columns(a) as usize;
        let ptrs = std::slice::from_raw_parts(sys::SUNSparseMatrix_IndexPointers(a), n + 1);
        let nnz = ptrs[n] as usize;
        let (rows, vals): (&[i64], &[f64]) = if nnz == 0 {
            (&[], &[])
        } else {
            (
                std::slice::from_raw_parts(sys::SUNSparseMatrix_IndexValues(a), nnz),
                std::slice::from_raw_parts(sys::SUNSparseMatrix_Data(a), nnz),
            )
        };
        Some(Matrix::Sparse {
            n,
            ptrs,
            rows,
            vals,
        })
    }
}

/// `gettype`.
unsafe extern "C" fn kind_op<T: OwnLinearSolver>(
    _s: sys::SUNLinearSolver,
) -> sys::SUNLinearSolver_Type {
    T::KIND
}

/// `getid` of every solver of ours.
unsafe extern "C" fn custom_id(_s: sys::SUNLinearSolver) -> sys::SUNLinearSolver_ID {
    sys::SUNLinearSolver_ID_SUNLINEARSOLVER_CUSTOM
}

/// `numiters` of a matrix-embedded solver (it iterates nothing).
unsafe extern "C" fn zero_iters(_s: sys::SUNLinearSolver) -> c_int {
    0
}

/// `initialize`: [`OwnLinearSolver::reset`].
unsafe extern "C" fn initialize_op<T: OwnLinearSolver>(s: sys::SUNLinearSolver) -> c_int {
    // SAFETY: `s` was built by `own::<T>`; SUNDIALS calls one operation at a time.
    let solver = unsafe { content::<T>(s) };
    // no panic may unwind into SUNDIALS
    catch_unwind(AssertUnwindSafe(|| solver.reset())).map_or(-1, |()| 0)
}

/// `setup`: [`OwnLinearSolver::setup`] of the matrix the integrator attached.
unsafe extern "C" fn setup_op<T: OwnLinearSolver>(
    s: sys::SUNLinearSolver,
    a: sys::SUNMatrix,
) -> c_int {
    // SAFETY: `s` was built by `own::<T>`; `a` is null or the live matrix the integrator
    // attached, not accessed elsewhere during the setup.
    let (solver, a) = unsafe { (content::<T>(s), matrix(a)) };
    // no panic may unwind into SUNDIALS
    catch_unwind(AssertUnwindSafe(|| solver.setup(a))).unwrap_or(-1)
}

/// `solve`: `b` copied into `x`, then [`OwnLinearSolver::solve`] in place.
unsafe extern "C" fn solve_op<T: OwnLinearSolver>(
    s: sys::SUNLinearSolver,
    _a: sys::SUNMatrix,
    x: sys::N_Vector,
    b: sys::N_Vector,
    _tol: f64,
) -> c_int {
    // SAFETY: `s` was built by `own::<T>`; x and b are the integrator's serial vectors
    // (possibly the same one), checked to have the solver's order before they are read.
    unsafe {
        let solver = content::<T>(s);
        let Some(n) = solver.order() else {
            return -1;
        };
        if sys::N_VGetLength(x) as usize != n || sys::N_VGetLength(b) as usize != n {
            return -1;
        }
        if x != b {
            slice_of_mut(x, n).copy_from_slice(slice_of(b, n));
        }
        let xs = slice_of_mut(x, n);
        // no panic may unwind into SUNDIALS
        catch_unwind(AssertUnwindSafe(|| solver.solve(xs))).unwrap_or(-1)
    }
}

/// `free`: the content `Box<T>` reclaimed, then the shell and its ops.
unsafe extern "C" fn free_op<T>(s: sys::SUNLinearSolver) -> c_int {
    // SAFETY: `s` was built by `own::<T>`; its content is our Box<T>, reclaimed once here,
    // then the empty shell and ops are freed by SUNDIALS.
    unsafe {
        if s.is_null() {
            return 0;
        }
        if !(*s).content.is_null() {
            drop(Box::from_raw((*s).content as *mut T));
            (*s).content = std::ptr::null_mut();
        }
        sys::SUNLinSolFreeEmpty(s);
    }
    0
}

/// A `SUNLinearSolver` (id `CUSTOM`, type [`OwnLinearSolver::KIND`]) owning `solver` (freed
/// with it), whose operations call it.
pub(crate) fn own<T: OwnLinearSolver>(
    ctx: &Context,
    solver: T,
) -> Result<LinearSolver, SolverError> {
    let content = Box::new(solver);
    // SAFETY: valid context; NULL checked; the ops table was allocated by SUNLinSolNewEmpty
    // and is ours to fill; the content pointer is reclaimed by `free_op::<T>`.
    unsafe {
        let s = sys::SUNLinSolNewEmpty(ctx.raw());
        if s.is_null() {
            return Err(SolverError::InvalidInput("SUNLinSolNewEmpty failed".into()));
        }
        let table = &mut *(*s).ops;
        table.gettype = Some(kind_op::<T>);
        table.getid = Some(custom_id);
        table.free = Some(free_op::<T>);
        table.initialize = Some(initialize_op::<T>);
        table.setup = Some(setup_op::<T>);
        table.solve = Some(solve_op::<T>);
        if T::KIND == sys::SUNLinearSolver_Type_SUNLINEARSOLVER_MATRIX_EMBEDDED {
            table.numiters = Some(zero_iters);
        }
        (*s).content = Box::into_raw(content) as *mut c_void;
        Ok(LinearSolver {
            raw: s,
            content: Some(TypeId::of::<T>()),
        })
    }
}

/// A solve's outcome from its solution `x`: 0, or recoverable where it is not finite (a
/// numerically singular factor, as a zero pivot is).
pub(crate) fn finite_solution(x: &[f64]) -> c_int {
    if x.iter().all(|v| v.is_finite()) {
        0
    } else {
        sys::SUNLS_PACKAGE_FAIL_REC as c_int
    }
}
