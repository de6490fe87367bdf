//! DAE against decoupled twin, side by side.

use serde::Serialize;

use crate::solve::{Solution, Summary};

/// What kind of quantity a column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnKind {
    /// A position coordinate (m).
    Position,
    /// An angle (rad).
    Angle,
    /// A linear velocity (m/s).
    Velocity,
    /// An angular velocity (rad/s).
    AngularVelocity,
    /// Energy, constraint error and anything else.
    Other,
}

/// Classifies a column by its name (`bar1.x` → position, `bar1.omega` → angular velocity, …).
pub fn column_kind(name: &str) -> ColumnKind {
    let last = name.rsplit('.').next().unwrap_or(name);
    match last {
        "x" | "y" | "z" => ColumnKind::Position,
        "angle" | "psi" | "theta" | "phi" => ColumnKind::Angle,
        "vx" | "vy" | "vz" => ColumnKind::Velocity,
        "omega" | "wx" | "wy" | "wz" | "wX" | "wY" | "wZ" => ColumnKind::AngularVelocity,
        _ => ColumnKind::Other,
    }
}

/// The largest difference over time of one kind of column.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LargestDifference {
    /// The difference.
    pub value: f64,
    /// In which column.
    pub column: String,
    /// At which time.
    pub t: f64,
}

/// The result of `bondmech compare`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Largest position difference (m).
    pub position: LargestDifference,
    /// Largest angle difference (rad).
    pub angle: LargestDifference,
    /// Largest velocity difference (m/s).
    pub velocity: LargestDifference,
    /// Largest angular velocity difference (rad/s).
    pub angular_velocity: LargestDifference,
    /// DAE run.
    pub dae: Summary,
    /// Decoupled run.
    pub decoupled: Summary,
}

impl Comparison {
    /// Compares two solutions at the same output times.
    pub fn new(dae: &Solution, dec: &Solution) -> Comparison {
        let mut best = [
            LargestDifference::default(),
            LargestDifference::default(),
            LargestDifference::default(),
            LargestDifference::default(),
        ];
        for (ci, name) in dae.columns.iter().enumerate() {
            let slot = match column_kind(name) {
                ColumnKind::Position => 0,
                ColumnKind::Angle => 1,
                ColumnKind::Velocity => 2,
                ColumnKind::AngularVelocity => 3,
                ColumnKind::Other => continue,
            };
            let Some(cj) = dec.columns.iter().position(|n| n == name) else {
                continue;
            };
            for (k, (ra, rb)) in dae.rows.iter().zip(&dec.rows).enumerate() {
                let d = (ra[ci] - rb[cj]).abs();
                if d > best[slot].value || (d.is_nan() && !best[slot].value.is_nan()) {
                    best[slot] = LargestDifference {
                        value: d,
                        column: name.clone(),
                        t: dae.times[k],
                    };
                }
            }
        }
        let [position, angle, velocity, angular_velocity] = best;
        Comparison {
            position,
            angle,
            velocity,
            angular_velocity,
            dae: dae.summary.clone(),
            decoupled: dec.summary.clone(),
        }
    }

    /// A readable table.
    pub fn table(&self) -> String {
        let mut s = String::new();
        s.push_str("largest difference DAE vs decoupled\n");
        for (what, d) in [
            ("position (m)", &self.position),
            ("angle (rad)", &self.angle),
            ("velocity (m/s)", &self.velocity),
            ("angular velocity (rad/s)", &self.angular_velocity),
        ] {
            if d.column.is_empty() {
                continue;
            }
            s.push_str(&format!(
                "  {what:<26} {:>11.3e}  in {} at t = {}\n",
                d.value, d.column, d.t
            ));
        }
        s.push('\n');
        s.push_str(&format!("{:<26} {:>16} {:>16}\n", "", "DAE", "decoupled"));
        let (a, b) = (&self.dae, &self.decoupled);
        let rows: Vec<(&str, String, String)> = vec![
            (
                "formulation",
                a.formulation.clone(),
                format!("k = {:.0e}", b.joint_stiffness),
            ),
            ("solver", a.solver.clone(), b.solver.clone()),
            ("unknowns", a.unknowns.to_string(), b.unknowns.to_string()),
            ("steps", a.steps.to_string(), b.steps.to_string()),
            (
                "residual/RHS evals",
                a.residual_evals.to_string(),
                b.residual_evals.to_string(),
            ),
            (
                "Jacobian evals",
                a.jacobian_evals.to_string(),
                b.jacobian_evals.to_string(),
            ),
            (
                "error test failures",
                a.error_test_failures.to_string(),
                b.error_test_failures.to_string(),
            ),
            (
                "CPU time (s)",
                format!("{:.3e}", a.cpu_seconds),
                format!("{:.3e}", b.cpu_seconds),
            ),
            (
                "max constraint error",
                format!("{:.3e}", a.max_constraint_error),
                format!("{:.3e}", b.max_constraint_error),
            ),
            (
                "energy drift (rel.)",
                format!("{:.3e}", a.energy_drift),
                format!("{:.3e}", b.energy_drift),
            ),
            ("compliance ε", format!("{:.1e}", a.compliance), "-".into()),
            (
                "singular passages",
                a.singular_passages.len().to_string(),
                "-".into(),
            ),
            (
                "compliant time (s)",
                format!("{:.3}", a.compliant_time),
                "-".into(),
            ),
        ];
        for (k, x, y) in rows {
            s.push_str(&format!("{k:<26} {x:>16} {y:>16}\n"));
        }
        for p in &a.singular_passages {
            let how = if p.failure == "conditioning peak" {
                "passed by the compliant GGL".to_string()
            } else {
                format!("{}; compliant GGL from t = {}", p.failure, p.restarted_at)
            };
            s.push_str(&format!(
                "singular passage at t = {:.6}: κ(G M⁻¹ Gᵀ) = {:.1e}, joints [{}]; {how}\n",
                p.t,
                p.condition,
                p.joints.join(", "),
            ));
        }
        s
    }
}
