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

/// An offset slider-crank with a horizontal cylinder, in the crank angle φ (Lagrange): the
/// new-user trial's case 2 (issue 46's "fast offset slider-crank" spins it at 14 rad/s).
///
/// Crank: uniform bar (m_c, central inertia I_c, length r) pinned at the origin at its end O,
/// its tip A = r (cos φ, sin φ). Rod: a body (m_r, central inertia I_r) pinned to the crank's A
/// at its point A, its centre at `c_A` from A in rod axes (not on the line A→B), its point B at
/// distance l along the rod's x-axis from A; B is the wrist pin of the piston, a point mass m_p
/// sliding along the line y = e (the offset). Gravity (0, −g). No other loads.
///
/// With the rod angle ψ (sin ψ = (e − r sin φ)/l, cos ψ > 0 on the branch with the piston
/// to the right of A, as l > r + |e|), and ′ = d/dφ:
///
/// ```text
///   s = e − r sin φ = l sin ψ,   s′ = −r cos φ,   s″ = r sin φ,
///   ψ′ = s′/(l cos ψ),           ψ″ = (s″ + l sin ψ ψ′²)/(l cos ψ),
///   x_p = r cos φ + l cos ψ,     x_p′ = −r sin φ − l sin ψ ψ′,
///                                x_p″ = −r cos φ − l cos ψ ψ′² − l sin ψ ψ″,
///   G = A + R(ψ) c_A,            G′ = A′ + ψ′ J R(ψ) c_A,   G″ = A″ + ψ″ J R(ψ) c_A − ψ′² R(ψ) c_A,
///   C = (r/2)(cos φ, sin φ)      (crank centre),  A′ = r (−sin φ, cos φ),  A″ = −r (cos φ, sin φ),
/// ```
///
/// (J the rotation by +90°). The reduced inertia and Lagrange's equation:
///
/// ```text
///   M(φ) = m_c |C′|² + I_c + m_r |G′|² + I_r ψ′² + m_p x_p′²,
///   ½ M′ = m_c C′·C″ + m_r G′·G″ + I_r ψ′ψ″ + m_p x_p′ x_p″,
///   V′ = g (m_c C′_y + m_r G′_y),
///   M φ̈ = −½ M′ φ̇² − V′.
/// ```
///
/// The energy `½ M φ̇² + g (m_c C_y + m_r G_y + m_p e)` is conserved (the tests check it).
#[derive(Clone, Copy, Debug)]
pub struct OffsetSliderCrank {
    /// Crank length r (m).
    pub r: f64,
    /// Crank mass (kg).
    pub m_crank: f64,
    /// Crank central inertia (kg m²).
    pub i_crank: f64,
    /// Rod length l from A to B (m), more than r + |e|.
    pub l: f64,
    /// Rod mass (kg).
    pub m_rod: f64,
    /// Rod central inertia (kg m²).
    pub i_rod: f64,
    /// Rod centre from its point A, in rod axes (m).
    pub rod_centre: [f64; 2],
    /// Piston mass (kg).
    pub m_piston: f64,
    /// Cylinder offset e: the piston moves on y = e (m).
    pub e: f64,
    /// Gravity magnitude g (m/s², along −Y).
    pub g: f64,
}

/// Positions of an [`OffsetSliderCrank`] and their φ-derivatives `[value, ′, ″]`.
#[derive(Clone, Copy, Debug)]
pub struct OffsetKinematics {
    /// Crank centre C.
    pub crank: [[f64; 2]; 3],
    /// Rod centre G.
    pub rod: [[f64; 2]; 3],
    /// Rod angle ψ.
    pub psi: [f64; 3],
    /// Piston x (its y is e).
    pub piston_x: [f64; 3],
}

impl OffsetSliderCrank {
    /// The new-user trial's case 2 (`tests/references/matched_tolerance.py`,
    /// `slider_crank_fast`): r 0.15 m, l 0.5 m, e 0.08 m; crank 1 kg (uniform), rod 0.6 kg,
    /// 0.02 kg m², centre (0.2, 0.04) from A; piston 0.4 kg.
    pub fn trial_case_2() -> OffsetSliderCrank {
        OffsetSliderCrank {
            r: 0.15,
            m_crank: 1.0,
            i_crank: 0.15 * 0.15 / 12.0,
            l: 0.5,
            m_rod: 0.6,
            i_rod: 0.02,
            rod_centre: [0.2, 0.04],
            m_piston: 0.4,
            e: 0.08,
            g: 9.81,
        }
    }

    /// The positions and their first two φ-derivatives.
    pub fn kinematics(&self, phi: f64) -> OffsetKinematics {
        let (r, l) = (self.r, self.l);
        let (sf, cf) = phi.sin_cos();
        let s = [self.e - r * sf, -r * cf, r * sf];
        let psi = (s[0] / l).asin();
        let (sp, cp) = psi.sin_cos();
        let p1 = s[1] / (l * cp);
        let p2 = (s[2] + l * sp * p1 * p1) / (l * cp);
        let x_p = [
            r * cf + l * cp,
            -r * sf - l * sp * p1,
            -r * cf - l * cp * p1 * p1 - l * sp * p2,
        ];
        let [ax, ay] = self.rod_centre;
        let w = [cp * ax - sp * ay, sp * ax + cp * ay];
        let jw = [-w[1], w[0]];
        let a = [[r * cf, r * sf], [-r * sf, r * cf], [-r * cf, -r * sf]];
        OffsetKinematics {
            crank: [
                [0.5 * a[0][0], 0.5 * a[0][1]],
                [0.5 * a[1][0], 0.5 * a[1][1]],
                [0.5 * a[2][0], 0.5 * a[2][1]],
            ],
            rod: [
                [a[0][0] + w[0], a[0][1] + w[1]],
                [a[1][0] + p1 * jw[0], a[1][1] + p1 * jw[1]],
                [
                    a[2][0] + p2 * jw[0] - p1 * p1 * w[0],
                    a[2][1] + p2 * jw[1] - p1 * p1 * w[1],
                ],
            ],
            psi: [psi, p1, p2],
            piston_x: x_p,
        }
    }

    /// Reduced inertia M(φ), ½ M′(φ) and V′(φ).
    fn reduced(&self, phi: f64) -> (f64, f64, f64) {
        let k = self.kinematics(phi);
        let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
        let m = self.m_crank * dot(k.crank[1], k.crank[1])
            + self.i_crank
            + self.m_rod * dot(k.rod[1], k.rod[1])
            + self.i_rod * k.psi[1] * k.psi[1]
            + self.m_piston * k.piston_x[1] * k.piston_x[1];
        let half_dm = self.m_crank * dot(k.crank[1], k.crank[2])
            + self.m_rod * dot(k.rod[1], k.rod[2])
            + self.i_rod * k.psi[1] * k.psi[2]
            + self.m_piston * k.piston_x[1] * k.piston_x[2];
        let dv = self.g * (self.m_crank * k.crank[1][1] + self.m_rod * k.rod[1][1]);
        (m, half_dm, dv)
    }

    /// φ̈ at (φ, φ̇).
    pub fn acceleration(&self, phi: f64, phi_dot: f64) -> f64 {
        let (m, half_dm, dv) = self.reduced(phi);
        -(half_dm * phi_dot * phi_dot + dv) / m
    }

    /// Energy `½ M φ̇² + V`.
    pub fn energy(&self, phi: f64, phi_dot: f64) -> f64 {
        let (m, _, _) = self.reduced(phi);
        let k = self.kinematics(phi);
        0.5 * m * phi_dot * phi_dot
            + self.g
                * (self.m_crank * k.crank[0][1] + self.m_rod * k.rod[0][1] + self.m_piston * self.e)
    }

    /// Integrates from (φ, φ̇) = `initial` at t = 0 and returns `[φ, φ̇]` at each of `times`
    /// (sorted, ≥ 0), with the tests' Dormand–Prince at `rtol`, `atol`.
    pub fn simulate_tol(
        &self,
        initial: [f64; 2],
        times: &[f64],
        rtol: f64,
        atol: f64,
    ) -> Vec<[f64; 2]> {
        assert!(
            self.l > self.r + self.e.abs(),
            "offset slider-crank: the rod must reach the cylinder line at every crank angle"
        );
        let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = self.acceleration(y[0], y[1]);
        };
        integrate(rhs, 0.0, &initial, times, rtol, atol)
            .into_iter()
            .map(|y| [y[0], y[1]])
            .collect()
    }

    /// [`OffsetSliderCrank::simulate_tol`] at the references' tolerances.
    pub fn simulate(&self, initial: [f64; 2], times: &[f64]) -> Vec<[f64; 2]> {
        self.simulate_tol(initial, times, REFERENCE_RTOL, REFERENCE_ATOL)
    }

    /// The scene (bodies crank, rod, piston; joints main, crankpin, wrist, cylinder) at
    /// (φ, φ̇) = `initial`, the velocities consistent, with the scene's `solve` block `solve`.
    pub fn scene(&self, initial: [f64; 2], solve: serde_json::Value) -> String {
        let [phi, w] = initial;
        let k = self.kinematics(phi);
        let [cx, cy] = self.rod_centre;
        let v = |p: [f64; 2]| [p[0] * w, p[1] * w];
        serde_json::json!({
            "name": "offset_slider_crank",
            "dimension": 2,
            "gravity": [0.0, -self.g],
            "bodies": [
                {"name": "crank", "mass": self.m_crank, "inertia": self.i_crank,
                 "points": {"O": [-0.5 * self.r, 0.0], "A": [0.5 * self.r, 0.0]},
                 "position": k.crank[0], "angle": phi,
                 "velocity": v(k.crank[1]), "angular_velocity": w},
                {"name": "rod", "mass": self.m_rod, "inertia": self.i_rod,
                 "points": {"A": [-cx, -cy], "B": [self.l - cx, -cy]},
                 "position": k.rod[0], "angle": k.psi[0],
                 "velocity": v(k.rod[1]), "angular_velocity": k.psi[1] * w},
                {"name": "piston", "mass": self.m_piston, "inertia": 0.0,
                 "position": [k.piston_x[0], self.e],
                 "velocity": [k.piston_x[1] * w, 0.0]},
            ],
            "joints": [
                {"name": "main", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0.0, 0.0], "O"]},
                {"name": "crankpin", "type": "revolute", "bodies": ["crank", "rod"], "points": ["A", "A"]},
                {"name": "wrist", "type": "revolute", "bodies": ["rod", "piston"], "points": ["B", [0.0, 0.0]]},
                {"name": "cylinder", "type": "prismatic", "bodies": ["ground", "piston"], "points": [[0.0, self.e], [0.0, 0.0]], "axis": [1.0, 0.0]},
            ],
            "solve": solve,
        })
        .to_string()
    }
}
