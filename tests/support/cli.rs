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
