//! DAE against decoupled twin, side by side.

use crate::solve::formulation::shared::joints_in_words;
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
    /// A joint reaction force component `J.Fx`, `J.Fy`, `J.Fz` (N).
    Force,
    /// A joint reaction moment component `J.Mx`, `J.My`, `J.Mz` (N·m).
    Moment,
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
        "Fx" | "Fy" | "Fz" => ColumnKind::Force,
        "Mx" | "My" | "Mz" => ColumnKind::Moment,
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

/// The body `b` when `name` is one of its Cardan columns `b.psi`, `b.theta`, `b.phi` and all
/// three are present.
fn cardan_body<'a>(name: &'a str, columns: &[String]) -> Option<&'a str> {
    let (body, last) = name.rsplit_once('.')?;
    if !matches!(last, "psi" | "theta" | "phi") {
        return None;
    }
    let has = |s: &str| columns.iter().any(|c| c == &format!("{body}.{s}"));
    (has("psi") && has("theta") && has("phi")).then_some(body)
}

/// Cardan rotation `R = Rz(ψ) Ry(θ) Rx(φ)` (seed 16.2).
fn cardan_matrix(psi: f64, theta: f64, phi: f64) -> [[f64; 3]; 3] {
    let (s1, c1) = psi.sin_cos();
    let (s2, c2) = theta.sin_cos();
    let (s3, c3) = phi.sin_cos();
    [
        [c1 * c2, c1 * s2 * s3 - s1 * c3, c1 * s2 * c3 + s1 * s3],
        [s1 * c2, s1 * s2 * s3 + c1 * c3, s1 * s2 * c3 - c1 * s3],
        [-s2, c2 * s3, c2 * c3],
    ]
}

/// Largest attitude difference of `body` over time: the angle of the relative rotation
/// `R_aᵀ R_b`, `acos((tr(R_aᵀ R_b) − 1)/2)`, reported under the column `body.cardan`. Comparing
/// ψ, θ, φ one by one would report the arbitrary branch that each run takes through
/// θ = ±π/2 (e.g. (ψ, φ) = (−π, π) against (−2π, 2π), the same orientation).
fn attitude_difference(body: &str, dae: &Solution, dec: &Solution, best: &mut LargestDifference) {
    let col = |s: &Solution, c: &str| s.columns.iter().position(|n| n == &format!("{body}.{c}"));
    let (Some(a), Some(b), Some(c)) = (col(dae, "psi"), col(dae, "theta"), col(dae, "phi")) else {
        return;
    };
    let (Some(x), Some(y), Some(z)) = (col(dec, "psi"), col(dec, "theta"), col(dec, "phi")) else {
        return;
    };
    for (k, kb) in paired_rows(dae, dec) {
        let (ra, rb) = (&dae.rows[k], &dec.rows[kb]);
        let ma = cardan_matrix(ra[a], ra[b], ra[c]);
        let mb = cardan_matrix(rb[x], rb[y], rb[z]);
        let trace: f64 = (0..3)
            .map(|i| (0..3).map(|j| ma[j][i] * mb[j][i]).sum::<f64>())
            .sum();
        // the sine form, |skew(R_aᵀ R_b)|, keeps small angles accurate where acos does not
        let mut s = [0.0; 3];
        for (n, (i, j)) in [(1, 2), (2, 0), (0, 1)].into_iter().enumerate() {
            let rij: f64 = (0..3).map(|l| ma[l][i] * mb[l][j]).sum();
            let rji: f64 = (0..3).map(|l| ma[l][j] * mb[l][i]).sum();
            s[n] = 0.5 * (rji - rij);
        }
        let sin = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        let d = sin.atan2(0.5 * (trace - 1.0));
        if d > best.value || (d.is_nan() && !best.value.is_nan()) {
            *best = LargestDifference {
                value: d,
                column: format!("{body}.cardan"),
                t: dae.times[k],
            };
        }
    }
}

/// Row pairs `(k_dae, k_dec)` at the same time: the output times both runs share (event rows,
/// at times only one run has, are left out).
fn paired_rows(dae: &Solution, dec: &Solution) -> Vec<(usize, usize)> {
    let mut out = Vec::with_capacity(dae.times.len());
    let mut j = 0;
    for (k, &t) in dae.times.iter().enumerate() {
        while j < dec.times.len() && dec.times[j] < t {
            j += 1;
        }
        if j < dec.times.len() && dec.times[j] == t {
            out.push((k, j));
            j += 1;
        }
    }
    out
}

/// Serialises a largest difference as `null` when no column of its kind was compared (e.g.
/// reactions that neither run computed), never as a difference of 0.
fn null_when_absent<S: serde::Serializer>(
    d: &LargestDifference,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    if d.column.is_empty() {
        s.serialize_none()
    } else {
        d.serialize(s)
    }
}

/// Which formulation `compare` recommends, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// `"dae"` or `"decoupled"`: the decoupled twin is recommended only where it is both
    /// cheaper (CPU) and within the scene's position tolerance of the DAE.
    pub recommended: String,
    /// Decoupled CPU time / DAE CPU time.
    pub cpu_ratio: f64,
    /// Decoupled steps / DAE steps.
    pub steps_ratio: f64,
    /// Largest position difference between the two (m).
    pub max_position_difference: f64,
    /// The scene's position tolerance: `atol + rtol · L`, `L` the largest position coordinate
    /// of the DAE's motion (m).
    pub position_tolerance: f64,
    /// One sentence.
    pub reason: String,
}

impl Verdict {
    /// Judges the twin against the DAE: cheaper and within `position_tolerance`, or not.
    pub fn new(
        dae: &Summary,
        dec: &Summary,
        max_position_difference: f64,
        position_tolerance: f64,
    ) -> Verdict {
        let cpu_ratio = dec.cpu_seconds / dae.cpu_seconds.max(1e-12);
        let steps_ratio = dec.steps as f64 / (dae.steps.max(1)) as f64;
        let d = max_position_difference;
        let within = d <= position_tolerance;
        let cheaper = cpu_ratio < 1.0;
        let complete = dae.completed && dec.completed;
        let recommended = if within && cheaper && complete {
            "decoupled"
        } else {
            "dae"
        };
        let k = dec.joint_stiffness;
        let reason = if !complete {
            "one of the runs did not reach the end; the DAE keeps the joints exact".to_string()
        } else if within && cheaper {
            format!(
                "the decoupled twin (k = {k:.0e}) is cheaper ({cpu_ratio:.2}× the DAE's CPU, {steps_ratio:.2}× its steps) and within the scene's tolerance ({d:.1e} m ≤ {position_tolerance:.1e} m)"
            )
        } else if within {
            format!(
                "the decoupled twin (k = {k:.0e}) agrees ({d:.1e} m ≤ {position_tolerance:.1e} m) but costs {cpu_ratio:.1}× the DAE's CPU and {steps_ratio:.1}× its steps"
            )
        } else if cheaper {
            format!(
                "the decoupled twin (k = {k:.0e}) is cheaper ({cpu_ratio:.2}× the DAE's CPU) but {d:.1e} m off, beyond the scene's tolerance {position_tolerance:.1e} m"
            )
        } else {
            format!(
                "the decoupled twin (k = {k:.0e}) costs {cpu_ratio:.1}× the DAE's CPU and {steps_ratio:.1}× its steps for a {d:.1e} m difference (tolerance {position_tolerance:.1e} m)"
            )
        };
        Verdict {
            recommended: recommended.into(),
            cpu_ratio,
            steps_ratio,
            max_position_difference: d,
            position_tolerance,
            reason,
        }
    }
}

/// The result of `bondmech compare`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Largest position difference (m).
    pub position: LargestDifference,
    /// Largest angle difference (rad); for a spatial body the angle of the rotation between the
    /// two attitudes (column `b.cardan`), not the difference of one Cardan angle.
    pub angle: LargestDifference,
    /// Largest velocity difference (m/s).
    pub velocity: LargestDifference,
    /// Largest angular velocity difference (rad/s).
    pub angular_velocity: LargestDifference,
    /// Largest joint reaction force difference (N; reaction columns present in both runs;
    /// JSON `null` when no reactions were computed).
    #[serde(serialize_with = "null_when_absent")]
    pub force: LargestDifference,
    /// Largest joint reaction moment difference (N·m; JSON `null` when not computed).
    #[serde(serialize_with = "null_when_absent")]
    pub moment: LargestDifference,
    /// DAE run.
    pub dae: Summary,
    /// Decoupled run.
    pub decoupled: Summary,
    /// What the twin's energy figure measures: its total includes the energy stored in the
    /// joint springs, which the DAE does not have.
    pub decoupled_energy_note: String,
    /// Which formulation to use, and why.
    pub verdict: Verdict,
}

impl Comparison {
    /// Compares two solutions at the same output times, judged at the default tolerances
    /// (`rtol` 1e-8, `atol` 1e-10).
    pub fn new(dae: &Solution, dec: &Solution) -> Comparison {
        Comparison::judged(dae, dec, (1e-8, 1e-10))
    }

    /// Compares two solutions at the same output times; `tolerances = (rtol, atol)` of the scene
    /// set the position tolerance of the verdict.
    pub fn judged(dae: &Solution, dec: &Solution, tolerances: (f64, f64)) -> Comparison {
        let mut best = [
            LargestDifference::default(),
            LargestDifference::default(),
            LargestDifference::default(),
            LargestDifference::default(),
            LargestDifference::default(),
            LargestDifference::default(),
        ];
        for (ci, name) in dae.columns.iter().enumerate() {
            // spatial attitudes are compared as rotations, not angle by angle (below)
            if let Some(body) = cardan_body(name, &dae.columns) {
                if name.ends_with(".psi") {
                    attitude_difference(body, dae, dec, &mut best[1]);
                }
                continue;
            }
            let slot = match column_kind(name) {
                ColumnKind::Position => 0,
                ColumnKind::Angle => 1,
                ColumnKind::Velocity => 2,
                ColumnKind::AngularVelocity => 3,
                ColumnKind::Force => 4,
                ColumnKind::Moment => 5,
                ColumnKind::Other => continue,
            };
            let Some(cj) = dec.columns.iter().position(|n| n == name) else {
                continue;
            };
            for (k, kb) in paired_rows(dae, dec) {
                let d = (dae.rows[k][ci] - dec.rows[kb][cj]).abs();
                if d > best[slot].value || (d.is_nan() && !best[slot].value.is_nan()) {
                    best[slot] = LargestDifference {
                        value: d,
                        column: name.clone(),
                        t: dae.times[k],
                    };
                }
            }
        }
        let [position, angle, velocity, angular_velocity, force, moment] = best;
        // the scene's tolerance, from the DAE's motion: atol + rtol · L
        let extent = dae
            .columns
            .iter()
            .enumerate()
            .filter(|(_, n)| column_kind(n) == ColumnKind::Position)
            .flat_map(|(c, _)| dae.rows.iter().map(move |r| r[c].abs()))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let tolerance = tolerances.1 + tolerances.0 * extent;
        let verdict = Verdict::new(&dae.summary, &dec.summary, position.value, tolerance);
        Comparison {
            position,
            angle,
            velocity,
            angular_velocity,
            force,
            moment,
            dae: dae.summary.clone(),
            decoupled: dec.summary.clone(),
            decoupled_energy_note: format!(
                "the decoupled twin's energy includes its joint springs' (k = {:.0e}): its drift is measured on that total, not on the mechanism's energy alone",
                dec.summary.joint_stiffness
            ),
            verdict,
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
            ("reaction force (N)", &self.force),
            ("reaction moment (N·m)", &self.moment),
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
                drift_cell(a.energy_drift),
                drift_cell(b.energy_drift),
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
        if b.energy_drift.is_some() {
            s.push_str(&format!("(energy drift: {})\n", self.decoupled_energy_note));
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
                joints_in_words(&p.joints),
            ));
        }
        let v = &self.verdict;
        s.push_str(&format!(
            "\nverdict: use {} — {}\n",
            v.recommended, v.reason
        ));
        s
    }
}

/// `1.234e-7`, or `- (not conserved)` where the scene exchanges energy.
fn drift_cell(d: Option<f64>) -> String {
    d.map_or_else(|| "- (not conserved)".into(), |d| format!("{d:.3e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn solution(columns: &[&str], rows: Vec<Vec<f64>>) -> Solution {
        Solution {
            columns: columns.iter().map(|c| c.to_string()).collect(),
            times: (0..rows.len()).map(|k| k as f64).collect(),
            rows,
            summary: Default::default(),
        }
    }

    /// Bricard's mechanism: bar1 turns about Y through θ = π/2, where the DAE took the branch
    /// (ψ, φ) = (−2π, 2π) and the twin (0, 0): the same attitude, reported as 2π apart before.
    #[test]
    fn compare_cardan_branch_through_gimbal_lock_is_not_a_difference() {
        let cols = ["bar1.psi", "bar1.theta", "bar1.phi", "bar2.angle"];
        let a = solution(&cols, vec![vec![-2.0 * PI, 1.5385, 2.0 * PI, 0.0]]);
        let b = solution(&cols, vec![vec![0.0, 1.5385, 0.0, 0.0]]);
        let c = Comparison::new(&a, &b);
        assert!(c.angle.value < 1e-12, "{:?}", c.angle);
        // (ψ, θ, φ) and (ψ + π, π − θ, φ + π) are one attitude too
        let b2 = solution(&cols, vec![vec![-PI, PI - 1.5385, 3.0 * PI, 0.0]]);
        assert!(Comparison::new(&a, &b2).angle.value < 1e-12);
    }

    #[test]
    fn compare_cardan_reports_the_relative_rotation_angle() {
        let cols = ["bar1.psi", "bar1.theta", "bar1.phi", "bar2.angle"];
        let a = solution(&cols, vec![vec![0.3, 0.2, 0.1, 0.0]]);
        // a further 1e-3 rad about the body x axis: φ + 1e-3
        let b = solution(&cols, vec![vec![0.3, 0.2, 0.1 + 1e-3, 0.0]]);
        let c = Comparison::new(&a, &b);
        assert!((c.angle.value - 1e-3).abs() < 1e-12, "{:?}", c.angle);
        assert_eq!(c.angle.column, "bar1.cardan");
        // planar angles keep the plain difference
        let d = solution(&cols, vec![vec![0.3, 0.2, 0.1, 0.5]]);
        let c = Comparison::new(&a, &d);
        assert!((c.angle.value - 0.5).abs() < 1e-15 && c.angle.column == "bar2.angle");
    }
}
