//! Loading never panics, whatever the input: random bytes, random JSON, and
//! valid scenes with one field replaced by random JSON.

use bondmech::scene::Scene;
use proptest::prelude::*;
use serde_json::{json, Value};

fn arb_json() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::Bool),
        any::<f64>()
            .prop_filter("finite", |x| x.is_finite())
            .prop_map(|x| json!(x)),
        (-5i64..5).prop_map(|x| json!(x)),
        "[a-zA-Z0-9_. ]{0,8}".prop_map(Value::String),
        Just(json!("ground")),
        Just(json!("bar1")),
        Just(json!("O")),
    ];
    leaf.prop_recursive(3, 24, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::vec(("[a-z_]{1,6}", inner), 0..4)
                .prop_map(|kv| Value::Object(kv.into_iter().collect())),
        ]
    })
}

fn base() -> Value {
    json!({
        "dimension": 2, "gravity": [0.0, -9.81],
        "bodies": [{ "name": "bar1", "mass": 1.0, "inertia": 0.08,
                     "points": { "O": [-0.5, 0.0], "A": [0.5, 0.0] }, "position": [0.5, 0.0] }],
        "joints": [{ "type": "revolute", "bodies": ["ground", "bar1"], "points": [[0.0, 0.0], "O"] }],
        "springs": [{ "bodies": ["ground", "bar1"], "points": [[1.0, 0.0], "A"], "stiffness": 10.0 }],
        "loads": [{ "type": "force", "body": "bar1", "point": "A", "value": [0.0, "t"] }],
        "solve": { "t_end": 1.0, "output_step": 0.1 },
        "outputs": ["bar1.A", "energy"]
    })
}

/// JSON pointers to every value inside `base()`.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    out.push(at.clone());
    match v {
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| pointers(x, format!("{at}/{i}"), out)),
        Value::Object(o) => o
            .iter()
            .for_each(|(k, x)| pointers(x, format!("{at}/{k}"), out)),
        _ => {}
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let text = String::from_utf8_lossy(&bytes);
        prop_assert!(Scene::from_json_str(&text).is_err());
    }

    #[test]
    fn random_json_never_panics(v in arb_json()) {
        let _ = Scene::from_json_str(&v.to_string());
    }

    #[test]
    fn a_valid_scene_with_one_field_replaced_never_panics(which in any::<prop::sample::Index>(), v in arb_json()) {
        let mut scene = base();
        let mut ptrs = Vec::new();
        pointers(&scene, String::new(), &mut ptrs);
        let ptr = which.get(&ptrs[1..]).clone();
        *scene.pointer_mut(&ptr).unwrap() = v;
        match Scene::from_json_str(&scene.to_string()) {
            Err(e) => {
                // Every problem is one line with a message.
                for p in e.problems() {
                    prop_assert!(!p.message.is_empty());
                    prop_assert!(!p.message.contains('\n'));
                }
            }
            Ok(s) => {
            let _ = s.output_times();
            let again = Scene::from_json_str(&s.to_json_string());
            prop_assert!(again.is_ok(), "{:?}", again.err());
            prop_assert_eq!(again.unwrap(), s);
            }
        }
    }
}
