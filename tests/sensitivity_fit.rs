//! `fit` recovers parameters from measurement-like data made without bondmech: the closed-form
//! damped oscillation of a block on a spring-damper, and a damped compound pendulum integrated
//! by a classical Runge–Kutta written here; Gaussian noise from a seeded generator.

use bondmech::sensitivity::{fit, FitData, FitRequest};
use bondmech::Scene;

/// SplitMix64 and Box–Muller: reproducible standard normal samples.
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn sample(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

const SIGMA: f64 = 1e-4;

fn block_scene(k: f64, c: f64) -> Scene {
    let s = serde_json::json!({
        "name": "block", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [{"name": "block", "mass": 2.0, "inertia": 0.01, "points": {"c": [0.0, 0.0]},
                    "position": [0.1, 0.0], "angle": 0.0}],
        "joints": [{"name": "rail", "type": "prismatic", "bodies": ["ground", "block"],
                    "points": [[0.0, 0.0], "c"], "axis": [1.0, 0.0]}],
        "springs": [{"name": "s1", "bodies": ["ground", "block"], "points": [[0.0, 0.0], "c"],
                     "stiffness": k, "damping": c, "rest_length": 0.0}],
        "solve": {"t_end": 3.0, "output_step": 0.01, "rtol": 1e-9, "atol": 1e-11}
    });
    Scene::from_json_str(&s.to_string()).unwrap()
}

#[test]
fn fit_recovers_stiffness_and_damping_from_noisy_closed_form_data() {
    let (m, k, c, x0): (f64, f64, f64, f64) = (2.0, 50.0, 1.5, 0.1);
    let a = c / (2.0 * m);
    let w = (k / m - a * a).sqrt();
    let mut noise = Normal(49);
    let rows: Vec<Vec<f64>> = (1..=150)
        .map(|i| {
            let t = 0.02 * i as f64;
            let x = x0 * (-a * t).exp() * ((w * t).cos() + a / w * (w * t).sin());
            vec![t, x + SIGMA * noise.sample()]
        })
        .collect();
    let data = FitData::from_table(vec!["t".into(), "block.x".into()], rows).unwrap();
    // 20 % off
    let scene = block_scene(1.2 * k, 1.2 * c);
    let req = FitRequest {
        params: vec!["springs[s1].stiffness".into(), "springs[s1].damping".into()],
        columns: None,
        max_iterations: None,
    };
    let r = fit(&scene, &data, &req).unwrap();
    eprintln!("{}", r.table());
    assert!(r.converged, "{}", r.reason);
    for (i, truth) in [k, c].into_iter().enumerate() {
        let (v, se) = (r.values[i], r.std_errors[i]);
        let rel = (v - truth).abs() / truth;
        assert!(rel < 5e-3, "{}: {v} vs {truth} ({rel:.2e})", r.paths[i]);
        assert!(
            se > 0.0 && (v - truth).abs() < 3.0 * se,
            "{}: |{v} − {truth}| ≥ 3 × {se:.3e}",
            r.paths[i]
        );
    }
    // the residual is the noise
    assert!(
        (r.residual_rms / SIGMA - 1.0).abs() < 0.2,
        "rms {}",
        r.residual_rms
    );
    let j = r.to_json();
    assert_eq!(j["converged"], true);
    assert!(j["parameters"]["springs[s1].stiffness"].is_number());
    assert_eq!(j["covariance"].as_array().unwrap().len(), 2);
}

/// A bar pendulum hanging from the pivot at the origin by its point O = (−L, 0), its centre of
/// mass at distance L, started hanging straight down with angular velocity ω₀; a
/// spring-damper of rest length 0 from the pivot to the centre of mass damps it with the
/// torque `−c L² φ'` (its spring force is radial: no torque).
fn pendulum_scene(l: f64, c: f64) -> Scene {
    let s = serde_json::json!({
        "name": "swing", "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [{"name": "bar", "mass": 1.0, "inertia": 1.0 / 12.0,
                    "points": {"O": [-l, 0.0], "c": [0.0, 0.0]},
                    "position": [0.0, -l], "angle": -std::f64::consts::FRAC_PI_2,
                    "angular_velocity": 3.0}],
        "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0.0, 0.0], "O"]}],
        "springs": [{"name": "drag", "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "c"],
                     "stiffness": 1.0, "damping": c, "rest_length": 0.0}],
        "solve": {"t_end": 4.0, "output_step": 0.05, "rtol": 1e-9, "atol": 1e-11}
    });
    Scene::from_json_str(&s.to_string()).unwrap()
}

/// `(I + m L²) φ'' = −m g L cos φ − c L² φ'` by RK4 with 1e-4 s steps, sampled every 0.05 s.
fn swing(l: f64, c: f64) -> Vec<(f64, f64)> {
    let (m, g, i) = (1.0, 9.81, 1.0 / 12.0);
    let j = i + m * l * l;
    let f = |phi: f64, w: f64| (w, (-m * g * l * phi.cos() - c * l * l * w) / j);
    let (mut phi, mut w) = (-std::f64::consts::FRAC_PI_2, 3.0);
    let h = 1e-4;
    let mut out = Vec::new();
    for step in 1..=40_000 {
        let (k1p, k1w) = f(phi, w);
        let (k2p, k2w) = f(phi + 0.5 * h * k1p, w + 0.5 * h * k1w);
        let (k3p, k3w) = f(phi + 0.5 * h * k2p, w + 0.5 * h * k2w);
        let (k4p, k4w) = f(phi + h * k3p, w + h * k3w);
        phi += h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
        w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
        if step % 500 == 0 {
            out.push((step as f64 * h, phi));
        }
    }
    out
}

#[test]
fn fit_recovers_a_pendulums_length_and_damping_from_a_swing() {
    let (l, c) = (0.5, 0.3);
    let mut noise = Normal(7);
    let rows: Vec<Vec<f64>> = swing(l, c)
        .into_iter()
        .map(|(t, phi)| vec![t, phi + SIGMA * noise.sample()])
        .collect();
    let data = FitData::from_table(vec!["t".into(), "bar.angle".into()], rows).unwrap();
    let scene = pendulum_scene(0.8 * l, 1.2 * c);
    let req = FitRequest {
        params: vec![
            "bodies[bar].points.O[0]".into(),
            "springs[drag].damping".into(),
        ],
        columns: Some(vec!["bar.angle".into()]),
        max_iterations: None,
    };
    let r = fit(&scene, &data, &req).unwrap();
    eprintln!("{}", r.table());
    assert!(r.converged, "{}", r.reason);
    for (i, truth) in [-l, c].into_iter().enumerate() {
        let (v, se) = (r.values[i], r.std_errors[i]);
        assert!(
            (v - truth).abs() < 5e-3 * truth.abs(),
            "{}: {v} vs {truth}",
            r.paths[i]
        );
        assert!(
            (v - truth).abs() < 3.0 * se,
            "{}: |{v} − {truth}| ≥ 3 × {se:.3e}",
            r.paths[i]
        );
    }
}
