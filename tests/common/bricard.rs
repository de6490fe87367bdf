//! Bricard's mechanism (IFToMM benchmark A04) as an exact 1-DOF model, derived by hand.
//!
//! Geometry (benchmark and scene `scenes/bricard.json`): five bars of length 1 along the cube
//! edges P0(0,0,0) → P1(1,0,0) → P2(1,−1,0) → P3(1,−1,1) → P4(0,−1,1) → P5(0,0,1), hinge i at
//! P_i with global axis a_i = Y, Z, X, Y, Z, X in the initial configuration; hinge 6 (at P5)
//! closes the loop to ground. Gravity (0, −g, 0).
//!
//! Kinematics (product of exponentials): with q_i the rotation of hinge i relative to the
//! initial configuration, bar k has the rigid motion `T_k = E_1(q_1) ··· E_k(q_k)`, `E_i` the
//! rotation by q_i about the line (P_i, a_i). Loop closure: `E_1 ··· E_6 = I` (6 equations whose
//! Jacobian has rank 5 — the mechanism is overconstrained — so given q_1 the other five angles
//! are solved by Gauss–Newton in the least-squares sense, which is exact on the 1-DOF family).
//!
//! Dynamics (Lagrange in q = q_1): `T = ½ M(q) q̇²`, `M = Σ m |c_k'|² + ω_k'ᵀ R_k J_k R_kᵀ ω_k'`
//! (c_k centre of bar k, ω_k' its angular velocity per unit q̇), `V = Σ m g c_k,y`, so
//! `M q̈ + ½ M' q̇² + V' = 0`. Derivatives with respect to q by central differences of the exact
//! closure solution.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::integrate::integrate;

/// Gravity of the benchmark.
pub const G: f64 = 9.81;
/// Hinge points P0..P5.
pub const POINTS: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, -1.0, 1.0],
    [0.0, -1.0, 1.0],
    [0.0, 0.0, 1.0],
];
/// Hinge axes (global, initial configuration).
pub const AXES: [[f64; 3]; 6] = [
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 0.0],
];
/// Bar mass.
pub const MASS: f64 = 1.0;
/// Square cross-section side of the benchmark bars.
pub const SECTION: f64 = 0.1;

/// A rigid motion x ↦ R x + t.
#[derive(Clone, Copy)]
struct Motion {
    r: Matrix3<f64>,
    t: Vector3<f64>,
}

impl Motion {
    fn identity() -> Self {
        Motion {
            r: Matrix3::identity(),
            t: Vector3::zeros(),
        }
    }
    fn then(&self, other: &Motion) -> Motion {
        Motion {
            r: self.r * other.r,
            t: self.r * other.t + self.t,
        }
    }
    fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.r * p + self.t
    }
}

/// Rotation by q about the line through p with unit direction a (Rodrigues).
fn hinge(p: [f64; 3], a: [f64; 3], q: f64) -> Motion {
    let a = Vector3::from(a);
    let p = Vector3::from(p);
    let k = Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0);
    let r = Matrix3::identity() + k * q.sin() + k * k * (1.0 - q.cos());
    Motion { r, t: p - r * p }
}

/// The five bar motions T_1..T_5 and the closure motion T_6 for hinge angles q.
fn motions(q: &[f64; 6]) -> [Motion; 6] {
    let mut out = [Motion::identity(); 6];
    let mut acc = Motion::identity();
    for i in 0..6 {
        acc = acc.then(&hinge(POINTS[i], AXES[i], q[i]));
        out[i] = acc;
    }
    out
}

fn closure_residual(q: &[f64; 6]) -> DVector<f64> {
    let t = motions(q)[5];
    let r = t.r;
    DVector::from_vec(vec![
        t.t.x,
        t.t.y,
        t.t.z,
        0.5 * (r[(2, 1)] - r[(1, 2)]),
        0.5 * (r[(0, 2)] - r[(2, 0)]),
        0.5 * (r[(1, 0)] - r[(0, 1)]),
    ])
}

/// Solves the loop closure for q_2..q_6 given q_1, starting from `guess` (Gauss–Newton with a
/// finite-difference Jacobian and an SVD least-squares step). Panics if it does not converge.
pub fn close(q1: f64, guess: &[f64; 6]) -> [f64; 6] {
    let mut q = *guess;
    q[0] = q1;
    for _ in 0..50 {
        let r = closure_residual(&q);
        if r.norm() < 1e-14 {
            return q;
        }
        let mut jac = DMatrix::zeros(6, 5);
        for j in 0..5 {
            let h = 1e-7;
            let mut qp = q;
            let mut qm = q;
            qp[j + 1] += h;
            qm[j + 1] -= h;
            let d = (closure_residual(&qp) - closure_residual(&qm)) / (2.0 * h);
            jac.set_column(j, &d);
        }
        let step = jac.svd(true, true).solve(&r, 1e-12).expect("svd solve");
        for j in 0..5 {
            q[j + 1] -= step[j];
        }
    }
    let r = closure_residual(&q).norm();
    assert!(
        r < 1e-12,
        "Bricard closure did not converge at q1 = {q1}: |r| = {r:e}"
    );
    q
}

/// Principal moments of a benchmark bar about its centre, in a frame whose first axis is the bar.
pub fn bar_inertia() -> [f64; 3] {
    let a2 = SECTION * SECTION;
    [
        MASS * 2.0 * a2 / 12.0,
        MASS * (1.0 + a2) / 12.0,
        MASS * (1.0 + a2) / 12.0,
    ]
}

/// Global inertia tensor of bar k (0-based) in its initial configuration (bar along P_k → P_{k+1}).
fn initial_inertia(k: usize) -> Matrix3<f64> {
    let [ja, jt, _] = bar_inertia();
    let e = (Vector3::from(POINTS[k + 1]) - Vector3::from(POINTS[k])).normalize();
    Matrix3::identity() * jt + e * e.transpose() * (ja - jt)
}

fn centre(k: usize) -> Vector3<f64> {
    0.5 * (Vector3::from(POINTS[k]) + Vector3::from(POINTS[k + 1]))
}

/// Position of the hinge point P3 (the joint between bars 3 and 4) for hinge angles q.
pub fn p3(q: &[f64; 6]) -> Vector3<f64> {
    motions(q)[2].apply(&Vector3::from(POINTS[3]))
}

/// Generalized mass M(q1), potential V(q1) and V'(q1) on the 1-DOF family.
fn mass_potential(q1: f64, guess: &[f64; 6]) -> (f64, f64, f64, [f64; 6]) {
    let h = 1e-5;
    let q0 = close(q1, guess);
    let qp = close(q1 + h, &q0);
    let qm = close(q1 - h, &q0);
    let (t0, tp, tm) = (motions(&q0), motions(&qp), motions(&qm));
    let (mut m, mut v, mut dv) = (0.0, 0.0, 0.0);
    for k in 0..5 {
        let c = centre(k);
        let x = t0[k].apply(&c);
        let dx = (tp[k].apply(&c) - tm[k].apply(&c)) / (2.0 * h);
        let dr = (tp[k].r - tm[k].r) / (2.0 * h);
        let w = dr * t0[k].r.transpose();
        let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        let j = t0[k].r * initial_inertia(k) * t0[k].r.transpose();
        m += MASS * dx.norm_squared() + omega.dot(&(j * omega));
        v += MASS * G * x.y;
        dv += MASS * G * dx.y;
    }
    (m, v, dv, q0)
}

/// Total energy ½ M q̇² + V of the 1-DOF model at (q1, q̇1).
pub fn energy(q1: f64, q1dot: f64) -> f64 {
    let (m, v, _, _) = mass_potential(q1, &[q1, 0.0, 0.0, 0.0, 0.0, 0.0]);
    0.5 * m * q1dot * q1dot + v
}

/// Integrates the 1-DOF Lagrange equation from (q1, q̇1) = (0, ω0) and returns, at each of
/// `times`, the hinge angles q (closure solved) and q̇1.
pub fn simulate(omega0: f64, times: &[f64], rtol: f64, atol: f64) -> Vec<([f64; 6], f64)> {
    let mut guess = [0.0; 6];
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        let h = 1e-4;
        let (m, _, dv, q) = mass_potential(y[0], &guess);
        let (mp, _, _, _) = mass_potential(y[0] + h, &q);
        let (mm, _, _, _) = mass_potential(y[0] - h, &q);
        let dm = (mp - mm) / (2.0 * h);
        guess = q;
        dy[0] = y[1];
        dy[1] = -(0.5 * dm * y[1] * y[1] + dv) / m;
    };
    let ys = integrate(rhs, 0.0, &[0.0, omega0], times, rtol, atol);
    let mut g = [0.0; 6];
    ys.iter()
        .map(|y| {
            g = close(y[0], &g);
            (g, y[1])
        })
        .collect()
}
