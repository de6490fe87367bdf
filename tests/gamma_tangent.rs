//! The acceleration rows' `γ = Σ_k ∂(G_v v)/∂q_k · (K(q) v)_k (+ ∂(G_v v)/∂t)`, built by one
//! forward sweep (`ExprGraph::tangents`) in `ConstraintExprs::derive`, against the same sum
//! built term by term from the symbolic partial derivatives (the construction it replaced), at
//! random states of every bundled scene with joints: the two agree to rounding.

mod common;

use bondmech::dae::ConstraintExprs;
use bondmech::Scene;

#[test]
fn gamma_by_one_forward_sweep_equals_the_sum_of_its_partial_derivatives_on_every_scene() {
    let mut checked = 0;
    for path in common::bundled_scene_paths() {
        let scene = Scene::from_path(&path).expect("scene");
        let Ok(mut sys) = bondmech::mech::build(&scene) else {
            continue;
        };
        let c = ConstraintExprs::derive(&mut sys);
        if c.g.is_empty() {
            continue;
        }
        let (nq, nv) = (sys.nq(), sys.nv());
        let reference: Vec<_> = c
            .gvv
            .clone()
            .into_iter()
            .map(|e| {
                let mut terms = Vec::new();
                for k in 0..nq {
                    let d = sys.graph.diff(e, sys.q_slot(k));
                    if !sys.graph.is_zero(d) {
                        terms.push(sys.graph.mul(d, sys.kinematics[k]));
                    }
                }
                terms.push(sys.graph.diff(e, 0));
                sys.graph.sum(&terms)
            })
            .collect();
        let mut next = common::uniform(0x2545_f491_4f6c_dd1d);
        for _ in 0..5 {
            // t, then coordinates and velocities of order one
            let x: Vec<f64> = (0..1 + nq + nv).map(|_| next()).collect();
            for (k, (&a, &b)) in c.gamma.iter().zip(&reference).enumerate() {
                let (u, w) = (sys.graph.eval(a, &x), sys.graph.eval(b, &x));
                assert!(
                    (u - w).abs() <= 1e-12 * (1.0 + w.abs()),
                    "{}: γ[{k}] {u:e} by the forward sweep, {w:e} by the partials",
                    path.display()
                );
            }
        }
        checked += 1;
    }
    assert!(checked >= 15, "only {checked} scenes with joints");
}
