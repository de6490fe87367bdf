//! One integrator behind the executor: IDA, CVODE or ARKODE's explicit Runge–Kutta, with the
//! counters of the integrators it replaced (a re-init or a new segment keeps counting). The
//! formulations' hooks query and re-initialise it; the executor builds it from a problem
//! ([`super::executor`]).

use super::error::SolveError;
use super::kinematic::KinematicSteps;
use crate::sundials::{Cvode, Erk, Ida, SolverError, SolverStats, Step};

/// One integrator.
pub(super) enum Integ {
    Ida(Ida),
    Cvode(Cvode),
    Erk(Erk),
    /// A reduced problem with no state (a kinematic analysis): straight to each time.
    Kinematic(KinematicSteps),
}

/// The integrator of the current segment, with the counters of the earlier segments and of
/// the integrator's life before its last re-initialisation.
pub(crate) struct Solver {
    integ: Integ,
    earlier: SolverStats,
}

macro_rules! each {
    ($s:expr, $i:ident => $e:expr) => {
        match $s {
            Integ::Ida($i) => $e,
            Integ::Cvode($i) => $e,
            Integ::Erk($i) => $e,
            Integ::Kinematic($i) => $e,
        }
    };
}

impl Solver {
    pub(super) fn solve_to(&mut self, t: f64) -> Result<Step, SolverError> {
        each!(&mut self.integ, i => i.solve_to(t))
    }

    /// [`Solver::solve_to`] that returns early at the first internal step before `t` for which
    /// `watch(t_n, y(t_n))` is `true` (IDA; the other integrators are not watched).
    pub(super) fn solve_to_watched(
        &mut self,
        t: f64,
        watch: &mut dyn FnMut(f64, &[f64]) -> bool,
    ) -> Result<Step, SolverError> {
        match &mut self.integ {
            Integ::Ida(i) => i.solve_to_watched(t, watch),
            other => each!(other, i => i.solve_to(t)),
        }
    }

    /// The state at the last return.
    pub(crate) fn y(&self) -> &[f64] {
        each!(&self.integ, i => i.y())
    }

    /// The interpolated state at `t` (within the last step) into `out`.
    pub(crate) fn dky(&mut self, t: f64, out: &mut [f64]) -> Result<(), SolverError> {
        each!(&mut self.integ, i => i.dky(t, 0, out))
    }

    /// The counters of the whole run so far.
    pub(crate) fn stats(&self) -> SolverStats {
        let mut s = self.earlier.clone();
        s.accumulate(&each!(&self.integ, i => i.stats()));
        s
    }

    /// Last internal step size.
    pub(crate) fn last_step(&self) -> f64 {
        each!(&self.integ, i => i.stats()).last_step
    }

    /// Time of the last internal step (CVODE, ARKODE; IDA: its current time).
    pub(crate) fn last_step_time(&self) -> f64 {
        match &self.integ {
            Integ::Ida(i) => i.t(),
            Integ::Cvode(c) => c.last_step_time(),
            Integ::Erk(e) => e.last_step_time(),
            Integ::Kinematic(k) => k.last_step_time(),
        }
    }

    /// IDA's steps accepted after recovered failures (empty for the other integrators).
    pub(crate) fn recovered_failures(&self) -> Vec<crate::sundials::RecoveredFailure> {
        match &self.integ {
            Integ::Ida(i) => i.recovered_failures().to_vec(),
            _ => Vec::new(),
        }
    }

    /// IDA, when it is the integrator.
    pub(crate) fn ida(&mut self) -> Option<&mut Ida> {
        match &mut self.integ {
            Integ::Ida(i) => Some(i),
            _ => None,
        }
    }

    /// Re-initialises IDA at `(t, y, y')` (its counters restart; the executor keeps them).
    pub(crate) fn reinit_ida(&mut self, t: f64, y: &[f64], yp: &[f64]) -> Result<(), SolveError> {
        self.bank();
        if let Integ::Ida(i) = &mut self.integ {
            i.reinit(t, y, yp)?;
        }
        Ok(())
    }

    /// Re-initialises an ODE integrator at `(t, y)`; an explicit method starts with step `h`
    /// (a restart at a switching function's zero changes the right-hand side's derivatives,
    /// not the time scale of the motion).
    pub(crate) fn reinit_ode(&mut self, t: f64, y: &[f64], h: f64) -> Result<(), SolveError> {
        self.bank();
        match &mut self.integ {
            Integ::Ida(_) => {}
            Integ::Cvode(c) => c.reinit(t, y)?,
            Integ::Erk(e) => {
                e.reinit(t, y)?;
                e.set_init_step(if h.is_finite() { h.abs() } else { 0.0 })?;
            }
            Integ::Kinematic(k) => k.reinit(t)?,
        }
        Ok(())
    }

    /// Steps until `t` is reached (a re-integration to a known point, roots muted by the
    /// formulation).
    pub(crate) fn advance_to(&mut self, t: f64) -> Result<(), SolveError> {
        loop {
            match self.solve_to(t) {
                Ok(s) if s.t >= t => return Ok(()),
                Ok(_) => continue,
                Err(e) => return Err(e.into()),
            }
        }
    }

    /// Counts `spent` (time of the run outside the integrator: the formulation's checks, the
    /// rows written) against the wall-clock budget.
    pub(super) fn charge_wall_clock(&mut self, spent: std::time::Duration) {
        each!(&mut self.integ, i => i.charge_wall_clock(spent));
    }

    /// Moves the current integrator's counters to the earlier ones (before a re-init).
    pub(super) fn bank(&mut self) {
        self.earlier = self.stats();
    }

    /// The solver of `integ`, carrying `earlier` counters and charging its budgets with the
    /// steps and wall-clock time already spent.
    pub(super) fn new(
        mut integ: Integ,
        (earlier, wall): (SolverStats, std::time::Duration),
    ) -> Solver {
        each!(&mut integ, i => {
            i.charge_wall_clock(wall);
            i.charge_steps(earlier.steps);
        });
        Solver { integ, earlier }
    }
}
