//! Randomized robustness (issue 26): the bundled scenes mutated — values of another type,
//! flipped signs, extreme magnitudes, missing and extra keys, truncated text — and each
//! outcome must be a result or a clear error, never a panic, an abort or a hang, through the
//! command line's library entry (scene → model → streamed solve) and through the service's
//! handler (`POST /v1/run`).
//!
//! A fixed budget of cases (below); CI pins `PROPTEST_RNG_SEED` (`.ci/run`), and any failure
//! is recorded in `tests/robustness.proptest-regressions` and replayed first.

mod service_support;

use std::ops::ControlFlow;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use bondmech::scene::Scene;
use proptest::prelude::*;
use serde_json::{json, Value};

/// Cases of each property: together a few thousand, under a minute on a 2-core machine.
const LIBRARY_CASES: u32 = 3000;
const SERVICE_CASES: u32 = 1000;

/// Longest a case may take (a solve is stopped after [`SOLVE_BUDGET`]; anything near this is
/// a hang in the making).
const CASE_LIMIT: Duration = Duration::from_secs(20);
const SOLVE_BUDGET: Duration = Duration::from_millis(200);

/// The bundled scenes, as JSON values.
fn scenes() -> &'static [(String, Value)] {
    static SCENES: OnceLock<Vec<(String, Value)>> = OnceLock::new();
    SCENES.get_or_init(|| {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut v: Vec<(String, Value)> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .filter(|e| e.path().extension().is_some_and(|x| x == "json"))
            .map(|e| {
                let text = std::fs::read_to_string(e.path()).unwrap();
                (
                    e.file_name().to_string_lossy().into_owned(),
                    serde_json::from_str(&text).unwrap(),
                )
            })
            .collect();
        v.sort_by(|a, b| a.0.cmp(&b.0));
        assert!(v.len() >= 10, "the bundled scenes");
        v
    })
}

/// JSON pointers to every value inside `v` (the root excluded).
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    if !at.is_empty() {
        out.push(at.clone());
    }
    match v {
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| pointers(x, format!("{at}/{i}"), out)),
        Value::Object(o) => o.iter().for_each(|(k, x)| {
            pointers(
                x,
                format!("{at}/{}", k.replace('~', "~0").replace('/', "~1")),
                out,
            )
        }),
        _ => {}
    }
}

/// One edit of a scene.
#[derive(Clone, Debug)]
enum Mutation {
    /// The value at a pointer replaced by another JSON value (often of another type).
    Replace(prop::sample::Index, Value),
    /// A number's sign flipped (a string `"x"` becomes `"-(x)"`).
    FlipSign(prop::sample::Index),
    /// A number scaled by `10^k`, or set to an extreme.
    Magnitude(prop::sample::Index, f64),
    /// A key or an array element removed.
    Remove(prop::sample::Index),
    /// An unknown key added to an object.
    Extra(prop::sample::Index, String, Value),
}

fn arb_value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::Bool),
        prop_oneof![
            Just(0.0),
            Just(-1.0),
            Just(1e308),
            Just(-1e308),
            Just(5e-324),
            Just(1e-320),
            -1e3..1e3f64,
        ]
        .prop_map(|x| json!(x)),
        (-3i64..100_000).prop_map(|x| json!(x)),
        prop_oneof![
            Just("t".to_string()),
            Just("-1.5".to_string()),
            Just("1/t".to_string()),
            Just("sqrt(-1)".to_string()),
            Just("ground".to_string()),
            Just("bar1".to_string()),
            Just("dae".to_string()),
            Just("decoupled".to_string()),
            Just("left-arm".to_string()),
            "[a-zA-Z0-9_. ,()*+-]{0,12}",
        ]
        .prop_map(Value::String),
    ];
    leaf.prop_recursive(2, 12, 3, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::vec(("[a-z_]{1,8}", inner), 0..3)
                .prop_map(|kv| Value::Object(kv.into_iter().collect())),
        ]
    })
}

fn arb_mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        3 => (any::<prop::sample::Index>(), arb_value()).prop_map(|(i, v)| Mutation::Replace(i, v)),
        2 => any::<prop::sample::Index>().prop_map(Mutation::FlipSign),
        2 => (
            any::<prop::sample::Index>(),
            prop_oneof![
                Just(1e-320),
                Just(1e-300),
                Just(1e-30),
                Just(1e-8),
                Just(1e8),
                Just(1e30),
                Just(1e300),
                Just(0.0),
                Just(f64::MAX)
            ]
        )
            .prop_map(|(i, k)| Mutation::Magnitude(i, k)),
        2 => any::<prop::sample::Index>().prop_map(Mutation::Remove),
        1 => (any::<prop::sample::Index>(), "[a-z_]{1,10}", arb_value())
            .prop_map(|(i, k, v)| Mutation::Extra(i, k, v)),
    ]
}

/// Applies `m` to `v` (a pointer that vanished with an earlier edit does nothing).
fn apply(v: &mut Value, m: &Mutation) {
    let mut ptrs = Vec::new();
    pointers(v, String::new(), &mut ptrs);
    if ptrs.is_empty() {
        return;
    }
    match m {
        Mutation::Replace(i, x) => {
            if let Some(t) = v.pointer_mut(i.get(&ptrs).as_str()) {
                *t = x.clone();
            }
        }
        Mutation::FlipSign(i) => {
            if let Some(t) = v.pointer_mut(i.get(&ptrs).as_str()) {
                match t {
                    Value::Number(n) => *t = json!(-n.as_f64().unwrap_or(0.0)),
                    Value::String(s) => *t = json!(format!("-({s})")),
                    _ => {}
                }
            }
        }
        Mutation::Magnitude(i, k) => {
            if let Some(t) = v.pointer_mut(i.get(&ptrs).as_str()) {
                if let Some(x) = t.as_f64() {
                    let y = if *k == 0.0 { 0.0 } else { x * k };
                    // JSON has no infinity: an overflow becomes the largest double
                    *t = json!(if y.is_finite() {
                        y
                    } else {
                        f64::MAX.copysign(y)
                    });
                }
            }
        }
        Mutation::Remove(i) => {
            let p = i.get(&ptrs).clone();
            let (parent, last) = p.rsplit_once('/').expect("a pointer has a slash");
            match v.pointer_mut(parent) {
                Some(Value::Object(o)) => {
                    o.remove(&last.replace("~1", "/").replace("~0", "~"));
                }
                Some(Value::Array(a)) => {
                    if let Ok(k) = last.parse::<usize>() {
                        if k < a.len() {
                            a.remove(k);
                        }
                    }
                }
                _ => {}
            }
        }
        Mutation::Extra(i, k, x) => {
            let p = i.get(&ptrs).clone();
            let target = match v.pointer(&p) {
                Some(Value::Object(_)) => p,
                _ => p.rsplit_once('/').map(|(a, _)| a.to_string()).unwrap(),
            };
            if let Some(Value::Object(o)) = v.pointer_mut(&target) {
                o.insert(k.clone(), x.clone());
            }
        }
    }
}

fn arb_case() -> impl Strategy<Value = (usize, Vec<Mutation>, Option<prop::sample::Index>)> {
    (
        0..scenes().len(),
        prop::collection::vec(arb_mutation(), 1..4),
        // one case in eight: the text cut somewhere
        prop::option::weighted(0.125, any::<prop::sample::Index>()),
    )
}

/// The mutated scene text.
fn case_text(which: usize, muts: &[Mutation], cut: &Option<prop::sample::Index>) -> String {
    let mut v = scenes()[which].1.clone();
    for m in muts {
        apply(&mut v, m);
    }
    let text = v.to_string();
    match cut {
        Some(i) => {
            let mut k = i.index(text.len().max(1));
            while !text.is_char_boundary(k) {
                k -= 1;
            }
            text[..k].to_string()
        }
        None => text,
    }
}

/// A clear error: one or more lines, each saying something, none of them a panic.
fn clear(message: &str) -> Result<(), TestCaseError> {
    prop_assert!(!message.trim().is_empty(), "an empty error message");
    prop_assert!(!message.contains("panicked"), "{message}");
    Ok(())
}

/// The command line's path through the library: read, build, solve (streamed, a few rows,
/// with a wall-clock budget). `Ok` for a result or a clear error.
fn library_outcome(text: &str) -> Result<(), TestCaseError> {
    let scene = match Scene::from_json_str(text) {
        Ok(s) => s,
        Err(e) => return clear(&e.to_string()),
    };
    let model = match bondmech::Model::new(&scene) {
        Ok(m) => m,
        Err(e) => return clear(&e.to_string()),
    };
    let mut opts = model.default_options();
    opts.output_times.truncate(6);
    opts.max_wall_clock = Some(SOLVE_BUDGET);
    opts.keep_rows = false;
    let mut rows = 0usize;
    match model.solve_streaming(&opts, &mut |r| {
        rows += 1;
        assert!(r.t.is_finite());
        ControlFlow::Continue(())
    }) {
        Ok(sol) => {
            prop_assert!(rows >= 1 && !sol.times.is_empty());
            Ok(())
        }
        Err(e) => clear(&e.to_string()),
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: LIBRARY_CASES,
        max_shrink_iters: 200,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_scenes_give_a_result_or_a_clear_error_through_the_library(
        (which, muts, cut) in arb_case()
    ) {
        let text = case_text(which, &muts, &cut);
        let start = Instant::now();
        library_outcome(&text)?;
        prop_assert!(start.elapsed() < CASE_LIMIT, "{:?} for {}", start.elapsed(), scenes()[which].0);
    }
}

/// One server for every service case.
fn server() -> &'static bondmech::service::Server {
    static SERVER: OnceLock<bondmech::service::Server> = OnceLock::new();
    SERVER.get_or_init(|| {
        let mut config = bondmech::service::Config::default();
        config.limits.max_solve_seconds = SOLVE_BUDGET.as_secs_f64();
        config.limits.max_rows = 2_000;
        service_support::start(config)
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: SERVICE_CASES,
        max_shrink_iters: 100,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_scenes_give_a_result_or_a_problem_through_the_service(
        (which, muts, cut) in arb_case()
    ) {
        let text = case_text(which, &muts, &cut);
        let start = Instant::now();
        let r = service_support::post(server().addr(), "/v1/run?t_end=0.05", text.as_bytes());
        prop_assert!(start.elapsed() < CASE_LIMIT, "{:?}", start.elapsed());
        prop_assert!(r.status != 500 && r.status < 600, "{}: {}", r.status, r.text());
        if r.status >= 400 {
            let j = r.json();
            let detail = j["detail"].as_str().unwrap_or_default().to_string();
            clear(&detail)?;
        }
    }
}
