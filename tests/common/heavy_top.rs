//! The heavy symmetric top (Lagrange top) on a fixed point, as an independent reference.
//!
//! A body of mass m whose centre of mass lies at `s = (0, 0, l)` in body axes from the fixed
//! point O, with principal moments `J_c = diag(A_c, A_c, C)` about its centre. About O the
//! moments are `J_O = J_c + m(|s|² I − s sᵀ) = diag(A_c + m l², A_c + m l², C)`, and Euler's
//! equations about the fixed point, in body axes, read
//!
//! ```text
//!   J_O ω' = s × (Rᵀ m g_vec) − ω × J_O ω,     R' = R [ω]×,     g_vec = (0, 0, −g),
//! ```
//!
//! with `R` the body → global rotation. No constraint force appears: O is the origin of the
//! moments, so this is the minimal model (three rotational degrees of freedom), derived apart
//! from bondmech's (which moves the centre of mass, a quaternion and a spherical joint's
//! reaction). Invariants checked by the tests: the energy `½ ωᵀ J_O ω + m g (R s)_Z`, the
//! angular momentum about the vertical `(R J_O ω)_Z`, and the spin `ω₃` (the gravity torque
//! `s × F` has no component along `s`, and `J₁ = J₂`).

use nalgebra::{Matrix3, Vector3};

use super::integrate::integrate;
use super::rigid_body::skew;

/// A symmetric top on a fixed point.
#[derive(Clone, Copy, Debug)]
pub struct HeavyTop {
    /// Mass (kg).
    pub mass: f64,
    /// Distance of the centre of mass from the fixed point along the body z axis (m).
    pub l: f64,
    /// Transverse principal moment about the centre of mass (kg·m²).
    pub a_c: f64,
    /// Axial principal moment (kg·m²).
    pub c: f64,
    /// Gravity (m/s², downwards along global Z).
    pub g: f64,
}

/// The top's state at one time.
#[derive(Clone, Copy, Debug)]
pub struct TopState {
    /// Time (s).
    pub t: f64,
    /// Angular velocity in body axes.
    pub omega: Vector3<f64>,
    /// Attitude, body → global.
    pub rotation: Matrix3<f64>,
}

impl HeavyTop {
    /// `J_O`, the principal moments about the fixed point.
    pub fn moments(&self) -> Vector3<f64> {
        let a = self.a_c + self.mass * self.l * self.l;
        Vector3::new(a, a, self.c)
    }

    /// Global position of the centre of mass, `R s`.
    pub fn centre(&self, s: &TopState) -> Vector3<f64> {
        s.rotation * Vector3::new(0.0, 0.0, self.l)
    }

    /// Energy `½ ωᵀ J_O ω + m g Z_c`.
    pub fn energy(&self, s: &TopState) -> f64 {
        let h = self.moments().component_mul(&s.omega);
        0.5 * s.omega.dot(&h) + self.mass * self.g * self.centre(s).z
    }

    /// Angular momentum about the vertical through O, `(R J_O ω)_Z`.
    pub fn momentum_z(&self, s: &TopState) -> f64 {
        (s.rotation * self.moments().component_mul(&s.omega)).z
    }

    /// Integrates from body rates `omega0` and attitude `r0` at t = 0 to each of `times`
    /// (sorted, ≥ 0) with the tests' Dormand–Prince at rtol = atol = `tol`.
    pub fn simulate(
        &self,
        omega0: Vector3<f64>,
        r0: Matrix3<f64>,
        times: &[f64],
        tol: f64,
    ) -> Vec<TopState> {
        let j = self.moments();
        let (m, g, l) = (self.mass, self.g, self.l);
        let mut y0 = vec![omega0.x, omega0.y, omega0.z];
        y0.extend(r0.transpose().iter()); // row-major
        let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
            let w = Vector3::new(y[0], y[1], y[2]);
            let r = Matrix3::from_row_slice(&y[3..12]);
            let s = Vector3::new(0.0, 0.0, l);
            let weight = r.transpose() * Vector3::new(0.0, 0.0, -m * g);
            let torque = s.cross(&weight) - w.cross(&j.component_mul(&w));
            let wd = torque.component_div(&j);
            dy[..3].copy_from_slice(wd.as_slice());
            let dr = r * skew(&w);
            for i in 0..3 {
                for k in 0..3 {
                    dy[3 + 3 * i + k] = dr[(i, k)];
                }
            }
        };
        let ys = integrate(rhs, 0.0, &y0, times, tol, tol);
        times
            .iter()
            .zip(ys)
            .map(|(&t, y)| TopState {
                t,
                omega: Vector3::new(y[0], y[1], y[2]),
                rotation: Matrix3::from_row_slice(&y[3..12]),
            })
            .collect()
    }
}
