//! Why does the GGL DAE take more steps than index 1? A measurement, not a benchmark: the GGL
//! residual of `dae::GglFormulation` run on IDA with different error-test weightings, against
//! the minimal-coordinate reference, on the double pendulum and the slider-crank.
//!
//! Variants (λ, μ are always algebraic and out of the error test, as in `solve::run`):
//! * `all q, v` — what `solve::run` does: every q and v in the error test, `atol` on both;
//! * `q only` — velocities excluded from the error test (id 0 + suppress_alg);
//! * `v atol ×1e3` — velocities kept but with a 1000× looser absolute tolerance;
//! * `no dependent v` — the dependent velocities (the index-2 components fixed by `G_v v = 0`,
//!   chosen as index 1 chooses them) excluded;
//! * `no dependent q, v` — the dependent coordinates and velocities excluded.
//!
//! Run with `cargo bench --bench ggl_error_test`.

#[path = "common/minimal.rs"]
mod minimal;

use std::sync::Arc;

use bondmech::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use bondmech::partition::select_dependent;
use bondmech::report::sweep::median;
use bondmech::solve::formulation::GglFormulation;
use bondmech::sundials::{DenseMatrixMut, Ida, IdaOptions, Multistep};
use bondmech::{FormulationKind, Model, Scene};
use cpu_time::ThreadTime;
use minimal::{bondmech_rows, max_difference, solve_minimal, MinimalModel};

struct Outcome {
    steps: u64,
    error: f64,
    cpu: f64,
    etf: u64,
}

fn run_ggl(
    model: &Model,
    mm: &MinimalModel,
    times: &[f64],
    reference: &[Vec<f64>],
    rtol: f64,
    variant: &str,
) -> Option<Outcome> {
    let atol = rtol * 1e-2;
    let mut sys = model.system().clone();
    let t0 = times[0];
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, t0).ok()?;
    let ggl = GglFormulation::build(&mut sys, &c, 0.0);
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let mut y0 = init.q.clone();
    y0.extend(&init.v);
    y0.extend(&init.lambda);
    y0.extend(std::iter::repeat_n(0.0, nc));
    let mut yp0 = MechanicsTapes::eval(&tapes.kinematics, t0, &y0[..nq + nv]);
    yp0.extend(&init.vdot);
    yp0.extend(std::iter::repeat_n(0.0, 2 * nc));
    let mut id = ggl.id.clone();
    let mut at = vec![atol; nq + nv];
    at.extend(std::iter::repeat_n(1e-2, 2 * nc));
    let gv = tapes.gv.matrix(t0, &y0[..nq + nv]);
    let preferred: Vec<bool> = sys
        .velocities
        .iter()
        .map(|v| matches!(v.name.rsplit('.').next().unwrap_or(""), "vx" | "vy" | "vz"))
        .collect();
    let dependent = select_dependent(&gv, &preferred)?;
    match variant {
        "all q, v" => {}
        "q only" => id[nq..nq + nv].iter_mut().for_each(|x| *x = 0.0),
        "v atol x1e3" => at[nq..nq + nv].iter_mut().for_each(|x| *x *= 1e3),
        "no dependent v" => dependent.iter().for_each(|&j| id[nq + j] = 0.0),
        "no dependent q, v" => {
            // in these planar scenes q and v are in the same order (x, y, angle per body)
            dependent.iter().for_each(|&j| {
                id[nq + j] = 0.0;
                id[j] = 0.0;
            })
        }
        _ => unreachable!(),
    }
    let opts = IdaOptions {
        rtol,
        atol: at,
        max_steps: Some(10_000_000),
        id: Some(id),
        suppress_alg: true,
        stop_time: times.last().copied(),
        init_step: Some(1e-4f64.min(0.1 * (times[1] - times[0]))),
        ..IdaOptions::default()
    };
    let dae = Arc::new(ggl.dae);
    let (d1, d2) = (dae.clone(), dae.clone());
    let mut w1 = d1.workspace();
    let mut w2 = d2.workspace();
    let residual = Box::new(move |t: f64, y: &[f64], yp: &[f64], r: &mut [f64]| {
        d1.residual(&mut w1, t, y, yp, r);
        Ok(())
    });
    let jacobian = Box::new(
        move |t: f64, cj: f64, y: &[f64], yp: &[f64], jm: &mut DenseMatrixMut<'_>| {
            jm.fill_zero();
            d2.jacobian(&mut w2, t, cj, y, yp, |r, c, v| jm.add(r, c, v));
            Ok(())
        },
    );
    let clock = ThreadTime::now();
    let mut ida = Ida::new(t0, &y0, &yp0, residual, Some(jacobian), &opts).ok()?;
    let mut states = vec![y0[..nq + nv].to_vec()];
    for &t in &times[1..] {
        ida.solve_to(t).ok()?;
        states.push(ida.y()[..nq + nv].to_vec());
    }
    let cpu = clock.elapsed().as_secs_f64();
    let s = ida.stats();
    // outputs through the model's own output tape (names = the solution columns)
    let names: Vec<String> = sys.outputs.iter().map(|o| o.name.clone()).collect();
    let rows: Vec<Vec<f64>> = states
        .iter()
        .zip(times)
        .map(|(x, &t)| {
            let out = MechanicsTapes::eval(&tapes.outputs, t, x);
            mm.columns
                .iter()
                .map(|c| out[names.iter().position(|n| n == c).expect("column")])
                .collect()
        })
        .collect();
    // angles are unwrapped by solve::run; these scenes stay within (−π, π] over the horizon
    Some(Outcome {
        steps: s.steps,
        error: max_difference(&rows, reference),
        cpu,
        etf: s.error_test_failures,
    })
}

fn main() {
    for (name, mm) in [
        ("double_pendulum", minimal::DOUBLE_PENDULUM),
        ("slider_crank", minimal::SLIDER_CRANK),
    ] {
        let scene = Scene::from_path(format!("scenes/{name}.json")).unwrap();
        let model = Model::new(&scene).unwrap();
        let times = scene.output_times();
        let reference = solve_minimal(&mm, Multistep::Adams, 1e-12, 1e-14, &times).rows;
        println!("\n{name}: steps / error vs minimal reference / error-test failures / CPU ms (median of 3)");
        println!(
            "{:<20} {:>6} {:>7} {:>10} {:>5} {:>9}",
            "variant", "rtol", "steps", "error", "etf", "CPU ms"
        );
        for rtol in [1e-6, 1e-8] {
            for variant in [
                "all q, v",
                "q only",
                "v atol x1e3",
                "no dependent v",
                "no dependent q, v",
            ] {
                let mut cpu = Vec::new();
                let mut last = None;
                for _ in 0..3 {
                    if let Some(o) = run_ggl(&model, &mm, &times, &reference, rtol, variant) {
                        cpu.push(o.cpu);
                        last = Some(o);
                    }
                }
                match last {
                    Some(o) => println!(
                        "{:<20} {:>6.0e} {:>7} {:>10.2e} {:>5} {:>9.3}",
                        variant,
                        rtol,
                        o.steps,
                        o.error,
                        o.etf,
                        median(&mut cpu) * 1e3
                    ),
                    None => println!("{variant:<20} {rtol:>6.0e} failed"),
                }
            }
            let mut o = model.default_options();
            o.formulation = FormulationKind::Index1;
            o.rtol = rtol;
            o.atol = rtol * 1e-2;
            o.max_steps = Some(10_000_000);
            if let Ok(s) = model.solve(&o) {
                println!(
                    "{:<20} {:>6.0e} {:>7} {:>10.2e} {:>5} {:>9.3}",
                    "index1 (solve::run)",
                    rtol,
                    s.summary.steps,
                    max_difference(&bondmech_rows(&s, mm.columns), &reference),
                    s.summary.error_test_failures,
                    s.summary.cpu_seconds * 1e3
                );
            }
        }
    }
}
