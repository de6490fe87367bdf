//! A small tokenizer for the expression strings of modulated elements and sources.
//!
//! It does not evaluate anything (that is the expression module's job); it only finds the
//! variable identifiers so that validation can check them against the graph:
//! `t`, `p_<I>` (momentum), `x_<I>` (displacement = ∫ flow of the inertia), `x_<1-junction>`
//! (∫ of the junction's common flow, e.g. a body angle `x_bar1.omega`), `q_<C>` and the
//! graph's declared signals. Function names ([`crate::expr::FUNCTIONS`]) and `pi` are not
//! variables.

use crate::expr::is_function;

/// A problem found while scanning an expression.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScanError {
    /// A character that cannot start any token.
    BadCharacter(char, usize),
    /// Parentheses do not balance.
    Unbalanced,
    /// A name followed by `(` that is not a known function.
    UnknownFunction(String),
    /// The expression is empty.
    Empty,
    /// The expression is longer than [`MAX_EXPRESSION_BYTES`] (its length in bytes).
    TooLong(usize),
}

/// Longest expression scanned (1 MiB): beyond it an expression is refused before anything
/// else is done with it (a 10 MB sum took seconds to scan and could not be parsed anyway:
/// [`crate::expr::MAX_OPERANDS`]).
pub const MAX_EXPRESSION_BYTES: usize = 1 << 20;

impl std::fmt::Display for ScanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ScanError::BadCharacter(c, i) => write!(f, "unexpected character '{c}' at {i}"),
            ScanError::Unbalanced => write!(f, "unbalanced parentheses"),
            ScanError::UnknownFunction(n) => write!(f, "unknown function '{n}'"),
            ScanError::Empty => write!(f, "empty expression"),
            ScanError::TooLong(n) => write!(
                f,
                "expression of {n} bytes, longer than the limit of {MAX_EXPRESSION_BYTES} bytes; no law of a mechanism is that long — tabulate it instead (a `table`)"
            ),
        }
    }
}

/// Returns the variable identifiers of `expr` in order of appearance (with repeats removed).
/// Identifiers may contain dots (`bar1.I_J`).
pub fn variables(expr: &str) -> Result<Vec<String>, ScanError> {
    if expr.len() > MAX_EXPRESSION_BYTES {
        return Err(ScanError::TooLong(expr.len()));
    }
    let chars: Vec<char> = expr.chars().collect();
    let mut vars: Vec<String> = Vec::new();
    // the names already in `vars`: a lookup per name, not a scan of `vars`
    let mut seen: std::collections::HashSet<String> = std::collections::HashSet::new();
    let mut depth: i64 = 0;
    let mut i = 0;
    let mut any = false;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        any = true;
        if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            i += 1;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
        } else if c == '`' {
            // a quoted name: any character up to the closing backquote
            let start = i + 1;
            let Some(len) = chars[start..].iter().position(|&d| d == '`') else {
                return Err(ScanError::BadCharacter('`', i));
            };
            let name: String = chars[start..start + len].iter().collect();
            i = start + len + 1;
            if seen.insert(name.clone()) {
                vars.push(name);
            }
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len()
                && (chars[i].is_alphanumeric() || chars[i] == '_' || chars[i] == '.')
            {
                i += 1;
            }
            let name: String = chars[start..i].iter().collect();
            let mut j = i;
            while j < chars.len() && chars[j].is_whitespace() {
                j += 1;
            }
            let is_call = j < chars.len() && chars[j] == '(';
            if is_call {
                if !is_function(&name) {
                    return Err(ScanError::UnknownFunction(name));
                }
            } else if name != "pi" && !is_function(&name) && seen.insert(name.clone()) {
                vars.push(name);
            }
        } else {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth < 0 {
                        return Err(ScanError::Unbalanced);
                    }
                }
                '+' | '-' | '*' | '/' | '^' | ',' => {}
                _ => return Err(ScanError::BadCharacter(c, i)),
            }
            i += 1;
        }
    }
    if !any {
        return Err(ScanError::Empty);
    }
    if depth != 0 {
        return Err(ScanError::Unbalanced);
    }
    Ok(vars)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_dotted_state_names_and_skips_functions_and_pi() {
        let v = variables("-0.5*sin(x_bar1.omega) + 2e-3*p_m1 / pi + t").unwrap();
        assert_eq!(v, vec!["x_bar1.omega", "p_m1", "t"]);
    }

    #[test]
    fn rejects_unknown_function_and_unbalanced() {
        assert_eq!(
            variables("foo(t)"),
            Err(ScanError::UnknownFunction("foo".into()))
        );
        assert_eq!(variables("sin(t"), Err(ScanError::Unbalanced));
        assert!(matches!(
            variables("t # 2"),
            Err(ScanError::BadCharacter('#', _))
        ));
    }
}
