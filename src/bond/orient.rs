//! Causal strokes as a degree-constrained orientation, solved by bipartite matching (max flow).
//!
//! Every bond has exactly one *effort source* among its two ends (the element that computes its
//! effort; the other end computes its flow). The causality rules are rules on how many of its
//! bonds an element is the effort source of:
//! Se 1, Sf 0, 1-junction exactly 1 (the bond whose other end imposes the common flow),
//! 0-junction exactly `d − 1` (one bond imposes the common effort), TF/MTF exactly 1 (one
//! stroke in, one out), GY/MGY 2 (both strokes away: efforts from flows; 0, both strokes at
//! it, when 2 cannot hold: the caller solves again), R 0 or 1, I 0 when
//! integral and 1 when differential, C 1 when integral and 0 when differential.
//!
//! That is a bipartite `b`-matching between bonds (each matched once) and elements (each
//! matched between `lo` and `hi` times): a max flow `source → bond → end element → sink` with
//! capacities on the element → sink arcs, solved by Dinic's algorithm (`O(E √V)` on these unit
//! networks). Lower bounds are met first and never undone (an augmenting path never lowers an
//! element's count), then the capacities are raised in stages so that, when the rules cannot
//! all hold, the ones given up are the least important: structural rules first, then the
//! storages' wanted causality, then the upper bounds, then storages may change causality,
//! then a transformer may divide by a modulus that is zero at the state, and last any bond is
//! placed (the elements left outside their rule are the conflicts). Nodes and arcs are built
//! in the canonical (name) order, so the result does not depend on the order in the file.

use std::collections::VecDeque;

/// A max-flow network with Dinic's algorithm; node 0 is the source, node 1 the sink.
#[derive(Debug, Clone)]
pub struct Network {
    adj: Vec<Vec<usize>>,
    to: Vec<usize>,
    cap: Vec<i64>,
    level: Vec<i32>,
    iter: Vec<usize>,
}

impl Network {
    /// A network with `n` nodes and no arcs.
    pub fn new(n: usize) -> Self {
        Network {
            adj: vec![Vec::new(); n],
            to: Vec::new(),
            cap: Vec::new(),
            level: vec![0; n],
            iter: vec![0; n],
        }
    }

    /// Adds an arc `a → b` of capacity `c`; returns its index (its reverse is `index ^ 1`).
    pub fn arc(&mut self, a: usize, b: usize, c: i64) -> usize {
        let i = self.to.len();
        self.to.push(b);
        self.cap.push(c);
        self.adj[a].push(i);
        self.to.push(a);
        self.cap.push(0);
        self.adj[b].push(i + 1);
        i
    }

    /// Raises the capacity of arc `i` by `d`.
    pub fn raise(&mut self, i: usize, d: i64) {
        self.cap[i] += d;
    }

    /// Flow on arc `i` (its reverse residual capacity).
    pub fn flow(&self, i: usize) -> i64 {
        self.cap[i ^ 1]
    }

    fn bfs(&mut self) -> bool {
        self.level.iter_mut().for_each(|l| *l = -1);
        self.level[0] = 0;
        let mut q = VecDeque::from([0usize]);
        while let Some(v) = q.pop_front() {
            for &i in &self.adj[v] {
                let w = self.to[i];
                if self.cap[i] > 0 && self.level[w] < 0 {
                    self.level[w] = self.level[v] + 1;
                    q.push_back(w);
                }
            }
        }
        self.level[1] >= 0
    }

    fn dfs(&mut self, v: usize, f: i64) -> i64 {
        if v == 1 {
            return f;
        }
        while self.iter[v] < self.adj[v].len() {
            let i = self.adj[v][self.iter[v]];
            let w = self.to[i];
            if self.cap[i] > 0 && self.level[w] == self.level[v] + 1 {
                let d = self.dfs(w, f.min(self.cap[i]));
                if d > 0 {
                    self.cap[i] -= d;
                    self.cap[i ^ 1] += d;
                    return d;
                }
            }
            self.iter[v] += 1;
        }
        0
    }

    /// Augments to a maximum flow from the current one; returns the flow added.
    ///
    /// The recursion depth is at most the BFS depth, 3 on a fresh bipartite network and
    /// longer only along alternating paths; it is bounded by the number of nodes.
    pub fn augment(&mut self) -> i64 {
        let mut total = 0;
        while self.bfs() {
            self.iter.iter_mut().for_each(|i| *i = 0);
            loop {
                let f = self.dfs(0, i64::MAX);
                if f == 0 {
                    break;
                }
                total += f;
            }
        }
        total
    }
}
