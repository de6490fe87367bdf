//! The `universal` (Hooke's) joint (docs/scene-format.md §5) against the classical relation
//! between the shaft angles and a 1-DOF Lagrange model derived by hand.
//!
//! `scenes/hooke_joint.json`: shaft 1 turns about X (hinged to the ground), shaft 2 about
//! `d = (cos β, sin β, 0)` (held at the cross and, at its far end, by a ball joint on a point
//! mass that slides along `d`, so no joint repeats another's rows); the cross joins them at the
//! origin with fork axis `a1 = y` on shaft 1 and `a2 = z` on shaft 2.
//! Angle convention: θ₁ is shaft 1's rotation about X from the position where its fork axis
//! lies in the plane of the two shafts; θ₂ is shaft 2's rotation about `d` (right-handed) from
//! the position where its fork axis is perpendicular to that plane. Both are the shafts'
//! Cardan φ (shaft 1: `R = Rx(θ₁)`; shaft 2: `R = Rz(β) Rx(θ₂)`). With
//! `A₁ = Rx(θ₁) ŷ = (0, cos θ₁, sin θ₁)` and `A₂ = Rot(d, θ₂) ẑ = cos θ₂ ẑ + sin θ₂ (d × ẑ)`,
//! `d × ẑ = (sin β, −cos β, 0)`, the cross's row `A₁·A₂ = 0` reads
//! `sin θ₁ cos θ₂ − cos β cos θ₁ sin θ₂ = 0`, i.e. **tan θ₂ = tan θ₁ / cos β**.
//!
//! Dynamics (no gravity; the shafts' centres lie on their axes): differentiating the relation,
//! `θ₂' = k(θ₁) θ₁'` with `k = cos β / (cos²β cos²θ₁ + sin²θ₁) = cos β / (1 − sin²β cos²θ₁)`
//! (the textbook `sin²θ₁` form measures θ₁ from the other fork position), so `T = ½ (J₁ + J₂ k²) θ₁'²` (J_i the shafts' moments about
//! their own axes) and Lagrange gives `(J₁ + J₂ k²) θ₁'' + J₂ k k' θ₁'² = 0`, with
//! `k' = −2 cos β sin²β sin θ₁ cos θ₁ / (1 − sin²β cos²θ₁)²` (the follower stays put). The
//! cross is the only joint that acts on shaft 2 about `d` (the ball joint at F, on the axis,
//! transmits a force only), so the cross's moment on
//! shaft 2 about its joint point (on the axis) has `M·d = J₂ θ₂'' = J₂ (k θ₁'' + k' θ₁'²)`.

mod common;
mod support;

use bondmech::{FormulationKind, Scene};
use common::integrate::integrate;

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/hooke_joint.json");

#[test]
fn hooke_joint_shaft_angles_obey_tan_theta2_equals_tan_theta1_over_cos_beta() {
    // the bundled scene's data, written out here
    let (beta, j1, j2, w1): (f64, f64, f64, f64) = (0.5, 0.002, 0.002, 3.0);
    let (sb, cb) = beta.sin_cos();
    let k = |t: f64| cb / (1.0 - sb * sb * t.cos().powi(2));
    let dk = |t: f64| {
        let den = 1.0 - sb * sb * t.cos().powi(2);
        -2.0 * cb * sb * sb * t.sin() * t.cos() / (den * den)
    };
    let accel = |t: f64, w: f64| -j2 * k(t) * dk(t) * w * w / (j1 + j2 * k(t) * k(t));
    // the bundled scene with the joints' reactions among its outputs
    let model = support::solve::model_with_reactions(SCENE);
    for (f, tol) in [
        (FormulationKind::Dae, 1e-7),
        (FormulationKind::Ggl, 1e-7),
        // the twin's springs (k = 1e8) hardly load: the shafts transmit a small torque
        (FormulationKind::Decoupled, 1e-5),
    ] {
        let sol = support::solve::solve_tight(&model, f);
        let reference = integrate(
            |_t, y, dy| {
                dy[0] = y[1];
                dy[1] = accel(y[0], y[1]);
            },
            0.0,
            &[0.0, w1],
            &sol.times,
            1e-13,
            1e-13,
        );
        let (mut worst_rel, mut worst_ref, mut worst_m): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for (i, y) in reference.iter().enumerate() {
            let v = |c: &str| sol.value(i, c).unwrap();
            let (t1, t2) = (v("shaft1.phi"), v("shaft2.phi"));
            // the relation, free of divisions, and on the same branch (θ₂ within a quarter
            // turn of θ₁)
            worst_rel = worst_rel.max((t1.sin() * t2.cos() - cb * t1.cos() * t2.sin()).abs());
            assert!((t2 - t1).abs() < 0.5, "{f:?}: θ₁ = {t1}, θ₂ = {t2}");
            // against the Lagrange model: θ₁ and θ₂ = atan(tan θ₁ / cos β) on θ₁'s branch
            let want2 = y[0] + ((y[0].tan() / cb).atan() - y[0].tan().atan());
            worst_ref = worst_ref.max((t1 - y[0]).abs()).max((t2 - want2).abs());
            if f != FormulationKind::Decoupled && i > 0 {
                let m = [v("cross.Mx"), v("cross.My"), v("cross.Mz")];
                let about_d = m[0] * cb + m[1] * sb;
                let want = j2 * (k(y[0]) * accel(y[0], y[1]) + dk(y[0]) * y[1] * y[1]);
                worst_m = worst_m.max((about_d - want).abs());
            }
        }
        assert!(
            sol.times.last().copied() == Some(3.0) && reference.last().unwrap()[0] > 6.0,
            "the shafts should turn more than a revolution"
        );
        assert!(
            worst_rel < tol,
            "{f:?}: tan relation residual {worst_rel:e}"
        );
        assert!(
            worst_ref < 10.0 * tol,
            "{f:?}: largest angle error against the Lagrange model {worst_ref:e} (summary {:?})",
            sol.summary
        );
        // the torque it carries is ~ J₂ k' θ₁'² ≈ 0.01 N·m
        assert!(
            worst_m < 1e-7,
            "{f:?}: cross moment about d, error {worst_m:e} N·m"
        );
    }
}

#[test]
fn universal_bad_input_is_refused_with_the_json_path() {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(SCENE).unwrap()).unwrap();
    for (what, key, value, path) in [
        (
            "zero fork axis",
            "axes",
            serde_json::json!([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            "joints[3].axes[0]",
        ),
        (
            "2D fork axis",
            "axes",
            serde_json::json!([[0.0, 1.0, 0.0], [0.0, 1.0]]),
            "joints[3].axes[1]",
        ),
        (
            "one axis",
            "axes",
            serde_json::json!([[0.0, 1.0, 0.0]]),
            "joints[3].axes",
        ),
        (
            "axis instead of axes",
            "axis",
            serde_json::json!([0.0, 1.0, 0.0]),
            "joints[3].axis",
        ),
        (
            "ground shaft",
            "bodies",
            serde_json::json!(["ground", "shaft2"]),
            "joints[3].bodies[0]",
        ),
        ("no axes", "axes", serde_json::Value::Null, "joints[3].axes"),
    ] {
        let mut v = support::solve::with_joint_field(&base, 3, key, value);
        if what == "ground shaft" {
            v["joints"][3]["points"] = serde_json::json!([[0.0, 0.0, 0.0], "U"]);
        }
        support::solve::assert_refused_at(&v, what, path);
    }
    // a universal joint in a planar scene: refused at its type
    let planar = r#"{"dimension": 2,
        "bodies": [{"name": "a", "mass": 1, "inertia": 1, "position": [0, 0]},
                   {"name": "b", "mass": 1, "inertia": 1, "position": [1, 0]}],
        "joints": [{"type": "universal", "bodies": ["a", "b"], "points": [[0, 0], [0, 0]],
                    "axes": [[0, 1, 0], [0, 0, 1]]}],
        "solve": {"t_end": 1}}"#;
    let err = Scene::from_json_str(planar)
        .expect_err("planar")
        .to_string();
    assert!(err.contains("joints[0].type"), "{err}");
}
