//! Every joint kind's own fields survive writing a scene back to JSON: parse → write → parse
//! gives back an equal scene for each bundled scene of the four newer kinds (gear, slot,
//! rack_pinion, universal), and the written joint carries exactly its kind's keys.

use bondmech::Scene;

#[test]
fn scenes_of_every_new_joint_kind_round_trip_through_json() {
    for (file, joint, keys) in [
        (
            "gear_train",
            "mesh",
            vec!["name", "type", "bodies", "ratio"],
        ),
        (
            "bead_in_slot",
            "slot",
            vec!["name", "type", "bodies", "points", "axis"],
        ),
        (
            "rack_pinion",
            "mesh",
            vec!["name", "type", "bodies", "points", "radius", "axis"],
        ),
        (
            "hooke_joint",
            "cross",
            vec!["name", "type", "bodies", "points", "axes"],
        ),
    ] {
        let path = format!("{}/scenes/{file}.json", env!("CARGO_MANIFEST_DIR"));
        let scene = Scene::from_path(&path).unwrap();
        let text = serde_json::to_string(&scene).unwrap();
        let back = Scene::from_json_str(&text).unwrap_or_else(|e| panic!("{file}: {e}\n{text}"));
        assert_eq!(back.joints, scene.joints, "{file}");
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let j = v["joints"]
            .as_array()
            .unwrap()
            .iter()
            .find(|j| j["name"] == joint)
            .unwrap();
        let mut got: Vec<&str> = j.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        let mut want = keys.clone();
        got.sort();
        want.sort();
        assert_eq!(got, want, "{file}: {j}");
    }
}
