//! Issue 34, "the default holds", tried as a new user would: reference mechanisms written from
//! docs/scene-format.md that the other tests do not cover, each run on the default formulation
//! (no `formulation` in the scene) against a reference derived here, independent of bondmech:
//!
//! - a planar five-bar (2 DOF closed loop) under gravity, its bodies and joints also listed
//!   reversed and shuffled;
//! - three bars on one pin (a star hinged at the end of a grounded bar), the shared pin written
//!   four ways, and a point mass hinged to two bars at once (a double pendulum's knee);
//! - bead-in-slot variants: a bar pinned away from its end with a spring of non-zero rest
//!   length pulling the bead back and forth through the pivot for 10 s, a slot offset from the
//!   pivot, a bead starting exactly at the pivot;
//! - a disc rolling on a fixed inclined rack (exact);
//! - a Hooke's joint driveshaft written with both shafts in their own bearings (redundant rows),
//!   driven (exact: tan θ₂ = tan θ₁ / cos β) and free (a 1-DOF reference).
//!
//! References: for pinned planar bodies, Newton–Euler in absolute coordinates with the pins'
//! multipliers (`[M Cᵀ; C 0] [z''; λ] = [F; θ'² R s terms]`, index 1: the textbook form, no
//! partition, nothing of bondmech); for the bead, Lagrange in (θ, s) written out below; both
//! integrated by the tests' Dormand–Prince 5(4) at `REFERENCE_RTOL`. The scenes run at rtol 1e-8,
//! atol 1e-10; the bounds are 3–60× the errors this test build measured on main 593b5f3 (listed per
//! test; the release CLI's differ by rounding, e.g. the star 1.3–3.6e-6).
//! The scenes and a Python/scipy cross-check are in tests/references/trial/.

mod common;

use bondmech::{Model, Scene, Solution};
use common::integrate::integrate;
use common::{REFERENCE_ATOL, REFERENCE_RTOL};
use nalgebra::{DMatrix, DVector};
use serde_json::{json, Value};

const G: f64 = 9.81;

/// The solve settings of every scene here: 0.01 s outputs, rtol 1e-8, atol 1e-10.
fn solve_settings(t_end: f64) -> Value {
    json!({ "t_end": t_end, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10 })
}

/// Runs `scene` on the formulation its file names (none: the default).
fn run(scene: &Value) -> Solution {
    let model = Model::new(&Scene::from_json_str(&scene.to_string()).expect("scene reads"))
        .expect("model builds");
    let sol = model
        .solve(&model.default_options())
        .unwrap_or_else(|e| panic!("the default runs to the end: {e}"));
    assert_eq!(sol.summary.formulation, "dae", "the default is the DAE");
    sol
}

/// `a − b` folded into (−π, π].
fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

/// Planar bodies joined by pins, in absolute coordinates z = (x_i, y_i, θ_i).
///
/// A pin between the point `s_a` of body a (global coordinates when a is the ground) and `s_b`
/// of body b: `g = r_a + R(θ_a) s_a − r_b − R(θ_b) s_b = 0`. Newton–Euler with multipliers:
/// `M z'' + Cᵀ λ = F`, `C z'' = θ_a'² R(θ_a) s_a − θ_b'² R(θ_b) s_b`, with
/// `∂g/∂θ = (−(R s)_y, (R s)_x)` and `F` the weights. A body of inertia 0 whose pins are all at
/// its centre (a point mass) keeps its angle: its θ row reads `θ'' = 0`.
struct PinModel {
    /// (mass, central inertia) per body.
    bodies: Vec<(f64, f64)>,
    pins: Vec<Pin>,
}

/// A pin: (body a or `None` for the ground, s_a, body b, s_b).
type Pin = (Option<usize>, [f64; 2], usize, [f64; 2]);

/// A joint of the star written as (first body, second body, its point, the other's point).
type StarPin<'a> = (&'a str, &'a str, &'a str, &'a str);

impl PinModel {
    fn accelerations(&self, z: &[f64], zd: &[f64]) -> Vec<f64> {
        let n = 3 * self.bodies.len();
        let m = 2 * self.pins.len();
        let mut k = DMatrix::<f64>::zeros(n + m, n + m);
        let mut rhs = DVector::<f64>::zeros(n + m);
        for (i, &(mass, inertia)) in self.bodies.iter().enumerate() {
            k[(3 * i, 3 * i)] = mass;
            k[(3 * i + 1, 3 * i + 1)] = mass;
            k[(3 * i + 2, 3 * i + 2)] = if inertia > 0.0 { inertia } else { 1.0 };
            rhs[3 * i + 1] = -mass * G;
        }
        let rot = |th: f64, s: [f64; 2]| {
            let (sn, c) = th.sin_cos();
            [c * s[0] - sn * s[1], sn * s[0] + c * s[1]]
        };
        for (p, &(a, sa, b, sb)) in self.pins.iter().enumerate() {
            let row = n + 2 * p;
            let mut put = |body: usize, s: [f64; 2], sign: f64, rhs: &mut DVector<f64>| {
                let rs = rot(z[3 * body + 2], s);
                // ∂g/∂θ = (−(R s)_y, (R s)_x)
                for (d, perp) in [(0usize, -rs[1]), (1, rs[0])] {
                    k[(row + d, 3 * body + d)] = sign;
                    k[(3 * body + d, row + d)] = sign;
                    k[(row + d, 3 * body + 2)] = sign * perp;
                    k[(3 * body + 2, row + d)] = sign * perp;
                    rhs[row + d] += sign * zd[3 * body + 2].powi(2) * rs[d];
                }
            };
            if let Some(a) = a {
                put(a, sa, 1.0, &mut rhs);
            }
            put(b, sb, -1.0, &mut rhs);
        }
        let x = k
            .lu()
            .solve(&rhs)
            .expect("the reference's saddle matrix is regular");
        x.as_slice()[..n].to_vec()
    }

    /// z at `times`, from z0 at rest.
    fn simulate(&self, z0: &[f64], times: &[f64]) -> Vec<Vec<f64>> {
        let n = z0.len();
        let mut y0 = z0.to_vec();
        y0.resize(2 * n, 0.0);
        integrate(
            |_, y, dy| {
                let a = self.accelerations(&y[..n], &y[n..]);
                dy[..n].copy_from_slice(&y[n..]);
                dy[n..].copy_from_slice(&a);
            },
            0.0,
            &y0,
            times,
            REFERENCE_RTOL,
            REFERENCE_ATOL,
        )
    }
}

/// A uniform bar's body: points O = (−L/2, 0) and A = (L/2, 0).
fn bar(name: &str, length: f64, mass: f64, z: &[f64]) -> Value {
    json!({ "name": name, "mass": mass, "inertia": mass * length * length / 12.0,
            "points": { "O": [-length / 2.0, 0.0], "A": [length / 2.0, 0.0] },
            "position": [z[0], z[1]], "angle": z[2] })
}

fn pin(name: &str, a: &str, b: &str, pa: Value, pb: Value) -> Value {
    json!({ "name": name, "type": "revolute", "bodies": [a, b], "points": [pa, pb] })
}

/// Largest error (m or rad) of the bodies' x, y and angle columns (`names[i]` is body i of
/// the reference; `None`: a point mass whose angle is not compared).
fn worst_body_error(sol: &Solution, names: &[(&str, bool)], reference: &[Vec<f64>]) -> f64 {
    let mut worst = 0.0f64;
    for (k, z) in reference.iter().enumerate() {
        for (i, &(name, angle)) in names.iter().enumerate() {
            let v = |c: &str| sol.value(k, &format!("{name}.{c}")).unwrap();
            worst = worst
                .max((v("x") - z[3 * i]).abs())
                .max((v("y") - z[3 * i + 1]).abs());
            if angle {
                worst = worst.max(angle_diff(v("angle"), z[3 * i + 2]).abs());
            }
        }
    }
    worst
}

fn times(t_end: f64) -> Vec<f64> {
    let n = (t_end / 0.01).round() as usize;
    (0..=n).map(|i| i as f64 * 0.01).collect()
}

// ---------------------------------------------------------------------------------------------
// Five-bar

const FIVE_BAR: [(&str, f64, f64); 4] = [
    ("c1", 0.5, 1.0),
    ("k2", 1.2, 1.5),
    ("k3", 1.2, 1.5),
    ("c4", 0.5, 1.0),
];
const FIVE_BAR_GROUND: f64 = 1.2;

/// The five-bar's bodies at crank angles q1 (at the origin) and q4 (at (d, 0)), the couplers'
/// joint C above the line from B to D.
fn five_bar_start(q1: f64, q4: f64) -> Vec<f64> {
    let (l1, l2, l3, l4, d) = (0.5, 1.2, 1.2, 0.5, FIVE_BAR_GROUND);
    let b = [l1 * q1.cos(), l1 * q1.sin()];
    let dd = [d + l4 * q4.cos(), l4 * q4.sin()];
    let s = ((dd[0] - b[0]).powi(2) + (dd[1] - b[1]).powi(2)).sqrt();
    let u = [(dd[0] - b[0]) / s, (dd[1] - b[1]) / s];
    let a = (l2 * l2 - l3 * l3 + s * s) / (2.0 * s);
    let h = (l2 * l2 - a * a).sqrt();
    let c = [b[0] + a * u[0] - h * u[1], b[1] + a * u[1] + h * u[0]];
    vec![
        b[0] / 2.0,
        b[1] / 2.0,
        q1,
        (b[0] + c[0]) / 2.0,
        (b[1] + c[1]) / 2.0,
        (c[1] - b[1]).atan2(c[0] - b[0]),
        (dd[0] + c[0]) / 2.0,
        (dd[1] + c[1]) / 2.0,
        (c[1] - dd[1]).atan2(c[0] - dd[0]),
        d + l4 / 2.0 * q4.cos(),
        l4 / 2.0 * q4.sin(),
        q4,
    ]
}

fn five_bar_scene(z0: &[f64], body_order: &[usize], joint_order: &[usize]) -> Value {
    let bodies: Vec<Value> = FIVE_BAR
        .iter()
        .enumerate()
        .map(|(i, &(n, l, m))| bar(n, l, m, &z0[3 * i..]))
        .collect();
    let joints = [
        pin("A", "ground", "c1", json!([0.0, 0.0]), json!("O")),
        pin("B", "c1", "k2", json!("A"), json!("O")),
        pin("C", "k2", "k3", json!("A"), json!("A")),
        pin("D", "k3", "c4", json!("O"), json!("A")),
        pin(
            "E",
            "ground",
            "c4",
            json!([FIVE_BAR_GROUND, 0.0]),
            json!("O"),
        ),
    ];
    json!({
        "name": "five_bar", "gravity": [0.0, -G],
        "bodies": body_order.iter().map(|&i| bodies[i].clone()).collect::<Vec<_>>(),
        "joints": joint_order.iter().map(|&i| joints[i].clone()).collect::<Vec<_>>(),
        "solve": solve_settings(3.0)
    })
}

fn five_bar_model() -> PinModel {
    let (h1, h2) = (0.25, 0.6);
    PinModel {
        bodies: FIVE_BAR
            .iter()
            .map(|&(_, l, m)| (m, m * l * l / 12.0))
            .collect(),
        pins: vec![
            (None, [0.0, 0.0], 0, [-h1, 0.0]),
            (Some(0), [h1, 0.0], 1, [-h2, 0.0]),
            (Some(1), [h2, 0.0], 2, [h2, 0.0]),
            (Some(2), [-h2, 0.0], 3, [h1, 0.0]),
            (None, [FIVE_BAR_GROUND, 0.0], 3, [-h1, 0.0]),
        ],
    }
}

/// Measured on main 593b5f3: 1.5e-6 (as written), 1.9e-6 (reversed), 3.2e-6 (shuffled); the
/// runs differ from each other by at most 2.3e-6.
#[test]
fn five_bar_released_from_rest_follows_the_reference_in_any_order() {
    let z0 = five_bar_start(-20f64.to_radians(), -150f64.to_radians());
    let t = times(3.0);
    let reference = five_bar_model().simulate(&z0, &t);
    let names: Vec<(&str, bool)> = FIVE_BAR.iter().map(|&(n, _, _)| (n, true)).collect();
    let orders: [(&str, [usize; 4], [usize; 5]); 3] = [
        ("as written", [0, 1, 2, 3], [0, 1, 2, 3, 4]),
        ("reversed", [3, 2, 1, 0], [4, 3, 2, 1, 0]),
        ("shuffled", [2, 0, 3, 1], [2, 4, 0, 3, 1]),
    ];
    let mut runs = Vec::new();
    for (what, bo, jo) in orders {
        let sol = run(&five_bar_scene(&z0, &bo, &jo));
        assert_eq!(sol.times.len(), t.len(), "{what}: every row");
        let e = worst_body_error(&sol, &names, &reference);
        assert!(e < 1e-5, "five-bar {what}: {e:.2e} from the reference");
        runs.push(sol);
    }
    for other in &runs[1..] {
        for (n, _) in &names {
            for c in ["x", "y", "angle"] {
                let col = format!("{n}.{c}");
                let (a, b) = (runs[0].column(&col).unwrap(), other.column(&col).unwrap());
                let d = a
                    .iter()
                    .zip(&b)
                    .map(|(p, q)| (p - q).abs())
                    .fold(0.0, f64::max);
                assert!(d < 1e-5, "{col}: orders differ by {d:.2e}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Bodies sharing one pin

const STAR: [(&str, f64, f64); 3] = [("A", 1.0, 1.0), ("B", 0.8, 0.7), ("C", 0.6, 0.5)];

/// Bar A pinned to the ground at its end O, bars B and C hinged at A's other end P, released
/// at rest at angles 0, −0.5, 1.0.
fn star_start() -> Vec<f64> {
    let (a, b, c) = (0.0f64, -0.5f64, 1.0f64);
    let p = [a.cos(), a.sin()];
    vec![
        0.5 * a.cos(),
        0.5 * a.sin(),
        a,
        p[0] + 0.4 * b.cos(),
        p[1] + 0.4 * b.sin(),
        b,
        p[0] + 0.3 * c.cos(),
        p[1] + 0.3 * c.sin(),
        c,
    ]
}

/// Measured on main 593b5f3: 4.2e-6 (A–B, A–C), 5.0e-6 (A–B, B–C), 2.7e-6 (A–C, C–B), 4.2e-6
/// (B–A, C–A).
#[test]
fn three_bars_on_one_pin_follow_the_reference_however_the_pin_is_written() {
    let z0 = star_start();
    let t = times(3.0);
    let model = PinModel {
        bodies: STAR
            .iter()
            .map(|&(_, l, m)| (m, m * l * l / 12.0))
            .collect(),
        pins: vec![
            (None, [0.0, 0.0], 0, [-0.5, 0.0]),
            (Some(0), [0.5, 0.0], 1, [-0.4, 0.0]),
            (Some(0), [0.5, 0.0], 2, [-0.3, 0.0]),
        ],
    };
    let reference = model.simulate(&z0, &t);
    let names: Vec<(&str, bool)> = STAR.iter().map(|&(n, _, _)| (n, true)).collect();
    let bodies: Vec<Value> = STAR
        .iter()
        .enumerate()
        .map(|(i, &(n, l, m))| bar(n, l, m, &z0[3 * i..]))
        .collect();
    let ways: [(&str, [StarPin; 2]); 4] = [
        ("A-B, A-C", [("A", "B", "A", "O"), ("A", "C", "A", "O")]),
        ("A-B, B-C", [("A", "B", "A", "O"), ("B", "C", "O", "O")]),
        ("A-C, C-B", [("A", "C", "A", "O"), ("C", "B", "O", "O")]),
        ("B-A, C-A", [("B", "A", "O", "A"), ("C", "A", "O", "A")]),
    ];
    for (what, pins) in ways {
        let mut joints = vec![pin("O", "ground", "A", json!([0.0, 0.0]), json!("O"))];
        for (i, (a, b, pa, pb)) in pins.iter().enumerate() {
            joints.push(pin(&format!("P{i}"), a, b, json!(pa), json!(pb)));
        }
        let scene = json!({ "name": "star", "gravity": [0.0, -G], "bodies": bodies,
                            "joints": joints, "solve": solve_settings(3.0) });
        let e = worst_body_error(&run(&scene), &names, &reference);
        assert!(e < 2e-5, "star written {what}: {e:.2e} from the reference");
    }
}

/// A double pendulum whose knee is a point mass K hinged to both bars (bar1 1 m 1 kg, K 0.8 kg,
/// bar2 0.7 m 0.6 kg), released at rest at 0 and 0.4 rad. Measured on main 593b5f3: 2.0e-7 (as
/// written), 1.8e-7 (reversed).
#[test]
fn a_point_mass_hinged_to_two_bars_follows_the_reference() {
    let (t1, t2) = (0.0f64, 0.4f64);
    let k = [t1.cos(), t1.sin()];
    let z0 = vec![
        0.5 * t1.cos(),
        0.5 * t1.sin(),
        t1,
        k[0],
        k[1],
        0.0,
        k[0] + 0.35 * t2.cos(),
        k[1] + 0.35 * t2.sin(),
        t2,
    ];
    let t = times(3.0);
    let model = PinModel {
        bodies: vec![(1.0, 1.0 / 12.0), (0.8, 0.0), (0.6, 0.6 * 0.49 / 12.0)],
        pins: vec![
            (None, [0.0, 0.0], 0, [-0.5, 0.0]),
            (Some(0), [0.5, 0.0], 1, [0.0, 0.0]),
            (Some(1), [0.0, 0.0], 2, [-0.35, 0.0]),
        ],
    };
    let reference = model.simulate(&z0, &t);
    let bodies = [
        bar("bar1", 1.0, 1.0, &z0[0..]),
        json!({ "name": "K", "mass": 0.8, "inertia": 0.0, "position": [k[0], k[1]] }),
        bar("bar2", 0.7, 0.6, &z0[6..]),
    ];
    let joints = [
        pin("shoulder", "ground", "bar1", json!([0.0, 0.0]), json!("O")),
        pin("k1", "bar1", "K", json!("A"), json!([0.0, 0.0])),
        pin("k2", "K", "bar2", json!([0.0, 0.0]), json!("O")),
    ];
    let names = [("bar1", true), ("K", false), ("bar2", true)];
    for (what, order) in [("as written", [0, 1, 2]), ("reversed", [2, 1, 0])] {
        let scene = json!({ "name": "knee", "gravity": [0.0, -G],
            "bodies": order.iter().map(|&i| bodies[i].clone()).collect::<Vec<_>>(),
            "joints": order.iter().map(|&i| joints[i].clone()).collect::<Vec<_>>(),
            "solve": solve_settings(3.0) });
        let e = worst_body_error(&run(&scene), &names, &reference);
        assert!(e < 1e-5, "knee {what}: {e:.2e} from the reference");
    }
}

// ---------------------------------------------------------------------------------------------
// Bead in a slot

/// A bar (mass `mb`, length `lb`, centre `cb` from the pivot along the slot's direction) pinned
/// to the ground at its point P; a bead (point mass `m`) in a slot parallel to the bar's axis
/// at the offset `h`, at `R(θ) (s, h)` from the pivot; a spring (stiffness `k`, rest length
/// `l0`) from the bar's point `(ax, ay)` (pivot frame) to the bead. With `J_P = mb lb²/12 + mb cb²`:
///
/// `T = ½ J_P θ'² + ½ m ((s' − h θ')² + s² θ'²)`,
/// `V = mb g cb sin θ + m g (s sin θ + h cos θ) + ½ k (|d| − l0)²`, `d = (s − ax, h − ay)`,
///
/// so with `M = [[J_P + m (h² + s²), −m h], [−m h, m]]`:
/// `M (θ'', s'') = (−2 m s s' θ' − ∂V/∂θ, m s θ'² − ∂V/∂s)`,
/// `∂V/∂θ = mb g cb cos θ + m g (s cos θ − h sin θ)`, `∂V/∂s = m g sin θ + k (|d| − l0)(s − ax)/|d|`
/// (`k d_s` when `l0 = 0`). Regular at `s = 0`: the bead passes the pivot.
#[derive(Clone, Copy)]
struct Bead {
    mb: f64,
    lb: f64,
    cb: f64,
    m: f64,
    h: f64,
    k: f64,
    anchor: [f64; 2],
    l0: f64,
}

impl Bead {
    fn simulate(&self, s0: f64, t: &[f64]) -> Vec<Vec<f64>> {
        let b = *self;
        let jp = b.mb * b.lb * b.lb / 12.0 + b.mb * b.cb * b.cb;
        integrate(
            move |_, y, dy| {
                let (th, s, thd, sd) = (y[0], y[1], y[2], y[3]);
                let (sn, c) = th.sin_cos();
                let (dx, dyy) = (s - b.anchor[0], b.h - b.anchor[1]);
                let spring = if b.l0 == 0.0 {
                    b.k * dx
                } else {
                    let len = (dx * dx + dyy * dyy).sqrt();
                    b.k * (len - b.l0) * dx / len
                };
                let dv_th = b.mb * G * b.cb * c + b.m * G * (s * c - b.h * sn);
                let dv_s = b.m * G * sn + spring;
                let f = [
                    -2.0 * b.m * s * sd * thd - dv_th,
                    b.m * s * thd * thd - dv_s,
                ];
                let (m11, m12, m22) = (jp + b.m * (b.h * b.h + s * s), -b.m * b.h, b.m);
                let det = m11 * m22 - m12 * m12;
                dy[0] = thd;
                dy[1] = sd;
                dy[2] = (m22 * f[0] - m12 * f[1]) / det;
                dy[3] = (m11 * f[1] - m12 * f[0]) / det;
            },
            0.0,
            &[0.0, s0, 0.0, 0.0],
            t,
            REFERENCE_RTOL,
            REFERENCE_ATOL,
        )
    }

    /// The scene, the bar horizontal at rest, the bead at `s0`.
    fn scene(&self, s0: f64, t_end: f64) -> Value {
        json!({
            "name": "bead_variant", "gravity": [0.0, -G],
            "bodies": [
                { "name": "bar", "mass": self.mb, "inertia": self.mb * self.lb * self.lb / 12.0,
                  "points": { "P": [-self.cb, 0.0], "S": [-self.cb, self.h],
                              "Q": [self.anchor[0] - self.cb, self.anchor[1]] },
                  "position": [self.cb, 0.0], "angle": 0.0 },
                { "name": "bead", "mass": self.m, "inertia": 0.0, "position": [s0, self.h] }
            ],
            "joints": [
                { "name": "pivot", "type": "revolute", "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "P"] },
                { "name": "slot", "type": "slot", "bodies": ["bar", "bead"], "points": ["S", [0.0, 0.0]], "axis": [1.0, 0.0] }
            ],
            "springs": [{ "name": "spring", "bodies": ["bar", "bead"], "points": ["Q", [0.0, 0.0]],
                          "stiffness": self.k, "rest_length": self.l0 }],
            "solve": solve_settings(t_end)
        })
    }

    /// Largest error of the bar's angle and the bead's position, and the times the bead
    /// crossed the foot of the slot (s = 0) in the reference.
    fn check(&self, s0: f64, t_end: f64) -> (f64, usize) {
        let t = times(t_end);
        let reference = self.simulate(s0, &t);
        let sol = run(&self.scene(s0, t_end));
        assert_eq!(sol.times.len(), t.len());
        let mut worst = 0.0f64;
        for (k, y) in reference.iter().enumerate() {
            let v = |c: &str| sol.value(k, c).unwrap();
            let (sn, c) = y[0].sin_cos();
            let (bx, by) = (y[1] * c - self.h * sn, y[1] * sn + self.h * c);
            worst = worst
                .max(angle_diff(v("bar.angle"), y[0]).abs())
                .max((v("bead.x") - bx).abs())
                .max((v("bead.y") - by).abs());
        }
        let crossings = reference
            .windows(2)
            .filter(|w| w[0][1].signum() != w[1][1].signum())
            .count();
        (worst, crossings)
    }
}

/// The bar (1.5 m) pinned 0.25 m off its centre, the spring from the bar's far end with rest
/// length 0.9 m: the bead swings through the pivot 25 times in 10 s. Measured on main 593b5f3:
/// 2.5e-7.
#[test]
fn a_bead_pulled_through_an_off_centre_pivot_by_a_spring_with_rest_length() {
    let b = Bead {
        mb: 1.0,
        lb: 1.5,
        cb: 0.25,
        m: 0.5,
        h: 0.0,
        k: 30.0,
        anchor: [1.0, 0.0],
        l0: 0.9,
    };
    let (e, crossings) = b.check(0.6, 10.0);
    assert!(
        crossings >= 20,
        "the bead passes the pivot ({crossings} times)"
    );
    assert!(e < 1e-5, "{e:.2e} from the reference");
}

/// The slot 0.1 m beside the pivot (the bead never reaches the pivot; its slot's foot s = 0
/// passes it six times in 3 s), and the bead starting exactly at the pivot of a slot through it
/// (17 passes in 10 s). Measured on main 593b5f3: 5.7e-7 and 1.3e-6.
#[test]
fn a_bead_in_an_offset_slot_and_one_starting_at_the_pivot() {
    let offset = Bead {
        mb: 1.0,
        lb: 1.0,
        cb: 0.5,
        m: 0.5,
        h: 0.1,
        k: 20.0,
        anchor: [0.0, 0.1],
        l0: 0.0,
    };
    let (e, crossings) = offset.check(0.6, 3.0);
    assert!(crossings >= 4, "{crossings} passes");
    assert!(e < 1e-5, "offset slot: {e:.2e} from the reference");
    let at_pivot = Bead {
        h: 0.0,
        anchor: [0.0, 0.0],
        ..offset
    };
    let (e, crossings) = at_pivot.check(0.0, 10.0);
    assert!(crossings >= 10, "{crossings} passes");
    assert!(e < 1e-5, "bead from the pivot: {e:.2e} from the reference");
}

// ---------------------------------------------------------------------------------------------
// Rolling and a driveshaft

/// A disc (2 kg, radius 0.1 m, J = m ρ²/2) rolling on a fixed rack inclined at 0.3 rad (the
/// ground as the rack, its centre in a slot parallel to the incline), thrown uphill at 1 m/s:
/// `x = v0 t + a t²/2` along the incline, `a = g sin α / (1 + J/(m ρ²))`, angle `−x/ρ`.
/// Measured on main 593b5f3: 1.6e-10.
#[test]
fn a_disc_rolls_on_an_inclined_rack_exactly() {
    let (al, rho, m, v0): (f64, f64, f64, f64) = (0.3, 0.1, 2.0, -1.0);
    let j = 0.5 * m * rho * rho;
    let acc = G * al.sin() / (1.0 + j / (m * rho * rho));
    let u = [al.cos(), -al.sin()];
    let n = [al.sin(), al.cos()];
    let c0 = [rho * n[0], rho * n[1]];
    let scene = json!({
        "name": "rolling_disc", "gravity": [0.0, -G],
        "bodies": [{ "name": "disc", "mass": m, "inertia": j, "position": c0,
                     "velocity": [v0 * u[0], v0 * u[1]], "angular_velocity": -v0 / rho }],
        "joints": [
            { "name": "track", "type": "slot", "bodies": ["ground", "disc"], "points": [c0, [0.0, 0.0]], "axis": u },
            { "name": "teeth", "type": "rack_pinion", "bodies": ["disc", "ground"], "points": [[0.0, 0.0], [0.0, 0.0]],
              "radius": rho, "axis": u }
        ],
        "solve": solve_settings(2.0)
    });
    let sol = run(&scene);
    let mut worst = 0.0f64;
    for (k, &t) in sol.times.iter().enumerate() {
        let x = v0 * t + 0.5 * acc * t * t;
        let v = |c: &str| sol.value(k, c).unwrap();
        worst = worst
            .max((v("disc.x") - c0[0] - x * u[0]).abs())
            .max((v("disc.y") - c0[1] - x * u[1]).abs())
            .max((v("disc.angle") + x / rho).abs());
    }
    assert!(worst < 1e-8, "{worst:.2e} from the exact rolling");
}

const BETA: f64 = 0.5;
const J_AXIAL: f64 = 0.002;

/// Two shafts (1 kg, moments [0.002, 0.03, 0.03], axis along body x) meeting at the origin at
/// the angle β, each in its own bearing (a spatial hinge to the ground along its axis), joined
/// by a universal joint whose forks are shaft 1's y and shaft 2's z: the bearings and the cross
/// repeat the cross's point rows (redundant joints), as a user writes a driveshaft.
fn driveshaft(driven: bool) -> Value {
    let d = [BETA.cos(), BETA.sin(), 0.0];
    let mut scene = json!({
        "name": "driveshaft", "dimension": 3,
        "bodies": [
            { "name": "shaft1", "mass": 1.0, "inertia": [J_AXIAL, 0.03, 0.03],
              "points": { "B": [0.0, 0.0, 0.0], "U": [0.3, 0.0, 0.0] },
              "position": [-0.3, 0.0, 0.0], "angular_velocity": [3.0, 0.0, 0.0] },
            { "name": "shaft2", "mass": 1.0, "inertia": [J_AXIAL, 0.03, 0.03],
              "points": { "B": [0.0, 0.0, 0.0], "U": [-0.3, 0.0, 0.0] },
              "position": [0.3 * d[0], 0.3 * d[1], 0.0], "cardan": [BETA, 0.0, 0.0],
              "angular_velocity": [3.0 / BETA.cos(), 0.0, 0.0] }
        ],
        "joints": [
            { "name": "bearing1", "type": "revolute", "bodies": ["ground", "shaft1"], "points": [[-0.3, 0.0, 0.0], "B"], "axis": [1.0, 0.0, 0.0] },
            { "name": "bearing2", "type": "revolute", "bodies": ["ground", "shaft2"], "points": [[0.3 * d[0], 0.3 * d[1], 0.0], "B"], "axis": d },
            { "name": "cross", "type": "universal", "bodies": ["shaft1", "shaft2"], "points": ["U", "U"], "axes": [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }
        ],
        "solve": solve_settings(3.0)
    });
    if driven {
        scene["drivers"] =
            json!([{ "name": "motor", "joint": "bearing1", "angular_velocity": 3.0 }]);
    }
    scene
}

/// Largest error of both shafts' Cardan φ against `(θ1, θ2)` per row.
fn shaft_error(sol: &Solution, reference: &[(f64, f64)]) -> f64 {
    let mut worst = 0.0f64;
    for (k, &(t1, t2)) in reference.iter().enumerate() {
        let v = |c: &str| sol.value(k, c).unwrap();
        worst = worst
            .max(angle_diff(v("shaft1.phi"), t1).abs())
            .max(angle_diff(v("shaft2.phi"), t2).abs());
    }
    worst
}

/// Driven at 3 rad/s: `θ2 = atan2(sin θ1, cos β cos θ1)` exactly. Measured on main 593b5f3:
/// 9e-16.
#[test]
fn a_driveshaft_in_two_bearings_driven_obeys_hookes_law() {
    let sol = run(&driveshaft(true));
    assert!(
        !sol.summary.redundant_joints.is_empty(),
        "the bearings and the cross are redundant"
    );
    let reference: Vec<(f64, f64)> = sol
        .times
        .iter()
        .map(|&t| {
            let t1 = 3.0 * t;
            (t1, t1.sin().atan2(BETA.cos() * t1.cos()))
        })
        .collect();
    let e = shaft_error(&sol, &reference);
    assert!(e < 1e-8, "{e:.2e} from tan θ2 = tan θ1 / cos β");
}

/// Free: one DOF θ1 with `T = ½ (J1 + J2 r²) θ1'²`, `r = dθ2/dθ1 = cos β / (cos²β cos²θ1 +
/// sin²θ1)`, so `(J1 + J2 r²) θ1'' = −J2 r r' θ1'²`, `r' = −cos β sin 2θ1 (1 − cos²β) / den²`.
/// Measured on main 593b5f3: 1.4e-7.
#[test]
fn a_free_driveshaft_in_two_bearings_follows_the_reference() {
    let cb = BETA.cos();
    let t = times(3.0);
    let ys = integrate(
        |_, y, dy| {
            let (s, c) = y[0].sin_cos();
            let den = cb * cb * c * c + s * s;
            let r = cb / den;
            let rp = -cb * 2.0 * s * c * (1.0 - cb * cb) / (den * den);
            dy[0] = y[1];
            dy[1] = -J_AXIAL * r * rp * y[1] * y[1] / (J_AXIAL + J_AXIAL * r * r);
        },
        0.0,
        &[0.0, 3.0],
        &t,
        REFERENCE_RTOL,
        REFERENCE_ATOL,
    );
    let reference: Vec<(f64, f64)> = ys
        .iter()
        .map(|y| (y[0], y[0].sin().atan2(cb * y[0].cos())))
        .collect();
    let sol = run(&driveshaft(false));
    assert_eq!(sol.times.len(), t.len());
    let e = shaft_error(&sol, &reference);
    assert!(e < 1e-6, "{e:.2e} from the 1-DOF reference");
}
