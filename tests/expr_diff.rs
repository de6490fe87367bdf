//! Symbolic derivatives of every operation against central finite differences and
//! against hand-derived formulas (first and second derivatives).

use bondmech::expr::{Expr, ExprGraph};
use proptest::prelude::*;

/// Central difference of `e` in variable `v` at `pt`, step h·max(1, |x|).
fn fd(g: &ExprGraph, e: Expr, v: usize, pt: &[f64], h: f64) -> f64 {
    let h = h * pt[v].abs().max(1.0);
    let (mut p, mut m) = (pt.to_vec(), pt.to_vec());
    p[v] += h;
    m[v] -= h;
    (g.eval(e, &p) - g.eval(e, &m)) / (2.0 * h)
}

fn assert_matches_fd(g: &mut ExprGraph, e: Expr, pt: &[f64], what: &str) {
    for v in 0..pt.len() {
        let d = g.diff(e, v as u32);
        let sym = g.eval(d, pt);
        let num = fd(g, e, v, pt, 1e-6);
        let tol = 1e-6 * (1.0 + sym.abs() + g.eval(e, pt).abs());
        assert!(
            (sym - num).abs() <= tol,
            "{what}: d/dx{v} at {pt:?}: symbolic {sym}, FD {num}"
        );
    }
}

type Build = fn(&mut ExprGraph, Expr, Expr) -> Expr;

/// Every operation, with arguments (x, y) ∈ [0.2, 2] × [-2, -0.2] (tan at x/2) away from domain edges
/// and kinks (x > 0 > y, |x| ≠ |y| except on a measure-zero set).
fn ops() -> Vec<(&'static str, Build)> {
    vec![
        ("add", |g, x, y| g.add(x, y)),
        ("sub", |g, x, y| g.sub(x, y)),
        ("mul", |g, x, y| g.mul(x, y)),
        ("div", |g, x, y| g.div(x, y)),
        ("pow general", |g, x, y| g.pow(x, y)),
        ("pow const exponent", |g, x, _| {
            let c = g.constant(2.5);
            g.pow(x, c)
        }),
        ("pow const integer exponent", |g, _, y| {
            let c = g.constant(3.0);
            g.pow(y, c)
        }),
        ("pow const base", |g, _, y| {
            let c = g.constant(1.7);
            g.pow(c, y)
        }),
        ("atan2", |g, x, y| g.atan2(y, x)),
        ("atan2 swapped", |g, x, y| g.atan2(x, y)),
        ("min", |g, x, y| {
            let t = g.scale(0.3, x);
            let s = g.add(t, y);
            g.min(x, s)
        }),
        ("max", |g, x, y| g.max(x, y)),
        ("neg", |g, x, y| {
            let p = g.mul(x, y);
            g.neg(p)
        }),
        ("sin", |g, x, y| {
            let p = g.mul(x, y);
            g.sin(p)
        }),
        ("cos", |g, x, y| {
            let p = g.mul(x, y);
            g.cos(p)
        }),
        ("tan", |g, x, _| {
            // x/2 ∈ [0.1, 1], clear of the pole at π/2.
            let h = g.scale(0.5, x);
            g.tan(h)
        }),
        ("sqrt", |g, x, _| g.sqrt(x)),
        ("abs", |g, _, y| g.abs(y)),
        ("abs of product", |g, x, y| {
            let p = g.mul(x, y);
            g.abs(p)
        }),
        ("exp", |g, x, y| {
            let p = g.mul(x, y);
            g.exp(p)
        }),
        ("ln", |g, x, _| g.ln(x)),
        ("table", |g, x, y| {
            let a = g.sub(x, y);
            g.table(&[0.0, 0.5, 1.5, 3.0, 5.0], &[1.0, 2.0, -1.0, 0.5, 0.5], a)
        }),
    ]
}

proptest! {
    #[test]
    fn derivative_of_every_operation_matches_central_differences(
        x in 0.2f64..2.0, y in -2.0f64..-0.2
    ) {
        for (what, build) in ops() {
            let mut g = ExprGraph::new();
            let (vx, vy) = (g.var(0), g.var(1));
            let e = build(&mut g, vx, vy);
            // Skip the rare points within FD reach of a table breakpoint.
            if what == "table" && [0.5, 1.5, 3.0].iter().any(|b| (x - y - b).abs() < 1e-4) {
                continue;
            }
            if what == "min" && (0.7 * x - y).abs() < 1e-4 {
                continue;
            }
            assert_matches_fd(&mut g, e, &[x, y], what);
            // the reverse sweep's gradient, of the operation and of the operation composed
            // (its adjoint is then not 1): against the same central differences
            let s = g.sin(vy);
            let composed = g.mul(e, s);
            for f in [e, composed] {
                let grad = g.gradient(f, &[0, 1, 2]);
                let pt = [x, y];
                for (v, &d) in grad.iter().take(2).enumerate() {
                    let sym = g.eval(d, &pt);
                    let num = fd(&g, f, v, &pt, 1e-6);
                    let tol = 1e-6 * (1.0 + sym.abs() + g.eval(f, &pt).abs());
                    prop_assert!((sym - num).abs() <= tol, "{}: gradient d/dx{} {} vs FD {}", what, v, sym, num);
                }
                prop_assert!(g.is_zero(grad[2]), "{}: no x2 in the expression", what);
            }
        }
    }
}

#[test]
fn second_derivative_of_x_sin_x_is_2cos_x_minus_x_sin_x() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let s = g.sin(x);
    let e = g.mul(s, x);
    let d1 = g.diff(e, 0);
    let d2 = g.diff(d1, 0);
    for &t in &[-2.0f64, -0.3, 0.0, 0.7, 3.0] {
        let want1 = t.sin() + t * t.cos();
        let want2 = 2.0 * t.cos() - t * t.sin();
        assert!((g.eval(d1, &[t]) - want1).abs() < 1e-14);
        assert!((g.eval(d2, &[t]) - want2).abs() < 1e-14, "t = {t}");
    }
}

#[test]
fn mixed_second_derivative_of_pendulum_constraint() {
    // g(x, y) = x² + y² − L²: ∂²g/∂x∂y = 0, ∂²g/∂x² = 2.
    let mut g = ExprGraph::new();
    let e = g.parse("x^2 + y^2 - 4", &mut |_| None).err();
    assert!(e.is_some(), "names must be resolved by the caller");
    let (x, y) = (g.var(0), g.var(1));
    let e = g.parse("x^2 + y^2 - 4", &mut |n| match n {
        "x" => Some(x),
        "y" => Some(y),
        _ => None,
    });
    let e = e.unwrap();
    let dx = g.diff(e, 0);
    let dxy = g.diff(dx, 1);
    let dxx = g.diff(dx, 0);
    assert!(g.is_zero(dxy));
    assert_eq!(g.as_const(dxx), Some(2.0));
}

#[test]
fn derivatives_are_memoised_and_of_constants_are_zero() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let e = g.parse("sin(x)^2 * exp(x)", &mut |_| Some(x)).unwrap();
    let d1 = g.diff(e, 0);
    let n = g.len();
    assert_eq!(g.diff(e, 0), d1);
    assert_eq!(g.len(), n);
    assert!({
        let t = g.diff(e, 1);
        g.is_zero(t)
    });
    let c = g.constant(3.0);
    assert!({
        let t = g.diff(c, 0);
        g.is_zero(t)
    });
    assert_eq!(
        {
            let t = g.diff(x, 0);
            g.as_const(t)
        },
        Some(1.0)
    );
}

#[test]
fn third_derivative_of_atan2_matches_fd_of_the_second() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let e = g.atan2(y, x);
    let d1 = g.diff(e, 0);
    let d2 = g.diff(d1, 1);
    let d3 = g.diff(d2, 0);
    // Analytic: ∂atan2(y,x)/∂x = −y/(x²+y²); ∂²/∂y∂x = (y² − x²)/(x²+y²)².
    let (a, b) = (0.8, -1.3);
    let r2: f64 = a * a + b * b;
    assert!((g.eval(d1, &[a, b]) - (-b / r2)).abs() < 1e-15);
    assert!((g.eval(d2, &[a, b]) - (b * b - a * a) / (r2 * r2)).abs() < 1e-15);
    let num = fd(&g, d2, 0, &[a, b], 1e-6);
    assert!((g.eval(d3, &[a, b]) - num).abs() < 1e-7);
}

#[test]
fn table_slope_is_the_segment_slope_and_zero_outside() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let e = g.table(&[0.0, 1.0, 3.0], &[2.0, 4.0, 3.0], x);
    let d = g.diff(e, 0);
    let cases = [
        (-1.0, 0.0),
        (0.0, 2.0),
        (0.5, 2.0),
        (1.0, -0.5),
        (2.0, -0.5),
        (3.0, 0.0),
        (9.0, 0.0),
    ];
    for (t, slope) in cases {
        assert_eq!(g.eval(d, &[t]), slope, "slope at {t}");
    }
    assert!(
        {
            let t = g.diff(d, 0);
            g.is_zero(t)
        },
        "table slope is piecewise constant"
    );
}

#[test]
fn abs_min_max_derivatives_select_the_active_branch() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let a = g.abs(x);
    let da = g.diff(a, 0);
    assert_eq!(g.eval(da, &[-2.0, 0.0]), -1.0);
    assert_eq!(g.eval(da, &[2.0, 0.0]), 1.0);
    let m = g.min(x, y);
    let (dmx, dmy) = (g.diff(m, 0), g.diff(m, 1));
    assert_eq!(
        (g.eval(dmx, &[1.0, 2.0]), g.eval(dmy, &[1.0, 2.0])),
        (1.0, 0.0)
    );
    assert_eq!(
        (g.eval(dmx, &[3.0, 2.0]), g.eval(dmy, &[3.0, 2.0])),
        (0.0, 1.0)
    );
    let mx = g.max(x, y);
    let (dmx, dmy) = (g.diff(mx, 0), g.diff(mx, 1));
    assert_eq!(
        (g.eval(dmx, &[1.0, 2.0]), g.eval(dmy, &[1.0, 2.0])),
        (0.0, 1.0)
    );
    assert_eq!(
        (g.eval(dmx, &[3.0, 2.0]), g.eval(dmy, &[3.0, 2.0])),
        (1.0, 0.0)
    );
}

#[test]
fn sparse_jacobian_lists_only_structural_nonzeros() {
    // f₀ = x·y, f₁ = sin z, f₂ = 3 (no dependence); columns ordered (z, x, y).
    let mut g = ExprGraph::new();
    let (x, y, z) = (g.var(0), g.var(1), g.var(2));
    let f0 = g.mul(x, y);
    let f1 = g.sin(z);
    let f2 = g.constant(3.0);
    let jac = g.jacobian(&[f0, f1, f2], &[2, 0, 1]);
    let pt = [2.0, 5.0, 0.25];
    let got: Vec<(usize, usize, f64)> = jac
        .iter()
        .map(|&(i, j, d)| (i, j, g.eval(d, &pt)))
        .collect();
    assert_eq!(got, vec![(0, 1, 5.0), (0, 2, 2.0), (1, 0, 0.25f64.cos())]);
    // A variable outside `wrt` gives no column.
    assert!(g.jacobian(&[f1], &[0, 1]).is_empty());
}

#[test]
fn graph_and_tape_are_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<ExprGraph>();
    check::<bondmech::expr::Tape>();
    check::<bondmech::expr::ParseError>();
}
