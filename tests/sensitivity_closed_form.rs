//! Forward sensitivities of a block on a prismatic joint held by a spring-damper to the
//! ground, `m x'' + c x' + k x = 0`, against the derivatives of the closed-form damped
//! oscillation `x(t) = x₀ e^{−at} (cos ωt + (a/ω) sin ωt)`, `a = c/2m`, `ω² = k/m − a²`,
//! differentiated by hand (no run of bondmech in the reference).

use bondmech::sensitivity::{sensitivity, SensitivityRequest};
use bondmech::Scene;

const M: f64 = 2.0;
const K: f64 = 50.0;
const C: f64 = 1.5;
const X0: f64 = 0.1;

fn block_scene(formulation: &str) -> Scene {
    let s = serde_json::json!({
        "name": "block",
        "dimension": 2,
        "gravity": [0.0, -9.81],
        "bodies": [{
            "name": "block", "mass": M, "inertia": 0.01,
            "points": {"c": [0.0, 0.0]},
            "position": [X0, 0.0], "angle": 0.0
        }],
        "joints": [{"name": "rail", "type": "prismatic", "bodies": ["ground", "block"],
                    "points": [[0.0, 0.0], "c"], "axis": [1.0, 0.0]}],
        "springs": [{"name": "s1", "bodies": ["ground", "block"], "points": [[0.0, 0.0], "c"],
                     "stiffness": K, "damping": C, "rest_length": 0.0}],
        "solve": {"formulation": formulation, "t_end": 3.0, "output_step": 0.01,
                  "rtol": 1e-10, "atol": 1e-12}
    });
    Scene::from_json_str(&s.to_string()).unwrap()
}

/// `(x, ∂x/∂k, ∂x/∂c, ∂x/∂m)` of the closed form at `t`.
fn closed_form(t: f64) -> [f64; 4] {
    let a = C / (2.0 * M);
    let w = (K / M - a * a).sqrt();
    let e = (-a * t).exp();
    let (s, co) = (w * t).sin_cos();
    let x = X0 * e * (co + a / w * s);
    let x_a = -t * x + X0 * e * s / w;
    let x_w = X0 * e * (-t * s - a / (w * w) * s + a / w * t * co);
    // a = c / 2m; w² = k/m − a²
    let (a_k, a_c, a_m) = (0.0, 1.0 / (2.0 * M), -C / (2.0 * M * M));
    let w_k = (1.0 / M - 2.0 * a * a_k) / (2.0 * w);
    let w_c = (-2.0 * a * a_c) / (2.0 * w);
    let w_m = (-K / (M * M) - 2.0 * a * a_m) / (2.0 * w);
    [
        x,
        x_a * a_k + x_w * w_k,
        x_a * a_c + x_w * w_c,
        x_a * a_m + x_w * w_m,
    ]
}

fn check(formulation: &str) {
    let scene = block_scene(formulation);
    let paths = [
        "springs[s1].stiffness",
        "springs[s1].damping",
        "bodies[block].mass",
    ];
    let s = sensitivity(&scene, &SensitivityRequest::new(&paths)).unwrap();
    let x = s.column("block.x").expect("the block's x column");
    for (i, t) in s.times.iter().enumerate() {
        assert!((x[i] - closed_form(*t)[0]).abs() < 1e-7, "x at t = {t}");
    }
    for (k, p) in paths.iter().enumerate() {
        let name = format!("d(block.x)/d({p})");
        let got = s
            .column(&name)
            .unwrap_or_else(|| panic!("no column {name}"));
        let want: Vec<f64> = s.times.iter().map(|&t| closed_form(t)[k + 1]).collect();
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        let err = got
            .iter()
            .zip(&want)
            .fold(0.0f64, |m, (g, w)| m.max((g - w).abs()));
        eprintln!(
            "{formulation} {name}: max error {err:.3e} of max {scale:.3e} ({:.2e} relative)",
            err / scale
        );
        assert!(
            err <= 1e-6 * scale,
            "{name}: error {err:.3e} > 1e-6 × {scale:.3e}"
        );
    }
}

/// `x(t)` is linear in the start: `∂x/∂x₀ = x(t)/x₀` and `∂x/∂v₀ = e^{−at} sin(ωt)/ω`.
#[test]
fn sensitivities_to_the_initial_position_and_velocity_match_the_closed_form() {
    let mut v: serde_json::Value =
        serde_json::from_str(&block_scene("dae").to_json_string()).unwrap();
    v["bodies"][0]["velocity"] = serde_json::json!([0.0, 0.0]);
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let paths = ["bodies[block].position[0]", "bodies[block].velocity[0]"];
    let s = sensitivity(&scene, &SensitivityRequest::new(&paths)).unwrap();
    let a = C / (2.0 * M);
    let w = (K / M - a * a).sqrt();
    let want = |k: usize, t: f64| match k {
        0 => closed_form(t)[0] / X0,
        _ => (-a * t).exp() * (w * t).sin() / w,
    };
    for (k, p) in paths.iter().enumerate() {
        let got = s.column(&format!("d(block.x)/d({p})")).unwrap();
        let scale = s.times.iter().fold(0.0f64, |m, &t| m.max(want(k, t).abs()));
        let err = s
            .times
            .iter()
            .zip(&got)
            .fold(0.0f64, |m, (&t, g)| m.max((g - want(k, t)).abs()));
        eprintln!("d(block.x)/d({p}): max error {err:.3e} of max {scale:.3e}");
        assert!(err <= 1e-6 * scale, "{p}: {err:.3e} > 1e-6 × {scale:.3e}");
    }
}

#[test]
fn sensitivities_to_stiffness_damping_and_mass_match_the_closed_form_dae() {
    check("dae");
}

#[test]
fn sensitivities_match_the_closed_form_index1() {
    check("index1");
}
