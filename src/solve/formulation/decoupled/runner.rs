//! The decoupled twin (seed 16.6): every joint replaced by a stiff spring-damper, all inertias
//! in integral causality, the ODE `y' = f(t, y)` with `y = [q, v]` on CVODE BDF with the exact
//! Jacobian `∂f/∂y`. It starts prestressed: each spring stretched by `λ / k` so that it carries
//! the pinned mechanism's joint force at the start.

use std::sync::Arc;

use crate::dae::{ConsistentState, ExplicitOde, MechanicsTapes};
use crate::mech::MultibodySystem;
use crate::solve::formulation::DecoupledFormulation;
use crate::solve::formulation::Job;
use crate::solve::formulation::{ExplicitProblem, Formulation, Problem, Start};
use crate::solve::options::SolveOptions;
use crate::solve::reactions::Multipliers;
use crate::solve::rows::OutputEval;
use crate::solve::solution::Summary;
use crate::solve::SolveError;

/// The twin's ODE and its prestressed start.
struct Decoupled {
    ode: Arc<ExplicitOde>,
    y0: Vec<f64>,
    max_order: Option<i32>,
    stab_lim_det: bool,
    linear_solver: &'static str,
}

impl<'a> Formulation<'a> for Decoupled {
    fn first_row_state(&self) -> Vec<f64> {
        self.y0.clone()
    }

    fn segment(&mut self, _t: f64, summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        summary.solver = "CVODE".into();
        summary.unknowns = self.ode.n;
        summary.linear_solver = self.linear_solver.into();
        Ok(Start::Run(Problem::Explicit(ExplicitProblem {
            ode: self.ode.clone(),
            y0: self.y0.clone(),
            max_order: self.max_order,
            stab_lim_det: self.stab_lim_det,
        })))
    }
}

/// The twin of `sys` from the consistent start `init`, with its rows (the joint springs'
/// forces as reactions) and events.
pub(crate) fn job<'a>(
    sys: &MultibodySystem,
    dec: DecoupledFormulation,
    tapes: MechanicsTapes,
    init: &ConsistentState,
    opts: &SolveOptions,
) -> Job<'a> {
    let t0 = opts.output_times[0];
    let mut y0 = crate::solve::formulation::decoupled::prestressed_positions(
        &tapes,
        t0,
        &init.q,
        &init.v,
        &init.lambda,
        opts.joint_stiffness,
    );
    y0.extend(&init.v);
    // the joint springs' forces, compiled only when reactions are read
    let row_force = if crate::solve::formulation::shared::needs_reactions(sys) {
        &dec.row_force[..]
    } else {
        &[]
    };
    let multipliers = Multipliers::Springs(sys.graph.compile(row_force));
    let events = crate::solve::formulation::shared::events(sys, &tapes, &multipliers);
    let rows = OutputEval::new(sys, tapes, &multipliers);
    let ode = Arc::new(dec.ode);
    Job {
        formulation: Box::new(Decoupled {
            linear_solver: opts.linear_solver.resolved_name(ode.n),
            ode,
            y0,
            max_order: opts.twin_max_order,
            stab_lim_det: opts.twin_stab_lim_det,
        }),
        rows: Box::new(rows),
        events,
    }
}
