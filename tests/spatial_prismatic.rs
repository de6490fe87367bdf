//! Spatial prismatic joints against the closed form of a block on a tilted frictionless rail:
//! the rail direction `u` descends at angle α, so along the rail `s(t) = v₀ t + ½ g sin α t²`, the
//! centre moves as `c(t) = c₀ + s(t) u` and the attitude never changes.

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::rigid_body::cardan_matrix;
use nalgebra::Vector3;

const G: f64 = 9.81;

#[test]
fn block_on_tilted_frictionless_rail_follows_closed_form() {
    let (alpha, beta): (f64, f64) = (0.5, 0.8);
    let u = Vector3::new(
        alpha.cos() * beta.cos(),
        alpha.cos() * beta.sin(),
        -alpha.sin(),
    );
    let (psi, theta, phi) = (0.4, 0.2, -0.3);
    let rot = cardan_matrix(psi, theta, phi);
    let s_pt = Vector3::new(0.1, -0.05, 0.2); // the sliding point, body coordinates
    let p0 = Vector3::new(1.0, 0.5, 2.0); // a point of the rail
    let v0 = 0.3;
    let ub = rot.transpose() * u; // rail direction in the block frame
    let cases = [
        (
            "block, ground first",
            "[0.1,0.2,0.25]",
            rot * s_pt,
            format!(
                r#"{{"name":"rail","type":"prismatic","bodies":["ground","block"],"points":[[{},{},{}],"S"],"axis":[{},{},{}]}}"#,
                p0.x, p0.y, p0.z, u.x, u.y, u.z
            ),
        ),
        (
            "block, block first",
            "[0.1,0.2,0.25]",
            rot * s_pt,
            format!(
                r#"{{"name":"rail","type":"prismatic","bodies":["block","ground"],"points":["S",[{},{},{}]],"axis":[{},{},{}]}}"#,
                p0.x, p0.y, p0.z, ub.x, ub.y, ub.z
            ),
        ),
        (
            "point-mass bead",
            "[0,0,0]",
            Vector3::zeros(),
            format!(
                r#"{{"name":"rail","type":"prismatic","bodies":["ground","block"],"points":[[{},{},{}],"C"],"axis":[{},{},{}]}}"#,
                p0.x, p0.y, p0.z, u.x, u.y, u.z
            ),
        ),
    ];
    for (label, inertia, offset, joint) in cases {
        let c0 = p0 - offset;
        let cardan = if inertia == "[0,0,0]" {
            "[0,0,0]".to_string()
        } else {
            format!("[{psi},{theta},{phi}]")
        };
        let json = format!(
            r#"{{"name":"rail","dimension":3,"gravity":[0,0,-{G}],
            "bodies":[{{"name":"block","mass":2,"inertia":{inertia},
                "points":{{"S":[{},{},{}],"C":[0,0,0]}},"position":[{},{},{}],"cardan":{cardan},
                "velocity":[{},{},{}]}}],
            "joints":[{joint}],
            "solve":{{"t_end":1.5,"output_step":0.1}},"outputs":["energy"]}}"#,
            s_pt.x,
            s_pt.y,
            s_pt.z,
            c0.x,
            c0.y,
            c0.z,
            v0 * u.x,
            v0 * u.y,
            v0 * u.z,
        );
        let scene = Scene::from_json_str(&json).expect("scene");
        let model = Model::new(&scene).expect("model");
        let mut o = model.default_options();
        o.formulation = FormulationKind::Ggl;
        o.rtol = 1e-10;
        o.atol = 1e-12;
        let sol = model.solve(&o).expect("solve");
        assert!(
            sol.summary.max_constraint_error < 1e-9,
            "{label}: {:?}",
            sol.summary
        );
        for (k, &t) in sol.times.iter().enumerate() {
            let s = v0 * t + 0.5 * G * alpha.sin() * t * t;
            let want = c0 + u * s;
            let v = |n: &str| sol.value(k, &format!("block.{n}")).unwrap();
            let got = Vector3::new(v("x"), v("y"), v("z"));
            assert!(
                (got - want).norm() < 1e-7,
                "{label}, t = {t}: {got} vs closed form {want}"
            );
            if inertia != "[0,0,0]" {
                for (n, a0) in [("psi", psi), ("theta", theta), ("phi", phi)] {
                    assert!((v(n) - a0).abs() < 1e-8, "{label}, t = {t}: {n} = {}", v(n));
                }
            }
        }
        // it really slid: more than a metre in 1.5 s
        let k = sol.times.len() - 1;
        assert!((sol.value(k, "block.z").unwrap() - c0.z).abs() > 1.0);
    }
}

#[test]
fn prismatic_with_a_point_mass_first_is_refused_naming_the_body() {
    let json = r#"{"name":"x","dimension":3,"gravity":[0,0,-9.81],
      "bodies":[{"name":"bead","mass":1,"inertia":[0,0,0],"points":{"C":[0,0,0]},"position":[0,0,-1]}],
      "joints":[{"name":"rail","type":"prismatic","axis":[1,0,0],"bodies":["bead","ground"],"points":["C",[0,0,-1]]}],
      "solve":{"t_end":1,"output_step":0.1}}"#;
    let scene = Scene::from_json_str(json).expect("valid scene");
    let err = Model::new(&scene).unwrap_err().to_string();
    assert!(err.contains("joints[0].bodies[0]"), "{err}");
}

/// A bead (point mass) sliding freely on a horizontal arm that turns about a vertical hinge:
/// a prismatic joint between two moving bodies. Conserved: the energy and the angular momentum
/// about the hinge axis `J_z ω + m (x v_y − y v_x)`; the bead stays on the arm's line, and as it
/// slides out the arm slows down (hand check: ω(t) = L / (J_z + m ρ²), ρ its distance to the
/// axis).
#[test]
fn bead_sliding_on_a_turning_arm_conserves_energy_and_angular_momentum() {
    let (ma, la, mb) = (2.0, 1.0, 0.5);
    let jz = ma * la * la / 12.0;
    let (w0, rho0, u0) = (2.0, 0.2, 0.1);
    // arm: centre at the origin on the Z hinge, along body x; bead at (ρ0, 0, 0) moving
    // outward at u0 and with the arm's rotation
    let json = format!(
        r#"{{"name":"bead_on_arm","dimension":3,"gravity":[0,0,-{}],
        "bodies":[
          {{"name":"arm","mass":{ma},"inertia":[0.01,{jz},{jz}],"points":{{"C":[0,0,0]}},
            "angular_velocity":[0,0,{w0}]}},
          {{"name":"bead","mass":{mb},"inertia":[0,0,0],"points":{{"C":[0,0,0]}},
            "position":[{rho0},0,0],"velocity":[{u0},{},0]}}],
        "joints":[
          {{"name":"hinge","type":"revolute","bodies":["ground","arm"],"points":[[0,0,0],"C"],"axis":[0,0,1]}},
          {{"name":"rail","type":"prismatic","bodies":["arm","bead"],"points":["C","C"],"axis":[1,0,0]}}],
        "solve":{{"t_end":2.0,"output_step":0.05}},"outputs":["energy"]}}"#,
        G,
        w0 * rho0
    );
    let scene = Scene::from_json_str(&json).expect("scene");
    let model = Model::new(&scene).expect("model");
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let sol = model.solve(&o).expect("solve");
    assert!(sol.summary.max_constraint_error < 1e-9, "{:?}", sol.summary);
    let l0 = (jz + mb * rho0 * rho0) * w0;
    let e = sol.column("energy").unwrap();
    for (k, &ek) in e.iter().enumerate() {
        let v = |n: &str| sol.value(k, n).unwrap();
        let (x, y) = (v("bead.x"), v("bead.y"));
        let wz = v("arm.wZ");
        let lz = jz * wz + mb * (x * v("bead.vy") - y * v("bead.vx"));
        assert!((lz - l0).abs() < 1e-8 * l0, "L_z at {k}: {lz} vs {l0}");
        assert!(
            (ek - e[0]).abs() < 1e-8 * e[0].abs().max(1.0),
            "energy at {k}"
        );
        let rho = x.hypot(y);
        assert!(
            (wz - l0 / (jz + mb * rho * rho)).abs() < 1e-8,
            "ω at {k}: {wz}"
        );
        // on the arm's line: perpendicular to the arm direction (cos ψ, sin ψ)
        let psi = v("arm.psi");
        assert!(
            (-psi.sin() * x + psi.cos() * y).abs() < 1e-9,
            "off the arm at {k}"
        );
        assert!(v("bead.z").abs() < 1e-9);
    }
    let k = e.len() - 1;
    let rho_end = sol
        .value(k, "bead.x")
        .unwrap()
        .hypot(sol.value(k, "bead.y").unwrap());
    assert!(rho_end > 0.5, "the bead must slide out (ρ = {rho_end})");
}
