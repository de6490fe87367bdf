//! What the runners share. Each formulation's runner implements [`super::Formulation`] over
//! the equations of its own folder (`ggl/equations.rs` the GGL's residual, `ggl/runner.rs`
//! its restarts, compliant switch and statistics) (no run loop: the executor runs them all): the GGL (plain and compliant), the index-1 DAE (`index1`
//! and the chapter's `dae`), the partitioned ODE, the decoupled twin, and a raw bond graph's
//! own equations. What the mechanism formulations share (their events, compliance and
//! tolerances) is here.

use super::Events;
use crate::dae::ConsistentState;
use crate::dae::ConstraintExprs;
use crate::dae::MechanicsTapes;
use crate::mech::MultibodySystem;
use crate::solve::options::SolveOptions;
use crate::solve::reactions::{EventEval, Multipliers, ReactionEval, StateMultipliers};

/// The scene's events with the reactions read from `multipliers` (`None`: the scene has none).
pub(crate) fn events(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    multipliers: &Multipliers,
) -> Option<Events> {
    let eval = EventEval::new(sys, || {
        ReactionEval::new(sys, &tapes.gv, multipliers.clone(), (true, true))
    });
    (eval.len() > 0).then(|| Events {
        eval,
        defs: sys.events.clone(),
    })
}

/// The multipliers an IDA formulation's events read: solved from the interpolated `(t, q, v)`
/// ([`Multipliers::FromState`]), not interpolated (IDA's error test leaves them out).
pub(crate) fn solved_multipliers(sys: &MultibodySystem, tapes: &MechanicsTapes) -> Multipliers {
    Multipliers::FromState(Box::new(StateMultipliers::new(
        tapes.forces.clone(),
        tapes.gamma.clone(),
        sys.mass.clone(),
    )))
}

/// Whether a solve computes reactions at all (as output columns or inside an event).
pub(crate) fn needs_reactions(sys: &MultibodySystem) -> bool {
    sys.reaction_outputs || !sys.drivers.is_empty() || sys.events.iter().any(|e| e.uses_reactions)
}

/// The compliant GGL's `ε`: `solve.compliance`, or `1e-10 / M_max` (a joint force of 1 N moves
/// the joint by 1e-10 m on the heaviest inertia's scale).
pub(crate) fn default_compliance(sys: &MultibodySystem, opts: &SolveOptions) -> f64 {
    let mref = sys.mass.iter().fold(0.0f64, |a, &b| a.max(b)).max(1e-300);
    opts.compliance.unwrap_or(1e-10 / mref)
}

/// The absolute tolerance of the multipliers in IDA's Newton convergence test.
pub(crate) fn multiplier_atol(opts: &SolveOptions) -> f64 {
    opts.multiplier_atol.unwrap_or(1e-2)
}

/// What a mechanism formulation's job starts from: the system, its constraint expressions and
/// tapes, the consistent start (and its state `x = [q, v]` at `t0`, the first output time) and
/// the options.
pub(crate) struct JobStart<'a, 'b> {
    pub sys: MultibodySystem,
    pub c: &'a ConstraintExprs,
    pub tapes: MechanicsTapes,
    pub init: &'b ConsistentState,
    pub opts: &'b SolveOptions,
    pub t0: f64,
    pub x: Vec<f64>,
}

impl<'a, 'b> JobStart<'a, 'b> {
    /// The start of a job from the consistent start `init` at the first output time.
    pub(crate) fn new(
        sys: MultibodySystem,
        c: &'a ConstraintExprs,
        tapes: MechanicsTapes,
        init: &'b ConsistentState,
        opts: &'b SolveOptions,
    ) -> Self {
        let t0 = opts.output_times[0];
        let x: Vec<f64> = init.q.iter().chain(&init.v).copied().collect();
        JobStart {
            sys,
            c,
            tapes,
            init,
            opts,
            t0,
            x,
        }
    }
}

/// The joints a warning names, in words a reader can take in: every name up to
/// [`LISTED_JOINTS`], else the first four, an ellipsis, the last two and how many there are
/// (`pivot0, pivot1, pivot2, pivot3, …, left39, right39 (121 joints)`); the run's JSON keeps
/// the whole list (`singular_passages[].joints`).
///
/// ```text
/// [a, b]                      → "a, b"
/// [j0, j1, …, j120] (121)     → "j0, j1, j2, j3, …, j119, j120 (121 joints)"
/// ```
pub(crate) fn joints_in_words(names: &[String]) -> String {
    if names.len() <= LISTED_JOINTS {
        return names.join(", ");
    }
    let n = names.len();
    format!(
        "{}, …, {} ({n} joints)",
        names[..4].join(", "),
        names[n - 2..].join(", ")
    )
}

/// The most joints a warning lists by name ([`joints_in_words`]).
pub(crate) const LISTED_JOINTS: usize = 8;

#[cfg(test)]
mod tests {
    use super::joints_in_words;

    #[test]
    fn a_warning_about_121_joints_names_six_and_counts_them() {
        let names: Vec<String> = (0..121).map(|i| format!("j{i}")).collect();
        assert_eq!(
            joints_in_words(&names),
            "j0, j1, j2, j3, …, j119, j120 (121 joints)"
        );
        assert_eq!(joints_in_words(&names[..8]), names[..8].join(", "));
    }
}
