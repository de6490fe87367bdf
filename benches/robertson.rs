//! Robertson kinetics DAE on IDA (dense, analytic Jacobian), t = 0 → 4e10,
//! rtol 1e-4, atol (1e-8, 1e-6, 1e-6), as in SUNDIALS' idaRoberts_dns example.

use bondmech::sundials::{Ida, IdaOptions};
use criterion::{criterion_group, criterion_main, Criterion};

fn solve_robertson() -> f64 {
    let opts = IdaOptions {
        rtol: 1e-4,
        atol: vec![1e-8, 1e-6, 1e-6],
        ..IdaOptions::default()
    };
    let mut ida = Ida::new(
        0.0,
        &[1.0, 0.0, 0.0],
        &[-0.04, 0.04, 0.0],
        Box::new(|_t, y, yp, r| {
            r[0] = -0.04 * y[0] + 1.0e4 * y[1] * y[2];
            r[1] = -r[0] - 3.0e7 * y[1] * y[1] - yp[1];
            r[0] -= yp[0];
            r[2] = y[0] + y[1] + y[2] - 1.0;
            Ok(())
        }),
        Some(Box::new(|_t, cj, y, _yp, j| {
            j.set(0, 0, -0.04 - cj);
            j.set(1, 0, 0.04);
            j.set(2, 0, 1.0);
            j.set(0, 1, 1.0e4 * y[2]);
            j.set(1, 1, -1.0e4 * y[2] - 6.0e7 * y[1] - cj);
            j.set(2, 1, 1.0);
            j.set(0, 2, 1.0e4 * y[1]);
            j.set(1, 2, -1.0e4 * y[1]);
            j.set(2, 2, 1.0);
            Ok(())
        })),
        &opts,
    )
    .expect("valid Robertson setup");
    let mut tout = 0.4;
    for _ in 0..12 {
        ida.solve_to(tout).expect("Robertson solves");
        tout *= 10.0;
    }
    ida.y()[0]
}

fn bench(c: &mut Criterion) {
    c.bench_function("robertson_ida_dense_0_to_4e10", |b| b.iter(solve_robertson));
}

criterion_group!(benches, bench);
criterion_main!(benches);
