//! Issue 38, "the project's own probe over every command and output flag": each command that
//! writes (`run`, `compare`, `sweep`, `sweep-merge`, `graph`, `plot`, `animate`, `fmu`,
//! `equilibrium` and `linearize` (issue 51: their `--json` overwrote the scene), and the
//! CSV, text and JSON they print on standard output) is pointed at every kind of output a user
//! can give — a new regular file, an existing one, a symbolic link to one, a FIFO with a reader,
//! a null device and a full device (made with `mknod` in the test's own directory, as root;
//! skipped with a message otherwise), a directory, a path under a regular file, a read-only
//! file, and the command's own input — and `run`, `sweep` and `serve` get SIGINT or SIGTERM
//! after a delay. Every outcome is checked for:
//!
//! - **no data loss**: the inputs are byte for byte unchanged; an output is either complete
//!   (the CSV's rows all as long as its header, the JSON parses, the SVG or HTML closed, the
//!   zip's end record present) or the command fails (exit ≠ 0) naming that output; a file that
//!   existed before a failure is left as it was; no temporary file is left;
//! - **no hang**: each command is killed after 60 s (a failure);
//! - **no panic**: no exit 101, no "panicked" on standard error;
//! - **no abort**: no death by a signal other than the one the test sent;
//! - **no harm**: a device node stays a device, a FIFO a FIFO, a symbolic link a link.
//!
//! Nothing here names a path under the machine's `/dev`.

mod support;

use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use support::cli::{fresh_dir, scene, temp_files};
use support::nodes::{char_device, fifo, is_char_device, is_root};

const BIN: &str = env!("CARGO_BIN_EXE_bondmech");

/// What kind of thing an output flag names.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Kind {
    /// A file; `ext` is the extension the command wants (`csv`, `json`, `svg`, `html`, `fmu`,
    /// `dot`).
    File(&'static str),
    /// A directory the command fills.
    Dir,
}

/// One command and output flag: the arguments with `OUT` for the output and `SCENE`, `CSV`,
/// `SHARD` for the inputs.
struct Probe {
    name: &'static str,
    args: &'static [&'static str],
    kind: Kind,
}

const PROBES: &[Probe] = &[
    Probe {
        name: "run --out",
        args: &["run", "SCENE", "--t-end", "0.2", "--out", "OUT"],
        kind: Kind::File("csv"),
    },
    Probe {
        name: "run --summary",
        args: &[
            "run",
            "SCENE",
            "--t-end",
            "0.2",
            "--out",
            "OTHER.csv",
            "--summary",
            "OUT",
        ],
        kind: Kind::File("json"),
    },
    Probe {
        name: "run --plot",
        args: &["run", "SCENE", "--t-end", "0.2", "--plot", "OUT"],
        kind: Kind::Dir,
    },
    Probe {
        name: "compare --json",
        args: &["compare", "SCENE", "--t-end", "0.2", "--json", "OUT"],
        kind: Kind::File("json"),
    },
    Probe {
        name: "graph --out",
        args: &["graph", "SCENE", "--out", "OUT"],
        kind: Kind::File("dot"),
    },
    Probe {
        name: "graph --causality --out",
        args: &["graph", "SCENE", "--causality", "--out", "OUT"],
        kind: Kind::File("json"),
    },
    Probe {
        name: "graph --as-scene --out",
        args: &["graph", "SCENE", "--as-scene", "--out", "OUT"],
        kind: Kind::File("json"),
    },
    Probe {
        name: "animate --out",
        args: &["animate", "SCENE", "--t-end", "0.2", "--out", "OUT"],
        kind: Kind::File("svg"),
    },
    Probe {
        name: "animate --out html",
        args: &["animate", "SCENE", "--t-end", "0.2", "--out", "OUT"],
        kind: Kind::File("html"),
    },
    Probe {
        name: "animate --frames",
        args: &[
            "animate",
            "SCENE",
            "--t-end",
            "0.2",
            "--out",
            "OTHER.svg",
            "--frames",
            "OUT",
        ],
        kind: Kind::File("json"),
    },
    Probe {
        name: "animate --csv --out",
        args: &["animate", "SCENE", "--csv", "CSV", "--out", "OUT"],
        kind: Kind::File("svg"),
    },
    Probe {
        name: "plot --out",
        args: &["plot", "CSV", "--out", "OUT"],
        kind: Kind::Dir,
    },
    Probe {
        name: "fmu --out",
        args: &["fmu", "SCENE", "--library", "LIB", "--out", "OUT"],
        kind: Kind::File("fmu"),
    },
    Probe {
        name: "sweep --out",
        args: &[
            "sweep",
            "SCENE",
            "--quick",
            "--t-end",
            "0.05",
            "--repeats",
            "1",
            "--out",
            "OUT",
        ],
        kind: Kind::Dir,
    },
    Probe {
        name: "sweep --vary --out",
        args: &[
            "sweep",
            "SCENE",
            "--vary",
            "bodies[0].mass=[1,2]",
            "--t-end",
            "0.1",
            "--out",
            "OUT",
        ],
        kind: Kind::Dir,
    },
    Probe {
        name: "sweep-merge --out",
        args: &["sweep-merge", "SHARD", "--out", "OUT"],
        kind: Kind::Dir,
    },
    // issue 51: `--json` onto the scene overwrote it
    Probe {
        name: "equilibrium --json",
        args: &["equilibrium", "SCENE", "--json", "OUT"],
        kind: Kind::File("json"),
    },
    Probe {
        name: "linearize --json",
        args: &["linearize", "SCENE", "--json", "OUT"],
        kind: Kind::File("json"),
    },
    Probe {
        name: "linearize --bode",
        args: &[
            "linearize",
            "ISCENE",
            "--json",
            "OTHER.json",
            "--bode",
            "OUT",
        ],
        kind: Kind::File("svg"),
    },
];

/// The kinds of target an output is pointed at.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Target {
    New,
    Existing,
    Symlink,
    Fifo,
    NullDevice,
    FullDevice,
    Directory,
    UnderAFile,
    ReadOnly,
    TheInput,
}

const TARGETS: &[Target] = &[
    Target::New,
    Target::Existing,
    Target::Symlink,
    Target::Fifo,
    Target::NullDevice,
    Target::FullDevice,
    Target::Directory,
    Target::UnderAFile,
    Target::ReadOnly,
    Target::TheInput,
];

const OLD: &[u8] = b"the previous output, to be kept or replaced whole\n";

/// Runs `BIN args` with standard output to `stdout` (a pipe when `None`), killing it after
/// `limit`; `signal` (name, delay) is sent once after the delay. `None` when it hung.
fn run(
    args: &[String],
    stdout: Option<std::fs::File>,
    signal: Option<(&str, Duration)>,
    limit: Duration,
) -> Option<Output> {
    let mut cmd = Command::new(BIN);
    // the signals this test sends act on the child whatever the test inherited
    support::signals::default_signals(&mut cmd)
        .args(args)
        .stdin(Stdio::null())
        .stderr(Stdio::piped());
    let piped = stdout.is_none();
    match stdout {
        Some(f) => cmd.stdout(f),
        None => cmd.stdout(Stdio::piped()),
    };
    let mut child = cmd.spawn().expect("bondmech runs");
    let so = piped.then(|| child.stdout.take().unwrap());
    let mut se = child.stderr.take().unwrap();
    let out_t = std::thread::spawn(move || {
        let mut v = Vec::new();
        if let Some(mut so) = so {
            std::io::Read::read_to_end(&mut so, &mut v).ok();
        }
        v
    });
    let err_t = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut se, &mut v).ok();
        v
    });
    let start = Instant::now();
    let mut sent = false;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(Output {
                status,
                stdout: out_t.join().unwrap(),
                stderr: err_t.join().unwrap(),
            });
        }
        if let Some((sig, after)) = signal {
            if !sent && start.elapsed() >= after {
                let ok = Command::new("kill")
                    .args(["-s", sig, &child.id().to_string()])
                    .status()
                    .unwrap()
                    .success();
                assert!(ok);
                sent = true;
            }
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The checks common to every outcome: no hang, no panic, no abort (a death by `sent` is
/// allowed only if the caller sent it); the problems found, as text.
fn common(o: &Option<Output>, sent: Option<i32>) -> Vec<String> {
    let mut bad = Vec::new();
    let Some(o) = o else {
        return vec!["no answer within 60 s (hang)".into()];
    };
    let err = String::from_utf8_lossy(&o.stderr);
    if o.status.code() == Some(101) || err.contains("panicked") {
        bad.push(format!("panic: {err}"));
    }
    if let Some(s) = o.status.signal() {
        if Some(s) != sent {
            bad.push(format!("killed by signal {s}: {err}"));
        }
    }
    bad
}

/// Whether `bytes` are a complete output of kind `ext`.
fn complete(ext: &str, bytes: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes);
    let ok = match ext {
        // every record as long as the header (RFC 4180 quoting read by the csv crate)
        "csv" => {
            let mut r = csv::ReaderBuilder::new()
                .has_headers(true)
                .flexible(false)
                .from_reader(bytes);
            let n = r.headers().map(|h| h.len()).unwrap_or(0);
            let records: Result<Vec<_>, _> = r.records().collect();
            n > 1 && text.ends_with('\n') && records.is_ok_and(|v| !v.is_empty())
        }
        "json" => serde_json::from_slice::<serde_json::Value>(bytes).is_ok(),
        "svg" => text.trim_end().ends_with("</svg>"),
        "html" => text.trim_end().ends_with("</html>"),
        "dot" => text.trim_start().starts_with("digraph") && text.trim_end().ends_with('}'),
        // a zip ends with its end-of-central-directory record (no comment)
        "fmu" => bytes.len() > 22 && bytes[bytes.len() - 22..].starts_with(b"PK\x05\x06"),
        _ => unreachable!("{ext}"),
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "incomplete {ext} ({} bytes): …{}",
            bytes.len(),
            text.chars()
                .rev()
                .take(80)
                .collect::<String>()
                .chars()
                .rev()
                .collect::<String>()
        ))
    }
}

/// A directory output is complete when it holds at least one file and each is complete by its
/// extension.
fn complete_dir(d: &Path) -> Result<(), String> {
    let mut n = 0;
    for e in std::fs::read_dir(d).map_err(|e| e.to_string())? {
        let p = e.unwrap().path();
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ["csv", "json", "svg"].contains(&ext) {
            complete(ext, &std::fs::read(&p).unwrap())
                .map_err(|e| format!("{}: {e}", p.display()))?;
            n += 1;
        }
    }
    if n == 0 {
        return Err(format!("{}: no output file", d.display()));
    }
    Ok(())
}

/// The inputs the probes read: a copy of the pendulum, the pendulum with an input torque (for
/// a Bode plot), a CSV of it, a sweep shard.
struct Inputs {
    scene: PathBuf,
    iscene: PathBuf,
    csv: PathBuf,
    shard: PathBuf,
    lib: PathBuf,
}

impl Inputs {
    fn make(d: &Path) -> Inputs {
        let scene_path = d.join("pendulum.json");
        std::fs::copy(scene("pendulum.json"), &scene_path).unwrap();
        let iscene = d.join("pendulum_input.json");
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&scene_path).unwrap()).unwrap();
        v["inputs"] = serde_json::json!([{"name": "tau", "start": 0.0}]);
        v["loads"] = serde_json::json!([
            {"name": "motor", "type": "torque", "body": "bar", "value": "tau"}
        ]);
        std::fs::write(&iscene, v.to_string()).unwrap();
        let csv = d.join("pendulum.csv");
        let o = run(
            &strings(&[
                "run",
                scene_path.to_str().unwrap(),
                "--t-end",
                "0.2",
                "--out",
                csv.to_str().unwrap(),
            ]),
            None,
            None,
            Duration::from_secs(60),
        )
        .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let shard = d.join("shard");
        let o = run(
            &strings(&[
                "sweep",
                scene_path.to_str().unwrap(),
                "--vary",
                "bodies[0].mass=[1,2]",
                "--t-end",
                "0.1",
                "--shard",
                "1/1",
                "--out",
                shard.to_str().unwrap(),
            ]),
            None,
            None,
            Duration::from_secs(60),
        )
        .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let exe = PathBuf::from(BIN);
        let lib = [
            exe.parent().unwrap().join("deps/libbondmech_fmu.so"),
            exe.parent().unwrap().join("libbondmech_fmu.so"),
        ]
        .into_iter()
        .find(|p| p.is_file())
        .expect("the FMU library of this build");
        Inputs {
            scene: scene_path,
            iscene,
            csv,
            shard,
            lib,
        }
    }

    /// Every file the inputs hold, with its bytes.
    fn snapshot(&self) -> Vec<(PathBuf, Vec<u8>)> {
        let mut v = vec![
            (self.scene.clone(), std::fs::read(&self.scene).unwrap()),
            (self.iscene.clone(), std::fs::read(&self.iscene).unwrap()),
            (self.csv.clone(), std::fs::read(&self.csv).unwrap()),
        ];
        for e in std::fs::read_dir(&self.shard).unwrap() {
            let p = e.unwrap().path();
            v.push((p.clone(), std::fs::read(&p).unwrap()));
        }
        v
    }
}

fn strings(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

/// Sets up `target` for an output of `kind` in the fresh directory `d`: the path to give, and a
/// FIFO reader thread when there is one.
fn make_target(
    d: &Path,
    target: Target,
    kind: Kind,
    input: &Path,
) -> Option<(PathBuf, Option<std::thread::JoinHandle<Vec<u8>>>)> {
    let ext = match kind {
        Kind::File(e) => e,
        Kind::Dir => "d",
    };
    let p = d.join(format!("out.{ext}"));
    let mut reader = None;
    match target {
        Target::New => {}
        Target::Existing => match kind {
            Kind::File(_) => std::fs::write(&p, OLD).unwrap(),
            Kind::Dir => {
                std::fs::create_dir(&p).unwrap();
                std::fs::write(p.join("notes.txt"), OLD).unwrap();
            }
        },
        Target::Symlink => {
            let real = d.join(format!("real.{ext}"));
            match kind {
                Kind::File(_) => std::fs::write(&real, OLD).unwrap(),
                Kind::Dir => std::fs::create_dir(&real).unwrap(),
            }
            std::os::unix::fs::symlink(&real, &p).unwrap();
        }
        Target::Fifo => {
            let f = fifo(d, &format!("out.{ext}"));
            // the reader opens non-blocking-free: a thread that reads to the end; when the
            // command never opens the FIFO the test opens it for writing to release it
            let q = f.clone();
            reader = Some(std::thread::spawn(move || {
                std::fs::read(&q).unwrap_or_default()
            }));
        }
        Target::NullDevice => {
            char_device(d, &format!("out.{ext}"), 3)?;
        }
        Target::FullDevice => {
            char_device(d, &format!("out.{ext}"), 7)?;
        }
        Target::Directory => {
            if kind == Kind::Dir {
                // a directory is what a directory output wants: give a file there instead
                std::fs::write(&p, OLD).unwrap();
            } else {
                std::fs::create_dir(&p).unwrap();
            }
        }
        Target::UnderAFile => {
            std::fs::write(d.join("plain"), OLD).unwrap();
            return Some((d.join("plain").join(format!("out.{ext}")), None));
        }
        Target::ReadOnly => {
            let ro = d.join("ro");
            std::fs::create_dir(&ro).unwrap();
            let p = ro.join(format!("out.{ext}"));
            match kind {
                Kind::File(_) => std::fs::write(&p, OLD).unwrap(),
                Kind::Dir => std::fs::create_dir(&p).unwrap(),
            }
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o555)).unwrap();
            std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
            return Some((p, None));
        }
        Target::TheInput => return Some((input.to_path_buf(), None)),
    }
    Some((p, reader))
}

/// Releases a FIFO whose reader still waits (the command never opened it).
fn release_fifo(p: &Path, reader: std::thread::JoinHandle<Vec<u8>>) -> Vec<u8> {
    if !reader.is_finished() {
        // opening for writing lets the reader's open return; it then reads end of file
        let _ = std::fs::OpenOptions::new().write(true).open(p);
    }
    reader.join().unwrap()
}

fn check_probe(root: &Path, inputs: &Inputs, probe: &Probe, target: Target) -> Vec<String> {
    let d = root.join(format!(
        "{}-{target:?}",
        probe.name.replace([' ', '-'], "_")
    ));
    std::fs::create_dir_all(&d).unwrap();
    // the command's own input: the scene, or the CSV for `plot`, or a shard's file
    let input = match probe.args[0] {
        "plot" => inputs.csv.clone(),
        "sweep-merge" => inputs.shard.clone(),
        _ if probe.args.contains(&"ISCENE") => inputs.iscene.clone(),
        _ => inputs.scene.clone(),
    };
    let Some((out, reader)) = make_target(&d, target, probe.kind, &input) else {
        return Vec::new(); // a device node needs root
    };
    let before = inputs.snapshot();
    let existed = std::fs::symlink_metadata(&out).ok();
    let old_file = matches!(probe.kind, Kind::File(_))
        && matches!(
            target,
            Target::Existing | Target::Symlink | Target::ReadOnly
        );
    let args: Vec<String> = probe
        .args
        .iter()
        .map(|a| match *a {
            "SCENE" => inputs.scene.display().to_string(),
            "ISCENE" => inputs.iscene.display().to_string(),
            "CSV" => inputs.csv.display().to_string(),
            "SHARD" => inputs.shard.display().to_string(),
            "LIB" => inputs.lib.display().to_string(),
            "OUT" => out.display().to_string(),
            "OTHER.csv" => d.join("other.csv").display().to_string(),
            "OTHER.svg" => d.join("other.svg").display().to_string(),
            "OTHER.json" => d.join("other.json").display().to_string(),
            a => a.to_string(),
        })
        .collect();
    let o = run(&args, None, None, Duration::from_secs(60));
    let mut bad = common(&o, None);
    let streamed = reader.map(|r| release_fifo(&out, r));
    let Some(o) = o else { return bad };
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    println!(
        "{:<26} {:<11} exit {:?}  {}",
        probe.name,
        format!("{target:?}"),
        o.status.code(),
        err.lines()
            .last()
            .unwrap_or("")
            .chars()
            .take(150)
            .collect::<String>()
    );
    // inputs untouched
    for (p, bytes) in &before {
        if std::fs::read(p).ok().as_deref() != Some(bytes.as_slice()) {
            bad.push(format!("input {} changed", p.display()));
        }
    }
    // no harm to what the output named
    match target {
        Target::NullDevice | Target::FullDevice if !is_char_device(&out) => {
            bad.push("the device node was replaced".into())
        }
        Target::Fifo if !std::fs::symlink_metadata(&out).is_ok_and(|m| m.file_type().is_fifo()) => {
            bad.push("the FIFO was replaced".into())
        }
        Target::Symlink
            if !std::fs::symlink_metadata(&out).is_ok_and(|m| m.file_type().is_symlink()) =>
        {
            bad.push("the symbolic link was replaced".into())
        }
        _ => {}
    }
    let temps: Vec<String> = [d.clone(), d.join("ro")]
        .iter()
        .filter(|p| p.is_dir())
        .flat_map(|p| temp_files(p))
        .collect();
    if !temps.is_empty() {
        bad.push(format!("temporary files left: {temps:?}"));
    }
    let real = std::fs::canonicalize(&out).unwrap_or(out.clone());
    if o.status.success() {
        // a failure every kind of command must report
        if matches!(
            target,
            Target::FullDevice | Target::UnderAFile | Target::TheInput | Target::Directory
        ) {
            bad.push(format!("exit 0 onto {target:?}: {err}"));
        }
        match (probe.kind, target) {
            (
                Kind::File(ext),
                Target::New | Target::Existing | Target::Symlink | Target::ReadOnly,
            ) => match std::fs::read(&real) {
                Ok(b) => {
                    if let Err(e) = complete(ext, &b) {
                        bad.push(e)
                    }
                }
                Err(e) => bad.push(format!("no output: {e}")),
            },
            (Kind::File(ext), Target::Fifo) => {
                if let Err(e) = complete(ext, streamed.as_deref().unwrap_or_default()) {
                    bad.push(format!("through the FIFO: {e}"))
                }
            }
            (Kind::Dir, Target::New | Target::Existing | Target::Symlink | Target::ReadOnly) => {
                if let Err(e) = complete_dir(&real) {
                    bad.push(e)
                }
            }
            _ => {}
        }
    } else {
        let code = o.status.code();
        if code != Some(1) && code != Some(2) {
            bad.push(format!("failed with {:?}", o.status));
        }
        let fname = out.file_name().unwrap().to_string_lossy();
        if !err.contains(fname.as_ref()) {
            bad.push(format!("the error does not name {fname}: {err}"));
        }
        // a file, FIFO or device where a directory output is wanted is called what it is
        if probe.kind == Kind::Dir
            && matches!(
                target,
                Target::Directory | Target::Fifo | Target::NullDevice | Target::FullDevice
            )
            && !err.contains("is a file")
        {
            bad.push(format!(
                "a file in place of the directory not said so: {err}"
            ));
        }
        // a file that was there is left whole: as it was, or a complete new output
        if old_file && existed.is_some() {
            let now = std::fs::read(&real).unwrap_or_default();
            let ext = match probe.kind {
                Kind::File(e) => e,
                Kind::Dir => unreachable!(),
            };
            if now != OLD && complete(ext, &now).is_err() {
                bad.push("a failed command left a cut output".into());
            }
        }
        if target == Target::New
            && std::fs::symlink_metadata(&out).is_ok()
            && probe.kind != Kind::Dir
        {
            bad.push("a failed command left a new output behind".into());
        }
    }
    // let the next run clean up a read-only directory
    let _ = std::fs::set_permissions(d.join("ro"), std::fs::Permissions::from_mode(0o755));
    bad.into_iter()
        .map(|b| format!("{} onto {target:?}: {b}", probe.name))
        .collect()
}

#[test]
fn every_command_and_output_flag_onto_every_kind_of_target_loses_nothing() {
    let root = fresh_dir("outprobe", "all");
    let inputs = Inputs::make(&root);
    if !is_root() {
        eprintln!("device-node targets skipped: making a device node with mknod needs root");
    }
    let mut jobs: Vec<(&Probe, Target)> = Vec::new();
    for p in PROBES {
        for &t in TARGETS {
            jobs.push((p, t));
        }
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let problems: Vec<String> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..3)
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                        let Some((p, t)) = jobs.get(i) else { break };
                        mine.extend(check_probe(&root, &inputs, p, *t));
                    }
                    mine
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    assert!(
        problems.is_empty(),
        "{} problems in {} cases:\n{}",
        problems.len(),
        jobs.len(),
        problems.join("\n")
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Issue 51: `linearize --json x.svg --bode x.svg` silently kept one of the two outputs. Every
/// command with two output flags, both given one path (a file that exists, one that does not,
/// and the same file through a symbolic link): refused before any work, naming both flags and
/// the path; the file left as it was (or not made), the inputs unchanged.
#[test]
fn regression_two_outputs_onto_one_path_kept_one_of_them() {
    let root = fresh_dir("outprobe", "twice");
    let inputs = Inputs::make(&root);
    let s = inputs.scene.display().to_string();
    let i = inputs.iscene.display().to_string();
    // (command, its arguments before the outputs, the two flags, the extension)
    let cases: &[(&str, Vec<&str>, [&str; 2], &str)] = &[
        (
            "run",
            vec![&s, "--t-end", "0.2"],
            ["--out", "--summary"],
            "csv",
        ),
        (
            "animate",
            vec![&s, "--t-end", "0.2"],
            ["--out", "--frames"],
            "json",
        ),
        ("linearize", vec![&i], ["--json", "--bode"], "svg"),
    ];
    let mut bad = Vec::new();
    for (k, (cmd, pre, [f1, f2], ext)) in cases.iter().enumerate() {
        for how in ["existing", "new", "link"] {
            let d = root.join(format!("{cmd}-{how}-{k}"));
            std::fs::create_dir_all(&d).unwrap();
            let first = d.join(format!("out.{ext}"));
            let second = match how {
                "existing" => {
                    std::fs::write(&first, OLD).unwrap();
                    first.clone()
                }
                "new" => first.clone(),
                _ => {
                    std::fs::write(&first, OLD).unwrap();
                    let l = d.join(format!("link.{ext}"));
                    std::os::unix::fs::symlink(&first, &l).unwrap();
                    l
                }
            };
            let before = inputs.snapshot();
            let mut args = vec![cmd.to_string()];
            args.extend(pre.iter().map(|a| a.to_string()));
            args.extend([
                f1.to_string(),
                first.display().to_string(),
                f2.to_string(),
                second.display().to_string(),
            ]);
            let o = run(&args, None, None, Duration::from_secs(60)).expect("no hang");
            let err = String::from_utf8_lossy(&o.stderr).into_owned();
            let case = format!("{cmd} {f1} {f2} onto one {how} file");
            if o.status.success() {
                bad.push(format!("{case}: exit 0"));
            }
            if !(err.contains(f1) && err.contains(f2) && err.contains(&format!("out.{ext}"))
                || err.contains(f1) && err.contains(f2) && err.contains(&format!("link.{ext}")))
            {
                bad.push(format!(
                    "{case}: the error names neither both flags nor the file: {err}"
                ));
            }
            match how {
                "new" if first.exists() => bad.push(format!("{case}: the file was made")),
                "existing" | "link" if std::fs::read(&first).unwrap() != OLD => {
                    bad.push(format!("{case}: the file changed"))
                }
                _ => {}
            }
            for (p, b) in &before {
                if std::fs::read(p).ok().as_deref() != Some(b.as_slice()) {
                    bad.push(format!("{case}: input {} changed", p.display()));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let _ = std::fs::remove_dir_all(&root);
}

/// The commands that print to standard output (CSV, tables, text, DOT, JSON), onto a pipe, a
/// regular file and a full device: complete, or a failure naming standard output.
#[test]
fn every_command_printing_to_standard_output_fails_on_a_full_device_and_completes_on_a_file() {
    let root = fresh_dir("outprobe", "stdout");
    let inputs = Inputs::make(&root);
    let s = inputs.scene.display().to_string();
    let commands: Vec<(Vec<String>, Option<&str>)> = vec![
        (strings(&["run", &s, "--t-end", "0.2"]), Some("csv")),
        (strings(&["run", &s, "--t-end", "0.2", "--table"]), None),
        (
            strings(&["run", &s, "--t-end", "0.2", "--out", "-"]),
            Some("csv"),
        ),
        (strings(&["compare", &s, "--t-end", "0.2"]), None),
        (strings(&["graph", &s]), Some("dot")),
        (strings(&["graph", &s, "--causality"]), Some("json")),
        (strings(&["graph", &s, "--as-scene"]), Some("json")),
        (strings(&["equations", &s]), None),
    ];
    let full = char_device(&root, "full", 7);
    if full.is_none() {
        eprintln!("the full-device case skipped: making a device node with mknod needs root");
    }
    let mut bad = Vec::new();
    for (i, (args, ext)) in commands.iter().enumerate() {
        let before = inputs.snapshot();
        // a pipe
        let o = run(args, None, None, Duration::from_secs(60));
        bad.extend(
            common(&o, None)
                .into_iter()
                .map(|b| format!("{args:?} to a pipe: {b}")),
        );
        if let Some(o) = &o {
            let e = String::from_utf8_lossy(&o.stderr);
            let answered =
                o.status.success() || e.contains("standard output") || e.contains("--out");
            if !answered {
                bad.push(format!("{args:?} to a pipe: {:?} {e}", o.status));
            }
            if o.status.success() {
                if let Some(ext) = ext {
                    if let Err(m) = complete(ext, &o.stdout) {
                        bad.push(format!("{args:?} to a pipe: {m}"));
                    }
                }
            }
        }
        // a regular file
        let f = root.join(format!("stdout{i}"));
        let o = run(
            args,
            Some(std::fs::File::create(&f).unwrap()),
            None,
            Duration::from_secs(60),
        );
        bad.extend(
            common(&o, None)
                .into_iter()
                .map(|b| format!("{args:?} to a file: {b}")),
        );
        if let (Some(o), Some(ext)) = (&o, ext) {
            if o.status.success() {
                if let Err(m) = complete(ext, &std::fs::read(&f).unwrap()) {
                    bad.push(format!("{args:?} to a file: {m}"));
                }
            }
        }
        // a full device
        if let Some(full) = &full {
            let dev = std::fs::OpenOptions::new().write(true).open(full).unwrap();
            let o = run(args, Some(dev), None, Duration::from_secs(60));
            bad.extend(
                common(&o, None)
                    .into_iter()
                    .map(|b| format!("{args:?} to a full device: {b}")),
            );
            if let Some(o) = &o {
                let e = String::from_utf8_lossy(&o.stderr);
                if o.status.success() || !e.contains("standard output") {
                    bad.push(format!("{args:?} to a full device: {:?}: {e}", o.status));
                }
            }
            assert!(is_char_device(full));
        }
        for (p, bytes) in &before {
            if std::fs::read(p).ok().as_deref() != Some(bytes.as_slice()) {
                bad.push(format!("{args:?}: input {} changed", p.display()));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let _ = std::fs::remove_dir_all(&root);
}

/// `run`, `sweep` and `serve` signalled with SIGINT or SIGTERM after a delay: `run` keeps a
/// whole CSV and exits 130 / 143; `sweep` keeps the points it finished and exits likewise;
/// `serve` drains and exits 0; none dies by the signal, none leaves a temporary file.
#[test]
fn run_sweep_and_serve_interrupted_keep_whole_outputs_and_exit_by_the_signal_number() {
    let root = fresh_dir("outprobe", "signals");
    let inputs = Inputs::make(&root);
    let s = inputs.scene.display().to_string();
    let mut bad = Vec::new();
    for (sig, code) in [("INT", 130), ("TERM", 143)] {
        // a run to t = 1e5 (hours): stopped after 1 s
        let out = root.join(format!("run-{sig}.csv"));
        let args = strings(&["run", &s, "--t-end", "1e5", "--out", out.to_str().unwrap()]);
        let o = run(
            &args,
            None,
            Some((sig, Duration::from_secs(1))),
            Duration::from_secs(60),
        );
        bad.extend(
            common(&o, None)
                .into_iter()
                .map(|b| format!("run {sig}: {b}")),
        );
        if let Some(o) = &o {
            if o.status.code() != Some(code) {
                bad.push(format!(
                    "run {sig}: {:?} {}",
                    o.status,
                    String::from_utf8_lossy(&o.stderr)
                ));
            }
            match std::fs::read(&out) {
                Ok(b) => {
                    if let Err(e) = complete("csv", &b) {
                        bad.push(format!("run {sig}: {e}"));
                    }
                }
                Err(e) => bad.push(format!("run {sig}: no CSV: {e}")),
            }
        }
        // a sweep of long runs: stopped after 2 s
        let dir = root.join(format!("sweep-{sig}"));
        let args = strings(&[
            "sweep",
            &s,
            "--vary",
            "bodies[0].mass=[1,2,3,4]",
            "--t-end",
            "1e4",
            "--out",
            dir.to_str().unwrap(),
        ]);
        let o = run(
            &args,
            None,
            Some((sig, Duration::from_secs(2))),
            Duration::from_secs(60),
        );
        bad.extend(
            common(&o, None)
                .into_iter()
                .map(|b| format!("sweep {sig}: {b}")),
        );
        if let Some(o) = &o {
            if o.status.code() != Some(code) {
                bad.push(format!(
                    "sweep {sig}: {:?} {}",
                    o.status,
                    String::from_utf8_lossy(&o.stderr)
                ));
            }
            if dir.is_dir() {
                if let Err(e) = complete_dir(&dir) {
                    bad.push(format!("sweep {sig}: {e}"));
                }
                if !temp_files(&dir).is_empty() {
                    bad.push(format!(
                        "sweep {sig}: temporary files {:?}",
                        temp_files(&dir)
                    ));
                }
            }
        }
        if !temp_files(&root).is_empty() {
            bad.push(format!("{sig}: temporary files {:?}", temp_files(&root)));
        }
        // the server drains and exits 0
        let args = strings(&["serve", "--addr", "127.0.0.1:0"]);
        let o = run(
            &args,
            None,
            Some((sig, Duration::from_millis(700))),
            Duration::from_secs(60),
        );
        bad.extend(
            common(&o, None)
                .into_iter()
                .map(|b| format!("serve {sig}: {b}")),
        );
        if let Some(o) = &o {
            if !o.status.success() {
                bad.push(format!(
                    "serve {sig}: {:?} {}",
                    o.status,
                    String::from_utf8_lossy(&o.stderr)
                ));
            }
        }
    }
    for (p, bytes) in &inputs.snapshot() {
        assert_eq!(&std::fs::read(p).unwrap(), bytes, "{}", p.display());
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let _ = std::fs::remove_dir_all(&root);
}
