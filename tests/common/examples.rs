//! Hand-derived accelerations of the planar example scenes (`scenes/pendulum.json`,
//! `two_bars.json`, `four_bar.json`), independent of bondmech. Conventions as in `mod.rs`:
//! `e(θ) = (cos θ, sin θ)`, `e⊥(θ) = (−sin θ, cos θ)`.

use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};

fn e(t: f64) -> Vector2<f64> {
    Vector2::new(t.cos(), t.sin())
}
fn ep(t: f64) -> Vector2<f64> {
    Vector2::new(-t.sin(), t.cos())
}

/// Bar (mass m, length L, central inertia J) pinned at its end O = (−L/2, 0) to the origin,
/// gravity (0, −g). Lagrange in θ: `(J + m L²/4) θ'' = −m g (L/2) cos θ`.
/// Returns (θ'', centre acceleration).
pub fn pendulum_accelerations(
    m: f64,
    l: f64,
    j: f64,
    g: f64,
    th: f64,
    w: f64,
) -> (f64, Vector2<f64>) {
    let d = 0.5 * l;
    let a = -m * g * d * th.cos() / (j + m * d * d);
    (a, d * (a * ep(th) - w * w * e(th)))
}

/// One bar of the free two-bar chain: mass, central inertia, and the signed offset `d` of its
/// centre from the hinge along its axis (`c = H + d e(θ)`).
#[derive(Clone, Copy, Debug)]
pub struct HingedBar {
    /// Mass (kg).
    pub m: f64,
    /// Central moment of inertia (kg m²).
    pub j: f64,
    /// Centre offset from the hinge along the body x axis (m).
    pub d: f64,
}

/// Two bars hinged at H, free in the plane, gravity `gv`; coordinates (H_x, H_y, θ₁, θ₂).
/// With `c_i = H + d_i e_i`: `c_i'' = H'' + d_i θ_i'' e_i⊥ − d_i θ_i'² e_i` and
/// `T = Σ ½ m_i |c_i'|² + ½ J_i θ_i'²`; Lagrange's equations are
/// `(m₁+m₂) H'' + Σ m_i d_i e_i⊥ θ_i'' = Σ m_i d_i θ_i'² e_i + (m₁+m₂) g`,
/// `m_i d_i e_i⊥·H'' + (m_i d_i² + J_i) θ_i'' = m_i d_i e_i⊥·g`.
/// Returns (H'', θ₁'', θ₂'').
pub fn two_bar_accelerations(
    bars: [HingedBar; 2],
    gv: Vector2<f64>,
    th: [f64; 2],
    w: [f64; 2],
) -> (Vector2<f64>, f64, f64) {
    let mt = bars[0].m + bars[1].m;
    let mut a = Matrix4::zeros();
    let mut b = Vector4::zeros();
    a[(0, 0)] = mt;
    a[(1, 1)] = mt;
    let mut rhs_h = mt * gv;
    for (i, bar) in bars.iter().enumerate() {
        let (u, up) = (e(th[i]), ep(th[i]));
        let c = bar.m * bar.d * up;
        a[(0, 2 + i)] = c.x;
        a[(1, 2 + i)] = c.y;
        a[(2 + i, 0)] = c.x;
        a[(2 + i, 1)] = c.y;
        a[(2 + i, 2 + i)] = bar.m * bar.d * bar.d + bar.j;
        rhs_h += bar.m * bar.d * w[i] * w[i] * u;
        b[2 + i] = c.dot(&gv);
    }
    b[0] = rhs_h.x;
    b[1] = rhs_h.y;
    let x = a.lu().solve(&b).expect("two-bar mass matrix is regular");
    (Vector2::new(x[0], x[1]), x[2], x[3])
}

/// Four-bar linkage: crank (r₁) pinned at the origin, coupler (r₂) from the crank tip A to B,
/// rocker (r₃) from O₄ = (d, 0) to B; uniform bars with masses `m` and central inertias `j`,
/// gravity (0, −g).
#[derive(Clone, Copy, Debug)]
pub struct FourBar {
    /// Link lengths crank, coupler, rocker (m).
    pub r: [f64; 3],
    /// Masses (kg).
    pub m: [f64; 3],
    /// Central inertias (kg m²).
    pub j: [f64; 3],
    /// Ground pivot distance d (m).
    pub d: f64,
    /// Gravity (m/s²), along −Y.
    pub g: f64,
}

/// A consistent four-bar configuration for crank angle φ and rate φ'.
#[derive(Clone, Copy, Debug)]
pub struct FourBarState {
    /// Absolute angles of crank, coupler, rocker.
    pub th: [f64; 3],
    /// Their rates.
    pub w: [f64; 3],
    /// Centres of crank, coupler, rocker.
    pub c: [Vector2<f64>; 3],
    /// Centre velocities.
    pub v: [Vector2<f64>; 3],
}

impl FourBar {
    /// Position by circle intersection (B on the left of A→O₄, the open branch of
    /// `four_bar.json`), velocities from the loop `r₁ω₁e₁⊥ + r₂ω₂e₂⊥ = r₃ω₃e₃⊥`.
    pub fn state(&self, phi: f64, w1: f64) -> FourBarState {
        let [r1, r2, r3] = self.r;
        let a = r1 * e(phi);
        let o4 = Vector2::new(self.d, 0.0);
        let dv = o4 - a;
        let dist = dv.norm();
        // B = A + x û + y n̂ with û = (O4 − A)/|O4 − A|, n̂ its left normal
        let x = (r2 * r2 - r3 * r3 + dist * dist) / (2.0 * dist);
        let y = (r2 * r2 - x * x).sqrt();
        let uh = dv / dist;
        let nh = Vector2::new(-uh.y, uh.x);
        let b = a + x * uh + y * nh;
        let t2 = (b - a).y.atan2((b - a).x);
        let t3 = (b - o4).y.atan2((b - o4).x);
        let am = Matrix2::from_columns(&[r2 * ep(t2), -r3 * ep(t3)]);
        let k = am
            .lu()
            .solve(&(-r1 * ep(phi)))
            .expect("not at a dead point");
        let w = [w1, k.x * w1, k.y * w1];
        let th = [phi, t2, t3];
        let c = [0.5 * a, a + 0.5 * r2 * e(t2), o4 + 0.5 * r3 * e(t3)];
        let v = [
            0.5 * r1 * w1 * ep(phi),
            r1 * w1 * ep(phi) + 0.5 * r2 * w[1] * ep(t2),
            0.5 * r3 * w[2] * ep(t3),
        ];
        FourBarState { th, w, c, v }
    }

    /// Angular accelerations of the three links at a consistent state.
    ///
    /// Differentiating the loop twice: `[r₂e₂⊥, −r₃e₃⊥](α₂, α₃) = −r₁α₁e₁⊥ + r₁ω₁²e₁ + r₂ω₂²e₂
    /// − r₃ω₃²e₃`, so `α_i = κ_i α₁ + h_i`, and the centre accelerations are `P_i α₁ + Q_i`.
    /// Jourdain's principle with the virtual rate δφ (velocity coefficients `P_i`, `κ_i`):
    /// `Σ m_i P_i·(P_i α₁ + Q_i) + J_i κ_i (κ_i α₁ + h_i) = Σ m_i P_i·(0, −g)`.
    pub fn accelerations(&self, s: &FourBarState) -> [f64; 3] {
        let [r1, r2, r3] = self.r;
        let [t1, t2, t3] = s.th;
        let [w1, w2, w3] = s.w;
        let am = Matrix2::from_columns(&[r2 * ep(t2), -r3 * ep(t3)]);
        let lu = am.lu();
        // angular accelerations (α₂, α₃) and centre accelerations for a given α₁
        let acc = |a1: f64| {
            let rhs = -r1 * a1 * ep(t1) + r1 * w1 * w1 * e(t1) + r2 * w2 * w2 * e(t2)
                - r3 * w3 * w3 * e(t3);
            let x = lu.solve(&rhs).expect("not at a dead point");
            let al = [a1, x.x, x.y];
            let tip = r1 * (a1 * ep(t1) - w1 * w1 * e(t1));
            let c = [
                0.5 * tip,
                tip + 0.5 * r2 * (al[1] * ep(t2) - w2 * w2 * e(t2)),
                0.5 * r3 * (al[2] * ep(t3) - w3 * w3 * e(t3)),
            ];
            (al, c)
        };
        let (h, q) = acc(0.0);
        let (h1, q1) = acc(1.0);
        let kappa: [f64; 3] = std::array::from_fn(|i| h1[i] - h[i]);
        let p: [Vector2<f64>; 3] = std::array::from_fn(|i| q1[i] - q[i]);
        let gv = Vector2::new(0.0, -self.g);
        let (mut lhs, mut rhs) = (0.0, 0.0);
        for i in 0..3 {
            lhs += self.m[i] * p[i].dot(&p[i]) + self.j[i] * kappa[i] * kappa[i];
            rhs += self.m[i] * p[i].dot(&(gv - q[i])) - self.j[i] * kappa[i] * h[i];
        }
        let a1 = rhs / lhs;
        acc(a1).0
    }
}
