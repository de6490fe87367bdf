//! Causality by matching and numeric rank (issue 13, item 5).

use bondmech::bond::causality::generic_value;
use bondmech::bond::rank::constraint_rank;
use bondmech::graph::SceneGraph;
use bondmech::mech::Variant;
use bondmech::Scene;

#[test]
#[ignore]
fn debug_ranks() {
    for s in ["bricard", "hinged_double_pendulum_3d", "double_pendulum"] {
        let scene = Scene::from_path(format!("scenes/{s}.json")).unwrap();
        let g = SceneGraph::new(&scene, Variant::Pinned).unwrap().graph;
        let gen = |n: &str| Some(generic_value(n));
        let r = constraint_rank(&g, 0.0, &gen, &[], &vec![false; g.elements.len()]);
        let vals = bondmech::graph::initial_values(&scene);
        let st = |n: &str| vals.get(n).copied().or(Some(generic_value(n)));
        let r2 = constraint_rank(&g, 0.0, &st, &[], &vec![false; g.elements.len()]);
        eprintln!("{s}: generic {} state {} rows {}", r.rank, r2.rank, r.rows);
    }
}
