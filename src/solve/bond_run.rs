//! Solving a raw bond graph scene (no bodies): the graph validated, its causality assigned,
//! its equations read ([`crate::bond::equations`]) and run by the executor as the formulation
//! of `solve/formulation/raw_graph/runner.rs` (an ODE on CVODE, or the velocity-level index-2 DAE
//! — its index-1 variant when `formulation` is [`FormulationKind::Index1`] — on IDA); under
//! `decoupled` the graph's twin. Columns and figures: see that module.

use std::ops::ControlFlow;

use cpu_time::ThreadTime;

use super::executor::{execute, from_t_start};
use super::formulation::raw_graph::runner::{self as raw_graph, columns_of};
use super::non_finite::{map_solver_cause, name_in_bond_graph};
use super::options::{FormulationKind, SolveOptions};
use super::solution::{Row, Solution, Summary};
use crate::bond::assign_causality;
use crate::bond::equations::BondEquations;
use crate::bond::json::RawBondGraph;
use crate::bond::model::BondGraph;
use crate::dae::ImplicitDae;
use crate::scene::Scene;
use crate::solve::SolveError;

fn bond_error(e: impl std::fmt::Display) -> SolveError {
    SolveError::BondGraph(e.to_string().replace('\n', "; "))
}

/// [`bond_error`] for the equations of `g`: a zero inertia with integral causality names the
/// JSON path of its value (`bond_graph.elements[i].value`; it was "element 'm': missing a
/// nonzero inertia", no path).
fn equation_error(g: &BondGraph, e: crate::bond::equations::EquationError) -> SolveError {
    use crate::bond::equations::EquationError;
    if let EquationError::MissingParameter { element, what } = &e {
        let at = g
            .elements
            .iter()
            .position(|x| x.name == *element && x.kind == crate::bond::ElementKind::I);
        if let (Some(i), true) = (at, what.starts_with("a nonzero inertia")) {
            return SolveError::BondGraph(format!(
                "{}.value: I element '{element}' has inertia 0 but integral causality: its flow p/I is undefined (a massless flow is fixed only by joint closures: give the graph its closures, or the element a nonzero value)",
                crate::bond::validate::element_path(i)
            ));
        }
    }
    bond_error(e)
}

/// Every error of an invalid raw bond graph, `; `-separated, each starting with its JSON path.
fn validation_error(e: crate::bond::ValidationErrors) -> SolveError {
    SolveError::BondGraph(
        e.0.iter()
            .map(|b| b.to_string())
            .collect::<Vec<_>>()
            .join("; "),
    )
}

/// The scene's `"bond_graph"` JSON (`null` when it has none).
fn raw_value(scene: &Scene) -> &serde_json::Value {
    scene
        .bond_graph
        .as_ref()
        .unwrap_or(&serde_json::Value::Null)
}

/// Warnings about the parameters of a scene's raw bond graph `g` (a modulus 0 at the start, a
/// number written as a string), each starting with its JSON path
/// ([`crate::bond::parameter_span::warnings`]).
pub fn scene_bond_graph_warnings(scene: &Scene, g: &BondGraph) -> Vec<String> {
    crate::bond::parameter_span::warnings(g, Some(raw_value(scene)), scene.solve.t_start)
}

/// The raw bond graph of a scene (`"bond_graph"`), validated.
pub fn scene_bond_graph(scene: &Scene) -> Result<BondGraph, SolveError> {
    let raw = scene
        .bond_graph
        .as_ref()
        .ok_or_else(|| SolveError::BondGraph("the scene has no bond_graph".into()))?;
    let raw = RawBondGraph::from_value(raw).map_err(validation_error)?;
    let g = raw.to_graph().map_err(validation_error)?;
    let mut errors = crate::bond::validate::check_expression_values(&g, scene.solve.t_start);
    if errors.is_empty() {
        // expressions of t over the whole run, of the states at the start, resistor laws
        errors = crate::bond::parameter_span::check_over_span(
            &g,
            Some(raw_value(scene)),
            scene.solve.t_start,
            scene.solve.t_end,
        );
    }
    if !errors.is_empty() {
        return Err(validation_error(crate::bond::ValidationErrors(errors)));
    }
    Ok(g)
}

/// The solve options written in a raw bond graph scene's `solve` section (see
/// [`solve_bond_graph_streaming`] for what each formulation does on a raw graph).
pub fn raw_bond_graph_options(scene: &Scene) -> SolveOptions {
    let s = &scene.solve;
    SolveOptions {
        formulation: s.formulation,
        joint_stiffness: s.joint_stiffness,
        joint_damping: s.joint_damping,
        rtol: s.rtol,
        atol: s.atol,
        t_start: s.t_start,
        output_times: scene.output_times(),
        max_steps: s.max_steps,
        max_wall_clock: s
            .max_wall_seconds
            .and_then(|w| crate::scene::validate::wall_clock(w).ok()),
        ..SolveOptions::default()
    }
}

/// Solves the raw `"bond_graph"` of a scene with `opts`.
pub fn solve_raw_bond_graph(scene: &Scene, opts: &SolveOptions) -> Result<Solution, SolveError> {
    solve_bond_graph(&scene_bond_graph(scene)?, opts)
}

/// The output columns of a raw bond graph's solutions (see the module documentation), known
/// before solving.
pub fn bond_graph_columns(g: &BondGraph, opts: &SolveOptions) -> Result<Vec<String>, SolveError> {
    let g = &graph_solved(g, opts)?;
    let causality = assign_causality(g).map_err(bond_error)?;
    let eq = BondEquations::new(g, &causality).map_err(|e| equation_error(g, e))?;
    Ok(columns_of(&eq).1)
}

/// The graph a formulation solves: the graph itself, or under `decoupled` its twin, every
/// joint row opened and a spring put in its place (seed 16.6, [`crate::bond::decouple`]).
fn graph_solved<'a>(
    g: &'a BondGraph,
    opts: &SolveOptions,
) -> Result<std::borrow::Cow<'a, BondGraph>, SolveError> {
    if opts.formulation != FormulationKind::Decoupled {
        return Ok(std::borrow::Cow::Borrowed(g));
    }
    let twin = crate::bond::decouple::decouple(g, opts.joint_stiffness, opts.joint_damping)
        .map_err(|e| SolveError::Options(format!("formulation 'decoupled': {e}")))?;
    // a graph without joint rows has nothing to decouple: refused by name, never run as is
    // under a name that says otherwise
    if twin.springs.is_empty() {
        return Err(SolveError::Options(
            "formulation 'decoupled': this raw bond graph has no joint rows (no Sf = 0, no two-bond 1-junction holding a constraint) to replace by stiff springs, so there is nothing to decouple; leave --formulation out (its own equations are solved as they are)".into(),
        ));
    }
    Ok(std::borrow::Cow::Owned(twin.graph))
}

/// Solves a raw bond graph: CVODE when its equations are an ODE, IDA otherwise.
///
/// Errors: invalid graph, causal conflicts (redundant constraints), declared signals (a raw
/// scene has nothing to supply them), no consistent start, solver failure.
pub fn solve_bond_graph(g: &BondGraph, opts: &SolveOptions) -> Result<Solution, SolveError> {
    solve_bond_graph_streaming(g, opts, &mut |_| ControlFlow::Continue(()))
}

/// [`solve_bond_graph`], handing each output row to `observer` as soon as it is computed
/// (`ControlFlow::Break(())` stops early; the solution then ends with that row). The motion
/// starts at `opts.t_start`; rows are written at `opts.output_times`.
pub fn solve_bond_graph_streaming(
    g: &BondGraph,
    opts: &SolveOptions,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, SolveError> {
    from_t_start(opts, observer, |opts, observer| {
        solve_from_first_output(g, opts, observer)
    })
}

/// A raw bond graph's joint rows constrain its flows only (no position-level closures): the
/// formulations that need `g(q)` (`ggl`, `compliant_ggl`, `partitioned`) are refused by name,
/// never run as another; `dae` and `index1` run the graph's own DAE and `decoupled` its twin.
fn refuse_without_closures(g: &BondGraph, f: FormulationKind) -> Result<(), SolveError> {
    match f {
        FormulationKind::Dae | FormulationKind::Index1 => Ok(()),
        FormulationKind::Decoupled => Err(SolveError::Options(
            "formulation 'decoupled': the twin still has constraint rows (a joint row that is not an Sf = 0 or a two-bond 1-junction)".into(),
        )),
        FormulationKind::Ggl | FormulationKind::CompliantGgl | FormulationKind::Partitioned => {
            let rows: Vec<String> = crate::bond::causality::joint_row_elements(g)
                .into_iter()
                .map(|e| format!("'{}'", g.element(e).name))
                .collect();
            Err(SolveError::Options(format!(
                "formulation '{}' needs the joints' position-level closures g(q), and this raw bond graph's constraint junctions ({}) carry none; use dae, index1 or decoupled, or give the junctions closures (a mechanism scene's `graph --as-scene` export has them)",
                f.name(),
                rows.join(", ")
            )))
        }
    }
}

/// [`solve_bond_graph_streaming`] with the first output time as the start time.
fn solve_from_first_output(
    g: &BondGraph,
    opts: &SolveOptions,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, SolveError> {
    let clock = ThreadTime::now();
    let t0 = *opts
        .output_times
        .first()
        .ok_or_else(|| SolveError::Options("no output times".into()))?;
    if let Some(s) = g.signals.first() {
        return Err(SolveError::BondGraph(format!(
            "signal '{s}' has no source in a raw bond graph scene (signals are supplied by the mechanism layer)"
        )));
    }
    let decoupled = opts.formulation == FormulationKind::Decoupled;
    let g = &graph_solved(g, opts)?;
    let causality = assign_causality(g).map_err(bond_error)?;
    let eq = BondEquations::new(g, &causality).map_err(|e| equation_error(g, e))?;
    // the equations are the causality's: its integral storages are the states, its
    // differential inertias the dependent unknowns
    let report = causality.report(g);
    let mut summary = Summary {
        unknowns: eq.n,
        states: report.states,
        dependent: report.differential.into_iter().map(|d| d.element).collect(),
        ..Summary::default()
    };
    let job = if let Some(ode) = eq.ode() {
        summary.formulation = if decoupled {
            summary.joint_stiffness = opts.joint_stiffness;
            "decoupled".into()
        } else {
            "bond_ode".into()
        };
        summary.solver = "CVODE".into();
        raw_graph::ode_job(g, &eq, ode, eq.initial.clone())
    } else {
        refuse_without_closures(g, opts.formulation)?;
        let index1 = opts.formulation == FormulationKind::Index1;
        let dae: ImplicitDae = if index1 {
            eq.index1()
        } else {
            eq.velocity_index2()
        };
        summary.formulation = if index1 {
            "bond_index1".into()
        } else {
            "bond_velocity_index2".into()
        };
        summary.solver = "IDA".into();
        let (y0, yp0) = eq.consistent_start(t0, &eq.initial).map_err(bond_error)?;
        summary.initial_velocity_correction = y0
            .iter()
            .zip(&eq.initial)
            .take(eq.n_states + eq.n_dependent)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        let id = eq.id();
        // λ and z are efforts/flows of the same order as the states: by default they get the
        // states' atol in Newton's convergence test (they are excluded from the error test).
        // Measured on two rigidly coupled masses at rtol 1e-9, atol 1e-11: the mechanisms'
        // 1e-2 leaves λ wrong by 7e-3; atol 1e-9 gives 7e-8 in fewer steps (430 vs 469).
        let alg_atol = opts.multiplier_atol.unwrap_or(opts.atol);
        let atol: Vec<f64> = id
            .iter()
            .map(|&d| if d > 0.5 { opts.atol } else { alg_atol })
            .collect();
        raw_graph::dae_job(
            g,
            &eq,
            crate::solve::formulation::IdDae { dae, id },
            atol,
            (y0, yp0),
        )
    };
    summary.build_cpu_seconds = clock.elapsed().as_secs_f64();
    execute(job, opts, &mut summary, observer)
        .map_err(|e| map_solver_cause(e, |se| name_in_bond_graph(g, &eq, se)))
}
