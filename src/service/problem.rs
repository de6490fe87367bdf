//! Errors as `application/problem+json` (RFC 9457): a `type` URI, a `title` per type, the HTTP
//! `status`, a `detail` for this occurrence, and extension members (`errors`, `limit`,
//! `t_reached`, `columns`, `rows`, `parameter`, `line`, `column`).

use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use serde_json::{Map, Value};

/// The media type of every error body (RFC 9457 §3).
pub const PROBLEM_JSON: &str = "application/problem+json";

/// One problem: status, type, title, detail and extension members.
#[derive(Clone, Debug)]
pub struct Problem {
    /// HTTP status code.
    pub status: StatusCode,
    /// Short name of the problem type; the `type` member is `urn:bondmech:problem:<kind>`.
    pub kind: &'static str,
    /// Human-readable summary of the problem type (the same for every occurrence).
    pub title: &'static str,
    /// What went wrong in this request.
    pub detail: String,
    /// Extension members (RFC 9457 §3.2).
    pub extra: Map<String, Value>,
    /// Seconds for a `Retry-After` header (503 responses).
    pub retry_after: Option<u64>,
}

impl Problem {
    /// A problem of `kind` with `status`, `title` and `detail`.
    pub fn new(
        status: StatusCode,
        kind: &'static str,
        title: &'static str,
        detail: impl Into<String>,
    ) -> Problem {
        Problem {
            status,
            kind,
            title,
            detail: detail.into(),
            extra: Map::new(),
            retry_after: None,
        }
    }

    /// Adds the extension member `key`.
    pub fn with(mut self, key: &str, value: impl Into<Value>) -> Problem {
        self.extra.insert(key.to_string(), value.into());
        self
    }

    /// 400: a query parameter that is unknown, repeated or not parseable.
    pub fn bad_parameter(parameter: &str, detail: impl Into<String>) -> Problem {
        Problem::new(
            StatusCode::BAD_REQUEST,
            "invalid-parameter",
            "Invalid query parameter",
            detail,
        )
        .with("parameter", parameter)
    }

    /// 422: a request over one of the server's limits, named in `limit` with its value.
    pub fn limit(limit: &str, value: impl Into<Value>, detail: impl Into<String>) -> Problem {
        Problem::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "limit-exceeded",
            "Request over a server limit",
            detail,
        )
        .with("limit", limit)
        .with("limit_value", value)
    }

    /// 503 with `Retry-After`: no solve slot and no room in the queue (or shutting down).
    pub fn unavailable(detail: impl Into<String>, retry_after: u64) -> Problem {
        let mut p = Problem::new(
            StatusCode::SERVICE_UNAVAILABLE,
            "unavailable",
            "Service unavailable",
            detail,
        );
        p.retry_after = Some(retry_after);
        p
    }

    /// 500: a bug (a panic caught in a solve); never caused by bad input.
    pub fn internal(detail: impl Into<String>) -> Problem {
        Problem::new(
            StatusCode::INTERNAL_SERVER_ERROR,
            "internal",
            "Internal server error",
            detail,
        )
    }

    /// The JSON object of the problem.
    pub fn to_json(&self) -> Value {
        let mut m = Map::new();
        m.insert(
            "type".into(),
            format!("urn:bondmech:problem:{}", self.kind).into(),
        );
        m.insert("title".into(), self.title.into());
        m.insert("status".into(), self.status.as_u16().into());
        m.insert("detail".into(), self.detail.clone().into());
        for (k, v) in &self.extra {
            m.insert(k.clone(), v.clone());
        }
        Value::Object(m)
    }
}

impl IntoResponse for Problem {
    fn into_response(self) -> Response {
        let body = serde_json::to_vec(&self.to_json()).unwrap_or_default();
        let mut r = (self.status, body).into_response();
        r.headers_mut()
            .insert(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON));
        if let Some(s) = self.retry_after {
            r.headers_mut()
                .insert(header::RETRY_AFTER, HeaderValue::from(s));
        }
        r
    }
}
