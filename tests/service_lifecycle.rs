//! The service's life cycle on 127.0.0.1: a client that disconnects stops its solve; a
//! graceful shutdown lets in-flight solves finish, refuses new work, and stops solves still
//! running when the grace runs out (with the rows computed so far). Waits poll `/metrics` a
//! bounded number of times; nothing asserts a duration.

mod service_support;

use std::io::{BufRead, BufReader, Write};
use std::net::SocketAddr;
use std::time::Duration;

use bondmech::service::{Config, Limits};
use service_support::*;

/// The twin at k = 1e10 over the double pendulum's 3 s: minutes of work, a row every few
/// hundred milliseconds.
const LONG: &str = "/v1/run?formulation=decoupled&joint_stiffness=1e10";

/// Polls `/metrics` until `pred` holds (at most about 60 s).
fn wait_for(addr: SocketAddr, what: &str, pred: impl Fn(&str) -> bool) -> String {
    for _ in 0..600 {
        let m = get(addr, "/metrics").text();
        if pred(&m) {
            return m;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("never saw: {what}");
}

fn in_flight(m: &str) -> f64 {
    metric(m, "bondmech_solves_in_flight").unwrap()
}

fn long_budget() -> Config {
    Config {
        limits: Limits {
            max_solve_seconds: 600.0,
            ..Config::default().limits
        },
        ..Config::default()
    }
}

#[test]
fn a_client_that_disconnects_stops_its_json_solve() {
    let server = start(long_budget());
    let addr = server.addr();
    let body = scene_text("double_pendulum.json");
    let mut s = connect(addr);
    write_head(
        &mut s,
        "POST",
        LONG,
        &[
            ("Content-Type", "application/json"),
            ("Content-Length", &body.len().to_string()),
        ],
    );
    s.write_all(body.as_bytes()).unwrap();
    wait_for(addr, "the solve running", |m| in_flight(m) == 1.0);
    drop(s);
    let m = wait_for(addr, "the solve stopped", |m| in_flight(m) == 0.0);
    assert_eq!(metric(&m, "bondmech_solves_cancelled_total"), Some(1.0));
    server.shutdown().unwrap();
}

#[test]
fn a_client_that_disconnects_stops_its_ndjson_stream() {
    let server = start(long_budget());
    let addr = server.addr();
    let body = scene_text("double_pendulum.json");
    let mut s = connect(addr);
    write_head(
        &mut s,
        "POST",
        &format!("{LONG}&format=ndjson"),
        &[
            ("Content-Type", "application/json"),
            ("Content-Length", &body.len().to_string()),
        ],
    );
    s.write_all(body.as_bytes()).unwrap();
    // read the head and the first lines of the stream: the solve is sending rows
    let mut r = BufReader::new(s);
    let mut line = String::new();
    r.read_line(&mut line).unwrap();
    assert!(line.starts_with("HTTP/1.1 200"), "{line}");
    let mut seen_row = false;
    for _ in 0..40 {
        line.clear();
        r.read_line(&mut line).unwrap();
        if line.contains("[0.0,") {
            seen_row = true;
            break;
        }
    }
    assert!(seen_row, "the first row was streamed");
    drop(r);
    let m = wait_for(addr, "the stream's solve stopped", |m| in_flight(m) == 0.0);
    assert_eq!(metric(&m, "bondmech_solves_cancelled_total"), Some(1.0));
    server.shutdown().unwrap();
}

#[test]
fn graceful_shutdown_finishes_in_flight_work_and_refuses_new_work() {
    let mut server = start(long_budget());
    let addr = server.addr();
    // a solve of half a second or so of work (the scene's 20 s; 5 s became too quick to see)
    let client = std::thread::spawn(move || {
        post(
            addr,
            "/v1/run?t_end=20",
            scene_text("four_bar_chain_3.json").as_bytes(),
        )
    });
    wait_for(addr, "the solve running", |m| in_flight(m) == 1.0);
    server.begin_shutdown();
    // new connections are refused (the listener is closed), or answered 503 if accepted
    // before it closed
    std::thread::sleep(Duration::from_millis(50));
    if let Ok(r) = request(addr, "GET", "/healthz", None, b"") {
        assert_eq!(r.status, 503, "{}", r.text());
        assert!(r.header("retry-after").is_some());
    }
    let r = client.join().unwrap();
    assert_eq!(r.status, 200, "{}", r.text());
    let j = r.json();
    assert_eq!(
        j["rows"].as_array().unwrap().len(),
        401,
        "the whole run: 20 s every 0.05 s"
    );
    server.shutdown().unwrap();
    assert!(
        std::net::TcpStream::connect(addr).is_err(),
        "nothing listens after the shutdown"
    );
}

#[test]
fn solves_still_running_when_the_grace_runs_out_stop_with_their_rows() {
    let mut server = start(Config {
        shutdown_grace: Duration::from_millis(300),
        ..long_budget()
    });
    let addr = server.addr();
    let client =
        std::thread::spawn(move || post(addr, LONG, scene_text("double_pendulum.json").as_bytes()));
    wait_for(addr, "the solve running", |m| in_flight(m) == 1.0);
    server.begin_shutdown();
    let r = client.join().unwrap();
    let p = r.problem(503);
    assert!(r.header("retry-after").is_some());
    assert!(!p["rows"].as_array().unwrap().is_empty(), "{p}");
    assert!(p["t_reached"].as_f64().unwrap() < 3.0);
    server.shutdown().unwrap();
}
