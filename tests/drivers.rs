//! Drivers (`"drivers"`: prescribed joint motion) against independent references:
//!
//! * a slider-crank whose crank is driven at constant speed, with gravity and a piston force
//!   (DOF 0, an inverse-dynamics run): the piston position from the exact kinematics, the motor
//!   torque from the power balance `τ ω = dT/dt + dV/dt − F·v` of the closed-form motion;
//! * a pendulum hanging from a cart driven along a line by a prescribed displacement: the
//!   pendulum's angle and the driver's force against a one-coordinate model derived below and
//!   integrated by `tests/common`'s Dormand–Prince integrator;
//! * a bar on a spatial hinge driven at constant speed: its centre on the closed-form circle,
//!   its torque the weight's moment;
//! * bad input refused naming the JSON path.
//!
//! Nothing here takes a reference value from bondmech.

mod common;

use bondmech::{FormulationKind, Model, Scene, Solution};
use common::integrate::integrate;
use serde_json::{json, Value};

const G: f64 = 9.81;

fn solve(scene: &Value, f: FormulationKind, rtol: f64) -> Solution {
    let scene = Scene::from_json_str(&scene.to_string()).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = f;
    o.rtol = rtol;
    o.atol = rtol * 1e-2;
    model.solve(&o).unwrap_or_else(|e| panic!("{f:?}: {e}"))
}

fn col(sol: &Solution, name: &str) -> Vec<f64> {
    sol.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", sol.columns))
}

/// The driven slider-crank's data: crank `r` (uniform bar, mass `mc`), rod `l` (uniform bar,
/// mass `mr`), piston `mp` on the Y axis; crank angle `θ0 + ω t`; piston force
/// `F(θ) = −20 (1 + cos θ)` (Y), gravity −Y.
struct Crank {
    r: f64,
    l: f64,
    mc: f64,
    mr: f64,
    mp: f64,
    th0: f64,
    w: f64,
    /// Driven at `ω(t) = w (1 − e^{−2t}/2)` (an `angular_velocity` of t) instead of at `w`.
    spin_up: bool,
}

impl Crank {
    /// The crank angle `θ(t)`: `θ0 + w t`, or spinning up `θ0 + w (t + (e^{−2t} − 1)/4)`.
    fn angle(&self, t: f64) -> f64 {
        if self.spin_up {
            self.th0 + self.w * (t + ((-2.0 * t).exp() - 1.0) / 4.0)
        } else {
            self.th0 + self.w * t
        }
    }
    /// The crank speed `θ'(t)`.
    fn speed(&self, t: f64) -> f64 {
        if self.spin_up {
            self.w * (1.0 - 0.5 * (-2.0 * t).exp())
        } else {
            self.w
        }
    }
    fn jc(&self) -> f64 {
        self.mc * self.r * self.r / 12.0
    }
    fn jr(&self) -> f64 {
        self.mr * self.l * self.l / 12.0
    }
    /// Exact kinematics at time `t`: crank angle, crank pin A, piston y, rod angle.
    fn pose(&self, t: f64) -> (f64, [f64; 2], f64, f64) {
        let th = self.angle(t);
        let a = [self.r * th.cos(), self.r * th.sin()];
        let yb = a[1] + (self.l * self.l - a[0] * a[0]).sqrt();
        let phi = (yb - a[1]).atan2(-a[0]);
        (th, a, yb, phi)
    }
    /// Kinetic and potential energy at `t` (velocities by a central difference of the exact
    /// positions, 8th order in `h`).
    fn energies(&self, t: f64) -> (f64, f64) {
        let pos = |t: f64| {
            let (th, a, yb, phi) = self.pose(t);
            // crank centre, rod centre, piston y, crank angle, rod angle
            [
                a[0] / 2.0,
                a[1] / 2.0,
                a[0] / 2.0,
                (a[1] + yb) / 2.0,
                yb,
                th,
                phi,
            ]
        };
        let rate = derivative(|t| pos(t).to_vec(), t);
        let p = pos(t);
        let kin = 0.5 * self.mc * (rate[0].powi(2) + rate[1].powi(2))
            + 0.5 * self.jc() * rate[5].powi(2)
            + 0.5 * self.mr * (rate[2].powi(2) + rate[3].powi(2))
            + 0.5 * self.jr() * rate[6].powi(2)
            + 0.5 * self.mp * rate[4].powi(2);
        let pot = G * (self.mc * p[1] + self.mr * p[3] + self.mp * p[4]);
        (kin, pot)
    }
    /// The motor torque from the power balance `τ ω = dT/dt + dV/dt − F·v`.
    fn torque(&self, t: f64) -> f64 {
        let e = derivative(
            |t| {
                let (k, v) = self.energies(t);
                vec![k + v]
            },
            t,
        )[0];
        let (th, _, _, _) = self.pose(t);
        let vy = derivative(|t| vec![self.pose(t).2], t)[0];
        let f = -20.0 * (1.0 + th.cos());
        (e - f * vy) / self.speed(t)
    }
    fn scene(&self) -> Value {
        let (th, a, yb, phi) = self.pose(0.0);
        json!({
            "name": "driven_slider_crank",
            "gravity": [0.0, -G],
            "bodies": [
                {"name": "crank", "mass": self.mc, "inertia": self.jc(),
                 "points": {"O": [-self.r / 2.0, 0.0], "A": [self.r / 2.0, 0.0]},
                 "position": [a[0] / 2.0, a[1] / 2.0], "angle": th},
                {"name": "rod", "mass": self.mr, "inertia": self.jr(),
                 "points": {"A": [-self.l / 2.0, 0.0], "B": [self.l / 2.0, 0.0]},
                 "position": [a[0] / 2.0, (a[1] + yb) / 2.0], "angle": phi},
                {"name": "piston", "mass": self.mp, "inertia": 1e-4,
                 "points": {"P": [0.0, 0.0]}, "position": [0.0, yb]}
            ],
            "joints": [
                {"name": "main_bearing", "type": "revolute", "bodies": ["ground", "crank"],
                 "points": [[0.0, 0.0], "O"]},
                {"name": "crank_pin", "type": "revolute", "bodies": ["crank", "rod"],
                 "points": ["A", "A"]},
                {"name": "wrist_pin", "type": "revolute", "bodies": ["rod", "piston"],
                 "points": ["B", "P"]},
                {"name": "cylinder", "type": "prismatic", "bodies": ["ground", "piston"],
                 "points": [[0.0, 0.0], "P"], "axis": [0.0, 1.0]}
            ],
            "loads": [{"name": "gas", "type": "force", "body": "piston", "point": "P",
                       "value": ["0", "-20*(1 + cos(crank.angle))"]}],
            "drivers": [if self.spin_up {
                json!({"name": "motor", "joint": "main_bearing",
                       "angular_velocity": format!("{}*(1 - 0.5*exp(-2*t))", self.w)})
            } else {
                json!({"name": "motor", "joint": "main_bearing",
                       "angle": format!("{} + {}*t", self.th0, self.w)})
            }],
            "solve": {"t_end": 0.7, "output_step": 0.01},
            "outputs": ["piston.P"]
        })
    }
}

/// `f'(t)` by the 8th-order central difference (h = 1e-3).
fn derivative(f: impl Fn(f64) -> Vec<f64>, t: f64) -> Vec<f64> {
    let h = 1e-3;
    let c = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
    let mut out = vec![0.0; f(t).len()];
    for (k, ck) in c.iter().enumerate() {
        let d = (k + 1) as f64 * h;
        let (p, m) = (f(t + d), f(t - d));
        for i in 0..out.len() {
            out[i] += ck * (p[i] - m[i]) / h;
        }
    }
    out
}

fn crank() -> Crank {
    Crank {
        r: 0.1,
        l: 0.3,
        mc: 1.0,
        mr: 0.5,
        mp: 0.3,
        th0: 1.0471975511965976,
        w: 10.0,
        spin_up: false,
    }
}

#[test]
fn slider_crank_driven_at_constant_speed_is_inverse_dynamics_with_the_power_balance_torque() {
    driven_slider_crank_matches_its_kinematics_and_power_balance(crank());
}

/// A rate driver whose speed is an expression of t (`angular_velocity`
/// `10*(1 − 0.5 exp(−2t))`): the row is the integral of the rate in closed form, so the crank
/// angle is `θ0 + 10 (t + (e^{−2t} − 1)/4)` to the Newton tolerance, and the torque closes the
/// power balance as at constant speed.
#[test]
fn slider_crank_spun_up_by_a_rate_of_t_follows_the_integrated_angle_and_power_balance() {
    driven_slider_crank_matches_its_kinematics_and_power_balance(Crank {
        spin_up: true,
        ..crank()
    });
}

fn driven_slider_crank_matches_its_kinematics_and_power_balance(c: Crank) {
    let scene = c.scene();
    let model = Model::new(&Scene::from_json_str(&scene.to_string()).unwrap()).unwrap();
    assert_eq!(model.dof().unwrap().dof, 0, "the driver takes the one DOF");
    for f in [
        FormulationKind::Ggl,
        FormulationKind::Index1,
        FormulationKind::Dae,
        FormulationKind::Partitioned,
    ] {
        let sol = solve(&scene, f, 1e-10);
        let t = sol.times.clone();
        let y = col(&sol, "piston.P.y");
        let tau = col(&sol, "motor.torque");
        let angle = col(&sol, "crank.angle");
        let power = col(&sol, "motor.power");
        let want: Vec<f64> = t.iter().map(|&t| c.torque(t)).collect();
        let peak = want.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(peak > 1.0, "a torque worth checking: peak {peak}");
        for k in 0..t.len() {
            let (th, _, yb, _) = c.pose(t[k]);
            assert!(
                (angle[k] - th).abs() < 1e-9,
                "{f:?} t = {}: crank angle {} vs {th}",
                t[k],
                angle[k]
            );
            assert!(
                (y[k] - yb).abs() < 1e-9,
                "{f:?} t = {}: piston {} vs exact {yb}",
                t[k],
                y[k]
            );
            assert!(
                (tau[k] - want[k]).abs() < 1e-6 * peak,
                "{f:?} t = {}: torque {} vs power balance {} (peak {peak})",
                t[k],
                tau[k],
                want[k]
            );
            assert!((power[k] - want[k] * c.speed(t[k])).abs() < 1e-6 * peak * c.w);
        }
        let worst = (0..t.len())
            .map(|k| (tau[k] - want[k]).abs())
            .fold(0.0f64, f64::max);
        eprintln!(
            "{f:?}: torque error {:.2e} of the peak {peak:.3} N m",
            worst / peak
        );
        assert!(
            sol.summary.kinematic_analysis && sol.summary.dof == 0,
            "{:?}",
            sol.summary
        );
        let note = sol.summary.energy_note.clone();
        assert!(
            note.contains("motor"),
            "energy note names the driver: {note}"
        );
    }
}

/// Cart of mass `mc` on a horizontal rail (prismatic to ground along X), driven by
/// `x_c(t) = 0.1 (1 − cos 3t)`; a uniform bar (mass `m`, length `L`, `a = L/2`) pinned at its
/// end O to the cart's point. With `α` the bar's angle (centre `c = (x_c + a cos α, a sin α)`),
/// Lagrange's equation of the one coordinate α is
///
/// `(J + m a²) α'' = m a sin α ẍ_c − m g a cos α`,
///
/// and the driver's force on the cart along the rail is the rate of the horizontal momentum
/// (gravity and the rail's reaction are vertical): `F = mc ẍ_c + m (ẍ_c − a (cos α α'² + sin α α''))`.
#[test]
fn cart_driven_by_a_displacement_swings_its_pendulum_like_the_one_coordinate_model() {
    let (mc, m, l) = (2.0, 0.8, 0.6);
    let a = l / 2.0;
    let j = m * l * l / 12.0;
    let alpha0 = -1.2;
    let xc = |t: f64| 0.1 * (1.0 - (3.0 * t).cos());
    let xdd = |t: f64| 0.9 * (3.0 * t).cos();
    let acc =
        move |t: f64, al: f64| (m * a * al.sin() * xdd(t) - m * G * a * al.cos()) / (j + m * a * a);
    let times: Vec<f64> = (0..=40).map(|i| 0.05 * i as f64).collect();
    let reference = integrate(
        |t, y, dy| {
            dy[0] = y[1];
            dy[1] = acc(t, y[0]);
        },
        0.0,
        &[alpha0, 0.0],
        &times,
        1e-13,
        1e-13,
    );
    let scene = json!({
        "gravity": [0.0, -G],
        "bodies": [
            {"name": "cart", "mass": mc, "inertia": 0.05, "points": {"H": [0.0, 0.0]},
             "position": [0.0, 0.0]},
            {"name": "bar", "mass": m, "inertia": j,
             "points": {"O": [-a, 0.0], "A": [a, 0.0]},
             "position": [a * alpha0.cos(), a * alpha0.sin()], "angle": alpha0}
        ],
        "joints": [
            {"name": "rail", "type": "prismatic", "bodies": ["ground", "cart"],
             "points": [[0.0, 0.0], "H"], "axis": [1.0, 0.0]},
            {"name": "hinge", "type": "revolute", "bodies": ["cart", "bar"], "points": ["H", "O"]}
        ],
        "drivers": [{"name": "push", "joint": "rail", "displacement": "0.1*(1-cos(3*t))"}],
        "solve": {"t_end": 2.0, "output_step": 0.05}
    });
    for f in [
        FormulationKind::Dae,
        FormulationKind::Ggl,
        FormulationKind::Index1,
        FormulationKind::Partitioned,
    ] {
        let sol = solve(&scene, f, 1e-10);
        let t = sol.times.clone();
        let alpha = col(&sol, "bar.angle");
        let x = col(&sol, "cart.x");
        let force = col(&sol, "push.force");
        for k in 0..t.len() {
            let (al, w) = (reference[k][0], reference[k][1]);
            let add = acc(t[k], al);
            let want = mc * xdd(t[k]) + m * (xdd(t[k]) - a * (al.cos() * w * w + al.sin() * add));
            assert!((x[k] - xc(t[k])).abs() < 1e-9, "{f:?} t = {}: cart x", t[k]);
            assert!(
                (alpha[k] - al).abs() < 1e-6,
                "{f:?} t = {}: angle {} vs reference {al}",
                t[k],
                alpha[k]
            );
            assert!(
                (force[k] - want).abs() < 1e-5,
                "{f:?} t = {}: force {} vs reference {want}",
                t[k],
                force[k]
            );
        }
    }
}

/// A uniform bar (mass `m`, length `L`) on a spatial hinge about global Z at its end, gravity
/// −Y, driven at `ω`: its centre runs on the circle of radius `a = L/2`, `(a cos ωt, a sin ωt)`,
/// and the motor's torque balances the weight's moment about the axis, `τ = m g a cos ωt`
/// (constant speed: no angular acceleration; Z is a principal axis: no gyroscopic moment about it).
#[test]
fn spatial_hinge_driven_at_constant_speed_follows_the_circle_and_holds_the_weight() {
    let (m, l, w) = (1.5, 0.8, 2.0);
    let a = l / 2.0;
    let jt = m * l * l / 12.0;
    let scene = json!({
        "dimension": 3,
        "gravity": [0.0, -G, 0.0],
        "bodies": [{"name": "bar", "mass": m, "inertia": [1e-3, jt, jt],
                    "points": {"O": [-a, 0.0, 0.0]}, "position": [a, 0.0, 0.0]}],
        "joints": [{"name": "hinge", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0.0, 0.0, 0.0], "O"], "axis": [0.0, 0.0, 1.0]}],
        "drivers": [{"name": "spin", "joint": "hinge", "angular_velocity": w}],
        "solve": {"t_end": 4.0, "output_step": 0.05}
    });
    for f in [FormulationKind::Dae, FormulationKind::Ggl] {
        let sol = solve(&scene, f, 1e-10);
        let t = sol.times.clone();
        let (x, y) = (col(&sol, "bar.x"), col(&sol, "bar.y"));
        let tau = col(&sol, "spin.torque");
        for k in 0..t.len() {
            let th = w * t[k];
            assert!(
                (x[k] - a * th.cos()).abs() < 1e-8 && (y[k] - a * th.sin()).abs() < 1e-8,
                "{f:?} t = {}: centre ({}, {})",
                t[k],
                x[k],
                y[k]
            );
            let want = m * G * a * th.cos();
            assert!(
                (tau[k] - want).abs() < 1e-6 * m * G * a,
                "{f:?} t = {}: torque {} vs {want}",
                t[k],
                tau[k]
            );
        }
    }
}

fn refusal(scene: &Value) -> String {
    match Scene::from_json_str(&scene.to_string()) {
        Err(e) => e.to_string(),
        Ok(s) => match Model::new(&s) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {scene}"),
        },
    }
}

fn bad(drivers: Value) -> Value {
    let mut s = crank().scene();
    s["joints"].as_array_mut().unwrap().push(
        json!({"name": "glue", "type": "weld", "bodies": ["ground", "piston"],
                     "points": [[0.0, 0.0], "P"]}),
    );
    s["drivers"] = drivers;
    s
}

#[test]
fn bad_drivers_are_refused_naming_the_path() {
    let e = refusal(&bad(json!([{"name": "m", "joint": "nope", "angle": "t"}])));
    assert!(e.contains("drivers[0].joint") && e.contains("nope"), "{e}");
    let e = refusal(&bad(
        json!([{"name": "m", "joint": "cylinder", "angle": "t"}]),
    ));
    assert!(
        e.contains("drivers[0].angle")
            && e.contains("a prismatic joint is driven by displacement or velocity"),
        "{e}"
    );
    let e = refusal(&bad(json!([
        {"name": "m", "joint": "main_bearing", "angle": "t"},
        {"name": "n", "joint": "main_bearing", "angular_velocity": 1}
    ])));
    assert!(
        e.contains("drivers[1].joint") && e.contains("already driven by drivers[0]"),
        "{e}"
    );
    let e = refusal(&bad(json!([{"name": "m", "joint": "glue", "angle": "t"}])));
    assert!(e.contains("drivers[0].joint") && e.contains("weld"), "{e}");
    let e = refusal(&bad(
        json!([{"name": "m", "joint": "main_bearing", "angle": "t", "angular_velocity": 2}]),
    ));
    assert!(e.contains("drivers[0].angular_velocity"), "{e}");
    // a rate with no closed-form integral: refused naming the path and the term
    let e = refusal(&bad(
        json!([{"name": "m", "joint": "main_bearing", "angular_velocity": "1 + sin(t^2)"}]),
    ));
    assert!(
        e.contains("drivers[0].angular_velocity") && e.contains("sin(t^2)") && e.contains("angle"),
        "{e}"
    );
}

/// The bundled driven slider-crank: the bond graph draws the driver as `Sf motor`, causality
/// counts it (DOF 0), and over one revolution the motor's work is the gas force's cycle work
/// (T and V return): `W = −∮ F dy = 20 ∮ (1 + cos θ) dy`, with `y = r sin θ + √(l² − r² cos² θ)`
/// the rod term's integral vanishes by symmetry and `20 ∮ cos θ · r cos θ dθ = 20 r π`.
#[test]
fn bundled_driven_slider_crank_draws_its_driver_and_does_the_gas_work() {
    let path = format!(
        "{}/scenes/slider_crank_driven.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let scene = Scene::from_json_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let model = Model::new(&scene).unwrap();
    let graph = bondmech::mech::scene_bond_graph(&scene, bondmech::mech::Variant::Pinned).unwrap();
    let sf = graph
        .elements
        .iter()
        .find(|e| e.name == "motor")
        .expect("an element named after the driver");
    assert_eq!(sf.kind, bondmech::bond::model::ElementKind::Sf);
    assert_eq!(
        model.causality().unwrap().dof,
        0,
        "the driver takes the DOF"
    );
    let sol = model.solve(&model.default_options()).unwrap();
    let w = sol.summary.driver_work.expect("driver work reported");
    let want = 20.0 * 0.1 * std::f64::consts::PI;
    assert!((w - want).abs() < 1e-6 * want, "driver work {w} vs {want}");
    assert!(sol.summary.kinematic_analysis);
    assert!(
        sol.summary.warnings.is_empty(),
        "{:?}",
        sol.summary.warnings
    );
}

#[test]
fn an_event_may_watch_a_driver_column() {
    let mut scene = crank().scene();
    scene["events"] = json!([{"name": "peak", "when": "motor.torque - 4", "direction": "rising"}]);
    let c = crank();
    // ggl integrates; partitioned has no state here (DOF 0) and finds the zero by bisection
    for f in [FormulationKind::Ggl, FormulationKind::Partitioned] {
        let sol = solve(&scene, f, 1e-10);
        let ev = sol.summary.events.first().expect("the torque passes 4 N m");
        assert!(
            (c.torque(ev.t) - 4.0).abs() < 1e-5,
            "{f:?}: torque at the event {}",
            c.torque(ev.t)
        );
    }
}

/// `graph --as-scene` of a driven scene: the raw graph carries the driver's `Sf(t)` and its
/// closure, and solves to the mechanism's motion (the piston on the exact kinematics).
#[test]
fn exported_graph_of_a_driven_scene_solves_to_the_exact_kinematics() {
    let c = crank();
    let scene = Scene::from_json_str(&c.scene().to_string()).unwrap();
    let raw = bondmech::graph::bond_graph_scene(&scene).unwrap();
    let sol = solve(&raw, FormulationKind::Ggl, 1e-10);
    let y = col(&sol, "piston.P.y");
    for (k, &t) in sol.times.iter().enumerate() {
        let (_, _, yb, _) = c.pose(t);
        assert!((y[k] - yb).abs() < 1e-9, "t = {t}: piston {} vs {yb}", y[k]);
    }
}
