//! The three-angle chart of the spatial rigid bodies' attitudes for [`super::linearize`].
//!
//! A spatial body's attitude is integrated as four Euler parameters `e` (three degrees of
//! freedom) and its angular velocity as the body-frame `ω`. About the operating point
//! `(e₀, ω₀, ω̇₀)` the linearization takes, for each spatial body,
//!
//! ```text
//!   R = exp([φ]×) R_c(t),    R_c(t) = exp([ω_s⁰]× (t − t*)) R₀       (space-frame rotation vector φ)
//!   e = exp(φ/2) ⊗ e_c(t),   ω = Rᵀ Ω,   ω' = Rᵀ Ω'                    (Ω the space-frame angular velocity)
//! ```
//!
//! so the four coordinates `e0…e3` become the three chart coordinates `B.rx, B.ry, B.rz` (zero
//! at the operating point) and the velocities `B.wx…wz` the space-frame `B.wX, B.wY, B.wZ`
//! (the run CSV's columns). The chart turns with the operating point's angular velocity
//! `ω_s⁰ = R₀ ω₀`; its rates are `J_l(φ) φ' = Ω − exp([φ]×) ω_s⁰`, whose linearization at
//! `φ = 0` is `δφ' = δΩ + ω_s⁰ × φ`. At an equilibrium (`ω₀ = 0`) it is the plain chart
//! `R = exp([φ]×) R₀`; at a steady rotation (a relative equilibrium such as a sleeping top or
//! a body spinning about a principal axis) the co-rotating chart and the space-frame velocities
//! make the equations along the motion time-invariant, so `A`'s eigenvalues are those of the
//! classical small-motion analysis in the inertial frame.
//!
//! Nothing of the physics is written twice: the equations' Jacobian by the integrator's
//! unknowns `z = [q, v, v', λ]` is chained through `∂z/∂z̃` at the operating point, `z̃ = [q̃,
//! ṽ, ṽ', λ]` the chart's unknowns (first derivatives are all the linearization needs). The
//! identities used: `∂e/∂φ_k = ½ (0, u_k) ⊗ e₀`, `∂(RᵀΩ)/∂φ = R₀ᵀ [Ω⁰]×`,
//! `∂(RᵀΩ')/∂φ = R₀ᵀ [Ω'⁰]×` and `ω' = Rᵀ Ω'` (as `Ṙᵀ Ω = −Rᵀ (Ω × Ω) = 0`).

use nalgebra::{DMatrix, Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::mech::body::BodyKinematics;
use crate::mech::MultibodySystem;

/// Where a chart coordinate comes from.
#[derive(Clone, Copy, Debug)]
enum Source {
    /// An integrator coordinate (its index in `q`).
    Coordinate(usize),
    /// Component `k` of the rotation vector of spatial body `body` (index in [`Chart::bodies`]).
    Angle { body: usize, k: usize },
}

/// One spatial body's slots and operating point.
#[derive(Clone, Debug)]
struct Body {
    /// indices in `q` of `e0…e3`
    e: [usize; 4],
    /// indices in `v` of the body-frame `ω`
    w: [usize; 3],
    /// indices in `q̃` of `φ`
    phi: [usize; 3],
    /// `R₀` (body to space)
    r0: Matrix3<f64>,
    /// the space-frame angular velocity `Ω⁰ = R₀ ω₀`
    omega_s: Vector3<f64>,
}

/// The chart of the spatial bodies (see the module documentation).
#[derive(Clone, Debug)]
pub(super) struct Chart {
    bodies: Vec<Body>,
    q_of: Vec<Source>,
    dims: (usize, usize, usize),
    /// The chart's coordinate names (`q̃`).
    pub q_names: Vec<String>,
    /// The chart's velocity names (`ṽ`).
    pub v_names: Vec<String>,
    /// `∂z/∂z̃` at the operating point (`nz × nz̃`).
    pub p: DMatrix<f64>,
}

fn cross(a: &Vector3<f64>) -> Matrix3<f64> {
    a.cross_matrix()
}

impl Chart {
    /// The chart at the operating point `x = [q, v]` with accelerations `acc`; `None` when the
    /// mechanism has no spatial rigid body (the integrator's coordinates are the chart).
    pub(super) fn new(sys: &MultibodySystem, x: &[f64], acc: &[f64]) -> Option<Chart> {
        let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
        let mut spatial: Vec<(String, [usize; 4], [usize; 3])> = Vec::new();
        for (name, b) in &sys.bodies {
            if let BodyKinematics::Spatial { e, w, .. } = b {
                let e = e.map(|s| s as usize - 1);
                let w = w.map(|s| s as usize - 1 - nq);
                if e.iter().all(|&i| i < nq) && w.iter().all(|&j| j < nv) {
                    spatial.push((name.clone(), e, w));
                }
            }
        }
        if spatial.is_empty() {
            return None;
        }
        let mut q_of = Vec::new();
        let mut q_names = Vec::new();
        let mut bodies = Vec::new();
        let mut v_names: Vec<String> = sys.velocities.iter().map(|c| c.name.clone()).collect();
        // the bodies' operating points, in `spatial`'s order
        let mut phi_at: Vec<[usize; 3]> = vec![[0; 3]; spatial.len()];
        for i in 0..nq {
            if let Some(b) = spatial.iter().position(|s| s.1[0] == i) {
                for k in 0..3 {
                    phi_at[b][k] = q_of.len();
                    q_of.push(Source::Angle { body: b, k });
                    q_names.push(format!("{}.{}", spatial[b].0, ["rx", "ry", "rz"][k]));
                }
            } else if spatial.iter().any(|s| s.1.contains(&i)) {
                continue;
            } else {
                q_of.push(Source::Coordinate(i));
                q_names.push(sys.coords[i].name.clone());
            }
        }
        for (b, (name, e, w)) in spatial.iter().enumerate() {
            let quat = Quaternion::new(x[e[0]], x[e[1]], x[e[2]], x[e[3]]);
            let r0 = UnitQuaternion::from_quaternion(quat)
                .to_rotation_matrix()
                .into_inner();
            let wb = Vector3::new(x[nq + w[0]], x[nq + w[1]], x[nq + w[2]]);
            for (k, n) in ["wX", "wY", "wZ"].iter().enumerate() {
                v_names[w[k]] = format!("{name}.{n}");
            }
            bodies.push(Body {
                e: *e,
                w: *w,
                phi: phi_at[b],
                r0,
                omega_s: r0 * wb,
            });
        }
        let nqt = q_of.len();
        let (nz, nzt) = (nq + 2 * nv + nc, nqt + 2 * nv + nc);
        let mut p = DMatrix::zeros(nz, nzt);
        for (a, s) in q_of.iter().enumerate() {
            if let Source::Coordinate(i) = *s {
                p[(i, a)] = 1.0;
            }
        }
        let angular: Vec<usize> = bodies.iter().flat_map(|b| b.w).collect();
        for j in (0..nv).filter(|j| !angular.contains(j)) {
            p[(nq + j, nqt + j)] = 1.0;
            p[(nq + nv + j, nqt + nv + j)] = 1.0;
        }
        for k in 0..nc {
            p[(nq + 2 * nv + k, nqt + 2 * nv + k)] = 1.0;
        }
        for b in &bodies {
            // ∂e/∂φ_k = ½ (0, u_k) ⊗ e₀, (0, u) ⊗ (a, c) = (−u·c, a u + u × c)
            let (a, c) = (x[b.e[0]], Vector3::new(x[b.e[1]], x[b.e[2]], x[b.e[3]]));
            for k in 0..3 {
                let u = Vector3::ith(k, 1.0);
                let vec = a * u + u.cross(&c);
                p[(b.e[0], b.phi[k])] = -0.5 * u.dot(&c);
                for m in 0..3 {
                    p[(b.e[m + 1], b.phi[k])] = 0.5 * vec[m];
                }
            }
            // ω = Rᵀ Ω, ω' = Rᵀ Ω'
            let rt = b.r0.transpose();
            let wb_dot = Vector3::new(acc[b.w[0]], acc[b.w[1]], acc[b.w[2]]);
            let dw = rt * cross(&b.omega_s);
            let ddw = rt * cross(&(b.r0 * wb_dot));
            for k in 0..3 {
                for m in 0..3 {
                    p[(nq + b.w[k], nqt + b.w[m])] = rt[(k, m)];
                    p[(nq + nv + b.w[k], nqt + nv + b.w[m])] = rt[(k, m)];
                    p[(nq + b.w[k], b.phi[m])] = dw[(k, m)];
                    p[(nq + nv + b.w[k], b.phi[m])] = ddw[(k, m)];
                }
            }
        }
        Some(Chart {
            bodies,
            q_of,
            dims: (nq, nv, nc),
            q_names,
            v_names,
            p,
        })
    }

    /// The number of chart coordinates.
    pub(super) fn nq(&self) -> usize {
        self.q_of.len()
    }

    /// The chart coordinates' rates by `z̃` (`nq̃ × nz̃`), from the integrator coordinates'
    /// `fz = ∂(K(q) v)/∂z` (`nq × nz`): an integrator coordinate's row chained through
    /// [`Chart::p`], a rotation vector's `δφ' = δΩ + Ω⁰ × φ`.
    pub(super) fn rates(&self, fz: &DMatrix<f64>) -> DMatrix<f64> {
        let nqt = self.nq();
        let mut out = DMatrix::zeros(nqt, self.p.ncols());
        for (a, s) in self.q_of.iter().enumerate() {
            match *s {
                Source::Coordinate(i) => out.set_row(a, &(fz.row(i) * &self.p)),
                Source::Angle { body, k } => {
                    let b = &self.bodies[body];
                    out[(a, nqt + b.w[k])] = 1.0;
                    let wx = cross(&b.omega_s);
                    for m in 0..3 {
                        out[(a, b.phi[m])] = wx[(k, m)];
                    }
                }
            }
        }
        out
    }

    /// `G_q` and `G_v` in the chart's coordinates and velocities.
    pub(super) fn jacobians(
        &self,
        gq: &DMatrix<f64>,
        gv: &DMatrix<f64>,
    ) -> (DMatrix<f64>, DMatrix<f64>) {
        let (nq, nv, _) = self.dims;
        let nqt = self.nq();
        let pq = self.p.view((0, 0), (nq, nqt));
        let pv = self.p.view((nq, nqt), (nv, nv));
        (gq * pq, gv * pv)
    }

    /// Whether chart coordinate `a` is an attitude angle (the joints prefer the others,
    /// translations, dependent).
    pub(super) fn is_angle(&self, a: usize) -> bool {
        matches!(self.q_of.get(a), Some(Source::Angle { .. }))
    }

    /// Whether velocity `j` is a spatial body's angular velocity.
    pub(super) fn is_angular(&self, j: usize) -> bool {
        self.bodies.iter().any(|b| b.w.contains(&j))
    }
}

impl Chart {
    /// The states' names of `part` (over the chart's coordinates and velocities).
    pub(super) fn state_names(&self, part: &crate::partition::Partition) -> Vec<String> {
        part.ind_q
            .iter()
            .map(|&i| self.q_names[i].clone())
            .chain(part.ind_v.iter().map(|&j| self.v_names[j].clone()))
            .collect()
    }
}
