//! A partition of a mechanism's coordinates and velocities into the ODE's states and the
//! dependent unknowns (coordinate partitioning), and what its Newton solves for the dependent
//! coordinates share: the failures, the limits, the tangent predictor and the branch test.
//! Used by the partitioned right-hand side ([`crate::solve::formulation::partitioned::equations`]) and the symbolic
//! elimination ([`crate::solve::formulation::partitioned::elimination`]).

use crate::partition::thresholds::BRANCH_FRACTION;

/// Why a right-hand side of the partitioned ODE could not be evaluated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PartitionError {
    /// Newton on `g(q) = 0` for the dependent coordinates did not converge (the integrator
    /// retries with a smaller step).
    #[error("Newton on the joints did not converge at t = {t} (last correction {correction:e})")]
    Newton {
        /// Time of the evaluation.
        t: f64,
        /// Size of the last correction.
        correction: f64,
    },
    /// Newton converged far from the tangent prediction (a correction of at least
    /// [`BRANCH_FRACTION`] of the prediction): the trial step probably crossed to another branch
    /// of the joints' solutions near a bifurcation (the integrator retries with a smaller step).
    #[error("Newton on the joints left the tangent prediction at t = {t} (correction {correction:e}, prediction {predicted:e})")]
    Branch {
        /// Time of the evaluation.
        t: f64,
        /// Size of Newton's correction of the prediction.
        correction: f64,
        /// Size of the prediction.
        predicted: f64,
    },
    /// The dependent block of `G_q` or `G_v` is singular at this state.
    #[error("the dependent block of the joints' Jacobian is singular at t = {t}")]
    SingularBlock {
        /// Time of the evaluation.
        t: f64,
    },
    /// The reduced mass matrix `Rᵀ M R` is singular (a degree of freedom without inertia).
    #[error("the reduced mass matrix is singular at t = {t}")]
    SingularMass {
        /// Time of the evaluation.
        t: f64,
    },
    /// The dependent block's condition estimate passed the re-choice threshold: the runner
    /// chooses a new partition at the last accepted step.
    #[error("the dependent block's condition estimate {condition:.1e} asks for a new partition at t = {t}")]
    Repartition {
        /// Time of the evaluation.
        t: f64,
        /// Condition estimate.
        condition: f64,
    },
}

/// A choice of dependent and independent coordinates and velocities (sorted index lists).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Dependent coordinates `q_D` (one per constraint row).
    pub dep_q: Vec<usize>,
    /// Independent coordinates `q_I` (ODE states).
    pub ind_q: Vec<usize>,
    /// Dependent velocities `v_D`.
    pub dep_v: Vec<usize>,
    /// Independent velocities `v_I` (ODE states).
    pub ind_v: Vec<usize>,
}

impl Partition {
    /// The names of the states: the independent coordinates, then the independent velocities.
    pub fn state_names(&self, sys: &crate::mech::MultibodySystem) -> Vec<String> {
        let q = self.ind_q.iter().map(|&i| sys.coords[i].name.clone());
        q.chain(self.ind_v.iter().map(|&j| sys.velocities[j].name.clone()))
            .collect()
    }

    /// The partition with the dependent coordinates `dep_q` (of `nq`) and velocities `dep_v`
    /// (of `nv`); the independent ones are the rest, in order.
    pub fn of_dependent((nq, nv): (usize, usize), dep_q: Vec<usize>, dep_v: Vec<usize>) -> Self {
        let rest = |n: usize, d: &[usize]| (0..n).filter(|i| !d.contains(i)).collect();
        Partition {
            ind_q: rest(nq, &dep_q),
            ind_v: rest(nv, &dep_v),
            dep_q,
            dep_v,
        }
    }

    /// Number of ODE states `|q_I| + |v_I|`.
    pub fn n_states(&self) -> usize {
        self.ind_q.len() + self.ind_v.len()
    }

    /// The ODE state `[q_I, v_I]` of a full state `x = [q, v]` (`nq` coordinates).
    pub fn states_of(&self, nq: usize, x: &[f64]) -> Vec<f64> {
        self.ind_q
            .iter()
            .map(|&i| x[i])
            .chain(self.ind_v.iter().map(|&j| x[nq + j]))
            .collect()
    }
}

/// Whether Newton's correction `corr` of the tangent prediction (of size `predicted`, for a
/// move `moved` of the independent coordinates) means it converged on another branch of the
/// joints' solutions: more than [`BRANCH_FRACTION`] of the prediction plus the predictor's own
/// truncation error (bounded by `moved²`: it is exact to first order, and to second with its
/// curvature term) and the Newton tolerance. The truncation term matters where the dependent
/// coordinates are stationary (a slider-crank's rod angle at a dead centre: the prediction is
/// tiny, its third-order error is not), as at an output row completed far from the last
/// evaluation.
pub(crate) fn left_branch(corr: f64, predicted: f64, moved: f64, newton_tol: f64) -> bool {
    corr > BRANCH_FRACTION * (predicted + moved * moved) + 1e3 * newton_tol
}

/// The tangent predictor's step `Δq_D = B Δq_I + ½ δ² c` into `out` (the caller subtracts it):
/// `B = G_D⁻¹ G_I` (row-major `|D| × |q_I|`) of the last call, and, when `c = G_D⁻¹ γ` of the
/// last right-hand side is given, the curvature term `½ G_D⁻¹ H(Δq, Δq)`: along the last
/// velocity `v`, `Δq ≈ δ v` and `H(Δq, Δq) ≈ δ² H(v, v) = δ² γ`, with `δ` the step along `v`
/// that moves `q_I` by `Δq_I = q_I − q_I,prev` (least squares; `v_I` given by `v`).
pub(crate) fn tangent_step(
    b: &[f64],
    c: Option<&[f64]>,
    qi: &[f64],
    qi_prev: &[f64],
    v: impl Iterator<Item = f64>,
    out: &mut [f64],
) {
    let ni = qi.len();
    for (k, o) in out.iter_mut().enumerate() {
        *o = b[k * ni..(k + 1) * ni]
            .iter()
            .zip(qi.iter().zip(qi_prev))
            .map(|(b, (y, p))| b * (y - p))
            .sum();
    }
    let Some(c) = c else { return };
    let (num, den) = v
        .zip(qi.iter().zip(qi_prev))
        .fold((0.0, 0.0), |(n, d), (v, (y, p))| {
            (n + (y - p) * v, d + v * v)
        });
    if den > 0.0 {
        let half = 0.5 * (num / den) * (num / den);
        for (o, c) in out.iter_mut().zip(c) {
            *o += half * c;
        }
    }
}

/// What a Newton solve for the dependent coordinates may take: its tolerance, its iterations,
/// and the condition estimate above which the partition is to be re-chosen (the fields of a
/// [`PartitionedRhs`](crate::solve::formulation::PartitionedRhs) of the same names, handed to the elimination's Newton).
#[derive(Clone, Copy, Debug)]
pub(crate) struct NewtonLimits {
    pub(crate) tolerance: f64,
    pub(crate) max_iterations: usize,
    pub(crate) repartition_above: f64,
}

/// Coordinates preferred as dependent where `q' ≠ v` (3D bodies' quaternions, body-fixed
/// frames): the translations (`x`, `y`, `z` of a body's centre), whose velocities the joints
/// put in differential causality (seed 16.5, 16.7); on a spatial body whose angular inertias
/// the bond graph prefers in differential causality (a freely rotating body,
/// [`crate::bond::model::BondGraph::prefer_differential`]), its quaternion instead, so that
/// its coordinates' states follow its velocities' (the centre's position with `V`).
pub fn preferred_coordinates(sys: &crate::mech::MultibodySystem) -> Vec<bool> {
    let mut p: Vec<bool> = sys
        .coords
        .iter()
        .map(|c| matches!(c.name.rsplit('.').next(), Some("x" | "y" | "z")))
        .collect();
    for (r, e) in freely_rotating(sys).map(|(r, e, _, _)| (r, e)) {
        for s in r {
            p[s as usize - 1] = false;
        }
        for s in e {
            p[s as usize - 1] = true;
        }
    }
    p
}

/// The slots `(r, e, v, w)` of the spatial bodies whose angular inertias the bond graph prefers
/// in differential causality (the freely rotating ones,
/// [`crate::bond::model::BondGraph::prefer_differential`]).
fn freely_rotating(
    sys: &crate::mech::MultibodySystem,
) -> impl Iterator<Item = ([u32; 3], [u32; 4], [u32; 3], [u32; 3])> + '_ {
    let nq = sys.nq();
    let preferred = move |slot: u32| {
        sys.bond_graph.as_deref().is_some_and(|graph| {
            sys.inertias
                .get(slot as usize - 1 - nq)
                .is_some_and(|n| graph.prefer_differential.contains(n))
        })
    };
    sys.bodies.iter().filter_map(move |(_, kin)| match kin {
        crate::mech::body::BodyKinematics::Spatial { r, e, v, w }
            if w.iter().all(|&s| preferred(s)) =>
        {
            Some((*r, *e, *v, *w))
        }
        _ => None,
    })
}

/// The velocities that IDA's error test measures even where they are dependent (index-1 DAE,
/// [`crate::solve::formulation::error_test_mask`]): every velocity of a freely rotating spatial body (its
/// centre's `V` and its body-frame `ω`). Measured on the heavy top (5 s, rtol 1e-9 / 1e-10 /
/// 1e-11, its centre's velocity the states): 822 / 1510 / 2200 × rtol with its dependent `ω_x,
/// ω_y` and `V_z` out of the test, 579 / 218 / 1919 × with them in, at about the same steps
/// (docs/performance.md, "The heavy top's states").
pub fn always_measured_velocities(sys: &crate::mech::MultibodySystem) -> Vec<bool> {
    let nq = sys.nq();
    let mut m = vec![false; sys.nv()];
    for (_, _, v, w) in freely_rotating(sys) {
        for s in v.iter().chain(&w) {
            m[*s as usize - 1 - nq] = true;
        }
    }
    m
}
