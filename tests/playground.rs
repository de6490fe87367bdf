//! The playground (`GET /` of `bondmech serve`, issue 37) in a real browser: runs
//! `tests/playground_browser.py`, which starts `bondmech serve` on a free port and drives
//! headless Chromium through the page with Selenium — pick a scene, run, scrub, compare, a
//! spatial scene, a raw bond graph, a scene that fails to solve, a bad scene's problems, a
//! cancelled long run, a scene whose name is markup — and checks that no request leaves the
//! origin and the console stays clean. Its screenshots go to `target/tmp/playground/` (a test
//! run leaves the source tree alone); with `BONDMECH_PLAYGROUND_SCREENSHOTS=docs/playground`
//! they refresh the ones in the docs.
//!
//! Needs Debian's `chromium` and `chromium-driver` and `python3` with `selenium` (PyPI);
//! `.ci/run` installs them. Without them the test says so and passes locally, and fails under
//! CI (`CI` set), as `tests/fmu.rs` does.

use std::path::{Path, PathBuf};
use std::process::Command;

fn found(cmd: &str, args: &[&str]) -> bool {
    Command::new(cmd)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

/// What is missing to run the browser test, if anything.
fn missing() -> Vec<&'static str> {
    let mut m = Vec::new();
    if !found("chromium", &["--version"]) && !found("chromium-browser", &["--version"]) {
        m.push("chromium (apt-get install chromium)");
    }
    if !Path::new("/usr/bin/chromedriver").exists() && !found("chromedriver", &["--version"]) {
        m.push("chromedriver (apt-get install chromium-driver)");
    }
    if !found("python3", &["-c", "import selenium"]) {
        m.push("selenium for python3 (pip install selenium)");
    }
    m
}

#[test]
fn the_playground_works_in_a_real_browser() {
    let missing = missing();
    if !missing.is_empty() {
        if std::env::var_os("CI").is_some() {
            panic!(
                "the browser test needs {}: CI must install them (.ci/run)",
                missing.join(", ")
            );
        }
        eprintln!("skipped: {} not installed", missing.join(", "));
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = PathBuf::from(env!("CARGO_BIN_EXE_bondmech"));
    let out = Command::new("python3")
        .arg(root.join("tests/playground_browser.py"))
        .arg(&exe)
        .arg(match std::env::var_os("BONDMECH_PLAYGROUND_SCREENSHOTS") {
            Some(dir) => root.join(dir),
            None => Path::new(env!("CARGO_TARGET_TMPDIR")).join("playground"),
        })
        .output()
        .expect("python3 runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "the playground's browser test failed:\n{stdout}\n{stderr}"
    );
    assert!(stdout.contains("all playground checks passed"), "{stdout}");
}
