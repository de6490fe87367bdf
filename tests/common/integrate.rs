//! Adaptive explicit Runge–Kutta integrator: Dormand–Prince 5(4) ("DOPRI5",
//! Hairer, Nørsett & Wanner, *Solving ODEs I*, table II.5.2) with local
//! extrapolation (the 5th-order solution is propagated, the embedded 4th-order
//! one only estimates the error).
//!
//! For y' = f(t, y) one step of size h computes the seven stages
//! k_i = f(t + c_i h, y + h Σ_j a_ij k_j) and y_{n+1} = y_n + h Σ_i b_i k_i.
//! The error estimate is e = h Σ_i (b_i − b̂_i) k_i, measured in the weighted
//! RMS norm ‖e‖ = sqrt(mean((e_i / (atol + rtol·max(|y_n,i|, |y_{n+1},i|)))²));
//! a step is accepted when ‖e‖ ≤ 1 and the next step is
//! h·clamp(0.9·‖e‖^(−1/5), 0.2, 5). Steps are shortened to land exactly on each
//! requested output time (no interpolation), so the accuracy at the output
//! times is that of the integration itself. With rtol = atol = 1e-13 smooth
//! problems are reproduced to ~1e-12 relative.

/// Steps (accepted or rejected) after which integration gives up: a smooth
/// reference problem never needs this many, so reaching it means a bug.
const MAX_STEPS: usize = 2_000_000;

/// Dormand–Prince nodes c_i.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

/// Dormand–Prince coupling coefficients a_ij (row i, j < i); the 7th row
/// equals the weights B and is applied through them.
const A: [[f64; 6]; 6] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
];

/// 5th-order weights b_i (b_7 = 0: stage 7 is evaluated at y_{n+1}).
const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];

/// Error weights b_i − b̂_i (b̂: the embedded 4th-order weights).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Integrates y' = f(t, y) from (t0, y0) and returns y at each of `times`
/// (which must be non-decreasing and not earlier than `t0`).
///
/// `f(t, y, dydt)` writes the derivative into `dydt`. `rtol`/`atol` are the
/// relative/absolute local error tolerances of the weighted RMS norm.
///
/// # Panics
/// If `times` is not sorted or starts before `t0`, if the step size
/// underflows or more than `MAX_STEPS` steps are needed (the problem is not smooth); this is test support code, and a
/// panic with a message is the clearest failure there.
pub fn integrate(
    mut f: impl FnMut(f64, &[f64], &mut [f64]),
    t0: f64,
    y0: &[f64],
    times: &[f64],
    rtol: f64,
    atol: f64,
) -> Vec<Vec<f64>> {
    let n = y0.len();
    let mut t = t0;
    let mut y = y0.to_vec();
    let mut k: Vec<Vec<f64>> = vec![vec![0.0; n]; 7];
    let mut y_stage = vec![0.0; n];
    let mut y_new = vec![0.0; n];
    let mut out = Vec::with_capacity(times.len());
    let mut steps = 0usize;

    f(t, &y, &mut k[0]);
    let mut h = initial_step(&y, &k[0], rtol, atol);

    for &t_out in times {
        assert!(
            t_out >= t,
            "integrate: output time {t_out} precedes current time {t} (times must be sorted and >= t0)"
        );
        while t < t_out {
            steps += 1;
            assert!(
                steps <= MAX_STEPS,
                "integrate: more than {MAX_STEPS} steps before t = {t_out} (stuck at t = {t})"
            );
            let remaining = t_out - t;
            let landing = h >= remaining * (1.0 - 1e-12);
            let h_step = if landing { remaining } else { h };
            assert!(
                h_step > 1e-14 * t.abs().max(1.0),
                "integrate: step size underflow at t = {t} (h = {h_step})"
            );
            // Stages 2..6 (stage 1 is k[0] = f(t, y), kept from the last step).
            for s in 1..6 {
                combine(&y, h_step, &A[s], &k[..s], &mut y_stage);
                let (_, after) = k.split_at_mut(s);
                f(t + C[s] * h_step, &y_stage, &mut after[0]);
            }
            // 5th-order solution, then stage 7 at it (first-same-as-last).
            combine(&y, h_step, &B, &k[..6], &mut y_new);
            f(t + h_step, &y_new, &mut k[6]);
            let mut err_sq = 0.0;
            for i in 0..n {
                let mut e = 0.0;
                for (s, ks) in k.iter().enumerate() {
                    e += E[s] * ks[i];
                }
                let scale = atol + rtol * y[i].abs().max(y_new[i].abs());
                err_sq += (h_step * e / scale).powi(2);
            }
            let err = (err_sq / n.max(1) as f64).sqrt();
            let factor = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            if err <= 1.0 {
                t = if landing { t_out } else { t + h_step };
                y.copy_from_slice(&y_new);
                let (first, rest) = k.split_at_mut(1);
                first[0].copy_from_slice(&rest[5]);
                // A step shortened to land on an output time says little about
                // the size the next one may take: never shrink h because of it.
                h = if landing {
                    h.max(h_step * factor)
                } else {
                    h_step * factor
                };
            } else {
                h = h_step * factor;
            }
        }
        out.push(y.clone());
    }
    out
}

/// out = y + h Σ_j w_j k_j.
fn combine(y: &[f64], h: f64, w: &[f64], k: &[Vec<f64>], out: &mut [f64]) {
    for (i, o) in out.iter_mut().enumerate() {
        let acc: f64 = k.iter().zip(w).map(|(kj, wj)| wj * kj[i]).sum();
        *o = y[i] + h * acc;
    }
}

/// First step guess: a small fraction of the scale on which y changes,
/// ~0.01·‖y‖/‖y'‖ in the weighted norm, capped to (1e-6, 1e-2) of that scale
/// by the tolerance; the step controller corrects it within a few steps.
fn initial_step(y: &[f64], dydt: &[f64], rtol: f64, atol: f64) -> f64 {
    let n = y.len().max(1) as f64;
    let mut dy = 0.0;
    let mut f = 0.0;
    for (yi, fi) in y.iter().zip(dydt) {
        let scale = atol + rtol * yi.abs();
        dy += (yi / scale).powi(2);
        f += (fi / scale).powi(2);
    }
    let (dy, f) = ((dy / n).sqrt(), (f / n).sqrt());
    if dy < 1e-5 || f < 1e-5 {
        1e-6
    } else {
        (0.01 * dy / f).min(1e-2)
    }
}
