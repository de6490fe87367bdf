//! `linearize` of spatial rigid bodies (issue 48): the attitude in a three-angle chart about the
//! operating point (a space-frame rotation vector `φ`, `R = exp([φ]×) R₀`, turning with the
//! operating point's angular velocity; the velocity states the space-frame angular velocity
//! `B.wX, B.wY, B.wZ`), against closed forms derived below, never bondmech's output.

use bondmech::{linearize, LinearModel, LinearizeOptions, OperatingPoint, Scene};
use serde_json::{json, Value};

const G: f64 = 9.81;

fn scene(v: &Value) -> Scene {
    Scene::from_json_str(&v.to_string()).unwrap()
}

fn at(t: f64) -> LinearizeOptions {
    LinearizeOptions {
        at: OperatingPoint::Time(t),
        ..LinearizeOptions::default()
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// A symmetric body `top` (mass `m`, principal moments `[jc, jc, j3]` about its centre, the
/// symmetry axis along body `axis`) on a spherical joint at the origin, its centre `l` above
/// it (`l < 0`: below), the symmetry axis vertical, spinning at `spin` rad/s about it.
fn top(m: f64, jc: f64, j3: f64, l: f64, spin: f64, axis: usize) -> Value {
    let (inertia, ball, cardan, w) = match axis {
        // body z vertical
        2 => (
            [jc, jc, j3],
            [0.0, 0.0, -l],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, spin],
        ),
        // body x turned vertical by θ = −π/2 about y: R_y(−π/2) e_x = e_z
        _ => (
            [j3, jc, jc],
            [-l, 0.0, 0.0],
            [0.0, -std::f64::consts::FRAC_PI_2, 0.0],
            [spin, 0.0, 0.0],
        ),
    };
    json!({
        "name": "top", "dimension": 3, "gravity": [0.0, 0.0, -G],
        "bodies": [{"name": "top", "mass": m, "inertia": inertia,
                    "points": {"ball": ball},
                    "position": [0.0, 0.0, l], "cardan": cardan,
                    "velocity": [0.0, 0.0, 0.0], "angular_velocity": w}],
        "joints": [{"name": "ball", "type": "spherical", "bodies": ["ground", "top"],
                    "points": [[0.0, 0.0, 0.0], "ball"]}],
        "solve": {"t_end": 1.0, "rtol": 1e-10, "atol": 1e-12}
    })
}

fn largest_real_part(lm: &LinearModel) -> f64 {
    lm.eigenvalues
        .iter()
        .fold(f64::NEG_INFINITY, |m, e| m.max(e.0))
}

/// The positive imaginary parts of the eigenvalues away from zero, ascending.
fn frequencies(lm: &LinearModel, floor: f64) -> Vec<f64> {
    let mut w: Vec<f64> = lm
        .eigenvalues
        .iter()
        .filter(|e| e.1 > floor)
        .map(|e| e.1)
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

/// The sleeping top (Lagrange top spinning upright), derived here.
///
/// Let `J₁ = J_c + m l²` be the transverse moment about the fixed point (the scene gives
/// `J_c` about the centre), `J₃` the axial one, `Ω` the spin. Near upright let the axis be
/// `k = (u_x, u_y, 1)` in space, `u = u_x + i u_y`. The spin `n = ω·k = Ω` is conserved (the
/// body is symmetric and gravity has no torque about the axis); the angular momentum about the
/// fixed point is `L = J₁ k × k̇ + J₃ n k`, so its horizontal part is, to first order,
/// `L_h = J₁ (−u̇_y, u̇_x) + J₃ Ω (u_x, u_y)`, i.e. `L_h = i J₁ u̇ + J₃ Ω u` in complex form. The
/// gravity torque `(l k) × (−m g e_z) = m g l (−u_y, u_x)` is `i m g l u`. `L̇_h = τ_h`:
///
/// ```text
///   i J₁ ü + J₃ Ω u̇ = i m g l u   ⇔   J₁ ü − i J₃ Ω u̇ − m g l u = 0,
/// ```
///
/// and `u = e^{st}` gives `J₁ s² − i J₃ Ω s − m g l = 0`, `s = i [J₃Ω ± √(J₃²Ω² − 4 J₁ m g l)] / (2 J₁)`.
/// With the conjugate equation (for `ū`) the real characteristic polynomial is
/// `(J₁s² − mgl)² + J₃²Ω² s² = J₁² s⁴ + (J₃²Ω² − 2 J₁ m g l) s² + (m g l)²`: the eigenvalues
/// are `±i ω±`, `ω± = [J₃Ω ± √(J₃²Ω² − 4 J₁ m g l)] / (2 J₁)` (nutation `ω+`, slow precession
/// `ω−`) when `J₃²Ω² > 4 J₁ m g l`, and a pair with positive real part below: the threshold
/// is `Ω² = 4 m g l J₁ / J₃²`. The spin angle and the spin rate add a zero pair.
fn sleeping_top_reference(m: f64, jc: f64, j3: f64, l: f64, spin: f64) -> (f64, f64) {
    let j1 = jc + m * l * l;
    let mgl = m * G * l;
    let root = (j3 * j3 * spin * spin - 4.0 * j1 * mgl).sqrt();
    (
        (j3 * spin - root) / (2.0 * j1),
        (j3 * spin + root) / (2.0 * j1),
    )
}

#[test]
fn sleeping_top_has_the_closed_form_nutation_and_precession_frequencies() {
    // the bundled heavy top's numbers: 1 kg, l = 0.5, J_c = [0.02, 0.02, 0.03]
    let (m, jc, j3, l) = (1.0, 0.02, 0.03, 0.5);
    for axis in [2, 0] {
        for spin in [120.0, 200.0, 400.0] {
            let lm = linearize(&scene(&top(m, jc, j3, l, spin, axis)), &at(0.0)).unwrap();
            assert!(!lm.equilibrium, "a spinning top is a steady motion");
            assert!(lm.modes.is_empty());
            assert_eq!(lm.states.len(), 6, "{:?}", lm.states);
            for s in ["top.rx", "top.ry", "top.rz", "top.wX", "top.wY", "top.wZ"] {
                assert!(lm.states.iter().any(|x| x == s), "{s} in {:?}", lm.states);
            }
            let (slow, fast) = sleeping_top_reference(m, jc, j3, l, spin);
            let w = frequencies(&lm, 1e-6 * slow);
            assert_eq!(w.len(), 2, "axis {axis} spin {spin}: {:?}", lm.eigenvalues);
            let (e_slow, e_fast) = (rel(w[0], slow), rel(w[1], fast));
            println!(
                "axis {axis} spin {spin}: ω− {:.12} (ref {slow:.12}, rel {e_slow:.1e}), ω+ {:.12} (ref {fast:.12}, rel {e_fast:.1e})",
                w[0], w[1]
            );
            assert!(e_slow < 1e-6 && e_fast < 1e-6);
            // stable: every eigenvalue on the imaginary axis; the spin a zero pair
            assert!(largest_real_part(&lm) < 1e-6 * fast, "{:?}", lm.eigenvalues);
            let zeros = lm
                .eigenvalues
                .iter()
                .filter(|e| e.0.hypot(e.1) < 1e-6 * slow)
                .count();
            assert_eq!(zeros, 2, "{:?}", lm.eigenvalues);
        }
    }
}

#[test]
fn sleeping_top_stability_threshold_is_found_where_the_closed_form_puts_it() {
    let (m, jc, j3, l) = (1.0, 0.02, 0.03, 0.5);
    let j1 = jc + m * l * l;
    let threshold = (4.0 * m * G * l * j1 / (j3 * j3)).sqrt();
    for axis in [2, 0] {
        let unstable = |spin: f64| {
            let lm = linearize(&scene(&top(m, jc, j3, l, spin, axis)), &at(0.0)).unwrap();
            largest_real_part(&lm) > 1e-5
        };
        // bracket: half and twice the threshold's order from the scene's own numbers
        let (mut lo, mut hi) = (10.0, 400.0);
        assert!(unstable(lo) && !unstable(hi));
        while hi - lo > 1e-10 * hi {
            let mid = 0.5 * (lo + hi);
            if unstable(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let found = 0.5 * (lo + hi);
        let e = rel(found, threshold);
        println!(
            "axis {axis}: threshold {found:.12} rad/s, closed form {threshold:.12}, rel {e:.1e}"
        );
        assert!(e < 1e-6, "{found} vs {threshold}");
        // just above and below, the eigenvalues say so
        assert!(unstable(threshold * (1.0 - 1e-6)) && !unstable(threshold * (1.0 + 1e-6)));
    }
}

#[test]
fn hanging_rigid_spherical_pendulum_swings_at_the_compound_pendulum_frequency() {
    // centre l below the ball; transverse J_c and axial J3 about the centre
    let (m, jc, j3, l) = (2.0, 0.05, 0.01, 0.6);
    let w = (m * G * l / (jc + m * l * l)).sqrt();
    for (name, op) in [
        ("at rest", at(0.0)),
        ("equilibrium", LinearizeOptions::default()),
    ] {
        let lm = linearize(&scene(&top(m, jc, j3, -l, 0.0, 2)), &op).unwrap();
        assert!(lm.equilibrium, "{name}");
        let freq = frequencies(&lm, 1e-6 * w);
        assert_eq!(freq.len(), 2, "{name}: {:?}", lm.eigenvalues);
        for f in &freq {
            println!(
                "{name}: {f:.12} vs √(mgl/J_pivot) {w:.12}, rel {:.1e}",
                rel(*f, w)
            );
            assert!(rel(*f, w) < 1e-9, "{name}: {f} vs {w}");
        }
        assert!(lm.eigenvalues.iter().all(|e| e.0.abs() < 1e-9 * w));
        let zeros = lm
            .eigenvalues
            .iter()
            .filter(|e| e.0.hypot(e.1) < 1e-6 * w)
            .count();
        assert_eq!(zeros, 2, "{name}: the spin about the vertical");
        // two modes at w, their shapes the two swing planes, named by the chart
        let swing: Vec<_> = lm
            .modes
            .iter()
            .filter(|md| rel(md.omega_n, w) < 1e-9)
            .collect();
        assert_eq!(swing.len(), 2, "{name}: {:?}", lm.modes);
        assert_eq!(swing[0].multiplicity, 2);
        let big = |shape: &[(String, nalgebra::Complex<f64>)]| -> Vec<String> {
            shape
                .iter()
                .filter(|(n, c)| n.starts_with("top.r") && c.norm() > 0.5)
                .map(|(n, _)| n.clone())
                .collect()
        };
        let (a, b) = (big(&swing[0].shape), big(&swing[1].shape));
        assert!(a.len() == 1 && b.len() == 1 && a != b, "{a:?} {b:?}");
        assert!(a.iter().chain(&b).all(|n| n == "top.rx" || n == "top.ry"));
    }
}

#[test]
fn hanging_ball_turned_anyhow_has_the_same_frequencies() {
    // a spherical inertia about its centre, so any attitude hangs the same way: the chart is
    // taken about a general quaternion
    let (m, j, l) = (1.5, 0.02, 0.4);
    let w = (m * G * l / (j + m * l * l)).sqrt();
    let cardan = [0.3, -0.5, 1.1];
    let (s1, c1) = f64::sin_cos(cardan[0]);
    let (s2, c2) = f64::sin_cos(cardan[1]);
    let (s3, c3) = f64::sin_cos(cardan[2]);
    // R = R_z(ψ) R_y(θ) R_x(φ); the ball's body coordinates s = Rᵀ (0, 0, l) (it is l above
    // the centre)
    let r = [
        [c1 * c2, c1 * s2 * s3 - s1 * c3, c1 * s2 * c3 + s1 * s3],
        [s1 * c2, s1 * s2 * s3 + c1 * c3, s1 * s2 * c3 - c1 * s3],
        [-s2, c2 * s3, c2 * c3],
    ];
    let s = [r[2][0] * l, r[2][1] * l, r[2][2] * l];
    let v = json!({
        "name": "ball", "dimension": 3, "gravity": [0.0, 0.0, -G],
        "bodies": [{"name": "bob", "mass": m, "inertia": [j, j, j],
                    "points": {"ball": s},
                    "position": [0.0, 0.0, -l], "cardan": cardan}],
        "joints": [{"name": "ball", "type": "spherical", "bodies": ["ground", "bob"],
                    "points": [[0.0, 0.0, 0.0], "ball"]}],
        "solve": {"t_end": 1.0}
    });
    let lm = linearize(&scene(&v), &at(0.0)).unwrap();
    assert!(lm.equilibrium);
    let freq = frequencies(&lm, 1e-6 * w);
    assert_eq!(freq.len(), 2, "{:?}", lm.eigenvalues);
    for f in &freq {
        assert!(rel(*f, w) < 1e-9, "{f} vs {w}");
    }
}

#[test]
fn spatial_states_are_named_by_the_chart_and_can_be_chosen() {
    let v = top(1.0, 0.02, 0.03, -0.5, 0.0, 2);
    let named = LinearizeOptions {
        at: OperatingPoint::Time(0.0),
        states: Some(vec!["top.rx".into(), "top.ry".into(), "top.rz".into()]),
        ..LinearizeOptions::default()
    };
    let lm = linearize(&scene(&v), &named).unwrap();
    // the operating point under the run CSV's names, the quaternion of unit norm
    let op = |n: &str| lm.operating_point.iter().find(|(k, _)| k == n).map(|p| p.1);
    assert_eq!(op("top.qw"), Some(1.0), "{:?}", lm.operating_point);
    assert!(op("top.e0").is_none());
    assert_eq!(
        lm.states,
        ["top.rx", "top.ry", "top.rz", "top.wX", "top.wY", "top.wZ"]
    );
    let bad = LinearizeOptions {
        states: Some(vec!["top.qw".into()]),
        ..named
    };
    let e = linearize(&scene(&v), &bad).unwrap_err().to_string();
    assert!(e.contains("top.rx"), "{e}");
}
