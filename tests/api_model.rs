//! The model API: thread safety, streaming with early stop, and inspection before solving.

use std::ops::ControlFlow;

use bondmech::{Ground, Mechanism, Model, PlanarBody, Scene, Solution, SpatialBody, SpringDamper};

const _: () = {
    const fn send_sync<T: Send + Sync>() {}
    send_sync::<Model>();
    send_sync::<Scene>();
    send_sync::<Solution>();
    send_sync::<bondmech::Error>();
};

fn double_pendulum() -> Model {
    let scene = Mechanism::planar()
        .gravity([0.0, -9.81])
        .body(PlanarBody::bar("bar1", 1.0, 1.0).at([0.5, 0.0], 0.0))
        .body(PlanarBody::bar("bar2", 1.0, 1.0).at([1.5, 0.0], 0.0))
        .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
        .revolute("knee", ("bar1", "A"), ("bar2", "O"))
        .t_end(1.0)
        .build()
        .unwrap();
    Model::new(&scene).unwrap()
}

fn bits(s: &Solution) -> Vec<Vec<u64>> {
    s.rows
        .iter()
        .map(|r| r.iter().map(|v| v.to_bits()).collect())
        .collect()
}

#[test]
fn solves_on_four_threads_at_once_give_identical_bits() {
    let model = double_pendulum();
    let opts = model.default_options();
    let alone = model.solve(&opts).unwrap();
    let together: Vec<Solution> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| s.spawn(|| model.solve(&opts).unwrap()))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for s in &together {
        assert_eq!(s.columns, alone.columns);
        assert_eq!(bits(s), bits(&alone));
        assert_eq!(s.summary.steps, alone.summary.steps);
    }
}

#[test]
fn streaming_observer_stops_early_and_gets_what_it_saw() {
    let model = double_pendulum();
    let opts = model.default_options(); // 101 output times
    let mut seen: Vec<(f64, Vec<f64>)> = Vec::new();
    let sol = model
        .solve_streaming(&opts, &mut |row| {
            seen.push((row.t, row.values.to_vec()));
            if seen.len() == 10 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .unwrap();
    assert_eq!(seen.len(), 10);
    assert_eq!(sol.rows.len(), seen.len());
    assert_eq!(sol.times.len(), seen.len());
    for (k, (t, values)) in seen.iter().enumerate() {
        assert_eq!(sol.times[k], *t);
        assert_eq!(&sol.rows[k], values);
    }
    // the streamed rows are the first rows of a full solve
    let full = model.solve(&opts).unwrap();
    assert_eq!(full.rows.len(), 101);
    assert_eq!(full.rows[..10], sol.rows[..]);
}

#[test]
fn streaming_without_a_stop_sees_every_output_time() {
    let model = double_pendulum();
    let opts = model.default_options();
    let mut n = 0;
    let sol = model
        .solve_streaming(&opts, &mut |_| {
            n += 1;
            ControlFlow::Continue(())
        })
        .unwrap();
    assert_eq!(n, opts.output_times.len());
    assert_eq!(sol.rows.len(), n);
}

// DOF by hand (seed 16.5, 16.7): 3 per planar body, minus 2 per pin, 2 per slider;
// 6 for a free body in space.

#[test]
fn double_pendulum_has_two_dof() {
    let d = double_pendulum().dof().unwrap();
    assert_eq!(
        (d.velocities, d.constraint_rows, d.rank, d.dof),
        (6, 4, 4, 2)
    );
    assert!(d.redundant_joints.is_empty());
}

#[test]
fn slider_crank_has_one_dof() {
    let m = Model::new(&Scene::from_path("scenes/slider_crank.json").unwrap()).unwrap();
    assert_eq!(m.dof().unwrap().dof, 1);
}

#[test]
fn free_body_has_six_dof() {
    let scene = Mechanism::spatial()
        .body(SpatialBody::new("b", 1.0, [1.0, 2.0, 3.0]))
        .t_end(1.0)
        .build()
        .unwrap();
    let d = Model::new(&scene).unwrap().dof().unwrap();
    assert_eq!((d.velocities, d.dof), (6, 6));
}

#[test]
fn bar_pinned_twice_at_the_same_point_reports_a_redundant_joint() {
    // Two pins between the same bar and ground at the same place: the second adds nothing.
    let scene = Mechanism::planar()
        .body(PlanarBody::bar("bar", 1.0, 1.0).at([0.5, 0.0], 0.0))
        .revolute("pin1", Ground.at([0.0, 0.0]), ("bar", "O"))
        .revolute("pin2", Ground.at([0.0, 0.0]), ("bar", "O"))
        .t_end(1.0)
        .build()
        .unwrap();
    let d = Model::new(&scene).unwrap().dof().unwrap();
    assert_eq!((d.constraint_rows, d.rank, d.dof), (4, 2, 1));
    assert!(!d.redundant_joints.is_empty());
}

#[test]
fn equations_name_coordinates_and_joints() {
    let m = double_pendulum();
    let eq = m.equations();
    assert_eq!(eq.kinematics.len(), 6);
    assert_eq!(eq.dynamics.len(), 6);
    assert_eq!(eq.constraints.len(), 4);
    let rows = m.constraint_rows();
    assert_eq!(rows.len(), 4);
    for (line, row) in eq.constraints.iter().zip(rows) {
        assert!(
            line.starts_with(&format!("{} ({})", row.joint, row.direction)),
            "{line}"
        );
    }
    assert!(eq.constraints[0].starts_with("pivot"));
    assert!(eq.constraints[3].starts_with("knee"));
    // gravity on a 1 kg body: m·vy' = −9.81
    let vy = eq
        .dynamics
        .iter()
        .find(|l| l.contains("bar1.vy'"))
        .expect("a bar1.vy line");
    assert!(vy.contains("-9.81"), "{vy}");
    let text = eq.to_string();
    assert!(text.contains("bar2.angle"), "{text}");
    assert!(
        text.contains("cos(bar1.angle)") || text.contains("sin(bar1.angle)"),
        "{text}"
    );
}

#[test]
fn mass_on_a_spring_built_in_code_oscillates_as_a_cosine() {
    // m = 1 kg, k = 4 N/m, rest length 1 m, released at 1.5 m: x(t) = 1 + 0.5 cos(2t).
    let scene = Mechanism::planar()
        .body(PlanarBody::point_mass("m", 1.0).at([1.5, 0.0], 0.0))
        .spring(SpringDamper::new("s", Ground.at([0.0, 0.0]), "m", 4.0).rest_length(1.0))
        .t_end(3.0)
        .output_step(0.1)
        .tolerances(1e-10, 1e-12)
        .build()
        .unwrap();
    let model = Model::new(&scene).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    for (k, &t) in sol.times.iter().enumerate() {
        let x = sol.value(k, "m.x").unwrap();
        let want = 1.0 + 0.5 * (2.0 * t).cos();
        assert!((x - want).abs() < 1e-6, "t = {t}: {x} vs {want}");
    }
}

// Bond graph inspection and raw bond graph scenes through `Model`.

fn scene_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

#[test]
fn double_pendulum_causality_has_two_integral_and_four_differential_inertias_seed_16_7() {
    // Seed 16.7, Fig. 19: each bar has three inertias (m ẋ, m ẏ, J θ̇); the two pins impose
    // four flows, so four inertias take differential causality and two stay integral (the
    // two angles of a double pendulum).
    let model = double_pendulum();
    let r = model.causality().unwrap();
    assert_eq!(r.integral_inertias, 2);
    assert_eq!(r.differential.len(), 4);
    assert!(r.conflicts.is_empty());
    // the same DOF as the count from the equations, n_v − rank G_v
    assert_eq!(model.dof().unwrap().dof, r.integral_inertias);
    // the graph holds the six inertias, two per bar coordinate
    let g = model.bond_graph().unwrap();
    let inertias = g
        .elements
        .iter()
        .filter(|e| e.kind == bondmech::bond::ElementKind::I)
        .count();
    assert_eq!(inertias, 6);
}

#[test]
fn raw_bond_graph_model_solved_via_the_api_equals_the_cli_csv_bit_for_bit() {
    let path = scene_path("bg_mass_spring_damper.json");
    let model = Model::new(&Scene::from_path(&path).unwrap()).unwrap();
    assert!(model.is_raw_bond_graph());
    assert!(model.mechanism().is_none());
    let sol = model.solve(&model.default_options()).unwrap();

    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .arg("run")
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(String::from_utf8(out.stdout).unwrap(), sol.to_csv());

    // and it is the damped oscillator of the scene's description:
    // x(t) = e^{-ζω0 t}(x0 cos ωd t + ζω0 x0/ωd sin ωd t), ω0 = √(k/m) = 2, ζ = b/(2√(km)) = 0.05
    let (m, k, b, x0) = (1.5f64, 6.0f64, 0.3f64, 0.1f64);
    let w0 = (k / m).sqrt();
    let zeta = b / (2.0 * (k * m).sqrt());
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    let q = sol.column("q_k").unwrap();
    assert_eq!(sol.times.len(), 201);
    for (t, x) in sol.times.iter().zip(&q) {
        let want =
            (-zeta * w0 * t).exp() * (x0 * (wd * t).cos() + zeta * w0 * x0 / wd * (wd * t).sin());
        assert!((x - want).abs() < 1e-6, "t = {t}: {x} vs {want}");
    }
}

#[test]
fn raw_bond_graph_causality_has_two_integral_storages_and_no_twin() {
    let model =
        Model::new(&Scene::from_path(scene_path("bg_mass_spring_damper.json")).unwrap()).unwrap();
    let r = model.causality().unwrap();
    // seed 16.5: degrees of freedom are the integral-causality inertias (p_m); the spring's
    // displacement q_k is a state but not a degree of freedom
    assert_eq!(r.dof, 1);
    assert_eq!(r.state_count, 2); // p_m and q_k
    assert!(r.differential.is_empty());
    let err = model.compare(&model.default_options()).unwrap_err();
    assert!(err.to_string().contains("raw bond graph"), "{err}");
    assert!(model.dof().is_err());
}

#[test]
fn raw_bond_graph_streaming_stops_early_with_the_rows_seen() {
    let model =
        Model::new(&Scene::from_path(scene_path("bg_mass_spring_damper.json")).unwrap()).unwrap();
    let opts = model.default_options();
    let mut n = 0;
    let sol = model
        .solve_streaming(&opts, &mut |_| {
            n += 1;
            if n == 5 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .unwrap();
    assert_eq!(n, 5);
    assert_eq!(sol.rows.len(), 5);
    let full = model.solve(&opts).unwrap();
    assert_eq!(full.rows[..5], sol.rows[..]);
}
