//! Spatial slider-crank with two spherical joints (scene `scenes/spatial_slider_crank.json`):
//! crank (r = 0.3 m) hinged to ground about Z at the origin, coupler (ℓ = 1.2 m) on spherical
//! joints at the crank tip B and at a point-mass slider S on a rail along Z through (a, 0, 0),
//! a = 0.6 m; gravity −Y, no drive. Reference: the exact 1-DOF model derived by hand below.
//!
//! Loop closure (in the crank angle θ): B = r(cos θ, sin θ, 0), S = (a, 0, s) with
//! |S − B| = ℓ, so s(θ) = √(ℓ² − r² + 2ar cos θ − a²) (the branch s > 0), s' = −a r sin θ / s.
//! Coupler: centre c = (B + S)/2, unit axis d = (S − B)/ℓ. Both spherical joints act through the
//! coupler's axis and gravity through its centre, so for the axisymmetric coupler the spin about
//! d keeps its initial value 0 (Euler, axial component: J_a ω̇_a = 0) and its angular velocity is
//! d × ḋ, of magnitude |ḋ|. Kinetic energy `T = ½ M(θ) θ̇²` with
//! `M = J_O + m_c |c'|² + J_t |d'|² + m_s s'²` (J_O = m_k r²/3 crank about its pivot,
//! J_t = m_c ℓ²/12), potential `V = g (m_k + m_c)(r/2) sin θ` (slider at y = 0). Lagrange:
//! `M θ̈ + ½ M' θ̇² + V' = 0`, integrated by the tests' own Dormand–Prince integrator.

mod common;

use bondmech::{Model, Scene};
use common::integrate::integrate;
use common::{REFERENCE_ATOL, REFERENCE_RTOL};

const G: f64 = 9.81;
const R: f64 = 0.3;
const A: f64 = 0.6;
const L: f64 = 1.2;
const OMEGA0: f64 = 8.0;

fn slider(theta: f64) -> (f64, f64) {
    let s = (L * L - R * R + 2.0 * A * R * theta.cos() - A * A).sqrt();
    (s, -A * R * theta.sin() / s)
}

/// Generalized mass M(θ) of the hand-derived model (all bodies 1 kg).
fn mass(theta: f64) -> f64 {
    let (s, ds) = slider(theta);
    let db = [-R * theta.sin(), R * theta.cos(), 0.0];
    let dsv = [0.0, 0.0, ds];
    let _ = s;
    let dc: f64 = (0..3).map(|i| (0.5 * (db[i] + dsv[i])).powi(2)).sum();
    let dd: f64 = (0..3).map(|i| ((dsv[i] - db[i]) / L).powi(2)).sum();
    R * R / 3.0 + dc + L * L / 12.0 * dd + ds * ds
}

fn model() -> Model {
    let json = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/spatial_slider_crank.json"
    ))
    .expect("scene file");
    Model::new(&Scene::from_json_str(&json).expect("scene is valid")).expect("model builds")
}

#[test]
fn spatial_slider_crank_conserves_energy_and_matches_hand_derived_1dof_lagrange_model() {
    check_spatial_slider_crank(None);
}

#[test]
fn partitioned_spatial_slider_crank_conserves_energy_and_matches_hand_derived_1dof_lagrange_model()
{
    check_spatial_slider_crank(Some(bondmech::FormulationKind::Partitioned));
}

fn check_spatial_slider_crank(formulation: Option<bondmech::FormulationKind>) {
    let m = model();
    let mut o = m.default_options();
    if let Some(f) = formulation {
        o.formulation = f;
    }
    let times: Vec<f64> = (0..=100).map(|i| 0.05 * i as f64).collect();
    o.output_times = times.clone();
    let s = m.solve(&o).expect("solves");
    let sm = &s.summary;
    assert!(sm.redundant_joints.is_empty(), "{sm:?}");
    assert!(
        sm.initial_velocity_correction < 1e-12,
        "the scene's velocities are consistent"
    );

    // energy: E(0) = ½ M(0) ω0² (θ = 0 is at V = 0)
    let e0 = 0.5 * mass(0.0) * OMEGA0 * OMEGA0;
    let energy = s.column("energy").unwrap();
    assert!(
        (energy[0] - e0).abs() < 1e-12,
        "E(0) = {} vs {e0}",
        energy[0]
    );
    let drift = energy.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max);
    eprintln!("energy drift {drift:e} J of {e0} J");
    // measured 4.6e-6 J over 5 s at rtol 1e-8 (it grows with the number of steps); 4x margin
    assert!(drift < 2e-5, "energy drift {drift:e} J");

    let cerr = s.column("constraint_error").unwrap();
    let worst = cerr.iter().fold(0.0_f64, |a, &b| a.max(b));
    assert!(worst < 1e-8, "constraint error {worst:e}");

    // the coupler's free spin (tiny axial inertia) stays at its initial value 0
    let spin = s.column("coupler.wx").unwrap();
    let worst_spin = spin.iter().fold(0.0_f64, |a, &b| a.max(b.abs()));
    eprintln!("max coupler spin {worst_spin:e} rad/s");
    // measured 3.5e-13 rad/s: nothing drives the spin, though its inertia is only 1e-4 kg m²
    assert!(worst_spin < 1e-9, "coupler spin {worst_spin:e} rad/s");

    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        let h = 1e-5;
        let dm = (mass(y[0] + h) - mass(y[0] - h)) / (2.0 * h);
        let dv = G * 2.0 * 0.5 * R * y[0].cos();
        dy[0] = y[1];
        dy[1] = -(0.5 * dm * y[1] * y[1] + dv) / mass(y[0]);
    };
    let reference = integrate(
        rhs,
        0.0,
        &[0.0, OMEGA0],
        &times,
        REFERENCE_RTOL,
        REFERENCE_ATOL,
    );
    let (mut worst_b, mut worst_s) = (0.0_f64, 0.0_f64);
    for (k, y) in reference.iter().enumerate() {
        let bx = s.value(k, "crank.A.x").unwrap();
        let by = s.value(k, "crank.A.y").unwrap();
        worst_b = worst_b.max((bx - R * y[0].cos()).hypot(by - R * y[0].sin()));
        let sz = s.value(k, "slider.C.z").unwrap();
        worst_s = worst_s.max((sz - slider(y[0]).0).abs());
    }
    eprintln!("max |B - B_ref| {worst_b:e} m, max |s - s_ref| {worst_s:e} m");
    // measured 6.7e-6 m and 3.8e-6 m over 5 s at the scene's rtol 1e-8 (a phase error that grows
    // with time; 1.1e-7 m and 6.5e-8 m at rtol 1e-10, so the gap is the
    // solver tolerance, not the model), bound 3x the rtol-1e-8 figures
    assert!(
        worst_b < 2e-5,
        "crank tip off the 1-DOF model by {worst_b:e} m"
    );
    assert!(
        worst_s < 2e-5,
        "slider off the 1-DOF model by {worst_s:e} m"
    );
}
