//! The hash-consed expression arena and its construction-time simplifications.
//!
//! Every node is stored once: building the same node twice returns the same [`Expr`],
//! and commutative operations (`+`, `×`, `min`, `max`) put their operands in a
//! canonical order first, so `a + b` and `b + a` are the same node. Children always
//! have smaller indices than their parents, so arena order is a topological order.
//!
//! Simplifications applied when a node is built (`c` constants, `x`, `y` anything):
//! constant folding of every operation; `x + 0 = 0 + x = x`; `x − 0 = x`; `0 − x = −x`;
//! `x − x = 0`; `x + (−y) = x − y`; `x − (−y) = x + y`; `x·1 = x`; `x·(−1) = −x`;
//! `c₁·(c₂·x) = (c₁c₂)·x`; `(−x)·(−y) = x·y`; `x/1 = x`; `x^1 = x`; `x^0 = 1`; `1^x = 1`;
//! `−(−x) = x`; `−(x − y) = y − x`; `−(c·x) = (−c)·x`; `|−x| = |x|`; `||x|| = |x|`;
//! `min(x, x) = max(x, x) = x`.
//!
//! Annihilation (`x·0 = 0`, `0/x = 0`, `x − x = 0`) is applied only when `x` is not a
//! constant: a constant `inf` or `NaN` is folded by IEEE arithmetic instead (`0·inf = NaN`).
//! For a non-constant `x` the algebraic identity is used, as every symbolic system
//! does; it differs from IEEE only where `x` evaluates to `inf` or `NaN`.
//! Constants are normalised: `−0.0` is stored as `0.0` and every NaN as the canonical NaN.

use super::hash::{FxMap, FxSet};
use super::ops::{apply_bin, apply_un, select, BinOp, TableData, UnOp};

/// Handle of a node in an [`ExprGraph`]. Only meaningful with the graph that made it.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Expr(pub(crate) u32);

impl Expr {
    /// Position of the node in its graph's arena.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One node of the arena.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Node {
    /// A constant, stored as its (normalised) bit pattern.
    Const(u64),
    /// Slot `i` of the evaluation input vector.
    Var(u32),
    Un(UnOp, Expr),
    Bin(BinOp, Expr, Expr),
    /// `if c > 0 { a } else { b }`.
    Select(Expr, Expr, Expr),
    /// Piecewise-linear table `k` at the argument.
    Table(u32, Expr),
    /// Slope of table `k` at the argument (piecewise constant).
    TableSlope(u32, Expr),
}

impl Node {
    /// Children, in order, into `out` (at most three).
    pub(crate) fn children(&self) -> ([Expr; 3], usize) {
        let z = Expr(0);
        match *self {
            Node::Const(_) | Node::Var(_) => ([z; 3], 0),
            Node::Un(_, a) | Node::Table(_, a) | Node::TableSlope(_, a) => ([a, z, z], 1),
            Node::Bin(_, a, b) => ([a, b, z], 2),
            Node::Select(c, a, b) => ([c, a, b], 3),
        }
    }
}

/// Hash-consed arena of expression nodes (see the module docs for the simplifications).
#[derive(Clone, Debug, Default)]
pub struct ExprGraph {
    pub(crate) nodes: Vec<Node>,
    index: FxMap<Node, Expr>,
    pub(crate) tables: Vec<TableData>,
    table_index: FxMap<Vec<u64>, u32>,
    pub(crate) diff_memo: FxMap<(Expr, u32), Expr>,
    /// The variables of the expression [`ExprGraph::depends_on`] was last asked about.
    last_vars: LastVars,
}

/// A one-entry cache `(e, vars(e))` behind a mutex (the graph stays `Sync`): callers ask
/// [`ExprGraph::depends_on`] about one expression for every variable slot in turn, so one
/// traversal then serves them all (measured: N-link pendulum, N = 512, the bond graph's
/// integrability check made 1.5 million full traversals, 60 % of the model build).
#[derive(Default)]
struct LastVars(std::sync::Mutex<Option<(Expr, std::sync::Arc<[u32]>)>>);

impl Clone for LastVars {
    fn clone(&self) -> Self {
        LastVars(std::sync::Mutex::new(
            self.0.lock().map(|g| g.clone()).unwrap_or(None),
        ))
    }
}

impl std::fmt::Debug for LastVars {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LastVars")
    }
}

fn normalise(c: f64) -> f64 {
    if c == 0.0 {
        0.0
    } else if c.is_nan() {
        f64::NAN
    } else {
        c
    }
}

impl ExprGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of distinct nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// No node yet.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    pub(crate) fn node(&self, e: Expr) -> Node {
        self.nodes[e.0 as usize]
    }

    /// Returns the existing node or appends it.
    pub(crate) fn intern(&mut self, n: Node) -> Expr {
        if let Some(&e) = self.index.get(&n) {
            return e;
        }
        let e = Expr(u32::try_from(self.nodes.len()).expect("expression graph exceeds 2^32 nodes"));
        self.nodes.push(n);
        self.index.insert(n, e);
        e
    }

    /// The constant `c` (`−0.0` is stored as `0.0`).
    pub fn constant(&mut self, c: f64) -> Expr {
        self.intern(Node::Const(normalise(c).to_bits()))
    }

    /// The constant 0.
    pub fn zero(&mut self) -> Expr {
        self.constant(0.0)
    }

    /// The constant 1.
    pub fn one(&mut self) -> Expr {
        self.constant(1.0)
    }

    /// Variable slot `index` of the evaluation input vector.
    pub fn var(&mut self, index: u32) -> Expr {
        self.intern(Node::Var(index))
    }

    /// The value of `e` if it is a constant node.
    pub fn as_const(&self, e: Expr) -> Option<f64> {
        match self.node(e) {
            Node::Const(b) => Some(f64::from_bits(b)),
            _ => None,
        }
    }

    /// `e` is the constant 0.
    pub fn is_zero(&self, e: Expr) -> bool {
        self.as_const(e) == Some(0.0)
    }

    fn is_const_eq(&self, e: Expr, c: f64) -> bool {
        self.as_const(e) == Some(c)
    }

    fn is_nonconst(&self, e: Expr) -> bool {
        self.as_const(e).is_none()
    }

    fn un(&mut self, op: UnOp, a: Expr) -> Expr {
        if let Some(x) = self.as_const(a) {
            return self.constant(apply_un(op, x));
        }
        self.intern(Node::Un(op, a))
    }

    fn bin(&mut self, op: BinOp, a: Expr, b: Expr) -> Expr {
        if let (Some(x), Some(y)) = (self.as_const(a), self.as_const(b)) {
            return self.constant(apply_bin(op, x, y));
        }
        let (a, b) = if op.is_commutative() {
            self.order(a, b)
        } else {
            (a, b)
        };
        self.intern(Node::Bin(op, a, b))
    }

    /// Canonical operand order: a constant first, otherwise by arena index.
    fn order(&self, a: Expr, b: Expr) -> (Expr, Expr) {
        match (self.as_const(a).is_some(), self.as_const(b).is_some()) {
            (false, true) => (b, a),
            (true, false) => (a, b),
            _ => (a.min(b), a.max(b)),
        }
    }

    /// `a + b`.
    pub fn add(&mut self, a: Expr, b: Expr) -> Expr {
        if self.is_zero(a) {
            return b;
        }
        if self.is_zero(b) {
            return a;
        }
        if let Node::Un(UnOp::Neg, y) = self.node(b) {
            if self.is_nonconst(a) {
                return self.sub(a, y);
            }
        }
        if let Node::Un(UnOp::Neg, x) = self.node(a) {
            if self.is_nonconst(b) {
                return self.sub(b, x);
            }
        }
        self.bin(BinOp::Add, a, b)
    }

    /// `a − b`.
    pub fn sub(&mut self, a: Expr, b: Expr) -> Expr {
        if self.is_zero(b) {
            return a;
        }
        if self.is_zero(a) {
            return self.neg(b);
        }
        if a == b && self.is_nonconst(a) {
            return self.zero();
        }
        if let Node::Un(UnOp::Neg, y) = self.node(b) {
            return self.add(a, y);
        }
        self.bin(BinOp::Sub, a, b)
    }

    /// `a · b`.
    pub fn mul(&mut self, a: Expr, b: Expr) -> Expr {
        let (a, b) = self.order(a, b);
        // After ordering, a constant (if any) is `a`.
        if let Some(c) = self.as_const(a) {
            if self.as_const(b).is_none() {
                if c == 1.0 {
                    return b;
                }
                if c == 0.0 {
                    return a;
                }
                if c == -1.0 {
                    return self.neg(b);
                }
                if let Node::Bin(BinOp::Mul, b1, b2) = self.node(b) {
                    if let Some(c2) = self.as_const(b1) {
                        let k = self.constant(c * c2);
                        return self.mul(k, b2);
                    }
                }
                if let Node::Un(UnOp::Neg, x) = self.node(b) {
                    let k = self.constant(-c);
                    return self.mul(k, x);
                }
            }
        }
        if let (Node::Un(UnOp::Neg, x), Node::Un(UnOp::Neg, y)) = (self.node(a), self.node(b)) {
            return self.mul(x, y);
        }
        self.bin(BinOp::Mul, a, b)
    }

    /// `a / b`.
    pub fn div(&mut self, a: Expr, b: Expr) -> Expr {
        if self.is_const_eq(b, 1.0) {
            return a;
        }
        if self.is_zero(a) && self.is_nonconst(b) {
            return a;
        }
        if self.is_const_eq(b, -1.0) {
            return self.neg(a);
        }
        self.bin(BinOp::Div, a, b)
    }

    /// `a ^ b`.
    pub fn pow(&mut self, a: Expr, b: Expr) -> Expr {
        if self.is_const_eq(b, 1.0) {
            return a;
        }
        if self.is_zero(b) || self.is_const_eq(a, 1.0) {
            // IEEE: x^0 = 1 and 1^y = 1 even for NaN.
            return self.one();
        }
        self.bin(BinOp::Pow, a, b)
    }

    /// `atan2(a, b)`: the angle of the point `(b, a)`.
    pub fn atan2(&mut self, a: Expr, b: Expr) -> Expr {
        self.bin(BinOp::Atan2, a, b)
    }

    /// `min(a, b)`.
    pub fn min(&mut self, a: Expr, b: Expr) -> Expr {
        if a == b {
            return a;
        }
        self.bin(BinOp::Min, a, b)
    }

    /// `max(a, b)`.
    pub fn max(&mut self, a: Expr, b: Expr) -> Expr {
        if a == b {
            return a;
        }
        self.bin(BinOp::Max, a, b)
    }

    /// `−a`.
    pub fn neg(&mut self, a: Expr) -> Expr {
        match self.node(a) {
            Node::Un(UnOp::Neg, x) => x,
            Node::Bin(BinOp::Sub, x, y) => self.sub(y, x),
            Node::Bin(BinOp::Mul, c, x) if self.as_const(c).is_some() => {
                let k = self.constant(-self.as_const(c).unwrap_or(0.0));
                self.mul(k, x)
            }
            _ => self.un(UnOp::Neg, a),
        }
    }

    /// `sin a`.
    pub fn sin(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Sin, a)
    }

    /// `cos a`.
    pub fn cos(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Cos, a)
    }

    /// `tan a`.
    pub fn tan(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Tan, a)
    }

    /// `√a`.
    pub fn sqrt(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Sqrt, a)
    }

    /// `|a|`.
    pub fn abs(&mut self, a: Expr) -> Expr {
        match self.node(a) {
            Node::Un(UnOp::Neg, x) => self.abs(x),
            Node::Un(UnOp::Abs, _) => a,
            _ => self.un(UnOp::Abs, a),
        }
    }

    /// `eᵃ`.
    pub fn exp(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Exp, a)
    }

    /// Natural logarithm `ln a`.
    pub fn ln(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Ln, a)
    }

    /// `sign(a)` ∈ {−1, 0, +1}: the derivative of `|a|`.
    pub fn sign(&mut self, a: Expr) -> Expr {
        self.un(UnOp::Sign, a)
    }

    /// `if c > 0 { a } else { b }` (used for the derivatives of `min` and `max`).
    pub fn select(&mut self, c: Expr, a: Expr, b: Expr) -> Expr {
        if a == b {
            return a;
        }
        if let Some(cv) = self.as_const(c) {
            return if select(cv, 1.0, 0.0) == 1.0 { a } else { b };
        }
        self.intern(Node::Select(c, a, b))
    }

    /// `Σ terms` (0 for no terms).
    pub fn sum(&mut self, terms: &[Expr]) -> Expr {
        let mut acc = self.zero();
        for &t in terms {
            acc = self.add(acc, t);
        }
        acc
    }

    /// `c · a`.
    pub fn scale(&mut self, c: f64, a: Expr) -> Expr {
        let k = self.constant(c);
        self.mul(k, a)
    }

    /// `Σ aᵢ bᵢ` over the common length.
    pub fn dot(&mut self, a: &[Expr], b: &[Expr]) -> Expr {
        let mut acc = self.zero();
        for (&x, &y) in a.iter().zip(b) {
            let p = self.mul(x, y);
            acc = self.add(acc, p);
        }
        acc
    }

    /// Piecewise-linear interpolation of the points `(tᵢ, vᵢ)` at `arg`, held at `v₀` below
    /// `t₀` and at `vₙ` above `tₙ`. `t` must be strictly increasing (the caller validates);
    /// extra entries of the longer slice are ignored.
    pub fn table(&mut self, t: &[f64], v: &[f64], arg: Expr) -> Expr {
        let n = t.len().min(v.len());
        let data = TableData {
            t: t[..n].to_vec(),
            v: v[..n].to_vec(),
        };
        if let Some(x) = self.as_const(arg) {
            return self.constant(data.value(x));
        }
        let k = self.table_id(data);
        self.intern(Node::Table(k, arg))
    }

    fn table_id(&mut self, data: TableData) -> u32 {
        let key: Vec<u64> = data
            .t
            .iter()
            .chain(&data.v)
            .map(|x| x.to_bits())
            .chain([data.t.len() as u64])
            .collect();
        if let Some(&k) = self.table_index.get(&key) {
            return k;
        }
        let k = self.tables.len() as u32;
        self.tables.push(data);
        self.table_index.insert(key, k);
        k
    }

    /// Slope of table `k` at `arg` (internal: the derivative of a table node).
    pub(crate) fn table_slope(&mut self, k: u32, arg: Expr) -> Expr {
        if let Some(x) = self.as_const(arg) {
            let s = self.tables[k as usize].slope(x);
            return self.constant(s);
        }
        self.intern(Node::TableSlope(k, arg))
    }

    /// [`Self::reachable`] by one sweep down the arena from the highest root, marking children
    /// (a node's children precede it): linear in the arena below the roots, without hashing,
    /// for the large output sets of a compile (a Jacobian's thousands of entries sharing most
    /// of the graph: Bricard's index-1 Jacobian reaches 100 000 nodes).
    pub(crate) fn reachable_marked(&self, roots: &[Expr]) -> Vec<u32> {
        let Some(top) = roots.iter().map(|e| e.0 as usize).max() else {
            return Vec::new();
        };
        let mut mark = vec![false; top + 1];
        for r in roots {
            mark[r.0 as usize] = true;
        }
        let mut order = Vec::new();
        for i in (0..=top).rev() {
            if !mark[i] {
                continue;
            }
            order.push(i as u32);
            let (ch, n) = self.nodes[i].children();
            for c in &ch[..n] {
                mark[c.0 as usize] = true;
            }
        }
        order.reverse();
        order
    }

    /// Nodes reachable from `roots`, in ascending arena (= topological) order.
    pub(crate) fn reachable(&self, roots: &[Expr]) -> Vec<u32> {
        let mut seen = FxSet::default();
        let mut stack: Vec<Expr> = roots.to_vec();
        let mut order = Vec::new();
        while let Some(e) = stack.pop() {
            if !seen.insert(e.0) {
                continue;
            }
            order.push(e.0);
            let (ch, n) = self.node(e).children();
            stack.extend_from_slice(&ch[..n]);
        }
        order.sort_unstable();
        order
    }

    /// Sorted, unique variable indices `e` depends on.
    pub fn vars(&self, e: Expr) -> Vec<u32> {
        let mut v: Vec<u32> = self
            .reachable(&[e])
            .into_iter()
            .filter_map(|i| match self.nodes[i as usize] {
                Node::Var(k) => Some(k),
                _ => None,
            })
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// `e` mentions variable `var`. The variables of the last `e` asked about are kept, so
    /// asking about one expression for many variables traverses it once.
    pub fn depends_on(&self, e: Expr, var: u32) -> bool {
        let target = Node::Var(var);
        match self.index.get(&target) {
            None => false,
            Some(&v) if v > e => false,
            Some(_) => {
                let Ok(mut last) = self.last_vars.0.lock() else {
                    // a poisoned cache (a panic elsewhere): answer without it
                    return self.vars(e).binary_search(&var).is_ok();
                };
                match last.as_ref() {
                    Some((k, vars)) if *k == e => vars.binary_search(&var).is_ok(),
                    _ => {
                        let vars: std::sync::Arc<[u32]> = self.vars(e).into();
                        let found = vars.binary_search(&var).is_ok();
                        *last = Some((e, vars));
                        found
                    }
                }
            }
        }
    }

    /// Reference interpreter: the value of `e` at `vars` (missing variables read as NaN).
    /// Slow (allocates); use [`ExprGraph::compile`] for repeated evaluation.
    pub fn eval(&self, e: Expr, vars: &[f64]) -> f64 {
        let order = self.reachable(&[e]);
        let mut val: FxMap<u32, f64> = FxMap::default();
        for &i in &order {
            let g = |x: Expr| val[&x.0];
            let y = match self.nodes[i as usize] {
                Node::Const(b) => f64::from_bits(b),
                Node::Var(k) => vars.get(k as usize).copied().unwrap_or(f64::NAN),
                Node::Un(op, a) => apply_un(op, g(a)),
                Node::Bin(op, a, b) => apply_bin(op, g(a), g(b)),
                Node::Select(c, a, b) => select(g(c), g(a), g(b)),
                Node::Table(k, a) => self.tables[k as usize].value(g(a)),
                Node::TableSlope(k, a) => self.tables[k as usize].slope(g(a)),
            };
            val.insert(i, y);
        }
        val[&e.0]
    }
}
