//! Issue 26, "no panic, no lost file, no hang": one regression test per finding of the
//! 588-case bad-input probe (each failed on main at 990857e), and the issue's "Must show"
//! items (an output onto a hard or symbolic link of the input, a SIGTERM mid-write, a 1e7-row
//! run and 6000 free bodies under `ulimit -v 4194304`).

#[path = "support/nodes.rs"]
#[allow(dead_code)] // the probe uses the sink only
mod nodes;
mod service_support;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use bondmech::scene::Scene;
use serde_json::{json, Value};
use service_support::{post, start};

const BIN: &str = env!("CARGO_BIN_EXE_bondmech");

/// A fresh directory for one test.
fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bondmech-probe-{}-{name}", std::process::id()));
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

/// Runs `bondmech ARGS` and kills it after `limit` (a hang fails the test instead of hanging
/// it); `None` when it had to be killed.
fn run_within(args: &[&str], limit: Duration) -> Option<Output> {
    run_shell_within(None, args, limit)
}

/// [`run_within`], through `sh -c 'ulimit -v KIB; exec bondmech ARGS'` when `ulimit_kib` is
/// given.
fn run_shell_within(ulimit_kib: Option<u64>, args: &[&str], limit: Duration) -> Option<Output> {
    let mut cmd = match ulimit_kib {
        Some(kib) => {
            let mut c = Command::new("sh");
            c.arg("-c")
                .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
                .arg(BIN)
                .args(args);
            c
        }
        None => {
            let mut c = Command::new(BIN);
            c.args(args);
            c
        }
    };
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bondmech runs");
    // drain the pipes on threads so that a chatty child never blocks
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let out_t = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut so, &mut v).ok();
        v
    });
    let err_t = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut se, &mut v).ok();
        v
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(Output {
                status,
                stdout: out_t.join().unwrap(),
                stderr: err_t.join().unwrap(),
            });
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit code 1 with one `bondmech:` line containing every fragment (no panic: 101, no abort:
/// a signal).
fn assert_clear_error(o: &Output, fragments: &[&str]) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(1), "{:?}: {e}", o.status);
    assert!(
        e.starts_with("bondmech: ") && !e.contains("panicked"),
        "{e}"
    );
    for f in fragments {
        assert!(e.contains(f), "expected {f:?} in: {e}");
    }
}

// ---------------------------------------------------------------------------------------------
// 1. A large time budget went unchecked into Duration::from_secs_f64 (panic, HTTP 500).
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_max_wall_seconds_1e20_panicked_in_duration_from_secs_f64() {
    let p = scene_path("pendulum.json");
    let out = dir("wall1e20").join("o.csv");
    let o = run_within(
        &[
            "run",
            p.to_str().unwrap(),
            "--max-wall-seconds",
            "1e20",
            "--out",
            out.to_str().unwrap(),
        ],
        Duration::from_secs(60),
    )
    .expect("no hang");
    assert_clear_error(&o, &["--max-wall-seconds", "solve.max_wall_seconds", "1e9"]);
    // the same number in a scene names its field
    let mut v = scene_json("pendulum.json");
    v["solve"]["max_wall_seconds"] = json!(1e300);
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("solve.max_wall_seconds: must be <= 1e9"), "{e}");
}

#[test]
fn regression_service_max_wall_seconds_1e300_answered_500() {
    let server = start(bondmech::service::Config::default());
    let body = std::fs::read(scene_path("pendulum.json")).unwrap();
    let r = post(server.addr(), "/v1/run?max_wall_seconds=1e300", &body);
    let j = r.problem(422);
    assert_eq!(j["parameter"], "max_wall_seconds", "{j}");
    // the server is still up and answers a good request
    let ok = post(server.addr(), "/v1/run?max_wall_seconds=5", &body);
    assert_eq!(ok.status, 200, "{}", ok.text());
}

#[test]
fn regression_serve_shutdown_grace_and_max_solve_seconds_1e300_killed_the_server_at_start() {
    use clap::Parser;
    #[derive(clap::Parser)]
    struct Args {
        #[command(flatten)]
        serve: bondmech::service::ServeArgs,
    }
    for (flag, value) in [
        ("--shutdown-grace", "1e300"),
        ("--max-solve-seconds", "1e300"),
        ("--shutdown-grace", "-1"),
        ("--max-solve-seconds", "0"),
        // counts that become semaphores and threads
        ("--max-concurrent", "18446744073709551615"),
        ("--queue", "18446744073709551615"),
    ] {
        let args = Args::try_parse_from(["serve".to_string(), format!("{flag}={value}")])
            .expect("the flag parses as a number");
        let e = args
            .serve
            .config()
            .expect_err("an absurd duration is refused");
        assert!(e.starts_with(flag), "{flag} {value}: {e}");
    }
    let ok = Args::try_parse_from([
        "serve",
        "--shutdown-grace",
        "0",
        "--max-solve-seconds",
        "1e9",
    ])
    .unwrap();
    ok.serve
        .config()
        .expect("the bounds themselves are accepted");
}

// ---------------------------------------------------------------------------------------------
// 2. The output-is-not-an-input check compared paths, not files (hard links).
// ---------------------------------------------------------------------------------------------

/// A copy of the pendulum scene in `d`, and its bytes.
fn scene_copy(d: &Path) -> (PathBuf, Vec<u8>) {
    let p = d.join("p.json");
    std::fs::copy(scene_path("pendulum.json"), &p).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    (p, bytes)
}

#[test]
fn regression_out_onto_a_hard_link_of_the_scene_overwrote_it() {
    let d = dir("hardlink");
    let (p, before) = scene_copy(&d);
    for (i, flag) in ["--out", "--summary"].into_iter().enumerate() {
        let link = d.join(format!("link{i}.csv"));
        std::fs::hard_link(&p, &link).unwrap();
        let o = run_within(
            &["run", p.to_str().unwrap(), flag, link.to_str().unwrap()],
            Duration::from_secs(60),
        )
        .unwrap();
        assert_clear_error(&o, &[flag, "hard link"]);
        assert_eq!(
            std::fs::read(&p).unwrap(),
            before,
            "{flag}: the scene is intact"
        );
    }
    // compare --json too
    let link = d.join("cmp.json");
    std::fs::hard_link(&p, &link).unwrap();
    let o = run_within(
        &[
            "compare",
            p.to_str().unwrap(),
            "--json",
            link.to_str().unwrap(),
        ],
        Duration::from_secs(120),
    )
    .unwrap();
    assert_clear_error(&o, &["--json", "hard link"]);
    assert_eq!(std::fs::read(&p).unwrap(), before);
}

#[test]
fn out_onto_a_symbolic_link_of_the_scene_is_refused_and_leaves_it_intact() {
    let d = dir("symlink");
    let (p, before) = scene_copy(&d);
    let link = d.join("out.csv");
    std::os::unix::fs::symlink(&p, &link).unwrap();
    let o = run_within(
        &["run", p.to_str().unwrap(), "--out", link.to_str().unwrap()],
        Duration::from_secs(60),
    )
    .unwrap();
    assert_clear_error(&o, &["--out", "symbolic link"]);
    assert_eq!(std::fs::read(&p).unwrap(), before);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
}

// ---------------------------------------------------------------------------------------------
// 3. --out was written in place: a SIGTERM mid-write cut the file and lost the previous one.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_sigterm_mid_write_cut_the_output_and_lost_the_previous_one() {
    let d = dir("sigterm");
    let (p, scene_before) = scene_copy(&d);
    let out = d.join("out.csv");
    let previous = b"t,previous\n0,1\n".to_vec();
    std::fs::write(&out, &previous).unwrap();
    // ~1e6 rows: several seconds of writing
    let mut child = Command::new(BIN)
        .args([
            "run",
            p.to_str().unwrap(),
            "--set",
            "solve.t_end=10",
            "--set",
            "solve.output_step=1e-5",
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // wait until rows are being written: into a file beside the target (now), or into the
    // target itself (before the fix: it had then lost its previous content)
    let start = Instant::now();
    let writing = loop {
        let target_changed = std::fs::read(&out).map_or(true, |b| b != previous);
        let temp_growing = std::fs::read_dir(&d).unwrap().flatten().any(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(".out.csv.") && e.metadata().is_ok_and(|m| m.len() > 100_000)
        });
        if target_changed || temp_growing {
            break true;
        }
        if child.try_wait().unwrap().is_some() || start.elapsed() > Duration::from_secs(120) {
            break false;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    assert!(writing, "the run never started writing");
    // SIGKILL: a run that cannot react. (Since issue 38, SIGTERM and SIGINT stop the solve at
    // its next step and rename the rows so far into place whole, exit 143 / 130:
    // tests/interrupt.rs; a kill must still leave the previous output untouched.)
    let killed = Command::new("kill")
        .args(["-KILL", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert!(!status.success(), "killed mid-write: {status:?}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        previous,
        "a killed run leaves the previous output as it was"
    );
    assert_eq!(std::fs::read(&p).unwrap(), scene_before, "and the input");
}

// ---------------------------------------------------------------------------------------------
// 4. A --plot directory that cannot be made was found after the solve; the rows were lost.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_plot_dir_that_cannot_be_made_lost_the_rows_and_did_not_name_the_flag() {
    let d = dir("plot");
    let (p, _) = scene_copy(&d);
    let out = d.join("o5.csv");
    let plots = p.join("plots"); // under a file
    let started = Instant::now();
    let o = run_within(
        &[
            "run",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--plot",
            plots.to_str().unwrap(),
            // a long run: refused before it, not after
            "--set",
            "solve.t_end=1000",
            "--set",
            "solve.output_step=0.01",
        ],
        Duration::from_secs(120),
    )
    .unwrap();
    assert_clear_error(&o, &["--plot", "p.json is a file"]);
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "refused before solving"
    );
    assert!(!out.exists(), "nothing was solved, nothing written");
}

// ---------------------------------------------------------------------------------------------
// 5. The memory guard read the machine's free memory, not ulimit -v: SIGABRT under a cap.
// ---------------------------------------------------------------------------------------------

/// `n` free planar bodies (no joints), 1 s.
fn free_bodies_scene(n: usize) -> Value {
    let bodies: Vec<Value> = (0..n)
        .map(|i| {
            json!({"name": format!("b{i}"), "mass": 1.0, "inertia": 0.1,
                   "position": [i as f64, 0.0]})
        })
        .collect();
    json!({"dimension": 2, "gravity": [0.0, -9.81], "bodies": bodies,
           "solve": {"t_end": 1.0, "output_step": 0.5}})
}

#[test]
fn regression_6000_free_bodies_aborted_under_ulimit_v_4_gib_instead_of_being_refused() {
    let d = dir("free6000");
    let p = d.join("free.json");
    std::fs::write(&p, free_bodies_scene(6000).to_string()).unwrap();
    let out = d.join("o.csv");
    let started = Instant::now();
    let o = run_shell_within(
        Some(4_194_304),
        &["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()],
        Duration::from_secs(120),
    )
    .expect("no hang");
    assert_clear_error(&o, &["too large", "ulimit -v", "18000 coordinates"]);
    assert!(
        started.elapsed() < Duration::from_secs(60),
        "refused up front"
    );
}

// ---------------------------------------------------------------------------------------------
// 6. Output rows were built in memory before writing: abort at the documented row limit.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_1e6_rows_aborted_under_a_200_mb_address_space_instead_of_streaming() {
    // before the fix the rows and then their CSV text were built in memory: 1e6 rows of the
    // pendulum aborted under `ulimit -v 200000`; streamed, they need a few MB
    let d = dir("rows");
    let summary = d.join("s.json");
    let out = d.join("o.csv");
    let p = scene_path("pendulum.json");
    let o = run_shell_within(
        Some(200_000),
        &[
            "run",
            p.to_str().unwrap(),
            "--set",
            "solve.t_end=10",
            "--set",
            "solve.output_step=1e-5",
            "--out",
            out.to_str().unwrap(),
            "--summary",
            summary.to_str().unwrap(),
        ],
        Duration::from_secs(300),
    )
    .expect("no hang");
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().count(), 1_000_002, "header and 1e6 + 1 rows");
    assert!(text.ends_with('\n'));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(s["completed"], true);
    assert_eq!(s["t_reached"], 10.0);
}

#[test]
fn a_1e7_row_run_under_ulimit_v_4_gib_completes_streaming_to_its_sink() {
    // the documented row limit, 1e7 rows (t_end 10 s at 1e-6 s), streamed to a sink that
    // discards them (a null device node made in the test's directory, or a drained FIFO)
    let d = dir("rows1e7");
    let summary = d.join("s.json");
    let (sink, reader) = nodes::discard_sink(&d);
    let p = scene_path("bg_mass_spring_damper.json");
    let o = run_shell_within(
        Some(4_194_304),
        &[
            "run",
            p.to_str().unwrap(),
            "--set",
            "solve.output_step=1e-6",
            "--out",
            sink.to_str().unwrap(),
            "--summary",
            summary.to_str().unwrap(),
        ],
        Duration::from_secs(600),
    )
    .expect("no hang");
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(s["completed"], true);
    assert_eq!(s["t_reached"], 10.0);
    if let Some(r) = reader {
        assert!(
            r.join().unwrap() > 1_000_000_000,
            "the rows went through the FIFO"
        );
    } else {
        assert!(nodes::is_char_device(&sink), "the sink is still a device");
    }
}

#[test]
fn rows_kept_in_memory_beyond_the_limit_are_refused_up_front_naming_the_setting() {
    // --table keeps the rows: under a 300 MB address space 1e7 of them cannot be kept
    let p = scene_path("pendulum.json");
    let o = run_shell_within(
        Some(300_000),
        &[
            "run",
            p.to_str().unwrap(),
            "--set",
            "solve.t_end=10",
            "--set",
            "solve.output_step=1e-6",
            "--table",
        ],
        Duration::from_secs(120),
    )
    .expect("no hang");
    assert_clear_error(&o, &["output rows", "solve.output_step", "ulimit -v"]);
}

// ---------------------------------------------------------------------------------------------
// 7. A huge start time stepped forever (t + h == t).
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_t_start_1e300_stepped_forever_because_t_plus_h_equals_t() {
    let p = scene_path("pendulum.json");
    let out = dir("t1e300").join("o.csv");
    let o = run_within(
        &[
            "run",
            p.to_str().unwrap(),
            "--set",
            "solve.t_start=1e300",
            "--set",
            "solve.t_end=2e300",
            "--set",
            "solve.output_step=1e298",
            "--out",
            out.to_str().unwrap(),
        ],
        Duration::from_secs(60),
    )
    .expect("stopped by itself, not after 60 s");
    assert_clear_error(&o, &["cannot advance the time", "t = 1e300"]);
}

// ---------------------------------------------------------------------------------------------
// 8. Scene handling was quadratic in the number of named points; 200 000 bodies hung.
// ---------------------------------------------------------------------------------------------

/// The pendulum with `n` more named points, each an output; 0.01 s.
fn many_points(n: usize) -> String {
    let mut v = scene_json("pendulum.json");
    let points = v["bodies"][0]["points"].as_object_mut().unwrap();
    for i in 0..n {
        points.insert(format!("p{i}"), json!([0.001 * i as f64, 0.0]));
    }
    v["outputs"] = json!((0..n).map(|i| format!("bar.p{i}")).collect::<Vec<_>>());
    v["solve"]["t_end"] = json!(0.01);
    v.to_string()
}

/// CPU seconds of this thread to read, build and solve `text`: the other tests of this binary
/// run beside it, and under their load the wall clock measured them too (a ratio of 8.6 once,
/// on an unchanged program that gives 4-5 alone).
fn load_and_solve_seconds(text: &str) -> f64 {
    let t = cpu_time::ThreadTime::now();
    let scene = Scene::from_json_str(text).unwrap();
    let model = bondmech::Model::new(&scene).unwrap();
    let sol = model.solve(&model.default_options()).unwrap();
    assert_eq!(sol.times.len(), 2);
    t.elapsed().as_secs_f64()
}

#[test]
fn regression_40k_named_points_took_quadratic_time() {
    let (small, large) = (many_points(10_000), many_points(40_000));
    let t_small = load_and_solve_seconds(&small);
    let t_large = load_and_solve_seconds(&large);
    // 4 times the points: about 4 times the time when linear, 16 when quadratic (before the
    // fix: 1.4 s and 17.4 s in this profile, a ratio of 12)
    assert!(
        t_large < 8.0 * t_small.max(0.05),
        "10 000 points: {t_small:.2} s, 40 000: {t_large:.2} s"
    );
}

#[test]
fn regression_200k_bodies_were_neither_solved_nor_refused_within_60_s() {
    let text = free_bodies_scene(200_000).to_string();
    let t = Instant::now();
    let e = Scene::from_json_str(&text).unwrap_err().to_string();
    assert!(
        e.contains("bodies: 200000 entries, more than the limit of 100000"),
        "{e}"
    );
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
    // inside the limit, a model far too large is refused by the memory guard at once
    let t = Instant::now();
    let scene = Scene::from_json_str(&free_bodies_scene(50_000).to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err();
    assert!(matches!(e, bondmech::Error::TooLarge(_)), "{e}");
    assert!(t.elapsed() < Duration::from_secs(30), "{:?}", t.elapsed());
}

// ---------------------------------------------------------------------------------------------
// 9. A point name with a comma went unquoted into the CSV header (corrupt CSV, exit 0).
//    Since issue 51 such a name is refused where it is written: column lists (`--columns`,
//    `outputs`, the service's `output=`) are comma-separated, and tools reading a header by
//    splitting it on commas broke on the quoted cell.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_point_name_with_a_comma_corrupted_the_csv_header() {
    let d = dir("comma");
    let mut v = scene_json("pendulum.json");
    v["bodies"][0]["points"]["P,1"] = json!([0.5, 0.0]);
    v["outputs"] = json!(["bar.P,1", "energy"]);
    let p = d.join("comma.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let out = d.join("o.csv");
    let o = run_within(
        &["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()],
        Duration::from_secs(60),
    )
    .unwrap();
    assert_clear_error(&o, &["bodies[0].points.P,1", "must not contain ','"]);
    assert!(!out.exists(), "no CSV written");
}

// ---------------------------------------------------------------------------------------------
// 10. Element values given as expression strings skipped the sign checks.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_inertia_minus_1_5_given_as_an_expression_string_ran() {
    let mut v = scene_json("bg_mass_spring_damper.json");
    assert_eq!(v["bond_graph"]["elements"][2]["kind"], "I");
    v["bond_graph"]["elements"][2]["value"] = json!("-1.5");
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(
        e.contains("bond_graph.elements[2].value") && e.contains("inertia must be >= 0"),
        "{e}"
    );
    // a resistance of t - 1 is negative at the start (t_start = 0)
    let mut v = scene_json("bg_mass_spring_damper.json");
    v["bond_graph"]["elements"][4]["value"] = json!("t - 1");
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    let e = bondmech::Model::new(&scene).unwrap_err().to_string();
    assert!(
        e.contains("bond_graph.elements[4].value") && e.contains("resistance must be >= 0"),
        "{e}"
    );
    // evaluated at t_start: from t_start = 2 it is positive
    v["solve"]["t_start"] = json!(2.0);
    v["solve"]["t_end"] = json!(3.0);
    v["solve"]["output_step"] = json!(0.5);
    let scene = Scene::from_json_str(&v.to_string()).unwrap();
    bondmech::Model::new(&scene).expect("1 + ... > 0 from t = 2");
}

// ---------------------------------------------------------------------------------------------
// 11. Silently accepted: an infinite span, duplicate keys inside bond_graph, duplicate spring
//     and load names, /v1/graph?decoupled=true on a raw bond graph.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_infinite_time_span_was_accepted_as_one_completed_row() {
    let mut v = scene_json("bg_mass_spring_damper.json");
    v["solve"] = json!({"t_start": -1e308, "t_end": 1e308, "output_times": [0.0, 1.0]});
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("solve.t_end") && e.contains("must be finite"),
        "{e}"
    );
}

#[test]
fn regression_duplicate_keys_inside_bond_graph_were_silently_dropped() {
    let text = std::fs::read_to_string(scene_path("bg_mass_spring_damper.json")).unwrap();
    let dup = text.replace(
        r#"{"name": "m", "kind": "I", "value": 1.5}"#,
        r#"{"name": "m", "kind": "I", "value": 1.5, "value": -3}"#,
    );
    assert_ne!(dup, text);
    let e = Scene::from_json_str(&dup).unwrap_err().to_string();
    assert!(
        e.contains("bond_graph.elements[2].value: duplicate key"),
        "{e}"
    );
}

#[test]
fn regression_duplicate_spring_and_load_names_were_accepted_and_set_edited_the_first() {
    let spring = json!({"name": "s", "bodies": ["ground", "bar"], "points": [[1.0, 0.0], "A"], "stiffness": 1.0});
    let mut v = scene_json("pendulum.json");
    v["springs"] = json!([spring, spring]);
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("springs[1].name: duplicate spring name 's'"),
        "{e}"
    );
    let load =
        json!({"name": "f", "type": "force", "body": "bar", "point": "A", "value": [0.0, 1.0]});
    let mut v = scene_json("pendulum.json");
    v["loads"] = json!([load, load]);
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("loads[1].name: duplicate load name 'f'"), "{e}");
}

#[test]
fn regression_service_drew_a_decoupled_raw_bond_graph_that_the_cli_refuses() {
    let server = start(bondmech::service::Config::default());
    let body = std::fs::read(scene_path("bg_mass_spring_damper.json")).unwrap();
    let r = post(server.addr(), "/v1/graph?decoupled=true", &body);
    let j = r.problem(422);
    assert!(
        j["detail"]
            .as_str()
            .unwrap()
            .contains("no joints to decouple"),
        "{j}"
    );
    let ok = post(server.addr(), "/v1/graph", &body);
    assert_eq!(ok.status, 200, "{}", ok.text());
}

// ---------------------------------------------------------------------------------------------
// 12. Body names the spec allows were refused with an internal bond-graph message.
// ---------------------------------------------------------------------------------------------

#[test]
fn regression_legal_body_names_left_arm_arm_1_arm_umlaut_arm_plus_1_were_refused() {
    for scene in ["pendulum.json", "hinged_double_pendulum_3d.json"] {
        for name in ["left-arm", "arm 1", "Ärm", "arm+1"] {
            let v = scene_json(scene);
            let old = v["bodies"][0]["name"].as_str().unwrap().to_string();
            let text = v
                .to_string()
                .replace(&format!("\"{old}"), &format!("\"{name}"));
            let s = Scene::from_json_str(&text).unwrap_or_else(|e| panic!("{scene} '{name}': {e}"));
            let model =
                bondmech::Model::new(&s).unwrap_or_else(|e| panic!("{scene} '{name}': {e}"));
            let mut opts = model.default_options();
            opts.output_times.truncate(5);
            let sol = model
                .solve(&opts)
                .unwrap_or_else(|e| panic!("{scene} '{name}': {e}"));
            assert!(
                sol.columns.contains(&format!("{name}.x")),
                "{:?}",
                sol.columns
            );
        }
    }
    // a name the expressions cannot quote is refused with its path
    let mut v = scene_json("pendulum.json");
    v["bodies"][0]["name"] = json!("a`b");
    let e = Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bodies[0].name: 'a`b' must not contain '`'"),
        "{e}"
    );
}

#[test]
fn a_load_expression_reads_a_quoted_body_name() {
    let mut v = scene_json("pendulum.json");
    let text = v.to_string().replace("\"bar", "\"left-arm");
    v = serde_json::from_str(&text).unwrap();
    v["loads"] = json!([{"type": "torque", "body": "left-arm",
                         "value": "-0.1 * `left-arm.omega`"}]);
    let s = Scene::from_json_str(&v.to_string()).unwrap();
    let model = bondmech::Model::new(&s).unwrap();
    let mut opts = model.default_options();
    opts.output_times.truncate(5);
    model.solve(&opts).unwrap();
}

// ---------------------------------------------------------------------------------------------
// A run stopped by a budget keeps its rows, streamed or not.
// ---------------------------------------------------------------------------------------------

#[test]
fn a_run_stopped_by_a_budget_keeps_every_streamed_row_and_counts_them() {
    let d = dir("budget");
    let out = d.join("o.csv");
    let p = scene_path("pendulum.json");
    let o = run_within(
        &[
            "run",
            p.to_str().unwrap(),
            "--max-steps",
            "300",
            "--out",
            out.to_str().unwrap(),
        ],
        Duration::from_secs(60),
    )
    .unwrap();
    assert_clear_error(&o, &["--max-steps", "written to"]);
    let e = stderr(&o);
    let rows = std::fs::read_to_string(&out).unwrap().lines().count() - 1;
    assert!(rows > 2, "{rows} rows");
    assert!(e.contains(&format!("the {rows} rows up to t = ")), "{e}");
}
