//! The `rack_pinion` joint (docs/scene-format.md §5) against a 1-DOF Lagrange model derived by
//! hand, integrated by `tests/common/integrate.rs`.
//!
//! The bundled `scenes/rack_pinion.json`: a pinion of mass `m_p` and inertia `J_c` about its
//! centre of mass, which sits a distance `e` from its axle C (pinned to the ground at the
//! origin; the centre of mass at angle θ from X); pitch radius ρ; a vertical rack of mass `m_r`
//! on its right (axis +Y, the pinion on the rack's left) sliding on a vertical guide. The
//! mesh gives `y_r − y_r(0) = ρ (θ − θ(0))`. In the one coordinate θ:
//!
//! `T = ½ (J_c + m_p e² + m_r ρ²) θ'²`, `V = m_p g e sin θ + m_r g ρ θ`,
//!
//! so `(J_c + m_p e² + m_r ρ²) θ'' = −m_p g e cos θ − m_r g ρ`. The rack's Newton along Y,
//! `m_r ρ θ'' = F_y − m_r g`, gives the tooth force on the rack, `F_y = m_r (ρ θ'' + g)`; the
//! mesh pushes the rack along its axis only (`F_x = 0`).

mod common;
mod support;

use bondmech::{FormulationKind, Scene};
use common::integrate::integrate;

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/rack_pinion.json");
const G: f64 = 9.81;

#[test]
fn rack_and_pinion_under_gravity_matches_the_one_dof_lagrange_model() {
    // the bundled scene's data, written out here
    let (m_p, j_c, e, rho, m_r) = (0.8, 0.004, 0.02, 0.05, 0.3);
    let j = j_c + m_p * e * e + m_r * rho * rho;
    let theta_ddot = |th: f64| (-m_p * G * e * th.cos() - m_r * G * rho) / j;
    // the bundled scene with the joints' reactions among its outputs
    let model = support::solve::model_with_reactions(SCENE);
    for (f, tol) in [
        (FormulationKind::Dae, 1e-7),
        (FormulationKind::Ggl, 1e-7),
        // the twin's mesh and guide springs (k = 1e8) yield by ~ F / k
        (FormulationKind::Decoupled, 1e-5),
    ] {
        let sol = support::solve::solve_tight(&model, f);
        let reference = integrate(
            |_t, y, dy| {
                dy[0] = y[1];
                dy[1] = theta_ddot(y[0]);
            },
            0.0,
            &[0.0, 0.0],
            &sol.times,
            1e-13,
            1e-13,
        );
        let (mut worst, mut worst_force): (f64, f64) = (0.0, 0.0);
        for (k, y) in reference.iter().enumerate() {
            let v = |c: &str| sol.value(k, c).unwrap();
            worst = worst
                .max((v("pinion.angle") - y[0]).abs())
                .max((v("rack.y") - rho * y[0]).abs() / rho);
            if f != FormulationKind::Decoupled && k > 0 {
                let fy = m_r * (rho * theta_ddot(y[0]) + G);
                worst_force = worst_force
                    .max((v("mesh.Fy") - fy).abs())
                    .max(v("mesh.Fx").abs());
            }
        }
        // the pinion turns through about 9 rad in the second
        assert!(
            reference.last().unwrap()[0] < -5.0,
            "the reference should turn the pinion"
        );
        assert!(
            worst < tol * 10.0,
            "{f:?}: largest angle error {worst:e} rad (summary {:?})",
            sol.summary
        );
        assert!(
            worst_force < 1e-5,
            "{f:?}: largest tooth force error {worst_force:e} N"
        );
    }
}

#[test]
fn rack_pinion_bad_input_is_refused_with_the_json_path() {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(SCENE).unwrap()).unwrap();
    for (what, key, value, path) in [
        (
            "zero radius",
            "radius",
            serde_json::json!(0.0),
            "joints[2].radius",
        ),
        (
            "negative radius",
            "radius",
            serde_json::json!(-0.05),
            "joints[2].radius",
        ),
        (
            "zero axis",
            "axis",
            serde_json::json!([0.0, 0.0]),
            "joints[2].axis",
        ),
        (
            "3D axis",
            "axis",
            serde_json::json!([0.0, 1.0, 0.0]),
            "joints[2].axis",
        ),
        (
            "ground pinion",
            "bodies",
            serde_json::json!(["ground", "rack"]),
            "joints[2].bodies[0]",
        ),
        (
            "no radius",
            "radius",
            serde_json::Value::Null,
            "joints[2].radius",
        ),
        ("no axis", "axis", serde_json::Value::Null, "joints[2].axis"),
    ] {
        let mut v = support::solve::with_joint_field(&base, 2, key, value);
        if what == "ground pinion" {
            v["joints"][2]["points"] = serde_json::json!([[0.0, 0.0], "P"]);
        }
        support::solve::assert_refused_at(&v, what, path);
    }
    let mut v = base;
    v["joints"][0]["radius"] = serde_json::json!(1.0);
    let err = Scene::from_json_str(&v.to_string())
        .expect_err("radius on a pin")
        .to_string();
    assert!(err.contains("joints[0].radius"), "{err}");
}
