//! Load on 127.0.0.1: 32 concurrent clients sending a mix of valid, invalid, over-the-limit
//! and over-budget requests to a server with 2 solve slots and a small queue. Every request
//! must be answered — 200, a 4xx problem, or 503 with `Retry-After` — never a 500 or a dropped
//! connection; valid answers must carry the command line's numbers; the server must be alive
//! and idle afterwards. The CI version sends 96 requests; the ignored one sends several hundred,
//! reports memory (RSS before and after), throughput against one CLI process per solve, and
//! p50/p99 latency (`cargo test --release --test service_load -- --ignored --nocapture`).
//! The request loops are bounded in count; nothing asserts a duration.

mod service_support;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use bondmech::service::{Config, Limits};
use service_support::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Kind {
    Valid,
    ValidNdjson,
    MalformedJson,
    InvalidScene,
    OverLimit,
    OverBudget,
}

const MIX: [Kind; 8] = [
    Kind::Valid,
    Kind::Valid,
    Kind::ValidNdjson,
    Kind::MalformedJson,
    Kind::InvalidScene,
    Kind::OverLimit,
    Kind::OverBudget,
    Kind::Valid,
];

/// The valid request: the double pendulum over 1 s (101 rows).
const VALID: &str = "/v1/run?t_end=1";

struct Requests {
    double_pendulum: String,
    reference: Vec<Vec<f64>>,
}

impl Requests {
    fn new() -> Requests {
        let (ok, csv, err) = cli(&["run", &scene_path("double_pendulum.json"), "--t-end", "1"]);
        assert!(ok, "{err}");
        Requests {
            double_pendulum: scene_text("double_pendulum.json"),
            reference: parse_csv(&csv).1,
        }
    }

    /// Sends one request of `kind`; checks the answer; returns its status.
    fn send(&self, addr: std::net::SocketAddr, kind: Kind) -> u16 {
        let dp = self.double_pendulum.as_bytes();
        let r = match kind {
            Kind::Valid => request(addr, "POST", VALID, Some("application/json"), dp),
            Kind::ValidNdjson => request(
                addr,
                "POST",
                &format!("{VALID}&format=ndjson"),
                Some("application/json"),
                dp,
            ),
            Kind::MalformedJson => request(
                addr,
                "POST",
                "/v1/run",
                Some("application/json"),
                &dp[..dp.len() / 2],
            ),
            Kind::InvalidScene => request(
                addr,
                "POST",
                "/v1/run",
                Some("application/json"),
                self.double_pendulum
                    .replace("\"mass\": 1.0", "\"mass\": -1.0")
                    .as_bytes(),
            ),
            Kind::OverLimit => request(
                addr,
                "POST",
                "/v1/run?t_end=1e9",
                Some("application/json"),
                dp,
            ),
            Kind::OverBudget => request(
                addr,
                "POST",
                "/v1/run?formulation=decoupled&joint_stiffness=1e10",
                Some("application/json"),
                dp,
            ),
        };
        let r = r.unwrap_or_else(|e| panic!("{kind:?}: no answer: {e}"));
        if r.status == 503 {
            let p = r.problem(503);
            let retry: u64 = r
                .header("retry-after")
                .unwrap_or_else(|| panic!("503 without Retry-After: {p}"))
                .parse()
                .unwrap();
            assert!(retry >= 1);
            return 503;
        }
        let expected = match kind {
            Kind::Valid | Kind::ValidNdjson => 200,
            Kind::MalformedJson => 400,
            Kind::InvalidScene | Kind::OverLimit | Kind::OverBudget => 422,
        };
        assert_eq!(r.status, expected, "{kind:?}: {}", r.text());
        match kind {
            Kind::Valid => assert_eq!(json_rows(&r.json()["rows"]), self.reference),
            Kind::ValidNdjson => {
                let lines: Vec<serde_json::Value> = r
                    .text()
                    .lines()
                    .map(|l| serde_json::from_str(l).unwrap())
                    .collect();
                let rows = json_rows(&serde_json::Value::Array(
                    lines[1..lines.len() - 1].to_vec(),
                ));
                assert_eq!(rows, self.reference);
                assert!(lines.last().unwrap()["summary"].is_object());
            }
            Kind::OverLimit => assert_eq!(r.json()["limit"], "max_rows"),
            Kind::OverBudget => {
                let p = r.json();
                assert_eq!(p["limit"], "max_solve_seconds", "{p}");
                assert!(!p["rows"].as_array().unwrap().is_empty(), "{p}");
            }
            _ => {}
        }
        r.status
    }
}

#[derive(Default)]
struct Tally {
    statuses: Vec<(Kind, u16)>,
    /// Latencies (s) of answered valid requests (200).
    valid_latency: Vec<f64>,
}

/// `clients` threads share `n` requests cycling through [`MIX`] (or only valid ones).
fn hammer(
    addr: std::net::SocketAddr,
    req: &Arc<Requests>,
    clients: usize,
    n: usize,
    only_valid: bool,
) -> (Tally, f64) {
    let next = Arc::new(AtomicUsize::new(0));
    let tally = Arc::new(Mutex::new(Tally::default()));
    let start = Instant::now();
    let threads: Vec<_> = (0..clients)
        .map(|_| {
            let (next, tally, req) = (next.clone(), tally.clone(), req.clone());
            std::thread::spawn(move || loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                if i >= n {
                    break;
                }
                let kind = if only_valid {
                    Kind::Valid
                } else {
                    MIX[i % MIX.len()]
                };
                let t = Instant::now();
                let status = req.send(addr, kind);
                let dt = t.elapsed().as_secs_f64();
                let mut g = tally.lock().unwrap();
                g.statuses.push((kind, status));
                if status == 200 && kind == Kind::Valid {
                    g.valid_latency.push(dt);
                }
            })
        })
        .collect();
    for t in threads {
        t.join().expect("a client thread failed");
    }
    let wall = start.elapsed().as_secs_f64();
    let t = Arc::try_unwrap(tally).ok().unwrap().into_inner().unwrap();
    assert_eq!(t.statuses.len(), n, "every request answered");
    (t, wall)
}

fn config(queue: usize) -> Config {
    Config {
        max_concurrent: 2,
        queue,
        limits: Limits {
            max_solve_seconds: 0.5,
            ..Config::default().limits
        },
        ..Config::default()
    }
}

/// After a run: alive, idle, and every request counted once (metrics against `before`, the
/// metrics text before the run).
fn check_after(addr: std::net::SocketAddr, before: &str, tally: &Tally) {
    let h = get(addr, "/healthz");
    assert_eq!(h.status, 200);
    let mut m = String::new();
    for _ in 0..600 {
        m = get(addr, "/metrics").text();
        if metric(&m, "bondmech_solves_in_flight") == Some(0.0)
            && metric(&m, "bondmech_queue_length") == Some(0.0)
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    assert_eq!(metric(&m, "bondmech_solves_in_flight"), Some(0.0), "{m}");
    assert_eq!(metric(&m, "bondmech_queue_length"), Some(0.0), "{m}");
    for status in [200u16, 400, 422, 503] {
        let sent = tally.statuses.iter().filter(|(_, s)| *s == status).count() as f64;
        let name = format!("bondmech_requests_total{{route=\"/v1/run\",status=\"{status}\"}}");
        let counted = metric(&m, &name).unwrap_or(0.0) - metric(before, &name).unwrap_or(0.0);
        assert_eq!(counted, sent, "status {status}: {m}");
    }
    let saturated = tally.statuses.iter().filter(|(_, s)| *s == 503).count() as f64;
    let name = "bondmech_rejections_total{reason=\"saturated\"}";
    assert_eq!(
        metric(&m, name).unwrap() - metric(before, name).unwrap(),
        saturated
    );
    assert!(!m.contains("status=\"500\""), "{m}");
}

#[test]
fn thirty_two_clients_mixed_requests_two_slots_small_queue() {
    let req = Arc::new(Requests::new());
    let server = start(config(4));
    let before = get(server.addr(), "/metrics").text();
    let (tally, _) = hammer(server.addr(), &req, 32, 96, false);
    let count = |s: u16| tally.statuses.iter().filter(|(_, x)| *x == s).count();
    eprintln!(
        "96 requests: {} × 200, {} × 400, {} × 422, {} × 503",
        count(200),
        count(400),
        count(422),
        count(503)
    );
    assert!(count(200) > 0, "some valid requests were solved");
    check_after(server.addr(), &before, &tally);
    // and it still solves
    assert_eq!(req.send(server.addr(), Kind::Valid), 200);
    server.shutdown().unwrap();
}

fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .unwrap()
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap()
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

#[test]
#[ignore = "a few hundred requests and a throughput comparison: run with --ignored --nocapture"]
fn load_report_memory_throughput_latency() {
    let req = Arc::new(Requests::new());
    let server = start(config(16));
    let addr = server.addr();
    // warm-up (allocator pools, thread stacks), then five measured rounds of the mix
    hammer(addr, &req, 32, 100, false);
    let rss0 = rss_kib();
    let mut rss = Vec::new();
    let mut all = Tally::default();
    for _ in 0..5 {
        let before = get(addr, "/metrics").text();
        let (t, _) = hammer(addr, &req, 32, 200, false);
        check_after(addr, &before, &t);
        rss.push(rss_kib());
        all.statuses.extend(t.statuses);
        all.valid_latency.extend(t.valid_latency);
    }
    let count = |s: u16| all.statuses.iter().filter(|(_, x)| *x == s).count();
    eprintln!(
        "mixed load, 1000 requests, 32 clients, 2 slots, queue 16: {} × 200, {} × 400, {} × 422, {} × 503, 0 other",
        count(200),
        count(400),
        count(422),
        count(503)
    );
    eprintln!(
        "RSS after warm-up {} KiB; after each 200-request round {:?} KiB",
        rss0, rss
    );
    let mut lat = all.valid_latency.clone();
    eprintln!(
        "valid requests under the mixed load: p50 {:.1} ms, p99 {:.1} ms ({} answered 200)",
        percentile(&mut lat, 0.5) * 1e3,
        percentile(&mut lat, 0.99) * 1e3,
        lat.len()
    );

    // throughput: valid solves only, the server (2 slots, 32 clients) against one CLI process
    // per solve, 2 at a time
    let n = 200;
    // the default budget here: the queue wait is bounded by it, and no request is over it
    let server2 = start(Config {
        max_concurrent: 2,
        ..Config::default()
    });
    let (t, wall) = hammer(server2.addr(), &req, 32, n, true);
    let ok = t.statuses.iter().filter(|(_, s)| *s == 200).count();
    let mut lat = t.valid_latency.clone();
    let service_rate = ok as f64 / wall;
    eprintln!(
        "service: {ok} of {n} valid solves in {wall:.2} s = {service_rate:.1} solves/s; p50 {:.1} ms, p99 {:.1} ms",
        percentile(&mut lat, 0.5) * 1e3,
        percentile(&mut lat, 0.99) * 1e3
    );
    // unloaded: 2 clients for 2 slots, no queueing
    let (t, _) = hammer(server2.addr(), &req, 2, 50, true);
    let mut lat = t.valid_latency.clone();
    eprintln!(
        "service, 2 clients: p50 {:.1} ms, p99 {:.1} ms",
        percentile(&mut lat, 0.5) * 1e3,
        percentile(&mut lat, 0.99) * 1e3
    );
    let path = scene_path("double_pendulum.json");
    let next = Arc::new(AtomicUsize::new(0));
    let start = Instant::now();
    let workers: Vec<_> = (0..2)
        .map(|_| {
            let (next, path) = (next.clone(), path.clone());
            std::thread::spawn(move || {
                while next.fetch_add(1, Ordering::SeqCst) < n {
                    let (ok, _, err) = cli(&["run", &path, "--t-end", "1"]);
                    assert!(ok, "{err}");
                }
            })
        })
        .collect();
    for w in workers {
        w.join().unwrap();
    }
    let cli_wall = start.elapsed().as_secs_f64();
    let cli_rate = n as f64 / cli_wall;
    eprintln!(
        "CLI: {n} processes, 2 at a time, in {cli_wall:.2} s = {cli_rate:.1} solves/s; service / CLI = {:.2}",
        service_rate / cli_rate
    );
    server.shutdown().unwrap();
    server2.shutdown().unwrap();
    // memory is flat: the last round grows RSS by less than 5 % over the first
    assert!(
        (rss[4] as f64) < 1.05 * rss[0] as f64 + 2048.0,
        "RSS grew: {rss0} → {rss:?} KiB"
    );
}
