//! Static equilibrium (`Model::equilibrium`, `bondmech equilibrium`) against references derived
//! by hand in one coordinate: the equilibrium is a root of `dV/dθ` (the potential of gravity,
//! springs and constant loads), its stability the sign of `d²V/dθ²`. The roots are found here
//! by Newton on closed forms or on an 8th-order central difference of `V`, never by bondmech.

use bondmech::{Model, Scene};
use serde_json::{json, Value};

const G: f64 = 9.81;

fn equilibrium(scene: &Value) -> bondmech::analysis::equilibrium::Equilibrium {
    let scene = Scene::from_json_str(&scene.to_string()).unwrap();
    Model::new(&scene).unwrap().equilibrium().unwrap()
}

/// `f'(x)` by the 8th-order central difference.
fn derivative(f: &dyn Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    let c = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
    c.iter()
        .enumerate()
        .map(|(k, ck)| {
            let d = (k + 1) as f64 * h;
            ck * (f(x + d) - f(x - d)) / h
        })
        .sum()
}

/// A root of `f` by Newton from `x` (derivative by central differences), to 1e-14.
fn root(f: &dyn Fn(f64) -> f64, mut x: f64) -> f64 {
    for _ in 0..100 {
        let d = derivative(f, x, 1e-4);
        let dx = f(x) / d;
        x -= dx;
        if dx.abs() < 1e-14 {
            break;
        }
    }
    x
}

/// A uniform bar (mass m, length L) pinned at its end O to the origin; a spring of stiffness
/// k and rest length 0 from the ground point P to its end A. With θ the bar's angle,
/// `V = m g (L/2) sin θ + ½ k |A(θ) − P|²`, `A = L (cos θ, sin θ)`, so
/// `dV/dθ = m g (L/2) cos θ + k L (P_x sin θ − P_y cos θ)`.
fn sprung_bar(theta0: f64, k: f64, p: [f64; 2]) -> Value {
    let l = 1.0;
    json!({
        "gravity": [0.0, -G],
        "bodies": [{"name": "bar", "mass": 1.0, "inertia": l * l / 12.0,
                    "points": {"O": [-l / 2.0, 0.0], "A": [l / 2.0, 0.0]},
                    "position": [l / 2.0 * theta0.cos(), l / 2.0 * theta0.sin()],
                    "angle": theta0}],
        "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "bar"],
                    "points": [[0.0, 0.0], "O"]}],
        "springs": [{"name": "spring", "bodies": ["ground", "bar"], "points": [p, "A"],
                     "stiffness": k, "rest_length": 0.0}],
        "outputs": ["reactions"],
        "solve": {"t_end": 1.0}
    })
}

#[test]
fn sprung_bar_rests_where_the_potential_is_stationary_and_is_stable() {
    let (k, p) = (50.0, [1.0, 1.0]);
    let dv = |th: f64| G * 0.5 * th.cos() + k * (p[0] * th.sin() - p[1] * th.cos());
    let want = root(&dv, 0.3);
    let d2v = derivative(&dv, want, 1e-4);
    assert!(d2v > 0.0, "the reference is a minimum");
    let eq = equilibrium(&sprung_bar(0.3, k, p));
    let got = eq.coordinate("bar.angle").unwrap();
    eprintln!(
        "sprung bar: |Δθ| = {:.1e}, {} iterations",
        (got - want).abs(),
        eq.iterations
    );
    assert!(
        (got - want).abs() < 1e-8,
        "angle {got} vs dV/dθ = 0 at {want}"
    );
    assert!(eq.converged && eq.stable, "{eq:?}");
    assert_eq!(eq.stiffness_eigenvalues.len(), 1);
    // the pivot's force balances the weight and the spring (on the bar, global)
    let a = [got.cos(), got.sin()];
    let spring = [k * (p[0] - a[0]), k * (p[1] - a[1])];
    let fy = eq
        .reactions
        .iter()
        .find(|(n, _)| n == "pivot.Fy")
        .map(|(_, v)| *v)
        .unwrap();
    assert!(
        (fy + spring[1] - G).abs() < 1e-8,
        "pivot.Fy {fy} + spring {} = weight",
        spring[1]
    );
    let json = eq.to_json();
    for key in [
        "converged",
        "iterations",
        "residual",
        "coordinates",
        "reactions",
        "drivers",
        "stable",
        "stiffness_eigenvalues",
    ] {
        assert!(json.get(key).is_some(), "{key} in {json}");
    }
}

#[test]
fn inverted_bar_is_found_and_reported_unstable() {
    // no spring: the bar balances upright (θ = π/2) when started near it, a maximum of V
    let mut scene = sprung_bar(1.7, 0.0, [1.0, 1.0]);
    scene["springs"] = json!([]);
    let eq = equilibrium(&scene);
    let got = eq.coordinate("bar.angle").unwrap();
    assert!(
        (got - std::f64::consts::FRAC_PI_2).abs() < 1e-8,
        "angle {got}"
    );
    assert!(!eq.stable, "{eq:?}");
    assert!(eq.stiffness_eigenvalues[0] < 0.0);
}

/// Closed four-bar: crank a (pinned at the origin), coupler b, rocker c (pinned at (d, 0)),
/// uniform bars; a spring (k, rest length l0) from the ground point S to the coupler's centre;
/// a constant torque τ on the rocker; gravity. One coordinate, the crank angle φ: the loop
/// closes with the coupler's far end B on the circle of radius c about (d, 0) (upper branch),
/// and `V(φ) = g Σ m_i y_i + ½ k (|M − S| − l0)² − τ ψ` (ψ the rocker's angle: the torque's
/// work). The equilibrium is the root of `dV/dφ` near the start.
#[test]
fn closed_four_bar_with_spring_and_load_rests_like_the_one_coordinate_model() {
    let (a, b, c, d) = (0.4, 1.0, 0.8, 1.0);
    let (ma, mb, mc) = (1.0, 2.0, 1.5);
    let (k, l0, tau) = (200.0, 0.1, 2.0);
    let s = [0.2, 1.0];
    let pose = |phi: f64| {
        let pa = [a * phi.cos(), a * phi.sin()];
        let dx = [d - pa[0], -pa[1]];
        let e = (dx[0] * dx[0] + dx[1] * dx[1]).sqrt();
        let u = [dx[0] / e, dx[1] / e];
        let x = (b * b - c * c + e * e) / (2.0 * e);
        let h = (b * b - x * x).sqrt();
        let pb = [pa[0] + x * u[0] - h * u[1], pa[1] + x * u[1] + h * u[0]];
        let beta = (pb[1] - pa[1]).atan2(pb[0] - pa[0]);
        let psi = pb[1].atan2(pb[0] - d);
        (pa, pb, beta, psi)
    };
    let v = |phi: f64| {
        let (pa, pb, _, psi) = pose(phi);
        let m = [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0];
        let stretch = ((m[0] - s[0]).powi(2) + (m[1] - s[1]).powi(2)).sqrt() - l0;
        G * (ma * pa[1] / 2.0 + mb * m[1] + mc * pb[1] / 2.0) + 0.5 * k * stretch * stretch
            - tau * psi
    };
    let dv = |phi: f64| derivative(&v, phi, 1e-3);
    let phi0 = 1.2;
    let want = root(&dv, phi0);
    let (pa, pb, beta, psi) = pose(phi0);
    let bar = |name: &str, l: f64, m: f64, centre: [f64; 2], angle: f64| {
        json!({"name": name, "mass": m, "inertia": m * l * l / 12.0,
               "points": {"O": [-l / 2.0, 0.0], "A": [l / 2.0, 0.0], "M": [0.0, 0.0]},
               "position": centre, "angle": angle})
    };
    let scene = json!({
        "gravity": [0.0, -G],
        "bodies": [
            bar("crank", a, ma, [pa[0] / 2.0, pa[1] / 2.0], phi0),
            bar("coupler", b, mb, [(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0], beta),
            bar("rocker", c, mc, [(d + pb[0]) / 2.0, pb[1] / 2.0], psi)
        ],
        "joints": [
            {"name": "o2", "type": "revolute", "bodies": ["ground", "crank"], "points": [[0.0, 0.0], "O"]},
            {"name": "a", "type": "revolute", "bodies": ["crank", "coupler"], "points": ["A", "O"]},
            {"name": "b", "type": "revolute", "bodies": ["coupler", "rocker"], "points": ["A", "A"]},
            {"name": "o4", "type": "revolute", "bodies": ["ground", "rocker"], "points": [[d, 0.0], "O"]}
        ],
        "springs": [{"name": "spring", "bodies": ["ground", "coupler"], "points": [s, "M"],
                     "stiffness": k, "rest_length": l0}],
        "loads": [{"name": "tau", "type": "torque", "body": "rocker", "value": tau}],
        "solve": {"t_end": 1.0}
    });
    let eq = equilibrium(&scene);
    let got = eq.coordinate("crank.angle").unwrap();
    eprintln!(
        "four-bar: |Δφ| = {:.1e}, {} iterations, eigenvalues {:?}",
        (got - want).abs(),
        eq.iterations,
        eq.stiffness_eigenvalues
    );
    assert!(
        (got - want).abs() < 1e-8,
        "crank angle {got} vs one-coordinate model {want}"
    );
    let (_, _, _, psi_want) = pose(want);
    let psi_got = eq.coordinate("rocker.angle").unwrap();
    assert!(
        (psi_got - psi_want).abs() < 1e-8,
        "rocker {psi_got} vs {psi_want}"
    );
    let stable_want = derivative(&dv, want, 1e-3) > 0.0;
    assert_eq!(eq.stable, stable_want, "{eq:?}");
    assert_eq!(eq.stiffness_eigenvalues.len(), 1, "one DOF");
}

#[test]
fn a_scene_may_start_from_its_equilibrium_and_stays_there() {
    let (k, p) = (50.0, [1.0, 1.0]);
    let dv = |th: f64| G * 0.5 * th.cos() + k * (p[0] * th.sin() - p[1] * th.cos());
    let want = root(&dv, 0.3);
    let mut scene = sprung_bar(0.3, k, p);
    scene["solve"]["start"] = json!("equilibrium");
    let scene = Scene::from_json_str(&scene.to_string()).unwrap();
    let model = Model::new(&scene).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    for a in sol.column("bar.angle").unwrap() {
        assert!((a - want).abs() < 1e-8, "angle {a} vs rest {want}");
    }
}

#[test]
fn a_load_that_never_balances_is_refused_naming_why() {
    // a torque of 100 N m on a 1 kg bar of 1 m: the weight's moment is at most 4.9 N m
    let mut scene = sprung_bar(0.3, 0.0, [1.0, 1.0]);
    scene["springs"] = json!([]);
    scene["loads"] = json!([{"name": "motor", "type": "torque", "body": "bar", "value": 100.0}]);
    let scene = Scene::from_json_str(&scene.to_string()).unwrap();
    let e = Model::new(&scene)
        .unwrap()
        .equilibrium()
        .unwrap_err()
        .to_string();
    assert!(e.contains("no equilibrium"), "{e}");
}

/// Regression: released horizontal, a pinned bar's gravity stiffness is zero (`d²V/dθ² =
/// −m g a sin θ = 0` at θ = 0), Newton's step has no component along the one DOF, and the search
/// stalled there ("the loads never balance") on the bundled pendulum and double pendulum. The
/// damped steps along the loads go down to the hanging equilibrium: θ = −π/2, centre at
/// `−a`, the pin carrying the weight, stable with `d²V/dθ² = m g a` (the bar of 1 kg and 1 m,
/// `a = 0.5`); the double pendulum's two bars hang straight.
#[test]
fn regression_a_bar_released_horizontal_stalled_and_now_hangs_down() {
    let root = env!("CARGO_MANIFEST_DIR");
    let read = |name: &str| -> Value {
        serde_json::from_str(
            &std::fs::read_to_string(format!("{root}/scenes/{name}.json")).unwrap(),
        )
        .unwrap()
    };
    let pendulum = read("pendulum");
    assert_eq!(
        pendulum["bodies"][0]["angle"],
        json!(0.0),
        "released horizontal"
    );
    let e = equilibrium(&pendulum);
    assert!(e.converged && e.stable, "{e:?}");
    let half_pi = std::f64::consts::FRAC_PI_2;
    assert!(
        (e.coordinate("bar.angle").unwrap() + half_pi).abs() < 1e-10,
        "{e:?}"
    );
    assert!(
        (e.coordinate("bar.y").unwrap() + 0.5).abs() < 1e-10,
        "{e:?}"
    );
    assert!(e.coordinate("bar.x").unwrap().abs() < 1e-10, "{e:?}");
    let fy = e.reactions.iter().find(|(k, _)| k == "pivot.Fy").unwrap().1;
    assert!((fy - G).abs() < 1e-9, "the pin carries the weight: {fy}");
    // one DOF: the stiffness eigenvalue is mass-normalised (issue 48: it was K_r's own on the
    // unit velocity direction, m g a / (1 + a²), metres and radians mixed), the squared
    // frequency of the small swings, ω² = m g a / J_O with J_O = J + m a² (1/12 + 1/4)
    let k = e.stiffness_eigenvalues[0];
    let want = G * 0.5 / (1.0 / 12.0 + 0.25);
    assert!((k - want).abs() < 1e-9 * want, "{k} vs {want}");

    let e = equilibrium(&read("double_pendulum"));
    assert!(e.converged && e.stable, "{e:?}");
    for bar in ["bar1", "bar2"] {
        let a = e.coordinate(&format!("{bar}.angle")).unwrap();
        assert!((a + half_pi).abs() < 1e-10, "{bar} at {a}");
    }
}
