//! 3D joints against conservation laws: a rod on a spherical joint (a spherical physical
//! pendulum) keeps its energy and its angular momentum about the vertical through the pivot.

use bondmech::{FormulationKind, Model, Scene};
use nalgebra::{Matrix3, Vector3};

fn cardan(psi: f64, theta: f64, phi: f64) -> Matrix3<f64> {
    // R = Ψ(ψ about Z) Θ(θ about y') Φ(φ about x''), seed 16.2, written out independently
    let (sp, cp) = psi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sf, cf) = phi.sin_cos();
    let z = Matrix3::new(cp, -sp, 0.0, sp, cp, 0.0, 0.0, 0.0, 1.0);
    let y = Matrix3::new(ct, 0.0, st, 0.0, 1.0, 0.0, -st, 0.0, ct);
    let x = Matrix3::new(1.0, 0.0, 0.0, 0.0, cf, -sf, 0.0, sf, cf);
    z * y * x
}

#[test]
fn spherical_rod_pendulum_conserves_energy_and_vertical_momentum() {
    let (m, l, g) = (2.0, 1.0, 9.81);
    let jt = m * l * l / 12.0;
    // rod along body x, hanging 60° from the vertical in the X–Z plane, spinning about Z
    let tilt: f64 = 1.0;
    let (s, c) = tilt.sin_cos();
    let centre = [0.5 * l * s, 0.0, -0.5 * l * c];
    // body x points from the pivot to the tip: direction (sin t, 0, −cos t) = R e_x; with
    // ψ = 0, φ = 0 the Cardan θ about y gives R e_x = (cos θ, 0, −sin θ): θ = π/2 − t
    let theta = std::f64::consts::FRAC_PI_2 - tilt;
    let json = format!(
        r#"{{"name":"spherical_pendulum","dimension":3,"gravity":[0,0,-{g}],
        "bodies":[{{"name":"rod","mass":{m},"inertia":[0.001,{jt},{jt}],
                   "points":{{"O":[-{h},0,0]}},"position":[{cx},{cy},{cz}],"cardan":[0,{theta},0],
                   "velocity":[0,{vy},0],"angular_velocity":[0,0,0]}}],
        "joints":[{{"name":"ball","type":"spherical","bodies":["ground","rod"],"points":[[0,0,0],"O"]}}],
        "solve":{{"t_end":3.0,"output_step":0.05}},
        "outputs":["energy"]}}"#,
        h = 0.5 * l,
        cx = centre[0],
        cy = centre[1],
        cz = centre[2],
        vy = 1.5,
    );
    let scene = Scene::from_json_str(&json).expect("valid scene");
    let model = Model::new(&scene).expect("model");
    let mut o = model.default_options();
    o.formulation = FormulationKind::Ggl;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    let sol = model.solve(&o).expect("solve");
    let j = Matrix3::from_diagonal(&Vector3::new(0.001, jt, jt));
    let lz = |k: usize| {
        let v = |n: &str| sol.value(k, &format!("rod.{n}")).unwrap();
        let r = cardan(v("psi"), v("theta"), v("phi"));
        let wg = Vector3::new(v("wX"), v("wY"), v("wZ"));
        let spin = r * j * r.transpose() * wg;
        m * (v("x") * v("vy") - v("y") * v("vx")) + spin.z
    };
    let e = sol.column("energy").unwrap();
    let (l0, e0) = (lz(0), e[0]);
    assert!(
        l0.abs() > 0.1,
        "the test needs angular momentum about Z (got {l0})"
    );
    for (k, (&t, &ek)) in sol.times.iter().zip(&e).enumerate() {
        assert!(
            (lz(k) - l0).abs() < 1e-8 * l0.abs(),
            "L_z at t = {t}: {} vs {l0}",
            lz(k)
        );
        assert!(
            (ek - e0).abs() < 1e-8 * e0.abs().max(1.0),
            "energy at t = {t}"
        );
    }
    assert!(sol.summary.max_constraint_error < 1e-9, "{:?}", sol.summary);
    // the pivot stays at the origin: the rod's point O, computed from the outputs
    let k = sol.times.len() - 1;
    let v = |n: &str| sol.value(k, &format!("rod.{n}")).unwrap();
    let r = cardan(v("psi"), v("theta"), v("phi"));
    let o_pt = Vector3::new(v("x"), v("y"), v("z")) + r * Vector3::new(-0.5 * l, 0.0, 0.0);
    assert!(o_pt.norm() < 1e-8, "pivot drifted to {o_pt}");
}
