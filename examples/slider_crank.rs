//! Slider-crank (biela-manivela, seed 16.8, Fig. 29) of a vertical cylinder: crank 0.1 m,
//! rod 0.3 m, piston on a prismatic joint along Y, a constant driving torque on the crank and a
//! gas force on the piston written as an expression of the crank angle.
//!
//! `cargo run --example slider_crank`

use bondmech::{Ground, Mechanism, Model, PlanarBody};

/// Peak of the gas force (N), as in scenes/slider_crank.json.
const GAS_PEAK: f64 = 10.0;

/// The gas force on the piston along Y for crank angle `theta`: `−GAS_PEAK · max(0, cos θ)`.
/// The scene below gets the same law as an expression string built from [`GAS_PEAK`].
fn gas_force(theta: f64) -> f64 {
    -GAS_PEAK * theta.cos().max(0.0)
}

fn main() -> Result<(), bondmech::Error> {
    let (r, l) = (0.1_f64, 0.3_f64);
    let th = 60f64.to_radians();
    // Closed-loop start: crank pin A on the circle, wrist pin B on the cylinder axis x = 0.
    let a = [r * th.cos(), r * th.sin()];
    let b = [0.0, r * th.sin() + (l * l - (r * th.cos()).powi(2)).sqrt()];
    let rod_angle = (b[1] - a[1]).atan2(b[0] - a[0]);

    let scene = Mechanism::planar()
        .name("slider_crank")
        .gravity([0.0, -9.81])
        .body(PlanarBody::bar("crank", 1.0, r).at([a[0] / 2.0, a[1] / 2.0], th))
        .body(
            PlanarBody::bar("rod", 0.5, l)
                .at([(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0], rod_angle),
        )
        .body(
            PlanarBody::new("piston", 0.3, 2e-4)
                .point("P", [0.0, 0.0])
                .at(b, 0.0),
        )
        .revolute("main_bearing", Ground.at([0.0, 0.0]), ("crank", "O"))
        .revolute("crank_pin", ("crank", "A"), ("rod", "O"))
        .revolute("wrist_pin", ("rod", "A"), ("piston", "P"))
        .prismatic(
            "cylinder",
            Ground.at([0.0, 0.0]),
            ("piston", "P"),
            [0.0, 1.0],
        )
        .torque("drive", "crank", 1.5)
        // The gas force of scenes/slider_crank.json (see `gas_force`), θ the crank angle.
        .force(
            "gas",
            ("piston", "P"),
            [
                "0".to_string(),
                format!("-{GAS_PEAK:?}*max(0, cos(crank.angle))"),
            ],
        )
        .output("energy")
        .t_end(1.0)
        .output_step(0.1)
        .tolerances(1e-8, 1e-10)
        .build()?;
    let model = Model::new(&scene)?;
    println!("{} DOF", model.dof()?.dof);
    let sol = model.solve(&model.default_options())?;

    println!(
        "{:>5} {:>12} {:>10} {:>10} {:>12} {:>10}",
        "t", "crank [deg]", "omega", "piston.y", "gas [N]", "|g|"
    );
    let mut worst_closure = 0.0f64;
    for (k, t) in sol.times.iter().enumerate() {
        let v = |c: &str| sol.value(k, c).expect("a column of the solution");
        let angle = v("crank.angle");
        println!(
            "{t:>5.2} {:>12.2} {:>10.4} {:>10.5} {:>12.4} {:>10.1e}",
            angle.to_degrees(),
            v("crank.omega"),
            v("piston.y"),
            gas_force(angle),
            v("constraint_error")
        );
        // loop closure by hand: the wrist pin on the axis x = 0 at
        // y_B = r sin θ + √(l² − r² cos² θ)
        let y_b = r * angle.sin() + (l * l - (r * angle.cos()).powi(2)).sqrt();
        worst_closure = worst_closure.max((v("piston.y") - y_b).abs());
    }
    println!(
        "{} steps, {} residual evaluations",
        sol.summary.steps, sol.summary.residual_evals
    );
    println!("largest loop-closure error of piston.y: {worst_closure:.1e} m");
    assert!(
        worst_closure < 1e-6,
        "the piston left the crank-rod loop: {worst_closure:e} m"
    );
    Ok(())
}
