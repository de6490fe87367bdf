//! Running the `bondmech` binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `bondmech ARGS…` and returns its output.
pub fn bondmech(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args(args)
        .output()
        .expect("bondmech runs")
}

/// A path `name` in a temporary folder of this test process.
pub fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bondmech-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The path of a bundled scene.
pub fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

/// `(header, rows)` of a CSV file written by `bondmech run` (a header line of column names,
/// then one line of numbers per output time).
pub fn read_csv(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// A fresh, empty directory `bondmech-<prefix>-<pid>-<name>` for one test.
pub fn fresh_dir(prefix: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bondmech-{prefix}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The names in `d` that look like an output's temporary file (`.NAME.XXXXXX.tmp`).
pub fn temp_files(d: &Path) -> Vec<String> {
    std::fs::read_dir(d)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && n.ends_with(".tmp"))
        .collect()
}
