//! Tape layout: reachability, sharing, register reuse, tables, and a timing report.

use bondmech::expr::{Expr, ExprGraph};

#[test]
fn shared_subexpressions_are_computed_once() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let s = g.sin(x);
    let p = g.mul(s, s);
    let e = g.add(p, s); // sin² x + sin x: three instructions (sin, mul, add)
    let tape = g.compile(&[e]);
    assert_eq!(tape.len(), 3);
    let mut w = tape.workspace();
    let mut out = [0.0];
    tape.eval(&[0.3], &mut w, &mut out);
    let s = 0.3f64.sin();
    assert_eq!(out[0], s * s + s);
}

#[test]
fn only_nodes_reachable_from_the_outputs_are_compiled() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(7));
    let mut big = y;
    for _ in 0..500 {
        let c = g.cos(big);
        big = g.add(c, y);
    }
    let small = g.exp(x);
    let tape = g.compile(&[small]);
    assert_eq!(tape.len(), 1);
    assert_eq!(tape.n_vars(), 1, "var 7 is not reachable");
    assert_eq!(tape.n_outputs(), 1);
    let tape = g.compile(&[small, big]);
    assert_eq!(tape.len(), 1001);
    assert_eq!(tape.n_vars(), 8);
}

#[test]
fn registers_are_reused_along_a_long_chain() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let mut e = x;
    for k in 0..1000 {
        let c = g.constant(k as f64 * 1e-3);
        let s = g.sin(e);
        e = g.add(s, c);
    }
    let tape = g.compile(&[e]);
    assert_eq!(tape.len(), 1999); // first step adds constant 0 and so folds away
                                  // 1 variable + 999 distinct constants + a handful of registers.
    assert!(
        tape.workspace_len() <= 1 + tape.n_consts() + 2,
        "workspace {}",
        tape.workspace_len()
    );
    let (mut w, mut out) = (tape.workspace(), [0.0]);
    tape.eval(&[0.5], &mut w, &mut out);
    let mut want = 0.5f64;
    for k in 0..1000 {
        want = want.sin() + k as f64 * 1e-3;
    }
    assert_eq!(out[0], want);
}

#[test]
fn outputs_may_be_variables_or_constants() {
    let mut g = ExprGraph::new();
    let x = g.var(2);
    let c = g.constant(-4.5);
    let tape = g.compile(&[c, x]);
    assert_eq!(tape.len(), 0);
    assert!(tape.is_empty());
    assert_eq!(tape.n_vars(), 3);
    let (mut w, mut out) = (tape.workspace(), [0.0; 2]);
    tape.eval(&[0.0, 0.0, 7.0], &mut w, &mut out);
    assert_eq!(out, [-4.5, 7.0]);
    let empty = g.compile(&[]);
    assert_eq!((empty.n_outputs(), empty.n_vars()), (0, 0));
}

#[test]
fn table_interpolates_linearly_and_clamps_outside() {
    // Points (0, 1), (2, 5), (3, -1): hand-computed values.
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let e = g.table(&[0.0, 2.0, 3.0], &[1.0, 5.0, -1.0], x);
    let tape = g.compile(&[e]);
    let (mut w, mut out) = (tape.workspace(), [0.0]);
    for (t, want) in [
        (-5.0, 1.0),
        (0.0, 1.0),
        (0.5, 2.0),
        (2.0, 5.0),
        (2.25, 3.5),
        (3.0, -1.0),
        (10.0, -1.0),
    ] {
        tape.eval(&[t], &mut w, &mut out);
        assert_eq!(out[0], want, "table at {t}");
        assert_eq!(g.eval(e, &[t]), want);
    }
    // A single point is a constant function.
    let one = g.table(&[1.0], &[4.0], x);
    assert_eq!(g.eval(one, &[-3.0]), 4.0);
    assert_eq!(g.eval(one, &[3.0]), 4.0);
}

#[test]
fn pendulum_residual_and_jacobian_on_one_tape() {
    // F = [x² + y² − L², x·vx + y·vy], Jacobian row ∂F₁/∂(x, y) = (2x, 2y).
    let mut g = ExprGraph::new();
    let v: Vec<Expr> = (0..4).map(|i| g.var(i)).collect();
    let mut r = |n: &str| {
        ["x", "y", "vx", "vy"]
            .iter()
            .position(|&m| m == n)
            .map(|i| v[i])
    };
    let f1 = g.parse("x^2 + y^2 - 1.5^2", &mut r).unwrap();
    let f2 = g.parse("x*vx + y*vy", &mut r).unwrap();
    let (j11, j12) = (g.diff(f1, 0), g.diff(f1, 1));
    let (j21, j23) = (g.diff(f2, 0), g.diff(f2, 2));
    let tape = g.compile(&[f1, f2, j11, j12, j21, j23]);
    let (mut w, mut out) = (tape.workspace(), [0.0; 6]);
    tape.eval(&[0.9, -1.2, 0.4, 0.3], &mut w, &mut out);
    let want = [0.81 + 1.44 - 2.25, 0.36 - 0.36, 1.8, -2.4, 0.4, 0.9];
    for (o, w) in out.iter().zip(want) {
        assert!((o - w).abs() < 1e-15, "{out:?} vs {want:?}");
    }
}

/// Timing report: `cargo test --test expr_tape -- --ignored --nocapture`.
#[test]
#[ignore]
fn report_compile_and_eval_time_of_a_200_node_expression() {
    let mut g = ExprGraph::new();
    let vars: Vec<Expr> = (0..10).map(|i| g.var(i)).collect();
    let mut pool = vars.clone();
    let mut k = 0usize;
    while g.len() < 110 {
        let (a, b) = (
            pool[(k * 7 + 3) % pool.len()],
            pool[(k * 13 + 5) % pool.len()],
        );
        let e = match k % 5 {
            0 => g.mul(a, b),
            1 => g.add(a, b),
            2 => g.sin(a),
            3 => g.sub(a, b),
            _ => g.cos(b),
        };
        pool.push(e);
        k += 1;
    }
    let e = g.sum(&pool[10..]);
    let t0 = std::time::Instant::now();
    let tape = g.compile(&[e]);
    let tc = t0.elapsed();
    let grads: Vec<Expr> = (0..10).map(|v| g.diff(e, v)).collect();
    let mut outs = vec![e];
    outs.extend(&grads);
    let t0 = std::time::Instant::now();
    let jt = g.compile(&outs);
    let tcj = t0.elapsed();
    let x: Vec<f64> = (0..10).map(|i| 0.1 * i as f64).collect();
    let time = |t: &bondmech::expr::Tape| {
        let (mut w, mut out) = (t.workspace(), vec![0.0; t.n_outputs()]);
        let n = 100_000;
        let t0 = std::time::Instant::now();
        for _ in 0..n {
            t.eval(&x, &mut w, &mut out);
        }
        t0.elapsed().as_secs_f64() / n as f64 * 1e9
    };
    println!("graph nodes {}", g.len());
    // Compile cost at a few thousand nodes: 200 random-ish gradients of a chain.
    let mut big = vars[0];
    for k in 0..1500 {
        let a = vars[k % 10];
        let s = g.sin(big);
        big = g.mul(s, a);
    }
    let t0 = std::time::Instant::now();
    let bt = g.compile(&[big]);
    println!(
        "3000-instruction tape: {} instr, compile {:?}",
        bt.len(),
        t0.elapsed()
    );
    println!(
        "value tape: {} instr, work {} slots, compile {:?}, eval {:.0} ns",
        tape.len(),
        tape.workspace_len(),
        tc,
        time(&tape)
    );
    println!(
        "value+gradient tape: {} instr, work {} slots, compile {:?}, eval {:.0} ns",
        jt.len(),
        jt.workspace_len(),
        tcj,
        time(&jt)
    );
}

#[test]
fn eval_parts_reads_consecutive_slices_as_one_input_vector() {
    // Residual of y' = -2y + sin t as F(t, y, y') = y' + 2y - sin t, with t = var 0, y = var 1, y' = var 2.
    let mut g = ExprGraph::new();
    let (t, y, yp) = (g.var(0), g.var(1), g.var(2));
    let ty = g.scale(2.0, y);
    let s = g.sin(t);
    let a = g.add(yp, ty);
    let f = g.sub(a, s);
    let tape = g.compile(&[f]);
    let (mut w, mut out) = (tape.workspace(), [0.0]);
    tape.eval_parts(&[&[0.5], &[3.0], &[-1.0, 99.0]], &mut w, &mut out);
    assert_eq!(out[0], -1.0 + 6.0 - 0.5f64.sin());
    let mut out2 = [0.0];
    tape.eval(&[0.5, 3.0, -1.0], &mut w, &mut out2);
    assert_eq!(out, out2);
}

/// Pseudo-random expressions over three variables (0: fixed, 1: iterated, 2: last), with
/// shared subexpressions and every kind of dependence across the stages.
/// A linear congruential generator of indices below `n` (the random expressions' choices).
fn lcg(seed: u64) -> impl FnMut(usize) -> usize {
    let mut state = seed;
    move |n: usize| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 33) as usize) % n
    }
}

fn staged_expressions(g: &mut ExprGraph, seed: u64) -> Vec<Expr> {
    let mut next = lcg(seed);
    let mut pool: Vec<Expr> = vec![g.var(0), g.var(1), g.var(2), g.constant(0.7)];
    for _ in 0..60 {
        let a = pool[next(pool.len())];
        let b = pool[next(pool.len())];
        let e = match next(6) {
            0 => g.sin(a),
            1 => g.cos(a),
            2 => g.mul(a, b),
            3 => g.add(a, b),
            4 => g.sub(a, b),
            _ => {
                let s = g.sin(b);
                g.mul(a, s)
            }
        };
        pool.push(e);
    }
    pool[pool.len() - 12..].to_vec()
}

#[test]
fn staged_tape_rerunning_a_later_stage_matches_a_full_evaluation() {
    for seed in 0..40 {
        let mut g = ExprGraph::new();
        let outs = staged_expressions(&mut g, seed);
        let full = g.compile(&outs);
        let staged = g.compile_staged(&outs, &|v| v as usize, 3);
        assert_eq!(staged.n_stages(), 3);
        assert_eq!(
            (0..3).map(|s| staged.stage_len(s)).sum::<usize>(),
            full.len(),
            "the same instructions, reordered"
        );
        let mut w = staged.workspace();
        let mut got = vec![0.0; outs.len()];
        let mut want = vec![0.0; outs.len()];
        let mut wf = full.workspace();
        let mut vars = [0.3, -1.1, 2.0];
        staged.eval_stages(&vars, &mut w, &mut got, 0..3);
        full.eval(&vars, &mut wf, &mut want);
        assert_eq!(got, want, "all stages at once (seed {seed})");
        // Newton-like: variable 1 changes, stage 1 and 2 re-run; then only 2 after var 2
        for k in 0..4 {
            vars[1] += 0.37 * (k as f64 + 1.0);
            staged.eval_stages(&vars, &mut w, &mut got, 1..3);
            full.eval(&vars, &mut wf, &mut want);
            assert_eq!(
                got, want,
                "stages 1.. after variable 1 changed (seed {seed})"
            );
            vars[2] -= 0.21;
            staged.eval_stages(&vars, &mut w, &mut got, 2..3);
            full.eval(&vars, &mut wf, &mut want);
            assert_eq!(got, want, "stage 2 after variable 2 changed (seed {seed})");
            // and the reference interpreter (not the tape compiler), bit for bit
            let reference: Vec<f64> = outs.iter().map(|&o| g.eval(o, &vars)).collect();
            assert_eq!(
                got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                reference.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                "against ExprGraph::eval (seed {seed})"
            );
        }
    }
}

/// Random expressions over `n_vars` variables, against the graph's own recursive evaluator
/// bit for bit. A tape whose variables, constants and registers fit in 256 slots runs with
/// one-byte register indices into a fixed block; a larger one with four-byte indices into the
/// caller's slice: both interpreters are exercised.
fn tape_matches_the_graph(n_vars: usize, seed: u64) -> usize {
    let mut next = lcg(seed);
    let mut g = ExprGraph::new();
    let mut pool: Vec<Expr> = (0..n_vars).map(|k| g.var(k as u32)).collect();
    pool.push(g.constant(0.7));
    for _ in 0..3 * n_vars {
        let a = pool[next(pool.len())];
        let b = pool[next(pool.len())];
        let e = match next(7) {
            0 => g.sin(a),
            1 => g.cos(a),
            2 => g.mul(a, b),
            3 => g.add(a, b),
            4 => g.sub(a, b),
            5 => g.neg(a),
            _ => {
                let c = g.constant(1.0 + next(100) as f64);
                g.div(a, c)
            }
        };
        pool.push(e);
    }
    let outs = pool[pool.len() - n_vars..].to_vec();
    let tape = g.compile(&outs);
    let vars: Vec<f64> = (0..n_vars).map(|k| 0.1 * k as f64 - 0.9).collect();
    let mut got = vec![0.0; outs.len()];
    tape.eval(&vars, &mut tape.workspace(), &mut got);
    for (k, &o) in outs.iter().enumerate() {
        let want = g.eval(o, &vars);
        assert_eq!(
            got[k].to_bits(),
            want.to_bits(),
            "output {k} of {n_vars} variables (seed {seed}): tape {} graph {want}",
            got[k]
        );
    }
    tape.workspace_len()
}

#[test]
fn small_and_large_tapes_evaluate_as_the_graph_does() {
    for seed in 0..10 {
        // a few variables: fits the 256-slot register block
        assert_eq!(tape_matches_the_graph(6, seed), 256);
        // hundreds of variables: past it
        assert!(tape_matches_the_graph(300, seed) > 300);
    }
}
