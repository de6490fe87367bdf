//! The attitude quaternion columns `b.qw, b.qx, b.qy, b.qz` of spatial bodies: against the
//! analytic rotation of a body spinning steadily about a principal axis, against the Cardan
//! columns written beside them, unit length, continuous through θ = ±90°.

use bondmech::{Model, Scene};

fn solve(json: &str, t_end: f64) -> bondmech::Solution {
    let model = Model::new(&Scene::from_json_str(json).unwrap()).unwrap();
    let mut opts = model.default_options();
    opts.output_times = model.output_times_until(t_end).unwrap();
    model.solve(&opts).unwrap()
}

/// `R(q)` for a unit quaternion `(w, x, y, z)`.
fn rotation(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Seed 16.2: `R = Rz(ψ) Ry(θ) Rx(φ)`.
fn cardan(psi: f64, theta: f64, phi: f64) -> [[f64; 3]; 3] {
    let (s1, c1) = psi.sin_cos();
    let (s2, c2) = theta.sin_cos();
    let (s3, c3) = phi.sin_cos();
    [
        [c1 * c2, c1 * s2 * s3 - s1 * c3, c1 * s2 * c3 + s1 * s3],
        [s1 * c2, s1 * s2 * s3 + c1 * c3, s1 * s2 * c3 - c1 * s3],
        [-s2, c2 * s3, c2 * c3],
    ]
}

fn quaternion(sol: &bondmech::Solution, body: &str, k: usize) -> [f64; 4] {
    ["qw", "qx", "qy", "qz"].map(|c| sol.value(k, &format!("{body}.{c}")).unwrap())
}

#[test]
fn steady_spin_about_a_principal_axis_is_the_analytic_quaternion() {
    // No torque, ω = (0, 0, 2) rad/s about the principal z axis: R(t) = Rz(2t), whose
    // quaternion is (cos t, 0, 0, sin t) — continuous past ψ = π (no sign flip).
    let json = r#"{
      "dimension": 3, "gravity": [0, 0, 0],
      "bodies": [{ "name": "b", "mass": 1, "inertia": [1, 2, 3], "frame": "body",
                   "position": [0, 0, 0], "cardan": [0, 0, 0],
                   "angular_velocity": [0, 0, 2] }],
      "solve": { "t_end": 2.5, "output_step": 0.05, "rtol": 1e-10, "atol": 1e-12 }
    }"#;
    let sol = solve(json, 2.5);
    let cols: Vec<&str> = sol.columns.iter().map(String::as_str).collect();
    let i = cols.iter().position(|c| *c == "b.phi").unwrap();
    assert_eq!(&cols[i + 1..i + 5], ["b.qw", "b.qx", "b.qy", "b.qz"]);
    for (k, &t) in sol.times.iter().enumerate() {
        let q = quaternion(&sol, "b", k);
        let exact = [t.cos(), 0.0, 0.0, t.sin()];
        for c in 0..4 {
            assert!(
                (q[c] - exact[c]).abs() < 1e-7,
                "t = {t}: q = {q:?}, exact {exact:?}"
            );
        }
    }
}

#[test]
fn quaternion_and_cardan_columns_describe_one_rotation_through_gimbal_lock() {
    // The tennis-racket body flips: θ passes near ±90° where the Cardan angles are singular;
    // the quaternion stays unit, continuous, and gives the same R as the Cardan columns.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/free_body_3d.json");
    let json = std::fs::read_to_string(path).unwrap();
    let sol = solve(&json, 6.0);
    let mut prev: Option<[f64; 4]> = None;
    for k in 0..sol.times.len() {
        let q = quaternion(&sol, "body", k);
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-12, "|q| = {norm}");
        let v = |c: &str| sol.value(k, &format!("body.{c}")).unwrap();
        let (a, b) = (rotation(q), cardan(v("psi"), v("theta"), v("phi")));
        for i in 0..3 {
            for j in 0..3 {
                assert!((a[i][j] - b[i][j]).abs() < 1e-9, "t = {}", sol.times[k]);
            }
        }
        if let Some(p) = prev {
            let dot: f64 = p.iter().zip(&q).map(|(a, b)| a * b).sum();
            assert!(dot > 0.99, "quaternion jumps at t = {}", sol.times[k]);
        }
        prev = Some(q);
    }
}
