//! Complete elliptic integral of the first kind and the exact period of a
//! pendulum.
//!
//! K(m) = ∫₀^{π/2} dθ / sqrt(1 − m sin²θ) = π / (2·AGM(1, sqrt(1 − m)))
//! (Abramowitz & Stegun 17.6), with the parameter convention m = k² of A&S
//! chapter 17. A pendulum that obeys θ'' = −(g/L) sin θ and swings with
//! amplitude θ₀ has the period T = 4 sqrt(L/g) K(sin²(θ₀/2)).

use std::f64::consts::PI;

/// Arithmetic–geometric mean of `a` and `b` (both ≥ 0), iterated until the
/// two means agree to rounding.
pub fn agm(mut a: f64, mut b: f64) -> f64 {
    for _ in 0..64 {
        if (a - b).abs() <= 1e-16 * a.abs() {
            break;
        }
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
    }
    a
}

/// Complete elliptic integral of the first kind K(m), parameter m = k² < 1.
pub fn elliptic_k(m: f64) -> f64 {
    assert!(m < 1.0, "elliptic_k: parameter m = {m} must be < 1");
    PI / (2.0 * agm(1.0, (1.0 - m).sqrt()))
}

/// Exact period of a simple pendulum of length `length` (m) under gravity `g`
/// (m/s²) swinging with amplitude `amplitude` (rad, from the bottom, < π):
/// T = 4 sqrt(L/g) K(sin²(θ₀/2)). For a physical pendulum pass the equivalent
/// length L = J_pivot / (m·d).
pub fn pendulum_period(length: f64, g: f64, amplitude: f64) -> f64 {
    4.0 * (length / g).sqrt() * elliptic_k((0.5 * amplitude).sin().powi(2))
}

/// Jacobi elliptic functions `(sn, cn)` of argument `u` and parameter `m = k²` (0 ≤ m < 1), by
/// the arithmetic–geometric mean (A&S 16.4.3): a₀ = 1, b₀ = √(1−m), c₀ = √m, then
/// aₙ = (aₙ₋₁+bₙ₋₁)/2, bₙ = √(aₙ₋₁bₙ₋₁), cₙ = (aₙ₋₁−bₙ₋₁)/2 until cₙ vanishes; φ_N = 2ᴺ a_N u
/// and φₙ₋₁ = (φₙ + arcsin(cₙ/aₙ · sin φₙ))/2; sn = sin φ₀, cn = cos φ₀.
pub fn jacobi_sn_cn(u: f64, m: f64) -> (f64, f64) {
    assert!(
        (0.0..1.0).contains(&m),
        "jacobi_sn_cn: m = {m} must be in [0, 1)"
    );
    let mut a = vec![1.0f64];
    let mut c = vec![m.sqrt()];
    let mut b = (1.0 - m).sqrt();
    while c.last().unwrap().abs() > 1e-16 && a.len() < 64 {
        let (an, bn) = (a.last().unwrap(), b);
        let cn = 0.5 * (an - bn);
        let next_a = 0.5 * (an + bn);
        b = (an * bn).sqrt();
        a.push(next_a);
        c.push(cn);
    }
    let n = a.len() - 1;
    let mut phi = 2f64.powi(n as i32) * a[n] * u;
    for i in (1..=n).rev() {
        phi = 0.5 * (phi + (c[i] / a[i] * phi.sin()).asin());
    }
    (phi.sin(), phi.cos())
}

/// Exact angle from the downward vertical of a simple pendulum (length `length`, gravity `g`)
/// released at rest from `amplitude` (< π) at t = 0: θ(t) = 2 arcsin(k sn(K + ω₀t, k²)) with
/// k = sin(θ₀/2), ω₀ = √(g/L), K = K(k²) (sn(K) = 1 gives θ(0) = θ₀, θ'(0) = 0).
pub fn pendulum_angle(length: f64, g: f64, amplitude: f64, t: f64) -> f64 {
    let k = (0.5 * amplitude).sin();
    let m = k * k;
    let w0 = (g / length).sqrt();
    let (sn, _) = jacobi_sn_cn(elliptic_k(m) + w0 * t, m);
    2.0 * (k * sn).asin()
}
