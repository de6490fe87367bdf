//! The FMU instance in Rust, without an importer: modes, steps, inputs, state.

use bondmech::fmu::{describe, ExportOptions, FmiVersion, VariableKind};
use bondmech_fmu::{Mode, Slave, State, StepOutcome};

fn scene_text(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../scenes/{name}.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

fn slave(name: &str, parameters: &[&str]) -> Slave {
    let text = scene_text(name);
    let options = ExportOptions {
        fmi: FmiVersion::V3,
        parameters: parameters.iter().map(|p| p.to_string()).collect(),
        ..ExportOptions::default()
    };
    Slave::from_parts(describe(&text, name, &options).unwrap(), text)
}

fn outputs(s: &Slave, n: u32) -> Vec<f64> {
    let vrs: Vec<u32> = (0..n).collect();
    let mut v = vec![0.0; vrs.len()];
    s.get(&vrs, &mut v).unwrap();
    v
}

#[test]
fn parameters_are_fixed_after_initialisation_and_steps_must_follow_on() {
    let mut s = slave("double_pendulum", &["bodies[bar2].mass"]);
    s.set(&[1], &[2.0]).unwrap();
    s.enter_initialization(0.0, Some(1.0)).unwrap();
    s.exit_initialization().unwrap();
    assert_eq!(s.mode(), Mode::Stepping);
    let e = s.set(&[1], &[3.0]).unwrap_err().to_string();
    assert!(e.contains("fixed after initialisation"), "{e}");
    assert!(s.set(&[0], &[1.0]).is_err(), "time is not settable");
    let e = s.do_step(0.5, 0.01).unwrap_err().to_string();
    assert!(e.contains("the FMU is at t = 0"), "{e}");
    assert_eq!(
        s.mode(),
        Mode::Stepping,
        "a refused call does not fail the instance"
    );
    assert_eq!(s.do_step(0.0, 0.01).unwrap(), StepOutcome::Done);
    assert!((s.time() - 0.01).abs() < 1e-15);
}

#[test]
fn a_bad_parameter_fails_initialisation_with_the_scene_error() {
    let mut s = slave("double_pendulum", &["bodies[bar2].mass"]);
    s.set(&[1], &[-1.0]).unwrap();
    s.enter_initialization(0.0, None).unwrap();
    let e = s.exit_initialization().unwrap_err().to_string();
    assert!(e.contains("bodies[1].mass"), "{e}");
    assert_eq!(s.mode(), Mode::Failed);
    s.reset();
    assert_eq!(s.mode(), Mode::Instantiated);
}

#[test]
fn state_bytes_round_trip_and_restore_continues_the_same() {
    let text = scene_text("slider_crank_input");
    let config = describe(&text, "slider_crank_input", &ExportOptions::default()).unwrap();
    let input = config
        .of_kind(VariableKind::Input)
        .next()
        .unwrap()
        .value_reference;
    let n = config.variables.len() as u32;
    let mut s = Slave::from_parts(config, text);
    s.enter_initialization(0.0, Some(0.2)).unwrap();
    s.exit_initialization().unwrap();
    for k in 0..5 {
        s.set(&[input], &[1.5 + 0.1 * k as f64]).unwrap();
        s.do_step(k as f64 * 0.01, 0.01).unwrap();
    }
    let bytes = s.state().unwrap().to_bytes();
    let run = |s: &mut Slave| {
        let mut rows = Vec::new();
        for k in 5..10 {
            s.set(&[input], &[2.0 - 0.1 * k as f64]).unwrap();
            s.do_step(k as f64 * 0.01, 0.01).unwrap();
            rows.push(outputs(s, n));
        }
        rows
    };
    let first = run(&mut s);
    s.restore(&State::from_bytes(&bytes).unwrap()).unwrap();
    assert!((s.time() - 0.05).abs() < 1e-15);
    assert_eq!(run(&mut s), first);
    assert!(State::from_bytes(b"{}").is_err());
}

#[test]
fn a_stop_event_ends_the_simulation_at_the_event() {
    let mut scene: serde_json::Value =
        serde_json::from_str(&scene_text("double_pendulum")).unwrap();
    scene["events"] = serde_json::json!([
        {"name": "low", "when": "bar2.A.y + 1.5", "direction": "falling", "action": "stop"}
    ]);
    let text = scene.to_string();
    let config = describe(&text, "double_pendulum", &ExportOptions::default()).unwrap();
    let tip = config
        .variables
        .iter()
        .find(|v| v.name == "bar2.A.y")
        .unwrap()
        .value_reference;
    let mut s = Slave::from_parts(config, text);
    s.enter_initialization(0.0, Some(3.0)).unwrap();
    s.exit_initialization().unwrap();
    let mut k = 0;
    let t_stop = loop {
        match s.do_step(k as f64 * 0.01, 0.01).unwrap() {
            StepOutcome::Done => k += 1,
            StepOutcome::Terminated(t) => break t,
        }
        assert!(k < 300, "the event never stopped the run");
    };
    assert_eq!(s.mode(), Mode::Terminated);
    assert!(
        t_stop > k as f64 * 0.01 && t_stop < (k + 1) as f64 * 0.01,
        "{t_stop} in step {k}"
    );
    assert_eq!(s.time(), t_stop);
    let mut y = [0.0];
    s.get(&[tip], &mut y).unwrap();
    assert!((y[0] + 1.5).abs() < 1e-6, "the tip at the stop: {}", y[0]);
    // stepping on is refused politely: still terminated at the same time
    assert_eq!(
        s.do_step(t_stop, 0.01).unwrap(),
        StepOutcome::Terminated(t_stop)
    );
}

/// Inputs that change at every step: after the first replays the instance restarts from the
/// state at each change; the result stays within the solver's tolerance of one solve of the
/// scene with the inputs' history written as a step function of t.
#[test]
fn restarts_from_the_state_follow_the_replayed_solve() {
    use bondmech::scene::inputs::piecewise_constant;
    let text = scene_text("slider_crank_input");
    let config = describe(&text, "slider_crank_input", &ExportOptions::default()).unwrap();
    let input = config
        .of_kind(VariableKind::Input)
        .next()
        .unwrap()
        .value_reference;
    let outputs: Vec<(u32, String)> = config
        .of_kind(VariableKind::Output)
        .map(|v| (v.value_reference, v.name.clone()))
        .collect();
    let mut s = Slave::from_parts(config, text.clone());
    s.enter_initialization(0.0, Some(0.3)).unwrap();
    s.exit_initialization().unwrap();
    let steps = 3 * bondmech_fmu::REPLAYS;
    let h = 0.01;
    let mut history = Vec::new();
    let mut rows = Vec::new();
    for k in 0..steps {
        let u = 1.5 + 0.5 * ((k % 3) as f64 - 1.0);
        history.push((k as f64 * h, u));
        s.set(&[input], &[u]).unwrap();
        s.do_step(k as f64 * h, h).unwrap();
        let vrs: Vec<u32> = outputs.iter().map(|o| o.0).collect();
        let mut v = vec![0.0; vrs.len()];
        s.get(&vrs, &mut v).unwrap();
        rows.push(v);
    }
    // the reference: one solve, the torque as the same step function of t
    let scene = bondmech::Scene::from_json_str(&text)
        .unwrap()
        .with_input_expressions(&[("torque".into(), piecewise_constant(&history))]);
    let model = bondmech::Model::new(&scene).unwrap();
    let mut opts = model.default_options();
    opts.output_times = (1..=steps).map(|k| k as f64 * h).collect();
    let reference = model.solve(&opts).unwrap();
    let mut worst = 0.0f64;
    for (c, (_, name)) in outputs.iter().enumerate() {
        let col = reference.column(name).unwrap();
        let scale = col.iter().fold(1e-3f64, |a, x| a.max(x.abs()));
        for (k, row) in rows.iter().enumerate() {
            worst = worst.max((row[c] - col[k]).abs() / scale);
        }
    }
    println!("restarts against one solve: {worst:e} relative");
    assert!(
        worst < 1e-5,
        "restarts moved the outputs by {worst:e} relative"
    );
    assert!(
        worst > 0.0,
        "no restart happened (the rows are the replay's to the bit)"
    );
}
