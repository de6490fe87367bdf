//! Naming the culprit of a non-finite residual or right-hand side.
//!
//! The SUNDIALS callbacks remember the state of the last evaluation that produced NaN or ±∞
//! ([`SolverError::NonFinite`]); the formulations' tapes fuse every load and element into one
//! residual, so the culprit is found by evaluating the scene's load expressions (or the raw bond
//! graph's element parameters and laws) one by one at that time and state.

use crate::bond::equations::BondEquations;
use crate::bond::model::BondGraph;
use crate::mech::{MultibodySystem, NonFiniteValue};
use crate::solve::SolveError;
use crate::sundials::SolverError;

/// `e`, with a non-finite residual of a mechanism's formulation traced to the load (JSON path,
/// name, expression) or generalized force that produced it. The state of every formulation
/// starts with `[q, v]`.
pub(crate) fn name_in_mechanism(sys: &MultibodySystem, e: SolveError) -> SolveError {
    let e = map_solver_cause(e, |solver| name_solver_error(sys, solver));
    // a step that collapsed against a load's pole (`1/(t - 0.1)` grows without bound but stays
    // finite until t = 0.1, which the steps never reach): the load named as the culprit
    match e {
        SolveError::Incomplete { cause, partial } => {
            let cause = match *cause {
                // a collapsed step: the load running away, else the unknown that is
                SolveError::Solver(s @ SolverError::StepCollapse { .. }) => {
                    collapse_culprit(sys, s)
                }
                SolveError::Solver(
                    s @ (SolverError::NoProgress { .. } | SolverError::Flag { .. }),
                ) => match s.time().and_then(|t| sys.load_pole(t)) {
                    Some(culprit) => SolveError::NonFinite {
                        culprit: Box::new(culprit),
                        stuck: true,
                        solver: Box::new(s),
                    },
                    None => SolveError::Solver(s),
                },
                other => other,
            };
            SolveError::Incomplete {
                cause: Box::new(cause),
                partial,
            }
        }
        other => other,
    }
}

/// A [`SolverError::StepCollapse`] traced to its cause: a load of time that grows without
/// bound there ([`MultibodySystem::load_runaway`]) or has a pole, else the unknown of the
/// motion (`bar.omega`) the largest component of the state is.
fn collapse_culprit(sys: &MultibodySystem, s: SolverError) -> SolveError {
    let SolverError::StepCollapse {
        t,
        h,
        tout,
        steps_to_go,
        index,
        value,
    } = s
    else {
        return SolveError::Solver(s);
    };
    let pace = format!(
        "the step size collapsed to {h:.1e} s, {steps_to_go:.1e} steps from the next output at t = {tout}"
    );
    let culprit = match sys.load_runaway(t).or_else(|| sys.load_pole(t)) {
        Some(mut c) => {
            c.what = format!("{}; {pace}", c.what);
            c
        }
        None => {
            let nq = sys.nq();
            let name = if index < nq {
                sys.coords.get(index).map(|c| c.name.clone())
            } else {
                sys.velocities.get(index - nq).map(|c| c.name.clone())
            };
            match name {
                Some(name) => NonFiniteValue {
                    path: name,
                    what: format!(
                        "the largest unknown of the motion: it runs away, a state or load growing without bound; {pace}"
                    ),
                    t,
                    value,
                },
                None => return SolveError::Solver(s),
            }
        }
    };
    SolveError::NonFinite {
        culprit: Box::new(culprit),
        stuck: true,
        solver: Box::new(s),
    }
}

/// `e` with `f` applied to the solver error it comes from: `e` itself, or the cause of an
/// [`SolveError::Incomplete`] (a solve that stopped and kept its rows). Other errors are unchanged.
pub(crate) fn map_solver_cause(
    e: SolveError,
    f: impl FnOnce(SolverError) -> SolveError,
) -> SolveError {
    match e {
        SolveError::Solver(s) => f(s),
        SolveError::Incomplete { cause, partial } => SolveError::Incomplete {
            cause: Box::new(map_solver_cause(*cause, f)),
            partial,
        },
        other => other,
    }
}

fn name_solver_error(sys: &MultibodySystem, solver: SolverError) -> SolveError {
    if !matches!(solver, SolverError::NonFinite { .. }) {
        return SolveError::Solver(solver);
    }
    let SolverError::NonFinite { t, y, stuck, .. } = &solver else {
        unreachable!("matched above")
    };
    let n = sys.nq() + sys.nv();
    match (y.len() >= n)
        .then(|| sys.non_finite_source(*t, &y[..n]))
        .flatten()
    {
        Some(culprit) => SolveError::NonFinite {
            culprit: Box::new(culprit),
            stuck: *stuck,
            solver: Box::new(solver),
        },
        None => SolveError::Solver(solver),
    }
}

/// `e` (from solving the equations `eq` of the raw bond graph `g`), with a non-finite residual
/// or right-hand side traced to the element (index, name, field) whose parameter or law is not
/// finite there, or else to the storage element whose equation is.
pub(crate) fn name_in_bond_graph(g: &BondGraph, eq: &BondEquations, e: SolverError) -> SolveError {
    let SolverError::NonFinite {
        t, y, stuck, index, ..
    } = &e
    else {
        return match e.time().filter(|_| {
            matches!(
                e,
                SolverError::NoProgress { .. }
                    | SolverError::StepCollapse { .. }
                    | SolverError::Flag { .. }
            )
        }) {
            Some(t) => match bond_graph_pole(g, eq, t) {
                Some(culprit) => SolveError::NonFinite {
                    culprit: Box::new(culprit),
                    stuck: true,
                    solver: Box::new(e),
                },
                None => SolveError::Solver(e),
            },
            None => SolveError::Solver(e),
        };
    };
    // slots [t, y, y'] (y' unknown here: zero; parameters and laws do not use it)
    let mut vars = vec![0.0; 1 + 2 * eq.n + eq.signals.len()];
    vars[0] = *t;
    for (k, v) in y.iter().take(eq.n).enumerate() {
        vars[1 + k] = *v;
    }
    let element = |id: usize, what: String, value: f64| NonFiniteValue {
        path: crate::bond::validate::element_path(id),
        what,
        t: *t,
        value,
    };
    for term in &eq.terms {
        let value = eq.graph.eval(term.expr, &vars);
        if !value.is_finite() {
            let el = g.element(term.element);
            let src = match (term.field, &el.parameter, &el.law) {
                ("effort_law", _, Some(l)) => l.effort.clone(),
                ("flow_law", _, Some(l)) => l.flow.clone(),
                (_, Some(crate::bond::model::Parameter::Expr(s)), _) => Some(s.clone()),
                _ => None,
            };
            let what = match src {
                Some(s) => format!(
                    "{} '{}', {} {}",
                    el.kind.as_str(),
                    el.name,
                    term.field,
                    crate::expr::excerpt(&s, 0)
                ),
                None => format!("{} '{}', {}", el.kind.as_str(), el.name, term.field),
            };
            return SolveError::NonFinite {
                culprit: Box::new(element(term.element.0, what, value)),
                stuck: *stuck,
                solver: Box::new(e),
            };
        }
    }
    // no single parameter: name the element whose equation it is
    let Some(name) = eq.names.get(*index) else {
        return SolveError::Solver(e);
    };
    let stem = ["p_", "q_", "x_", "lambda_"]
        .iter()
        .find_map(|p| name.strip_prefix(p))
        .unwrap_or(name);
    match g.elements.iter().position(|el| el.name == stem) {
        Some(i) => {
            let el = &g.elements[i];
            let value = if let SolverError::NonFinite { value, .. } = &e {
                *value
            } else {
                f64::NAN
            };
            SolveError::NonFinite {
                culprit: Box::new(element(
                    i,
                    format!("{} '{}', the equation of {name}", el.kind.as_str(), el.name),
                    value,
                )),
                stuck: *stuck,
                solver: Box::new(e),
            }
        }
        None => SolveError::Solver(e),
    }
}

/// The element parameter of time alone (`Se` value `"1/(t - 0.1)"`) with a pole at `t`, where a
/// raw bond graph's steps stopped: its value above 1e6 and changing by its own size within 1 ns
/// (the rule of [`MultibodySystem::load_pole`]), or not finite.
fn bond_graph_pole(g: &BondGraph, eq: &BondEquations, t: f64) -> Option<NonFiniteValue> {
    const POLE_RATE: f64 = 1e9;
    let mut graph = eq.graph.clone();
    let mut vars = vec![0.0; 1 + 2 * eq.n + eq.signals.len()];
    vars[0] = t;
    for term in &eq.terms {
        if graph.vars(term.expr).iter().any(|&s| s != 0) {
            continue;
        }
        let value = graph.eval(term.expr, &vars);
        let d = graph.diff(term.expr, 0);
        let rate = graph.eval(d, &vars);
        let relative = (rate / value).abs();
        if value.is_finite()
            && rate.is_finite()
            && !(relative > POLE_RATE && rate.abs() > POLE_RATE && value.abs() > 1e6)
        {
            continue;
        }
        let el = g.element(term.element);
        let src = match &el.parameter {
            Some(crate::bond::model::Parameter::Expr(s)) => crate::expr::excerpt(s, 0),
            _ => String::new(),
        };
        return Some(NonFiniteValue {
            path: crate::bond::validate::element_path(term.element.0),
            what: format!(
                "{} '{}', {} {src}, a pole: it changes by its own size within {:.1e} s",
                el.kind.as_str(),
                el.name,
                term.field,
                1.0 / relative
            ),
            t,
            value,
        });
    }
    None
}
