//! How the error of the index-1 DAE's independent unknowns reaches the dependent ones, as error
//! weights for IDA's local error test.
//!
//! The index-1 DAE tests the error of its independent coordinates `q_I` and velocities `v_I`
//! only: the dependent ones follow from the joints (`g(q) = 0`, `G_v v = 0`) and IDA's
//! estimate of their error is a predictor miss, not an error (it stalls the steps where the
//! dependent block's pivot is weak: docs/performance.md). Their error is nonetheless what the
//! user reads: to first order
//!
//! ```text
//!   δv_D = −G_v[R, D]⁻¹ G_v[R, I] δv_I = −B_v δv_I,     δq_D = −G_q[R, D_q]⁻¹ G_q[R, I_q] δq_I = −B_q δq_I
//! ```
//!
//! so the weight of each independent unknown `j` is raised to
//!
//! ```text
//!   w_j ← √( w_j² + Σ_k (w_k B_kj)² )          (k over the dependent unknowns out of the test)
//! ```
//!
//! with `w = 1 / (rtol |y| + atol)` IDA's own weights: an error `δ_j` that keeps `w_j δ_j ≤ 1`
//! keeps every dependent `w_k |B_kj δ_j| ≤ 1` as well, so the error test bounds the dependent
//! unknowns' error (to the factor `√n_I` of several independent errors adding up) the way the
//! GGL's test, which measures every coordinate, does. Where the block is well conditioned
//! (`|B| ≲ 1`) the weights barely change; near a weak pivot they tighten the steps in proportion
//! to the amplification, until the partition is re-chosen.
//!
//! # Example
//!
//! A pendulum of length 1 in Cartesian coordinates, `x² + y² = 1` at `(x, y) = (0.6, −0.8)`,
//! with `y` dependent: `δy = −(x/y) δx = 0.75 δx`, so `x`'s weight grows by `y`'s times 0.75.
//!
//! ```
//! use bondmech::partition::amplification::{raise_block, BlockColumns};
//! use nalgebra::DMatrix;
//! let g = DMatrix::from_row_slice(1, 2, &[1.2, -1.6]); // ∂(x² + y²)/∂(x, y)
//! let mut w = vec![1.0, 2.0];
//! let cols = BlockColumns::new(&[0], &[1], &[1.0, 0.0]); // row 0; y dependent, out of the test
//! raise_block(&g, &cols, 0, &mut w, &mut Vec::new());
//! assert!((w[0] - (1.0f64 + (2.0f64 * 0.75).powi(2)).sqrt()).abs() < 1e-12);
//! assert_eq!(w[1], 2.0);
//! ```

use super::thresholds::AMPLIFIED_ROWS;
use crate::dae::mechanics::MatrixTape;
use nalgebra::DMatrix;

/// The raised error weights of one index-1 partition ([`DependentAmplification::raise`]).
#[derive(Clone, Debug)]
pub struct DependentAmplification {
    gq: MatrixTape,
    gv: MatrixTape,
    nq: usize,
    /// The velocities' block `G_v[R, D]` and the coordinates' `G_q[R, D_q]` (`None` where the
    /// dependent coordinates do not square the rows).
    velocities: BlockColumns,
    coordinates: Option<BlockColumns>,
    vars: Vec<f64>,
    gq_work: (Vec<f64>, Vec<f64>),
    gv_work: (Vec<f64>, Vec<f64>),
    gq_m: DMatrix<f64>,
    gv_m: DMatrix<f64>,
    scratch: Vec<f64>,
}

impl DependentAmplification {
    /// The amplification of the partition `(dependent velocities, dependent coordinates, joint
    /// rows)` with IDA's mask `id` (`None` where the block is larger than [`AMPLIFIED_ROWS`]).
    pub fn new(
        (gq, gv): (&MatrixTape, &MatrixTape),
        (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
        (nq, nv): (usize, usize),
        id: &[f64],
    ) -> Option<DependentAmplification> {
        if rows.is_empty() || rows.len() > AMPLIFIED_ROWS || id.len() < nq + nv {
            return None;
        }
        Some(DependentAmplification {
            gq: gq.clone(),
            gv: gv.clone(),
            nq,
            velocities: BlockColumns::new(rows, dependent, &id[nq..nq + nv]),
            coordinates: (coordinates.len() == rows.len())
                .then(|| BlockColumns::new(rows, coordinates, &id[..nq])),
            vars: Vec::new(),
            gq_work: gq.workspace(),
            gv_work: gv.workspace(),
            gq_m: DMatrix::zeros(0, 0),
            gv_m: DMatrix::zeros(0, 0),
            scratch: Vec::new(),
        })
    }

    /// Raises IDA's weights `w` (of `y = [q, v, …]` at time `t`) by the dependent velocities'
    /// and coordinates' amplification of the independent ones' error.
    pub fn raise(&mut self, t: f64, y: &[f64], w: &mut [f64]) {
        let nq = self.nq;
        let nv = self.gv.cols;
        let x = &y[..nq + nv];
        self.gv
            .matrix_into(t, x, (&mut self.vars, &mut self.gv_work), &mut self.gv_m);
        raise_block(&self.gv_m, &self.velocities, nq, w, &mut self.scratch);
        if let Some(cols) = &self.coordinates {
            self.gq
                .matrix_into(t, x, (&mut self.vars, &mut self.gq_work), &mut self.gq_m);
            raise_block(&self.gq_m, cols, 0, w, &mut self.scratch);
        }
    }
}

/// The columns of one block of [`raise_block`]: the joint rows, the dependent columns, the
/// measured independent columns `J` and the dependent columns out of the error test (by their
/// place in `dependent`).
#[derive(Clone, Debug)]
pub struct BlockColumns {
    rows: Vec<usize>,
    dependent: Vec<usize>,
    measured: Vec<usize>,
    unmeasured: Vec<(usize, usize)>,
}

impl BlockColumns {
    /// The block `g[rows, dependent]` of a matrix with `ncols` columns under the mask `id`
    /// (1 measured, 0 out of the test) over them.
    pub fn new(rows: &[usize], dependent: &[usize], id: &[f64]) -> BlockColumns {
        BlockColumns {
            rows: rows.to_vec(),
            dependent: dependent.to_vec(),
            measured: (0..id.len())
                .filter(|&j| id[j] != 0.0 && !dependent.contains(&j))
                .collect(),
            unmeasured: dependent
                .iter()
                .enumerate()
                .filter(|(_, &k)| id[k] == 0.0)
                .map(|(a, &k)| (a, k))
                .collect(),
        }
    }
}

/// Raises the weights `w[offset + j]` of the measured columns `j` of `g` (outside the dependent
/// ones), by `Σ_k (w_k B_kj)²` over the dependent columns `k` out of the error test,
/// `B = g[R, D]⁻¹ g[R, J]` (nothing where the block is singular or `D` does not square `R`).
/// One Gaussian elimination with partial pivoting of `[g[R, D] | g[R, J]]` in `scratch`
/// (reused: no allocation once it has grown).
pub fn raise_block(
    g: &DMatrix<f64>,
    cols: &BlockColumns,
    offset: usize,
    w: &mut [f64],
    scratch: &mut Vec<f64>,
) {
    let (rows, dependent) = (&cols.rows, &cols.dependent);
    let r = rows.len();
    if dependent.len() != r || cols.unmeasured.is_empty() || cols.measured.is_empty() {
        return;
    }
    let width = r + cols.measured.len();
    scratch.clear();
    scratch.resize(r * width, 0.0);
    let mut scale = 0.0f64;
    for (a, &row) in rows.iter().enumerate() {
        let line = &mut scratch[a * width..(a + 1) * width];
        for (b, &k) in dependent.iter().enumerate() {
            line[b] = g[(row, k)];
            scale = scale.max(line[b].abs());
        }
        for (c, &j) in cols.measured.iter().enumerate() {
            line[r + c] = g[(row, j)];
        }
    }
    // forward elimination with partial pivoting on the block's columns
    for p in 0..r {
        let pivot_row = (p..r)
            .max_by(|&a, &b| {
                scratch[a * width + p]
                    .abs()
                    .total_cmp(&scratch[b * width + p].abs())
            })
            .unwrap_or(p);
        let pivot = scratch[pivot_row * width + p];
        if pivot.is_nan() || pivot.abs() <= scale * f64::EPSILON * r as f64 {
            return;
        }
        if pivot_row != p {
            for c in 0..width {
                scratch.swap(p * width + c, pivot_row * width + c);
            }
        }
        for a in p + 1..r {
            let f = scratch[a * width + p] / pivot;
            if f != 0.0 {
                for c in p..width {
                    scratch[a * width + c] -= f * scratch[p * width + c];
                }
            }
        }
    }
    // back substitution: the right-hand columns become B = g[R, D]⁻¹ g[R, J]
    for p in (0..r).rev() {
        let pivot = scratch[p * width + p];
        for c in r..width {
            let mut v = scratch[p * width + c];
            for b in p + 1..r {
                v -= scratch[p * width + b] * scratch[b * width + c];
            }
            scratch[p * width + c] = v / pivot;
        }
    }
    for (c, &j) in cols.measured.iter().enumerate() {
        let s: f64 = cols
            .unmeasured
            .iter()
            .map(|&(a, k)| (w[offset + k] * scratch[a * width + r + c]).powi(2))
            .sum();
        if s.is_finite() {
            w[offset + j] = (w[offset + j].powi(2) + s).sqrt();
        }
    }
}
