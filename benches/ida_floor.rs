//! IDA's floor (issue 25): what IDA alone — bondmech's wrapper with its serial vector kernels
//! (`src/sundials/fast_ops.rs`), a custom linear solver — costs per step on a DAE with the
//! same number of unknowns and the same differential/algebraic pattern as the default `dae`
//! on the two problems of `../shared/docs/peers.md` (20 unknowns, 4 differential, for the
//! double pendulum; 30 unknowns, 2 differential, for the smooth slider-crank), forced to the
//! same number of steps as the `dae` needs at its hard-way rtol, against the limit's whole
//! solve (the minimal-coordinate model on CVODE BDF, `benches/common/minimal.rs`) timed in the
//! same run.
//!
//! The floor's DAE is linear and trivially cheap: each independent coordinate `q` and its
//! velocity `v` (differential, id 1) oscillate,
//!
//! ```text
//!   F_q = q' − v = 0,   F_v = v' + ω² q = 0        (q = cos ωt, v = −ω sin ωt)
//!   F_z = z_j − c_j q_(j) = 0                         (every other unknown: algebraic, id 0)
//! ```
//!
//! so a Newton matrix `J = ∂F/∂y + c_j ∂F/∂y'` is solved in closed form: per pair
//! `[c_j −1; ω² c_j]` (`x_q = (b_v + c_j b_q)/(ω² + c_j²)`, `x_v = c_j x_q − b_q`), then
//! `x_z = b_z + c x_q`. The residual and the linear solver cost a few dozen flops: what is
//! left is IDA (its step logic, its Newton iteration, its vector work). `ω` is chosen by
//! bisection so that IDA, at the `dae`'s rtol and with its options (algebraic unknowns out of
//! the error test, the same first step, a fresh Newton matrix at every `c_j` change), takes the
//! `dae`'s number of steps within 5 %. Each floor solve is checked against `cos ωt`.
//!
//! Run with `cargo bench --bench ida_floor` (`BONDMECH_FLOOR_BENCH=quick` skips criterion).

#[path = "common/case.rs"]
mod bench_case;
#[path = "common/minimal.rs"]
mod minimal;
use bench_case::{peer_cases, Case, Run};

use std::time::Duration;

use bondmech::report::sweep::median;
use bondmech::sundials::{CallbackResult, Ida, IdaLinearSolver, IdaOptions};
use bondmech::FormulationKind;
use cpu_time::ThreadTime;
use criterion::Criterion;

const TARGET: f64 = 1e-6;
const REPEATS: usize = 31;

/// The shape of a `dae` run: its coordinates, constraint rows and independent coordinates
/// (the causality's states), which fix the unknowns `[q, v, a_D, λ]` and their id.
struct Shape {
    nq: usize,
    nc: usize,
    independent: &'static [usize],
}

impl Shape {
    fn n(&self) -> usize {
        2 * self.nq + 2 * self.nc
    }

    /// 1 (differential) for the independent coordinates and velocities, else 0.
    fn id(&self) -> Vec<f64> {
        let mut id = vec![0.0; self.n()];
        for &i in self.independent {
            id[i] = 1.0;
            id[self.nq + i] = 1.0;
        }
        id
    }
}

/// Double pendulum: bar1 (x, y, θ), bar2 (x, y, θ); 4 pin rows; the angles are the states.
const DOUBLE_PENDULUM: Shape = Shape {
    nq: 6,
    nc: 4,
    independent: &[2, 5],
};
/// Slider-crank: crank, rod (x, y, θ each), piston (x, y); 7 rows; the crank angle is the state.
const SLIDER_CRANK: Shape = Shape {
    nq: 8,
    nc: 7,
    independent: &[2],
};

/// The floor DAE of a [`Shape`] at frequency `omega`.
#[derive(Clone)]
struct Floor {
    n: usize,
    nq: usize,
    omega2: f64,
    /// Independent coordinates.
    ind: Vec<usize>,
    /// Each algebraic unknown, its coefficient and the independent coordinate it follows.
    alg: Vec<(usize, f64, usize)>,
}

impl Floor {
    fn new(shape: &Shape, omega: f64) -> Floor {
        let id = shape.id();
        let ind = shape.independent.to_vec();
        let alg = (0..shape.n())
            .filter(|&u| id[u] == 0.0)
            .enumerate()
            .map(|(j, u)| (u, 0.1 + 0.01 * j as f64, ind[j % ind.len()]))
            .collect();
        Floor {
            n: shape.n(),
            nq: shape.nq,
            omega2: omega * omega,
            ind,
            alg,
        }
    }

    fn residual(&self, y: &[f64], yp: &[f64], r: &mut [f64]) {
        for &i in &self.ind {
            let v = self.nq + i;
            r[i] = yp[i] - y[v];
            r[v] = yp[v] + self.omega2 * y[i];
        }
        for &(u, c, i) in &self.alg {
            r[u] = y[u] - c * y[i];
        }
    }

    fn initial(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut y, mut yp) = (vec![0.0; self.n], vec![0.0; self.n]);
        for &i in &self.ind {
            y[i] = 1.0;
            yp[self.nq + i] = -self.omega2;
        }
        for &(u, c, _) in &self.alg {
            y[u] = c;
        }
        (y, yp)
    }
}

/// The closed-form solve of the floor's Newton matrix.
struct FloorSolver {
    f: Floor,
    cj: f64,
}

impl IdaLinearSolver for FloorSolver {
    fn setup(&mut self, _t: f64, cj: f64, _y: &[f64], _yp: &[f64]) -> CallbackResult {
        self.cj = cj;
        Ok(())
    }

    fn solve(&mut self, b: &mut [f64]) -> CallbackResult {
        let (cj, w2, nq) = (self.cj, self.f.omega2, self.f.nq);
        for &i in &self.f.ind {
            let v = nq + i;
            let xq = (b[v] + cj * b[i]) / (w2 + cj * cj);
            b[v] = cj * xq - b[i];
            b[i] = xq;
        }
        for &(u, c, i) in &self.f.alg {
            b[u] += c * b[i];
        }
        Ok(())
    }
}

/// One floor solve over `times` at `rtol` (atol = rtol/100): its steps, CPU seconds (IDA's
/// creation included, as the limit's includes CVODE's) and largest error of `q` against
/// `cos ωt` at the outputs.
fn floor_solve(shape: &Shape, omega: f64, rtol: f64, times: &[f64]) -> (u64, f64, f64) {
    let clock = ThreadTime::now();
    let f = Floor::new(shape, omega);
    let (y0, yp0) = f.initial();
    let opts = IdaOptions {
        rtol,
        atol: vec![rtol * 1e-2],
        max_steps: Some(u64::MAX),
        id: Some(shape.id()),
        suppress_alg: true,
        stop_time: times.last().copied(),
        // as bondmech's formulations (src/solve/integrators.rs, ida_options)
        init_step: Some(1e-4f64.min(0.1 * (times[1] - times[0]))),
        delta_cj_lsetup: Some(0.0),
        ..IdaOptions::default()
    };
    let fr = f.clone();
    let residual = Box::new(move |_t: f64, y: &[f64], yp: &[f64], r: &mut [f64]| {
        fr.residual(y, yp, r);
        Ok(())
    });
    let solver = Box::new(FloorSolver {
        f: f.clone(),
        cj: 0.0,
    });
    let mut ida = Ida::new_with_linear_solver(times[0], &y0, &yp0, residual, solver, &opts)
        .expect("IDA starts");
    let mut error = 0.0f64;
    for &t in &times[1..] {
        let s = ida.solve_to(t).expect("IDA solves the floor DAE");
        let exact = (omega * s.t).cos();
        for &i in &f.ind {
            error = error.max((ida.y()[i] - exact).abs());
        }
    }
    let steps = ida.stats().steps;
    (steps, clock.elapsed().as_secs_f64(), error)
}

/// The `ω` whose floor solve takes `steps` steps within 5 % (bisection on `log ω`; the step
/// count grows with `ω`).
fn matched_omega(shape: &Shape, steps: u64, rtol: f64, times: &[f64]) -> (f64, u64) {
    let (mut lo, mut hi) = (1e-2f64.ln(), 1e4f64.ln());
    let mut best = (1.0, 0u64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let (s, _, _) = floor_solve(shape, mid.exp(), rtol, times);
        best = (mid.exp(), s);
        if (s as f64 - steps as f64).abs() <= 0.05 * steps as f64 {
            break;
        }
        if s < steps {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    best
}

fn timed<T>(mut f: impl FnMut() -> (T, f64)) -> (T, f64) {
    let mut cpus = Vec::with_capacity(REPEATS);
    let mut last = None;
    for _ in 0..REPEATS {
        let (r, cpu) = f();
        cpus.push(cpu);
        last = Some(r);
    }
    (last.expect("repeats > 0"), median(&mut cpus))
}

struct Chosen {
    omega: f64,
    floor_rtol: f64,
    limit_rtol: f64,
}

fn main() {
    let cases = peer_cases();
    let shapes = [&DOUBLE_PENDULUM, &SLIDER_CRANK];
    let mut chosen = Vec::new();
    println!(
        "{:<22} {:>7} {:>6} {:>8} {:>7} {:>10} {:>9} {:>9}",
        "case", "rtol", "n", "ω", "steps", "cpu µs", "µs/step", "× limit"
    );
    for (case, shape) in cases.iter().zip(shapes) {
        // the dae's hard-way rtol: the loosest decade 1e-6 … 1e-10 with error ≤ TARGET
        let dae = (6..=10)
            .map(|e| 10f64.powi(-e))
            .find_map(|rtol| {
                let mut o = case.options(rtol);
                o.formulation = FormulationKind::Dae;
                Run::bondmech(case, &o)
                    .filter(|r| r.error <= TARGET)
                    .map(|r| (rtol, r))
            })
            .expect("the dae reaches the target at some decade");
        let (dae_rtol, dae_run) = dae;
        let (limit_rtol, _) = minimal::matched_rtol(TARGET, |r| Some(case.limit(r).1))
            .expect("the limit reaches the target");
        let (lim, lim_cpu) = timed(|| {
            let (r, _) = case.limit(limit_rtol);
            let cpu = r.cpu_seconds;
            (r, cpu)
        });
        // the dae itself in this process (summary.cpu_seconds, median), for the comparison
        let (_, dae_cpu) = timed(|| {
            let mut o = case.options(dae_rtol);
            o.formulation = FormulationKind::Dae;
            let r = Run::bondmech(case, &o).expect("the dae solves");
            let cpu = r.cpu;
            (r, cpu)
        });
        let (omega, _) = matched_omega(shape, dae_run.steps, dae_rtol, &case.times);
        let ((steps, error), cpu) = timed(|| {
            let (s, cpu, e) = floor_solve(shape, omega, dae_rtol, &case.times);
            ((s, e), cpu)
        });
        // the floor is a real solve: q = cos ωt to the tolerance's order
        assert!(
            error < 1e3 * dae_rtol,
            "floor solve off cos ωt by {error:.1e}"
        );
        println!(
            "{:<22} {:>7.1e} {:>6} {:>8} {:>7} {:>10.0} {:>9.3} {:>9} (limit: rtol {:.1e}, {} steps)",
            format!("{} limit", case.name),
            limit_rtol,
            case.minimal.n,
            "",
            lim.steps,
            lim_cpu * 1e6,
            lim_cpu * 1e6 / lim.steps.max(1) as f64,
            "1.00",
            limit_rtol,
            lim.steps
        );
        println!(
            "{:<22} {:>7.1e} {:>6} {:>8.2} {:>7} {:>10.0} {:>9.3} {:>9.2} (dae: {} steps, error {:.1e})",
            format!("{} floor", case.name),
            dae_rtol,
            shape.n(),
            omega,
            steps,
            cpu * 1e6,
            cpu * 1e6 / steps.max(1) as f64,
            cpu / lim_cpu,
            dae_run.steps,
            error
        );
        println!(
            "{:<22} {:>7.1e} {:>6} {:>8} {:>7} {:>10.0} {:>9.3} {:>9.2} (in this process; {} residuals, {} Jacobians)",
            format!("{} dae", case.name),
            dae_rtol,
            shape.n(),
            "",
            dae_run.steps,
            dae_cpu * 1e6,
            dae_cpu * 1e6 / dae_run.steps.max(1) as f64,
            dae_cpu / lim_cpu,
            dae_run.res,
            dae_run.jac
        );
        chosen.push(Chosen {
            omega,
            floor_rtol: dae_rtol,
            limit_rtol,
        });
    }
    if std::env::var("BONDMECH_FLOOR_BENCH").as_deref() == Ok("quick") {
        return;
    }
    let mut crit = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    for ((case, shape), ch) in cases.iter().zip(shapes).zip(&chosen) {
        let case: &Case = case;
        let mut g = crit.benchmark_group(format!("floor_{}", case.name));
        g.bench_function("limit", |b| b.iter(|| case.limit(ch.limit_rtol)));
        g.bench_function("ida_floor", |b| {
            b.iter(|| floor_solve(shape, ch.omega, ch.floor_rtol, &case.times))
        });
        g.finish();
    }
    crit.final_summary();
}
