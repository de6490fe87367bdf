//! The spherical pendulum: a point mass m on a massless rigid link of length L to a fixed point
//! at the origin, gravity (0, 0, −g), in spherical coordinates (Lagrange).
//!
//! θ is the link's angle from the downward vertical −Z, φ its azimuth from X about Z:
//!
//! ```text
//!   x = L (sin θ cos φ, sin θ sin φ, −cos θ),
//!   T = ½ m L² (θ̇² + sin²θ φ̇²),   V = −m g L cos θ,
//! ```
//!
//! so Lagrange's equations read
//!
//! ```text
//!   θ̈ = sin θ cos θ φ̇² − (g/L) sin θ,
//!   φ̈ = −2 cot θ θ̇ φ̇                 (d/dt (sin²θ φ̇) = 0),
//! ```
//!
//! regular away from θ = 0 and π, which a motion with a non-zero angular momentum about the
//! vertical `p_φ = m L² sin²θ φ̇` never reaches. The energy `T + V` and `p_φ` are conserved (the
//! tests check both).

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// A spherical pendulum.
#[derive(Clone, Copy, Debug)]
pub struct SphericalPendulum {
    /// Link length L (m).
    pub length: f64,
    /// Gravity (m/s², along −Z).
    pub g: f64,
}

/// One state: `[θ, φ, θ̇, φ̇]` at time `t`.
#[derive(Clone, Copy, Debug)]
pub struct SphericalState {
    /// Time (s).
    pub t: f64,
    /// Angle from the downward vertical (rad).
    pub theta: f64,
    /// Azimuth (rad), continuous.
    pub phi: f64,
    /// θ̇.
    pub theta_dot: f64,
    /// φ̇.
    pub phi_dot: f64,
}

impl SphericalPendulum {
    /// `(θ̈, φ̈)` at `y = [θ, φ, θ̇, φ̇]`.
    pub fn accelerations(&self, y: &[f64]) -> (f64, f64) {
        let (s, c) = y[0].sin_cos();
        (
            s * c * y[3] * y[3] - self.g / self.length * s,
            -2.0 * c / s * y[2] * y[3],
        )
    }

    /// The mass's position.
    pub fn position(&self, s: &SphericalState) -> [f64; 3] {
        let (st, ct) = s.theta.sin_cos();
        let (sp, cp) = s.phi.sin_cos();
        let l = self.length;
        [l * st * cp, l * st * sp, -l * ct]
    }

    /// Energy per unit mass, `½ L² (θ̇² + sin²θ φ̇²) − g L cos θ`.
    pub fn energy(&self, s: &SphericalState) -> f64 {
        let l = self.length;
        0.5 * l * l * (s.theta_dot.powi(2) + (s.theta.sin() * s.phi_dot).powi(2))
            - self.g * l * s.theta.cos()
    }

    /// Angular momentum about the vertical per unit mass, `L² sin²θ φ̇`.
    pub fn momentum_z(&self, s: &SphericalState) -> f64 {
        self.length.powi(2) * s.theta.sin().powi(2) * s.phi_dot
    }

    /// Integrates from `y0 = [θ, φ, θ̇, φ̇]` at t = 0 to each of `times` (sorted, ≥ 0) with the
    /// tests' Dormand–Prince at `rtol`, `atol`.
    pub fn simulate_tol(
        &self,
        y0: [f64; 4],
        times: &[f64],
        rtol: f64,
        atol: f64,
    ) -> Vec<SphericalState> {
        let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
            let (a, b) = self.accelerations(y);
            dy[0] = y[2];
            dy[1] = y[3];
            dy[2] = a;
            dy[3] = b;
        };
        let ys = integrate(rhs, 0.0, &y0, times, rtol, atol);
        times
            .iter()
            .zip(ys)
            .map(|(&t, y)| SphericalState {
                t,
                theta: y[0],
                phi: y[1],
                theta_dot: y[2],
                phi_dot: y[3],
            })
            .collect()
    }

    /// [`SphericalPendulum::simulate_tol`] at the references' tolerances.
    pub fn simulate(&self, y0: [f64; 4], times: &[f64]) -> Vec<SphericalState> {
        self.simulate_tol(y0, times, REFERENCE_RTOL, REFERENCE_ATOL)
    }

    /// The scene: a 1 kg point bob (`bob`) on a `distance` joint (`rod`) to the ground at the
    /// origin, at (L, 0, 0) moving at (0, `v0`, 0) (θ = π/2, φ = 0, φ̇ = v0/L), with the
    /// scene's `solve` block `solve`.
    pub fn scene(&self, v0: f64, solve: serde_json::Value) -> String {
        serde_json::json!({
            "name": "spherical_pendulum",
            "dimension": 3,
            "gravity": [0.0, 0.0, -self.g],
            "bodies": [{"name": "bob", "mass": 1.0, "inertia": [0.0, 0.0, 0.0],
                        "position": [self.length, 0.0, 0.0], "velocity": [0.0, v0, 0.0]}],
            "joints": [{"name": "rod", "type": "distance", "bodies": ["ground", "bob"],
                        "points": [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]}],
            "solve": solve,
        })
        .to_string()
    }
}
