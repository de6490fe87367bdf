//! How well a dependent block holds the dependent velocities: `μ(D) = σ_max(G_v) / σ_min(G_D)`
//! (dense singular values), its cheap upper bound and the lower bound over every block.

use nalgebra::DMatrix;

/// How well the dependent block `G_v[:, D]` holds the dependent velocities, relative to the
/// whole velocity Jacobian: `μ(D) = σ_max(G_v) / σ_min(G_v[:, D])` (2-norm), ∞ for a singular
/// block.
///
/// It bounds the block's own condition number, `μ(D) ≥ κ(G_v[:, D])` (a block's columns are
/// some of `G_v`'s, so `σ_max(G_D) ≤ σ_max(G_v)`), and, unlike `κ(G_D)`, it also sees a block
/// that loses its grip uniformly: a point mass on a massless link, `G_v = [x  y]` with `D =
/// {x}`, has `κ(G_D) = 1` at every position but `μ = |(x, y)| / |x|`, which grows without bound
/// as the bob passes under the pivot — where `v_x = −(y/x) v_y` can no longer be solved for.
/// `v_D = −G_D⁻¹ G_I v_I` amplifies the independent velocities by at most `μ(D)`.
///
/// ```
/// use bondmech::partition::dependent_condition;
/// use nalgebra::DMatrix;
/// // the bob 0.01 rad from under the pivot: x = sin 0.01, y = −cos 0.01
/// let gv = DMatrix::from_row_slice(1, 2, &[0.01f64.sin(), -0.01f64.cos()]);
/// assert!((dependent_condition(&gv, &[0]) - 1.0 / 0.01f64.sin()).abs() < 1e-9);
/// assert!((dependent_condition(&gv, &[1]) - 1.0 / 0.01f64.cos()).abs() < 1e-9);
/// ```
pub fn dependent_condition(gv: &DMatrix<f64>, dependent: &[usize]) -> f64 {
    let m = gv.nrows();
    if m == 0 {
        return 1.0;
    }
    let sub = DMatrix::from_fn(m, dependent.len(), |i, k| gv[(i, dependent[k])]);
    let mn = sub.singular_values().min();
    let mx = gv.singular_values().max();
    if mn <= 0.0 {
        f64::INFINITY
    } else {
        mx / mn
    }
}

/// An upper bound on [`dependent_condition`] without singular values, for the dense path's
/// routine examinations: `μ(D) = σ_max(G_v) · σ_max(G_D⁻¹)`, and for a symmetric positive
/// semi-definite `m × m` matrix `P` with largest eigenvalue `λ`,
///
/// ```text
///   λ⁸ ≤ trace(P⁸) = ‖P⁴‖_F² ≤ m λ⁸,   so   λ ≤ ‖P⁴‖_F^(1/4) ≤ m^(1/8) λ;
///   σ_max(G_v)² = λ_max(G_v G_vᵀ),   σ_max(G_D⁻¹)² = λ_max(G_D⁻ᵀ G_D⁻¹),
///   μ(D) ≤ ‖(G_v G_vᵀ)⁴‖_F^(1/8) · ‖(G_D⁻ᵀ G_D⁻¹)⁴‖_F^(1/8) ≤ m^(1/8) μ(D).
/// ```
///
/// `m` = the rows (`m^(1/8)` is 1.19 at 4 rows, 1.28 at 7, 1.41 at 16). One inversion of the
/// block and, per factor, three symmetric products (`m²(m + 1)/2` multiply-adds each), where
/// the two singular value decompositions of [`dependent_condition`] cost several times as
/// much. Each matrix is scaled by its largest entry before its powers are formed (no
/// overflow). ∞ for a
/// singular or non-square block; 1 without rows, as [`dependent_condition`].
///
/// ```
/// use bondmech::partition::{dependent_condition, dependent_condition_bound};
/// use nalgebra::DMatrix;
/// let gv = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, -0.3, 0.0, 1.0, 0.4]);
/// let (mu, bound) = (dependent_condition(&gv, &[0, 1]), dependent_condition_bound(&gv, &[0, 1]));
/// assert!(mu <= bound && bound <= 2f64.powf(0.125) * mu * (1.0 + 1e-12));
/// ```
pub fn dependent_condition_bound(gv: &DMatrix<f64>, dependent: &[usize]) -> f64 {
    if gv.nrows() == 0 {
        return 1.0;
    }
    match dependent_condition_bound_factors(gv, dependent) {
        Some((top, inverse)) if (top * inverse).is_finite() => top * inverse,
        _ => f64::INFINITY,
    }
}

/// The two factors of [`dependent_condition_bound`]: `(a, b)` with `a ≥ σ_max(G_v)` and `b ≥
/// σ_max(G_D⁻¹) = 1 / σ_min(G_D)`; `None` for a singular or non-square block (or no rows).
/// With them, at a nearby `G_v + Δ` (Weyl: singular values move by at most `‖Δ‖₂ ≤ ‖Δ‖_F`,
/// and `Δ_D` is a block of `Δ`),
///
/// ```text
///   μ(D) ≤ (a + ‖Δ‖_F) / (1/b − ‖Δ‖_F)        where ‖Δ‖_F < 1/b.
/// ```
pub fn dependent_condition_bound_factors(
    gv: &DMatrix<f64>,
    dependent: &[usize],
) -> Option<(f64, f64)> {
    let m = gv.nrows();
    if m == 0 || dependent.len() != m {
        return None;
    }
    // G_v column-major (nalgebra's storage); the block's inverse (Gauss–Jordan)
    let mut rows = gv.as_slice().to_vec();
    let mut block = vec![0.0; m * m];
    for (k, col) in block.chunks_exact_mut(m).enumerate() {
        for (i, c) in col.iter_mut().enumerate() {
            *c = gv[(i, dependent[k])];
        }
    }
    // `block` holds G_D column-major, i.e. G_Dᵀ row-major: its inverse is G_D⁻ᵀ row-major,
    // G_D⁻¹ column-major
    if !invert_row_major(&mut block, m) {
        return None;
    }
    Some((
        largest_singular_value_bound(&mut rows, m),
        largest_singular_value_bound(&mut block, m),
    ))
}

/// `‖(A Aᵀ)⁴‖_F^(1/8) ≥ σ_max(A)` for the column-major `m × (a.len() / m)` matrix `a`
/// (overwritten: scaled by its largest entry `s` first, `A = s B`, so that the powers of
/// `B Bᵀ` neither overflow nor underflow).
fn largest_singular_value_bound(a: &mut [f64], m: usize) -> f64 {
    let s = a.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    if s == 0.0 || !s.is_finite() {
        return if s == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let inv_s = 1.0 / s;
    a.iter_mut().for_each(|v| *v *= inv_s);
    let mut p = vec![0.0; m * m];
    let mut p2 = vec![0.0; m * m];
    gram_into(a, m, &mut p); // P = B Bᵀ
    gram_into(&p, m, &mut p2); // P² = P Pᵀ (P symmetric)
    gram_into(&p2, m, &mut p); // P⁴
    let frobenius = p.iter().map(|v| v * v).sum::<f64>().sqrt();
    s * frobenius.powf(0.125)
}

/// `g = X Xᵀ = Σ_c x_c x_cᵀ` for the column-major matrix `x` with columns `x_c` of length `m`
/// (`g`: `m × m`, column-major), column by column as updates `g_j += x_jc x_c` (no
/// reductions: the compiler vectorises them).
fn gram_into(x: &[f64], m: usize, g: &mut [f64]) {
    g.fill(0.0);
    for xc in x.chunks_exact(m) {
        for (gj, &s) in g.chunks_exact_mut(m).zip(xc) {
            if s != 0.0 {
                for (gi, &xi) in gj.iter_mut().zip(xc) {
                    *gi += s * xi;
                }
            }
        }
    }
}

/// Replaces the row-major `m × m` matrix `a` by its inverse (Gauss–Jordan elimination with
/// partial pivoting); `false` on a zero or non-finite pivot.
fn invert_row_major(a: &mut [f64], m: usize) -> bool {
    let mut inv = vec![0.0; m * m];
    for i in 0..m {
        inv[i * m + i] = 1.0;
    }
    // the pivot row of `a` and of the inverse, copied out for the elimination
    let (mut ak, mut ik) = (vec![0.0; m], vec![0.0; m]);
    for k in 0..m {
        let mut p = k;
        for r in k + 1..m {
            if a[r * m + k].abs() > a[p * m + k].abs() {
                p = r;
            }
        }
        if p != k {
            for c in 0..m {
                a.swap(k * m + c, p * m + c);
                inv.swap(k * m + c, p * m + c);
            }
        }
        let pivot = a[k * m + k];
        if pivot == 0.0 || !pivot.is_finite() {
            return false;
        }
        let scale = 1.0 / pivot;
        for (c, (x, y)) in ak.iter_mut().zip(ik.iter_mut()).enumerate() {
            a[k * m + c] *= scale;
            inv[k * m + c] *= scale;
            (*x, *y) = (a[k * m + c], inv[k * m + c]);
        }
        for r in (0..m).filter(|&r| r != k) {
            let f = a[r * m + k];
            if f != 0.0 {
                for (x, y) in a[r * m..(r + 1) * m].iter_mut().zip(&ak) {
                    *x -= f * y;
                }
                for (x, y) in inv[r * m..(r + 1) * m].iter_mut().zip(&ik) {
                    *x -= f * y;
                }
            }
        }
    }
    a.copy_from_slice(&inv);
    a.iter().all(|v| v.is_finite())
}

/// A lower bound on [`dependent_condition`] over every square block of `nc` columns of the
/// `nc × nv` matrix `gv`: `μ(D) ≥ κ(G_v) = σ_max(G_v) / σ_min(G_v)`. (Deleting columns does not
/// raise a singular value, `G_v G_vᵀ ⪰ G_D G_Dᵀ`, so `σ_min(G_D) ≤ σ_min(G_v)`.) 0 when `gv` has
/// no rows or more rows than columns.
pub fn block_condition_bound(gv: &DMatrix<f64>) -> f64 {
    let (m, n) = gv.shape();
    if m == 0 || m > n {
        return 0.0;
    }
    let s = gv.singular_values();
    let smin = s.min();
    if smin <= 0.0 {
        return f64::INFINITY;
    }
    s.max() / smin
}
