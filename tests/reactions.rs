//! Joint reactions (`"outputs": ["reactions"]`): the force and moment each joint exerts on its
//! second body, global frame, moment about the joint point on that body. Every reference value
//! is derived by hand from Newton–Euler balances of the body (stated at each test), never taken
//! from bondmech.

use bondmech::{FormulationKind, Model, Scene, Solution};
use serde_json::{json, Value};

const G: f64 = 9.81;

/// The DAE formulations; each must give the same physical forces (GGL's stabilising μ is zero
/// on the exact solution, the compliant form adds only ε λ to the velocity rows).
const DAE: [FormulationKind; 3] = [
    FormulationKind::Ggl,
    FormulationKind::CompliantGgl,
    FormulationKind::Index1,
];

fn solve(scene: &Value, f: FormulationKind, rtol: f64) -> Solution {
    let scene = Scene::from_json_str(&scene.to_string()).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = f;
    o.rtol = rtol;
    o.atol = rtol * 1e-2;
    model.solve(&o).unwrap()
}

fn col(sol: &Solution, name: &str) -> Vec<f64> {
    sol.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", sol.columns))
}

/// A uniform bar of mass `m`, length `l`, pinned at its end O to the ground at the origin,
/// released horizontal at rest; it stops (event) when its centre passes below the pivot.
fn falling_bar(m: f64, l: f64) -> Value {
    json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [{ "name": "bar", "mass": m, "inertia": m * l * l / 12.0,
                     "points": { "O": [-l / 2.0, 0.0] }, "position": [l / 2.0, 0.0] }],
        "joints": [{ "name": "pivot", "type": "revolute",
                     "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "O"] }],
        "solve": { "t_end": 2.0, "output_step": 0.01 },
        "outputs": ["reactions"],
        "events": [{ "name": "vertical", "when": "bar.x", "direction": "falling", "action": "stop" }]
    })
}

/// At the vertical the bar has fallen through L/2, so ½ J_O ω² = m g L/2 with J_O = m L²/3:
/// ω² = 3g/L. The gravity moment about O vanishes there, so α = 0 and the centre's acceleration
/// is centripetal, (L/2) ω² = 1.5 g, upward. Newton: F_y − m g = 1.5 m g, F_x = m · 0 = 0:
/// the pin carries 2.5 m g, vertical.
#[test]
fn pinned_bar_released_horizontal_carries_two_and_a_half_weights_at_the_vertical() {
    let (m, l) = (2.0, 1.5);
    for f in DAE {
        let sol = solve(&falling_bar(m, l), f, 1e-10);
        let last = sol.rows.len() - 1;
        let fy = sol.value(last, "pivot.Fy").unwrap();
        let fx = sol.value(last, "pivot.Fx").unwrap();
        assert_eq!(sol.summary.events.len(), 1, "{f:?}");
        assert!(
            (fy - 2.5 * m * G).abs() < 1e-6 * m * G,
            "{f:?}: pivot.Fy = {fy}, expected 2.5 m g = {}",
            2.5 * m * G
        );
        assert!(
            fx.abs() < 1e-6 * m * G,
            "{f:?}: pivot.Fx = {fx}, expected 0"
        );
        // no moment column for a pin
        assert!(sol.column("pivot.Mz").is_none());
        // at release (ω = 0, α = 3g/(2L)): the centre accelerates down at (L/2) α = 3g/4, so
        // the pin holds m g / 4
        let fy0 = sol.value(0, "pivot.Fy").unwrap();
        assert!((fy0 - 0.25 * m * G).abs() < 1e-8 * m * G, "{f:?}: {fy0}");
    }
}

/// Both bars hanging straight down at rest: the top pin carries both weights, the knee the
/// lower bar's weight (statics), at every time, on every formulation, twin included.
#[test]
fn hanging_double_pendulum_at_rest_carries_both_weights_at_the_top_and_one_at_the_knee() {
    let (m1, m2, l) = (1.3, 0.7, 0.8);
    let bar = |name: &str, m: f64, y: f64| {
        json!({ "name": name, "mass": m, "inertia": m * l * l / 12.0,
                "points": { "O": [-l / 2.0, 0.0], "A": [l / 2.0, 0.0] },
                "position": [0.0, y], "angle": -std::f64::consts::FRAC_PI_2 })
    };
    let scene = json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [bar("bar1", m1, -l / 2.0), bar("bar2", m2, -1.5 * l)],
        "joints": [
            { "name": "pivot", "type": "revolute", "bodies": ["ground", "bar1"], "points": [[0.0, 0.0], "O"] },
            { "name": "knee", "type": "revolute", "bodies": ["bar1", "bar2"], "points": ["A", "O"] }
        ],
        "solve": { "t_end": 1.0, "output_step": 0.1 },
        "outputs": ["reactions"]
    });
    let mut all = DAE.to_vec();
    all.push(FormulationKind::Decoupled);
    for f in all {
        let sol = solve(&scene, f, 1e-9);
        for (name, fy_expected) in [("pivot", (m1 + m2) * G), ("knee", m2 * G)] {
            for (k, (fx, fy)) in col(&sol, &format!("{name}.Fx"))
                .iter()
                .zip(col(&sol, &format!("{name}.Fy")))
                .enumerate()
            {
                assert!(
                    (fy - fy_expected).abs() < 1e-7 * fy_expected && fx.abs() < 1e-7,
                    "{f:?} {name} at row {k}: ({fx}, {fy}), expected (0, {fy_expected})"
                );
            }
        }
    }
}

/// A horizontal cantilever welded to the ground at its end O: the weld holds the weight,
/// F = (0, m g), and the moment of the weight about O, m g L/2 counter-clockwise.
#[test]
fn welded_cantilever_carries_the_weight_and_its_moment() {
    let (m, l) = (3.0, 0.9);
    let scene = json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [{ "name": "beam", "mass": m, "inertia": m * l * l / 12.0,
                     "points": { "O": [-l / 2.0, 0.0] }, "position": [l / 2.0, 0.0] }],
        "joints": [{ "name": "clamp", "type": "weld", "bodies": ["ground", "beam"], "points": [[0.0, 0.0], "O"] }],
        "solve": { "t_end": 0.5, "output_step": 0.1 },
        "outputs": ["reactions"]
    });
    for f in DAE {
        let sol = solve(&scene, f, 1e-9);
        for k in 0..sol.rows.len() {
            let v = |c: &str| sol.value(k, c).unwrap();
            assert!(v("clamp.Fx").abs() < 1e-8, "{f:?}");
            assert!((v("clamp.Fy") - m * G).abs() < 1e-8 * m * G, "{f:?}");
            let mz = v("clamp.Mz");
            assert!(
                (mz - m * G * l / 2.0).abs() < 1e-8 * m * G * l,
                "{f:?}: clamp.Mz = {mz}, expected m g L/2 = {}",
                m * G * l / 2.0
            );
        }
    }
}

/// A block on a horizontal frictionless rail (prismatic, ground first), pushed by a horizontal
/// force P applied a height h above its centre; the joint point C on the block is a distance d
/// ahead of the centre. The block cannot turn and slides with a = P/m, so the rail pushes only
/// across the rail: F = (0, m g). Its moment about the centre must cancel that of the push,
/// (0, h) × (P, 0) = −h P, so M_centre = h P; about C, M_C = M_centre − (C − centre) × F
/// = h P − d m g.
#[test]
fn pushed_slider_rail_moment_about_the_joint_point() {
    let (m, p, h, d) = (1.7, 4.0, 0.25, 0.3);
    let scene = json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [{ "name": "block", "mass": m, "inertia": 0.05,
                     "points": { "C": [d, 0.0], "T": [0.0, h] }, "position": [-d, 0.0] }],
        "joints": [{ "name": "rail", "type": "prismatic", "axis": [1.0, 0.0],
                     "bodies": ["ground", "block"], "points": [[0.0, 0.0], "C"] }],
        "loads": [{ "type": "force", "body": "block", "point": "T", "value": [p, 0.0] }],
        "solve": { "t_end": 1.0, "output_step": 0.1 },
        "outputs": ["reactions"]
    });
    for f in DAE {
        let sol = solve(&scene, f, 1e-9);
        let k = sol.rows.len() - 1;
        let v = |c: &str| sol.value(k, c).unwrap();
        // the slide itself: x(1) = −d + ½ (P/m) t²
        assert!((v("block.x") - (-d + 0.5 * p / m)).abs() < 1e-6, "{f:?}");
        assert!(v("rail.Fx").abs() < 1e-7, "{f:?}: {}", v("rail.Fx"));
        assert!((v("rail.Fy") - m * G).abs() < 1e-7 * m * G, "{f:?}");
        let expected = h * p - d * m * G;
        assert!(
            (v("rail.Mz") - expected).abs() < 1e-7 * m * G,
            "{f:?}: rail.Mz = {}, expected h P − d m g = {expected}",
            v("rail.Mz")
        );
    }
}

/// The joint's second body is ground: the columns are the force and moment on the ground,
/// the opposite of the wrench on the first body moved to the ground's joint point. The
/// cantilever of the test above, listed the other way round: F = (0, −m g), M = −m g L/2.
#[test]
fn reaction_on_ground_as_second_body_is_action_and_reaction() {
    let (m, l) = (3.0, 0.9);
    let scene = json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [{ "name": "beam", "mass": m, "inertia": m * l * l / 12.0,
                     "points": { "O": [-l / 2.0, 0.0] }, "position": [l / 2.0, 0.0] }],
        "joints": [{ "name": "clamp", "type": "weld", "bodies": ["beam", "ground"], "points": ["O", [0.0, 0.0]] }],
        "solve": { "t_end": 0.2, "output_step": 0.1 },
        "outputs": ["reactions"]
    });
    let sol = solve(&scene, FormulationKind::Ggl, 1e-9);
    let v = |c: &str| sol.value(1, c).unwrap();
    assert!(v("clamp.Fx").abs() < 1e-8);
    assert!((v("clamp.Fy") + m * G).abs() < 1e-8 * m * G);
    assert!((v("clamp.Mz") + m * G * l / 2.0).abs() < 1e-8 * m * G * l);
}

/// 3D: a bar of length L on a vertical hinge (axis z) at its end O, horizontal, gravity −z,
/// spinning about the hinge at constant ω (gravity does no work about z). At φ = ω t the bar
/// points along e = (cos φ, sin φ, 0); the centre moves on a circle of radius L/2, so
/// F = m (L/2) ω² (−e) + (0, 0, m g). The hinge carries the moment of the weight about O:
/// (L/2) e × (0, 0, −m g) = (L/2) m g (−sin φ, cos φ, 0), so M = (L/2) m g (sin φ, −cos φ, 0)
/// (the angular momentum about O, J_O ω ẑ, is constant: no gyroscopic term).
#[test]
fn spinning_bar_on_a_vertical_hinge_force_and_moment() {
    let (m, l, w) = (1.2, 0.8, 3.0);
    let j = m * l * l / 12.0;
    let scene = json!({
        "dimension": 3, "gravity": [0.0, 0.0, -G],
        "bodies": [{ "name": "bar", "mass": m, "inertia": [0.01, j, j],
                     "points": { "O": [-l / 2.0, 0.0, 0.0] }, "position": [l / 2.0, 0.0, 0.0],
                     "velocity": [0.0, w * l / 2.0, 0.0], "angular_velocity": [0.0, 0.0, w] }],
        "joints": [{ "name": "hinge", "type": "revolute", "axis": [0.0, 0.0, 1.0],
                     "bodies": ["ground", "bar"], "points": [[0.0, 0.0, 0.0], "O"] }],
        "solve": { "t_end": 1.0, "output_step": 0.05 },
        "outputs": ["reactions"]
    });
    for f in [FormulationKind::Ggl, FormulationKind::CompliantGgl] {
        let sol = solve(&scene, f, 1e-10);
        let mut worst = 0.0f64;
        for (k, &t) in sol.times.iter().enumerate() {
            let v = |c: &str| sol.value(k, c).unwrap();
            let (s, c) = (w * t).sin_cos();
            let cen = m * l / 2.0 * w * w;
            let expected = [
                ("hinge.Fx", -cen * c),
                ("hinge.Fy", -cen * s),
                ("hinge.Fz", m * G),
                ("hinge.Mx", l / 2.0 * m * G * s),
                ("hinge.My", -l / 2.0 * m * G * c),
                ("hinge.Mz", 0.0),
            ];
            for (name, e) in expected {
                worst = worst.max((v(name) - e).abs());
            }
        }
        assert!(
            worst < 1e-6 * m * G,
            "{f:?}: largest hinge reaction error {worst:e}"
        );
    }
}

/// The decoupled twin reads its reactions from its joint springs; as the joints stiffen they
/// approach the DAE's (the double pendulum released horizontal, a dynamic case): the largest
/// difference falls by about the stiffness ratio.
#[test]
fn twin_reactions_approach_the_dae_as_the_joints_stiffen() {
    let scene = Scene::from_path("scenes/double_pendulum.json").unwrap();
    let mut scene_value: Value =
        serde_json::from_str(&serde_json::to_string(&scene).unwrap()).unwrap();
    scene_value["outputs"] = json!(["reactions"]);
    scene_value["solve"]["t_end"] = json!(0.5);
    scene_value["solve"]["output_step"] = json!(0.05);
    let scene = Scene::from_json_str(&scene_value.to_string()).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.rtol = 1e-9;
    o.atol = 1e-11;
    let dae = model.solve(&o).unwrap();
    let mut diffs = Vec::new();
    for k in [1e5, 1e7] {
        o.formulation = FormulationKind::Decoupled;
        o.joint_stiffness = k;
        let twin = model.solve(&o).unwrap();
        let mut worst = 0.0f64;
        for c in ["pivot.Fx", "pivot.Fy", "knee.Fx", "knee.Fy"] {
            for (a, b) in col(&dae, c).iter().zip(col(&twin, c)) {
                worst = worst.max((a - b).abs());
            }
        }
        diffs.push(worst);
    }
    eprintln!(
        "twin − DAE reaction difference: k = 1e5: {:e} N, k = 1e7: {:e} N",
        diffs[0], diffs[1]
    );
    // `compare` diffs the same columns (forces in N) at the shared output times
    o.formulation = FormulationKind::Dae;
    let (cmp, _, _) = model.compare(&o).unwrap();
    assert!(cmp.force.column.ends_with(".Fx") || cmp.force.column.ends_with(".Fy"));
    assert_eq!(cmp.force.value, diffs[1]);
    assert!(cmp.moment.column.is_empty(), "pins transmit no moment");
    assert!(diffs[1] < 0.05 * diffs[0], "{diffs:?}");
    assert!(diffs[1] < 0.05, "{diffs:?}");
}

#[test]
fn reactions_in_a_raw_bond_graph_scene_are_refused_with_the_path() {
    let text = std::fs::read_to_string("scenes/bg_mass_spring_damper.json").unwrap();
    let mut v: Value = serde_json::from_str(&text).unwrap();
    v["outputs"] = json!(["reactions"]);
    let err = Scene::from_json_str(&v.to_string()).unwrap_err();
    assert!(err.to_string().contains("outputs[0]"), "{err}");
}

/// A point bob on a massless rod (inertia 0: its rotation is a kinematic variable of the pin),
/// released horizontal: at the bottom v² = 2 g L (energy), so the rod pulls with
/// m g + m v²/L = 3 m g, vertical.
#[test]
fn point_bob_on_a_massless_rod_pulls_three_weights_at_the_bottom() {
    let (m, l) = (0.6, 1.3);
    let scene = json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [{ "name": "bob", "mass": m, "inertia": 0.0,
                     "points": { "O": [-l, 0.0] }, "position": [l, 0.0] }],
        "joints": [{ "name": "pivot", "type": "revolute", "bodies": ["ground", "bob"], "points": [[0.0, 0.0], "O"] }],
        "solve": { "t_end": 2.0, "output_step": 0.01 },
        "outputs": ["reactions"],
        "events": [{ "name": "bottom", "when": "bob.x", "direction": "falling", "action": "stop" }]
    });
    for f in DAE {
        let sol = solve(&scene, f, 1e-10);
        let k = sol.rows.len() - 1;
        let (fx, fy) = (
            sol.value(k, "pivot.Fx").unwrap(),
            sol.value(k, "pivot.Fy").unwrap(),
        );
        assert!(
            fx.abs() < 1e-6 * m * G && (fy - 3.0 * m * G).abs() < 1e-6 * m * G,
            "{f:?}: ({fx}, {fy}), expected (0, 3 m g = {})",
            3.0 * m * G
        );
    }
}

/// The same statics with the lower bar in the seed's body-fixed frame (16.3: velocities along
/// the body axes): the reaction does not depend on the frame the equations are written in.
#[test]
fn body_fixed_frame_gives_the_same_knee_force() {
    let (m1, m2, l) = (1.1, 0.9, 0.7);
    let bar = |name: &str, m: f64, y: f64, frame: &str| {
        json!({ "name": name, "mass": m, "inertia": m * l * l / 12.0, "frame": frame,
                "points": { "O": [-l / 2.0, 0.0], "A": [l / 2.0, 0.0] },
                "position": [0.0, y], "angle": -std::f64::consts::FRAC_PI_2 })
    };
    let scene = json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [bar("bar1", m1, -l / 2.0, "inertial"), bar("bar2", m2, -1.5 * l, "body")],
        "joints": [
            { "name": "pivot", "type": "revolute", "bodies": ["ground", "bar1"], "points": [[0.0, 0.0], "O"] },
            { "name": "knee", "type": "revolute", "bodies": ["bar1", "bar2"], "points": ["A", "O"] }
        ],
        "solve": { "t_end": 0.5, "output_step": 0.1 },
        "outputs": ["reactions"]
    });
    let sol = solve(&scene, FormulationKind::Ggl, 1e-9);
    for k in 0..sol.rows.len() {
        let v = |c: &str| sol.value(k, c).unwrap();
        assert!(v("knee.Fx").abs() < 1e-7 && (v("knee.Fy") - m2 * G).abs() < 1e-7 * m2 * G);
        assert!((v("pivot.Fy") - (m1 + m2) * G).abs() < 1e-7 * (m1 + m2) * G);
    }
}

/// 3D: a box hanging at rest from a ball joint at its top point, gravity −z, tilted axes (the
/// body's frame is not the global one): the joint carries the weight, F = (0, 0, m g), and has
/// no moment columns; the same on the twin.
#[test]
fn body_hanging_from_a_spherical_joint_carries_its_weight() {
    let (m, h) = (2.3, 0.4);
    let scene = json!({
        "dimension": 3, "gravity": [0.0, 0.0, -G],
        "bodies": [{ "name": "box", "mass": m, "inertia": [0.05, 0.07, 0.09],
                     "points": { "top": [0.0, 0.0, h] }, "position": [0.0, 0.0, -h],
                     "cardan": [0.7, 0.0, 0.0] }],
        "joints": [{ "name": "ball", "type": "spherical", "bodies": ["ground", "box"],
                     "points": [[0.0, 0.0, 0.0], "top"] }],
        "solve": { "t_end": 0.5, "output_step": 0.1 },
        "outputs": ["reactions"]
    });
    for f in [FormulationKind::Ggl, FormulationKind::Decoupled] {
        let sol = solve(&scene, f, 1e-9);
        assert!(sol.column("ball.Mx").is_none());
        for k in 0..sol.rows.len() {
            let v = |c: &str| sol.value(k, c).unwrap();
            assert!(
                v("ball.Fx").abs() < 1e-7 && v("ball.Fy").abs() < 1e-7,
                "{f:?}"
            );
            assert!(
                (v("ball.Fz") - m * G).abs() < 1e-7 * m * G,
                "{f:?}: {}",
                v("ball.Fz")
            );
        }
    }
}
