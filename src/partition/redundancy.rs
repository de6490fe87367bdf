//! Redundant joints: the joints' self-stress (the left null space of `G_v`), which rows
//! determine the motion, and how well the kept rows hold it (the grip of the rows left out).

use nalgebra::DMatrix;

use super::select::select_dependent;

/// The rows of `gv` that determine the motion where `redundant` of its rows are redundant
/// (sorted; all rows when `redundant` is 0): the rows left out are those where the joints'
/// self-stress — the left null space `N` of `gv`, `Nᵀ G_v = 0`, the eigenvectors of `G_v G_vᵀ`
/// of its `redundant` smallest eigenvalues — is held best ([`select_dependent`] on `Nᵀ`, the
/// rows in `prefer` (the causality's redundant junctions) first). Leaving out rows `L` keeps
/// the rank exactly when `N[L, :]` is regular, and the kept rows are best conditioned when it
/// is well conditioned. `None` when no such choice exists.
///
/// ```
/// use bondmech::partition::independent_rows;
/// use nalgebra::DMatrix;
/// // the third row is the sum of the first two: N ∝ (1, 1, −1), any one row can go
/// let g = DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 2.0, 0.0, 1.0, 1.0, 1.0, 1.0, 3.0]);
/// assert_eq!(independent_rows(&g, 1, &[2]), Some(vec![0, 1]));
/// assert_eq!(independent_rows(&g, 1, &[0]), Some(vec![1, 2]));
/// // a row of zeros is the one left out, whatever is preferred
/// let z = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 0.0, 0.0]);
/// assert_eq!(independent_rows(&z, 1, &[0]), Some(vec![0]));
/// ```
pub fn independent_rows(
    gv: &DMatrix<f64>,
    redundant: usize,
    prefer: &[usize],
) -> Option<Vec<usize>> {
    let m = gv.nrows();
    if redundant == 0 {
        return Some((0..m).collect());
    }
    independent_rows_of_stress(&self_stress(gv, redundant)?, prefer)
}

/// [`independent_rows`] from the self-stress `Nᵀ` ([`SelfStress`]).
pub fn independent_rows_of_stress(nt: &DMatrix<f64>, prefer: &[usize]) -> Option<Vec<usize>> {
    let m = nt.ncols();
    let mask: Vec<bool> = (0..m).map(|k| prefer.contains(&k)).collect();
    let left = select_dependent(nt, &mask)?;
    Some((0..m).filter(|k| !left.contains(k)).collect())
}

/// The joints' self-stress at one configuration, `Nᵀ` (`redundant × rows`, the orthonormal
/// left null space of `G_v`), computed once for the several questions asked of it
/// ([`independent_rows_of_stress`], [`SelfStress::grip`]).
pub struct SelfStress(DMatrix<f64>);

impl SelfStress {
    /// The self-stress of `gv` with `redundant` redundant rows (`None` when it has fewer rows).
    pub fn new(gv: &DMatrix<f64>, redundant: usize) -> Option<Self> {
        self_stress(gv, redundant).map(SelfStress)
    }

    /// [`independent_rows`] at this configuration.
    pub fn independent_rows(&self, prefer: &[usize]) -> Option<Vec<usize>> {
        independent_rows_of_stress(&self.0, prefer)
    }

    /// [`redundant_row_grip`] of the kept `rows` at this configuration.
    pub fn grip(&self, rows: &[usize]) -> f64 {
        grip_of_stress(&self.0, rows)
    }
}

/// `Nᵀ` (`redundant × rows`): the orthonormal left null space of `gv`, `Nᵀ G_v = 0`, as the
/// eigenvectors of `G_v G_vᵀ` of its `redundant` smallest eigenvalues. `None` when `redundant`
/// exceeds the rows.
fn self_stress(gv: &DMatrix<f64>, redundant: usize) -> Option<DMatrix<f64>> {
    let m = gv.nrows();
    if redundant > m {
        return None;
    }
    let eig = (gv * gv.transpose()).symmetric_eigen();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    Some(DMatrix::from_fn(redundant, m, |i, k| {
        eig.eigenvectors[(k, order[i])]
    }))
}

/// How well leaving out the rows outside `rows` keeps the rank of `gv`, `redundant` of whose
/// rows are redundant: `σ_min(N[L, :])` with `L` the rows left out and `N` the orthonormal
/// self-stress ([`independent_rows`]), in `[0, 1]`; 0 when the kept rows lose rank (the
/// self-stress has no component on the rows left out), 1 when nothing is redundant.
///
/// ```
/// use bondmech::partition::redundant_row_grip;
/// use nalgebra::DMatrix;
/// // rows 0 and 1 repeat each other: N = (1, −1)/√2, either row can go
/// let g = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 1.0, 2.0]);
/// assert!((redundant_row_grip(&g, 1, &[0]) - 0.5f64.sqrt()).abs() < 1e-12);
/// ```
pub fn redundant_row_grip(gv: &DMatrix<f64>, redundant: usize, rows: &[usize]) -> f64 {
    if redundant == 0 {
        return 1.0;
    }
    match self_stress(gv, redundant) {
        Some(nt) => grip_of_stress(&nt, rows),
        None => 0.0,
    }
}

/// `σ_min(N[L, :])` of the self-stress `Nᵀ` with `L` the rows outside `rows`.
fn grip_of_stress(nt: &DMatrix<f64>, rows: &[usize]) -> f64 {
    let redundant = nt.nrows();
    let left: Vec<usize> = (0..nt.ncols()).filter(|k| !rows.contains(k)).collect();
    if left.len() != redundant {
        return 0.0;
    }
    DMatrix::from_fn(redundant, redundant, |i, j| nt[(i, left[j])])
        .singular_values()
        .min()
}
