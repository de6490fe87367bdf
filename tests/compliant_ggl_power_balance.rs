//! The compliant GGL's joints give back the energy they absorb (issue 46, the trial's F3).
//!
//! With `E = T + V` the scene's energy, the compliant GGL's residual gives
//! `dE/dt = P − λᵀ G_v v − ∂E/∂q · G_qᵀ μ + α vᵀ M v` (`P` the scene's own forces' power, zero
//! on a conservative scene). Before the restoring rate `α` the joints absorbed
//! `p = ε |λ|² + ∂E/∂q · G_qᵀ μ`, which near a singular configuration cost a change-point
//! four-bar 1.75e-5 J per passage at any tolerance. Here `q'` and `v'` are read off the
//! residual at states that satisfy its joint rows (`g = ε μ`, `G_v v = ε λ`) with large
//! multipliers, and `dE/dt` is formed with the energy's gradient by central differences of
//! the energy expression: the conservation law is the reference, nothing of the formulation's
//! own derivation.

use bondmech::dae::ConstraintExprs;
use bondmech::solve::formulation::GglFormulation;

const SCENE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/references/trial/findings/f3_change_point_four_bar.json"
);

/// A deterministic sequence in (−1, 1).
fn wobble(k: usize) -> f64 {
    ((k as f64 * 12.9898).sin() * 43_758.545_3).fract()
}

#[test]
fn regression_the_compliant_joints_absorb_energy_at_large_multipliers() {
    let scene = bondmech::Scene::from_path(SCENE).expect("the finding's scene");
    let mut sys = bondmech::mech::build(&scene).expect("builds");
    let c = ConstraintExprs::derive(&mut sys);
    let eps = 1e-10;
    let ggl = GglFormulation::build(&mut sys, &c, eps);
    let (nq, nv, nc) = ggl.dims;
    let n = nq + nv + 2 * nc;
    let x0 = sys.initial_state();
    let mass = sys.mass.clone();
    let mut ws = ggl.dae.workspace();
    let mut tested = 0;
    for trial in 0..6 {
        // a state a little off the joints: positions by 1e-11, velocities by 1e-5 (m, rad)
        let mut x = x0.clone();
        for (i, xi) in x.iter_mut().enumerate() {
            let scale = if i < nq { 1e-11 } else { 1e-5 };
            *xi += scale * wobble(7 * trial + i + 1);
        }
        let mut vars = vec![0.0; 1 + nq + nv];
        vars[1..].copy_from_slice(&x);
        let g: Vec<f64> = (0..nc).map(|k| sys.graph.eval(c.g[k], &vars)).collect();
        let gvv: Vec<f64> = (0..nc).map(|k| sys.graph.eval(c.gvv[k], &vars)).collect();
        // the joint rows hold: μ = g / ε, λ = G_v v / ε
        let mut y = x.clone();
        y.extend(gvv.iter().map(|w| w / eps));
        y.extend(g.iter().map(|gk| gk / eps));
        let mut r = vec![0.0; n];
        ggl.residual(&mut ws, (eps, true), 0.0, &y, &vec![0.0; n], &mut r);
        for k in 0..2 * nc {
            assert!(
                r[nq + nv + k].abs() < 1e-9,
                "joint row {k}: {}",
                r[nq + nv + k]
            );
        }
        // F is linear in y' (q' with unit coefficients, v' with M): read q', v' off F(y, 0)
        let qp: Vec<f64> = (0..nq).map(|i| -r[i]).collect();
        let vp: Vec<f64> = (0..nv).map(|j| -r[nq + j] / mass[j]).collect();
        // dE/dt by central differences of the energy expression
        let energy = |z: &[f64]| {
            let mut v = vec![0.0; 1 + nq + nv];
            v[1..].copy_from_slice(z);
            sys.graph.eval(sys.energy, &v)
        };
        let mut de_dt = 0.0;
        let mut scale = 0.0;
        for i in 0..nq + nv {
            let h = 1e-6 * (1.0 + x[i].abs());
            let (mut a, mut b) = (x.clone(), x.clone());
            a[i] += h;
            b[i] -= h;
            let d = (energy(&a) - energy(&b)) / (2.0 * h);
            let rate = if i < nq { qp[i] } else { vp[i - nq] };
            de_dt += d * rate;
            scale += (d * rate).abs();
        }
        // the power the joints absorb: ε|λ|² alone is already this large
        let lam2: f64 = gvv.iter().map(|w| (w / eps).powi(2)).sum();
        let absorbed = eps * lam2;
        assert!(
            absorbed > 0.1,
            "trial {trial}: ε|λ|² = {absorbed:.3e} W tests nothing"
        );
        eprintln!(
            "trial {trial}: ε|λ|² = {absorbed:.3e} W, dE/dt = {de_dt:.3e} W (terms {scale:.3e})"
        );
        // given back up to the bound τ puts on α (1e-4 of p here) and the differences' error
        assert!(
            de_dt.abs() <= 1e-3 * absorbed + 1e-7 * scale,
            "trial {trial}: dE/dt = {de_dt:.3e} W where the joints absorb {absorbed:.3e} W"
        );
        tested += 1;
    }
    assert_eq!(tested, 6);
}
