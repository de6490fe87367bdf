//! The mechanism components against independent derivations: accelerations of the double
//! pendulum at random consistent states (Lagrange in the joint angles), the body-fixed frame
//! (16.3) against the non-rotating frame (16.8), a weld, a damped spring (closed form) and a
//! tabulated load (integrated by hand).

mod common;

use bondmech::dae::{consistent_state_from, ConstraintExprs, MechanicsTapes};
use bondmech::mech::build;
use bondmech::{FormulationKind, Model, Scene};
use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};
use common::n_link::{simulate_n_link, NLinkPendulum};

const G: f64 = 9.81;

fn double_pendulum(frame: &str) -> String {
    format!(
        r#"{{"name":"dp","dimension":2,"gravity":[0,-{G}],
        "bodies":[
          {{"name":"bar1","mass":1.0,"inertia":{j},"frame":"{frame}","points":{{"O":[-0.5,0],"A":[0.5,0]}},
            "position":[0.5,0],"angle":0}},
          {{"name":"bar2","mass":1.0,"inertia":{j},"frame":"{frame}","points":{{"O":[-0.5,0],"A":[0.5,0]}},
            "position":[1.5,0],"angle":0}}],
        "joints":[
          {{"name":"pivot","type":"revolute","bodies":["ground","bar1"],"points":[[0,0],"O"]}},
          {{"name":"knee","type":"revolute","bodies":["bar1","bar2"],"points":["A","O"]}}],
        "solve":{{"t_end":3.0,"output_step":0.5}}}}"#,
        j = 1.0 / 12.0
    )
}

#[test]
fn double_pendulum_accelerations_match_lagrange_at_random_states() {
    let scene = Scene::from_json_str(&double_pendulum("inertial")).unwrap();
    let mut sys = build(&scene).unwrap();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let reference = DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 1.0,
        l2: 1.0,
        g: G,
    };
    let names: Vec<String> = sys.coords.iter().map(|c| c.name.clone()).collect();
    let idx = |n: &str| names.iter().position(|x| x == n).unwrap();
    // a small deterministic pseudo-random sequence (no dependence on bondmech)
    let mut rnd = common::uniform(12345);
    for _ in 0..20 {
        let (t1, t2) = (3.0 * rnd(), 3.0 * rnd());
        let (w1, w2) = (4.0 * rnd(), 4.0 * rnd());
        let (c1, s1) = (t1.cos(), t1.sin());
        let (c2, s2) = (t2.cos(), t2.sin());
        let mut x = vec![0.0; sys.nq() + sys.nv()];
        let nq = sys.nq();
        x[idx("bar1.x")] = 0.5 * c1;
        x[idx("bar1.y")] = 0.5 * s1;
        x[idx("bar1.angle")] = t1;
        x[idx("bar2.x")] = c1 + 0.5 * c2;
        x[idx("bar2.y")] = s1 + 0.5 * s2;
        x[idx("bar2.angle")] = t2;
        x[nq + idx("bar1.x")] = -0.5 * s1 * w1;
        x[nq + idx("bar1.y")] = 0.5 * c1 * w1;
        x[nq + idx("bar1.angle")] = w1;
        x[nq + idx("bar2.x")] = -s1 * w1 - 0.5 * s2 * w2;
        x[nq + idx("bar2.y")] = c1 * w1 + 0.5 * c2 * w2;
        x[nq + idx("bar2.angle")] = w2;
        let st = consistent_state_from(&sys, &tapes, 0.0, &x).unwrap();
        assert!(st.position_correction < 1e-12 && st.velocity_correction < 1e-12);
        let (a1, a2) = reference.accelerations(t1, t2, w1, w2);
        let got1 = st.vdot[idx("bar1.angle")];
        let got2 = st.vdot[idx("bar2.angle")];
        assert!(
            (got1 - a1).abs() < 1e-9 * (1.0 + a1.abs()),
            "ω1' {got1} vs {a1}"
        );
        assert!(
            (got2 - a2).abs() < 1e-9 * (1.0 + a2.abs()),
            "ω2' {got2} vs {a2}"
        );
    }
}

#[test]
fn body_fixed_frame_double_pendulum_matches_minimal_coordinates() {
    let scene = Scene::from_json_str(&double_pendulum("body")).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let s = model.solve(&o).unwrap();
    let r = simulate_double_pendulum(
        &DoublePendulum {
            m1: 1.0,
            l1: 1.0,
            m2: 1.0,
            l2: 1.0,
            g: G,
        },
        [0.0; 4],
        &s.times,
    );
    for (k, rk) in r.iter().enumerate() {
        for (col, want) in [
            ("bar2.x", rk.c2[0]),
            ("bar2.y", rk.c2[1]),
            ("bar1.vx", rk.v1[0]),
        ] {
            let got = s.value(k, col).unwrap();
            assert!(
                (got - want).abs() < 1e-7,
                "{col} at t = {}: {got} vs {want}",
                s.times[k]
            );
        }
    }
}

#[test]
fn two_bars_welded_end_to_end_swing_as_one_long_bar() {
    let json = format!(
        r#"{{"name":"welded","dimension":2,"gravity":[0,-{G}],
        "bodies":[
          {{"name":"a","mass":1.0,"inertia":{j},"points":{{"O":[-0.5,0],"A":[0.5,0]}},"position":[0.5,0],"angle":0}},
          {{"name":"b","mass":1.0,"inertia":{j},"points":{{"O":[-0.5,0],"A":[0.5,0]}},"position":[1.5,0],"angle":0}}],
        "joints":[
          {{"name":"pivot","type":"revolute","bodies":["ground","a"],"points":[[0,0],"O"]}},
          {{"name":"glue","type":"weld","bodies":["a","b"],"points":["A","O"]}}],
        "solve":{{"t_end":2.0,"output_step":0.25}}}}"#,
        j = 1.0 / 12.0
    );
    let model = Model::new(&Scene::from_json_str(&json).unwrap()).unwrap();
    let mut o = model.default_options();
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let s = model.solve(&o).unwrap();
    let r = simulate_n_link(
        &NLinkPendulum {
            masses: vec![2.0],
            lengths: vec![2.0],
            g: G,
        },
        &[0.0],
        &[0.0],
        &s.times,
    );
    for (k, rk) in r.iter().enumerate() {
        for col in ["a.angle", "b.angle"] {
            let got = s.value(k, col).unwrap();
            assert!(
                (got - rk.theta[0]).abs() < 1e-7,
                "{col} at t = {}",
                s.times[k]
            );
        }
    }
}

#[test]
fn damped_spring_to_ground_follows_the_closed_form() {
    // point mass m on a zero-rest-length spring k with damper c: x'' + (c/m) x' + (k/m) x = 0
    let (m, k, c, x0): (f64, f64, f64, f64) = (2.0, 50.0, 1.5, 0.3);
    let json = format!(
        r#"{{"name":"msd","dimension":2,"gravity":[0,0],
        "bodies":[{{"name":"m","mass":{m},"inertia":0,"position":[{x0},0],"angle":0}}],
        "springs":[{{"name":"s","bodies":["ground","m"],"points":[[0,0],[0,0]],"stiffness":{k},"rest_length":0,"damping":{c}}}],
        "solve":{{"t_end":2.0,"output_step":0.1,"formulation":"dae"}}}}"#
    );
    let model = Model::new(&Scene::from_json_str(&json).unwrap()).unwrap();
    for f in [FormulationKind::Ggl, FormulationKind::Decoupled] {
        let mut o = model.default_options();
        o.formulation = f;
        o.rtol = 1e-10;
        o.atol = 1e-12;
        let s = model.solve(&o).unwrap();
        let wn = (k / m).sqrt();
        let zeta = c / (2.0 * (k * m).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        for (i, &t) in s.times.iter().enumerate() {
            let want =
                x0 * (-zeta * wn * t).exp() * ((wd * t).cos() + zeta * wn / wd * (wd * t).sin());
            let got = s.value(i, "m.x").unwrap();
            assert!(
                (got - want).abs() < 1e-8,
                "{f:?} x at t = {t}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn tabulated_force_integrates_to_the_hand_computed_motion() {
    // F(t) = 2t on [0, 1], 2 on [1, 2]; m = 1: x(1) = 1/3, x(2) = 1/3 + 1 + 1 = 7/3
    let json = r#"{"name":"pushed","dimension":2,"gravity":[0,0],
        "bodies":[{"name":"m","mass":1.0,"inertia":0,"position":[0,0],"angle":0}],
        "loads":[{"type":"force","body":"m","value":{"table":{"t":[0,1,2],"v":[[0,0],[2,0],[2,0]]}}}],
        "solve":{"t_end":2.0,"output_times":[0,0.5,1.0,1.5,2.0]}}"#;
    let model = Model::new(&Scene::from_json_str(json).unwrap()).unwrap();
    let mut o = model.default_options();
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let s = model.solve(&o).unwrap();
    for (i, &t) in s.times.iter().enumerate() {
        let want = if t <= 1.0 {
            t * t * t / 3.0
        } else {
            1.0 / 3.0 + (t - 1.0) + (t - 1.0) * (t - 1.0)
        };
        let got = s.value(i, "m.x").unwrap();
        assert!((got - want).abs() < 1e-7, "x at t = {t}: {got} vs {want}");
    }
}

#[test]
fn three_bars_sharing_one_pin_stay_together_and_conserve_energy() {
    // a "Y": bar a hangs from the ground; bars b and c hang from a's tip, all three meeting
    // at one point
    let j = 1.0 / 12.0;
    let json = format!(
        r#"{{"name":"y","dimension":2,"gravity":[0,-{G}],
        "bodies":[
          {{"name":"a","mass":1.0,"inertia":{j},"points":{{"O":[-0.5,0],"A":[0.5,0]}},"position":[0.5,0],"angle":0}},
          {{"name":"b","mass":1.0,"inertia":{j},"points":{{"O":[-0.5,0],"A":[0.5,0]}},"position":[1.0,-0.5],"angle":-1.5707963267948966}},
          {{"name":"c","mass":0.5,"inertia":{jc},"points":{{"O":[-0.5,0],"A":[0.5,0]}},"position":[1.5,0],"angle":0}}],
        "joints":[
          {{"name":"pivot","type":"revolute","bodies":["ground","a"],"points":[[0,0],"O"]}},
          {{"name":"ab","type":"revolute","bodies":["a","b"],"points":["A","O"]}},
          {{"name":"ac","type":"revolute","bodies":["a","c"],"points":["A","O"]}}],
        "solve":{{"t_end":3.0,"output_step":0.05}},
        "outputs":["a.A","b.O","c.O","energy"]}}"#,
        jc = 0.5 / 12.0
    );
    let model = Model::new(&Scene::from_json_str(&json).unwrap()).unwrap();
    let mut o = model.default_options();
    o.rtol = 1e-9;
    o.atol = 1e-11;
    let s = model.solve(&o).unwrap();
    let e = s.column("energy").unwrap();
    for k in 0..s.times.len() {
        for p in ["b.O", "c.O"] {
            for ax in ["x", "y"] {
                let d = s.value(k, &format!("a.A.{ax}")).unwrap()
                    - s.value(k, &format!("{p}.{ax}")).unwrap();
                assert!(
                    d.abs() < 1e-9,
                    "{p}.{ax} left the pin at t = {}: {d:e}",
                    s.times[k]
                );
            }
        }
        // the motion is violent (energy ~ 20 J exchanged): conserved to 1e-6 relative
        assert!(
            (e[k] - e[0]).abs() < 1e-6 * 20.0,
            "energy at t = {}",
            s.times[k]
        );
    }
}

#[test]
fn decoupled_twin_solves_with_joint_stiffness_1e12() {
    let scene = Scene::from_json_str(&double_pendulum("inertial")).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = FormulationKind::Decoupled;
    o.joint_stiffness = 1e12;
    // critically damped joint springs (c = 2√(k m)): undamped, the twin's error test has to
    // follow the spring oscillation at √(k/m) = 1e6 rad/s (measured: 5.8 million steps per
    // simulated second at k = 1e12, growing like √k)
    o.joint_damping = 2e6;
    o.output_times = (0..=10).map(|i| 0.1 * i as f64).collect();
    o.rtol = 1e-8;
    o.atol = 1e-12;
    o.max_steps = Some(2_000_000);
    let s = model.solve(&o).expect("k = 1e12 still solves");
    let r = simulate_double_pendulum(
        &DoublePendulum {
            m1: 1.0,
            l1: 1.0,
            m2: 1.0,
            l2: 1.0,
            g: G,
        },
        [0.0; 4],
        &s.times,
    );
    // the springs stretch by about m g / k ≈ 1e-11 m; the motion matches the pinned one
    assert!(s.summary.max_constraint_error < 1e-9, "{:?}", s.summary);
    for (k, rk) in r.iter().enumerate() {
        let got = s.value(k, "bar2.y").unwrap();
        assert!(
            (got - rk.c2[1]).abs() < 1e-4,
            "t = {}: {got} vs {}",
            s.times[k],
            rk.c2[1]
        );
    }
}
