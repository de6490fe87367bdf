//! Random expression DAGs: symbolic derivatives (first and second) against central
//! finite differences, and the compiled tape against the reference interpreter.

use bondmech::expr::{Expr, ExprGraph};
use proptest::prelude::*;

const N_VARS: usize = 3;

/// One construction step: operation code, two operand picks, a constant.
type Step = (u8, usize, usize, f64);

/// Builds a DAG from `steps` over the variables and a few constants; returns the last node.
/// `safe` wraps arguments so every operation stays inside its smooth domain
/// (the wrapped forms still exercise each operation's own derivative rule).
fn build(g: &mut ExprGraph, steps: &[Step], safe: bool) -> Expr {
    let mut pool: Vec<Expr> = (0..N_VARS as u32).map(|i| g.var(i)).collect();
    pool.push(g.constant(0.75));
    for &(op, i, j, c) in steps {
        let a = pool[i % pool.len()];
        let b = pool[j % pool.len()];
        let one = g.one();
        let sq = |g: &mut ExprGraph, x: Expr| {
            let x2 = g.mul(x, x);
            g.add(one, x2) // 1 + x² ≥ 1
        };
        let e = match op % 22 {
            0 => g.add(a, b),
            1 => g.sub(a, b),
            2 => g.mul(a, b),
            3 if safe => {
                let d = sq(g, b);
                g.div(a, d)
            }
            3 => g.div(a, b),
            4 if safe => {
                let base = sq(g, a);
                let ex = g.sin(b);
                g.pow(base, ex)
            }
            4 => g.pow(a, b),
            5 => {
                let k = g.constant([2.0, 3.0, -1.0, 0.5, -1.5][(c.abs() * 10.0) as usize % 5]);
                let base = if safe { sq(g, a) } else { a };
                g.pow(base, k)
            }
            6 => g.atan2(a, b),
            7 => g.min(a, b),
            8 => g.max(a, b),
            9 => g.neg(a),
            10 => g.sin(a),
            11 => g.cos(a),
            12 if safe => {
                let s = g.sin(a);
                g.tan(s)
            }
            12 => g.tan(a),
            13 if safe => {
                let s = sq(g, a);
                g.sqrt(s)
            }
            13 => g.sqrt(a),
            14 => g.abs(a),
            15 if safe => {
                let s = g.sin(a);
                g.exp(s)
            }
            15 => g.exp(a),
            16 if safe => {
                let s = sq(g, a);
                g.ln(s)
            }
            16 => g.ln(a),
            17 => g.table(&[-1.0, 0.0, 0.5, 2.0], &[0.5, -1.0, 2.0, 3.0], a),
            18 => g.scale(c, a),
            19 => {
                let k = g.constant(c);
                g.add(k, a)
            }
            20 => {
                let p = g.mul(a, b);
                g.sum(&[a, p, b])
            }
            _ => g.dot(&[a, b], &[b, a]),
        };
        pool.push(e);
    }
    *pool.last().unwrap()
}

fn steps() -> impl Strategy<Value = Vec<Step>> {
    prop::collection::vec(
        (any::<u8>(), any::<usize>(), any::<usize>(), -2.0f64..2.0),
        1..10,
    )
}

fn point() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.5f64..1.5, N_VARS)
}

/// Central difference with step `h` (absolute; the points are O(1)).
fn fd(g: &ExprGraph, e: Expr, v: usize, pt: &[f64], h: f64) -> f64 {
    let (mut p, mut m) = (pt.to_vec(), pt.to_vec());
    p[v] += h;
    m[v] -= h;
    (g.eval(e, &p) - g.eval(e, &m)) / (2.0 * h)
}

/// Checks `d` = ∂e/∂x_v against FD unless FD itself is unreliable here (a kink or branch
/// cut within reach, or huge values): FD with steps 1e-5 and 1e-6 must agree first.
fn check_against_fd(
    g: &ExprGraph,
    e: Expr,
    d: Expr,
    v: usize,
    pt: &[f64],
) -> Result<(), TestCaseError> {
    let f = g.eval(e, pt);
    if !f.is_finite() || f.abs() > 1e4 {
        return Ok(());
    }
    let (f1, f2) = (fd(g, e, v, pt, 1e-5), fd(g, e, v, pt, 1e-6));
    if !f1.is_finite() || (f1 - f2).abs() > 1e-5 * (1.0 + f1.abs()) {
        return Ok(());
    }
    let sym = g.eval(d, pt);
    let tol = 1e-5 * (1.0 + sym.abs() + f.abs());
    prop_assert!(
        (sym - f1).abs() <= tol,
        "∂/∂x{} at {:?}: symbolic {} vs FD {}",
        v,
        pt,
        sym,
        f1
    );
    Ok(())
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn first_derivatives_of_random_dags_match_central_differences(s in steps(), pt in point()) {
        let mut g = ExprGraph::new();
        let e = build(&mut g, &s, true);
        for v in 0..N_VARS {
            let d = g.diff(e, v as u32);
            check_against_fd(&g, e, d, v, &pt)?;
        }
    }

    #[test]
    fn reverse_gradient_of_random_dags_matches_central_differences(s in steps(), pt in point()) {
        let mut g = ExprGraph::new();
        let e = build(&mut g, &s, true);
        let wrt: Vec<u32> = (0..N_VARS as u32).collect();
        let grad = g.gradient(e, &wrt);
        for (v, &d) in grad.iter().enumerate() {
            check_against_fd(&g, e, d, v, &pt)?;
        }
    }

    #[test]
    fn second_derivatives_of_random_dags_match_differences_of_first(s in steps(), pt in point()) {
        let mut g = ExprGraph::new();
        let e = build(&mut g, &s, true);
        for v in 0..N_VARS {
            let d = g.diff(e, v as u32);
            for w in 0..N_VARS {
                let dd = g.diff(d, w as u32);
                check_against_fd(&g, d, dd, w, &pt)?;
            }
        }
    }

    #[test]
    fn tape_equals_interpreter_bit_for_bit_on_random_dags(
        s in steps(), pt in prop::collection::vec(-3.0f64..3.0, N_VARS), safe in any::<bool>()
    ) {
        let mut g = ExprGraph::new();
        let e = build(&mut g, &s, safe);
        let mut outs = vec![e];
        for v in 0..N_VARS as u32 {
            let d = g.diff(e, v);
            outs.push(d);
            outs.push(g.diff(d, 0));
        }
        outs.push(e); // duplicates are fine
        let tape = g.compile(&outs);
        let mut work = vec![0.0; tape.workspace_len()]; // any slice of that length works
        let mut out = vec![0.0; tape.n_outputs()];
        for _ in 0..2 {
            tape.eval(&pt, &mut work, &mut out);
            for (k, (&o, &x)) in out.iter().zip(&outs).enumerate() {
                let want = g.eval(x, &pt);
                prop_assert!(same(o, want), "output {}: tape {} vs interpreter {}", k, o, want);
            }
        }
    }
}
