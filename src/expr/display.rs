//! Readable infix rendering with the minimal parentheses for the parser's precedence
//! (`+ −` < `× /` < unary `−` < `^`, `^` right-associative).

use super::graph::{Expr, ExprGraph, Node};
use super::ops::{BinOp, UnOp};

const ADD: u8 = 1;
const MUL: u8 = 2;
const NEG: u8 = 3;
const POW: u8 = 4;
const ATOM: u8 = 5;

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
    pub fn display(&self, e: Expr, name: &dyn Fn(u32) -> String) -> String {
        self.fmt(e, name).0
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
    fn operand(&self, e: Expr, min: u8, name: &dyn Fn(u32) -> String) -> String {
        let (s, p) = self.fmt(e, name);
        if p < min {
            format!("({s})")
        } else {
            s
        }
    }

    fn fmt(&self, e: Expr, name: &dyn Fn(u32) -> String) -> (String, u8) {
        let p = self.prec(e);
        let call = |f: &str, args: &[Expr]| {
            let parts: Vec<String> = args.iter().map(|&a| self.fmt(a, name).0).collect();
            format!("{f}({})", parts.join(", "))
        };
        let s = match self.node(e) {
            Node::Const(b) => fmt_const(f64::from_bits(b)),
            Node::Var(k) => name(k),
            Node::Un(UnOp::Neg, a) => format!("-{}", self.operand(a, NEG, name)),
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
                call(f, &[a])
            }
            Node::Bin(op, a, b) => match op {
                BinOp::Add => format!(
                    "{} + {}",
                    self.operand(a, ADD, name),
                    self.operand(b, ADD, name)
                ),
                BinOp::Sub => format!(
                    "{} - {}",
                    self.operand(a, ADD, name),
                    self.operand(b, MUL, name)
                ),
                BinOp::Mul => format!(
                    "{} * {}",
                    self.operand(a, MUL, name),
                    self.operand(b, MUL, name)
                ),
                BinOp::Div => format!(
                    "{} / {}",
                    self.operand(a, MUL, name),
                    self.operand(b, NEG, name)
                ),
                BinOp::Pow => format!(
                    "{}^{}",
                    self.operand(a, ATOM, name),
                    self.operand(b, NEG, name)
                ),
                BinOp::Atan2 => call("atan2", &[a, b]),
                BinOp::Min => call("min", &[a, b]),
                BinOp::Max => call("max", &[a, b]),
            },
            Node::Select(c, a, b) => call("select", &[c, a, b]),
            Node::Table(k, a) => call(&format!("table{k}"), &[a]),
            Node::TableSlope(k, a) => call(&format!("table{k}_slope"), &[a]),
        };
        (s, p)
    }
}
