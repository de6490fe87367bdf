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
