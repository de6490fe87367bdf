//! Consistent initial values, computed by bondmech (IDA's `IDACalcIC` cannot initialise GGL).
//!
//! 1. Positions: the least change `min ‖q − q₀‖` with `g(q) = 0`, by Gauss–Newton steps
//!    `Δq = −G_q⁺ g(q)` (pseudo-inverse, so redundant rows do no harm).
//! 2. Velocities: the least change with `G_v v + b = 0`: `v ← v − G_v⁺ (G_v v + b)` (`b = ∂g/∂t`
//!    of a driver's row, zero otherwise).
//! 3. Accelerations and multipliers: `[M G_vᵀ; G_v 0] [v'; λ] = [Q; −γ]`, solved in the
//!    least-squares sense; the rank of `G_v` tells which joints are redundant.
//!
//! Steps 2 and 3 take dense SVDs (cubic in the size). From [`SPARSE_START_UNKNOWNS`] on, a
//! mechanism whose joints have full rank and whose coordinates all have inertia takes sparse
//! Cholesky factorisations of `G_v G_vᵀ` and `G_v M⁻¹ G_vᵀ` instead, which give the same
//! least-change velocities and the same multipliers there ([`SparseGram`]).

use nalgebra::{DMatrix, DVector};

use super::gram::SparseGram;
use super::mechanics::MechanicsTapes;
use crate::mech::{ConstraintRow, MultibodySystem};
use crate::thresholds::{RANK_TOL, SPARSE_START_CONDITION, SPARSE_START_UNKNOWNS};

/// A state that satisfies the position, velocity and acceleration constraints.
#[derive(Clone, Debug, PartialEq)]
pub struct ConsistentState {
    /// Coordinates.
    pub q: Vec<f64>,
    /// Velocities.
    pub v: Vec<f64>,
    /// Accelerations.
    pub vdot: Vec<f64>,
    /// Constraint forces (multipliers) λ.
    pub lambda: Vec<f64>,
    /// ‖q − q₀‖ of the position projection.
    pub position_correction: f64,
    /// ‖v − v₀‖ of the velocity projection.
    pub velocity_correction: f64,
    /// Rank of `G_v` at the initial state.
    pub rank: usize,
    /// Joints whose rows are linearly dependent at the initial state (redundant constraints).
    pub redundant_joints: Vec<String>,
}

/// Why no consistent initial state exists.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InitError {
    /// The position projection did not converge.
    #[error("at t = {t}: the positions cannot be projected onto the joints: |g| = {residual:.3e} after {iterations} iterations (worst row: joint '{joint}', {direction}; joints left open: [{open}])")]
    PositionProjection {
        /// Time of the projection (the start, or a restart of the solver).
        t: f64,
        /// Final largest |g|.
        residual: f64,
        /// Iterations done.
        iterations: usize,
        /// Joint of the worst row.
        joint: String,
        /// Its direction.
        direction: String,
        /// Every joint with a row still violated by more than 1e-6 of the worst, comma-separated.
        open: String,
    },
    /// `[M G_vᵀ; G_v 0]` is singular beyond redundant constraints.
    #[error("at t = {t}: the mass–constraint matrix is singular: {what}")]
    Singular {
        /// Time of the failed initialisation.
        t: f64,
        /// Which coordinates are undetermined.
        what: String,
    },
    /// Drivers whose rows depend on each other and on the joints' rows: they over-constrain
    /// the mechanism (a redundant driver row is a contradiction, whatever the two motions).
    #[error("at t = {t}: {drivers} over-constrain the mechanism: their rows are linearly dependent with each other and the joints [{joints}] (a self-stress of the drivers through those joints, rank of G_v {rank} for {rows} rows); each driver takes a degree of freedom, and a degree of freedom driven twice is a contradiction unless the two motions agree for ever, which bondmech does not assume — drive it once (remove one of the drivers, or free a joint)")]
    ConflictingDrivers {
        /// Time of the check (the start).
        t: f64,
        /// The drivers, `drivers[i] 'name' (joint 'J')`, comma-separated.
        drivers: String,
        /// The joints whose rows take part with them, comma-separated.
        joints: String,
        /// Rank of `G_v` there.
        rank: usize,
        /// Rows of `G_v` (joints' and drivers').
        rows: usize,
    },
    /// Something evaluated to NaN or infinity.
    #[error("at t = {t}: the state evaluates to a non-finite value in {what}")]
    NonFinite {
        /// Time of the failed initialisation.
        t: f64,
        /// What was being evaluated.
        what: String,
    },
    /// A load (or another scene quantity) evaluates to NaN or infinity at the start: its JSON
    /// path, name, expression and the time.
    #[error("{0}")]
    NonFiniteSource(crate::mech::NonFiniteValue),
}

/// Where no coordinate is massless, why `[M G_vᵀ; G_v 0]` can still be singular: its entries
/// span more than its rank tolerance ([`RANK_TOL`], relative) can tell apart. Names the
/// smallest and largest mass or inertia (`bodies[i].mass`, `bodies[i].inertia`) and the largest
/// joint-row coefficient `|∂g/∂v|` (its joint), with the ratio of the largest of these entries
/// to the smallest (issue 38: a body of 1e100 kg
/// with an inertia of 1e-100 kg·m², or joint points 1e11 m from a centre, failed naming none).
fn scale_spread(sys: &MultibodySystem, gv: &DMatrix<f64>) -> String {
    let field = |j: usize| {
        let name = &sys.velocities[j].name;
        let (body, what) = name.rsplit_once('.').unwrap_or((name.as_str(), ""));
        let kind = if what.starts_with('v') {
            "mass"
        } else {
            "inertia"
        };
        match sys.bodies.iter().position(|(b, _)| b == body) {
            Some(i) => format!("bodies[{i}].{kind}, velocity '{name}'"),
            None => format!("velocity '{name}'"),
        }
    };
    let mut lo: Option<(f64, usize)> = None;
    let mut hi: Option<(f64, usize)> = None;
    for (j, &m) in sys.mass.iter().enumerate() {
        if m > 0.0 {
            if lo.is_none_or(|(l, _)| m < l) {
                lo = Some((m, j));
            }
            if hi.is_none_or(|(h, _)| m > h) {
                hi = Some((m, j));
            }
        }
    }
    let mut g: Option<(f64, usize)> = None;
    for i in 0..gv.nrows() {
        for j in 0..gv.ncols() {
            let a = gv[(i, j)].abs();
            if a > 0.0 && g.is_none_or(|(b, _)| a > b) {
                g = Some((a, i));
            }
        }
    }
    let (Some((lo, jl)), Some((hi, jh))) = (lo, hi) else {
        return "the joints leave a body without mass or inertia free".into();
    };
    let mut text = if lo == hi {
        format!("every mass and inertia is {lo:e} ({})", field(jl))
    } else {
        format!(
            "the smallest mass or inertia is {lo:e} ({}), the largest {hi:e} ({})",
            field(jl),
            field(jh)
        )
    };
    let mut spread = hi / lo;
    if let Some((gmax, row)) = g {
        let joint = sys.rows.get(row).map_or("", |r| r.joint.as_str());
        text.push_str(&format!(
            ", the largest joint-row coefficient is {gmax:e} (joint '{joint}')"
        ));
        // the matrix holds both: the ratio of its largest to its smallest entry
        spread = hi.max(gmax) / lo.min(gmax);
    }
    text.push_str(&format!(
        ": a spread of {spread:.1e}, beyond what the rank test (relative {RANK_TOL:e}) tells apart in double precision; give the scene in units where these are closer to 1, or fix the body whose value is out of scale"
    ));
    text
}

fn pinv_apply(a: &DMatrix<f64>, b: &DVector<f64>) -> (DVector<f64>, usize) {
    if a.nrows() == 0 || a.ncols() == 0 {
        return (DVector::zeros(a.ncols()), 0);
    }
    let svd = a.clone().svd(true, true);
    let smax = svd.singular_values.max();
    let tol = RANK_TOL * smax.max(1e-300);
    let rank = svd.singular_values.iter().filter(|&&s| s > tol).count();
    let x = svd
        .solve(b, tol)
        .unwrap_or_else(|_| DVector::zeros(a.ncols()));
    (x, rank)
}

/// Joints whose rows take part in a linear dependency of `a`'s rows: the eigenvectors of
/// `a aᵀ` with (relatively) zero eigenvalue span the left null space.
pub fn dependent_joints(a: &DMatrix<f64>, rows: &[ConstraintRow]) -> Vec<String> {
    if a.nrows() == 0 {
        return vec![];
    }
    let eig = (a * a.transpose()).symmetric_eigen();
    let lmax = eig.eigenvalues.amax().max(1e-300);
    let mut joints = Vec::new();
    for (k, &l) in eig.eigenvalues.iter().enumerate() {
        if l.abs() <= 1e-12 * lmax {
            for (i, &c) in eig.eigenvectors.column(k).iter().enumerate() {
                if c.abs() > 1e-6 && !joints.contains(&rows[i].joint) {
                    joints.push(rows[i].joint.clone());
                }
            }
        }
    }
    joints
}

/// Drivers that over-constrain the mechanism at `(t0, x)`: the joints' self-stress — the left
/// null space `N` of `G_v` (`Nᵀ G_v = 0`), the eigenvectors of `G_v G_vᵀ` of relatively zero
/// eigenvalue — restricted to the combinations that load a driver row (`N w` for `w` in the
/// row space of `N`'s driver rows), where the loss of rank holds along the motion
/// ([`rank_loss_persists`], so a singular configuration at the start is not taken for one).
/// Such a combination says that one driver's row `G_d v = ṡ_d(t)` is fixed by the others' and
/// the joints' rows: the two prescriptions contradict each other unless they agree at every
/// instant; bondmech refuses them whether or not they agree (`docs/scene-format.md` §23).
/// `None` when no driver row takes part in a redundancy.
pub fn conflicting_drivers(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t0: f64,
    x: &[f64],
) -> Option<InitError> {
    if sys.drivers.is_empty() {
        return None;
    }
    let gv = tapes.gv.matrix(t0, x);
    let m = gv.nrows();
    if m == 0 {
        return None;
    }
    let eig = (&gv * gv.transpose()).symmetric_eigen();
    let lmax = eig.eigenvalues.amax().max(1e-300);
    let null: Vec<usize> = (0..m)
        .filter(|&k| eig.eigenvalues[k].abs() <= 1e-12 * lmax)
        .collect();
    if null.is_empty() {
        return None;
    }
    let n = DMatrix::from_fn(m, null.len(), |i, k| eig.eigenvectors[(i, null[k])]);
    let drows: Vec<usize> = sys.drivers.iter().map(|d| d.row).collect();
    let nd = DMatrix::from_fn(drows.len(), null.len(), |i, k| n[(drows[i], k)]);
    let svd = nd.svd(false, true);
    let vt = svd.v_t?;
    let conflicts: Vec<DVector<f64>> = svd
        .singular_values
        .iter()
        .enumerate()
        .filter(|(_, &s)| s > 1e-6)
        .map(|(k, _)| &n * vt.row(k).transpose())
        .collect();
    if conflicts.is_empty() {
        return None;
    }
    let rank = m - null.len();
    // the rank's loss holds along the motion: the independent rows (joints first) kept
    let mut kept: Vec<usize> = Vec::new();
    let mut basis: Vec<DVector<f64>> = Vec::new();
    let order = (0..m)
        .filter(|i| !drows.contains(i))
        .chain(drows.iter().copied());
    let scale = gv.norm().max(1e-300);
    for i in order {
        let mut r: DVector<f64> = gv.row(i).transpose();
        for b in &basis {
            let c = b.dot(&r);
            r -= b * c;
        }
        let nr = r.norm();
        if nr > 1e-9 * scale && basis.len() < rank {
            basis.push(r / nr);
            kept.push(i);
        }
    }
    kept.sort_unstable();
    if !rank_loss_persists(tapes, t0, x, &kept, rank) {
        return None;
    }
    let involved = |i: usize| conflicts.iter().any(|c| c[i].abs() > 1e-6 * c.amax());
    let drivers: Vec<String> = sys
        .drivers
        .iter()
        .filter(|d| involved(d.row))
        .map(|d| format!("drivers[{}] '{}' (joint '{}')", d.index, d.name, d.joint))
        .collect();
    let mut joints: Vec<String> = Vec::new();
    for i in (0..m).filter(|i| !drows.contains(i) && involved(*i)) {
        if !joints.contains(&sys.rows[i].joint) {
            joints.push(sys.rows[i].joint.clone());
        }
    }
    Some(InitError::ConflictingDrivers {
        t: t0,
        drivers: drivers.join(" and "),
        joints: joints.join(", "),
        rank,
        rows: m,
    })
}

/// Projects the user's initial state onto the constraints (see the module documentation).
pub fn consistent_state(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t0: f64,
) -> Result<ConsistentState, InitError> {
    project(sys, tapes, t0, &sys.initial_state(), &sys.given_velocities)
}

/// As [`consistent_state`], from the state `x0 = [q, v]` instead of the user's initial values
/// (every velocity may change: the least change of all of them).
pub fn consistent_state_from(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t0: f64,
    x0: &[f64],
) -> Result<ConsistentState, InitError> {
    project(sys, tapes, t0, x0, &[])
}

/// The velocities' least change `Δv = G_v⁺ (G_v v + b)` that closes the joints, or, where some
/// velocities are `given` (the scene's), the least change of the others alone,
/// `Δv_N = G_v[:, N]⁺ (G_v v + b)`, where they can close the joints by themselves (the residual
/// `G_v[:, N] Δv_N − (G_v v + b)` at rounding); the given ones then stay as written. Returns the
/// change and the rank of `G_v`.
fn velocity_change(
    gv: &DMatrix<f64>,
    gv_v: &DVector<f64>,
    given: &[bool],
) -> (DVector<f64>, usize) {
    let (dv, rank) = pinv_apply(gv, gv_v);
    let free: Vec<usize> = (0..gv.ncols())
        .filter(|&j| !given.get(j).copied().unwrap_or(false))
        .collect();
    if free.len() == gv.ncols() || free.is_empty() || gv_v.norm() == 0.0 {
        return (dv, rank);
    }
    let gn = DMatrix::from_fn(gv.nrows(), free.len(), |i, k| gv[(i, free[k])]);
    let (dn, _) = pinv_apply(&gn, gv_v);
    let residual = (&gn * &dn - gv_v).norm();
    // closed to rounding: the scale of the rows' terms (G_v v's entries before they cancel)
    let scale = gv.norm() * (gv_v.norm() + dv.norm()) + gv_v.norm();
    if residual > 1e3 * f64::EPSILON * scale {
        return (dv, rank);
    }
    let mut out = DVector::zeros(gv.ncols());
    for (k, &j) in free.iter().enumerate() {
        out[j] = dn[k];
    }
    (out, rank)
}

fn project(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t0: f64,
    x0: &[f64],
    given: &[bool],
) -> Result<ConsistentState, InitError> {
    let (nq, nv, nc) = tapes.dims;
    let x0 = x0.to_vec();
    let mut x = x0.clone();
    let finite = |v: &[f64], what: &str| finite_at(t0, v.iter().copied(), what);
    // 1. positions
    let mut iterations = 0;
    let scale = 1.0 + x0[..nq].iter().fold(0.0f64, |a, b| a.max(b.abs()));
    loop {
        let g = MechanicsTapes::eval(&tapes.g, t0, &x);
        finite(&g, "the joint constraints g(q)")?;
        let worst = g.iter().enumerate().fold((0usize, 0.0f64), |a, (i, &v)| {
            if v.abs() > a.1 {
                (i, v.abs())
            } else {
                a
            }
        });
        if worst.1 <= 1e-13 * scale {
            break;
        }
        if iterations >= 60 {
            if let Some(e) = conflicting_drivers(sys, tapes, t0, &x0) {
                return Err(e);
            }
            let r = &sys.rows[worst.0];
            let mut open: Vec<&str> = Vec::new();
            for (row, v) in sys.rows.iter().zip(&g) {
                if v.abs() > 1e-6 * worst.1 && !open.contains(&row.joint.as_str()) {
                    open.push(&row.joint);
                }
            }
            return Err(InitError::PositionProjection {
                t: t0,
                open: open.join(", "),
                residual: worst.1,
                iterations,
                joint: r.joint.clone(),
                direction: r.direction.clone(),
            });
        }
        let gq = tapes.gq.matrix(t0, &x);
        finite(gq.as_slice(), "the constraint Jacobian")?;
        let (dq, _) = pinv_apply(&gq, &DVector::from_vec(g));
        for i in 0..nq {
            x[i] -= dq[i];
        }
        iterations += 1;
    }
    let position_correction = (0..nq).map(|i| (x[i] - x0[i]).powi(2)).sum::<f64>().sqrt();
    // 2. velocities (the sparse path from G_v's non-zeros, linear in the size; the dense
    // G_v only where it is not taken)
    let gv_entries = tapes.gv.entries(t0, &x);
    finite_at(
        t0,
        gv_entries.iter().map(|e| e.2),
        "the velocity constraint Jacobian",
    )?;
    let v0 = DVector::from_column_slice(&x[nq..]);
    if let Some(sparse) = sparse_start(sys, tapes, t0, &mut x, &gv_entries, given)? {
        let position_correction = (0..nq).map(|i| (x[i] - x0[i]).powi(2)).sum::<f64>().sqrt();
        return Ok(ConsistentState {
            position_correction,
            ..sparse
        });
    }
    let gv = tapes.gv.matrix(t0, &x);
    // G_v v + b: the velocity rows (b = ∂g/∂t, a driver's prescribed rate)
    let mut gv_v = &gv * &v0;
    if tapes.bias.is_some() {
        gv_v += DVector::from_vec(tapes.bias_at(t0, &x));
    }
    let (dv, rank) = velocity_change(&gv, &gv_v, given);
    for j in 0..nv {
        x[nq + j] -= dv[j];
    }
    let velocity_correction = dv.norm();
    if rank < nc {
        if let Some(e) = conflicting_drivers(sys, tapes, t0, &x) {
            return Err(e);
        }
    }
    let redundant_joints = if rank < nc {
        dependent_joints(&gv, &sys.rows)
    } else {
        vec![]
    };
    // 3. accelerations and multipliers
    let (q, gamma) = forces_and_gamma(sys, tapes, t0, &x)?;
    let n = nv + nc;
    let (mut a, mut b) = (DMatrix::zeros(n, n), DVector::zeros(n));
    dynamics_system(
        &sys.mass,
        |i, j| gv[(i, j)],
        (&q, &gamma),
        a.as_mut_slice(),
        b.as_mut_slice(),
    );
    let (sol, rank_a) = pinv_apply(&a, &b);
    if rank_a < nv + rank {
        let massless: Vec<&str> = sys
            .velocities
            .iter()
            .zip(&sys.mass)
            .filter(|(_, &m)| m == 0.0)
            .map(|(c, _)| c.name.as_str())
            .collect();
        let undetermined = nv + rank - rank_a;
        let what = if massless.is_empty() {
            format!(
                "{undetermined} of {nv} accelerations are undetermined; {}",
                scale_spread(sys, &gv)
            )
        } else {
            format!(
                "{undetermined} of {nv} accelerations are undetermined; massless coordinates: [{}] — a rotation without inertia must be fixed by the joints",
                massless.join(", ")
            )
        };
        return Err(InitError::Singular { t: t0, what });
    }
    Ok(ConsistentState {
        q: x[..nq].to_vec(),
        v: x[nq..].to_vec(),
        vdot: sol.rows(0, nv).iter().copied().collect(),
        lambda: sol.rows(nv, nc).iter().copied().collect(),
        position_correction,
        velocity_correction,
        rank,
        redundant_joints,
    })
}

/// Whether the joints' loss of rank at `(t0, x)` holds along the motion — redundant joints
/// (Bricard's loop, a parallel third crank: `rank G_v < nc` at every configuration the
/// mechanism moves through) — rather than at this configuration only (a four-bar started on
/// its aligned configuration: a singular configuration, `rank G_v = nc` once it moves).
///
/// The configuration is moved a small step `ε = 1e-3 (1 + max |q|)` along a generic direction
/// `d = (I − G_q[K, :]⁺ G_q[K, :]) z` of the null space of `G_q[K, :]`, the Jacobian of the independent rows `kept`, and
/// brought back onto `g_K(q) = 0` (Gauss–Newton, minimum-norm steps). Where the rows left out
/// are redundant, the manifold `g_K = 0` is the mechanism's own and `G_v` keeps its rank
/// `rank` there; at a singular configuration the manifold `g_K = 0` is wider than the
/// mechanism's, and `G_v` regains rank (its smallest singular value grows like `ε`, far above
/// the rank tolerance).
///
/// ```text
///   q₁ = q₀ + ε d,  G_q[K, :] d = 0;   q₁ ← q₁ − G_q[K, :]⁺ g_K(q₁)   (until g_K ≈ 0)
///   persists  ⇔  rank G_v(q₁) ≤ rank
/// ```
pub fn rank_loss_persists(
    tapes: &MechanicsTapes,
    t0: f64,
    x: &[f64],
    kept: &[usize],
    rank: usize,
) -> bool {
    let (nq, nv, _) = tapes.dims;
    let mut y = x[..nq + nv].to_vec();
    let scale = 1.0 + y[..nq].iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let rows_of =
        |m: &DMatrix<f64>| DMatrix::from_fn(kept.len(), m.ncols(), |i, j| m[(kept[i], j)]);
    let gq = rows_of(&tapes.gq.matrix(t0, &y));
    // d = (I − G⁺G) z: a generic z (fixed, so that the same run gives the same answer)
    // projected onto the null space of the independent rows
    let z = DVector::from_fn(nq, |i, _| (1.0 + 0.754_877_666 * (i as f64 + 1.0)).sin());
    let (back, _) = pinv_apply(&gq, &(&gq * &z));
    let mut d = z - back;
    if d.norm() == 0.0 {
        return true;
    }
    d /= d.norm();
    let eps = 1e-3 * scale;
    for i in 0..nq {
        y[i] += eps * d[i];
    }
    for _ in 0..20 {
        let g_all = MechanicsTapes::eval(&tapes.g, t0, &y);
        let g = DVector::from_iterator(kept.len(), kept.iter().map(|&i| g_all[i]));
        if !g.iter().all(|v| v.is_finite()) {
            return true;
        }
        if g.amax() <= 1e-13 * scale {
            break;
        }
        let jq = rows_of(&tapes.gq.matrix(t0, &y));
        let (dq, _) = pinv_apply(&jq, &g);
        for i in 0..nq {
            y[i] -= dq[i];
        }
    }
    let gv = tapes.gv.matrix(t0, &y);
    let (_, moved_rank) = pinv_apply(&gv, &DVector::zeros(gv.nrows()));
    moved_rank <= rank
}

/// The accelerations' and multipliers' system of a state (`M` diagonal, `G_v` given entry by
/// entry, `nc = γ.len()` rows):
///
/// ```text
///   [ M    G_vᵀ ] [ v' ]   [  Q ]
///   [ G_v  0    ] [ λ  ] = [ −γ ]
/// ```
///
/// written into the column-major `(nv + nc)²` slice `a` (every entry set) and `b`. The start
/// ([`consistent_state_from`]) and the multipliers of an interpolated state
/// (`solve::reactions`) solve it.
pub(crate) fn dynamics_system(
    mass: &[f64],
    gv: impl Fn(usize, usize) -> f64,
    (q, gamma): (&[f64], &[f64]),
    a: &mut [f64],
    b: &mut [f64],
) {
    let (nv, nc) = (mass.len(), gamma.len());
    let n = nv + nc;
    a.fill(0.0);
    for j in 0..nv {
        a[j * n + j] = mass[j];
        b[j] = q[j];
    }
    for i in 0..nc {
        b[nv + i] = -gamma[i];
        for j in 0..nv {
            let g = gv(i, j);
            a[j * n + nv + i] = g;
            a[(nv + i) * n + j] = g;
        }
    }
}

/// `Err(NonFinite)` naming `what` at `t` unless every value is finite.
fn finite_at(t: f64, values: impl IntoIterator<Item = f64>, what: &str) -> Result<(), InitError> {
    if values.into_iter().all(f64::is_finite) {
        Ok(())
    } else {
        Err(InitError::NonFinite {
            t,
            what: what.to_string(),
        })
    }
}

/// The generalized forces `Q` and the constraint acceleration terms `γ` at `(t, x)`, finite
/// (a non-finite force is traced to the load that made it where one did).
fn forces_and_gamma(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t: f64,
    x: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), InitError> {
    let q = MechanicsTapes::eval(&tapes.forces, t, x);
    if !q.iter().all(|f| f.is_finite()) {
        if let Some(culprit) = sys.non_finite_source(t, x) {
            return Err(InitError::NonFiniteSource(culprit));
        }
    }
    finite_at(t, q.iter().copied(), "the generalized forces")?;
    let gamma = MechanicsTapes::eval(&tapes.gamma, t, x);
    finite_at(
        t,
        gamma.iter().copied(),
        "the constraint acceleration terms",
    )?;
    Ok((q, gamma))
}

/// Steps 2 and 3 of [`consistent_state_from`] for a large mechanism with full-rank joints and
/// an inertia on every coordinate, linear in its size: with `B = G_v G_vᵀ` and
/// `A = G_v M⁻¹ G_vᵀ` (both SPD, [`SparseGram`]),
///
/// ```text
///   v ← v − G_vᵀ B⁻¹ G_v v                   (the least change with G_v v = 0)
///   λ = A⁻¹ (G_v M⁻¹ Q + γ),  v' = M⁻¹ (Q − G_vᵀ λ)
/// ```
///
/// which is what the pseudo-inverses of the dense path give when `G_v` has full row rank.
/// `None` (the caller takes the dense path) below [`SPARSE_START_UNKNOWNS`], with a massless
/// coordinate, or when `B` is not safely positive definite (κ estimate over
/// [`SPARSE_START_CONDITION`]: possibly redundant joints, which the SVD names).
/// `position_correction` is left 0 for the caller. `gv`: the non-zeros of `G_v` as
/// `(row, column, value)`; every product with `G_v` runs over them.
fn sparse_start(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t0: f64,
    x: &mut [f64],
    gv: &[(usize, usize, f64)],
    given: &[bool],
) -> Result<Option<ConsistentState>, InitError> {
    let (nq, nv, nc) = tapes.dims;
    if nv + nc < SPARSE_START_UNKNOWNS || nc == 0 || sys.mass.iter().any(|&m| m <= 0.0) {
        return Ok(None);
    }
    let Some(b) = SparseGram::from_entries(nc, nv, gv, &vec![1.0; nv]) else {
        return Ok(None);
    };
    if b.condition_estimate(20) > SPARSE_START_CONDITION {
        return Ok(None);
    }
    let w: Vec<f64> = sys.mass.iter().map(|m| 1.0 / m).collect();
    let Some(a) = SparseGram::from_entries(nc, nv, gv, &w) else {
        return Ok(None);
    };
    // y = G_v x and y = G_vᵀ x over the non-zeros
    let g_times = |x: &[f64]| {
        let mut y = vec![0.0; nc];
        for &(i, j, g) in gv {
            y[i] += g * x[j];
        }
        y
    };
    let gt_times = |x: &[f64]| {
        let mut y = vec![0.0; nv];
        for &(i, j, g) in gv {
            y[j] += g * x[i];
        }
        y
    };
    // velocities: the least change of those the scene does not give, where they close the
    // joints by themselves (`G_v diag(free) G_vᵀ` SPD and as well conditioned), else of all
    let free: Vec<f64> = (0..nv)
        .map(|j| {
            if given.get(j).copied().unwrap_or(false) {
                0.0
            } else {
                1.0
            }
        })
        .collect();
    let keep_given = free.contains(&0.0) && free.contains(&1.0);
    let b_free = keep_given
        .then(|| SparseGram::from_entries(nc, nv, gv, &free))
        .flatten()
        .filter(|bf| bf.condition_estimate(20) <= SPARSE_START_CONDITION);
    let (b, free) = match &b_free {
        Some(bf) => (bf, free),
        None => (&b, vec![1.0; nv]),
    };
    let mut r = g_times(&x[nq..]);
    if tapes.bias.is_some() {
        for (ri, bi) in r.iter_mut().zip(tapes.bias_at(t0, x)) {
            *ri += bi;
        }
    }
    b.solve_in_place(&mut r);
    let dv: Vec<f64> = gt_times(&r).iter().zip(&free).map(|(d, f)| d * f).collect();
    for j in 0..nv {
        x[nq + j] -= dv[j];
    }
    // accelerations and multipliers
    let (q, gamma) = forces_and_gamma(sys, tapes, t0, x)?;
    let minv_q: Vec<f64> = (0..nv).map(|j| q[j] / sys.mass[j]).collect();
    let mut lambda = g_times(&minv_q);
    for (l, g) in lambda.iter_mut().zip(&gamma) {
        *l += g;
    }
    a.solve_in_place(&mut lambda);
    let gt_lambda = gt_times(&lambda);
    let vdot = (0..nv)
        .map(|j| (q[j] - gt_lambda[j]) / sys.mass[j])
        .collect();
    Ok(Some(ConsistentState {
        q: x[..nq].to_vec(),
        v: x[nq..].to_vec(),
        vdot,
        lambda,
        position_correction: 0.0,
        velocity_correction: dv.iter().map(|d| d * d).sum::<f64>().sqrt(),
        rank: nc,
        redundant_joints: vec![],
    }))
}
