//! `bondmech serve` as a process: it announces its address, answers, and exits 0 on SIGTERM
//! (graceful shutdown); a bad flag is refused with a message naming it.

mod service_support;
#[path = "support/signals.rs"]
mod signals;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::Duration;

use service_support::*;

#[test]
fn serve_answers_and_exits_cleanly_on_sigterm() {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_bondmech"));
    let mut child = signals::default_signals(&mut cmd)
        .args(["serve", "--addr", "127.0.0.1:0", "--max-concurrent", "1"])
        .stderr(Stdio::piped())
        .spawn()
        .expect("bondmech serve starts");
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    // "bondmech: serving on http://127.0.0.1:PORT (1 solve slots, queue 64)"
    let addr: std::net::SocketAddr = line
        .split("http://")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("{line}"))
        .parse()
        .unwrap();
    assert_eq!(get(addr, "/healthz").status, 200);
    let r = post(
        addr,
        "/v1/run?t_end=0.05&format=csv",
        scene_text("pendulum.json").as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let mut exit = None;
    for _ in 0..300 {
        if let Some(s) = child.try_wait().unwrap() {
            exit = Some(s);
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let Some(exit) = exit else {
        let _ = child.kill();
        panic!("bondmech serve did not exit after SIGTERM");
    };
    assert!(exit.success(), "{exit}");
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut stderr, &mut rest).unwrap();
    assert!(rest.contains("shutting down"), "{rest}");
}

#[test]
fn serve_refuses_a_bad_flag_naming_it() {
    let (ok, _, err) = cli(&["serve", "--max-concurrent", "0"]);
    assert!(!ok);
    assert!(err.contains("--max-concurrent"), "{err}");
    let (ok, _, err) = cli(&["serve", "--max-solve-seconds=0"]);
    assert!(!ok);
    assert!(err.contains("--max-solve-seconds"), "{err}");
}

/// `serve` with `flag 0`, killed after 20 s if it starts serving (the old behaviour: a server
/// that refused every request): whether it exited unsuccessfully, and its standard error.
fn serve_with_zero(flag: &str) -> (bool, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bondmech"))
        .args(["serve", "--addr", "127.0.0.1:0", flag, "0"])
        .stderr(Stdio::piped())
        .spawn()
        .expect("bondmech serve starts");
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    (status.is_some_and(|s| !s.success()), err)
}

#[test]
fn regression_serve_max_rows_0_and_max_elements_0_started_a_server_that_refused_every_request() {
    for flag in [
        "--max-rows",
        "--max-elements",
        "--max-body",
        "--max-expression-length",
    ] {
        let (refused, err) = serve_with_zero(flag);
        assert!(refused, "serve {flag} 0 started: {err}");
        assert!(
            err.contains(flag) && err.contains("at least 1"),
            "{flag}: {err}"
        );
    }
}
