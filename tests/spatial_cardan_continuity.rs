//! Cardan angles are outputs that must stay continuous (scene contract): a body tumbling about
//! its y axis passes θ = ±π/2, where (ψ, θ, φ) and (ψ + π, π − θ, φ + π) are the same attitude.
//! Reference: torque-free rotation about a principal axis, R(t) = Ry(ω t), so ψ = φ = 0 and
//! θ = ω t exactly (Euler's equations with ω along a principal axis keep ω constant).

use bondmech::{Model, Scene};

#[test]
fn cardan_angles_stay_continuous_through_theta_half_pi() {
    check_tumble(None);
}

#[test]
fn partitioned_cardan_angles_stay_continuous_through_theta_half_pi() {
    check_tumble(Some(bondmech::FormulationKind::Partitioned));
}

fn check_tumble(formulation: Option<bondmech::FormulationKind>) {
    let json = r#"{"name":"tumble","dimension":3,"gravity":[0,0,0],
      "bodies":[{"name":"b","mass":1,"inertia":[0.1,0.2,0.3],"position":[0,0,0],
                 "cardan":[0,0,0],"angular_velocity":[0,2,0]}],
      "solve":{"t_end":4,"output_step":0.01,"rtol":1e-10,"atol":1e-12}}"#;
    let m = Model::new(&Scene::from_json_str(json).unwrap()).unwrap();
    let mut o = m.default_options();
    if let Some(f) = formulation {
        o.formulation = f;
    }
    let s = m.solve(&o).unwrap();
    // 4 s at 2 rad/s: θ runs to 8 rad, through π/2, 3π/2 and 5π/2
    for (k, &t) in s.times.iter().enumerate() {
        let (psi, theta, phi) = (
            s.value(k, "b.psi").unwrap(),
            s.value(k, "b.theta").unwrap(),
            s.value(k, "b.phi").unwrap(),
        );
        assert!(
            psi.abs() < 1e-6 && phi.abs() < 1e-6 && (theta - 2.0 * t).abs() < 1e-6,
            "t = {t}: (ψ, θ, φ) = ({psi}, {theta}, {phi}), expected (0, {}, 0)",
            2.0 * t
        );
    }
}
