//! Chain of N parallelogram four-bar linkages in series, 1 DOF.
//!
//! N + 1 cranks (uniform bars, mass m, length L) are pinned to the ground at
//! their ends O, at x = 0, 1·L_pitch, …, N·L_pitch on y = 0 (pitch = coupler
//! length = L here), and joined at their tops A by N couplers (the same bars).
//! On the parallelogram branch every crank has the same angle φ (from X;
//! upright φ = π/2) and the couplers translate without rotating, their centres
//! moving like the crank tips L(cos φ, sin φ) + const. So
//!
//! T = ½ (N+1)(m L²/3) φ̇² + ½ N m L² φ̇² = ½ J φ̇²,
//! V = (N+1) m g (L/2) sin φ + N m g L sin φ = W sin φ,
//!
//! and Lagrange gives J φ̈ = −W cos φ: a physical pendulum about φ = −π/2 of
//! equivalent length J g / W.

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// Parameters of the four-bar chain.
#[derive(Clone, Copy, Debug)]
pub struct FourBarChain {
    /// Number of four-bar loops N (N + 1 cranks, N couplers).
    pub loops: usize,
    /// Mass of every bar (kg).
    pub m: f64,
    /// Length of every bar (m).
    pub l: f64,
    /// Gravity magnitude g (m/s²), acting along −Y.
    pub g: f64,
}

/// State of the chain at one time.
#[derive(Clone, Copy, Debug)]
pub struct FourBarChainState {
    /// Time (s).
    pub t: f64,
    /// Common crank angle φ (rad).
    pub phi: f64,
    /// Common crank rate φ̇ (rad/s).
    pub phi_dot: f64,
    /// Top (point A) of the first crank, pinned at the origin.
    pub first_crank_top: [f64; 2],
    /// Kinetic + gravitational energy (J), V = 0 with every centre at y = 0.
    pub energy: f64,
}

impl FourBarChain {
    /// Reduced inertia J = (N+1) m L²/3 + N m L².
    pub fn reduced_inertia(&self) -> f64 {
        let n = self.loops as f64;
        (n + 1.0) * self.m * self.l * self.l / 3.0 + n * self.m * self.l * self.l
    }

    /// Gravity coefficient W with V = W sin φ: W = (N+1) m g L/2 + N m g L.
    pub fn weight_moment(&self) -> f64 {
        let n = self.loops as f64;
        (n + 1.0) * self.m * self.g * self.l / 2.0 + n * self.m * self.g * self.l
    }

    /// Length of the simple pendulum with the same motion, J g / W.
    pub fn equivalent_length(&self) -> f64 {
        self.reduced_inertia() * self.g / self.weight_moment()
    }

    /// The state for (φ, φ̇) at time `t`.
    pub fn state(&self, t: f64, phi: f64, phi_dot: f64) -> FourBarChainState {
        let (s, c) = phi.sin_cos();
        FourBarChainState {
            t,
            phi,
            phi_dot,
            first_crank_top: [self.l * c, self.l * s],
            energy: 0.5 * self.reduced_inertia() * phi_dot * phi_dot + self.weight_moment() * s,
        }
    }
}

/// Integrates the chain from (φ, φ̇) = `initial` at t = 0 and returns the
/// state at each of `times` (sorted, ≥ 0).
pub fn simulate_four_bar_chain(
    p: &FourBarChain,
    initial: [f64; 2],
    times: &[f64],
) -> Vec<FourBarChainState> {
    let (j, w) = (p.reduced_inertia(), p.weight_moment());
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        dy[0] = y[1];
        dy[1] = -w * y[0].cos() / j;
    };
    let ys = integrate(rhs, 0.0, &initial, times, REFERENCE_RTOL, REFERENCE_ATOL);
    times
        .iter()
        .zip(ys)
        .map(|(&t, y)| p.state(t, y[0], y[1]))
        .collect()
}

/// The chain as a scene (JSON text only, no `bondmech` code): N + 1 upright cranks pinned at
/// x = 0..N, N horizontal couplers on top, uniform 1 m 1 kg bars,
/// cranks turning at 1 rad/s (couplers translating at the crank tips' velocity (−1, 0)).
pub fn chain_json(n: usize) -> String {
    let g = 9.81;
    // at φ = π/2 exactly: sin 1, cos 0 (not the rounded cos(π/2))
    let (bodies, joints) = chain_parts(n, std::f64::consts::FRAC_PI_2, (1.0, 0.0), 1.0);
    format!(
        r#"{{"name":"four_bar_chain_{n}","dimension":2,"gravity":[0,-{g}],
        "bodies":[{}],"joints":[{}],
        "solve":{{"formulation":"dae","t_end":20.0,"output_step":0.05,"rtol":1e-8,"atol":1e-10}},
        "outputs":["crank0.A","energy","constraint_error"]}}"#,
        bodies.join(",\n"),
        joints.join(",\n")
    )
}

/// The chain of `n` parallelogram four-bars with every crank at angle `phi` (from +X) turning
/// at `phi_dot`: crank `i` pinned at `(i, 0)`, coupler `i` joining the tops of cranks `i` and
/// `i + 1` (the configuration of [`chain_json`] at another angle; a 1 s horizon).
pub fn chain_json_at(n: usize, phi: f64, phi_dot: f64) -> String {
    let (bodies, joints) = chain_parts(n, phi, phi.sin_cos(), phi_dot);
    format!(
        r#"{{"name":"four_bar_chain_{n}","dimension":2,"gravity":[0,-9.81],
        "bodies":[{}],"joints":[{}],"solve":{{"formulation":"dae","t_end":1.0}}}}"#,
        bodies.join(",\n"),
        joints.join(",\n")
    )
}

/// Bodies and joints of the chain of `n` four-bars with every crank at angle `phi`
/// (`(sin φ, cos φ)` given) turning at `phi_dot`.
fn chain_parts(n: usize, phi: f64, (s, c): (f64, f64), phi_dot: f64) -> (Vec<String>, Vec<String>) {
    let bar = r#""mass":1.0,"inertia":0.08333333333333333,"points":{"O":[-0.5,0],"A":[0.5,0]}"#;
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    for i in 0..=n {
        bodies.push(format!(
            r#"{{"name":"crank{i}",{bar},"position":[{x},{y}],"angle":{phi},"velocity":[{vx},{vy}],"angular_velocity":{phi_dot}}}"#,
            x = i as f64 + 0.5 * c,
            y = 0.5 * s,
            vx = -0.5 * s * phi_dot,
            vy = 0.5 * c * phi_dot,
        ));
        joints.push(format!(
            r#"{{"name":"pivot{i}","type":"revolute","bodies":["ground","crank{i}"],"points":[[{i},0],"O"]}}"#
        ));
    }
    for i in 0..n {
        bodies.push(format!(
            r#"{{"name":"coupler{i}",{bar},"position":[{x},{y}],"angle":0,"velocity":[{vx},{vy}],"angular_velocity":0}}"#,
            x = i as f64 + 0.5 + c,
            y = s,
            vx = -s * phi_dot,
            vy = c * phi_dot,
        ));
        joints.push(format!(
            r#"{{"name":"pin{i}l","type":"revolute","bodies":["crank{i}","coupler{i}"],"points":["A","O"]}}"#
        ));
        joints.push(format!(
            r#"{{"name":"pin{i}r","type":"revolute","bodies":["crank{j}","coupler{i}"],"points":["A","A"]}}"#,
            j = i + 1
        ));
    }
    (bodies, joints)
}
