//! Scene paths: pointing at one field of a scene and changing it (`--set`, `sweep --vary`).
//!
//! A *scene path* is written the way scene errors name fields:
//!
//! | path | points at |
//! |---|---|
//! | `gravity` | a top-level field |
//! | `solve.rtol` | a field of an object (created when missing) |
//! | `bodies[1].mass` | a field of the second body (indices start at 0) |
//! | `bodies[bar2].mass` | the body whose `"name"` is `bar2` (any array of named objects: `joints[knee]`, `springs[s1]`, `loads[gas]`) |
//! | `joints[2].points[0]` | an array entry |
//! | `bodies[0].points.A` | a named point (object keys are plain segments) |
//! | `gravity[1]` | one component of a vector |
//!
//! Keys are runs of characters other than `.`, `[`, `]` and `=`; a bracket holds either a
//! non-negative integer (an index) or a name. An assignment is `PATH=JSON`: the value is JSON,
//! so strings are quoted (`solve.formulation="index1"`) and vectors are arrays
//! (`gravity=[0,-1.62]`).
//!
//! Applying an assignment replaces the value at the path. A missing *object key* is added
//! (`solve.rtol` in a scene that relies on the default), so the scene's own parser judges it:
//! a misspelt last key comes back as `solve.rtl: unknown field (did you mean "rtol"? expected one of: …)`. Every
//! other mistake is a [`PathError`] naming the path: a key missing in front of an index (with
//! the keys present there), an index out of range (with the length), an unknown name (with the
//! names present), indexing into something that is not an array or object, a malformed path,
//! malformed JSON. After the assignments the scene is parsed and validated as if read from a
//! file, so a value of the wrong type or meaning is reported with its JSON path
//! (`bodies[1].mass: must be > 0 (got -1)`), followed by the assignment that set it.
//!
//! ```
//! use bondmech::scene::path::{apply, parse_assignment, ScenePath};
//! use serde_json::json;
//!
//! let mut scene = json!({"bodies": [{"name": "bar1", "mass": 1.0}, {"name": "bar2", "mass": 1.0}],
//!                        "gravity": [0.0, -9.81]});
//! let set = parse_assignment("bodies[bar2].mass=2.5").unwrap();
//! let resolved = apply(&mut scene, set.path(), set.value()).unwrap();
//! assert_eq!(resolved, "bodies[1].mass");
//! assert_eq!(scene["bodies"][1]["mass"], json!(2.5));
//!
//! let err = apply(&mut scene, &ScenePath::parse("bodies[5].mass").unwrap(), json!(1)).unwrap_err();
//! assert!(err.to_string().contains("has 2 entries"), "{err}");
//! ```

use std::fmt;
use std::path::Path;

pub use super::error::PathError;
use super::error::{Problem, SceneError};
use super::parse;
use super::tree::Json;
use super::Scene;

/// One step of a [`ScenePath`].
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Segment {
    /// An object key: `mass`, `solve`, a point name.
    Key(String),
    /// An array index (from 0): `[1]`.
    Index(usize),
    /// The entry of an array whose `"name"` field is this: `[bar2]`.
    Name(String),
}

/// A parsed scene path such as `bodies[1].mass` (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScenePath {
    text: String,
    segments: Vec<Segment>,
}

fn is_key_char(c: char) -> bool {
    !matches!(c, '.' | '[' | ']' | '=') && !c.is_whitespace()
}

impl ScenePath {
    /// Parses `bodies[1].mass`, `bodies[bar2].mass`, `solve.rtol`, `gravity`, … .
    pub fn parse(text: &str) -> Result<ScenePath, PathError> {
        let bad = |pos: usize, message: String| PathError::Syntax {
            path: text.to_string(),
            message: format!("{message} (at character {})", pos + 1),
        };
        let t = text.trim();
        if t.is_empty() {
            return Err(PathError::Syntax {
                path: text.into(),
                message: "empty path: name a field, e.g. bodies[0].mass or solve.rtol".into(),
            });
        }
        let chars: Vec<char> = t.chars().collect();
        let mut segments = Vec::new();
        let mut i = 0;
        let mut expect_key = true; // at the start and after '.'
        while i < chars.len() {
            let c = chars[i];
            if c == '[' {
                if expect_key && !segments.is_empty() {
                    return Err(bad(i, "expected a key after '.'".into()));
                }
                if segments.is_empty() {
                    return Err(bad(i, "a path starts with a key, e.g. bodies[0]".into()));
                }
                let close = chars[i + 1..]
                    .iter()
                    .position(|&c| c == ']')
                    .map(|p| p + i + 1)
                    .ok_or_else(|| bad(i, "'[' without ']'".into()))?;
                let inner: String = chars[i + 1..close].iter().collect();
                let inner = inner.trim();
                if inner.is_empty() {
                    return Err(bad(i, "empty brackets (give an index or a name)".into()));
                }
                if inner.contains('[') {
                    return Err(bad(i, "nested '['".into()));
                }
                if inner.chars().all(|c| c.is_ascii_digit()) {
                    let n = inner
                        .parse::<usize>()
                        .map_err(|_| bad(i, format!("index '{inner}' too large")))?;
                    segments.push(Segment::Index(n));
                } else if inner.starts_with('-') && inner[1..].chars().all(|c| c.is_ascii_digit()) {
                    return Err(bad(i + 1, format!("negative index {inner}")));
                } else {
                    segments.push(Segment::Name(inner.to_string()));
                }
                i = close + 1;
                expect_key = false;
            } else if c == '.' {
                if expect_key {
                    return Err(bad(i, "empty key".into()));
                }
                expect_key = true;
                i += 1;
            } else if is_key_char(c) {
                if !expect_key {
                    return Err(bad(i, format!("expected '.' or '[' before '{c}'")));
                }
                let start = i;
                while i < chars.len() && is_key_char(chars[i]) {
                    i += 1;
                }
                segments.push(Segment::Key(chars[start..i].iter().collect()));
                expect_key = false;
            } else {
                return Err(bad(i, format!("unexpected '{c}'")));
            }
        }
        if expect_key {
            return Err(bad(chars.len() - 1, "path ends with '.'".into()));
        }
        Ok(ScenePath {
            text: t.to_string(),
            segments,
        })
    }

    /// The path as written.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// Its segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }
}

impl fmt::Display for ScenePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl std::str::FromStr for ScenePath {
    type Err = PathError;
    fn from_str(s: &str) -> Result<Self, PathError> {
        ScenePath::parse(s)
    }
}

/// `PATH=JSON`: a scene path and the value to put there.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    path: ScenePath,
    value: Json,
    text: String,
    origin: &'static str,
}

impl Assignment {
    /// An assignment of `value` at `path`.
    pub fn new(path: ScenePath, value: serde_json::Value) -> Assignment {
        let text = format!("{path}={value}");
        Assignment {
            path,
            value: Json::from_value(&value),
            text,
            origin: "--set",
        }
    }

    /// The same assignment, named after `flag` (`--vary`) in scene errors.
    pub fn labelled(mut self, flag: &'static str) -> Assignment {
        self.origin = flag;
        self
    }

    /// The path.
    pub fn path(&self) -> &ScenePath {
        &self.path
    }

    /// The value (object keys sorted; the scene loader keeps the order they were written in).
    pub fn value(&self) -> serde_json::Value {
        self.value.to_value()
    }

    /// The assignment as written (`bodies[1].mass=2`).
    pub fn as_str(&self) -> &str {
        &self.text
    }

    pub(crate) fn tree_value(&self) -> &Json {
        &self.value
    }

    pub(crate) fn from_tree(path: ScenePath, value: Json, text: String) -> Assignment {
        Assignment {
            path,
            value,
            text,
            origin: "--set",
        }
    }
}

impl fmt::Display for Assignment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// A value that is not JSON but looks like a bare word: the user probably meant a string.
fn bare_word_hint(value: &str) -> String {
    let v = value.trim();
    if !v.is_empty()
        && v.chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.'))
        && v.parse::<f64>().is_err()
    {
        format!(" (a string needs JSON quotes: '...=\"{v}\"')")
    } else {
        String::new()
    }
}

/// Parses `PATH=JSON` (split at the first `=`), e.g. `bodies[0].mass=2`, `gravity=[0,-1.62]`,
/// `solve.formulation="index1"`.
pub fn parse_assignment(text: &str) -> Result<Assignment, PathError> {
    let bad = |message: String| PathError::Assignment {
        assignment: text.to_string(),
        message,
    };
    if text.trim().is_empty() {
        return Err(bad(
            "empty: expected PATH=JSON, e.g. bodies[0].mass=2 or solve.rtol=1e-9".into(),
        ));
    }
    let (p, v) = text
        .split_once('=')
        .ok_or_else(|| bad("expected PATH=JSON, e.g. bodies[0].mass=2".into()))?;
    if p.trim().is_empty() {
        return Err(bad(
            "the path before '=' is empty: name the field to change, e.g. bodies[0].mass=2 or solve.rtol=1e-9 (paths: docs/scene-format.md §17)".into(),
        ));
    }
    let path = ScenePath::parse(p)?;
    if v.trim().is_empty() {
        return Err(bad("no value after '=' (give a JSON value)".into()));
    }
    let value: Json = serde_json::from_str(v)
        .map_err(|e| bad(format!("the value is not JSON: {e}{}", bare_word_hint(v))))?;
    Ok(Assignment::from_tree(
        path.clone(),
        value,
        format!("{}={}", path, v.trim()),
    ))
}

/// Parses `PATH=[v1, v2, …]` (a `sweep --vary`): the path and the list of values.
pub fn parse_variation(text: &str) -> Result<(ScenePath, Vec<serde_json::Value>), PathError> {
    let (path, items) = parse_variation_tree(text)?;
    // as written (integers stay integers), for reports
    let values = match serde_json::from_str(text.split_once('=').map_or("", |(_, v)| v)) {
        Ok(serde_json::Value::Array(v)) => v,
        _ => items.iter().map(Json::to_value).collect(),
    };
    Ok((path, values))
}

/// [`parse_variation`] with the values as order-preserving trees (what is applied to a scene).
pub(crate) fn parse_variation_tree(text: &str) -> Result<(ScenePath, Vec<Json>), PathError> {
    let a = parse_assignment(text)?;
    match a.tree_value() {
        Json::Array(items) if !items.is_empty() => Ok((a.path.clone(), items.clone())),
        Json::Array(_) => Err(PathError::Assignment {
            assignment: text.into(),
            message: "the list of values is empty".into(),
        }),
        other => Err(PathError::Assignment {
            assignment: text.into(),
            message: format!(
                "expected a JSON array of values, got {} (write PATH=[v1, v2, ...]; a vector \
                 parameter takes an array of arrays, e.g. gravity=[[0,-9.81],[0,-1.62]])",
                other.kind()
            ),
        }),
    }
}

fn article(kind: &str) -> String {
    match kind {
        "array" | "object" => format!("an {kind}"),
        "null" => "null".into(),
        _ => format!("a {kind}"),
    }
}

/// Puts `value` at `path` in `root`; returns the path with names resolved to indices
/// (`bodies[bar2].mass` → `bodies[1].mass`), the form in which scene errors name it.
pub(crate) fn apply_tree(
    root: &mut Json,
    path: &ScenePath,
    value: Json,
) -> Result<String, PathError> {
    let mut at = String::new();
    let mut node = root;
    let n = path.segments.len();
    for (k, seg) in path.segments.iter().enumerate() {
        let next_is_key = matches!(path.segments.get(k + 1), Some(Segment::Key(_)));
        let last = k + 1 == n;
        let not_container = |node: &Json, at: &str, wanted: String| PathError::NotContainer {
            path: path.text.clone(),
            at: at.to_string(),
            found: article(node.kind()),
            wanted,
        };
        match seg {
            Segment::Key(key) => {
                if !matches!(node, Json::Object(_)) {
                    return Err(not_container(node, &at, format!("key '{key}'")));
                }
                let Json::Object(entries) = node else {
                    unreachable!("checked above")
                };
                let child = super::error::field(&at, key);
                let pos = match entries.iter().rposition(|(k2, _)| k2 == key) {
                    Some(p) => p,
                    None if last || next_is_key => {
                        let fresh = if last {
                            Json::Null
                        } else {
                            Json::Object(Vec::new())
                        };
                        entries.push((key.clone(), fresh));
                        entries.len() - 1
                    }
                    None => {
                        return Err(PathError::UnknownKey {
                            path: path.text.clone(),
                            at,
                            key: key.clone(),
                            available: entries.iter().map(|(k2, _)| k2.clone()).collect(),
                        })
                    }
                };
                at = child;
                node = &mut entries[pos].1;
            }
            Segment::Index(i) => {
                if !matches!(node, Json::Array(_)) {
                    return Err(not_container(node, &at, format!("index {i}")));
                }
                let Json::Array(items) = node else {
                    unreachable!("checked above")
                };
                if *i >= items.len() {
                    return Err(PathError::IndexOutOfRange {
                        path: path.text.clone(),
                        at,
                        index: *i,
                        len: items.len(),
                    });
                }
                at = super::error::index(&at, *i);
                node = &mut items[*i];
            }
            Segment::Name(name) => {
                if !matches!(node, Json::Array(_)) {
                    return Err(not_container(node, &at, format!("entry named '{name}'")));
                }
                let Json::Array(items) = node else {
                    unreachable!("checked above")
                };
                let name_of = |j: &Json| match j {
                    Json::Object(e) => e.iter().find_map(|(k, v)| match (k.as_str(), v) {
                        ("name", Json::String(s)) => Some(s.clone()),
                        _ => None,
                    }),
                    _ => None,
                };
                let Some(i) = items
                    .iter()
                    .position(|j| name_of(j).as_deref() == Some(name))
                else {
                    return Err(PathError::UnknownName {
                        path: path.text.clone(),
                        at,
                        name: name.clone(),
                        names: items.iter().filter_map(name_of).collect(),
                    });
                };
                at = super::error::index(&at, i);
                node = &mut items[i];
            }
        }
    }
    *node = value;
    Ok(at)
}

/// Puts `value` at `path` in a scene's JSON; returns the path with names resolved to indices.
///
/// `serde_json::Value` sorts object keys: for a scene whose named points' order matters, load
/// through [`scene_from_json_with`] (order kept) instead of re-serialising the `Value`.
pub fn apply(
    root: &mut serde_json::Value,
    path: &ScenePath,
    value: serde_json::Value,
) -> Result<String, PathError> {
    let mut tree = Json::from_value(root);
    let resolved = apply_tree(&mut tree, path, Json::from_value(&value))?;
    *root = tree.to_value();
    Ok(resolved)
}

/// Applies `sets` in order to an order-preserving scene tree, parses and validates the result;
/// problems at a path an assignment set are followed by that assignment.
pub(crate) fn scene_from_tree_with(
    mut tree: Json,
    default_name: &str,
    sets: &[Assignment],
) -> Result<Scene, SceneError> {
    let mut resolved = Vec::with_capacity(sets.len());
    for a in sets {
        let r = apply_tree(&mut tree, &a.path, a.value.clone())?;
        resolved.push((r, format!("{} {}", a.origin, a.as_str())));
    }
    let annotate = |mut problems: Vec<Problem>| {
        for p in &mut problems {
            // the last assignment to a path wins, so name the last one that covers the problem
            if let Some((_, text)) = resolved.iter().rev().find(|(r, _)| covers(r, &p.path)) {
                p.message = format!("{} (set by {text})", p.message);
            }
        }
        SceneError::Invalid { problems }
    };
    let scene = parse::scene_from_tree(&tree, default_name).map_err(annotate)?;
    let problems = super::validate::validate(&scene);
    if !problems.is_empty() {
        return Err(annotate(problems));
    }
    Ok(scene)
}

/// Whether the problem at `problem` lies at or under the assigned path `set`.
fn covers(set: &str, problem: &str) -> bool {
    problem == set
        || problem
            .strip_prefix(set)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// Parses scene text, applies `sets` in order, then parses and validates the result as a scene
/// file would be (`name` defaults to `default_name`).
pub fn scene_from_json_with(
    text: &str,
    default_name: &str,
    sets: &[Assignment],
) -> Result<Scene, SceneError> {
    let tree = parse::parse_tree(text).map_err(|problems| SceneError::Invalid { problems })?;
    scene_from_tree_with(tree, default_name, sets)
}

/// [`scene_from_json_with`] for assignments as written (`PATH=JSON` text, e.g. from `--set`).
pub fn scene_from_json_with_sets(
    text: &str,
    default_name: &str,
    sets: &[String],
) -> Result<Scene, SceneError> {
    let sets = sets
        .iter()
        .map(|s| parse_assignment(s))
        .collect::<Result<Vec<_>, _>>()?;
    scene_from_json_with(text, default_name, &sets)
}

/// Reads a scene file with `PATH=JSON` assignments applied (`run --set`, `compare --set`);
/// with no assignments it is exactly [`Scene::from_path`].
pub fn scene_from_path_with(p: impl AsRef<Path>, sets: &[String]) -> Result<Scene, SceneError> {
    if sets.is_empty() {
        return Scene::from_path(p);
    }
    let sets = sets
        .iter()
        .map(|s| parse_assignment(s))
        .collect::<Result<Vec<_>, _>>()?;
    let (text, stem) = read_scene_text(p.as_ref())?;
    scene_from_json_with(&text, &stem, &sets)
}

/// Reads a scene file's text and the default name (its stem).
pub fn read_scene_text(p: &Path) -> Result<(String, String), SceneError> {
    let text = super::read_text(p)?;
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".to_string());
    Ok((text, stem))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn segs(p: &str) -> Vec<Segment> {
        ScenePath::parse(p).unwrap().segments
    }

    #[test]
    fn parses_keys_indices_and_names() {
        use Segment::*;
        assert_eq!(segs("gravity"), vec![Key("gravity".into())]);
        assert_eq!(
            segs("bodies[1].mass"),
            vec![Key("bodies".into()), Index(1), Key("mass".into())]
        );
        assert_eq!(
            segs("bodies[bar2].points.A[0]"),
            vec![
                Key("bodies".into()),
                Name("bar2".into()),
                Key("points".into()),
                Key("A".into()),
                Index(0)
            ]
        );
        assert_eq!(
            segs("joints[2].points[0]"),
            vec![
                Key("joints".into()),
                Index(2),
                Key("points".into()),
                Index(0)
            ]
        );
    }

    #[test]
    fn rejects_malformed_paths_with_the_position() {
        for bad in [
            "",
            "bodies[",
            "bodies[]",
            "bodies..mass",
            "bodies.",
            "[0]",
            "bodies[-1]",
            "a]b",
            "bodies[0]mass",
            "a b",
        ] {
            let e = ScenePath::parse(bad).unwrap_err();
            assert!(matches!(e, PathError::Syntax { .. }), "{bad}: {e}");
            assert!(e.to_string().contains("bad scene path"), "{e}");
        }
        assert!(ScenePath::parse("bodies[-1]")
            .unwrap_err()
            .to_string()
            .contains("negative index -1"));
    }

    #[test]
    fn applies_and_reports_index_name_key_errors() {
        let mut v = json!({"bodies": [{"name": "a", "mass": 1.0}, {"name": "b", "mass": 2.0}],
                            "gravity": [0.0, -9.81], "solve": {"t_end": 1.0}});
        let p = |s| ScenePath::parse(s).unwrap();
        assert_eq!(
            apply(&mut v, &p("gravity[1]"), json!(-1.62)).unwrap(),
            "gravity[1]"
        );
        assert_eq!(v["gravity"], json!([0.0, -1.62]));
        assert_eq!(
            apply(&mut v, &p("solve.rtol"), json!(1e-9)).unwrap(),
            "solve.rtol"
        );
        assert_eq!(v["solve"]["rtol"], json!(1e-9));
        assert_eq!(
            apply(&mut v, &p("bodies[b].mass"), json!(3.0)).unwrap(),
            "bodies[1].mass"
        );
        assert_eq!(v["bodies"][1]["mass"], json!(3.0));

        let e = apply(&mut v, &p("bodies[2].mass"), json!(1)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "bodies[2].mass: index 2 out of range: 'bodies' has 2 entries"
        );
        let e = apply(&mut v, &p("bodies[c].mass"), json!(1)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "bodies[c].mass: no entry named 'c' in 'bodies' (names there: a, b)"
        );
        let e = apply(&mut v, &p("bodeis[0].mass"), json!(1)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "bodeis[0].mass: no key 'bodeis' in the scene (keys there: bodies, gravity, solve)"
        );
        let e = apply(&mut v, &p("gravity.x"), json!(1)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "gravity.x: 'gravity' is an array, it has no key 'x'"
        );
        let e = apply(&mut v, &p("solve.t_end[0]"), json!(1)).unwrap_err();
        assert!(
            e.to_string().contains("is a number, it has no index 0"),
            "{e}"
        );
    }

    #[test]
    fn assignments_need_json_values() {
        let a = parse_assignment("gravity=[0, -1.62]").unwrap();
        assert_eq!(a.value(), json!([0.0, -1.62]));
        assert_eq!(a.path().as_str(), "gravity");
        let e = parse_assignment("solve.formulation=index1").unwrap_err();
        assert!(e.to_string().contains("needs JSON quotes"), "{e}");
        assert!(parse_assignment("gravity").is_err());
        assert!(parse_assignment("gravity=").is_err());
        let (p, vals) = parse_variation("gravity=[[0,-9.81],[0,-1.62]]").unwrap();
        assert_eq!(p.as_str(), "gravity");
        assert_eq!(vals, vec![json!([0, -9.81]), json!([0, -1.62])]);
        assert!(parse_variation("bodies[0].mass=2").is_err());
        assert!(parse_variation("bodies[0].mass=[]").is_err());
    }
}
