//! Admission: a request's CPU work before it takes a solve slot — the body parsed as JSON,
//! checked against the [`Limits`], read and validated as a scene, the query applied, the cost
//! estimated — runs on the blocking pool, never on the async runtime's worker threads (issue
//! 51). Those two threads drive every connection: work done there (a scene of the largest
//! allowed body takes milliseconds to parse and validate) delays every other request's future,
//! short ones included, by as long. Only reading the body (I/O) and waiting for a slot happen
//! on the async side.

use axum::body::Body;
use axum::http::{HeaderMap, StatusCode};

use super::limits::{check_document, parse_json, read_body, Limits};
use super::problem::Problem;
use super::solve::invalid_scene;
use super::App;
use crate::scene::Scene;

/// Reads the body (async), then on the blocking pool parses and validates the scene in it,
/// checks it against the limits and hands it to `then` (the route's own checks and
/// estimates), whose result is returned.
pub(super) async fn scene<T: Send + 'static>(
    app: &App,
    headers: &HeaderMap,
    body: Body,
    then: impl FnOnce(Scene, &Limits) -> Result<T, Problem> + Send + 'static,
) -> Result<T, Problem> {
    let bytes = read_body(headers, body, &app.limits).await?;
    let limits = app.limits.clone();
    tokio::task::spawn_blocking(move || {
        let scene = parse_scene(&bytes, &limits)?;
        then(scene, &limits)
    })
    .await
    .unwrap_or_else(|e| {
        Err(Problem::internal(format!(
            "the admission job was lost: {e}"
        )))
    })
}

/// The scene in `bytes`: 400 for malformed JSON or text that is not UTF-8, 422 over a limit or
/// for an invalid scene (every problem with its JSON path).
pub(super) fn parse_scene(bytes: &[u8], limits: &Limits) -> Result<Scene, Problem> {
    let doc = parse_json(bytes)?;
    check_document(&doc, limits)?;
    let text = std::str::from_utf8(bytes).map_err(|e| {
        Problem::new(
            StatusCode::BAD_REQUEST,
            "malformed-json",
            "Malformed JSON",
            format!("the body is not UTF-8: {e}"),
        )
    })?;
    Scene::from_json_str(text).map_err(|e| {
        let problems: Vec<(String, String)> = e
            .problems()
            .iter()
            .map(|p| (p.path.clone(), p.message.clone()))
            .collect();
        if problems.is_empty() {
            invalid_scene([(String::new(), e.to_string())])
        } else {
            invalid_scene(problems)
        }
    })
}
