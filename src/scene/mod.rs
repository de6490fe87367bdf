//! Scene format v1: JSON scenes (serde), validated with the JSON path of every bad field.
//!
//! The public contract is `docs/scene-format.md`; every field there keeps its
//! name and meaning. A scene is loaded in two stages, each reporting *all* of
//! its problems as `path: message` lines:
//!
//! 1. [`parse`]: JSON syntax (line and column), types, required fields,
//!    unknown or duplicated keys, enumeration spellings;
//! 2. [`validate`]: meaning — lengths for the dimension, finite numbers,
//!    signs, references between bodies, joints, springs, loads and outputs.
//!
//! ```
//! use bondmech::scene::Scene;
//! let s = Scene::from_json_str(r#"{
//!   "dimension": 2, "gravity": [0, -9.81],
//!   "bodies": [{ "name": "bob", "mass": 1, "inertia": 0,
//!                "points": { "O": [-1, 0] }, "position": [1, 0] }],
//!   "joints": [{ "type": "revolute", "bodies": ["ground", "bob"], "points": [[0, 0], "O"] }],
//!   "solve": { "t_end": 1, "output_step": 0.5 } }"#).unwrap();
//! assert_eq!(s.output_times(), vec![0.0, 0.5, 1.0]);
//! ```
//!
//! Fields added to the contract (all optional):
//! - everywhere: `"comment"` (ignored); top level: `"description"` (kept).
//! - joints: `"name"` defaults to `"joint<i>"`; loads: `"name"` (default `"load<i>"`);
//!   springs: `"name"` (default `"spring<i>"`).
//! - body (spatial): `"cardan"` defaults to `[0, 0, 0]`; `"frame"` as in the plane.
//! - torque in a spatial scene: `[tx, ty, tz]` in the global frame.
//! - load `value`: an array mixing numbers and expression strings is an expression
//!   per component (numbers become constant expressions); a table's `"v"` holds
//!   one value per time, a scalar for a planar torque or an array otherwise.
//! - `solve`: `"formulation"` also accepts `"ggl"`, `"index1"`, `"compliant_ggl"`;
//!   `"output_step"` defaults to `t_end / 100`; `"max_wall_seconds"`.
//! - `outputs`: `body.point`, `body.<standard column>` or one of
//!   [`model::SCALAR_OUTPUTS`].
//!
//! Defaults: `dimension` 2, `gravity` zero, `frame` `"inertial"`, `position`,
//! `velocity`, `angular_velocity`, `angle` zero, `rtol` 1e-6, `atol` 1e-8,
//! `joint_stiffness` 1e8, `joint_damping` 0, spring `damping` 0,
//! `rest_length` = initial distance. `name` defaults to the file stem.

pub mod drivers;
mod error;
mod fields;
pub mod inputs;
pub mod joint_kind;
pub mod model;
pub mod overrides;
pub mod parse;
pub mod path;
pub mod schema;
mod space;
pub(crate) mod tree;
pub mod validate;
mod write;

pub use error::{Problem, SceneError};
pub(crate) use fields::did_you_mean_note;
pub use joint_kind::{JointKind, JOINT_TYPES};
pub use model::*;
pub use overrides::{OverrideProblem, SolveOverrides};

use std::path::Path;

impl Scene {
    /// Parses and validates scene text; the error lists every problem with its JSON path.
    pub fn from_json_str(s: &str) -> Result<Scene, SceneError> {
        Self::from_json_named(s, "scene")
    }

    /// Reads, parses and validates a scene file; `name` defaults to the file stem.
    pub fn from_path(p: impl AsRef<Path>) -> Result<Scene, SceneError> {
        let p = p.as_ref();
        let text = read_text(p)?;
        let stem = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".to_string());
        Self::from_json_named(&text, &stem)
    }

    fn from_json_named(s: &str, default_name: &str) -> Result<Scene, SceneError> {
        let scene = parse::parse_scene(s, default_name)
            .map_err(|problems| SceneError::Invalid { problems })?;
        scene.validate()?;
        Ok(scene)
    }

    /// Checks the meaning of the scene (see [`validate::validate`]).
    pub fn validate(&self) -> Result<(), SceneError> {
        let problems = validate::validate(self);
        if problems.is_empty() {
            Ok(())
        } else {
            Err(SceneError::Invalid { problems })
        }
    }

    /// Things worth telling the user that do not make the scene invalid
    /// (see [`validate::warnings`]).
    pub fn warnings(&self) -> Vec<Problem> {
        validate::warnings(self)
    }

    /// The scene as pretty-printed JSON (format v1), named points in their order.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(&write::scene_tree(self))
            .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

/// Reads scene text from `reader` (`path` names it in errors), refusing more than
/// [`validate::MAX_SCENE_BYTES`] at once: a 10 GB file is not read into memory to be refused.
/// Binary data is refused at its first NUL byte, as soon as it is read (`/dev/zero` is not
/// read for 64 MiB to be called too long), text that is not UTF-8 at its first bad byte, and
/// an empty text (an empty file, a closed standard input) as empty — each naming `path`.
pub fn read_text_from(reader: impl std::io::Read, path: &Path) -> Result<String, SceneError> {
    use std::io::Read;
    let io = |source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut bytes: Vec<u8> = Vec::new();
    let mut reader = reader.take(validate::MAX_SCENE_BYTES as u64 + 1);
    let mut chunk = vec![0u8; 64 * 1024];
    loop {
        let n = match reader.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io(e)),
        };
        if let Some(k) = chunk[..n].iter().position(|&b| b == 0) {
            return Err(SceneError::NotText {
                path: path.to_path_buf(),
                offset: bytes.len() + k,
                why: "is a NUL byte: this is binary data, not a JSON scene (a device such as /dev/zero, or a binary file)",
            });
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
    validate::check_text_length(bytes.len()).map_err(|e| SceneError::Invalid {
        problems: vec![Problem::new(e.path(), e.to_string())],
    })?;
    let text = String::from_utf8(bytes).map_err(|e| SceneError::NotText {
        path: path.to_path_buf(),
        offset: e.utf8_error().valid_up_to(),
        why: "is not UTF-8: a scene is JSON text in UTF-8",
    })?;
    if text.trim().is_empty() {
        return Err(SceneError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(text)
}

/// Reads a scene file (see [`read_text_from`]).
pub fn read_text(path: &Path) -> Result<String, SceneError> {
    let file = std::fs::File::open(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_text_from(file, path)
}
