//! Spatial revolute joints (hinges, `"type": "revolute"` with an `axis` in a 3D scene) against
//! independent references:
//!
//! * a compound pendulum of a general rigid body (principal axes not aligned with the hinge)
//!   hinged to ground about a horizontal axis: a 1-DOF model derived by hand below and integrated
//!   by `tests/common`'s Dormand–Prince integrator;
//! * a double pendulum of two bars on two parallel hinges, moving in the vertical X–Z plane:
//!   the planar double pendulum of `tests/common/double_pendulum.rs`, mapped into 3D.

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};
use common::integrate::integrate;
use common::rigid_body::cardan_matrix;
use nalgebra::{Matrix3, Vector3};

const G: f64 = 9.81;

/// Rodrigues: rotation of `r` by angle `phi` about the unit axis `a`.
fn rotate(a: &Vector3<f64>, phi: f64, r: &Vector3<f64>) -> Vector3<f64> {
    let (s, c) = phi.sin_cos();
    r * c + a.cross(r) * s + a * (a.dot(r) * (1.0 - c))
}

/// Compound pendulum hinged to ground at the origin about the horizontal unit axis `â`.
///
/// Hand derivation (1 DOF, the rotation angle φ about `â` from the initial configuration):
/// the centre is `r(φ) = Rot(â, φ) r₀`; only the part `r⊥ = r₀ − (r₀·â) â` turns, so
/// `z(φ) = cos φ r⊥_z + sin φ (â × r⊥)_z` (â horizontal: the parallel part has no height).
/// `T = ½ I φ'²` with `I = m |r⊥|² + nᵀ J n` (parallel axes; `n = R₀ᵀ â` the hinge axis in the
/// principal frame), `V = m g z(φ)`, so `I φ'' = −m g (−sin φ r⊥_z + cos φ (â × r⊥)_z)`.
#[test]
fn hinged_compound_pendulum_matches_one_dof_reference_for_both_joint_orders() {
    let m = 1.5;
    let jp = [0.02, 0.05, 0.06];
    let (psi, theta, phi) = (0.3, -0.2, 0.5);
    let r0m = cardan_matrix(psi, theta, phi);
    let s_o = Vector3::new(-0.4, 0.1, 0.05); // hinge point in body coordinates
    let beta: f64 = 0.7;
    let a = Vector3::new(beta.cos(), beta.sin(), 0.0);
    let w0 = 1.2; // initial rate about â
    let r0 = -(r0m * s_o); // centre, so that the hinge point sits at the origin
    let r_perp = r0 - a * a.dot(&r0);
    let n = r0m.transpose() * a;
    let jm = Matrix3::from_diagonal(&Vector3::from(jp));
    let inertia = m * r_perp.norm_squared() + (n.transpose() * jm * n)[0];
    let ar = a.cross(&r_perp);
    let v0 = a.cross(&r0) * w0;
    let wb = n * w0; // body-frame angular velocity
    let times: Vec<f64> = (0..=30).map(|i| 0.1 * i as f64).collect();
    let reference = integrate(
        |_t, y, dy| {
            let (s, c) = y[0].sin_cos();
            dy[0] = y[1];
            dy[1] = -m * G * (-s * r_perp.z + c * ar.z) / inertia;
        },
        0.0,
        &[0.0, w0],
        &times,
        1e-13,
        1e-13,
    );
    let axis_in_body = n; // for the order [bar, ground]: the axis in the bar's frame
    for (order, joint) in [
        (
            "ground first",
            format!(
                r#"{{"name":"hinge","type":"revolute","bodies":["ground","bar"],"points":[[0,0,0],"O"],"axis":[{},{},{}]}}"#,
                a.x, a.y, a.z
            ),
        ),
        (
            "body first",
            format!(
                r#"{{"name":"hinge","type":"revolute","bodies":["bar","ground"],"points":["O",[0,0,0]],"axis":[{},{},{}]}}"#,
                axis_in_body.x, axis_in_body.y, axis_in_body.z
            ),
        ),
    ] {
        let json = format!(
            r#"{{"name":"hinged_body","dimension":3,"gravity":[0,0,-{G}],
            "bodies":[{{"name":"bar","mass":{m},"inertia":[{},{},{}],
                "points":{{"O":[{},{},{}]}},"position":[{},{},{}],"cardan":[{psi},{theta},{phi}],
                "velocity":[{},{},{}],"angular_velocity":[{},{},{}]}}],
            "joints":[{joint}],
            "solve":{{"t_end":3.0,"output_step":0.1}},"outputs":["energy"]}}"#,
            jp[0],
            jp[1],
            jp[2],
            s_o.x,
            s_o.y,
            s_o.z,
            r0.x,
            r0.y,
            r0.z,
            v0.x,
            v0.y,
            v0.z,
            wb.x,
            wb.y,
            wb.z
        );
        let scene = Scene::from_json_str(&json).expect("valid scene");
        let model = Model::new(&scene).expect("model");
        let mut o = model.default_options();
        o.formulation = FormulationKind::Ggl;
        o.rtol = 1e-11;
        o.atol = 1e-13;
        o.output_times = times.clone();
        let sol = model.solve(&o).expect("solve");
        assert!(
            sol.summary.max_constraint_error < 1e-9,
            "{order}: {:?}",
            sol.summary
        );
        let e = sol.column("energy").unwrap();
        // relative to the potential energy exchanged in a swing, m g |r⊥|
        let escale = m * G * r_perp.norm();
        for (k, y) in reference.iter().enumerate() {
            let want = rotate(&a, y[0], &r0);
            let v = |c: &str| sol.value(k, &format!("bar.{c}")).unwrap();
            let got = Vector3::new(v("x"), v("y"), v("z"));
            assert!(
                (got - want).norm() < 1e-6,
                "{order}, t = {}: centre {got} vs reference {want}",
                times[k]
            );
            let wg = Vector3::new(v("wX"), v("wY"), v("wZ"));
            assert!(
                (wg - a * y[1]).norm() < 1e-6,
                "{order}, t = {}: ω {wg} vs {}",
                times[k],
                a * y[1]
            );
            assert!(
                (e[k] - e[0]).abs() < 1e-8 * escale,
                "{order}: energy {} vs {} at t = {}",
                e[k],
                e[0],
                times[k]
            );
        }
        // the reference swings: the check is not of a body at rest
        let swing = reference.iter().map(|y| y[0].abs()).fold(0.0, f64::max);
        assert!(swing > 0.5, "swing {swing}");
    }
}

/// The planar double pendulum (bars along body x, O = (−L/2, 0), A = (L/2, 0), gravity −Y,
/// absolute angles α from X) mapped into the vertical X–Z plane: planar (x, y) → (x, 0, y), the
/// planar CCW rotation by α → rotation by α about −Y, i.e. Cardan (0, −α, roll). Bar 1 carries a
/// roll about its own axis, so the knee axis written in bar 1's frame, `R_x(roll)ᵀ ŷ`, is not a
/// body axis; its inertia [J/3, J, J] is symmetric about the bar, so the roll changes nothing.
fn double_pendulum_3d(th: [f64; 2], w: [f64; 2], p: &DoublePendulum, roll: f64) -> String {
    let st = p.state(0.0, th[0], th[1], w[0], w[1]);
    let body = |name: &str, m: f64, l: f64, c: [f64; 2], v: [f64; 2], al: f64, wr: f64, r: f64| {
        let j = m * l * l / 12.0;
        // body angular velocity R_x(r)ᵀ (0, −ω, 0)
        let (sr, cr) = r.sin_cos();
        format!(
            r#"{{"name":"{name}","mass":{m},"inertia":[{},{j},{j}],
              "points":{{"O":[{},0,0],"A":[{},0,0]}},"position":[{},0,{}],"cardan":[0,{},{r}],
              "velocity":[{},0,{}],"angular_velocity":[0,{},{}]}}"#,
            j / 3.0,
            -0.5 * l,
            0.5 * l,
            c[0],
            c[1],
            -al,
            v[0],
            v[1],
            -wr * cr,
            wr * sr
        )
    };
    let b1 = body("bar1", p.m1, p.l1, st.c1, st.v1, th[0], w[0], roll);
    let b2 = body("bar2", p.m2, p.l2, st.c2, st.v2, th[1], w[1], 0.0);
    let (sr, cr) = roll.sin_cos();
    format!(
        r#"{{"name":"double_pendulum_3d","dimension":3,"gravity":[0,0,-{}],
        "bodies":[{b1},{b2}],
        "joints":[
          {{"name":"pivot","type":"revolute","bodies":["ground","bar1"],"points":[[0,0,0],"O"],"axis":[0,1,0]}},
          {{"name":"knee","type":"revolute","bodies":["bar1","bar2"],"points":["A","O"],"axis":[0,{cr},{}]}}],
        "solve":{{"t_end":2.0,"output_step":0.1}},"outputs":["energy"]}}"#,
        p.g, -sr
    )
}

fn dp() -> DoublePendulum {
    DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 0.7,
        l2: 0.8,
        g: G,
    }
}

#[test]
fn double_pendulum_on_two_parallel_hinges_matches_planar_reference() {
    let p = dp();
    let th = [
        -std::f64::consts::FRAC_PI_2 + 0.8,
        -std::f64::consts::FRAC_PI_2 + 1.5,
    ];
    let w = [0.5, -1.0];
    let scene = Scene::from_json_str(&double_pendulum_3d(th, w, &p, 0.4)).expect("scene");
    let model = Model::new(&scene).expect("model");
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let sol = model.solve(&o).expect("solve");
    let r = simulate_double_pendulum(&p, [th[0], th[1], w[0], w[1]], &sol.times);
    assert!(sol.summary.max_constraint_error < 1e-9, "{:?}", sol.summary);
    let e = sol.column("energy").unwrap();
    for (k, rk) in r.iter().enumerate() {
        let v = |n: &str| sol.value(k, n).unwrap();
        for (b, c) in [("bar1", rk.c1), ("bar2", rk.c2)] {
            let got = [
                v(&format!("{b}.x")),
                v(&format!("{b}.y")),
                v(&format!("{b}.z")),
            ];
            let err = ((got[0] - c[0]).powi(2) + got[1].powi(2) + (got[2] - c[1]).powi(2)).sqrt();
            assert!(
                err < 1e-6,
                "t = {}: {b} at {got:?}, reference ({}, 0, {})",
                sol.times[k],
                c[0],
                c[1]
            );
        }
        // same energy as the planar reference (V = 0 at z = 0 in both)
        assert!(
            (e[k] - rk.energy).abs() < 1e-7,
            "t = {}: energy {} vs {}",
            sol.times[k],
            e[k],
            rk.energy
        );
    }
}

/// The decoupled twin of the hinged double pendulum: springs on the three point rows of each
/// hinge and torsional springs on its two axis rows, stiffness k. With critically damped joint
/// springs the spring deflections are ~ m g / k, so the motion follows the pinned reference.
#[test]
fn decoupled_twin_of_hinged_double_pendulum_follows_planar_reference() {
    let p = dp();
    let th = [
        -std::f64::consts::FRAC_PI_2 + 0.8,
        -std::f64::consts::FRAC_PI_2 + 1.5,
    ];
    let w = [0.5, -1.0];
    let scene = Scene::from_json_str(&double_pendulum_3d(th, w, &p, 0.4)).expect("scene");
    let model = Model::new(&scene).expect("model");
    let mut o = model.default_options();
    o.formulation = FormulationKind::Decoupled;
    o.joint_stiffness = 1e8;
    o.joint_damping = 2e4; // 2 √(k m) with m ~ 1
    o.output_times = (0..=10).map(|i| 0.1 * i as f64).collect();
    o.rtol = 1e-8;
    o.atol = 1e-12;
    o.max_steps = Some(2_000_000);
    let sol = model.solve(&o).expect("twin solves");
    let r = simulate_double_pendulum(&p, [th[0], th[1], w[0], w[1]], &sol.times);
    assert!(sol.summary.max_constraint_error < 1e-5, "{:?}", sol.summary);
    for (k, rk) in r.iter().enumerate() {
        let got = [
            sol.value(k, "bar2.x").unwrap(),
            sol.value(k, "bar2.z").unwrap(),
        ];
        let err = ((got[0] - rk.c2[0]).powi(2) + (got[1] - rk.c2[1]).powi(2)).sqrt();
        assert!(
            err < 1e-3,
            "t = {}: bar2 {got:?} vs {:?}",
            sol.times[k],
            rk.c2
        );
    }
}

#[test]
fn spatial_revolute_without_axis_is_refused_naming_the_axis() {
    let json = r#"{"name":"x","dimension":3,"gravity":[0,0,-9.81],
      "bodies":[{"name":"bar","mass":1,"inertia":[0.1,0.1,0.1],"points":{"O":[-0.5,0,0]},
                 "position":[0.5,0,0]}],
      "joints":[{"name":"hinge","type":"revolute","bodies":["ground","bar"],"points":[[0,0,0],"O"]}],
      "solve":{"t_end":1,"output_step":0.1}}"#;
    let err = Scene::from_json_str(json).unwrap_err().to_string();
    assert!(err.contains("joints[0].axis"), "{err}");
    assert!(err.contains("hinge"), "{err}");
}

#[test]
fn planar_revolute_with_axis_is_refused_naming_the_axis() {
    let json = r#"{"name":"x","dimension":2,"gravity":[0,-9.81],
      "bodies":[{"name":"bar","mass":1,"inertia":0.1,"points":{"O":[-0.5,0]},"position":[0.5,0]}],
      "joints":[{"name":"pin","type":"revolute","bodies":["ground","bar"],"points":[[0,0],"O"],"axis":[0,0,1]}],
      "solve":{"t_end":1,"output_step":0.1}}"#;
    let err = Scene::from_json_str(json).unwrap_err().to_string();
    assert!(err.contains("joints[0].axis"), "{err}");
}

/// `scenes/hinged_double_pendulum_3d.json` moves like the planar double pendulum released
/// horizontal at rest (planar y → z).
#[test]
fn hinged_double_pendulum_scene_matches_planar_reference() {
    let path = format!(
        "{}/scenes/hinged_double_pendulum_3d.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let scene = Scene::from_path(&path).expect("scene");
    let model = Model::new(&scene).expect("model");
    let mut o = model.default_options();
    o.rtol = 1e-10;
    o.atol = 1e-12;
    o.output_times = (0..=20).map(|i| 0.1 * i as f64).collect();
    let sol = model.solve(&o).expect("solve");
    let p = DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 1.0,
        l2: 1.0,
        g: G,
    };
    let r = simulate_double_pendulum(&p, [0.0; 4], &sol.times);
    for (k, rk) in r.iter().enumerate() {
        let (x, z) = (
            sol.value(k, "bar2.A.x").unwrap(),
            sol.value(k, "bar2.A.z").unwrap(),
        );
        let err = (x - rk.a2[0]).hypot(z - rk.a2[1]);
        assert!(
            err < 1e-6,
            "t = {}: tip ({x}, {z}) vs {:?}",
            sol.times[k],
            rk.a2
        );
        assert!(sol.value(k, "bar2.A.y").unwrap().abs() < 1e-9);
    }
}
