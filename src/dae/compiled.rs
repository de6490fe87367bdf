//! Compiled residuals and right-hand sides with their exact Jacobians.
//!
//! An [`ImplicitDae`] holds `F(t, y, y')` and the structural non-zeros of `∂F/∂y` and `∂F/∂y'`,
//! each compiled to a flat [`Tape`]; IDA's iteration matrix is assembled as
//! `J = ∂F/∂y + c_j ∂F/∂y'`. An [`ExplicitOde`] holds `y' = f(t, y)` and `∂f/∂y` for CVODE.
//! Variable slots: `0 = t`, `1..=n` the unknowns `y`, `n+1..=2n` their derivatives `y'`.

use std::sync::Arc;

use crate::expr::{Expr, ExprGraph, Tape};

/// One structural non-zero of a Jacobian.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Row (equation).
    pub row: usize,
    /// Column (unknown).
    pub col: usize,
}

/// A fully implicit DAE `F(t, y, y') = 0` with exact derivatives.
///
/// The tapes may compute more rows than the DAE has (candidate rows `R(t, y, y')`); the DAE's
/// rows are then a selection of them, `F_i = R_{s(i)}` ([`ImplicitDae::build_selected`]), which
/// [`ImplicitDae::with_selection`] changes without compiling anything again (the index-1
/// DAE's dependent coordinates: a coordinate's row is its kinematics `q_i' = K_i v` or a
/// position constraint). The Jacobian's entries are the candidate rows' exact derivatives,
/// selected the same way.
#[derive(Clone, Debug)]
pub struct ImplicitDae {
    /// Number of unknowns (and equations).
    pub n: usize,
    residual: Arc<Tape>,
    jacobian: Arc<Tape>,
    /// The entries of `∂R/∂y` and `∂R/∂y'` (candidate rows), in the Jacobian tape's order.
    all_dy: Arc<Vec<Entry>>,
    all_dyp: Arc<Vec<Entry>>,
    /// `s`: the candidate row of each of the DAE's rows (`None`: the candidate rows are the
    /// rows).
    selection: Option<Vec<usize>>,
    /// The selected entries (rows numbered as the DAE's) and their places in the Jacobian
    /// tape's output.
    dy: Vec<Entry>,
    dy_at: Vec<usize>,
    dyp: Vec<Entry>,
    dyp_at: Vec<usize>,
}

/// Preallocated buffers for evaluating a compiled system without allocating.
#[derive(Clone, Debug)]
pub struct Workspace {
    vars: Vec<f64>,
    work_r: Vec<f64>,
    work_j: Vec<f64>,
    jac: Vec<f64>,
    /// The candidate rows of a selecting DAE (empty otherwise).
    rows: Vec<f64>,
    /// The work buffer of a [`CompanionScalar`] (sized at its first evaluation).
    work_s: Vec<f64>,
}

impl ImplicitDae {
    /// Differentiates `residual` (expressions over slots `[t, y, y']`) and compiles everything.
    pub fn build(g: &mut ExprGraph, residual: &[Expr], n: usize) -> Self {
        assert_eq!(residual.len(), n, "one residual per unknown");
        Self::build_selected(g, residual, n, None)
    }

    /// Differentiates the candidate rows `candidates` (expressions over slots `[t, y, y']`,
    /// `y` of length `n`) and compiles them; the DAE's row `i` is candidate `selection[i]`
    /// (every candidate in order when `None`).
    pub fn build_selected(
        g: &mut ExprGraph,
        candidates: &[Expr],
        n: usize,
        selection: Option<Vec<usize>>,
    ) -> Self {
        let mut dy = Vec::new();
        let mut dyp = Vec::new();
        let mut dy_e = Vec::new();
        let mut dyp_e = Vec::new();
        for (row, &f) in candidates.iter().enumerate() {
            for v in g.vars(f) {
                let v = v as usize;
                if v == 0 {
                    continue;
                }
                let d = g.diff(f, v as u32);
                if g.is_zero(d) {
                    continue;
                }
                if v <= n {
                    dy.push(Entry { row, col: v - 1 });
                    dy_e.push(d);
                } else if v <= 2 * n {
                    dyp.push(Entry {
                        row,
                        col: v - 1 - n,
                    });
                    dyp_e.push(d);
                }
            }
        }
        let mut outs = dy_e;
        outs.extend(dyp_e);
        let mut dae = ImplicitDae {
            n,
            residual: Arc::new(g.compile(candidates)),
            jacobian: Arc::new(g.compile(&outs)),
            all_dy: Arc::new(dy),
            all_dyp: Arc::new(dyp),
            selection: None,
            dy: Vec::new(),
            dy_at: Vec::new(),
            dyp: Vec::new(),
            dyp_at: Vec::new(),
        };
        dae.select(selection);
        dae
    }

    /// The same candidate rows and tapes with the DAE's rows `selection` (one candidate row
    /// per unknown, each at most once).
    pub fn with_selection(&self, selection: Vec<usize>) -> Self {
        let mut dae = ImplicitDae {
            n: self.n,
            residual: Arc::clone(&self.residual),
            jacobian: Arc::clone(&self.jacobian),
            all_dy: Arc::clone(&self.all_dy),
            all_dyp: Arc::clone(&self.all_dyp),
            selection: None,
            dy: Vec::new(),
            dy_at: Vec::new(),
            dyp: Vec::new(),
            dyp_at: Vec::new(),
        };
        dae.select(Some(selection));
        dae
    }

    /// Number of candidate rows the tapes compute.
    pub fn candidates(&self) -> usize {
        self.residual.n_outputs()
    }

    fn select(&mut self, selection: Option<Vec<usize>>) {
        let m = self.residual.n_outputs();
        let row_of: Vec<Option<usize>> = match &selection {
            None => (0..m).map(Some).collect(),
            Some(s) => {
                assert_eq!(s.len(), self.n, "one candidate row per unknown");
                let mut r = vec![None; m];
                for (i, &c) in s.iter().enumerate() {
                    assert!(r[c].is_none(), "candidate row {c} selected twice");
                    r[c] = Some(i);
                }
                r
            }
        };
        let pick = |all: &[Entry], offset: usize| -> (Vec<Entry>, Vec<usize>) {
            all.iter()
                .enumerate()
                .filter_map(|(k, e)| {
                    row_of[e.row].map(|row| (Entry { row, col: e.col }, offset + k))
                })
                .unzip()
        };
        (self.dy, self.dy_at) = pick(&self.all_dy, 0);
        (self.dyp, self.dyp_at) = pick(&self.all_dyp, self.all_dy.len());
        self.selection = selection;
    }

    /// Buffers for [`Self::residual`] and [`Self::jacobian`].
    pub fn workspace(&self) -> Workspace {
        Workspace {
            vars: vec![0.0; 1 + 2 * self.n],
            work_r: self.residual.workspace(),
            work_j: self.jacobian.workspace(),
            jac: vec![0.0; self.all_dy.len() + self.all_dyp.len()],
            rows: vec![
                0.0;
                if self.selection.is_some() {
                    self.candidates()
                } else {
                    0
                }
            ],
            work_s: Vec::new(),
        }
    }

    /// Number of structural non-zeros of `∂F/∂y` and `∂F/∂y'`.
    pub fn nonzeros(&self) -> (usize, usize) {
        (self.dy.len(), self.dyp.len())
    }

    /// The structural non-zeros of `J = ∂F/∂y + cj ∂F/∂y'` as `(row, col)` (an entry in both
    /// parts appears twice): the sparsity pattern of IDA's Newton matrix, fixed for the tapes.
    pub fn structure(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.dy.iter().chain(&self.dyp).map(|e| (e.row, e.col))
    }

    /// Evaluates `F(t, y, y')` into `r`.
    pub fn residual(&self, ws: &mut Workspace, t: f64, y: &[f64], yp: &[f64], r: &mut [f64]) {
        fill_vars(&mut ws.vars, t, y, Some(yp));
        match &self.selection {
            None => self.residual.eval(&ws.vars, &mut ws.work_r, r),
            Some(s) => {
                self.residual.eval(&ws.vars, &mut ws.work_r, &mut ws.rows);
                for (ri, &c) in r.iter_mut().zip(s) {
                    *ri = ws.rows[c];
                }
            }
        }
    }

    /// Calls `put(row, col, value)` for every entry of `∂F/∂y + cj ∂F/∂y'` (entries may repeat:
    /// the caller adds them).
    pub fn jacobian(
        &self,
        ws: &mut Workspace,
        t: f64,
        cj: f64,
        y: &[f64],
        yp: &[f64],
        mut put: impl FnMut(usize, usize, f64),
    ) {
        self.eval_jacobian(ws, t, y, yp);
        for (e, &k) in self.dy.iter().zip(&self.dy_at) {
            put(e.row, e.col, ws.jac[k]);
        }
        for (e, &k) in self.dyp.iter().zip(&self.dyp_at) {
            put(e.row, e.col, cj * ws.jac[k]);
        }
    }

    /// The two parts of the iteration matrix at `(t, y, y')` as `(row, col, value)` lists:
    /// `∂F/∂y` into `dy` and `∂F/∂y'` into `dyp` (cleared first; an entry may repeat: values
    /// add). The sensitivity residual `F_y s + F_y' s' + ∂F/∂p` reads them.
    pub fn jacobian_parts(
        &self,
        ws: &mut Workspace,
        t: f64,
        (y, yp): (&[f64], &[f64]),
        dy: &mut Vec<(usize, usize, f64)>,
        dyp: &mut Vec<(usize, usize, f64)>,
    ) {
        self.eval_jacobian(ws, t, y, yp);
        dy.clear();
        dyp.clear();
        dy.extend(
            self.dy
                .iter()
                .zip(&self.dy_at)
                .map(|(e, &k)| (e.row, e.col, ws.jac[k])),
        );
        dyp.extend(
            self.dyp
                .iter()
                .zip(&self.dyp_at)
                .map(|(e, &k)| (e.row, e.col, ws.jac[k])),
        );
    }

    /// The candidate row of each of the DAE's rows (`None`: every candidate in order).
    pub fn selection(&self) -> Option<&[usize]> {
        self.selection.as_deref()
    }

    /// The Jacobian tape's outputs at `(t, y, y')` into `ws.jac`.
    fn eval_jacobian(&self, ws: &mut Workspace, t: f64, y: &[f64], yp: &[f64]) {
        fill_vars(&mut ws.vars, t, y, Some(yp));
        self.jacobian.eval(&ws.vars, &mut ws.work_j, &mut ws.jac);
    }
}

impl ImplicitDae {
    /// `values[slots[k]] += J_k` for the `k`-th entry of `J = ∂F/∂y + cj ∂F/∂y'` at `(t, cj)` and
    /// `(y, y')` in the order
    /// of [`Self::structure`] (`∂F/∂y`'s entries, then `∂F/∂y'`'s times `cj`); `false`
    /// (nothing written) when `slots` does not hold one place per entry, or a place lies
    /// outside `values`.
    pub fn jacobian_into_slots(
        &self,
        ws: &mut Workspace,
        (t, cj): (f64, f64),
        (y, yp): (&[f64], &[f64]),
        (slots, values): (&[usize], &mut [f64]),
    ) -> bool {
        let (n_dy, n_dyp) = (self.dy_at.len(), self.dyp_at.len());
        if slots.len() != n_dy + n_dyp || slots.iter().any(|&s| s >= values.len()) {
            return false;
        }
        self.eval_jacobian(ws, t, y, yp);
        let (s_dy, s_dyp) = slots.split_at(n_dy);
        for (&slot, &k) in s_dy.iter().zip(&self.dy_at) {
            values[slot] += ws.jac[k];
        }
        for (&slot, &k) in s_dyp.iter().zip(&self.dyp_at) {
            values[slot] += cj * ws.jac[k];
        }
        true
    }
}

/// An explicit ODE `y' = f(t, y)` with its exact Jacobian `∂f/∂y`.
#[derive(Clone, Debug)]
pub struct ExplicitOde {
    /// Number of states.
    pub n: usize,
    rhs: Tape,
    jacobian: Tape,
    dy: Vec<Entry>,
}

impl ExplicitOde {
    /// Differentiates `rhs` (expressions over slots `[t, y]`) and compiles it.
    pub fn build(g: &mut ExprGraph, rhs: &[Expr]) -> Self {
        let n = rhs.len();
        let mut dy = Vec::new();
        let mut dy_e = Vec::new();
        for (row, &f) in rhs.iter().enumerate() {
            for v in g.vars(f) {
                let v = v as usize;
                if v == 0 || v > n {
                    continue;
                }
                let d = g.diff(f, v as u32);
                if g.is_zero(d) {
                    continue;
                }
                dy.push(Entry { row, col: v - 1 });
                dy_e.push(d);
            }
        }
        ExplicitOde {
            n,
            rhs: g.compile(rhs),
            jacobian: g.compile(&dy_e),
            dy,
        }
    }

    /// Buffers for [`Self::rhs`] and [`Self::jacobian`].
    pub fn workspace(&self) -> Workspace {
        Workspace {
            vars: vec![0.0; 1 + self.n],
            work_r: self.rhs.workspace(),
            work_j: self.jacobian.workspace(),
            jac: vec![0.0; self.dy.len()],
            rows: Vec::new(),
            work_s: Vec::new(),
        }
    }

    /// Evaluates `f(t, y)` into `ydot`.
    pub fn rhs(&self, ws: &mut Workspace, t: f64, y: &[f64], ydot: &mut [f64]) {
        fill_vars(&mut ws.vars, t, y, None);
        self.rhs.eval(&ws.vars, &mut ws.work_r, ydot);
    }

    /// Calls `put(row, col, value)` for every structural non-zero of `∂f/∂y`.
    pub fn jacobian(
        &self,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
        mut put: impl FnMut(usize, usize, f64),
    ) {
        fill_vars(&mut ws.vars, t, y, None);
        self.jacobian.eval(&ws.vars, &mut ws.work_j, &mut ws.jac);
        for (e, v) in self.dy.iter().zip(&ws.jac) {
            put(e.row, e.col, *v);
        }
    }

    /// The structural non-zeros of `∂f/∂y` as `(row, col)`: with the diagonal, the sparsity
    /// pattern of CVODE's Newton matrix `I − γ ∂f/∂y`.
    pub fn structure(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.dy.iter().map(|e| (e.row, e.col))
    }

    /// Number of structural non-zeros of `∂f/∂y`.
    pub fn nonzeros(&self) -> usize {
        self.dy.len()
    }
}

/// A scalar of an [`ImplicitDae`]'s variables `[t, y, y']`, read after one of its evaluations
/// from the variables that evaluation loaded into the [`Workspace`] (no copy of `y` again).
/// The GGL's compliant joints read their slip power with it.
#[derive(Clone, Debug)]
pub struct CompanionScalar {
    tape: Arc<Tape>,
}

impl CompanionScalar {
    /// Compiles `e` (an expression over the DAE's slots).
    pub fn build(g: &mut ExprGraph, e: Expr) -> Self {
        CompanionScalar {
            tape: Arc::new(g.compile(&[e])),
        }
    }

    /// The scalar at the variables of the last [`ImplicitDae::residual`] or
    /// [`ImplicitDae::jacobian`] evaluated with `ws` (its buffer is allocated at the first
    /// call only).
    pub fn eval_loaded(&self, ws: &mut Workspace) -> f64 {
        if ws.work_s.is_empty() {
            ws.work_s = self.tape.workspace();
        }
        let mut out = [0.0];
        self.tape.eval(&ws.vars, &mut ws.work_s, &mut out);
        out[0]
    }
}

fn fill_vars(vars: &mut [f64], t: f64, y: &[f64], yp: Option<&[f64]>) {
    vars[0] = t;
    let n = y.len();
    vars[1..=n].copy_from_slice(y);
    if let Some(yp) = yp {
        vars[n + 1..=2 * n].copy_from_slice(yp);
    }
}
