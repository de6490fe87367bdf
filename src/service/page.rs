//! The playground (`GET /`): one page to work in — pick a bundled scene, edit it with
//! validation as you type, run, compare, scrub the animation, look at the bond graph (issue 37).
//!
//! The page is three files compiled into the binary (`assets/playground.{html,js,css}`), plus
//! the 3D view's renderer of `bondmech animate --out FILE.html` (`/view3d.js`), all
//! served by the service itself under a Content-Security-Policy that allows nothing outside
//! the origin ([`CSP`]): no CDN, no network, no inline script. The page draws only what the
//! service returns (`/v1/run`'s rows as polylines, `/v1/animate`'s SVG or 3D view data,
//! `/v1/graph`'s SVG);
//! every text that comes from a scene is inserted as text, never as markup.
//!
//! Also here, the routes the page needs and any client may use: `GET /v1/scenes` (the bundled
//! scenes' names), `GET /v1/scenes/{name}` (one scene's JSON), `POST /v1/validate` (the
//! command line's validation problems, always 200) — none of them take a solve slot, so they
//! answer while every slot is busy.

use std::sync::Arc;

use axum::body::Body;
use axum::extract::{Path, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};

use super::problem::Problem;
use super::App;

/// The bundled scenes, `(name, JSON text)` sorted by name: every `scenes/*.json` of the source
/// tree, embedded at compile time by `build.rs` so that an installed binary (which has no
/// checkout next to it) serves them too.
pub const BUNDLED_SCENES: &[(&str, &str)] =
    include!(concat!(env!("OUT_DIR"), "/bundled_scenes.rs"));

/// The page's Content-Security-Policy: scripts, styles, pictures and requests from the origin
/// only; no plugins, frames, `<base>` or form posts anywhere.
pub const CSP: &str =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; \
    connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

const HTML: &str = include_str!("assets/playground.html");
const JS: &str = include_str!("assets/playground.js");
const CSS: &str = include_str!("assets/playground.css");

fn asset(text: &'static str, content_type: &'static str) -> Response {
    let mut r = Response::new(Body::from(text));
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    h.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(CSP),
    );
    h.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    h.insert(
        header::REFERRER_POLICY,
        HeaderValue::from_static("no-referrer"),
    );
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    r
}

/// `GET /`: the page.
pub(super) async fn index() -> Response {
    asset(HTML, "text/html; charset=utf-8")
}

/// `GET /playground.js`.
pub(super) async fn script() -> Response {
    asset(JS, "text/javascript; charset=utf-8")
}

/// `GET /view3d.js`: the 3D view's renderer, the one `bondmech animate --out FILE.html`
/// inlines ([`crate::report::animate::view3d_script`]).
pub(super) async fn view3d_script() -> Response {
    asset(
        crate::report::animate::view3d_script(),
        "text/javascript; charset=utf-8",
    )
}

/// `GET /playground.css`.
pub(super) async fn style() -> Response {
    asset(CSS, "text/css; charset=utf-8")
}

fn json(body: String) -> Response {
    let mut r = Response::new(Body::from(body));
    r.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/json"),
    );
    r
}

/// `GET /v1/scenes`: the bundled scenes' names (file names without `.json`), sorted.
pub(super) async fn scenes() -> Response {
    let names: Vec<&str> = BUNDLED_SCENES.iter().map(|(n, _)| *n).collect();
    json(serde_json::to_string(&names).unwrap_or_default())
}

/// `GET /v1/scenes/{name}`: the scene file's JSON, byte for byte; 404 naming the scenes for
/// any other name.
pub(super) async fn scene(Path(name): Path<String>) -> Response {
    match BUNDLED_SCENES.iter().find(|(n, _)| *n == name) {
        Some((_, text)) => json(text.to_string()),
        None => Problem::new(
            StatusCode::NOT_FOUND,
            "not-found",
            "No such scene",
            format!(
                "no bundled scene '{name}' (GET /v1/scenes lists them: {})",
                BUNDLED_SCENES
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
        .into_response(),
    }
}

/// `POST /v1/validate`: the scene checked as `/v1/run` checks it (JSON, limits, the scene's
/// rules), without solving. Always 200 (a page validating as you type logs no failed request):
/// `{"valid": true}` or `{"valid": false, "errors": [{path, message}], "line"?, "column"?}`,
/// the paths and messages those of the command line (`bodies[0].mass: must be > 0`).
pub(super) async fn validate(
    State(app): State<Arc<App>>,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let answer = match check(&app, &headers, body).await {
        Ok(()) => serde_json::json!({"valid": true, "errors": []}),
        Err(p) => {
            let doc = p.to_json();
            let errors = match doc.get("errors").and_then(|e| e.as_array()) {
                Some(list) if !list.is_empty() => serde_json::Value::from(list.clone()),
                _ => {
                    serde_json::json!([{"path": doc.get("limit").cloned().unwrap_or_default(), "message": p.detail}])
                }
            };
            let mut a = serde_json::json!({"valid": false, "errors": errors});
            for key in ["line", "column"] {
                if let Some(v) = doc.get(key) {
                    a[key] = v.clone();
                }
            }
            a
        }
    };
    json(answer.to_string())
}

async fn check(app: &App, headers: &HeaderMap, body: Body) -> Result<(), Problem> {
    super::routes::scene_from(app, headers, body)
        .await
        .map(drop)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded list is the `scenes/` directory: every file, under its name, with its text.
    #[test]
    fn bundled_scenes_are_the_scenes_directory() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter_map(|n| n.strip_suffix(".json").map(str::to_string))
            .collect();
        files.sort();
        let names: Vec<&str> = BUNDLED_SCENES.iter().map(|(n, _)| *n).collect();
        assert_eq!(names, files);
        for (n, text) in BUNDLED_SCENES {
            let on_disk = std::fs::read_to_string(dir.join(format!("{n}.json"))).unwrap();
            assert_eq!(*text, on_disk, "{n}");
        }
    }

    /// The policy names no other origin and allows no inline script.
    #[test]
    fn the_policy_allows_only_the_origin() {
        for directive in CSP.split(';') {
            for source in directive.split_whitespace().skip(1) {
                assert!(
                    ["'self'", "'none'", "data:"].contains(&source),
                    "{directive}"
                );
            }
        }
        assert!(CSP.contains("default-src 'none'") && CSP.contains("script-src 'self'"));
    }
}
