//! The handlers: each checks its query on the async side, reads the body there, has the scene
//! parsed, validated and checked against the limits on the blocking pool ([`super::admit`]),
//! takes a solve slot, and does the work on a blocking thread through the library's
//! [`crate::model::Model`] API.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use axum::body::{Body, Bytes};
use axum::extract::{RawQuery, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use tokio::sync::{mpsc, oneshot};

use super::body::ChannelBody;
use super::limits::check_rows;
use super::metrics::Rejection;
use super::pool::{join, CancelOnDrop, StopFlags};
use super::problem::Problem;
use super::solve::{
    invalid_scene, invalid_value, library_problem, solution_json, solve_rows, Budget, Params,
    SolveParams, TimedRow, SOLVE_PARAMS,
};
use super::App;
use crate::model::Model;
use crate::report::SweepConfig;
use crate::scene::Scene;

/// The routes, for metrics labels and the 404 answer.
pub const ROUTES: [&str; 19] = [
    "/healthz",
    "/metrics",
    "/openapi.json",
    "/v1/run",
    "/v1/compare",
    "/v1/graph",
    "/v1/equilibrium",
    "/v1/linearize",
    "/v1/sensitivity",
    "/v1/fit",
    "/v1/sweep",
    "/v1/animate",
    "/v1/validate",
    "/v1/scenes",
    "/v1/scenes/{name}",
    "/",
    "/playground.js",
    "/playground.css",
    "other",
];

fn route_label(path: &str) -> &'static str {
    if path
        .strip_prefix("/v1/scenes/")
        .is_some_and(|n| !n.is_empty())
    {
        return "/v1/scenes/{name}";
    }
    ROUTES
        .iter()
        .copied()
        .find(|r| *r == path)
        .unwrap_or("other")
}

/// A request id: the client's `X-Request-Id` when it is a short printable token, else a new
/// one (process-unique: the start time and a counter).
fn request_id(headers: &HeaderMap) -> String {
    use std::sync::atomic::AtomicU64;
    static NEXT: AtomicU64 = AtomicU64::new(0);
    if let Some(v) = headers.get("x-request-id").and_then(|v| v.to_str().ok()) {
        let v = v.trim();
        if !v.is_empty()
            && v.len() <= 128
            && v.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.:/+=".contains(c))
        {
            return v.to_string();
        }
    }
    static START: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    let start = *START.get_or_init(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_micros() as u64)
    });
    format!("{start:x}-{:x}", NEXT.fetch_add(1, Ordering::Relaxed))
}

/// Counts every answer by route and status, times it (per-route latency histogram), gives it
/// a request id (`X-Request-Id`: the client's, or a new one; echoed on the answer and logged
/// with every error answer), and counts the requests being answered (a drain waits for them).
pub async fn count_requests(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    let route = route_label(req.uri().path());
    let id = request_id(req.headers());
    let counted = !matches!(route, "/healthz" | "/metrics");
    if counted {
        app.metrics.active_requests.fetch_add(1, Ordering::SeqCst);
    }
    struct Active<'a>(&'a App, bool);
    impl Drop for Active<'_> {
        fn drop(&mut self) {
            if self.1 {
                self.0
                    .metrics
                    .active_requests
                    .fetch_sub(1, Ordering::SeqCst);
            }
        }
    }
    let _active = Active(&app, counted);
    let start = std::time::Instant::now();
    let query_len = req.uri().query().map_or(0, str::len);
    let mut resp = if query_len > MAX_QUERY_BYTES {
        query_too_long(query_len).into_response()
    } else {
        next.run(req).await
    };
    let status = resp.status().as_u16();
    app.metrics.request(route, status);
    app.metrics
        .observe_latency(route, start.elapsed().as_secs_f64());
    if let Ok(v) = HeaderValue::from_str(&id) {
        resp.headers_mut().insert("x-request-id", v);
    }
    if status >= 500 || (status >= 400 && route != "other") {
        eprintln!(
            "bondmech: request {id} {} → {status} ({:.3} s)",
            route,
            start.elapsed().as_secs_f64()
        );
    }
    resp
}

/// Longest query string a request may carry, in bytes: the routes take a few short
/// parameters. (A request line over 64 KiB is refused before any route sees it, by the HTTP
/// layer, with a bare `414 URI Too Long`.)
pub const MAX_QUERY_BYTES: usize = 8192;

/// 414 for a query string over [`MAX_QUERY_BYTES`], naming the limit and what the routes take.
fn query_too_long(len: usize) -> Problem {
    Problem::new(
        StatusCode::URI_TOO_LONG,
        "query-too-long",
        "Query string too long",
        format!(
            "the query string is {len} bytes, over the limit of {MAX_QUERY_BYTES} bytes: the routes take a few short parameters (rtol, t_end, format, …; see /openapi.json), the scene goes in the body"
        ),
    )
    .with("limit", "max_query_bytes")
    .with("limit_value", MAX_QUERY_BYTES)
}

/// Turns a handler's result into a response, counting refusals.
fn respond(app: &App, r: Result<Response, Problem>) -> Response {
    match r {
        Ok(resp) => resp,
        Err(p) => {
            match p.kind {
                "body-too-large" => app.metrics.reject(Rejection::BodyTooLarge),
                "limit-exceeded" => app.metrics.reject(Rejection::Limit),
                "unavailable" => app.metrics.reject(Rejection::Saturated),
                "shutting-down" => app.metrics.reject(Rejection::ShuttingDown),
                _ => {}
            }
            p.into_response()
        }
    }
}

fn with_type(body: impl Into<Body>, content_type: &'static str) -> Response {
    let mut r = Response::new(body.into());
    r.headers_mut()
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    r
}

const JSON: &str = "application/json";
const NDJSON: &str = "application/x-ndjson";

/// 503 while shutting down: new work is refused, in-flight work finishes.
fn not_shutting_down(app: &App) -> Result<(), Problem> {
    if app.shutting_down.load(Ordering::SeqCst) {
        let mut p = Problem::unavailable(
            "the server is shutting down and takes no new work",
            app.retry_after,
        );
        p.kind = "shutting-down";
        return Err(p);
    }
    Ok(())
}

/// Reads the body, then parses and validates the scene in it and checks it against the
/// limits on the blocking pool ([`super::admit`]).
pub(super) async fn scene_from(
    app: &App,
    headers: &HeaderMap,
    body: Body,
) -> Result<Scene, Problem> {
    super::admit::scene(app, headers, body, |scene, _| Ok(scene)).await
}

/// `GET /healthz`: version and the linked SUNDIALS; 503 while shutting down (readiness).
pub async fn healthz(State(app): State<Arc<App>>) -> Response {
    if let Err(p) = not_shutting_down(&app) {
        return p.into_response();
    }
    let (ma, mi, pa) = crate::sundials::version::version();
    let body = serde_json::json!({
        "status": "ok",
        "version": env!("CARGO_PKG_VERSION"),
        "sundials": format!("{ma}.{mi}.{pa}"),
        "sundials_headers": crate::sundials::version::header_version(),
    });
    with_type(body.to_string(), JSON)
}

/// `GET /metrics`: Prometheus text format.
pub async fn metrics(State(app): State<Arc<App>>) -> Response {
    with_type(
        app.metrics.render(),
        "text/plain; version=0.0.4; charset=utf-8",
    )
}

/// `GET /openapi.json`.
pub async fn openapi() -> Response {
    with_type(super::openapi::document().to_string(), JSON)
}

/// 404 for any other path.
pub async fn not_found(req: Request) -> Response {
    Problem::new(
        StatusCode::NOT_FOUND,
        "not-found",
        "No such route",
        format!(
            "no route {} (routes: {}; see /openapi.json)",
            req.uri().path(),
            ROUTES[..ROUTES.len() - 1].join(", ")
        ),
    )
    .into_response()
}

/// 405 for a known path with the wrong method.
pub async fn method_not_allowed(req: Request) -> Response {
    Problem::new(
        StatusCode::METHOD_NOT_ALLOWED,
        "method-not-allowed",
        "Method not allowed",
        format!(
            "{} does not take {} (see /openapi.json)",
            req.uri().path(),
            req.method()
        ),
    )
    .into_response()
}

/// `POST /v1/run`.
pub async fn run(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = run_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn run_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let mut allowed = SOLVE_PARAMS.to_vec();
    allowed.extend(["format", "animate"]);
    let params = Params::parse(q.as_deref(), &allowed)?;
    let format = params.choice("format", &["json", "csv", "ndjson"])?;
    let animate = animate_param(&params, format)?;
    let solve = SolveParams::from(&params)?;
    let (scene, cost) = admit_solve(app, headers, body, solve).await?;
    let slot = app.pool.acquire_for(cost).await?;
    let stop = app.stop_flags();
    let mut guard = CancelOnDrop::new(&stop);
    if format == "ndjson" {
        let r = run_ndjson(app, slot, scene, stop, animate).await;
        guard.disarm();
        return r;
    }
    let app2 = app.clone();
    let job = app.pool.spawn(slot, move || {
        let mut partial: Vec<Vec<f64>> = Vec::new();
        let r = solve_rows(
            &scene,
            &app2.limits,
            &stop,
            &app2.metrics,
            &mut |_, _| {},
            &mut |t, v| {
                let mut row = Vec::with_capacity(v.len() + 1);
                row.push(t);
                row.extend_from_slice(v);
                partial.push(row);
                true
            },
        );
        match r {
            Ok(sol) if format == "csv" => Ok(with_type(sol.to_csv(), "text/csv; charset=utf-8")),
            Ok(sol) => Ok(with_type(solution_json(&sol), JSON)),
            Err(f) => Err(match f.columns {
                Some(c) => f
                    .problem
                    .with("columns", c)
                    .with("rows", f.partial.unwrap_or(partial)),
                None => *f.problem,
            }),
        }
    });
    let r = join(job).await;
    guard.disarm();
    r
}

/// The scene of a solving route with its query applied, and its estimated cost, made on the
/// blocking pool ([`super::admit`]): the server's row limit first (it counts the rows without
/// making them), then the scene's own rules on the query's values.
async fn admit_solve(
    app: &App,
    headers: &HeaderMap,
    body: Body,
    solve: SolveParams,
) -> Result<(Scene, f64), Problem> {
    super::admit::scene(app, headers, body, move |mut scene, limits| {
        check_rows(&scene, solve.overrides.t_end, limits)?;
        solve.apply_to_scene(&mut scene)?;
        let cost = super::pool::estimated_cost(&scene);
        Ok((scene, cost))
    })
    .await
}

/// Sends one NDJSON line; `false` when the client has gone.
fn send_line(tx: &mpsc::Sender<Bytes>, v: &impl serde::Serialize) -> bool {
    let mut line = serde_json::to_vec(v).unwrap_or_default();
    line.push(b'\n');
    tx.blocking_send(Bytes::from(line)).is_ok()
}

/// A streamed answer: 200 and the lines once the job has produced its first one (`started`),
/// or the problem the job met before that.
async fn stream_response(
    started: oneshot::Receiver<Result<(), Problem>>,
    rx: mpsc::Receiver<Bytes>,
) -> Result<Response, Problem> {
    match started.await {
        Ok(Ok(())) => Ok(with_type(
            Body::new(ChannelBody::new(Vec::new(), rx)),
            NDJSON,
        )),
        Ok(Err(p)) => Err(p),
        Err(_) => Err(Problem::internal("the solve job ended without an answer")),
    }
}

/// The animation a streamed run or comparison is asked for (`animate=svg|view3d`): drawn from
/// the solve's own rows, so that the page needs no second solve. Only with `format=ndjson`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Animate {
    /// The SMIL-animated SVG of `/v1/animate` (a planar or a spatial scene).
    Svg,
    /// The 3D view's data of `/v1/animate?format=view3d` (a spatial scene).
    View3d,
}

fn animate_param(params: &Params, format: &str) -> Result<Option<Animate>, Problem> {
    let Some(a) = params.text("animate") else {
        return Ok(None);
    };
    let a = match a {
        "svg" => Animate::Svg,
        "view3d" => Animate::View3d,
        other => {
            return Err(Problem::bad_parameter(
                "animate",
                format!("animate: expected svg or view3d (got '{other}')"),
            ))
        }
    };
    if format != "ndjson" {
        return Err(invalid_value(
            "animate",
            format!("animate: the animation is sent as a line of the stream: it needs format=ndjson (got format={format})"),
        ));
    }
    Ok(Some(a))
}

/// The NDJSON line `{"<key>": {"format": "svg", "svg": "<svg…>"}}` or
/// `{"<key>": {"format": "view3d", "data": {…}}}` of the motion in `sol` (its own rows, poses
/// interpolated between rows further apart than the animation allows), or
/// `{"<key>": {"error": <problem>}}` when it cannot be drawn (a raw bond graph, a planar
/// scene asked for view3d).
pub fn animation_line(scene: &Scene, sol: &crate::Solution, animate: Animate, key: &str) -> Bytes {
    use crate::report::animate::{animation, view3d_json, AnimationFormat, AnimationOptions};
    let aopts = AnimationOptions {
        source: "the solution".into(),
        ..AnimationOptions::default()
    };
    let refused = |detail: String| {
        let p = invalid_value("animate", detail);
        serde_json::json!({ key: {"error": p.to_json()} })
    };
    let mut line = if scene.bodies.is_empty() {
        serde_json::to_vec(&refused(
            "animate: a raw bond graph has no geometry to draw".into(),
        ))
    } else {
        match animate {
            Animate::View3d if scene.dimension != crate::scene::Dimension::Spatial => {
                serde_json::to_vec(&refused(
                    "animate=view3d: the 3D view needs a spatial scene (\"dimension\": 3); a planar scene is drawn as SVG (animate=svg)".into(),
                ))
            }
            Animate::View3d => match view3d_json(scene, sol, &aopts) {
                Ok(data) => {
                    let mut v = format!("{{\"{key}\":{{\"format\":\"view3d\",\"data\":")
                        .into_bytes();
                    v.extend_from_slice(data.trim_end().as_bytes());
                    v.extend_from_slice(b"}}");
                    Ok(v)
                }
                Err(e) => serde_json::to_vec(&refused(format!("animate: {e}"))),
            },
            Animate::Svg => match animation(scene, sol, &aopts, AnimationFormat::Svg) {
                Ok(svg) => {
                    serde_json::to_vec(&serde_json::json!({ key: {"format": "svg", "svg": svg} }))
                }
                Err(e) => serde_json::to_vec(&refused(format!("animate: {e}"))),
            },
        }
    }
    .unwrap_or_default();
    line.push(b'\n');
    Bytes::from(line)
}

async fn run_ndjson(
    app: &Arc<App>,
    slot: tokio::sync::OwnedSemaphorePermit,
    scene: Scene,
    stop: StopFlags,
    animate: Option<Animate>,
) -> Result<Response, Problem> {
    let (tx, rx) = mpsc::channel::<Bytes>(64);
    let (started_tx, started_rx) = oneshot::channel();
    let app2 = app.clone();
    // detached: the job ends by itself (finished, budget, or its channel closed)
    drop(app.pool.spawn(slot, move || {
        let mut started = Some(started_tx);
        let r = solve_rows(
            &scene,
            &app2.limits,
            &stop,
            &app2.metrics,
            &mut |columns, rows| {
                send_line(&tx, &serde_json::json!({"columns": columns, "rows": rows}));
            },
            &mut |t, v| {
                let ok = send_line(&tx, &TimedRow(t, v));
                if let Some(s) = started.take() {
                    let _ = s.send(Ok(()));
                }
                ok
            },
        );
        match r {
            Ok(sol) => {
                if let Some(a) = animate {
                    let _ = tx.blocking_send(animation_line(&scene, &sol, a, "animation"));
                }
                send_line(&tx, &serde_json::json!({"summary": sol.summary}));
            }
            Err(f) if f.cancelled => {}
            Err(f) => match started.take() {
                Some(s) => {
                    let _ = s.send(Err(*f.problem));
                }
                None => {
                    send_line(&tx, &serde_json::json!({"error": f.problem.to_json()}));
                }
            },
        }
        Ok(())
    }));
    stream_response(started_rx, rx).await
}

/// `POST /v1/compare`: the DAE and the decoupled twin, the `compare --json` document.
pub async fn compare(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = compare_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn compare_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let mut allowed = SOLVE_PARAMS.to_vec();
    allowed.extend(["format", "animate"]);
    let params = Params::parse(q.as_deref(), &allowed)?;
    let format = params.choice("format", &["json", "ndjson"])?;
    let animate = animate_param(&params, format)?;
    let solve = SolveParams::from(&params)?;
    let (scene, _) = admit_solve(app, headers, body, solve).await?;
    let slot = app.pool.acquire().await?;
    if format == "ndjson" {
        return compare_ndjson(app, slot, scene, animate).await;
    }
    let limits = app.limits.clone();
    let job = app.pool.spawn(slot, move || {
        let budget = Budget::of(&scene, &limits);
        let model = Model::new(&scene).map_err(|e| library_problem(&e, budget))?;
        // two solves: each gets half of the budget
        let half = Budget {
            seconds: budget.seconds / 2.0,
            limit: budget.limit,
        };
        let opts = super::solve::options(&model, half, &limits)?;
        let (cmp, _, _) = model
            .compare(&opts)
            .map_err(|e| library_problem(&e, half))?;
        let text = serde_json::to_vec_pretty(&cmp)
            .map_err(|e| Problem::internal(format!("the comparison does not serialise: {e}")))?;
        Ok(with_type(text, JSON))
    });
    join(job).await
}

/// `POST /v1/compare?format=ndjson`: the two solves streamed as progress lines
/// `{"progress": {"solve": "dae"|"twin", "rows": k, "of": n}}`, then the twin's own run
/// `{"twin": {"columns", "rows", "summary"}}`, with `animate=svg|view3d` the twin's motion drawn
/// from those rows (`{"twin_animation": …}`), and last `{"compare": <the compare --json
/// document>}` — one solve of each, so a page needs nothing else for the comparison. A failure
/// after the first line ends the stream with `{"error": <problem>}`.
async fn compare_ndjson(
    app: &Arc<App>,
    slot: tokio::sync::OwnedSemaphorePermit,
    scene: Scene,
    animate: Option<Animate>,
) -> Result<Response, Problem> {
    let (tx, rx) = mpsc::channel::<Bytes>(64);
    let (started_tx, started_rx) = oneshot::channel();
    let limits = app.limits.clone();
    let metrics = app.metrics.clone();
    let shutdown = app.stop_flags().shutdown;
    drop(app.pool.spawn(slot, move || {
        let mut started = Some(started_tx);
        let fail =
            |p: Problem, started: &mut Option<oneshot::Sender<Result<(), Problem>>>| match started
                .take()
            {
                Some(s) => {
                    let _ = s.send(Err(p));
                }
                None => {
                    send_line(&tx, &serde_json::json!({"error": p.to_json()}));
                }
            };
        let budget = Budget::of(&scene, &limits);
        let model = match Model::new(&scene) {
            Ok(m) => m,
            Err(e) => {
                fail(library_problem(&e, budget), &mut started);
                return Ok(());
            }
        };
        if model.is_raw_bond_graph() {
            let e = crate::Error::Options(
                "compare needs bodies and joints (a raw bond graph has no decoupled twin)".into(),
            );
            fail(library_problem(&e, budget), &mut started);
            return Ok(());
        }
        // two solves: each gets half of the budget
        let half = Budget {
            seconds: budget.seconds / 2.0,
            limit: budget.limit,
        };
        let opts = match super::solve::options(&model, half, &limits) {
            Ok(o) => o,
            Err(p) => {
                fail(p, &mut started);
                return Ok(());
            }
        };
        let mut a = opts.clone();
        if a.formulation == crate::FormulationKind::Decoupled {
            a.formulation = crate::FormulationKind::Dae;
        }
        let mut b = opts.clone();
        b.formulation = crate::FormulationKind::Decoupled;
        let n = opts.output_times.len();
        let every = (n / 50).max(1);
        let mut solutions = Vec::with_capacity(2);
        for (name, o) in [("dae", &a), ("twin", &b)] {
            if !send_line(
                &tx,
                &serde_json::json!({"progress": {"solve": name, "rows": 0, "of": n}}),
            ) {
                return Ok(());
            }
            if let Some(s) = started.take() {
                let _ = s.send(Ok(()));
            }
            let mut k = 0usize;
            let mut gone = false;
            let r = model.solve_streaming(o, &mut |_| {
                k += 1;
                if k.is_multiple_of(every)
                    && !send_line(
                        &tx,
                        &serde_json::json!({"progress": {"solve": name, "rows": k, "of": n}}),
                    )
                {
                    gone = true;
                }
                if gone || tx.is_closed() || shutdown.load(Ordering::SeqCst) {
                    std::ops::ControlFlow::Break(())
                } else {
                    std::ops::ControlFlow::Continue(())
                }
            });
            if gone || tx.is_closed() {
                metrics.cancelled();
                return Ok(());
            }
            if !k.is_multiple_of(every) {
                send_line(
                    &tx,
                    &serde_json::json!({"progress": {"solve": name, "rows": k, "of": n}}),
                );
            }
            match r {
                Ok(_) if shutdown.load(Ordering::SeqCst) => {
                    fail(
                        Problem::unavailable(
                            "the server is shutting down: the comparison was stopped",
                            1,
                        ),
                        &mut started,
                    );
                    return Ok(());
                }
                Ok(sol) => solutions.push(sol),
                Err(e) => {
                    fail(library_problem(&e, half), &mut started);
                    return Ok(());
                }
            }
        }
        let (dec, dae) = (solutions.pop(), solutions.pop());
        let (Some(dae), Some(dec)) = (dae, dec) else {
            return Ok(());
        };
        let cmp = crate::Comparison::judged(&dae, &dec, (a.rtol, a.atol));
        let mut twin = b"{\"twin\":".to_vec();
        twin.extend_from_slice(&solution_json(&dec));
        twin.extend_from_slice(b"}\n");
        if tx.blocking_send(Bytes::from(twin)).is_err() {
            return Ok(());
        }
        if let Some(an) = animate {
            let _ = tx.blocking_send(animation_line(&scene, &dec, an, "twin_animation"));
        }
        send_line(&tx, &serde_json::json!({ "compare": cmp }));
        Ok(())
    }));
    stream_response(started_rx, rx).await
}

/// `POST /v1/graph?format=dot|svg|causality&decoupled=false&collapse=true|false`.
pub async fn graph(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = graph_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn graph_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let params = Params::parse(q.as_deref(), &["format", "decoupled", "collapse"])?;
    let format = params.choice("format", &["dot", "svg", "causality"])?;
    let decoupled = params.flag("decoupled")?.unwrap_or(false);
    // one node per body or joint (`true`), every element (`false`), or by the graph's size
    let collapse = params.flag("collapse")?;
    let scene = scene_from(app, headers, body).await?;
    let slot = app.pool.acquire_for(0.0).await?;
    let limits = app.limits.clone();
    let job = app.pool.spawn(slot, move || {
        let budget = Budget::of(&scene, &limits);
        let model = Model::new(&scene).map_err(|e| library_problem(&e, budget))?;
        let variant = if decoupled {
            crate::mech::Variant::Decoupled
        } else {
            crate::mech::Variant::Pinned
        };
        let g = model
            .scene_graph(variant)
            .map_err(|e| library_problem(&e, budget))?;
        let dot = match collapse {
            Some(c) => g.dot_with(c),
            None => g.dot(),
        };
        Ok(match format {
            "causality" => {
                let text = serde_json::to_string_pretty(&g.report()).unwrap_or_default() + "\n";
                with_type(text, JSON)
            }
            "svg" => with_type(
                super::svg::render(&dot, budget.duration())?,
                "image/svg+xml",
            ),
            _ => with_type(dot, "text/vnd.graphviz; charset=utf-8"),
        })
    });
    join(job).await
}

/// `POST /v1/equilibrium`: the static equilibrium nearest the scene's configuration, the
/// `bondmech equilibrium --json` document ([`crate::analysis::equilibrium::Equilibrium::to_json`]).
pub async fn equilibrium(State(app): State<Arc<App>>, headers: HeaderMap, body: Body) -> Response {
    let r = equilibrium_inner(&app, &headers, body).await;
    respond(&app, r)
}

async fn equilibrium_inner(
    app: &Arc<App>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let scene = scene_from(app, headers, body).await?;
    let slot = app.pool.acquire_for(0.0).await?;
    let limits = app.limits.clone();
    let job = app.pool.spawn(slot, move || {
        let budget = Budget::of(&scene, &limits);
        let model = Model::new(&scene).map_err(|e| library_problem(&e, budget))?;
        let eq = model
            .equilibrium()
            .map_err(|e| library_problem(&e, budget))?;
        let text = serde_json::to_string_pretty(&eq.to_json()).unwrap_or_default() + "\n";
        Ok(with_type(text, JSON))
    });
    join(job).await
}

/// The comma-separated list of query parameter `key` (empty when absent).
fn query_list(params: &super::solve::Params, key: &str) -> Vec<String> {
    params
        .text(key)
        .map(|s| {
            s.split(',')
                .map(|c| c.trim().to_string())
                .filter(|c| !c.is_empty())
                .collect()
        })
        .unwrap_or_default()
}

/// A sensitivity run's or a fit's refusal: 422 naming the parameter's path or the data's
/// column (`parameter`: `param`, or `data` for the data).
fn sensitivity_problem(e: &crate::sensitivity::SensitivityError) -> Problem {
    use crate::sensitivity::SensitivityError as S;
    match e {
        S::Path { .. } | S::Unsupported { .. } | S::Perturbed { .. } => {
            super::solve::invalid_value("param", e.to_string())
        }
        S::Data(_) => super::solve::invalid_value("data", e.to_string()),
        S::Solve(_) | S::Solver(_) => Problem::new(
            axum::http::StatusCode::UNPROCESSABLE_ENTITY,
            "solve-failed",
            "The solve failed",
            e.to_string(),
        ),
        S::Scene(_) | S::Fit(_) => Problem::new(
            axum::http::StatusCode::UNPROCESSABLE_ENTITY,
            "sensitivity-refused",
            "Sensitivities or fit refused",
            e.to_string(),
        ),
    }
}

/// `POST /v1/sensitivity?param=PATH,PATH`: the run's columns and their sensitivities
/// `d(<column>)/d(<PATH>)` as CSV (`bondmech sensitivity`), the scene in the body.
pub async fn sensitivity(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = sensitivity_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn sensitivity_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let params = Params::parse(q.as_deref(), &["param"])?;
    let paths = query_list(&params, "param");
    if paths.is_empty() {
        return Err(Problem::bad_parameter(
            "param",
            "give the parameters' scene paths: ?param=bodies[bar2].mass,springs[s1].stiffness",
        ));
    }
    let scene = scene_from(app, headers, body).await?;
    let slot = app.pool.acquire_for(0.0).await?;
    let job = app.pool.spawn(slot, move || {
        let mut req = crate::sensitivity::SensitivityRequest::new(&[]);
        req.params = paths;
        let s =
            crate::sensitivity::sensitivity(&scene, &req).map_err(|e| sensitivity_problem(&e))?;
        Ok(with_type(s.to_csv(), "text/csv; charset=utf-8"))
    });
    join(job).await
}

/// `POST /v1/fit?param=PATH,PATH&columns=COL,COL`: the fit's JSON (`bondmech fit --json`); the
/// body is `{"scene": {…}, "data": "<CSV text>" | {"t": […], "<column>": […], …}}`.
pub async fn fit(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = fit_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn fit_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let params = Params::parse(q.as_deref(), &["param", "columns"])?;
    let paths = query_list(&params, "param");
    if paths.is_empty() {
        return Err(Problem::bad_parameter(
            "param",
            "give the parameters' scene paths: ?param=springs[s1].stiffness,springs[s1].damping",
        ));
    }
    let columns = params
        .text("columns")
        .map(|_| query_list(&params, "columns"));
    let bytes = super::limits::read_body(headers, body, &app.limits).await?;
    let limits = app.limits.clone();
    let (scene, data) = tokio::task::spawn_blocking(move || fit_body(&bytes, &limits))
        .await
        .unwrap_or_else(|e| {
            Err(Problem::internal(format!(
                "the admission job was lost: {e}"
            )))
        })?;
    let slot = app.pool.acquire_for(0.0).await?;
    let job = app.pool.spawn(slot, move || {
        let req = crate::sensitivity::FitRequest {
            params: paths,
            columns,
            max_iterations: None,
        };
        let r =
            crate::sensitivity::fit(&scene, &data, &req).map_err(|e| sensitivity_problem(&e))?;
        let text = serde_json::to_string_pretty(&r.to_json()).unwrap_or_default() + "\n";
        Ok(with_type(text, JSON))
    });
    join(job).await
}

/// The scene and the data of a fit's body (see [`fit`]).
fn fit_body(
    bytes: &[u8],
    limits: &super::limits::Limits,
) -> Result<(Scene, crate::sensitivity::FitData), Problem> {
    use crate::sensitivity::FitData;
    let doc = super::limits::parse_json(bytes)?;
    let Some(obj) = doc.as_object() else {
        return Err(super::solve::invalid_value(
            "body",
            "the body is {\"scene\": {…}, \"data\": \"<CSV>\" or {\"t\": […], \"<column>\": […]}}",
        ));
    };
    let scene_doc = obj
        .get("scene")
        .ok_or_else(|| super::solve::invalid_value("body", "the body has no \"scene\""))?;
    let text = scene_doc.to_string();
    let scene = super::admit::parse_scene(text.as_bytes(), limits)?;
    let data = match obj.get("data") {
        Some(serde_json::Value::String(csv)) => FitData::from_csv(csv),
        Some(serde_json::Value::Object(cols)) => {
            let header: Vec<String> = cols.keys().cloned().collect();
            let mut series = Vec::with_capacity(header.len());
            for (k, v) in cols {
                let values: Option<Vec<f64>> = v
                    .as_array()
                    .map(|a| a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect());
                match values {
                    Some(v) => series.push(v),
                    None => {
                        return Err(super::solve::invalid_value(
                            "data",
                            format!("data column '{k}' is not an array of numbers"),
                        ))
                    }
                }
            }
            let rows = series.first().map_or(0, Vec::len);
            if let Some((k, _)) = header.iter().zip(&series).find(|(_, s)| s.len() != rows) {
                return Err(super::solve::invalid_value(
                    "data",
                    format!("data column '{k}' has another length than the others"),
                ));
            }
            let table: Vec<Vec<f64>> = (0..rows)
                .map(|i| series.iter().map(|s| s[i]).collect())
                .collect();
            FitData::from_table(header, table)
        }
        _ => {
            return Err(super::solve::invalid_value(
                "data",
                "the body's \"data\" is CSV text or an object of columns",
            ))
        }
    }
    .map_err(|e| super::solve::invalid_value("data", e.to_string()))?;
    Ok((scene, data))
}

/// `POST /v1/linearize?at=&output=&states=`: the linear model about the operating point, the
/// `bondmech linearize --json` document ([`crate::analysis::linear_model::LinearModel::to_json`]);
/// `output` and `states` are comma-separated column names.
pub async fn linearize(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = linearize_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn linearize_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let params = Params::parse(q.as_deref(), &["at", "output", "states"])?;
    let at: crate::analysis::linear_model::OperatingPoint =
        params.text("at").unwrap_or("equilibrium").parse().map_err(
            |e: crate::analysis::linear_model::LinearizeError| {
                Problem::bad_parameter("at", e.to_string())
            },
        )?;
    let list = |key: &str| -> Vec<String> {
        params
            .text(key)
            .map(|s| {
                s.split(',')
                    .map(|c| c.trim().to_string())
                    .filter(|c| !c.is_empty())
                    .collect()
            })
            .unwrap_or_default()
    };
    let options = crate::analysis::linear_model::LinearizeOptions {
        at,
        outputs: list("output"),
        states: params.text("states").map(|_| list("states")),
    };
    let scene = scene_from(app, headers, body).await?;
    let slot = app.pool.acquire_for(0.0).await?;
    let limits = app.limits.clone();
    let job = app.pool.spawn(slot, move || {
        let budget = Budget::of(&scene, &limits);
        use crate::analysis::linear_model::LinearizeError as L;
        // the library's messages name the CLI's flags (`--output`, `--at`); here the query
        // parameters are `output` and `at`
        let query = |e: &crate::Error, flag: &str| {
            e.to_string()
                .replacen(&format!("--{flag} "), &format!("{flag} "), 1)
                .replacen(&format!("--{flag}="), &format!("{flag}="), 1)
        };
        let lm = crate::linearize(&scene, &options).map_err(|e| match &e {
            crate::Error::Linearize(L::UnknownOutput { name, why }) => {
                super::solve::invalid_value("output", format!("output '{name}': {why}"))
            }
            crate::Error::Linearize(L::States(_)) => {
                super::solve::invalid_value("states", e.to_string())
            }
            crate::Error::Linearize(L::BeforeStart { .. } | L::AfterEnd { .. }) => {
                super::solve::invalid_value("at", query(&e, "at"))
            }
            _ => library_problem(&e, budget),
        })?;
        let text = serde_json::to_string_pretty(&lm.to_json()).unwrap_or_default() + "\n";
        Ok(with_type(text, JSON))
    });
    join(job).await
}

/// `POST /v1/sweep?quick=true`: NDJSON progress lines, then the sweep report.
pub async fn sweep(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = sweep_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

/// Most timed runs per sweep point a request may ask for.
pub const MAX_SWEEP_REPEATS: usize = 5;

async fn sweep_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    not_shutting_down(app)?;
    let params = Params::parse(q.as_deref(), &["quick", "t_end", "accuracy", "repeats"])?;
    let quick = params.flag("quick")?.unwrap_or(true);
    let mut cfg = if quick {
        SweepConfig::quick()
    } else {
        SweepConfig::full()
    };
    if let Some(t) = params.number("t_end")? {
        if !(t > 0.0 && t.is_finite()) {
            return Err(invalid_value(
                "t_end",
                format!("t_end: must be > 0 (got {t})"),
            ));
        }
        cfg.t_end = Some(t);
    }
    if let Some(a) = params.number("accuracy")? {
        if !(a > 0.0 && a.is_finite()) {
            return Err(invalid_value(
                "accuracy",
                format!("accuracy: must be > 0 (got {a})"),
            ));
        }
        cfg.accuracy = a;
    }
    if let Some(r) = params.number("repeats")? {
        if !(r >= 1.0 && r.fract() == 0.0) {
            return Err(invalid_value(
                "repeats",
                format!("repeats: must be a whole number >= 1 (got {r})"),
            ));
        }
        if r > MAX_SWEEP_REPEATS as f64 {
            return Err(Problem::limit(
                "max_sweep_repeats",
                MAX_SWEEP_REPEATS,
                format!("repeats = {r} is over the limit max_sweep_repeats = {MAX_SWEEP_REPEATS}"),
            ));
        }
        cfg.repeats = r as usize;
    }
    let t_end = cfg.t_end;
    let mut scene = super::admit::scene(app, headers, body, move |scene, limits| {
        check_rows(&scene, t_end, limits)?;
        if scene.bond_graph.is_some() {
            return Err(invalid_scene([(
                "bond_graph".to_string(),
                "sweep needs bodies and joints (a raw bond graph has no decoupled twin)"
                    .to_string(),
            )]));
        }
        Ok(scene)
    })
    .await?;
    // the whole sweep within the budget: each of its solves (accuracy and timed runs) gets a
    // share
    let budget = Budget::of(&scene, &app.limits);
    let solves = (cfg.total_points() * (1 + cfg.repeats)) as f64;
    scene.solve.max_wall_seconds = Some(budget.seconds / solves);
    let slot = app.pool.acquire().await?;
    let (tx, rx) = mpsc::channel::<Bytes>(64);
    let (started_tx, started_rx) = oneshot::channel();
    drop(app.pool.spawn(slot, move || {
        let started = Mutex::new(Some(started_tx));
        let start = || {
            if let Some(s) = started.lock().unwrap_or_else(|e| e.into_inner()).take() {
                let _ = s.send(Ok(()));
            }
        };
        let model = match Model::new(&scene) {
            Ok(m) => m,
            Err(e) => {
                if let Some(s) = started.lock().unwrap_or_else(|e| e.into_inner()).take() {
                    let _ = s.send(Err(library_problem(&e, budget)));
                }
                return Ok(());
            }
        };
        let total = cfg.total_points();
        let done = AtomicUsize::new(0);
        let r = crate::study::sweep::run_sweep(&model, &cfg, &|label| {
            let k = done.fetch_add(1, Ordering::SeqCst) + 1;
            send_line(
                &tx,
                &serde_json::json!({"progress": {"done": k, "total": total, "point": label}}),
            );
            start();
        });
        match r {
            Ok(report) => {
                start();
                send_line(&tx, &serde_json::json!({ "sweep": report }));
            }
            Err(e) => {
                let p = library_problem(&e, budget);
                match started.lock().unwrap_or_else(|e| e.into_inner()).take() {
                    Some(s) => {
                        let _ = s.send(Err(p));
                    }
                    None => {
                        send_line(&tx, &serde_json::json!({"error": p.to_json()}));
                    }
                }
            }
        }
        Ok(())
    }));
    stream_response(started_rx, rx).await
}

/// `POST /v1/animate?view=xy|xz|yz|iso&speed=S&format=svg|frames|view3d` and the solve
/// parameters: the `bondmech animate --out FILE.svg` picture (an SVG animated with SMIL; its
/// root states `data-t0`, `data-t-end`, `data-speed`, `data-duration`, so a page scrubs it with
/// `setCurrentTime((t − t0) / speed)`), the frames as drawn (`--frames`), or, for a spatial
/// scene, the data of the 3D view (JSON, drawn by the renderer served at `/view3d.js`, the one
/// `bondmech animate --out FILE.html` inlines). Solved as the
/// command line solves it: again at denser output times when a body would turn more than 15°
/// between rows, all within the one budget.
pub async fn animate(
    State(app): State<Arc<App>>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Response {
    let r = animate_inner(&app, q, &headers, body).await;
    respond(&app, r)
}

async fn animate_inner(
    app: &Arc<App>,
    q: Option<String>,
    headers: &HeaderMap,
    body: Body,
) -> Result<Response, Problem> {
    use crate::report::animate::{
        animation, denser_output_times, frames_json, view3d_json, AnimationFormat,
        AnimationOptions, View,
    };
    not_shutting_down(app)?;
    let mut allowed = SOLVE_PARAMS.to_vec();
    allowed.extend(["format", "view", "speed"]);
    let params = Params::parse(q.as_deref(), &allowed)?;
    let format = params.choice("format", &["svg", "frames", "view3d"])?;
    let view = match params.text("view") {
        None => None,
        Some(v) => Some(View::parse(v).ok_or_else(|| {
            invalid_value(
                "view",
                format!("view: expected xy, xz, yz or iso (got '{v}')"),
            )
        })?),
    };
    let speed = params.number("speed")?;
    if let Some(s) = speed {
        if !(s > 0.0 && s.is_finite()) {
            return Err(invalid_value(
                "speed",
                format!("speed: must be > 0 (got {s})"),
            ));
        }
    }
    let solve = SolveParams::from(&params)?;
    let (scene, cost) = super::admit::scene(app, headers, body, move |mut scene, limits| {
        if scene.bodies.is_empty() {
            return Err(invalid_scene([(
                "bond_graph".to_string(),
                "animate needs a scene with bodies (a raw bond graph has no geometry to draw)"
                    .to_string(),
            )]));
        }
        if format == "view3d" && scene.dimension != crate::scene::Dimension::Spatial {
            return Err(invalid_value(
                "format",
                "format=view3d: the 3D view needs a spatial scene (\"dimension\": 3); a planar scene is drawn as SVG (format=svg)",
            ));
        }
        check_rows(&scene, solve.overrides.t_end, limits)?;
        solve.apply_to_scene(&mut scene)?;
        let cost = super::pool::estimated_cost(&scene);
        Ok((scene, cost))
    })
    .await?;
    let slot = app.pool.acquire_for(cost).await?;
    let limits = app.limits.clone();
    let stop = app.stop_flags();
    let mut guard = CancelOnDrop::new(&stop);
    let metrics = app.metrics.clone();
    let job = app.pool.spawn(slot, move || {
        let budget = Budget::of(&scene, &limits);
        let start = std::time::Instant::now();
        let model = Model::new(&scene).map_err(|e| library_problem(&e, budget))?;
        let mut opts = super::solve::options(&model, budget, &limits)?;
        // each solve stops at its next output row when the client has gone or the server's
        // shutdown grace has run out
        let solve = |opts: &crate::solve::SolveOptions| {
            let mut stopped = false;
            let sol = model
                .solve_streaming(opts, &mut |_| {
                    stopped = stop.client_gone.load(Ordering::SeqCst)
                        || stop.shutdown.load(Ordering::SeqCst);
                    if stopped {
                        std::ops::ControlFlow::Break(())
                    } else {
                        std::ops::ControlFlow::Continue(())
                    }
                })
                .map_err(|e| library_problem(&e, budget))?;
            if stopped {
                if stop.client_gone.load(Ordering::SeqCst) {
                    metrics.cancelled();
                }
                return Err(Problem::unavailable(
                    "the animation's solve was stopped (client gone or shutting down)",
                    1,
                ));
            }
            Ok(sol)
        };
        opts.keep_rows = true;
        let mut sol = solve(&opts)?;
        let report = |e: crate::report::ReportError| library_problem(&e.into(), budget);
        // rows close enough that every frame is a row (as `bondmech animate` does), each solve
        // with what is left of the one budget
        for _ in 0..4 {
            let Some(times) = denser_output_times(&scene, &sol).map_err(report)? else {
                break;
            };
            if times.len() > limits.max_rows {
                break;
            }
            opts.output_times = times.into_iter().filter(|&t| t >= opts.t_start).collect();
            opts.max_wall_clock = Some(budget.duration().saturating_sub(start.elapsed()));
            sol = solve(&opts)?;
        }
        let aopts = AnimationOptions {
            speed,
            view,
            source: "the solution".into(),
            ..AnimationOptions::default()
        };
        Ok(if format == "frames" {
            with_type(frames_json(&scene, &sol, &aopts).map_err(report)?, JSON)
        } else if format == "view3d" {
            with_type(view3d_json(&scene, &sol, &aopts).map_err(report)?, JSON)
        } else {
            with_type(
                animation(&scene, &sol, &aopts, AnimationFormat::Svg).map_err(report)?,
                "image/svg+xml",
            )
        })
    });
    let r = join(job).await;
    guard.disarm();
    r
}
