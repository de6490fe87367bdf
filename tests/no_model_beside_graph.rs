//! No model of the mechanism beside its bond graph: for every bundled mechanism scene, each
//! constraint junction's closure `g_k(x)`, differentiated along the graph's own flows
//! (`d/dt g_k = ∂g_k/∂t + Σ_i ∂g_k/∂x_i · x_i'`, with `x_i'` the flow of the junction whose
//! displacement `x_i` is), equals the junction's flow sum `G_k v` read off the graph, at 50
//! random states (coordinates far from the start, velocities random) to 1e-12.
//!
//! Both sides come from the graph `bondmech graph` draws ([`Model::bond_graph`]): the
//! closures and displacements it carries as annotations, the flow sums from its junctions
//! and bonds. What the solvers solve is read off the same graph; a closure written by a
//! second model that disagreed with the graph's junctions would fail here.

mod common;

use bondmech::bond::mechanics::read_mechanics;
use bondmech::{Model, Scene};

/// A small deterministic generator (splitmix64) for the random states.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }
}

#[test]
fn every_closure_differentiated_along_the_graph_flows_is_its_junction_flow_sum() {
    let mut rng = Rng(20261125);
    let mut rows_checked = 0;
    let mut scenes_checked = 0;
    for path in common::bundled_scene_paths() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let scene = Scene::from_path(&path).unwrap();
        if scene.bond_graph.is_some() {
            continue;
        }
        let model = Model::new(&scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        let graph = model.bond_graph().unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut eqs = read_mechanics(&graph).unwrap_or_else(|e| panic!("{name}: {e}"));
        let nq = eqs.nq();
        let x0 = eqs.initial_slots();
        let mut closures = 0;
        for r in eqs.rows.clone() {
            let Some(g) = r.closure else { continue };
            closures += 1;
            // d/dt g along the graph's own flows: ∂g/∂t + Σ ∂g/∂x_i · K_i(x) v
            let mut terms = vec![eqs.graph.diff(g, 0)];
            for s in eqs.graph.vars(g) {
                let k = s as usize;
                if (1..=nq).contains(&k) {
                    let d = eqs.graph.diff(g, s);
                    terms.push(eqs.graph.mul(d, eqs.kinematics[k - 1]));
                }
            }
            let rate = eqs.graph.sum(&terms);
            for _ in 0..50 {
                let mut slots = x0.clone();
                slots[0] = rng.uniform(0.0, 2.0);
                for (k, v) in slots.iter_mut().enumerate().skip(1) {
                    *v = if k <= nq {
                        *v + rng.uniform(-1.5, 1.5)
                    } else {
                        rng.uniform(-3.0, 3.0)
                    };
                }
                let (a, b) = (eqs.graph.eval(rate, &slots), eqs.graph.eval(r.flow, &slots));
                assert!(
                    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs())),
                    "{name}: joint '{}' ({}): d/dt g = {a:e}, junction flow sum {b:e}",
                    r.joint,
                    r.direction
                );
            }
        }
        assert_eq!(
            closures,
            eqs.rows.len(),
            "{name}: every constraint junction of a mechanism's graph carries its closure"
        );
        rows_checked += closures;
        scenes_checked += 1;
    }
    assert!(scenes_checked >= 12, "{scenes_checked} mechanism scenes");
    assert!(rows_checked >= 100, "{rows_checked} rows");
}
