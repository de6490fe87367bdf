//! Substitution of variables by expressions, `e[xᵥ := sᵥ]`, rebuilding every node through the
//! graph's constructors so that the construction-time simplifications (constant folding,
//! `x·0 = 0`, `x − x = 0`, …) apply to the result.

use super::graph::{Expr, ExprGraph, Node};
use super::hash::FxMap;
use super::ops::{BinOp, UnOp};

impl ExprGraph {
    /// `e` with every variable `v` in `map` replaced by `map[v]` (the replacements are not
    /// substituted again).
    ///
    /// ```
    /// use bondmech::expr::ExprGraph;
    /// let mut g = ExprGraph::new();
    /// let (x, y) = (g.var(0), g.var(1));
    /// let e = g.parse("x*y + sin(y)", &mut |n| match n { "x" => Some(x), "y" => Some(y), _ => None }).unwrap();
    /// let two = g.constant(2.0);
    /// let s = g.substitute(e, &[(1, two)]); // 2x + sin 2
    /// assert!((g.eval(s, &[3.0]) - (6.0 + 2f64.sin())).abs() < 1e-15);
    /// ```
    pub fn substitute(&mut self, e: Expr, map: &[(u32, Expr)]) -> Expr {
        self.substitute_all(&[e], map)[0]
    }

    /// [`Self::substitute`] for several expressions sharing one memo (shared subexpressions
    /// are rebuilt once).
    pub fn substitute_all(&mut self, roots: &[Expr], map: &[(u32, Expr)]) -> Vec<Expr> {
        let by_var: FxMap<u32, Expr> = map.iter().copied().collect();
        let mut new: FxMap<u32, Expr> = FxMap::default();
        for i in self.reachable(roots) {
            let e = match self.node(Expr(i)) {
                Node::Var(k) => by_var.get(&k).copied().unwrap_or(Expr(i)),
                node => self.rebuild(node, &new),
            };
            new.insert(i, e);
        }
        roots.iter().map(|r| new[&r.0]).collect()
    }

    /// `node` built again through the constructors from its children's images in `new`
    /// (constants and variables are themselves).
    pub(crate) fn rebuild(&mut self, node: Node, new: &FxMap<u32, Expr>) -> Expr {
        let m = |x: Expr| new[&x.0];
        match node {
            Node::Const(_) | Node::Var(_) => self.intern(node),
            Node::Un(op, a) => {
                let a = m(a);
                match op {
                    UnOp::Neg => self.neg(a),
                    UnOp::Sin => self.sin(a),
                    UnOp::Cos => self.cos(a),
                    UnOp::Tan => self.tan(a),
                    UnOp::Sqrt => self.sqrt(a),
                    UnOp::Abs => self.abs(a),
                    UnOp::Exp => self.exp(a),
                    UnOp::Ln => self.ln(a),
                    UnOp::Sign => self.sign(a),
                }
            }
            Node::Bin(op, a, b) => {
                let (a, b) = (m(a), m(b));
                match op {
                    BinOp::Add => self.add(a, b),
                    BinOp::Sub => self.sub(a, b),
                    BinOp::Mul => self.mul(a, b),
                    BinOp::Div => self.div(a, b),
                    BinOp::Pow => self.pow(a, b),
                    BinOp::Atan2 => self.atan2(a, b),
                    BinOp::Min => self.min(a, b),
                    BinOp::Max => self.max(a, b),
                }
            }
            Node::Select(c, a, b) => {
                let (c, a, b) = (m(c), m(a), m(b));
                self.select(c, a, b)
            }
            Node::Table(k, a) => {
                let a = m(a);
                match self.as_const(a) {
                    Some(x) => {
                        let v = self.tables[k as usize].value(x);
                        self.constant(v)
                    }
                    None => self.intern(Node::Table(k, a)),
                }
            }
            Node::TableSlope(k, a) => {
                let a = m(a);
                self.table_slope(k, a)
            }
        }
    }
}
