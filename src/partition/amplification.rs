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
    /// dependent coordinates do not square the rows), each with its `B`.
    velocities: (BlockColumns, Amplification),
    coordinates: Option<(BlockColumns, Amplification)>,
    /// The coordinates' block is the velocities' (`q' = v`, so `G_q = G_v`, and the same
    /// dependent and measured columns): one elimination serves both.
    shared: bool,
    vars: Vec<f64>,
    gq_work: (Vec<f64>, Vec<f64>),
    gv_work: (Vec<f64>, Vec<f64>),
    gq_m: DMatrix<f64>,
    gv_m: DMatrix<f64>,
    scratch: Vec<f64>,
}

impl DependentAmplification {
    /// The amplification of the partition `(dependent velocities, dependent coordinates, joint
    /// rows)` with IDA's mask `id` (`None` where the block is larger than [`AMPLIFIED_ROWS`]);
    /// `rates_are_velocities`: the coordinates' rates are the velocities (`q' = v`, planar
    /// mechanisms and points), so `G_q = G_v`.
    pub fn new(
        (gq, gv): (&MatrixTape, &MatrixTape),
        (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
        (nq, nv): (usize, usize),
        id: &[f64],
        rates_are_velocities: bool,
    ) -> Option<DependentAmplification> {
        if rows.is_empty() || rows.len() > AMPLIFIED_ROWS || id.len() < nq + nv {
            return None;
        }
        let velocities = BlockColumns::new(rows, dependent, &id[nq..nq + nv]);
        let coordinates = (coordinates.len() == rows.len())
            .then(|| BlockColumns::new(rows, coordinates, &id[..nq]));
        let shared = rates_are_velocities && coordinates.as_ref() == Some(&velocities);
        Some(DependentAmplification {
            gq: gq.clone(),
            gv: gv.clone(),
            nq,
            velocities: (velocities, Amplification::default()),
            coordinates: coordinates.map(|c| (c, Amplification::default())),
            shared,
            vars: Vec::new(),
            gq_work: gq.workspace(),
            gv_work: gv.workspace(),
            gq_m: DMatrix::zeros(0, 0),
            gv_m: DMatrix::zeros(0, 0),
            scratch: Vec::new(),
        })
    }

    /// Raises IDA's weights `w` (of `y = [q, v, …]` at time `t`) by the dependent velocities'
    /// and coordinates' amplification of the independent ones' error, `B` eliminated at
    /// `(t, y)` (once for both where they share their block).
    ///
    /// Eliminating `B` only when IDA refreshes its Newton matrix was tried (a five-bar spent
    /// 29 k instructions a step here, a third of its integration): the spherical pendulum's
    /// error grew 3–6× (its `B = x/y` turns within a few steps near a re-selection), so `B`
    /// follows every step.
    pub fn raise(&mut self, t: f64, y: &[f64], w: &mut [f64]) {
        let nq = self.nq;
        let nv = self.gv.cols;
        let x = &y[..nq + nv];
        self.gv
            .matrix_into(t, x, (&mut self.vars, &mut self.gv_work), &mut self.gv_m);
        let (cols, b) = &mut self.velocities;
        b.eliminate(&self.gv_m, cols, &mut self.scratch);
        b.raise(cols, nq, w);
        if let Some((cols, b)) = &mut self.coordinates {
            if self.shared {
                self.velocities.1.raise(cols, 0, w);
            } else {
                self.gq
                    .matrix_into(t, x, (&mut self.vars, &mut self.gq_work), &mut self.gq_m);
                b.eliminate(&self.gq_m, cols, &mut self.scratch);
                b.raise(cols, 0, w);
            }
        }
    }
}

/// `B = g[R, D]⁻¹ g[R, J]` of one block, the rows of the dependent columns out of the error
/// test only (`None`: the block is singular or does not square its rows).
#[derive(Clone, Debug, Default)]
pub struct Amplification {
    /// Row-major, `unmeasured × measured`.
    b: Option<Vec<f64>>,
}

impl Amplification {
    /// Eliminates `B` from `g` (one Gaussian elimination with partial pivoting of
    /// `[g[R, D] | g[R, J]]` in `scratch`, reused: no allocation once it has grown).
    pub fn eliminate(&mut self, g: &DMatrix<f64>, cols: &BlockColumns, scratch: &mut Vec<f64>) {
        let mut b = self.b.take().unwrap_or_default();
        if eliminate_block(g, cols, scratch, &mut b) {
            self.b = Some(b);
        }
    }

    /// Raises the weights `w[offset + j]` of the measured columns `j` by
    /// `Σ_k (w_k B_kj)²` over the dependent columns `k` out of the error test.
    pub fn raise(&self, cols: &BlockColumns, offset: usize, w: &mut [f64]) {
        let Some(b) = &self.b else {
            return;
        };
        let m = cols.measured.len();
        for (c, &j) in cols.measured.iter().enumerate() {
            let s: f64 = cols
                .unmeasured
                .iter()
                .enumerate()
                .map(|(u, &(_, k))| (w[offset + k] * b[u * m + c]).powi(2))
                .sum();
            if s.is_finite() {
                w[offset + j] = (w[offset + j].powi(2) + s).sqrt();
            }
        }
    }
}

/// The columns of one block of [`raise_block`]: the joint rows, the dependent columns, the
/// measured independent columns `J` and the dependent columns out of the error test (by their
/// place in `dependent`).
#[derive(Clone, Debug, PartialEq)]
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
/// `B = g[R, D]⁻¹ g[R, J]` (nothing where the block is singular or `D` does not square `R`):
/// [`Amplification::eliminate`], then [`Amplification::raise`].
pub fn raise_block(
    g: &DMatrix<f64>,
    cols: &BlockColumns,
    offset: usize,
    w: &mut [f64],
    scratch: &mut Vec<f64>,
) {
    let mut b = Amplification::default();
    b.eliminate(g, cols, scratch);
    b.raise(cols, offset, w);
}

/// `B = g[R, D]⁻¹ g[R, J]`'s rows of the unmeasured dependent columns into `out`
/// (`unmeasured × measured`, row-major); `false` where the block is singular, does not square
/// `R`, or nothing is to raise.
fn eliminate_block(
    g: &DMatrix<f64>,
    cols: &BlockColumns,
    scratch: &mut Vec<f64>,
    out: &mut Vec<f64>,
) -> bool {
    let (rows, dependent) = (&cols.rows, &cols.dependent);
    let r = rows.len();
    if dependent.len() != r || cols.unmeasured.is_empty() || cols.measured.is_empty() {
        return false;
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
    // forward elimination with partial pivoting on the block's columns (row slices, so the
    // inner update is one bounds-checked zip: 11 k instructions a step on a five-bar's 10 × 12
    // block when indexed entry by entry)
    for p in 0..r {
        let mut pivot_row = p;
        for a in p + 1..r {
            if scratch[a * width + p].abs() > scratch[pivot_row * width + p].abs() {
                pivot_row = a;
            }
        }
        let pivot = scratch[pivot_row * width + p];
        if pivot.is_nan() || pivot.abs() <= scale * f64::EPSILON * r as f64 {
            return false;
        }
        if pivot_row != p {
            let (top, bottom) = scratch.split_at_mut(pivot_row * width);
            top[p * width..(p + 1) * width].swap_with_slice(&mut bottom[..width]);
        }
        let (top, bottom) = scratch.split_at_mut((p + 1) * width);
        let prow = &top[p * width + p..(p + 1) * width];
        for line in bottom[..(r - p - 1) * width].chunks_exact_mut(width) {
            let f = line[p] / pivot;
            if f != 0.0 {
                for (x, y) in line[p..].iter_mut().zip(prow) {
                    *x -= f * y;
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
    let m = cols.measured.len();
    out.clear();
    for &(a, _) in &cols.unmeasured {
        out.extend_from_slice(&scratch[a * width + r..a * width + r + m]);
    }
    true
}
