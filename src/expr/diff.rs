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

    /// Derivative of node `e` once all children's derivatives are memoised.
    fn diff_node(&mut self, e: Expr, var: u32) -> Expr {
        let d = |g: &Self, x: Expr| g.diff_memo[&(x, var)];
        match self.node(e) {
            Node::Const(_) | Node::TableSlope(..) | Node::Un(UnOp::Sign, _) => self.zero(),
            Node::Var(k) => {
                if k == var {
                    self.one()
                } else {
                    self.zero()
                }
            }
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
