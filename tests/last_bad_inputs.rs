//! Issue 51, "the last bad inputs": one regression test per finding the 614-case bad-input
//! probe left (each named after it), and the data loss of `linearize` and `equilibrium`:
//!
//! - data loss: `linearize --json SCENE.json`, `equilibrium --json SCENE.json` overwrote the
//!   scene; `--json x.svg --bode x.svg` kept one of the two (the output probe,
//!   `tests/output_probe.rs`, covers every command and kind of target);
//! - silently accepted: a raw graph's R with a negative resistance expression, a stiffness
//!   zero at t = 0, a modulus zero at t = 0, a stiffness given as a string of a number,
//!   `--formulation decoupled` on a raw graph, `graph --as-scene` on a body-frame scene,
//!   `max_steps` of 2⁶⁴ − 1, a name with a comma;
//! - vague: a scene read from `/dev/zero`, a negative `--atol`, `--set` with an empty path,
//!   standard input closed, `serve --max-body 0`, a 6000-element graph, 10⁴ events,
//!   `max_wall_seconds` of 1e300 in the service's query or the scene, a huge query string;
//! - hangs: a torque `exp(1e6*t)`, 10⁷ output rows.

mod service_support;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use bondmech::{Model, Scene};
use serde_json::{json, Value};
use service_support::{post, start};

const BIN: &str = env!("CARGO_BIN_EXE_bondmech");

/// A fresh directory for one test.
fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bondmech-last-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn scene_json(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(scene_path(name)).unwrap()).unwrap()
}

/// Runs `bondmech ARGS` with standard input `stdin` (empty when `None`), killed after 60 s.
fn run_with(args: &[&str], stdin: Option<Vec<u8>>) -> Output {
    let mut child = Command::new(BIN)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bondmech runs");
    let mut input = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        if let Some(b) = stdin {
            let _ = input.write_all(&b);
        }
    });
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("bondmech {args:?} did not end within 60 s");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = feeder.join();
    child.wait_with_output().unwrap()
}

fn run(args: &[&str]) -> Output {
    run_with(args, None)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The command failed with exit 1 (not a panic, not a usage error) and its message holds every
/// fragment.
fn assert_refused(o: &Output, fragments: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(1), "exit {:?}: {err}", o.status);
    assert!(!err.contains("panicked"), "{err}");
    for f in fragments {
        assert!(err.contains(f), "missing {f:?} in: {err}");
    }
}

/// The model error of `scene` (it must fail to build).
fn model_error(scene: &Value) -> String {
    let s = Scene::from_json_str(&scene.to_string()).unwrap();
    match Model::new(&s) {
        Ok(_) => panic!("accepted: {scene}"),
        Err(e) => e.to_string(),
    }
}

/// The summary warnings of a run of `scene` (it must run).
fn run_warnings(scene: &Value) -> Vec<String> {
    let s = Scene::from_json_str(&scene.to_string()).unwrap();
    let m = Model::new(&s).unwrap();
    m.solve(&m.default_options()).unwrap().summary.warnings
}

// ---------------------------------------------------------------------------------------------
// Data loss
// ---------------------------------------------------------------------------------------------

/// A copy of the pendulum in `d`, and its bytes.
fn scene_copy(d: &Path) -> (PathBuf, Vec<u8>) {
    let p = d.join("pendulum.json");
    std::fs::copy(scene_path("pendulum.json"), &p).unwrap();
    (p.clone(), std::fs::read(&p).unwrap())
}

#[test]
fn regression_linearize_json_onto_its_scene_overwrote_it() {
    let d = dir("lin-json");
    let (p, before) = scene_copy(&d);
    let link = d.join("link.json");
    std::os::unix::fs::symlink(&p, &link).unwrap();
    for out in [&p, &link] {
        let o = run(&[
            "linearize",
            p.to_str().unwrap(),
            "--json",
            out.to_str().unwrap(),
        ]);
        assert_refused(&o, &["--json", "is an input of this command"]);
        assert_eq!(std::fs::read(&p).unwrap(), before, "the scene is unchanged");
    }
    // the Bode plot onto the scene too (a .svg name for the scene)
    let svg_scene = d.join("scene.svg");
    std::fs::copy(&p, &svg_scene).unwrap();
    let o = run(&[
        "linearize",
        svg_scene.to_str().unwrap(),
        "--bode",
        svg_scene.to_str().unwrap(),
    ]);
    assert_refused(&o, &["--bode", "is an input of this command"]);
    assert_eq!(std::fs::read(&svg_scene).unwrap(), before);
}

#[test]
fn regression_equilibrium_json_onto_its_scene_overwrote_it() {
    let d = dir("eq-json");
    let (p, before) = scene_copy(&d);
    let o = run(&[
        "equilibrium",
        p.to_str().unwrap(),
        "--json",
        p.to_str().unwrap(),
    ]);
    assert_refused(
        &o,
        &["--json", "pendulum.json", "is an input of this command"],
    );
    assert_eq!(std::fs::read(&p).unwrap(), before, "the scene is unchanged");
    // and elsewhere it writes a whole JSON document
    let out = d.join("eq.json");
    let o = run(&[
        "equilibrium",
        p.to_str().unwrap(),
        "--json",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert!(v.get("coordinates").is_some(), "{v}");
}

#[test]
fn regression_linearize_json_and_bode_onto_one_file_kept_one_of_them() {
    let d = dir("lin-twice");
    let mut v = scene_json("pendulum.json");
    v["inputs"] = json!([{"name": "tau", "start": 0.0}]);
    v["loads"] = json!([{"name": "motor", "type": "torque", "body": "bar", "value": "tau"}]);
    let p = d.join("input.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let x = d.join("x.svg");
    let o = run(&[
        "linearize",
        p.to_str().unwrap(),
        "--json",
        x.to_str().unwrap(),
        "--bode",
        x.to_str().unwrap(),
    ]);
    assert_refused(
        &o,
        &["--bode", "--json", "x.svg", "give each output its own file"],
    );
    assert!(!x.exists(), "nothing written");
    // each on its own file: both written
    let j = d.join("x.json");
    let o = run(&[
        "linearize",
        p.to_str().unwrap(),
        "--json",
        j.to_str().unwrap(),
        "--bode",
        x.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read_to_string(&x)
        .unwrap()
        .trim_end()
        .ends_with("</svg>"));
    serde_json::from_slice::<Value>(&std::fs::read(&j).unwrap()).unwrap();
}

// ---------------------------------------------------------------------------------------------
// Silently accepted
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_negative_resistance_expression_of_a_raw_graph_ran() {
    let base = scene_json("bg_mass_spring_damper.json");
    assert_eq!(base["bond_graph"]["elements"][4]["kind"], "R");
    // 0 at the start, negative after: refused at the first sample where it is negative
    let mut v = base.clone();
    v["bond_graph"]["elements"][4]["value"] = json!("-0.3*t");
    let e = model_error(&v);
    assert!(
        e.contains("bond_graph.elements[4].value")
            && e.contains("a resistance must be >= 0")
            && e.contains("\"-0.3*t\" evaluates to -0.015")
            && e.contains("at t = 0.05"),
        "{e}"
    );
    // an expression of the state, negative at the initial state
    let mut v = base.clone();
    v["bond_graph"]["elements"][4]["value"] = json!("-(0.3 + q_k^2)");
    let e = model_error(&v);
    assert!(
        e.contains("bond_graph.elements[4].value") && e.contains("a resistance must be >= 0"),
        "{e}"
    );
    // a law that gives energy (e·f < 0)
    let mut v = base.clone();
    let r = v["bond_graph"]["elements"][4].as_object_mut().unwrap();
    r.remove("value");
    r.insert("effort_law".into(), json!("-0.3*f"));
    let e = model_error(&v);
    assert!(
        e.contains("bond_graph.elements[4].effort_law") && e.contains("must dissipate"),
        "{e}"
    );
    // a resistance that stays >= 0 runs, and a dissipating law too
    let mut v = base.clone();
    v["bond_graph"]["elements"][4]["value"] = json!("0.3*(1 + t)");
    run_warnings(&v);
    let mut v = base;
    let r = v["bond_graph"]["elements"][4].as_object_mut().unwrap();
    r.remove("value");
    r.insert("effort_law".into(), json!("0.3*f*abs(f)"));
    run_warnings(&v);
}

#[test]
fn regression_stiffness_or_compliance_expression_zero_at_t0_ran() {
    let base = scene_json("bg_mass_spring_damper.json");
    assert_eq!(base["bond_graph"]["elements"][3]["kind"], "C");
    let mut v = base.clone();
    v["bond_graph"]["elements"][3]["stiffness"] = json!("6*t");
    let e = model_error(&v);
    assert!(
        e.contains("bond_graph.elements[3].stiffness")
            && e.contains("6*t")
            && e.contains("a stiffness must be > 0"),
        "{e}"
    );
    let mut v = base.clone();
    let c = v["bond_graph"]["elements"][3].as_object_mut().unwrap();
    c.remove("stiffness");
    c.insert("compliance".into(), json!("t/6"));
    let e = model_error(&v);
    assert!(
        e.contains("bond_graph.elements[3].compliance") && e.contains("a compliance must be > 0"),
        "{e}"
    );
    // from the start on positive: runs
    let mut v = base;
    v["bond_graph"]["elements"][3]["stiffness"] = json!("6*(1 + t)");
    run_warnings(&v);
}

#[test]
fn regression_modulus_zero_at_t0_ran_without_a_word() {
    let mut v = scene_json("bg_dc_motor.json");
    assert_eq!(v["bond_graph"]["elements"][4]["kind"], "GY");
    v["bond_graph"]["elements"][4]["modulus"] = json!("0.1*t");
    v["solve"]["t_end"] = json!(1.0);
    let w = run_warnings(&v);
    assert!(
        w.iter()
            .any(|w| w.starts_with("bond_graph.elements[4].modulus")
                && w.contains("is 0 at t_start = 0")),
        "{w:?}"
    );
    // the command line says it on standard error
    let d = dir("modulus");
    let p = d.join("m.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let o = run(&["run", p.to_str().unwrap(), "--table"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("bondmech: warning: bond_graph.elements[4].modulus"),
        "{}",
        stderr(&o)
    );
    // a modulus of the state that is 0 at rest is the model's own coupling: no warning
    let bf = body_frame_double_pendulum(0.0, 0.0);
    let g = graph_as_scene(&bf);
    assert!(
        !run_warnings(&g).iter().any(|w| w.contains("modulus")),
        "{:?}",
        run_warnings(&g)
    );
}

#[test]
fn regression_stiffness_given_as_a_string_of_a_number_ran_without_a_word() {
    let mut v = scene_json("bg_mass_spring_damper.json");
    v["bond_graph"]["elements"][3]["stiffness"] = json!("6");
    let w = run_warnings(&v);
    assert!(
        w.iter()
            .any(|w| w.starts_with("bond_graph.elements[3].stiffness")
                && w.contains("a string holding a number")
                && w.contains("without quotes")),
        "{w:?}"
    );
    // the same motion as the number
    let a = {
        let s = Scene::from_json_str(&v.to_string()).unwrap();
        let m = Model::new(&s).unwrap();
        m.solve(&m.default_options()).unwrap()
    };
    let s = Scene::from_path(scene_path("bg_mass_spring_damper.json")).unwrap();
    let m = Model::new(&s).unwrap();
    let b = m.solve(&m.default_options()).unwrap();
    assert_eq!(a.rows, b.rows);
}

#[test]
fn regression_formulation_decoupled_on_a_raw_bond_graph_ran_it_as_is() {
    let p = scene_path("bg_mass_spring_damper.json");
    let o = run(&[
        "run",
        p.to_str().unwrap(),
        "--formulation",
        "decoupled",
        "--table",
    ]);
    assert_refused(&o, &["formulation 'decoupled'", "nothing to decouple"]);
    // the scene's own solve.formulation too
    let mut v = scene_json("bg_mass_spring_damper.json");
    v["solve"]["formulation"] = json!("decoupled");
    let e = model_solve_error(&v);
    assert!(e.contains("nothing to decouple"), "{e}");
}

fn model_solve_error(v: &Value) -> String {
    let s = Scene::from_json_str(&v.to_string()).unwrap();
    let m = Model::new(&s).unwrap();
    m.solve(&m.default_options()).unwrap_err().to_string()
}

/// The double pendulum with both bars in their body-fixed frames (seed 16.3), started at
/// angle `a` turning at `w` as one rigid bar.
fn body_frame_double_pendulum(a: f64, w: f64) -> Value {
    let mut v = scene_json("double_pendulum.json");
    for (k, b) in v["bodies"].as_array_mut().unwrap().iter_mut().enumerate() {
        let r = 0.5 + k as f64;
        b["frame"] = json!("body");
        b["angle"] = json!(a);
        b["position"] = json!([r * a.cos(), r * a.sin()]);
        b["angular_velocity"] = json!(w);
        b["velocity"] = json!([-r * w * a.sin(), r * w * a.cos()]);
    }
    v["solve"] = json!({"t_end": 1.0, "output_step": 0.01, "rtol": 1e-10, "atol": 1e-12});
    v
}

/// `graph --as-scene` of `v`.
fn graph_as_scene(v: &Value) -> Value {
    let s = Scene::from_json_str(&v.to_string()).unwrap();
    bondmech::graph::bond_graph_scene(&s).unwrap()
}

/// `graph --as-scene` on a body-frame scene was accepted without a word while the format
/// said it was refused: it is exported, and the export runs as the scene does — documented as
/// legal (docs/scene-format.md §11.6), checked here.
#[test]
fn regression_graph_as_scene_on_a_body_frame_scene_was_accepted_silently() {
    let v = body_frame_double_pendulum(0.7, 2.0);
    let g = graph_as_scene(&v);
    let solve = |v: &Value| {
        let s = Scene::from_json_str(&v.to_string()).unwrap();
        let m = Model::new(&s).unwrap();
        m.solve(&m.default_options()).unwrap()
    };
    let (a, b) = (solve(&v), solve(&g));
    assert_eq!(a.times.len(), b.times.len());
    let mut worst = 0.0f64;
    for col in [
        "bar1.angle",
        "bar2.angle",
        "bar2.A.x",
        "bar2.A.y",
        "bar1.omega",
    ] {
        let (x, y) = (a.column(col).unwrap(), b.column(col).unwrap());
        for (p, q) in x.iter().zip(&y) {
            worst = worst.max((p - q).abs());
        }
    }
    assert!(worst < 1e-8, "the export runs as the scene: {worst:e}");
    // what it cannot carry is said: events
    let d = dir("as-scene");
    let mut v = v;
    v["events"] = json!([{"name": "down", "when": "bar2.A.y + 1", "action": "record"}]);
    let p = d.join("bf.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let out = d.join("g.json");
    let o = run(&[
        "graph",
        p.to_str().unwrap(),
        "--as-scene",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: events: the scene's 1 events are not carried over"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn regression_max_steps_2_pow_64_minus_1_was_accepted() {
    // 2⁶⁴ − 1 as a JSON number
    let text = scene_json("pendulum.json").to_string().replacen(
        "\"rtol\"",
        "\"max_steps\": 18446744073709551615, \"rtol\"",
        1,
    );
    let e = Scene::from_json_str(&text).unwrap_err().to_string();
    assert!(
        e.contains("solve.max_steps") && e.contains("must be <= 1e15"),
        "{e}"
    );
    let p = scene_path("pendulum.json");
    let o = run(&[
        "run",
        p.to_str().unwrap(),
        "--max-steps",
        "18446744073709551615",
        "--table",
    ]);
    assert_refused(
        &o,
        &["--max-steps", "must be <= 1e15", "leave max_steps out"],
    );
    let server = start(bondmech::service::Config {
        addr: "127.0.0.1:0".parse().unwrap(),
        ..Default::default()
    });
    let r = post(
        server.addr(),
        "/v1/run?max_steps=18446744073709551615&t_end=0.1",
        std::fs::read(&p).unwrap().as_slice(),
    );
    let pr = r.problem(422);
    assert_eq!(pr["parameter"], "max_steps", "{pr}");
    // a large budget that means something still runs
    let o = run(&[
        "run",
        p.to_str().unwrap(),
        "--max-steps",
        "1000000000",
        "--table",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn regression_body_or_point_name_with_a_comma_broke_the_csv_header() {
    let mut v = scene_json("pendulum.json");
    v["bodies"][0]["points"]["P,1"] = json!([0.5, 0.0]);
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bodies[0].points.P,1") && e.contains("must not contain ','"),
        "{e}"
    );
    let mut v = scene_json("pendulum.json");
    v["bodies"][0]["name"] = json!("bar,1");
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bodies[0].name") && e.contains("'bar,1' must not contain ','"),
        "{e}"
    );
    let mut v = scene_json("pendulum.json");
    v["joints"][0]["name"] = json!("pin,a");
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("joints[0].name") && e.contains("','"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Vague
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_scene_from_dev_zero_was_read_for_64_mib_and_called_too_long() {
    // standard input fed with zeros (as `run - < /dev/zero`): refused at the first byte, at once
    let t0 = Instant::now();
    let o = run_with(&["run", "-"], Some(vec![0u8; 1 << 20]));
    assert_refused(&o, &["standard input", "byte 0 is a NUL byte", "/dev/zero"]);
    assert!(t0.elapsed() < Duration::from_secs(20));
    // a character device with /dev/zero's numbers, made in the test's own directory (root)
    let d = dir("zero");
    let z = d.join("zero");
    let made = Command::new("mknod")
        .arg(&z)
        .args(["c", "1", "5"])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        let t0 = Instant::now();
        let o = run(&["run", z.to_str().unwrap()]);
        assert_refused(&o, &["byte 0 is a NUL byte", "not a JSON scene"]);
        assert!(t0.elapsed() < Duration::from_secs(20));
    } else {
        eprintln!("the device-node case needs root (mknod); standard input was checked");
    }
    // an empty file is called empty
    let e = d.join("empty.json");
    std::fs::write(&e, "").unwrap();
    assert_refused(
        &run(&["run", e.to_str().unwrap()]),
        &["empty.json", "is empty"],
    );
}

#[test]
fn regression_negative_atol_was_taken_for_a_flag() {
    let p = scene_path("pendulum.json");
    let o = run(&["run", p.to_str().unwrap(), "--atol", "-1", "--table"]);
    assert_refused(&o, &["--atol", "solve.atol", "-1"]);
    assert!(
        !stderr(&o).contains("unexpected argument"),
        "{}",
        stderr(&o)
    );
    let o = run(&["run", p.to_str().unwrap(), "--t-end", "-2", "--table"]);
    assert_refused(&o, &["--t-end", "-2"]);
}

#[test]
fn regression_set_with_an_empty_path_was_vague() {
    let p = scene_path("pendulum.json");
    let o = run(&["run", p.to_str().unwrap(), "--set", "=1", "--table"]);
    assert_refused(
        &o,
        &["'=1'", "the path before '=' is empty", "bodies[0].mass=2"],
    );
    let o = run(&["run", p.to_str().unwrap(), "--set", "", "--table"]);
    assert_refused(&o, &["empty: expected PATH=JSON"]);
}

#[test]
fn regression_closed_standard_input_was_vague() {
    // standard input closed (`<&-`), and empty
    let o = Command::new("sh")
        .arg("-c")
        .arg("exec \"$0\" run - <&-")
        .arg(BIN)
        .output()
        .unwrap();
    assert_refused(
        &o,
        &["standard input", "is empty (closed, or /dev/null)", "run -"],
    );
    let o = run_with(&["run", "-"], Some(Vec::new()));
    assert_refused(&o, &["standard input", "is empty"]);
}

#[test]
fn regression_serve_max_body_0_was_vague() {
    let t0 = Instant::now();
    let o = run(&["serve", "--addr", "127.0.0.1:0", "--max-body", "0"]);
    assert_refused(
        &o,
        &[
            "--max-body",
            "must be at least 1",
            "refuse every request body",
        ],
    );
    assert!(
        t0.elapsed() < Duration::from_secs(20),
        "it did not start serving"
    );
}

/// A chain of `n` masses joined by springs: about 4n elements.
fn chain_graph(n: usize) -> Value {
    let mut els = Vec::new();
    let mut bonds = Vec::new();
    for i in 0..n {
        els.push(json!({"name": format!("v{i}"), "kind": "1"}));
        els.push(json!({"name": format!("m{i}"), "kind": "I", "value": 1.0}));
        bonds.push(json!({"from": format!("v{i}"), "to": format!("m{i}")}));
    }
    for i in 0..n - 1 {
        els.push(json!({"name": format!("z{i}"), "kind": "0"}));
        els.push(
            json!({"name": format!("k{i}"), "kind": "C", "stiffness": 1.0,
                        "initial": if i == 0 { 0.1 } else { 0.0 }}),
        );
        bonds.push(json!({"from": format!("v{i}"), "to": format!("z{i}")}));
        bonds.push(json!({"from": format!("z{i}"), "to": format!("v{}", i + 1)}));
        bonds.push(json!({"from": format!("z{i}"), "to": format!("k{i}")}));
    }
    json!({"bond_graph": {"elements": els, "bonds": bonds},
           "solve": {"t_end": 1.0, "output_step": 0.1}})
}

#[test]
fn regression_6000_element_graph_was_vague() {
    let v = chain_graph(1500);
    assert_eq!(v["bond_graph"]["elements"].as_array().unwrap().len(), 5998);
    // the command line runs it
    let d = dir("g6000");
    let p = d.join("g.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let o = run(&["run", p.to_str().unwrap(), "--table"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // the service refuses it naming its lists, the limit and the flag that sets it
    let server = start(bondmech::service::Config {
        addr: "127.0.0.1:0".parse().unwrap(),
        ..Default::default()
    });
    let r = post(server.addr(), "/v1/run", v.to_string().as_bytes());
    let pr = r.problem(422);
    let detail = pr["detail"].as_str().unwrap();
    assert!(
        detail.contains("bond_graph.elements 5998")
            && detail.contains("bond_graph.bonds")
            && detail.contains("max_elements = 512")
            && detail.contains("--max-elements"),
        "{pr}"
    );
}

#[test]
fn regression_1e4_events_were_vague() {
    let mut v = scene_json("pendulum.json");
    v["solve"]["t_end"] = json!(1.01);
    v["events"] = (1..=10_000)
        .map(|i| json!({"name": format!("e{i}"), "when": format!("t - {}", i as f64 * 1e-4), "action": "record"}))
        .collect();
    // the service counts them against max_elements, naming them
    let server = start(bondmech::service::Config {
        addr: "127.0.0.1:0".parse().unwrap(),
        ..Default::default()
    });
    let r = post(server.addr(), "/v1/run", v.to_string().as_bytes());
    let pr = r.problem(422);
    assert!(
        pr["detail"].as_str().unwrap().contains("events 10000"),
        "{pr}"
    );
    // the command line runs them; its table lists a few and counts the rest
    let d = dir("events");
    let p = d.join("e.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let o = run(&["run", p.to_str().unwrap(), "--table"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(out.matches("\nevent e").count(), 20, "{out}");
    assert!(
        out.contains("… and 9980 more events (summary.events lists all 10000"),
        "{out}"
    );
}

#[test]
fn regression_max_wall_seconds_1e300_was_vague_in_the_query_and_the_scene() {
    let server = start(bondmech::service::Config {
        addr: "127.0.0.1:0".parse().unwrap(),
        ..Default::default()
    });
    let text = std::fs::read(scene_path("pendulum.json")).unwrap();
    let r = post(
        server.addr(),
        "/v1/run?max_wall_seconds=1e300&t_end=0.1",
        &text,
    );
    let pr = r.problem(422);
    assert_eq!(pr["parameter"], "max_wall_seconds", "{pr}");
    assert!(
        pr["detail"].as_str().unwrap().contains("must be <= 1e9")
            && pr["detail"]
                .as_str()
                .unwrap()
                .contains("leave the setting out"),
        "{pr}"
    );
    let mut v = scene_json("pendulum.json");
    v["solve"]["max_wall_seconds"] = json!(1e300);
    let r = post(server.addr(), "/v1/run?t_end=0.1", v.to_string().as_bytes());
    let pr = r.problem(422);
    assert_eq!(pr["errors"][0]["path"], "solve.max_wall_seconds", "{pr}");
    let o = run(&[
        "run",
        scene_path("pendulum.json").to_str().unwrap(),
        "--max-wall-seconds",
        "1e300",
    ]);
    assert_refused(&o, &["--max-wall-seconds", "must be <= 1e9"]);
}

#[test]
fn regression_huge_query_string_was_answered_414_without_a_word() {
    let server = start(bondmech::service::Config {
        addr: "127.0.0.1:0".parse().unwrap(),
        ..Default::default()
    });
    let text = std::fs::read(scene_path("pendulum.json")).unwrap();
    let q = format!("/v1/run?t_end=0.1&formulation={}", "a".repeat(20_000));
    let r = post(server.addr(), &q, &text);
    let pr = r.problem(414);
    let detail = pr["detail"].as_str().unwrap();
    assert!(
        detail.contains("over the limit of 8192 bytes")
            && detail.contains("the scene goes in the body"),
        "{pr}"
    );
    assert_eq!(pr["limit"], "max_query_bytes");
    // a query within the limit is read as usual
    let r = post(server.addr(), "/v1/run?t_end=0.1&format=csv", &text);
    assert_eq!(r.status, 200);
}

// ---------------------------------------------------------------------------------------------
// Hangs
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_torque_exp_1e6_t_stepped_for_minutes_at_t_5_5e_5() {
    let d = dir("exp");
    let mut v = scene_json("pendulum.json");
    v["loads"] = json!([{"name": "motor", "type": "torque", "body": "bar", "value": "exp(1e6*t)"}]);
    let p = d.join("exp.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let out = d.join("o.csv");
    let t0 = Instant::now();
    let o = run(&["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let took = t0.elapsed();
    assert_refused(
        &o,
        &[
            "loads[0].value",
            "load 'motor'",
            "exp(1e6*t)",
            "grows without bound",
            "overflows by t ≈ 7.1",
            "step size collapsed",
        ],
    );
    // the cause named within seconds, far from any budget (none is set)
    assert!(took < Duration::from_secs(30), "{took:?}");
    // the rows before the collapse are kept
    assert!(std::fs::read_to_string(&out).unwrap().starts_with("t,"));
}

#[test]
fn regression_1e7_output_rows_ran_for_minutes_without_a_word() {
    let d = dir("rows");
    let out = d.join("o.csv");
    let p = scene_path("pendulum.json");
    // 2e6 + 1 rows; stopped by a 1 s budget so that the test writes little
    let o = run(&[
        "run",
        p.to_str().unwrap(),
        "--set",
        "solve.t_end=20",
        "--set",
        "solve.output_step=1e-5",
        "--max-wall-seconds",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(
        err.contains("bondmech: warning: 2000001 output rows of 11 columns")
            && err.contains("takes minutes")
            && err.contains("solve.output_step"),
        "{err}"
    );
    // the warning comes before the work, and the budget still bounds it
    assert!(
        err.find("warning").unwrap() < err.find("max_wall_seconds").unwrap(),
        "{err}"
    );
    assert_eq!(o.status.code(), Some(1), "{err}");
    // a run of a million rows less one says nothing
    let o = run(&[
        "run",
        p.to_str().unwrap(),
        "--set",
        "solve.t_end=1",
        "--set",
        "solve.output_step=1e-3",
        "--table",
    ]);
    assert!(!stderr(&o).contains("output rows"), "{}", stderr(&o));
}
