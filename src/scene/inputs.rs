//! Scene inputs (`"inputs"`): names the load expressions may use, set from outside.
//!
//! ```json
//! "inputs": [{"name": "torque", "start": 0.0, "unit": "N.m"}],
//! "loads": [{"type": "torque", "body": "crank", "value": "torque"}]
//! ```
//!
//! A run holds every input at its `start` value; an FMU (`bondmech fmu`) lets its importer set
//! them, held constant over each communication step. Both work by rewriting the load
//! expressions before the model is built: each input's name is replaced by a parenthesised
//! expression ([`Scene::with_input_expressions`]) — its start value for a run
//! ([`Scene::with_inputs_at_start`]), the piecewise-constant history of the values an importer
//! set for an FMU ([`piecewise_constant`]) — so the solver sees ordinary load expressions of
//! `t` and the columns.
//!
//! ```
//! use bondmech::scene::inputs::{piecewise_constant, replace_name};
//! assert_eq!(replace_name("2*torque + torque2 - crank.torque", "torque", "(1.5)"),
//!            "2*(1.5) + torque2 - crank.torque");
//! let u = piecewise_constant(&[(0.0, 0.0), (0.5, 2.0)]);
//! assert!(u.contains("max") && u.contains("min"));
//! ```

use super::error::{field, index, Problems};
use super::model::{LoadValue, Scene, SCALAR_OUTPUTS};

/// Names an input may not take: the time, π and the expression functions.
const RESERVED: &[&str] = &[
    "t", "pi", "sin", "cos", "tan", "sqrt", "abs", "exp", "ln", "log", "atan2", "min", "max",
    "pow", "sign", "select",
];

/// Whether `name` is a plain identifier: letters, digits and `_`, not starting with a digit.
fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The checks of `"inputs"`: identifier names, unique, not reserved, finite start values, and
/// a scene with loads to use them in (not a raw bond graph).
pub(crate) fn validate(p: &mut Problems, scene: &Scene) {
    let mut seen: Vec<&str> = Vec::new();
    for (i, u) in scene.inputs.iter().enumerate() {
        let path = index("inputs", i);
        let np = field(&path, "name");
        if !is_identifier(&u.name) {
            p.push(
                &np,
                format!(
                    "'{}' is not a name an expression can use (letters, digits and '_', not starting with a digit)",
                    u.name
                ),
            );
        } else if RESERVED.contains(&u.name.as_str()) || SCALAR_OUTPUTS.contains(&u.name.as_str()) {
            p.push(
                &np,
                format!(
                    "'{}' is reserved in expressions (the time, π, a function or an output)",
                    u.name
                ),
            );
        } else if seen.contains(&u.name.as_str()) {
            p.push(&np, format!("duplicate input name '{}'", u.name));
        }
        seen.push(&u.name);
        if !u.start.is_finite() {
            p.push(
                field(&path, "start"),
                format!("must be finite (got {})", u.start),
            );
        }
        if scene.bond_graph.is_some() {
            p.push(
                &path,
                "inputs are used in load expressions; a raw bond graph scene has no loads",
            );
        }
    }
}

/// `expr` with every occurrence of the name `name` (a whole name, not part of a longer one,
/// not a function call) replaced by `with`.
pub fn replace_name(expr: &str, name: &str, with: &str) -> String {
    let b = expr.as_bytes();
    let is_name_char = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'.';
    let mut out = String::with_capacity(expr.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            // a number literal: digits, fraction, exponent (so `1e5` is not the name `e5`)
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                if j < b.len() && b[j].is_ascii_digit() {
                    i = j;
                    while i < b.len() && b[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            out.push_str(&expr[start..i]);
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && is_name_char(b[i]) {
                i += 1;
            }
            let word = &expr[start..i];
            let call = expr[i..].trim_start().starts_with('(');
            if word == name && !call {
                out.push_str(with);
            } else {
                out.push_str(word);
            }
        } else {
            // any other character, copied whole (UTF-8 safe)
            let ch = expr[i..].chars().next().unwrap_or(' ');
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// A number as expression text that reads back exactly (negative numbers parenthesised).
fn number(x: f64) -> String {
    if x < 0.0 {
        format!("({x:e})")
    } else {
        format!("{x:e}")
    }
}

/// A piecewise-constant signal as an expression of `t`: `history[0].1` before
/// `history[1].0`, then `history[k].1` from `history[k].0` on (the first time is ignored: the
/// first value holds from the start). Each jump is a ramp `min(1, max(0, (t − t_k)/w + 1))`
/// of width `w = 1e-13 max(1, |t_k|)` ending at `t_k`, so the new value holds from `t_k` on:
/// a step for the integrator (a few ulps of `t`), continuous for the expression graph.
pub fn piecewise_constant(history: &[(f64, f64)]) -> String {
    let Some(&(_, first)) = history.first() else {
        return "0".into();
    };
    let mut s = number(first);
    for w in history.windows(2) {
        let ((_, before), (tk, after)) = (w[0], w[1]);
        let jump = after - before;
        if jump == 0.0 {
            continue;
        }
        let slope = 1.0 / (1e-13 * tk.abs().max(1.0));
        s.push_str(&format!(
            " + {}*min(1, max(0, (t - {})*{} + 1))",
            number(jump),
            number(tk),
            number(slope)
        ));
    }
    s
}

impl Scene {
    /// The scene with each input's name in the load expressions replaced by the expression
    /// given for it in `exprs` (`(name, expression)` pairs), or by its start value when not
    /// given. Load values that are not expressions are unchanged; `inputs` is kept.
    pub fn with_input_expressions(&self, exprs: &[(String, String)]) -> Scene {
        let mut scene = self.clone();
        if scene.inputs.is_empty() {
            return scene;
        }
        let replacements: Vec<(String, String)> = self
            .inputs
            .iter()
            .map(|u| {
                let e = exprs
                    .iter()
                    .find(|(n, _)| *n == u.name)
                    .map(|(_, e)| e.clone())
                    .unwrap_or_else(|| number(u.start));
                (u.name.clone(), format!("({e})"))
            })
            .collect();
        for load in &mut scene.loads {
            if let LoadValue::Expr(components) = &mut load.value {
                for c in components.iter_mut() {
                    for (name, with) in &replacements {
                        *c = replace_name(c, name, with);
                    }
                }
            }
        }
        for driver in &mut scene.drivers {
            for (name, with) in &replacements {
                driver.value = replace_name(&driver.value, name, with);
            }
        }
        scene
    }

    /// The scene with every input held at its start value (what `bondmech run` solves).
    pub fn with_inputs_at_start(&self) -> Scene {
        self.with_input_expressions(&[])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_replaced_whole_and_numbers_left_alone() {
        assert_eq!(
            replace_name("u*1e5+u_2+max(u,u)", "u", "(3)"),
            "(3)*1e5+u_2+max((3),(3))"
        );
        assert_eq!(replace_name("e5 + 2e5", "e5", "(1)"), "(1) + 2e5");
        assert_eq!(replace_name("u (2)", "u", "(1)"), "u (2)");
    }

    #[test]
    fn piecewise_constant_reads_back_its_values() {
        use crate::expr::ExprGraph;
        let text = piecewise_constant(&[(0.0, -1.0), (0.5, 2.0), (0.75, 2.0), (1.0, 0.25)]);
        let mut g = ExprGraph::new();
        let tv = g.var(0);
        let e = g
            .parse(&text, &mut |n: &str| (n == "t").then_some(tv))
            .unwrap();
        for (t, want) in [
            (0.0, -1.0),
            (0.4999, -1.0),
            (0.5, 2.0),
            (0.99, 2.0),
            (1.0, 0.25),
        ] {
            assert_eq!(g.eval(e, &[t]), want, "t = {t}");
        }
    }
}
