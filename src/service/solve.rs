//! One solve job, on a blocking thread: the scene turned into a [`Model`], the request's query
//! applied to its options, the wall-clock budget set, and the rows streamed out through
//! [`Model::solve_streaming`] so that a stop (budget, disconnect, shutdown) keeps what was
//! computed. Library errors become problems here.

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use axum::http::StatusCode;
use serde::ser::{Serialize, SerializeSeq, Serializer};
use serde_json::Value;

use super::limits::Limits;
use super::metrics::Metrics;
use super::pool::StopFlags;
use super::problem::Problem;
use crate::error::Error;
use crate::model::Model;
use crate::scene::{Scene, SolveOverrides};
use crate::settings::FormulationKind;
use crate::settings::LinearSolverKind;
use crate::solve::{Solution, SolveOptions};
use crate::sundials::SolverError;

/// Query parameters, each at most once, from a fixed list per route.
pub struct Params(BTreeMap<String, String>);

impl Params {
    /// Parses `raw` (the URI's query): 400 for a parameter not in `allowed` or given twice.
    pub fn parse(raw: Option<&str>, allowed: &[&str]) -> Result<Params, Problem> {
        let mut m = BTreeMap::new();
        for (k, v) in form_urlencoded::parse(raw.unwrap_or("").as_bytes()) {
            if !allowed.contains(&k.as_ref()) {
                return Err(Problem::bad_parameter(
                    &k,
                    format!(
                        "unknown query parameter '{k}' (this route takes: {})",
                        allowed.join(", ")
                    ),
                ));
            }
            if m.insert(k.to_string(), v.into_owned()).is_some() {
                return Err(Problem::bad_parameter(
                    &k,
                    format!("query parameter '{k}' is given more than once"),
                ));
            }
        }
        Ok(Params(m))
    }

    /// A string parameter.
    pub fn text(&self, key: &str) -> Option<&str> {
        self.0.get(key).map(String::as_str)
    }

    /// A number: 400 when it does not parse.
    pub fn number(&self, key: &str) -> Result<Option<f64>, Problem> {
        self.text(key)
            .map(|s| {
                s.trim().parse::<f64>().map_err(|_| {
                    Problem::bad_parameter(key, format!("{key}: not a number ('{s}')"))
                })
            })
            .transpose()
    }

    /// `true`/`1` or `false`/`0`: 400 otherwise.
    pub fn flag(&self, key: &str) -> Result<Option<bool>, Problem> {
        self.text(key)
            .map(|s| match s {
                "true" | "1" | "" => Ok(true),
                "false" | "0" => Ok(false),
                _ => Err(Problem::bad_parameter(
                    key,
                    format!("{key}: expected true or false (got '{s}')"),
                )),
            })
            .transpose()
    }

    /// One of `choices` (the first when absent): 400 otherwise.
    pub fn choice(&self, key: &str, choices: &[&'static str]) -> Result<&'static str, Problem> {
        match self.text(key) {
            None => Ok(choices[0]),
            Some(s) => choices.iter().copied().find(|c| *c == s).ok_or_else(|| {
                Problem::bad_parameter(
                    key,
                    format!("{key}: expected one of {} (got '{s}')", choices.join(", ")),
                )
            }),
        }
    }
}

/// 422 for a query value that parses but makes no sense.
pub fn invalid_value(parameter: &str, detail: impl Into<String>) -> Problem {
    Problem::new(
        StatusCode::UNPROCESSABLE_ENTITY,
        "invalid-parameter-value",
        "Invalid query parameter value",
        detail,
    )
    .with("parameter", parameter)
}

/// The solve flags of the command line, as query parameters: the same [`SolveOverrides`] of
/// the scene's `solve` section, validated by the scene's own rules when applied.
#[derive(Clone, Debug, Default)]
pub struct SolveParams {
    /// `formulation`, `rtol`, `atol`, `t_end`, `joint_stiffness`, `max_steps`,
    /// `max_wall_seconds` (the server's limit still applies when it is smaller),
    /// `linear_solver` (`auto`, `dense`, `sparse` or `faer`, `klu`).
    pub overrides: SolveOverrides,
    /// `reactions=true`: every joint's reaction columns, as `"outputs": ["reactions"]`.
    pub reactions: bool,
}

/// Query parameters shared by `/v1/run` and `/v1/compare` (the command line's solve flags).
pub const SOLVE_PARAMS: [&str; 9] = [
    "rtol",
    "atol",
    "t_end",
    "formulation",
    "joint_stiffness",
    "max_steps",
    "max_wall_seconds",
    "linear_solver",
    "reactions",
];

impl SolveParams {
    /// Reads the solve parameters (400 when a number does not parse; 422 for an unknown
    /// formulation or linear solver, or a `max_steps` that is not a whole number). Their ranges are the scene's,
    /// checked by [`SolveParams::apply_to_scene`].
    pub fn from(p: &Params) -> Result<SolveParams, Problem> {
        let max_steps = match p.number("max_steps")? {
            Some(n) if n >= 1.0 && n.fract() == 0.0 && n <= u64::MAX as f64 => Some(n as u64),
            Some(n) => {
                return Err(invalid_value(
                    "max_steps",
                    format!("max_steps: must be a whole number >= 1 (got {n})"),
                ))
            }
            None => None,
        };
        let formulation = match p.text("formulation") {
            None => None,
            Some(f) => Some(FormulationKind::parse(f).ok_or_else(|| {
                invalid_value(
                    "formulation",
                    format!("formulation: unknown '{f}' (expected dae, ggl, compliant_ggl, index1, decoupled or partitioned)"),
                )
            })?),
        };
        let linear_solver = match p.text("linear_solver") {
            None => None,
            Some(l) => Some(LinearSolverKind::parse(l).ok_or_else(|| {
                invalid_value(
                    "linear_solver",
                    format!(
                        "linear_solver: unknown '{l}' (expected auto, dense, sparse, faer or klu)"
                    ),
                )
            })?),
        };
        Ok(SolveParams {
            overrides: SolveOverrides {
                formulation,
                rtol: p.number("rtol")?,
                atol: p.number("atol")?,
                t_end: p.number("t_end")?,
                joint_stiffness: p.number("joint_stiffness")?,
                max_steps,
                max_wall_seconds: p.number("max_wall_seconds")?,
                linear_solver,
            },
            reactions: p.flag("reactions")?.unwrap_or(false),
        })
    }

    /// Writes the parameters into `scene` as the command line writes its flags, and validates
    /// it again: 422 naming the parameter whose value the scene's rules refuse.
    pub fn apply_to_scene(&self, scene: &mut Scene) -> Result<(), Problem> {
        if self.reactions && !scene.outputs.iter().any(|o| o == "reactions") {
            scene.outputs.push("reactions".into());
        }
        self.overrides.apply(scene).map_err(|problems| {
            match problems
                .iter()
                .find_map(|p| p.overridden.map(|name| (name, p)))
            {
                Some((name, p)) => invalid_value(name, format!("{name}: {}", p.problem)),
                None => invalid_scene(
                    problems
                        .into_iter()
                        .map(|p| (p.problem.path, p.problem.message)),
                ),
            }
        })
    }
}

/// The wall-clock budget of one solve and the setting that fixed it.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// Seconds.
    pub seconds: f64,
    /// `max_solve_seconds` (the server's) or `solve.max_wall_seconds` (the scene's, smaller).
    pub limit: &'static str,
}

impl Budget {
    /// The smaller of the server's limit and the scene's own `solve.max_wall_seconds`.
    pub fn of(scene: &Scene, limits: &Limits) -> Budget {
        match scene.solve.max_wall_seconds {
            Some(s) if s < limits.max_solve_seconds => Budget {
                seconds: s,
                limit: "solve.max_wall_seconds",
            },
            _ => Budget {
                seconds: limits.max_solve_seconds,
                limit: "max_solve_seconds",
            },
        }
    }

    /// As a duration.
    pub fn duration(&self) -> Duration {
        // the seconds were range-checked where they were given (scene, query, --max-solve-seconds)
        crate::scene::validate::wall_clock(self.seconds).unwrap_or(Duration::ZERO)
    }
}

/// The model's options (the query is already in its scene, see
/// [`SolveParams::apply_to_scene`]) with the row limit checked and the wall-clock budget set.
pub fn options(model: &Model, budget: Budget, limits: &Limits) -> Result<SolveOptions, Problem> {
    let mut opts = model.default_options();
    if opts.output_times.len() > limits.max_rows {
        return Err(Problem::limit(
            "max_rows",
            limits.max_rows,
            format!(
                "the run would write {} output rows, over the limit max_rows = {}",
                opts.output_times.len(),
                limits.max_rows
            ),
        ));
    }
    opts.max_wall_clock = Some(budget.duration());
    Ok(opts)
}

/// 422 listing every `{path, message}` of an invalid scene (the command line's lines).
pub fn invalid_scene(problems: impl IntoIterator<Item = (String, String)>) -> Problem {
    let list: Vec<(String, String)> = problems.into_iter().collect();
    let detail = list
        .iter()
        .map(|(p, m)| {
            if p.is_empty() {
                m.clone()
            } else {
                format!("{p}: {m}")
            }
        })
        .collect::<Vec<_>>()
        .join("; ");
    let errors: Vec<Value> = list
        .into_iter()
        .map(|(path, message)| serde_json::json!({"path": path, "message": message}))
        .collect();
    Problem::new(
        StatusCode::UNPROCESSABLE_ENTITY,
        "invalid-scene",
        "Invalid scene",
        detail,
    )
    .with("errors", errors)
}

/// A library error as a problem. Errors caused by the scene or the options are 422; only an
/// I/O error (which a request cannot cause) is a 500.
pub fn library_problem(e: &Error, budget: Budget) -> Problem {
    let unprocessable = |kind, title, detail: String| {
        Problem::new(StatusCode::UNPROCESSABLE_ENTITY, kind, title, detail)
    };
    // a solve stopped before its end: the cause decides the answer (the service keeps the
    // rows itself, through the streaming observer)
    if let Error::Incomplete { cause, .. } = e {
        return library_problem(cause, budget);
    }
    if let Error::Scene(se) = e {
        if !se.problems().is_empty() {
            return invalid_scene(
                se.problems()
                    .iter()
                    .map(|p| (p.path.clone(), p.message.clone())),
            );
        }
    }
    if let Error::Mechanism(me) = e {
        return invalid_scene([(me.path.clone(), me.message.clone())]);
    }
    if let Error::Solver(s) = e {
        return match s {
            SolverError::WallClock { t, .. } => budget_problem(
                format!(
                    "the solve ran past its wall-clock budget of {} s ({}) and stopped at t = {t}; the rows computed so far are in 'rows'",
                    budget.seconds, budget.limit
                ),
                budget.limit,
                budget.seconds.into(),
                Some(*t),
            ),
            SolverError::TooMuchWork { t, max_steps } | SolverError::StepBudget { t, max_steps } => {
                budget_problem(
                    format!("{s}; raise solve.max_steps (query max_steps). The rows computed so far are in 'rows'"),
                    "solve.max_steps",
                    (*max_steps).into(),
                    Some(*t),
                )
            }
            other => {
                let p = unprocessable("solver-failed", "The solver failed", other.to_string());
                match other.time() {
                    Some(t) => p.with("t_reached", t),
                    None => p,
                }
            }
        };
    }
    if let Error::Io { .. } = e {
        return Problem::internal(e.to_string());
    }
    let (kind, title) = match e {
        Error::Init(_) => ("initialisation-failed", "No consistent initial state"),
        Error::Options(_) | Error::Report(_) => ("invalid-options", "Invalid solve options"),
        Error::BondGraph(_) => ("invalid-bond-graph", "Invalid bond graph"),
        Error::Linearize(_) => ("linearize-refused", "The scene cannot be linearized"),
        Error::Equilibrium(_) => ("no-equilibrium", "No static equilibrium"),
        Error::Sensitivity(_) => ("sensitivity-refused", "Sensitivities or fit refused"),
        _ => ("solve-failed", "The solve failed"),
    };
    unprocessable(kind, title, e.to_string())
}

/// 422: a solve stopped by a budget (`limit`), with the time it reached.
pub fn budget_problem(detail: String, limit: &str, value: Value, t: Option<f64>) -> Problem {
    let p = Problem::new(
        StatusCode::UNPROCESSABLE_ENTITY,
        "solve-budget-exceeded",
        "Solve stopped by its budget",
        detail,
    )
    .with("limit", limit)
    .with("limit_value", value);
    match t {
        Some(t) => p.with("t_reached", t),
        None => p,
    }
}

/// Why a solve job did not produce a full solution.
#[derive(Debug)]
pub struct Failure {
    /// The answer.
    pub problem: Box<Problem>,
    /// The columns (with `t` first) when the solve had started: the partial rows go with them.
    pub columns: Option<Vec<String>>,
    /// The client went away: nobody reads the answer.
    pub cancelled: bool,
    /// The library's own partial solution (`[t, values...]` rows) when it stopped the solve
    /// part-way ([`Error::Incomplete`]): the rows at the output times so far and, where the
    /// solver got there, the state at the time reached — what the command line writes.
    pub partial: Option<Vec<Vec<f64>>>,
}

impl Failure {
    fn before(problem: Problem) -> Failure {
        Failure {
            problem: Box::new(problem),
            columns: None,
            cancelled: false,
            partial: None,
        }
    }
}

/// What a solve job hands its caller before the first row: the columns (with `t`) and the
/// number of rows asked for.
pub type OnStart<'a> = &'a mut dyn FnMut(&[String], usize);

/// Builds the model (the query is already in `scene`), applies the budget, and solves, handing each row to `on_row`
/// (which returns `false` when its client has gone). Stops at the next output row when the
/// client has gone, the server's shutdown grace has run out, or the budget is spent.
pub fn solve_rows(
    scene: &Scene,
    limits: &Limits,
    stop: &StopFlags,
    metrics: &Metrics,
    on_start: OnStart<'_>,
    on_row: &mut dyn FnMut(f64, &[f64]) -> bool,
) -> Result<Solution, Failure> {
    let budget = Budget::of(scene, limits);
    let model = Model::new(scene).map_err(|e| Failure::before(library_problem(&e, budget)))?;
    let opts = options(&model, budget, limits).map_err(Failure::before)?;
    let mut columns = vec!["t".to_string()];
    columns.extend(
        model
            .row_columns(&opts)
            .map_err(|e| Failure::before(library_problem(&e, budget)))?,
    );
    let n_rows = opts.output_times.len();
    on_start(&columns, n_rows);
    #[derive(PartialEq)]
    enum Why {
        ClientGone,
        Shutdown,
        Budget,
    }
    let deadline = Instant::now() + budget.duration();
    let mut why = None;
    let mut last_t = None;
    let mut rows = 0usize;
    let r = model.solve_streaming(&opts, &mut |row| {
        last_t = Some(row.t);
        rows += 1;
        why = if !on_row(row.t, row.values) || stop.client_gone.load(Ordering::SeqCst) {
            Some(Why::ClientGone)
        } else if stop.shutdown.load(Ordering::SeqCst) {
            Some(Why::Shutdown)
        } else if Instant::now() > deadline && rows < n_rows {
            Some(Why::Budget)
        } else {
            None
        };
        if why.is_some() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    let started = |problem: Problem| Failure {
        problem: Box::new(problem),
        columns: Some(columns.clone()),
        cancelled: false,
        partial: None,
    };
    match (r, why) {
        (Ok(sol), None) => Ok(sol),
        (Ok(_), Some(Why::ClientGone)) => {
            metrics.cancelled();
            Err(Failure {
                problem: Box::new(Problem::new(
                    StatusCode::from_u16(499).unwrap_or(StatusCode::BAD_REQUEST),
                    "cancelled",
                    "Client closed the request",
                    "the client disconnected; the solve was stopped",
                )),
                columns: None,
                cancelled: true,
                partial: None,
            })
        }
        (Ok(_), Some(Why::Shutdown)) => Err(started(Problem::unavailable(
            format!(
                "the server is shutting down: the solve was stopped at t = {}; the rows computed so far are in 'rows'",
                last_t.unwrap_or(f64::NAN)
            ),
            1,
        )
        .with("t_reached", last_t.unwrap_or(f64::NAN)))),
        (Ok(_), Some(Why::Budget)) => {
            metrics.budget_stop();
            Err(started(budget_problem(
                format!(
                    "the solve ran past its wall-clock budget of {} s ({}) and stopped at t = {}; the rows computed so far are in 'rows'",
                    budget.seconds,
                    budget.limit,
                    last_t.unwrap_or(f64::NAN)
                ),
                budget.limit,
                budget.seconds.into(),
                last_t,
            )))
        }
        (Err(e), _) => {
            let p = library_problem(&e, budget);
            if p.kind == "solve-budget-exceeded" {
                metrics.budget_stop();
            }
            let mut f = started(p);
            f.partial = e.partial_solution().map(|sol| {
                sol.times
                    .iter()
                    .zip(&sol.rows)
                    .map(|(t, r)| std::iter::once(*t).chain(r.iter().copied()).collect())
                    .collect()
            });
            Err(f)
        }
    }
}

/// One row `[t, values...]` serialised as a JSON array of numbers.
pub struct TimedRow<'a>(pub f64, pub &'a [f64]);

impl Serialize for TimedRow<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.1.len() + 1))?;
        seq.serialize_element(&self.0)?;
        for v in self.1 {
            seq.serialize_element(v)?;
        }
        seq.end()
    }
}

/// `/v1/run`'s JSON: columns (with `t`), rows, summary.
pub fn solution_json(sol: &Solution) -> Vec<u8> {
    #[derive(serde::Serialize)]
    struct Body<'a> {
        columns: Vec<&'a str>,
        rows: Vec<TimedRow<'a>>,
        summary: &'a crate::solve::Summary,
    }
    let body = Body {
        columns: std::iter::once("t")
            .chain(sol.columns.iter().map(String::as_str))
            .collect(),
        rows: sol
            .times
            .iter()
            .zip(&sol.rows)
            .map(|(t, r)| TimedRow(*t, r))
            .collect(),
        summary: &sol.summary,
    };
    serde_json::to_vec(&body).unwrap_or_default()
}
