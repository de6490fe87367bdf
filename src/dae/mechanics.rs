//! The constraint calculus every formulation shares, derived once from a [`MultibodySystem`]:
//!
//! * `g(q)` and `G_q = ∂g/∂q` (position level),
//! * `G_v v = G_q K(q) v` and `G_v = ∂(G_v v)/∂v` (velocity level, the flows that the
//!   differential-causality inertias receive from the junction structure),
//! * `γ = ∂(G_v v)/∂q · K(q) v + ∂(G_v v)/∂t`, so that the acceleration-level constraint reads
//!   `G_v v' + γ = 0`,
//! * `b = ∂g/∂t`, the velocity bias of a rheonomic row (a driver's `g = s(q) − s(t)`): the
//!   velocity-level row is `G_v v + b = 0` (the flow row `G_v v` above includes `b`; `b` alone
//!   is what the numerical projections onto the velocity constraints need),
//!
//! plus numeric tapes of all of them for initialisation, diagnostics and outputs.

use crate::expr::{Expr, ExprGraph, Tape};
use crate::mech::MultibodySystem;

/// The tape slots `[t, q, v]` of a state `x = [q, v]` at `t` (allocating; for one-off use).
pub fn slots(t: f64, x: &[f64]) -> Vec<f64> {
    let mut vars = Vec::with_capacity(1 + x.len());
    vars.push(t);
    vars.extend_from_slice(x);
    vars
}

/// Symbolic constraint quantities (see the module documentation).
#[derive(Clone, Debug)]
pub struct ConstraintExprs {
    /// `g(q)`.
    pub g: Vec<Expr>,
    /// `∂g/∂q`, `nc × nq`.
    pub gq: Vec<Vec<Expr>>,
    /// `G_v v`.
    pub gvv: Vec<Expr>,
    /// `G_v`, `nc × nv`.
    pub gv: Vec<Vec<Expr>>,
    /// `γ`.
    pub gamma: Vec<Expr>,
    /// `b = ∂g/∂t` (zero expressions for the rows that do not depend on `t`).
    pub bias: Vec<Expr>,
}

impl ConstraintExprs {
    /// The effort (force balance) row of velocity `j`, `M_j a_j − Q_j + Σ_k G_v[k, j] λ_k`:
    /// the `inertia` terms first (`M_j a_j`, and whatever a formulation adds there, e.g. the
    /// energy invariant's `μ M_j v_j`), then `−Q_j` (`force` is `Q_j`), then `G_v[k, j] λ_k`
    /// for every row `k` that involves velocity `j`, with `λ_k` the variable in slot `lambda(k)`.
    /// Every formulation, `linearize` and `equilibrium` build it here, in this term order (the
    /// tapes' floating-point sums follow it).
    pub fn effort_row(
        &self,
        g: &mut ExprGraph,
        (j, force): (usize, Expr),
        inertia: &[Expr],
        lambda: impl Fn(usize) -> u32,
    ) -> Expr {
        let mut terms = inertia.to_vec();
        terms.push(g.neg(force));
        self.push_reactions(g, j, &lambda, false, &mut terms);
        g.sum(&terms)
    }

    /// The static balance of velocity `j` (the effort row at rest, `a = 0`, with its sign
    /// turned): `Q_j − Σ_k G_v[k, j] λ_k`.
    pub fn static_row(
        &self,
        g: &mut ExprGraph,
        (j, force): (usize, Expr),
        lambda: impl Fn(usize) -> u32,
    ) -> Expr {
        let mut terms = vec![force];
        self.push_reactions(g, j, &lambda, true, &mut terms);
        g.sum(&terms)
    }

    /// Appends `± G_v[k, j] λ_k` for every row `k` whose `G_v[k, j]` is not the zero
    /// expression (`negate`: `−G_v[k, j] λ_k`).
    fn push_reactions(
        &self,
        g: &mut ExprGraph,
        j: usize,
        lambda: &impl Fn(usize) -> u32,
        negate: bool,
        terms: &mut Vec<Expr>,
    ) {
        for k in 0..self.gv.len() {
            if !g.is_zero(self.gv[k][j]) {
                let l = g.var(lambda(k));
                let p = g.mul(self.gv[k][j], l);
                terms.push(if negate { g.neg(p) } else { p });
            }
        }
    }

    /// The acceleration-level constraint row `k`, `γ_k + Σ_j G_v[k, j] a_j`, with `a_j` the
    /// variable in slot `acc(j)` for every velocity `j` that row `k` involves.
    pub fn acceleration_row(
        &self,
        g: &mut ExprGraph,
        k: usize,
        acc: impl Fn(usize) -> u32,
    ) -> Expr {
        let mut terms = vec![self.gamma[k]];
        for j in 0..self.gv[k].len() {
            if !g.is_zero(self.gv[k][j]) {
                let a = g.var(acc(j));
                terms.push(g.mul(self.gv[k][j], a));
            }
        }
        g.sum(&terms)
    }

    /// Derives every constraint quantity from the system's `g` and `K`.
    ///
    /// Linear in the size of the mechanism: each row is differentiated only by the variables
    /// it mentions (a joint's rows mention the coordinates of its two bodies), and every other
    /// entry of `G_q`, `G_v` is the zero expression without being derived.
    pub fn derive(sys: &mut MultibodySystem) -> Self {
        let (nq, nv) = (sys.nq(), sys.nv());
        let g = sys.constraints.clone();
        let q_slots: Vec<u32> = (0..nq).map(|k| sys.q_slot(k)).collect();
        let v_slots: Vec<u32> = (0..nv).map(|j| sys.v_slot(j)).collect();
        // the flows the bond graph's constraint junctions impose, or d/dt g = Σ_k ∂g/∂q_k (K v)_k
        let gvv = if sys.flow_rows.len() == g.len() && !g.is_empty() {
            sys.flow_rows.clone()
        } else {
            g.iter()
                .map(|&gi| {
                    let terms: Vec<Expr> = sparse_row(&mut sys.graph, gi, &q_slots)
                        .into_iter()
                        .map(|(k, d)| sys.graph.mul(d, sys.kinematics[k]))
                        .collect();
                    sys.graph.sum(&terms)
                })
                .collect()
        };
        let gv = dense_rows(&mut sys.graph, &gvv, &v_slots);
        let gq = dense_rows(&mut sys.graph, &g, &q_slots);
        // γ = Σ_k ∂(G_v v)/∂q_k · (K v)_k (+ ∂(G_v v)/∂t for a rheonomic row): the tangent
        // of G_v v along q̇ = K(q) v, one forward sweep for all rows (linear in their size)
        let mut coordinate_of = vec![None; 1 + nq + nv];
        for (k, &s) in q_slots.iter().enumerate() {
            coordinate_of[s as usize] = Some(k);
        }
        let kinematics = sys.kinematics.clone();
        let along = sys.graph.tangents(&gvv, &|s| {
            coordinate_of
                .get(s as usize)
                .copied()
                .flatten()
                .map(|k| kinematics[k])
        });
        let gamma = gvv
            .iter()
            .zip(along)
            .map(|(&e, t)| {
                if sys.graph.depends_on(e, 0) {
                    let dt = sys.graph.diff(e, 0);
                    sys.graph.add(t, dt)
                } else {
                    t
                }
            })
            .collect();
        // b = G_v v − Σ_j G_v[i][j] v_j: the part of the flow row free of v (∂g/∂t, `−ṡ(t)`)
        let zero = sys.graph.zero();
        // the rheonomic rows: the drivers' (a constant rate is free of t but not of v's
        // complement), and any flow row that mentions t (a raw graph's Sf(t))
        let mut driven: Vec<usize> = sys.drivers.iter().map(|d| d.row).collect();
        // (a graph read back, `graph --as-scene`, knows no drivers: a flow row that is not
        // zero at rest, v = 0, has a prescribed part)
        let mut at_rest = vec![0.0; 1 + nq + nv];
        for (k, c) in sys.coords.iter().enumerate() {
            at_rest[1 + k] = c.initial;
        }
        for (i, &e) in gvv.iter().enumerate() {
            if !driven.contains(&i) && sys.graph.eval(e, &at_rest) != 0.0 {
                driven.push(i);
            }
        }
        let bias = gvv
            .iter()
            .zip(&gv)
            .enumerate()
            .map(|(i, (&e, row))| {
                if !driven.contains(&i) && !sys.graph.depends_on(e, 0) {
                    return zero;
                }
                let mut terms: Vec<Expr> = Vec::new();
                for (&d, &s) in row.iter().zip(&v_slots) {
                    if !sys.graph.is_zero(d) {
                        let v = sys.graph.var(s);
                        terms.push(sys.graph.mul(d, v));
                    }
                }
                let gv_v = sys.graph.sum(&terms);
                sys.graph.sub(e, gv_v)
            })
            .collect();
        ConstraintExprs {
            g,
            gq,
            gvv,
            gv,
            gamma,
            bias,
        }
    }
}

impl ConstraintExprs {
    /// The quantities of the rows `kept` only (in that order): the independent rows of
    /// redundant joints ([`crate::partition::independent_rows`]), which determine the motion alone.
    pub fn keep_rows(&self, kept: &[usize]) -> ConstraintExprs {
        let pick = |v: &[Expr]| kept.iter().map(|&k| v[k]).collect::<Vec<_>>();
        let pick_rows = |v: &[Vec<Expr>]| kept.iter().map(|&k| v[k].clone()).collect::<Vec<_>>();
        ConstraintExprs {
            g: pick(&self.g),
            gq: pick_rows(&self.gq),
            gvv: pick(&self.gvv),
            gv: pick_rows(&self.gv),
            gamma: pick(&self.gamma),
            bias: pick(&self.bias),
        }
    }
}

/// `(k, ∂e/∂x_{slots[k]})` for every `k` whose slot `e` mentions, `k` ascending (derivatives
/// that simplify to zero included, as a dense loop over all `k` would give them). `slots` is
/// ascending.
fn sparse_row(graph: &mut ExprGraph, e: Expr, slots: &[u32]) -> Vec<(usize, Expr)> {
    debug_assert!(slots.windows(2).all(|w| w[0] < w[1]));
    graph
        .vars(e)
        .into_iter()
        .filter_map(|v| slots.binary_search(&v).ok())
        .map(|k| (k, graph.diff(e, slots[k])))
        .collect()
}

/// The Jacobian `∂rows/∂x_slots` as dense rows: the zero expression wherever a row does not
/// mention the slot (which is what differentiating it would give), derived only where it does.
fn dense_rows(graph: &mut ExprGraph, rows: &[Expr], slots: &[u32]) -> Vec<Vec<Expr>> {
    let zero = graph.zero();
    rows.iter()
        .map(|&e| {
            let mut row = vec![zero; slots.len()];
            for (k, d) in sparse_row(graph, e, slots) {
                row[k] = d;
            }
            row
        })
        .collect()
}

/// Numeric tapes over the state layout `[t, q, v]`.
#[derive(Clone, Debug)]
pub struct MechanicsTapes {
    /// nq, nv, nc
    pub dims: (usize, usize, usize),
    /// `g(q)`
    pub g: Tape,
    /// `∂g/∂q`, `nc × nq`
    pub gq: MatrixTape,
    /// `G_v`, `nc × nv`
    pub gv: MatrixTape,
    /// `Q(t, q, v)`
    pub forces: Tape,
    /// `K(q) v`
    pub kinematics: Tape,
    /// `γ`
    pub gamma: Tape,
    /// `b = ∂g/∂t` (the rheonomic rows' velocity bias), `None` when no row depends on `t`
    pub bias: Option<Tape>,
    /// output columns, then energy, then kinetic energy
    pub outputs: Tape,
}

impl MechanicsTapes {
    /// Compiles the numeric tapes; `extra_energy` (the decoupled twin's joint springs) is added
    /// to the mechanical energy.
    pub fn new(sys: &mut MultibodySystem, c: &ConstraintExprs, extra_energy: Option<Expr>) -> Self {
        let energy = match extra_energy {
            Some(e) => sys.graph.add(sys.energy, e),
            None => sys.energy,
        };
        let gr = &sys.graph;
        let mut outs: Vec<Expr> = sys
            .outputs
            .iter()
            .map(|o| if o.name == "energy" { energy } else { o.expr })
            .collect();
        outs.push(energy);
        outs.push(sys.kinetic);
        MechanicsTapes {
            dims: (sys.nq(), sys.nv(), sys.nc()),
            g: gr.compile(&c.g),
            gq: MatrixTape::new(gr, &c.gq, sys.nq()),
            gv: MatrixTape::new(gr, &c.gv, sys.nv()),
            forces: gr.compile(&sys.forces),
            kinematics: gr.compile(&sys.kinematics),
            gamma: gr.compile(&c.gamma),
            bias: c
                .bias
                .iter()
                .any(|&b| !gr.is_zero(b))
                .then(|| gr.compile(&c.bias)),
            outputs: gr.compile(&outs),
        }
    }

    /// The velocity bias `b = ∂g/∂t` at `(t, x)` (zeros without rheonomic rows).
    pub fn bias_at(&self, t: f64, x: &[f64]) -> Vec<f64> {
        match &self.bias {
            Some(b) => Self::eval(b, t, x),
            None => vec![0.0; self.dims.2],
        }
    }

    /// Evaluates a tape at `(t, x)` with `x = [q, v]` (allocating; for one-off use).
    pub fn eval(tape: &Tape, t: f64, x: &[f64]) -> Vec<f64> {
        let mut work = tape.workspace();
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(&slots(t, x), &mut work, &mut out);
        out
    }
}

/// A matrix of expressions compiled by its structural non-zeros only, so `∂g/∂q` and `G_v` of
/// a large mechanism cost what their non-zeros cost (a chain's rows touch two bodies each),
/// and evaluated into a dense row-major array.
#[derive(Clone, Debug)]
pub struct MatrixTape {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    tape: Tape,
    /// Row-major position of each compiled entry.
    position: Vec<usize>,
}

impl MatrixTape {
    /// Compiles the entries of `m` (`rows × cols`, one `Vec` per row) that are not
    /// structurally zero.
    pub fn new(graph: &ExprGraph, m: &[Vec<Expr>], cols: usize) -> Self {
        let mut position = Vec::new();
        let mut entries = Vec::new();
        for (i, row) in m.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if !graph.is_zero(e) {
                    position.push(i * cols + j);
                    entries.push(e);
                }
            }
        }
        MatrixTape {
            rows: m.len(),
            cols,
            tape: graph.compile(&entries),
            position,
        }
    }

    /// Row-major positions (`row · cols + col`) of the structural non-zeros, in the order
    /// [`MatrixTape::eval_nonzeros`] returns their values.
    pub fn positions(&self) -> &[usize] {
        &self.position
    }

    /// The values of the structural non-zeros at the slots `vars = [t, q, v]` (in `work.1`).
    pub fn eval_nonzeros<'w>(&self, vars: &[f64], work: &'w mut (Vec<f64>, Vec<f64>)) -> &'w [f64] {
        self.tape.eval(vars, &mut work.0, &mut work.1);
        &work.1
    }

    /// Number of structural non-zeros.
    pub fn nnz(&self) -> usize {
        self.position.len()
    }

    /// Work buffers for [`MatrixTape::eval_into`]: the tape's, and one value per non-zero.
    pub fn workspace(&self) -> (Vec<f64>, Vec<f64>) {
        (self.tape.workspace(), vec![0.0; self.nnz()])
    }

    /// Evaluates at the slots `vars = [t, q, v]` into the dense row-major `out`
    /// (`rows · cols`, zero where the matrix is structurally zero).
    pub fn eval_into(&self, vars: &[f64], work: &mut (Vec<f64>, Vec<f64>), out: &mut [f64]) {
        out.fill(0.0);
        for (&k, &v) in self.position.iter().zip(self.eval_nonzeros(vars, work)) {
            out[k] = v;
        }
    }

    /// The matrix at `(t, x)`, `x = [q, v]`, into `out` (`rows × cols`; zero where the matrix
    /// is structurally zero), with the buffers `work` ([`MatrixTape::workspace`]) and `vars`
    /// (the slots `[t, q, v]`): allocates nothing once they have their sizes. For the checks
    /// made at every step.
    pub fn matrix_into(
        &self,
        t: f64,
        x: &[f64],
        (vars, work): (&mut Vec<f64>, &mut (Vec<f64>, Vec<f64>)),
        out: &mut nalgebra::DMatrix<f64>,
    ) {
        vars.clear();
        vars.push(t);
        vars.extend_from_slice(x);
        if out.shape() != (self.rows, self.cols) {
            *out = nalgebra::DMatrix::zeros(self.rows, self.cols);
        } else {
            out.fill(0.0);
        }
        for (&k, &v) in self.position.iter().zip(self.eval_nonzeros(vars, work)) {
            out[(k / self.cols, k % self.cols)] = v;
        }
    }

    /// The matrix at `(t, x)`, `x = [q, v]` (allocating; for one-off use).
    pub fn matrix(&self, t: f64, x: &[f64]) -> nalgebra::DMatrix<f64> {
        nalgebra::DMatrix::from_row_slice(self.rows, self.cols, &self.eval(t, x))
    }

    /// The structural non-zeros at `(t, x)`, `x = [q, v]`, as `(row, column, value)` in
    /// row-major order (allocating; linear in the non-zeros, for large mechanisms).
    pub fn entries(&self, t: f64, x: &[f64]) -> Vec<(usize, usize, f64)> {
        let mut work = self.workspace();
        let values = self.eval_nonzeros(&slots(t, x), &mut work);
        self.position
            .iter()
            .zip(values)
            .map(|(&k, &v)| (k / self.cols, k % self.cols, v))
            .collect()
    }

    /// The dense row-major matrix at `(t, x)`, `x = [q, v]` (allocating; for one-off use).
    pub fn eval(&self, t: f64, x: &[f64]) -> Vec<f64> {
        let mut work = self.workspace();
        let mut out = vec![0.0; self.rows * self.cols];
        self.eval_into(&slots(t, x), &mut work, &mut out);
        out
    }
}
