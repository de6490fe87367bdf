//! Conditioning of the joints at one state: how close `G_v` is to losing rank.
//!
//! The matrix that must be inverted to find the constraint forces is the mass-weighted Gram
//! matrix `A = G_v M⁺ G_vᵀ` (λ from `A λ = G_v M⁺ Q + γ`; `M⁺` skips massless coordinates).
//! Its spectral condition `κ = λ_max / λ_min` measures how near the joints are to a singular
//! configuration (four-bar chains aligned on the ground line, an isosceles slider-crank at its
//! bifurcation): there `λ_min → 0` and the plain GGL Newton matrix becomes singular. The
//! eigenvectors of `A` whose eigenvalues are (relatively) small say which joint rows lose
//! independence.

use nalgebra::DMatrix;

use crate::dae::gram::SparseGram;
use crate::mech::ConstraintRow;
use crate::partition::thresholds::{
    INVOLVED_SHARE, NEAR_NULL_RATIO, SPARSE_CONDITION_ITERATIONS, SPARSE_CONDITION_ROWS,
    SPARSE_CONDITION_TOL,
};

/// The conditioning of the joints at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct JointConditioning {
    /// `κ(G_v M⁺ G_vᵀ) = λ_max / λ_min` (infinite when `λ_min ≤ 0`).
    pub condition: f64,
    /// Joints whose rows take part in the near-dependency (the eigenvectors of the eigenvalues
    /// within [`NEAR_NULL_RATIO`] of the smallest one), in row order.
    pub joints: Vec<String>,
}

/// Conditioning of `G_v M⁺ G_vᵀ` for `gv` (`nc × nv`) and the diagonal mass matrix `mass`.
pub fn joint_conditioning(
    gv: &DMatrix<f64>,
    mass: &[f64],
    rows: &[ConstraintRow],
) -> JointConditioning {
    let nc = gv.nrows();
    if nc == 0 {
        return JointConditioning {
            condition: 1.0,
            joints: vec![],
        };
    }
    // faer's blocked eigensolver on this thread (nalgebra's unblocked one took 4 % of the
    // 40-four-bar chain's solve at its 20 passages); nalgebra where faer does not converge
    let (eigenvalues, eigenvectors) = match lower_evd(gram_lower(gv, mass).as_ref(), true) {
        Some((s, Some(u))) => (s, DMatrix::from_fn(nc, nc, |i, k| u[(i, k)])),
        _ => {
            let eig = mass_weighted_gram(gv, mass).symmetric_eigen();
            (eig.eigenvalues.iter().copied().collect(), eig.eigenvectors)
        }
    };
    let lmax = eigenvalues
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let lmin = eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
    let condition = ratio(lmax, lmin);
    let floor = lmin.max(lmax * f64::EPSILON) * NEAR_NULL_RATIO;
    let mut involved = vec![false; nc];
    for (k, &l) in eigenvalues.iter().enumerate() {
        if l > floor {
            continue;
        }
        let col = eigenvectors.column(k);
        let big = col.amax();
        for (i, &c) in col.iter().enumerate() {
            if c.abs() > INVOLVED_SHARE * big {
                involved[i] = true;
            }
        }
    }
    let mut joints: Vec<String> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        if involved[i] && !joints.contains(&r.joint) {
            joints.push(r.joint.clone());
        }
    }
    JointConditioning { condition, joints }
}

/// `A = G_v M⁺ G_vᵀ`, formed as `(G_v M^{-1/2}) (G_v M^{-1/2})ᵀ`.
fn mass_weighted_gram(gv: &DMatrix<f64>, mass: &[f64]) -> DMatrix<f64> {
    let mut a = gv.clone();
    for (j, &m) in mass.iter().enumerate() {
        let w = if m > 0.0 { 1.0 / m.sqrt() } else { 0.0 };
        a.column_mut(j).scale_mut(w);
    }
    &a * a.transpose()
}

/// `κ(G_v M⁺ G_vᵀ) = λ_max / λ_min` alone (no eigenvectors: the solver monitors it at every
/// output and asks for the joints, [`joint_conditioning`], only where κ is large).
///
/// From [`SPARSE_CONDITION_ROWS`] joint rows on, the two extreme eigenvalues come from
/// Lanczos iterations on the sparse Gram matrix and on its inverse through a sparse Cholesky
/// factor ([`sparse_joint_condition_number`]: linear in the size of a chain-like mechanism);
/// where that factorisation fails (`G_v M⁺ G_vᵀ` not numerically positive definite, e.g. a
/// massless coordinate or a rank loss) or the iterations do not converge, and below that
/// size, from all eigenvalues of the dense Gram matrix ([`dense_joint_condition_number`]).
pub fn joint_condition_number(gv: &DMatrix<f64>, mass: &[f64]) -> f64 {
    if gv.nrows() == 0 {
        return 1.0;
    }
    if gv.nrows() >= SPARSE_CONDITION_ROWS {
        if let Some(kappa) = sparse_joint_condition_number(gv, mass) {
            return kappa;
        }
    }
    dense_joint_condition_number(gv, mass)
}

/// `κ(A) = λ_max / λ_min` of `A = G_v M⁺ G_vᵀ` from its extreme eigenvalues only: `A` sparse
/// (`O(nnz)`), factored `A = L Lᵀ` by faer's sparse Cholesky, `λ_max` the largest eigenvalue
/// of `A` and `1 / λ_min` that of `A⁻¹ = L⁻ᵀ L⁻¹`, each by Lanczos to the relative accuracy
/// [`SPARSE_CONDITION_TOL`] ([`crate::dae::gram::lanczos_largest`]). `None` when the
/// Cholesky factorisation fails (`A` not numerically positive definite) or an iteration does
/// not converge.
pub fn sparse_joint_condition_number(gv: &DMatrix<f64>, mass: &[f64]) -> Option<f64> {
    if gv.nrows() == 0 {
        return Some(1.0);
    }
    let w = inverse_masses(mass);
    let gram = SparseGram::new(gv, &w)?;
    let (lmin, lmax) =
        gram.extreme_eigenvalues(SPARSE_CONDITION_TOL, SPARSE_CONDITION_ITERATIONS)?;
    Some(ratio(lmax, lmin))
}

/// [`sparse_joint_condition_number`] from the nonzeros `(row, column, value)` of the `nc × nv`
/// `G_v` in row-major order ([`crate::dae::MatrixTape::entries`]): the same Gram matrix, summed
/// in the same order, without reading a dense `G_v` (linear in the non-zeros).
pub fn sparse_joint_condition_number_of(
    (nc, nv): (usize, usize),
    entries: &[(usize, usize, f64)],
    mass: &[f64],
) -> Option<f64> {
    if nc == 0 {
        return Some(1.0);
    }
    let gram = SparseGram::from_entries(nc, nv, entries, &inverse_masses(mass))?;
    let (lmin, lmax) =
        gram.extreme_eigenvalues(SPARSE_CONDITION_TOL, SPARSE_CONDITION_ITERATIONS)?;
    Some(ratio(lmax, lmin))
}

/// `M⁺`'s diagonal: `1 / m_j`, 0 for a massless coordinate.
fn inverse_masses(mass: &[f64]) -> Vec<f64> {
    mass.iter()
        .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
        .collect()
}

/// `κ(G_v M⁺ G_vᵀ) = λ_max / λ_min` from all eigenvalues of the dense Gram matrix.
///
/// The Gram matrix is accumulated from the nonzeros of `G_v` column by column (a joint row
/// touches the velocities of two bodies, so this costs `O(nnz)` instead of the dense product's
/// `O(nc² nv)`), and its eigenvalues come from faer's blocked symmetric tridiagonalisation on
/// this thread (measured on the 40-four-bar chain, 242 rows: the monitor took a quarter of
/// the solve with nalgebra's unblocked eigenvalues and dense product).
pub fn dense_joint_condition_number(gv: &DMatrix<f64>, mass: &[f64]) -> f64 {
    let nc = gv.nrows();
    if nc == 0 {
        return 1.0;
    }
    let a = gram_lower(gv, mass);
    let Some((ev, _)) = lower_evd(a.as_ref(), false) else {
        // faer's iteration did not converge: the dense reference path
        let ev = mass_weighted_gram(gv, mass).symmetric_eigenvalues();
        return ratio(ev.max(), ev.min());
    };
    let lmax = ev.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let lmin = ev.iter().copied().fold(f64::INFINITY, f64::min);
    ratio(lmax, lmin)
}

fn ratio(lmax: f64, lmin: f64) -> f64 {
    if lmin > 0.0 && lmax > 0.0 {
        lmax / lmin
    } else {
        f64::INFINITY
    }
}

/// The lower triangle of `A = G_v M⁺ G_vᵀ`, accumulated from the nonzeros of `G_v` column by
/// column: `A_ik += G_ij G_kj / m_j` for `i ≥ k` (massless coordinates skipped).
fn gram_lower(gv: &DMatrix<f64>, mass: &[f64]) -> faer::Mat<f64> {
    let (nc, nv) = gv.shape();
    let mut a = faer::Mat::<f64>::zeros(nc, nc);
    let mut col: Vec<(usize, f64)> = Vec::new();
    for j in 0..nv {
        let w = if mass[j] > 0.0 { 1.0 / mass[j] } else { 0.0 };
        if w == 0.0 {
            continue;
        }
        col.clear();
        col.extend((0..nc).filter_map(|i| {
            let v = gv[(i, j)];
            (v != 0.0).then_some((i, v))
        }));
        for &(i, x) in &col {
            for &(k, y) in &col {
                if k <= i {
                    a[(i, k)] += x * w * y;
                }
            }
        }
    }
    a
}

/// Eigenvalues and, when `vectors`, eigenvectors (columns) of the symmetric matrix whose lower
/// triangle `a` holds, sequentially (faer's blocked solver; `None` when it does not converge).
fn lower_evd(
    a: faer::MatRef<'_, f64>,
    vectors: bool,
) -> Option<(Vec<f64>, Option<faer::Mat<f64>>)> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd;
    let n = a.nrows();
    let par = faer::Par::Seq;
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = vectors.then(|| faer::Mat::<f64>::zeros(n, n));
    let compute = if vectors {
        evd::ComputeEigenvectors::Yes
    } else {
        evd::ComputeEigenvectors::No
    };
    let mut mem = MemBuffer::new(evd::self_adjoint_evd_scratch::<f64>(
        n,
        compute,
        par,
        Default::default(),
    ));
    evd::self_adjoint_evd(
        a,
        s.as_mut(),
        u.as_mut().map(|u| u.as_mut()),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    Some((s.column_vector().iter().copied().collect(), u))
}
