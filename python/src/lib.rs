//! `bondmech._native`: the library's public API for Python (PyO3, numpy arrays).
//!
//! Everything here converts: Python values in, the library's own calls (`Scene`, `Model`,
//! `SolveOverrides`, `VarySweep`, the builder) in between, numpy arrays and exceptions out.
//! There is no second solver path: a `Scene.run()` is the command line's `run` (the scene, its
//! `--set` assignments, the flags written into its `solve` section, `Model::new`,
//! `Model::solve`). Every solve releases the GIL (`Python::detach`), so Python threads solve in
//! parallel; between output rows it checks for signals at most every
//! [`SIGNAL_CHECK_INTERVAL`], so Ctrl-C interrupts a long solve.
//!
//! The pure-Python package `bondmech` (python/bondmech) wraps this module: `load`, the
//! exceptions, the sweep table.

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice, PyString, PyTuple};

use bondmech::scene::path::{parse_assignment, scene_from_json_with, Assignment};
use bondmech::scene::SolveOverrides;
use bondmech::FormulationKind;
use bondmech::{Error, LinearSolverKind, Model};

mod builder;

/// How often a solve looks for signals (Ctrl-C) between output rows; each look takes the GIL
/// for a moment.
pub const SIGNAL_CHECK_INTERVAL: Duration = Duration::from_millis(50);

// ---------------------------------------------------------------------------------------------
// errors

/// `bondmech._errors.<name>(*args)` as a Python exception.
fn py_error<'py>(py: Python<'py>, name: &str, args: impl pyo3::call::PyCallArgs<'py>) -> PyErr {
    let made = py
        .import("bondmech._errors")
        .and_then(|m| m.getattr(name))
        .and_then(|cls| cls.call1(args));
    match made {
        Ok(instance) => PyErr::from_value(instance),
        Err(e) => e,
    }
}

/// `[{"path": …, "message": …}]`.
fn problems_list<'py>(
    py: Python<'py>,
    problems: impl IntoIterator<Item = (String, String)>,
) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for (path, message) in problems {
        let d = PyDict::new(py);
        d.set_item("path", path)?;
        d.set_item("message", message)?;
        list.append(d)?;
    }
    Ok(list)
}

fn scene_error(py: Python<'_>, message: String, problems: Vec<(String, String)>) -> PyErr {
    match problems_list(py, problems) {
        Ok(list) => py_error(py, "SceneError", (message, list)),
        Err(e) => e,
    }
}

/// The library's error as the Python exception the package documents.
fn to_py_err(py: Python<'_>, e: Error) -> PyErr {
    let message = e.to_string();
    match e {
        Error::Scene(se) => {
            let mut problems: Vec<(String, String)> = se
                .problems()
                .iter()
                .map(|p| (p.path.clone(), p.message.clone()))
                .collect();
            if problems.is_empty() {
                problems.push((String::new(), message.clone()));
            }
            scene_error(py, message, problems)
        }
        Error::Mechanism(me) => scene_error(py, message, vec![(me.path, me.message)]),
        Error::BondGraph(m) => scene_error(py, message, vec![("bond_graph".into(), m)]),
        Error::TooLarge(_) => scene_error(py, message.clone(), vec![(String::new(), message)]),
        Error::Options(_) | Error::Report(_) | Error::Linearize(_) | Error::Sensitivity(_) => {
            py_error(py, "OptionsError", (message,))
        }
        Error::Io { path, source } => {
            pyo3::exceptions::PyOSError::new_err(format!("{path}: {source}"))
        }
        Error::Incomplete { cause, partial } => {
            let s = &partial.summary;
            let t_reached = s.t_reached;
            let stopped_by = s.stopped_by.clone();
            let budget = matches!(
                stopped_by.as_deref(),
                Some("max_steps") | Some("max_wall_seconds")
            );
            let cause = cause.to_string();
            let sol = match Solution::new(py, *partial).and_then(|s| Py::new(py, s)) {
                Ok(sol) => sol,
                Err(e) => return e,
            };
            let name = if budget {
                "BudgetExceeded"
            } else {
                "SolveError"
            };
            py_error(py, name, (message, t_reached, sol, stopped_by, cause))
        }
        // the solver failed before any row was kept (initialisation, a non-finite load, …)
        other => py_error(
            py,
            "SolveError",
            (
                message,
                f64::NAN,
                py.None(),
                Option::<String>::None,
                other.to_string(),
            ),
        ),
    }
}

/// `Result<T, bondmech::Error>` → `PyResult<T>`.
trait IntoPyResult<T> {
    fn py(self, py: Python<'_>) -> PyResult<T>;
}

impl<T> IntoPyResult<T> for Result<T, Error> {
    fn py(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| to_py_err(py, e))
    }
}

impl<T> IntoPyResult<T> for Result<T, bondmech::report::ReportError> {
    fn py(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| to_py_err(py, Error::from(e)))
    }
}

impl<T> IntoPyResult<T> for Result<T, bondmech::scene::SceneError> {
    fn py(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| to_py_err(py, Error::Scene(e)))
    }
}

// ---------------------------------------------------------------------------------------------
// JSON ↔ Python

/// `json.dumps(value)` with numpy scalars and arrays accepted (`bondmech._util.to_json`).
fn to_json(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<String> {
    py.import("bondmech._util")?
        .getattr("to_json")?
        .call1((value,))?
        .extract()
}

/// `json.loads(text)`.
fn from_json<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.getattr("loads")?.call1((text,))
}

// ---------------------------------------------------------------------------------------------
// Solution

/// A solved trajectory: one row per output time (the command line's CSV as numpy arrays).
///
/// `t` (1-D float64), `columns` (the CSV's column names without `t`), `values` (2-D float64,
/// rows × columns), `sol[name]` (one column, 1-D), `summary` (the summary JSON as a dict).
/// The arrays are read-only views of the solution.
#[pyclass(module = "bondmech", name = "Solution", frozen)]
pub struct Solution {
    inner: bondmech::Solution,
    t: Py<PyArray1<f64>>,
    values: Py<PyAny>,
}

fn read_only(array: &Bound<'_, PyAny>) -> PyResult<()> {
    let kwargs = PyDict::new(array.py());
    kwargs.set_item("write", false)?;
    array.call_method("setflags", (), Some(&kwargs))?;
    Ok(())
}

impl Solution {
    fn new(py: Python<'_>, inner: bondmech::Solution) -> PyResult<Solution> {
        let t = PyArray1::from_vec(py, inner.times.clone());
        let ncols = inner.columns.len();
        let mut flat = Vec::with_capacity(inner.rows.len() * ncols);
        for r in &inner.rows {
            flat.extend_from_slice(r);
        }
        let values: Bound<'_, PyArray2<f64>> =
            PyArray1::from_vec(py, flat).reshape([inner.rows.len(), ncols])?;
        read_only(t.as_any())?;
        read_only(values.as_any())?;
        Ok(Solution {
            inner,
            t: t.unbind(),
            values: values.into_any().unbind(),
        })
    }
}

#[pymethods]
impl Solution {
    /// Output times (s), 1-D float64.
    #[getter]
    fn t(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.t.clone_ref(py)
    }

    /// Column names without `t`, in the CSV's order.
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.inner.columns.clone()
    }

    /// All columns, 2-D float64: `values[k, c]` is column `c` at `t[k]`.
    #[getter]
    fn values(&self, py: Python<'_>) -> Py<PyAny> {
        self.values.clone_ref(py)
    }

    /// The solver summary (the `--summary` JSON) as a dict: steps, evaluations, CPU time,
    /// largest constraint error, energy drift, `completed`, `t_reached`, warnings, events, …
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        from_json(py, &self.summary_json())
    }

    /// The summary as the JSON text `bondmech run --summary` writes.
    fn summary_json(&self) -> String {
        serde_json::to_string_pretty(&self.inner.summary).expect("summary serialises")
    }

    /// The CSV text `bondmech run --out` writes, byte for byte.
    fn to_csv(&self) -> String {
        self.inner.to_csv()
    }

    /// One column over time (1-D view); `"t"` gives the times.
    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        if name == "t" {
            return Ok(self.t.bind(py).clone().into_any());
        }
        let Some(c) = self.inner.columns.iter().position(|n| n == name) else {
            return Err(PyKeyError::new_err(format!(
                "no column '{name}' (columns: t, {})",
                self.inner.columns.join(", ")
            )));
        };
        self.values.bind(py).get_item((PySlice::full(py), c))
    }

    fn __contains__(&self, name: &str) -> bool {
        name == "t" || self.inner.columns.iter().any(|n| n == name)
    }

    /// Number of rows.
    fn __len__(&self) -> usize {
        self.inner.times.len()
    }

    fn __repr__(&self) -> String {
        let s = &self.inner.summary;
        format!(
            "<bondmech.Solution: {} rows × {} columns, t = {} … {}, {} ({} steps){}>",
            self.inner.times.len(),
            self.inner.columns.len(),
            self.inner.times.first().copied().unwrap_or(f64::NAN),
            self.inner.times.last().copied().unwrap_or(f64::NAN),
            s.formulation,
            s.steps,
            if s.completed { "" } else { ", incomplete" }
        )
    }

    /// A `pandas.DataFrame` of the columns, indexed by `t` (needs pandas).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = py.import("pandas").map_err(|_| {
            pyo3::exceptions::PyImportError::new_err(
                "Solution.to_pandas needs pandas (pip install pandas)",
            )
        })?;
        let index_kwargs = PyDict::new(py);
        index_kwargs.set_item("name", "t")?;
        let index = pd
            .getattr("Index")?
            .call((self.t.bind(py),), Some(&index_kwargs))?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("columns", self.columns())?;
        kwargs.set_item("index", index)?;
        kwargs.set_item("copy", true)?;
        pd.getattr("DataFrame")?
            .call((self.values.bind(py),), Some(&kwargs))
    }
}

// ---------------------------------------------------------------------------------------------
// Scene

/// A scene: a mechanism (bodies, joints, …) or a raw bond graph, validated.
///
/// Made by `bondmech.load(path_or_dict)` or `Mechanism.build()`. `set(path, value)` changes one
/// field as the command line's `--set` does; `run()` solves.
#[pyclass(module = "bondmech", name = "Scene")]
#[derive(Clone)]
pub struct Scene {
    /// The scene text as loaded (JSON).
    text: String,
    /// Default name (the file stem).
    name: String,
    /// `--set` assignments, in order.
    sets: Vec<Assignment>,
    /// The validated scene: `text` with `sets` applied.
    scene: bondmech::Scene,
}

/// The keyword arguments of `run` and `compare` that override the scene's `solve` section.
#[derive(Clone, Default)]
struct RunArgs {
    formulation: Option<String>,
    rtol: Option<f64>,
    atol: Option<f64>,
    t_end: Option<f64>,
    reactions: bool,
    linear_solver: Option<String>,
    max_wall_seconds: Option<f64>,
    max_steps: Option<u64>,
    joint_stiffness: Option<f64>,
}

impl RunArgs {
    /// The scene with the arguments written into its `solve` section (and `"reactions"` into
    /// its outputs), validated again: `bondmech run`'s flags, applied the same way.
    fn apply(&self, py: Python<'_>, scene: &bondmech::Scene) -> PyResult<bondmech::Scene> {
        let mut scene = scene.clone();
        if self.reactions && !scene.outputs.iter().any(|o| o == "reactions") {
            scene.outputs.push("reactions".into());
        }
        let formulation = match &self.formulation {
            None => None,
            Some(f) => Some(FormulationKind::parse(f).ok_or_else(|| {
                py_error(
                    py,
                    "OptionsError",
                    (format!(
                        "formulation='{f}': unknown (expected dae, ggl, compliant_ggl, index1, partitioned or decoupled)"
                    ),),
                )
            })?),
        };
        let linear_solver = match &self.linear_solver {
            None => None,
            Some(l) => Some(LinearSolverKind::parse(l).ok_or_else(|| {
                py_error(
                    py,
                    "OptionsError",
                    (format!(
                        "linear_solver='{l}': unknown (expected auto, dense, sparse or klu)"
                    ),),
                )
            })?),
        };
        let overrides = SolveOverrides {
            formulation,
            rtol: self.rtol,
            atol: self.atol,
            t_end: self.t_end,
            joint_stiffness: self.joint_stiffness,
            max_steps: self.max_steps,
            max_wall_seconds: self.max_wall_seconds,
            linear_solver,
        };
        overrides.apply(&mut scene).map_err(|problems| {
            let lines: Vec<String> = problems
                .iter()
                .map(|p| match p.overridden {
                    Some(arg) => format!("{arg}=: {}", p.problem),
                    None => p.problem.to_string(),
                })
                .collect();
            scene_error(
                py,
                lines.join("\n"),
                problems
                    .into_iter()
                    .map(|p| (p.problem.path, p.problem.message))
                    .collect(),
            )
        })?;
        Ok(scene)
    }
}

/// Runs `solve` (which gets a per-row observer) without the GIL; between rows, at most every
/// [`SIGNAL_CHECK_INTERVAL`], takes the GIL to run Python's signal handlers, and stops the
/// solve when one raises (Ctrl-C → `KeyboardInterrupt`).
fn detached_solve<T: Send>(
    py: Python<'_>,
    solve: impl FnOnce(&mut dyn FnMut() -> ControlFlow<()>) -> T + Send,
) -> PyResult<T> {
    let mut interrupted: Option<PyErr> = None;
    let out = py.detach(|| {
        let mut last = Instant::now();
        let mut observer = || {
            if last.elapsed() < SIGNAL_CHECK_INTERVAL {
                return ControlFlow::Continue(());
            }
            last = Instant::now();
            match Python::attach(|py| py.check_signals()) {
                Ok(()) => ControlFlow::Continue(()),
                Err(e) => {
                    interrupted = Some(e);
                    ControlFlow::Break(())
                }
            }
        };
        solve(&mut observer)
    });
    match interrupted {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// `Model::new` then `Model::solve_streaming` with the scene's own options: what `bondmech run`
/// does after reading its flags.
fn solve_scene(
    scene: &bondmech::Scene,
    check: &mut dyn FnMut() -> ControlFlow<()>,
) -> Result<bondmech::Solution, Error> {
    let model = Model::new(scene)?;
    let opts = model.default_options();
    model.solve_streaming(&opts, &mut |_| check())
}

impl Scene {
    fn from_text(py: Python<'_>, text: String, name: String) -> PyResult<Scene> {
        let scene = scene_from_json_with(&text, &name, &[]).py(py)?;
        Ok(Scene {
            text,
            name,
            sets: Vec::new(),
            scene,
        })
    }

    /// A scene made in code (the builder): its JSON is the text.
    pub(crate) fn from_scene(scene: bondmech::Scene) -> Scene {
        Scene {
            text: scene.to_json_string(),
            name: scene.name.clone(),
            sets: Vec::new(),
            scene,
        }
    }
}

#[pymethods]
impl Scene {
    /// Reads and validates a scene file (`name` defaults to the file stem).
    #[staticmethod]
    fn from_path(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Scene> {
        let (text, name) = bondmech::scene::path::read_scene_text(&path).py(py)?;
        Scene::from_text(py, text, name)
    }

    /// Parses and validates scene JSON text.
    #[staticmethod]
    #[pyo3(signature = (text, name = "scene"))]
    fn from_json(py: Python<'_>, text: String, name: &str) -> PyResult<Scene> {
        Scene::from_text(py, text, name.to_string())
    }

    /// Rebuilds a scene from its text, default name and `PATH=JSON` assignments (pickling).
    #[staticmethod]
    fn _from_parts(
        py: Python<'_>,
        text: String,
        name: String,
        sets: Vec<String>,
    ) -> PyResult<Scene> {
        let mut s = Scene::from_text(py, text, name)?;
        for a in sets {
            let a = parse_assignment(&a)
                .map_err(bondmech::scene::SceneError::from)
                .py(py)?;
            s.push_set(py, a)?;
        }
        Ok(s)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.borrow();
        let sets: Vec<String> = this.sets.iter().map(|a| a.as_str().to_string()).collect();
        let ctor = slf.get_type().getattr("_from_parts")?;
        let args = (this.text.clone(), this.name.clone(), sets).into_pyobject(py)?;
        PyTuple::new(py, [ctor, args.into_any()])
    }

    /// Changes one field, as `bondmech run --set PATH=JSON` does: `path` is written as errors
    /// name fields (`bodies[bar2].mass`, `gravity`, `solve.rtol`, `joints[knee].points[0]`),
    /// `value` any JSON-able Python value. The scene is validated again; a bad path or value
    /// raises `SceneError` and leaves the scene unchanged. Returns the scene (for chaining).
    fn set<'py>(
        slf: Bound<'py, Self>,
        path: &str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        let json = to_json(py, value)?;
        // exactly the command line's `--set PATH=JSON` (object keys keep their order)
        let assignment = parse_assignment(&format!("{path}={json}"))
            .map_err(bondmech::scene::SceneError::from)
            .py(py)?
            .labelled("Scene.set");
        slf.borrow_mut().push_set(py, assignment)?;
        Ok(slf)
    }

    /// The scene as a dict (scene format v1, every default written out), with the `set`
    /// changes applied: `bondmech.load(scene.to_dict())` gives the same scene.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        from_json(py, &self.scene.to_json_string())
    }

    /// The scene as JSON text (scene format v1).
    fn to_json(&self) -> String {
        self.scene.to_json_string()
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.scene.name.clone()
    }

    /// Whether the scene is a raw `"bond_graph"` (no bodies or joints).
    #[getter]
    fn is_bond_graph(&self) -> bool {
        self.scene.bond_graph.is_some()
    }

    /// The `set` assignments so far, as `PATH=JSON` text (the command line's `--set`).
    #[getter]
    fn sets(&self) -> Vec<String> {
        self.sets.iter().map(|a| a.as_str().to_string()).collect()
    }

    /// Solves the scene. The keyword arguments are `bondmech run`'s flags (`None` keeps the
    /// scene's `solve` field) and obey the scene's own rules. The GIL is released while it
    /// solves. Raises `SceneError` (bad argument), `OptionsError`, `SolveError` (with
    /// `.t_reached` and `.partial`) or `BudgetExceeded` (`max_wall_seconds`, `max_steps`).
    #[pyo3(signature = (formulation=None, rtol=None, atol=None, t_end=None, reactions=false, linear_solver=None, max_wall_seconds=None, max_steps=None, joint_stiffness=None))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        slf: PyRef<'_, Self>,
        formulation: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        t_end: Option<f64>,
        reactions: bool,
        linear_solver: Option<String>,
        max_wall_seconds: Option<f64>,
        max_steps: Option<u64>,
        joint_stiffness: Option<f64>,
    ) -> PyResult<Solution> {
        let py = slf.py();
        let args = RunArgs {
            formulation,
            rtol,
            atol,
            t_end,
            reactions,
            linear_solver,
            max_wall_seconds,
            max_steps,
            joint_stiffness,
        };
        let scene = args.apply(py, &slf.scene)?;
        drop(slf);
        let solved = detached_solve(py, |check| solve_scene(&scene, check))?;
        Solution::new(py, solved.py(py)?)
    }

    /// The static equilibrium nearest the scene's configuration (`bondmech equilibrium
    /// --json`) as a dict: `converged`, `iterations`, `residual`, `coordinates`, `reactions`,
    /// `drivers`, `stable`, `stiffness_eigenvalues`. Raises `SceneError` or `SolveError` (no
    /// equilibrium: why in the message).
    fn equilibrium<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let model = bondmech::Model::new(&self.scene).py(py)?;
        let eq = model.equilibrium().py(py)?;
        from_json(py, &eq.to_json().to_string())
    }

    /// The linear model x' = A x + B u, y = C x + D u about an operating point (`bondmech
    /// linearize --json`) as a dict: `at`, `t`, `operating_point`, `states`, `inputs`,
    /// `outputs`, `A`, `B`, `C`, `D` (2-D float64 numpy arrays; `B` and `D` have no columns
    /// without inputs), `modes` (`eigenvalue` `[re, im]`, `omega_n`, `frequency_hz`,
    /// `damping_ratio`, `shape`), `notes`. `at` is `"equilibrium"` or `"t=T"`; `outputs` run CSV
    /// columns (default: the states); `states` the independent coordinates by name. Raises
    /// `OptionsError` (a bad `at`, output or state; a singular operating point), `SceneError`
    /// or `SolveError`.
    #[pyo3(signature = (at = "equilibrium", outputs = None, states = None))]
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        at: &str,
        outputs: Option<Vec<String>>,
        states: Option<Vec<String>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let at: bondmech::OperatingPoint = at.parse().map_err(Error::from).py(py)?;
        let options = bondmech::LinearizeOptions {
            at,
            outputs: outputs.unwrap_or_default(),
            states,
        };
        let scene = self.scene.clone();
        let lm = py
            .detach(move || bondmech::linearize(&scene, &options))
            .py(py)?;
        let doc = from_json(py, &lm.to_json().to_string())?;
        for (key, m) in [("A", &lm.a), ("B", &lm.b), ("C", &lm.c), ("D", &lm.d)] {
            let flat: Vec<f64> = (0..m.nrows())
                .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
                .collect();
            let arr = PyArray1::from_vec(py, flat).reshape([m.nrows(), m.ncols()])?;
            doc.set_item(key, arr)?;
        }
        Ok(doc)
    }

    /// Forward sensitivities (IDAS, exact ∂F/∂p): a dict with `t` (1-D), `columns`, `values`
    /// (2-D, rows × columns: the run), `sensitivities` (`{"d(<column>)/d(<path>)": 1-D array}`,
    /// the `bondmech sensitivity` columns), `warnings`. `params` are scene paths as `set`
    /// takes them (`"bodies[bar2].mass"`). Raises `OptionsError` naming the path, `SceneError`
    /// or `SolveError`.
    #[pyo3(signature = (params, t_end = None))]
    fn sensitivity<'py>(
        &self,
        py: Python<'py>,
        params: Vec<String>,
        t_end: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let scene = self.scene.clone();
        let mut req = bondmech::sensitivity::SensitivityRequest::new(&[]);
        req.params = params;
        req.t_end = t_end;
        let s = py
            .detach(move || bondmech::sensitivity::sensitivity(&scene, &req).map_err(Error::from))
            .py(py)?;
        let doc = PyDict::new(py);
        doc.set_item("t", PyArray1::from_vec(py, s.times.clone()))?;
        doc.set_item("columns", s.columns.clone())?;
        let (n, m) = (s.rows.len(), s.columns.len());
        let flat: Vec<f64> = s.rows.iter().flatten().copied().collect();
        doc.set_item("values", PyArray1::from_vec(py, flat).reshape([n, m])?)?;
        let sens = PyDict::new(py);
        for (i, name) in s.sensitivity_columns.iter().enumerate() {
            let col: Vec<f64> = s.sensitivity_rows.iter().map(|r| r[i]).collect();
            sens.set_item(name, PyArray1::from_vec(py, col))?;
        }
        doc.set_item("sensitivities", sens)?;
        doc.set_item("warnings", s.warnings.clone())?;
        Ok(doc.into_any())
    }

    /// Fits scene parameters to measured data (Levenberg–Marquardt on the exact
    /// sensitivities, from the scene's values): the `bondmech fit --json` document as a dict
    /// (`converged`, `iterations`, `parameters`, `std_errors`, `covariance`, `correlation`,
    /// `residual_rms`, …). `data`: CSV text, a dict of columns (`"t"` and run columns) or a
    /// pandas DataFrame with those columns. Raises `OptionsError` naming the path or the column.
    #[pyo3(signature = (data, params, columns = None))]
    fn fit<'py>(
        &self,
        py: Python<'py>,
        data: &Bound<'py, PyAny>,
        params: Vec<String>,
        columns: Option<Vec<String>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        use bondmech::sensitivity::{FitData, FitRequest};
        let data = if let Ok(text) = data.extract::<String>() {
            FitData::from_csv(&text)
        } else {
            // a DataFrame: its columns as lists; a mapping: as it is
            let table = if data.hasattr("to_dict")? && data.hasattr("columns")? {
                data.call_method1("to_dict", ("list",))?
            } else {
                data.clone()
            };
            let dict = table.cast::<PyDict>().map_err(|_| {
                PyTypeError::new_err("data: CSV text, a dict of columns or a pandas DataFrame")
            })?;
            let mut header = Vec::new();
            let mut series: Vec<Vec<f64>> = Vec::new();
            for (k, v) in dict.iter() {
                header.push(k.extract::<String>()?);
                series.push(v.extract::<Vec<f64>>()?);
            }
            let rows = series.first().map_or(0, Vec::len);
            if series.iter().any(|s| s.len() != rows) {
                return Err(PyValueError::new_err(
                    "data: the columns have different lengths",
                ));
            }
            let table: Vec<Vec<f64>> = (0..rows)
                .map(|i| series.iter().map(|s| s[i]).collect())
                .collect();
            FitData::from_table(header, table)
        }
        .map_err(Error::from)
        .py(py)?;
        let scene = self.scene.clone();
        let req = FitRequest {
            params,
            columns,
            max_iterations: None,
        };
        let r = py
            .detach(move || bondmech::sensitivity::fit(&scene, &data, &req).map_err(Error::from))
            .py(py)?;
        from_json(py, &r.to_json().to_string())
    }

    fn __repr__(&self) -> String {
        let s = &self.scene;
        if s.bond_graph.is_some() {
            format!("<bondmech.Scene '{}': raw bond graph>", s.name)
        } else {
            format!(
                "<bondmech.Scene '{}': {} bodies, {} joints, t_end = {}>",
                s.name,
                s.bodies.len(),
                s.joints.len(),
                s.solve.t_end
            )
        }
    }
}

impl Scene {
    /// Applies one more assignment to the scene's text (with the earlier ones) and validates.
    fn push_set(&mut self, py: Python<'_>, a: Assignment) -> PyResult<()> {
        let mut sets = self.sets.clone();
        sets.push(a);
        self.scene = scene_from_json_with(&self.text, &self.name, &sets).py(py)?;
        self.sets = sets;
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// compare, graph, sweep

/// `bondmech compare --json`: the DAE (IDA) and the decoupled twin (CVODE) solved with the same
/// options, compared (a dict). `formulation` chooses the DAE side.
#[pyfunction]
#[pyo3(signature = (scene, joint_stiffness=None, formulation=None, rtol=None, atol=None, t_end=None, reactions=false, linear_solver=None, max_wall_seconds=None, max_steps=None))]
#[allow(clippy::too_many_arguments)]
fn compare<'py>(
    py: Python<'py>,
    scene: PyRef<'_, Scene>,
    joint_stiffness: Option<f64>,
    formulation: Option<String>,
    rtol: Option<f64>,
    atol: Option<f64>,
    t_end: Option<f64>,
    reactions: bool,
    linear_solver: Option<String>,
    max_wall_seconds: Option<f64>,
    max_steps: Option<u64>,
) -> PyResult<Bound<'py, PyAny>> {
    if formulation
        .as_deref()
        .and_then(FormulationKind::parse)
        .is_some_and(|f| f == FormulationKind::Decoupled)
    {
        return Err(py_error(
            py,
            "OptionsError",
            ("formulation='decoupled': compare always solves the decoupled twin as its second run; formulation chooses the DAE side (dae, compliant_ggl or index1)",),
        ));
    }
    let args = RunArgs {
        formulation,
        rtol,
        atol,
        t_end,
        reactions,
        linear_solver,
        max_wall_seconds,
        max_steps,
        joint_stiffness,
    };
    let scene = args.apply(py, &scene.scene)?;
    let json = py
        .detach(|| {
            let model = Model::new(&scene)?;
            let (cmp, _, _) = model.compare(&model.default_options())?;
            Ok::<_, Error>(serde_json::to_string(&cmp).expect("comparison serialises"))
        })
        .py(py)?;
    from_json(py, &json)
}

/// `bondmech graph`: the bond graph as Graphviz DOT (a str), or with `causality=True` the
/// causality report (a dict: dof, states, differential, conflicts, algebraic_loops).
/// `decoupled=True` gives the decoupled twin's graph.
#[pyfunction]
#[pyo3(signature = (scene, causality=false, decoupled=false))]
fn graph<'py>(
    py: Python<'py>,
    scene: PyRef<'_, Scene>,
    causality: bool,
    decoupled: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let model = Model::new(&scene.scene).py(py)?;
    if decoupled && model.is_raw_bond_graph() {
        return Err(py_error(
            py,
            "OptionsError",
            ("decoupled=True: a raw bond graph has no joints to decouple",),
        ));
    }
    let decoupled = decoupled
        || (!model.is_raw_bond_graph()
            && model.scene().solve.formulation == FormulationKind::Decoupled);
    let variant = if decoupled {
        bondmech::mech::Variant::Decoupled
    } else {
        bondmech::mech::Variant::Pinned
    };
    let g = model.scene_graph(variant).py(py)?;
    if causality {
        let text = serde_json::to_string(&g.report()).expect("report serialises");
        from_json(py, &text)
    } else {
        Ok(PyString::new(py, &g.dot()).into_any())
    }
}

/// `bondmech sweep --vary`: runs every point (or the points of `shard = (i, n)`, 1 ≤ i ≤ n) on
/// `workers` threads (all cores when `None`) without the GIL and returns the report as JSON
/// text (`vary.json`). `vary` is a list of `PATH=[…]` strings.
#[pyfunction]
#[pyo3(signature = (scene, vary, columns=None, workers=None, t_end=None, shard=None))]
fn _sweep(
    py: Python<'_>,
    scene: PyRef<'_, Scene>,
    vary: Vec<String>,
    columns: Option<Vec<String>>,
    workers: Option<usize>,
    t_end: Option<f64>,
    shard: Option<(usize, usize)>,
) -> PyResult<String> {
    use bondmech::report::vary::Shard;
    use bondmech::study::vary::VarySweep;
    let sets: Vec<String> = scene.sets.iter().map(|a| a.as_str().to_string()).collect();
    let (text, name) = (scene.text.clone(), scene.name.clone());
    drop(scene);
    let shard = match shard {
        None => None,
        Some((i, n)) => Some(
            Shard::parse(&format!("{i}/{n}"))
                .map_err(Error::from)
                .py(py)?,
        ),
    };
    if workers == Some(0) {
        return Err(PyValueError::new_err("workers must be at least 1"));
    }
    // no signal checks inside a sweep: its points run on rayon's threads (Ctrl-C is seen
    // when the sweep returns)
    let report = py.detach(|| {
        let sweep = VarySweep::new(&text, &name, &sets, &vary, t_end, columns, None)?;
        let tick = || {};
        let report = match workers {
            None => sweep.run(shard, &tick),
            Some(w) => rayon::ThreadPoolBuilder::new()
                .num_threads(w)
                .build()
                .map_err(|e| Error::Options(format!("workers={w}: {e}")))?
                .install(|| sweep.run(shard, &tick)),
        };
        report.map(|r| serde_json::to_string(&r).expect("report serialises"))
    });
    report.py(py)
}

/// Merges the JSON reports of the shards of one sweep into the whole sweep's report (JSON),
/// refusing shards of another sweep, missing or repeated ones (`bondmech sweep-merge`).
#[pyfunction]
fn _sweep_merge(py: Python<'_>, reports: Vec<String>) -> PyResult<String> {
    let mut parts = Vec::with_capacity(reports.len());
    for (k, text) in reports.iter().enumerate() {
        let r: bondmech::report::vary::VaryReport = serde_json::from_str(text)
            .map_err(|e| PyValueError::new_err(format!("report {k}: not a sweep report ({e})")))?;
        parts.push((std::path::PathBuf::from(format!("part {k}")), r));
    }
    let merged = bondmech::report::vary::merge(&parts).py(py)?;
    Ok(serde_json::to_string(&merged).expect("report serialises"))
}

/// The CSV text of a sweep report (JSON), as `bondmech sweep --vary` writes `vary.csv`.
#[pyfunction]
fn _sweep_csv(report: &str) -> PyResult<String> {
    let r: bondmech::report::vary::VaryReport = serde_json::from_str(report)
        .map_err(|e| PyValueError::new_err(format!("not a sweep report ({e})")))?;
    Ok(r.csv())
}

/// Thread CPU seconds of `repeats` calls of the library alone — the solve options written into
/// the scene, `Model::new`, `Model::solve` — on this thread, without the GIL: the reference of
/// the overhead benchmark (python/benches/overhead.py). Returns (CPU seconds, steps).
#[pyfunction]
#[pyo3(signature = (scene, repeats=1))]
fn _library_cpu_seconds(
    py: Python<'_>,
    scene: PyRef<'_, Scene>,
    repeats: usize,
) -> PyResult<(f64, u64)> {
    let scene = RunArgs::default().apply(py, &scene.scene)?;
    let out = py.detach(|| {
        let clock = cpu_time::ThreadTime::now();
        let mut steps = 0;
        for _ in 0..repeats {
            let scene = scene.clone();
            let model = Model::new(&scene)?;
            steps = model.solve(&model.default_options())?.summary.steps;
        }
        Ok::<_, Error>((clock.elapsed().as_secs_f64(), steps))
    });
    out.py(py)
}

/// The package version and the SUNDIALS version (major, minor, patch) it runs on.
#[pyfunction]
fn _versions() -> (String, (u32, u32, u32)) {
    (
        env!("CARGO_PKG_VERSION").to_string(),
        bondmech::sundials::version::version(),
    )
}

/// The name of an object's Python type (for error messages).
pub(crate) fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// A `TypeError`: what was expected (`what`) and the type that came instead.
pub(crate) fn type_error(what: &str, obj: &Bound<'_, PyAny>) -> PyErr {
    PyTypeError::new_err(format!("{what}: got {}", type_name(obj)))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Solution>()?;
    builder::register(m)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(graph, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_merge, m)?)?;
    m.add_function(wrap_pyfunction!(_sweep_csv, m)?)?;
    m.add_function(wrap_pyfunction!(_library_cpu_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(_versions, m)?)?;
    m.add("SIGNAL_CHECK_SECONDS", SIGNAL_CHECK_INTERVAL.as_secs_f64())?;
    Ok(())
}
