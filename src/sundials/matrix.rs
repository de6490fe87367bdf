//! Dense `SUNMatrix` (column-major, `A[i + j*nrows]`): RAII owner and borrowed view.

use super::context::Context;
use super::error::SolverError;
use sundials_sys as sys;

/// The order and data of `a` when it is a square dense `SUNMatrix` (what a dense linear
/// solver's setup receives), `None` otherwise.
///
/// # Safety
/// `a` must be null or a live `SUNMatrix`.
pub(crate) unsafe fn square_dense(a: sys::SUNMatrix) -> Option<(usize, *mut f64)> {
    // SAFETY: the caller's contract; the type is checked before the dense accessors.
    unsafe {
        if a.is_null() || sys::SUNMatGetID(a) != sys::SUNMatrix_ID_SUNMATRIX_DENSE {
            return None;
        }
        let n = sys::SUNDenseMatrix_Columns(a) as usize;
        (sys::SUNDenseMatrix_Rows(a) as usize == n).then(|| (n, sys::SUNDenseMatrix_Data(a)))
    }
}

/// Owned dense `SUNMatrix`, destroyed on drop.
pub(crate) struct DenseMatrix {
    raw: sys::SUNMatrix,
}

impl DenseMatrix {
    /// New `n x n` dense matrix.
    pub(crate) fn square(ctx: &Context, n: usize) -> Result<DenseMatrix, SolverError> {
        // SAFETY: valid context and positive dimensions; NULL is checked below.
        let raw = unsafe {
            sys::SUNDenseMatrix(n as sys::sunindextype, n as sys::sunindextype, ctx.raw())
        };
        if raw.is_null() {
            return Err(SolverError::InvalidInput("SUNDenseMatrix failed".into()));
        }
        Ok(DenseMatrix { raw })
    }

    pub(crate) fn raw(&self) -> sys::SUNMatrix {
        self.raw
    }
}

impl Drop for DenseMatrix {
    fn drop(&mut self) {
        // SAFETY: `raw` came from SUNDenseMatrix and is destroyed exactly once.
        unsafe { sys::SUNMatDestroy(self.raw) }
    }
}

/// Mutable view of a SUNDIALS dense matrix, column-major.
pub struct DenseMatrixMut<'a> {
    data: &'a mut [f64],
    nrows: usize,
    ncols: usize,
}

impl<'a> DenseMatrixMut<'a> {
    /// View of a dense `SUNMatrix` passed to a Jacobian callback.
    ///
    /// # Safety
    /// `m` must be a live dense matrix not accessed elsewhere during `'a`.
    pub(crate) unsafe fn from_raw(m: sys::SUNMatrix) -> DenseMatrixMut<'a> {
        // SAFETY: guaranteed by the caller; a dense matrix stores rows*cols f64s contiguously.
        unsafe {
            let nrows = sys::SUNDenseMatrix_Rows(m) as usize;
            let ncols = sys::SUNDenseMatrix_Columns(m) as usize;
            let data = std::slice::from_raw_parts_mut(sys::SUNDenseMatrix_Data(m), nrows * ncols);
            DenseMatrixMut { data, nrows, ncols }
        }
    }

    /// View of a column-major buffer of `nrows * ncols` values.
    pub fn from_slice(
        data: &'a mut [f64],
        nrows: usize,
        ncols: usize,
    ) -> Option<DenseMatrixMut<'a>> {
        (data.len() == nrows * ncols).then_some(DenseMatrixMut { data, nrows, ncols })
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.nrows
    }

    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    fn index(&self, i: usize, j: usize) -> usize {
        assert!(
            i < self.nrows && j < self.ncols,
            "matrix index ({i}, {j}) out of bounds"
        );
        i + j * self.nrows
    }

    /// `A[i, j] = v`.
    pub fn set(&mut self, i: usize, j: usize, v: f64) {
        let k = self.index(i, j);
        self.data[k] = v;
    }

    /// `A[i, j] += v`.
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.index(i, j);
        self.data[k] += v;
    }

    /// `A[i, j]`.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.data[self.index(i, j)]
    }

    /// Set every entry to zero.
    pub fn fill_zero(&mut self) {
        self.data.fill(0.0);
    }

    /// All entries, column-major.
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        self.data
    }
}
