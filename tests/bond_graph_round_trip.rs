//! A mechanism's bond graph round-trips as a scene: `graph --as-scene` writes the complete
//! pinned graph (closures, coordinates, output columns) as a raw `"bond_graph"` scene, and
//! solving that file gives the mechanism's trajectories and column names.

mod support;
use bondmech::scene::Scene;
use bondmech::{Model, Solution};
use support::cli::{bondmech, scene as scene_path, tmp};

fn scene(name: &str) -> Scene {
    Scene::from_path(scene_path(&format!("{name}.json"))).unwrap()
}

/// The scene with tight tolerances and (for the long chains) a shorter horizon.
fn tight(mut s: Scene, t_end: f64) -> Scene {
    s.solve.rtol = 1e-10;
    s.solve.atol = 1e-12;
    s.solve.t_end = s.solve.t_end.min(t_end);
    s.solve.output_times = None;
    s
}

fn solve(s: &Scene) -> Solution {
    let m = Model::new(s).unwrap();
    m.solve(&m.default_options()).unwrap()
}

fn round_trip(name: &str, t_end: f64) {
    let s = tight(scene(name), t_end);
    let raw = bondmech::graph::bond_graph_scene(&s).unwrap();
    let back = Scene::from_json_str(&raw.to_string()).unwrap();
    assert!(back.bodies.is_empty() && back.bond_graph.is_some());
    let (a, b) = (solve(&s), solve(&back));
    assert_eq!(a.columns, b.columns, "{name}: column names");
    assert_eq!(a.times, b.times, "{name}");
    for (k, (ra, rb)) in a.rows.iter().zip(&b.rows).enumerate() {
        for (c, (x, y)) in ra.iter().zip(rb).enumerate() {
            if a.columns[c] == "constraint_error" {
                continue;
            }
            assert!(
                (x - y).abs() <= 1e-8,
                "{name}: {} at t = {}: mechanism {x} vs its bond graph {y}",
                a.columns[c],
                a.times[k]
            );
        }
    }
    // the raw graph holds its joints too
    let ce = b.column("constraint_error").unwrap();
    assert!(
        ce.iter().all(|e| *e < 1e-8),
        "{name}: constraint error {ce:?}"
    );
}

#[test]
fn double_pendulum_round_trips_through_its_bond_graph() {
    round_trip("double_pendulum", 3.0);
}

#[test]
fn pendulums_and_two_bars_round_trip_through_their_bond_graphs() {
    for n in ["pendulum", "pendulum_point_mass", "two_bars"] {
        round_trip(n, 2.0);
    }
}

#[test]
fn slider_crank_four_bars_and_andrews_round_trip_through_their_bond_graphs() {
    round_trip("slider_crank", 0.5);
    round_trip("four_bar", 1.0);
    round_trip("four_bar_chain_3", 1.0);
    round_trip("andrews_squeezer", 0.01);
}

/// The exported graph is a graph like any other: a rotational damper (an R on the first bar's
/// ω junction) added by hand makes the pendulum lose energy at every step, which the
/// conservative mechanism does not.
#[test]
fn an_r_added_to_the_exported_graph_dissipates_energy() {
    let s = tight(scene("double_pendulum"), 2.0);
    let mut raw = bondmech::graph::bond_graph_scene(&s).unwrap();
    let g = raw["bond_graph"].as_object_mut().unwrap();
    g["elements"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"name": "hinge_damper", "kind": "R", "value": 0.05}));
    g["bonds"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"from": "bar1.omega", "to": "hinge_damper"}));
    let edited = Scene::from_json_str(&raw.to_string()).unwrap();
    let e = solve(&edited).column("energy").unwrap();
    assert!(e.windows(2).all(|w| w[1] <= w[0] + 1e-9), "energy rises");
    assert!(
        e[0] - e[e.len() - 1] > 1e-3,
        "no dissipation: {} → {}",
        e[0],
        e[e.len() - 1]
    );
    let e0 = solve(&s).column("energy").unwrap();
    assert!(
        (e0[0] - e0[e0.len() - 1]).abs() < 1e-6,
        "the mechanism itself conserves energy"
    );
}

#[test]
fn graph_as_scene_cli_writes_a_scene_that_runs() {
    let out = tmp("dp_graph_scene.json");
    let o = bondmech(&[
        "graph",
        &scene_path("double_pendulum.json"),
        "--as-scene",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = bondmech(&["run", out.to_str().unwrap(), "--t-end", "0.1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = String::from_utf8(o.stdout).unwrap();
    assert!(csv.starts_with("t,bar1.x,bar1.y,bar1.angle"), "{csv}");
    // a drawing's file name is refused
    let o = bondmech(&[
        "graph",
        &scene_path("double_pendulum.json"),
        "--as-scene",
        "--out",
        tmp("x.svg").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
}

#[test]
fn spatial_scenes_round_trip_through_their_bond_graphs() {
    round_trip("free_body_3d", 2.0);
    round_trip("hinged_double_pendulum_3d", 1.0);
    round_trip("spatial_slider_crank", 0.2);
    round_trip("bricard", 0.5);
}

/// The decoupled twin is a transformation of the graph, so the exported graph has the same
/// twin: solved with `formulation: "decoupled"`, the raw file gives the mechanism's twin
/// trajectories (both open the same constraint junctions and put in the same springs).
#[test]
fn exported_graph_has_the_mechanisms_decoupled_twin() {
    let mut s = tight(scene("double_pendulum"), 0.5);
    s.solve.formulation = bondmech::FormulationKind::Decoupled;
    s.solve.joint_stiffness = 1e5;
    s.solve.joint_damping = 2.0;
    let raw = bondmech::graph::bond_graph_scene(&s).unwrap();
    let back = Scene::from_json_str(&raw.to_string()).unwrap();
    let (a, b) = (solve(&s), solve(&back));
    assert_eq!(a.summary.formulation, "decoupled");
    assert_eq!(b.summary.formulation, "decoupled");
    assert_eq!(a.columns, b.columns);
    for (k, (ra, rb)) in a.rows.iter().zip(&b.rows).enumerate() {
        for (c, (x, y)) in ra.iter().zip(rb).enumerate() {
            assert!(
                (x - y).abs() <= 1e-8,
                "{} at t = {}: mechanism's twin {x} vs its graph's twin {y}",
                a.columns[c],
                a.times[k]
            );
        }
    }
    // the twin's springs stretch: it is not the pinned mechanism
    assert!(a.summary.max_constraint_error > 1e-7);
}

/// Regression: the springs of zero rest length were drawn as `<s>.x.x.k` while the graph's
/// completion looked for `<s>.x.k`, so such a scene quietly fell back to the equations
/// assembled beside the graph. Now it is read off its graph, spring elements named per axis.
#[test]
fn zero_rest_length_spring_is_read_off_its_bond_graph() {
    let s = Scene::from_json_str(
        r#"{"name":"msd","dimension":2,"gravity":[0,-9.81],
        "bodies":[{"name":"m","mass":2,"inertia":0,"position":[0.3,0],"angle":0}],
        "springs":[{"name":"s","bodies":["ground","m"],"points":[[0,0],[0,0]],"stiffness":50,"rest_length":0,"damping":1.5}],
        "solve":{"t_end":1.0,"output_step":0.1}}"#,
    )
    .unwrap();
    let sys = bondmech::mech::build(&s).unwrap();
    assert_eq!(sys.source, bondmech::mech::EquationSource::BondGraph);
    let g = sys.bond_graph.as_deref().unwrap();
    for n in ["s.x.k", "s.y.k", "s.x.c", "s.y.c"] {
        assert!(g.element_by_name(n).is_some(), "no element {n}");
    }
    assert!(g.element_by_name("s.x.x.k").is_none());
}
