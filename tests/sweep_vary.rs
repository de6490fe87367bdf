//! Parameter sweeps (`sweep --vary`), their shards (`--shard i/n`, `sweep-merge`) and `--set`.
//!
//! References independent of the code under test: a serial run (one rayon thread) for the
//! parallel one; the unsharded sweep for the merged shards; a scene edited with serde_json (not
//! through `scene::path`) for `run --set` and for a sweep point; and a hand-built reference table
//! for the error column.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use bondmech::report::reference::reference_from_csv;
use bondmech::report::vary::{merge, merge_command, Shard, VaryReport, CSV_FILE};
use bondmech::report::ExternalReference;
use bondmech::study::vary::VarySweep;
use bondmech::{Model, Scene};

const SCENE: &str = "scenes/double_pendulum.json";

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bondmech-vary-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn bondmech(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args(args)
        .output()
        .expect("bondmech runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Fails with a one-line message on stderr (no panic, no backtrace).
fn refused(args: &[&str], needle: &str) {
    let o = bondmech(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
    assert!(e.contains(needle), "{args:?}: expected '{needle}' in: {e}");
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
}

fn sweep(vary: &[&str], reference: Option<&Path>) -> VarySweep {
    let text = std::fs::read_to_string(SCENE).unwrap();
    let vary: Vec<String> = vary.iter().map(|s| s.to_string()).collect();
    let reference = reference.map(|p| ExternalReference {
        source: p.display().to_string(),
        solution: reference_from_csv(p).unwrap(),
    });
    let t_end = if reference.is_some() { None } else { Some(0.5) };
    VarySweep::new(&text, "double_pendulum", &[], &vary, t_end, None, reference).unwrap()
}

/// The report as its JSON file has it (NaN as null), every CPU time set to zero (the only field
/// that may differ between runs).
fn without_cpu(mut r: VaryReport) -> serde_json::Value {
    for p in &mut r.points {
        p.cpu_seconds = 0.0;
    }
    serde_json::to_value(&r).unwrap()
}

/// A CSV line split into fields (fields may be quoted, with `""` for a quote).
fn fields(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                out.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(String::new()),
            (c, _) => out.last_mut().unwrap().push(c),
        }
    }
    out
}

/// The CSV table without its `cpu_seconds` column.
fn csv_without_cpu(text: &str) -> Vec<Vec<String>> {
    let rows: Vec<Vec<String>> = text.lines().map(fields).collect();
    let cpu = rows[0].iter().position(|h| h == "cpu_seconds").unwrap();
    rows.into_iter()
        .map(|mut r| {
            r.remove(cpu);
            r
        })
        .collect()
}

const TWO_PARAMETERS: [&str; 2] = [
    "bodies[bar2].mass=[0.5, 1, 2]",
    "gravity=[[0,-9.81],[0,-1.62]]",
];

#[test]
fn parallel_sweep_equals_serial_sweep_except_cpu_times() {
    let s = sweep(&TWO_PARAMETERS, None);
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let serial = pool(1).install(|| s.run(None, &|| {})).unwrap();
    let parallel = pool(4).install(|| s.run(None, &|| {})).unwrap();
    assert_eq!(serial.points.len(), 6);
    // the cartesian product, first --vary slowest
    let values: Vec<String> = serial
        .points
        .iter()
        .map(|p| format!("{},{}", p.values[0], p.values[1]))
        .collect();
    assert_eq!(
        values,
        [
            "0.5,[0,-9.81]",
            "0.5,[0,-1.62]",
            "1,[0,-9.81]",
            "1,[0,-1.62]",
            "2,[0,-9.81]",
            "2,[0,-1.62]"
        ]
    );
    assert!(serial.points.iter().all(|p| p.failure.is_none()));
    // the points differ from each other (so equality below means something)
    let angle = |r: &VaryReport, k: usize| {
        r.points[k]
            .final_values
            .iter()
            .find(|f| f.column == "bar2.angle")
            .unwrap()
            .value
    };
    assert!((angle(&serial, 0) - angle(&serial, 2)).abs() > 1e-3);
    assert_eq!(without_cpu(serial), without_cpu(parallel));
}

#[test]
fn sweep_point_equals_run_of_a_scene_edited_with_serde_json() {
    // independent of scene::path: edit the JSON with serde_json, write it, `run` it
    let dir = tmp("point");
    std::fs::create_dir_all(&dir).unwrap();
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(SCENE).unwrap()).unwrap();
    v["bodies"][1]["mass"] = serde_json::json!(2.0);
    v["gravity"] = serde_json::json!([0.0, -1.62]);
    let edited = dir.join("edited.json");
    std::fs::write(&edited, v.to_string()).unwrap();
    let csv_hand = dir.join("hand.csv");
    let o = bondmech(&[
        "run",
        edited.to_str().unwrap(),
        "--t-end",
        "0.5",
        "--out",
        csv_hand.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));

    // `run --set` on the original gives the same CSV, byte for byte
    let csv_set = dir.join("set.csv");
    let o = bondmech(&[
        "run",
        SCENE,
        "--set",
        "bodies[bar2].mass=2",
        "--set",
        "gravity=[0,-1.62]",
        "--t-end",
        "0.5",
        "--out",
        csv_set.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let hand = std::fs::read_to_string(&csv_hand).unwrap();
    assert_eq!(hand, std::fs::read_to_string(&csv_set).unwrap());

    // and the sweep's point (mass 2, moon gravity) has the hand-edited run's last row
    let r = sweep(&TWO_PARAMETERS, None).run(None, &|| {}).unwrap();
    let p = &r.points[5];
    assert_eq!(p.values[0], serde_json::json!(2));
    let header: Vec<&str> = hand.lines().next().unwrap().split(',').collect();
    let last: Vec<f64> = hand
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(p.t_final, last[0]);
    assert_eq!(p.final_values.len(), header.len() - 1);
    for f in &p.final_values {
        let c = header.iter().position(|h| *h == f.column).unwrap();
        assert_eq!(f.value, last[c], "{}", f.column);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn write_shards(s: &VarySweep, n: usize, name: &str) -> Vec<PathBuf> {
    (1..=n)
        .map(|i| {
            let d = tmp(&format!("{name}-shard{i}"));
            let r = s.run(Some(Shard { index: i, count: n }), &|| {}).unwrap();
            r.write_all(&d).unwrap();
            d
        })
        .collect()
}

#[test]
fn shards_then_merge_equal_the_unsharded_sweep() {
    let s = sweep(&TWO_PARAMETERS, None);
    let whole_dir = tmp("whole");
    let whole = s.run(None, &|| {}).unwrap();
    whole.write_all(&whole_dir).unwrap();
    // 4 shards of 6 points: round robin, sizes 2, 2, 1, 1; given out of order
    let mut dirs = write_shards(&s, 4, "two");
    dirs.reverse();
    let merged_dir = tmp("merged");
    let merged = merge_command(&dirs, &merged_dir).unwrap();
    assert_eq!(without_cpu(merged), without_cpu(whole.clone()));
    let read = |d: &Path| std::fs::read_to_string(d.join(CSV_FILE)).unwrap();
    let (a, b) = (read(&whole_dir), read(&merged_dir));
    assert_eq!(a.lines().count(), 7);
    assert_eq!(csv_without_cpu(&a), csv_without_cpu(&b));
    // the JSON read back equals the report (NaN-free here, f64 round trip exact)
    assert_eq!(
        without_cpu(VaryReport::read(&merged_dir).unwrap()),
        without_cpu(whole)
    );
    for d in dirs.iter().chain([&whole_dir, &merged_dir]) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn shards_then_merge_equal_the_unsharded_sweep_with_reference_errors_and_plot() {
    let dir = tmp("ref");
    std::fs::create_dir_all(&dir).unwrap();
    // an independent reference: the scene with bar2's mass 1 at a tight tolerance, 0.5 s
    let scene = Scene::from_path(SCENE).unwrap();
    let m = Model::new(&scene).unwrap();
    let mut o = m.default_options();
    o.rtol = 1e-12;
    o.atol = 1e-14;
    o.output_times = m.output_times_until(0.5).unwrap();
    let reference = dir.join("ref.csv");
    std::fs::write(&reference, m.solve(&o).unwrap().to_csv()).unwrap();

    let s = sweep(
        &["bodies[bar2].mass=[0.5, 0.9, 1, 1.1, 2]"],
        Some(&reference),
    );
    let whole = s.run(None, &|| {}).unwrap();
    // the errors: zero-ish at the reference's own mass, growing away from it
    let err: Vec<f64> = whole.points.iter().map(|p| p.error).collect();
    assert!(err[2] < 1e-6, "{err:?}");
    assert!(
        err[1] > 1e-3 && err[3] > 1e-3 && err[0] > err[1] && err[4] > err[3],
        "{err:?}"
    );
    let whole_dir = dir.join("whole");
    whole.write_all(&whole_dir).unwrap();
    let dirs = write_shards(&s, 2, "ref");
    let merged_dir = dir.join("merged");
    let merged = merge_command(&dirs, &merged_dir).unwrap();
    assert_eq!(without_cpu(merged), without_cpu(whole));
    let read = |d: &Path, f: &str| std::fs::read_to_string(d.join(f)).unwrap();
    assert_eq!(
        csv_without_cpu(&read(&whole_dir, CSV_FILE)),
        csv_without_cpu(&read(&merged_dir, CSV_FILE))
    );
    assert!(read(&whole_dir, CSV_FILE)
        .lines()
        .next()
        .unwrap()
        .contains(",error,"));
    // the plot (error against the mass) has no CPU time in it: identical files
    let svg = read(&whole_dir, "vary.svg");
    assert!(
        svg.starts_with("<svg") && svg.contains("bodies[bar2].mass"),
        "{svg}"
    );
    assert_eq!(svg, read(&merged_dir, "vary.svg"));
    for d in dirs.iter().chain([&dir]) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn merge_refuses_other_sweeps_missing_and_duplicate_shards() {
    let a = sweep(&["bodies[bar2].mass=[1, 2, 3]"], None);
    let b = sweep(&["bodies[bar2].mass=[1, 2, 4]"], None);
    let read = |dirs: &[PathBuf]| -> Vec<(PathBuf, VaryReport)> {
        dirs.iter()
            .map(|d| (d.clone(), VaryReport::read(d).unwrap()))
            .collect()
    };
    let sa = write_shards(&a, 3, "a");
    let sb = write_shards(&b, 3, "b");
    let err = |parts: Vec<(PathBuf, VaryReport)>| merge(&parts).unwrap_err().to_string();

    let e = err(read(&[sa[0].clone(), sb[1].clone(), sa[2].clone()]));
    assert!(
        e.contains("shards of different sweeps") && e.contains("--vary"),
        "{e}"
    );
    let e = err(read(&[sa[0].clone(), sa[2].clone()]));
    assert!(e.contains("missing shard 2/3"), "{e}");
    let e = err(read(&[
        sa[0].clone(),
        sa[1].clone(),
        sa[1].clone(),
        sa[2].clone(),
    ]));
    assert!(e.contains("shard 2/3 given twice"), "{e}");

    // a split into 2 mixed with a split into 3 of the same sweep
    let s2 = write_shards(&a, 2, "a2");
    let e = err(read(&[sa[0].clone(), s2[1].clone()]));
    assert!(
        e.contains("is shard 2/2") && e.contains("shard of 3"),
        "{e}"
    );

    // a whole sweep is not a shard
    let whole = tmp("a-whole");
    a.run(None, &|| {}).unwrap().write_all(&whole).unwrap();
    let e = err(read(std::slice::from_ref(&whole)));
    assert!(e.contains("holds a whole sweep"), "{e}");

    // a shard whose points were edited
    let mut parts = read(&sa);
    parts[1].1.points.pop();
    assert!(merge(&parts)
        .unwrap_err()
        .to_string()
        .contains("its points are not those of shard 2/3"));

    // the CLI: one line, naming the directories
    let out = tmp("merge-out");
    let args: Vec<&str> = [
        "sweep-merge",
        sa[0].to_str().unwrap(),
        sb[1].to_str().unwrap(),
    ]
    .into_iter()
    .chain(["--out", out.to_str().unwrap()])
    .collect();
    refused(&args, "shards of different sweeps");
    // the output must not be one of the inputs
    refused(
        &[
            "sweep-merge",
            sa[0].to_str().unwrap(),
            sa[1].to_str().unwrap(),
            sa[2].to_str().unwrap(),
            "--out",
            sa[1].to_str().unwrap(),
        ],
        "is an input directory",
    );
    refused(
        &[
            "sweep-merge",
            "/nonexistent-bondmech-dir",
            "--out",
            out.to_str().unwrap(),
        ],
        "cannot read vary.json",
    );
    for d in sa.iter().chain(&sb).chain(&s2).chain([&whole, &out]) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn cli_vary_shard_and_merge_write_the_unsharded_csv() {
    let base = tmp("cli");
    let d = |n: &str| base.join(n).to_str().unwrap().to_string();
    let common = [
        "sweep",
        SCENE,
        "--vary",
        "bodies[bar1].mass=[1,2]",
        "--vary",
        "solve.rtol=[1e-6,1e-8]",
        "--t-end",
        "0.2",
        "--columns",
        "bar2.angle,bar1.angle",
    ];
    let run = |extra: &[&str]| {
        let args: Vec<&str> = common
            .iter()
            .copied()
            .chain(extra.iter().copied())
            .collect();
        let o = bondmech(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        // not a terminal: no progress bar
        assert!(!stderr(&o).contains('\u{1b}'));
    };
    run(&["--out", &d("whole")]);
    run(&["--shard", "1/2", "--out", &d("s1")]);
    run(&["--shard", "2/2", "--out", &d("s2")]);
    let o = bondmech(&["sweep-merge", &d("s2"), &d("s1"), "--out", &d("merged")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |n: &str| std::fs::read_to_string(base.join(n).join(CSV_FILE)).unwrap();
    let whole = read("whole");
    assert_eq!(
        whole.lines().next().unwrap(),
        "index,bodies[bar1].mass,solve.rtol,failure,formulation,steps,residual_evals,\
         jacobian_evals,error_test_failures,cpu_seconds,max_constraint_error,energy_drift,\
         t_final,final.bar2.angle,final.bar1.angle"
    );
    assert_eq!(csv_without_cpu(&whole), csv_without_cpu(&read("merged")));
    // the tighter tolerance takes more steps: the varied value reached the solver
    let rows = csv_without_cpu(&whole);
    let steps = |k: usize| rows[k + 1][5].parse::<u64>().unwrap();
    assert!(steps(1) > steps(0) && steps(3) > steps(2), "{rows:?}");
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn bad_paths_values_and_flags_are_refused_with_one_line() {
    let out = tmp("bad");
    let o = out.to_str().unwrap();
    refused(
        &["run", SCENE, "--set", "bodies[7].mass=1"],
        "bodies[7].mass: index 7 out of range: 'bodies' has 2 entries",
    );
    refused(
        &["run", SCENE, "--set", "bodies[bar9].mass=1"],
        "no entry named 'bar9' in 'bodies' (names there: bar1, bar2)",
    );
    refused(
        &["run", SCENE, "--set", "solve.rtl=1e-9"],
        "solve.rtl: unknown field (did you mean \"rtol\"? expected one of: formulation, t_start, t_end",
    );
    refused(
        &["run", SCENE, "--set", "bodeis[0].mass=1"],
        "no key 'bodeis' in the scene (keys there: name",
    );
    refused(
        &["compare", SCENE, "--set", "bodies[0].mass=\"heavy\""],
        "bodies[0].mass: expected a number, got string (set by --set bodies[0].mass=\"heavy\")",
    );
    refused(
        &["run", SCENE, "--set", "solve.formulation=index1"],
        "a string needs JSON quotes",
    );
    refused(&["run", SCENE, "--set", "gravity"], "expected PATH=JSON");
    refused(
        &[
            "sweep",
            SCENE,
            "--vary",
            "bodies[1].mass=[1,-1]",
            "--out",
            o,
        ],
        "sweep point 1 (bodies[1].mass=-1): bodies[1].mass: must be > 0",
    );
    refused(
        &["sweep", SCENE, "--vary", "bodies[1].mass=2", "--out", o],
        "expected a JSON array of values",
    );
    for bad in ["0/2", "3/2", "2", "a/b", "1/0"] {
        refused(
            &[
                "sweep",
                SCENE,
                "--vary",
                "bodies[1].mass=[1,2]",
                "--shard",
                bad,
                "--out",
                o,
            ],
            &format!("--shard '{bad}'"),
        );
    }
    refused(
        &["sweep", SCENE, "--shard", "1/2", "--out", o],
        "need --vary",
    );
    refused(
        &[
            "sweep",
            SCENE,
            "--vary",
            "bodies[1].mass=[1,2]",
            "--vary",
            "bodies[bar2].mass=[3]",
            "--out",
            o,
        ],
        "--vary bodies[1].mass and --vary bodies[bar2].mass both vary bodies[1].mass",
    );
    refused(
        &[
            "sweep",
            SCENE,
            "--vary",
            "bodies[1].mass=[1,2]",
            "--quick",
            "--out",
            o,
        ],
        "--quick belongs to the tolerance/stiffness sweep",
    );
    refused(
        &[
            "sweep",
            SCENE,
            "--vary",
            "bodies[1].mass=[1]",
            "--t-end",
            "0.1",
            "--columns",
            "bar3.x",
            "--out",
            o,
        ],
        "--columns: no column 'bar3.x' (the runs write: bar1.x",
    );
    // an output directory that cannot be written is refused before anything is solved
    let file = tmp("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let blocked = file.join("sub");
    refused(
        &[
            "sweep",
            SCENE,
            "--vary",
            "bodies[1].mass=[1,2]",
            "--out",
            blocked.to_str().unwrap(),
        ],
        "not-a-dir",
    );
    // outputs never overwrite inputs: a scene called vary.json in the output directory
    let dir = tmp("overwrite");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("vary.json");
    std::fs::copy(SCENE, &scene).unwrap();
    refused(
        &[
            "sweep",
            scene.to_str().unwrap(),
            "--vary",
            "bodies[1].mass=[1,2]",
            "--out",
            dir.to_str().unwrap(),
        ],
        "would overwrite the input",
    );
    assert_eq!(
        std::fs::read_to_string(&scene).unwrap(),
        std::fs::read_to_string(SCENE).unwrap()
    );
    for p in [&out, &dir] {
        let _ = std::fs::remove_dir_all(p);
    }
    let _ = std::fs::remove_file(&file);
}

#[test]
fn set_applies_to_a_scene_read_from_standard_input() {
    use std::io::Write;
    use std::process::Stdio;
    let args = [
        "--set",
        "solve.rtol=1e-9",
        "--set",
        "bodies[0].angle=0.3",
        "--t-end",
        "0.3",
    ];
    let from_file = bondmech(&[&["run", SCENE][..], &args[..]].concat());
    assert!(from_file.status.success(), "{}", stderr(&from_file));
    let mut child = Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args(["run", "-"])
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(std::fs::read_to_string(SCENE).unwrap().as_bytes())
        .unwrap();
    let from_stdin = child.wait_with_output().unwrap();
    assert!(from_stdin.status.success(), "{}", stderr(&from_stdin));
    assert_eq!(from_file.stdout, from_stdin.stdout);
    // and the assignments took effect
    let plain = bondmech(&["run", SCENE, "--t-end", "0.3"]);
    assert!(plain.status.success());
    assert_ne!(plain.stdout, from_file.stdout);
}
