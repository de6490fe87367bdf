//! ARKODE's explicit Runge–Kutta through `bondmech::sundials::Erk`: the harmonic oscillator
//! `y'' = −y` (exact solution cos t, −sin t) at many output times, where every step lands on
//! an output (the stop time), and the counters.

use bondmech::sundials::{Erk, ErkOptions};

fn oscillator(rtol: f64, n_out: usize, t_end: f64) -> (f64, u64) {
    let opts = ErkOptions {
        rtol,
        atol: rtol * 1e-2,
        max_steps: Some(1_000_000),
        max_total_steps: None,
        max_wall_clock: None,
        stop_time: Some(t_end),
    };
    let rhs = Box::new(|_t: f64, y: &[f64], yd: &mut [f64]| {
        yd[0] = y[1];
        yd[1] = -y[0];
        Ok(())
    });
    let mut e = Erk::new(0.0, &[1.0, 0.0], rhs, &opts).expect("ERK starts");
    let mut worst = 0.0f64;
    for i in 1..=n_out {
        let t = t_end * i as f64 / n_out as f64;
        let s = e.solve_to(t).expect("ERK solves");
        assert_eq!(s.t, t, "lands on the output time");
        let y = e.y();
        worst = worst.max((y[0] - t.cos()).abs().max((y[1] + t.sin()).abs()));
    }
    (worst, e.stats().steps)
}

#[test]
fn erk_follows_the_harmonic_oscillator_at_sparse_and_dense_outputs() {
    // the bounds: a hundred times the tolerance over eight periods (measured 1.5e-6 and 3e-10)
    for (rtol, bound) in [(1e-6, 1e-4), (1e-9, 1e-7)] {
        let (sparse, steps_sparse) = oscillator(rtol, 10, 50.0);
        let (dense, steps_dense) = oscillator(rtol, 5000, 50.0);
        eprintln!("rtol {rtol:e}: sparse {sparse:.2e} ({steps_sparse} steps), dense {dense:.2e} ({steps_dense} steps)");
        assert!(
            sparse < bound,
            "rtol {rtol:e}: error {sparse:e} with 10 outputs"
        );
        assert!(
            dense < bound,
            "rtol {rtol:e}: error {dense:e} with 5000 outputs"
        );
        // landing on 5000 outputs costs at most one extra step per output
        assert!(steps_dense <= steps_sparse + 5000, "{steps_dense} steps");
    }
}

/// The order conditions of an explicit Runge–Kutta method up to order 5 (Butcher's rooted
/// trees: `Φ(τ) = 1/γ(τ)` for every tree of at most five vertices), each as `(order,
/// Φ(τ) − 1/γ(τ))`.
fn order_defects(c: &[f64], a: &[f64], b: &[f64]) -> Vec<(usize, f64)> {
    let s = c.len();
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>();
    let mul = |x: &[f64], y: &[f64]| -> Vec<f64> { x.iter().zip(y).map(|(p, q)| p * q).collect() };
    let am = |x: &[f64]| -> Vec<f64> { (0..s).map(|i| dot(&a[i * s..(i + 1) * s], x)).collect() };
    let one = vec![1.0; s];
    let c2 = mul(c, c);
    let c3 = mul(&c2, c);
    let ac = am(c);
    let ac2 = am(&c2);
    let aac = am(&ac);
    vec![
        (1, dot(b, &one) - 1.0),
        (2, dot(b, c) - 1.0 / 2.0),
        (3, dot(b, &c2) - 1.0 / 3.0),
        (3, dot(b, &ac) - 1.0 / 6.0),
        (4, dot(b, &c3) - 1.0 / 4.0),
        (4, dot(b, &mul(c, &ac)) - 1.0 / 8.0),
        (4, dot(b, &ac2) - 1.0 / 12.0),
        (4, dot(b, &aac) - 1.0 / 24.0),
        (5, dot(b, &mul(&c3, c)) - 1.0 / 5.0),
        (5, dot(b, &mul(&c2, &ac)) - 1.0 / 10.0),
        (5, dot(b, &mul(c, &ac2)) - 1.0 / 15.0),
        (5, dot(b, &mul(c, &aac)) - 1.0 / 30.0),
        (5, dot(b, &mul(&ac, &ac)) - 1.0 / 20.0),
        (5, dot(b, &am(&c3)) - 1.0 / 20.0),
        (5, dot(b, &am(&mul(c, &ac))) - 1.0 / 40.0),
        (5, dot(b, &am(&ac2)) - 1.0 / 60.0),
        (5, dot(b, &am(&aac)) - 1.0 / 120.0),
    ]
}

#[test]
fn tsitouras_table_satisfies_the_order_conditions_of_order_5_and_its_embedding_of_order_4() {
    let t = bondmech::sundials::tables::ButcherTable::tsitouras5();
    let s = t.stages();
    assert_eq!((s, t.q, t.p), (7, 5, 4));
    for i in 0..s {
        let row: f64 = t.a[i * s..(i + 1) * s].iter().sum();
        assert!(
            (row - t.c[i]).abs() < 1e-14,
            "row {i}: Σa = {row}, c = {}",
            t.c[i]
        );
        assert!(
            t.a[i * s + i..(i + 1) * s].iter().all(|&x| x == 0.0),
            "explicit"
        );
    }
    // first same as last: the last stage is the solution
    assert_eq!(&t.a[6 * s..6 * s + 6], &t.b[..6]);
    for (order, defect) in order_defects(&t.c, &t.a, &t.b) {
        assert!(defect.abs() < 1e-13, "order {order}: defect {defect:e}");
    }
    for (order, defect) in order_defects(&t.c, &t.a, &t.d) {
        if order <= 4 {
            assert!(
                defect.abs() < 1e-13,
                "embedding, order {order}: defect {defect:e}"
            );
        }
    }
    // and no more: the embedding is not of order 5, the method not of order 6 (b·c⁵ ≠ 1/6)
    let fifth = order_defects(&t.c, &t.a, &t.d);
    assert!(fifth.iter().any(|&(o, d)| o == 5 && d.abs() > 1e-6));
    let b_c5: f64 = t.b.iter().zip(&t.c).map(|(b, c)| b * c.powi(5)).sum();
    assert!((b_c5 - 1.0 / 6.0).abs() > 1e-6);
}
