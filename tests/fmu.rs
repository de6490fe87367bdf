//! `bondmech fmu` checked by an independent importer, FMPy (issue 28): each test runs one
//! check of `tests/fmu_fmpy.py`, which exports FMUs with the CLI, simulates them with FMPy and
//! compares with `bondmech run`.
//!
//! Needs `python3` with FMPy (`pip install fmpy`; `.ci/run` installs it). The FMU's shared
//! library is the `bondmech-fmu` crate's, which cargo builds for these tests (a
//! dev-dependency). Without FMPy the tests say so and pass, except in CI (`CI` set), where
//! they fail.

use std::path::{Path, PathBuf};
use std::process::Command;

fn fmpy_available() -> bool {
    Command::new("python3")
        .args(["-c", "import fmpy, numpy"])
        .output()
        .is_ok_and(|o| o.status.success())
}

fn check(name: &str) {
    let exe = PathBuf::from(env!("CARGO_BIN_EXE_bondmech"));
    if !fmpy_available() {
        if std::env::var_os("CI").is_some() {
            panic!(
                "FMPy is missing (python3 -c 'import fmpy'): CI must install it (pip install fmpy)"
            );
        }
        eprintln!("skipped: python3 with FMPy is not installed (pip install fmpy)");
        return;
    }
    // the library of this build: bondmech-fmu is a dev-dependency, so cargo has just built
    // it in deps/ (target/debug/libbondmech_fmu.so is `cargo build`'s, possibly older)
    let lib = exe.parent().unwrap().join("deps/libbondmech_fmu.so");
    assert!(lib.is_file(), "{} is missing", lib.display());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fmu_fmpy.py");
    let out = Command::new("python3")
        .env("BONDMECH_FMU_LIBRARY", &lib)
        .arg(&script)
        .arg(name)
        .arg(&exe)
        .output()
        .expect("python3 runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "check {name} failed:\n{stdout}\n{stderr}"
    );
}

/// `fmpy.validate_fmu` finds no problem in the FMI 2.0 and 3.0 export of every bundled scene,
/// the archive holds the files at the standard's places, and each FMU runs two steps.
#[test]
fn every_bundled_scene_exports_a_valid_fmi2_and_fmi3_fmu() {
    check("validate");
}

/// FMPy's simulation of the double pendulum and the slider-crank (communication step 1e-2 s)
/// equals `bondmech run` at the same output times to 1e-9 relative (measured: 0).
#[test]
fn fmpy_simulation_equals_bondmech_run() {
    check("run");
}

/// A torque input stepped by FMPy equals the CLI run with the torque as a step expression of
/// t to 1e-8.
#[test]
fn stepped_input_equals_a_step_expression_of_t() {
    check("input");
}

/// A driver's speed given as an input and stepped by FMPy: the crank angle is the integral of
/// the steps (closed form) to 1e-8 rad.
#[test]
fn a_driver_speed_input_stepped_by_the_importer_turns_the_crank_by_its_integral() {
    check("driver_input");
}

/// `bodies[bar2].mass` set through the FMU equals `run --set`.
#[test]
fn parameter_set_through_the_fmu_equals_run_set() {
    check("parameter");
}

/// Two instances in one process at once give the results of each alone.
#[test]
fn two_instances_in_one_process_equal_each_alone() {
    check("instances");
}

/// A failing solve returns an error status with a logged message naming the element and the
/// time, and the importer goes on.
#[test]
fn failing_solve_is_an_error_status_and_the_importer_goes_on() {
    check("failure");
}

/// A restored (and a deserialised) FMU state continues as the instance did.
#[test]
fn fmu_state_restored_and_deserialised_continues_the_same() {
    check("state");
}
