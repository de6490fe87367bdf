//! A raw bond graph's own equations ([`crate::bond::equations`]): an ODE on CVODE (BDF,
//! Newton, exact Jacobian) when every storage is in integral causality and no loop is
//! algebraic, else a DAE on IDA — the velocity-level index-2 DAE, or its index-1 variant
//! under `index1` — with the causality's integral storages as states and its
//! differential-causality inertias as dependent unknowns.
//!
//! Output columns: every unknown of `y` except the loop variables (`p_<I>`, `q_<C>`, `x_…`,
//! dependent `p_<I>`, `lambda_<I>`), then `f_<I>` (flow `p/m`) of every inertia, `e_<C>`
//! (effort `q/C`) of every capacitor, and `energy = Σ p²/2m + Σ q²/2C`.
//! `summary.max_constraint_error` is the largest `|φ_d − p_d/m_d|` at the output times and
//! `summary.energy_drift` the largest `|E(t) − E(0)|` relative to `max(|E(0)|, max E)`.

use std::sync::Arc;

use crate::bond::equations::{BondEquations, VariableKind};
use crate::bond::model::BondGraph;
use crate::dae::ExplicitOde;
use crate::expr::Tape;
use crate::solve::formulation::IdDae;
use crate::solve::formulation::{ExplicitProblem, Formulation, ImplicitProblem, Problem, Start};
use crate::solve::formulation::{Job, RowEval};
use crate::solve::solution::Summary;
use crate::solve::SolveError;

/// The indices into `y` of the leading columns, and all column names.
pub(crate) fn columns_of(eq: &BondEquations) -> (Vec<usize>, Vec<String>) {
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
    exchange: Option<String>,
}

impl Outputs {
    fn new(eq: &BondEquations, exchange: Option<String>) -> Self {
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
            exchange,
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

/// Why a bond graph's stored energy is not conserved ([`BondGraph::energy_exchange`]).
fn energy_exchange(g: &BondGraph) -> Option<String> {
    g.energy_exchange()
}

impl RowEval for Outputs {
    fn columns(&self) -> Vec<String> {
        self.columns.clone()
    }
    fn row(&mut self, t: f64, x: &[f64]) -> Vec<f64> {
        Outputs::row(self, t, x)
    }
    fn max_constraint_error(&self) -> f64 {
        self.max_c
    }
    fn energy_drift(&self) -> f64 {
        self.drift()
    }
    fn energy_exchange(&self) -> Option<String> {
        self.exchange.clone()
    }
}

/// A raw bond graph's equations as one problem: the ODE or the DAE.
struct RawGraph {
    problem: Option<Problem>,
    y0: Vec<f64>,
}

impl<'a> Formulation<'a> for RawGraph {
    fn first_row_state(&self) -> Vec<f64> {
        self.y0.clone()
    }

    fn segment(&mut self, _t: f64, _summary: &mut Summary) -> Result<Start<'a>, SolveError> {
        // one segment: no recovery restarts it
        self.problem.take().map(Start::Run).ok_or_else(|| {
            SolveError::BondGraph("the raw bond graph's equations were used up".into())
        })
    }
}

/// The raw graph's ODE `y' = f(t, y)` from `y0`, with its rows.
pub(crate) fn ode_job<'a>(
    g: &BondGraph,
    eq: &BondEquations,
    ode: ExplicitOde,
    y0: Vec<f64>,
) -> Job<'a> {
    Job {
        formulation: Box::new(RawGraph {
            problem: Some(Problem::Explicit(ExplicitProblem {
                ode: Arc::new(ode),
                y0: y0.clone(),
                max_order: None,
                stab_lim_det: false,
            })),
            y0,
        }),
        rows: Box::new(Outputs::new(eq, energy_exchange(g))),
        events: None,
    }
}

/// The raw graph's DAE `F(t, y, y') = 0` from the consistent `(y0, y0')`, with per-unknown
/// absolute tolerances `atol`, and its rows.
pub(crate) fn dae_job<'a>(
    g: &BondGraph,
    eq: &BondEquations,
    dae: IdDae,
    atol: Vec<f64>,
    (y0, yp0): (Vec<f64>, Vec<f64>),
) -> Job<'a> {
    Job {
        formulation: Box::new(RawGraph {
            problem: Some(Problem::Implicit(ImplicitProblem {
                dae: Arc::new(dae),
                atol,
                y0: y0.clone(),
                yp0,
                schur: None,
                weights: None,
            })),
            y0,
        }),
        rows: Box::new(Outputs::new(eq, energy_exchange(g))),
        events: None,
    }
}
