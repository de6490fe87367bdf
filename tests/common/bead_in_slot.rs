//! A bead in a slot along a swinging bar, in polar coordinates (Lagrange).
//!
//! A uniform bar (mass `M`, length `L`) is pinned at its end O to the ground at the origin;
//! its angle θ is measured from global X, counter-clockwise. A bead (point mass `m`) slides
//! without friction in a slot along the bar's axis through O, at distance `r` from O. Gravity
//! is (0, −g). With `J_O = M L²/3`:
//!
//! `T = ½ J_O θ'² + ½ m (r'² + r² θ'²)`, `V = M g (L/2) sin θ + m g r sin θ`,
//!
//! so Lagrange's equations are
//!
//! * `r'' = r θ'² − g sin θ`,
//! * `(J_O + m r²) θ'' = −2 m r r' θ' − (M L/2 + m r) g cos θ`.
//!
//! The slot's force on the bead is normal to the bar: along `e_θ = (−sin θ, cos θ)` it is
//! `m (r θ'' + 2 r' θ' + g cos θ)`, along `e_r` zero.
//!
//! With a spring of stiffness `k` and rest length 0 from O to the bead
//! ([`BeadInSlot::simulate_sprung`]), `V` gains `½ k r²`: its force acts along `e_r` and has no
//! moment about O, so only `r'' = r θ'² − g sin θ − (k/m) r` changes. Where the slot runs
//! through O the bead passes it: `r` is the signed coordinate along the slot (the bead at
//! `r (cos θ, sin θ)` for either sign), and the equations stay regular at `r = 0`
//! (`J_O + m r² ≥ J_O > 0`).

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// The bar and bead.
#[derive(Clone, Copy, Debug)]
pub struct BeadInSlot {
    /// Bar mass (kg).
    pub bar_mass: f64,
    /// Bar length (m).
    pub length: f64,
    /// Bead mass (kg).
    pub bead_mass: f64,
    /// Gravity (m/s²).
    pub g: f64,
}

/// One state of the reference: `[θ, θ', r, r']` and the accelerations `θ''`, `r''`.
#[derive(Clone, Copy, Debug)]
pub struct PolarState {
    /// Bar angle from global X.
    pub theta: f64,
    /// Its rate.
    pub theta_dot: f64,
    /// Bead distance from O along the bar.
    pub r: f64,
    /// Its rate.
    pub r_dot: f64,
    /// θ''.
    pub theta_ddot: f64,
    /// r''.
    pub r_ddot: f64,
}

impl BeadInSlot {
    /// `(θ'', r'')` at the state `y = [θ, θ', r, r']`.
    pub fn accelerations(&self, y: &[f64]) -> (f64, f64) {
        self.accelerations_sprung(0.0, y)
    }

    /// `(θ'', r'')` at `y = [θ, θ', r, r']` with the spring `k` (N/m, rest length 0) from O to
    /// the bead.
    pub fn accelerations_sprung(&self, k: f64, y: &[f64]) -> (f64, f64) {
        self.accelerations_rigid(k, 0.0, y)
    }

    /// `(θ'', r'')` at `y = [θ, θ', r, r']`, the spring `k` as in
    /// [`BeadInSlot::accelerations_sprung`], for a bead that is a rigid body of central inertia
    /// `i_bead` turning with the bar (a `prismatic` joint instead of the slot): `T` gains
    /// `½ i_bead θ'²`, so `J_O` becomes `J_O + i_bead` and nothing else changes.
    pub fn accelerations_rigid(&self, k: f64, i_bead: f64, y: &[f64]) -> (f64, f64) {
        let (m_bar, l, m, g) = (self.bar_mass, self.length, self.bead_mass, self.g);
        let j_o = m_bar * l * l / 3.0 + i_bead;
        let (th, w, r, rd) = (y[0], y[1], y[2], y[3]);
        let (s, c) = th.sin_cos();
        let th_dd = -(2.0 * m * r * rd * w + (m_bar * l / 2.0 + m * r) * g * c) / (j_o + m * r * r);
        let r_dd = r * w * w - g * s - k / m * r;
        (th_dd, r_dd)
    }

    /// The reference at `times`, from `y0 = [θ, θ', r, r']`.
    pub fn simulate(&self, y0: [f64; 4], times: &[f64]) -> Vec<PolarState> {
        self.simulate_sprung(0.0, y0, times)
    }

    /// The reference at `times` from `y0 = [θ, θ', r, r']`, the bead pulled toward O by a
    /// spring of stiffness `k` (N/m) and rest length 0.
    pub fn simulate_sprung(&self, k: f64, y0: [f64; 4], times: &[f64]) -> Vec<PolarState> {
        self.simulate_rigid(k, 0.0, y0, times)
    }

    /// As [`BeadInSlot::simulate_sprung`] for a bead of central inertia `i_bead` turning with
    /// the bar ([`BeadInSlot::accelerations_rigid`]).
    pub fn simulate_rigid(
        &self,
        k: f64,
        i_bead: f64,
        y0: [f64; 4],
        times: &[f64],
    ) -> Vec<PolarState> {
        let ys = integrate(
            |_t, y, dy| {
                let (th_dd, r_dd) = self.accelerations_rigid(k, i_bead, y);
                dy[0] = y[1];
                dy[1] = th_dd;
                dy[2] = y[3];
                dy[3] = r_dd;
            },
            0.0,
            &y0,
            times,
            REFERENCE_RTOL,
            REFERENCE_ATOL,
        );
        ys.iter()
            .map(|y| {
                let (theta_ddot, r_ddot) = self.accelerations_rigid(k, i_bead, y);
                PolarState {
                    theta: y[0],
                    theta_dot: y[1],
                    r: y[2],
                    r_dot: y[3],
                    theta_ddot,
                    r_ddot,
                }
            })
            .collect()
    }
}
