//! Independent reference models for bondmech's accuracy tests.
//!
//! Every model here is derived by hand in minimal coordinates (Lagrange's
//! equations in joint angles) and integrated by [`integrate::integrate`], an
//! adaptive Dormand–Prince 5(4) integrator written for these tests. Nothing in
//! this module uses `bondmech`: the references must stay independent of the
//! code they check.
//!
//! Conventions (those of `docs/scene-format.md`): planar, global X right, Y up,
//! gravity (0, −g); a body's angle is the angle of its body x-axis from global
//! X, counter-clockwise; a uniform bar of length L has its points O = (−L/2, 0)
//! and A = (+L/2, 0) in body coordinates and inertia m L²/12 about its centre.
//! Results are returned in global terms (centre positions, absolute angles,
//! their rates, named point positions, energy).
#![allow(dead_code)]

pub mod bead_in_slot;
pub mod bricard;
pub mod double_pendulum;
pub mod elliptic;
pub mod examples;
pub mod five_bar;
pub mod four_bar_chain;
pub mod heavy_top;
pub mod integrate;
pub mod n_link;
pub mod rigid_body;
pub mod slider_crank;
pub mod spherical_pendulum;

/// Relative tolerance used by every reference model.
pub const REFERENCE_RTOL: f64 = 1e-13;
/// Absolute tolerance used by every reference model.
pub const REFERENCE_ATOL: f64 = 1e-13;

/// The bundled scenes' files (`scenes/*.json`), sorted by name.
pub fn bundled_scene_paths() -> Vec<std::path::PathBuf> {
    let dir = format!("{}/scenes", env!("CARGO_MANIFEST_DIR"));
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .expect("scenes/ is readable")
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    v.sort();
    v
}

/// A small deterministic pseudo-random sequence, uniform in [−1, 1) (a 64-bit linear
/// congruential generator, Knuth's MMIX constants; the top 53 bits).
pub fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}
