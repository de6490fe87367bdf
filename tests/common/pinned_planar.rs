//! Planar rigid bodies joined by pins, in absolute coordinates, by Newton–Euler with
//! multipliers: a reference for closed loops that no single minimal coordinate covers.
//!
//! Each body `i` has its centre `(x_i, y_i)`, angle `θ_i`, mass `m_i` and central inertia
//! `J_i`. A pin joins point `s_a` of body `a` (body-fixed; or a fixed point when `a` is the
//! ground) to point `s_b` of body `b`: `g = r_a + R(θ_a) s_a − r_b − R(θ_b) s_b = 0`. With
//! `C = ∂g/∂z` and `γ = (∂(C ż)/∂z) ż` (for a pin, `−R(θ) s θ'²` per end, signed),
//!
//! `[M Cᵀ; C 0] [z''; λ] = [F; −γ]`,   `F` gravity `(0, −m g, 0)` per body,
//!
//! integrated by the tests' Dormand–Prince at rtol = atol = 1e-13. Nothing of bondmech.

use nalgebra::{DMatrix, DVector};

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// One pin: `(Some(a), s_a)` or `(None, fixed point)`, then body `b` and its point `s_b`.
#[derive(Clone, Copy, Debug)]
pub struct Pin {
    /// The first body (`None`: the ground) and its point (body frame, or the ground point).
    pub a: (Option<usize>, [f64; 2]),
    /// The second body and its point (body frame).
    pub b: (usize, [f64; 2]),
}

/// Bodies `(mass, central inertia)` and pins, under gravity `(0, −g)`.
#[derive(Clone, Debug)]
pub struct PinnedPlanar {
    /// `(m, J)` per body.
    pub bodies: Vec<(f64, f64)>,
    /// The pins.
    pub pins: Vec<Pin>,
    /// Gravity (m/s²).
    pub g: f64,
}

fn rot(th: f64, s: [f64; 2]) -> [f64; 2] {
    let (sn, c) = th.sin_cos();
    [c * s[0] - sn * s[1], sn * s[0] + c * s[1]]
}

impl PinnedPlanar {
    /// `z''` at `(z, ż)`, `z = [x_0, y_0, θ_0, x_1, …]`.
    pub fn accelerations(&self, z: &[f64], zd: &[f64]) -> Vec<f64> {
        let n = 3 * self.bodies.len();
        let m = 2 * self.pins.len();
        let mut k = DMatrix::zeros(n + m, n + m);
        let mut rhs = DVector::zeros(n + m);
        for (i, &(mass, inertia)) in self.bodies.iter().enumerate() {
            k[(3 * i, 3 * i)] = mass;
            k[(3 * i + 1, 3 * i + 1)] = mass;
            k[(3 * i + 2, 3 * i + 2)] = inertia;
            rhs[3 * i + 1] = -mass * self.g;
        }
        for (p, pin) in self.pins.iter().enumerate() {
            let row = n + 2 * p;
            let mut ends = vec![(pin.b.0, pin.b.1, -1.0)];
            if let Some(a) = pin.a.0 {
                ends.push((a, pin.a.1, 1.0));
            }
            for (body, s, sign) in ends {
                let th = z[3 * body + 2];
                let rs = rot(th, s);
                // ∂(R s)/∂θ = (−(R s)_y, (R s)_x); its rate's part −R s θ'² goes to −γ
                let dr = [-rs[1], rs[0]];
                for d in 0..2 {
                    k[(row + d, 3 * body + d)] = sign;
                    k[(3 * body + d, row + d)] = sign;
                    k[(row + d, 3 * body + 2)] = sign * dr[d];
                    k[(3 * body + 2, row + d)] = sign * dr[d];
                    rhs[row + d] += sign * zd[3 * body + 2].powi(2) * rs[d];
                }
            }
        }
        let sol = k
            .lu()
            .solve(&rhs)
            .expect("the pinned bodies' saddle is regular");
        sol.rows(0, n).iter().copied().collect()
    }

    /// `z` at each of `times` from `(z0, ż0)` at `times[0]`.
    pub fn simulate(&self, z0: &[f64], zd0: &[f64], times: &[f64]) -> Vec<Vec<f64>> {
        let n = z0.len();
        let y0: Vec<f64> = z0.iter().chain(zd0).copied().collect();
        integrate(
            |_, y, dy| {
                let a = self.accelerations(&y[..n], &y[n..]);
                dy[..n].copy_from_slice(&y[n..]);
                dy[n..].copy_from_slice(&a);
            },
            times[0],
            &y0,
            times,
            REFERENCE_RTOL,
            REFERENCE_ATOL,
        )
        .into_iter()
        .map(|y| y[..n].to_vec())
        .collect()
    }
}
