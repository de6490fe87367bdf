//! Free rigid body in space (seed 16.1–16.2): principal inertia [1, 2, 3] spinning about its
//! intermediate axis with a small perturbation. The spin is unstable and the body flips
//! (tennis-racket effect) while the kinetic energy and |h| stay constant.
//!
//! `cargo run --example free_body_3d`

use bondmech::scene::BodyFrame;
use bondmech::{Mechanism, Model, SpatialBody};

fn main() -> Result<(), bondmech::Error> {
    let j = [1.0, 2.0, 3.0];
    let scene = Mechanism::spatial()
        .name("free_body_3d")
        .body(
            SpatialBody::new("body", 1.0, j)
                .frame(BodyFrame::BodyFixed)
                .point("tip", [0.0, 1.0, 0.0])
                .angular_velocity([0.01, 1.0, 0.01]),
        )
        .output("body.tip")
        .output("energy")
        .t_end(20.0)
        .output_step(2.0)
        .tolerances(1e-8, 1e-10)
        .build()?;
    let model = Model::new(&scene)?;
    let sol = model.solve(&model.default_options())?;

    println!(
        "{:>5} {:>9} {:>9} {:>9} {:>9} {:>12} {:>12}",
        "t", "wx", "wy", "wz", "tip.y", "energy", "|h|"
    );
    let (mut e_range, mut h_range) = ((f64::MAX, f64::MIN), (f64::MAX, f64::MIN));
    for (k, t) in sol.times.iter().enumerate() {
        let v = |c: &str| sol.value(k, c).expect("a column of the solution");
        let w = [v("body.wx"), v("body.wy"), v("body.wz")];
        let h = (0..3).map(|i| (j[i] * w[i]).powi(2)).sum::<f64>().sqrt();
        println!(
            "{t:>5.1} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>12.9} {:>12.9}",
            w[0],
            w[1],
            w[2],
            v("body.tip.y"),
            v("energy"),
            h
        );
        e_range = (e_range.0.min(v("energy")), e_range.1.max(v("energy")));
        h_range = (h_range.0.min(h), h_range.1.max(h));
    }
    println!("{} steps", sol.summary.steps);
    // torque-free (Euler's equations): kinetic energy ½ Σ J_i w_i² and |h| = |J w| are constant
    let (de, dh) = (e_range.1 - e_range.0, h_range.1 - h_range.0);
    assert!(de < 1e-6 * e_range.1.abs(), "energy not conserved: {de:e}");
    assert!(dh < 1e-6 * h_range.1.abs(), "|h| not conserved: {dh:e}");
    Ok(())
}
