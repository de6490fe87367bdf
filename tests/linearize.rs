//! The linear model (`bondmech linearize`, `bondmech::linearize`) against references derived in
//! minimal coordinates, never by bondmech: the mass and stiffness matrices of a Lagrangian in
//! sympy (`tests/references/linearize_lagrange.py`, its closed forms written below), a
//! one-coordinate four-bar model, and the minimal-coordinate double pendulum of
//! `tests/common/double_pendulum.rs`.

mod common;

use bondmech::{linearize, LinearModel, LinearizeOptions, OperatingPoint, Scene};
use nalgebra::{Complex, DMatrix};
use serde_json::{json, Value};

const G: f64 = 9.81;

fn scene(v: &Value) -> Scene {
    Scene::from_json_str(&v.to_string()).unwrap()
}

fn lin(v: &Value, options: &LinearizeOptions) -> LinearModel {
    linearize(&scene(v), options).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Two uniform bars (m1, L1), (m2, L2) hanging from a pin at the origin and from each other,
/// started `tilt` rad off the vertical (the equilibrium search brings them down).
fn double_pendulum(m1: f64, l1: f64, m2: f64, l2: f64, tilt: f64, frame: &str) -> Value {
    let a1 = -std::f64::consts::FRAC_PI_2 + tilt;
    let a2 = -std::f64::consts::FRAC_PI_2 - 0.5 * tilt;
    let (s1, c1) = a1.sin_cos();
    let (s2, c2) = a2.sin_cos();
    json!({
        "gravity": [0.0, -G],
        "bodies": [
            {"name": "bar1", "mass": m1, "inertia": m1 * l1 * l1 / 12.0, "frame": frame,
             "points": {"O": [-l1 / 2.0, 0.0], "A": [l1 / 2.0, 0.0]},
             "position": [l1 / 2.0 * c1, l1 / 2.0 * s1], "angle": a1},
            {"name": "bar2", "mass": m2, "inertia": m2 * l2 * l2 / 12.0, "frame": frame,
             "points": {"O": [-l2 / 2.0, 0.0], "A": [l2 / 2.0, 0.0]},
             "position": [l1 * c1 + l2 / 2.0 * c2, l1 * s1 + l2 / 2.0 * s2], "angle": a2}
        ],
        "joints": [
            {"name": "pivot", "type": "revolute", "bodies": ["ground", "bar1"],
             "points": [[0.0, 0.0], "O"]},
            {"name": "knee", "type": "revolute", "bodies": ["bar1", "bar2"], "points": ["A", "O"]}
        ],
        "solve": {"t_end": 1.0, "rtol": 1e-10, "atol": 1e-12}
    })
}

/// The sympy Lagrangian's closed forms (angles φ from the downward vertical):
/// `M = [[L1²(m1/3 + m2), m2 L1 L2/2], [m2 L1 L2/2, m2 L2²/3]]`,
/// `K = diag(g L1 (m1 + 2 m2)/2, g L2 m2/2)`; `det(K − ω² M) = 0` solved in closed form, and the
/// mode shape `φ2/φ1 = (K11 − ω² M11)/(ω² M12)` from the first row.
fn double_pendulum_reference(m1: f64, l1: f64, m2: f64, l2: f64) -> [(f64, f64); 2] {
    let m11 = l1 * l1 * (m1 / 3.0 + m2);
    let m12 = m2 * l1 * l2 / 2.0;
    let m22 = m2 * l2 * l2 / 3.0;
    let k11 = G * l1 * (m1 + 2.0 * m2) / 2.0;
    let k22 = G * l2 * m2 / 2.0;
    // (k11 − λ m11)(k22 − λ m22) − λ² m12² = p λ² + q λ + r
    let p = m11 * m22 - m12 * m12;
    let q = -(k11 * m22 + k22 * m11);
    let r = k11 * k22;
    let disc = (q * q - 4.0 * p * r).sqrt();
    // the smaller root without cancellation: λ₁ λ₂ = r / p
    let big = (-q + disc) / (2.0 * p);
    let small = r / (p * big);
    [small, big].map(|l| (l.sqrt(), (k11 - l * m11) / (l * m12)))
}

fn shape(m: &bondmech::analysis::linear_model::Mode, name: &str) -> Complex<f64> {
    m.shape.iter().find(|(n, _)| n == name).unwrap().1
}

#[test]
fn hanging_double_pendulum_frequencies_and_mode_shapes_match_the_lagrangian() {
    let (m1, l1, m2, l2) = (1.3, 0.8, 0.7, 1.1);
    let lm = lin(
        &double_pendulum(m1, l1, m2, l2, 0.3, "inertial"),
        &LinearizeOptions::default(),
    );
    assert_eq!(
        lm.states,
        ["bar1.angle", "bar2.angle", "bar1.omega", "bar2.omega"]
    );
    assert_eq!(lm.modes.len(), 2, "{}", lm.table());
    let want = double_pendulum_reference(m1, l1, m2, l2);
    for (m, (w, ratio)) in lm.modes.iter().zip(want) {
        let got_ratio = shape(m, "bar2.angle") / shape(m, "bar1.angle");
        eprintln!(
            "ω {:.15} vs {w:.15} (rel {:.1e}); shape {:.12} vs {ratio:.12}",
            m.omega_n,
            rel(m.omega_n, w),
            got_ratio.re
        );
        assert!(rel(m.omega_n, w) < 1e-7, "{}", lm.table());
        assert!(m.damping_ratio.unwrap().abs() < 1e-9, "undamped: {m:?}");
        assert!(
            (got_ratio - Complex::new(ratio, 0.0)).norm() < 1e-7 * ratio.abs(),
            "mode shape φ2/φ1 {got_ratio} vs {ratio}"
        );
    }
    // no inputs: B and D are empty, C = I on the states
    assert_eq!((lm.b.nrows(), lm.b.ncols()), (4, 0));
    assert_eq!((lm.d.nrows(), lm.d.ncols()), (4, 0));
    assert_eq!(lm.c, DMatrix::identity(4, 4));
}

/// A uniform bar (m, L) pinned at its end, with a viscous torque `−c ω` and an input torque
/// `tau` (start `tau0`).
fn damped_pendulum(m: f64, l: f64, c: f64, tau0: f64, angle: f64) -> Value {
    let (s, co) = angle.sin_cos();
    json!({
        "gravity": [0.0, -G],
        "inputs": [{"name": "tau", "start": tau0}],
        "bodies": [{"name": "bar", "mass": m, "inertia": m * l * l / 12.0,
                    "points": {"O": [-l / 2.0, 0.0], "A": [l / 2.0, 0.0]},
                    "position": [l / 2.0 * co, l / 2.0 * s], "angle": angle}],
        "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0.0, 0.0], "O"]}],
        "loads": [{"name": "drive", "type": "torque", "body": "bar",
                   "value": format!("-{c}*bar.omega + tau")}],
        "solve": {"t_end": 1.0, "rtol": 1e-12, "atol": 1e-14}
    })
}

#[test]
fn damped_pendulum_natural_frequency_and_damping_ratio() {
    let (m, l, c) = (1.2, 0.9, 0.25);
    let lm = lin(
        &damped_pendulum(m, l, c, 0.0, -1.2),
        &LinearizeOptions::default(),
    );
    // sympy: J = m L²/3, K = m g L/2 about hanging
    let (j, k) = (m * l * l / 3.0, m * G * l / 2.0);
    let (wn, zeta) = ((k / j).sqrt(), c / (2.0 * (k * j).sqrt()));
    assert_eq!(lm.modes.len(), 1, "{}", lm.table());
    let md = &lm.modes[0];
    eprintln!(
        "ω_n {} vs {wn}, ζ {:?} vs {zeta}",
        md.omega_n, md.damping_ratio
    );
    assert!(rel(md.omega_n, wn) < 1e-9);
    assert!(rel(md.damping_ratio.unwrap(), zeta) < 1e-9);
    assert!(rel(md.frequency_hz, wn / (2.0 * std::f64::consts::PI)) < 1e-9);
    assert_eq!(lm.inputs, ["tau"]);
    assert_eq!((lm.b.nrows(), lm.b.ncols()), (2, 1));
}

#[test]
fn transfer_function_from_the_input_torque_to_the_angle() {
    let (m, l, c, tau0) = (1.2, 0.9, 0.25, 1.1);
    let options = LinearizeOptions {
        outputs: vec!["bar.angle".into()],
        ..LinearizeOptions::default()
    };
    let lm = lin(&damped_pendulum(m, l, c, tau0, -1.2), &options);
    // about the equilibrium tilted by the input: K = m g (L/2) cos φ*, sin φ* = τ0 / (m g L/2)
    let j = m * l * l / 3.0;
    let phi = (tau0 / (m * G * l / 2.0)).asin();
    let k = m * G * l / 2.0 * phi.cos();
    for w in [0.3, 4.1, 25.0] {
        let s = Complex::new(0.0, w);
        let want = Complex::new(1.0, 0.0) / (s * s * j + s * c + k);
        let got = lm.frequency_response(w).unwrap()[(0, 0)];
        eprintln!("H({w}i) = {got} vs {want}");
        assert!((got - want).norm() < 1e-6 * want.norm(), "{got} vs {want}");
    }
}

/// Four-bar of `scenes/four_bar.json` (crank 0.1, coupler 0.35, rocker 0.3, ground 0.4) with a
/// spring from the ground point P to the coupler's middle.
const FOUR_BAR: [f64; 4] = [0.1, 0.35, 0.3, 0.4];
const FOUR_BAR_MASS: [f64; 3] = [0.2, 0.5, 0.4];
const SPRING_P: [f64; 2] = [0.1, 0.45];
const SPRING_K: f64 = 60.0;
const SPRING_L0: f64 = 0.12;

/// The one-coordinate model: the coupler and rocker angles (φ, ψ) of crank angle θ by Newton on
/// the loop `a e(θ) + b e(φ) = (d, 0) + c e(ψ)`, their rates per unit θ̇ from its derivative.
fn four_bar_closure(th: f64, guess: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let [a, b, c, d] = FOUR_BAR;
    let [mut ph, mut ps] = guess;
    for _ in 0..50 {
        let r = [
            a * th.cos() + b * ph.cos() - d - c * ps.cos(),
            a * th.sin() + b * ph.sin() - c * ps.sin(),
        ];
        // ∂r/∂(φ, ψ)
        let j = [[-b * ph.sin(), c * ps.sin()], [b * ph.cos(), -c * ps.cos()]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let dph = (r[0] * j[1][1] - r[1] * j[0][1]) / det;
        let dps = (j[0][0] * r[1] - j[1][0] * r[0]) / det;
        ph -= dph;
        ps -= dps;
        if dph.abs() + dps.abs() < 1e-16 {
            break;
        }
    }
    // rates: J (φ', ψ') = −∂r/∂θ
    let j = [[-b * ph.sin(), c * ps.sin()], [b * ph.cos(), -c * ps.cos()]];
    let rt = [-a * th.sin(), a * th.cos()];
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let dph = -(rt[0] * j[1][1] - rt[1] * j[0][1]) / det;
    let dps = -(j[0][0] * rt[1] - j[1][0] * rt[0]) / det;
    ([ph, ps], [dph, dps])
}

/// `(V'(θ), J_eff(θ))` of the one-coordinate four-bar: `V` gravity plus the spring,
/// `J_eff = Σ m |dr/dθ|² + J (dα/dθ)²`, every derivative from the closure's rates (exact).
fn four_bar_model(th: f64, guess: [f64; 2]) -> (f64, f64, [f64; 2]) {
    let [a, b, c, d] = FOUR_BAR;
    let [m1, m2, m3] = FOUR_BAR_MASS;
    let ([ph, ps], [dph, dps]) = four_bar_closure(th, guess);
    let e = |x: f64| [x.cos(), x.sin()];
    let de = |x: f64| [-x.sin(), x.cos()];
    // centres and their derivatives by θ
    let r1 = [a / 2.0 * e(th)[0], a / 2.0 * e(th)[1]];
    let dr1 = [a / 2.0 * de(th)[0], a / 2.0 * de(th)[1]];
    let r2 = [
        a * e(th)[0] + b / 2.0 * e(ph)[0],
        a * e(th)[1] + b / 2.0 * e(ph)[1],
    ];
    let dr2 = [
        a * de(th)[0] + b / 2.0 * de(ph)[0] * dph,
        a * de(th)[1] + b / 2.0 * de(ph)[1] * dph,
    ];
    let dr3 = [c / 2.0 * de(ps)[0] * dps, c / 2.0 * de(ps)[1] * dps];
    let _ = d;
    let n2 = |v: [f64; 2]| v[0] * v[0] + v[1] * v[1];
    let j = m1 * n2(dr1)
        + m1 * a * a / 12.0
        + m2 * n2(dr2)
        + m2 * b * b / 12.0 * dph * dph
        + m3 * n2(dr3)
        + m3 * c * c / 12.0 * dps * dps;
    // V' = g Σ m dy/dθ + k (L − L0) dL/dθ, spring from P to the coupler's centre
    let s = [r2[0] - SPRING_P[0], r2[1] - SPRING_P[1]];
    let len = n2(s).sqrt();
    let dlen = (s[0] * dr2[0] + s[1] * dr2[1]) / len;
    let _ = r1;
    let dv = G * (m1 * dr1[1] + m2 * dr2[1] + m3 * dr3[1]) + SPRING_K * (len - SPRING_L0) * dlen;
    (dv, j, [ph, ps])
}

fn four_bar_scene() -> Value {
    let mut s: Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/four_bar.json"))
            .unwrap(),
    )
    .unwrap();
    s["springs"] = json!([{"name": "spring", "bodies": ["ground", "coupler"],
                           "points": [SPRING_P, [0.0, 0.0]],
                           "stiffness": SPRING_K, "rest_length": SPRING_L0}]);
    s["solve"]["rtol"] = json!(1e-10);
    s["solve"]["atol"] = json!(1e-12);
    s
}

#[test]
fn four_bar_with_a_spring_oscillates_at_the_one_coordinate_frequency() {
    let lm = lin(&four_bar_scene(), &LinearizeOptions::default());
    assert_eq!(lm.states.len(), 2, "one DOF: {:?}", lm.states);
    // the equilibrium: V'(θ) = 0 by Newton on the one-coordinate model from the scene's 60°
    let guess0 = [0.6287151276455405, 1.7957749733962085];
    let dvj = |th: f64| four_bar_model(th, guess0);
    let d = |f: &dyn Fn(f64) -> f64, x: f64, h: f64| {
        let c = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
        c.iter()
            .enumerate()
            .map(|(k, ck)| {
                let s = (k + 1) as f64 * h;
                ck * (f(x + s) - f(x - s)) / h
            })
            .sum::<f64>()
    };
    let dv = |th: f64| dvj(th).0;
    let mut th = 60f64.to_radians();
    for _ in 0..100 {
        let step = dv(th) / d(&dv, th, 1e-4);
        th -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    let th = th.rem_euclid(std::f64::consts::TAU);
    let got_th = lm
        .operating_point
        .iter()
        .find(|(n, _)| n == "crank.angle")
        .unwrap()
        .1
        .rem_euclid(std::f64::consts::TAU);
    let k = d(&dv, th, 1e-3);
    let j = dvj(th).1;
    let w = (k / j).sqrt();
    eprintln!(
        "four-bar: θ* {got_th} vs {th}; V'' {k}, J {j}; ω {} vs {w}",
        lm.modes[0].omega_n
    );
    assert!((got_th - th).abs() < 1e-9, "equilibrium {got_th} vs {th}");
    assert!(k > 0.0, "a stable equilibrium");
    assert_eq!(lm.modes.len(), 1, "{}", lm.table());
    assert!(rel(lm.modes[0].omega_n, w) < 1e-7, "{}", lm.table());
}

fn eigenvalues(lm: &LinearModel) -> Vec<f64> {
    lm.modes.iter().map(|m| m.omega_n).collect()
}

#[test]
fn eigenvalues_do_not_depend_on_the_partition_or_the_body_frame() {
    let (m1, l1, m2, l2) = (1.3, 0.8, 0.7, 1.1);
    let base = lin(
        &double_pendulum(m1, l1, m2, l2, 0.3, "inertial"),
        &LinearizeOptions::default(),
    );
    let others = [
        lin(
            &double_pendulum(m1, l1, m2, l2, 0.3, "inertial"),
            &LinearizeOptions {
                states: Some(vec!["bar1.x".into(), "bar2.x".into()]),
                ..LinearizeOptions::default()
            },
        ),
        lin(
            &double_pendulum(m1, l1, m2, l2, 0.3, "inertial"),
            &LinearizeOptions {
                states: Some(vec!["bar1.x".into(), "bar2.angle".into()]),
                ..LinearizeOptions::default()
            },
        ),
        lin(
            &double_pendulum(m1, l1, m2, l2, 0.3, "body"),
            &LinearizeOptions::default(),
        ),
    ];
    let want = eigenvalues(&base);
    for o in &others {
        let got = eigenvalues(o);
        eprintln!("states {:?}: {got:?} vs {want:?}", o.states);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!(rel(*g, *w) < 1e-9, "{g} vs {w}: {}", o.table());
        }
    }
    assert_eq!(others[0].states[..2], ["bar1.x", "bar2.x"]);
    // (away from an equilibrium the eigenvalues of A are not invariant: in other coordinates
    // y = φ(x) the Jacobian gains d/dt(φ') (φ')⁻¹ along the motion, which vanishes only at
    // rest; there A itself is checked against the minimal-coordinate model below.) In the same
    // states, the body-fixed frame (velocities u, w along the bars, q' = K(q) v) gives the
    // inertial frame's A at t = 0.4 after release, to the accuracy of the two solves
    let at = LinearizeOptions {
        at: OperatingPoint::Time(0.4),
        ..LinearizeOptions::default()
    };
    let inertial = lin(&double_pendulum(m1, l1, m2, l2, 1.0, "inertial"), &at);
    let body = lin(&double_pendulum(m1, l1, m2, l2, 1.0, "body"), &at);
    assert_eq!(inertial.states, body.states);
    let scale = inertial.a.amax();
    let diff = (&inertial.a - &body.a).amax();
    eprintln!("A at t = 0.4, inertial vs body frame: {diff:.1e} (of {scale:.1})");
    assert!(diff < 1e-6 * scale, "{} vs {}", inertial.a, body.a);
}

#[test]
fn away_from_equilibrium_a_is_the_jacobian_of_the_minimal_coordinate_model() {
    let (m1, l1, m2, l2) = (1.3, 0.8, 0.7, 1.1);
    let lm = lin(
        &double_pendulum(m1, l1, m2, l2, 1.0, "inertial"),
        &LinearizeOptions {
            at: OperatingPoint::Time(0.4),
            ..LinearizeOptions::default()
        },
    );
    let value = |n: &str| lm.operating_point.iter().find(|(k, _)| k == n).unwrap().1;
    let y = [
        value("bar1.angle"),
        value("bar2.angle"),
        value("bar1.omega"),
        value("bar2.omega"),
    ];
    assert!(y[2].abs() > 0.5, "moving: {y:?}");
    // the reference: Lagrange's equations in (θ1, θ2) (tests/common/double_pendulum.rs), its
    // Jacobian by 8th-order central differences of that closed form
    let dp = common::double_pendulum::DoublePendulum {
        m1,
        l1,
        m2,
        l2,
        g: G,
    };
    let f = |y: [f64; 4]| {
        let (a1, a2) = dp.accelerations(y[0], y[1], y[2], y[3]);
        [y[2], y[3], a1, a2]
    };
    let h = 1e-3;
    let c = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
    for col in 0..4 {
        let mut d = [0.0; 4];
        for (k, ck) in c.iter().enumerate() {
            let s = (k + 1) as f64 * h;
            let (mut yp, mut ym) = (y, y);
            yp[col] += s;
            ym[col] -= s;
            let (fp, fm) = (f(yp), f(ym));
            for r in 0..4 {
                d[r] += ck * (fp[r] - fm[r]) / h;
            }
        }
        for (r, want) in d.iter().enumerate() {
            let got = lm.a[(r, col)];
            assert!(
                (got - want).abs() < 1e-8 * (1.0 + want.abs()),
                "A[{r},{col}] = {got} vs {want}"
            );
        }
    }
    // not an equilibrium's A: the velocity terms are there
    assert!(
        lm.a[(2, 2)].abs() > 1e-3 || lm.a[(2, 3)].abs() > 1e-3,
        "{}",
        lm.a
    );
}

/// `θ(t) − θ*` of the nonlinear run with the input stepped by `du` at t = 0, and the linear
/// model's `C x(t)`, `x(t) = A⁻¹ (e^{At} − I) B du`; the largest difference over the rows.
fn step_difference(du: f64) -> f64 {
    let (m, l, c, tau0) = (1.2, 0.9, 0.25, 1.1);
    let phi = (tau0 / (m * G * l / 2.0)).asin();
    let th = -std::f64::consts::FRAC_PI_2 + phi;
    let base = damped_pendulum(m, l, c, tau0, th);
    let lm = lin(
        &base,
        &LinearizeOptions {
            outputs: vec!["bar.angle".into()],
            ..LinearizeOptions::default()
        },
    );
    let mut stepped = base.clone();
    stepped["inputs"][0]["start"] = json!(tau0 + du);
    stepped["solve"]["t_end"] = json!(3.0);
    stepped["solve"]["output_step"] = json!(0.05);
    let model = bondmech::Model::new(&scene(&stepped)).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    let col = sol.columns.iter().position(|c| c == "bar.angle").unwrap();
    let ainv = lm.a.clone().try_inverse().unwrap();
    let mut worst = 0.0f64;
    for (t, row) in sol.times.iter().zip(&sol.rows) {
        let e = (lm.a.clone() * *t).exp();
        let x = &ainv * (e - DMatrix::identity(2, 2)) * &lm.b * du;
        let y = (&lm.c * x)[(0, 0)];
        worst = worst.max((row[col] - th - y).abs());
    }
    worst
}

#[test]
fn step_response_agrees_with_the_nonlinear_run_to_second_order() {
    let d1 = step_difference(1e-4);
    let d2 = step_difference(5e-5);
    eprintln!("step 1e-4: {d1:.3e}, 5e-5: {d2:.3e}, ratio {:.3}", d1 / d2);
    assert!(d1 < 1e-7, "small against the response (~2e-5)");
    assert!((d1 / d2 - 4.0).abs() < 0.3, "ratio {}", d1 / d2);
}

#[test]
fn bad_requests_are_refused_naming_what_is_wrong() {
    let e = "t=abc".parse::<OperatingPoint>().unwrap_err().to_string();
    assert!(
        e.contains("--at 't=abc'") && e.contains("'abc' is not a number"),
        "{e}"
    );
    let e = "middle".parse::<OperatingPoint>().unwrap_err().to_string();
    assert!(e.contains("expected 'equilibrium' or 't=T'"), "{e}");
    assert_eq!(
        " t=0.25 ".parse::<OperatingPoint>().unwrap(),
        OperatingPoint::Time(0.25)
    );
    let s = scene(&double_pendulum(1.0, 1.0, 1.0, 1.0, 0.0, "inertial"));
    let e = linearize(
        &s,
        &LinearizeOptions {
            outputs: vec!["bar3.angle".into()],
            ..LinearizeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("--output 'bar3.angle'")
            && e.contains("not a column")
            && e.contains("bar2.angle"),
        "{e}"
    );
    let e = linearize(
        &s,
        &LinearizeOptions {
            at: OperatingPoint::Time(-1.0),
            ..LinearizeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("before the scene's start"), "{e}");
    let e = linearize(
        &s,
        &LinearizeOptions {
            states: Some(vec!["bar1.angle".into()]),
            ..LinearizeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("states: 1 independent coordinates given, the joints leave 2"),
        "{e}"
    );
    // a spatial rigid body is no longer refused (issue 48): its attitude is linearized in a
    // rotation-vector chart (tests/linearize_spatial.rs checks the numbers); the bundled top,
    // tilted and spinning, is a moving operating point
    let top = Scene::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/heavy_top.json"
    ))
    .unwrap();
    let lm = linearize(
        &top,
        &LinearizeOptions {
            at: OperatingPoint::Time(0.0),
            ..LinearizeOptions::default()
        },
    )
    .unwrap();
    assert!(!lm.equilibrium);
    assert_eq!(lm.states.len(), 6, "{:?}", lm.states);
    assert!(lm.states.iter().any(|s| s == "top.rx"), "{:?}", lm.states);
    assert!(
        lm.states.iter().all(|s| !s.contains(".e")),
        "{:?}",
        lm.states
    );
}

#[test]
fn cli_writes_the_json_document_and_refuses_bad_flags() {
    let exe = env!("CARGO_BIN_EXE_bondmech");
    let dir = std::env::temp_dir().join(format!("bondmech-linearize-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene_path = dir.join("dp.json");
    std::fs::write(
        &scene_path,
        double_pendulum(1.3, 0.8, 0.7, 1.1, 0.3, "inertial").to_string(),
    )
    .unwrap();
    let json_path = dir.join("lin.json");
    let out = std::process::Command::new(exe)
        .args(["linearize", scene_path.to_str().unwrap(), "--json"])
        .arg(&json_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("omega_n") && text.contains("bar2.angle"),
        "{text}"
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    for key in [
        "at",
        "operating_point",
        "states",
        "inputs",
        "outputs",
        "A",
        "B",
        "C",
        "D",
        "modes",
    ] {
        assert!(doc.get(key).is_some(), "{key} missing: {doc}");
    }
    let want = double_pendulum_reference(1.3, 0.8, 0.7, 1.1);
    let w0 = doc["modes"][0]["omega_n"].as_f64().unwrap();
    assert!(rel(w0, want[0].0) < 1e-7);
    assert_eq!(doc["B"], json!([[], [], [], []]));
    for (flag, value, expect) in [
        ("--at", "t=x", "--at 't=x'"),
        ("--output", "nope", "--output 'nope'"),
    ] {
        let out = std::process::Command::new(exe)
            .args(["linearize", scene_path.to_str().unwrap(), flag, value])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(expect), "{err}");
    }
    // the Bode plot: refused without inputs, drawn with one (a resonance marked)
    let bode = dir.join("bode.svg");
    let out = std::process::Command::new(exe)
        .args(["linearize", scene_path.to_str().unwrap(), "--bode"])
        .arg(&bode)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("no inputs"), "{err}");
    let damped = dir.join("damped.json");
    std::fs::write(
        &damped,
        damped_pendulum(1.2, 0.9, 0.25, 0.0, -1.2).to_string(),
    )
    .unwrap();
    let out = std::process::Command::new(exe)
        .args([
            "linearize",
            damped.to_str().unwrap(),
            "--output",
            "bar.angle",
            "--bode",
        ])
        .arg(&bode)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(&bode).unwrap();
    assert!(
        svg.contains("tau → bar.angle") && svg.contains("mode 1") && svg.contains("magnitude (dB)"),
        "{}",
        &svg[..svg.len().min(400)]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The isosceles slider-crank (rod as long as the crank, `tests/singular_slider_crank.rs`) at its
/// bifurcation φ = 0: the joints' Jacobian loses rank there, so no partition exists.
#[test]
fn a_singular_configuration_is_refused_saying_so() {
    let r: f64 = 0.1;
    let h = r / 2.0;
    let s = json!({
        "gravity": [0.0, -G],
        "bodies": [
            {"name": "crank", "mass": 1.0, "inertia": r * r / 12.0,
             "points": {"O": [-h, 0.0], "A": [h, 0.0]}, "position": [h, 0.0], "angle": 0.0},
            {"name": "rod", "mass": 0.5, "inertia": 0.5 * r * r / 12.0,
             "points": {"O": [-h, 0.0], "A": [h, 0.0]}, "position": [h, 0.0],
             "angle": std::f64::consts::PI},
            {"name": "piston", "mass": 0.3, "inertia": 0.0, "position": [0.0, 0.0], "angle": 0.0}
        ],
        "joints": [
            {"name": "main", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0.0, 0.0], "O"]},
            {"name": "crankpin", "type": "revolute", "bodies": ["crank", "rod"], "points": ["A", "O"]},
            {"name": "wristpin", "type": "revolute", "bodies": ["rod", "piston"], "points": ["A", [0.0, 0.0]]},
            {"name": "cylinder", "type": "prismatic", "bodies": ["ground", "piston"],
             "points": [[0.0, 0.0], [0.0, 0.0]], "axis": [0.0, 1.0]}
        ],
        "loads": [{"type": "torque", "body": "crank", "value": 2.0}],
        "solve": {"t_end": 1.0}
    });
    let e = linearize(
        &scene(&s),
        &LinearizeOptions {
            at: OperatingPoint::Time(0.0),
            ..LinearizeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    eprintln!("{e}");
    assert!(
        e.contains("the operating point (t = 0) has no linearization in these states")
            && e.contains("singular"),
        "{e}"
    );
}

/// A driver's effort column is an output: the double pendulum with its knee held straight by a
/// driver (`angle` 0) swings as one compound pendulum, and the torque the knee's motor gives
/// bar 2 follows bar 2's moment balance about the knee, `τ = (J2 + m2 (L2/2) d2) α + m2 g (L2/2) φ`
/// with `d2 = L1 + L2/2` and `α = −ω² φ`, `ω² = g (m1 L1/2 + m2 d2) / (m1 L1²/3 + J2 + m2 d2²)`.
#[test]
fn a_drivers_torque_is_an_output() {
    let (m1, l1, m2, l2) = (1.3, 0.8, 0.7, 1.1);
    let mut s = double_pendulum(m1, l1, m2, l2, 0.0, "inertial");
    s["bodies"][0]["angle"] = json!(-1.2);
    s["bodies"][1]["angle"] = json!(-1.2);
    s["drivers"] = json!([{"name": "motor", "joint": "knee", "angle": "0"}]);
    let lm = lin(
        &s,
        &LinearizeOptions {
            outputs: vec!["motor.torque".into(), "bar1.angle".into()],
            ..LinearizeOptions::default()
        },
    );
    assert_eq!(lm.states.len(), 2, "{:?}", lm.states);
    let j2 = m2 * l2 * l2 / 12.0;
    let d2 = l1 + l2 / 2.0;
    let w2 = G * (m1 * l1 / 2.0 + m2 * d2) / (m1 * l1 * l1 / 3.0 + j2 + m2 * d2 * d2);
    assert!(rel(lm.modes[0].omega_n, w2.sqrt()) < 1e-9, "{}", lm.table());
    let want = -(j2 + m2 * l2 / 2.0 * d2) * w2 + m2 * G * l2 / 2.0;
    // torque per unit of the swing angle (the state whose C row is the angle's)
    let k = (0..lm.states.len())
        .max_by(|&a, &b| lm.c[(1, a)].abs().total_cmp(&lm.c[(1, b)].abs()))
        .unwrap();
    let got = lm.c[(0, k)] / lm.c[(1, k)];
    eprintln!("dτ/dφ {got} vs {want}");
    // both counter-clockwise: the motor's torque on bar 2 and the angles
    assert!(rel(got, want) < 1e-9, "{got} vs {want}");
    assert_eq!((lm.d.nrows(), lm.d.ncols()), (2, 0));
}
