//! Index-1 formulation with dummy derivatives (Mattsson–Söderlind), acceleration level.
//!
//! The velocities split into independent `I` and dependent `D` ones (`|D|` = number of
//! constraint rows, `G_v[:, D]` nonsingular) — the dependent ones are those the bond graph gives
//! differential causality. The derivatives of the dependent quantities become algebraic
//! "dummy" unknowns `a_D`, and the position and velocity constraints are kept, so nothing drifts:
//!
//! ```text
//!   q_I' = v_I                        (differential)
//!   0 = g(q)                          (determines q_D)
//!   M_I v_I' = Q_I − G_Iᵀ λ           (differential)
//!   0 = G_v v                         (determines v_D)
//!   M_D a_D = Q_D − G_Dᵀ λ            (dummy derivatives a_D = v_D')
//!   0 = G_I v_I' + G_D a_D + γ        (acceleration-level constraint, determines λ)
//! ```
//!
//! Valid where `G_D` is well conditioned; the runner watches its condition number and re-selects
//! `D` (restarting IDA) when it degrades. Where the coordinates' rates are not the velocities
//! (`q' = K(q) v`: a 3D body's quaternion, a body-fixed planar frame), the dependent coordinates
//! `D_q` (`G_q[:, D_q]` nonsingular) are chosen apart from the dependent velocities and the
//! independent ones keep `q_I' = K_I(q) v` ([`Index1Formulation::build_partitioned`]).

use nalgebra::DMatrix;

use super::compiled::ImplicitDae;
use super::mechanics::ConstraintExprs;
use crate::expr::Expr;
use crate::mech::{MechError, MultibodySystem};
use crate::sundials::schur::SchurSplit;

/// The compiled index-1 residual for one choice of dependent velocities.
#[derive(Clone, Debug)]
pub struct Index1Formulation {
    /// The compiled residual.
    pub dae: ImplicitDae,
    /// Dependent velocity indices (sorted).
    pub dependent: Vec<usize>,
    /// Dependent coordinate indices (sorted; the velocity indices when `q' = v`).
    pub coordinates: Vec<usize>,
    /// The joint rows the dependent block is solved from (sorted): every row, or, where the
    /// joints are redundant, a maximal independent set ([`independent_rows`]); the other rows'
    /// multipliers are held at zero.
    pub rows: Vec<usize>,
    /// Multipliers `λ`: one per joint row, redundant rows included.
    pub multipliers: usize,
    /// The energy invariant's unknowns `(κ, μ)` after `λ`, where the run keeps the energy
    /// ([`EnergyInvariant`]); `None` otherwise.
    pub energy: Option<EnergyInvariant>,
    /// IDA's error-test mask ([`error_test_mask`]): 1 for the independent coordinates and
    /// velocities; 0 for the dependent ones, the dummy accelerations, the multipliers and the
    /// energy invariant's unknowns.
    pub id: Vec<f64>,
}

/// IDA's error-test mask of the index-1 DAE `y = [q, v, a_D, λ, …]` (`(nq, nv, n)`: coordinates,
/// velocities, unknowns; `coordinates` the dependent coordinates, `dependent` the dependent
/// velocities): the independent coordinates and velocities are measured; the dependent ones,
/// the dummy accelerations, the multipliers and the energy invariant's unknowns are not (IDA's
/// `id` with `IDASetSuppressAlg`; bondmech never calls `IDACalcIC`, so the mask is all `id`
/// means here).
///
/// Measuring the dependent velocities too was tried (issue 46) and is not the default: their
/// error is the independent ones' amplified by the dependent block, and with them in the test a
/// five-bar whose couplers' block degrades to μ ≈ 10–100 before a re-selection went from 12×,
/// 8.6×, 4.1× the GGL's error at rtol 1e-7 / 1e-8 / 1e-9 to 1.7×, 0.52×, 0.61×. But IDA's local
/// error estimate of an algebraic unknown is its predictor's miss, and `v_D = −G_v[R, D]⁻¹ G_v[R, I]
/// v_I` varies on the time scale of the block's smallest singular value: a bead in a slot beside
/// its pivot (rtol 1e-9) took 10 162 error-test failures in 15 345 steps and ended 1.6e-6 off
/// (3.5e-8 before), a spherical pendulum stayed at order 1 with h ≈ 9e-6 for 700 steps and lost
/// 1.6e-4 J. What the five-bar needs is the independent velocities weighted by the block's
/// amplification, not the dependent ones' predictor (docs/performance.md, "The default's error
/// test"). The exception, `measured`: the velocities of a freely rotating spatial body stay in
/// the test when dependent ([`super::partition::always_measured_velocities`]).
///
/// ```
/// use bondmech::dae::index1::error_test_mask;
/// // a pendulum bob: q = (x, y), v = (vx, vy), y and vy dependent; then a_D and λ
/// let none = [false, false];
/// assert_eq!(error_test_mask((2, 2, 6), &[1], &[1], &none), vec![1.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
/// ```
pub fn error_test_mask(
    (nq, nv, n): (usize, usize, usize),
    coordinates: &[usize],
    dependent: &[usize],
    measured: &[bool],
) -> Vec<f64> {
    let mut id = vec![1.0; nq + nv];
    for &i in coordinates {
        id[i] = 0.0;
    }
    for &j in dependent {
        if !measured.get(j).copied().unwrap_or(false) {
            id[nq + j] = 0.0;
        }
    }
    id.resize(n, 0.0);
    id
}

/// The energy of a conservative mechanism kept as an invariant of the index-1 DAE, `E(q, v) =
/// E₀`, with one multiplier `μ` acting along the energy's gradient on the joints' manifold
/// (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, IV.4: projection onto the
/// invariant; here as a row of the DAE, so IDA keeps it at every step instead of a projection
/// after the step):
///
/// ```text
///   q_I' = K_I(q) v − μ ĝ_I,        ĝ_I = h_I − G_q[R, I]ᵀ κ       (the reduced gradient)
///   h = ∂E/∂q − (∂(G_v v)/∂q)ᵀ η                                   (v_D moves with q)
///   0 = G_v[R, D]ᵀ η − ∂E/∂v_D                                     (determines η)
///   0 = G_q[R, D_q]ᵀ κ − h_D                                       (determines κ)
///   M v' = Q − G_vᵀ λ − μ M v                                      (independent and dummy rows)
///   0 = E(q, v) − E₀                                               (determines μ)
/// ```
///
/// `ĝ_I` is the gradient of `E` along the manifold in the independent coordinates at fixed
/// independent velocities (the dependent coordinates and velocities follow the joints), and `−μ M v` removes kinetic energy
/// along the velocity itself (tangent: `G_v v = 0`), so `dE/dμ = −(|ĝ_I|² + vᵀ M v)`, which
/// vanishes only at rest in an equilibrium: the row holds wherever the mechanism moves. In the
/// exact solution `μ = 0`; numerically `μ` absorbs the integrator's energy error, which BDF's
/// numerical damping makes one-signed and which, over hundreds of periods of an undamped
/// oscillation, becomes a phase error (the IFToMM A01 pendulum). `η`, `κ` and `μ` are algebraic
/// and left out of the local error test (`μ` is an index-2 unknown, as the GGL's position
/// multipliers are).
#[derive(Clone, Debug, PartialEq)]
pub struct EnergyInvariant {
    /// The energy kept, `E₀` (J).
    pub e0: f64,
    /// Offset of `η` in `y` (`r` entries, one per independent joint row), then `κ` (`r`),
    /// then `μ`.
    pub offset: usize,
}

/// Picks `nc` columns of `G_v` by Gram–Schmidt with column pivoting (largest remaining norm
/// first), taking the `preferred` columns first and the others only when the preferred ones
/// cannot complete the set. Returns `None` when `G_v` has lower rank than its number of rows.
///
/// The preference reproduces the seed's causality pattern (16.5, 16.7): the joints force the
/// translational inertias into differential causality, while the rotations — on which the
/// MTF moduli depend — keep integral causality and become the independent coordinates.
pub fn select_dependent(gv: &DMatrix<f64>, preferred: &[bool]) -> Option<Vec<usize>> {
    let (m, n) = gv.shape();
    let mut cols: Vec<nalgebra::DVector<f64>> = (0..n).map(|j| gv.column(j).into_owned()).collect();
    let scale = cols
        .iter()
        .map(|c| c.norm())
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let mut chosen = Vec::with_capacity(m);
    // a column is usable when what is left of it after projection is not negligible
    let usable = 1e-3 * scale;
    for _ in 0..m {
        let pick = |pref_only: bool, chosen: &Vec<usize>, cols: &Vec<nalgebra::DVector<f64>>| {
            (0..n)
                .filter(|j| {
                    !chosen.contains(j)
                        && (!pref_only || preferred.get(*j).copied().unwrap_or(false))
                })
                .map(|j| (j, cols[j].norm()))
                .filter(|&(_, nrm)| nrm > usable)
                .fold(None, |a: Option<(usize, f64)>, b| match a {
                    Some(x) if x.1 >= b.1 => Some(x),
                    _ => Some(b),
                })
        };
        let (best, norm) = pick(true, &chosen, &cols).or_else(|| pick(false, &chosen, &cols))?;
        if norm <= 1e-10 * scale {
            return None;
        }
        chosen.push(best);
        let u = cols[best].clone() / norm;
        for c in cols.iter_mut() {
            let p = u.dot(c);
            *c -= &u * p;
        }
    }
    chosen.sort_unstable();
    Some(chosen)
}

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
/// use bondmech::dae::dependent_condition;
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
/// use bondmech::dae::{dependent_condition, dependent_condition_bound};
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

/// Joint rows from which [`JointRows`] reads `G_v` by its non-zeros and measures the dependent
/// block's grip by sparse Cholesky factors and Lanczos iterations (linear in the size of a
/// chain) instead of dense singular values (cubic): the size from which the joints' condition
/// monitor takes its sparse path ([`crate::dae::singular::SPARSE_CONDITION_ROWS`]). Measured
/// on the N-link pendulum (`cargo bench --bench sparse`, `BONDMECH_SPARSE_BENCH=dae`): at
/// N = 64 (128 rows) the dense singular values at the outputs took three quarters of the run.
pub const SPARSE_GRIP_ROWS: usize = super::singular::SPARSE_CONDITION_ROWS;

/// Relative accuracy of the smallest eigenvalues of `G_v G_vᵀ` and `G_D G_Dᵀ` on the sparse
/// path (the Lanczos residual bound, [`super::gram::lanczos_largest`] on the inverse): the
/// checks compare `μ(D)` and `κ(G_v)` with thresholds a factor 2 or 10 apart. The small
/// eigenvalues are well separated; a few steps suffice.
pub const SPARSE_GRIP_TOL: f64 = 1e-3;

/// Relative accuracy of `λ_max(G_v G_vᵀ)` on the sparse path (plain Lanczos from below: the
/// Ritz value is a lower bound). The top of a chain's spectrum is clustered, and resolving it
/// costs steps that grow with the chain (measured on the N-link pendulum at N = 256: 102 steps
/// for 1e-3, 10 for 1e-2, where the value found was 0.3 % below the top); `μ(D) ∝ √λ_max` is
/// then within 0.5 %.
pub const SPARSE_GRIP_TOP_TOL: f64 = 1e-2;

/// Lanczos steps for `λ_max(G_v G_vᵀ)` on the sparse path, after which the Ritz value is taken
/// as it is (a lower bound of `λ_max`; its deficit on a clustered top falls with the steps'
/// square): with the chain nearly straight (the joint rows along it decoupled from the
/// rotations) the residual test took steps enough to cost a tenth of the run at N = 32 (perf:
/// `top_eigenvalue` and the tridiagonal bisections 8 %). The re-selection's test
/// `μ(D) > INDEX1_RESELECT_GAIN κ(G_v)` does not depend on it: `λ_max` divides out of the ratio.
pub const SPARSE_GRIP_TOP_STEPS: usize = 16;

/// Lanczos steps for `λ_max(G_v G_vᵀ)` from the previous output's Ritz vector
/// ([`JointRows::with_hints`]): the Krylov space holds that vector, so the Ritz value is at
/// least its Rayleigh quotient at the new state — as close to the top as the last estimate
/// was where the motion between outputs is smooth — and the steps refine it. On the N-link
/// pendulum the 16 cold steps at every output were 6 % of the run at N = 128.
pub const SPARSE_GRIP_TOP_WARM_STEPS: usize = 4;

/// Lanczos steps per eigenvalue on the sparse path before the dense singular values decide.
const SPARSE_GRIP_ITERATIONS: usize = 200;

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
/// come from Lanczos iterations ([`super::gram::lanczos_largest`]: on the inverse of the sparse
/// Gram matrix through its Cholesky factor for `λ_min`, [`super::gram::SparseGram`]; on the
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
    pub fn new(tape: &super::MatrixTape, t: f64, x: &[f64]) -> Self {
        if tape.rows >= SPARSE_GRIP_ROWS {
            Self::from_entries((tape.rows, tape.cols), tape.entries(t, x))
        } else {
            Self::from_dense(tape.matrix(t, x))
        }
    }

    /// The dense `gv` (the dense path whatever its size).
    pub fn from_dense(gv: DMatrix<f64>) -> Self {
        JointRows {
            shape: gv.shape(),
            sparse: false,
            entries: Vec::new(),
            dense: Some(gv),
            top: None,
            bottom: None,
            block_vector: Vec::new(),
            hint: Vec::new(),
            bottom_vector: Vec::new(),
            block_known: None,
            top_vector: Vec::new(),
        }
    }

    /// The `nc × nv` matrix of the non-zeros `entries` (row-major; the sparse path whatever
    /// its size).
    pub fn from_entries(shape: (usize, usize), entries: Vec<(usize, usize, f64)>) -> Self {
        JointRows {
            shape,
            sparse: true,
            entries,
            dense: None,
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
            (super::gram::start_vector(m), SPARSE_GRIP_TOP_STEPS)
        };
        let top_vector = &mut self.top_vector;
        *self.top.get_or_insert_with(|| {
            let mut w = vec![0.0; n];
            let (top, u) = super::gram::lanczos_largest_vector(
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
            let pair = super::gram::SparseGram::from_entries(m, n, &self.entries, &vec![1.0; n])
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
/// Lanczos ([`super::gram::lanczos_largest`], relative accuracy [`SPARSE_GRIP_TOL`]) on
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
    let (top, u) = super::gram::lanczos_largest_vector(
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
            super::gram::start_vector(n)
        },
        SPARSE_GRIP_TOL,
        SPARSE_GRIP_ITERATIONS,
    );
    (top.converged && top.theta > 0.0).then(|| (1.0 / top.theta, u))
}

impl Index1Formulation {
    /// The split of `y = [q, v, a_D, λ]` (`nq` coordinates) for the Schur solver of the Newton matrix
    /// ([`crate::sundials::schur`]): the independent coordinates and velocities `(q_I, v_I)`,
    /// and the dependent blocks in the order that makes them block lower triangular — `q_D`
    /// (rows `g = 0`, block `G_qD`), `v_D` (rows `G_v v = 0`, block `G_vD`), then the saddle
    /// of the dummy accelerations and the multipliers,
    ///
    /// ```text
    ///   [M_D  G_Dᵀ] [a_D]     (the dependent inertias' dynamics)
    ///   [G_D  0   ] [λ  ]     (the acceleration constraints, rows R; λ_k = 0 for k ∉ R)
    /// ```
    ///
    /// as two triangular blocks: `a_D` from the acceleration constraints (`G_D = G_v[R, D]`,
    /// square), then `λ` from the dynamics rows and the redundant rows' `λ_k = 0`
    /// (`[G_Dᵀ G_{R̄,D}ᵀ; 0 I]`), `M_D` below the block diagonal. Two inversions of the joint
    /// rows' size instead of one of twice it: a quarter of the saddle's work.
    pub fn schur_split(&self, nq: usize) -> SchurSplit {
        let r = self.dependent.len();
        let extra = if self.energy.is_some() { 2 * r + 1 } else { 0 };
        let nv = self.dae.n - nq - r - self.multipliers - extra;
        let mut outer: Vec<usize> = (0..nq)
            .filter(|i| !self.coordinates.contains(i))
            .chain(
                (0..nv)
                    .filter(|j| !self.dependent.contains(j))
                    .map(|j| nq + j),
            )
            .collect();
        // rows nq + nv .. + r: the dependent inertias' dynamics; then one row per joint row k:
        // its acceleration constraint (k ∈ R) or λ_k = 0
        let (a0, l0) = (nq + nv, nq + nv + r);
        let mut blocks = vec![
            self.coordinates.clone(),
            self.dependent.iter().map(|&j| nq + j).collect(),
            (a0..l0).collect(),
            (l0..l0 + self.multipliers).collect(),
        ];
        let mut row_blocks = blocks.clone();
        row_blocks[2] = self.rows.iter().map(|&k| l0 + k).collect();
        row_blocks[3] = (a0..l0)
            .chain(
                (0..self.multipliers)
                    .filter(|k| !self.rows.contains(k))
                    .map(|k| l0 + k),
            )
            .collect();
        if let Some(inv) = &self.energy {
            // η after λ (its rows read q, v), κ after it (its rows read q, v, η), μ with the
            // degrees of freedom (its row reads every coordinate and velocity)
            for b in [
                inv.offset..inv.offset + r,
                inv.offset + r..inv.offset + 2 * r,
            ] {
                blocks.push(b.clone().collect());
                row_blocks.push(b.collect());
            }
            outer.push(inv.offset + 2 * r);
        }
        SchurSplit {
            outer,
            blocks,
            row_blocks,
        }
    }

    /// Builds the residual for the dependent set `dependent` (velocity indices), with the same
    /// indices as the dependent coordinates: needs `q' = v` (planar bodies in the seed's
    /// non-rotating frame, 16.8). [`Index1Formulation::build_partitioned`] takes both sets.
    ///
    /// Slots: `y = [q, v, a_D, λ]` at `1..=n`, `y'` at `n+1..=2n`.
    pub fn build(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        dependent: &[usize],
    ) -> Result<Self, MechError> {
        let (nq, nv) = (sys.nq(), sys.nv());
        let identity = nq == nv
            && (0..nq).all(|i| {
                let s = sys.v_slot(i);
                let v = sys.graph.var(s);
                sys.kinematics[i] == v
            });
        if !identity {
            return Err(MechError::at(
                "solve.formulation",
                "the index-1 formulation with one dependent set needs q' = v (planar bodies in the default non-rotating frame); give the dependent coordinates too",
            ));
        }
        let rows: Vec<usize> = (0..sys.nc()).collect();
        Self::build_partitioned(sys, c, dependent, dependent, &rows)
    }

    /// Builds the residual for dependent velocities `dependent` and dependent coordinates
    /// `coordinates` (each `r` indices, `r` = `rows.len()`, the independent joint rows `R`:
    /// every row unless the joints are redundant; `G_v[R, D]` and `G_q[R, D_q]` nonsingular) of a
    /// mechanism whose coordinates move as `q' = K(q) v` (quaternions of 3D bodies, body-fixed
    /// planar frames, or `K = I`):
    ///
    /// ```text
    ///   q_I' = K_I(q) v                   (differential: the coordinates not in D_q)
    ///   0 = g(q)                          (determines q_D)
    ///   M_I v_I' = Q_I − G_Iᵀ λ           (differential)
    ///   0 = G_v v                         (determines v_D)
    ///   M_D a_D = Q_D − G_Dᵀ λ            (a_D = v_D')
    ///   0 = G_I v_I' + G_D a_D + γ        (determines λ)
    /// ```
    ///
    /// with `g`, `G_v v` and the acceleration rows taken over the rows `R` only, and `λ_k = 0`
    /// for a row `k` outside `R` (a redundant row: its force is not determined by the motion,
    /// and the reactions reported take it as zero).
    ///
    /// Slots: `y = [q, v, a_D, λ]` at `1..=n` (`a_D` of length `r`, `λ` one per row), `y'` at
    /// `n+1..=2n`.
    pub fn build_partitioned(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        dependent: &[usize],
        coordinates: &[usize],
        rows: &[usize],
    ) -> Result<Self, MechError> {
        Self::build_with_energy(sys, c, (dependent, coordinates, rows), None)
    }

    /// The same formulation (dependent velocities, joint rows, compiled tapes) with the
    /// dependent coordinates `coordinates` (`r` sorted indices, `G_q[R, D_q]` nonsingular): the
    /// coordinates' rows are selected again among the candidates the tapes compute (the
    /// kinematic row of each coordinate, each position row), nothing is compiled. `None` for a
    /// formulation that keeps the energy invariant (its rows depend on `D_q` otherwise).
    pub fn with_coordinates(&self, nq: usize, coordinates: &[usize]) -> Option<Self> {
        let r = self.rows.len();
        if self.energy.is_some()
            || coordinates.len() != r
            || coordinates.iter().any(|&i| i >= nq)
            || self.dae.candidates() != self.dae.n + r
        {
            return None;
        }
        // the velocities' and the other unknowns' entries of the mask do not depend on the
        // coordinates chosen ([`error_test_mask`])
        let mut id = self.id.clone();
        for (i, d) in id.iter_mut().enumerate().take(nq) {
            *d = if coordinates.contains(&i) { 0.0 } else { 1.0 };
        }
        Some(Index1Formulation {
            dae: self
                .dae
                .with_selection(coordinate_rows(nq, self.dae.n, coordinates)),
            dependent: self.dependent.clone(),
            coordinates: coordinates.to_vec(),
            rows: self.rows.clone(),
            multipliers: self.multipliers,
            energy: None,
            id,
        })
    }

    /// [`Index1Formulation::build_partitioned`] with, where `e0` is given, the system's energy
    /// kept at `e0` as an invariant ([`EnergyInvariant`]): `y = [q, v, a_D, λ, η, κ, μ]`.
    pub fn build_with_energy(
        sys: &mut MultibodySystem,
        c: &ConstraintExprs,
        (dependent, coordinates, rows): (&[usize], &[usize], &[usize]),
        e0: Option<f64>,
    ) -> Result<Self, MechError> {
        let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
        let r = rows.len();
        if dependent.len() != r || coordinates.len() != r || rows.iter().any(|&k| k >= nc) {
            return Err(MechError::at(
                "solve.formulation",
                format!(
                    "index-1 needs {r} dependent velocities and coordinates for its {r} independent rows of {nc}, got {} and {}",
                    dependent.len(),
                    coordinates.len()
                ),
            ));
        }
        let n = nq + nv + r + nc + if e0.is_some() { 2 * r + 1 } else { 0 };
        let eta = |k: usize| (1 + nq + nv + r + nc + k) as u32;
        let kappa = |k: usize| (1 + nq + nv + r + nc + r + k) as u32;
        let mu_slot = (1 + nq + nv + r + nc + 2 * r) as u32;
        let a_slot = |k: usize| (1 + nq + nv + k) as u32;
        let lam = |k: usize| (1 + nq + nv + r + k) as u32;
        let qp = |i: usize| (1 + n + i) as u32;
        let vp = |j: usize| (1 + n + nq + j) as u32;
        let dpos = |j: usize| dependent.iter().position(|&d| d == j);
        let qpos = |i: usize| coordinates.iter().position(|&d| d == i);
        let energy = sys.energy;
        let v_slots: Vec<u32> = (0..nv).map(|j| sys.v_slot(j)).collect();
        let measured = super::partition::always_measured_velocities(sys);
        let g = &mut sys.graph;
        // ∂E/∂q and ∂E/∂v in one reverse sweep (linear in the energy's size)
        let (de_dq, de_dv) = if e0.is_some() {
            let slots: Vec<u32> = (0..nq)
                .map(|i| (1 + i) as u32)
                .chain(v_slots.iter().copied())
                .collect();
            let mut d = g.gradient(energy, &slots);
            let dv = d.split_off(nq);
            (d, dv)
        } else {
            (Vec::new(), Vec::new())
        };
        // h = ∂E/∂q − (∂(G_v v)/∂q)ᵀ η: the energy's gradient in the coordinates with the
        // dependent velocities' dependence on them (G_v[R, D]ᵀ η = ∂E/∂v_D)
        let grad: Vec<Expr> = if e0.is_some() {
            (0..nq)
                .map(|i| {
                    let mut terms = vec![de_dq[i]];
                    for (k, &rk) in rows.iter().enumerate() {
                        if g.depends_on(c.gvv[rk], (1 + i) as u32) {
                            let d = g.diff(c.gvv[rk], (1 + i) as u32);
                            let e = g.var(eta(k));
                            let t = g.mul(d, e);
                            terms.push(g.neg(t));
                        }
                    }
                    g.sum(&terms)
                })
                .collect()
        } else {
            Vec::new()
        };
        let mu = g.var(mu_slot);
        let mut res: Vec<Expr> = Vec::with_capacity(n);
        // without the invariant, every coordinate's kinematic row and every position row are
        // candidates, the dependent coordinates' choice a selection among them
        // ([`Index1Formulation::with_coordinates`]): q_i' − K_i v for i ∉ D_q, g_{R_k} for the
        // k-th dependent coordinate
        let selectable = e0.is_none();
        if selectable {
            for i in 0..nq {
                let a = g.var(qp(i));
                res.push(g.sub(a, sys.kinematics[i]));
            }
            res.extend(rows.iter().map(|&k| c.g[k]));
        }
        // q rows
        for i in (0..nq).filter(|_| !selectable) {
            match qpos(i) {
                Some(k) => res.push(c.g[rows[k]]),
                None => {
                    let a = g.var(qp(i));
                    let mut row = g.sub(a, sys.kinematics[i]);
                    if let Some(&h) = grad.get(i) {
                        // + μ ĝ_i, ĝ_i = h_i − Σ_k G_q[R_k, i] κ_k
                        let mut terms = vec![h];
                        for (k, &rk) in rows.iter().enumerate() {
                            if !g.is_zero(c.gq[rk][i]) {
                                let kk = g.var(kappa(k));
                                let t = g.mul(c.gq[rk][i], kk);
                                terms.push(g.neg(t));
                            }
                        }
                        let gi = g.sum(&terms);
                        let push = g.mul(mu, gi);
                        row = g.add(row, push);
                    }
                    res.push(row);
                }
            }
        }
        // dynamics with the multipliers, for v_j' (independent) or a_j (dependent)
        let keep = e0.is_some();
        let dyn_row = |g: &mut crate::expr::ExprGraph, j: usize, acc: Expr| {
            let mut terms = vec![g.scale(sys.mass[j], acc)];
            if keep && sys.mass[j] != 0.0 {
                // + μ M_j v_j
                let v = g.var(v_slots[j]);
                let mv = g.scale(sys.mass[j], v);
                terms.push(g.mul(mu, mv));
            }
            terms.push(g.neg(sys.forces[j]));
            for k in 0..nc {
                if !g.is_zero(c.gv[k][j]) {
                    let l = g.var(lam(k));
                    terms.push(g.mul(c.gv[k][j], l));
                }
            }
            g.sum(&terms)
        };
        for j in 0..nv {
            match dpos(j) {
                Some(k) => res.push(c.gvv[rows[k]]),
                None => {
                    let a = g.var(vp(j));
                    res.push(dyn_row(g, j, a));
                }
            }
        }
        for (k, &j) in dependent.iter().enumerate() {
            let a = g.var(a_slot(k));
            res.push(dyn_row(g, j, a));
        }
        for k in 0..nc {
            if !rows.contains(&k) {
                // a redundant row: its multiplier is held at zero
                res.push(g.var(lam(k)));
                continue;
            }
            let mut terms = vec![c.gamma[k]];
            for j in 0..nv {
                if g.is_zero(c.gv[k][j]) {
                    continue;
                }
                let acc = match dpos(j) {
                    Some(kk) => g.var(a_slot(kk)),
                    None => g.var(vp(j)),
                };
                terms.push(g.mul(c.gv[k][j], acc));
            }
            res.push(g.sum(&terms));
        }
        if let Some(e0) = e0 {
            // η: G_v[R, D]ᵀ η − ∂E/∂v_D = 0, one row per dependent velocity
            for &j in dependent {
                let mut terms = vec![];
                terms.push(g.neg(de_dv[j]));
                for (k, &rk) in rows.iter().enumerate() {
                    if !g.is_zero(c.gv[rk][j]) {
                        let e = g.var(eta(k));
                        terms.push(g.mul(c.gv[rk][j], e));
                    }
                }
                res.push(g.sum(&terms));
            }
            // κ: G_q[R, D_q]ᵀ κ − h_D = 0, one row per dependent coordinate
            for &i in coordinates {
                let mut terms = vec![g.neg(grad[i])];
                for (k, &rk) in rows.iter().enumerate() {
                    if !g.is_zero(c.gq[rk][i]) {
                        let kk = g.var(kappa(k));
                        terms.push(g.mul(c.gq[rk][i], kk));
                    }
                }
                res.push(g.sum(&terms));
            }
            // μ: E(q, v) − E₀ = 0
            let e = g.constant(e0);
            res.push(g.sub(energy, e));
        }
        let id = error_test_mask((nq, nv, n), coordinates, dependent, &measured);
        let dae = if selectable {
            ImplicitDae::build_selected(g, &res, n, Some(coordinate_rows(nq, n, coordinates)))
        } else {
            ImplicitDae::build(g, &res, n)
        };
        Ok(Index1Formulation {
            dae,
            dependent: dependent.to_vec(),
            coordinates: coordinates.to_vec(),
            rows: rows.to_vec(),
            multipliers: nc,
            energy: e0.map(|e0| EnergyInvariant {
                e0,
                offset: nq + nv + r + nc,
            }),
            id,
        })
    }
}

/// The candidate row of each row of the index-1 DAE without the energy invariant (`n` rows,
/// the candidates `[q_i' − K_i v (nq), g_{R_k} (r), the other n − nq rows]`): coordinate `i`'s
/// row is its kinematic row, or the `k`-th position row where `i` is the `k`-th dependent
/// coordinate; the other rows follow in order.
fn coordinate_rows(nq: usize, n: usize, coordinates: &[usize]) -> Vec<usize> {
    let r = coordinates.len();
    (0..nq)
        .map(|i| match coordinates.iter().position(|&d| d == i) {
            Some(k) => nq + k,
            None => i,
        })
        .chain((nq..n).map(|j| j + r))
        .collect()
}

/// The rows of `gv` that determine the motion where `redundant` of its rows are redundant
/// (sorted; all rows when `redundant` is 0): the rows left out are those where the joints'
/// self-stress — the left null space `N` of `gv`, `Nᵀ G_v = 0`, the eigenvectors of `G_v G_vᵀ`
/// of its `redundant` smallest eigenvalues — is held best ([`select_dependent`] on `Nᵀ`, the
/// rows in `prefer` (the causality's redundant junctions) first). Leaving out rows `L` keeps
/// the rank exactly when `N[L, :]` is regular, and the kept rows are best conditioned when it
/// is well conditioned. `None` when no such choice exists.
///
/// ```
/// use bondmech::dae::independent_rows;
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
/// use bondmech::dae::redundant_row_grip;
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

#[cfg(test)]
mod tests {
    use super::*;

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
