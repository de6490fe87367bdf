//! Consistent initialisation: the least-change projection of a perturbed start (hand-computed
//! linearised correction) and the refusal of a mechanism that cannot be assembled.

use bondmech::{FormulationKind, Model, Scene, SolveOptions};

const G: f64 = 9.81;

/// Double pendulum of two 1 m bars, bar 2 placed `dy` above the knee.
fn perturbed_double_pendulum(dy: f64) -> String {
    format!(
        r#"{{"name":"dp","dimension":2,"gravity":[0,-{G}],
        "bodies":[
          {{"name":"bar1","mass":1.0,"inertia":{j},"frame":"inertial","points":{{"O":[-0.5,0],"A":[0.5,0]}},
            "position":[0.5,0],"angle":0}},
          {{"name":"bar2","mass":1.0,"inertia":{j},"frame":"inertial","points":{{"O":[-0.5,0],"A":[0.5,0]}},
            "position":[1.5,{dy}],"angle":0}}],
        "joints":[
          {{"name":"pivot","type":"revolute","bodies":["ground","bar1"],"points":[[0,0],"O"]}},
          {{"name":"knee","type":"revolute","bodies":["bar1","bar2"],"points":["A","O"]}}],
        "solve":{{"t_end":0.5,"output_step":0.05,"rtol":1e-8,"atol":1e-10}}}}"#,
        j = 1.0 / 12.0
    )
}

#[test]
fn perturbed_start_is_corrected_by_the_least_change_projection() {
    let dy: f64 = 0.01;
    let model = Model::new(&Scene::from_json_str(&perturbed_double_pendulum(dy)).unwrap()).unwrap();
    let s = model
        .solve(&model.default_options())
        .expect("a perturbed start is projected");
    // Hand linearisation at θ1 = θ2 = 0, q = (x1, y1, θ1, x2, y2, θ2): g = (0, 0, 0, −dy); only
    // the y rows are active, r1 = (y1, θ1) row of the pivot = (1, −½), r2 = knee y row over
    // (y1, θ1, y2, θ2) = (1, ½, −1, ½). The least-norm Δq with r1·Δq = 0, r2·Δq = dy has
    // ‖Δq‖² = dyᵀ (R Rᵀ)⁻¹ dy with R Rᵀ = [[5/4, 3/4], [3/4, 5/2]]: ‖Δq‖² = dy² (5/4)/det,
    // det = 41/16, and Δy2 = −b with b = (5/4) dy / det.
    let det: f64 = 1.25 * 2.5 - 0.75 * 0.75;
    let norm = dy * (1.25 / det).sqrt();
    let b = 1.25 * dy / det;
    let got = s.summary.initial_position_correction;
    // the nonlinear projection differs from the linearised one by O(‖Δq‖²) ~ 5e-5 relative
    assert!(
        (got - norm).abs() < 1e-3 * norm,
        "correction {got} vs hand {norm}"
    );
    assert_eq!(s.summary.initial_velocity_correction, 0.0);
    let y2 = s.value(0, "bar2.y").unwrap();
    assert!((y2 - (dy - b)).abs() < 1e-5, "bar2.y {y2} vs {}", dy - b);
    // the projected start (and the motion) satisfy the joints
    assert!(
        s.summary.max_constraint_error < 1e-9,
        "{}",
        s.summary.max_constraint_error
    );
    assert!(s.value(0, "constraint_error").unwrap() < 1e-12);
}

/// A four-bar whose coupler (0.5 m) cannot bridge the 1 m gap between crank and rocker tips.
fn unassemblable_four_bar() -> String {
    let bar = |name: &str, len: f64, x: f64, y: f64, angle: f64| {
        format!(
            r#"{{"name":"{name}","mass":1.0,"inertia":{i},"points":{{"O":[{h},0],"A":[{k},0]}},"position":[{x},{y}],"angle":{angle}}}"#,
            i = len * len / 12.0,
            h = -len / 2.0,
            k = len / 2.0
        )
    };
    let up = std::f64::consts::FRAC_PI_2;
    format!(
        r#"{{"name":"broken","dimension":2,"gravity":[0,-9.81],"bodies":[{},{},{}],
        "joints":[
          {{"name":"pivotA","type":"revolute","bodies":["ground","crank"],"points":[[0,0],"O"]}},
          {{"name":"pinB","type":"revolute","bodies":["crank","coupler"],"points":["A","O"]}},
          {{"name":"pinC","type":"revolute","bodies":["coupler","rocker"],"points":["A","A"]}},
          {{"name":"pivotD","type":"revolute","bodies":["ground","rocker"],"points":[[3,0],"O"]}}],
        "solve":{{"t_end":1.0,"output_step":0.1}}}}"#,
        bar("crank", 1.0, 0.0, 0.5, up),
        bar("coupler", 0.5, 0.25, 1.0, 0.0),
        bar("rocker", 1.0, 3.0, 0.5, up),
    )
}

#[test]
fn unassemblable_four_bar_is_refused_naming_its_joints_and_the_time() {
    let model = Model::new(&Scene::from_json_str(&unassemblable_four_bar()).unwrap()).unwrap();
    for f in [
        FormulationKind::Ggl,
        FormulationKind::Index1,
        FormulationKind::Decoupled,
    ] {
        let o = SolveOptions {
            formulation: f,
            ..model.default_options()
        };
        let e = model.solve(&o).unwrap_err().to_string();
        assert!(e.contains("cannot be projected onto the joints"), "{e}");
        assert!(e.contains("at t = 0"), "{e}");
        assert!(e.contains("pinB") || e.contains("pinC"), "{e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
}
