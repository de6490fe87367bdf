//! Symbolic differentiation `∂e/∂xᵥ`, memoised per `(e, v)` so shared subexpressions are
//! differentiated once and derivatives of derivatives reuse earlier work.
//!
//! Rules (`e` the node itself, `a'` = ∂a/∂xᵥ):
//! `(a ± b)' = a' ± b'`; `(ab)' = a'b + ab'`; `(a/b)' = (a' − e·b')/b`;
//! `(a^c)' = c·a^(c−1)·a'` for constant `c`, otherwise `(a^b)' = e·(b'·ln a + b·a'/a)`;
//! `sin' = cos·a'`; `cos' = −sin·a'`; `tan' = (1 + e²)·a'`; `√a' = a'/(2e)`;
//! `|a|' = sign(a)·a'`; `exp' = e·a'`; `ln' = a'/a`;
//! `atan2(y, x)' = (x·y' − y·x')/(x² + y²)`;
//! `min(a, b)' = select(b − a, a', b')`; `max(a, b)' = select(a − b, a', b')`;
//! `select(c, a, b)' = select(c, a', b')`; `table(a)' = slope(a)·a'`;
//! `sign`, `slope` are piecewise constant: derivative 0.

use super::graph::{Expr, ExprGraph, Node};
use super::hash::FxMap;
use super::ops::{BinOp, UnOp};

impl ExprGraph {
    /// Symbolic derivative `∂e/∂x_var`, memoised per `(e, var)`.
    pub fn diff(&mut self, e: Expr, var: u32) -> Expr {
        if let Some(&d) = self.diff_memo.get(&(e, var)) {
            return d;
        }
        // Iterative post-order so deep expressions cannot overflow the stack.
        let mut stack = vec![e];
        while let Some(&top) = stack.last() {
            if self.diff_memo.contains_key(&(top, var)) {
                stack.pop();
                continue;
            }
            let (ch, n) = self.node(top).children();
            let pending: Vec<Expr> = ch[..n]
                .iter()
                .copied()
                .filter(|c| !self.diff_memo.contains_key(&(*c, var)))
                .collect();
            if pending.is_empty() {
                let d = self.diff_node(top, var);
                self.diff_memo.insert((top, var), d);
                stack.pop();
            } else {
                stack.extend(pending);
            }
        }
        self.diff_memo[&(e, var)]
    }

    /// The gradient `∂e/∂x_v` for each `v` in `wrt` (zero where `e` does not mention `v`), by
    /// one reverse sweep over `e`'s DAG: the adjoint of the root is 1, and each node, from `e`
    /// down to the variables, passes `ē_child += ē_node · ∂node/∂child` on to its children;
    /// a variable's derivative is its adjoint. The cost is linear in the size of `e` for all
    /// of `wrt` at once, where [`Self::diff`] walks `e` once per variable (an N-body energy,
    /// `O(N)` nodes in `6N` velocities and coordinates: `O(N²)` for `diff`). The local
    /// derivatives are those of `diff`; only the order of the operations differs.
    ///
    /// ```
    /// use bondmech::expr::ExprGraph;
    /// let mut g = ExprGraph::new();
    /// let (x, y) = (g.var(1), g.var(2));
    /// let xy = g.mul(x, y);
    /// let s = g.sin(x);
    /// let e = g.add(xy, s); // e = x y + sin x
    /// let grad = g.gradient(e, &[1, 2, 3]);
    /// let tape = g.compile(&grad);
    /// let mut out = [0.0; 3];
    /// tape.eval(&[0.0, 0.5, 2.0, 7.0], &mut tape.workspace(), &mut out);
    /// assert!((out[0] - (2.0 + 0.5f64.cos())).abs() < 1e-15); // ∂e/∂x = y + cos x
    /// assert_eq!(out[1], 0.5); // ∂e/∂y = x
    /// assert_eq!(out[2], 0.0); // e does not mention x₃
    /// ```
    pub fn gradient(&mut self, e: Expr, wrt: &[u32]) -> Vec<Expr> {
        let nodes = self.reachable(&[e]);
        // the adjoints' partial sums, by the node's position in `nodes` (ascending arena
        // order = topological: every child before its parents)
        let pos = |i: u32| {
            nodes
                .binary_search(&i)
                .expect("a child of a reachable node")
        };
        let mut adj: Vec<Vec<Expr>> = vec![Vec::new(); nodes.len()];
        let mut of_var: FxMap<u32, Vec<Expr>> = FxMap::default();
        let one = self.one();
        adj[nodes.len() - 1].push(one);
        for k in (0..nodes.len()).rev() {
            let terms = std::mem::take(&mut adj[k]);
            if terms.is_empty() {
                continue;
            }
            let a = self.sum(&terms);
            if self.is_zero(a) {
                continue;
            }
            let node = Expr(nodes[k]);
            let mut pass = |g: &mut Self, child: Expr, d: Expr| {
                if !g.is_zero(d) {
                    adj[pos(child.0)].push(d);
                }
            };
            match self.node(node) {
                Node::Const(_) | Node::TableSlope(..) | Node::Un(UnOp::Sign, _) => {}
                Node::Var(v) => of_var.entry(v).or_default().push(a),
                Node::Un(op, x) => {
                    let d = match op {
                        UnOp::Neg => self.neg(a),
                        UnOp::Sin => {
                            let c = self.cos(x);
                            self.mul(c, a)
                        }
                        UnOp::Cos => {
                            let s = self.sin(x);
                            let ns = self.neg(s);
                            self.mul(ns, a)
                        }
                        UnOp::Tan => {
                            let e2 = self.mul(node, node);
                            let one = self.one();
                            let f = self.add(one, e2);
                            self.mul(f, a)
                        }
                        UnOp::Sqrt => {
                            let two_e = self.scale(2.0, node);
                            self.div(a, two_e)
                        }
                        UnOp::Abs => {
                            let s = self.sign(x);
                            self.mul(s, a)
                        }
                        UnOp::Exp => self.mul(node, a),
                        UnOp::Ln => self.div(a, x),
                        UnOp::Sign => unreachable!("handled above"),
                    };
                    pass(self, x, d);
                }
                Node::Bin(op, x, y) => {
                    let (dx, dy) = match op {
                        BinOp::Add => (a, a),
                        BinOp::Sub => (a, self.neg(a)),
                        BinOp::Mul => (self.mul(a, y), self.mul(x, a)),
                        BinOp::Div => {
                            // e = x / y: ∂e/∂x = 1/y, ∂e/∂y = −e/y
                            let dx = self.div(a, y);
                            let ae = self.mul(node, a);
                            let q = self.div(ae, y);
                            (dx, self.neg(q))
                        }
                        BinOp::Pow => {
                            // ∂/∂x = y·x^(y−1); ∂/∂y = e·ln x, only where y is not constant
                            let one = self.one();
                            let ym1 = self.sub(y, one);
                            let p = self.pow(x, ym1);
                            let f = self.mul(y, p);
                            let dx = self.mul(f, a);
                            let dy = if self.as_const(y).is_some() {
                                self.zero()
                            } else {
                                let l = self.ln(x);
                                let el = self.mul(node, l);
                                self.mul(el, a)
                            };
                            (dx, dy)
                        }
                        BinOp::Atan2 => {
                            // e = atan2(x = y-coordinate, y = x-coordinate)
                            let xx = self.mul(x, x);
                            let yy = self.mul(y, y);
                            let den = self.add(xx, yy);
                            let ya = self.mul(y, a);
                            let xa = self.mul(x, a);
                            let dx = self.div(ya, den);
                            let q = self.div(xa, den);
                            (dx, self.neg(q))
                        }
                        BinOp::Min | BinOp::Max => {
                            // as diff: select(y − x, ·, ·) for min, select(x − y, ·, ·) for max
                            let c = if op == BinOp::Min {
                                self.sub(y, x)
                            } else {
                                self.sub(x, y)
                            };
                            let z = self.zero();
                            (self.select(c, a, z), self.select(c, z, a))
                        }
                    };
                    pass(self, x, dx);
                    pass(self, y, dy);
                }
                Node::Select(c, x, y) => {
                    let z = self.zero();
                    let (dx, dy) = (self.select(c, a, z), self.select(c, z, a));
                    pass(self, x, dx);
                    pass(self, y, dy);
                }
                Node::Table(t, x) => {
                    let s = self.table_slope(t, x);
                    let d = self.mul(s, a);
                    pass(self, x, d);
                }
            }
        }
        wrt.iter()
            .map(|v| match of_var.get(v) {
                Some(terms) => self.sum(terms),
                None => self.zero(),
            })
            .collect()
    }

    /// Sparse Jacobian `∂fᵢ/∂x_{wrt[j]}`: the entries `(i, j, derivative)` that are not
    /// identically zero, row by row, columns ascending. Only variables each `fᵢ` actually
    /// mentions are differentiated.
    pub fn jacobian(&mut self, f: &[Expr], wrt: &[u32]) -> Vec<(usize, usize, Expr)> {
        let mut col: Vec<(u32, usize)> = wrt.iter().enumerate().map(|(j, &v)| (v, j)).collect();
        col.sort_unstable();
        let mut entries = Vec::new();
        for (i, &fi) in f.iter().enumerate() {
            let mut row: Vec<(usize, Expr)> = Vec::new();
            for v in self.vars(fi) {
                let lo = col.partition_point(|&(w, _)| w < v);
                for &(_, j) in col[lo..].iter().take_while(|&&(w, _)| w == v) {
                    let d = self.diff(fi, v);
                    if !self.is_zero(d) {
                        row.push((j, d));
                    }
                }
            }
            row.sort_unstable_by_key(|&(j, _)| j);
            entries.extend(row.into_iter().map(|(j, d)| (i, j, d)));
        }
        entries
    }

    /// The directional derivatives (forward mode) of `roots` along `direction`: with
    /// `ẋ_v = direction(v)` for each variable `v` (zero where it gives `None`),
    ///
    /// ```text
    ///   ė = Σ_v ∂e/∂x_v · ẋ_v,
    /// ```
    ///
    /// built by one forward sweep over the roots' DAG (children before parents), each node's
    /// tangent from its children's by the rules of [`Self::diff`]. The result is linear in the
    /// roots' size, where the sum of [`Self::diff`] over the variables holds one derivative
    /// expression per variable: for a point on a 3D body, `R(q) p / |q|²` through its four
    /// quaternion components, the tangent shares `|q|²`'s rate `2 q·q̇` among the entries
    /// instead of differentiating it four times.
    ///
    /// ```
    /// use bondmech::expr::ExprGraph;
    /// let mut g = ExprGraph::new();
    /// let (x, y) = (g.var(1), g.var(2));
    /// let xy = g.mul(x, y);
    /// let e = g.sin(xy); // e = sin(x y)
    /// let (dx, dy) = (g.constant(3.0), g.constant(-1.0));
    /// let de = g.tangents(&[e], &|v| match v { 1 => Some(dx), 2 => Some(dy), _ => None })[0];
    /// // ė = cos(x y) (y ẋ + x ẏ) at x = 0.5, y = 2: cos(1) (6 − 0.5)
    /// let v = g.eval(de, &[0.0, 0.5, 2.0]);
    /// assert!((v - 1f64.cos() * 5.5).abs() < 1e-15);
    /// ```
    pub fn tangents(
        &mut self,
        roots: &[Expr],
        direction: &dyn Fn(u32) -> Option<Expr>,
    ) -> Vec<Expr> {
        let nodes = self.reachable(roots);
        let zero = self.zero();
        let mut tangent: FxMap<u32, Expr> = FxMap::default();
        for &n in &nodes {
            let t = self.chain_node(Expr(n), &|_, x: Expr| tangent[&x.0], &|k| {
                direction(k).unwrap_or(zero)
            });
            tangent.insert(n, t);
        }
        roots.iter().map(|r| tangent[&r.0]).collect()
    }

    /// Derivative of node `e` once all children's derivatives are memoised.
    fn diff_node(&mut self, e: Expr, var: u32) -> Expr {
        let (zero, one) = (self.zero(), self.one());
        self.chain_node(e, &|g: &Self, x: Expr| g.diff_memo[&(x, var)], &|k| {
            if k == var {
                one
            } else {
                zero
            }
        })
    }

    /// The chain rule at node `e`: its derivative from its children's (`d`) and the
    /// variables' (`dvar`), by the rules of the module documentation.
    fn chain_node(
        &mut self,
        e: Expr,
        d: &dyn Fn(&Self, Expr) -> Expr,
        dvar: &dyn Fn(u32) -> Expr,
    ) -> Expr {
        match self.node(e) {
            Node::Const(_) | Node::TableSlope(..) | Node::Un(UnOp::Sign, _) => self.zero(),
            Node::Var(k) => dvar(k),
            Node::Un(op, a) => {
                let da = d(self, a);
                if self.is_zero(da) {
                    return da;
                }
                let f = match op {
                    UnOp::Neg => return self.neg(da),
                    UnOp::Sin => self.cos(a),
                    UnOp::Cos => {
                        let s = self.sin(a);
                        self.neg(s)
                    }
                    UnOp::Tan => {
                        let e2 = self.mul(e, e);
                        let one = self.one();
                        self.add(one, e2)
                    }
                    UnOp::Sqrt => {
                        let two_e = self.scale(2.0, e);
                        return self.div(da, two_e);
                    }
                    UnOp::Abs => self.sign(a),
                    UnOp::Exp => e,
                    UnOp::Ln => return self.div(da, a),
                    UnOp::Sign => unreachable!("handled above"),
                };
                self.mul(f, da)
            }
            Node::Bin(op, a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                match op {
                    BinOp::Add => self.add(da, db),
                    BinOp::Sub => self.sub(da, db),
                    BinOp::Mul => {
                        let p = self.mul(da, b);
                        let q = self.mul(a, db);
                        self.add(p, q)
                    }
                    BinOp::Div => {
                        let q = self.mul(e, db);
                        let num = self.sub(da, q);
                        self.div(num, b)
                    }
                    BinOp::Pow => self.diff_pow(e, a, b, da, db),
                    BinOp::Atan2 => {
                        // a = y, b = x.
                        let p = self.mul(b, da);
                        let q = self.mul(a, db);
                        let num = self.sub(p, q);
                        let aa = self.mul(a, a);
                        let bb = self.mul(b, b);
                        let den = self.add(aa, bb);
                        self.div(num, den)
                    }
                    BinOp::Min => {
                        let c = self.sub(b, a);
                        self.select(c, da, db)
                    }
                    BinOp::Max => {
                        let c = self.sub(a, b);
                        self.select(c, da, db)
                    }
                }
            }
            Node::Select(c, a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                self.select(c, da, db)
            }
            Node::Table(k, a) => {
                let da = d(self, a);
                if self.is_zero(da) {
                    return da;
                }
                let s = self.table_slope(k, a);
                self.mul(s, da)
            }
        }
    }

    fn diff_pow(&mut self, e: Expr, a: Expr, b: Expr, da: Expr, db: Expr) -> Expr {
        if self.is_zero(db) {
            if self.is_zero(da) {
                return da;
            }
            // b·a^(b−1)·a' (b constant or independent of the variable).
            let one = self.one();
            let bm1 = self.sub(b, one);
            let p = self.pow(a, bm1);
            let f = self.mul(b, p);
            return self.mul(f, da);
        }
        // e·(b'·ln a + b·a'/a)
        let la = self.ln(a);
        let t1 = self.mul(db, la);
        let t2 = if self.is_zero(da) {
            da
        } else {
            let r = self.div(da, a);
            self.mul(b, r)
        };
        let s = self.add(t1, t2);
        self.mul(e, s)
    }
}
