//! What a solve hands back: the rows at the output times ([`Solution`]), each streamed as a
//! [`Row`] while the solve runs, and the statistics and quality figures ([`Summary`]).

use serde::Serialize;

/// Statistics and quality figures of one solve (the `--summary` JSON).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// `ggl`, `compliant_ggl` or `decoupled`.
    pub formulation: String,
    /// `IDA` or `CVODE`.
    pub solver: String,
    /// The partition at the start, by element name (the `dae`, `index1` and `partitioned`
    /// formulations, and raw bond graphs): the integral-causality storages whose flows (the
    /// inertias) and displacements (the springs' capacitors) are the states, as
    /// `graph --causality` lists them in `states`.
    pub states: Vec<String>,
    /// The differential-causality inertias whose flows are dependent unknowns at the start (as
    /// `graph --causality` lists them in `differential[].element`).
    pub dependent: Vec<String>,
    /// Number of unknowns handed to the solver.
    pub unknowns: usize,
    /// Linear solver of the Newton iterations: `dense`, `faer` or `klu` (what `auto` chose).
    pub linear_solver: String,
    /// Internal steps.
    pub steps: u64,
    /// Residual (IDA) or right-hand side (CVODE) evaluations.
    pub residual_evals: u64,
    /// Jacobian evaluations.
    pub jacobian_evals: u64,
    /// Linear solver setups (factorisations).
    pub linear_setups: u64,
    /// Error test failures.
    pub error_test_failures: u64,
    /// Newton iterations.
    pub nonlinear_iterations: u64,
    /// Newton convergence failures.
    pub nonlinear_conv_failures: u64,
    /// Last step size.
    pub last_step: f64,
    /// CPU seconds of the integration (this thread; model building excluded).
    pub cpu_seconds: f64,
    /// CPU seconds spent building the model (scene → compiled tapes).
    pub build_cpu_seconds: f64,
    /// Largest |g(q)| at the output times (for the decoupled twin: the largest spring stretch).
    pub max_constraint_error: f64,
    /// `max |E(t) − E(0)| / max(|E(0)|, max T)` over the rows, reported only when the scene
    /// conserves energy (`energy_check` = `conserved`); `None` (JSON `null`) otherwise.
    pub energy_drift: Option<f64>,
    /// `conserved` (no dampers, no loads, no resistors or sources: `energy_drift` measures
    /// the integration's drift) or `not_conserved` (see `energy_note`).
    pub energy_check: String,
    /// Why energy is not conserved (the first damper, load, resistor or source that
    /// exchanges it), or empty.
    pub energy_note: String,
    /// The drivers' work `∫ Σ P_d dt` (J) from the start to the last row, by the trapezoidal
    /// rule on the rows' `<driver>.power` columns: the energy balance of a driven scene is
    /// `E(t) − E(0) = W_drivers + W_loads − W_dampers`; `None` (JSON `null`) without drivers.
    pub driver_work: Option<f64>,
    /// How `driver_work` was summed: the trapezoidal rule on the rows, how many and their
    /// largest spacing (its error is the rule's, O(h²) in the output spacing, not the
    /// solver's); empty without drivers.
    pub driver_work_note: String,
    /// Degrees of freedom left by the joints and drivers at the start (`n_v − rank G_v`).
    pub dof: usize,
    /// The drivers take every degree of freedom (`dof` 0): a kinematic analysis — positions by
    /// Newton on the rows, velocities and accelerations from the rows' derivatives, efforts
    /// (driver torques, reactions) from the dynamics (inverse dynamics): no integration error
    /// beyond the Newton tolerance.
    pub kinematic_analysis: bool,
    /// Whether the solve reached its last output time.
    pub completed: bool,
    /// The time the integration reached (the last output time when `completed`).
    pub t_reached: f64,
    /// What stopped an incomplete solve: `max_steps`, `max_wall_seconds`, `interrupt` (SIGINT,
    /// SIGTERM: [`crate::interrupt`]) or `solver_error`.
    pub stopped_by: Option<String>,
    /// ‖q − q₀‖ of the initial projection onto the joints.
    pub initial_position_correction: f64,
    /// ‖v − v₀‖ of the initial projection.
    pub initial_velocity_correction: f64,
    /// Joints found redundant at the start (linearly dependent rows).
    pub redundant_joints: Vec<String>,
    /// Compliance ε of the compliant GGL where it was used (0 when plain GGL did all the work).
    pub compliance: f64,
    /// Whether the compliant GGL was used at all (chosen, redundant joints, or singular passages).
    pub compliance_used: bool,
    /// Simulated time spent in the compliant GGL (s).
    pub compliant_time: f64,
    /// Singular passages met by the GGL: plain GGL failed near a rank-deficient `G_v` and the
    /// compliant GGL carried the motion through (the switch), and every later passage, found
    /// as a peak of `κ(G_v M⁺ G_vᵀ)` above [`PASSAGE_CONDITION`](crate::partition::thresholds::PASSAGE_CONDITION) at the output times.
    pub singular_passages: Vec<SingularPassage>,
    /// Times the index-1 formulation re-selected its dependent velocities.
    pub index1_reselections: u64,
    /// Whether the default DAE kept the mechanism's energy as an invariant (a row
    /// `E(q, v) = E₀` with its multiplier, [`crate::solve::formulation::EnergyInvariant`]).
    pub energy_invariant: bool,
    /// Times the partitioned formulation re-chose its dependent coordinates and velocities
    /// (its dependent block had degraded).
    pub partition_rechoices: u64,
    /// Zeros of the loads' switching functions the partitioned formulation stopped at (and
    /// mode corrections at outputs): each restarts its integrator on the other branch of a
    /// `max`, `min`, `abs`, `sign` or `select` (`expr::switches`).
    pub switchings: u64,
    /// Times the GGL re-chose the dependent velocities it leaves out of IDA's error test
    /// (including switches to and from keeping every velocity in it).
    pub ggl_error_test_reselections: u64,
    /// Integrator of the partitioned formulation (`adams`, `bdf` or `erk`; empty otherwise).
    pub integrator: String,
    /// Joint stiffness of the decoupled twin (0 otherwise).
    pub joint_stiffness: f64,
    /// Non-fatal remarks about the model.
    pub warnings: Vec<String>,
    /// Events met, in time order (`"events"` of the scene): name and time of each zero
    /// crossing that counted; a `stop` event is the last one.
    pub events: Vec<EventRecord>,
    /// GGL on IDA: the steps accepted after recovered Newton convergence or error test failures
    /// (time and counts), at most [`crate::sundials::MAX_LOGGED_FAILURES`]; empty for the
    /// other formulations.
    pub recovered_failures: Vec<crate::sundials::RecoveredFailure>,
}

/// How many warnings of one routine kind (a re-selection of the partition) a run lists; the
/// rest are counted in one closing line ([`Summary::routine_warning`]). A 100 s run of a bead
/// sliding through its bar's pivot re-selects its dependent velocity about 200 times, each a
/// correct and expected event: 205 warning lines buried the one that mattered.
pub const ROUTINE_WARNINGS_LISTED: u64 = 3;

impl Summary {
    /// A warning of a routine event of kind `kind` (e.g. `"index1: partition re-selected"`):
    /// listed for the first `ROUTINE_WARNINGS_LISTED` (3) events of that kind; after that one line
    /// `"<kind>: N more times (not listed; …)"` counts the others.
    pub fn routine_warning(&mut self, kind: &str, message: String) {
        let folded = format!("{kind}: ");
        let more = |w: &str| -> Option<u64> {
            w.strip_prefix(&folded)?
                .split_once(" more time")?
                .0
                .parse()
                .ok()
        };
        if let Some(i) = self.warnings.iter().position(|w| more(w).is_some()) {
            let n = more(&self.warnings[i]).unwrap_or(0) + 1;
            self.warnings[i] = format!(
                "{kind}: {n} more times (not listed; the summary's counters have every one)"
            );
            return;
        }
        let listed = self.warnings.iter().filter(|w| w.starts_with(kind)).count() as u64;
        if listed < ROUTINE_WARNINGS_LISTED {
            self.warnings.push(message);
        } else {
            self.warnings.push(format!(
                "{kind}: 1 more time (not listed; the summary's counters have every one)"
            ));
        }
    }
}

/// One event met during a solve.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EventRecord {
    /// The event's name.
    pub name: String,
    /// Time of the zero crossing (located by the integrator's root finding).
    pub t: f64,
}

/// A solved trajectory: one row per output time.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Column names (without `t`).
    pub columns: Vec<String>,
    /// Output times.
    pub times: Vec<f64>,
    /// `rows[k][c]`: column `c` at `times[k]`.
    pub rows: Vec<Vec<f64>>,
    /// Statistics.
    pub summary: Summary,
}

impl Solution {
    /// The values of column `name` over time.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.columns.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| r[c]).collect())
    }

    /// The value of column `name` at output index `k`.
    pub fn value(&self, k: usize, name: &str) -> Option<f64> {
        let c = self.columns.iter().position(|n| n == name)?;
        self.rows.get(k).map(|r| r[c])
    }

    /// CSV text: header `t,<columns>`, one row per output time (written by the `csv` crate:
    /// a column name holding a comma or a quote is quoted per RFC 4180).
    pub fn to_csv(&self) -> String {
        let mut bytes = Vec::new();
        self.write_csv(&mut bytes)
            .expect("writing to memory does not fail");
        String::from_utf8(bytes).expect("CSV of UTF-8 names and numbers is UTF-8")
    }

    /// Writes [`Solution::to_csv`] to `w`, row by row.
    pub fn write_csv(&self, w: impl std::io::Write) -> std::io::Result<()> {
        let mut csv = crate::output::CsvRows::new(w, &self.columns)?;
        for (t, r) in self.times.iter().zip(&self.rows) {
            csv.row(*t, r)?;
        }
        csv.finish().map(drop)
    }
}

/// One output row handed to a streaming observer.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// Time.
    pub t: f64,
    /// Column values (same order as [`Solution::columns`]).
    pub values: &'a [f64],
}

/// A singular passage: plain GGL failed near a rank-deficient `G_v` and the solve continued
/// with the compliant GGL from the last output before the failure.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SingularPassage {
    /// Time of plain GGL's last accepted step before it failed (where `G_v` was losing rank).
    pub t: f64,
    /// Joints whose rows were losing independence there.
    pub joints: Vec<String>,
    /// `κ(G_v M⁺ G_vᵀ)` at that step.
    pub condition: f64,
    /// The output time the compliant GGL restarted from (the last one plain GGL reached).
    pub restarted_at: f64,
    /// Time at which plain GGL resumed (`None`: compliant to the end).
    pub plain_again_at: Option<f64>,
    /// The IDA failure that revealed the passage (e.g. `IDA_CONV_FAIL`), or `conditioning
    /// peak` for a passage found while the compliant GGL was already running (no restart; then
    /// `t` is the peak of κ located between outputs and `restarted_at = t`).
    pub failure: String,
}

impl SingularPassage {
    /// A passage through the singular configuration `c` found at `t`, the run restarted at
    /// `restarted_at` (not plain again yet), for the reason `failure`.
    pub(crate) fn begun(
        t: f64,
        c: crate::partition::JointConditioning,
        restarted_at: f64,
        failure: String,
    ) -> Self {
        SingularPassage {
            t,
            joints: c.joints,
            condition: c.condition,
            restarted_at,
            plain_again_at: None,
            failure,
        }
    }
}
