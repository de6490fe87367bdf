//! Switching functions: the non-smooth operations of an expression (`max`, `min`, `abs`,
//! `sign`, `select` on a non-constant condition) with their branch held by a *mode* variable,
//! so that an integrator sees a smooth right-hand side between the zeros of the switching
//! functions and a root finder stops it there (the state events of hybrid-system
//! simulation).
//!
//! Each such node `n` becomes, with `s` its switching function and `m` its mode variable,
//!
//! ```text
//!   max(a, b) → select(|m|, select(m, a, b), max(a, b)),   s = a − b
//!   min(a, b) → select(|m|, select(m, a, b), min(a, b)),   s = b − a
//!   |a|       → select(|m|, select(m, a, −a), |a|),       s = a
//!   sign(a)   → select(|m|, select(m, 1, −1), sign(a)),   s = a
//!   select(c, a, b) → select(|m|, select(m, a, b), select(c, a, b)),   s = c
//! ```
//!
//! so `m = +1` holds the branch taken where `s > 0`, `m = −1` the other one, and `m = 0` gives
//! the literal operation (a switch that chatters is released to it). Tables (piecewise linear
//! in their argument) are left as they are.

use super::graph::{Expr, ExprGraph, Node};
use super::hash::FxMap;
use super::ops::{BinOp, UnOp};

/// Expressions rewritten by [`ExprGraph::freeze_switches`].
#[derive(Clone, Debug)]
pub struct FrozenSwitches {
    /// The rewritten expressions, in the order given.
    pub exprs: Vec<Expr>,
    /// The switching function of mode `k` (variable `first_mode + k`); a switch nested in
    /// another's arguments has the smaller index, and the outer one's function reads its
    /// mode.
    pub switching: Vec<Expr>,
}

impl ExprGraph {
    /// Rewrites `roots` with every non-smooth node's branch held by a mode variable (slots
    /// `first_mode`, `first_mode + 1`, …; see the module documentation).
    ///
    /// ```
    /// use bondmech::expr::ExprGraph;
    /// let mut g = ExprGraph::new();
    /// let x = g.var(0);
    /// let e = g.parse("10*max(0, cos(x))", &mut |n| (n == "x").then_some(x)).unwrap();
    /// let f = g.freeze_switches(&[e], 1);
    /// assert_eq!(f.switching.len(), 1); // s = ±cos x
    /// // at x = 2 (cos 2 < 0) the mode of the sign of s gives the literal value 0, the other
    /// // one holds the cos branch continued past its zero
    /// let m = g.eval(f.switching[0], &[2.0, 0.0]).signum();
    /// assert_eq!(g.eval(f.exprs[0], &[2.0, m]), 0.0);
    /// assert!((g.eval(f.exprs[0], &[2.0, -m]) - 10.0 * 2f64.cos()).abs() < 1e-15);
    /// // mode 0: the literal max
    /// assert_eq!(g.eval(f.exprs[0], &[2.0, 0.0]), 0.0);
    /// ```
    pub fn freeze_switches(&mut self, roots: &[Expr], first_mode: u32) -> FrozenSwitches {
        let mut new: FxMap<u32, Expr> = FxMap::default();
        let mut switching = Vec::new();
        for i in self.reachable(roots) {
            let old = Expr(i);
            let m = |x: Expr| new[&x.0];
            let node = self.node(old);
            let branches = match node {
                Node::Bin(op @ (BinOp::Max | BinOp::Min), a, b) => {
                    let (a, b) = (m(a), m(b));
                    let (lit, s) = if op == BinOp::Max {
                        (self.max(a, b), self.sub(a, b))
                    } else {
                        (self.min(a, b), self.sub(b, a))
                    };
                    Some((lit, s, a, b))
                }
                Node::Un(UnOp::Abs, a) => {
                    let a = m(a);
                    let na = self.neg(a);
                    Some((self.abs(a), a, a, na))
                }
                Node::Un(UnOp::Sign, a) => {
                    let a = m(a);
                    let (one, minus) = (self.one(), self.constant(-1.0));
                    Some((self.sign(a), a, one, minus))
                }
                Node::Select(c, a, b) => {
                    let (c, a, b) = (m(c), m(a), m(b));
                    Some((self.select(c, a, b), c, a, b))
                }
                _ => None,
            };
            let e = match branches {
                // folded to a constant or a single branch: nothing to hold
                Some((lit, s, a, b)) if self.as_const(s).is_none() && a != b => {
                    let mode = self.var(first_mode + switching.len() as u32);
                    switching.push(s);
                    let held = self.select(mode, a, b);
                    let on = self.abs(mode);
                    self.select(on, held, lit)
                }
                Some((lit, ..)) => lit,
                None => self.rebuild(node, &new),
            };
            new.insert(i, e);
        }
        FrozenSwitches {
            exprs: roots.iter().map(|r| new[&r.0]).collect(),
            switching,
        }
    }
}
