//! Issue 48: the analyses right at their edges — reactions under drivers, conflicting drivers,
//! repeated modes, spatial equilibrium, moving operating points, the stiffness's units — each
//! against a reference derived here by hand (Newton–Euler, closed forms, a separately written
//! minimal model), never from bondmech's output.

use bondmech::{
    linearize, FormulationKind, LinearizeOptions, Model, OperatingPoint, Scene, Solution,
};
use serde_json::{json, Value};

const G: f64 = 9.81;

fn scene(v: &Value) -> Scene {
    Scene::from_json_str(&v.to_string()).unwrap()
}

fn solve(v: &Value, f: FormulationKind) -> Solution {
    let model = Model::new(&scene(v)).unwrap();
    let mut o = model.default_options();
    o.formulation = f;
    model.solve(&o).unwrap_or_else(|e| panic!("{f:?}: {e}"))
}

fn col(sol: &Solution, name: &str) -> Vec<f64> {
    sol.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", sol.columns))
}

const FOUR: [FormulationKind; 4] = [
    FormulationKind::Dae,
    FormulationKind::Index1,
    FormulationKind::Ggl,
    FormulationKind::Partitioned,
];

/// `(cos θ, sin θ)`.
fn u(th: f64) -> [f64; 2] {
    [th.cos(), th.sin()]
}

/// The acceleration of the point at distance `a` along a body at angle `θ` (rate `ω`,
/// acceleration `α`) from a point that does not accelerate: `a (α u⊥ − ω² u)`.
fn swing(a: f64, th: f64, w: f64, al: f64) -> [f64; 2] {
    let [c, s] = u(th);
    [a * (-al * s - w * w * c), a * (al * c - w * w * s)]
}

/// The largest |got − want| over the rows, and the largest |want|.
fn error_and_peak(got: &[f64], want: &[f64]) -> (f64, f64) {
    let err = got
        .iter()
        .zip(want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let peak = want.iter().fold(0.0f64, |m, w| m.max(w.abs()));
    (err, peak)
}

// ---------------------------------------------------------------------------------------------
// 1. Reactions under drivers, on every formulation, against Newton–Euler
// ---------------------------------------------------------------------------------------------

/// A bar (1.5 kg, 0.8 m, uniform) pinned at its end O to the origin and driven at
/// `ω(t) = 2 + sin 3t` from `t₀ = 0.3`: `θ(t) = θ₀ + 2 (t − t₀) − (cos 3t − cos 3t₀)/3`,
/// `α = 3 cos 3t`. Newton on the bar: `F_pin + m g = m a_c`, `a_c` the centre's acceleration
/// about the fixed pin; the motor's torque about O: `τ = J_O α + m g (L/2) cos θ`
/// (`J_O = m L²/3`, gravity along −y).
#[test]
fn reactions_of_a_driven_bar_follow_newton_euler_on_every_formulation() {
    let (m, l, t0, th0) = (1.5, 0.8, 0.3, -0.4f64);
    let a = l / 2.0;
    let bar = json!({
        "name": "driven_bar", "gravity": [0, -G],
        "bodies": [{"name": "bar", "mass": m, "inertia": m * l * l / 12.0,
                    "points": {"O": [-a, 0], "A": [a, 0]},
                    "position": [a * th0.cos(), a * th0.sin()], "angle": th0}],
        "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0, 0], "O"]}],
        "drivers": [{"name": "motor", "joint": "pivot", "angular_velocity": "2 + sin(3*t)"}],
        "solve": {"t_start": t0, "t_end": 4.0, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10},
        "outputs": ["reactions"]
    });
    let theta = |t: f64| th0 + 2.0 * (t - t0) - ((3.0 * t).cos() - (3.0 * t0).cos()) / 3.0;
    for f in FOUR {
        let sol = solve(&bar, f);
        let ts = sol.times.clone();
        let (mut fx, mut fy, mut tau) = (Vec::new(), Vec::new(), Vec::new());
        for &t in &ts {
            let (th, w, al) = (theta(t), 2.0 + (3.0 * t).sin(), 3.0 * (3.0 * t).cos());
            let ac = swing(a, th, w, al);
            fx.push(m * ac[0]);
            fy.push(m * ac[1] + m * G);
            tau.push(m * l * l / 3.0 * al + m * G * a * th.cos());
        }
        for (name, want) in [("pivot.Fx", &fx), ("pivot.Fy", &fy), ("motor.torque", &tau)] {
            let (err, peak) = error_and_peak(&col(&sol, name), want);
            eprintln!(
                "driven bar, {f:?}: {name} off Newton–Euler by {err:.2e} of {peak:.3} ({:.1e} of the peak; {} steps)",
                err / peak,
                sol.summary.steps
            );
            assert!(err <= 1e-6 * peak, "{f:?} {name}: {err:e} of {peak}");
        }
    }
}

/// A two-link arm driven in both joints: the shoulder's angle `θ₁(t) = −1 + ½ sin 2t`, the
/// elbow's rate `φ' = 1.5 + cos t` (`φ = 0.4 + 1.5 t + sin t`, `θ₂ = θ₁ + φ`). Centres
/// `c₁ = a₁ u(θ₁)`, `c₂ = L₁ u(θ₁) + a₂ u(θ₂)`; Newton on bar 2 gives the elbow's force on
/// it, `F_e = m₂ c₂'' − m₂ g`, on bar 1 the shoulder's, `F_s = m₁ c₁'' − m₁ g + F_e`; the
/// elbow motor's torque on bar 2 is its moment balance about the elbow,
/// `τ_e = J₂ θ₂'' + a₂ u⊥(θ₂) × … = J₂ θ₂'' + (r₂ × m₂ (c₂'' − g))` with `r₂ = a₂ u(θ₂)`.
/// `partitioned` (DOF 0) must run to the end (it failed at t = 0.8 calling it invalid input).
#[test]
fn reactions_of_a_doubly_driven_arm_follow_newton_euler_on_every_formulation() {
    let (m1, l1, m2, l2) = (1.2, 0.7, 0.8, 0.5);
    let (a1, a2) = (l1 / 2.0, l2 / 2.0);
    let (j1, j2) = (m1 * l1 * l1 / 12.0, m2 * l2 * l2 / 12.0);
    let th1 = |t: f64| -1.0 + 0.5 * (2.0 * t).sin();
    let phi = |t: f64| 0.4 + 1.5 * t + t.sin();
    let (t1, t2) = (th1(0.0), th1(0.0) + phi(0.0));
    let arm = json!({
        "name": "driven_arm", "gravity": [0, -G],
        "bodies": [
            {"name": "upper", "mass": m1, "inertia": j1, "points": {"O": [-a1, 0], "A": [a1, 0]},
             "position": [a1 * t1.cos(), a1 * t1.sin()], "angle": t1},
            {"name": "fore", "mass": m2, "inertia": j2, "points": {"O": [-a2, 0], "A": [a2, 0]},
             "position": [l1 * t1.cos() + a2 * t2.cos(), l1 * t1.sin() + a2 * t2.sin()],
             "angle": t2}],
        "joints": [
            {"name": "shoulder", "type": "revolute", "bodies": ["ground", "upper"],
             "points": [[0, 0], "O"]},
            {"name": "elbow", "type": "revolute", "bodies": ["upper", "fore"],
             "points": ["A", "O"]}],
        "drivers": [
            {"name": "lift", "joint": "shoulder", "angle": "-1 + 0.5*sin(2*t)"},
            {"name": "bend", "joint": "elbow", "angular_velocity": "1.5 + cos(t)"}],
        "solve": {"t_end": 3.0, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10},
        "outputs": ["reactions"]
    });
    for f in FOUR {
        let sol = solve(&arm, f);
        assert!(sol.summary.completed, "{f:?}: {:?}", sol.summary);
        let ts = sol.times.clone();
        assert!(
            (ts.last().unwrap() - 3.0).abs() < 1e-12,
            "{f:?} reached {ts:?}"
        );
        let mut want: [Vec<f64>; 5] = Default::default();
        for &t in &ts {
            let (w1, al1) = ((2.0 * t).cos(), -2.0 * (2.0 * t).sin());
            let (w2, al2) = (w1 + 1.5 + t.cos(), al1 - t.sin());
            let (p1, p2) = (th1(t), th1(t) + phi(t));
            let c1 = swing(a1, p1, w1, al1);
            let elbow = swing(l1, p1, w1, al1);
            let rel = swing(a2, p2, w2, al2);
            let c2 = [elbow[0] + rel[0], elbow[1] + rel[1]];
            let fe = [m2 * c2[0], m2 * c2[1] + m2 * G];
            let fs = [m1 * c1[0] + fe[0], m1 * c1[1] + m1 * G + fe[1]];
            // bar 2 about its centre: J₂ α₂ = τ_e + (r_e × F_e), r_e = −a₂ u(θ₂) (the elbow
            // point from the centre)
            let re = [-a2 * p2.cos(), -a2 * p2.sin()];
            let tau_e = j2 * al2 - (re[0] * fe[1] - re[1] * fe[0]);
            for (k, v) in [fs[0], fs[1], fe[0], fe[1], tau_e].into_iter().enumerate() {
                want[k].push(v);
            }
        }
        let names = [
            "shoulder.Fx",
            "shoulder.Fy",
            "elbow.Fx",
            "elbow.Fy",
            "bend.torque",
        ];
        for (name, want) in names.iter().zip(&want) {
            let (err, peak) = error_and_peak(&col(&sol, name), want);
            eprintln!(
                "driven arm, {f:?}: {name} off Newton–Euler by {err:.2e} of {peak:.3} ({:.1e} of the peak)",
                err / peak
            );
            assert!(err <= 1e-6 * peak, "{f:?} {name}: {err:e} of {peak}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 2. Drivers that over-constrain the mechanism
// ---------------------------------------------------------------------------------------------

fn four_bar_with(drivers: Value) -> Value {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/four_bar.json"))
            .unwrap();
    let mut s: Value = serde_json::from_str(&text).unwrap();
    s["drivers"] = drivers;
    s["solve"]["t_end"] = json!(1.0);
    s
}

fn refusal(v: &Value, f: FormulationKind) -> String {
    let model = Model::new(&scene(v)).unwrap();
    let mut o = model.default_options();
    o.formulation = f;
    match model.solve(&o) {
        Ok(sol) => panic!("{f:?} accepted: {:?}", sol.summary.warnings),
        Err(e) => e.to_string(),
    }
}

/// The one-DOF four-bar with its crank driven at 5 rad/s and its rocker at 1 rad/s: refused at
/// the start on every formulation, naming both drivers, their joints and the loop's joints.
#[test]
fn conflicting_drivers_are_refused_naming_the_drivers_and_the_joints_they_fight_over() {
    let s = four_bar_with(json!([
        {"name": "crank_motor", "joint": "crank_pivot", "angular_velocity": 5},
        {"name": "rocker_motor", "joint": "rocker_pivot", "angular_velocity": 1}
    ]));
    for f in [
        FormulationKind::Dae,
        FormulationKind::Index1,
        FormulationKind::Ggl,
        FormulationKind::Partitioned,
        FormulationKind::Decoupled,
    ] {
        let e = refusal(&s, f);
        eprintln!("{f:?}: {e}");
        for name in [
            "drivers[0] 'crank_motor' (joint 'crank_pivot')",
            "drivers[1] 'rocker_motor' (joint 'rocker_pivot')",
            "over-constrain",
            "crank_coupler",
            "coupler_rocker",
        ] {
            assert!(e.contains(name), "{f:?}: {name} not in {e}");
        }
    }
}

/// The same motion prescribed twice — a parallelogram four-bar (crank = rocker, coupler =
/// ground link), whose rocker turns exactly as its crank, driven at 5 rad/s at both — is
/// refused just the same (documented: bondmech does not assume two drivers agree for ever).
#[test]
fn compatible_redundant_drivers_are_refused_as_consistently_as_conflicting_ones() {
    let (r, d, th) = (0.1f64, 0.3, 1.0f64);
    let c = [r * th.cos(), r * th.sin()];
    let bar = |name: &str, m: f64, l: f64, pos: [f64; 2], angle: f64| {
        json!({"name": name, "mass": m, "inertia": m * l * l / 12.0,
               "points": {"O": [-l / 2.0, 0], "A": [l / 2.0, 0]},
               "position": pos, "angle": angle})
    };
    let s = json!({
        "name": "parallelogram", "gravity": [0, -G],
        "bodies": [
            bar("crank", 0.2, r, [c[0] / 2.0, c[1] / 2.0], th),
            bar("coupler", 0.5, d, [c[0] + d / 2.0, c[1]], 0.0),
            bar("rocker", 0.2, r, [d + c[0] / 2.0, c[1] / 2.0], th)],
        "joints": [
            {"name": "crank_pivot", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0, 0], "O"]},
            {"name": "crank_coupler", "type": "revolute", "bodies": ["crank", "coupler"], "points": ["A", "O"]},
            {"name": "coupler_rocker", "type": "revolute", "bodies": ["coupler", "rocker"], "points": ["A", "A"]},
            {"name": "rocker_pivot", "type": "revolute", "bodies": ["ground", "rocker"], "points": [[d, 0], "O"]}],
        "drivers": [
            {"name": "m1", "joint": "crank_pivot", "angular_velocity": 5},
            {"name": "m2", "joint": "rocker_pivot", "angular_velocity": 5}],
        "solve": {"t_end": 1.0, "output_step": 0.01}
    });
    for f in [
        FormulationKind::Dae,
        FormulationKind::Ggl,
        FormulationKind::Partitioned,
    ] {
        let e = refusal(&s, f);
        eprintln!("{f:?}: {e}");
        assert!(
            e.contains("drivers[0] 'm1'")
                && e.contains("drivers[1] 'm2'")
                && e.contains("over-constrain"),
            "{f:?}: {e}"
        );
    }
    // one of them alone drives it (DOF 0), the rocker turning with the crank
    let mut one = s.clone();
    one["drivers"] = json!([{"name": "m1", "joint": "crank_pivot", "angular_velocity": 5}]);
    let sol = solve(&one, FormulationKind::Dae);
    let (crank, rocker) = (col(&sol, "crank.angle"), col(&sol, "rocker.angle"));
    let ts = sol.times.clone();
    for k in 0..ts.len() {
        assert!((crank[k] - (th + 5.0 * ts[k])).abs() < 1e-8);
        assert!(
            (rocker[k] - crank[k]).abs() < 1e-8,
            "parallelogram at {}",
            ts[k]
        );
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Repeated eigenvalues: a basis of the eigenspace
// ---------------------------------------------------------------------------------------------

fn spherical_pendulum(l: f64, position: [f64; 3], velocity: [f64; 3], t_end: f64) -> Value {
    json!({
        "name": "spherical_pendulum", "dimension": 3, "gravity": [0, 0, -G],
        "bodies": [{"name": "bob", "mass": 1.0, "inertia": [0, 0, 0],
                    "position": position, "velocity": velocity}],
        "joints": [{"name": "rod", "type": "distance", "bodies": ["ground", "bob"],
                    "points": [[0, 0, 0], [0, 0, 0]], "length": l}],
        "solve": {"t_end": t_end, "output_step": 0.01, "rtol": 1e-10, "atol": 1e-12}
    })
}

/// `|⟨a, b⟩| / (|a| |b|)` of two complex shapes.
fn cosine(a: &[(String, nalgebra::Complex<f64>)], b: &[(String, nalgebra::Complex<f64>)]) -> f64 {
    let dot = a
        .iter()
        .zip(b)
        .fold(nalgebra::Complex::new(0.0, 0.0), |s, (x, y)| {
            s + x.1.conj() * y.1
        });
    let n = |v: &[(String, nalgebra::Complex<f64>)]| {
        v.iter().map(|x| x.1.norm_sqr()).sum::<f64>().sqrt()
    };
    dot.norm() / (n(a) * n(b))
}

/// A spherical pendulum hanging at rest: two modes at `√(g/L)`, each of multiplicity 2, their
/// shapes independent (the two swing planes).
#[test]
fn repeated_modes_of_a_hanging_spherical_pendulum_are_independent() {
    let l = 1.3;
    let s = spherical_pendulum(l, [0.0, 0.0, -l], [0.0; 3], 1.0);
    let lm = linearize(&scene(&s), &LinearizeOptions::default()).unwrap();
    eprintln!("{}", lm.table());
    let w = (G / l).sqrt();
    assert_eq!(lm.modes.len(), 2, "{}", lm.table());
    for m in &lm.modes {
        assert!((m.omega_n - w).abs() < 1e-9 * w, "{}", lm.table());
        assert_eq!(m.multiplicity, 2);
    }
    let c = cosine(&lm.modes[0].shape, &lm.modes[1].shape);
    eprintln!("|cosine| of the two shapes: {c:.2e}");
    assert!(c <= 0.5, "{}", lm.table());
    let json = lm.to_json();
    assert_eq!(json["modes"][0]["multiplicity"], 2);
}

// ---------------------------------------------------------------------------------------------
// 4. Spatial: equilibrium with unit quaternions under the run's column names; conical motion
// ---------------------------------------------------------------------------------------------

/// The heavy top's equilibrium reports its attitude as the run CSV does: `top.qw … top.qz`, a
/// unit quaternion, no `e0…e3`.
#[test]
fn spatial_equilibrium_reports_unit_quaternions_under_the_run_column_names() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/heavy_top.json"
    ))
    .unwrap();
    let sc = Scene::from_json_str(&text).unwrap();
    let model = Model::new(&sc).unwrap();
    let eq = model.equilibrium().unwrap();
    let columns = model.columns().unwrap();
    let body = &sc.bodies[0].name;
    let q: Vec<f64> = ["qw", "qx", "qy", "qz"]
        .iter()
        .map(|n| {
            let name = format!("{body}.{n}");
            assert!(columns.contains(&name), "{name} is a run column");
            eq.coordinate(&name)
                .unwrap_or_else(|| panic!("{name} in {:?}", eq.coordinates))
        })
        .collect();
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    eprintln!("heavy top at rest: q = {q:?}, |q| = {norm}");
    assert!((norm - 1.0).abs() < 1e-14, "|q| = {norm}");
    assert!(
        eq.coordinates.iter().all(|(n, _)| !n.contains(".e")),
        "{:?}",
        eq.coordinates
    );
    for (name, _) in &eq.coordinates {
        assert!(columns.contains(name), "{name} is not a run column");
    }
}

/// The spherical pendulum in conical motion (the bob on a horizontal circle at `θ₀` from the
/// downward vertical, `φ' ² = g / (L cos θ₀)`), linearized at `t = T` in the states
/// `(x, y, vx, vy)`: `A` is the Jacobian of the pendulum's Cartesian equations
/// `a = g − ((r·g + |v|²)/L²) r` with `z = −√(L² − x² − y²)`, `vz = −(x vx + y vy)/z`
/// (differentiated here by central differences of that closed form), at the closed-form state
/// at `T`; the point moves, so it is not called an equilibrium and has no modes.
#[test]
fn conical_spherical_pendulum_linearized_at_a_time_matches_its_closed_form() {
    let (l, th0, t_at) = (1.1f64, 0.7f64, 0.9);
    let rate = (G / (l * th0.cos())).sqrt();
    let rho = l * th0.sin();
    let s = spherical_pendulum(l, [rho, 0.0, -l * th0.cos()], [0.0, rho * rate, 0.0], 2.0);
    let lm = linearize(
        &scene(&s),
        &LinearizeOptions {
            at: OperatingPoint::Time(t_at),
            states: Some(vec!["bob.x".into(), "bob.y".into()]),
            ..LinearizeOptions::default()
        },
    )
    .unwrap();
    eprintln!("{}", lm.table());
    assert_eq!(lm.states, ["bob.x", "bob.y", "bob.vx", "bob.vy"]);
    assert!(!lm.equilibrium && lm.modes.is_empty(), "{}", lm.table());
    assert!(
        lm.notes.iter().any(|n| n.contains("not an equilibrium")),
        "{:?}",
        lm.notes
    );
    assert_eq!(lm.eigenvalues.len(), 4);
    // the closed-form state at T
    let ph = rate * t_at;
    let y0 = [
        rho * ph.cos(),
        rho * ph.sin(),
        -rho * rate * ph.sin(),
        rho * rate * ph.cos(),
    ];
    let f = |y: [f64; 4]| {
        let z = -(l * l - y[0] * y[0] - y[1] * y[1]).sqrt();
        let vz = -(y[0] * y[2] + y[1] * y[3]) / z;
        let r = [y[0], y[1], z];
        let lam = (-G * z + y[2] * y[2] + y[3] * y[3] + vz * vz) / (l * l);
        [y[2], y[3], -lam * r[0], -lam * r[1]]
    };
    let h = 1e-4;
    let mut a = [[0.0; 4]; 4];
    for k in 0..4 {
        let at = |s: f64| {
            let mut y = y0;
            y[k] += s * h;
            f(y)
        };
        let (p1, m1, p2, m2) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
        for i in 0..4 {
            a[i][k] = (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h);
        }
    }
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (i, row) in a.iter().enumerate() {
        for (k, want) in row.iter().enumerate() {
            worst = worst.max((lm.a[(i, k)] - want).abs());
        }
    }
    eprintln!("conical pendulum at t = {t_at}: A off the closed form by {worst:.2e} of {scale:.2}");
    assert!(worst < 1e-6 * scale, "{}\nvs {a:?}", lm.a);
}

// ---------------------------------------------------------------------------------------------
// 5. Operating points, stiffness units, neutral equilibria
// ---------------------------------------------------------------------------------------------

fn pendulum(extra: Value) -> Value {
    let mut s = json!({
        "name": "bar", "gravity": [0, -G],
        "bodies": [{"name": "bar", "mass": 1.0, "inertia": 1.0 / 12.0,
                    "points": {"O": [-0.5, 0], "A": [0.5, 0]},
                    "position": [0.5 * (-1.2f64).cos(), 0.5 * (-1.2f64).sin()], "angle": -1.2}],
        "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0, 0], "O"]}],
        "solve": {"t_end": 2.0, "output_step": 0.01}
    });
    if let Value::Object(m) = extra {
        for (k, v) in m {
            s[k] = v;
        }
    }
    s
}

#[test]
fn linearize_at_a_time_after_t_end_is_refused_by_name() {
    let e = linearize(
        &scene(&pendulum(json!({}))),
        &LinearizeOptions {
            at: OperatingPoint::Time(2.5),
            ..LinearizeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    eprintln!("{e}");
    assert!(e.contains("--at t=2.5") && e.contains("t_end = 2"), "{e}");
}

/// A bar on a pin with a spring from its tip to a ground point: `ω² = V''(θ*) / J_O`
/// (`J_O = m L²/3`), whatever the coordinates' units — the stiffness eigenvalue is the
/// generalized eigenvalue of `K_r` and `M_r`, not `K_r`'s own (which mixed m and rad).
#[test]
fn stiffness_eigenvalues_are_mass_normalised() {
    let (k, p) = (40.0, [0.8, 0.9]);
    let s = pendulum(json!({
        "springs": [{"bodies": ["ground", "bar"], "points": [p, "A"], "stiffness": k, "rest_length": 0.3}]
    }));
    let eq = Model::new(&scene(&s)).unwrap().equilibrium().unwrap();
    let th = eq.coordinate("bar.angle").unwrap();
    // V(θ) = m g (L/2) sin θ + ½ k (|A − P| − l₀)², A = L u(θ)
    let v = |t: f64| {
        let a = [t.cos(), t.sin()];
        let d = ((a[0] - p[0]).powi(2) + (a[1] - p[1]).powi(2)).sqrt();
        G * 0.5 * t.sin() + 0.5 * k * (d - 0.3).powi(2)
    };
    let h = 1e-3;
    let d2v = (-v(th + 2.0 * h) + 16.0 * v(th + h) - 30.0 * v(th) + 16.0 * v(th - h)
        - v(th - 2.0 * h))
        / (12.0 * h * h);
    let want = d2v / (1.0 / 3.0);
    let got = eq.stiffness_eigenvalues[0];
    eprintln!("sprung bar at {th}: ω² = {got} vs V''/J_O = {want} (V'' = {d2v})");
    assert!((got - want).abs() < 1e-7 * want.abs(), "{got} vs {want}");
    let stability = if want > 0.0 { "stable" } else { "unstable" };
    assert_eq!(eq.to_json()["stability"], stability);
}

/// Without gravity and springs a bar on a pin rests anywhere: neutral, not unstable.
#[test]
fn a_neutral_equilibrium_is_called_neutral() {
    let s = pendulum(json!({"gravity": [0, 0]}));
    let eq = Model::new(&scene(&s)).unwrap().equilibrium().unwrap();
    eprintln!("{}", eq.table());
    assert_eq!(eq.to_json()["stability"], "neutral", "{}", eq.table());
    assert!(!eq.stable);
    assert!(eq.table().contains("neutral"));
}

// ---------------------------------------------------------------------------------------------
// 6. The smaller items
// ---------------------------------------------------------------------------------------------

/// A driven scene at rest (velocities not given): the drivers' rates are set by the initial
/// projection, which is no violation of the joints.
#[test]
fn zero_initial_velocities_of_a_driven_scene_do_not_warn_they_violate_the_joints() {
    let s = pendulum(json!({
        "drivers": [{"name": "motor", "joint": "pivot", "angular_velocity": 3}]
    }));
    let sol = solve(&s, FormulationKind::Dae);
    assert!(sol.summary.initial_velocity_correction > 1.0);
    assert!(
        sol.summary.warnings.iter().all(|w| !w.contains("violate")),
        "{:?}",
        sol.summary.warnings
    );
    // velocities the scene gives that disagree with the drivers are still said to
    // (ω = 1 about the pin: the centre's velocity ω ẑ × r, which the pin holds)
    let mut given = s.clone();
    let th = -1.2f64;
    given["bodies"][0]["angular_velocity"] = json!(1.0);
    given["bodies"][0]["velocity"] = json!([-0.5 * th.sin(), 0.5 * th.cos()]);
    let sol = solve(&given, FormulationKind::Dae);
    assert!(
        sol.summary
            .warnings
            .iter()
            .any(|w| w.contains("disagree with the prescribed rates of [drivers[0] 'motor']")),
        "{:?}",
        sol.summary.warnings
    );
}

/// The default `dae` labels its re-selection warnings `dae:`, not `index1:`.
#[test]
fn a_dae_run_warns_with_its_own_label() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bead_slot_through_pivot.json"
    ))
    .unwrap();
    let model = Model::new(&Scene::from_json_str(&text).unwrap()).unwrap();
    let o = model.default_options();
    let sol = model.solve(&o).unwrap();
    eprintln!("{:?}", sol.summary.warnings);
    assert_eq!(sol.summary.formulation, "dae");
    assert!(sol.summary.index1_reselections > 0, "the scene re-selects");
    assert!(
        sol.summary
            .warnings
            .iter()
            .any(|w| w.starts_with("dae: partition re-selected")),
        "{:?}",
        sol.summary.warnings
    );
    assert!(
        sol.summary
            .warnings
            .iter()
            .all(|w| !w.starts_with("index1:")),
        "{:?}",
        sol.summary.warnings
    );
}

#[test]
fn a_mistyped_output_or_joint_name_gets_a_did_you_mean() {
    let e = Scene::from_json_str(&pendulum(json!({"outputs": ["enrgy"]})).to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("did you mean 'energy'?"), "{e}");
    let e = Scene::from_json_str(
        &pendulum(json!({"drivers": [{"joint": "pivto", "angle": "t"}]})).to_string(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("no joint named 'pivto' (did you mean 'pivot'?"),
        "{e}"
    );
    let e = Scene::from_json_str(&pendulum(json!({"outputs": ["bar.omgea"]})).to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("did you mean 'omega'?"), "{e}");
    let e = linearize(
        &scene(&pendulum(json!({}))),
        &LinearizeOptions {
            outputs: vec!["bar.angel".into()],
            ..LinearizeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("did you mean 'bar.angle'?"), "{e}");
}

#[test]
fn equilibrium_and_linearize_report_their_cpu_time() {
    let s = scene(&pendulum(json!({})));
    let eq = Model::new(&s).unwrap().equilibrium().unwrap();
    assert!(eq.cpu_seconds > 0.0 && eq.to_json()["cpu_seconds"].as_f64().unwrap() > 0.0);
    assert!(eq.table().contains("CPU"));
    let lm = linearize(&s, &LinearizeOptions::default()).unwrap();
    assert!(lm.cpu_seconds > 0.0 && lm.to_json()["cpu_seconds"].as_f64().unwrap() > 0.0);
    assert!(lm.table().contains("CPU"));
}

#[test]
fn service_docs_list_the_equilibrium_route() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/service.md")).unwrap();
    for route in ["POST /v1/equilibrium", "POST /v1/linearize"] {
        assert!(text.contains(route), "{route} not in docs/service.md");
    }
}

/// `driver_work` is the trapezoidal rule on the rows: the summary says so, with the output step
/// that sets its error.
#[test]
fn driver_work_says_it_is_the_trapezoid_rule_on_the_rows() {
    let s = pendulum(json!({
        "drivers": [{"name": "motor", "joint": "pivot", "angular_velocity": "2 + sin(3*t)"}]
    }));
    let sol = solve(&s, FormulationKind::Dae);
    assert!(sol.summary.driver_work.is_some());
    let note = &sol.summary.driver_work_note;
    eprintln!("{note}");
    assert!(
        note.contains("trapezoidal rule") && note.contains("201 rows"),
        "{note}"
    );
}
