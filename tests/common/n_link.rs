//! N-link pendulum of uniform bars, in the absolute angles θ₁ … θ_N.
//!
//! Bar 1 is pinned at the origin at its O; bar k's O is pinned to bar k−1's A.
//! With e_i = (cos θ_i, sin θ_i), e_i⊥ = (−sin θ_i, cos θ_i), the centre of bar k
//! is c_k = Σ_{i<k} L_i e_i + (L_k/2) e_k, so ∂c_k/∂θ_i = a_ki e_i⊥ with
//! a_ki = L_i (i < k), L_k/2 (i = k), 0 (i > k). Then
//!
//! T = ½ Σ_ij M_ij θ̇_i θ̇_j,  M_ij = μ_ij cos(θ_i − θ_j) + δ_ij m_i L_i²/12,
//! μ_ij = Σ_k m_k a_ki a_kj,   V = g Σ_k m_k y_k,  ∂V/∂θ_i = g cos θ_i Σ_k m_k a_ki,
//!
//! and Lagrange (∂M_ij/∂θ_l only through cos(θ_i − θ_j)) gives
//! Σ_j M_ij θ̈_j = −Σ_j μ_ij sin(θ_i − θ_j) θ̇_j² − g cos θ_i Σ_k m_k a_ki,
//! solved at every evaluation by Cholesky (M is symmetric positive definite).
//! For N = 2 this is exactly the double pendulum of `double_pendulum.rs`.

use nalgebra::{DMatrix, DVector};

use super::integrate::integrate;
use super::{REFERENCE_ATOL, REFERENCE_RTOL};

/// Parameters of the N-link pendulum: one (mass, length) per bar, from the
/// pinned one outwards.
#[derive(Clone, Debug)]
pub struct NLinkPendulum {
    /// Masses m_k (kg).
    pub masses: Vec<f64>,
    /// Lengths L_k (m).
    pub lengths: Vec<f64>,
    /// Gravity magnitude g (m/s²), acting along −Y.
    pub g: f64,
}

/// State of the N-link pendulum at one time.
#[derive(Clone, Debug)]
pub struct NLinkState {
    /// Time (s).
    pub t: f64,
    /// Absolute angles θ_k (rad).
    pub theta: Vec<f64>,
    /// Angular rates θ̇_k (rad/s).
    pub omega: Vec<f64>,
    /// Centres c_k (x, y).
    pub centres: Vec<[f64; 2]>,
    /// Centre velocities.
    pub velocities: Vec<[f64; 2]>,
    /// Point A (far end) of every bar.
    pub tips: Vec<[f64; 2]>,
    /// Total mechanical energy (J), V = 0 at y = 0.
    pub energy: f64,
}

impl NLinkPendulum {
    /// Number of links N.
    pub fn links(&self) -> usize {
        self.masses.len()
    }

    /// Lever a_ki of θ_i on the centre of bar k.
    fn lever(&self, k: usize, i: usize) -> f64 {
        match i.cmp(&k) {
            std::cmp::Ordering::Less => self.lengths[i],
            std::cmp::Ordering::Equal => 0.5 * self.lengths[k],
            std::cmp::Ordering::Greater => 0.0,
        }
    }

    /// μ_ij = Σ_k m_k a_ki a_kj.
    fn mu(&self) -> DMatrix<f64> {
        let n = self.links();
        DMatrix::from_fn(n, n, |i, j| {
            (0..n)
                .map(|k| self.masses[k] * self.lever(k, i) * self.lever(k, j))
                .sum()
        })
    }

    /// Angular accelerations θ̈ for angles `th` and rates `w`.
    pub fn accelerations(&self, th: &[f64], w: &[f64]) -> Vec<f64> {
        let n = self.links();
        let mu = self.mu();
        let mass = DMatrix::from_fn(n, n, |i, j| {
            let own = if i == j {
                self.masses[i] * self.lengths[i].powi(2) / 12.0
            } else {
                0.0
            };
            mu[(i, j)] * (th[i] - th[j]).cos() + own
        });
        let rhs = DVector::from_fn(n, |i, _| {
            let centrifugal: f64 = (0..n)
                .map(|j| mu[(i, j)] * (th[i] - th[j]).sin() * w[j] * w[j])
                .sum();
            let weight: f64 = (0..n).map(|k| self.masses[k] * self.lever(k, i)).sum();
            -centrifugal - self.g * th[i].cos() * weight
        });
        let chol = mass
            .cholesky()
            .expect("n-link mass matrix must be positive definite");
        chol.solve(&rhs).iter().copied().collect()
    }

    /// The global-terms state at time `t`.
    pub fn state(&self, t: f64, th: &[f64], w: &[f64]) -> NLinkState {
        let n = self.links();
        let mut joint = [0.0, 0.0];
        let mut joint_v = [0.0, 0.0];
        let (mut centres, mut velocities, mut tips) = (vec![], vec![], vec![]);
        let mut energy = 0.0;
        for k in 0..n {
            let (s, c) = th[k].sin_cos();
            let l = self.lengths[k];
            let cen = [joint[0] + 0.5 * l * c, joint[1] + 0.5 * l * s];
            let v = [
                joint_v[0] - 0.5 * l * w[k] * s,
                joint_v[1] + 0.5 * l * w[k] * c,
            ];
            joint = [joint[0] + l * c, joint[1] + l * s];
            joint_v = [joint_v[0] - l * w[k] * s, joint_v[1] + l * w[k] * c];
            let m = self.masses[k];
            energy += 0.5 * m * (v[0] * v[0] + v[1] * v[1])
                + 0.5 * (m * l * l / 12.0) * w[k] * w[k]
                + m * self.g * cen[1];
            centres.push(cen);
            velocities.push(v);
            tips.push(joint);
        }
        NLinkState {
            t,
            theta: th.to_vec(),
            omega: w.to_vec(),
            centres,
            velocities,
            tips,
            energy,
        }
    }
}

/// Integrates the N-link pendulum from angles `theta0` and rates `omega0` at
/// t = 0 and returns the state at each of `times` (sorted, ≥ 0).
///
/// # Panics
/// If the parameter or initial-value lengths disagree.
pub fn simulate_n_link(
    p: &NLinkPendulum,
    theta0: &[f64],
    omega0: &[f64],
    times: &[f64],
) -> Vec<NLinkState> {
    let n = p.links();
    assert!(
        p.lengths.len() == n && theta0.len() == n && omega0.len() == n,
        "n-link: {n} masses but {} lengths, {} angles, {} rates",
        p.lengths.len(),
        theta0.len(),
        omega0.len()
    );
    let y0: Vec<f64> = theta0.iter().chain(omega0).copied().collect();
    let rhs = |_t: f64, y: &[f64], dy: &mut [f64]| {
        dy[..n].copy_from_slice(&y[n..]);
        let acc = p.accelerations(&y[..n], &y[n..]);
        dy[n..].copy_from_slice(&acc);
    };
    let ys = integrate(rhs, 0.0, &y0, times, REFERENCE_RTOL, REFERENCE_ATOL);
    times
        .iter()
        .zip(ys)
        .map(|(&t, y)| p.state(t, &y[..n], &y[n..]))
        .collect()
}
