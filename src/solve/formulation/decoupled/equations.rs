//! The decoupled twin (seed 16.6, Fig. 17–18, 21): every joint row replaced by a stiff spring.
//!
//! The twin is a transformation of the mechanism's bond graph ([`crate::bond::decouple`]):
//! each constraint junction is opened and a C of stiffness `k` (displacement: the joint's
//! closure `g_i(q)`) with an R of damping `c` is put in, as the chapter draws it, so every
//! inertia gets integral causality. Reading that graph as a mechanism
//! ([`crate::bond::mechanics`]) gives the ODE
//!
//! ```text
//!   q' = K(q) v
//!   M v' = Q(t, q, v) − G_vᵀ (k g(q) + c G_v v)
//! ```
//!
//! solved by CVODE (BDF, Newton, exact Jacobian): `graph --decoupled` draws exactly this graph.
//! Rows that fix an angle (prismatic, weld) get a torsional spring of the same numeric
//! stiffness `k` (N·m/rad).

use crate::bond::decouple::{decouple, DecoupledGraph};
use crate::bond::mechanics::read_mechanics_in;
use crate::dae::compiled::ExplicitOde;
use crate::expr::Expr;
use crate::mech::{MechError, MultibodySystem};

/// The stiff-spring ODE of a multibody system, compiled with its exact Jacobian.
#[derive(Clone, Debug)]
pub struct DecoupledFormulation {
    /// `y' = f(t, y)` with `y = [q, v]`.
    pub ode: ExplicitOde,
    /// Joint stiffness k.
    pub stiffness: f64,
    /// Joint damping c.
    pub damping: f64,
    /// Spring energy `½ k Σ g_i²` (the twin's springs' stored energy), to add to the
    /// mechanical energy.
    pub spring_energy: Expr,
    /// Force of each row's spring-damper, `k g_i + c (G_v v)_i` (the effort at the opened
    /// junction): the twin's counterpart of the multipliers λ (the joint reactions are read
    /// from it).
    pub row_force: Vec<Expr>,
    /// The twin's bond graph.
    pub twin: DecoupledGraph,
}

impl DecoupledFormulation {
    /// Opens the joints of the bond graph `sys` was read from, reads the twin's equations into
    /// `sys`'s expression arena and compiles the ODE; fails when a coordinate has no inertia
    /// (the ODE would be singular) or when `sys` was not read from a bond graph.
    pub fn build(
        sys: &mut MultibodySystem,
        stiffness: f64,
        damping: f64,
    ) -> Result<Self, MechError> {
        let err = |m: String| MechError::at("solve.formulation", m);
        if let Some((j, _)) = sys.mass.iter().enumerate().find(|(_, &m)| m <= 0.0) {
            return Err(err(format!(
                "the decoupled twin needs an inertia on every coordinate, but '{}' has none (a point mass whose rotation is fixed only by joints): give the body an inertia, or solve it as a DAE",
                sys.velocities[j].name
            )));
        }
        let pinned = sys.bond_graph.clone().ok_or_else(|| {
            err("the decoupled twin is a transformation of the mechanism's bond graph, and this model's equations were not read from one".into())
        })?;
        let twin = decouple(&pinned, stiffness, damping)
            .map_err(|e| err(format!("decoupled twin: {e}")))?;
        let eqs = read_mechanics_in(&twin.graph, sys.graph.clone())
            .map_err(|e| err(format!("decoupled twin: {e}")))?;
        let same = |a: &[crate::bond::mechanics::NamedState], b: &[crate::mech::Coordinate]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.name == y.name)
        };
        if !same(&eqs.coords, &sys.coords) || !same(&eqs.velocities, &sys.velocities) {
            return Err(err(
                "decoupled twin: opening the joints changed the graph's states".into(),
            ));
        }
        let (nq, nv) = (sys.nq(), sys.nv());
        let mut g = eqs.graph;
        let mut row_force = Vec::with_capacity(twin.springs.len());
        let mut stored = Vec::with_capacity(twin.springs.len());
        for s in &twin.springs {
            let (_, delta, flow) = eqs
                .capacitors
                .iter()
                .find(|(c, _, _)| *c == s.spring)
                .copied()
                .ok_or_else(|| err(format!("decoupled twin: no spring for joint '{}'", s.joint)))?;
            // junction effort k δ + c f, and λ = s (k δ + c f)
            let a = g.scale(stiffness, delta);
            let b = g.scale(damping, flow);
            let e = g.add(a, b);
            row_force.push(g.scale(s.sign, e));
            let d2 = g.mul(delta, delta);
            stored.push(g.scale(0.5 * stiffness, d2));
        }
        let spring_energy = g.sum(&stored);
        let mut rhs: Vec<Expr> = eqs.kinematics.clone();
        for j in 0..nv {
            rhs.push(g.scale(1.0 / sys.mass[j], eqs.forces[j]));
        }
        debug_assert_eq!(rhs.len(), nq + nv);
        let ode = ExplicitOde::build(&mut g, &rhs);
        sys.graph = g;
        Ok(DecoupledFormulation {
            ode,
            stiffness,
            damping,
            spring_energy,
            row_force,
            twin,
        })
    }
}

/// Positions of the decoupled twin in static balance with the pinned mechanism's joint
/// forces: the least change of `q` with `k g(q) = λ` (the spring of each row carries the force
/// its joint row carried), so the start excites no spurious spring oscillation of amplitude
/// `λ/k` — which the error test would otherwise resolve at a cost growing like `√k`.
pub fn prestressed_positions(
    tapes: &crate::dae::MechanicsTapes,
    t0: f64,
    q: &[f64],
    v: &[f64],
    lambda: &[f64],
    stiffness: f64,
) -> Vec<f64> {
    let (nq, _, _) = tapes.dims;
    let target: Vec<f64> = lambda.iter().map(|l| l / stiffness).collect();
    let mut x: Vec<f64> = q.iter().chain(v).copied().collect();
    for _ in 0..10 {
        let g = crate::dae::MechanicsTapes::eval(&tapes.g, t0, &x);
        let r: Vec<f64> = g.iter().zip(&target).map(|(a, b)| a - b).collect();
        let scale = target.iter().fold(1e-300f64, |a, b| a.max(b.abs()));
        if r.iter().all(|e| e.abs() <= 1e-12 * scale + 1e-15) {
            break;
        }
        let gq = tapes.gq.matrix(t0, &x);
        let Some(dq) = gq
            .svd(true, true)
            .solve(&nalgebra::DVector::from_vec(r), 1e-12)
            .ok()
        else {
            break;
        };
        for i in 0..nq {
            x[i] -= dq[i];
        }
    }
    x.truncate(nq);
    x
}

/// Fraction of the bodies' size (translation rows) or radians (rotation rows) above which the
/// twin's initial spring stretch `λ/k` makes a warning: the twin then starts far from the
/// pinned mechanism, and its results say little about it.
pub const PRESTRESS_WARNING_FRACTION: f64 = 0.1;

/// A warning when the decoupled twin's springs start stretched by more than
/// [`PRESTRESS_WARNING_FRACTION`] of the bodies' size (`sys.body_size`; rows in metres: `x`, `y`,
/// `z`, `normal…`) or by more than 0.1 rad (rows fixing an angle), from the pinned mechanism's
/// joint forces `lambda` at the start and the stiffness `k`: the stretch of row `i` is `|λ_i|/k`
/// (the prestress of [`prestressed_positions`]). `None` when every stretch is below the limit.
///
/// `solve.joint_stiffness = 1e-3` on the compound pendulum (λ ≈ 2.8 N) starts the bar 2.8 km
/// from its pivot: this warning says so and names the stiffness that keeps the stretch under a
/// tenth of the limit.
pub fn prestress_warning(sys: &MultibodySystem, lambda: &[f64], stiffness: f64) -> Option<String> {
    let translation = |d: &str| matches!(d, "x" | "y" | "z") || d.starts_with("normal");
    let size = if sys.body_size > 0.0 {
        sys.body_size
    } else {
        1.0
    };
    // worst row relative to its limit
    let (i, ratio) = sys
        .rows
        .iter()
        .zip(lambda)
        .enumerate()
        .map(|(i, (row, l))| {
            let limit = if translation(&row.direction) {
                PRESTRESS_WARNING_FRACTION * size
            } else {
                PRESTRESS_WARNING_FRACTION
            };
            (i, (l.abs() / stiffness) / limit)
        })
        .filter(|(_, r)| r.is_finite())
        .fold(None, |best: Option<(usize, f64)>, (i, r)| match best {
            Some((_, b)) if b >= r => best,
            _ => Some((i, r)),
        })?;
    if ratio <= 1.0 {
        return None;
    }
    let row = &sys.rows[i];
    let stretch = lambda[i].abs() / stiffness;
    let (unit, what, limit) = if translation(&row.direction) {
        (
            "m",
            format!(
                "{:.0} % of the bodies' size ({size:.3e} m)",
                PRESTRESS_WARNING_FRACTION * 100.0
            ),
            PRESTRESS_WARNING_FRACTION * size,
        )
    } else {
        (
            "rad",
            format!("{PRESTRESS_WARNING_FRACTION} rad"),
            PRESTRESS_WARNING_FRACTION,
        )
    };
    let suggested = lambda[i].abs() / (0.1 * limit);
    Some(format!(
        "solve.joint_stiffness = {stiffness:e}: the decoupled twin's springs start stretched by λ/k = {stretch:.3e} {unit} (joint '{}', row {}, joint force {:.3e}), more than {what}: the twin starts far from the pinned mechanism and its results mean little; a stiffness of at least {suggested:.1e} keeps it under {:.1e} {unit}",
        row.joint, row.direction, lambda[i].abs(), 0.1 * limit
    ))
}
