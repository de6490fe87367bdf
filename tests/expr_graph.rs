//! Hash-consing, construction-time simplification, variable queries and display.

use bondmech::expr::ExprGraph;

fn name(i: u32) -> String {
    ["x", "y", "z"]
        .get(i as usize)
        .map_or(format!("v{i}"), |s| s.to_string())
}

#[test]
fn building_the_same_node_twice_returns_the_same_handle() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let s1 = g.sin(x);
    let n = g.len();
    let s2 = g.sin(x);
    assert_eq!(s1, s2);
    assert_eq!(g.len(), n, "no new node for a repeated build");
    assert_eq!(g.var(0), x);
    assert_eq!(g.constant(2.5), g.constant(2.5));
    let p1 = g.pow(x, y);
    let p2 = g.pow(x, y);
    assert_eq!(p1, p2);
    let t1 = g.table(&[0.0, 1.0], &[2.0, 3.0], x);
    let t2 = g.table(&[0.0, 1.0], &[2.0, 3.0], x);
    let t3 = g.table(&[0.0, 1.0], &[2.0, 4.0], x);
    assert_eq!(t1, t2, "equal tables share one node");
    assert_ne!(t1, t3);
}

#[test]
fn commutative_operations_hash_cons_regardless_of_operand_order() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let (ab, ba) = (g.add(x, y), g.add(y, x));
    assert_eq!(ab, ba);
    let (ab, ba) = (g.mul(x, y), g.mul(y, x));
    assert_eq!(ab, ba);
    let (ab, ba) = (g.min(x, y), g.min(y, x));
    assert_eq!(ab, ba);
    let (ab, ba) = (g.max(x, y), g.max(y, x));
    assert_eq!(ab, ba);
    // Non-commutative ones stay distinct.
    let (ab, ba) = (g.sub(x, y), g.sub(y, x));
    assert_ne!(ab, ba);
    let (ab, ba) = (g.div(x, y), g.div(y, x));
    assert_ne!(ab, ba);
    let (ab, ba) = (g.atan2(x, y), g.atan2(y, x));
    assert_ne!(ab, ba);
}

#[test]
fn constants_fold_for_every_operation() {
    let mut g = ExprGraph::new();
    let (a, b) = (g.constant(3.0), g.constant(4.0));
    let c = |g: &ExprGraph, e| g.as_const(e).unwrap();
    let e = g.add(a, b);
    assert_eq!(c(&g, e), 7.0);
    let e = g.sub(a, b);
    assert_eq!(c(&g, e), -1.0);
    let e = g.mul(a, b);
    assert_eq!(c(&g, e), 12.0);
    let e = g.div(a, b);
    assert_eq!(c(&g, e), 0.75);
    let e = g.pow(a, b);
    assert_eq!(c(&g, e), 81.0);
    let e = g.atan2(a, b);
    assert_eq!(c(&g, e), 3f64.atan2(4.0));
    let e = g.min(a, b);
    assert_eq!(c(&g, e), 3.0);
    let e = g.max(a, b);
    assert_eq!(c(&g, e), 4.0);
    let e = g.neg(a);
    assert_eq!(c(&g, e), -3.0);
    let e = g.sqrt(b);
    assert_eq!(c(&g, e), 2.0);
    let e = g.sin(a);
    assert_eq!(c(&g, e), 3f64.sin());
    let e = g.cos(a);
    assert_eq!(c(&g, e), 3f64.cos());
    let e = g.tan(a);
    assert_eq!(c(&g, e), 3f64.tan());
    let e = g.exp(a);
    assert_eq!(c(&g, e), 3f64.exp());
    let e = g.ln(b);
    assert_eq!(c(&g, e), 4f64.ln());
    let m = g.constant(-3.0);
    let e = g.abs(m);
    assert_eq!(c(&g, e), 3.0);
    let e = g.table(&[0.0, 10.0], &[0.0, 5.0], a);
    assert_eq!(c(&g, e), 1.5);
}

#[test]
fn identity_elements_and_annihilators_simplify() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let (zero, one) = (g.zero(), g.one());
    assert_eq!(g.add(x, zero), x);
    assert_eq!(g.add(zero, x), x);
    assert_eq!(g.sub(x, zero), x);
    let nx = g.neg(x);
    assert_eq!(g.sub(zero, x), nx);
    assert_eq!(g.mul(x, one), x);
    assert_eq!(g.mul(one, x), x);
    assert!({
        let t = g.mul(x, zero);
        g.is_zero(t)
    });
    assert!({
        let t = g.mul(zero, x);
        g.is_zero(t)
    });
    assert_eq!(g.div(x, one), x);
    assert!({
        let t = g.div(zero, x);
        g.is_zero(t)
    });
    assert_eq!(g.pow(x, one), x);
    assert_eq!(
        {
            let t = g.pow(x, zero);
            g.as_const(t)
        },
        Some(1.0)
    );
    assert_eq!(g.neg(nx), x);
    assert!({
        let t = g.sub(x, x);
        g.is_zero(t)
    });
    let m1 = g.constant(-1.0);
    assert_eq!(g.mul(m1, x), nx);
    assert_eq!(g.min(x, x), x);
    let ax = g.abs(x);
    assert_eq!(g.abs(nx), ax);
    assert_eq!(g.abs(ax), ax);
}

#[test]
fn zero_times_a_constant_inf_or_nan_follows_ieee_not_algebra() {
    let mut g = ExprGraph::new();
    let zero = g.zero();
    let inf = g.constant(f64::INFINITY);
    let nan = g.constant(f64::NAN);
    assert!({
        let t = g.mul(zero, inf);
        g.as_const(t)
    }
    .unwrap()
    .is_nan());
    assert!({
        let t = g.mul(nan, zero);
        g.as_const(t)
    }
    .unwrap()
    .is_nan());
    assert!({
        let t = g.div(zero, zero);
        g.as_const(t)
    }
    .unwrap()
    .is_nan());
}

#[test]
fn nested_constant_factors_fold_into_one() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let e = g.scale(3.0, x);
    let e = g.scale(2.0, e);
    let expected = g.scale(6.0, x);
    assert_eq!(e, expected);
    let ne = g.neg(e);
    let expected = g.scale(-6.0, x);
    assert_eq!(ne, expected);
    assert_eq!(g.display(ne, &name), "-6 * x");
}

#[test]
fn negations_become_subtractions() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let ny = g.neg(y);
    let xmy = g.sub(x, y);
    assert_eq!(g.add(x, ny), xmy);
    let xpy = g.add(x, y);
    assert_eq!(g.sub(x, ny), xpy);
    let ymx = g.sub(y, x);
    assert_eq!(g.neg(xmy), ymx);
    let nx = g.neg(x);
    let xy = g.mul(x, y);
    assert_eq!(g.mul(nx, ny), xy);
}

#[test]
fn sum_scale_and_dot_match_hand_values() {
    let mut g = ExprGraph::new();
    let v: Vec<_> = (0..3).map(|i| g.var(i)).collect();
    let s = g.sum(&v);
    assert_eq!(g.eval(s, &[1.0, 2.0, 4.0]), 7.0);
    let c: Vec<_> = [2.0, -1.0, 0.5].iter().map(|&c| g.constant(c)).collect();
    let d = g.dot(&c, &v);
    assert_eq!(g.eval(d, &[1.0, 2.0, 4.0]), 2.0);
    assert!({
        let t = g.sum(&[]);
        g.is_zero(t)
    });
}

#[test]
fn vars_are_sorted_unique_and_depends_on_agrees() {
    let mut g = ExprGraph::new();
    let (x0, x2, x5) = (g.var(0), g.var(2), g.var(5));
    let a = g.mul(x5, x0);
    let b = g.sin(x0);
    let e = g.add(a, b);
    assert_eq!(g.vars(e), vec![0, 5]);
    assert!(g.depends_on(e, 0));
    assert!(g.depends_on(e, 5));
    assert!(!g.depends_on(e, 2));
    assert!(!g.depends_on(e, 9));
    assert_eq!(g.vars(x2), vec![2]);
    let c = g.constant(1.0);
    assert!(g.vars(c).is_empty());
}

#[test]
fn display_uses_minimal_parentheses_and_round_trips_through_parse() {
    let mut g = ExprGraph::new();
    let (x, y, z) = (g.var(0), g.var(1), g.var(2));
    let cases: Vec<(String, &str)> = vec![
        ("x + y * z".into(), "x + y * z"),
        ("(x + y) * z".into(), "(x + y) * z"),
        ("x - (y - z)".into(), "x - (y - z)"),
        ("x / (y * z)".into(), "x / (y * z)"),
        ("-x^2".into(), "-x^2"),
        ("(-x)^2".into(), "(-x)^2"),
        ("x^y^z".into(), "x^y^z"),
        ("(x^y)^z".into(), "(x^y)^z"),
        ("sin(x) + atan2(y, x)".into(), "sin(x) + atan2(y, x)"),
    ];
    let mut resolve = |n: &str| match n {
        "x" => Some(x),
        "y" => Some(y),
        "z" => Some(z),
        _ => None,
    };
    for (src, want) in cases {
        let e = g.parse(&src, &mut resolve).unwrap();
        let shown = g.display(e, &name);
        // Canonical operand order may swap commutative operands; compare values and re-parse.
        let back = g.parse(&shown, &mut resolve).unwrap();
        assert_eq!(
            back, e,
            "{src} displayed as {shown} did not parse back to the same node"
        );
        let pt = [0.7, 1.3, 0.4];
        let want_e = g.parse(want, &mut resolve).unwrap();
        assert_eq!(g.eval(e, &pt), g.eval(want_e, &pt));
        assert_eq!(
            shown.matches('(').count(),
            want.matches('(').count(),
            "parentheses in {shown} vs {want}"
        );
    }
}

#[test]
fn display_of_exponentially_shared_or_very_deep_dags_is_bounded() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let mut e = g.sin(x);
    for _ in 0..60 {
        e = g.mul(e, e); // tree form would have 2^60 leaves
    }
    let s = g.display(e, &name);
    assert!(
        s.len() < 2 * bondmech::expr::DISPLAY_MAX_CHARS,
        "len {}",
        s.len()
    );
    assert!(s.contains('…'));
    let mut d = x;
    for _ in 0..100_000 {
        d = g.sin(d);
    }
    let s = g.display(d, &name);
    assert!(s.starts_with("sin(sin(") && s.contains('…'));
}

/// `expr::switches`: with the mode of the switching function's sign every operation equals
/// the literal one; with the other mode it continues the branch it held; mode 0 is the
/// literal operation. Checked at points on both sides of each switch.
#[test]
fn frozen_switches_hold_each_branch_and_mode_zero_is_the_literal_operation() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let mut r = |n: &str| match n {
        "x" => Some(x),
        "y" => Some(y),
        _ => None,
    };
    // (expression, the two branches as functions of (x, y))
    type Branch = fn(f64, f64) -> f64;
    let cases: [(&str, Branch, Branch); 5] = [
        ("max(x, y^2)", |x, _| x, |_, y| y * y),
        ("min(x, 2*y)", |x, _| x, |_, y| 2.0 * y),
        ("abs(x - y)", |x, y| x - y, |x, y| y - x),
        ("abs(x*y)/(x*y)", |_, _| 1.0, |_, _| -1.0),
        (
            "3 + 2*abs(sin(x))",
            |x, _| 3.0 + 2.0 * x.sin(),
            |x, _| 3.0 - 2.0 * x.sin(),
        ),
    ];
    for (text, p, q) in cases {
        let e = g.parse(text, &mut r).unwrap();
        let f = g.freeze_switches(&[e], 2);
        assert_eq!(f.switching.len(), 1, "{text}");
        for (xv, yv) in [(0.7, 0.3), (0.2, 0.9), (-1.1, 0.4), (2.5, -1.5)] {
            let s = g.eval(f.switching[0], &[xv, yv, 0.0]);
            let literal = g.eval(e, &[xv, yv]);
            let m = if s > 0.0 { 1.0 } else { -1.0 };
            let held = g.eval(f.exprs[0], &[xv, yv, m]);
            assert!((held - literal).abs() < 1e-15, "{text} at ({xv}, {yv})");
            assert_eq!(
                g.eval(f.exprs[0], &[xv, yv, 0.0]),
                literal,
                "{text}: mode 0"
            );
            // the two modes give the two branches, one of them the literal value
            let (a, b) = (
                g.eval(f.exprs[0], &[xv, yv, 1.0]),
                g.eval(f.exprs[0], &[xv, yv, -1.0]),
            );
            let (pa, qb) = (p(xv, yv), q(xv, yv));
            assert!(
                ((a - pa).abs() < 1e-14 && (b - qb).abs() < 1e-14)
                    || ((a - qb).abs() < 1e-14 && (b - pa).abs() < 1e-14),
                "{text} at ({xv}, {yv}): modes give {a}, {b}; branches {pa}, {qb}"
            );
        }
    }
    // sign (the derivative of abs) and select hold their branches too
    let sx = g.sign(x);
    let c = g.sub(x, y);
    let sel = g.select(c, x, y);
    let f = g.freeze_switches(&[sx, sel], 2);
    assert_eq!(f.switching.len(), 2);
    for (xv, yv) in [(0.7, 0.3), (-0.2, 0.9)] {
        assert_eq!(g.eval(f.exprs[0], &[xv, yv, 1.0, 0.0]), 1.0);
        assert_eq!(g.eval(f.exprs[0], &[xv, yv, -1.0, 0.0]), -1.0);
        assert_eq!(g.eval(f.exprs[0], &[xv, yv, 0.0, 0.0]), xv.signum());
        assert_eq!(g.eval(f.exprs[1], &[xv, yv, 0.0, 1.0]), xv);
        assert_eq!(g.eval(f.exprs[1], &[xv, yv, 0.0, -1.0]), yv);
        assert_eq!(g.eval(f.exprs[1], &[xv, yv, 0.0, 0.0]), xv.max(yv));
    }
    // nested: the outer switch's function reads the inner one's mode; constant conditions fold
    let e = g.parse("max(0, min(x, y))", &mut r).unwrap();
    let f = g.freeze_switches(&[e], 2);
    assert_eq!(f.switching.len(), 2);
    let c = g.parse("max(2, 3) + abs(-4)", &mut r).unwrap();
    assert!(g.freeze_switches(&[c], 2).switching.is_empty());
}
