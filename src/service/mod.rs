//! `bondmech serve`: the library as an HTTP/JSON service (axum on tokio), a face over
//! [`crate::model::Model`] like the command line.
//!
//! | route | answer |
//! |---|---|
//! | `GET /healthz` | version and linked SUNDIALS version; 503 while shutting down |
//! | `POST /v1/run?format=json\|csv\|ndjson` | the trajectory: JSON columns/rows/summary, the CLI's CSV, or NDJSON as the solver goes |
//! | `POST /v1/compare` | the `compare --json` document |
//! | `POST /v1/graph?format=dot\|svg\|causality` | the bond graph drawing or causality report |
//! | `POST /v1/equilibrium` | the static equilibrium (`bondmech equilibrium --json`) |
//! | `POST /v1/linearize?at=&output=&states=` | the linear model and its modes (`bondmech linearize --json`) |
//! | `POST /v1/sensitivity?param=` | the run's columns and their sensitivities (`bondmech sensitivity`, CSV) |
//! | `POST /v1/fit?param=&columns=` | parameters fitted to data (`bondmech fit --json`); body `{"scene", "data"}` |
//! | `POST /v1/sweep?quick=true` | NDJSON progress, then the sweep report |
//! | `POST /v1/animate?view=&speed=&format=svg\|frames` | the `animate` SVG (SMIL) or its frames |
//! | `POST /v1/validate` | `{valid, errors: [{path, message}]}`, the command line's problems (always 200) |
//! | `GET /v1/scenes`, `GET /v1/scenes/{name}` | the bundled scenes' names; one scene's JSON |
//! | `GET /` | the playground page ([`page`]) |
//! | `GET /metrics` | Prometheus text |
//! | `GET /openapi.json` | OpenAPI 3.1 |
//!
//! Errors are `application/problem+json` (RFC 9457, [`problem`]). A request's scene is parsed
//! and validated on the blocking pool, never on the async workers (module `admit`); solves run on a
//! bounded pool of blocking threads with a bounded queue in front ([`pool`]); a client that
//! disconnects stops its solve at the next output row; every request is checked against
//! [`Limits`] before it is queued. The user documentation is `docs/service.md`.
//!
//! Start it in-process (tests do, on `127.0.0.1:0`):
//!
//! ```no_run
//! let server = bondmech::service::Server::start(bondmech::service::Config {
//!     addr: "127.0.0.1:0".parse().unwrap(),
//!     ..Default::default()
//! })?;
//! println!("listening on http://{}", server.addr());
//! server.shutdown()?; // graceful, as on SIGTERM
//! # Ok::<(), std::io::Error>(())
//! ```

mod admit;
mod body;
pub mod limits;
pub mod metrics;
pub mod openapi;
pub mod page;
pub mod pool;
pub mod problem;
mod routes;
pub mod solve;
mod svg;

use std::future::Future;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use axum::routing::{get, post};
use axum::Router;

pub use limits::Limits;
pub use metrics::Metrics;
pub use problem::Problem;

use pool::{Pool, StopFlags};

/// Server settings; [`Config::default`] gives the documented defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Address to listen on (default `127.0.0.1:8080`; port 0 picks a free port).
    pub addr: SocketAddr,
    /// Solves running at once (default: the number of cores).
    pub max_concurrent: usize,
    /// Requests waiting for a solve slot (default 64); beyond it, 503.
    pub queue: usize,
    /// Per-request limits.
    pub limits: Limits,
    /// After SIGTERM/Ctrl-C, in-flight solves may finish for this long; then they are
    /// stopped at their next output row (default 10 s).
    pub shutdown_grace: Duration,
    /// The `Retry-After` of a 503, in seconds (default 1).
    pub retry_after: u64,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            addr: SocketAddr::from(([127, 0, 0, 1], 8080)),
            max_concurrent: std::thread::available_parallelism().map_or(1, |n| n.get()),
            queue: 64,
            limits: Limits {
                max_body: 1 << 20,
                max_elements: 512,
                max_expression_length: 4096,
                max_rows: 100_000,
                max_solve_seconds: 60.0,
                body_timeout: Duration::from_secs(30),
            },
            shutdown_grace: Duration::from_secs(10),
            retry_after: 1,
        }
    }
}

/// Most solves `--max-concurrent` may run at once (each is a blocking thread).
pub const MAX_CONCURRENT: usize = 1024;
/// Longest queue `--queue` may ask for.
pub const MAX_QUEUE: u64 = 1_000_000;
/// Largest request body `--max-body` may allow (1 GiB).
pub const MAX_BODY: u64 = 1 << 30;

/// The flags of `bondmech serve`.
#[derive(clap::Args, Clone, Debug)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long, default_value = "127.0.0.1:8080")]
    pub addr: SocketAddr,
    /// Solves running at once (default: the number of cores).
    #[arg(allow_negative_numbers = true, long = "max-concurrent")]
    pub max_concurrent: Option<usize>,
    /// Requests waiting for a solve slot; beyond it, 503 with Retry-After.
    #[arg(allow_negative_numbers = true, long, default_value_t = 64)]
    pub queue: usize,
    /// Largest request body in bytes (413 above it).
    #[arg(allow_negative_numbers = true, long = "max-body", default_value_t = 1 << 20)]
    pub max_body: u64,
    /// Wall-clock budget of one solve in seconds (422 with the rows so far past it).
    #[arg(
        allow_negative_numbers = true,
        long = "max-solve-seconds",
        default_value_t = 60.0
    )]
    pub max_solve_seconds: f64,
    /// Most bodies + joints + springs + loads + outputs + events + drivers + bond graph
    /// elements and bonds.
    #[arg(
        allow_negative_numbers = true,
        long = "max-elements",
        default_value_t = 512
    )]
    pub max_elements: usize,
    /// Longest string (expression) in a scene, in bytes.
    #[arg(
        allow_negative_numbers = true,
        long = "max-expression-length",
        default_value_t = 4096
    )]
    pub max_expression_length: usize,
    /// Most output rows per run.
    #[arg(
        allow_negative_numbers = true,
        long = "max-rows",
        default_value_t = 100_000
    )]
    pub max_rows: usize,
    /// Seconds in-flight solves may finish after SIGTERM/Ctrl-C.
    #[arg(
        allow_negative_numbers = true,
        long = "shutdown-grace",
        default_value_t = 10.0
    )]
    pub shutdown_grace: f64,
}

impl ServeArgs {
    /// The configuration, or a message naming the bad flag.
    pub fn config(&self) -> Result<Config, String> {
        let d = Config::default();
        use crate::scene::validate::{check_grace_seconds, check_wall_seconds, wall_clock};
        check_wall_seconds(self.max_solve_seconds)
            .map_err(|e| format!("--max-solve-seconds: {e}"))?;
        check_grace_seconds(self.shutdown_grace).map_err(|e| format!("--shutdown-grace: {e}"))?;
        let grace =
            wall_clock(self.shutdown_grace).map_err(|e| format!("--shutdown-grace: {e}"))?;
        if let Some(n) = self.max_concurrent {
            if !(1..=MAX_CONCURRENT).contains(&n) {
                return Err(format!(
                    "--max-concurrent: must be between 1 and {MAX_CONCURRENT} (got {n})"
                ));
            }
        }
        // counts and sizes that become semaphores, threads or buffers: bounded where parsed
        let counts: [(&str, u64, u64); 4] = [
            ("--queue", self.queue as u64, MAX_QUEUE),
            ("--max-body", self.max_body, MAX_BODY),
            (
                "--max-rows",
                self.max_rows as u64,
                crate::scene::validate::MAX_OUTPUT_TIMES as u64,
            ),
            (
                "--max-elements",
                self.max_elements as u64,
                crate::scene::validate::MAX_SCENE_ENTRIES as u64,
            ),
        ];
        // limits every request must stay within: 0 would make a server that refuses them all
        let floors: [(&str, u64, &str); 4] = [
            ("--max-body", self.max_body, "every request body"),
            (
                "--max-rows",
                self.max_rows as u64,
                "every run (a run has at least one row)",
            ),
            (
                "--max-elements",
                self.max_elements as u64,
                "every scene (a scene has at least one body or element)",
            ),
            (
                "--max-expression-length",
                self.max_expression_length as u64,
                "every scene with a name or an expression",
            ),
        ];
        for (flag, value, what) in floors {
            if value == 0 {
                return Err(format!(
                    "{flag}: must be at least 1 (got 0, which would refuse {what}: the server could answer nothing)"
                ));
            }
        }
        for (flag, value, max) in counts {
            if value > max {
                return Err(format!("{flag}: must be at most {max} (got {value})"));
            }
        }
        Ok(Config {
            addr: self.addr,
            max_concurrent: self.max_concurrent.unwrap_or(d.max_concurrent),
            queue: self.queue,
            limits: Limits {
                max_body: self.max_body,
                max_elements: self.max_elements,
                max_expression_length: self.max_expression_length,
                max_rows: self.max_rows,
                max_solve_seconds: self.max_solve_seconds,
                body_timeout: d.limits.body_timeout,
            },
            shutdown_grace: grace,
            retry_after: d.retry_after,
        })
    }
}

/// State shared by the handlers.
#[derive(Debug)]
struct App {
    limits: Limits,
    pool: Pool,
    metrics: Arc<Metrics>,
    /// Set on SIGTERM/Ctrl-C: new work is refused (503), `/healthz` answers 503.
    shutting_down: AtomicBool,
    /// Set when the shutdown grace has run out: running solves stop at their next row.
    stop_all: Arc<AtomicBool>,
    retry_after: u64,
}

impl App {
    fn stop_flags(&self) -> StopFlags {
        StopFlags {
            client_gone: Arc::new(AtomicBool::new(false)),
            shutdown: self.stop_all.clone(),
        }
    }
}

fn router(app: Arc<App>) -> Router {
    Router::new()
        .route("/healthz", get(routes::healthz))
        .route("/metrics", get(routes::metrics))
        .route("/openapi.json", get(routes::openapi))
        .route("/v1/run", post(routes::run))
        .route("/v1/compare", post(routes::compare))
        .route("/v1/graph", post(routes::graph))
        .route("/v1/equilibrium", post(routes::equilibrium))
        .route("/v1/linearize", post(routes::linearize))
        .route("/v1/sensitivity", post(routes::sensitivity))
        .route("/v1/fit", post(routes::fit))
        .route("/v1/sweep", post(routes::sweep))
        .route("/v1/animate", post(routes::animate))
        .route("/v1/validate", post(page::validate))
        .route("/v1/scenes", get(page::scenes))
        .route("/v1/scenes/{name}", get(page::scene))
        .route("/", get(page::index))
        .route("/playground.js", get(page::script))
        .route("/playground.css", get(page::style))
        .route("/view3d.js", get(page::view3d_script))
        .fallback(routes::not_found)
        .method_not_allowed_fallback(routes::method_not_allowed)
        .layer(axum::middleware::from_fn_with_state(
            app.clone(),
            routes::count_requests,
        ))
        .with_state(app)
}

/// Serves on `listener` until `stop` resolves, then shuts down gracefully: stops accepting,
/// refuses new work on open connections, lets in-flight work finish for `grace`, then stops
/// running solves at their next output row.
async fn serve(
    listener: tokio::net::TcpListener,
    config: Config,
    stop: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let metrics = Arc::new(Metrics::default());
    let queue_wait = crate::scene::validate::wall_clock(config.limits.max_solve_seconds)
        .unwrap_or(Duration::from_secs(60));
    let app = Arc::new(App {
        pool: Pool::new(
            config.max_concurrent,
            config.queue,
            queue_wait,
            config.retry_after,
            metrics.clone(),
        ),
        limits: config.limits.clone(),
        metrics,
        shutting_down: AtomicBool::new(false),
        stop_all: Arc::new(AtomicBool::new(false)),
        retry_after: config.retry_after,
    });
    let app2 = app.clone();
    let grace = config.shutdown_grace;
    // the drain: on the stop signal, refuse new work and answer 503 on /healthz (the listener
    // stays open, so a load balancer sees it), let the requests in flight finish (for at most
    // the grace period, then their solves stop at the next row), then close
    let signal = async move {
        stop.await;
        app2.shutting_down.store(true, Ordering::SeqCst);
        let app3 = app2.clone();
        tokio::spawn(async move {
            tokio::time::sleep(grace).await;
            app3.stop_all.store(true, Ordering::SeqCst);
        });
        let deadline = tokio::time::Instant::now() + grace;
        loop {
            let m = &app2.metrics;
            let busy = m.active_requests.load(Ordering::SeqCst)
                + m.in_flight.load(Ordering::SeqCst)
                + m.queued.load(Ordering::SeqCst);
            if busy == 0 || tokio::time::Instant::now() >= deadline {
                break;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    };
    axum::serve(listener, router(app))
        .with_graceful_shutdown(signal)
        .await
}

fn runtime(config: &Config) -> std::io::Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        // the solves (their slots and the fast lane's), and room for the admissions
        // (`admit`: parsing and validating a request's scene) beside them
        .max_blocking_threads(config.max_concurrent + pool::FAST_LANE_SLOTS + 2)
        .enable_all()
        .thread_name("bondmech-serve")
        .build()
}

fn bind(addr: SocketAddr) -> std::io::Result<std::net::TcpListener> {
    let l = std::net::TcpListener::bind(addr)?;
    l.set_nonblocking(true)?;
    Ok(l)
}

/// How long, after the grace, the runtime waits for solves still running before it exits
/// (a solve stops at its next output row, so this only bounds a pathological interval).
const EXIT_WAIT: Duration = Duration::from_secs(5);

/// Serves until SIGTERM or Ctrl-C (`bondmech serve`), then shuts down gracefully.
pub fn run(config: Config) -> std::io::Result<()> {
    let listener = bind(config.addr)?;
    eprintln!(
        "bondmech: serving on http://{} ({} solve slots, queue {})",
        listener.local_addr()?,
        config.max_concurrent,
        config.queue
    );
    let rt = runtime(&config)?;
    let grace = config.shutdown_grace;
    let r = rt.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)?;
        serve(listener, config, shutdown_signal()).await
    });
    rt.shutdown_timeout(grace + EXIT_WAIT);
    r
}

/// Resolves on Ctrl-C or SIGTERM.
async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        _ = ctrl_c => {},
        _ = term => {},
    }
    eprintln!("bondmech: shutting down");
}

/// A server running on its own thread (for tests and embedding).
pub struct Server {
    addr: SocketAddr,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<std::io::Result<()>>>,
}

impl Server {
    /// Binds `config.addr` (port 0: a free port) and serves on a new thread.
    pub fn start(config: Config) -> std::io::Result<Server> {
        let listener = bind(config.addr)?;
        let addr = listener.local_addr()?;
        let rt = runtime(&config)?;
        let (tx, rx) = tokio::sync::oneshot::channel::<()>();
        let grace = config.shutdown_grace;
        let thread = std::thread::Builder::new()
            .name("bondmech-server".into())
            .spawn(move || {
                let r = rt.block_on(async move {
                    let listener = tokio::net::TcpListener::from_std(listener)?;
                    serve(listener, config, async {
                        let _ = rx.await;
                    })
                    .await
                });
                rt.shutdown_timeout(grace + EXIT_WAIT);
                r
            })?;
        Ok(Server {
            addr,
            stop: Some(tx),
            thread: Some(thread),
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Starts the shutdown, as SIGTERM does, without waiting: the listener closes, new work
    /// is refused, in-flight work goes on for the grace period.
    pub fn begin_shutdown(&mut self) {
        if let Some(tx) = self.stop.take() {
            let _ = tx.send(());
        }
    }

    /// Shuts down as on SIGTERM and waits until the server has stopped.
    pub fn shutdown(mut self) -> std::io::Result<()> {
        self.stop_and_join()
    }

    fn stop_and_join(&mut self) -> std::io::Result<()> {
        self.begin_shutdown();
        match self.thread.take() {
            Some(t) => t
                .join()
                .unwrap_or_else(|_| Err(std::io::Error::other("the server thread panicked"))),
            None => Ok(()),
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.stop_and_join();
    }
}
