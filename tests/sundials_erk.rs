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
