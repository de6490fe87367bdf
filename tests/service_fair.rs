//! The service under load and at shutdown:
//! - fairness: with both solve slots kept busy by 8 clients sending a long scene (Bricard over
//!   10 s), a client sending the 2 ms raw-graph scene every 100 ms gets p99 ≤ 250 ms (a fast
//!   lane for cheap requests; the scenes parsed on the blocking pool, not the async workers);
//!   the CI tests run 6 s (probing once the slots are full) and 5 s (probing from the first
//!   request, issue 51), the ignored one the 20 s of the issue;
//! - drain: after the stop signal `/healthz` answers 503 while a request in flight still gets
//!   its 200;
//! - `/metrics` parses with a Prometheus text parser (`prometheus-parse`) and has the process
//!   metrics and per-route latency histograms;
//! - `X-Request-Id` is echoed, or generated when absent.

mod service_support;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use bondmech::service::Config;
use service_support::*;

fn config() -> Config {
    Config {
        max_concurrent: 2,
        queue: 64,
        shutdown_grace: Duration::from_secs(60),
        ..Config::default()
    }
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    let i = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[i]
}

/// Keeps both slots busy with Bricard while the probe sends the raw graph every 100 ms for
/// `seconds`; returns the probe's latencies (s) and the number of long solves answered.
fn fairness(seconds: f64) -> (Vec<f64>, usize) {
    let server = start(config());
    let addr = server.addr();
    let long = Arc::new(scene_text("bricard.json"));
    let short = scene_text("bg_mass_spring_damper.json");
    let stop = Arc::new(AtomicBool::new(false));
    let mut hogs = Vec::new();
    for _ in 0..8 {
        let (long, stop) = (long.clone(), stop.clone());
        hogs.push(std::thread::spawn(move || {
            let mut answered = 0;
            while !stop.load(Ordering::SeqCst) {
                let r = post(addr, "/v1/run?format=csv", long.as_bytes());
                assert!(r.status == 200 || r.status == 503, "{}", r.text());
                answered += usize::from(r.status == 200);
            }
            answered
        }));
    }
    // let the long requests fill the slots
    let t0 = Instant::now();
    while metric(&get(addr, "/metrics").text(), "bondmech_solves_in_flight") < Some(2.0) {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "the slots never filled"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let mut lat = Vec::new();
    let start_probe = Instant::now();
    while start_probe.elapsed().as_secs_f64() < seconds {
        let tick = Instant::now();
        let r = post(addr, "/v1/run?format=csv", short.as_bytes());
        lat.push(tick.elapsed().as_secs_f64());
        assert_eq!(r.status, 200, "{}", r.text());
        if let Some(rest) = Duration::from_millis(100).checked_sub(tick.elapsed()) {
            std::thread::sleep(rest);
        }
    }
    let busy = metric(&get(addr, "/metrics").text(), "bondmech_solves_in_flight").unwrap();
    assert!(busy >= 2.0, "the long solves kept the slots busy ({busy})");
    stop.store(true, Ordering::SeqCst);
    let answered = hogs.into_iter().map(|h| h.join().unwrap()).sum();
    drop(server);
    (lat, answered)
}

#[test]
fn short_requests_are_not_stuck_behind_long_ones() {
    let (mut lat, answered) = fairness(6.0);
    let n = lat.len();
    let (p50, p99) = (percentile(&mut lat, 0.5), percentile(&mut lat, 0.99));
    eprintln!(
        "short requests: {n}, p50 {p50:.4} s, p99 {p99:.4} s; long solves answered: {answered}"
    );
    assert!(n >= 40, "{n} probes");
    assert!(p99 <= 0.25, "p99 {p99} s (p50 {p50} s)");
}

#[test]
#[ignore = "20 s: the issue's figure; run with --ignored --nocapture"]
fn short_requests_p99_over_twenty_seconds() {
    let (mut lat, answered) = fairness(20.0);
    let n = lat.len();
    let (p50, p99, max) = (
        percentile(&mut lat, 0.5),
        percentile(&mut lat, 0.99),
        percentile(&mut lat, 1.0),
    );
    eprintln!(
        "short requests: {n}, p50 {p50:.4} s, p99 {p99:.4} s, max {max:.4} s; long solves answered: {answered}"
    );
    assert!(p99 <= 0.25, "p99 {p99} s");
}

/// Issue 51: the load of the issue from its first moment — 8 clients posting Bricard back to
/// back while a ninth posts the raw mass-spring-damper every 100 ms — without waiting for the
/// slots to fill first (the 6 s test above starts probing once they are full, after the burst
/// of the first requests, where the issue saw the first short requests wait 4–6 s). Every short
/// request is answered 200 within the p99 bound while long requests wait in the queue, and the
/// long clients get their answers too. 5 s of probing: short enough for CI, p99 of ~50 samples.
#[test]
fn regression_short_requests_waited_seconds_behind_long_ones_from_the_first_request() {
    let server = start(config());
    let addr = server.addr();
    let long = Arc::new(scene_text("bricard.json"));
    let short = scene_text("bg_mass_spring_damper.json");
    let stop = Arc::new(AtomicBool::new(false));
    let hogs: Vec<_> = (0..8)
        .map(|_| {
            let (long, stop) = (long.clone(), stop.clone());
            std::thread::spawn(move || {
                let mut answered = 0usize;
                while !stop.load(Ordering::SeqCst) {
                    let r = post(addr, "/v1/run?format=csv", long.as_bytes());
                    assert_eq!(r.status, 200, "{}", r.text());
                    answered += 1;
                }
                answered
            })
        })
        .collect();
    let mut lat = Vec::new();
    let mut queued_seen = 0.0f64;
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(5) {
        let tick = Instant::now();
        let r = post(addr, "/v1/run?format=csv", short.as_bytes());
        lat.push(tick.elapsed().as_secs_f64());
        assert_eq!(r.status, 200, "short request {}: {}", lat.len(), r.text());
        let queued = metric(&get(addr, "/metrics").text(), "bondmech_queue_length");
        queued_seen = queued_seen.max(queued.unwrap_or(0.0));
        if let Some(rest) = Duration::from_millis(100).checked_sub(tick.elapsed()) {
            std::thread::sleep(rest);
        }
    }
    stop.store(true, Ordering::SeqCst);
    let answered: Vec<usize> = hogs.into_iter().map(|h| h.join().unwrap()).collect();
    drop(server);
    let n = lat.len();
    let first: Vec<String> = lat.iter().take(5).map(|l| format!("{l:.3}")).collect();
    let (p50, p99) = (percentile(&mut lat, 0.5), percentile(&mut lat, 0.99));
    eprintln!(
        "short requests: {n}, first {first:?} s, p50 {p50:.4} s, p99 {p99:.4} s; long answers per client {answered:?}; queue up to {queued_seen}"
    );
    // the load held: long requests waited in the queue while the short ones were probed
    assert!(queued_seen >= 1.0, "no long request ever queued");
    assert!(n >= 30, "{n} probes");
    assert!(p99 <= 0.25, "p99 {p99} s (p50 {p50} s, first {first:?})");
    // and the long clients were answered too (2 slots over 5 s of 1–2 s solves)
    assert!(
        answered.iter().sum::<usize>() >= 2,
        "long answers: {answered:?}"
    );
}

#[test]
fn healthz_is_503_while_draining_and_the_request_in_flight_gets_its_200() {
    let mut server = start(config());
    let addr = server.addr();
    // a long solve: Bricard over 30 s
    let long = scene_text("bricard.json");
    let flight =
        std::thread::spawn(move || post(addr, "/v1/run?format=csv&t_end=30", long.as_bytes()));
    let t0 = Instant::now();
    while metric(&get(addr, "/metrics").text(), "bondmech_solves_in_flight") < Some(1.0) {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "the solve never started"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(get(addr, "/healthz").status, 200);
    server.begin_shutdown();
    // the drain: /healthz 503 (the listener is still open), new work refused
    let t1 = Instant::now();
    let mut health = get(addr, "/healthz");
    while health.status != 503 && t1.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(10));
        health = get(addr, "/healthz");
    }
    let p = health.problem(503);
    assert!(
        p["detail"].as_str().unwrap().contains("shutting down"),
        "{p}"
    );
    let refused = post(
        addr,
        "/v1/run?t_end=0.1",
        scene_text("pendulum.json").as_bytes(),
    );
    assert_eq!(refused.status, 503);
    // the request in flight is answered in full
    let r = flight.join().unwrap();
    assert_eq!(r.status, 200, "{}", r.text());
    let (_, rows) = parse_csv(&r.text());
    assert!(
        (rows.last().unwrap()[0] - 30.0).abs() < 1e-9,
        "the whole run"
    );
    drop(server);
}

#[test]
fn metrics_parse_as_prometheus_text_with_process_figures_and_latencies() {
    let server = start(config());
    let addr = server.addr();
    let r = post(
        addr,
        "/v1/run?t_end=0.1",
        scene_text("pendulum.json").as_bytes(),
    );
    assert_eq!(r.status, 200);
    let text = get(addr, "/metrics").text();
    let scrape = prometheus_parse::Scrape::parse(text.lines().map(|l| Ok(l.to_string())))
        .expect("Prometheus text");
    let value = |name: &str| -> f64 {
        let s = scrape
            .samples
            .iter()
            .find(|s| s.metric == name)
            .unwrap_or_else(|| panic!("no {name} in\n{text}"));
        match s.value {
            prometheus_parse::Value::Gauge(v)
            | prometheus_parse::Value::Counter(v)
            | prometheus_parse::Value::Untyped(v) => v,
            _ => panic!("{name} is not a number"),
        }
    };
    assert!(value("process_resident_memory_bytes") > 1e6);
    assert!(value("process_cpu_seconds_total") > 0.0);
    assert!(value("process_open_fds") >= 3.0);
    let run_latency = scrape.samples.iter().find(|s| {
        s.metric == "bondmech_request_duration_seconds" && s.labels.get("route") == Some("/v1/run")
    });
    match run_latency.map(|s| &s.value) {
        Some(prometheus_parse::Value::Histogram(buckets)) => {
            let total = buckets.iter().map(|b| b.count).fold(0.0, f64::max);
            assert!(total >= 1.0, "{buckets:?}");
        }
        other => panic!("no /v1/run latency histogram: {other:?}\n{text}"),
    }
    drop(server);
}

#[test]
fn request_ids_are_echoed_or_generated() {
    let server = start(config());
    let addr = server.addr();
    let mut s = connect(addr);
    write_head(&mut s, "GET", "/healthz", &[("X-Request-Id", "client-42")]);
    let r = read_response(&mut s).unwrap();
    assert_eq!(r.header("x-request-id"), Some("client-42"));
    let a = get(addr, "/healthz");
    let b = get(addr, "/nowhere");
    let (ia, ib) = (
        a.header("x-request-id").unwrap(),
        b.header("x-request-id").unwrap(),
    );
    assert!(!ia.is_empty() && ia != ib, "{ia} {ib}");
    // a header that is not a plain token is replaced
    let mut s = connect(addr);
    write_head(&mut s, "GET", "/healthz", &[("X-Request-Id", "a b <c>")]);
    let r = read_response(&mut s).unwrap();
    assert_ne!(r.header("x-request-id"), Some("a b <c>"));
    drop(server);
}

#[test]
fn openapi_scene_schema_is_generated_and_every_bundled_scene_fits_it() {
    let server = start(config());
    let doc = get(server.addr(), "/openapi.json").json();
    let scene = &doc["components"]["schemas"]["Scene"];
    assert_eq!(
        doc["paths"]["/v1/run"]["post"]["requestBody"]["content"]["application/json"]["schema"]
            ["$ref"],
        "#/components/schemas/Scene"
    );
    assert_eq!(scene["additionalProperties"], false);
    let defs = &scene["$defs"];
    // every reference resolves inside the document
    let text = scene.to_string();
    for r in text.split("\"$ref\":\"").skip(1) {
        let target = &r[..r.find('"').unwrap()];
        let name = target
            .strip_prefix("#/components/schemas/Scene/$defs/")
            .unwrap_or_else(|| panic!("reference {target}"));
        assert!(defs.get(name).is_some(), "{target} does not resolve");
    }
    // the bundled scenes use only the keys the schema names, and have its required ones
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let fits = |obj: &serde_json::Value, schema: &serde_json::Value, what: &str| {
            for k in obj.as_object().unwrap().keys() {
                assert!(
                    schema["properties"].get(k).is_some(),
                    "{}: {what} key {k} is not in the schema",
                    path.display()
                );
            }
            for r in schema["required"].as_array().into_iter().flatten() {
                assert!(obj.get(r.as_str().unwrap()).is_some(), "{what} needs {r}");
            }
        };
        fits(&v, scene, "scene");
        for (list, def) in [
            ("bodies", "Body"),
            ("joints", "Joint"),
            ("springs", "Spring"),
            ("loads", "Load"),
        ] {
            for item in v[list].as_array().into_iter().flatten() {
                fits(item, &defs[def], def);
            }
        }
        if let Some(s) = v.get("solve") {
            fits(s, &defs["Solve"], "solve");
        }
    }
    drop(server);
}
