//! Scalar semantics of every node kind, shared by constant folding, the reference
//! interpreter and the tape so that all three agree bit for bit.
//!
//! Conventions: `sign(x)` is −1, 0, +1 (NaN stays NaN); `select(c, a, b)` is `a` when
//! `c > 0` and `b` otherwise (also for NaN `c`); `pow(a, b)` uses `powi` for integer
//! exponents with |b| ≤ 1024 and `powf` otherwise; a table is the piecewise-linear
//! interpolant of `(tᵢ, vᵢ)`, held constant outside `[t₀, tₙ]`.

/// One-argument operations.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum UnOp {
    Neg,
    Sin,
    Cos,
    Tan,
    Sqrt,
    Abs,
    Exp,
    Ln,
    /// −1, 0 or +1: the derivative of `abs`.
    Sign,
}

/// Two-argument operations.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
}

impl BinOp {
    /// `a op b == b op a`.
    pub(crate) fn is_commutative(self) -> bool {
        matches!(self, BinOp::Add | BinOp::Mul | BinOp::Min | BinOp::Max)
    }
}

/// Evaluates a one-argument operation.
#[inline]
pub(crate) fn apply_un(op: UnOp, x: f64) -> f64 {
    match op {
        UnOp::Neg => -x,
        UnOp::Sin => x.sin(),
        UnOp::Cos => x.cos(),
        UnOp::Tan => x.tan(),
        UnOp::Sqrt => x.sqrt(),
        UnOp::Abs => x.abs(),
        UnOp::Exp => x.exp(),
        UnOp::Ln => x.ln(),
        UnOp::Sign => sign(x),
    }
}

/// Evaluates a two-argument operation.
#[inline]
pub(crate) fn apply_bin(op: BinOp, a: f64, b: f64) -> f64 {
    match op {
        BinOp::Add => a + b,
        BinOp::Sub => a - b,
        BinOp::Mul => a * b,
        BinOp::Div => a / b,
        BinOp::Pow => pow(a, b),
        BinOp::Atan2 => a.atan2(b),
        BinOp::Min => a.min(b),
        BinOp::Max => a.max(b),
    }
}

/// `a^b`, with the faster and exact-for-integers `powi` when `b` is a small integer.
#[inline]
pub(crate) fn pow(a: f64, b: f64) -> f64 {
    if b == b.trunc() && b.abs() <= 1024.0 {
        a.powi(b as i32)
    } else {
        a.powf(b)
    }
}

/// −1, 0 or +1 (NaN for NaN).
#[inline]
pub(crate) fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else if x == 0.0 {
        0.0
    } else {
        x
    }
}

/// `a` when `c > 0`, else `b`.
#[inline]
pub(crate) fn select(c: f64, a: f64, b: f64) -> f64 {
    if c > 0.0 {
        a
    } else {
        b
    }
}

/// A piecewise-linear table `(t, v)` with strictly increasing `t`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TableData {
    pub(crate) t: Vec<f64>,
    pub(crate) v: Vec<f64>,
}

impl TableData {
    /// Index `i` of the segment `[tᵢ, tᵢ₊₁)` containing `x`, for `t₀ ≤ x < tₙ`.
    #[inline]
    fn segment(&self, x: f64) -> usize {
        // partition_point: number of t_k <= x, at least 1 here.
        self.t.partition_point(|&tk| tk <= x) - 1
    }

    /// Interpolated value, clamped to `v₀` / `vₙ` outside `[t₀, tₙ]`.
    #[inline]
    pub(crate) fn value(&self, x: f64) -> f64 {
        let n = self.t.len().min(self.v.len());
        if n == 0 || x.is_nan() {
            return f64::NAN;
        }
        if x <= self.t[0] {
            return self.v[0];
        }
        if x >= self.t[n - 1] {
            return self.v[n - 1];
        }
        let i = self.segment(x);
        let (t0, t1, v0, v1) = (self.t[i], self.t[i + 1], self.v[i], self.v[i + 1]);
        v0 + (v1 - v0) * ((x - t0) / (t1 - t0))
    }

    /// Slope `(vᵢ₊₁ − vᵢ)/(tᵢ₊₁ − tᵢ)` of the segment `[tᵢ, tᵢ₊₁)` containing `x`
    /// (right-continuous at breakpoints); 0 for `x < t₀` or `x ≥ tₙ`.
    #[inline]
    pub(crate) fn slope(&self, x: f64) -> f64 {
        let n = self.t.len().min(self.v.len());
        if n == 0 || x.is_nan() {
            return f64::NAN;
        }
        if x < self.t[0] || x >= self.t[n - 1] {
            return 0.0;
        }
        let i = self.segment(x);
        (self.v[i + 1] - self.v[i]) / (self.t[i + 1] - self.t[i])
    }
}
