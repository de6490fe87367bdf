//! Flat evaluation tape: the nodes reachable from a set of outputs, in topological
//! order, as instructions over a register file (the caller's `work` slice).
//!
//! Layout of `work`: `[0, n_vars)` the input variables, then the constants, then the
//! registers. Each reachable node is computed once; a register is recycled after the
//! last instruction that reads it (outputs stay live to the end). [`Tape::eval`] does
//! not allocate.

use std::collections::HashMap;

use super::graph::{Expr, ExprGraph, Node};
use super::ops::{apply_bin, apply_un, select, BinOp, TableData, UnOp};

#[derive(Clone, Debug)]
enum Instr {
    Un { op: UnOp, dst: u32, a: u32 },
    Bin { op: BinOp, dst: u32, a: u32, b: u32 },
    Select { dst: u32, c: u32, a: u32, b: u32 },
    Table { dst: u32, table: u32, a: u32 },
    TableSlope { dst: u32, table: u32, a: u32 },
}

/// A compiled, allocation-free evaluator of several expressions at once.
#[derive(Clone, Debug)]
pub struct Tape {
    n_vars: usize,
    consts: Vec<f64>,
    instrs: Vec<Instr>,
    outputs: Vec<u32>,
    work_len: usize,
    tables: Vec<TableData>,
}

impl ExprGraph {
    /// Compiles `outputs` into a [`Tape`]: only nodes reachable from them, shared
    /// subexpressions once, registers reused after their last use.
    pub fn compile(&self, outputs: &[Expr]) -> Tape {
        let order = self.reachable(outputs);
        let n_vars = order
            .iter()
            .filter_map(|&i| match self.nodes[i as usize] {
                Node::Var(k) => Some(k as usize + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0);

        // Slots of leaves; position of the last instruction reading each computed node.
        let mut slot: HashMap<u32, u32> = HashMap::with_capacity(order.len());
        let mut consts = Vec::new();
        let mut last_use: HashMap<u32, usize> = HashMap::new();
        let mut n_instr = 0usize;
        for &i in &order {
            match self.nodes[i as usize] {
                Node::Var(k) => {
                    slot.insert(i, k);
                }
                Node::Const(b) => {
                    slot.insert(i, (n_vars + consts.len()) as u32);
                    consts.push(f64::from_bits(b));
                }
                n => {
                    let (ch, m) = n.children();
                    for c in &ch[..m] {
                        last_use.insert(c.0, n_instr);
                    }
                    n_instr += 1;
                }
            }
        }
        for o in outputs {
            last_use.insert(o.0, usize::MAX);
        }

        let base = (n_vars + consts.len()) as u32;
        let mut free: Vec<u32> = Vec::new();
        let mut n_regs = 0u32;
        let mut tables: Vec<TableData> = Vec::new();
        let mut table_map: HashMap<u32, u32> = HashMap::new();
        let mut instrs = Vec::with_capacity(n_instr);
        for &i in &order {
            let node = self.nodes[i as usize];
            if matches!(node, Node::Var(_) | Node::Const(_)) {
                continue;
            }
            let pos = instrs.len();
            let (ch, m) = node.children();
            let s = |c: Expr| slot[&c.0];
            // Free operands whose last reader is this instruction (before allocating dst,
            // so dst may overwrite an operand: every instruction reads before it writes).
            for (j, c) in ch[..m].iter().enumerate() {
                if ch[..j].contains(c) {
                    continue;
                }
                let cs = slot[&c.0];
                if cs >= base && last_use.get(&c.0) == Some(&pos) {
                    free.push(cs);
                }
            }
            let dst = free.pop().unwrap_or_else(|| {
                n_regs += 1;
                base + n_regs - 1
            });
            let mut tab = |k: u32| {
                *table_map.entry(k).or_insert_with(|| {
                    tables.push(self.tables[k as usize].clone());
                    (tables.len() - 1) as u32
                })
            };
            let ins = match node {
                Node::Un(op, a) => Instr::Un { op, dst, a: s(a) },
                Node::Bin(op, a, b) => Instr::Bin { op, dst, a: s(a), b: s(b) },
                Node::Select(c, a, b) => Instr::Select { dst, c: s(c), a: s(a), b: s(b) },
                Node::Table(k, a) => Instr::Table { dst, table: tab(k), a: s(a) },
                Node::TableSlope(k, a) => Instr::TableSlope { dst, table: tab(k), a: s(a) },
                Node::Var(_) | Node::Const(_) => unreachable!("leaves are skipped"),
            };
            instrs.push(ins);
            slot.insert(i, dst);
            // A node nobody reads (cannot happen for reachable non-outputs) frees at once.
            if !last_use.contains_key(&i) {
                free.push(dst);
            }
        }
        let outputs = outputs.iter().map(|o| slot[&o.0]).collect();
        Tape {
            n_vars,
            work_len: base as usize + n_regs as usize,
            consts,
            instrs,
            outputs,
            tables,
        }
    }
}

impl Tape {
    /// Number of outputs (length of `out` in [`Tape::eval`]).
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// `1 +` the largest variable index used, 0 if none (minimum length of `vars`).
    pub fn n_vars(&self) -> usize {
        self.n_vars
    }

    /// Scratch space for [`Tape::eval`], with the constants preloaded.
    pub fn workspace(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.work_len];
        w[self.n_vars..self.n_vars + self.consts.len()].copy_from_slice(&self.consts);
        w
    }

    /// Minimum length of the `work` slice.
    pub fn workspace_len(&self) -> usize {
        self.work_len
    }

    /// Number of instructions (computed nodes; variables and constants are free).
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    /// The tape computes nothing (every output is a variable or a constant).
    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// Number of distinct constants.
    pub fn n_consts(&self) -> usize {
        self.consts.len()
    }

    /// Evaluates all outputs at `vars` into `out`, using `work` as scratch. Does not
    /// allocate. Any `work` of at least [`Tape::workspace_len`] elements is accepted
    /// (constants are rewritten each call, which costs a few copies).
    ///
    /// # Panics
    /// If `vars.len() < n_vars()`, `work.len() < workspace_len()` or
    /// `out.len() != n_outputs()` (programming errors).
    pub fn eval(&self, vars: &[f64], work: &mut [f64], out: &mut [f64]) {
        assert!(vars.len() >= self.n_vars, "tape needs {} variables, got {}", self.n_vars, vars.len());
        assert!(work.len() >= self.work_len, "tape workspace needs {} slots, got {}", self.work_len, work.len());
        assert_eq!(out.len(), self.outputs.len(), "tape output length");
        let nv = self.n_vars;
        work[..nv].copy_from_slice(&vars[..nv]);
        work[nv..nv + self.consts.len()].copy_from_slice(&self.consts);
        for ins in &self.instrs {
            match *ins {
                Instr::Un { op, dst, a } => work[dst as usize] = apply_un(op, work[a as usize]),
                Instr::Bin { op, dst, a, b } => {
                    work[dst as usize] = apply_bin(op, work[a as usize], work[b as usize])
                }
                Instr::Select { dst, c, a, b } => {
                    work[dst as usize] = select(work[c as usize], work[a as usize], work[b as usize])
                }
                Instr::Table { dst, table, a } => {
                    work[dst as usize] = self.tables[table as usize].value(work[a as usize])
                }
                Instr::TableSlope { dst, table, a } => {
                    work[dst as usize] = self.tables[table as usize].slope(work[a as usize])
                }
            }
        }
        for (o, &s) in out.iter_mut().zip(&self.outputs) {
            *o = work[s as usize];
        }
    }
}
