//! A run with forward sensitivities on IDAS: the mechanism's DAE `F(t, y, y'; p) = 0` (the
//! index-1 formulation, `dae` and `index1`) and, for every parameter `p_k`,
//!
//! ```text
//!   F_y s_k + F_y' s_k' + ∂F/∂p_k = 0,     s_k = ∂y/∂p_k,
//! ```
//!
//! with the exact `F_y`, `F_y'` of the run's own tapes and `∂F/∂p_k` from the same residual
//! rows built with the parameters as symbols ([`super::symbols`]). The sensitivities start
//! consistent with the joints — the start's projection differentiated: the least change of the
//! coordinates `s_q = (I − G_q⁺ G_q) ∂q₀/∂p − G_q⁺ ∂g/∂p`, of the velocities the projection
//! changes (`F`: those the scene does not give, where they close the joints)
//! `s_v = ∂v₀/∂p − E_F G_F⁺ (G_v ∂v₀/∂p + ∂(G_v v)/∂q s_q + ∂(G_v v)/∂p)`, the algebraic unknowns
//! and the rates from the sensitivity residual at the start — and take part in IDAS's error
//! test. A column `c(t, q, v)` of the run gets `d(c)/d(p_k) = ∂c/∂(q, v) · s_k`.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use super::symbols::{self, SymbolicSystem};
use super::{SceneParameter, SensitivityError};
use crate::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use crate::expr::{Expr, Tape};
use crate::model::Model;
use crate::scene::Scene;
use crate::settings::FormulationKind;
use crate::solve::formulation::shared::JobStart;
use crate::solve::formulation::{
    ggl::runner as ggl, index1::runner as index1, DaeFormulation, GglFormulation, Problem, Start,
};
use crate::solve::integrators::{make_ida, make_ida_schur};
use crate::solve::{SolveOptions, Summary};
use crate::sundials::{Ida, SensResidualFn, SensStats, SolverStats, StepEvent};

/// What to run: the parameters' scene paths and, optionally, an earlier end.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SensitivityRequest {
    /// Scene paths of the parameters (`bodies[bar2].mass`, `springs[s1].stiffness`, …).
    pub params: Vec<String>,
    /// End the run here instead of at the scene's `t_end`.
    pub t_end: Option<f64>,
    /// Output times instead of the scene's (the first one is the start).
    pub output_times: Option<Vec<f64>>,
}

impl SensitivityRequest {
    /// The sensitivities with respect to `params` (scene paths).
    pub fn new(params: &[&str]) -> Self {
        SensitivityRequest {
            params: params.iter().map(|s| s.to_string()).collect(),
            ..SensitivityRequest::default()
        }
    }

    /// Ends the run at `t` (the scene's output grid up to `t`).
    pub fn t_end(mut self, t: f64) -> Self {
        self.t_end = Some(t);
        self
    }
}

/// A run's columns and their sensitivities at the output times.
#[derive(Clone, Debug, Default)]
pub struct Sensitivities {
    /// The parameters.
    pub params: Vec<SceneParameter>,
    /// The run's columns (without `t`).
    pub columns: Vec<String>,
    /// Output times.
    pub times: Vec<f64>,
    /// The run's rows, one per output time.
    pub rows: Vec<Vec<f64>>,
    /// `d(<column>)/d(<path>)` for every column with a sensitivity and every parameter
    /// (parameter-major).
    pub sensitivity_columns: Vec<String>,
    /// The sensitivities' rows, one per output time.
    pub sensitivity_rows: Vec<Vec<f64>>,
    /// For every sensitivity column: its run column's index and its parameter's.
    pub sources: Vec<(usize, usize)>,
    /// What the run says about the parameters (one does not enter the run, a column depends
    /// on one explicitly).
    pub warnings: Vec<String>,
    /// The integrator's counters.
    pub stats: SolverStats,
    /// The sensitivities' counters.
    pub sens_stats: SensStats,
    /// CPU seconds of the integration: from IDAS's creation to the last output row
    /// (sensitivity rows included), as a plain run's `summary.cpu_seconds`.
    pub cpu_seconds: f64,
}

impl Sensitivities {
    /// The values of the run's or the sensitivities' column `name` at the output times.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        if let Some(i) = self.columns.iter().position(|c| c == name) {
            return Some(self.rows.iter().map(|r| r[i]).collect());
        }
        let i = self.sensitivity_columns.iter().position(|c| c == name)?;
        Some(self.sensitivity_rows.iter().map(|r| r[i]).collect())
    }

    /// `d(<column>)/d(<param>)` at every output time, where it is computed.
    pub fn derivative(&self, column: &str, param: usize) -> Option<Vec<f64>> {
        let c = self.columns.iter().position(|x| x == column)?;
        let i = self.sources.iter().position(|&s| s == (c, param))?;
        Some(self.sensitivity_rows.iter().map(|r| r[i]).collect())
    }

    /// The CSV text: `t`, the run's columns, then the sensitivities' columns.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("t");
        for c in self.columns.iter().chain(&self.sensitivity_columns) {
            out.push(',');
            out.push_str(&csv_field(c));
        }
        out.push('\n');
        for ((t, r), s) in self
            .times
            .iter()
            .zip(&self.rows)
            .zip(&self.sensitivity_rows)
        {
            out.push_str(&format!("{t:?}"));
            for v in r.iter().chain(s) {
                out.push_str(&format!(",{v:?}"));
            }
            out.push('\n');
        }
        out
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The sensitivity column's name: `d(<column>)/d(<path>)`.
pub fn sensitivity_name(column: &str, path: &str) -> String {
    format!("d({column})/d({path})")
}

/// Runs `scene` with the forward sensitivities of `req` (see the module documentation).
pub fn sensitivity(
    scene: &Scene,
    req: &SensitivityRequest,
) -> Result<Sensitivities, SensitivityError> {
    if req.params.is_empty() {
        return Err(SensitivityError::Scene("give at least one --param".into()));
    }
    let mut params: Vec<SceneParameter> = Vec::with_capacity(req.params.len());
    for p in &req.params {
        if params.iter().any(|q| q.path == *p) {
            return Err(SensitivityError::Path {
                path: p.clone(),
                reason: "given twice".into(),
            });
        }
        params.push(SceneParameter::new(scene, p)?);
    }
    let model = Model::new(scene).map_err(|e| SensitivityError::Scene(e.to_string()))?;
    if model.is_raw_bond_graph() {
        return Err(SensitivityError::Scene(
            "sensitivities are computed for mechanisms, not raw bond graphs".into(),
        ));
    }
    let mut opts = model.default_options();
    if let Some(t) = req.t_end {
        opts.output_times = model
            .output_times_until(t)
            .map_err(|e| SensitivityError::Scene(e.to_string()))?;
    }
    if let Some(times) = &req.output_times {
        opts.output_times = times.clone();
    }
    run(scene, model.system().clone(), params, &opts)
}

/// The run of [`sensitivity`] on the system `sys` of `scene` with the options `opts`.
pub(crate) fn run(
    scene: &Scene,
    mut sys: crate::mech::MultibodySystem,
    params: Vec<SceneParameter>,
    opts: &SolveOptions,
) -> Result<Sensitivities, SensitivityError> {
    match opts.formulation {
        FormulationKind::Dae | FormulationKind::Index1 | FormulationKind::Ggl => {}
        other => {
            return Err(SensitivityError::Scene(format!(
                "sensitivities are computed on IDAS's DAEs (solve.formulation \"dae\", \"index1\" or \"ggl\"), not yet on \"{}\"",
                other.name()
            )))
        }
    }
    if opts.energy_invariant == Some(true) {
        return Err(SensitivityError::Scene(
            "sensitivities are not computed with solve.energy_invariant (its rows hold the start's energy)".into(),
        ));
    }
    // no invariant switched on part-way either: one DAE from start to end
    let opts = &SolveOptions {
        energy_invariant: Some(false),
        ..opts.clone()
    };
    if !sys.events.is_empty() {
        return Err(SensitivityError::Scene(
            "sensitivities are not computed for scenes with events (their times depend on the parameters)".into(),
        ));
    }
    let times = &opts.output_times;
    let t0 = *times
        .first()
        .ok_or_else(|| SensitivityError::Scene("no output times".into()))?;
    if opts.t_start != t0 {
        return Err(SensitivityError::Scene(
            "sensitivities start at the first output time (solve.t_start before it is not supported)".into(),
        ));
    }
    let mut sym = symbols::derive(scene, &sys, &params)?;
    let mut warnings = Vec::new();
    for (k, p) in params.iter().enumerate() {
        if !sym.enters[k] {
            warnings.push(format!(
                "--param {}: the scene does not depend on it; its sensitivities are zero",
                p.path
            ));
        }
        if !sym.explicit_columns[k].is_empty() {
            warnings.push(format!(
                "--param {}: the columns [{}] depend on it explicitly; their sensitivities are not written",
                p.path,
                sym.explicit_columns[k].join(", ")
            ));
        }
    }
    let (nq, nv) = (sys.nq(), sys.nv());
    let start = Start0::new(&mut sym)?;
    // the columns' gradients in the state [q, v]
    let slots: Vec<u32> = (1..=(nq + nv) as u32).collect();
    let outputs: Vec<(String, Vec<Expr>)> = sys
        .outputs
        .clone()
        .iter()
        .map(|o| (o.name.clone(), sys.graph.gradient(o.expr, &slots)))
        .collect();
    let flat: Vec<Expr> = outputs
        .iter()
        .flat_map(|(_, g)| g.iter().copied())
        .collect();
    let gradient_tape = sys.graph.compile(&flat);
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    let init = consistent_state(&sys, &tapes, t0).map_err(crate::solve::SolveError::from)?;
    let mut summary = Summary {
        formulation: opts.formulation.name().into(),
        ..Summary::default()
    };
    let job = if opts.formulation == FormulationKind::Ggl {
        if !init.redundant_joints.is_empty() {
            return Err(SensitivityError::Scene(
                "sensitivities on the ggl formulation need joints without redundant rows (the compliant GGL's)".into(),
            ));
        }
        let ggl = GglFormulation::build(&mut sys, &c, 0.0);
        ggl::job(sys, ggl, tapes, &init, (0.0, 0.0), t0, opts)
    } else {
        index1::job(JobStart::new(sys, &c, tapes, &init, opts), &mut summary)
    };
    let mut formulation = job.formulation;
    let mut rows_eval = job.rows;
    let columns = rows_eval.columns();
    let p = match formulation.segment(t0, &mut summary)? {
        Start::Run(Problem::Implicit(p)) => p,
        _ => {
            return Err(SensitivityError::Scene(
                "the index-1 formulation could not start here (it hands the run to the GGL)".into(),
            ))
        }
    };
    let prows = formulation.parameter_rows(&mut sym).unwrap_or_else(|| {
        Err(crate::solve::SolveError::Options(
            "the formulation has no sensitivities".into(),
        ))
    })?;
    let n = p.dae.len();
    let ns = params.len();
    let flat: Vec<Expr> = prows.rows.iter().flatten().copied().collect();
    let fp = Arc::new(sym.sys.graph.compile(&flat));
    let hidden = Hidden::new(&mut sym, &prows.hidden, n, prows.pinned);
    // the consistent start of the sensitivities
    let (s0, sp0) = start.sensitivities(&*p.dae, (&fp, &hidden), (t0, &p.y0, &p.yp0), (nq, nv))?;
    let clock = cpu_time::ThreadTime::now();
    let mut ida = build_ida(
        p.dae.clone(),
        p.atol.clone(),
        p.schur,
        t0,
        (&p.y0, &p.yp0),
        opts,
    )?;
    if let Some(w) = p.weights {
        ida.set_error_weights(opts.rtol, p.atol.clone(), w)?;
    }
    let atol_s: Vec<Vec<f64>> = params
        .iter()
        .map(|q| {
            let scale = if q.value != 0.0 { q.value.abs() } else { 1.0 };
            p.atol.iter().map(|a| a / scale).collect()
        })
        .collect();
    ida.enable_sensitivities(
        &s0,
        &sp0,
        sens_residual(p.dae.clone(), fp, n, ns),
        opts.rtol,
        &atol_s,
    )?;
    // which run columns have sensitivities: the outputs' columns without explicit dependence
    let mut sources = Vec::new();
    let mut sensitivity_columns = Vec::new();
    for (k, q) in params.iter().enumerate() {
        for (ci, name) in columns.iter().enumerate() {
            if !outputs.iter().any(|(o, _)| o == name) {
                continue;
            }
            if sym.explicit_columns[k].contains(name) {
                continue;
            }
            sources.push((ci, k));
            sensitivity_columns.push(sensitivity_name(name, &q.path));
        }
    }
    let out_index: Vec<usize> = sources
        .iter()
        .map(|&(ci, _)| {
            outputs
                .iter()
                .position(|(o, _)| *o == columns[ci])
                .unwrap_or(0)
        })
        .collect();
    let m = nq + nv;
    let mut grad = vec![0.0; flat_len(&outputs)];
    let mut work = gradient_tape.workspace();
    let mut vars = vec![0.0; 1 + m];
    let mut sens_row = |t: f64, x: &[f64], s: &[Vec<f64>]| -> Vec<f64> {
        vars[0] = t;
        vars[1..].copy_from_slice(&x[..m]);
        gradient_tape.eval(&vars, &mut work, &mut grad);
        sources
            .iter()
            .zip(&out_index)
            .map(|(&(_, k), &oi)| {
                let g = &grad[oi * m..(oi + 1) * m];
                g.iter().zip(&s[k][..m]).map(|(a, b)| a * b).sum()
            })
            .collect()
    };
    let mut result = Sensitivities {
        params,
        columns,
        times: Vec::with_capacity(times.len()),
        rows: Vec::with_capacity(times.len()),
        sensitivity_columns: Vec::new(),
        sensitivity_rows: Vec::with_capacity(times.len()),
        sources: Vec::new(),
        warnings,
        ..Sensitivities::default()
    };
    let mut x = formulation.first_row_state();
    result.times.push(t0);
    result.rows.push(rows_eval.row(t0, &x));
    result.sensitivity_rows.push(sens_row(t0, &x, &s0));
    for &tk in &times[1..] {
        let step = ida.solve_to(tk)?;
        if matches!(step.event, StepEvent::Root(_)) {
            return Err(SensitivityError::Scene(format!(
                "the run stopped at a root at t = {}",
                step.t
            )));
        }
        let s = ida.sensitivities(step.t)?;
        formulation.row_state(step.t, ida.y(), &mut x)?;
        result.times.push(step.t);
        result.rows.push(rows_eval.row(step.t, &x));
        result.sensitivity_rows.push(sens_row(step.t, &x, &s));
    }
    result.cpu_seconds = clock.elapsed().as_secs_f64();
    result.stats = ida.stats();
    result.sens_stats = ida.sens_stats();
    result.sensitivity_columns = sensitivity_columns;
    result.sources = sources;
    Ok(result)
}

fn flat_len(outputs: &[(String, Vec<Expr>)]) -> usize {
    outputs.iter().map(|(_, g)| g.len()).sum()
}

/// IDA for the segment's problem, as the executor builds it (Schur complement where asked).
fn build_ida(
    dae: Arc<dyn DaeFormulation>,
    atol: Vec<f64>,
    schur: Option<crate::sundials::schur::SchurSplit>,
    t0: f64,
    (y0, yp0): (&[f64], &[f64]),
    opts: &SolveOptions,
) -> Result<Ida, SensitivityError> {
    if let Some(split) = schur {
        if let Some(ida) = make_ida_schur(dae.clone(), split, atol.clone(), t0, (y0, yp0), opts) {
            return Ok(ida?);
        }
    }
    Ok(make_ida(dae, atol, t0, y0, yp0, opts)?)
}

/// The sensitivity residual `r_k = F_y s_k + F_y' s_k' + ∂F/∂p_k` of [`Ida::enable_sensitivities`].
fn sens_residual(
    dae: Arc<dyn DaeFormulation>,
    fp: Arc<Tape>,
    n: usize,
    ns: usize,
) -> SensResidualFn {
    let mut ws = dae.workspace();
    let (mut dy, mut dyp) = (Vec::new(), Vec::new());
    let mut vars = vec![0.0; 1 + 2 * n];
    let mut work = fp.workspace();
    let mut out = vec![0.0; n * ns];
    Box::new(move |t, y, yp, s, sp, r| {
        if !dae.jacobian_parts(&mut ws, t, (y, yp), &mut dy, &mut dyp) {
            return Err(crate::sundials::CallbackError::Fatal(
                "the formulation does not give ∂F/∂y and ∂F/∂y' apart".into(),
            ));
        }
        vars[0] = t;
        vars[1..=n].copy_from_slice(y);
        vars[n + 1..].copy_from_slice(yp);
        fp.eval(&vars, &mut work, &mut out);
        for (k, rk) in r.iter_mut().enumerate() {
            rk.copy_from_slice(&out[k * n..(k + 1) * n]);
            for &(row, col, v) in &dy {
                rk[row] += v * s[k][col];
            }
            for &(row, col, v) in &dyp {
                rk[row] += v * sp[k][col];
            }
        }
        Ok(())
    })
}

/// `(s_k(t₀), s_k'(t₀))` for every parameter.
type StartVectors = (Vec<Vec<f64>>, Vec<Vec<f64>>);

/// An index-2 DAE's hidden constraints `H(t, y, y'; p) = 0` at the start: `∂H/∂p_k`, `H_y`,
/// `H_y'` compiled from the rows over `[t, y, y']` and the parameters' symbols, and the
/// unknowns pinned at zero ([`crate::solve::formulation::ParameterRows`]).
struct Hidden {
    tape: Option<Tape>,
    rows: usize,
    ns: usize,
    pinned: Vec<usize>,
}

impl Hidden {
    fn new(sym: &mut SymbolicSystem, rows: &[Expr], n: usize, pinned: Vec<usize>) -> Self {
        let ns = sym.params.len();
        if rows.is_empty() {
            return Hidden {
                tape: None,
                rows: 0,
                ns,
                pinned,
            };
        }
        let mut exprs: Vec<Expr> = sym.derivatives(rows).into_iter().flatten().collect();
        let g = &mut sym.sys.graph;
        let values: Vec<(u32, Expr)> = sym
            .params
            .iter()
            .enumerate()
            .map(|(k, p)| (symbols::parameter_slot(k), g.constant(p.value)))
            .collect();
        let at = g.substitute_all(rows, &values);
        let slots: Vec<u32> = (1..=(2 * n) as u32).collect();
        for &h in &at {
            exprs.extend(g.gradient(h, &slots));
        }
        Hidden {
            tape: Some(g.compile(&exprs)),
            rows: rows.len(),
            ns,
            pinned,
        }
    }

    fn len(&self) -> usize {
        self.rows
    }

    /// `(∂H/∂p (parameter-major), H_y, H_y')` at `(t, y, y')`.
    fn evaluate(
        &self,
        (t, y, yp): (f64, &[f64], &[f64]),
        n: usize,
    ) -> (Vec<f64>, DMatrix<f64>, DMatrix<f64>) {
        let Some(tape) = &self.tape else {
            return (Vec::new(), DMatrix::zeros(0, n), DMatrix::zeros(0, n));
        };
        let mut vars = vec![t];
        vars.extend_from_slice(y);
        vars.extend_from_slice(yp);
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(&vars, &mut tape.workspace(), &mut out);
        let nh = self.rows;
        let dp = out[..self.ns * nh].to_vec();
        let grads = &out[self.ns * nh..];
        let hy = DMatrix::from_fn(nh, n, |h, c| grads[h * 2 * n + c]);
        let hyp = DMatrix::from_fn(nh, n, |h, c| grads[h * 2 * n + n + c]);
        (dp, hy, hyp)
    }
}

/// What the start's sensitivities need from the mechanism with the parameters as symbols:
/// `G_q`, `G_v`, `∂(G_v v)/∂q`, `∂g/∂p_k`, `∂(G_v v)/∂p_k` at the start, and the scene's
/// `∂q₀/∂p_k`, `∂v₀/∂p_k`.
struct Start0 {
    gq: DMatrix<f64>,
    gv: DMatrix<f64>,
    dgvv_dq: DMatrix<f64>,
    dg_dp: Vec<DVector<f64>>,
    dgvv_dp: Vec<DVector<f64>>,
    dq0: Vec<Vec<f64>>,
    dv0: Vec<Vec<f64>>,
    /// The velocities the scene gives (kept by the projection where the others close the
    /// joints, [`crate::dae::consistent_state`]).
    given: Vec<bool>,
    /// The start's `[t, q, v]` is read from the DAE's `y0` later; the tape is kept to evaluate.
    tape: Option<(Tape, usize, usize, usize)>,
}

impl Start0 {
    fn new(sym: &mut SymbolicSystem) -> Result<Self, SensitivityError> {
        let (nq, nv, nc) = (sym.sys.nq(), sym.sys.nv(), sym.sys.nc());
        let c = ConstraintExprs::derive(&mut sym.sys);
        let q_slots: Vec<u32> = (1..=nq as u32).collect();
        let mut exprs: Vec<Expr> = Vec::new();
        for k in 0..nc {
            exprs.extend(c.gq[k].iter().copied());
        }
        for k in 0..nc {
            exprs.extend(c.gv[k].iter().copied());
        }
        for k in 0..nc {
            let d = sym.sys.graph.gradient(c.gvv[k], &q_slots);
            exprs.extend(d);
        }
        let g = &mut sym.sys.graph;
        let values: Vec<(u32, Expr)> = sym
            .params
            .iter()
            .enumerate()
            .map(|(k, p)| (symbols::parameter_slot(k), g.constant(p.value)))
            .collect();
        let mut exprs = g.substitute_all(&exprs, &values);
        for d in sym.derivatives(&c.g) {
            exprs.extend(d);
        }
        for d in sym.derivatives(&c.gvv) {
            exprs.extend(d);
        }
        let tape = sym.sys.graph.compile(&exprs);
        Ok(Start0 {
            gq: DMatrix::zeros(nc, nq),
            gv: DMatrix::zeros(nc, nv),
            dgvv_dq: DMatrix::zeros(nc, nq),
            dg_dp: Vec::new(),
            dgvv_dp: Vec::new(),
            dq0: sym.dq0.clone(),
            dv0: sym.dv0.clone(),
            given: sym.sys.given_velocities.clone(),
            tape: Some((tape, nq, nv, nc)),
        })
    }

    /// Evaluates the matrices at `[t, q, v]`.
    fn evaluate(&mut self, t: f64, q: &[f64], v: &[f64]) {
        let Some((tape, nq, nv, nc)) = self.tape.take() else {
            return;
        };
        let mut vars = vec![t];
        vars.extend_from_slice(q);
        vars.extend_from_slice(v);
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(&vars, &mut tape.workspace(), &mut out);
        let mut at = 0;
        let mut take = |len: usize| {
            let s = out[at..at + len].to_vec();
            at += len;
            s
        };
        self.gq = DMatrix::from_row_slice(nc, nq, &take(nc * nq));
        self.gv = DMatrix::from_row_slice(nc, nv, &take(nc * nv));
        self.dgvv_dq = DMatrix::from_row_slice(nc, nq, &take(nc * nq));
        let ns = self.dq0.len();
        self.dg_dp = (0..ns).map(|_| DVector::from_vec(take(nc))).collect();
        self.dgvv_dp = (0..ns).map(|_| DVector::from_vec(take(nc))).collect();
    }

    /// `(s_k(t₀), s_k'(t₀))` for every parameter (see the module documentation).
    fn sensitivities(
        mut self,
        dae: &dyn DaeFormulation,
        (fp, hidden): (&Tape, &Hidden),
        (t0, y0, yp0): (f64, &[f64], &[f64]),
        (nq, nv): (usize, usize),
    ) -> Result<StartVectors, SensitivityError> {
        let n = dae.len();
        self.evaluate(t0, &y0[..nq], &y0[nq..nq + nv]);
        let pinv = |m: &DMatrix<f64>| {
            if m.nrows() == 0 {
                Ok(DMatrix::zeros(m.ncols(), 0))
            } else {
                m.clone()
                    .pseudo_inverse(1e-12 * m.norm().max(1.0))
                    .map_err(|e| {
                        SensitivityError::Scene(format!("the joints' matrix at the start: {e}"))
                    })
            }
        };
        let gq_p = pinv(&self.gq)?;
        let nq_proj = DMatrix::identity(nq, nq) - &gq_p * &self.gq;
        // the velocities the projection changes: those the scene does not give, where they
        // close the joints alone (the rank of their columns is G_v's), else all of them
        let free: Vec<usize> = (0..nv)
            .filter(|&j| !self.given.get(j).copied().unwrap_or(false))
            .collect();
        let rank = |m: &DMatrix<f64>| {
            if m.nrows() == 0 || m.ncols() == 0 {
                0
            } else {
                m.rank(1e-10 * m.norm().max(1.0))
            }
        };
        let gfree = DMatrix::from_fn(self.gv.nrows(), free.len(), |i, k| self.gv[(i, free[k])]);
        let free: Vec<usize> = if !free.is_empty() && rank(&gfree) == rank(&self.gv) {
            free
        } else {
            (0..nv).collect()
        };
        let gfree = DMatrix::from_fn(self.gv.nrows(), free.len(), |i, k| self.gv[(i, free[k])]);
        let gfree_p = pinv(&gfree)?;
        // F_y, F_y', ∂F/∂p at the start
        let mut ws = dae.workspace();
        let (mut dy, mut dyp) = (Vec::new(), Vec::new());
        if !dae.jacobian_parts(&mut ws, t0, (y0, yp0), &mut dy, &mut dyp) {
            return Err(SensitivityError::Scene(
                "the formulation does not give ∂F/∂y and ∂F/∂y' apart".into(),
            ));
        }
        let mut vars = vec![t0];
        vars.extend_from_slice(y0);
        vars.extend_from_slice(yp0);
        let mut fpv = vec![0.0; fp.n_outputs()];
        fp.eval(&vars, &mut fp.workspace(), &mut fpv);
        let mut fy = DMatrix::zeros(n, n);
        let mut fyp = DMatrix::zeros(n, n);
        let mut differential = vec![false; n];
        for &(r, c, v) in &dy {
            fy[(r, c)] += v;
        }
        for &(r, c, v) in &dyp {
            fyp[(r, c)] += v;
            differential[c] = true;
        }
        let a = DMatrix::from_fn(n, n, |r, c| {
            if differential[c] {
                fyp[(r, c)]
            } else {
                fy[(r, c)]
            }
        });
        // index 1: a regular matrix; an index-2 DAE (the GGL) adds its hidden constraints'
        // rows and its pinned unknowns (zero), and the stacked system is solved by least
        // squares (consistent: exactly)
        let lu = a.clone().lu();
        let nh = hidden.len();
        let (h_at, hy, hyp) = hidden.evaluate((t0, y0, yp0), n);
        let pinned = &hidden.pinned;
        let stacked = DMatrix::from_fn(n + nh + pinned.len(), n, |r, c| {
            if r < n {
                a[(r, c)]
            } else if r < n + nh {
                let h = r - n;
                if differential[c] {
                    hyp[(h, c)]
                } else {
                    hy[(h, c)]
                }
            } else if pinned[r - n - nh] == c {
                1.0
            } else {
                0.0
            }
        });
        let svd = stacked.svd(true, true);
        let ns = self.dq0.len();
        let (mut s0, mut sp0) = (Vec::with_capacity(ns), Vec::with_capacity(ns));
        for k in 0..ns {
            let dq = DVector::from_column_slice(&self.dq0[k]);
            let dv = DVector::from_column_slice(&self.dv0[k]);
            let sq = &nq_proj * dq - &gq_p * &self.dg_dp[k];
            // v_F ← v_F − G_F⁺ (G_v v + b) differentiated: s_v = ∂v₀/∂p − E_F G_F⁺ (G_v ∂v₀/∂p
            // + ∂(G_v v)/∂q s_q + ∂(G_v v)/∂p)
            let change = &gfree_p * (&self.gv * &dv + &self.dgvv_dq * &sq + &self.dgvv_dp[k]);
            let mut sv = dv.clone();
            for (i, &j) in free.iter().enumerate() {
                sv[j] -= change[i];
            }
            let mut s = vec![0.0; n];
            s[..nq].copy_from_slice(sq.as_slice());
            s[nq..nq + nv].copy_from_slice(sv.as_slice());
            // F_y s + F_y' s' + ∂F/∂p = 0 for the algebraic unknowns' s and the differential
            // unknowns' s'
            let mut rhs = DVector::from_column_slice(&fpv[k * n..(k + 1) * n]);
            for (c, &d) in differential.iter().enumerate() {
                if d {
                    rhs += fy.column(c) * s[c];
                }
            }
            let b = -rhs;
            let solved = if nh == 0 && pinned.is_empty() {
                lu.solve(&b).filter(|z| z.iter().all(|v| v.is_finite()))
            } else {
                // H_y s + H_y' s' + ∂H/∂p = 0 for the same unknowns
                let mut bb = DVector::zeros(n + nh + pinned.len());
                bb.rows_mut(0, n).copy_from(&b);
                for h in 0..nh {
                    let mut r = h_at[k * nh + h];
                    for (c, &d) in differential.iter().enumerate() {
                        if d {
                            r += hy[(h, c)] * s[c];
                        }
                    }
                    bb[n + h] = -r;
                }
                svd.solve(&bb, 1e-12 * svd.singular_values.max()).ok()
            };
            let z = solved.ok_or_else(|| {
                SensitivityError::Scene(
                    "the sensitivities' start: the DAE's matrix [F_y (algebraic), F_y' (differential)] is singular".into(),
                )
            })?;
            let mut sp = vec![0.0; n];
            for c in 0..n {
                if differential[c] {
                    sp[c] = z[c];
                } else {
                    s[c] = z[c];
                }
            }
            s0.push(s);
            sp0.push(sp);
        }
        Ok((s0, sp0))
    }
}
