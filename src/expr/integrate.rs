//! Closed-form antiderivatives `F` with `∂F/∂x = f`, for the expressions a rate driver gives.
//!
//! A driver prescribing a joint's rate `ṡ = ω(t)` has the position row
//! `s(q) − s(t₀) − ∫_{t₀}^{t} ω(τ) dτ = 0` (the flow source `Sf(t)` integrated: the closure of
//! the chapter's differential-causality inertia it drives). The integral is taken here in
//! closed form, so the row, its time derivative (`ω` itself) and the index reduction's
//! second derivative are all exact expressions. Rules, with `c` free of `x` and `L` linear
//! in `x` (`L' = ∂L/∂x` free of `x`, non-zero):
//!
//! | `f` | `F` |
//! |---|---|
//! | `c` | `c·x` |
//! | `f + g`, `f − g`, `−f`, `c·f`, `f / c` | by linearity |
//! | `L^n` (`n ≠ −1`), `c / L` | `L^(n+1) / ((n+1) L')`, `c ln|L| / L'` |
//! | `sin L`, `cos L`, `exp L`, `c^L` | `−cos L / L'`, `sin L / L'`, `exp L / L'`, `c^L / (L' ln c)` |
//! | `|L|`, `sign L`, `√L` | `L|L| / (2L')`, `|L| / L'`, `2L√L / (3L')` |
//! | `max(L₁, L₂)`, `min(L₁, L₂)` | `(L₁ + L₂ ± |L₁ − L₂|) / 2` by the rows above |
//! | `min(c₁, max(c₀, L))` (`c₀ ≤ c₁`) | `c₀x + ((m − c₀)²/2 + (c₁ − c₀) max(0, L − c₁)) / L'`, `m` the clamp |
//! | `p·g`, `p` a polynomial in `x` | by parts: `P·g`… `∫ p g = p G − ∫ p' G` |
//!
//! The clamp row is the form an FMU's piecewise-constant input takes
//! ([`crate::scene::inputs::piecewise_constant`]). Anything else is refused, naming the
//! subexpression ([`NotIntegrable`]).
//!
//! ```
//! use bondmech::expr::ExprGraph;
//! let mut g = ExprGraph::new();
//! let t = g.var(0);
//! let w = g.parse("10*(1 - exp(-2*t))", &mut |n| (n == "t").then_some(t)).unwrap();
//! let s = g.antiderivative(w, 0).unwrap(); // 10 t + 5 exp(−2t)
//! let at = |g: &ExprGraph, x: f64| g.eval(s, &[x]);
//! let exact = 10.0 * 1.5 + 5.0 * (-3f64).exp() - 5.0;
//! assert!((at(&g, 1.5) - at(&g, 0.0) - exact).abs() < 1e-13);
//! ```

use super::graph::{Expr, ExprGraph, Node};
use super::ops::{BinOp, UnOp};

/// How deep integration by parts and the rules may nest before giving up.
const MAX_DEPTH: usize = 24;

/// An expression with no closed-form antiderivative among the rules of [`crate::expr`]'s
/// `integrate` module.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("no closed-form integral for the term {term} (integrable: polynomials, sin/cos/exp/sqrt/powers of a linear argument, |·|, sign, min/max of linear terms and clamps, and their sums and products with a polynomial)")]
pub struct NotIntegrable {
    /// The offending subexpression, written with `x` for the variable.
    pub term: String,
}

impl ExprGraph {
    /// An antiderivative `F` of `f` with respect to variable `x` (`∂F/∂x = f`), in closed
    /// form by the rules of the module documentation; other variables are constants.
    pub fn antiderivative(&mut self, f: Expr, x: u32) -> Result<Expr, NotIntegrable> {
        if let Some(p) = self.prim(f, x, 0) {
            return Ok(p);
        }
        let bad = self.failing_term(f, x);
        let term = self.display(bad, &|i| {
            if i == x {
                "t".into()
            } else {
                format!("x{i}")
            }
        });
        Err(NotIntegrable { term })
    }

    /// The smallest subexpression of `f` the rules refuse (for the error message).
    fn failing_term(&mut self, f: Expr, x: u32) -> Expr {
        let (children, n) = self.node(f).children();
        for &c in &children[..n] {
            if self.depends_on(c, x) && self.prim(c, x, 0).is_none() {
                return self.failing_term(c, x);
            }
        }
        f
    }

    /// `∂e/∂x` when it is free of `x` and non-zero: `e` is linear in `x`.
    fn slope(&mut self, e: Expr, x: u32) -> Option<Expr> {
        let d = self.diff(e, x);
        (!self.depends_on(d, x) && !self.is_zero(d)).then_some(d)
    }

    /// Whether `e` is a polynomial in `x`: built from `x` and terms free of it by `+`, `−`,
    /// `×`, a division by a term free of `x` and whole non-negative constant powers.
    fn is_polynomial(&self, e: Expr, x: u32) -> bool {
        if !self.depends_on(e, x) {
            return true;
        }
        match self.node(e) {
            Node::Var(_) => true,
            Node::Un(UnOp::Neg, a) => self.is_polynomial(a, x),
            Node::Bin(BinOp::Add | BinOp::Sub | BinOp::Mul, a, b) => {
                self.is_polynomial(a, x) && self.is_polynomial(b, x)
            }
            Node::Bin(BinOp::Div, a, b) => !self.depends_on(b, x) && self.is_polynomial(a, x),
            Node::Bin(BinOp::Pow, a, n) => {
                self.as_const(n)
                    .is_some_and(|n| n >= 0.0 && n == n.trunc() && n <= 64.0)
                    && self.is_polynomial(a, x)
            }
            _ => false,
        }
    }

    fn prim(&mut self, f: Expr, x: u32, depth: usize) -> Option<Expr> {
        if depth > MAX_DEPTH {
            return None;
        }
        let xv = self.var(x);
        if !self.depends_on(f, x) {
            return Some(self.mul(f, xv));
        }
        let deeper = depth + 1;
        match self.node(f) {
            Node::Var(_) => {
                let sq = self.mul(xv, xv);
                Some(self.scale(0.5, sq))
            }
            Node::Un(UnOp::Neg, a) => {
                let p = self.prim(a, x, deeper)?;
                Some(self.neg(p))
            }
            Node::Bin(BinOp::Add, a, b) => {
                let (pa, pb) = (self.prim(a, x, deeper)?, self.prim(b, x, deeper)?);
                Some(self.add(pa, pb))
            }
            Node::Bin(BinOp::Sub, a, b) => {
                let (pa, pb) = (self.prim(a, x, deeper)?, self.prim(b, x, deeper)?);
                Some(self.sub(pa, pb))
            }
            Node::Bin(BinOp::Mul, a, b) => self.prim_product(a, b, x, deeper),
            Node::Bin(BinOp::Div, a, b) => {
                if !self.depends_on(b, x) {
                    let p = self.prim(a, x, deeper)?;
                    return Some(self.div(p, b));
                }
                // c / L = c ln|L| / L'
                if self.depends_on(a, x) {
                    return None;
                }
                let s = self.slope(b, x)?;
                let l = self.abs(b);
                let l = self.ln(l);
                let num = self.mul(a, l);
                Some(self.div(num, s))
            }
            Node::Bin(BinOp::Pow, base, n) => {
                if !self.depends_on(n, x) {
                    let s = self.slope(base, x)?;
                    if self.as_const(n) == Some(-1.0) {
                        let l = self.abs(base);
                        let l = self.ln(l);
                        return Some(self.div(l, s));
                    }
                    let one = self.one();
                    let n1 = self.add(n, one);
                    let p = self.pow(base, n1);
                    let den = self.mul(n1, s);
                    return Some(self.div(p, den));
                }
                // c^L = exp(L ln c): c^L / (L' ln c)
                if self.depends_on(base, x) {
                    return None;
                }
                let s = self.slope(n, x)?;
                let lc = self.ln(base);
                let den = self.mul(s, lc);
                Some(self.div(f, den))
            }
            Node::Un(
                op @ (UnOp::Sin | UnOp::Cos | UnOp::Exp | UnOp::Abs | UnOp::Sign | UnOp::Sqrt),
                a,
            ) => {
                let s = self.slope(a, x)?;
                let num = match op {
                    UnOp::Sin => {
                        let c = self.cos(a);
                        self.neg(c)
                    }
                    UnOp::Cos => self.sin(a),
                    UnOp::Exp => f,
                    UnOp::Abs => {
                        let m = self.mul(a, f);
                        self.scale(0.5, m)
                    }
                    UnOp::Sqrt => {
                        let m = self.mul(a, f);
                        self.scale(2.0 / 3.0, m)
                    }
                    _ => self.abs(a),
                };
                Some(self.div(num, s))
            }
            Node::Bin(op @ (BinOp::Min | BinOp::Max), a, b) => {
                if let Some(p) = self.prim_clamp(f, op, a, b, x) {
                    return Some(p);
                }
                // (a + b ± |a − b|) / 2, a and b linear (or differing by a constant)
                let sum = self.add(a, b);
                let ps = self.prim(sum, x, deeper)?;
                let d = self.sub(a, b);
                let pd = if self.depends_on(d, x) {
                    let s = self.slope(d, x)?;
                    let ad = self.abs(d);
                    let m = self.mul(d, ad);
                    let m = self.div(m, s);
                    self.scale(0.5, m)
                } else {
                    let ad = self.abs(d);
                    self.mul(ad, xv)
                };
                let both = if op == BinOp::Max {
                    self.add(ps, pd)
                } else {
                    self.sub(ps, pd)
                };
                Some(self.scale(0.5, both))
            }
            _ => None,
        }
    }

    /// `∫ a·b`: a factor free of `x` comes out; otherwise by parts with a polynomial factor
    /// `p` (`∫ p g = p G − ∫ p' G`, ending when `p'` is free of `x`).
    fn prim_product(&mut self, a: Expr, b: Expr, x: u32, depth: usize) -> Option<Expr> {
        if !self.depends_on(a, x) {
            let p = self.prim(b, x, depth)?;
            return Some(self.mul(a, p));
        }
        if !self.depends_on(b, x) {
            let p = self.prim(a, x, depth)?;
            return Some(self.mul(p, b));
        }
        let (p, g) = if self.is_polynomial(a, x) {
            (a, b)
        } else if self.is_polynomial(b, x) {
            (b, a)
        } else {
            return None;
        };
        let gi = self.prim(g, x, depth)?;
        let dp = self.diff(p, x);
        let first = self.mul(p, gi);
        let rest = self.mul(dp, gi);
        let rest = self.prim(rest, x, depth + 1)?;
        Some(self.sub(first, rest))
    }

    /// `min(c₁, max(c₀, L))` or `max(c₀, min(c₁, L))` with constants `c₀ ≤ c₁` and `L` linear:
    /// `c₀x + ((m − c₀)²/2 + (c₁ − c₀)·max(0, L − c₁)) / L'` (`m` = `f`, the clamp itself).
    fn prim_clamp(&mut self, f: Expr, op: BinOp, a: Expr, b: Expr, x: u32) -> Option<Expr> {
        let inner_op = if op == BinOp::Min {
            BinOp::Max
        } else {
            BinOp::Min
        };
        let (outer_c, inner) = match (self.as_const(a), self.as_const(b)) {
            (Some(c), None) => (c, b),
            (None, Some(c)) => (c, a),
            _ => return None,
        };
        let Node::Bin(iop, ia, ib) = self.node(inner) else {
            return None;
        };
        if iop != inner_op {
            return None;
        }
        let (inner_c, l) = match (self.as_const(ia), self.as_const(ib)) {
            (Some(c), None) => (c, ib),
            (None, Some(c)) => (c, ia),
            _ => return None,
        };
        let (c0, c1) = if op == BinOp::Min {
            (inner_c, outer_c)
        } else {
            (outer_c, inner_c)
        };
        if c0 > c1 {
            return None;
        }
        let s = self.slope(l, x)?;
        let xv = self.var(x);
        let (e0, e1) = (self.constant(c0), self.constant(c1));
        let lin = self.mul(e0, xv);
        let m = self.sub(f, e0);
        let sq = self.mul(m, m);
        let sq = self.scale(0.5, sq);
        let over = self.sub(l, e1);
        let zero = self.zero();
        let over = self.max(zero, over);
        let over = self.scale(c1 - c0, over);
        let num = self.add(sq, over);
        let q = self.div(num, s);
        Some(self.add(lin, q))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `∫_a^b f` by composite 10-point Gauss–Legendre on 400 panels (an independent quadrature).
    fn quadrature(g: &ExprGraph, f: Expr, a: f64, b: f64) -> f64 {
        const X: [f64; 5] = [
            0.148_874_338_981_631_2,
            0.433_395_394_129_247_2,
            0.679_409_568_299_024_4,
            0.865_063_366_688_984_5,
            0.973_906_528_517_171_7,
        ];
        const W: [f64; 5] = [
            0.295_524_224_714_752_9,
            0.269_266_719_309_996_4,
            0.219_086_362_515_982,
            0.149_451_349_150_580_6,
            0.066_671_344_308_688_1,
        ];
        let n = 400;
        let h = (b - a) / n as f64;
        let mut s = 0.0;
        for k in 0..n {
            let m = a + (k as f64 + 0.5) * h;
            for (xi, wi) in X.iter().zip(W) {
                for sg in [-1.0, 1.0] {
                    s += wi * g.eval(f, &[m + sg * xi * h / 2.0]) * h / 2.0;
                }
            }
        }
        s
    }

    /// Checks `text` on `[a, b]`; `kinks` are where it is not smooth (the quadrature's panels
    /// break there).
    fn check(text: &str, a: f64, b: f64, kinks: &[f64]) {
        let mut g = ExprGraph::new();
        let t = g.var(0);
        let f = g.parse(text, &mut |n| (n == "t").then_some(t)).unwrap();
        let big_f = g
            .antiderivative(f, 0)
            .unwrap_or_else(|e| panic!("{text}: {e}"));
        let exact = g.eval(big_f, &[b]) - g.eval(big_f, &[a]);
        let mut ends = vec![a];
        ends.extend_from_slice(kinks);
        ends.push(b);
        let q: f64 = ends.windows(2).map(|w| quadrature(&g, f, w[0], w[1])).sum();
        assert!(
            (exact - q).abs() <= 1e-10 * (1.0 + q.abs()),
            "{text} on [{a}, {b}]: closed form {exact}, quadrature {q}"
        );
        // and its derivative is the integrand, at points off the kinks
        let d = g.diff(big_f, 0);
        for k in 0..7 {
            let x = a + (b - a) * (k as f64 + 0.37) / 7.0;
            if kinks.iter().any(|&c| (x - c).abs() < 2e-3) {
                continue;
            }
            let (fd, fx) = (g.eval(d, &[x]), g.eval(f, &[x]));
            assert!(
                (fd - fx).abs() <= 1e-11 * (1.0 + fx.abs()),
                "{text} at {x}: F' = {fd}, f = {fx}"
            );
        }
    }

    #[test]
    fn closed_forms_agree_with_gauss_legendre_quadrature() {
        let smooth: &[f64] = &[];
        for (text, kinks) in [
            ("10", smooth),
            ("2*t + 3", smooth),
            ("t^3 - 4*t^2", smooth),
            ("10*(1 - exp(-2*t))", smooth),
            ("3*sin(2*t + 1) - cos(t/3)", smooth),
            ("t*sin(5*t)", smooth),
            ("t^2*exp(-t)", smooth),
            ("(1 + t)*cos(2*t)*4", smooth),
            ("abs(t - 1.3)", &[1.3]),
            ("max(0, 2*t - 1)", &[0.5]),
            ("min(10*t, 10)", &[1.0]),
            ("min(t, 3 - t)", &[1.5]),
            ("2 + 3*min(1, max(0, (t - 0.7)*1e3 + 1))", &[0.699, 0.7]),
            ("max(-1, min(2, 4*t - 3))", &[0.5, 1.25]),
            ("1/(t + 2)", smooth),
            ("(2*t + 1)^-2", smooth),
            ("2^t", smooth),
            ("sqrt(t + 1)", smooth),
            ("(t + 1)^0.5", smooth),
        ] {
            check(text, 0.0, 2.5, kinks);
        }
    }

    #[test]
    fn a_term_without_a_closed_form_is_named() {
        let mut g = ExprGraph::new();
        let t = g.var(0);
        let f = g
            .parse("1 + sin(t^2)", &mut |n| (n == "t").then_some(t))
            .unwrap();
        let e = g.antiderivative(f, 0).unwrap_err();
        assert!(e.term.contains("sin"), "{e}");
    }
}
