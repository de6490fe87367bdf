//! Typed trajectories over a `Solution`: the same numbers as the name-keyed columns, and the
//! geometry they must obey.

use bondmech::{BodyTrajectory, Ground, Mechanism, Model, PlanarBody, Scene};

fn double_pendulum() -> bondmech::Solution {
    let scene = Mechanism::planar()
        .gravity([0.0, -9.81])
        .body(PlanarBody::bar("bar1", 1.0, 1.0).at([0.5, 0.0], 0.0))
        .body(PlanarBody::bar("bar2", 1.0, 1.0).at([1.5, 0.0], 0.0))
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .revolute("knee", ("bar1", "A"), ("bar2", "O"))
        .output("bar2.A")
        .output("energy")
        .t_end(1.0)
        .tolerances(1e-8, 1e-10)
        .build()
        .unwrap();
    let model = Model::new(&scene).unwrap();
    model.solve(&model.default_options()).unwrap()
}

#[test]
fn planar_body_trajectory_equals_its_named_columns() {
    let sol = double_pendulum();
    let Some(BodyTrajectory::Planar(b)) = sol.body("bar2") else {
        panic!("bar2 is a planar body")
    };
    let col = |n: &str| sol.column(n).unwrap();
    assert_eq!(b.x, col("bar2.x"));
    assert_eq!(b.y, col("bar2.y"));
    assert_eq!(b.angle, col("bar2.angle"));
    assert_eq!(b.vx, col("bar2.vx"));
    assert_eq!(b.vy, col("bar2.vy"));
    assert_eq!(b.omega, col("bar2.omega"));
    assert_eq!(sol.times(), &sol.times[..]);
    assert_eq!(sol.energy().unwrap(), col("energy"));
    assert_eq!(sol.constraint_error().unwrap(), col("constraint_error"));
    assert!(sol.body("bar3").is_none());
}

#[test]
fn point_trajectory_is_the_bar_end_half_a_length_from_the_centre() {
    // A uniform bar of length 1 has A at (L/2)(cos θ, sin θ) from its centre.
    let sol = double_pendulum();
    let b = sol.body("bar2").unwrap();
    let b = b.planar().unwrap();
    let a = sol.point("bar2", "A").unwrap();
    assert!(a.z.is_none());
    assert_eq!(a.x, sol.column("bar2.A.x").unwrap());
    for k in 0..sol.times().len() {
        assert!((a.x[k] - (b.x[k] + 0.5 * b.angle[k].cos())).abs() < 1e-12);
        assert!((a.y[k] - (b.y[k] + 0.5 * b.angle[k].sin())).abs() < 1e-12);
    }
    assert!(sol.point("bar2", "O").is_none()); // not asked for in outputs
}

#[test]
fn spatial_body_trajectory_equals_its_named_columns() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/free_body_3d.json");
    let model = Model::new(&Scene::from_path(path).unwrap()).unwrap();
    let mut opts = model.default_options();
    opts.output_times = model.output_times_until(1.0).unwrap();
    let sol = model.solve(&opts).unwrap();
    let name = &model.scene().bodies[0].name;
    let t = sol.body(name).unwrap();
    assert!(t.planar().is_none());
    let s = t.spatial().unwrap();
    let col = |w: &str| sol.column(&format!("{name}.{w}")).unwrap();
    assert_eq!(s.z, col("z"));
    assert_eq!(s.vz, col("vz"));
    assert_eq!(s.wx, col("wx"));
    assert_eq!(s.w_inertial_z, col("wZ"));
    assert_eq!(s.psi, col("psi"));
    assert_eq!(s.phi, col("phi"));
    assert_eq!(s.theta, col("theta"));
}

#[test]
fn raw_bond_graph_solution_has_energy_but_no_bodies() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bg_mass_spring_damper.json");
    let model = Model::new(&Scene::from_path(path).unwrap()).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    let e = sol.energy().unwrap();
    // E(0) = ½ k x0² = ½·6·0.1² = 0.03 J (released at rest), and the damper only removes energy
    assert!((e[0] - 0.03).abs() < 1e-12, "{}", e[0]);
    assert!(e.windows(2).all(|w| w[1] <= w[0] + 1e-9));
    assert!(sol.body("m").is_none());
    assert!(sol.constraint_error().is_none());
}
