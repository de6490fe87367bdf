//! The linear model `ẋ = A x + B u`, `y = C x + D u` about an operating point, what asks for
//! it ([`LinearizeOptions`], [`OperatingPoint`]), why it may be refused ([`LinearizeError`]),
//! and its modes and frequency response. [`crate::linearize`] computes it
//! (`src/model_linearize.rs`: the mathematics there); `bondmech linearize` prints its table
//! ([`crate::report`]).

use nalgebra::{Complex, DMatrix};

/// Where the model is linearized.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OperatingPoint {
    /// The static equilibrium nearest the scene's configuration ([`crate::Model::equilibrium`]), at
    /// `t_start`, at rest.
    Equilibrium,
    /// The solved state at time `T` (s): the local linearization, wherever the motion is.
    Time(f64),
}

impl std::str::FromStr for OperatingPoint {
    type Err = LinearizeError;

    /// `equilibrium` or `t=T` (`T` in seconds, finite).
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        let bad = |why: &str| LinearizeError::BadAt {
            given: s.to_string(),
            why: why.to_string(),
        };
        let t = s.trim();
        if t == "equilibrium" {
            return Ok(OperatingPoint::Equilibrium);
        }
        let Some(rest) = t.strip_prefix("t=") else {
            return Err(bad("expected 'equilibrium' or 't=T' (T in seconds)"));
        };
        match rest.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(OperatingPoint::Time(v)),
            Ok(_) => Err(bad("T must be finite")),
            Err(_) => Err(bad(&format!(
                "'{}' is not a number of seconds (expected 't=T', e.g. 't=0.5')",
                rest.trim()
            ))),
        }
    }
}

impl std::fmt::Display for OperatingPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OperatingPoint::Equilibrium => write!(f, "equilibrium"),
            OperatingPoint::Time(t) => write!(f, "t={t}"),
        }
    }
}

/// What [`crate::linearize`] is asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearizeOptions {
    /// The operating point (default: the static equilibrium).
    pub at: OperatingPoint,
    /// Output columns `y` (run CSV columns that are functions of the state, or state names);
    /// empty: the states (`C = I`, `D = 0`).
    pub outputs: Vec<String>,
    /// The independent coordinates (and, optionally, velocities) by name, instead of the
    /// causality's choice at the operating point: `["bar1.x", "bar2.x"]`. Where `q' = v`, the
    /// velocities follow the coordinates.
    pub states: Option<Vec<String>>,
}

impl Default for LinearizeOptions {
    fn default() -> Self {
        LinearizeOptions {
            at: OperatingPoint::Equilibrium,
            outputs: Vec::new(),
            states: None,
        }
    }
}

/// Why a scene could not be linearized.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinearizeError {
    /// `--at` is neither `equilibrium` nor `t=T`.
    #[error("--at '{given}': {why}")]
    BadAt {
        /// What was given.
        given: String,
        /// What is wrong.
        why: String,
    },
    /// `--at t=T` before the scene's start.
    #[error("--at t={t}: before the scene's start t_start = {t_start}")]
    BeforeStart {
        /// The time asked for.
        t: f64,
        /// `solve.t_start`.
        t_start: f64,
    },
    /// An output column the linear model cannot have.
    #[error("--output '{name}': {why}")]
    UnknownOutput {
        /// The column asked for.
        name: String,
        /// Why (with the columns there are).
        why: String,
    },
    /// A raw bond graph scene.
    #[error("linearize needs bodies and joints (a raw bond graph has no coordinates)")]
    RawGraph,
    /// A spatial rigid body (its attitude is a quaternion).
    #[error("bodies '{body}': a spatial rigid body's attitude is a quaternion (four coordinates for three rotations), which has no minimal state here; linearize takes planar bodies and spatial point masses")]
    Spatial {
        /// The body's name.
        body: String,
    },
    /// An input used in a driver's prescribed motion.
    #[error("inputs '{input}' is used by drivers[{driver}] ('{name}'): an input that moves a joint enters through its rates, which a linear model ẋ = A x + B u does not have; use it in loads only")]
    InputInDriver {
        /// The input.
        input: String,
        /// Index of the driver.
        driver: usize,
        /// Its name.
        name: String,
    },
    /// A singular configuration, or a degree of freedom without inertia, at the operating
    /// point.
    #[error("the operating point (t = {t}) has no linearization in these states: {why}")]
    Singular {
        /// Time of the operating point.
        t: f64,
        /// What is singular.
        why: String,
    },
    /// The states given by name are not a partition.
    #[error("states: {0}")]
    States(String),
    /// A value is not finite at the operating point.
    #[error("linearize: {0} is not finite at the operating point")]
    NonFinite(String),
}

/// One mode of the linear model: an eigenvalue `λ` of `A` (one per conjugate pair, the one with
/// `Im λ ≥ 0`, or a real one) and its eigenvector.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// `λ = (Re, Im)` (1/s).
    pub eigenvalue: (f64, f64),
    /// `ω_n = |λ|` (rad/s).
    pub omega_n: f64,
    /// `ω_n / 2π` (Hz).
    pub frequency_hz: f64,
    /// `ζ = −Re λ / |λ|`; `None` for `λ = 0`.
    pub damping_ratio: Option<f64>,
    /// The eigenvector on the states, scaled so that its largest displacement component is
    /// `1 + 0i` (its largest component when no displacement moves).
    pub shape: Vec<(String, Complex<f64>)>,
}

/// The linear model `ẋ = A x + B u`, `y = C x + D u` about an operating point (see the module
/// documentation), with its modes.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearModel {
    /// `equilibrium` or `t=T`.
    pub at: String,
    /// Time of the operating point (s).
    pub t: f64,
    /// The full state there: coordinates then velocities, by name.
    pub operating_point: Vec<(String, f64)>,
    /// State names: the independent coordinates, then the independent velocities.
    pub states: Vec<String>,
    /// Input names (the scene's `"inputs"`), about their start values.
    pub inputs: Vec<String>,
    /// Output names.
    pub outputs: Vec<String>,
    /// `A` (states × states).
    pub a: DMatrix<f64>,
    /// `B` (states × inputs).
    pub b: DMatrix<f64>,
    /// `C` (outputs × states).
    pub c: DMatrix<f64>,
    /// `D` (outputs × inputs).
    pub d: DMatrix<f64>,
    /// The modes, ascending by `ω_n`.
    pub modes: Vec<Mode>,
    /// Remarks (e.g. the partition at the operating point is not the start's).
    pub notes: Vec<String>,
}

impl LinearModel {
    /// The frequency response `H(iω) = C (iω I − A)⁻¹ B + D` (outputs × inputs) at `omega`
    /// (rad/s); `None` where `iω` is an eigenvalue of `A`.
    pub fn frequency_response(&self, omega: f64) -> Option<DMatrix<Complex<f64>>> {
        let n = self.a.nrows();
        let m = DMatrix::from_fn(n, n, |i, j| {
            let d = if i == j {
                Complex::new(0.0, omega)
            } else {
                Complex::new(0.0, 0.0)
            };
            d - Complex::new(self.a[(i, j)], 0.0)
        });
        let b = self.b.map(|x| Complex::new(x, 0.0));
        let x = m.lu().solve(&b)?;
        let c = self.c.map(|x| Complex::new(x, 0.0));
        Some(c * x + self.d.map(|x| Complex::new(x, 0.0)))
    }

    /// The `--json` document: `at`, `operating_point` (object), `states`, `inputs`, `outputs`,
    /// `A`, `B`, `C`, `D` (arrays of rows), `modes` (`eigenvalue` `[re, im]`, `omega_n`,
    /// `frequency_hz`, `damping_ratio`, `shape` `{state: [re, im]}`), `notes`.
    pub fn to_json(&self) -> serde_json::Value {
        let rows = |m: &DMatrix<f64>| {
            serde_json::Value::Array(
                (0..m.nrows())
                    .map(|i| {
                        serde_json::json!((0..m.ncols()).map(|j| m[(i, j)]).collect::<Vec<_>>())
                    })
                    .collect(),
            )
        };
        let modes: Vec<serde_json::Value> = self
            .modes
            .iter()
            .map(|m| {
                let shape: serde_json::Map<String, serde_json::Value> = m
                    .shape
                    .iter()
                    .map(|(k, c)| (k.clone(), serde_json::json!([c.re, c.im])))
                    .collect();
                serde_json::json!({
                    "eigenvalue": [m.eigenvalue.0, m.eigenvalue.1],
                    "omega_n": m.omega_n,
                    "frequency_hz": m.frequency_hz,
                    "damping_ratio": m.damping_ratio,
                    "shape": shape,
                })
            })
            .collect();
        let op: serde_json::Map<String, serde_json::Value> = self
            .operating_point
            .iter()
            .map(|(k, v)| (k.clone(), serde_json::json!(v)))
            .collect();
        serde_json::json!({
            "at": self.at,
            "t": self.t,
            "operating_point": op,
            "states": self.states,
            "inputs": self.inputs,
            "outputs": self.outputs,
            "A": rows(&self.a),
            "B": rows(&self.b),
            "C": rows(&self.c),
            "D": rows(&self.d),
            "modes": modes,
            "notes": self.notes,
        })
    }
}

/// The modes of `a`: one per conjugate pair (`Im λ > 0`) and per real eigenvalue, ascending by
/// `|λ|`, each with its eigenvector (the null vector of `A − λI` by a complex SVD) scaled so
/// that its largest displacement component (of the first `n_coords` states) is 1, or its
/// largest component where the displacements do not move.
pub(crate) fn modes_of(a: &DMatrix<f64>, states: &[String], n_coords: usize) -> Vec<Mode> {
    let n = a.nrows();
    if n == 0 {
        return Vec::new();
    }
    let eig = a.clone().complex_eigenvalues();
    let mut modes: Vec<Mode> = eig
        .iter()
        .filter(|l| l.im >= 0.0)
        .map(|&l| {
            let m = DMatrix::from_fn(n, n, |i, j| {
                let d = if i == j { l } else { Complex::new(0.0, 0.0) };
                Complex::new(a[(i, j)], 0.0) - d
            });
            let svd = m.svd(false, true);
            let k = svd
                .singular_values
                .iter()
                .enumerate()
                .min_by(|x, y| x.1.total_cmp(y.1))
                .map_or(0, |(k, _)| k);
            let vt = svd.v_t.expect("asked for");
            let mut shape: Vec<Complex<f64>> = (0..n).map(|i| vt[(k, i)].conj()).collect();
            let largest = |v: &[Complex<f64>]| {
                v.iter()
                    .copied()
                    .max_by(|x, y| x.norm().total_cmp(&y.norm()))
                    .unwrap_or(Complex::new(0.0, 0.0))
            };
            let overall = largest(&shape);
            let coords = largest(&shape[..n_coords.min(n)]);
            let big = if coords.norm() > 1e-9 * overall.norm() {
                coords
            } else {
                overall
            };
            if big.norm() > 0.0 {
                for s in &mut shape {
                    *s /= big;
                }
            }
            let w = l.norm();
            Mode {
                eigenvalue: (l.re, l.im),
                omega_n: w,
                frequency_hz: w / (2.0 * std::f64::consts::PI),
                // (+ 0.0: an undamped mode's ζ is 0, not −0)
                damping_ratio: (w > 0.0).then(|| -l.re / w + 0.0),
                shape: states.iter().cloned().zip(shape).collect(),
            }
        })
        .collect();
    modes.sort_by(|x, y| x.omega_n.total_cmp(&y.omega_n));
    modes
}
