//! The example scenes' generated equations against hand-derived minimal-coordinate models
//! (Lagrange / Jourdain, in `tests/common`): the same accelerations at random consistent states.
//! Scenes: `pendulum.json`, `two_bars.json`, `slider_crank.json`, `four_bar.json`.

mod common;

use bondmech::dae::{consistent_state_from, ConsistentState, ConstraintExprs, MechanicsTapes};
use bondmech::mech::{build, MultibodySystem};
use bondmech::Scene;
use common::examples::{pendulum_accelerations, two_bar_accelerations, FourBar, HingedBar};
use common::slider_crank::SliderCrank;
use nalgebra::Vector2;

const G: f64 = 9.81;

fn load(name: &str) -> Scene {
    let path = format!("{}/scenes/{name}.json", env!("CARGO_MANIFEST_DIR"));
    Scene::from_json_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Deterministic pseudo-random numbers in (−1, 1) (no dependence on bondmech).
fn rng(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// The mass and inertia of a scene body, to check the hand model uses the scene's values.
fn mass_inertia(s: &Scene, b: &str) -> (f64, f64) {
    let body = &s.bodies[s.body_index(b).unwrap()];
    let j = match body.inertia {
        bondmech::scene::Inertia::Planar(j) => j,
        bondmech::scene::Inertia::Principal(j) => j[2],
    };
    (body.mass, j)
}

struct Probe {
    sys: MultibodySystem,
    tapes: MechanicsTapes,
}

impl Probe {
    fn new(scene: &Scene) -> Probe {
        let mut sys = build(scene).unwrap();
        let c = ConstraintExprs::derive(&mut sys);
        let tapes = MechanicsTapes::new(&mut sys, &c, None);
        Probe { sys, tapes }
    }

    /// The consistent state (with accelerations) at the given body states
    /// `(name, [x, y, angle], [vx, vy, omega])`; fails if bondmech had to correct it.
    fn at(&self, bodies: &[(&str, [f64; 3], [f64; 3])]) -> ConsistentState {
        let nq = self.sys.nq();
        let mut x = vec![0.0; nq + self.sys.nv()];
        for (b, q, v) in bodies {
            for (k, n) in ["x", "y", "angle"].iter().enumerate() {
                if let Some(i) = self.q(&format!("{b}.{n}")) {
                    x[i] = q[k];
                }
            }
            for (k, n) in ["vx", "vy", "omega"].iter().enumerate() {
                if let Some(i) = self.v(&format!("{b}.{n}")) {
                    x[nq + i] = v[k];
                }
            }
        }
        let st = consistent_state_from(&self.sys, &self.tapes, 0.0, &x).unwrap();
        assert!(
            st.position_correction < 1e-10 && st.velocity_correction < 1e-10,
            "the hand state is not consistent: {} {}",
            st.position_correction,
            st.velocity_correction
        );
        st
    }
    fn q(&self, n: &str) -> Option<usize> {
        self.sys.coords.iter().position(|c| c.name == n)
    }
    fn v(&self, n: &str) -> Option<usize> {
        self.sys.velocities.iter().position(|c| c.name == n)
    }
    fn acc(&self, st: &ConsistentState, n: &str) -> f64 {
        st.vdot[self.v(n).unwrap_or_else(|| panic!("no velocity {n}"))]
    }
}

fn close(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() < 1e-9 * (1.0 + want.abs()),
        "{what}: bondmech {got} vs hand {want}"
    );
}

fn e(t: f64) -> Vector2<f64> {
    Vector2::new(t.cos(), t.sin())
}
fn ep(t: f64) -> Vector2<f64> {
    Vector2::new(-t.sin(), t.cos())
}

#[test]
fn pendulum_scene_accelerations_match_lagrange_at_random_states() {
    let s = load("pendulum");
    let (m, l) = (1.0, 1.0);
    let j = m * l * l / 12.0;
    assert_eq!(mass_inertia(&s, "bar"), (m, j));
    let p = Probe::new(&s);
    let mut r = rng(7);
    for _ in 0..20 {
        let (th, w) = (3.2 * r(), 5.0 * r());
        let c = 0.5 * l * e(th);
        let v = 0.5 * l * w * ep(th);
        let st = p.at(&[("bar", [c.x, c.y, th], [v.x, v.y, w])]);
        let (a, ac) = pendulum_accelerations(m, l, j, G, th, w);
        close(p.acc(&st, "bar.omega"), a, "θ''");
        close(p.acc(&st, "bar.vx"), ac.x, "x''");
        close(p.acc(&st, "bar.vy"), ac.y, "y''");
    }
}

#[test]
fn two_bars_scene_accelerations_match_lagrange_at_random_states() {
    let s = load("two_bars");
    let (m, l) = (1.0, 1.0);
    let j = m * l * l / 12.0;
    assert_eq!(mass_inertia(&s, "bar1"), (m, j));
    assert_eq!(mass_inertia(&s, "bar2"), (m, j));
    assert_eq!(s.gravity, vec![0.0, 0.0]);
    // bar1's hinge point A is at +L/2 (centre = H − L/2 e₁), bar2's at −L/2 (centre = H + L/2 e₂)
    let bars = [
        HingedBar { m, j, d: -0.5 * l },
        HingedBar { m, j, d: 0.5 * l },
    ];
    let p = Probe::new(&s);
    let mut r = rng(11);
    for _ in 0..20 {
        let h = Vector2::new(r(), r());
        let hv = Vector2::new(2.0 * r(), 2.0 * r());
        let th = [3.2 * r(), 3.2 * r()];
        let w = [4.0 * r(), 4.0 * r()];
        let mut bodies = Vec::new();
        for (i, name) in ["bar1", "bar2"].iter().enumerate() {
            let c = h + bars[i].d * e(th[i]);
            let v = hv + bars[i].d * w[i] * ep(th[i]);
            bodies.push((*name, [c.x, c.y, th[i]], [v.x, v.y, w[i]]));
        }
        let st = p.at(&bodies);
        let (ha, a1, a2) = two_bar_accelerations(bars, Vector2::zeros(), th, w);
        close(p.acc(&st, "bar1.omega"), a1, "θ₁''");
        close(p.acc(&st, "bar2.omega"), a2, "θ₂''");
        for (i, (name, a)) in [("bar1", a1), ("bar2", a2)].into_iter().enumerate() {
            let ci = ha + bars[i].d * (a * ep(th[i]) - w[i] * w[i] * e(th[i]));
            close(p.acc(&st, &format!("{name}.vx")), ci.x, "centre x''");
            close(p.acc(&st, &format!("{name}.vy")), ci.y, "centre y''");
        }
    }
}

#[test]
fn slider_crank_scene_accelerations_match_lagrange_at_random_states() {
    let s = load("slider_crank");
    let sc = SliderCrank::bundled();
    let (mc, jc) = mass_inertia(&s, "crank");
    assert_eq!(mc, 1.0);
    assert!((jc - 1.0 * 0.01 / 12.0).abs() < 1e-15);
    let (mr, jr) = mass_inertia(&s, "rod");
    assert_eq!(mr, 0.5);
    assert!((jr - 0.5 * 0.09 / 12.0).abs() < 1e-15);
    assert_eq!(mass_inertia(&s, "piston").0, 0.3);
    let p = Probe::new(&s);
    let mut r = rng(23);
    for _ in 0..20 {
        let (phi, w) = (3.2 * r(), 30.0 * r());
        let k = sc.state(0.0, phi, w);
        let gas = -10.0 * phi.cos().max(0.0);
        let a = sc.acceleration(phi, w, gas);
        let st = p.at(&[
            (
                "crank",
                [k.crank_centre[0], k.crank_centre[1], phi],
                [-0.05 * w * phi.sin(), 0.05 * w * phi.cos(), w],
            ),
            (
                "rod",
                [k.rod_centre[0], k.rod_centre[1], k.rod_angle],
                [k.rod_velocity[0], k.rod_velocity[1], k.rod_omega],
            ),
            ("piston", [0.0, k.piston_y, 0.0], [0.0, k.piston_vy, 0.0]),
        ]);
        close(p.acc(&st, "crank.omega"), a, "φ''");
        // the piston acceleration: y_p'' = y_p' φ'' + y_p'' φ'², by finite differences of the
        // closed-form piston height (an independent check of the chain)
        let hstep = 1e-4;
        let y = |f: f64| sc.piston_height(f);
        let d1 = (y(phi + hstep) - y(phi - hstep)) / (2.0 * hstep);
        let d2 = (y(phi + hstep) - 2.0 * y(phi) + y(phi - hstep)) / (hstep * hstep);
        let ap = d1 * a + d2 * w * w;
        let got = p.acc(&st, "piston.vy");
        assert!(
            (got - ap).abs() < 1e-5 * (1.0 + ap.abs()),
            "piston y'': {got} vs {ap}"
        );
    }
}

#[test]
fn four_bar_scene_accelerations_match_hand_model_at_random_states() {
    let s = load("four_bar");
    let fb = FourBar {
        r: [0.1, 0.35, 0.3],
        m: [0.2, 0.5, 0.4],
        j: [
            0.2 * 0.01 / 12.0,
            0.5 * 0.35 * 0.35 / 12.0,
            0.4 * 0.09 / 12.0,
        ],
        d: 0.4,
        g: G,
    };
    for (i, b) in ["crank", "coupler", "rocker"].iter().enumerate() {
        let (m, j) = mass_inertia(&s, b);
        assert_eq!(m, fb.m[i]);
        assert!((j - fb.j[i]).abs() < 1e-15, "{b}: {j}");
    }
    // the hand model reproduces the scene's initial assembly (open branch)
    let st0 = fb.state(std::f64::consts::FRAC_PI_3, 0.0);
    let coupler = &s.bodies[s.body_index("coupler").unwrap()];
    assert!((st0.th[1] - coupler.angle).abs() < 1e-9);
    let p = Probe::new(&s);
    let mut r = rng(31);
    for _ in 0..20 {
        let (phi, w) = (3.2 * r(), 10.0 * r());
        let k = fb.state(phi, w);
        let names = ["crank", "coupler", "rocker"];
        let bodies: Vec<_> = (0..3)
            .map(|i| {
                (
                    names[i],
                    [k.c[i].x, k.c[i].y, k.th[i]],
                    [k.v[i].x, k.v[i].y, k.w[i]],
                )
            })
            .collect();
        let st = p.at(&bodies);
        let a = fb.accelerations(&k);
        for i in 0..3 {
            close(p.acc(&st, &format!("{}.omega", names[i])), a[i], names[i]);
        }
    }
}
