//! `bondmech sweep --quick` on the double pendulum: files written, and the measured errors behave
//! as the numerical analysis says (error falls with the tolerance for GGL, and as 1/k for the
//! decoupled twin), with the sweep's GGL reference itself checked against the independent
//! minimal-coordinate model of `tests/common/double_pendulum.rs`.

mod common;

use std::process::Command;

use bondmech::report::sweep::{solution_error, SweepConfig};
use bondmech::study::sweep::run_sweep;
use bondmech::{FormulationKind, Model, Scene};
use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};

fn model() -> Model {
    let scene = Scene::from_path("scenes/double_pendulum.json").expect("scene loads");
    Model::new(&scene).expect("model builds")
}

#[test]
fn cli_sweep_quick_writes_csv_json_and_svg() {
    let dir = std::env::temp_dir().join(format!("bondmech-sweep-{}", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args(["sweep", "scenes/double_pendulum.json", "--quick", "--out"])
        .arg(&dir)
        .output()
        .expect("bondmech runs");
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let wp = std::fs::read_to_string(dir.join("work_precision.csv")).expect("csv written");
    let mut lines = wp.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("series,formulation,joint_stiffness,rtol"));
    // 3 tolerances × (ggl, index1, decoupled k = 1e6)
    assert_eq!(lines.count(), 9, "{wp}");
    let k = std::fs::read_to_string(dir.join("stiffness.csv")).expect("csv written");
    assert_eq!(k.lines().count(), 1 + 1 + 3, "{k}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(json["work_precision"].as_array().unwrap().len(), 9);
    for svg in ["work_precision.svg", "stiffness.svg"] {
        let s = std::fs::read_to_string(dir.join(svg)).expect("svg written");
        assert!(s.starts_with("<svg") && s.contains("polyline"), "{svg}");
    }
    // not a terminal: no progress bar escape codes on stderr
    assert!(!String::from_utf8_lossy(&out.stderr).contains('\u{1b}'));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_reference_agrees_with_minimal_coordinate_model() {
    // the sweep measures errors against GGL at rtol 1e-11 (quick); that reference must itself be
    // far more accurate than the errors it measures (≥ 1e-7 at rtol 1e-8)
    let m = model();
    let mut o = m.default_options();
    let cfg = SweepConfig::quick();
    o.rtol = cfg.reference_rtol;
    o.atol = cfg.reference_rtol * cfg.atol_per_rtol;
    o.output_times = (0..=10).map(|i| 0.1 * i as f64).collect();
    o.formulation = FormulationKind::Ggl;
    let s = m.solve(&o).unwrap();
    let p = DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let r = simulate_double_pendulum(&p, [0.0; 4], &o.output_times);
    for (k, rk) in r.iter().enumerate() {
        for (col, want) in [
            ("bar1.x", rk.c1[0]),
            ("bar1.y", rk.c1[1]),
            ("bar2.x", rk.c2[0]),
            ("bar2.y", rk.c2[1]),
            ("bar2.angle", rk.theta2),
        ] {
            let got = s.value(k, col).unwrap();
            assert!((got - want).abs() < 1e-9, "{col} at {k}: {got} vs {want}");
        }
    }
}

#[test]
fn quick_sweep_errors_fall_with_tolerance_and_stiffness() {
    let m = model();
    let cfg = SweepConfig::quick();
    let r = run_sweep(&m, &cfg, &|_| {}).expect("sweep runs");
    let ggl: Vec<_> = r
        .work_precision
        .iter()
        .filter(|w| w.series == "ggl")
        .collect();
    assert_eq!(ggl.len(), 3);
    for w in ggl.windows(2) {
        // two decades of tolerance: at least one decade of error (BDF error ∝ tolerance)
        assert!(
            w[1].error < 0.1 * w[0].error,
            "GGL error {:e} at rtol {:e} vs {:e} at rtol {:e}",
            w[1].error,
            w[1].rtol,
            w[0].error,
            w[0].rtol
        );
    }
    // the decoupled twin: spring stretch = joint force / k, so both the error and the stretch
    // fall as 1/k (two decades per two decades of k) while k × stretch tends to the joint force
    let ks = &r.stiffness;
    assert_eq!(ks.len(), 3);
    for w in ks.windows(2) {
        let (a, b) = (&w[0].run, &w[1].run);
        assert!(
            b.error < 0.03 * a.error,
            "error {:e} -> {:e}",
            a.error,
            b.error
        );
        assert!(
            b.max_constraint_error < 0.03 * a.max_constraint_error,
            "stretch {:e} -> {:e}",
            a.max_constraint_error,
            b.max_constraint_error
        );
        // the fastest mode is a spring–mass oscillation: |λ|max ∝ sqrt(k)
        let ratio = w[1].largest_eigenvalue / w[0].largest_eigenvalue;
        assert!((ratio - 10.0).abs() < 0.5, "eigenvalue ratio {ratio}");
    }
    let f6 = ks[1].run.max_constraint_error * ks[1].run.joint_stiffness;
    let f8 = ks[2].run.max_constraint_error * ks[2].run.joint_stiffness;
    assert!((f6 - f8).abs() < 0.05 * f8, "joint force {f6} vs {f8}");
    let k = r.sufficient_stiffness.expect("k = 1e8 reaches 1e-4");
    assert!(k.joint_stiffness >= 1e6 && k.error <= cfg.accuracy);
}

#[test]
fn solution_error_is_zero_against_itself_and_nan_on_a_short_run() {
    let m = model();
    let mut o = m.default_options();
    o.output_times = vec![0.0, 0.1, 0.2];
    let s = m.solve(&o).unwrap();
    assert_eq!(solution_error(&s, &s), 0.0);
    let mut short = s.clone();
    short.rows.pop();
    assert!(solution_error(&short, &s).is_nan());
    let mut moved = s.clone();
    let c = moved.columns.iter().position(|n| n == "bar2.y").unwrap();
    moved.rows[2][c] += 0.25;
    assert_eq!(solution_error(&moved, &s), 0.25);
}

/// The independent minimal-coordinate double pendulum (tests/common) written as a reference CSV
/// the way a user would hand in a published solution: `t,bar1.x,…` at 0.02 s steps up to 1 s.
fn minimal_reference_csv() -> String {
    let p = DoublePendulum {
        m1: 1.0,
        l1: 1.0,
        m2: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let times: Vec<f64> = (0..=50).map(|i| 0.02 * i as f64).collect();
    let r = simulate_double_pendulum(&p, [0.0; 4], &times);
    let mut csv = String::from("t,bar1.x,bar1.y,bar2.x,bar2.y,bar2.angle\n");
    for (t, s) in times.iter().zip(&r) {
        csv.push_str(&format!(
            "{t:e},{:e},{:e},{:e},{:e},{:e}\n",
            s.c1[0], s.c1[1], s.c2[0], s.c2[1], s.theta2
        ));
    }
    csv
}

#[test]
fn sweep_measures_errors_against_an_independent_reference_csv() {
    let dir = std::env::temp_dir().join(format!("bondmech-sweep-ref-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ref_path = dir.join("minimal.csv");
    std::fs::write(&ref_path, minimal_reference_csv()).unwrap();

    // library: every run measured against the table, at its 51 times
    let m = model();
    let mut cfg = SweepConfig::quick();
    cfg.stiffness_grid = vec![1e6];
    cfg.decoupled_stiffnesses = vec![1e6];
    cfg.reference = Some(bondmech::report::ExternalReference {
        source: ref_path.display().to_string(),
        solution: bondmech::report::reference::reference_from_csv(&ref_path).unwrap(),
    });
    let r = run_sweep(&m, &cfg, &|_| {}).expect("sweep runs");
    assert_eq!(r.reference_source, ref_path.display().to_string());
    // the tight GGL run agrees with the hand-derived model (rtol 1e-11, positions to 1e-8)
    assert!(
        r.reference.error < 1e-8,
        "GGL vs minimal: {:e}",
        r.reference.error
    );
    let ggl: Vec<_> = r
        .work_precision
        .iter()
        .filter(|w| w.series == "ggl")
        .collect();
    // errors now measure distance to the independent model: they fall with the tolerance
    // and stay above the tight run's own error
    assert!(
        ggl[0].error > ggl[2].error && ggl[2].error < 1e-6,
        "{ggl:?}"
    );
    // the decoupled twin at k = 1e6 cannot beat its spring stretch (∝ 1/k ≈ 1e-5 m)
    let twin = &r.stiffness[0].run;
    assert!(
        twin.error > 1e-7 && twin.error < 1e-3,
        "twin error {:e}",
        twin.error
    );

    // CLI: the flag, and the report names the file
    let out = Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args([
            "sweep",
            "scenes/double_pendulum.json",
            "--quick",
            "--reference",
        ])
        .arg(&ref_path)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .expect("bondmech runs");
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("minimal.csv"), "{table}");

    // a reference that shares no column with the scene is refused, naming the file
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "t,foo.x\n0,1\n0.5,1\n1,1\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args([
            "sweep",
            "scenes/double_pendulum.json",
            "--quick",
            "--reference",
        ])
        .arg(&bad)
        .arg("--out")
        .arg(dir.join("out2"))
        .output()
        .expect("bondmech runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.csv") && err.contains("shares no position"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
