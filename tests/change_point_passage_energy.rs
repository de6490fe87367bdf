//! Passages through a change point do not dissipate (issue 46, the trial's F3).
//!
//! The change-point four-bar of `tests/references/trial/findings/f3_…` (ground 1.0, crank 0.3,
//! coupler 0.9, rocker 0.4: `0.3 + 1.0 = 0.9 + 0.4`, crank spinning at 6 rad/s, gravity)
//! lies on the ground line, every link aligned, whenever the crank points at π: there its two
//! assembly branches cross and the joints lose rank. The scene has no damper, no driver and no
//! load: its energy is conserved (the reference is the conservation law, nothing of bondmech).
//! Every formulation lost 1.75e-5 J (3e-6 of E) at every other passage, whatever the
//! tolerance: the compliant GGL that carries the passage (`G v − ελ = 0`) absorbed `ε|λ|²`.
//!
//! The property: at rtol 1e-8 and 1e-10 (atol rtol / 100), in every formulation that passes
//! singular configurations by a switch to the compliant GGL (`index1` does not claim to: it
//! stops at the fifth passage, naming the block; `compliant_ggl`, compliant from the start,
//! keeps its joints' loss: see `GglFormulation`'s documentation), the largest energy change across a passage shrinks with the tolerance; issue
//! 46's bar of `10 × rtol × E` is the ignored test below, with where it stands.

use bondmech::{FormulationKind, Model, Scene};
use std::f64::consts::PI;

const SCENE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/references/trial/findings/f3_change_point_four_bar.json"
);

/// Half the window around a passage over which its energy change is read (s): the crank turns
/// at 6–10 rad/s, so the aligned configuration is left well inside it, and the next passage is
/// 0.4 s away.
const WINDOW: f64 = 0.05;

/// The largest energy change across a passage and the number of passages, for one formulation
/// at one tolerance.
fn passage_losses(formulation: FormulationKind, rtol: f64) -> (f64, usize, f64) {
    let json = std::fs::read_to_string(SCENE).expect("the finding's scene");
    let m = Model::new(&Scene::from_json_str(&json).expect("valid")).expect("builds");
    let mut o = m.default_options();
    o.formulation = formulation;
    o.rtol = rtol;
    o.atol = rtol / 100.0;
    let sol = m
        .solve(&o)
        .unwrap_or_else(|e| panic!("{formulation:?} at rtol {rtol:e}: {e}"));
    assert!(sol.summary.completed, "{formulation:?}: {:?}", sol.summary);
    let angle = sol.column("crank.angle").expect("crank.angle");
    let energy = sol.column("energy").expect("energy");
    let t = &sol.times;
    let e0 = energy[0];
    // a passage: the crank angle crosses π + 2πk (the column is continuous, not wrapped)
    let branch = |a: f64| ((a - PI) / (2.0 * PI)).floor();
    let mut worst = 0.0f64;
    let mut passages = 0;
    for i in 1..t.len() {
        if branch(angle[i - 1]) == branch(angle[i]) {
            continue;
        }
        let before = (0..i).rev().find(|&k| t[k] <= t[i] - WINDOW);
        let after = (i..t.len()).find(|&k| t[k] >= t[i] + WINDOW);
        if let (Some(b), Some(a)) = (before, after) {
            passages += 1;
            worst = worst.max((energy[a] - energy[b]).abs());
        }
    }
    (worst, passages, e0)
}

/// The largest energy change across a passage at rtol 1e-8 and 1e-10, and the energy.
fn losses(formulation: FormulationKind) -> ([f64; 2], f64) {
    let mut worst = [0.0; 2];
    let mut energy = 0.0;
    for (k, rtol) in [1e-8, 1e-10].into_iter().enumerate() {
        let (loss, passages, e0) = passage_losses(formulation, rtol);
        assert!(passages >= 5, "{formulation:?}: {passages} passages read");
        eprintln!(
            "{formulation:?} rtol {rtol:e}: largest energy change across a passage {loss:.2e} J = {:.1} × rtol × E ({passages} passages)",
            loss / (rtol * e0)
        );
        worst[k] = loss;
        energy = e0;
    }
    (worst, energy)
}

/// What passed a change point lost the same energy at every tolerance (1.75e-5 J at rtol
/// 1e-8 and 1e-10 alike); now the change shrinks with the tolerance, at least 5× for 100×.
fn shrinks(formulation: FormulationKind) {
    let ([loose, tight], _) = losses(formulation);
    assert!(
        tight * 5.0 <= loose,
        "{formulation:?}: the passages' energy change does not shrink with rtol: {loose:.3e} J at rtol 1e-8, {tight:.3e} J at 1e-10"
    );
}

/// Issue 46's bar: at most 10 × rtol × E per passage. Not met yet (one run, release): the
/// largest change at rtol 1e-8 / 1e-10 is 8.0e-7 / 2.9e-8 J on `dae`, 4.9e-7 / 2.0e-8 on
/// `ggl`, 5.0e-7 / 6.9e-8 on `partitioned`, against
/// 5.7e-7 / 5.7e-9 (E = 5.73 J): the compliant joints now give back what they absorb
/// (`tests/compliant_ggl_power_balance.rs`); what is left is IDA's error over the passage's
/// many small steps.
fn within_the_bar(formulation: FormulationKind) {
    let (worst, energy) = losses(formulation);
    for (loss, rtol) in worst.into_iter().zip([1e-8, 1e-10]) {
        assert!(
            loss <= 10.0 * rtol * energy,
            "{formulation:?} at rtol {rtol:e}: a passage changed the energy by {loss:.3e} J, more than 10 × rtol × E = {:.3e}",
            10.0 * rtol * energy
        );
    }
}

#[test]
fn regression_the_default_lost_the_same_energy_at_every_tolerance() {
    shrinks(FormulationKind::Dae);
}

#[test]
fn regression_the_ggl_lost_the_same_energy_at_every_tolerance() {
    shrinks(FormulationKind::Ggl);
}

#[test]
fn regression_the_partitioned_formulation_lost_the_same_energy_at_every_tolerance() {
    shrinks(FormulationKind::Partitioned);
}

#[test]
#[ignore = "issue 46's bar of 10 × rtol × E per passage is not met yet: see within_the_bar"]
fn every_passage_within_ten_rtol_of_the_energy() {
    for f in [
        FormulationKind::Dae,
        FormulationKind::Ggl,
        FormulationKind::Partitioned,
    ] {
        within_the_bar(f);
    }
}
