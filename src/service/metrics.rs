//! Counters and a histogram, written in the Prometheus text exposition format (version 0.0.4).

use std::collections::BTreeMap;
use std::fmt::Write;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Upper bounds (s) of the solve-duration histogram buckets.
pub const SOLVE_BUCKETS: [f64; 12] = [
    0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 10.0, 60.0,
];

/// Upper bounds (s) of the per-route request latency histogram buckets.
pub const LATENCY_BUCKETS: [f64; 14] = [
    0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 60.0,
];

/// Why a request was refused without being solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Rejection {
    /// No solve slot and the queue full (or the wait in the queue too long): 503.
    Saturated,
    /// The server is shutting down: 503.
    ShuttingDown,
    /// `Content-Length` or the body over `max_body`: 413.
    BodyTooLarge,
    /// Another limit (elements, expression length, rows): 422.
    Limit,
}

impl Rejection {
    fn label(self) -> &'static str {
        match self {
            Rejection::Saturated => "saturated",
            Rejection::ShuttingDown => "shutting_down",
            Rejection::BodyTooLarge => "body_too_large",
            Rejection::Limit => "limit",
        }
    }
}

/// The service's metrics.
#[derive(Debug, Default)]
pub struct Metrics {
    requests: Mutex<BTreeMap<(&'static str, u16), u64>>,
    rejections: Mutex<BTreeMap<Rejection, u64>>,
    /// Solves running now.
    pub in_flight: AtomicUsize,
    /// Requests waiting for a solve slot now.
    pub queued: AtomicUsize,
    cancelled: AtomicU64,
    budget_stops: AtomicU64,
    hist: Mutex<Histogram>,
    latency: Mutex<BTreeMap<&'static str, Latency>>,
    /// Requests being answered now (every route but `/healthz` and `/metrics`).
    pub active_requests: AtomicUsize,
}

#[derive(Debug, Default)]
struct Histogram {
    counts: [u64; SOLVE_BUCKETS.len()],
    count: u64,
    sum: f64,
}

#[derive(Debug, Default)]
struct Latency {
    counts: [u64; LATENCY_BUCKETS.len()],
    count: u64,
    sum: f64,
}

/// The process's own figures from `/proc/self` (Linux): resident memory (bytes), CPU seconds
/// (user + system), open file descriptors, start time (Unix seconds).
struct ProcessFigures {
    resident_bytes: Option<u64>,
    cpu_seconds: f64,
    open_fds: Option<usize>,
}

fn process_figures() -> ProcessFigures {
    let resident_bytes = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map(|kb| kb * 1024);
    let open_fds = std::fs::read_dir("/proc/self/fd").ok().map(|d| d.count());
    let cpu_seconds = cpu_time::ProcessTime::try_now()
        .map(|t| t.as_duration().as_secs_f64())
        .unwrap_or(0.0);
    ProcessFigures {
        resident_bytes,
        cpu_seconds,
        open_fds,
    }
}

impl Metrics {
    /// Counts one answered request.
    pub fn request(&self, route: &'static str, status: u16) {
        let mut m = self.requests.lock().unwrap_or_else(|e| e.into_inner());
        *m.entry((route, status)).or_default() += 1;
    }

    /// Counts one refusal.
    pub fn reject(&self, why: Rejection) {
        let mut m = self.rejections.lock().unwrap_or_else(|e| e.into_inner());
        *m.entry(why).or_default() += 1;
    }

    /// Counts a solve stopped because its client went away.
    pub fn cancelled(&self) {
        self.cancelled.fetch_add(1, Ordering::Relaxed);
    }

    /// Counts a solve stopped by its wall-clock or step budget.
    pub fn budget_stop(&self) {
        self.budget_stops.fetch_add(1, Ordering::Relaxed);
    }

    /// Records the wall-clock seconds of one finished solve job.
    pub fn observe_solve(&self, seconds: f64) {
        let mut h = self.hist.lock().unwrap_or_else(|e| e.into_inner());
        for (c, &b) in h.counts.iter_mut().zip(SOLVE_BUCKETS.iter()) {
            if seconds <= b {
                *c += 1;
            }
        }
        h.count += 1;
        h.sum += seconds;
    }

    /// Records how long one request to `route` took to answer (its headers).
    pub fn observe_latency(&self, route: &'static str, seconds: f64) {
        let mut m = self.latency.lock().unwrap_or_else(|e| e.into_inner());
        let h = m.entry(route).or_default();
        for (c, &b) in h.counts.iter_mut().zip(LATENCY_BUCKETS.iter()) {
            if seconds <= b {
                *c += 1;
            }
        }
        h.count += 1;
        h.sum += seconds;
    }

    /// Number of answered requests with `route` and `status` so far.
    pub fn requests_with(&self, route: &str, status: u16) -> u64 {
        let m = self.requests.lock().unwrap_or_else(|e| e.into_inner());
        m.iter()
            .filter(|((r, s), _)| *r == route && *s == status)
            .map(|(_, n)| *n)
            .sum()
    }

    /// The Prometheus text exposition.
    pub fn render(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# HELP bondmech_requests_total Requests answered, by route and status code.\n# TYPE bondmech_requests_total counter"
        );
        for ((route, status), n) in self
            .requests
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
        {
            let _ = writeln!(
                s,
                "bondmech_requests_total{{route=\"{route}\",status=\"{status}\"}} {n}"
            );
        }
        let _ = writeln!(
            s,
            "# HELP bondmech_rejections_total Requests refused before solving, by reason.\n# TYPE bondmech_rejections_total counter"
        );
        let rej = self.rejections.lock().unwrap_or_else(|e| e.into_inner());
        for why in [
            Rejection::Saturated,
            Rejection::ShuttingDown,
            Rejection::BodyTooLarge,
            Rejection::Limit,
        ] {
            let n = rej.get(&why).copied().unwrap_or(0);
            let _ = writeln!(
                s,
                "bondmech_rejections_total{{reason=\"{}\"}} {n}",
                why.label()
            );
        }
        drop(rej);
        let _ = writeln!(
            s,
            "# HELP bondmech_solves_in_flight Solves running now.\n# TYPE bondmech_solves_in_flight gauge\nbondmech_solves_in_flight {}",
            self.in_flight.load(Ordering::Relaxed)
        );
        let _ = writeln!(
            s,
            "# HELP bondmech_queue_length Requests waiting for a solve slot.\n# TYPE bondmech_queue_length gauge\nbondmech_queue_length {}",
            self.queued.load(Ordering::Relaxed)
        );
        let _ = writeln!(
            s,
            "# HELP bondmech_solves_cancelled_total Solves stopped because the client disconnected.\n# TYPE bondmech_solves_cancelled_total counter\nbondmech_solves_cancelled_total {}",
            self.cancelled.load(Ordering::Relaxed)
        );
        let _ = writeln!(
            s,
            "# HELP bondmech_solve_budget_stops_total Solves stopped by their wall-clock or step budget.\n# TYPE bondmech_solve_budget_stops_total counter\nbondmech_solve_budget_stops_total {}",
            self.budget_stops.load(Ordering::Relaxed)
        );
        let h = self.hist.lock().unwrap_or_else(|e| e.into_inner());
        let _ = writeln!(
            s,
            "# HELP bondmech_solve_seconds Wall-clock seconds of solve jobs (model build and solve).\n# TYPE bondmech_solve_seconds histogram"
        );
        for (c, b) in h.counts.iter().zip(SOLVE_BUCKETS.iter()) {
            let _ = writeln!(s, "bondmech_solve_seconds_bucket{{le=\"{b}\"}} {c}");
        }
        let _ = writeln!(
            s,
            "bondmech_solve_seconds_bucket{{le=\"+Inf\"}} {}\nbondmech_solve_seconds_sum {}\nbondmech_solve_seconds_count {}",
            h.count, h.sum, h.count
        );
        drop(h);
        let _ = writeln!(
            s,
            "# HELP bondmech_request_duration_seconds Seconds from a request's arrival to its answer's headers, by route.\n# TYPE bondmech_request_duration_seconds histogram"
        );
        for (route, h) in self
            .latency
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
        {
            for (c, b) in h.counts.iter().zip(LATENCY_BUCKETS.iter()) {
                let _ = writeln!(
                    s,
                    "bondmech_request_duration_seconds_bucket{{route=\"{route}\",le=\"{b}\"}} {c}"
                );
            }
            let _ = writeln!(
                s,
                "bondmech_request_duration_seconds_bucket{{route=\"{route}\",le=\"+Inf\"}} {}\nbondmech_request_duration_seconds_sum{{route=\"{route}\"}} {}\nbondmech_request_duration_seconds_count{{route=\"{route}\"}} {}",
                h.count, h.sum, h.count
            );
        }
        let p = process_figures();
        let _ = writeln!(
            s,
            "# HELP process_cpu_seconds_total Total user and system CPU time spent in seconds.\n# TYPE process_cpu_seconds_total counter\nprocess_cpu_seconds_total {}",
            p.cpu_seconds
        );
        if let Some(rss) = p.resident_bytes {
            let _ = writeln!(
                s,
                "# HELP process_resident_memory_bytes Resident memory size in bytes.\n# TYPE process_resident_memory_bytes gauge\nprocess_resident_memory_bytes {rss}"
            );
        }
        if let Some(fds) = p.open_fds {
            let _ = writeln!(
                s,
                "# HELP process_open_fds Number of open file descriptors.\n# TYPE process_open_fds gauge\nprocess_open_fds {fds}"
            );
        }
        let _ = writeln!(
            s,
            "# HELP bondmech_requests_active Requests being answered now.\n# TYPE bondmech_requests_active gauge\nbondmech_requests_active {}",
            self.active_requests.load(Ordering::Relaxed)
        );
        s
    }
}
