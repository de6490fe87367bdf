//! Recursive-descent parser of infix expressions.
//!
//! Grammar (byte positions in errors are 0-based offsets into the source):
//! ```text
//! expr    := term (('+' | '-') term)*
//! term    := unary (('*' | '/') unary)*
//! unary   := ('-' | '+') unary | power
//! power   := primary ('^' unary)?            -- right-associative; -x^2 = -(x^2)
//! primary := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! number  := digits ['.' digits] [('e'|'E') ['+'|'-'] digits]  |  '.' digits [...]
//! name    := (letter | '_') (letter | digit | '_' | '.')*  |  '`' (any character but '`')+ '`'
//! ```
//! A name in backquotes may hold any character but a backquote: `` `x_left-arm.omega` `` is the
//! angle of a body called `left-arm` ([`quote_name`] writes a name so).
//! Functions: `sin cos tan sqrt abs exp ln log(=ln) sign` (one argument), `atan2 min max pow`
//! (two), `select(c, a, b)` (`a` where `c > 0`, else `b`: what the derivative of `min`, `max`
//! and `abs` is written with, so that every expression the graph displays reads back). The name `pi` is the constant π; every other name goes to the resolver.

use super::graph::{Expr, ExprGraph};

/// Why a source string is not a valid expression, with the byte position.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParseError {
    /// The resolver does not know this name.
    #[error("at {pos}: unknown name '{name}'")]
    UnknownName {
        /// Byte offset of the name.
        pos: usize,
        /// The name as written.
        name: String,
    },
    /// A name followed by `(` that is not a known function.
    #[error("at {pos}: unknown function '{name}'")]
    UnknownFunction {
        /// Byte offset of the name.
        pos: usize,
        /// The name as written.
        name: String,
    },
    /// A known function called with the wrong number of arguments.
    #[error("at {pos}: function '{name}' takes {expected} argument(s), got {found}")]
    WrongArity {
        /// Byte offset of the function name.
        pos: usize,
        /// The function.
        name: String,
        /// Arguments it takes.
        expected: usize,
        /// Arguments given.
        found: usize,
    },
    /// A malformed number literal.
    #[error("at {pos}: invalid number '{text}'")]
    BadNumber {
        /// Byte offset of the literal.
        pos: usize,
        /// The literal as written.
        text: String,
    },
    /// Something else was required here.
    #[error("at {pos}: expected {expected}, found {found}")]
    Expected {
        /// Byte offset where it was expected.
        pos: usize,
        /// What was expected, e.g. `')'` or `an operand`.
        expected: String,
        /// What was found instead (`end of input` at the end).
        found: String,
    },
    /// Nested deeper than [`MAX_DEPTH`] (parentheses, signs, function calls, powers): refused
    /// so that hostile input cannot overflow the stack.
    #[error("at {pos}: expression nested too deeply (more than {} parentheses, function calls or powers inside one another, or {limit} signs)", limit / 2)]
    TooDeep {
        /// Byte offset where the limit was passed.
        pos: usize,
        /// The limit ([`MAX_DEPTH`]).
        limit: usize,
    },
    /// More than [`MAX_OPERANDS`] operands: refused at once, so that a runaway expression (a
    /// 10 MB sum) answers in milliseconds instead of being compiled and evaluated at every step.
    #[error("at {pos}: expression of more than {limit} operands (numbers, names, calls); no law of a mechanism is that long — tabulate it instead (a load's `table`)")]
    TooLarge {
        /// Byte offset where the limit was passed.
        pos: usize,
        /// The limit ([`MAX_OPERANDS`]).
        limit: usize,
    },
}

impl ParseError {
    /// Byte offset of the error in the source.
    pub fn pos(&self) -> usize {
        match self {
            ParseError::UnknownName { pos, .. }
            | ParseError::UnknownFunction { pos, .. }
            | ParseError::WrongArity { pos, .. }
            | ParseError::BadNumber { pos, .. }
            | ParseError::Expected { pos, .. }
            | ParseError::TooDeep { pos, .. }
            | ParseError::TooLarge { pos, .. } => *pos,
        }
    }
}

struct Parser<'a, 'r> {
    src: &'a str,
    pos: usize,
    g: &'a mut ExprGraph,
    resolve: &'r mut dyn FnMut(&str) -> Option<Expr>,
    depth: usize,
    /// Operands read so far (each `unary`).
    operands: usize,
}

/// Nesting limit, so hostile input cannot overflow the stack.
pub const MAX_DEPTH: usize = 256;

/// Operand limit of one expression (numbers, names, calls and signs, each counted where it is
/// read): 100 000, some 100 times the longest law written by hand or by `graph --as-scene`,
/// and a bound on the work of one evaluation (a tape of at most a few hundred thousand
/// instructions).
pub const MAX_OPERANDS: usize = 100_000;

/// The functions an expression may call, with their number of arguments: `sin`, `cos`,
/// `tan`, `sqrt`, `abs`, `exp`, `ln`, `log` take one; `atan2(y, x)`, `min`, `max`, `pow` two.
/// The parser reads exactly these; the bond graph's identifier scan skips them.
pub const FUNCTIONS: &[(&str, usize)] = &[
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("sqrt", 1),
    ("abs", 1),
    ("exp", 1),
    ("ln", 1),
    ("log", 1),
    ("sign", 1),
    ("atan2", 2),
    ("min", 2),
    ("max", 2),
    ("pow", 2),
    ("select", 3),
];

/// Whether `name` is one of the [`FUNCTIONS`].
pub fn is_function(name: &str) -> bool {
    FUNCTIONS.iter().any(|(f, _)| *f == name)
}

/// `name` as an expression reads it: as is when it is a plain name (a letter or `_`, then
/// letters, digits, `_` and `.`; not a function or `pi`), else in backquotes
/// (`` `x_left-arm.omega` ``). A name holding a backquote cannot be written (scene validation
/// refuses such names).
pub fn quote_name(name: &str) -> std::borrow::Cow<'_, str> {
    let b = name.as_bytes();
    let plain = b.first().is_some_and(|&c| is_name_start(c))
        && b.iter().all(|&c| is_name_char(c))
        && name != "pi"
        && !is_function(name);
    if plain {
        std::borrow::Cow::Borrowed(name)
    } else {
        std::borrow::Cow::Owned(format!("`{name}`"))
    }
}

fn is_name_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_'
}

fn is_name_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'.'
}

impl Parser<'_, '_> {
    fn bytes(&self) -> &[u8] {
        self.src.as_bytes()
    }

    fn skip_ws(&mut self) {
        while self.pos < self.src.len() && self.bytes()[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.bytes().get(self.pos).copied()
    }

    fn found(&self) -> String {
        match self.src[self.pos..].chars().next() {
            None => "end of input".to_string(),
            Some(c) => format!("'{c}'"),
        }
    }

    fn expected(&mut self, what: &str) -> ParseError {
        self.skip_ws();
        ParseError::Expected {
            pos: self.pos,
            expected: what.to_string(),
            found: self.found(),
        }
    }

    fn too_deep(&mut self) -> ParseError {
        self.skip_ws();
        ParseError::TooDeep {
            pos: self.pos,
            limit: MAX_DEPTH,
        }
    }

    fn expect(&mut self, c: u8) -> Result<(), ParseError> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.expected(&format!("'{}'", c as char)))
        }
    }

    fn expr(&mut self) -> Result<Expr, ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.too_deep());
        }
        let mut acc = self.term()?;
        loop {
            match self.peek() {
                Some(b'+') => {
                    self.pos += 1;
                    let r = self.term()?;
                    acc = self.g.add(acc, r);
                }
                Some(b'-') => {
                    self.pos += 1;
                    let r = self.term()?;
                    acc = self.g.sub(acc, r);
                }
                _ => break,
            }
        }
        self.depth -= 1;
        Ok(acc)
    }

    fn term(&mut self) -> Result<Expr, ParseError> {
        let mut acc = self.unary()?;
        loop {
            match self.peek() {
                Some(b'*') => {
                    self.pos += 1;
                    let r = self.unary()?;
                    acc = self.g.mul(acc, r);
                }
                Some(b'/') => {
                    self.pos += 1;
                    let r = self.unary()?;
                    acc = self.g.div(acc, r);
                }
                _ => break,
            }
        }
        Ok(acc)
    }

    fn unary(&mut self) -> Result<Expr, ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.too_deep());
        }
        self.operands += 1;
        if self.operands > MAX_OPERANDS {
            self.skip_ws();
            return Err(ParseError::TooLarge {
                pos: self.pos,
                limit: MAX_OPERANDS,
            });
        }
        let r = match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                let a = self.unary()?;
                Ok(self.g.neg(a))
            }
            Some(b'+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        };
        self.depth -= 1;
        r
    }

    fn power(&mut self) -> Result<Expr, ParseError> {
        let base = self.primary()?;
        if self.peek() == Some(b'^') {
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(self.g.pow(base, exp));
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<Expr, ParseError> {
        match self.peek() {
            Some(b'(') => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect(b')')?;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number(),
            Some(c) if is_name_start(c) => self.name(),
            Some(b'`') => self.quoted_name(),
            _ => Err(self.expected("a number, a name or '('")),
        }
    }

    fn digits(&mut self) -> usize {
        let start = self.pos;
        while self.pos < self.src.len() && self.bytes()[self.pos].is_ascii_digit() {
            self.pos += 1;
        }
        self.pos - start
    }

    fn number(&mut self) -> Result<Expr, ParseError> {
        let start = self.pos;
        let mut n = self.digits();
        if self.bytes().get(self.pos) == Some(&b'.') {
            self.pos += 1;
            n += self.digits();
        }
        let bad = |p: &Self| ParseError::BadNumber {
            pos: start,
            text: p.src[start..p.pos].to_string(),
        };
        if n == 0 {
            return Err(bad(self));
        }
        if matches!(self.bytes().get(self.pos), Some(b'e' | b'E')) {
            self.pos += 1;
            if matches!(self.bytes().get(self.pos), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            if self.digits() == 0 {
                return Err(bad(self));
            }
        }
        if self.bytes().get(self.pos).is_some_and(|&c| is_name_char(c)) {
            // e.g. "2x" or "1.5.3": consume the rest for the message.
            while self.bytes().get(self.pos).is_some_and(|&c| is_name_char(c)) {
                self.pos += 1;
            }
            return Err(bad(self));
        }
        match self.src[start..self.pos].parse::<f64>() {
            Ok(v) => Ok(self.g.constant(v)),
            Err(_) => Err(bad(self)),
        }
    }

    fn name(&mut self) -> Result<Expr, ParseError> {
        let start = self.pos;
        while self.bytes().get(self.pos).is_some_and(|&c| is_name_char(c)) {
            self.pos += 1;
        }
        let name = &self.src[start..self.pos];
        if self.peek() == Some(b'(') {
            self.pos += 1;
            return self.call(name, start);
        }
        if name == "pi" {
            return Ok(self.g.constant(std::f64::consts::PI));
        }
        (self.resolve)(name).ok_or_else(|| ParseError::UnknownName {
            pos: start,
            name: name.to_string(),
        })
    }

    /// A name in backquotes (any character but a backquote): never a function or `pi`.
    fn quoted_name(&mut self) -> Result<Expr, ParseError> {
        let start = self.pos;
        let body = start + 1;
        let Some(len) = self.src[body..].find('`') else {
            self.pos = self.src.len();
            return Err(self.expected("a closing '`' after the quoted name"));
        };
        let name = &self.src[body..body + len];
        self.pos = body + len + 1;
        (self.resolve)(name).ok_or_else(|| ParseError::UnknownName {
            pos: start,
            name: name.to_string(),
        })
    }

    fn call(&mut self, name: &'_ str, pos: usize) -> Result<Expr, ParseError> {
        let Some(&(_, arity)) = FUNCTIONS.iter().find(|(f, _)| *f == name) else {
            return Err(ParseError::UnknownFunction {
                pos,
                name: name.to_string(),
            });
        };
        let mut args = Vec::with_capacity(2);
        if self.peek() != Some(b')') {
            loop {
                args.push(self.expr()?);
                if self.peek() == Some(b',') {
                    self.pos += 1;
                } else {
                    break;
                }
            }
        }
        self.expect(b')')?;
        if args.len() != arity {
            return Err(ParseError::WrongArity {
                pos,
                name: name.to_string(),
                expected: arity,
                found: args.len(),
            });
        }
        let g = &mut *self.g;
        Ok(match name {
            "sin" => g.sin(args[0]),
            "cos" => g.cos(args[0]),
            "tan" => g.tan(args[0]),
            "sqrt" => g.sqrt(args[0]),
            "abs" => g.abs(args[0]),
            "exp" => g.exp(args[0]),
            "ln" | "log" => g.ln(args[0]),
            "sign" => g.sign(args[0]),
            "select" => g.select(args[0], args[1], args[2]),
            "atan2" => g.atan2(args[0], args[1]),
            "min" => g.min(args[0], args[1]),
            "max" => g.max(args[0], args[1]),
            _ => g.pow(args[0], args[1]),
        })
    }
}

impl ExprGraph {
    /// Parses infix `src` (see the module grammar), resolving names through `resolve`.
    /// Never panics; errors carry the byte position and what was expected.
    pub fn parse(
        &mut self,
        src: &str,
        resolve: &mut dyn FnMut(&str) -> Option<Expr>,
    ) -> Result<Expr, ParseError> {
        let mut p = Parser {
            src,
            pos: 0,
            g: self,
            resolve,
            depth: 0,
            operands: 0,
        };
        let e = p.expr()?;
        if p.peek().is_some() {
            return Err(p.expected("an operator or end of input"));
        }
        Ok(e)
    }
}
