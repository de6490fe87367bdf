//! Index 1 must re-choose its dependent velocities when the chosen block of `G_v` degrades.
//! A bead slides freely along a pendulum bar (prismatic joint on the bar): the bead translation
//! that carries the slider's perpendicular row has coefficient cos θ (or sin θ), so as the bar
//! swings through the vertical the initial choice (the bead's vertical velocity) loses its grip.
//! Reference: the hand-derived 2-DOF Lagrange model in (θ, s), integrated by the tests' own
//! Dormand–Prince integrator.

mod common;

use bondmech::{FormulationKind, Model, Scene, SolveOptions};
use common::integrate::integrate;
use common::{REFERENCE_ATOL, REFERENCE_RTOL};

const G: f64 = 9.81;
const M_BAR: f64 = 1.0;
const L: f64 = 1.0;
const M_BEAD: f64 = 0.5;
const I_BEAD: f64 = 0.01;
const S0: f64 = 0.25;

fn scene() -> String {
    format!(
        r#"{{"name":"bead_on_pendulum","dimension":2,"gravity":[0,-{G}],
        "bodies":[
          {{"name":"bar","mass":{M_BAR},"inertia":{jb},"points":{{"O":[-0.5,0],"A":[0.5,0]}},"position":[0.5,0],"angle":0}},
          {{"name":"bead","mass":{M_BEAD},"inertia":{I_BEAD},"position":[{S0},0],"angle":0}}],
        "joints":[
          {{"name":"pivot","type":"revolute","bodies":["ground","bar"],"points":[[0,0],"O"]}},
          {{"name":"slide","type":"prismatic","bodies":["bar","bead"],"points":[[0,0],[0,0]],"axis":[1,0]}}],
        "solve":{{"formulation":"index1","t_end":1.0,"output_step":0.01,"rtol":1e-9,"atol":1e-11}}}}"#,
        jb = M_BAR * L * L / 12.0
    )
}

/// θ, s of the Lagrangian T = ½(J_O + I_b + m_b s²)θ̇² + ½ m_b ṡ², V = g (m L/2 + m_b s) sin θ:
/// m_b s̈ = m_b s θ̇² − m_b g sin θ,
/// (J_O + I_b + m_b s²) θ̈ = −2 m_b s ṡ θ̇ − g (m L/2 + m_b s) cos θ.
fn reference(times: &[f64]) -> Vec<Vec<f64>> {
    let jo = M_BAR * L * L / 3.0;
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        let (th, s, w, u) = (y[0], y[1], y[2], y[3]);
        dy[0] = w;
        dy[1] = u;
        dy[2] = (-2.0 * M_BEAD * s * u * w - G * (M_BAR * L / 2.0 + M_BEAD * s) * th.cos())
            / (jo + I_BEAD + M_BEAD * s * s);
        dy[3] = s * w * w - G * th.sin();
    };
    integrate(
        rhs,
        0.0,
        &[0.0, S0, 0.0, 0.0],
        times,
        REFERENCE_RTOL,
        REFERENCE_ATOL,
    )
}

#[test]
fn index1_reselects_dependents_through_the_vertical_and_follows_lagrange() {
    let model = Model::new(&Scene::from_json_str(&scene()).unwrap()).unwrap();
    let mut o = model.default_options();
    assert_eq!(o.formulation, FormulationKind::Index1);
    o.output_times = SolveOptions::times(1.0, 0.01);
    let s = model
        .solve(&o)
        .expect("index 1 carries the bead through the vertical");
    let r = reference(&s.times);
    // the bar must actually swing through the vertical (θ = −π/2) in this horizon
    assert!(
        r.iter().any(|y| y[0] < -std::f64::consts::FRAC_PI_2 - 0.2),
        "reference never passes the vertical: {:?}",
        r.iter().map(|y| y[0]).fold(0.0f64, f64::min)
    );
    assert!(
        s.summary.index1_reselections >= 1,
        "no re-selection: {:?}",
        s.summary
    );
    assert!(
        s.summary.warnings.iter().any(|w| w.contains("re-selected")),
        "{:?}",
        s.summary.warnings
    );
    for (k, rk) in r.iter().enumerate() {
        let th = s.value(k, "bar.angle").unwrap();
        let (bx, by) = (s.value(k, "bead.x").unwrap(), s.value(k, "bead.y").unwrap());
        assert!(
            (th - rk[0]).abs() < 1e-6,
            "θ at t = {}: {th} vs {}",
            s.times[k],
            rk[0]
        );
        let (ex, ey) = (rk[1] * rk[0].cos(), rk[1] * rk[0].sin());
        assert!(
            (bx - ex).hypot(by - ey) < 1e-6,
            "bead at t = {}: ({bx}, {by}) vs ({ex}, {ey})",
            s.times[k]
        );
    }
    eprintln!("{:?}", s.summary.warnings);
}

/// Re-selections are routine: the first three are listed in the warnings, one line counts the
/// rest, and the summary's counter has every one. Regression (issue 46, F5): a correct 100 s
/// run of a bead through its bar's pivot printed 205 warning lines, one per re-selection.
#[test]
fn regression_every_routine_reselection_was_a_warning_line() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bead_slot_through_pivot.json"
    );
    let json = std::fs::read_to_string(path).expect("scene file");
    let model = Model::new(&Scene::from_json_str(&json).expect("valid")).expect("builds");
    let mut o = model.default_options();
    o.output_times = (0..=1000).map(|k| k as f64 * 0.02).collect();
    let s = model.solve(&o).expect("solves").summary;
    let listed = s
        .warnings
        .iter()
        .filter(|w| w.contains("re-selected at t = "))
        .count() as u64;
    let more: u64 = s
        .warnings
        .iter()
        .find_map(|w| {
            let (_, rest) = w.split_once("re-selected: ")?;
            rest.split_whitespace().next()?.parse().ok()
        })
        .unwrap_or(0);
    eprintln!(
        "{} re-selections: {listed} listed, {more} counted; warnings {:?}",
        s.index1_reselections, s.warnings
    );
    assert!(s.index1_reselections > 10, "{s:?}");
    assert_eq!(listed, 3, "{:?}", s.warnings);
    assert_eq!(listed + more, s.index1_reselections, "{:?}", s.warnings);
    assert!(s.warnings.len() <= 6, "{:?}", s.warnings);
}
