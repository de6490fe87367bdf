//! A planar five-bar linkage (2 DOF, one closed loop) in its four link angles, the loop
//! closure kept by multipliers.
//!
//! Crank c1 (length L₁) is pinned to the ground at the origin, crank c4 (L₄) at D = (d, 0);
//! coupler k2 (L₂) is pinned to c1's tip, coupler k3 (L₃) to c4's tip, and the couplers'
//! far ends are pinned together. Every link is a uniform bar (mass mᵢ, central inertia
//! Iᵢ = mᵢLᵢ²/12) with the conventions of `docs/scene-format.md` (points O = (−L/2, 0) and
//! A = (+L/2, 0), the angle that of the body x-axis from global X). Coordinates: the absolute
//! angles q = (θ₁, θ₂, θ₃, θ₄) of c1, k2, k3, c4; with uᵢ = (cos θᵢ, sin θᵢ) and
//! uᵢ⊥ = (−sin θᵢ, cos θᵢ) the centres are
//!
//! ```text
//!   c1: (L₁/2) u₁            k2: L₁ u₁ + (L₂/2) u₂
//!   c4: D + (L₄/2) u₄        k3: D + L₄ u₄ + (L₃/2) u₃
//! ```
//!
//! i.e. each centre is `x_b = const_b + Σⱼ a_bj uⱼ` (the coefficients `a_bj` below), with
//! velocity `Σⱼ a_bj θ̇ⱼ uⱼ⊥` and acceleration `Σⱼ a_bj (θ̈ⱼ uⱼ⊥ − θ̇ⱼ² uⱼ)`. The two chains
//! (c1, k2) and (c4, k3) are open in these coordinates; the loop is closed by
//!
//! ```text
//!   g(q) = L₁u₁ + L₂u₂ − D − L₄u₄ − L₃u₃ = 0        (k2's A on k3's A),
//!   G = ∂g/∂q = [L₁u₁⊥, L₂u₂⊥, −L₃u₃⊥, −L₄u₄⊥],     G q̈ = Σⱼ sⱼ Lⱼ θ̇ⱼ² uⱼ  (s = (1, 1, −1, −1)).
//! ```
//!
//! Lagrange's equations of the open chains with the closure's multipliers λ (index 1):
//!
//! ```text
//!   [ M  Gᵀ ] [ q̈ ]   [ Q − b ]     M_jk = Σ_b m_b a_bj a_bk cos(θⱼ − θₖ) + δ_jk Iⱼ,
//!   [ G  0  ] [ λ ] = [ G q̈   ]     b_j  = Σ_b m_b a_bj Σₖ a_bk θ̇ₖ² sin(θⱼ − θₖ),
//!                                   Q_j  = −g cos θⱼ Σ_b m_b a_bj,
//! ```
//!
//! regular wherever `G` has rank 2 (all four links would have to be parallel to lose it), so
//! also where the couplers line up and the crank angles stop being coordinates. The energy
//! `½ q̇ᵀ M q̇ + g Σ_b m_b y_b` is conserved and `g(q)` stays zero (the tests check both).

use nalgebra::{Matrix4, Matrix6, Vector4, Vector6};

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// A five-bar of uniform bars.
#[derive(Clone, Copy, Debug)]
pub struct FiveBar {
    /// Distance of the second ground pivot D = (d, 0) from the origin (m).
    pub d: f64,
    /// Lengths of c1, k2, k3, c4 (m).
    pub lengths: [f64; 4],
    /// Masses of c1, k2, k3, c4 (kg).
    pub masses: [f64; 4],
    /// Gravity (m/s², along −Y).
    pub g: f64,
}

/// The bodies' names, in the order of the coordinates.
pub const NAMES: [&str; 4] = ["c1", "k2", "k3", "c4"];

/// One state of the five-bar.
#[derive(Clone, Copy, Debug)]
pub struct FiveBarState {
    /// Time (s).
    pub t: f64,
    /// The link angles θ₁..θ₄ (c1, k2, k3, c4).
    pub q: [f64; 4],
    /// Their rates.
    pub qd: [f64; 4],
}

fn u(a: f64) -> [f64; 2] {
    [a.cos(), a.sin()]
}

impl FiveBar {
    /// Issue 46's five-bar: ground pivots 0.4 m apart, cranks 0.3 m, couplers 0.7 m, uniform
    /// bars of 1 kg/m.
    pub fn issue_46() -> FiveBar {
        let lengths = [0.3, 0.7, 0.7, 0.3];
        FiveBar {
            d: 0.4,
            lengths,
            masses: lengths,
            g: 9.81,
        }
    }

    /// The coefficients `a_bj` of the centres and their constant parts.
    fn coefficients(&self) -> ([[f64; 4]; 4], [[f64; 2]; 4]) {
        let [l1, l2, l3, l4] = self.lengths;
        (
            [
                [0.5 * l1, 0.0, 0.0, 0.0],
                [l1, 0.5 * l2, 0.0, 0.0],
                [0.0, 0.0, 0.5 * l3, l4],
                [0.0, 0.0, 0.0, 0.5 * l4],
            ],
            [[0.0, 0.0], [0.0, 0.0], [self.d, 0.0], [self.d, 0.0]],
        )
    }

    /// Central inertias mᵢLᵢ²/12.
    pub fn inertias(&self) -> [f64; 4] {
        std::array::from_fn(|i| self.masses[i] * self.lengths[i].powi(2) / 12.0)
    }

    /// The four angles with the cranks at `q1`, `q4` and the couplers' joint on the side
    /// `up` (left of the line from c1's tip to c4's tip): the two circles' intersection.
    pub fn start(&self, q1: f64, q4: f64, up: bool) -> [f64; 4] {
        let [l1, l2, l3, l4] = self.lengths;
        let b = [l1 * q1.cos(), l1 * q1.sin()];
        let dd = [self.d + l4 * q4.cos(), l4 * q4.sin()];
        let (dx, dy) = (dd[0] - b[0], dd[1] - b[1]);
        let s = dx.hypot(dy);
        let uu = [dx / s, dy / s];
        let a = (l2 * l2 - l3 * l3 + s * s) / (2.0 * s);
        let h = (l2 * l2 - a * a).sqrt() * if up { 1.0 } else { -1.0 };
        let c = [b[0] + a * uu[0] - h * uu[1], b[1] + a * uu[1] + h * uu[0]];
        [
            q1,
            (c[1] - b[1]).atan2(c[0] - b[0]),
            (c[1] - dd[1]).atan2(c[0] - dd[0]),
            q4,
        ]
    }

    /// The closure `g(q)` (k2's A minus k3's A).
    pub fn closure(&self, q: &[f64; 4]) -> [f64; 2] {
        let [l1, l2, l3, l4] = self.lengths;
        let us: [[f64; 2]; 4] = std::array::from_fn(|j| u(q[j]));
        std::array::from_fn(|k| {
            l1 * us[0][k] + l2 * us[1][k]
                - l3 * us[2][k]
                - l4 * us[3][k]
                - if k == 0 { self.d } else { 0.0 }
        })
    }

    /// The centres (x, y) and velocities of the four bodies (order of [`NAMES`]).
    pub fn centres(&self, q: &[f64; 4], qd: &[f64; 4]) -> [([f64; 2], [f64; 2]); 4] {
        let (a, c) = self.coefficients();
        std::array::from_fn(|b| {
            let mut x = c[b];
            let mut v = [0.0; 2];
            for j in 0..4 {
                let (s, co) = q[j].sin_cos();
                x[0] += a[b][j] * co;
                x[1] += a[b][j] * s;
                v[0] -= a[b][j] * qd[j] * s;
                v[1] += a[b][j] * qd[j] * co;
            }
            (x, v)
        })
    }

    fn mass_matrix(&self, q: &[f64; 4]) -> Matrix4<f64> {
        let (a, _) = self.coefficients();
        let inertia = self.inertias();
        Matrix4::from_fn(|j, k| {
            let m: f64 = a
                .iter()
                .zip(&self.masses)
                .map(|(ab, mb)| mb * ab[j] * ab[k])
                .sum();
            m * (q[j] - q[k]).cos() + if j == k { inertia[j] } else { 0.0 }
        })
    }

    /// Total energy `½ q̇ᵀ M q̇ + g Σ m y`.
    pub fn energy(&self, q: &[f64; 4], qd: &[f64; 4]) -> f64 {
        let m = self.mass_matrix(q);
        let v = Vector4::from(*qd);
        let potential: f64 = self
            .centres(q, qd)
            .iter()
            .zip(&self.masses)
            .map(|((x, _), mb)| mb * self.g * x[1])
            .sum();
        0.5 * v.dot(&(m * v)) + potential
    }

    /// The accelerations q̈ from the system above.
    pub fn accelerations(&self, q: &[f64; 4], qd: &[f64; 4]) -> [f64; 4] {
        let (a, _) = self.coefficients();
        let m = self.mass_matrix(q);
        let mut k = Matrix6::zeros();
        let mut rhs = Vector6::zeros();
        k.fixed_view_mut::<4, 4>(0, 0).copy_from(&m);
        let sign = [1.0, 1.0, -1.0, -1.0];
        for j in 0..4 {
            let (s, c) = q[j].sin_cos();
            let l = self.lengths[j];
            // G's column j: sⱼ Lⱼ uⱼ⊥
            k[(4, j)] = -sign[j] * l * s;
            k[(5, j)] = sign[j] * l * c;
            k[(j, 4)] = k[(4, j)];
            k[(j, 5)] = k[(5, j)];
            rhs[4] += sign[j] * l * qd[j] * qd[j] * c;
            rhs[5] += sign[j] * l * qd[j] * qd[j] * s;
            let mut bias = 0.0;
            let mut weight = 0.0;
            for (ab, mb) in a.iter().zip(&self.masses) {
                weight += mb * ab[j];
                for ((abk, qk), qdk) in ab.iter().zip(q).zip(qd) {
                    bias += mb * ab[j] * abk * qdk * qdk * (q[j] - qk).sin();
                }
            }
            rhs[j] = -self.g * c * weight - bias;
        }
        let x = k
            .lu()
            .solve(&rhs)
            .expect("the five-bar's KKT matrix is regular");
        [x[0], x[1], x[2], x[3]]
    }

    /// Integrates from `(q0, qd0)` at t = 0 to each of `times` (sorted, ≥ 0) with the tests'
    /// Dormand–Prince at `rtol`, `atol`.
    pub fn simulate_tol(
        &self,
        q0: [f64; 4],
        qd0: [f64; 4],
        times: &[f64],
        rtol: f64,
        atol: f64,
    ) -> Vec<FiveBarState> {
        let mut y0 = q0.to_vec();
        y0.extend(qd0);
        let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
            let q = [y[0], y[1], y[2], y[3]];
            let qd = [y[4], y[5], y[6], y[7]];
            dy[..4].copy_from_slice(&qd);
            dy[4..].copy_from_slice(&self.accelerations(&q, &qd));
        };
        let ys = integrate(rhs, 0.0, &y0, times, rtol, atol);
        times
            .iter()
            .zip(ys)
            .map(|(&t, y)| FiveBarState {
                t,
                q: [y[0], y[1], y[2], y[3]],
                qd: [y[4], y[5], y[6], y[7]],
            })
            .collect()
    }

    /// [`FiveBar::simulate_tol`] at the references' tolerances.
    pub fn simulate(&self, q0: [f64; 4], qd0: [f64; 4], times: &[f64]) -> Vec<FiveBarState> {
        self.simulate_tol(q0, qd0, times, REFERENCE_RTOL, REFERENCE_ATOL)
    }

    /// The scene of this five-bar at rest at the angles `q` (bodies c1, k2, k3, c4; revolute
    /// joints A (ground–c1), B (c1–k2), C (k2–k3), D (k3–c4), E (ground–c4)), with the scene's
    /// `solve` block `solve`.
    pub fn scene(&self, name: &str, q: &[f64; 4], solve: serde_json::Value) -> String {
        let centres = self.centres(q, &[0.0; 4]);
        let inertia = self.inertias();
        let bodies: Vec<serde_json::Value> = (0..4)
            .map(|b| {
                let l = self.lengths[b];
                serde_json::json!({
                    "name": NAMES[b],
                    "mass": self.masses[b],
                    "inertia": inertia[b],
                    "points": {"O": [-0.5 * l, 0.0], "A": [0.5 * l, 0.0]},
                    "position": centres[b].0,
                    "angle": q[b],
                })
            })
            .collect();
        let joints = serde_json::json!([
            {"name": "A", "type": "revolute", "bodies": ["ground", "c1"], "points": [[0.0, 0.0], "O"]},
            {"name": "B", "type": "revolute", "bodies": ["c1", "k2"], "points": ["A", "O"]},
            {"name": "C", "type": "revolute", "bodies": ["k2", "k3"], "points": ["A", "A"]},
            {"name": "D", "type": "revolute", "bodies": ["k3", "c4"], "points": ["O", "A"]},
            {"name": "E", "type": "revolute", "bodies": ["ground", "c4"], "points": [[self.d, 0.0], "O"]},
        ]);
        serde_json::json!({
            "name": name,
            "dimension": 2,
            "gravity": [0.0, -self.g],
            "bodies": bodies,
            "joints": joints,
            "solve": solve,
        })
        .to_string()
    }
}
