//! Readable infix rendering with the minimal parentheses for the parser's precedence
//! (`+ −` < `× /` < unary `−` < `^`, `^` right-associative).

use super::graph::{Expr, ExprGraph, Node};
use super::ops::{BinOp, UnOp};

const ADD: u8 = 1;
const MUL: u8 = 2;
const NEG: u8 = 3;
const POW: u8 = 4;
const ATOM: u8 = 5;

/// Length beyond which [`ExprGraph::display`] elides the rest as `…`.
pub const DISPLAY_MAX_CHARS: usize = 20_000;
/// Nesting depth beyond which [`ExprGraph::display`] elides subexpressions as `…`.
pub const DISPLAY_MAX_DEPTH: usize = 200;

/// Formats a constant: integers without a fraction, others in shortest round-trip form.
pub(crate) fn fmt_const(c: f64) -> String {
    if c == c.trunc() && c.abs() < 1e15 {
        format!("{}", c)
    } else {
        format!("{:?}", c)
    }
}

impl ExprGraph {
    /// Readable infix form of `e`, naming variable `i` by `name(i)`.
    ///
    /// Shared subexpressions are written out at every use, so the text of a deep DAG
    /// can be exponentially long: past [`DISPLAY_MAX_CHARS`] characters or
    /// [`DISPLAY_MAX_DEPTH`] levels of nesting the remainder is elided as `…`.
    pub fn display(&self, e: Expr, name: &dyn Fn(u32) -> String) -> String {
        let mut budget = DISPLAY_MAX_CHARS;
        self.fmt(e, name, &mut budget, 0, DISPLAY_MAX_DEPTH).0
    }

    /// The complete infix form of `e` (nothing elided), to be parsed back: the text a bond
    /// graph scene stores its moduli and closures in. `None` when it would exceed `max_chars`.
    pub fn display_exact(
        &self,
        e: Expr,
        name: &dyn Fn(u32) -> String,
        max_chars: usize,
    ) -> Option<String> {
        let mut budget = max_chars;
        let s = self.fmt(e, name, &mut budget, 0, usize::MAX).0;
        (budget > 0).then_some(s)
    }

    fn prec(&self, e: Expr) -> u8 {
        match self.node(e) {
            Node::Const(b) if f64::from_bits(b) < 0.0 => NEG,
            Node::Bin(BinOp::Add | BinOp::Sub, ..) => ADD,
            Node::Bin(BinOp::Mul | BinOp::Div, ..) => MUL,
            Node::Un(UnOp::Neg, _) => NEG,
            Node::Bin(BinOp::Pow, ..) => POW,
            _ => ATOM,
        }
    }

    /// Text of `e` wrapped in parentheses when its precedence is below `min`.
    fn operand(
        &self,
        e: Expr,
        min: u8,
        name: &dyn Fn(u32) -> String,
        budget: &mut usize,
        depth: usize,
        max_depth: usize,
    ) -> String {
        let (s, p) = self.fmt(e, name, budget, depth, max_depth);
        if p < min {
            format!("({s})")
        } else {
            s
        }
    }

    fn fmt(
        &self,
        e: Expr,
        name: &dyn Fn(u32) -> String,
        budget: &mut usize,
        depth: usize,
        max_depth: usize,
    ) -> (String, u8) {
        if *budget == 0 || depth > max_depth {
            return ("…".to_string(), ATOM);
        }
        let depth = depth + 1;
        let p = self.prec(e);
        let call = |f: &str, args: &[Expr], budget: &mut usize| {
            let parts: Vec<String> = args
                .iter()
                .map(|&a| self.fmt(a, name, budget, depth, max_depth).0)
                .collect();
            format!("{f}({})", parts.join(", "))
        };
        let s = match self.node(e) {
            Node::Const(b) => fmt_const(f64::from_bits(b)),
            Node::Var(k) => name(k),
            Node::Un(UnOp::Neg, a) => {
                format!("-{}", self.operand(a, NEG, name, budget, depth, max_depth))
            }
            Node::Un(op, a) => {
                let f = match op {
                    UnOp::Sin => "sin",
                    UnOp::Cos => "cos",
                    UnOp::Tan => "tan",
                    UnOp::Sqrt => "sqrt",
                    UnOp::Abs => "abs",
                    UnOp::Exp => "exp",
                    UnOp::Ln => "ln",
                    UnOp::Sign | UnOp::Neg => "sign",
                };
                call(f, &[a], budget)
            }
            Node::Bin(op, a, b) => match op {
                BinOp::Add => format!(
                    "{} + {}",
                    self.operand(a, ADD, name, budget, depth, max_depth),
                    self.operand(b, ADD, name, budget, depth, max_depth)
                ),
                BinOp::Sub => format!(
                    "{} - {}",
                    self.operand(a, ADD, name, budget, depth, max_depth),
                    self.operand(b, MUL, name, budget, depth, max_depth)
                ),
                BinOp::Mul => format!(
                    "{} * {}",
                    self.operand(a, MUL, name, budget, depth, max_depth),
                    self.operand(b, MUL, name, budget, depth, max_depth)
                ),
                BinOp::Div => format!(
                    "{} / {}",
                    self.operand(a, MUL, name, budget, depth, max_depth),
                    self.operand(b, NEG, name, budget, depth, max_depth)
                ),
                BinOp::Pow => format!(
                    "{}^{}",
                    self.operand(a, ATOM, name, budget, depth, max_depth),
                    self.operand(b, NEG, name, budget, depth, max_depth)
                ),
                BinOp::Atan2 => call("atan2", &[a, b], budget),
                BinOp::Min => call("min", &[a, b], budget),
                BinOp::Max => call("max", &[a, b], budget),
            },
            Node::Select(c, a, b) => call("select", &[c, a, b], budget),
            Node::Table(k, a) => call(&format!("table{k}"), &[a], budget),
            Node::TableSlope(k, a) => call(&format!("table{k}_slope"), &[a], budget),
        };
        *budget = budget.saturating_sub(s.len());
        (s, p)
    }
}
