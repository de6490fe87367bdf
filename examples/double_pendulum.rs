//! Double pendulum of two hinged uniform bars (seed 16.7, Fig. 19–21): the pinned mechanism
//! as a DAE on IDA and its decoupled stiff-spring twin on CVODE, side by side.
//!
//! `cargo run --example double_pendulum`

use bondmech::{Ground, Mechanism, Model, PlanarBody};

fn main() -> Result<(), bondmech::Error> {
    let scene = Mechanism::planar()
        .name("double_pendulum")
        .gravity([0.0, -9.81])
        .body(PlanarBody::bar("bar1", 1.0, 1.0).at([0.5, 0.0], 0.0))
        .body(PlanarBody::bar("bar2", 1.0, 1.0).at([1.5, 0.0], 0.0))
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .revolute("knee", ("bar1", "A"), ("bar2", "O"))
        .output("bar2.A")
        .output("energy")
        .t_end(2.0)
        .output_step(0.25)
        .tolerances(1e-8, 1e-10)
        .build()?;
    let model = Model::new(&scene)?;
    let dof = model.dof()?;
    println!(
        "{} velocities, {} constraint rows (rank {}), {} DOF",
        dof.velocities, dof.constraint_rows, dof.rank, dof.dof
    );

    let (comparison, dae, twin) = model.compare(&model.default_options())?;
    println!(
        "{:>6} {:>11} {:>11} {:>11} {:>11} {:>11}",
        "t", "angle1", "angle2", "A.x", "A.y", "A.y twin"
    );
    let e0 = dae.value(0, "energy").expect("energy column");
    let mut worst_energy = 0.0f64;
    for (k, t) in dae.times.iter().enumerate() {
        let v = |c: &str| dae.value(k, c).expect("a column of the solution");
        worst_energy = worst_energy.max((v("energy") - e0).abs());
        println!(
            "{t:>6.2} {:>11.6} {:>11.6} {:>11.6} {:>11.6} {:>11.6}",
            v("bar1.angle"),
            v("bar2.angle"),
            v("bar2.A.x"),
            v("bar2.A.y"),
            twin.value(k, "bar2.A.y").expect("a column of the twin")
        );
    }
    println!("\n{}", comparison.table());
    // no friction: the DAE keeps the energy (scale m g L = 9.81 J) and the pins hold
    assert!(
        worst_energy < 1e-5 * 9.81,
        "energy not conserved: {worst_energy:e} J"
    );
    assert!(
        dae.summary.max_constraint_error < 1e-6,
        "pins violated: {:e}",
        dae.summary.max_constraint_error
    );
    Ok(())
}
