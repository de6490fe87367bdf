//! The "integrator" of a reduced problem with no state: a kinematic analysis.
//!
//! When drivers take every degree of freedom (DOF 0), a reduced formulation (`partitioned`)
//! has no independent coordinate to integrate: every coordinate is dependent, solved at each
//! row from the joints' and drivers' rows (positions by Newton, velocities and accelerations
//! from their derivatives, efforts from the dynamics). [`KinematicSteps`] stands where CVODE
//! would: it steps straight to each requested time, with no integration error, and locates
//! the zeros of the root functions (events) by bisection on `t` (they are functions of `t`
//! alone here).

use crate::sundials::{CallbackError, CvodeRootFn, SolverError, SolverStats, Step, StepEvent};

/// Bisection steps on an event's bracket (to the last bit of `t`).
const MAX_BISECTIONS: usize = 200;

/// Steps of a problem without state (see the module documentation).
pub(crate) struct KinematicSteps {
    t: f64,
    roots: Option<(usize, CvodeRootFn)>,
    /// The root functions at `t`.
    g: Vec<f64>,
    stats: SolverStats,
}

impl KinematicSteps {
    /// Starts at `t` with the root functions `roots` (`n`, `g(t, [], out)`).
    pub(crate) fn new(t: f64, roots: Option<(usize, CvodeRootFn)>) -> Result<Self, SolverError> {
        let mut s = KinematicSteps {
            t,
            roots,
            g: Vec::new(),
            stats: SolverStats::default(),
        };
        s.g = s.eval(t)?;
        Ok(s)
    }

    fn eval(&mut self, t: f64) -> Result<Vec<f64>, SolverError> {
        let Some((n, f)) = &mut self.roots else {
            return Ok(Vec::new());
        };
        let mut g = vec![0.0; *n];
        self.stats.root_evals += 1;
        f(t, &[], &mut g).map_err(|e| {
            let message = match e {
                CallbackError::Recoverable(m) | CallbackError::Fatal(m) => m,
            };
            SolverError::CallbackFailed { t, message }
        })?;
        Ok(g)
    }

    /// Which root functions change sign from `a` to `b` (`±1` by direction, 0 otherwise).
    fn crossings(a: &[f64], b: &[f64]) -> Vec<i32> {
        a.iter()
            .zip(b)
            .map(|(&x, &y)| {
                if x < 0.0 && y >= 0.0 {
                    1
                } else if x > 0.0 && y <= 0.0 {
                    -1
                } else {
                    0
                }
            })
            .collect()
    }

    /// Goes to `tout`, or to the first zero of a root function before it.
    pub(crate) fn solve_to(&mut self, tout: f64) -> Result<Step, SolverError> {
        self.stats.steps += 1;
        self.stats.last_step = tout - self.t;
        let g_out = self.eval(tout)?;
        let dirs = Self::crossings(&self.g, &g_out);
        if dirs.iter().all(|&d| d == 0) {
            self.t = tout;
            self.g = g_out;
            return Ok(Step {
                t: tout,
                event: StepEvent::Reached,
            });
        }
        // bisect to the first sign change: [a, b] holds it, g(a) as before
        let (mut a, mut b, mut gb) = (self.t, tout, g_out);
        for _ in 0..MAX_BISECTIONS {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            let gm = self.eval(m)?;
            if Self::crossings(&self.g, &gm).iter().any(|&d| d != 0) {
                (b, gb) = (m, gm);
            } else {
                a = m;
                self.g = gm;
            }
        }
        let dirs = Self::crossings(&self.g, &gb);
        self.t = b;
        self.g = gb;
        Ok(Step {
            t: b,
            event: StepEvent::Root(dirs),
        })
    }

    /// The state: there is none.
    pub(crate) fn y(&self) -> &[f64] {
        &[]
    }

    /// The (empty) state at `t`.
    pub(crate) fn dky(&mut self, _t: f64, _k: i32, _out: &mut [f64]) -> Result<(), SolverError> {
        Ok(())
    }

    /// Requested times reached and root-function evaluations.
    pub(crate) fn stats(&self) -> SolverStats {
        self.stats.clone()
    }

    /// The time reached.
    pub(crate) fn last_step_time(&self) -> f64 {
        self.t
    }

    /// Restarts at `t`.
    pub(crate) fn reinit(&mut self, t: f64) -> Result<(), SolverError> {
        self.t = t;
        self.g = self.eval(t)?;
        Ok(())
    }

    /// Budgets do not apply: no step is taken but the requested ones.
    pub(crate) fn charge_wall_clock(&mut self, _spent: std::time::Duration) {}

    /// See [`KinematicSteps::charge_wall_clock`].
    pub(crate) fn charge_steps(&mut self, _steps: u64) {}
}
