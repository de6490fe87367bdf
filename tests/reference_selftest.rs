//! Self-tests of the independent reference models in `tests/common/`: each
//! model is checked against a closed form, a published table, a conservation
//! law or another model derived separately — never against bondmech.

mod common;

use std::f64::consts::{FRAC_PI_2, PI};

use common::double_pendulum::{simulate_double_pendulum, DoublePendulum};
use common::elliptic::{elliptic_k, jacobi_sn_cn, pendulum_angle, pendulum_period};
use common::four_bar_chain::{simulate_four_bar_chain, FourBarChain};
use common::integrate::integrate;
use common::n_link::{simulate_n_link, NLinkPendulum};
use common::rigid_body::{cardan_angles, cardan_matrix, simulate_rigid_body, RigidBody};
use common::slider_crank::{simulate_slider_crank, SliderCrank};
use nalgebra::{Matrix3, Vector3};

fn grid(t_end: f64, count: usize) -> Vec<f64> {
    (1..=count)
        .map(|i| t_end * i as f64 / count as f64)
        .collect()
}

// ---------------------------------------------------------------- integrator

#[test]
fn integrator_reproduces_harmonic_oscillator_cos_sin_to_1e_11() {
    let times = grid(20.0, 200);
    let ys = integrate(
        |_t, y, dy| {
            dy[0] = y[1];
            dy[1] = -y[0];
        },
        0.0,
        &[1.0, 0.0],
        &times,
        1e-13,
        1e-13,
    );
    for (t, y) in times.iter().zip(&ys) {
        assert!(
            (y[0] - t.cos()).abs() < 1e-11,
            "x({t}) = {} vs cos = {}",
            y[0],
            t.cos()
        );
        assert!(
            (y[1] + t.sin()).abs() < 1e-11,
            "v({t}) = {} vs -sin = {}",
            y[1],
            -t.sin()
        );
    }
}

#[test]
fn integrator_reproduces_exponential_decay_to_1e_11_relative() {
    let times = grid(10.0, 50);
    let ys = integrate(|_t, y, dy| dy[0] = -y[0], 0.0, &[1.0], &times, 1e-13, 1e-30);
    for (t, y) in times.iter().zip(&ys) {
        let exact = (-t).exp();
        assert!(
            ((y[0] - exact) / exact).abs() < 1e-11,
            "y({t}) = {} vs {exact}",
            y[0]
        );
    }
}

#[test]
fn integrator_returns_initial_value_at_start_time_and_handles_repeated_times() {
    let ys = integrate(
        |_t, y, dy| dy[0] = y[0],
        0.0,
        &[2.0],
        &[0.0, 1.0, 1.0],
        1e-13,
        1e-13,
    );
    assert_eq!(ys[0], vec![2.0]);
    assert_eq!(ys[1], ys[2]);
    assert!((ys[1][0] - 2.0 * 1f64.exp()).abs() < 1e-11);
}

#[test]
fn integrator_error_shrinks_with_tolerance_on_time_dependent_problem() {
    // y' = cos t · y, y(0) = 1  →  y = exp(sin t).
    let exact = 5f64.sin().exp();
    let err = |tol: f64| {
        let y = integrate(
            |t, y, dy| dy[0] = t.cos() * y[0],
            0.0,
            &[1.0],
            &[5.0],
            tol,
            tol,
        );
        (y[0][0] - exact).abs()
    };
    let (coarse, fine) = (err(1e-6), err(1e-12));
    assert!(coarse < 1e-4 && fine < 1e-11, "errors {coarse:e}, {fine:e}");
    assert!(fine < coarse * 1e-3, "errors {coarse:e} -> {fine:e}");
}

// ------------------------------------------------------------------ elliptic

#[test]
fn jacobi_sn_cn_match_abramowitz_stegun_and_identities() {
    // m = 0: sn = sin; sn² + cn² = 1; sn(K) = 1 (A&S 16.5)
    let (s, c) = jacobi_sn_cn(0.7, 0.0);
    assert!((s - 0.7f64.sin()).abs() < 1e-15 && (c - 0.7f64.cos()).abs() < 1e-15);
    let (s, c) = jacobi_sn_cn(1.3, 0.6);
    assert!((s * s + c * c - 1.0).abs() < 1e-14, "{s} {c}");
    let (s, _) = jacobi_sn_cn(elliptic_k(0.5), 0.5);
    assert!((s - 1.0).abs() < 1e-14, "{s}");
}

#[test]
fn exact_pendulum_angle_matches_integrated_pendulum_released_horizontal() {
    // θ'' = −(g/L) sin θ from θ0 = π/2 at rest, integrated by the tests' Dormand–Prince
    let (l, g, a) = (1.0, 9.81, FRAC_PI_2);
    let times: Vec<f64> = (0..=40).map(|i| 0.25 * i as f64).collect();
    let ys = integrate(
        |_t, y, dy| {
            dy[0] = y[1];
            dy[1] = -(g / l) * y[0].sin();
        },
        0.0,
        &[a, 0.0],
        &times,
        1e-12,
        1e-12,
    );
    for (t, y) in times.iter().zip(&ys) {
        let exact = pendulum_angle(l, g, a, *t);
        assert!((exact - y[0]).abs() < 1e-9, "t = {t}: {exact} vs {}", y[0]);
    }
}

#[test]
fn elliptic_k_at_zero_is_half_pi() {
    assert!((elliptic_k(0.0) - FRAC_PI_2).abs() < 1e-15);
}

#[test]
fn elliptic_k_at_one_half_matches_abramowitz_stegun_table_17_1() {
    // A&S table 17.1: K(m = 0.5) = 1.85407 46773 01372.
    assert!((elliptic_k(0.5) - 1.854_074_677_301_372).abs() < 1e-14);
}

#[test]
fn pendulum_period_matches_small_amplitude_series() {
    // T = 2π sqrt(L/g) (1 + θ0²/16 + 11 θ0⁴/3072 + O(θ0⁶)).
    let (l, g, a): (f64, f64, f64) = (0.7, 9.81, 0.05);
    let series = 2.0 * PI * (l / g).sqrt() * (1.0 + a * a / 16.0 + 11.0 * a.powi(4) / 3072.0);
    let exact = pendulum_period(l, g, a);
    assert!(
        ((exact - series) / exact).abs() < 1e-9,
        "{exact} vs {series}"
    );
}

#[test]
fn pendulum_period_matches_integrated_simple_pendulum_at_large_amplitude() {
    let (l, g, a) = (1.3, 9.81, 2.5);
    let period = pendulum_period(l, g, a);
    let ys = integrate(
        |_t, y, dy| {
            dy[0] = y[1];
            dy[1] = -(g / l) * y[0].sin();
        },
        0.0,
        &[a, 0.0],
        &[0.5 * period, period],
        1e-13,
        1e-13,
    );
    assert!(
        (ys[0][0] + a).abs() < 1e-9 && ys[0][1].abs() < 1e-9,
        "half period {:?}",
        ys[0]
    );
    assert!(
        (ys[1][0] - a).abs() < 1e-9 && ys[1][1].abs() < 1e-9,
        "full period {:?}",
        ys[1]
    );
}

// ----------------------------------------------------------- double pendulum

const DP: DoublePendulum = DoublePendulum {
    m1: 1.0,
    l1: 1.0,
    m2: 0.7,
    l2: 1.4,
    g: 9.81,
};

#[test]
fn double_pendulum_conserves_energy_to_1e_10_over_3_s() {
    let states = simulate_double_pendulum(&DP, [0.0, 0.3, 0.0, 1.0], &grid(3.0, 300));
    let e0 = DP.state(0.0, 0.0, 0.3, 0.0, 1.0).energy;
    for s in &states {
        assert!(
            (s.energy - e0).abs() < 1e-10 * e0.abs().max(1.0),
            "E({}) = {} vs {e0}",
            s.t,
            s.energy
        );
    }
    // The motion is large: the tip really moved.
    assert!(states.iter().any(|s| s.a2[1] < -1.5));
}

#[test]
fn double_pendulum_small_oscillations_follow_linearised_normal_modes() {
    let eps = 1e-4;
    for (omega, shape) in DP.normal_modes() {
        let initial = [
            -FRAC_PI_2 + eps * shape[0],
            -FRAC_PI_2 + eps * shape[1],
            0.0,
            0.0,
        ];
        let period = 2.0 * PI / omega;
        let times = grid(3.0 * period, 120);
        for s in simulate_double_pendulum(&DP, initial, &times) {
            let c = (omega * s.t).cos();
            let e1 = s.theta1 - (-FRAC_PI_2 + eps * shape[0] * c);
            let e2 = s.theta2 - (-FRAC_PI_2 + eps * shape[1] * c);
            assert!(
                e1.abs() < 1e-6 * eps && e2.abs() < 1e-6 * eps,
                "mode ω = {omega}: t = {}, errors {e1:e}, {e2:e}",
                s.t
            );
        }
    }
}

#[test]
fn double_pendulum_positions_are_consistent_with_the_joints() {
    let s = DP.state(0.0, 0.4, -1.1, 0.3, -0.8);
    // Bar 2's O (= a1 − (L2/2) e2 from its centre) coincides with bar 1's A.
    let o2 = [
        s.c2[0] - 0.7 * (-1.1f64).cos(),
        s.c2[1] - 0.7 * (-1.1f64).sin(),
    ];
    assert!((o2[0] - s.a1[0]).abs() < 1e-15 && (o2[1] - s.a1[1]).abs() < 1e-15);
    assert!((s.c1[0].hypot(s.c1[1]) - 0.5).abs() < 1e-15);
}

// -------------------------------------------------------------------- n-link

#[test]
fn n_link_with_two_links_matches_double_pendulum() {
    let p = NLinkPendulum {
        masses: vec![DP.m1, DP.m2],
        lengths: vec![DP.l1, DP.l2],
        g: DP.g,
    };
    let times = grid(3.0, 30);
    let a = simulate_n_link(&p, &[0.2, -0.5], &[1.0, -2.0], &times);
    let b = simulate_double_pendulum(&DP, [0.2, -0.5, 1.0, -2.0], &times);
    for (x, y) in a.iter().zip(&b) {
        assert!((x.theta[0] - y.theta1).abs() < 1e-9 && (x.theta[1] - y.theta2).abs() < 1e-9);
        assert!((x.tips[1][0] - y.a2[0]).abs() < 1e-9 && (x.tips[1][1] - y.a2[1]).abs() < 1e-9);
    }
}

#[test]
fn n_link_with_one_link_has_exact_physical_pendulum_period() {
    // Uniform bar about its end: equivalent length J/(m d) = (L²/3)/(L/2) = 2L/3.
    let (l, amp) = (1.2, 1.0);
    let p = NLinkPendulum {
        masses: vec![2.0],
        lengths: vec![l],
        g: 9.81,
    };
    let period = pendulum_period(2.0 * l / 3.0, 9.81, amp);
    let s = simulate_n_link(&p, &[-FRAC_PI_2 + amp], &[0.0], &[period]);
    assert!((s[0].theta[0] - (-FRAC_PI_2 + amp)).abs() < 1e-9 && s[0].omega[0].abs() < 1e-9);
}

#[test]
fn n_link_conserves_energy_for_one_to_eight_links() {
    for n in [1, 2, 3, 5, 8] {
        let p = NLinkPendulum {
            masses: (0..n).map(|k| 1.0 + 0.1 * k as f64).collect(),
            lengths: (0..n).map(|k| 1.0 - 0.05 * k as f64).collect(),
            g: 9.81,
        };
        let theta0: Vec<f64> = (0..n).map(|k| 0.3 * k as f64).collect();
        let omega0 = vec![0.0; n];
        let e0 = p.state(0.0, &theta0, &omega0).energy;
        let states = simulate_n_link(&p, &theta0, &omega0, &grid(2.0, 20));
        for s in &states {
            assert!(
                (s.energy - e0).abs() < 1e-9 * e0.abs().max(1.0),
                "N = {n}: E({}) = {} vs {e0}",
                s.t,
                s.energy
            );
        }
    }
}

// -------------------------------------------------------------- slider-crank

const SC: SliderCrank = SliderCrank {
    r: 0.3,
    m_crank: 1.0,
    l: 0.9,
    m_rod: 0.8,
    m_piston: 0.5,
    g: 9.81,
    torque: 0.0,
    branch: 1.0,
};

#[test]
fn slider_crank_conserves_energy_without_torque_or_piston_force() {
    let initial = [0.2, 12.0];
    let e0 = SC.state(0.0, initial[0], initial[1]).energy;
    let states = simulate_slider_crank(&SC, initial, |_| 0.0, &grid(3.0, 300));
    for s in &states {
        assert!(
            (s.energy - e0).abs() < 1e-10 * e0.abs().max(1.0),
            "E({}) = {} vs {e0}",
            s.t,
            s.energy
        );
    }
    // The crank went round more than once (through both dead centres).
    assert!(states.last().unwrap().phi > 0.2 + 2.0 * PI);
}

#[test]
fn slider_crank_piston_follows_closed_form_kinematics_and_rod_joins_pin_and_piston() {
    let states = simulate_slider_crank(&SC, [0.2, 12.0], |_| 0.0, &grid(2.0, 100));
    let (r, l) = (SC.r, SC.l);
    for s in &states {
        let y = r * s.phi.sin() + (l * l - r * r * s.phi.cos().powi(2)).sqrt();
        assert!(
            (s.piston_y - y).abs() < 1e-14,
            "φ = {}: {} vs {y}",
            s.phi,
            s.piston_y
        );
        // Rod: from the crank pin to the piston at (0, y), length l, angle β.
        let d = [0.0 - s.crank_pin[0], s.piston_y - s.crank_pin[1]];
        assert!((d[0].hypot(d[1]) - l).abs() < 1e-13);
        assert!(
            (s.rod_angle.cos() * l - d[0]).abs() < 1e-13
                && (s.rod_angle.sin() * l - d[1]).abs() < 1e-13
        );
        assert!((s.rod_centre[0] - (s.crank_pin[0] + 0.5 * d[0])).abs() < 1e-14);
        assert!((s.rod_centre[1] - (s.crank_pin[1] + 0.5 * d[1])).abs() < 1e-14);
    }
    // Rod angle is continuous along the motion.
    for w in states.windows(2) {
        assert!((w[1].rod_angle - w[0].rod_angle).abs() < 0.5);
    }
}

#[test]
fn slider_crank_velocity_squared_term_is_half_the_derivative_of_reduced_inertia() {
    for branch in [1.0, -1.0] {
        let p = SliderCrank { branch, ..SC };
        for i in 0..24 {
            let phi = 0.1 + i as f64 * PI / 12.0;
            let h = 1e-5;
            let fd =
                0.5 * (p.reduced_inertia(phi + h).0 - p.reduced_inertia(phi - h).0) / (2.0 * h);
            let half_dj = p.reduced_inertia(phi).1;
            assert!(
                (half_dj - fd).abs() < 1e-8,
                "σ = {branch}, φ = {phi}: {half_dj} vs {fd}"
            );
        }
    }
}

#[test]
fn slider_crank_energy_change_equals_work_of_torque_and_constant_piston_force() {
    let p = SliderCrank { torque: 1.5, ..SC };
    let f0 = -20.0;
    let initial = [0.0, 3.0];
    let s0 = p.state(0.0, initial[0], initial[1]);
    for s in simulate_slider_crank(&p, initial, |_| f0, &grid(2.0, 50)) {
        let work = p.torque * (s.phi - s0.phi) + f0 * (s.piston_y - s0.piston_y);
        assert!(
            (s.energy - s0.energy - work).abs() < 1e-10,
            "t = {}: ΔE = {}, W = {work}",
            s.t,
            s.energy - s0.energy
        );
    }
}

#[test]
fn slider_crank_lower_branch_conserves_energy_and_keeps_piston_below() {
    let p = SliderCrank { branch: -1.0, ..SC };
    let initial = [1.0, -10.0];
    let e0 = p.state(0.0, initial[0], initial[1]).energy;
    for s in simulate_slider_crank(&p, initial, |_| 0.0, &grid(2.0, 100)) {
        assert!((s.energy - e0).abs() < 1e-10 * e0.abs().max(1.0));
        assert!(s.piston_y < s.crank_pin[1] && s.rod_angle < 0.0);
    }
}

// ---------------------------------------------------------------- rigid body

#[test]
fn rigid_body_conserves_global_momentum_and_energy_to_1e_10() {
    let body = RigidBody {
        inertia: [1.0, 2.0, 3.5],
    };
    let w0 = Vector3::new(0.3, 2.0, -0.7);
    let r0 = cardan_matrix(0.4, -0.3, 1.2);
    let s0 = body.state(0.0, w0, r0);
    for s in simulate_rigid_body(&body, w0, r0, &grid(10.0, 100)) {
        assert!(
            (s.momentum_global - s0.momentum_global).norm() < 1e-10 * s0.momentum_global.norm()
        );
        assert!((s.energy - s0.energy).abs() < 1e-10 * s0.energy);
        let orth = s.rotation.transpose() * s.rotation - Matrix3::identity();
        assert!(orth.norm() < 1e-10 && (s.rotation.determinant() - 1.0).abs() < 1e-10);
    }
}

#[test]
fn symmetric_rigid_body_rates_precess_at_analytic_frequency() {
    // J1 = J2: ω3 constant, (ω1, ω2) = A (cos Ωt, sin Ωt), Ω = (J3 − J1) ω3 / J1.
    let (j1, j3, w3, a) = (2.0, 3.0, 1.7, 0.4);
    let body = RigidBody {
        inertia: [j1, j1, j3],
    };
    let big_omega = (j3 - j1) * w3 / j1;
    for s in simulate_rigid_body(
        &body,
        Vector3::new(a, 0.0, w3),
        Matrix3::identity(),
        &grid(8.0, 40),
    ) {
        let exact = Vector3::new(a * (big_omega * s.t).cos(), a * (big_omega * s.t).sin(), w3);
        assert!(
            (s.omega_body - exact).norm() < 1e-11,
            "t = {}: {} vs {exact}",
            s.t,
            s.omega_body
        );
    }
}

/// Rotation by `angle` about the unit `axis` (Rodrigues' formula).
fn rodrigues(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let k = Matrix3::new(
        0.0, -axis.z, axis.y, axis.z, 0.0, -axis.x, -axis.y, axis.x, 0.0,
    );
    Matrix3::identity() + angle.sin() * k + (1.0 - angle.cos()) * k * k
}

#[test]
fn cardan_matrix_is_rotation_about_z_then_new_y_then_newest_x() {
    let (psi, theta, phi) = (0.7, -0.4, 2.1);
    // Successive rotations about the moving axes, each built by Rodrigues.
    let r1 = rodrigues(Vector3::z(), psi);
    let y1 = r1 * Vector3::y();
    let r2 = rodrigues(y1, theta) * r1;
    let x2 = r2 * Vector3::x();
    let r3 = rodrigues(x2, phi) * r2;
    assert!((cardan_matrix(psi, theta, phi) - r3).norm() < 1e-14);
}

#[test]
fn cardan_angles_invert_cardan_matrix_away_from_gimbal_lock() {
    for &(psi, theta, phi) in &[(0.7, -0.4, 2.1), (-3.0, 1.5, -0.2), (0.0, 0.0, 0.0)] {
        let [p2, t2, f2] = cardan_angles(&cardan_matrix(psi, theta, phi));
        assert!((p2 - psi).abs() < 1e-12 && (t2 - theta).abs() < 1e-12 && (f2 - phi).abs() < 1e-12);
    }
}

// ------------------------------------------------------------ four-bar chain

#[test]
fn four_bar_chain_conserves_energy() {
    for loops in [1, 4, 20] {
        let p = FourBarChain {
            loops,
            m: 1.0,
            l: 1.0,
            g: 9.81,
        };
        let initial = [FRAC_PI_2 - 0.1, 0.0];
        let e0 = p.state(0.0, initial[0], initial[1]).energy;
        for s in simulate_four_bar_chain(&p, initial, &grid(3.0, 60)) {
            assert!(
                (s.energy - e0).abs() < 1e-10 * e0.abs().max(1.0),
                "N = {loops}: E({}) = {}",
                s.t,
                s.energy
            );
        }
    }
}

#[test]
fn four_bar_chain_swings_with_exact_pendulum_period_of_equivalent_length() {
    let p = FourBarChain {
        loops: 3,
        m: 1.0,
        l: 1.0,
        g: 9.81,
    };
    // J = 4/3 + 3 = 13/3, W = 9.81 (2 + 3) → L_eq = 13/15 m.
    assert!((p.equivalent_length() - 13.0 / 15.0).abs() < 1e-15);
    let amp = 2.0;
    let period = pendulum_period(p.equivalent_length(), p.g, amp);
    let s = simulate_four_bar_chain(&p, [-FRAC_PI_2 + amp, 0.0], &[0.5 * period, period]);
    assert!((s[0].phi - (-FRAC_PI_2 - amp)).abs() < 1e-9 && s[0].phi_dot.abs() < 1e-9);
    assert!((s[1].phi - (-FRAC_PI_2 + amp)).abs() < 1e-9 && s[1].phi_dot.abs() < 1e-9);
    let top = s[1].first_crank_top;
    assert!((top[0] - s[1].phi.cos()).abs() < 1e-15 && (top[1] - s[1].phi.sin()).abs() < 1e-15);
}
