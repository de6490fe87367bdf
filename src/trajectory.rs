//! Typed views of a [`Solution`]: per-body state, requested points, energy and constraint
//! error over time, read from the name-keyed columns (`bar2.x`, `bar2.A.y`, `energy`, …) so a
//! typo becomes a `None` at one place instead of a `NaN` in a table.
//!
//! ```
//! use bondmech::{BodyTrajectory, Ground, Mechanism, Model, PlanarBody};
//!
//! let scene = Mechanism::planar()
//!     .gravity([0.0, -9.81])
//!     .body(PlanarBody::bar("bar", 1.0, 1.0).at([0.5, 0.0], 0.0))
//!     .revolute("pivot", Ground.at([0.0, 0.0]), ("bar", "O"))
//!     .output("bar.A")
//!     .output("energy")
//!     .t_end(0.5)
//!     .build()?;
//! let model = Model::new(&scene)?;
//! let sol = model.solve(&model.default_options())?;
//!
//! let Some(BodyTrajectory::Planar(bar)) = sol.body("bar") else { panic!("a planar body") };
//! let tip = sol.point("bar", "A").unwrap();
//! for k in 0..sol.times().len() {
//!     // the tip A is at the centre plus (L/2)(cos θ, sin θ)
//!     assert!((tip.x[k] - (bar.x[k] + 0.5 * bar.angle[k].cos())).abs() < 1e-9);
//! }
//! let energy = sol.energy().unwrap();
//! assert!((energy[energy.len() - 1] - energy[0]).abs() < 1e-3);
//! assert!(sol.constraint_error().unwrap().iter().all(|&g| g < 1e-6));
//! # Ok::<(), bondmech::Error>(())
//! ```

use crate::solve::Solution;

/// The state of a planar body over time (one entry per output time).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarTrajectory {
    /// Centre of mass `x` (m).
    pub x: Vec<f64>,
    /// Centre of mass `y` (m).
    pub y: Vec<f64>,
    /// Angle θ (rad, continuous: not wrapped to (−π, π]).
    pub angle: Vec<f64>,
    /// Centre of mass velocity `ẋ` (m/s).
    pub vx: Vec<f64>,
    /// Centre of mass velocity `ẏ` (m/s).
    pub vy: Vec<f64>,
    /// Angular velocity `ω = θ̇` (rad/s).
    pub omega: Vec<f64>,
}

/// The state of a spatial body over time (one entry per output time).
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialTrajectory {
    /// Centre of mass `x` (m).
    pub x: Vec<f64>,
    /// Centre of mass `y` (m).
    pub y: Vec<f64>,
    /// Centre of mass `z` (m).
    pub z: Vec<f64>,
    /// Centre of mass velocity, `x` component (m/s).
    pub vx: Vec<f64>,
    /// Centre of mass velocity, `y` component (m/s).
    pub vy: Vec<f64>,
    /// Centre of mass velocity, `z` component (m/s).
    pub vz: Vec<f64>,
    /// Angular velocity in body axes, `x` (rad/s).
    pub wx: Vec<f64>,
    /// Angular velocity in body axes, `y` (rad/s).
    pub wy: Vec<f64>,
    /// Angular velocity in body axes, `z` (rad/s).
    pub wz: Vec<f64>,
    /// Angular velocity in inertial axes, `ω_X = R ω` (rad/s).
    pub w_inertial_x: Vec<f64>,
    /// Angular velocity in inertial axes, `ω_Y` (rad/s).
    pub w_inertial_y: Vec<f64>,
    /// Angular velocity in inertial axes, `ω_Z` (rad/s).
    pub w_inertial_z: Vec<f64>,
    /// Cardan angle ψ of `R = Ψ Θ Φ` (seed 16.2): `atan2(R₂₁, R₁₁)`, continuous.
    pub psi: Vec<f64>,
    /// Cardan angle θ: `atan2(−R₃₁, √(R₁₁² + R₂₁²))`.
    pub theta: Vec<f64>,
    /// Cardan angle φ: `atan2(R₃₂, R₃₃)`, continuous.
    pub phi: Vec<f64>,
}

/// A body's trajectory: planar or spatial, after the scene's dimension.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyTrajectory {
    /// A body of a planar scene.
    Planar(PlanarTrajectory),
    /// A body of a spatial scene (boxed: fifteen series against the planar six).
    Spatial(Box<SpatialTrajectory>),
}

impl BodyTrajectory {
    /// The planar trajectory, if the body is planar.
    pub fn planar(&self) -> Option<&PlanarTrajectory> {
        match self {
            BodyTrajectory::Planar(p) => Some(p),
            BodyTrajectory::Spatial(_) => None,
        }
    }

    /// The spatial trajectory, if the body is spatial.
    pub fn spatial(&self) -> Option<&SpatialTrajectory> {
        match self {
            BodyTrajectory::Spatial(s) => Some(s),
            BodyTrajectory::Planar(_) => None,
        }
    }
}

/// The position of a body point over time (requested with `outputs: ["BODY.POINT"]`).
#[derive(Clone, Debug, PartialEq)]
pub struct PointTrajectory {
    /// `x` (m).
    pub x: Vec<f64>,
    /// `y` (m).
    pub y: Vec<f64>,
    /// `z` (m), for a spatial scene.
    pub z: Option<Vec<f64>>,
}

impl Solution {
    /// The output times (the same as the field [`Solution::times`]).
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The standard columns of body `name` (`name.x`, `name.y`, …) as a typed trajectory;
    /// `None` when the solution has no such body (or comes from a raw bond graph).
    pub fn body(&self, name: &str) -> Option<BodyTrajectory> {
        let c = |what: &str| self.column(&format!("{name}.{what}"));
        if self.columns.iter().any(|n| *n == format!("{name}.z")) {
            Some(BodyTrajectory::Spatial(Box::new(SpatialTrajectory {
                x: c("x")?,
                y: c("y")?,
                z: c("z")?,
                vx: c("vx")?,
                vy: c("vy")?,
                vz: c("vz")?,
                wx: c("wx")?,
                wy: c("wy")?,
                wz: c("wz")?,
                w_inertial_x: c("wX")?,
                w_inertial_y: c("wY")?,
                w_inertial_z: c("wZ")?,
                psi: c("psi")?,
                theta: c("theta")?,
                phi: c("phi")?,
            })))
        } else {
            Some(BodyTrajectory::Planar(PlanarTrajectory {
                x: c("x")?,
                y: c("y")?,
                angle: c("angle")?,
                vx: c("vx")?,
                vy: c("vy")?,
                omega: c("omega")?,
            }))
        }
    }

    /// The position of `point` of `body` (columns `body.point.x`, `.y`, `.z`); `None` unless
    /// the scene asked for it in `outputs`.
    pub fn point(&self, body: &str, point: &str) -> Option<PointTrajectory> {
        let c = |axis: &str| self.column(&format!("{body}.{point}.{axis}"));
        Some(PointTrajectory {
            x: c("x")?,
            y: c("y")?,
            z: c("z"),
        })
    }

    /// Total mechanical energy `E = T + V` over time (kinetic, gravity and springs; for a raw
    /// bond graph `Σ p²/2m + Σ q²/2C`); `None` unless the scene asked for `energy`.
    pub fn energy(&self) -> Option<Vec<f64>> {
        self.column("energy")
    }

    /// `max_i |g_i(q)|` at each output time (for the decoupled twin: the largest spring
    /// stretch); `None` for a raw bond graph, which has no such column.
    pub fn constraint_error(&self) -> Option<Vec<f64>> {
        self.column("constraint_error")
    }
}
