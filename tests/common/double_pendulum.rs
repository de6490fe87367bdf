//! Double pendulum of two uniform bars, in minimal coordinates.
//!
//! Bar 1 (m₁, L₁) is pinned at the origin at its end O = (−L₁/2, 0); bar 2
//! (m₂, L₂) has its O pinned to bar 1's A = (+L₁/2, 0). Generalized
//! coordinates: the absolute angles θ₁, θ₂ (body x-axes from global X, CCW),
//! rates ω₁, ω₂. With e_i = (cos θ_i, sin θ_i), e_i⊥ = (−sin θ_i, cos θ_i):
//!
//! centres  c₁ = (L₁/2) e₁,   c₂ = L₁ e₁ + (L₂/2) e₂,
//! velocities  v₁ = (L₁/2) ω₁ e₁⊥,   v₂ = L₁ ω₁ e₁⊥ + (L₂/2) ω₂ e₂⊥,
//!
//! T = ½ m₁|v₁|² + ½ (m₁L₁²/12) ω₁² + ½ m₂|v₂|² + ½ (m₂L₂²/12) ω₂²
//!   = ½ M₁₁ ω₁² + M₁₂ ω₁ ω₂ + ½ M₂₂ ω₂², with δ = θ₁ − θ₂ and
//! M₁₁ = m₁L₁²/3 + m₂L₁²,  M₂₂ = m₂L₂²/3,  M₁₂ = a cos δ,  a = m₂L₁L₂/2;
//! V = m₁ g (L₁/2) sin θ₁ + m₂ g (L₁ sin θ₁ + (L₂/2) sin θ₂).
//!
//! Lagrange, d/dt ∂T/∂ω_i − ∂T/∂θ_i + ∂V/∂θ_i = 0:
//! d/dt ∂T/∂ω₁ = M₁₁ω₁' + a cos δ ω₂' − a sin δ (ω₁ − ω₂) ω₂,  ∂T/∂θ₁ = −a sin δ ω₁ω₂
//! d/dt ∂T/∂ω₂ = a cos δ ω₁' + M₂₂ω₂' − a sin δ (ω₁ − ω₂) ω₁,  ∂T/∂θ₂ = +a sin δ ω₁ω₂
//! so
//! M₁₁ ω₁' + a cos δ ω₂' = −a sin δ ω₂² − (m₁/2 + m₂) g L₁ cos θ₁
//! a cos δ ω₁' + M₂₂ ω₂' = +a sin δ ω₁² − (m₂/2) g L₂ cos θ₂
//! solved by Cramer's rule (det = M₁₁M₂₂ − a² cos²δ > 0).
//!
//! Linearised about the hanging rest θ₁ = θ₂ = −π/2: M₀ x'' + K x = 0 with
//! M₀ = [[M₁₁, a], [a, M₂₂]], K = diag((m₁/2 + m₂) g L₁, (m₂/2) g L₂);
//! the normal frequencies are the ω with det(K − ω² M₀) = 0.

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// Parameters of the double pendulum of two uniform bars.
#[derive(Clone, Copy, Debug)]
pub struct DoublePendulum {
    /// Mass of bar 1 (kg).
    pub m1: f64,
    /// Length of bar 1 (m).
    pub l1: f64,
    /// Mass of bar 2 (kg).
    pub m2: f64,
    /// Length of bar 2 (m).
    pub l2: f64,
    /// Gravity magnitude g (m/s²), acting along −Y.
    pub g: f64,
}

/// State of the double pendulum at one time, in global terms.
#[derive(Clone, Copy, Debug)]
pub struct DoublePendulumState {
    /// Time (s).
    pub t: f64,
    /// Absolute angle of bar 1 (rad).
    pub theta1: f64,
    /// Absolute angle of bar 2 (rad).
    pub theta2: f64,
    /// Angular rate of bar 1 (rad/s).
    pub omega1: f64,
    /// Angular rate of bar 2 (rad/s).
    pub omega2: f64,
    /// Centre of bar 1 (x, y).
    pub c1: [f64; 2],
    /// Centre of bar 2 (x, y).
    pub c2: [f64; 2],
    /// Velocity of the centre of bar 1.
    pub v1: [f64; 2],
    /// Velocity of the centre of bar 2.
    pub v2: [f64; 2],
    /// Point A of bar 1 (the middle joint).
    pub a1: [f64; 2],
    /// Point A of bar 2 (the free tip).
    pub a2: [f64; 2],
    /// Total mechanical energy T + V (J), V = 0 at y = 0.
    pub energy: f64,
}

impl DoublePendulum {
    /// Mass-matrix constant a = m₂L₁L₂/2 and the diagonal M₁₁, M₂₂.
    fn inertia(&self) -> (f64, f64, f64) {
        let m11 = self.m1 * self.l1 * self.l1 / 3.0 + self.m2 * self.l1 * self.l1;
        let m22 = self.m2 * self.l2 * self.l2 / 3.0;
        let a = 0.5 * self.m2 * self.l1 * self.l2;
        (m11, m22, a)
    }

    /// Angular accelerations (ω₁', ω₂') from Lagrange's equations above.
    pub fn accelerations(&self, th1: f64, th2: f64, w1: f64, w2: f64) -> (f64, f64) {
        let (m11, m22, a) = self.inertia();
        let (s, c) = (th1 - th2).sin_cos();
        let r1 = -a * s * w2 * w2 - (0.5 * self.m1 + self.m2) * self.g * self.l1 * th1.cos();
        let r2 = a * s * w1 * w1 - 0.5 * self.m2 * self.g * self.l2 * th2.cos();
        let m12 = a * c;
        let det = m11 * m22 - m12 * m12;
        ((m22 * r1 - m12 * r2) / det, (m11 * r2 - m12 * r1) / det)
    }

    /// The global-terms state for (θ₁, θ₂, ω₁, ω₂) at time `t`.
    pub fn state(&self, t: f64, th1: f64, th2: f64, w1: f64, w2: f64) -> DoublePendulumState {
        let (s1, c1) = th1.sin_cos();
        let (s2, c2) = th2.sin_cos();
        let (l1, l2) = (self.l1, self.l2);
        let cen1 = [0.5 * l1 * c1, 0.5 * l1 * s1];
        let a1 = [l1 * c1, l1 * s1];
        let cen2 = [a1[0] + 0.5 * l2 * c2, a1[1] + 0.5 * l2 * s2];
        let a2 = [a1[0] + l2 * c2, a1[1] + l2 * s2];
        let v1 = [-0.5 * l1 * w1 * s1, 0.5 * l1 * w1 * c1];
        let v2 = [
            -l1 * w1 * s1 - 0.5 * l2 * w2 * s2,
            l1 * w1 * c1 + 0.5 * l2 * w2 * c2,
        ];
        let kinetic = 0.5 * self.m1 * (v1[0] * v1[0] + v1[1] * v1[1])
            + 0.5 * (self.m1 * l1 * l1 / 12.0) * w1 * w1
            + 0.5 * self.m2 * (v2[0] * v2[0] + v2[1] * v2[1])
            + 0.5 * (self.m2 * l2 * l2 / 12.0) * w2 * w2;
        let potential = self.g * (self.m1 * cen1[1] + self.m2 * cen2[1]);
        DoublePendulumState {
            t,
            theta1: th1,
            theta2: th2,
            omega1: w1,
            omega2: w2,
            c1: cen1,
            c2: cen2,
            v1,
            v2,
            a1,
            a2,
            energy: kinetic + potential,
        }
    }

    /// Normal-mode angular frequencies (rad/s, ascending) of small oscillations
    /// about the hanging rest, from det(K − ω² M₀) = 0, with the mode shapes
    /// (x₁, x₂) normalised to x₁ = 1.
    pub fn normal_modes(&self) -> [(f64, [f64; 2]); 2] {
        let (m11, m22, a) = self.inertia();
        let k1 = (0.5 * self.m1 + self.m2) * self.g * self.l1;
        let k2 = 0.5 * self.m2 * self.g * self.l2;
        // det = (k1 − λ m11)(k2 − λ m22) − λ² a² = 0  →  p λ² + q λ + r = 0
        let p = m11 * m22 - a * a;
        let q = -(k1 * m22 + k2 * m11);
        let r = k1 * k2;
        let disc = (q * q - 4.0 * p * r).sqrt();
        let lam = [(-q - disc) / (2.0 * p), (-q + disc) / (2.0 * p)];
        // First row of (K − λM₀) x = 0: (k1 − λ m11) x1 − λ a x2 = 0.
        lam.map(|l| (l.sqrt(), [1.0, (k1 - l * m11) / (l * a)]))
    }
}

/// Integrates the double pendulum from (θ₁, θ₂, ω₁, ω₂) = `initial` at t = 0
/// and returns the state at each of `times` (sorted, ≥ 0).
pub fn simulate_double_pendulum(
    p: &DoublePendulum,
    initial: [f64; 4],
    times: &[f64],
) -> Vec<DoublePendulumState> {
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        let (a1, a2) = p.accelerations(y[0], y[1], y[2], y[3]);
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = a1;
        dy[3] = a2;
    };
    let ys = integrate(rhs, 0.0, &initial, times, REFERENCE_RTOL, REFERENCE_ATOL);
    times
        .iter()
        .zip(ys)
        .map(|(&t, y)| p.state(t, y[0], y[1], y[2], y[3]))
        .collect()
}
