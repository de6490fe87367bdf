//! Accuracy over a long horizon: the point-mass pendulum (1 m massless link, 1 kg, released
//! horizontal) against the exact elliptic solution θ(t) = 2 arcsin(k sn(K + ω₀t, k²))
//! (`tests/common/elliptic.rs`, the AGM, independent of bondmech), over hundreds of periods at
//! the scene's rtol 1e-9. The benchmarks of this kind (IFToMM) ask 1e-3 m over the whole run;
//! the full 2000 s (845 periods) and the other formulations are measured by
//! `cargo bench --bench long_horizon` (README table).

mod common;

use bondmech::{FormulationKind, Model, Scene};
use common::elliptic::{pendulum_angle, pendulum_period};

const G: f64 = 9.81;

fn model() -> Model {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/pendulum_point_mass.json"
    );
    let json = std::fs::read_to_string(path).expect("scene file");
    Model::new(&Scene::from_json_str(&json).expect("scene is valid")).expect("model builds")
}

/// Largest distance of the bob from the exact solution over `times`.
fn bob_error(s: &bondmech::Solution) -> f64 {
    let amplitude = std::f64::consts::FRAC_PI_2;
    s.times
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let th = pendulum_angle(1.0, G, amplitude, t);
            let (x, y) = (s.value(k, "bob.x").unwrap(), s.value(k, "bob.y").unwrap());
            (x - th.sin()).hypot(y + th.cos())
        })
        .fold(0.0, f64::max)
}

/// 300 periods (710 s) with the partitioned formulation at rtol 1e-9: the bob stays within
/// 1e-4 m of the exact solution at every output (a tenth of the IFToMM 1e-3 over less than
/// the 2000 s, whose figure the bench measures), and returns to the release point after each
/// period of the exact period.
#[test]
fn partitioned_pendulum_follows_exact_elliptic_solution_over_300_periods() {
    let m = model();
    let period = pendulum_period(1.0, G, std::f64::consts::FRAC_PI_2);
    let n = 300;
    let mut times: Vec<f64> = (0..=n).map(|i| i as f64 * period).collect();
    // and points between the returns, where the bob moves fastest
    times.extend((0..n).map(|i| (i as f64 + 0.37) * period));
    times.sort_by(f64::total_cmp);
    let mut o = m.default_options();
    o.formulation = FormulationKind::Partitioned;
    o.rtol = 1e-9;
    o.atol = 1e-11;
    o.output_times = times;
    o.max_steps = Some(10_000_000);
    let s = m.solve(&o).expect("solves");
    let err = bob_error(&s);
    let sm = &s.summary;
    eprintln!(
        "partitioned, {n} periods: max error {err:.3e} m, {} steps, {} rhs, integrator {}, CPU {:.3} s, drift {:.2e}",
        sm.steps,
        sm.residual_evals,
        sm.integrator,
        sm.cpu_seconds,
        sm.energy_drift.unwrap_or(f64::NAN)
    );
    assert!(err < 1e-4, "the bob is {err:e} m off the exact solution");
    assert_eq!(
        sm.integrator, "erk",
        "the stiffness test picks explicit Runge–Kutta"
    );
    // one bob, one pin: the same partition throughout, no singular passage
    assert_eq!(sm.partition_rechoices, 0, "{sm:?}");
    assert!(sm.singular_passages.is_empty(), "{sm:?}");
    // the work: Verner 6(5) at rtol 1e-9 (measured 113 steps per period); a band against
    // regressions of the step control
    let per_period = sm.steps as f64 / n as f64;
    assert!(
        (50.0..250.0).contains(&per_period),
        "{per_period} steps per period"
    );
}

/// The default formulation (`dae`: the index-1 DAE on IDA) over the IFToMM A01 horizon
/// (2000 s, 845 periods) at rtol 1e-9, against the exact solution at 4001 outputs, with the
/// energy invariant's policy `policy` (`None`: the default, `auto`).
/// Returns the largest error, the summary and the energy at the end minus the start's.
fn default_over_2000_s(policy: Option<bool>) -> (f64, bondmech::Summary, f64) {
    let m = model();
    let mut o = m.default_options();
    o.rtol = 1e-9;
    o.atol = 1e-11;
    o.output_times = (0..=4000).map(|i| 0.5 * i as f64).collect();
    o.max_steps = Some(10_000_000);
    o.energy_invariant = policy;
    let s = m.solve(&o).expect("solves");
    let err = bob_error(&s);
    let sm = s.summary.clone();
    let e = s.column("energy").expect("energy column");
    let de = e[e.len() - 1] - e[0];
    eprintln!(
        "default ({}, invariant {}), 2000 s: max error {err:.3e} m, {} steps, {} Newton failures, {} error test failures, CPU {:.3} s, drift {:.2e}",
        sm.formulation,
        sm.energy_invariant,
        sm.steps,
        sm.nonlinear_conv_failures,
        sm.error_test_failures,
        sm.cpu_seconds,
        sm.energy_drift.unwrap_or(f64::NAN)
    );
    (err, sm, de)
}

/// Issue 34's target (IFToMM A01: 1e-3 m over 2000 s at rtol 1e-9) on the default: a tenth
/// into the run the energy's drift, projected to the end, exceeds 300 × what the tolerances
/// promise; the default gives the energy lost back (scaling the velocities) and keeps it from
/// there on as an invariant (`E = E₀` with its multiplier, `dae::EnergyInvariant`), and the
/// bob stays on the exact solution (measured: switched at t = 200.35 s, 1.2e-4 m at worst —
/// the phase lost before the switch —, 0.78 M steps; without it 1.35e-2 m).
#[test]
fn default_follows_the_a01_pendulum_over_2000_s_within_1e_3() {
    let (err, sm, e) = default_over_2000_s(None);
    assert_eq!(
        (sm.formulation.as_str(), sm.solver.as_str()),
        ("dae", "IDA")
    );
    assert!(sm.completed);
    assert!(sm.energy_invariant, "{sm:?}");
    assert!(
        sm.warnings
            .iter()
            .any(|w| w.contains("the energy is kept as an invariant from t =")),
        "{:?}",
        sm.warnings
    );
    // the energy the invariant keeps is the start's (the drift before the switch given back)
    assert!(e.abs() < 1e-7, "energy at the end {e:e} J off the start's");
    assert!(sm.nonlinear_conv_failures < 2_000, "{sm:?}");
    assert!(err < 1e-3, "the bob is {err:e} m off the exact solution");
}

/// Why the invariant: without it (`energy_invariant: never`) BDF's local errors on this
/// undamped oscillation go into its energy (+1.3e-5 J over the run, linear in t), the energy
/// sets the period of the nonlinear pendulum, and a period that drifts linearly puts the bob
/// off by a phase that grows quadratically (measured 1.35e-2 m; the period's sensitivity at
/// the 90° release, d ln T / dE = 0.0233 /J). CVODE's BDF on the partitioned ODE does the same
/// (1.8e-3 m).
#[test]
fn without_the_energy_invariant_bdf_drifts_off_the_a01_pendulum() {
    let (err, sm, _) = default_over_2000_s(Some(false));
    assert!(!sm.energy_invariant, "{sm:?}");
    assert!(sm.completed);
    assert!(
        err > 1e-3,
        "the bob is {err:e} m off the exact solution: BDF no longer drifts?"
    );
}
