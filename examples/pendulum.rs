//! Simple pendulum (seed 16.8, Fig. 26–27): a 1 kg point mass on a massless 1 m rod, pinned
//! at the origin, released horizontal at rest; solved as a DAE (GGL on IDA).
//!
//! `cargo run --example pendulum`

use bondmech::{Ground, Mechanism, Model, PlanarBody};

fn main() -> Result<(), bondmech::Error> {
    let scene = Mechanism::planar()
        .name("pendulum")
        .gravity([0.0, -9.81])
        .body(
            PlanarBody::point_mass("bob", 1.0)
                .point("O", [-1.0, 0.0]) // the rod's far end, 1 m from the bob
                .at([1.0, 0.0], 0.0),
        )
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bob", "O"))
        .output("energy")
        .t_end(2.0)
        .output_step(0.25)
        .tolerances(1e-8, 1e-10)
        .build()?;
    let model = Model::new(&scene)?;
    println!("{}", model.equations());
    let sol = model.solve(&model.default_options())?;

    println!(
        "{:>6} {:>10} {:>10} {:>10} {:>12}",
        "t", "x", "y", "angle", "energy"
    );
    let e0 = sol.value(0, "energy").expect("energy column");
    let (mut worst_energy, mut worst_radius) = (0.0f64, 0.0f64);
    for (k, t) in sol.times.iter().enumerate() {
        let v = |c: &str| sol.value(k, c).expect("a column of the solution");
        worst_energy = worst_energy.max((v("energy") - e0).abs());
        worst_radius = worst_radius.max((v("bob.x").hypot(v("bob.y")) - 1.0).abs());
        println!(
            "{t:>6.2} {:>10.6} {:>10.6} {:>10.6} {:>12.3e}",
            v("bob.x"),
            v("bob.y"),
            v("bob.angle"),
            v("energy")
        );
    }
    println!(
        "{} steps, max constraint error {:.1e}, energy drift {:.1e}",
        sol.summary.steps,
        sol.summary.max_constraint_error,
        sol.summary.energy_drift.unwrap_or(f64::NAN)
    );
    // no friction: m g L = 9.81 J is the energy scale; the bob stays 1 m from the pivot
    assert!(
        worst_energy < 1e-5 * 9.81,
        "energy not conserved: {worst_energy:e} J"
    );
    assert!(worst_radius < 1e-6, "the rod stretched: {worst_radius:e} m");
    Ok(())
}
