//! Solving a raw bond graph scene (no bodies): the equations of [`crate::bond::equations`]
//! on CVODE (pure ODE: BDF, Newton, exact Jacobian) or IDA (velocity-level index-2 DAE when
//! storages are in differential causality or loops are algebraic; the index-1 variant when
//! `formulation` is [`FormulationKind::Index1`]).
//!
//! Output columns: every unknown of `y` except the loop variables (`p_<I>`, `q_<C>`, `x_…`,
//! dependent `p_<I>`, `lambda_<I>`), then `f_<I>` (flow `p/m`) of every inertia, `e_<C>`
//! (effort `q/C`) of every capacitor, and `energy = Σ p²/2m + Σ q²/2C`.
//! `summary.max_constraint_error` is the largest `|φ_d − p_d/m_d|` at the output times and
//! `summary.energy_drift` the largest `|E(t) − E(0)|` relative to `max(|E(0)|, max E)`.

use std::ops::ControlFlow;
use std::sync::Arc;

use cpu_time::ThreadTime;

use super::non_finite::{map_solver_cause, name_in_bond_graph};
use super::options::{FormulationKind, SolveOptions};
use super::run::{
    emit, from_t_start, is_budget, set_completed, set_energy, stopped, Row, Solution, Summary,
};
use crate::bond::assign_causality;
use crate::bond::equations::{BondEquations, VariableKind};
use crate::bond::json::RawBondGraph;
use crate::bond::model::{BondGraph, ElementKind, Parameter};
use crate::dae::ImplicitDae;
use crate::expr::Tape;
use crate::scene::Scene;
use crate::sundials::{CvodeOptions, SolverStats};
use crate::Error;

fn bond_error(e: impl std::fmt::Display) -> Error {
    Error::BondGraph(e.to_string().replace('\n', "; "))
}

/// Every error of an invalid raw bond graph, `; `-separated, each starting with its JSON path.
fn validation_error(e: crate::bond::ValidationErrors) -> Error {
    Error::BondGraph(
        e.0.iter()
            .map(|b| b.to_string())
            .collect::<Vec<_>>()
            .join("; "),
    )
}

/// The raw bond graph of a scene (`"bond_graph"`), validated.
pub fn scene_bond_graph(scene: &Scene) -> Result<BondGraph, Error> {
    let raw = scene
        .bond_graph
        .as_ref()
        .ok_or_else(|| Error::BondGraph("the scene has no bond_graph".into()))?;
    let raw = RawBondGraph::from_value(raw).map_err(validation_error)?;
    let g = raw.to_graph().map_err(validation_error)?;
    let errors = crate::bond::validate::check_expression_values(&g, scene.solve.t_start);
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
pub fn solve_raw_bond_graph(scene: &Scene, opts: &SolveOptions) -> Result<Solution, Error> {
    solve_bond_graph(&scene_bond_graph(scene)?, opts)
}

/// The output columns of a raw bond graph's solutions (see the module documentation), known
/// before solving.
pub fn bond_graph_columns(g: &BondGraph, opts: &SolveOptions) -> Result<Vec<String>, Error> {
    let g = &graph_solved(g, opts)?;
    let causality = assign_causality(g).map_err(bond_error)?;
    let eq = BondEquations::new(g, &causality).map_err(bond_error)?;
    Ok(columns_of(&eq).1)
}

/// The graph a formulation solves: the graph itself, or under `decoupled` its twin, every
/// joint row opened and a spring put in its place (seed 16.6, [`crate::bond::decouple`]).
fn graph_solved<'a>(
    g: &'a BondGraph,
    opts: &SolveOptions,
) -> Result<std::borrow::Cow<'a, BondGraph>, Error> {
    if opts.formulation != FormulationKind::Decoupled {
        return Ok(std::borrow::Cow::Borrowed(g));
    }
    let twin = crate::bond::decouple::decouple(g, opts.joint_stiffness, opts.joint_damping)
        .map_err(|e| Error::Options(format!("formulation 'decoupled': {e}")))?;
    Ok(std::borrow::Cow::Owned(twin.graph))
}

/// The indices into `y` of the leading columns, and all column names.
fn columns_of(eq: &BondEquations) -> (Vec<usize>, Vec<String>) {
    let y_cols: Vec<usize> = (0..eq.n)
        .filter(|&i| eq.kinds[i] != VariableKind::Loop)
        .collect();
    let mut columns: Vec<String> = y_cols.iter().map(|&i| eq.names[i].clone()).collect();
    columns.extend(eq.outputs.iter().map(|(n, _)| n.clone()));
    (y_cols, columns)
}

/// Output rows from `[t, y]`.
struct Outputs {
    tape: Tape,
    columns: Vec<String>,
    /// Index into `y` of each leading column.
    y_cols: Vec<usize>,
    constraint_tape: Tape,
    vars: Vec<f64>,
    work: Vec<f64>,
    work_c: Vec<f64>,
    out: Vec<f64>,
    c: Vec<f64>,
    energy0: Option<f64>,
    energy_dev: f64,
    energy_max: f64,
    max_c: f64,
}

impl Outputs {
    fn new(eq: &BondEquations) -> Self {
        let (y_cols, columns) = columns_of(eq);
        let exprs: Vec<_> = eq.outputs.iter().map(|(_, e)| *e).collect();
        let tape = eq.graph.compile(&exprs);
        let constraint_tape = eq.graph.compile(&eq.constraints);
        Outputs {
            work: tape.workspace(),
            work_c: constraint_tape.workspace(),
            out: vec![0.0; exprs.len()],
            c: vec![0.0; eq.constraints.len()],
            vars: vec![0.0; 1 + eq.n],
            tape,
            constraint_tape,
            columns,
            y_cols,
            energy0: None,
            energy_dev: 0.0,
            energy_max: 0.0,
            max_c: 0.0,
        }
    }

    fn row(&mut self, t: f64, y: &[f64]) -> Vec<f64> {
        self.vars[0] = t;
        self.vars[1..].copy_from_slice(y);
        self.tape.eval(&self.vars, &mut self.work, &mut self.out);
        self.constraint_tape
            .eval(&self.vars, &mut self.work_c, &mut self.c);
        let energy = *self.out.last().unwrap_or(&0.0);
        let e0 = *self.energy0.get_or_insert(energy);
        self.energy_dev = self.energy_dev.max((energy - e0).abs());
        self.energy_max = self.energy_max.max(energy.abs());
        self.max_c = self.c.iter().fold(self.max_c, |a, b| a.max(b.abs()));
        let mut row: Vec<f64> = self.y_cols.iter().map(|&i| y[i]).collect();
        row.extend_from_slice(&self.out);
        row
    }

    fn drift(&self) -> f64 {
        let scale = self.energy0.unwrap_or(0.0).abs().max(self.energy_max);
        if scale > 0.0 {
            self.energy_dev / scale
        } else {
            self.energy_dev
        }
    }
}

fn fill_stats(summary: &mut Summary, s: &SolverStats) {
    summary.steps = s.steps;
    summary.residual_evals = s.residual_evals;
    summary.jacobian_evals = s.jacobian_evals;
    summary.linear_setups = s.linear_setups;
    summary.error_test_failures = s.error_test_failures;
    summary.nonlinear_iterations = s.nonlinear_iterations;
    summary.nonlinear_conv_failures = s.nonlinear_conv_failures;
    summary.last_step = s.last_step;
}

/// Solves a raw bond graph: CVODE when its equations are an ODE, IDA otherwise.
///
/// Errors: invalid graph, causal conflicts (redundant constraints), declared signals (a raw
/// scene has nothing to supply them), no consistent start, solver failure.
pub fn solve_bond_graph(g: &BondGraph, opts: &SolveOptions) -> Result<Solution, Error> {
    solve_bond_graph_streaming(g, opts, &mut |_| ControlFlow::Continue(()))
}

/// [`solve_bond_graph`], handing each output row to `observer` as soon as it is computed
/// (`ControlFlow::Break(())` stops early; the solution then ends with that row). The motion
/// starts at `opts.t_start`; rows are written at `opts.output_times`.
pub fn solve_bond_graph_streaming(
    g: &BondGraph,
    opts: &SolveOptions,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    from_t_start(opts, observer, |opts, observer| {
        solve_from_first_output(g, opts, observer)
    })
}

/// A raw bond graph's joint rows constrain its flows only (no position-level closures): the
/// formulations that need `g(q)` (`ggl`, `compliant_ggl`, `partitioned`) are refused by name,
/// never run as another; `dae` and `index1` run the graph's own DAE and `decoupled` its twin.
fn refuse_without_closures(g: &BondGraph, f: FormulationKind) -> Result<(), Error> {
    match f {
        FormulationKind::Dae | FormulationKind::Index1 => Ok(()),
        FormulationKind::Decoupled => Err(Error::Options(
            "formulation 'decoupled': the twin still has constraint rows (a joint row that is not an Sf = 0 or a two-bond 1-junction)".into(),
        )),
        FormulationKind::Ggl | FormulationKind::CompliantGgl | FormulationKind::Partitioned => {
            let rows: Vec<String> = crate::bond::causality::joint_row_elements(g)
                .into_iter()
                .map(|e| format!("'{}'", g.element(e).name))
                .collect();
            Err(Error::Options(format!(
                "formulation '{}' needs the joints' position-level closures g(q), and this raw bond graph's constraint junctions ({}) carry none; use dae, index1 or decoupled, or give the junctions closures (a mechanism scene's `graph --as-scene` export has them)",
                f.name(),
                rows.join(", ")
            )))
        }
    }
}

/// Why a bond graph's stored energy `Σ p²/2m + Σ q²/2C` is not conserved: its first resistor
/// or source that delivers power (a constant zero source does not); `None` when it is.
fn energy_exchange(g: &BondGraph) -> Option<String> {
    g.elements
        .iter()
        .find_map(|e| match (e.kind, &e.parameter) {
            (ElementKind::R, _) => Some(format!("resistor '{}' dissipates energy", e.name)),
            (ElementKind::Se | ElementKind::Sf, Some(Parameter::Const(v))) if *v == 0.0 => None,
            (ElementKind::Se | ElementKind::Sf, _) => {
                Some(format!("source '{}' delivers power", e.name))
            }
            _ => None,
        })
}

/// [`solve_bond_graph_streaming`] with the first output time as the start time.
fn solve_from_first_output(
    g: &BondGraph,
    opts: &SolveOptions,
    observer: &mut dyn FnMut(Row<'_>) -> ControlFlow<()>,
) -> Result<Solution, Error> {
    let clock = ThreadTime::now();
    let t0 = *opts
        .output_times
        .first()
        .ok_or_else(|| Error::Options("no output times".into()))?;
    if let Some(s) = g.signals.first() {
        return Err(Error::BondGraph(format!(
            "signal '{s}' has no source in a raw bond graph scene (signals are supplied by the mechanism layer)"
        )));
    }
    let decoupled = opts.formulation == FormulationKind::Decoupled;
    let g = &graph_solved(g, opts)?;
    let causality = assign_causality(g).map_err(bond_error)?;
    let eq = BondEquations::new(g, &causality).map_err(bond_error)?;
    // the equations are the causality's: its integral storages are the states, its
    // differential inertias the dependent unknowns
    let report = causality.report(g);
    let mut summary = Summary {
        unknowns: eq.n,
        states: report.states,
        dependent: report.differential.into_iter().map(|d| d.element).collect(),
        ..Summary::default()
    };
    let mut out = Outputs::new(&eq);
    let mut sol = Solution {
        columns: out.columns.clone(),
        times: Vec::new(),
        rows: Vec::new(),
        summary: Summary::default(),
    };
    if let Some(ode) = eq.ode() {
        summary.formulation = if decoupled {
            summary.joint_stiffness = opts.joint_stiffness;
            "decoupled".into()
        } else {
            "bond_ode".into()
        };
        summary.solver = "CVODE".into();
        summary.build_cpu_seconds = clock.elapsed().as_secs_f64();
        let y0 = eq.initial.clone();
        let cv_opts = CvodeOptions {
            rtol: opts.rtol,
            atol: vec![opts.atol],
            max_steps: Some(u64::MAX),
            max_total_steps: opts.max_steps,
            max_wall_clock: opts.max_wall_clock,
            stop_time: opts.output_times.last().copied(),
            ..CvodeOptions::default()
        };
        let run = ThreadTime::now();
        let mut cv = super::integrators::make_cvode(Arc::new(ode), t0, &y0, &cv_opts, opts)?;
        let mut stop = emit(&mut sol, observer, t0, out.row(t0, &y0), opts.keep_rows);
        for &t in &opts.output_times[1..] {
            if stop {
                break;
            }
            match cv.solve_to(t) {
                Ok(step) => {
                    stop = emit(
                        &mut sol,
                        observer,
                        step.t,
                        out.row(step.t, cv.y()),
                        opts.keep_rows,
                    );
                }
                Err(e) => {
                    fill_stats(&mut summary, &cv.stats());
                    summary.cpu_seconds = run.elapsed().as_secs_f64();
                    finish(&mut summary, &out, g);
                    let last = e.time().filter(|_| is_budget(&e)).and_then(|tr| {
                        let mut y = vec![0.0; cv.y().len()];
                        cv.dky(tr, 0, &mut y).ok()?;
                        Some((tr, out.row(tr, &y)))
                    });
                    return Err(map_solver_cause(stopped(e, sol, summary, last), |se| {
                        name_in_bond_graph(g, &eq, se)
                    }));
                }
            }
        }
        summary.cpu_seconds = run.elapsed().as_secs_f64();
        fill_stats(&mut summary, &cv.stats());
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
        summary.build_cpu_seconds = clock.elapsed().as_secs_f64();
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
        let dae = crate::dae::IdDae { dae, id };
        let run = ThreadTime::now();
        let mut ida = super::integrators::make_ida(Arc::new(dae), atol, t0, &y0, &yp0, opts)?;
        let mut stop = emit(&mut sol, observer, t0, out.row(t0, &y0), opts.keep_rows);
        for &t in &opts.output_times[1..] {
            if stop {
                break;
            }
            match ida.solve_to(t) {
                Ok(step) => {
                    stop = emit(
                        &mut sol,
                        observer,
                        step.t,
                        out.row(step.t, ida.y()),
                        opts.keep_rows,
                    );
                }
                Err(e) => {
                    fill_stats(&mut summary, &ida.stats());
                    summary.cpu_seconds = run.elapsed().as_secs_f64();
                    finish(&mut summary, &out, g);
                    let last = e.time().filter(|_| is_budget(&e)).and_then(|tr| {
                        let mut y = vec![0.0; ida.y().len()];
                        ida.dky(tr, 0, &mut y).ok()?;
                        Some((tr, out.row(tr, &y)))
                    });
                    return Err(map_solver_cause(stopped(e, sol, summary, last), |se| {
                        name_in_bond_graph(g, &eq, se)
                    }));
                }
            }
        }
        summary.cpu_seconds = run.elapsed().as_secs_f64();
        fill_stats(&mut summary, &ida.stats());
    }
    finish(&mut summary, &out, g);
    set_completed(&mut summary, &sol);
    sol.summary = summary;
    Ok(sol)
}

/// Constraint error and energy figures of the rows so far.
fn finish(summary: &mut Summary, out: &Outputs, g: &BondGraph) {
    summary.max_constraint_error = out.max_c;
    set_energy(summary, out.drift(), energy_exchange(g).as_deref());
}
