//! Equations generated from the seed's mechanism bond graphs (sections 16.5 and 16.7), written
//! as raw JSON following Fig. 16/20 with bars in the translating frame (Fig. 24), and from a
//! graph that forces a capacitor into differential causality. The reference rows are derived
//! by hand from planar rigid-body kinematics (`V_P = V + ω × r_P`), independently of the code.

use bondmech::bond::equations::{BondEquations, VariableKind};
use bondmech::bond::{assign_causality, BondGraph, RawBondGraph};
use serde_json::{json, Value};

fn graph(v: Value) -> BondGraph {
    let raw: RawBondGraph = serde_json::from_value(v).unwrap();
    raw.to_graph().unwrap()
}

/// Deterministic pseudo-random numbers in `[lo, hi)`.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Bar data: mass, centroidal inertia, half length.
#[derive(Clone, Copy)]
struct Bar {
    m: f64,
    j: f64,
    a: f64,
}

const BAR1: Bar = Bar {
    m: 2.0,
    j: 0.3,
    a: 0.6,
};
const BAR2: Bar = Bar {
    m: 1.5,
    j: 0.2,
    a: 0.4,
};

/// One bar `b` in the translating frame (Fig. 24): 1-junctions `vx vy w` with inertias
/// `mx my J`; each point P at `r_P` (a function of the bar angle `x_<b>w`) is a 0-junction
/// `s<P><axis>` per axis adding `V` and the MTF term `(ω × r_P)`, i.e. moduli `−r_y` and `r_x`.
/// The point's velocity leaves the 0-junction on its outward bond.
fn bar_json(
    elements: &mut Vec<Value>,
    bonds: &mut Vec<Value>,
    b: &str,
    bar: Bar,
    points: &[(&str, f64)],
) {
    for (jn, i, v) in [("vx", "mx", bar.m), ("vy", "my", bar.m), ("w", "J", bar.j)] {
        elements.push(json!({"name": format!("{b}{jn}"), "kind": "1"}));
        elements.push(json!({"name": format!("{b}{i}"), "kind": "I", "value": v}));
        bonds.push(json!({"from": format!("{b}{jn}"), "to": format!("{b}{i}")}));
    }
    for (p, along) in points {
        // r_P = along·a·(cos θ, sin θ)
        let k = along * bar.a;
        let mx = format!("-{k}*sin(x_{b}w)");
        let my = format!("{k}*cos(x_{b}w)");
        for (axis, modulus) in [("x", mx), ("y", my)] {
            let s = format!("{b}s{p}{axis}");
            let mm = format!("{b}m{p}{axis}");
            elements.push(json!({"name": s, "kind": "0"}));
            elements.push(json!({"name": mm, "kind": "MTF", "modulus": modulus}));
            bonds.push(json!({"from": format!("{b}v{axis}"), "to": s}));
            bonds.push(json!({"from": format!("{b}w"), "to": mm}));
            bonds.push(json!({"from": mm, "to": s}));
        }
    }
}

/// Two bars hinged at A (Fig. 16): a 1-junction `A<axis>` equates the velocity of A seen from
/// both bars (both point bonds flow into it, so the pin forces are equal and opposite). With
/// `pinned`, bar 1's end O is tied to ground by a zero flow source per axis (16.7, Fig. 20).
fn hinged_bars(pinned: bool) -> Value {
    let (mut e, mut b) = (vec![], vec![]);
    let mut p1 = vec![("A", 1.0)];
    if pinned {
        p1.push(("O", -1.0));
    }
    bar_json(&mut e, &mut b, "1", BAR1, &p1);
    bar_json(&mut e, &mut b, "2", BAR2, &[("A", -1.0)]);
    for axis in ["x", "y"] {
        let j = format!("A{axis}");
        e.push(json!({"name": j, "kind": "1"}));
        b.push(json!({"from": format!("1sA{axis}"), "to": j}));
        b.push(json!({"from": format!("2sA{axis}"), "to": j}));
        if pinned {
            let sf = format!("O{axis}");
            e.push(json!({"name": sf, "kind": "Sf", "value": 0.0}));
            b.push(json!({"from": format!("1sO{axis}"), "to": sf}));
        }
    }
    json!({"elements": e, "bonds": b})
}

fn equations(v: Value) -> BondEquations {
    let g = graph(v);
    BondEquations::new(&g, &assign_causality(&g).unwrap()).unwrap()
}

/// `[t, y]` with `y` filled by name; unnamed entries (multipliers) are 0.
fn slots(e: &BondEquations, values: &[(&str, f64)]) -> Vec<f64> {
    let mut v = vec![0.0; 1 + e.n];
    for (name, x) in values {
        let i = e
            .names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no unknown {name} in {:?}", e.names));
        v[1 + i] = *x;
    }
    v
}

fn rows(e: &BondEquations, vars: &[f64]) -> Vec<f64> {
    e.constraints
        .iter()
        .map(|&c| e.graph.eval(c, vars))
        .collect()
}

fn assert_close(got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() <= tol * (1.0 + w.abs()),
            "got {got:?}\nwant {want:?}"
        );
    }
}

/// Velocity of a point at `r = along·a·(cos θ, sin θ)` of a bar with centre velocity `v`.
fn point_velocity(v: [f64; 2], w: f64, bar: Bar, th: f64, along: f64) -> [f64; 2] {
    let r = [along * bar.a * th.cos(), along * bar.a * th.sin()];
    [v[0] - w * r[1], v[1] + w * r[0]]
}

// ------------------------------------------------------------ 16.7 double pendulum

/// The pendulum's velocity-level rows by hand, with the partition chosen at the graph's state
/// (both bars horizontal, x_1w = x_2w = 0; issue 13): the rotations are integral (ω1, ω2), the
/// translations differential in order `1mx 1my 2mx 2my`. The old SCAP partition (integral
/// 1mx, 2mx) found ω1 = −v1x/(a1 s1), a division by sin θ1 = 0 at that very state (NaN at
/// t = 0); this one never divides. By hand, with ω_i = h_i/J_i:
///   O fixed:  v1 = ω1 × (a1 e1)  (v1x = −a1 s1 ω1, v1y = a1 c1 ω1),
///   A shared: V_A1 = v1 + ω1 × (a1 e1),  v2 = V_A1 + ω2 × (a2 e2),
/// and each row is (velocity the pins require) − (velocity of the stored momentum).
fn pendulum_rows_by_hand(y: &Pend) -> [f64; 4] {
    let w1 = y.h1 / BAR1.j;
    let w2 = y.h2 / BAR2.j;
    let v1 = point_velocity([0.0, 0.0], w1, BAR1, y.th1, 1.0);
    let va = point_velocity(v1, w1, BAR1, y.th1, 1.0);
    let v2 = point_velocity(va, w2, BAR2, y.th2, 1.0);
    [
        v1[0] - y.p1x / BAR1.m,
        v1[1] - y.p1y / BAR1.m,
        v2[0] - y.p2x / BAR2.m,
        v2[1] - y.p2y / BAR2.m,
    ]
}

/// Positions and momenta of the two bars.
struct Pend {
    th1: f64,
    th2: f64,
    p1x: f64,
    p1y: f64,
    h1: f64,
    p2x: f64,
    p2y: f64,
    h2: f64,
}

impl Pend {
    /// The consistent state of the pinned pendulum for angles and angular velocities.
    fn consistent(th1: f64, th2: f64, w1: f64, w2: f64) -> Pend {
        let v1 = point_velocity([0.0, 0.0], w1, BAR1, th1, 1.0); // centre = O + ω×(a1 e1)
        let va = point_velocity([0.0, 0.0], w1, BAR1, th1, 2.0);
        let v2 = point_velocity(va, w2, BAR2, th2, 1.0);
        Pend {
            th1,
            th2,
            p1x: BAR1.m * v1[0],
            p1y: BAR1.m * v1[1],
            h1: BAR1.j * w1,
            p2x: BAR2.m * v2[0],
            p2y: BAR2.m * v2[1],
            h2: BAR2.j * w2,
        }
    }

    fn slots(&self, e: &BondEquations) -> Vec<f64> {
        slots(
            e,
            &[
                ("x_1w", self.th1),
                ("x_2w", self.th2),
                ("p_1mx", self.p1x),
                ("p_1my", self.p1y),
                ("p_1J", self.h1),
                ("p_2mx", self.p2x),
                ("p_2my", self.p2y),
                ("p_2J", self.h2),
            ],
        )
    }
}

/// An angle away from `sin θ = 0` (the rows are regular everywhere in this partition; the
/// sample keeps the states of the original test).
fn angle(r: &mut Lcg) -> f64 {
    let a = r.next(0.3, std::f64::consts::PI - 0.3);
    if r.next(0.0, 1.0) < 0.5 {
        a
    } else {
        -a
    }
}

#[test]
fn double_pendulum_has_four_constraint_rows_and_four_unknown_efforts() {
    let e = equations(hinged_bars(true));
    assert_eq!(e.n_dependent, 4);
    assert_eq!(e.constraints.len(), 4);
    assert_eq!(
        e.algebraic_names(),
        vec!["lambda_1mx", "lambda_1my", "lambda_2mx", "lambda_2my"]
    );
    let multipliers = e.kinds.iter().filter(|k| **k == VariableKind::Multiplier);
    assert_eq!(multipliers.count(), 4);
    // the two integral momenta and the two bar angles a modulus refers to
    assert_eq!(e.state_names(), ["p_1J", "p_2J", "x_1w", "x_2w"]);
}

#[test]
fn double_pendulum_rows_vanish_at_consistent_velocities() {
    let e = equations(hinged_bars(true));
    let mut r = Lcg(20);
    for _ in 0..30 {
        let y = Pend::consistent(
            angle(&mut r),
            angle(&mut r),
            r.next(-3.0, 3.0),
            r.next(-3.0, 3.0),
        );
        let got = rows(&e, &y.slots(&e));
        assert!(got.iter().all(|c| c.abs() < 1e-12), "{got:?}");
    }
}

#[test]
fn double_pendulum_rows_match_hand_kinematics_at_inconsistent_states() {
    let e = equations(hinged_bars(true));
    let mut r = Lcg(21);
    for _ in 0..30 {
        let y = Pend {
            th1: angle(&mut r),
            th2: angle(&mut r),
            p1x: r.next(-2.0, 2.0),
            p1y: r.next(-2.0, 2.0),
            h1: r.next(-2.0, 2.0),
            p2x: r.next(-2.0, 2.0),
            p2y: r.next(-2.0, 2.0),
            h2: r.next(-2.0, 2.0),
        };
        assert_close(&rows(&e, &y.slots(&e)), &pendulum_rows_by_hand(&y), 1e-11);
    }
}

#[test]
fn knee_velocity_mismatch_shows_in_the_second_bar_rows() {
    // Start consistent, then give bar 2 an extra δ along x keeping every other momentum. With
    // the rotations integral (the partition at the horizontal start), the pins require the
    // same v2x as before, so the row of 2mx becomes −δ (required − stored) and the others
    // stay 0: the knee's slip shows in bar 2's x row only.
    let e = equations(hinged_bars(true));
    let (th1, th2, delta) = (0.7, -1.1, 0.05);
    let mut y = Pend::consistent(th1, th2, 1.3, -0.4);
    y.p2x += BAR2.m * delta;
    let want = [0.0, 0.0, -delta, 0.0];
    assert_close(&rows(&e, &y.slots(&e)), &want, 1e-12);
}

// ------------------------------------------------------------ 16.5 two hinged bars

#[test]
fn two_hinged_bars_have_two_constraint_rows_matching_the_knee_kinematics() {
    // Integral: 1mx 1my 1J 2J; differential: 2mx 2my (the knee's rows pivot on bar 2's
    // translations at the horizontal start; the old partition 2my 2J divided by sin θ2 = 0
    // there). From the knee, v2 = V_A1 + ω2 × (a2 e2).
    let e = equations(hinged_bars(false));
    assert_eq!(e.constraints.len(), 2);
    assert_eq!(e.algebraic_names(), vec!["lambda_2mx", "lambda_2my"]);
    assert_eq!(
        e.state_names(),
        ["p_1mx", "p_1my", "p_1J", "p_2J", "x_1w", "x_2w"]
    );
    let mut r = Lcg(22);
    for _ in 0..30 {
        let (th1, th2) = (r.next(-3.0, 3.0), angle(&mut r));
        let p: Vec<f64> = (0..6).map(|_| r.next(-2.0, 2.0)).collect();
        let (v1, w1) = ([p[0] / BAR1.m, p[1] / BAR1.m], p[2] / BAR1.j);
        let va = point_velocity(v1, w1, BAR1, th1, 1.0);
        let v2 = point_velocity(va, p[5] / BAR2.j, BAR2, th2, 1.0);
        let want = [v2[0] - p[3] / BAR2.m, v2[1] - p[4] / BAR2.m];
        let vars = slots(
            &e,
            &[
                ("x_1w", th1),
                ("x_2w", th2),
                ("p_1mx", p[0]),
                ("p_1my", p[1]),
                ("p_1J", p[2]),
                ("p_2mx", p[3]),
                ("p_2my", p[4]),
                ("p_2J", p[5]),
            ],
        );
        assert_close(&rows(&e, &vars), &want, 1e-11);
        // and with bar 2 moved rigidly with the knee the rows vanish
        let w2c = r.next(-3.0, 3.0);
        let v2 = point_velocity(va, w2c, BAR2, th2, 1.0);
        let vars = slots(
            &e,
            &[
                ("x_1w", th1),
                ("x_2w", th2),
                ("p_1mx", p[0]),
                ("p_1my", p[1]),
                ("p_1J", p[2]),
                ("p_2mx", BAR2.m * v2[0]),
                ("p_2my", BAR2.m * v2[1]),
                ("p_2J", BAR2.j * w2c),
            ],
        );
        let got = rows(&e, &vars);
        assert!(got.iter().all(|c| c.abs() < 1e-12), "{got:?}");
    }
}

// ------------------------------------------------------------ differential capacitor

#[test]
fn parallel_capacitors_put_the_second_in_differential_causality() {
    // A flow source F charging two capacitors on one 0-junction: they share the effort, so once
    // C1 takes integral causality C2 can only receive the effort (SCAP: differential). Hand:
    //   row  q1/C1 − q2/C2 = 0 (equal efforts), q̇1 = F − μ, q̇2 = μ (μ the flow C2 imposes);
    //   differentiating the row, (F − μ)/C1 = μ/C2 → μ = F·C2/(C1 + C2): the compliances add.
    let (f, c1, c2) = (0.8, 0.5, 1.5);
    let g = graph(json!({"elements": [
        {"name": "F", "kind": "Sf", "value": f},
        {"name": "0", "kind": "0"},
        {"name": "C1", "kind": "C", "compliance": c1},
        {"name": "C2", "kind": "C", "compliance": c2}],
     "bonds": [{"from": "F", "to": "0"}, {"from": "0", "to": "C1"}, {"from": "0", "to": "C2"}]}));
    let c = assign_causality(&g).unwrap();
    let report = c.report(&g);
    assert_eq!(report.states, vec!["C1"]);
    assert_eq!(report.differential.len(), 1);
    assert_eq!(report.differential[0].element, "C2");
    // its effort is the 0-junction's common effort, imposed by C1
    assert_eq!(report.differential[0].forced_by_junction, "0");
    assert_eq!(report.differential[0].via_elements, vec!["C1"]);
    let e = BondEquations::new(&g, &c).unwrap();
    assert_eq!(e.names, vec!["q_C1", "q_C2", "lambda_C2"]);
    assert_eq!(e.constraints.len(), 1);
    let mut r = Lcg(23);
    for _ in 0..20 {
        let (q1, q2, mu) = (r.next(-1.0, 1.0), r.next(-1.0, 1.0), r.next(-1.0, 1.0));
        let vars = [0.0, q1, q2, mu];
        assert_close(&rows(&e, &vars), &[q1 / c1 - q2 / c2], 1e-13);
        assert_close(&[e.graph.eval(e.rhs[0], &vars)], &[f - mu], 1e-13);
    }
    let q1 = 0.3;
    let (y, yp) = e.consistent_start(0.0, &[q1, 0.0, 0.0]).unwrap();
    let mu = f * c2 / (c1 + c2);
    assert_close(&y, &[q1, q1 * c2 / c1, mu], 1e-12);
    assert_close(&yp[..2], &[f - mu, mu], 1e-12);
}
