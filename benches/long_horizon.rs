//! Accuracy over a long horizon: the point-mass pendulum (1 m massless link, 1 kg, released
//! horizontal) over 2000 s (845 periods) against the exact elliptic solution, for each
//! formulation at rtol 1e-8 … 1e-11 (atol = rtol/100): the largest distance of the bob from
//! θ(t) = 2 arcsin(k sn(K + ω₀t, k²)) at 4000 output times, the steps and the CPU seconds.
//! The README's long-horizon table comes from here.
//!
//! Run with `cargo bench --bench long_horizon` (a few minutes: the tightest GGL runs take
//! millions of steps; each run is capped at 120 s of wall clock).

#[allow(dead_code)] // the bench uses only the exact angle
#[path = "../tests/common/elliptic.rs"]
mod elliptic;

use std::time::Duration;

use bondmech::{FormulationKind, Integrator, Model, Scene};

const G: f64 = 9.81;
const T_END: f64 = 2000.0;

fn main() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/pendulum_point_mass.json"
    );
    let scene = Scene::from_json_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let model = Model::new(&scene).unwrap();
    let amplitude = std::f64::consts::FRAC_PI_2;
    let times: Vec<f64> = (0..=4000).map(|i| T_END * i as f64 / 4000.0).collect();
    let exact: Vec<(f64, f64)> = times
        .iter()
        .map(|&t| {
            let th = elliptic::pendulum_angle(1.0, G, amplitude, t);
            (th.sin(), -th.cos())
        })
        .collect();
    println!("point-mass pendulum, 2000 s, error = max |bob − exact| over 4001 outputs");
    println!(
        "{:<26} {:>8} {:>10} {:>10} {:>10}",
        "formulation", "rtol", "error (m)", "steps", "CPU (s)"
    );
    let methods: [(FormulationKind, Integrator, &str); 6] = [
        (
            FormulationKind::Partitioned,
            Integrator::Erk,
            "partitioned (ERK)",
        ),
        (
            FormulationKind::Partitioned,
            Integrator::Adams,
            "partitioned (Adams)",
        ),
        (
            FormulationKind::Partitioned,
            Integrator::Bdf,
            "partitioned (BDF)",
        ),
        (FormulationKind::Index1, Integrator::Auto, "index1"),
        (FormulationKind::Ggl, Integrator::Auto, "ggl"),
        (
            FormulationKind::CompliantGgl,
            Integrator::Auto,
            "compliant_ggl",
        ),
    ];
    for (f, integ, label) in methods {
        for rtol in [1e-8, 1e-9, 1e-10, 1e-11] {
            let mut o = model.default_options();
            o.formulation = f;
            o.integrator = integ;
            o.rtol = rtol;
            o.atol = rtol * 1e-2;
            o.output_times = times.clone();
            o.max_wall_clock = Some(Duration::from_secs(120));
            match model.solve(&o) {
                Ok(s) => {
                    let err = s
                        .times
                        .iter()
                        .enumerate()
                        .map(|(k, _)| {
                            let (x, y) =
                                (s.value(k, "bob.x").unwrap(), s.value(k, "bob.y").unwrap());
                            (x - exact[k].0).hypot(y - exact[k].1)
                        })
                        .fold(0.0, f64::max);
                    println!(
                        "{:<26} {:>8.0e} {:>10.2e} {:>10} {:>10.3}",
                        label, rtol, err, s.summary.steps, s.summary.cpu_seconds
                    );
                }
                Err(e) => println!("{label:<26} {rtol:>8.0e} failed: {e}"),
            }
        }
    }
}
