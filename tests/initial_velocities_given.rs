//! The velocities a scene writes are the user's (issue 46, F8): the initial projection changes
//! the velocities left out to close the joints, and keeps the written ones where the others can
//! close them alone.
//!
//! A slider-crank: crank (0.3 m) pinned at the origin and standing vertical, rod 0.7 m, piston on
//! the horizontal line through the pin. Given only the crank's `angular_velocity` ω = 4 rad/s,
//! by hand: the crank's centre (0, 0.15) moves at ω × r = (−0.6, 0), its pin A = (0, 0.3) at
//! (−1.2, 0); the piston B = (√(0.7² − 0.3²), 0) keeps |A − B| = 0.7, so
//! (A − B)·(v_A − v_B) = 0 with v_B horizontal gives v_B = (−1.2, 0), and the rod translates
//! (ω_rod = 0, its centre at (−1.2, 0)).
//!
//! Regression: the projection took the least change of every velocity and started the crank at
//! 3.807 rad/s (the trial's F8, an offset slider-crank).

use bondmech::{Model, Scene, Solution};

fn scene(crank: &str) -> String {
    let xb = (0.7f64 * 0.7 - 0.3 * 0.3).sqrt();
    let angle = (-0.3f64).atan2(xb);
    format!(
        r#"{{
  "gravity": [0, 0],
  "bodies": [
    {{ "name": "crank", "mass": 1.0, "inertia": 0.0075,
       "points": {{ "O": [-0.15, 0], "A": [0.15, 0] }},
       "position": [0, 0.15], "angle": 1.5707963267948966 {crank} }},
    {{ "name": "rod", "mass": 2.0, "inertia": 0.08,
       "points": {{ "A": [-0.35, 0], "B": [0.35, 0] }},
       "position": [{xr}, 0.15], "angle": {angle} }},
    {{ "name": "piston", "mass": 0.5, "inertia": 0.001, "points": {{ "P": [0, 0] }},
       "position": [{xb}, 0] }}
  ],
  "joints": [
    {{ "name": "main_bearing", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], "O"] }},
    {{ "name": "crank_pin", "type": "revolute", "bodies": ["crank", "rod"], "points": ["A", "A"] }},
    {{ "name": "wrist_pin", "type": "revolute", "bodies": ["rod", "piston"], "points": ["B", "P"] }},
    {{ "name": "cylinder", "type": "prismatic", "bodies": ["ground", "piston"], "points": [[0, 0], "P"], "axis": [1, 0] }}
  ],
  "solve": {{ "t_end": 0.01, "output_step": 0.01 }}
}}"#,
        xr = 0.5 * xb,
    )
}

fn first_row(json: &str) -> Solution {
    let model = Model::new(&Scene::from_json_str(json).expect("valid scene")).expect("builds");
    let mut o = model.default_options();
    o.output_times = vec![0.0, 0.01];
    model.solve(&o).expect("solves")
}

/// The warning of the initial velocity projection.
fn projection_warning(sol: &Solution) -> &str {
    sol.summary
        .warnings
        .iter()
        .find(|w| w.contains("initial velocities violate"))
        .expect("the projection is reported")
}

#[test]
fn regression_a_given_crank_angular_velocity_was_changed_by_the_projection() {
    let sol = first_row(&scene(r#", "angular_velocity": 4.0"#));
    let v = |c: &str| sol.value(0, c).expect(c);
    assert!(
        (v("crank.omega") - 4.0).abs() < 1e-12,
        "{}",
        v("crank.omega")
    );
    for (c, want) in [
        ("crank.vx", -0.6),
        ("crank.vy", 0.0),
        ("rod.vx", -1.2),
        ("rod.vy", 0.0),
        ("rod.omega", 0.0),
        ("piston.vx", -1.2),
        ("piston.vy", 0.0),
    ] {
        assert!((v(c) - want).abs() < 1e-12, "{c}: {} (want {want})", v(c));
    }
    let w = projection_warning(&sol);
    assert!(w.contains("the scene gives are kept"), "{w}");
}

/// The crank's centre velocity written as zero with ω = 4 contradicts the ground pin, which
/// only the crank's own (written) velocities enter: the others cannot close it, every velocity
/// takes the least change, and the warning says the written ones changed.
#[test]
fn written_velocities_that_contradict_a_joint_change_and_the_warning_says_so() {
    let sol = first_row(&scene(
        r#", "angular_velocity": 4.0, "velocity": [0.0, 0.0]"#,
    ));
    let omega = sol.value(0, "crank.omega").expect("crank.omega");
    assert!((omega - 4.0).abs() > 0.1, "{omega}");
    // whatever the projection chose, it lies on the ground pin: v_c = ω × (0, 0.15)
    let vx = sol.value(0, "crank.vx").expect("crank.vx");
    assert!((vx + 0.15 * omega).abs() < 1e-12, "{vx} vs {omega}");
    let w = projection_warning(&sol);
    assert!(w.contains("could not close the joints alone"), "{w}");
}

/// A scene written back keeps out what the user left out (a written zero would become a given
/// velocity on reading).
#[test]
fn a_written_scene_keeps_the_velocities_it_was_not_given_out() {
    let scene = Scene::from_json_str(&scene(r#", "angular_velocity": 4.0"#)).expect("valid");
    let text = scene.to_json_string();
    let again = Scene::from_json_str(&text).expect("round trip");
    let crank = &again.bodies[0];
    assert!(crank.angular_velocity_given && !crank.velocity_given);
    assert!(!again.bodies[1].velocity_given && !again.bodies[1].angular_velocity_given);
}
