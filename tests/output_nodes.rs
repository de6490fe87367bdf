//! Issue 38, "never harm the machine": an output that is not a regular file (a device node, a
//! FIFO) is written in place and never renamed over; a write error (a full device) fails the
//! command naming the file and leaves no temporary file; `fmu --out` never replaces its scene.
//! Every special file is made in the test's own directory (`mknod`, `mkfifo`), never `/dev`.

mod support;

use std::path::PathBuf;

use support::cli::{bondmech, scene, temp_files};
use support::nodes::{char_device, fifo, is_char_device, is_root};

/// A fresh directory for one test.
fn dir(name: &str) -> PathBuf {
    support::cli::fresh_dir("nodes", name)
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn regression_out_onto_a_device_node_replaced_it_with_a_regular_file() {
    if !is_root() {
        eprintln!("skipped: making a device node with mknod needs root");
        return;
    }
    let d = dir("device");
    let null = char_device(&d, "null", 3).expect("mknod as root");
    let full = char_device(&d, "full", 7).expect("mknod as root");
    // `animate` takes its format from the extension
    let full_svg = char_device(&d, "full.svg", 7).expect("mknod as root");
    // --out and --summary onto a null device: the run succeeds and the node stays a device
    let o = bondmech(&[
        "run",
        &scene("pendulum.json"),
        "--out",
        null.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(is_char_device(&null), "--out replaced the device node");
    let o = bondmech(&[
        "run",
        &scene("pendulum.json"),
        "--summary",
        null.to_str().unwrap(),
        "--out",
        d.join("o.csv").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(is_char_device(&null), "--summary replaced the device node");
    // the bytes go through the device: onto a full device every output flag fails with the
    // OS's "no space" and the node stays a device (a rename over it would have succeeded)
    for args in [
        vec!["run", "PENDULUM", "--out", "FULL"],
        vec!["run", "PENDULUM", "--summary", "FULL", "--out", "OTHER"],
        vec!["graph", "PENDULUM", "--out", "FULL"],
        vec!["animate", "PENDULUM", "--out", "FULL_SVG"],
    ] {
        let pendulum = scene("pendulum.json");
        let other = d.join("other.csv");
        let args: Vec<&str> = args
            .iter()
            .map(|a| match *a {
                "PENDULUM" => pendulum.as_str(),
                "FULL" => full.to_str().unwrap(),
                "FULL_SVG" => full_svg.to_str().unwrap(),
                "OTHER" => other.to_str().unwrap(),
                a => a,
            })
            .collect();
        let o = bondmech(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.contains("full") && e.contains("os error 28"),
            "{args:?}: {e}"
        );
        assert!(
            is_char_device(&full) && is_char_device(&full_svg),
            "{args:?} replaced the device node"
        );
        assert!(temp_files(&d).is_empty(), "{args:?}: {:?}", temp_files(&d));
    }
}

#[test]
fn out_onto_a_fifo_streams_the_same_bytes_to_its_reader() {
    let d = dir("fifo");
    let pipe = fifo(&d, "rows");
    let q = pipe.clone();
    let reader = std::thread::spawn(move || std::fs::read(&q).unwrap());
    let o = bondmech(&[
        "run",
        &scene("pendulum.json"),
        "--out",
        pipe.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let streamed = reader.join().unwrap();
    let file = d.join("o.csv");
    let o = bondmech(&[
        "run",
        &scene("pendulum.json"),
        "--out",
        file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let written = std::fs::read(&file).unwrap();
    assert!(written.len() > 1000);
    assert_eq!(streamed, written, "the FIFO's reader got the file's bytes");
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&pipe).unwrap().file_type().is_fifo());
    assert!(temp_files(&d).is_empty());
}

#[test]
fn regression_fmu_out_overwrote_the_scene_it_was_given() {
    let d = dir("fmu");
    let s = d.join("s.json");
    let text = std::fs::read_to_string(scene("pendulum.json")).unwrap();
    std::fs::write(&s, &text).unwrap();
    let link = d.join("link.json");
    std::os::unix::fs::symlink(&s, &link).unwrap();
    for out in [&s, &link] {
        let o = bondmech(&["fmu", s.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{e}");
        assert!(e.contains("--out") && e.contains("is an input"), "{e}");
        assert_eq!(
            std::fs::read_to_string(&s).unwrap(),
            text,
            "the scene is intact"
        );
    }
}
