//! The OpenAPI 3.1 description of every route (`GET /openapi.json`).

use serde_json::{json, Value};

fn problem(description: &str) -> Value {
    json!({
        "description": description,
        "content": {"application/problem+json": {"schema": {"$ref": "#/components/schemas/Problem"}}}
    })
}

fn unavailable() -> Value {
    json!({
        "description": "All solve slots busy and the queue full, or shutting down; retry after the given seconds.",
        "headers": {"Retry-After": {"schema": {"type": "integer"}, "description": "Seconds to wait."}},
        "content": {"application/problem+json": {"schema": {"$ref": "#/components/schemas/Problem"}}}
    })
}

fn query(name: &str, description: &str, schema: Value) -> Value {
    json!({"name": name, "in": "query", "required": false, "description": description, "schema": schema})
}

fn solve_params() -> Vec<Value> {
    vec![
        query(
            "rtol",
            "Relative tolerance (the scene's solve.rtol by default).",
            json!({"type": "number", "exclusiveMinimum": 0}),
        ),
        query(
            "atol",
            "Absolute tolerance (the scene's solve.atol by default).",
            json!({"type": "number", "exclusiveMinimum": 0}),
        ),
        query(
            "t_end",
            "End time (s); output times keep the scene's output_step.",
            json!({"type": "number", "exclusiveMinimum": 0}),
        ),
        query(
            "formulation",
            "dae (ggl), compliant_ggl, index1, decoupled or partitioned.",
            json!({"type": "string", "enum": ["dae", "ggl", "compliant_ggl", "index1", "decoupled", "partitioned"]}),
        ),
        query(
            "joint_stiffness",
            "Joint stiffness of the decoupled twin (N/m).",
            json!({"type": "number", "exclusiveMinimum": 0}),
        ),
        query(
            "max_steps",
            "Step budget of the whole run (solve.max_steps).",
            json!({"type": "integer", "minimum": 1}),
        ),
        query(
            "max_wall_seconds",
            "Wall-clock budget (solve.max_wall_seconds); the server's --max-solve-seconds applies when smaller.",
            json!({"type": "number", "exclusiveMinimum": 0}),
        ),
        query(
            "linear_solver",
            "Linear solver of the Newton iterations (solve.linear_solver): auto (dense below 30 unknowns, faer's sparse LU from there), dense, sparse (alias faer) or klu.",
            json!({"type": "string", "enum": ["auto", "dense", "sparse", "faer", "klu"]}),
        ),
        query(
            "reactions",
            "Add every joint's reaction columns (as \"outputs\": [\"reactions\"]).",
            json!({"type": "boolean", "default": false}),
        ),
    ]
}

fn scene_body() -> Value {
    json!({
        "required": true,
        "description": "A scene, exactly the file format (docs/scene-format.md): a mechanism or a raw bond graph.",
        "content": {"application/json": {"schema": {"$ref": "#/components/schemas/Scene"}}}
    })
}

fn scene_errors() -> Vec<(&'static str, Value)> {
    vec![
        ("400", problem("Malformed JSON (with line and column) or an invalid query parameter.")),
        ("413", problem("Body over max_body (decided from Content-Length before reading).")),
        ("415", problem("Content-Type is not JSON.")),
        ("422", problem("Invalid scene (errors: [{path, message}]), a request over a limit (limit names it), a solver failure, or a solve past its budget (limit, t_reached, columns and the rows computed so far).")),
        ("503", unavailable()),
    ]
}

fn post(summary: &str, params: Vec<Value>, ok: Value) -> Value {
    let mut responses = serde_json::Map::new();
    responses.insert("200".into(), ok);
    for (code, v) in scene_errors() {
        responses.insert(code.into(), v);
    }
    json!({"post": {"summary": summary, "parameters": params, "requestBody": scene_body(), "responses": responses}})
}

/// The scene schema ([`crate::scene::schema::scene_schema`]) as an OpenAPI component: its
/// definitions moved under `components/schemas` (`Scene.Body`, …) and its references
/// rewritten to point there.
fn scene_schema() -> Value {
    let mut s = crate::scene::schema::scene_schema();
    let defs = s
        .as_object_mut()
        .and_then(|o| o.remove("$defs"))
        .unwrap_or_else(|| json!({}));
    s.as_object_mut().map(|o| o.remove("$schema"));
    // inline the definitions as `$defs` of the component itself: references stay valid
    // relative to the component once rewritten
    let text = s
        .to_string()
        .replace("\"#/$defs/", "\"#/components/schemas/Scene/$defs/");
    let mut s: Value = serde_json::from_str(&text).expect("the schema stays JSON");
    let defs_text = defs
        .to_string()
        .replace("\"#/$defs/", "\"#/components/schemas/Scene/$defs/");
    s["$defs"] = serde_json::from_str(&defs_text).expect("the schema stays JSON");
    s
}

/// The document.
pub fn document() -> Value {
    let mut run_params = solve_params();
    run_params.push(query(
        "format",
        "json (default): columns, rows, summary; csv: the command line's CSV; ndjson: a {columns, rows} line, one row array per output time as it is computed, then {summary} (or {error}).",
        json!({"type": "string", "enum": ["json", "csv", "ndjson"], "default": "json"}),
    ));
    let animate_line = || {
        query(
            "animate",
            "With format=ndjson: also draw the motion from the solve's own rows (no second solve), sent as one more line before the last: svg (the /v1/animate SVG) or view3d (a spatial scene's 3D view data); {\"error\": problem} on that line when it cannot be drawn.",
            json!({"type": "string", "enum": ["svg", "view3d"]}),
        )
    };
    run_params.push(animate_line());
    let mut compare_params = solve_params();
    compare_params.push(query(
        "format",
        "json (default): the compare --json document; ndjson: {progress: {solve: dae|twin, rows, of}} lines during the two solves, then {twin: {columns, rows, summary}}, with animate {twin_animation}, and last {compare: document} (or {error}).",
        json!({"type": "string", "enum": ["json", "ndjson"], "default": "json"}),
    ));
    compare_params.push(animate_line());
    let mut animate_params = solve_params();
    animate_params.extend([
        query(
            "view",
            "xy (planar default), xz, yz or iso (spatial default: the 3D view).",
            json!({"type": "string", "enum": ["xy", "xz", "yz", "iso"]}),
        ),
        query(
            "speed",
            "Seconds of motion per second of playback (default 1, or slower for fast motions).",
            json!({"type": "number", "exclusiveMinimum": 0}),
        ),
        query(
            "format",
            "svg (default), frames (the points of every body in every frame, JSON) or view3d (a spatial scene's 3D view: bodies, joints, every body's pose per frame, JSON, drawn by /view3d.js).",
            json!({"type": "string", "enum": ["svg", "frames", "view3d"], "default": "svg"}),
        ),
    ]);
    json!({
        "openapi": "3.1.0",
        "info": {
            "title": "bondmech",
            "version": env!("CARGO_PKG_VERSION"),
            "description": "Mechanisms as bond graphs, solved with SUNDIALS (IDA DAE, CVODE decoupled twin). Errors are application/problem+json (RFC 9457)."
        },
        "paths": {
            "/healthz": {"get": {"summary": "Liveness and readiness: version and the linked SUNDIALS version.", "responses": {
                "200": {"description": "Up.", "content": {"application/json": {"schema": {"type": "object", "properties": {
                    "status": {"type": "string"}, "version": {"type": "string"}, "sundials": {"type": "string"}, "sundials_headers": {"type": "string"}}}}}},
                "503": unavailable()}}},
            "/metrics": {"get": {"summary": "Prometheus text format: requests by route and status, solves in flight, queue length, rejections, solve seconds.", "responses": {
                "200": {"description": "Metrics.", "content": {"text/plain": {"schema": {"type": "string"}}}}}}},
            "/openapi.json": {"get": {"summary": "This document.", "responses": {
                "200": {"description": "OpenAPI 3.1.", "content": {"application/json": {"schema": {"type": "object"}}}}}}},
            "/v1/run": post("Solve a scene.", run_params, json!({
                "description": "The trajectory.",
                "content": {
                    "application/json": {"schema": {"$ref": "#/components/schemas/Run"}},
                    "text/csv": {"schema": {"type": "string"}},
                    "application/x-ndjson": {"schema": {"type": "string"}}
                }
            })),
            "/v1/compare": post("Solve the DAE (IDA) and the decoupled twin (CVODE) and compare them (the compare --json document); each solve gets half of the budget.", compare_params, json!({
                "description": "The comparison.", "content": {"application/json": {"schema": {"type": "object"}}, "application/x-ndjson": {"schema": {"type": "string"}}}
            })),
            "/v1/equilibrium": post("The static equilibrium nearest the scene's configuration (Newton with a line search, the joints held) and its stability: the bondmech equilibrium --json document.", vec![], json!({
                "description": "converged, iterations, residual, coordinates, reactions, drivers, stable, stiffness_eigenvalues.", "content": {"application/json": {"schema": {"type": "object"}}}
            })),
            "/v1/linearize": post("The linear model x' = A x + B u, y = C x + D u about an operating point in the chapter's states, with its modes: the bondmech linearize --json document.", vec![
                query("at", "The operating point: equilibrium (default) or t=T (the solved state at time T, s).", json!({"type": "string", "default": "equilibrium"})),
                query("output", "Output columns y, comma-separated (default: the states).", json!({"type": "string"})),
                query("states", "The independent coordinates (and velocities), comma-separated, instead of the causality's choice.", json!({"type": "string"})),
            ], json!({
                "description": "at, t, operating_point, states, inputs, outputs, A, B, C, D, modes (eigenvalue, omega_n, frequency_hz, damping_ratio, shape), notes.", "content": {"application/json": {"schema": {"type": "object"}}}
            })),
            "/v1/sensitivity": post("The run's columns and their forward sensitivities d(<column>)/d(<path>) to scene parameters (IDAS, exact ∂F/∂p): the bondmech sensitivity CSV.", vec![
                query("param", "The parameters' scene paths, comma-separated (bodies[bar2].mass, springs[s1].stiffness, …).", json!({"type": "string"})),
            ], json!({
                "description": "t, the run's columns, then d(<column>)/d(<path>) for every column and parameter.", "content": {"text/csv": {"schema": {"type": "string"}}}
            })),
            "/v1/fit": post("Scene parameters fitted to measured data by Levenberg–Marquardt on the exact sensitivities: the bondmech fit --json document. Body: {\"scene\": {…}, \"data\": \"<CSV with t and run columns>\" or {\"t\": […], \"<column>\": […]}}.", vec![
                query("param", "The parameters' scene paths, comma-separated.", json!({"type": "string"})),
                query("columns", "The data's columns to fit, comma-separated (default all).", json!({"type": "string"})),
            ], json!({
                "description": "converged, reason, iterations, parameters, start, std_errors, covariance, correlation, residual_rms, columns, points.", "content": {"application/json": {"schema": {"type": "object"}}}
            })),
            "/v1/graph": post("The bond graph: DOT, SVG (Graphviz on the server) or the causality report.", vec![
                query("format", "dot (default), svg or causality.", json!({"type": "string", "enum": ["dot", "svg", "causality"], "default": "dot"})),
                query("decoupled", "Draw the decoupled twin (joints replaced by springs).", json!({"type": "boolean", "default": false})),
                query("collapse", "One node per body or joint (true) or every element (false); default: collapsed above 200 elements.", json!({"type": "boolean"})),
            ], json!({
                "description": "The drawing or the report.",
                "content": {
                    "text/vnd.graphviz": {"schema": {"type": "string"}},
                    "image/svg+xml": {"schema": {"type": "string"}},
                    "application/json": {"schema": {"type": "object"}}
                }
            })),
            "/v1/sweep": post("Tolerance (work-precision) and joint-stiffness sweeps: NDJSON {progress} lines, then {sweep} (or {error}).", vec![
                query("quick", "The quick sweep (3 tolerances, 3 stiffnesses, 1 s); default true.", json!({"type": "boolean", "default": true})),
                query("t_end", "End time of every run (s).", json!({"type": "number", "exclusiveMinimum": 0})),
                query("accuracy", "Error the smallest sufficient joint stiffness must reach.", json!({"type": "number", "exclusiveMinimum": 0})),
                query("repeats", "Timed runs per point (1 to 5).", json!({"type": "integer", "minimum": 1, "maximum": 5})),
            ], json!({
                "description": "Progress, then the report.", "content": {"application/x-ndjson": {"schema": {"type": "string"}}}
            })),
            "/v1/animate": post("The bondmech animate picture: an SVG animated with SMIL (root data-t0, data-t-end, data-speed, data-duration for scrubbing with setCurrentTime((t - t0) / speed)), its frames as JSON, or a spatial scene's 3D view data (JSON). A raw bond graph is a 422, and so is view3d for a planar scene.", animate_params, json!({
                "description": "The animation.",
                "content": {
                    "image/svg+xml": {"schema": {"type": "string"}},
                    "application/json": {"schema": {"type": "object", "properties": {
                        "frames": {"type": "array", "items": {"type": "object", "properties": {
                            "t": {"type": "number"}, "points": {"type": "object"}}}}}}}
                }
            })),
            "/v1/validate": {"post": {"summary": "Check a scene as /v1/run does (JSON, limits, the scene's rules) without solving; always 200.", "requestBody": scene_body(), "responses": {
                "200": {"description": "Valid, or the command line's problems with their JSON paths.", "content": {"application/json": {"schema": {"$ref": "#/components/schemas/Validation"}}}},
                "415": problem("Content-Type is not JSON.")}}},
            "/v1/scenes": {"get": {"summary": "The bundled scenes' names (the file names under scenes/ without .json), sorted.", "responses": {
                "200": {"description": "Names.", "content": {"application/json": {"schema": {"type": "array", "items": {"type": "string"}}}}}}}},
            "/v1/scenes/{name}": {"get": {"summary": "One bundled scene's file.", "parameters": [
                {"name": "name", "in": "path", "required": true, "description": "A name from GET /v1/scenes.", "schema": {"type": "string"}}
            ], "responses": {
                "200": {"description": "The scene, byte for byte.", "content": {"application/json": {"schema": {"$ref": "#/components/schemas/Scene"}}}},
                "404": problem("No bundled scene of that name (the detail lists them).")}}},
            "/": {"get": {"summary": "The playground: a page to pick, edit, run, compare and animate scenes (no network outside this origin; strict Content-Security-Policy).", "responses": {
                "200": {"description": "HTML.", "content": {"text/html": {"schema": {"type": "string"}}}}}}}
        },
        "components": {"schemas": {
            "Scene": scene_schema(),
            "Problem": {"type": "object", "description": "RFC 9457 problem details with extension members.", "properties": {
                "type": {"type": "string"}, "title": {"type": "string"}, "status": {"type": "integer"}, "detail": {"type": "string"},
                "errors": {"type": "array", "items": {"type": "object", "properties": {"path": {"type": "string"}, "message": {"type": "string"}}}},
                "line": {"type": "integer"}, "column": {"type": "integer"}, "parameter": {"type": "string"},
                "limit": {"type": "string"}, "limit_value": {},
                "t_reached": {"type": "number"}, "columns": {"type": "array", "items": {"type": "string"}},
                "rows": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}}
            }},
            "Validation": {"type": "object", "required": ["valid", "errors"], "properties": {
                "valid": {"type": "boolean"},
                "errors": {"type": "array", "items": {"type": "object", "properties": {"path": {"type": "string"}, "message": {"type": "string"}}}},
                "line": {"type": "integer"}, "column": {"type": "integer"}
            }},
            "Run": {"type": "object", "properties": {
                "columns": {"type": "array", "items": {"type": "string"}, "description": "t, then the command line's columns."},
                "rows": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}},
                "summary": {"type": "object", "description": "The run --summary JSON."}
            }}
        }}
    })
}
