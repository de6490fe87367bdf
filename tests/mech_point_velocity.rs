//! Point velocity outputs `b.P.vx`, `b.P.vy` (`b.P.vz`) against the rigid-body formula
//! `V_P = V_O + ω × (R s_P)`, evaluated in the test from the body's own state columns.

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::rigid_body::cardan_matrix;
use nalgebra::Vector3;

#[test]
fn planar_point_velocity_outputs_equal_centre_velocity_plus_omega_cross_r() {
    let json = r#"{"name":"dp","dimension":2,"gravity":[0,-9.81],
      "bodies":[
        {"name":"bar1","mass":1,"inertia":0.0833,"points":{"O":[-0.5,0],"A":[0.5,0]},"position":[0.5,0]},
        {"name":"bar2","mass":1,"inertia":0.0833,"points":{"O":[-0.5,0],"T":[0.5,0.1]},"position":[1.5,0]}],
      "joints":[
        {"name":"pivot","type":"revolute","bodies":["ground","bar1"],"points":[[0,0],"O"]},
        {"name":"knee","type":"revolute","bodies":["bar1","bar2"],"points":["A","O"]}],
      "solve":{"t_end":2,"output_step":0.1},
      "outputs":["bar2.T.vx","bar2.T.vy","bar2.T.x","bar1.O.vx","bar1.O.vy"]}"#;
    let scene = Scene::from_json_str(json).expect("point velocity outputs are accepted");
    let model = Model::new(&scene).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    let mut moving = 0.0f64;
    for k in 0..sol.times.len() {
        let v = |n: &str| sol.value(k, n).unwrap();
        let (sn, c) = v("bar2.angle").sin_cos();
        let s = [0.5, 0.1];
        let r = [c * s[0] - sn * s[1], sn * s[0] + c * s[1]];
        let w = v("bar2.omega");
        let want = [v("bar2.vx") - w * r[1], v("bar2.vy") + w * r[0]];
        assert!((v("bar2.T.vx") - want[0]).abs() < 1e-12, "vx at {k}");
        assert!((v("bar2.T.vy") - want[1]).abs() < 1e-12, "vy at {k}");
        assert!((v("bar2.T.x") - (v("bar2.x") + r[0])).abs() < 1e-12);
        moving = moving.max(want[0].abs());
        // the pivot point of bar1 does not move (up to the solver's constraint error)
        assert!(v("bar1.O.vx").abs() < 1e-6 && v("bar1.O.vy").abs() < 1e-6);
    }
    assert!(
        moving > 0.5,
        "the tip must move for the check to mean something"
    );
}

#[test]
fn spatial_point_velocity_outputs_equal_centre_velocity_plus_omega_cross_r() {
    let json = r#"{"name":"spin","dimension":3,"gravity":[0,0,0],
      "bodies":[{"name":"b","mass":1,"inertia":[0.1,0.2,0.25],"points":{"T":[0.3,-0.2,0.1]},
                 "velocity":[0.1,0.2,-0.3],"angular_velocity":[1.0,2.0,0.5],"cardan":[0.2,0.3,0.4]}],
      "solve":{"t_end":2,"output_step":0.1},
      "outputs":["b.T.vx","b.T.vy","b.T.vz"]}"#;
    let scene = Scene::from_json_str(json).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    let sol = model.solve(&o).unwrap();
    for k in 0..sol.times.len() {
        let v = |n: &str| sol.value(k, n).unwrap();
        let r = cardan_matrix(v("b.psi"), v("b.theta"), v("b.phi"));
        let wg = Vector3::new(v("b.wX"), v("b.wY"), v("b.wZ"));
        let want = Vector3::new(v("b.vx"), v("b.vy"), v("b.vz"))
            + wg.cross(&(r * Vector3::new(0.3, -0.2, 0.1)));
        let got = Vector3::new(v("b.T.vx"), v("b.T.vy"), v("b.T.vz"));
        assert!(
            (got - want).norm() < 1e-9,
            "t = {}: {got} vs {want}",
            sol.times[k]
        );
    }
}

#[test]
fn unknown_point_component_output_is_refused_naming_the_output() {
    let json = r#"{"name":"p","dimension":2,"gravity":[0,-9.81],
      "bodies":[{"name":"bar","mass":1,"inertia":0.1,"points":{"O":[-0.5,0]},"position":[0.5,0]}],
      "joints":[{"name":"pivot","type":"revolute","bodies":["ground","bar"],"points":[[0,0],"O"]}],
      "solve":{"t_end":1,"output_step":0.1},"outputs":["bar.O.vz","bar.Q.vx"]}"#;
    let err = Scene::from_json_str(json).unwrap_err().to_string();
    assert!(err.contains("outputs[0]") && err.contains("'vz'"), "{err}");
    assert!(
        err.contains("outputs[1]") && err.contains("no point 'Q'"),
        "{err}"
    );
}
