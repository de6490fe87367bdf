//! The bounded pool: at most `max_concurrent` solve jobs on blocking threads, at most `queue`
//! requests waiting for one (for at most the solve budget), everything beyond refused with 503
//! and `Retry-After` (counted as rejections where the answer is made).
//!
//! Short requests are not stuck behind long ones: a request whose estimated cost
//! ([`estimated_cost`]: unknowns × output rows, from the scene's size and horizon) is at most
//! [`FAST_LANE_COST`] takes a free solve slot, or else one of [`FAST_LANE_SLOTS`] extra slots
//! kept for such requests (the fast lane), with its own queue. A job's slot is held until the job itself ends, even when its client has
//! gone, so the bound holds for the work actually running.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tokio::task::JoinHandle;

use super::metrics::Metrics;
use super::problem::Problem;

/// Requests estimated at most this costly ([`estimated_cost`]) may use the fast lane.
pub const FAST_LANE_COST: f64 = 5_000.0;

/// Extra solve slots kept for cheap requests.
pub const FAST_LANE_SLOTS: usize = 1;

/// A request's estimated cost: unknowns (3 per planar body, 6 per spatial one, one per joint,
/// spring and bond graph element) times output rows, ×20 for the decoupled twin's stiff
/// springs. A rough ordering of requests, not a prediction of seconds.
pub fn estimated_cost(scene: &crate::scene::Scene) -> f64 {
    use crate::scene::Dimension;
    use crate::settings::FormulationKind;
    let per_body = match scene.dimension {
        Dimension::Planar => 3.0,
        Dimension::Spatial => 6.0,
    };
    let mut unknowns = per_body * scene.bodies.len() as f64
        + scene.joints.len() as f64
        + scene.springs.len() as f64;
    if let Some(g) = &scene.bond_graph {
        unknowns += g
            .get("elements")
            .and_then(|e| e.as_array())
            .map_or(0, |e| e.len()) as f64;
    }
    let rows = scene.output_times().len().max(1) as f64;
    let factor = if scene.solve.formulation == FormulationKind::Decoupled {
        20.0
    } else {
        1.0
    };
    unknowns.max(1.0) * rows * factor
}

/// Solve slots and the queue in front of them.
#[derive(Debug)]
pub struct Pool {
    slots: Arc<Semaphore>,
    fast: Arc<Semaphore>,
    queue: usize,
    queue_wait: Duration,
    retry_after: u64,
    metrics: Arc<Metrics>,
}

/// Decrements a gauge when dropped.
struct Gauge<'a>(&'a AtomicUsize);

impl<'a> Gauge<'a> {
    fn up(g: &'a AtomicUsize) -> Gauge<'a> {
        g.fetch_add(1, Ordering::SeqCst);
        Gauge(g)
    }
}

impl Drop for Gauge<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

impl Pool {
    /// `max_concurrent` slots, a queue of `queue`, a longest wait of `queue_wait`.
    pub fn new(
        max_concurrent: usize,
        queue: usize,
        queue_wait: Duration,
        retry_after: u64,
        metrics: Arc<Metrics>,
    ) -> Pool {
        Pool {
            slots: Arc::new(Semaphore::new(max_concurrent.max(1))),
            fast: Arc::new(Semaphore::new(FAST_LANE_SLOTS)),
            queue,
            queue_wait,
            retry_after,
            metrics,
        }
    }

    /// A slot for a request of estimated `cost` ([`estimated_cost`]): a cheap one takes a
    /// free solve slot or else waits for the fast lane; any other waits for a solve slot
    /// ([`Pool::acquire`]).
    pub async fn acquire_for(&self, cost: f64) -> Result<OwnedSemaphorePermit, Problem> {
        if cost.is_nan() || cost > FAST_LANE_COST {
            return self.acquire().await;
        }
        if let Ok(p) = self.slots.clone().try_acquire_owned() {
            return Ok(p);
        }
        self.wait_for(&self.fast).await
    }

    /// A solve slot: at once when one is free, else after waiting in the queue; 503 with
    /// `Retry-After` when the queue is full or the wait longer than allowed. A request
    /// whose client disconnects while queued leaves the queue (its future is dropped).
    pub async fn acquire(&self) -> Result<OwnedSemaphorePermit, Problem> {
        self.wait_for(&self.slots).await
    }

    /// A permit of `slots`, at once or after a bounded wait in the queue.
    async fn wait_for(&self, slots: &Arc<Semaphore>) -> Result<OwnedSemaphorePermit, Problem> {
        if let Ok(p) = slots.clone().try_acquire_owned() {
            return Ok(p);
        }
        let waiting = Gauge::up(&self.metrics.queued);
        if self.metrics.queued.load(Ordering::SeqCst) > self.queue {
            drop(waiting);
            return Err(Problem::unavailable(
                format!(
                    "all solve slots are busy and the queue is full ({} waiting): retry later",
                    self.queue
                ),
                self.retry_after,
            ));
        }
        let r = tokio::time::timeout(self.queue_wait, slots.clone().acquire_owned()).await;
        drop(waiting);
        match r {
            Ok(Ok(p)) => Ok(p),
            Ok(Err(_)) => {
                let mut p = Problem::unavailable("the server is shutting down", self.retry_after);
                p.kind = "shutting-down";
                Err(p)
            }
            Err(_) => Err(Problem::unavailable(
                format!(
                    "no solve slot became free within {} s: retry later",
                    self.queue_wait.as_secs_f64()
                ),
                self.retry_after,
            )),
        }
    }

    /// Runs `job` on a blocking thread holding `slot` until it returns; a panic becomes a 500
    /// problem (a bug, never bad input) and the worker thread survives.
    pub fn spawn<T: Send + 'static>(
        &self,
        slot: OwnedSemaphorePermit,
        job: impl FnOnce() -> Result<T, Problem> + Send + 'static,
    ) -> JoinHandle<Result<T, Problem>> {
        let metrics = self.metrics.clone();
        tokio::task::spawn_blocking(move || {
            let _slot = slot;
            let _running = Gauge::up(&metrics.in_flight);
            let start = Instant::now();
            let r = catch_unwind(AssertUnwindSafe(job));
            metrics.observe_solve(start.elapsed().as_secs_f64());
            match r {
                Ok(r) => r,
                Err(panic) => {
                    let msg = panic
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| panic.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "panic".into());
                    Err(Problem::internal(format!("the solve panicked: {msg}")))
                }
            }
        })
    }
}

/// Awaits a job; a lost job (cancelled runtime) becomes a 500 problem.
pub async fn join<T>(h: JoinHandle<Result<T, Problem>>) -> Result<T, Problem> {
    h.await
        .unwrap_or_else(|e| Err(Problem::internal(format!("the solve job was lost: {e}"))))
}

/// Why a solve should stop at its next output row.
#[derive(Clone, Debug, Default)]
pub struct StopFlags {
    /// Set when the client has gone (its request future was dropped).
    pub client_gone: Arc<AtomicBool>,
    /// Set when the server's shutdown grace period has run out.
    pub shutdown: Arc<AtomicBool>,
}

/// Sets [`StopFlags::client_gone`] when dropped, unless disarmed: lives in the request's
/// future, which hyper drops when the client disconnects.
pub struct CancelOnDrop {
    flag: Option<Arc<AtomicBool>>,
}

impl CancelOnDrop {
    /// Guards `flags.client_gone`.
    pub fn new(flags: &StopFlags) -> CancelOnDrop {
        CancelOnDrop {
            flag: Some(flags.client_gone.clone()),
        }
    }

    /// The request finished (or its response streams on): dropping no longer cancels.
    pub fn disarm(&mut self) {
        self.flag = None;
    }
}

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if let Some(f) = &self.flag {
            f.store(true, Ordering::SeqCst);
        }
    }
}
