//! Every joint kind is listed wherever kinds are listed: the kinds' spellings
//! (`bondmech::scene::JOINT_TYPES`) hold every kind a bundled scene uses, the scene schema's
//! `JointType` enum is exactly that list, the refusal of an unknown type names each kind, and
//! `docs/scene-format.md` §5 documents each kind (its spelling in the `type` row and a row of
//! its own in the table of rows). Regression: `universal` was missing from the list, so the
//! schema refused the bundled `hooke_joint.json` and the refusal of an unknown type did not
//! offer it.

use bondmech::scene::{schema::scene_schema, Scene, JOINT_TYPES};
use std::collections::BTreeSet;
use std::path::Path;

fn bundled_scenes() -> Vec<(String, serde_json::Value)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut out = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "json") {
            let v = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            out.push((p.display().to_string(), v));
        }
    }
    out
}

#[test]
fn every_joint_type_a_bundled_scene_uses_is_a_listed_kind() {
    let mut used = BTreeSet::new();
    for (file, v) in bundled_scenes() {
        for j in v["joints"].as_array().into_iter().flatten() {
            let t = j["type"].as_str().unwrap().to_string();
            assert!(
                JOINT_TYPES.contains(&t.as_str()),
                "{file}: {t} not in {JOINT_TYPES:?}"
            );
            used.insert(t);
        }
    }
    assert!(used.contains("universal"), "{used:?}");
}

#[test]
fn the_schema_lists_exactly_the_joint_kinds() {
    let s = scene_schema();
    let listed: BTreeSet<&str> = s["$defs"]["JointType"]["enum"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let kinds: BTreeSet<&str> = JOINT_TYPES.iter().copied().collect();
    assert_eq!(listed, kinds);
    assert!(listed.contains("universal"));
    // each kind's spelling appears once
    assert_eq!(kinds.len(), JOINT_TYPES.len(), "{JOINT_TYPES:?}");
}

#[test]
fn an_unknown_joint_type_is_refused_naming_every_kind() {
    let json = r#"{"name":"x","dimension":2,
        "bodies":[{"name":"b","mass":1,"inertia":0.1,"position":[0,0]}],
        "joints":[{"name":"j","type":"hinge","bodies":["ground","b"],"points":[[0,0],[0,0]]}],
        "solve":{"t_end":1}}"#;
    let err = Scene::from_json_str(json).unwrap_err().to_string();
    assert!(err.contains("joints[0].type"), "{err}");
    for k in JOINT_TYPES {
        assert!(
            err.contains(&format!("{k},")) || err.contains(&format!("{k})")),
            "{k}: {err}"
        );
    }
}

#[test]
fn the_scene_format_documents_every_joint_kind() {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scene-format.md"))
            .unwrap();
    let start = doc.find("## 5. Joints").expect("§5");
    let end = start + doc[start..].find("\n## 6.").expect("§6");
    let joints = &doc[start..end];
    let type_row = joints
        .lines()
        .find(|l| l.starts_with("| `type` |"))
        .expect("the type row");
    for k in JOINT_TYPES {
        assert!(
            type_row.contains(&format!("`\"{k}\"`")),
            "{k} missing in {type_row}"
        );
        assert!(
            joints.lines().any(|l| l.starts_with(&format!("| `{k}`"))),
            "§5 has no row for {k}"
        );
    }
}
