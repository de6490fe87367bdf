//! The `gear` joint (docs/scene-format.md §5) against its exact solution: two gears on axles
//! pinned to the ground, meshed with ratio r (θ_b − θ_b(0) = −r (θ_a − θ_a(0))), gear a driven
//! from rest by a constant torque τ. With ω_b = −r ω_a the kinetic energy is
//! ½ (J_a + r² J_b) ω_a², and the power balance τ ω_a = d/dt T gives the constant angular
//! acceleration α_a = τ / (J_a + r² J_b) (the pins do no work), so θ_a = ½ α_a t² and
//! θ_b = −r θ_a exactly. The mesh's moment on gear b is J_b α_b = −r J_b α_a, with no force.

mod support;

use bondmech::{FormulationKind, Model, Scene};

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/gear_train.json");

fn parameters() -> (f64, f64, f64, f64) {
    // the bundled scene's J_a, J_b, r, τ (read from the file, checked here by hand)
    (0.02, 0.08, 0.5, 0.5)
}

#[test]
fn gear_train_under_constant_torque_accelerates_at_tau_over_ja_plus_r2_jb() {
    let (ja, jb, r, tau) = parameters();
    let alpha = tau / (ja + r * r * jb);
    assert_eq!(alpha, 12.5);
    let scene = Scene::from_path(SCENE).unwrap();
    let model = Model::new(&scene).unwrap();
    for (f, tol) in [
        (FormulationKind::Dae, 1e-7),
        (FormulationKind::Ggl, 1e-7),
        // the twin's torsional mesh spring (k = 1e8 N·m/rad) deflects by ~ r J_b α / k
        (FormulationKind::Decoupled, 1e-5),
    ] {
        let sol = support::solve::solve_tight(&model, f);
        let mut worst: f64 = 0.0;
        for (k, &t) in sol.times.iter().enumerate() {
            let want_a = 0.5 * alpha * t * t;
            let a = sol.value(k, "a.angle").unwrap();
            let b = sol.value(k, "b.angle").unwrap();
            // relative to the largest angle reached (25 rad)
            worst = worst.max((a - want_a).abs()).max((b + r * want_a).abs());
            if f != FormulationKind::Decoupled && k > 0 {
                let mz = sol.value(k, "mesh.Mz").unwrap();
                assert!(
                    (mz + r * jb * alpha).abs() < 1e-6,
                    "{f:?}, t = {t}: mesh.Mz = {mz}, expected −r J_b α_a = {}",
                    -r * jb * alpha
                );
                for c in ["mesh.Fx", "mesh.Fy"] {
                    let v = sol.value(k, c).unwrap();
                    assert!(v.abs() < 1e-9, "{f:?}, t = {t}: {c} = {v}");
                }
            }
        }
        assert!(
            worst < tol * 25.0,
            "{f:?}: largest angle error {worst:e} rad (summary {:?})",
            sol.summary
        );
    }
}

#[test]
fn gear_bad_input_is_refused_with_the_json_path() {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(SCENE).unwrap()).unwrap();
    let cases: [(&str, serde_json::Value, &str); 5] = [
        (
            "zero ratio",
            serde_json::json!({"ratio": 0.0}),
            "joints[2].ratio",
        ),
        (
            "ground as a gear",
            serde_json::json!({"bodies": ["ground", "b"]}),
            "joints[2].bodies[0]",
        ),
        (
            "ground as the other gear",
            serde_json::json!({"bodies": ["a", "ground"]}),
            "joints[2].bodies[1]",
        ),
        (
            "points on a gear",
            serde_json::json!({"points": [[0.0, 0.0], [0.0, 0.0]]}),
            "joints[2].points",
        ),
        ("a ratio on a pin", serde_json::json!({}), "joints[0].ratio"),
    ];
    for (what, patch, path) in cases {
        let mut v = base.clone();
        if what == "a ratio on a pin" {
            v["joints"][0]["ratio"] = serde_json::json!(2.0);
        }
        for (k, x) in patch.as_object().unwrap() {
            v["joints"][2][k] = x.clone();
        }
        support::solve::assert_refused_at(&v, what, path);
    }
    // a gear in a spatial scene: refused at its type
    let spatial = r#"{"dimension": 3,
        "bodies": [{"name": "a", "mass": 1, "inertia": [1, 1, 1], "position": [0, 0, 0]},
                   {"name": "b", "mass": 1, "inertia": [1, 1, 1], "position": [1, 0, 0]}],
        "joints": [{"type": "spherical", "bodies": ["ground", "a"], "points": [[0, 0, 0], [0, 0, 0]]},
                   {"type": "spherical", "bodies": ["ground", "b"], "points": [[1, 0, 0], [0, 0, 0]]},
                   {"type": "gear", "bodies": ["a", "b"], "ratio": 2}],
        "solve": {"t_end": 1}}"#;
    let err = Scene::from_json_str(spatial)
        .expect_err("spatial")
        .to_string();
    assert!(err.contains("joints[2].type"), "{err}");
    // a missing ratio
    let mut v = base;
    v["joints"][2].as_object_mut().unwrap().remove("ratio");
    let err = Scene::from_json_str(&v.to_string())
        .expect_err("no ratio")
        .to_string();
    assert!(err.contains("joints[2].ratio"), "{err}");
}
