//! A parameter of a sensitivity run: a scene path as `--set` takes it (`bodies[bar2].mass`,
//! `springs[s1].stiffness`, `gravity[1]`, `bodies[block].position[0]`, …, docs/scene-format.md
//! §17), its value in the scene, and the scene with that value changed.

use serde_json::Value;

use super::SensitivityError;
use crate::scene::path::{scene_from_json_with, Assignment, ScenePath, Segment};
use crate::scene::Scene;

/// A numeric field of a scene named by its path.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneParameter {
    /// The path as given.
    pub path: String,
    /// Its value in the scene.
    pub value: f64,
    parsed: ScenePath,
}

impl SceneParameter {
    /// The field at `path` of `scene`: refused naming the path where the path names nothing
    /// or a field that is not a finite number.
    pub fn new(scene: &Scene, path: &str) -> Result<Self, SensitivityError> {
        let bad = |reason: String| SensitivityError::Path {
            path: path.to_string(),
            reason,
        };
        let parsed = ScenePath::parse(path).map_err(|e| bad(e.to_string()))?;
        let root: Value = serde_json::from_str(&scene.to_json_string())
            .map_err(|e| bad(format!("the scene cannot be read back: {e}")))?;
        let mut node = &root;
        let mut at = String::new();
        for seg in parsed.segments() {
            node = match seg {
                Segment::Key(k) => {
                    at = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    node.get(k).ok_or_else(|| {
                        bad(format!("the scene has no field '{at}'{}", keys_hint(node)))
                    })?
                }
                Segment::Index(i) => {
                    at = format!("{at}[{i}]");
                    node.get(i).ok_or_else(|| {
                        bad(format!(
                            "the scene has no entry '{at}' (index out of range)"
                        ))
                    })?
                }
                Segment::Name(n) => {
                    at = format!("{at}[{n}]");
                    node.as_array()
                        .and_then(|a| {
                            a.iter()
                                .find(|e| e.get("name") == Some(&Value::from(n.as_str())))
                        })
                        .ok_or_else(|| {
                            bad(format!("the scene has no entry named '{n}' at '{at}'"))
                        })?
                }
            };
        }
        let value = node.as_f64().ok_or_else(|| {
            bad(format!(
                "'{at}' is not a number but {}",
                match node {
                    Value::Null => "null".to_string(),
                    Value::Bool(_) => "a boolean".into(),
                    Value::String(s) => format!("the text \"{s}\""),
                    Value::Array(_) => "an array (name one component: [0], [1], …)".into(),
                    Value::Object(_) => "an object (name one of its fields)".into(),
                    Value::Number(_) => "a number".into(),
                }
            ))
        })?;
        if !value.is_finite() {
            return Err(bad(format!("'{at}' is not finite")));
        }
        Ok(SceneParameter {
            path: path.to_string(),
            value,
            parsed,
        })
    }

    /// `scene` with this parameter set to `value` (validated as a scene file is).
    pub fn scene_at(&self, scene: &Scene, value: f64) -> Result<Scene, SensitivityError> {
        let number = serde_json::Number::from_f64(value).ok_or_else(|| SensitivityError::Path {
            path: self.path.clone(),
            reason: format!("{value} is not a finite number"),
        })?;
        let set = Assignment::new(self.parsed.clone(), Value::Number(number));
        scene_from_json_with(&scene.to_json_string(), &scene.name, &[set]).map_err(|source| {
            SensitivityError::Perturbed {
                path: self.path.clone(),
                source,
            }
        })
    }

    /// `scene` with every parameter of `params` set to the matching entry of `values`.
    pub fn scene_with(
        scene: &Scene,
        params: &[SceneParameter],
        values: &[f64],
    ) -> Result<Scene, SensitivityError> {
        let mut sets = Vec::with_capacity(params.len());
        for (p, &v) in params.iter().zip(values) {
            let number = serde_json::Number::from_f64(v).ok_or_else(|| SensitivityError::Path {
                path: p.path.clone(),
                reason: format!("{v} is not a finite number"),
            })?;
            sets.push(Assignment::new(p.parsed.clone(), Value::Number(number)));
        }
        scene_from_json_with(&scene.to_json_string(), &scene.name, &sets).map_err(|source| {
            SensitivityError::Perturbed {
                path: params
                    .iter()
                    .map(|p| p.path.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
                source,
            }
        })
    }

    /// Whether the parameter must stay positive in a fit (a mass, an inertia, a stiffness, a
    /// damping, a length).
    pub fn positive(&self) -> bool {
        let last = self.parsed.segments().iter().rev().find_map(|s| match s {
            Segment::Key(k) => Some(k.as_str()),
            _ => None,
        });
        matches!(
            last,
            Some("mass" | "inertia" | "stiffness" | "damping" | "rest_length" | "length")
        )
    }
}

fn keys_hint(node: &Value) -> String {
    match node.as_object() {
        Some(o) if !o.is_empty() => format!(
            " (it has: {})",
            o.keys().cloned().collect::<Vec<_>>().join(", ")
        ),
        _ => String::new(),
    }
}
