//! The `slot` joint (docs/scene-format.md §5) against an independent reference: a bead in a
//! slot along a swinging bar, the Lagrange model in polar coordinates of
//! `tests/common/bead_in_slot.rs` integrated by `tests/common/integrate.rs`. Checked: the bar's
//! angle, the bead's position `r (cos θ, sin θ)`, energy conservation, and the slot's reaction
//! on the bead (normal to the bar, `m (r θ'' + 2 r' θ' + g cos θ)` along `e_θ`, none along it).

mod common;
mod support;

use bondmech::FormulationKind;
use common::bead_in_slot::BeadInSlot;

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/bead_in_slot.json");

#[test]
fn bead_in_a_slot_on_a_swinging_bar_matches_the_polar_lagrange_model() {
    // the bundled scene's bar, bead and start, written out here
    let model_ref = BeadInSlot {
        bar_mass: 1.0,
        length: 1.0,
        bead_mass: 0.5,
        g: 9.81,
    };
    // the bundled scene with the joints' reactions among its outputs
    let model = support::solve::model_with_reactions(SCENE);
    for (f, tol) in [
        (FormulationKind::Dae, 1e-7),
        (FormulationKind::Ggl, 1e-7),
        // the twin's slot spring (k = 1e8 N/m) yields by ~ N / k
        (FormulationKind::Decoupled, 1e-5),
    ] {
        let sol = support::solve::solve_tight(&model, f);
        let reference = model_ref.simulate([0.0, 0.0, 0.3, 0.0], &sol.times);
        let e = sol.column("energy").unwrap();
        let (mut worst, mut worst_force): (f64, f64) = (0.0, 0.0);
        for (k, y) in reference.iter().enumerate() {
            let v = |c: &str| sol.value(k, c).unwrap();
            let (s, c) = y.theta.sin_cos();
            worst = worst
                .max((v("bar.angle") - y.theta).abs())
                .max((v("bead.x") - y.r * c).abs())
                .max((v("bead.y") - y.r * s).abs());
            assert!(
                (e[k] - e[0]).abs() < 1e-6,
                "{f:?}: energy {} vs {} at t = {}",
                e[k],
                e[0],
                sol.times[k]
            );
            if f != FormulationKind::Decoupled && k > 0 {
                let (fx, fy) = (v("slot.Fx"), v("slot.Fy"));
                let normal = model_ref.bead_mass
                    * (y.r * y.theta_ddot + 2.0 * y.r_dot * y.theta_dot + model_ref.g * c);
                worst_force = worst_force
                    .max((-fx * s + fy * c - normal).abs())
                    .max((fx * c + fy * s).abs());
            }
        }
        assert!(
            worst < tol,
            "{f:?}: largest position error {worst:e} (summary {:?})",
            sol.summary
        );
        assert!(
            worst_force < 1e-5,
            "{f:?}: largest slot force error {worst_force:e} N"
        );
    }
}

#[test]
fn slot_bad_input_is_refused_with_the_json_path() {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(SCENE).unwrap()).unwrap();
    for (what, axis, path) in [
        ("zero axis", serde_json::json!([0.0, 0.0]), "joints[1].axis"),
        (
            "3D axis in a plane",
            serde_json::json!([1.0, 0.0, 0.0]),
            "joints[1].axis",
        ),
        ("no axis", serde_json::Value::Null, "joints[1].axis"),
    ] {
        let v = support::solve::with_joint_field(&base, 1, "axis", axis);
        support::solve::assert_refused_at(&v, what, path);
    }
}
