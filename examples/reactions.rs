//! Joint reactions, streamed: loads a JSON scene of one planar body on a ground pin (default
//! `scenes/pendulum.json`, a uniform bar released horizontal), asks for its reaction columns,
//! streams the solve row by row and prints the pin force next to the one Newton–Euler gives
//! for the body's state in that row; exits non-zero when they differ by more than 1e-6 m g.
//!
//! `cargo run --example reactions [SCENE.json]`
//!
//! The check: with `r` the centre of mass seen from the pin, `J_O = J + m |r|²` and `g` the
//! gravity vector, the moment about the pin gives `α = (r × m g)_z / J_O`, the centre
//! accelerates as `a = α ẑ × r − ω² r`, and the pin force on the body is `F = m a − m g`.

use std::ops::ControlFlow;
use std::process::ExitCode;

use bondmech::scene::joint_kind::Revolute;
use bondmech::scene::{Inertia, PointRef};
use bondmech::{Model, Scene};

fn main() -> ExitCode {
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("reactions: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<bool, Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scenes/pendulum.json".to_string());
    let mut scene = Scene::from_path(&path)?;
    // one body on one ground pin: the case whose force Newton–Euler gives in closed form
    let (body, pin) = match (scene.bodies.as_slice(), scene.joints.as_slice()) {
        ([b], [j]) if j.kind == Revolute::pin().into() && j.bodies[0] == "ground" => {
            (b.clone(), j.clone())
        }
        _ => {
            return Err(format!(
            "{path}: expected one planar body on one revolute joint to the ground (listed first)"
        )
            .into())
        }
    };
    let s_pin = match &pin.points[1] {
        PointRef::Named(n) => body.point(n).ok_or("pin point not on the body")?.to_vec(),
        PointRef::Coords(c) => c.clone(),
    };
    let Inertia::Planar(j_c) = body.inertia else {
        return Err("a planar body is expected".into());
    };
    let (m, g) = (body.mass, [scene.gravity[0], scene.gravity[1]]);
    scene.outputs.push("reactions".into());
    scene.solve.t_end = scene.solve.t_end.min(2.0);
    let model = Model::new(&scene)?;
    let columns = model.columns().ok_or("not a mechanism")?;
    let at = |c: &str| {
        columns
            .iter()
            .position(|n| n == c)
            .ok_or(format!("no column {c}"))
    };
    let (ia, iw) = (
        at(&format!("{}.angle", body.name))?,
        at(&format!("{}.omega", body.name))?,
    );
    let (ifx, ify) = (
        at(&format!("{}.Fx", pin.name))?,
        at(&format!("{}.Fy", pin.name))?,
    );

    let scale = m * g[0].hypot(g[1]).max(1.0);
    let mut worst = 0.0f64;
    println!(
        "{:>6} {:>12} {:>12} {:>12} {:>12}",
        "t", "Fx (N)", "Fy (N)", "Newton Fx", "Newton Fy"
    );
    let mut k = 0;
    // GGL's multipliers are converged by IDA's Newton iteration to their own absolute
    // tolerance (1e-2 by default, in N here): tighten it with the tolerances to read forces to
    // about 1e-7 m g (measured on scenes/pendulum.json: 1.5e-6 N; 3.9e-4 N with the scene's
    // rtol 1e-8 and the default multiplier tolerance)
    let mut opts = model.default_options();
    opts.rtol = 1e-10;
    opts.atol = 1e-12;
    opts.multiplier_atol = Some(1e-6);
    model.solve_streaming(&opts, &mut |row| {
        let (a, w) = (row.values[ia], row.values[iw]);
        // centre of mass seen from the pin: r = −R(α) s_pin
        let (sn, cs) = a.sin_cos();
        let r = [
            -(cs * s_pin[0] - sn * s_pin[1]),
            -(sn * s_pin[0] + cs * s_pin[1]),
        ];
        let j_o = j_c + m * (r[0] * r[0] + r[1] * r[1]);
        let alpha = m * (r[0] * g[1] - r[1] * g[0]) / j_o;
        let acc = [-alpha * r[1] - w * w * r[0], alpha * r[0] - w * w * r[1]];
        let newton = [m * acc[0] - m * g[0], m * acc[1] - m * g[1]];
        let (fx, fy) = (row.values[ifx], row.values[ify]);
        worst = worst
            .max((fx - newton[0]).abs())
            .max((fy - newton[1]).abs());
        if k % 20 == 0 {
            println!(
                "{:>6.2} {fx:>12.6} {fy:>12.6} {:>12.6} {:>12.6}",
                row.t, newton[0], newton[1]
            );
        }
        k += 1;
        ControlFlow::Continue(())
    })?;
    let ok = worst < 1e-6 * scale;
    println!(
        "{k} rows; largest difference from Newton–Euler {worst:.2e} N ({})",
        if ok { "ok" } else { "WRONG" }
    );
    Ok(ok)
}
