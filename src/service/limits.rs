//! What one request may ask, checked before any work is queued: the body size (from
//! `Content-Length` before reading, then while reading), the JSON syntax, the number of
//! elements, the length of every string (expressions), and the number of output rows.

use std::time::Duration;

use axum::body::{Body, Bytes};
use axum::http::{header, HeaderMap, StatusCode};
use http_body_util::BodyExt;
use serde_json::Value;

use super::problem::Problem;
use crate::scene::Scene;

/// Per-request limits (see [`super::Config`] for the defaults).
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// Largest request body in bytes (413 above it).
    pub max_body: u64,
    /// Largest number of bodies + joints + springs + loads + outputs + events + drivers + bond
    /// graph elements and bonds in one scene.
    pub max_elements: usize,
    /// Longest string in a scene, in bytes (expressions and names; `description` and `comment`
    /// are free text, bounded by `max_body` only).
    pub max_expression_length: usize,
    /// Most output rows (output times) one run may produce.
    pub max_rows: usize,
    /// Wall-clock budget of one solve, in seconds.
    pub max_solve_seconds: f64,
    /// Time allowed to receive the request body.
    pub body_timeout: Duration,
}

/// Reads the body: refuses from `Content-Length` alone when it is over the limit (413, nothing
/// read), refuses a chunked body as soon as it grows past the limit, and refuses media types
/// other than JSON (415).
pub async fn read_body(headers: &HeaderMap, body: Body, limits: &Limits) -> Result<Bytes, Problem> {
    if let Some(ct) = headers.get(header::CONTENT_TYPE) {
        let ct = ct.to_str().unwrap_or("").to_ascii_lowercase();
        let essence = ct.split(';').next().unwrap_or("").trim();
        if !(essence == "application/json" || essence.ends_with("+json")) {
            return Err(Problem::new(
                StatusCode::UNSUPPORTED_MEDIA_TYPE,
                "unsupported-media-type",
                "Unsupported media type",
                format!("the body must be a JSON scene (content-type application/json), got '{essence}'"),
            ));
        }
    }
    if let Some(cl) = headers.get(header::CONTENT_LENGTH) {
        let n: u64 = cl
            .to_str()
            .ok()
            .and_then(|s| s.trim().parse().ok())
            .ok_or_else(|| {
                Problem::new(
                    StatusCode::BAD_REQUEST,
                    "invalid-header",
                    "Invalid header",
                    "Content-Length is not a number",
                )
            })?;
        if n > limits.max_body {
            return Err(too_large(Some(n), limits.max_body));
        }
    }
    let read = async {
        let mut body = body;
        let mut buf: Vec<u8> = Vec::new();
        while let Some(frame) = body.frame().await {
            let frame = frame.map_err(|e| {
                Problem::new(
                    StatusCode::BAD_REQUEST,
                    "unreadable-body",
                    "The request body could not be read",
                    e.to_string(),
                )
            })?;
            if let Ok(data) = frame.into_data() {
                if buf.len() as u64 + data.len() as u64 > limits.max_body {
                    return Err(too_large(None, limits.max_body));
                }
                buf.extend_from_slice(&data);
            }
        }
        Ok(Bytes::from(buf))
    };
    match tokio::time::timeout(limits.body_timeout, read).await {
        Ok(r) => r,
        Err(_) => Err(Problem::new(
            StatusCode::REQUEST_TIMEOUT,
            "body-timeout",
            "Request body not received in time",
            format!(
                "the body was not received within {} s",
                limits.body_timeout.as_secs_f64()
            ),
        )),
    }
}

fn too_large(length: Option<u64>, max: u64) -> Problem {
    let detail = match length {
        Some(n) => format!("Content-Length {n} is over the limit max_body = {max} bytes"),
        None => format!("the body grew past the limit max_body = {max} bytes"),
    };
    Problem::new(
        StatusCode::PAYLOAD_TOO_LARGE,
        "body-too-large",
        "Request body too large",
        detail,
    )
    .with("limit", "max_body")
    .with("limit_value", max)
}

/// Parses the body as JSON: 400 with line and column on a syntax error.
pub fn parse_json(body: &[u8]) -> Result<Value, Problem> {
    serde_json::from_slice(body).map_err(|e| {
        Problem::new(
            StatusCode::BAD_REQUEST,
            "malformed-json",
            "Malformed JSON",
            format!("{e}"),
        )
        .with("line", e.line())
        .with("column", e.column())
    })
}

/// Counts the elements of a scene and measures its strings: 422 naming `max_elements` or
/// `max_expression_length` (with the JSON path of the long string).
pub fn check_document(doc: &Value, limits: &Limits) -> Result<(), Problem> {
    let len = |v: Option<&Value>| v.and_then(Value::as_array).map_or(0, Vec::len);
    let bg = doc.get("bond_graph");
    let lists: Vec<(&str, usize)> = ELEMENT_LISTS
        .iter()
        .map(|k| (*k, len(doc.get(*k))))
        .chain([
            (
                "bond_graph.elements",
                len(bg.and_then(|g| g.get("elements"))),
            ),
            ("bond_graph.bonds", len(bg.and_then(|g| g.get("bonds")))),
        ])
        .filter(|(_, n)| *n > 0)
        .collect();
    let elements: usize = lists.iter().map(|(_, n)| n).sum();
    if elements > limits.max_elements {
        let counted = lists
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(Problem::limit(
            "max_elements",
            limits.max_elements,
            format!(
                "the scene has {elements} elements ({counted}), over this server's limit max_elements = {} (set by `bondmech serve --max-elements`); the command line has no such limit",
                limits.max_elements
            ),
        ));
    }
    if let Some((path, n)) = longest_string(doc, String::new(), limits.max_expression_length) {
        return Err(Problem::limit(
            "max_expression_length",
            limits.max_expression_length,
            format!(
                "{path}: a string of {n} bytes, over the limit max_expression_length = {}",
                limits.max_expression_length
            ),
        )
        .with("path", path));
    }
    Ok(())
}

/// The scene's lists counted against `max_elements`, besides a bond graph's elements and bonds.
pub const ELEMENT_LISTS: [&str; 7] = [
    "bodies", "joints", "springs", "loads", "outputs", "events", "drivers",
];

/// Keys whose strings are free text, not expressions or names: bounded by `max_body` only.
const FREE_TEXT: [&str; 2] = ["description", "comment"];

/// The path and length of the first string (or key) longer than `max`, free text aside.
fn longest_string(v: &Value, path: String, max: usize) -> Option<(String, usize)> {
    match v {
        Value::String(s) if s.len() > max => Some((path, s.len())),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| longest_string(x, format!("{path}[{i}]"), max)),
        Value::Object(m) => m
            .iter()
            .filter(|(k, _)| !FREE_TEXT.contains(&k.as_str()))
            .find_map(|(k, x)| {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                if k.len() > max {
                    Some((p, k.len()))
                } else {
                    longest_string(x, p, max)
                }
            }),
        _ => None,
    }
}

/// The number of rows a run of `scene` writes, up to `t_end` when given (the rule of
/// [`crate::model::Model::output_times_until`]), computed without building the list of times.
pub fn row_count(scene: &Scene, t_end: Option<f64>) -> f64 {
    let s = &scene.solve;
    let t0 = s.t_start;
    let t1 = t_end.unwrap_or(s.t_end);
    match &s.output_times {
        Some(times) => times.iter().filter(|&&t| t <= t1).count() as f64,
        None => {
            let h = s.output_step.unwrap_or((t1 - t0) / 100.0);
            ((t1 - t0) / h - 1e-9).ceil().max(1.0) + 1.0
        }
    }
}

/// 422 naming `max_rows` when a run of `scene` would write more rows than allowed.
pub fn check_rows(scene: &Scene, t_end: Option<f64>, limits: &Limits) -> Result<(), Problem> {
    let n = row_count(scene, t_end);
    if n.is_nan() || n > limits.max_rows as f64 {
        return Err(Problem::limit(
            "max_rows",
            limits.max_rows,
            format!(
                "the run would write {n:.0} output rows, over the limit max_rows = {} (raise solve.output_step or lower t_end)",
                limits.max_rows
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(solve: &str) -> Scene {
        Scene::from_json_str(&format!(
            r#"{{"bodies": [{{"name": "b", "mass": 1, "inertia": 1}}], "solve": {solve}}}"#
        ))
        .unwrap()
    }

    #[test]
    fn row_count_is_the_length_of_the_output_times() {
        for (solve, t_end) in [
            (r#"{"t_end": 1, "output_step": 0.1}"#, None),
            (r#"{"t_end": 1, "output_step": 0.3}"#, None),
            (r#"{"t_end": 1}"#, None),
            (r#"{"t_end": 2, "t_start": 0.5, "output_step": 0.25}"#, None),
            (r#"{"t_end": 1, "output_times": [0.5, 1]}"#, None),
            (r#"{"t_end": 1, "output_step": 0.1}"#, Some(0.35)),
            (r#"{"t_end": 3, "output_times": [0.5, 1, 2, 3]}"#, Some(1.5)),
        ] {
            let s = scene(solve);
            let model = crate::model::Model::new(&s).unwrap();
            let times = match t_end {
                Some(t) => model.output_times_until(t).unwrap(),
                None => model.default_options().output_times,
            };
            assert_eq!(
                row_count(&s, t_end),
                times.len() as f64,
                "{solve} {t_end:?}"
            );
        }
    }

    #[test]
    fn long_strings_are_found_with_their_path_free_text_aside() {
        let doc: Value = serde_json::json!({
            "description": "x".repeat(100),
            "loads": [{"value": ["0", "y".repeat(50)], "comment": "z".repeat(100)}]
        });
        assert_eq!(
            longest_string(&doc, String::new(), 20),
            Some(("loads[0].value[1]".to_string(), 50))
        );
        assert_eq!(longest_string(&doc, String::new(), 50), None);
    }
}
