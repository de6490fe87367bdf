//! Torque-free rigid body in principal body axes, and Cardan angles (seed 16.2).
//!
//! Euler's equations for the body-frame angular velocity ω = (ω₁, ω₂, ω₃) with
//! principal moments J = diag(J₁, J₂, J₃):
//! J₁ ω₁' = (J₂ − J₃) ω₂ ω₃,  J₂ ω₂' = (J₃ − J₁) ω₃ ω₁,  J₃ ω₃' = (J₁ − J₂) ω₁ ω₂,
//! integrated together with the attitude R (body → global), R' = R [ω]×, where
//! [ω]× is the skew matrix with [ω]× v = ω × v. Invariants: the global angular
//! momentum L = R J ω and the energy E = ½ ωᵀ J ω.
//!
//! Cardan angles (seed 16.2): R = Ψ Θ Φ, Ψ = rotation by ψ about Z, Θ = by θ
//! about the new y', Φ = by φ about the new x'' — as a product of the
//! elementary matrices R_z(ψ) R_y(θ) R_x(φ). Inverse (|θ| < π/2):
//! ψ = atan2(R₂₁, R₁₁), θ = −asin R₃₁, φ = atan2(R₃₂, R₃₃).

use nalgebra::{Matrix3, Vector3};

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// Principal moments of inertia (kg·m²) of a rigid body.
#[derive(Clone, Copy, Debug)]
pub struct RigidBody {
    /// Principal moments J₁, J₂, J₃ about the body x, y, z axes.
    pub inertia: [f64; 3],
}

/// State of the torque-free body at one time.
#[derive(Clone, Copy, Debug)]
pub struct RigidBodyState {
    /// Time (s).
    pub t: f64,
    /// Angular velocity in body axes.
    pub omega_body: Vector3<f64>,
    /// Angular velocity in global axes, R ω.
    pub omega_global: Vector3<f64>,
    /// Attitude: body → global rotation.
    pub rotation: Matrix3<f64>,
    /// Global angular momentum R J ω.
    pub momentum_global: Vector3<f64>,
    /// Kinetic energy ½ ωᵀ J ω.
    pub energy: f64,
}

/// Elementary rotation by `a` about global X.
pub fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Elementary rotation by `a` about global Y.
pub fn rot_y(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Elementary rotation by `a` about global Z.
pub fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Cardan matrix R = Ψ(ψ about Z) · Θ(θ about y') · Φ(φ about x'') of seed 16.2
/// (body → global).
pub fn cardan_matrix(psi: f64, theta: f64, phi: f64) -> Matrix3<f64> {
    rot_z(psi) * rot_y(theta) * rot_x(phi)
}

/// Cardan angles [ψ, θ, φ] of a rotation matrix (θ in [−π/2, π/2]; ψ and φ
/// are ill-defined at θ = ±π/2).
pub fn cardan_angles(r: &Matrix3<f64>) -> [f64; 3] {
    let psi = r[(1, 0)].atan2(r[(0, 0)]);
    let theta = (-r[(2, 0)]).atan2(r[(0, 0)].hypot(r[(1, 0)]));
    let phi = r[(2, 1)].atan2(r[(2, 2)]);
    [psi, theta, phi]
}

/// The rotation matrix of a unit quaternion `q = (w, x, y, z)`:
/// `R = (w² − |v|²) I + 2 v vᵀ + 2 w [v]ₓ`, written out.
pub fn quaternion_matrix(q: [f64; 4]) -> Matrix3<f64> {
    let [w, x, y, z] = q;
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// Skew matrix [ω]× with [ω]× v = ω × v.
pub fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

impl RigidBody {
    /// The state for body rates `w` and attitude `r` at time `t`.
    pub fn state(&self, t: f64, w: Vector3<f64>, r: Matrix3<f64>) -> RigidBodyState {
        let j = Vector3::from(self.inertia);
        let h = j.component_mul(&w);
        RigidBodyState {
            t,
            omega_body: w,
            omega_global: r * w,
            rotation: r,
            momentum_global: r * h,
            energy: 0.5 * w.dot(&h),
        }
    }
}

/// Integrates the torque-free body from body rates `omega0` and attitude `r0`
/// at t = 0 and returns the state at each of `times` (sorted, ≥ 0).
pub fn simulate_rigid_body(
    body: &RigidBody,
    omega0: Vector3<f64>,
    r0: Matrix3<f64>,
    times: &[f64],
) -> Vec<RigidBodyState> {
    let [j1, j2, j3] = body.inertia;
    // State: ω (3) then R row-major (9).
    let mut y0 = vec![omega0.x, omega0.y, omega0.z];
    for i in 0..3 {
        for k in 0..3 {
            y0.push(r0[(i, k)]);
        }
    }
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        let (w1, w2, w3) = (y[0], y[1], y[2]);
        dy[0] = (j2 - j3) * w2 * w3 / j1;
        dy[1] = (j3 - j1) * w3 * w1 / j2;
        dy[2] = (j1 - j2) * w1 * w2 / j3;
        let r = Matrix3::from_row_slice(&y[3..12]);
        let dr = r * skew(&Vector3::new(w1, w2, w3));
        for i in 0..3 {
            for k in 0..3 {
                dy[3 + 3 * i + k] = dr[(i, k)];
            }
        }
    };
    let ys = integrate(rhs, 0.0, &y0, times, REFERENCE_RTOL, REFERENCE_ATOL);
    times
        .iter()
        .zip(ys)
        .map(|(&t, y)| {
            body.state(
                t,
                Vector3::new(y[0], y[1], y[2]),
                Matrix3::from_row_slice(&y[3..12]),
            )
        })
        .collect()
}
