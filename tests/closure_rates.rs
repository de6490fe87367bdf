//! No model beside the graph, checked at the constraint junctions: for every bundled
//! mechanism scene, the closure `g_k(x)` each constraint junction of the solver's bond graph
//! carries, differentiated along the graph's own flows (`dg_k/dt = ∂g_k/∂t + Σ_j ∂g_k/∂x_j ẋ_j`
//! with `ẋ = K(x) v` the displacements' junction flows read off the graph), equals the
//! junction's flow sum `G_k v` (the flow constraint the graph's bonds impose there) at 50
//! random states, to 1e-12 relative to the terms' size. Covers every joint kind a bundled scene
//! uses (revolute, spherical, hinge, prismatic, gear, slot, rack_pinion, universal; no bundled
//! scene has a weld).

mod common;

use bondmech::bond::mechanics::read_mechanics;
use bondmech::Scene;

#[test]
fn every_constraint_junction_closure_differentiates_to_its_flow_sum_at_50_random_states() {
    let mut checked = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for path in common::bundled_scene_paths() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let scene = Scene::from_path(&path).unwrap();
        if scene.bond_graph.is_some() {
            continue;
        }
        for j in &scene.joints {
            kinds.insert(j.kind.type_name());
        }
        let model = bondmech::Model::new(&scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        let graph = model
            .mechanism()
            .and_then(|m| m.bond_graph.clone())
            .expect("a mechanism has a bond graph");
        let mut eqs = read_mechanics(&graph).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!eqs.rows.is_empty() || scene.joints.is_empty(), "{name}");
        let nq = eqs.nq();
        let x0 = eqs.initial_slots();
        let mut rnd = common::uniform(0x5eed ^ name.len() as u64);
        // 50 states: coordinates within ±0.5 of the initial ones, velocities in [−2, 2), t in
        // [0, 1)
        let states: Vec<Vec<f64>> = (0..50)
            .map(|_| {
                x0.iter()
                    .enumerate()
                    .map(|(k, &x)| match k {
                        0 => 0.5 + 0.5 * rnd(),
                        k if k <= nq => x + 0.5 * rnd(),
                        _ => 2.0 * rnd(),
                    })
                    .collect()
            })
            .collect();
        let rows: Vec<_> = eqs.rows.clone();
        for r in &rows {
            let g = r.closure.unwrap_or_else(|| {
                panic!("{name}: {}.{} carries no closure", r.joint, r.direction)
            });
            let eg = &mut eqs.graph;
            let mut terms = vec![eg.diff(g, 0)];
            for s in eg.vars(g) {
                let k = s as usize;
                if (1..=nq).contains(&k) {
                    let d = eg.diff(g, s);
                    terms.push(eg.mul(d, eqs.kinematics[k - 1]));
                }
            }
            let rate = eg.sum(&terms);
            for x in &states {
                let (u, w) = (eg.eval(rate, x), eg.eval(r.flow, x));
                let m = (u - w).abs() / (1.0 + u.abs().max(w.abs()));
                assert!(
                    m <= 1e-12,
                    "{name}: {}.{}: dg/dt = {u} but the junction's flow sum is {w} (relative {m:e})",
                    r.joint,
                    r.direction
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 50, "only {checked} rows checked");
    for k in [
        "revolute",
        "spherical",
        "prismatic",
        "gear",
        "slot",
        "rack_pinion",
        "universal",
    ] {
        assert!(
            kinds.contains(k),
            "no bundled scene uses a {k} joint: {kinds:?}"
        );
    }
}
