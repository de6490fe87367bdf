//! Static equilibrium: the configuration where every flow and every momentum rate is zero —
//! the efforts of the springs, the sources (loads, drivers' efforts) and gravity balance
//! through the junction structure, with the joints' efforts as the multipliers.
//!
//! With `v = 0` the multibody system `M v' = Q(t, q, v) − G_vᵀ λ`, `g(q, t) = 0` at rest reads
//!
//! ```text
//!   F(q, λ) = [ Q(t₀, q, 0) − G_v(q)ᵀ λ ]  = 0      (nv rows: the inertias' effort balance)
//!             [ g(q, t₀)               ]          (nc rows: the joints and drivers held)
//! ```
//!
//! solved by Newton from the scene's configuration (least-squares steps `J Δ = −F` through an
//! SVD, so a quaternion's scale and redundant rows do no harm), globalised by a backtracking
//! line search on `½‖F‖²` (Armijo); where the Newton step does not lower it (a stiffness that
//! vanishes or is indefinite along a degree of freedom, as gravity's on a pendulum released
//! horizontal), damped steps `(K_r + μ I) Δ = Zᵀ f` along the loads (Levenberg–Marquardt on
//! the degrees of freedom, in a shrinking trust radius), the joints held again after each. The Jacobian `J = ∂F/∂(q, λ)` is exact (the expression
//! graph's derivatives). Stability: the tangent stiffness `K = −∂(Q − G_vᵀ λ)/∂q · ∂(K v)/∂v`
//! reduced to the degrees of freedom, `K_r = Zᵀ K Z` with `Z` an orthonormal basis of the null
//! space of `G_v` (the motions the joints and drivers allow), symmetrised; the equilibrium is
//! stable when `K_r` is positive definite (every eigenvalue above a tolerance relative to the
//! largest).

use nalgebra::{DMatrix, DVector};

use crate::dae::{ConstraintExprs, MechanicsTapes};
use crate::expr::Expr;
use crate::mech::MultibodySystem;
use crate::solve::reactions::{Multipliers, ReactionEval};

/// Largest number of Newton iterations.
pub const MAX_ITERATIONS: usize = 200;

/// A static equilibrium (see the module documentation).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Equilibrium {
    /// Whether Newton converged (`‖F‖∞` below the tolerance).
    pub converged: bool,
    /// Newton iterations taken.
    pub iterations: usize,
    /// `‖F‖∞` at the solution (N, N·m; the joint rows in m or rad).
    pub residual: f64,
    /// The coordinates, keyed by the run CSV's position columns (`bar.x`, `bar.angle`, …).
    pub coordinates: Vec<(String, f64)>,
    /// The joints' reactions keyed by their columns (`pivot.Fx`: on the joint's second body,
    /// global frame, as `run --reactions` writes them).
    pub reactions: Vec<(String, f64)>,
    /// The drivers' efforts keyed by their columns (`motor.torque`, `push.force`).
    pub drivers: Vec<(String, f64)>,
    /// `K_r` positive definite ([`Stability::Stable`]).
    pub stable: bool,
    /// Stable, neutral (no eigenvalue below zero, one at zero: a free wheel, a mechanism
    /// that may rest anywhere along a degree of freedom) or unstable.
    pub stability: Stability,
    /// The squared natural frequencies `ω²` (1/s²) of the small motions about the equilibrium,
    /// ascending: the generalized eigenvalues of the reduced tangent stiffness and mass,
    /// `K_r z = ω² M_r z`, `K_r = Zᵀ K Z`, `M_r = Zᵀ M Z` on the degrees of freedom (`Z` the
    /// null space of `G_v`) — independent of the coordinates and their units (a bar on a pin:
    /// `V''(θ) / J_pivot`). A negative one is an unstable direction (`−ω²` its growth rate
    /// squared). Where `M_r` is singular (a degree of freedom without inertia) the eigenvalues
    /// of `K_r` itself (N/m, N·m/rad, mixed).
    pub stiffness_eigenvalues: Vec<f64>,
    /// CPU seconds of the search (this thread; the scene's model building excluded).
    pub cpu_seconds: f64,
    /// The multipliers λ (one per constraint row).
    pub multipliers: Vec<f64>,
}

impl Equilibrium {
    /// The value of coordinate `name` (`bar.angle`).
    pub fn coordinate(&self, name: &str) -> Option<f64> {
        self.coordinates
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// The JSON document `bondmech equilibrium --json` writes: `converged`, `iterations`,
    /// `residual`, `coordinates`, `reactions`, `drivers` (objects keyed by column name),
    /// `stable`, `stability` (`stable`, `neutral`, `unstable`), `stiffness_eigenvalues` (`ω²`,
    /// 1/s²), `cpu_seconds`.
    pub fn to_json(&self) -> serde_json::Value {
        let obj = |v: &[(String, f64)]| {
            serde_json::Value::Object(
                v.iter()
                    .map(|(k, x)| (k.clone(), serde_json::json!(x)))
                    .collect(),
            )
        };
        serde_json::json!({
            "converged": self.converged,
            "iterations": self.iterations,
            "residual": self.residual,
            "coordinates": obj(&self.coordinates),
            "reactions": obj(&self.reactions),
            "drivers": obj(&self.drivers),
            "stable": self.stable,
            "stability": self.stability.name(),
            "stiffness_eigenvalues": self.stiffness_eigenvalues,
            "cpu_seconds": self.cpu_seconds,
        })
    }
}

/// What the reduced stiffness says of an equilibrium.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Stability {
    /// Every `ω²` above zero: a minimum of the potential on the degrees of freedom.
    Stable,
    /// No `ω²` below zero and at least one at zero (within [`NEUTRAL_OMEGA2`] of the largest):
    /// to first order the mechanism may rest anywhere along that direction.
    Neutral,
    /// Some `ω²` below zero.
    Unstable,
}

/// `|ω²| ≤ NEUTRAL_OMEGA2 · max(1, max |ω²|)` (1/s²) counts as zero: rounding in `K_r`
/// (its entries are sums of products of the loads and lever arms) is some 1e-14 of its size.
pub const NEUTRAL_OMEGA2: f64 = 1e-9;

impl Stability {
    /// The stability of the squared natural frequencies `eig`.
    pub fn of(eig: &[f64]) -> Self {
        let emax = eig.iter().fold(1.0f64, |a, b| a.max(b.abs()));
        let zero = NEUTRAL_OMEGA2 * emax;
        if eig.iter().any(|&e| e < -zero) {
            Stability::Unstable
        } else if eig.iter().any(|&e| e.abs() <= zero) {
            Stability::Neutral
        } else {
            Stability::Stable
        }
    }

    /// `stable`, `neutral` or `unstable`.
    pub fn name(self) -> &'static str {
        match self {
            Stability::Stable => "stable",
            Stability::Neutral => "neutral",
            Stability::Unstable => "unstable",
        }
    }
}

/// The generalized eigenvalues of `K_r = kr` and `M_r = Zᵀ diag(mass) Z`, ascending:
/// `K_r z = ω² M_r z` by Cholesky `M_r = L Lᵀ` and the symmetric `L⁻¹ K_r L⁻ᵀ`; the
/// eigenvalues of `K_r` where `M_r` is not positive definite.
fn mass_normalised_eigenvalues(kr: &DMatrix<f64>, z: &DMatrix<f64>, mass: &[f64]) -> Vec<f64> {
    if kr.nrows() == 0 {
        return Vec::new();
    }
    let m = DMatrix::from_diagonal(&DVector::from_column_slice(mass));
    let mr = z.transpose() * m * z;
    let mr = (&mr + mr.transpose()) * 0.5;
    let mut eig: Vec<f64> = match mr.cholesky() {
        Some(ch) => {
            let l = ch.l();
            let linv = l
                .clone()
                .try_inverse()
                .unwrap_or_else(|| DMatrix::identity(l.nrows(), l.ncols()));
            let s = &linv * kr * linv.transpose();
            let s = (&s + s.transpose()) * 0.5;
            s.symmetric_eigen().eigenvalues.iter().copied().collect()
        }
        None => kr
            .clone()
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .copied()
            .collect(),
    };
    eig.sort_by(f64::total_cmp);
    eig
}

/// Why no equilibrium was found.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EquilibriumError {
    /// Newton did not converge within [`MAX_ITERATIONS`].
    #[error("no equilibrium: Newton diverged ({iterations} iterations, residual {residual:.3e})")]
    Diverged {
        /// Iterations done.
        iterations: usize,
        /// `‖F‖∞` reached.
        residual: f64,
    },
    /// The line search found no decrease: `‖F‖` has a minimum that is not zero.
    #[error("no equilibrium: the loads never balance near the start (the residual stalls at {residual:.3e} after {iterations} iterations; worst row: {worst})")]
    NoBalance {
        /// Iterations done.
        iterations: usize,
        /// `‖F‖∞` reached.
        residual: f64,
        /// The row with the largest residual.
        worst: String,
    },
    /// A value is not finite.
    #[error("no equilibrium: {0} is not finite")]
    NonFinite(String),
    /// The scene is a raw bond graph.
    #[error("equilibrium needs bodies and joints (a raw bond graph has no coordinates)")]
    RawGraph,
}

/// The static equilibrium of `sys` nearest its initial configuration, with the loads, drivers
/// and inputs at `t0` (see the module documentation).
pub fn equilibrium(sys: &MultibodySystem, t0: f64) -> Result<Equilibrium, EquilibriumError> {
    let clock = cpu_time::ThreadTime::now();
    let mut eq = solve_equilibrium(sys, t0)?;
    eq.cpu_seconds = clock.elapsed().as_secs_f64();
    Ok(eq)
}

/// [`equilibrium`] without its clock.
fn solve_equilibrium(sys: &MultibodySystem, t0: f64) -> Result<Equilibrium, EquilibriumError> {
    let mut sys = sys.clone();
    let (nq, nv, nc) = (sys.nq(), sys.nv(), sys.nc());
    let c = ConstraintExprs::derive(&mut sys);
    let tapes = MechanicsTapes::new(&mut sys, &c, None);
    // λ in the slots after [t, q, v]
    let lam_slot = |i: usize| (1 + nq + nv + i) as u32;
    let g = &mut sys.graph;
    let mut f: Vec<Expr> = Vec::with_capacity(nv + nc);
    for j in 0..nv {
        f.push(c.static_row(g, (j, sys.forces[j]), lam_slot));
    }
    f.extend(c.g.iter().copied());
    let unknown_slots: Vec<u32> = (0..nq)
        .map(|k| (1 + k) as u32)
        .chain((0..nc).map(lam_slot))
        .collect();
    let mut jac = Vec::with_capacity(f.len() * unknown_slots.len());
    for &fi in &f {
        for &s in &unknown_slots {
            jac.push(g.diff(fi, s));
        }
    }
    // ∂(K v)/∂v: maps velocity directions to coordinate directions
    let mut kmap = Vec::with_capacity(nq * nv);
    for k in 0..nq {
        for j in 0..nv {
            kmap.push(g.diff(sys.kinematics[k], (1 + nq + j) as u32));
        }
    }
    let f_tape = g.compile(&f);
    let j_tape = g.compile(&jac);
    let k_tape = g.compile(&kmap);
    let n = nq + nc;
    let m = nv + nc;
    // the state vector [t, q, v = 0, λ]
    let mut vars = vec![0.0; 1 + nq + nv + nc];
    vars[0] = t0;
    for (k, c0) in sys.coords.iter().enumerate() {
        vars[1 + k] = c0.initial;
    }
    let eval = |tape: &crate::expr::Tape, vars: &[f64]| {
        let mut out = vec![0.0; tape.n_outputs()];
        tape.eval(vars, &mut tape.workspace(), &mut out);
        out
    };
    let x_of = |vars: &[f64]| -> Vec<f64> {
        vars[1..1 + nq]
            .iter()
            .chain(&vars[1 + nq + nv..])
            .copied()
            .collect()
    };
    let set_x = |vars: &mut [f64], x: &[f64]| {
        vars[1..1 + nq].copy_from_slice(&x[..nq]);
        vars[1 + nq + nv..].copy_from_slice(&x[nq..]);
    };
    let names: Vec<String> = sys
        .velocities
        .iter()
        .map(|v| format!("the effort balance on {}", v.name))
        .chain(
            sys.rows
                .iter()
                .map(|r| format!("{} ({})", r.joint, r.direction)),
        )
        .collect();
    let norm = |r: &[f64]| r.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let merit = |r: &[f64]| 0.5 * r.iter().map(|x| x * x).sum::<f64>();
    // first, the joints held: the least change of q onto g = 0 (as a solve's start)
    if nc > 0 {
        let init = crate::dae::consistent_state_from(&sys, &tapes, t0, &{
            let mut x0: Vec<f64> = vars[1..1 + nq].to_vec();
            x0.extend(std::iter::repeat_n(0.0, nv));
            x0
        })
        .map_err(|e| EquilibriumError::NonFinite(e.to_string()))?;
        vars[1..1 + nq].copy_from_slice(&init.q);
        vars[1 + nq + nv..].copy_from_slice(&init.lambda);
    }
    let scale = 1.0 + vars[1..1 + nq].iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let mut r = eval(&f_tape, &vars);
    let force_scale = 1.0 + r[..nv].iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let tol = |r: &[f64]| {
        let forces = r[..nv].iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let rows = r[nv..].iter().fold(0.0f64, |a, b| a.max(b.abs()));
        forces <= 1e-12 * force_scale && rows <= 1e-13 * scale
    };
    // the tangent stiffness reduced to the degrees of freedom at `vars`: `(K_r, Z, ∂(K v)/∂v)`
    let reduced = |vars: &[f64]| {
        let jv = eval(&j_tape, vars);
        let kv = eval(&k_tape, vars);
        let dq = DMatrix::from_fn(nv, nq, |j, k| -jv[j * n + k]);
        let kmat = DMatrix::from_row_slice(nq, nv, &kv);
        let stiffness = dq * &kmat; // nv × nv
        let state: Vec<f64> = vars[1..1 + nq + nv].to_vec();
        let z = null_space(&tapes.gv.matrix(t0, &state), nv);
        let kr = z.transpose() * &stiffness * &z;
        ((&kr + kr.transpose()) * 0.5, z, kmat)
    };
    // Where Newton's step does not lower ½‖F‖² (the stiffness vanishes or is indefinite along
    // a DOF: a pendulum released horizontal, where gravity's stiffness is zero), a damped step
    // along the loads: `(K_r + μ I) Δ = Zᵀ f` on the DOF (Levenberg–Marquardt; with `K_r = 0`
    // it is the load's direction, down the potential), `μ` large enough that `K_r + μ I` is
    // positive definite and the step within a trust radius, the joints then held again.
    let damped = |vars: &[f64], r: &[f64], radius: f64| -> Option<(Vec<f64>, Vec<f64>)> {
        let (kr, z, kmat) = reduced(vars);
        if kr.nrows() == 0 {
            return None;
        }
        let fr = z.transpose() * DVector::from_column_slice(&r[..nv]);
        let lmin = kr.symmetric_eigenvalues().min();
        let mu = (2.0 * (-lmin).max(0.0)).max(fr.norm() / radius).max(1e-300);
        let a = &kr + DMatrix::identity(kr.nrows(), kr.nrows()) * mu;
        let dr = a.cholesky()?.solve(&fr);
        let dq = kmat * (z * dr);
        let mut x0: Vec<f64> = vars[1..1 + nq]
            .iter()
            .zip(dq.iter())
            .map(|(a, d)| a + d)
            .collect();
        x0.extend(std::iter::repeat_n(0.0, nv));
        let held = crate::dae::consistent_state_from(&sys, &tapes, t0, &x0).ok()?;
        let mut tv = vars.to_vec();
        tv[1..1 + nq].copy_from_slice(&held.q);
        // the static multipliers there: λ = argmin ‖Q − G_vᵀ λ‖ (the loads the joints carry)
        tv[1 + nq + nv..].fill(0.0);
        let loads = DVector::from_column_slice(&eval(&f_tape, &tv)[..nv]);
        let state: Vec<f64> = tv[1..1 + nq + nv].to_vec();
        let gvt = tapes.gv.matrix(t0, &state).transpose();
        let lambda = gvt.svd(true, true).solve(&loads, 1e-12).ok()?;
        tv[1 + nq + nv..].copy_from_slice(lambda.as_slice());
        let rt = eval(&f_tape, &tv);
        rt.iter().all(|v| v.is_finite()).then_some((tv, rt))
    };
    let mut radius = 0.5 * scale;
    let mut iterations = 0;
    while !tol(&r) {
        if !r.iter().all(|x| x.is_finite()) {
            return Err(EquilibriumError::NonFinite("the effort balance".into()));
        }
        if iterations >= MAX_ITERATIONS {
            return Err(EquilibriumError::Diverged {
                iterations,
                residual: norm(&r),
            });
        }
        let jv = eval(&j_tape, &vars);
        let jm = DMatrix::from_row_slice(m, n, &jv);
        let svd = jm.clone().svd(true, true);
        let smax = svd.singular_values.max().max(1e-300);
        let rhs = -DVector::from_column_slice(&r);
        let step = svd
            .solve(&rhs, 1e-12 * smax)
            .map_err(|e| EquilibriumError::NonFinite(e.to_string()))?;
        // backtracking line search on ½‖F‖² along the Newton step (a descent direction)
        let x = x_of(&vars);
        let phi0 = merit(&r);
        let slope = -2.0 * phi0;
        let mut alpha = 1.0;
        let mut accepted = None;
        while alpha > 1e-10 {
            let trial: Vec<f64> = x
                .iter()
                .zip(step.iter())
                .map(|(a, d)| a + alpha * d)
                .collect();
            let mut tv = vars.clone();
            set_x(&mut tv, &trial);
            let rt = eval(&f_tape, &tv);
            if rt.iter().all(|v| v.is_finite()) && merit(&rt) <= phi0 + 1e-4 * alpha * slope {
                accepted = Some((tv, rt));
                break;
            }
            alpha *= 0.5;
        }
        iterations += 1;
        // Newton stalled: damped steps along the loads, the trust radius shrinking until one
        // lowers ½‖F‖²
        if accepted.is_none() && nv > 0 {
            while radius > 1e-12 * scale {
                if let Some((tv, rt)) = damped(&vars, &r, radius) {
                    if merit(&rt) < phi0 {
                        accepted = Some((tv, rt));
                        break;
                    }
                }
                radius *= 0.25;
            }
        }
        match accepted {
            Some((tv, rt)) => {
                vars = tv;
                r = rt;
            }
            None => {
                if tol(&r) {
                    break;
                }
                let worst = r
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                    .map(|(i, _)| names[i].clone())
                    .unwrap_or_default();
                return Err(EquilibriumError::NoBalance {
                    iterations,
                    residual: norm(&r),
                    worst,
                });
            }
        }
    }
    // the reduced tangent stiffness, mass-normalised: K_r z = ω² M_r z on the DOF
    let (kr, z, _) = reduced(&vars);
    let eig = mass_normalised_eigenvalues(&kr, &z, &sys.mass);
    let stability = Stability::of(&eig);
    let stable = stability == Stability::Stable;
    // reactions and drivers from the multipliers
    let mut y: Vec<f64> = vars[1..].to_vec();
    y.truncate(nq + nv + nc);
    let mut reval = ReactionEval::new(
        &sys,
        &tapes.gv,
        Multipliers::Unknowns(nq + nv),
        (true, true),
    );
    let mut out = vec![0.0; reval.n_columns];
    reval.eval(t0, &y, &mut out);
    let columns = sys.reaction_columns();
    let nr: usize = sys.reactions.iter().map(|r| r.n_columns()).sum();
    let pairs: Vec<(String, f64)> = columns.into_iter().zip(out).collect();
    let (reactions, drivers) = pairs.split_at(nr);
    Ok(Equilibrium {
        converged: true,
        iterations,
        residual: norm(&r),
        coordinates: run_coordinates(&sys, &vars[1..1 + nq]),
        reactions: reactions.to_vec(),
        drivers: drivers
            .iter()
            .filter(|(k, _)| !k.ends_with(".power"))
            .cloned()
            .collect(),
        stable,
        stability,
        stiffness_eigenvalues: eig,
        cpu_seconds: 0.0,
        multipliers: vars[1 + nq + nv..].to_vec(),
    })
}

/// The coordinates `q` keyed as the run CSV names them: a spatial body's Euler parameters
/// `e0…e3` (integrated, of any norm: the attitude is `e / |e|`, and the effort balance does
/// not fix the scale) become the unit quaternion `q = e / |e|` under `qw, qx, qy, qz`; every
/// other coordinate keeps its column's name.
pub(crate) fn run_coordinates(sys: &MultibodySystem, q: &[f64]) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = sys
        .coords
        .iter()
        .zip(q)
        .map(|(c, &v)| (c.name.clone(), v))
        .collect();
    for (body, _) in &sys.bodies {
        let at: Vec<usize> = (0..4)
            .filter_map(|k| {
                let name = format!("{body}.e{k}");
                out.iter().position(|(n, _)| *n == name)
            })
            .collect();
        if at.len() != 4 {
            continue;
        }
        let norm = at.iter().map(|&i| out[i].1 * out[i].1).sum::<f64>().sqrt();
        for (&i, n) in at.iter().zip(["qw", "qx", "qy", "qz"]) {
            out[i].0 = format!("{body}.{n}");
            if norm > 0.0 {
                out[i].1 /= norm;
            }
        }
    }
    out
}

/// An orthonormal basis (columns) of the null space of `a` (`rows × cols`).
fn null_space(a: &DMatrix<f64>, cols: usize) -> DMatrix<f64> {
    if a.nrows() == 0 {
        return DMatrix::identity(cols, cols);
    }
    // the eigenvectors of aᵀa with (relatively) zero eigenvalue
    let ata = a.transpose() * a;
    let e = ata.symmetric_eigen();
    let lmax = e.eigenvalues.amax().max(1e-300);
    let keep: Vec<usize> = (0..cols)
        .filter(|&k| e.eigenvalues[k].abs() <= 1e-10 * lmax)
        .collect();
    DMatrix::from_fn(cols, keep.len(), |i, k| e.eigenvectors[(i, keep[k])])
}
