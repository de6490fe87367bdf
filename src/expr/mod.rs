//! Expression DAG with symbolic derivatives and a flat evaluation tape.
//!
//! The equations of a mechanism (residuals `F(t, y, y')`, right-hand sides, constraint
//! functions `g(q)`) are built as expressions in a hash-consed [`ExprGraph`]; exact
//! Jacobians come from [`ExprGraph::diff`] (`∂e/∂xᵥ`, memoised); both are compiled by
//! [`ExprGraph::compile`] into a [`Tape`] evaluated without allocation inside solver
//! callbacks. [`ExprGraph::parse`] reads user formulas such as `r*cos(crank.angle)`.
//!
//! ```
//! use bondmech::expr::ExprGraph;
//! let mut g = ExprGraph::new();
//! let x = g.var(0);
//! let e = g.parse("x^2 * sin(x)", &mut |n| (n == "x").then_some(x)).unwrap();
//! let de = g.diff(e, 0); // 2x·sin x + x²·cos x
//! let tape = g.compile(&[e, de]);
//! let (mut work, mut out) = (tape.workspace(), [0.0; 2]);
//! tape.eval(&[1.0], &mut work, &mut out);
//! assert!((out[1] - (2.0 * 1f64.sin() + 1f64.cos())).abs() < 1e-15);
//! ```

mod diff;
mod display;
mod excerpt;
mod graph;
mod hash;
mod integrate;
mod ops;
mod parse;
mod subst;
mod switches;
mod tape;

pub use display::{DISPLAY_MAX_CHARS, DISPLAY_MAX_DEPTH};
pub use excerpt::{excerpt, EXCERPT_CONTEXT, EXCERPT_MAX_CHARS};
pub use graph::{Expr, ExprGraph};
pub use integrate::NotIntegrable;
pub use parse::{is_function, quote_name, ParseError, FUNCTIONS, MAX_DEPTH, MAX_OPERANDS};
pub use switches::FrozenSwitches;
pub use tape::{StagedTape, Tape};
