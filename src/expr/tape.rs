//! Flat evaluation tape: the nodes reachable from a set of outputs, in topological
//! order, as instructions over a register file (the caller's `work` slice).
//!
//! Layout of `work`: `[0, n_vars)` the input variables, then the constants, then the
//! registers. Each reachable node is computed once; a register is recycled after the
//! last instruction that reads it (outputs stay live to the end). [`Tape::eval`] does
//! not allocate.

use super::graph::{Expr, ExprGraph, Node};
use super::ops::{apply_bin, apply_un, select, BinOp, TableData, UnOp};

#[derive(Clone, Copy, Debug)]
enum Instr<I> {
    // the common operations get their own variants (one dispatch per instruction instead of
    // two: measured 1.3x faster on the partitioned right-hand sides); the rest go through
    // `apply_un` / `apply_bin`, which define every operation's semantics
    Neg { dst: I, a: I },
    Sin { dst: I, a: I },
    Cos { dst: I, a: I },
    Add { dst: I, a: I, b: I },
    Sub { dst: I, a: I, b: I },
    Mul { dst: I, a: I, b: I },
    Div { dst: I, a: I, b: I },
    Un { op: UnOp, dst: I, a: I },
    Bin { op: BinOp, dst: I, a: I, b: I },
    Select { dst: I, c: I, a: I, b: I },
    Table { dst: I, table: I, a: I },
    TableSlope { dst: I, table: I, a: I },
}

impl<I: Copy> Instr<I> {
    fn un(op: UnOp, dst: I, a: I) -> Self {
        match op {
            UnOp::Neg => Instr::Neg { dst, a },
            UnOp::Sin => Instr::Sin { dst, a },
            UnOp::Cos => Instr::Cos { dst, a },
            _ => Instr::Un { op, dst, a },
        }
    }

    fn bin(op: BinOp, dst: I, a: I, b: I) -> Self {
        match op {
            BinOp::Add => Instr::Add { dst, a, b },
            BinOp::Sub => Instr::Sub { dst, a, b },
            BinOp::Mul => Instr::Mul { dst, a, b },
            BinOp::Div => Instr::Div { dst, a, b },
            _ => Instr::Bin { op, dst, a, b },
        }
    }

    /// The same instruction with every index mapped by `f` (`None` if one does not fit).
    fn map<J>(self, f: impl Fn(I) -> Option<J>) -> Option<Instr<J>> {
        Some(match self {
            Instr::Neg { dst, a } => Instr::Neg {
                dst: f(dst)?,
                a: f(a)?,
            },
            Instr::Sin { dst, a } => Instr::Sin {
                dst: f(dst)?,
                a: f(a)?,
            },
            Instr::Cos { dst, a } => Instr::Cos {
                dst: f(dst)?,
                a: f(a)?,
            },
            Instr::Add { dst, a, b } => Instr::Add {
                dst: f(dst)?,
                a: f(a)?,
                b: f(b)?,
            },
            Instr::Sub { dst, a, b } => Instr::Sub {
                dst: f(dst)?,
                a: f(a)?,
                b: f(b)?,
            },
            Instr::Mul { dst, a, b } => Instr::Mul {
                dst: f(dst)?,
                a: f(a)?,
                b: f(b)?,
            },
            Instr::Div { dst, a, b } => Instr::Div {
                dst: f(dst)?,
                a: f(a)?,
                b: f(b)?,
            },
            Instr::Un { op, dst, a } => Instr::Un {
                op,
                dst: f(dst)?,
                a: f(a)?,
            },
            Instr::Bin { op, dst, a, b } => Instr::Bin {
                op,
                dst: f(dst)?,
                a: f(a)?,
                b: f(b)?,
            },
            Instr::Select { dst, c, a, b } => Instr::Select {
                dst: f(dst)?,
                c: f(c)?,
                a: f(a)?,
                b: f(b)?,
            },
            Instr::Table { dst, table, a } => Instr::Table {
                dst: f(dst)?,
                table: f(table)?,
                a: f(a)?,
            },
            Instr::TableSlope { dst, table, a } => Instr::TableSlope {
                dst: f(dst)?,
                table: f(table)?,
                a: f(a)?,
            },
        })
    }
}

/// Slots a compact tape addresses: every `u8` index is one of them, so reading and writing a
/// register needs no bounds check.
const COMPACT_SLOTS: usize = 256;

/// A tape's instructions: one-byte indices into a fixed block of [`COMPACT_SLOTS`] registers
/// where the whole work (variables, constants, registers) and the tables fit in it (every
/// residual of a planar mechanism of a few bodies), else four-byte indices into the caller's
/// slice. Both run through the one interpreter, [`execute`].
#[derive(Clone, Debug)]
enum Code {
    Compact(Vec<Instr<u8>>),
    Wide(Vec<Instr<u32>>),
}

impl Code {
    fn new(instrs: Vec<Instr<u32>>, work_len: usize, n_tables: usize) -> Code {
        if work_len <= COMPACT_SLOTS && n_tables <= COMPACT_SLOTS {
            let narrow = |i: u32| u8::try_from(i).ok();
            if let Some(c) = instrs.iter().map(|ins| ins.map(narrow)).collect() {
                return Code::Compact(c);
            }
        }
        Code::Wide(instrs)
    }

    fn len(&self) -> usize {
        match self {
            Code::Compact(c) => c.len(),
            Code::Wide(c) => c.len(),
        }
    }
}

/// Registers read and written through indices of type `Ix`.
trait Registers {
    type Ix: Copy;
    fn get(&self, i: Self::Ix) -> f64;
    fn set(&mut self, i: Self::Ix, v: f64);
}

impl Registers for [f64; COMPACT_SLOTS] {
    type Ix = u8;
    #[inline(always)]
    fn get(&self, i: u8) -> f64 {
        self[i as usize]
    }
    #[inline(always)]
    fn set(&mut self, i: u8, v: f64) {
        self[i as usize] = v;
    }
}

impl Registers for [f64] {
    type Ix = u32;
    #[inline(always)]
    fn get(&self, i: u32) -> f64 {
        self[i as usize]
    }
    #[inline(always)]
    fn set(&mut self, i: u32, v: f64) {
        self[i as usize] = v;
    }
}

/// Runs `code` over the registers `r`: each instruction reads its operands and writes `dst`.
fn execute<R, I>(code: &[Instr<I>], tables: &[TableData], r: &mut R)
where
    R: Registers<Ix = I> + ?Sized,
    I: Copy + Into<u32>,
{
    for ins in code {
        match *ins {
            // a constant operation: `apply_*` (the one definition of each operation's
            // semantics) folds to the operation itself
            Instr::Neg { dst, a } => r.set(dst, apply_un(UnOp::Neg, r.get(a))),
            Instr::Sin { dst, a } => r.set(dst, apply_un(UnOp::Sin, r.get(a))),
            Instr::Cos { dst, a } => r.set(dst, apply_un(UnOp::Cos, r.get(a))),
            Instr::Add { dst, a, b } => r.set(dst, apply_bin(BinOp::Add, r.get(a), r.get(b))),
            Instr::Sub { dst, a, b } => r.set(dst, apply_bin(BinOp::Sub, r.get(a), r.get(b))),
            Instr::Mul { dst, a, b } => r.set(dst, apply_bin(BinOp::Mul, r.get(a), r.get(b))),
            Instr::Div { dst, a, b } => r.set(dst, apply_bin(BinOp::Div, r.get(a), r.get(b))),
            Instr::Un { op, dst, a } => r.set(dst, apply_un(op, r.get(a))),
            Instr::Bin { op, dst, a, b } => r.set(dst, apply_bin(op, r.get(a), r.get(b))),
            Instr::Select { dst, c, a, b } => r.set(dst, select(r.get(c), r.get(a), r.get(b))),
            Instr::Table { dst, table, a } => {
                r.set(dst, tables[table.into() as usize].value(r.get(a)))
            }
            Instr::TableSlope { dst, table, a } => {
                r.set(dst, tables[table.into() as usize].slope(r.get(a)))
            }
        }
    }
}

/// A compiled, allocation-free evaluator of several expressions at once.
#[derive(Clone, Debug)]
pub struct Tape {
    n_vars: usize,
    consts: Vec<f64>,
    code: Code,
    outputs: Vec<u32>,
    work_len: usize,
    tables: Vec<TableData>,
}

impl ExprGraph {
    /// Compiles `outputs` into a [`Tape`]: only nodes reachable from them, shared
    /// subexpressions once, registers reused after their last use.
    pub fn compile(&self, outputs: &[Expr]) -> Tape {
        self.compile_staged(outputs, &|_| 0, 1).tape
    }

    /// Compiles `outputs` into a [`StagedTape`]: each computed node belongs to the latest
    /// stage of the variables it mentions (`var_stage`, clamped below `n_stages`; constants
    /// are stage 0), the instructions run stage by stage, and a stage can be run again after
    /// its variables changed without re-running the earlier ones (their values stay live,
    /// and no register is shared between stages). For evaluations where some variables stay
    /// fixed over several evaluations: the independent coordinates of a Newton iteration on
    /// the dependent ones, whose sines and cosines are then computed once.
    pub fn compile_staged(
        &self,
        outputs: &[Expr],
        var_stage: &dyn Fn(u32) -> usize,
        n_stages: usize,
    ) -> StagedTape {
        let n_stages = n_stages.max(1);
        let order = self.reachable_marked(outputs);
        let n_vars = order
            .iter()
            .filter_map(|&i| match self.nodes[i as usize] {
                Node::Var(k) => Some(k as usize + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0);

        // Dense per-reachable-node tables, indexed by position in `order` (found through a
        // table over the arena: compiling costs no hashing and no search)
        let mut position = vec![u32::MAX; order.last().map_or(0, |&i| i as usize + 1)];
        for (p, &i) in order.iter().enumerate() {
            position[i as usize] = p as u32;
        }
        let pos_of = |e: Expr| {
            let p = position[e.0 as usize];
            debug_assert!(p != u32::MAX, "child of a reachable node is reachable");
            p as usize
        };
        const NONE: u32 = u32::MAX;
        const LIVE_TO_END: u32 = u32::MAX - 1;
        let mut slot: Vec<u32> = vec![NONE; order.len()];
        let mut last_use: Vec<u32> = vec![NONE; order.len()]; // instruction index of last read
        let mut stage: Vec<usize> = vec![0; order.len()];
        let mut consts = Vec::new();
        // the computed nodes in evaluation order: by stage, topologically within one (a
        // node's stage is at least its children's, so children still come first)
        let mut seq: Vec<usize> = Vec::new();
        for (p, &i) in order.iter().enumerate() {
            match self.nodes[i as usize] {
                Node::Var(k) => {
                    slot[p] = k;
                    stage[p] = var_stage(k).min(n_stages - 1);
                }
                Node::Const(b) => {
                    slot[p] = (n_vars + consts.len()) as u32;
                    consts.push(f64::from_bits(b));
                }
                n => {
                    let (ch, m) = n.children();
                    stage[p] = ch[..m].iter().map(|c| stage[pos_of(*c)]).max().unwrap_or(0);
                    seq.push(p);
                }
            }
        }
        seq.sort_by_key(|&p| stage[p]);
        for (n_instr, &p) in seq.iter().enumerate() {
            let (ch, m) = self.nodes[order[p] as usize].children();
            for c in &ch[..m] {
                let cp = pos_of(*c);
                // a value read by a later stage must survive re-runs of that stage
                last_use[cp] = if stage[cp] < stage[p] || last_use[cp] == LIVE_TO_END {
                    LIVE_TO_END
                } else {
                    n_instr as u32
                };
            }
        }
        for o in outputs {
            last_use[pos_of(*o)] = LIVE_TO_END;
        }

        let base = (n_vars + consts.len()) as u32;
        let mut free: Vec<u32> = Vec::new();
        let mut n_regs = 0u32;
        let mut tables: Vec<TableData> = Vec::new();
        let mut table_map: Vec<(u32, u32)> = Vec::new();
        let mut instrs = Vec::with_capacity(seq.len());
        let mut bounds = vec![0; n_stages + 1];
        let mut current = 0;
        for &p in &seq {
            let node = self.nodes[order[p] as usize];
            if stage[p] != current {
                // registers are never shared between stages
                free.clear();
                for b in &mut bounds[current + 1..=stage[p]] {
                    *b = instrs.len();
                }
                current = stage[p];
            }
            let here = instrs.len() as u32;
            let (ch, m) = node.children();
            let mut cs = [0u32; 3];
            // Free operands whose last reader is this instruction (before allocating dst,
            // so dst may overwrite an operand: every instruction reads before it writes).
            for j in 0..m {
                let cp = pos_of(ch[j]);
                cs[j] = slot[cp];
                if cs[j] >= base && last_use[cp] == here && !ch[..j].contains(&ch[j]) {
                    free.push(cs[j]);
                }
            }
            let dst = free.pop().unwrap_or_else(|| {
                n_regs += 1;
                base + n_regs - 1
            });
            let mut tab = |k: u32| match table_map.iter().find(|(g, _)| *g == k) {
                Some(&(_, t)) => t,
                None => {
                    tables.push(self.tables[k as usize].clone());
                    let t = (tables.len() - 1) as u32;
                    table_map.push((k, t));
                    t
                }
            };
            let [c0, c1, c2] = cs;
            let ins = match node {
                Node::Un(op, _) => Instr::un(op, dst, c0),
                Node::Bin(op, ..) => Instr::bin(op, dst, c0, c1),
                Node::Select(..) => Instr::Select {
                    dst,
                    c: c0,
                    a: c1,
                    b: c2,
                },
                Node::Table(k, _) => Instr::Table {
                    dst,
                    table: tab(k),
                    a: c0,
                },
                Node::TableSlope(k, _) => Instr::TableSlope {
                    dst,
                    table: tab(k),
                    a: c0,
                },
                Node::Var(_) | Node::Const(_) => unreachable!("leaves are skipped"),
            };
            instrs.push(ins);
            slot[p] = dst;
        }
        for b in &mut bounds[current + 1..] {
            *b = instrs.len();
        }
        let outputs = outputs.iter().map(|o| slot[pos_of(*o)]).collect();
        let work_len = base as usize + n_regs as usize;
        let code = Code::new(instrs, work_len, tables.len());
        StagedTape {
            tape: Tape {
                n_vars,
                // a compact tape's work is the whole block its indices can address
                work_len: match code {
                    Code::Compact(_) => COMPACT_SLOTS,
                    Code::Wide(_) => work_len,
                },
                consts,
                code,
                outputs,
                tables,
            },
            bounds,
        }
    }
}

/// A [`Tape`] whose instructions run in stages ([`ExprGraph::compile_staged`]).
#[derive(Clone, Debug)]
pub struct StagedTape {
    tape: Tape,
    /// Instruction index where each stage starts (and the end).
    bounds: Vec<usize>,
}

impl StagedTape {
    /// The whole tape (all stages at once).
    pub fn tape(&self) -> &Tape {
        &self.tape
    }

    /// Number of stages.
    pub fn n_stages(&self) -> usize {
        self.bounds.len() - 1
    }

    /// Instructions of stage `s`.
    pub fn stage_len(&self, s: usize) -> usize {
        self.bounds[s + 1] - self.bounds[s]
    }

    /// Scratch space with the constants preloaded (as [`Tape::workspace`]).
    pub fn workspace(&self) -> Vec<f64> {
        self.tape.workspace()
    }

    /// Copies `vars` in and runs the stages `stages` (e.g. `0..2`), then writes every output
    /// into `out`. An output is current when its stage and every earlier one have run since
    /// the variables they mention last changed. `work` as for [`Tape::eval_prepared`].
    ///
    /// # Panics
    /// As [`Tape::eval_prepared`], or if `stages` runs past the last stage.
    pub fn eval_stages(
        &self,
        vars: &[f64],
        work: &mut [f64],
        out: &mut [f64],
        stages: std::ops::Range<usize>,
    ) {
        let t = &self.tape;
        t.load_vars(vars, work, out);
        t.run_instrs(self.bounds[stages.start]..self.bounds[stages.end], work);
        t.write_outputs(work, out);
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
        self.code.len()
    }

    /// The tape computes nothing (every output is a variable or a constant).
    pub fn is_empty(&self) -> bool {
        self.code.len() == 0
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
        assert!(
            vars.len() >= self.n_vars,
            "tape needs {} variables, got {}",
            self.n_vars,
            vars.len()
        );
        assert!(
            work.len() >= self.work_len,
            "tape workspace needs {} slots, got {}",
            self.work_len,
            work.len()
        );
        assert_eq!(out.len(), self.outputs.len(), "tape output length");
        work[..self.n_vars].copy_from_slice(&vars[..self.n_vars]);
        self.run(work, out);
    }

    /// Like [`Tape::eval`] with the input vector given as consecutive pieces, e.g.
    /// `[&[t], y, y']` for variables numbered `t = 0`, `y = 1..=n`, `y' = n+1..=2n`.
    /// Does not allocate.
    ///
    /// # Panics
    /// If the pieces hold fewer than `n_vars()` values in total, or as [`Tape::eval`].
    pub fn eval_parts(&self, parts: &[&[f64]], work: &mut [f64], out: &mut [f64]) {
        let total: usize = parts.iter().map(|p| p.len()).sum();
        assert!(
            total >= self.n_vars,
            "tape needs {} variables, got {}",
            self.n_vars,
            total
        );
        assert!(
            work.len() >= self.work_len,
            "tape workspace needs {} slots, got {}",
            self.work_len,
            work.len()
        );
        assert_eq!(out.len(), self.outputs.len(), "tape output length");
        let mut at = 0;
        for p in parts {
            let take = p.len().min(self.n_vars - at);
            work[at..at + take].copy_from_slice(&p[..take]);
            at += take;
        }
        self.run(work, out);
    }

    /// Executes the instructions once the variables are in `work[..n_vars]`.
    fn run(&self, work: &mut [f64], out: &mut [f64]) {
        let nv = self.n_vars;
        work[nv..nv + self.consts.len()].copy_from_slice(&self.consts);
        self.run_prepared(work, out);
    }

    /// Like [`Tape::eval`] for a `work` that came from this tape's [`Tape::workspace`] and
    /// is used with no other tape: its constants are in place (no instruction writes them),
    /// so only the variables are copied in. For small tapes evaluated very often (the
    /// partitioned right-hand side), where the copy of the constants is a visible cost.
    ///
    /// # Panics
    /// As [`Tape::eval`].
    pub fn eval_prepared(&self, vars: &[f64], work: &mut [f64], out: &mut [f64]) {
        self.load_vars(vars, work, out);
        self.run_prepared(work, out);
    }

    /// Checks the slices' lengths and copies the variables into `work` (constants in place).
    fn load_vars(&self, vars: &[f64], work: &mut [f64], out: &[f64]) {
        assert!(
            vars.len() >= self.n_vars && work.len() >= self.work_len,
            "tape needs {} variables and {} workspace slots, got {} and {}",
            self.n_vars,
            self.work_len,
            vars.len(),
            work.len()
        );
        assert_eq!(out.len(), self.outputs.len(), "tape output length");
        for (w, &v) in work[..self.n_vars].iter_mut().zip(vars) {
            *w = v;
        }
    }

    fn run_prepared(&self, work: &mut [f64], out: &mut [f64]) {
        self.run_instrs(0..self.code.len(), work);
        self.write_outputs(work, out);
    }

    fn write_outputs(&self, work: &[f64], out: &mut [f64]) {
        for (o, &s) in out.iter_mut().zip(&self.outputs) {
            *o = work[s as usize];
        }
    }

    fn run_instrs(&self, range: std::ops::Range<usize>, work: &mut [f64]) {
        match &self.code {
            Code::Compact(code) => {
                let regs: &mut [f64; COMPACT_SLOTS] = (&mut work[..COMPACT_SLOTS])
                    .try_into()
                    .expect("a compact tape's work holds its register block");
                execute(&code[range], &self.tables, regs)
            }
            Code::Wide(code) => execute(&code[range], &self.tables, work),
        }
    }
}
