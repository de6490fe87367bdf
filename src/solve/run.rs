//! Solving a mechanism: the consistent start, then the formulation chosen in
//! [`SolveOptions::formulation`] (one folder each, `solve/formulation/<name>/`) run by the one
//! executor (`solve/executor.rs`). The public names of the solve (its [`Solution`] and
//! [`Summary`], the thresholds of the recoveries) are re-exported here.

use std::ops::ControlFlow;

use cpu_time::ThreadTime;

use super::executor::{execute, from_t_start};
use super::formulation::shared::{default_compliance, JobStart};
use super::formulation::{
    decoupled::runner as decoupled, ggl::runner as ggl, index1::runner as index1,
    partitioned::runner as partitioned,
};
use super::options::{FormulationKind, SolveOptions};
use crate::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use crate::mech::MultibodySystem;
use crate::solve::formulation::{DecoupledFormulation, GglFormulation};
use crate::solve::SolveError;

pub use super::rows::output_columns;
pub use super::solution::{EventRecord, Row, SingularPassage, Solution, Summary};
pub use crate::partition::thresholds::{
    GGL_ERROR_TEST_SINGULAR, MAX_SWITCHINGS_PER_OUTPUT, PASSAGE_CONDITION, REGULAR_CONDITION,
    REGULAR_PARTITION, REPARTITION_CONDITION, REPARTITION_GROWTH, RESUME_PLAIN_GGL,
    SINGULAR_CONDITION, SINGULAR_PARTITION, STIFFNESS_LIMIT, TYPICAL_CONDITION,
};

/// Solves a multibody system with the chosen formulation, streaming rows to `observer`
/// (return `ControlFlow::Break(())` to stop early; the rows so far are returned).
///
/// The motion starts at `opts.t_start`; rows are written at `opts.output_times`.
pub fn solve_system(
    sys: MultibodySystem,
    opts: &SolveOptions,
    build_cpu_seconds: f64,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, SolveError> {
    from_t_start(opts, observer, |opts, observer| {
        solve_from_first_output(sys, opts, build_cpu_seconds, observer)
    })
}

/// [`solve_system`] with the first output time as the start time.
fn solve_from_first_output(
    mut sys: MultibodySystem,
    opts: &SolveOptions,
    build_cpu_seconds: f64,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, SolveError> {
    let t0 = *opts
        .output_times
        .first()
        .ok_or_else(|| SolveError::Options("no output times".into()))?;
    let clock = ThreadTime::now();
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, t0)?;
    let mut summary = Summary {
        initial_position_correction: init.position_correction,
        initial_velocity_correction: init.velocity_correction,
        redundant_joints: init.redundant_joints.clone(),
        warnings: sys.warnings.clone(),
        formulation: opts.formulation.name().into(),
        ..Summary::default()
    };
    // initial velocities that violate the joints are projected onto them: say by how much
    if init.velocity_correction > crate::mech::geometry::INITIAL_VIOLATION_WARNING {
        if let Some(w) = velocity_warning(&sys, &tapes, t0, &init) {
            summary.warnings.push(w);
        }
    }
    // the chapter's index-1 DAE and the partitioned ODE leave redundant rows out of their
    // dependent block (and say so); the other IDA formulations take the compliant GGL
    let own_rows = matches!(
        opts.formulation,
        FormulationKind::Dae | FormulationKind::Index1 | FormulationKind::Partitioned
    );
    if !init.redundant_joints.is_empty() && !own_rows {
        summary.warnings.push(format!(
            "redundant constraints at t = {t0}: joints [{}] are linearly dependent; solved with the compliant GGL",
            init.redundant_joints.join(", ")
        ));
    }
    // the partitioned ODE's states are the degrees of freedom: with none there is nothing to
    // integrate, and its rows are the kinematic analysis (solve::kinematic steps to them)
    let dof = init.v.len().saturating_sub(init.rank);
    summary.dof = dof;
    summary.kinematic_analysis = dof == 0 && !sys.drivers.is_empty();
    let mut build = build_cpu_seconds + clock.elapsed().as_secs_f64();
    // the formulation's build (and the index-1 DAE's causality analysis) is model building,
    // not integration
    let t = ThreadTime::now();
    let job = match opts.formulation {
        FormulationKind::Decoupled => {
            let dec =
                DecoupledFormulation::build(&mut sys, opts.joint_stiffness, opts.joint_damping)?;
            let tapes = MechanicsTapes::new(&mut sys, &c, Some(dec.spring_energy));
            summary.joint_stiffness = opts.joint_stiffness;
            summary
                .warnings
                .extend(crate::solve::formulation::decoupled::prestress_warning(
                    &sys,
                    &init.lambda,
                    opts.joint_stiffness,
                ));
            if opts.joint_damping != 0.0 && sys.energy_exchange.is_none() {
                sys.energy_exchange = Some(format!(
                    "the twin's joint springs have damping {} (solve.joint_damping)",
                    opts.joint_damping
                ));
            }
            decoupled::job(&sys, dec, tapes, &init, opts)
        }
        FormulationKind::Partitioned => {
            partitioned::job(JobStart::new(sys, &c, tapes, &init, opts), &mut summary)
        }
        FormulationKind::Index1 => {
            summary.formulation = "index1".into();
            index1::job(JobStart::new(sys, &c, tapes, &init, opts), &mut summary)
        }
        FormulationKind::Dae => {
            summary.formulation = "dae".into();
            index1::job(JobStart::new(sys, &c, tapes, &init, opts), &mut summary)
        }
        FormulationKind::Ggl | FormulationKind::CompliantGgl => {
            let eps_default = default_compliance(&sys, opts);
            let eps = if opts.formulation == FormulationKind::CompliantGgl
                || !init.redundant_joints.is_empty()
            {
                eps_default
            } else {
                0.0
            };
            let ggl = GglFormulation::build(&mut sys, &c, eps);
            ggl::job(sys, ggl, tapes, &init, (eps, eps_default), t0, opts)
        }
    };
    build += t.elapsed().as_secs_f64();
    let result = execute(job, opts, &mut summary, observer);
    // a formulation rebuilt during the run (index 1, dae) adds its own build time
    let mut sol = result.map_err(|e| e.map_partial(|p| p.summary.build_cpu_seconds += build))?;
    sol.summary.build_cpu_seconds += build;
    Ok(sol)
}

/// The warning for an initial velocity projection, or `None` where the projection only set the
/// drivers' prescribed rates from velocities the scene does not give (a driven scene at rest:
/// nothing the user wrote was wrong). The rows `G_v v₀ + b` at the user's velocities `v₀` (on
/// the projected positions) tell which rows were open: a joint's row (`b = 0`) — the initial
/// velocities violate the joints — or only drivers' rows (`b = −ṡ(t₀)`), which is worth a
/// warning only where the scene gives velocities that disagree with the prescribed rates.
fn velocity_warning(
    sys: &MultibodySystem,
    tapes: &MechanicsTapes,
    t0: f64,
    init: &crate::dae::ConsistentState,
) -> Option<String> {
    let tol = crate::mech::geometry::INITIAL_VIOLATION_WARNING;
    let change = || velocity_change_note(sys, &init.v);
    let mut x: Vec<f64> = init.q.clone();
    x.extend(sys.velocities.iter().map(|c| c.initial));
    let gv = tapes.gv.matrix(t0, &x);
    let v0 = nalgebra::DVector::from_column_slice(&x[init.q.len()..]);
    let mut r = &gv * &v0;
    if tapes.bias.is_some() {
        r += nalgebra::DVector::from_vec(tapes.bias_at(t0, &x));
    }
    let driver_rows: Vec<usize> = sys.drivers.iter().map(|d| d.row).collect();
    let joint_open = (0..r.len()).any(|i| !driver_rows.contains(&i) && r[i].abs() > tol);
    if joint_open || driver_rows.is_empty() {
        return Some(format!(
            "the initial velocities violate the joints: projected onto them before starting, changed by {:.3e} (norm of the change of all velocity coordinates, m/s and rad/s: summary.initial_velocity_correction){}",
            init.velocity_correction,
            change()
        ));
    }
    // velocities the scene gives, not all zero (zeros written out are a start at rest)
    let given = sys
        .given_velocities
        .iter()
        .zip(&sys.velocities)
        .any(|(&g, c)| g && c.initial != 0.0);
    let open: Vec<String> = sys
        .drivers
        .iter()
        .filter(|d| r[d.row].abs() > tol)
        .map(|d| format!("drivers[{}] '{}'", d.index, d.name))
        .collect();
    (given && !open.is_empty()).then(|| {
        format!(
            "the initial velocities disagree with the prescribed rates of [{}]: projected onto them before starting, changed by {:.3e} (summary.initial_velocity_correction){}",
            open.join(", "),
            init.velocity_correction,
            change()
        )
    })
}

/// What the initial projection did to the velocities `v` (projected from the scene's): the
/// largest change by name, and whether the velocities the scene gives were kept.
fn velocity_change_note(sys: &crate::mech::MultibodySystem, v: &[f64]) -> String {
    let changed = |j: usize| (v[j] - sys.velocities[j].initial).abs();
    let Some(j) =
        (0..v.len().min(sys.velocities.len())).max_by(|&a, &b| changed(a).total_cmp(&changed(b)))
    else {
        return String::new();
    };
    let given = |j: usize| sys.given_velocities.get(j).copied().unwrap_or(false);
    let given_changed = (0..v.len()).any(|k| given(k) && changed(k) > 0.0);
    let kept = if given_changed {
        "; the velocities the scene gives could not close the joints alone and changed too"
    } else if (0..v.len()).any(given) {
        "; the velocities the scene gives are kept, the others changed"
    } else {
        ""
    };
    format!(
        "; the largest change: '{}' {:.6e} → {:.6e}{kept}",
        sys.velocities[j].name, sys.velocities[j].initial, v[j]
    )
}
