//! Command-line flags and service query parameters that override a scene's `solve` section.
//!
//! Every face (the CLI's `--rtol`, the service's `?rtol=`) writes its overrides into the scene
//! through [`SolveOverrides::apply`] and the scene is validated again, so an override obeys
//! exactly the scene's own rules, and each refusal says which override caused it.
//!
//! ```
//! use bondmech::scene::SolveOverrides;
//! let mut scene = bondmech::Scene::from_path("scenes/double_pendulum.json").unwrap();
//! let bad = SolveOverrides { rtol: Some(1e308), ..SolveOverrides::default() };
//! let problems = bad.apply(&mut scene).unwrap_err();
//! assert_eq!(problems[0].overridden, Some("rtol"));
//! assert_eq!(problems[0].problem.path, "solve.rtol");
//! ```

use super::error::Problem;
use super::model::Scene;
use crate::settings::FormulationKind;

/// Values that replace the scene's `solve` fields (`None`: keep the scene's).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolveOverrides {
    /// `solve.formulation`.
    pub formulation: Option<FormulationKind>,
    /// `solve.rtol`.
    pub rtol: Option<f64>,
    /// `solve.atol`.
    pub atol: Option<f64>,
    /// `solve.t_end`: the run ends here and the scene's `output_times` after it are dropped
    /// (an `output_step` longer than the shortened run is cut to it).
    pub t_end: Option<f64>,
    /// `solve.joint_stiffness`.
    pub joint_stiffness: Option<f64>,
    /// `solve.max_steps`.
    pub max_steps: Option<u64>,
    /// `solve.max_wall_seconds`.
    pub max_wall_seconds: Option<f64>,
    /// `solve.linear_solver`.
    pub linear_solver: Option<crate::settings::LinearSolverKind>,
}

/// One problem of a scene with overrides applied, and the override it comes from (the field
/// name without `solve.`, e.g. `t_end`), if any.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverrideProblem {
    /// The override that caused it (`rtol`, `t_end`, …), `None` for a problem of the scene.
    pub overridden: Option<&'static str>,
    /// The problem, with the JSON path of the field.
    pub problem: Problem,
}

/// Scene fields each override writes (`t_end` also reshapes the output times).
const FIELDS: &[(&str, &[&str])] = &[
    ("formulation", &["solve.formulation"]),
    ("rtol", &["solve.rtol"]),
    ("atol", &["solve.atol"]),
    (
        "t_end",
        &["solve.t_end", "solve.output_step", "solve.output_times"],
    ),
    ("joint_stiffness", &["solve.joint_stiffness"]),
    ("max_steps", &["solve.max_steps"]),
    ("max_wall_seconds", &["solve.max_wall_seconds"]),
    ("linear_solver", &["solve.linear_solver"]),
];

impl SolveOverrides {
    /// Writes the overrides into `scene.solve` and validates the scene again; on failure,
    /// every problem of the scene, each with the override that caused it.
    pub fn apply(&self, scene: &mut Scene) -> Result<(), Vec<OverrideProblem>> {
        let s = &mut scene.solve;
        let mut set: Vec<&'static str> = Vec::new();
        let mut put = |name: &'static str| set.push(name);
        if let Some(f) = self.formulation {
            s.formulation = f;
            put("formulation");
        }
        if let Some(r) = self.rtol {
            s.rtol = r;
            put("rtol");
        }
        if let Some(a) = self.atol {
            s.atol = a;
            put("atol");
        }
        if let Some(k) = self.joint_stiffness {
            s.joint_stiffness = k;
            put("joint_stiffness");
        }
        if let Some(n) = self.max_steps {
            s.max_steps = Some(n);
            put("max_steps");
        }
        if let Some(w) = self.max_wall_seconds {
            s.max_wall_seconds = Some(w);
            put("max_wall_seconds");
        }
        if let Some(l) = self.linear_solver {
            s.linear_solver = l;
            put("linear_solver");
        }
        if let Some(t) = self.t_end {
            if let Some(times) = &mut s.output_times {
                times.retain(|&x| x <= t);
                if times.is_empty() && t.is_finite() {
                    return Err(vec![OverrideProblem {
                        overridden: Some("t_end"),
                        problem: Problem::new(
                            "solve.output_times",
                            format!("every time lies after t_end = {t}"),
                        ),
                    }]);
                }
            }
            if let Some(h) = &mut s.output_step {
                // a step longer than the shortened run gives just its two ends
                if t.is_finite() && t > s.t_start {
                    *h = h.min(t - s.t_start);
                }
            }
            s.t_end = t;
            put("t_end");
        }
        scene.validate().map_err(|e| {
            e.problems()
                .iter()
                .map(|p| OverrideProblem {
                    overridden: FIELDS
                        .iter()
                        .find(|(name, fields)| set.contains(name) && fields.contains(&&*p.path))
                        .map(|(name, _)| *name),
                    problem: p.clone(),
                })
                .collect()
        })
    }
}
