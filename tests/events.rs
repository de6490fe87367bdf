//! Scene events (`"events"`): zero crossings of an expression of `t` and the output columns,
//! located by SUNDIALS root finding on every formulation; rows at the event times, the list in
//! `summary.events`, `stop` ending the run there. The reference times are exact: the period of
//! a pendulum of amplitude π/2 from the complete elliptic integral (`tests/common/elliptic.rs`).

mod common;

use bondmech::{FormulationKind, Model, Scene, Solution};
use common::elliptic::pendulum_period;
use serde_json::{json, Value};

const G: f64 = 9.81;

/// A uniform bar (mass `m`, length `l`) pinned at its end to the ground, released horizontal at
/// rest: a compound pendulum of amplitude π/2 and equivalent length J_O/(m L/2) = 2L/3.
fn bar(m: f64, l: f64, events: Value, t_end: f64) -> Value {
    json!({
        "dimension": 2, "gravity": [0.0, -G],
        "bodies": [{ "name": "bar", "mass": m, "inertia": m * l * l / 12.0,
                     "points": { "O": [-l / 2.0, 0.0] }, "position": [l / 2.0, 0.0] }],
        "joints": [{ "name": "pivot", "type": "revolute",
                     "bodies": ["ground", "bar"], "points": [[0.0, 0.0], "O"] }],
        "solve": { "t_end": t_end, "output_step": 0.05 },
        "events": events
    })
}

fn period(l: f64) -> f64 {
    pendulum_period(2.0 * l / 3.0, G, std::f64::consts::FRAC_PI_2)
}

fn solve(scene: &Value, f: FormulationKind, rtol: f64) -> Solution {
    let scene = Scene::from_json_str(&scene.to_string()).unwrap();
    let model = Model::new(&scene).unwrap();
    let mut o = model.default_options();
    o.formulation = f;
    o.rtol = rtol;
    o.atol = rtol * 1e-2;
    model.solve(&o).unwrap()
}

/// The bar's centre passes below the pivot (`bar.x` falls through 0) at exactly a quarter of
/// the elliptic period; the `stop` event ends the run there, its row last.
#[test]
fn pendulum_released_horizontal_reaches_the_vertical_at_a_quarter_period() {
    let (m, l) = (1.0, 1.2);
    let quarter = period(l) / 4.0;
    let events =
        json!([{ "name": "vertical", "when": "bar.x", "direction": "falling", "action": "stop" }]);
    let scene = bar(m, l, events, 3.0);
    for f in [
        FormulationKind::Ggl,
        FormulationKind::CompliantGgl,
        FormulationKind::Index1,
    ] {
        let sol = solve(&scene, f, 1e-12);
        let ev = &sol.summary.events;
        assert_eq!(ev.len(), 1, "{f:?}: {ev:?}");
        assert_eq!(ev[0].name, "vertical");
        let rel = (ev[0].t - quarter).abs() / quarter;
        eprintln!(
            "{f:?}: event at {} s, T/4 = {quarter} s, relative error {rel:.1e}",
            ev[0].t
        );
        assert!(rel < 1e-9, "{f:?}: {} against {quarter}: {rel:e}", ev[0].t);
        // the event row is the last row, at the event time, with the bar vertical
        assert_eq!(*sol.times.last().unwrap(), ev[0].t, "{f:?}");
        // a stop event ends the run successfully: completed, at the event time
        assert!(
            sol.summary.completed && sol.summary.stopped_by.is_none(),
            "{f:?}"
        );
        assert_eq!(sol.summary.t_reached, ev[0].t, "{f:?}");
        let k = sol.rows.len() - 1;
        assert!(sol.value(k, "bar.x").unwrap().abs() < 1e-9, "{f:?}");
        // the output rows before it were kept: every multiple of 0.05 below T/4
        assert_eq!(
            sol.rows.len(),
            (quarter / 0.05).floor() as usize + 2,
            "{f:?}"
        );
    }
    // the decoupled twin finds it too (its pin stretches by about m g / k, hence the looser bound)
    let sol = solve(&scene, FormulationKind::Decoupled, 1e-10);
    let t = sol.summary.events[0].t;
    assert!(
        (t - quarter).abs() < 1e-5 * quarter,
        "twin: {t} against {quarter}"
    );
}

/// `record` events add rows and let the run go on; the direction picks the crossings: `bar.x`
/// falls through 0 at T/4, 5T/4, … and rises at 3T/4, 7T/4, … .
#[test]
fn record_events_follow_their_direction_and_add_rows() {
    let (m, l) = (0.8, 1.0);
    let t_period = period(l);
    let events = json!([
        { "name": "down", "when": "bar.x", "direction": "falling", "action": "record" },
        { "name": "up", "when": "bar.x", "direction": "rising" },
        { "name": "any", "when": "bar.x", "direction": "both" }
    ]);
    let t_end = 2.0 * t_period;
    let scene = bar(m, l, events, t_end);
    let plain = solve(&bar(m, l, json!([]), t_end), FormulationKind::Ggl, 1e-11);
    for f in [FormulationKind::Ggl, FormulationKind::Index1] {
        let sol = solve(&scene, f, 1e-11);
        let times = |name: &str| -> Vec<f64> {
            sol.summary
                .events
                .iter()
                .filter(|e| e.name == name)
                .map(|e| e.t)
                .collect()
        };
        let check = |name: &str, fractions: &[f64]| {
            let got = times(name);
            assert_eq!(got.len(), fractions.len(), "{f:?} {name}: {got:?}");
            for (t, q) in got.iter().zip(fractions) {
                assert!(
                    (t - q * t_period).abs() < 1e-8 * t_period,
                    "{f:?} {name}: {t} against {}",
                    q * t_period
                );
            }
        };
        check("down", &[0.25, 1.25]);
        check("up", &[0.75, 1.75]);
        check("any", &[0.25, 0.75, 1.25, 1.75]);
        // the run went to the end; each crossing got one row (the three events at one time
        // share it), inserted in time order between the output rows
        assert!((sol.times.last().unwrap() - t_end).abs() < 1e-12);
        assert_eq!(sol.rows.len(), plain.rows.len() + 4, "{f:?}");
        assert!(sol.times.windows(2).all(|w| w[0] <= w[1]), "{f:?}");
        for t in times("any") {
            let k = sol.times.iter().position(|&x| x == t).unwrap();
            assert!(sol.value(k, "bar.x").unwrap().abs() < 1e-8);
        }
    }
}

/// An event may watch a joint force: the pin force of the falling bar rises from m g/4 at
/// release to 2.5 m g at the vertical (tests/reactions.rs derives both), so it passes 2 m g on
/// the way down, where (energy) ω² = 3g sinφ / L and (moment about O) α = 3g cos φ/(2L) with φ
/// the angle below the horizontal; radial balance gives F_r = m g sin φ + m (L/2) ω² = 2.5 m g sin φ
/// and tangential F_t = m g cos φ − m (L/2) α = m g cos φ / 4, so |F|² = (2.5 sin φ)² +
/// (cos φ/4)² in units of (m g)², which reaches 4 at sin²φ = (4 − 1/16)/(6.25 − 1/16).
#[test]
fn an_event_on_a_reaction_column_fires_where_the_pin_force_reaches_twice_the_weight() {
    let (m, l) = (1.5, 1.0);
    let events = json!([{ "name": "strained", "when": "sqrt(pivot.Fx^2 + pivot.Fy^2) - 2 * 1.5 * 9.81",
                          "direction": "rising", "action": "stop" }]);
    let scene = bar(m, l, events, 2.0);
    let s2 = (4.0 - 1.0 / 16.0) / (6.25 - 1.0 / 16.0);
    for f in [FormulationKind::Ggl, FormulationKind::Decoupled] {
        let sol = solve(&scene, f, 1e-10);
        assert_eq!(sol.summary.events.len(), 1, "{f:?}");
        // at the event the bar's angle below the horizontal has sin φ = −bar.angle's sine
        let k = sol.rows.len() - 1;
        let phi = -sol.value(k, "bar.angle").unwrap();
        eprintln!(
            "{f:?}: sin²φ off by {:.2e}, {} steps",
            (phi.sin().powi(2) - s2).abs(),
            sol.summary.steps
        );
        let tol = if f == FormulationKind::Decoupled {
            1e-5
        } else {
            1e-8
        };
        assert!(
            (phi.sin().powi(2) - s2).abs() < tol,
            "{f:?}: sin²φ = {} against {s2}",
            phi.sin().powi(2)
        );
    }
}

fn problems(scene: &Value) -> String {
    match Scene::from_json_str(&scene.to_string()) {
        Err(e) => e.to_string(),
        Ok(s) => match Model::new(&s) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {scene}"),
        },
    }
}

/// Bad events are refused with the JSON path of the bad field, never a panic.
#[test]
fn bad_events_name_their_json_path() {
    let cases = [
        (json!([{ "when": "bar.x +" }]), "events[0].when", "expected"),
        (
            json!([{ "when": "bar.nope" }]),
            "events[0].when",
            "unknown name 'bar.nope'",
        ),
        (
            json!([{ "when": "pivot.Mz" }]),
            "events[0].when",
            "unknown name 'pivot.Mz'",
        ),
        (json!([{ "when": "" }]), "events[0].when", "non-empty"),
        (json!([{ "name": "e" }]), "events[0].when", "missing"),
        (json!([{ "when": 3 }]), "events[0].when", "string"),
        (
            json!([{ "when": "t - 1", "direction": "up" }]),
            "events[0].direction",
            "rising",
        ),
        (
            json!([{ "when": "t - 1", "action": "halt" }]),
            "events[0].action",
            "stop",
        ),
        (
            json!([{ "when": "t - 1", "tolerance": 1 }]),
            "events[0].tolerance",
            "unknown field",
        ),
        (
            json!([{ "name": "a", "when": "t - 1" }, { "name": "a", "when": "t - 2" }]),
            "events[1].name",
            "duplicate",
        ),
        (json!({ "when": "t - 1" }), "events", "array"),
    ];
    for (events, path, fragment) in cases {
        let msg = problems(&bar(1.0, 1.0, events.clone(), 1.0));
        assert!(
            msg.contains(path) && msg.contains(fragment),
            "{events}: expected {path} … {fragment}, got: {msg}"
        );
    }
}

/// An event in time only (`t - 0.3`) stops the run at 0.3 s on the twin as on the DAE, and a
/// scene written back to JSON keeps its events.
#[test]
fn time_event_stops_every_formulation_and_round_trips() {
    let events = json!([{ "name": "cut", "when": "t - 0.3", "action": "stop" }]);
    let scene = bar(1.0, 1.0, events, 1.0);
    for f in [
        FormulationKind::Ggl,
        FormulationKind::Index1,
        FormulationKind::Decoupled,
    ] {
        let sol = solve(&scene, f, 1e-8);
        let t = *sol.times.last().unwrap();
        assert!((t - 0.3).abs() < 1e-10, "{f:?}: stopped at {t}");
        assert_eq!(sol.summary.events[0].name, "cut");
    }
    let s = Scene::from_json_str(&scene.to_string()).unwrap();
    let back = Scene::from_json_str(&serde_json::to_string(&s).unwrap()).unwrap();
    assert_eq!(back.events, s.events);
}

/// An event whose value is not a number (here the square root of a negative height) stops the
/// solve with an error naming the event's JSON path, on IDA and on CVODE.
#[test]
fn an_event_that_is_not_a_number_fails_with_its_path() {
    let events = json!([{ "name": "bad", "when": "sqrt(bar.y - 0.1)" }]);
    let scene = Scene::from_json_str(&bar(1.0, 1.0, events, 1.0).to_string()).unwrap();
    let model = Model::new(&scene).unwrap();
    for f in [FormulationKind::Ggl, FormulationKind::Decoupled] {
        let mut o = model.default_options();
        o.formulation = f;
        let err = model.solve(&o).unwrap_err().to_string();
        assert!(
            err.contains("events[0].when") && err.contains("NaN"),
            "{f:?}: {err}"
        );
    }
}
