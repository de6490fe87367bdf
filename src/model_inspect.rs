//! Looking at a model before solving it: its equations in readable form, its degrees of
//! freedom and the joints behind each constraint row.
//!
//! The equations are those of [`MultibodySystem`](crate::mech::MultibodySystem):
//!
//! ```text
//!   q' = K(q) v,    M v' = Q(t, q, v) − G_vᵀ λ,    0 = g(q)
//! ```
//!
//! and the number of degrees of freedom is `n_v − rank G_v`, the velocities minus the
//! independent constraint rows (the seed's count of integral-causality inertias, 16.5, 16.7),
//! with the rank taken at the consistent initial state.

use std::fmt;

use crate::dae::{consistent_state, ConstraintExprs, MechanicsTapes};
use crate::error::{Error, Result};
use crate::mech::ConstraintRow;
use crate::model::Model;

/// The equations of a model as text, variables named after the scene (`bar1.x`, `bar1.omega`).
#[derive(Clone, Debug, PartialEq)]
pub struct Equations {
    /// Kinematics, one line per coordinate: `bar1.angle' = bar1.omega`.
    pub kinematics: Vec<String>,
    /// Dynamics, one line per velocity: `m · v' = Q` (the constraint forces `−G_vᵀλ` not
    /// written).
    pub dynamics: Vec<String>,
    /// Position constraints, one line per row, named after the joint, the bond graph's
    /// constraint junction and the inertia the row puts in differential causality:
    /// `pivot (x) [junction pivot.x, differential bar1.I_m_x]: -bar1.x + 0.5*cos(bar1.angle) = 0`.
    pub constraints: Vec<String>,
    /// The flow constraint each row's junction imposes, `G_v v = 0`, one line per row:
    /// `pivot.x: -bar1.vx - 0.5*sin(bar1.angle)*bar1.omega = 0`.
    pub flows: Vec<String>,
    /// Where the equations come from: `read off the bond graph (N elements, M bonds)` or
    /// `assembled from the bodies (reason)`.
    pub source: String,
}

impl fmt::Display for Equations {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "equations   {}", self.source)?;
        writeln!(f, "kinematics  q' = K(q) v")?;
        for l in &self.kinematics {
            writeln!(f, "  {l}")?;
        }
        writeln!(f, "dynamics    M v' = Q(t, q, v) - G_v^T lambda")?;
        for l in &self.dynamics {
            writeln!(f, "  {l}")?;
        }
        writeln!(f, "constraints 0 = g(q)")?;
        for l in &self.constraints {
            writeln!(f, "  {l}")?;
        }
        if !self.flows.is_empty() {
            writeln!(f, "junction flows  0 = G_v(q) v")?;
            for l in &self.flows {
                writeln!(f, "  {l}")?;
            }
        }
        Ok(())
    }
}

/// Degrees of freedom of a model at its consistent initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct DofReport {
    /// Number of generalized coordinates `q`.
    pub coordinates: usize,
    /// Number of velocities `v` (the inertias).
    pub velocities: usize,
    /// Number of constraint rows `g(q) = 0`.
    pub constraint_rows: usize,
    /// Rank of `G_v` (independent rows).
    pub rank: usize,
    /// `velocities − rank`.
    pub dof: usize,
    /// Joints whose rows are linearly dependent on others (redundant constraints).
    pub redundant_joints: Vec<String>,
}

impl Model {
    /// The name of variable slot `i` of the state layout `[t, q, v]`.
    fn slot_name(&self, i: u32) -> String {
        let sys = self.system();
        let i = i as usize;
        let (nq, nv) = (sys.nq(), sys.nv());
        if i == 0 {
            "t".to_string()
        } else if i <= nq {
            sys.coords[i - 1].name.clone()
        } else if i <= nq + nv {
            sys.velocities[i - 1 - nq].name.clone()
        } else {
            format!("x{i}")
        }
    }

    /// The equations in readable form (see [`Equations`]); empty for a raw bond graph scene.
    ///
    /// ```
    /// # use bondmech::{Ground, Mechanism, Model, PlanarBody};
    /// let scene = Mechanism::planar()
    ///     .gravity([0.0, -9.81])
    ///     .body(PlanarBody::point_mass("bob", 2.0).point("O", [-1.0, 0.0]).at([1.0, 0.0], 0.0))
    ///     .revolute("pivot", Ground.at([0.0, 0.0]), ("bob", "O"))
    ///     .t_end(1.0)
    ///     .build()?;
    /// let eq = Model::new(&scene)?.equations();
    /// assert_eq!(eq.constraints.len(), 2); // pivot x and y
    /// assert!(eq.constraints[0].starts_with("pivot"));
    /// println!("{eq}");
    /// # Ok::<(), bondmech::Error>(())
    /// ```
    pub fn equations(&self) -> Equations {
        let sys = self.system();
        let name = |i: u32| self.slot_name(i);
        let show = |e| sys.graph.display(e, &name);
        let kinematics = sys
            .coords
            .iter()
            .zip(&sys.kinematics)
            .map(|(c, &e)| format!("{}' = {}", c.name, show(e)))
            .collect();
        let dynamics = sys
            .velocities
            .iter()
            .zip(&sys.mass)
            .zip(&sys.forces)
            .map(|((v, m), &e)| format!("{m} * {}' = {}", v.name, show(e)))
            .collect();
        let report = self.causality().ok();
        let differential = |junction: &str| -> String {
            let Some(r) = &report else {
                return "?".into();
            };
            if let Some(d) = r.differential.iter().find(|d| d.origin == junction) {
                return format!("differential {}", d.element);
            }
            if r.redundant.iter().any(|x| x.junction == junction) {
                return "redundant".into();
            }
            "no differential inertia".into()
        };
        let constraints = sys
            .rows
            .iter()
            .zip(&sys.constraints)
            .map(|(r, &e)| {
                let junction = format!("{}.{}", r.joint, r.direction);
                format!(
                    "{} ({}) [junction {junction}, {}]: {} = 0",
                    r.joint,
                    r.direction,
                    differential(&junction),
                    show(e)
                )
            })
            .collect();
        let flows = sys
            .rows
            .iter()
            .zip(&sys.flow_rows)
            .map(|(r, &e)| format!("{}.{}: {} = 0", r.joint, r.direction, show(e)))
            .collect();
        let source = match &sys.source {
            crate::mech::EquationSource::BondGraph => "read off the bond graph".to_string(),
            crate::mech::EquationSource::Assembled(why) => {
                format!("assembled from the bodies ({why})")
            }
        };
        Equations {
            kinematics,
            dynamics,
            constraints,
            flows,
            source,
        }
    }

    /// The constraint rows `g_i(q) = 0` and the joint (and direction) each comes from.
    pub fn constraint_rows(&self) -> &[ConstraintRow] {
        &self.system().rows
    }

    /// Degrees of freedom `n_v − rank G_v`, with the rank taken at the consistent initial
    /// state (positions and velocities projected onto the joints, as a solve starts).
    ///
    /// Fails like a solve's start does when no consistent initial state exists, and for a
    /// raw bond graph scene (it has no coordinates: its DOF is [`Model::causality`]'s `dof`).
    /// [`Model::causality`] counts the same DOF from the bond graph: its inertias in integral
    /// causality.
    pub fn dof(&self) -> Result<DofReport> {
        if self.is_raw_bond_graph() {
            return Err(Error::Options(
                "dof() counts coordinates and joints; a raw bond graph has none (use causality())"
                    .into(),
            ));
        }
        let mut sys = self.system().clone();
        let c = ConstraintExprs::derive(&mut sys);
        let tapes = MechanicsTapes::new(&mut sys, &c, None);
        let t0 = self
            .default_options()
            .output_times
            .first()
            .copied()
            .unwrap_or(0.0);
        let init = consistent_state(&sys, &tapes, t0)?;
        Ok(DofReport {
            coordinates: sys.nq(),
            velocities: sys.nv(),
            constraint_rows: sys.nc(),
            rank: init.rank,
            dof: sys.nv() - init.rank.min(sys.nv()),
            redundant_joints: init.redundant_joints,
        })
    }
}
