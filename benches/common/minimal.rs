//! Hand-written minimal-coordinate models solved directly with CVODE — the practical speed limit
//! for these mechanisms. The equations are copied from the hand derivations in
//! `tests/common/double_pendulum.rs` and `tests/common/slider_crank.rs` (see there for the
//! Lagrangian derivation); nothing here uses bondmech's modelling, only its safe CVODE wrapper.
//!
//! Outputs are the columns bondmech writes (`b.x`, `b.y`, `b.angle` per body), so errors are
//! measured the same way for every method.
#![allow(dead_code)]

use bondmech::sundials::{Cvode, CvodeOptions, DenseMatrixMut, Multistep};
use cpu_time::ThreadTime;

/// Double pendulum of two uniform bars (1 m, 1 kg), pinned at the origin, both horizontal at
/// rest, gravity 9.81: θ̈ = M(δ)⁻¹ r(θ, θ̇) with δ = θ₁ − θ₂ (tests/common/double_pendulum.rs).
pub mod double_pendulum {
    const G: f64 = 9.81;
    // m1 = m2 = l1 = l2 = 1: M11 = 1/3 + 1, M22 = 1/3, a = 1/2, K1 = 1.5 g, K2 = 0.5 g
    const M11: f64 = 4.0 / 3.0;
    const M22: f64 = 1.0 / 3.0;
    const A: f64 = 0.5;
    const K1: f64 = 1.5 * G;
    const K2: f64 = 0.5 * G;

    /// `y' = f(y)`, `y = [θ₁, θ₂, ω₁, ω₂]`.
    pub fn rhs(y: &[f64], yd: &mut [f64]) {
        let (s, c) = (y[0] - y[1]).sin_cos();
        let r1 = -A * s * y[3] * y[3] - K1 * y[0].cos();
        let r2 = A * s * y[2] * y[2] - K2 * y[1].cos();
        let m12 = A * c;
        let det = M11 * M22 - m12 * m12;
        yd[0] = y[2];
        yd[1] = y[3];
        yd[2] = (M22 * r1 - m12 * r2) / det;
        yd[3] = (M11 * r2 - m12 * r1) / det;
    }

    /// Analytic `∂f/∂y`: from `M a = r`, `∂a/∂x = M⁻¹ (∂r/∂x − (∂M/∂x) a)`.
    pub fn jacobian(y: &[f64], yd: &[f64], j: &mut [[f64; 4]; 4]) {
        let (s, c) = (y[0] - y[1]).sin_cos();
        let (w1, w2) = (y[2], y[3]);
        let (a1, a2) = (yd[2], yd[3]);
        let m12 = A * c;
        let det = M11 * M22 - m12 * m12;
        // ∂r/∂(θ1, θ2, ω1, ω2)
        let dr1 = [
            -A * c * w2 * w2 + K1 * y[0].sin(),
            A * c * w2 * w2,
            0.0,
            -2.0 * A * s * w2,
        ];
        let dr2 = [
            A * c * w1 * w1,
            -A * c * w1 * w1 + K2 * y[1].sin(),
            2.0 * A * s * w1,
            0.0,
        ];
        // ∂M12/∂θ1 = −A s, ∂M12/∂θ2 = +A s
        let dm12 = [-A * s, A * s, 0.0, 0.0];
        *j = [[0.0; 4]; 4];
        j[0][2] = 1.0;
        j[1][3] = 1.0;
        for x in 0..4 {
            let b1 = dr1[x] - dm12[x] * a2;
            let b2 = dr2[x] - dm12[x] * a1;
            j[2][x] = (M22 * b1 - m12 * b2) / det;
            j[3][x] = (M11 * b2 - m12 * b1) / det;
        }
    }

    /// Initial state: both bars horizontal at rest.
    pub const Y0: [f64; 4] = [0.0; 4];

    /// The bondmech columns `bar1.x, bar1.y, bar1.angle, bar2.x, bar2.y, bar2.angle`.
    pub const COLUMNS: [&str; 6] = [
        "bar1.x",
        "bar1.y",
        "bar1.angle",
        "bar2.x",
        "bar2.y",
        "bar2.angle",
    ];

    /// The columns of [`COLUMNS`] at state `y`.
    pub fn outputs(y: &[f64]) -> Vec<f64> {
        let (s1, c1) = y[0].sin_cos();
        let (s2, c2) = y[1].sin_cos();
        vec![0.5 * c1, 0.5 * s1, y[0], c1 + 0.5 * c2, s1 + 0.5 * s2, y[1]]
    }
}

/// Slider-crank in the crank angle φ (tests/common/slider_crank.rs):
/// `J(φ) φ̈ = τ + F(φ) y_p′ − V′ − ½ J′ φ̇²`, for the bundled scene (`scenes/slider_crank.json`:
/// 1.5 N·m, gas force −10·max(0, cos φ), released at 60°) and for the smooth one of
/// `../shared/docs/peers.md` (`benches/scenes/peers_slider_crank.json`: 2 N·m, −20 N, 30°).
pub mod slider_crank {
    const R: f64 = 0.1;
    const L: f64 = 0.3;
    const MC: f64 = 1.0;
    const MR: f64 = 0.5;
    const MP: f64 = 0.3;
    const G: f64 = 9.81;

    /// The loads of one slider-crank: torque on the crank, force on the piston at crank angle φ.
    #[derive(Clone, Copy)]
    pub struct Loads {
        /// Constant torque τ on the crank.
        pub torque: f64,
        /// Piston force F(φ) along the cylinder.
        pub force: fn(f64) -> f64,
    }

    /// The bundled scene's loads (1.5 N·m, gas force −10·max(0, cos φ)).
    pub const BUNDLED: Loads = Loads {
        torque: 1.5,
        force: |phi| -10.0 * phi.cos().max(0.0),
    };

    /// The smooth slider-crank's loads (2 N·m, −20 N).
    pub const SMOOTH: Loads = Loads {
        torque: 2.0,
        force: |_| -20.0,
    };

    /// (x_r, y_r, y_p, β) and their first two φ-derivatives (branch σ = +1).
    fn kinematics(phi: f64) -> [[f64; 3]; 4] {
        let (s, c) = phi.sin_cos();
        let bs = (L * L - R * R * c * c).sqrt();
        let s1 = R * R * c * s / bs;
        let s2 = (R * R * (2.0 * phi).cos() - s1 * s1) / bs;
        [
            [0.5 * R * c, -0.5 * R * s, -0.5 * R * c],
            [R * s + 0.5 * bs, R * c + 0.5 * s1, -R * s + 0.5 * s2],
            [R * s + bs, R * c + s1, -R * s + s2],
            [
                bs.atan2(-R * c),
                -R * s / bs,
                -R * (c / bs - s * s1 / (bs * bs)),
            ],
        ]
    }

    /// φ̈ and ∂φ̈/∂φ̇.
    fn acceleration(loads: &Loads, phi: f64, w: f64) -> (f64, f64) {
        let [xr, yr, yp, be] = kinematics(phi);
        let jr = MR * L * L / 12.0;
        let j = MC * R * R / 3.0
            + MR * (xr[1] * xr[1] + yr[1] * yr[1])
            + jr * be[1] * be[1]
            + MP * yp[1] * yp[1];
        let hdj = MR * (xr[1] * xr[2] + yr[1] * yr[2]) + jr * be[1] * be[2] + MP * yp[1] * yp[2];
        let dv = G * (MC * 0.5 * R * phi.cos() + MR * yr[1] + MP * yp[1]);
        (
            (loads.torque + (loads.force)(phi) * yp[1] - dv - hdj * w * w) / j,
            -2.0 * hdj * w / j,
        )
    }

    /// `y' = f(y)`, `y = [φ, φ̇]`.
    pub fn rhs(loads: &Loads, y: &[f64], yd: &mut [f64]) {
        yd[0] = y[1];
        yd[1] = acceleration(loads, y[0], y[1]).0;
    }

    /// `∂f/∂y`: ∂φ̈/∂φ̇ analytic; ∂φ̈/∂φ by a central difference of the analytic φ̈
    /// (h = 1e-7, relative error ~1e-9 — it only steers Newton, never the solution).
    pub fn jacobian(loads: &Loads, y: &[f64], j: &mut [[f64; 2]; 2]) {
        let h = 1e-7;
        let d = (acceleration(loads, y[0] + h, y[1]).0 - acceleration(loads, y[0] - h, y[1]).0)
            / (2.0 * h);
        j[0] = [0.0, 1.0];
        j[1] = [d, acceleration(loads, y[0], y[1]).1];
    }

    /// Initial state of the bundled scene: crank at 60°, at rest.
    pub const Y0: [f64; 2] = [std::f64::consts::FRAC_PI_3, 0.0];

    /// Initial state of the smooth one: crank at 30°, at rest.
    pub const Y0_SMOOTH: [f64; 2] = [std::f64::consts::FRAC_PI_6, 0.0];

    /// The bondmech columns compared.
    pub const COLUMNS: [&str; 7] = [
        "crank.x",
        "crank.y",
        "crank.angle",
        "rod.x",
        "rod.y",
        "rod.angle",
        "piston.y",
    ];

    /// The columns of [`COLUMNS`] at state `y`.
    pub fn outputs(y: &[f64]) -> Vec<f64> {
        let [xr, yr, yp, be] = kinematics(y[0]);
        let (s, c) = y[0].sin_cos();
        vec![0.5 * R * c, 0.5 * R * s, y[0], xr[0], yr[0], be[0], yp[0]]
    }
}

/// `∂f/∂y` of a minimal model: `(y, f(y), set(row, col, value))`.
pub type JacobianFn = fn(&[f64], &[f64], &mut dyn FnMut(usize, usize, f64));

/// A minimal-coordinate model: its size, `f`, `∂f/∂y` (dense, row-major into the callback),
/// initial state and output columns.
#[derive(Clone, Copy)]
pub struct MinimalModel {
    /// Name.
    pub name: &'static str,
    /// Number of states.
    pub n: usize,
    /// Initial state.
    pub y0: &'static [f64],
    /// Right-hand side.
    pub rhs: fn(&[f64], &mut [f64]),
    /// Jacobian: `(y, f(y), set(row, col, value))`.
    pub jacobian: JacobianFn,
    /// Output column names.
    pub columns: &'static [&'static str],
    /// Output values at a state.
    pub outputs: fn(&[f64]) -> Vec<f64>,
}

fn dp_jac(y: &[f64], yd: &[f64], set: &mut dyn FnMut(usize, usize, f64)) {
    let mut j = [[0.0; 4]; 4];
    double_pendulum::jacobian(y, yd, &mut j);
    for (r, row) in j.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            set(r, c, *v);
        }
    }
}

fn sc_jac_with(loads: &slider_crank::Loads, y: &[f64], set: &mut dyn FnMut(usize, usize, f64)) {
    let mut j = [[0.0; 2]; 2];
    slider_crank::jacobian(loads, y, &mut j);
    for (r, row) in j.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            set(r, c, *v);
        }
    }
}

/// The double pendulum.
pub const DOUBLE_PENDULUM: MinimalModel = MinimalModel {
    name: "double_pendulum",
    n: 4,
    y0: &double_pendulum::Y0,
    rhs: double_pendulum::rhs,
    jacobian: dp_jac,
    columns: &double_pendulum::COLUMNS,
    outputs: double_pendulum::outputs,
};

/// The bundled slider-crank.
pub const SLIDER_CRANK: MinimalModel = MinimalModel {
    name: "slider_crank",
    n: 2,
    y0: &slider_crank::Y0,
    rhs: |y, yd| slider_crank::rhs(&slider_crank::BUNDLED, y, yd),
    jacobian: |y, _, set| sc_jac_with(&slider_crank::BUNDLED, y, set),
    columns: &slider_crank::COLUMNS,
    outputs: slider_crank::outputs,
};

/// The smooth slider-crank of `../shared/docs/peers.md`.
pub const PEERS_SLIDER_CRANK: MinimalModel = MinimalModel {
    name: "peers_slider_crank",
    n: 2,
    y0: &slider_crank::Y0_SMOOTH,
    rhs: |y, yd| slider_crank::rhs(&slider_crank::SMOOTH, y, yd),
    jacobian: |y, _, set| sc_jac_with(&slider_crank::SMOOTH, y, set),
    columns: &slider_crank::COLUMNS,
    outputs: slider_crank::outputs,
};

/// A minimal-coordinate solve: rows of [`MinimalModel::columns`] at the output times, steps and
/// integration CPU seconds.
pub struct MinimalRun {
    /// Output rows.
    pub rows: Vec<Vec<f64>>,
    /// CVODE internal steps.
    pub steps: u64,
    /// Jacobian evaluations.
    pub jacobian_evals: u64,
    /// CPU seconds of the solve (this thread, CVODE creation included).
    pub cpu_seconds: f64,
}

/// Solves `m` with CVODE (`Bdf` with the analytic Jacobian, or `Adams`) to each of `times`.
pub fn solve_minimal(
    m: &MinimalModel,
    method: Multistep,
    rtol: f64,
    atol: f64,
    times: &[f64],
) -> MinimalRun {
    let clock = ThreadTime::now();
    let opts = CvodeOptions {
        rtol,
        atol: vec![atol],
        max_steps: Some(1_000_000),
        stop_time: times.last().copied(),
        ..CvodeOptions::default()
    };
    let (f1, f2, jf) = (m.rhs, m.rhs, m.jacobian);
    let n = m.n;
    let rhs = Box::new(move |_t: f64, y: &[f64], yd: &mut [f64]| {
        f1(y, yd);
        Ok(())
    });
    let _ = f2;
    let jac = Box::new(
        move |_t: f64, y: &[f64], fy: &[f64], jm: &mut DenseMatrixMut<'_>| {
            jf(y, fy, &mut |r, c, v| jm.set(r, c, v));
            Ok(())
        },
    );
    let jac = if method == Multistep::Bdf {
        Some(jac as _)
    } else {
        None
    };
    let mut cv = Cvode::new(method, times[0], m.y0, rhs, jac, &opts).expect("CVODE starts");
    let mut rows = vec![(m.outputs)(m.y0)];
    for &t in &times[1..] {
        cv.solve_to(t).expect("CVODE solves");
        rows.push((m.outputs)(&cv.y()[..n]));
    }
    let s = cv.stats();
    MinimalRun {
        rows,
        steps: s.steps,
        jacobian_evals: s.jacobian_evals,
        cpu_seconds: clock.elapsed().as_secs_f64(),
    }
}

/// Solves `m` with ARKODE's explicit Runge–Kutta (the Butcher table bondmech's partitioned
/// formulation picks for `rtol`, `bondmech::sundials::erk::table_for`), landing on each of `times`.
pub fn solve_minimal_erk(m: &MinimalModel, rtol: f64, atol: f64, times: &[f64]) -> MinimalRun {
    let clock = ThreadTime::now();
    let opts = bondmech::sundials::ErkOptions {
        rtol,
        atol,
        max_steps: Some(1_000_000),
        max_total_steps: None,
        max_wall_clock: None,
        stop_time: times.last().copied(),
    };
    let f1 = m.rhs;
    let n = m.n;
    let rhs = Box::new(move |_t: f64, y: &[f64], yd: &mut [f64]| {
        f1(y, yd);
        Ok(())
    });
    let mut e = bondmech::sundials::Erk::new(times[0], m.y0, rhs, &opts).expect("ERK starts");
    let mut rows = vec![(m.outputs)(m.y0)];
    for &t in &times[1..] {
        e.solve_to(t).expect("ERK solves");
        rows.push((m.outputs)(&e.y()[..n]));
    }
    let s = e.stats();
    MinimalRun {
        rows,
        steps: s.steps,
        jacobian_evals: 0,
        cpu_seconds: clock.elapsed().as_secs_f64(),
    }
}

/// Largest |difference| between two row sets over all columns and times.
pub fn max_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
        .fold(0.0, f64::max)
}

/// The rows of `columns` from a bondmech solution.
pub fn bondmech_rows(sol: &bondmech::Solution, columns: &[&str]) -> Vec<Vec<f64>> {
    let idx: Vec<usize> = columns
        .iter()
        .map(|c| {
            sol.columns
                .iter()
                .position(|n| n == c)
                .unwrap_or_else(|| panic!("column {c} missing"))
        })
        .collect();
    sol.rows
        .iter()
        .map(|r| idx.iter().map(|&i| r[i]).collect())
        .collect()
}

/// The loosest rtol of the half-decade grid 1e-4 … 1e-11 whose error, and that of every
/// tighter grid point, is ≤ `target`, with its error; `None` if even 1e-11 misses. `error(rtol)`
/// runs the method (`None`: the run failed).
pub fn matched_rtol(target: f64, error: impl Fn(f64) -> Option<f64>) -> Option<(f64, f64)> {
    let grid: Vec<f64> = (0..=14)
        .map(|i| 10f64.powf(-4.0 - 0.5 * i as f64))
        .collect();
    let errors: Vec<f64> = grid
        .iter()
        .map(|&r| error(r).unwrap_or(f64::INFINITY))
        .collect();
    let mut best = None;
    for i in (0..grid.len()).rev() {
        if errors[i] <= target {
            best = Some((grid[i], errors[i]));
        } else {
            break;
        }
    }
    best
}
