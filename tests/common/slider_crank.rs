//! Slider-crank (biela-manivela) with a vertical cylinder, in the minimal
//! coordinate φ (crank angle from X, CCW).
//!
//! Crank: uniform bar (m_c, r) pinned at the origin at its end O. Rod: uniform
//! bar (m_r, l > r), its O pinned to the crank's A. Piston: point mass m_p at
//! the rod's A, constrained to the line x = 0 (cylinder axis along Y). Loads:
//! gravity (0, −g), a constant torque τ on the crank, a vertical force F(φ) on
//! the piston. The branch σ = ±1 says whether the piston is above (+1) or below
//! (−1) the crank pin; it is fixed for the motion (l > r: no dead-centre
//! branch change).
//!
//! Positions, with c = cos φ, s = sin φ, S(φ) = sqrt(l² − r²c²) > 0:
//! crank A   = r (c, s),            crank centre c_c = (r/2)(c, s),
//! piston    y_p = r s + σS,        rod angle β = atan2(σS, −r c),
//! rod centre c_r = crank A + (l/2)(cos β, sin β) = (r c/2, r s + σS/2).
//!
//! φ-derivatives (′ = d/dφ): S′ = r²cs/S, S″ = (r² cos 2φ − S′²)/S;
//! x_r′ = −r s/2,        x_r″ = −r c/2,
//! y_r′ = r c + σS′/2,   y_r″ = −r s + σS″/2,
//! y_p′ = r c + σS′,     y_p″ = −r s + σS″,
//! β′ = −σ r s/S,        β″ = −σ r (c/S − s S′/S²)   (from cos β = −r c/l).
//!
//! Kinetic energy T = ½ J(φ) φ̇² with the reduced inertia
//! J(φ) = m_c r²/3 + m_r (x_r′² + y_r′²) + (m_r l²/12) β′² + m_p y_p′²,
//! potential V(φ) = g (m_c (r/2) s + m_r y_r + m_p y_p), generalized force
//! Q = τ + F(φ) y_p′. Lagrange: d/dt(J φ̇) − ½ J′ φ̇² = −V′ + Q, i.e.
//! J φ̈ = τ + F y_p′ − V′ − ½ J′ φ̇², with
//! ½ J′ = m_r (x_r′x_r″ + y_r′y_r″) + (m_r l²/12) β′β″ + m_p y_p′y_p″,
//! V′ = g (m_c (r/2) c + m_r y_r′ + m_p y_p′).

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// Parameters of the slider-crank.
#[derive(Clone, Copy, Debug)]
pub struct SliderCrank {
    /// Crank length r (m).
    pub r: f64,
    /// Crank mass (kg).
    pub m_crank: f64,
    /// Rod length l (m), must exceed r.
    pub l: f64,
    /// Rod mass (kg).
    pub m_rod: f64,
    /// Piston mass (kg).
    pub m_piston: f64,
    /// Gravity magnitude g (m/s²), acting along −Y.
    pub g: f64,
    /// Constant torque on the crank (N·m, CCW positive).
    pub torque: f64,
    /// Branch: +1 piston above the crank pin, −1 below.
    pub branch: f64,
}

impl SliderCrank {
    /// The bundled `scenes/slider_crank.json` (its description gives these values).
    pub fn bundled() -> SliderCrank {
        SliderCrank {
            r: 0.1,
            m_crank: 1.0,
            l: 0.3,
            m_rod: 0.5,
            m_piston: 0.3,
            g: 9.81,
            torque: 1.5,
            branch: 1.0,
        }
    }
}

/// State of the slider-crank at one time, in global terms.
#[derive(Clone, Copy, Debug)]
pub struct SliderCrankState {
    /// Time (s).
    pub t: f64,
    /// Crank angle φ (rad), continuous.
    pub phi: f64,
    /// Crank rate φ̇ (rad/s).
    pub phi_dot: f64,
    /// Crank centre (x, y).
    pub crank_centre: [f64; 2],
    /// Crank point A = rod point O (x, y).
    pub crank_pin: [f64; 2],
    /// Rod angle β (rad), continuous on the branch of the initial configuration.
    pub rod_angle: f64,
    /// Rod angular rate β̇ (rad/s).
    pub rod_omega: f64,
    /// Rod centre (x, y).
    pub rod_centre: [f64; 2],
    /// Rod centre velocity.
    pub rod_velocity: [f64; 2],
    /// Piston height y_p (x = 0).
    pub piston_y: f64,
    /// Piston velocity ẏ_p.
    pub piston_vy: f64,
    /// Kinetic + gravitational energy (J), V = 0 at y = 0 (excludes the work
    /// of τ and F).
    pub energy: f64,
}

/// Positions and their first two φ-derivatives, for one φ.
struct Kinematics {
    y_r: [f64; 3],
    x_r: [f64; 3],
    y_p: [f64; 3],
    beta: [f64; 3],
}

impl SliderCrank {
    fn kinematics(&self, phi: f64) -> Kinematics {
        let (r, l, sg) = (self.r, self.l, self.branch);
        let (s, c) = phi.sin_cos();
        let big_s = (l * l - r * r * c * c).sqrt();
        let s1 = r * r * c * s / big_s;
        let s2 = (r * r * (2.0 * phi).cos() - s1 * s1) / big_s;
        Kinematics {
            x_r: [0.5 * r * c, -0.5 * r * s, -0.5 * r * c],
            y_r: [
                r * s + 0.5 * sg * big_s,
                r * c + 0.5 * sg * s1,
                -r * s + 0.5 * sg * s2,
            ],
            y_p: [r * s + sg * big_s, r * c + sg * s1, -r * s + sg * s2],
            beta: [
                (sg * big_s).atan2(-r * c),
                -sg * r * s / big_s,
                -sg * r * (c / big_s - s * s1 / (big_s * big_s)),
            ],
        }
    }

    /// Reduced inertia J(φ) and ½ dJ/dφ.
    pub fn reduced_inertia(&self, phi: f64) -> (f64, f64) {
        let k = self.kinematics(phi);
        let j_rod = self.m_rod * self.l * self.l / 12.0;
        let j = self.m_crank * self.r * self.r / 3.0
            + self.m_rod * (k.x_r[1].powi(2) + k.y_r[1].powi(2))
            + j_rod * k.beta[1].powi(2)
            + self.m_piston * k.y_p[1].powi(2);
        let half_dj = self.m_rod * (k.x_r[1] * k.x_r[2] + k.y_r[1] * k.y_r[2])
            + j_rod * k.beta[1] * k.beta[2]
            + self.m_piston * k.y_p[1] * k.y_p[2];
        (j, half_dj)
    }

    /// Closed-form piston height y_p = r sin φ + σ sqrt(l² − r² cos² φ).
    pub fn piston_height(&self, phi: f64) -> f64 {
        self.kinematics(phi).y_p[0]
    }

    /// Crank acceleration φ̈ for a piston force `force` (N, along +Y).
    pub fn acceleration(&self, phi: f64, phi_dot: f64, force: f64) -> f64 {
        let k = self.kinematics(phi);
        let (j, half_dj) = self.reduced_inertia(phi);
        let dv = self.g
            * (self.m_crank * 0.5 * self.r * phi.cos()
                + self.m_rod * k.y_r[1]
                + self.m_piston * k.y_p[1]);
        (self.torque + force * k.y_p[1] - dv - half_dj * phi_dot * phi_dot) / j
    }

    /// The global-terms state for (φ, φ̇) at time `t`.
    pub fn state(&self, t: f64, phi: f64, phi_dot: f64) -> SliderCrankState {
        let k = self.kinematics(phi);
        let (s, c) = phi.sin_cos();
        let (j, _) = self.reduced_inertia(phi);
        let potential = self.g
            * (self.m_crank * 0.5 * self.r * s + self.m_rod * k.y_r[0] + self.m_piston * k.y_p[0]);
        SliderCrankState {
            t,
            phi,
            phi_dot,
            crank_centre: [0.5 * self.r * c, 0.5 * self.r * s],
            crank_pin: [self.r * c, self.r * s],
            rod_angle: k.beta[0],
            rod_omega: k.beta[1] * phi_dot,
            rod_centre: [k.x_r[0], k.y_r[0]],
            rod_velocity: [k.x_r[1] * phi_dot, k.y_r[1] * phi_dot],
            piston_y: k.y_p[0],
            piston_vy: k.y_p[1] * phi_dot,
            energy: 0.5 * j * phi_dot * phi_dot + potential,
        }
    }
}

/// Integrates the slider-crank from (φ, φ̇) = `initial` at t = 0 under the
/// piston force `force(φ)` (N, along +Y) and returns the state at each of
/// `times` (sorted, ≥ 0).
///
/// # Panics
/// If l ≤ r (the rod could not reach the cylinder axis at every φ) or the
/// branch is not ±1.
pub fn simulate_slider_crank(
    p: &SliderCrank,
    initial: [f64; 2],
    force: impl Fn(f64) -> f64,
    times: &[f64],
) -> Vec<SliderCrankState> {
    assert!(
        p.l > p.r,
        "slider-crank: rod length {} must exceed crank length {}",
        p.l,
        p.r
    );
    assert!(
        p.branch.abs() == 1.0,
        "slider-crank: branch must be +1 or -1, got {}",
        p.branch
    );
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        dy[0] = y[1];
        dy[1] = p.acceleration(y[0], y[1], force(y[0]));
    };
    let ys = integrate(rhs, 0.0, &initial, times, REFERENCE_RTOL, REFERENCE_ATOL);
    times
        .iter()
        .zip(ys)
        .map(|(&t, y)| p.state(t, y[0], y[1]))
        .collect()
}
