//! Parser: precedence against hand-computed values, names with dots, errors with positions.

use bondmech::expr::{Expr, ExprGraph, ParseError};
use proptest::prelude::*;

/// Parses `src` with x = var 0, y = var 1, `crank.angle` = var 2, `bar2.A.x` = var 3,
/// evaluated at x = 2, y = 3, crank.angle = 0.5, bar2.A.x = -1.5.
fn value(src: &str) -> f64 {
    let mut g = ExprGraph::new();
    let vars: Vec<Expr> = (0..4).map(|i| g.var(i)).collect();
    let e = g
        .parse(src, &mut |n| match n {
            "x" => Some(vars[0]),
            "y" => Some(vars[1]),
            "crank.angle" => Some(vars[2]),
            "bar2.A.x" => Some(vars[3]),
            _ => None,
        })
        .unwrap_or_else(|e| panic!("{src}: {e}"));
    g.eval(e, &[2.0, 3.0, 0.5, -1.5])
}

fn error(src: &str) -> ParseError {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    g.parse(src, &mut |n| (n == "x").then_some(x))
        .expect_err(src)
}

#[test]
fn precedence_matches_hand_computed_values() {
    // x = 2, y = 3
    assert_eq!(value("1 + 2 * 3"), 7.0);
    assert_eq!(value("(1 + 2) * 3"), 9.0);
    assert_eq!(value("-x^2"), -4.0);
    assert_eq!(value("(-x)^2"), 4.0);
    assert_eq!(value("2^3^2"), 512.0); // right-associative: 2^9
    assert_eq!(value("2^-1"), 0.5);
    assert_eq!(value("x - y - 1"), -2.0); // left-associative
    assert_eq!(value("12 / x / y"), 2.0);
    assert_eq!(value("-x * y"), -6.0);
    assert_eq!(value("x * -y"), -6.0);
    assert_eq!(value("--x"), 2.0);
    assert_eq!(value("+x"), 2.0);
    assert_eq!(value("x^2 * y"), 12.0);
    assert_eq!(value("2 * x^y"), 16.0);
    assert_eq!(value("  x\t+\ny "), 5.0);
}

#[test]
fn numbers_in_every_accepted_form() {
    assert_eq!(value("1"), 1.0);
    assert_eq!(value("1.5"), 1.5);
    assert_eq!(value("1e-3"), 1e-3);
    assert_eq!(value("2.5E+2"), 250.0);
    assert_eq!(value(".5"), 0.5);
    assert_eq!(value("3."), 3.0);
}

#[test]
fn functions_constants_and_dotted_names() {
    assert_eq!(value("sin(crank.angle)"), 0.5f64.sin());
    assert_eq!(value("cos(0)"), 1.0);
    assert_eq!(value("tan(crank.angle)"), 0.5f64.tan());
    assert_eq!(value("sqrt(16)"), 4.0);
    assert_eq!(value("abs(bar2.A.x)"), 1.5);
    assert_eq!(value("exp(1)"), std::f64::consts::E);
    assert_eq!(value("ln(exp(2))"), 2.0);
    assert_eq!(value("log(x)"), 2f64.ln());
    assert_eq!(value("atan2(1, 0)"), std::f64::consts::FRAC_PI_2);
    assert_eq!(value("min(x, y)"), 2.0);
    assert_eq!(value("max(x, y)"), 3.0);
    assert_eq!(value("pow(x, y)"), 8.0);
    assert_eq!(value("pi"), std::f64::consts::PI);
    assert_eq!(value("2*pi*x"), 4.0 * std::f64::consts::PI);
}

#[test]
fn unknown_names_are_reported_with_their_position() {
    let e = error("2 * alpah + 1");
    assert_eq!(
        e,
        ParseError::UnknownName {
            pos: 4,
            name: "alpah".into()
        }
    );
    assert_eq!(e.to_string(), "at 4: unknown name 'alpah'");
    assert_eq!(error("foo(x)").to_string(), "at 0: unknown function 'foo'");
}

#[test]
fn syntax_errors_name_the_position_and_what_was_expected() {
    let e = error("(x + 1");
    assert_eq!(e.pos(), 6);
    assert_eq!(e.to_string(), "at 6: expected ')', found end of input");
    assert_eq!(error("x +").pos(), 3);
    assert_eq!(error("x + * 2").pos(), 4);
    assert_eq!(error("x 2").pos(), 2);
    assert_eq!(error("").pos(), 0);
    assert_eq!(error("sin(x").pos(), 5);
    assert_eq!(
        error("x)").to_string(),
        "at 1: expected an operator or end of input, found ')'"
    );
    assert!(matches!(
        error("atan2(x)"),
        ParseError::WrongArity {
            pos: 0,
            expected: 2,
            found: 1,
            ..
        }
    ));
    assert!(matches!(
        error("sin(x, x)"),
        ParseError::WrongArity {
            expected: 1,
            found: 2,
            ..
        }
    ));
    assert!(matches!(error("1e"), ParseError::BadNumber { pos: 0, .. }));
    assert!(matches!(
        error("x + 2x"),
        ParseError::BadNumber { pos: 4, .. }
    ));
    assert!(matches!(
        error("1.2.3"),
        ParseError::BadNumber { pos: 0, .. }
    ));
    assert_eq!(error("x # 1").pos(), 2);
}

#[test]
fn absurd_nesting_is_an_error_not_a_stack_overflow() {
    // a variant of its own since issue 38 (was `Expected { expected: "less deeply nested
    // expression" }`), its message saying what the limit is
    let src = "(".repeat(100_000) + "x" + &")".repeat(100_000);
    assert!(matches!(error(&src), ParseError::TooDeep { .. }));
    let src = "-".repeat(100_000) + "x";
    assert!(matches!(error(&src), ParseError::TooDeep { .. }));
    // a long expression is refused at its operand limit, not compiled
    let src = vec!["x"; 200_000].join("+");
    assert!(matches!(
        error(&src),
        ParseError::TooLarge { limit: 100_000, .. }
    ));
}

proptest! {
    #[test]
    fn random_strings_never_panic(s in "\\PC{0,40}") {
        let mut g = ExprGraph::new();
        let x = g.var(0);
        let _ = g.parse(&s, &mut |n| (n == "x").then_some(x));
    }

    #[test]
    fn random_token_soup_never_panics(toks in prop::collection::vec(
        prop::sample::select(vec!["x", "1", ".5", "1e3", "(", ")", "+", "-", "*", "/", "^", ",",
            "sin", "atan2", "pi", " ", "é", "2x", "e-", "a.b"]), 0..30)) {
        let s: String = toks.concat();
        let mut g = ExprGraph::new();
        let x = g.var(0);
        if let Err(e) = g.parse(&s, &mut |n| (n == "x").then_some(x)) {
            prop_assert!(e.pos() <= s.len());
            prop_assert!(s.is_char_boundary(e.pos()));
        }
    }
}
