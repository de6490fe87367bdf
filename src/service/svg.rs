//! DOT → SVG through Graphviz `dot`, with a time limit (the process is killed past it).

use std::io::{Read, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use axum::http::StatusCode;

use super::problem::Problem;

/// Renders `dot` text to SVG; 501 when Graphviz is not installed on the server, 422 when it
/// takes longer than `limit`.
pub fn render(dot: &str, limit: Duration) -> Result<Vec<u8>, Problem> {
    let mut child = Command::new("dot")
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| {
            Problem::new(
                StatusCode::NOT_IMPLEMENTED,
                "graphviz-missing",
                "SVG drawing is not available on this server",
                format!("cannot run Graphviz 'dot' ({e}); ask for format=dot and draw it locally"),
            )
        })?;
    let mut stdin = child.stdin.take();
    let text = dot.to_string();
    let writer = std::thread::spawn(move || {
        if let Some(s) = stdin.as_mut() {
            let _ = s.write_all(text.as_bytes());
        }
        // stdin dropped here: dot sees the end of its input
    });
    let mut stdout = child.stdout.take();
    let reader = std::thread::spawn(move || {
        let mut v = Vec::new();
        if let Some(s) = stdout.as_mut() {
            let _ = s.read_to_end(&mut v);
        }
        v
    });
    let deadline = Instant::now() + limit;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Some(s),
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(5)),
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
        }
    };
    let _ = writer.join();
    let svg = reader.join().unwrap_or_default();
    match status {
        Some(s) if s.success() => Ok(svg),
        Some(s) => {
            let mut err = String::new();
            if let Some(mut e) = child.stderr.take() {
                let _ = e.read_to_string(&mut err);
            }
            Err(Problem::internal(format!(
                "Graphviz 'dot' failed ({s}): {}",
                err.trim()
            )))
        }
        None => Err(Problem::limit(
            "max_solve_seconds",
            limit.as_secs_f64(),
            format!(
                "Graphviz 'dot' did not finish within {} s",
                limit.as_secs_f64()
            ),
        )),
    }
}
