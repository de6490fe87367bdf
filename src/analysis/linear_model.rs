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
    /// `--at t=T` after the scene's end.
    #[error("--at t={t}: after the scene's end t_end = {t_end} (the operating point is a state the scene's solve reaches, within [t_start, t_end]: give T in that span, or lengthen it with --set solve.t_end=…)")]
    AfterEnd {
        /// The time asked for.
        t: f64,
        /// The scene's last output time (`solve.t_end`).
        t_end: f64,
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

/// Velocities (m/s, rad/s) and accelerations (m/s², rad/s²) at or below this size count as
/// zero when `--at t=T` asks whether the operating point is an equilibrium: the solve's own
/// accuracy at its default tolerances is far below it, and a motion that slow is at rest for
/// every mechanism bondmech models.
pub const AT_REST: f64 = 1e-6;

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
    /// How many times `λ` is an eigenvalue of `A` (its algebraic multiplicity); a repeated
    /// eigenvalue lists one mode per dimension of its eigenspace, each with this count.
    pub multiplicity: usize,
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
    /// Whether the operating point is a static equilibrium (at rest, no acceleration):
    /// `--at equilibrium`, or a state at `--at t=T` where every velocity and acceleration is
    /// below [`AT_REST`]. Only there are `A`'s eigenvalues modes.
    pub equilibrium: bool,
    /// Every eigenvalue of `A` (repeated ones as often as they are), ascending by `|λ|`.
    pub eigenvalues: Vec<(f64, f64)>,
    /// The modes, ascending by `ω_n` (about an equilibrium; empty about a moving operating
    /// point, where `A`'s eigenvalues describe how deviations grow or turn at that instant
    /// and are not modes: no frequencies, no damping ratios).
    pub modes: Vec<Mode>,
    /// Remarks (e.g. the partition at the operating point is not the start's).
    pub notes: Vec<String>,
    /// CPU seconds of the linearization (this thread: the operating point's equilibrium
    /// search or solve included, the scene's first model building excluded).
    pub cpu_seconds: f64,
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
                    "multiplicity": m.multiplicity,
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
            "equilibrium": self.equilibrium,
            "eigenvalues": self
                .eigenvalues
                .iter()
                .map(|e| serde_json::json!([e.0, e.1]))
                .collect::<Vec<_>>(),
            "modes": modes,
            "notes": self.notes,
            "cpu_seconds": self.cpu_seconds,
        })
    }
}

/// The modes of `a`: one per conjugate pair (`Im λ > 0`) and per real eigenvalue, ascending by
/// `|λ|`, each with its eigenvector scaled so that its largest displacement component (of the
/// first `n_coords` states) is 1, or its largest component where the displacements do not move.
///
/// A repeated eigenvalue (eigenvalues of `A` within `1e-6 ‖A‖` of each other, one cluster of
/// algebraic multiplicity `m`) gets a basis of its eigenspace, the null space of `A − λ̄ I`
/// (`λ̄` the cluster's mean): the right singular vectors of `A − λ̄ I` whose singular values are
/// below `1e-6 ‖A‖` — as many modes as the eigenspace has dimensions (the geometric
/// multiplicity, `m` for a semisimple eigenvalue, fewer where `A` is defective), each with
/// [`Mode::multiplicity`] `m`. The basis is brought to the form in which each vector has one
/// displacement component that the others lack (Gauss–Jordan on the largest displacement
/// components), so a spherical pendulum's two modes at `√(g/L)` are its two planes, not one
/// plane twice.
pub(crate) fn modes_of(a: &DMatrix<f64>, states: &[String], n_coords: usize) -> Vec<Mode> {
    let n = a.nrows();
    if n == 0 {
        return Vec::new();
    }
    let zero = Complex::new(0.0, 0.0);
    let scale = a.norm().max(f64::MIN_POSITIVE);
    let tol = 1e-6 * scale;
    let eig = complex_eigenvalues(a);
    let upper: Vec<Complex<f64>> = eig.iter().copied().filter(|l| l.im >= 0.0).collect();
    // clusters of (numerically) equal eigenvalues, one per distinct λ with Im λ ≥ 0; a real
    // eigenvalue's conjugate is itself, a complex one's is counted on its own side
    let mut clusters: Vec<Vec<Complex<f64>>> = Vec::new();
    for &l in &upper {
        match clusters
            .iter_mut()
            .find(|c| c.iter().any(|&m| (m - l).norm() <= tol))
        {
            Some(c) => c.push(l),
            None => clusters.push(vec![l]),
        }
    }
    let mut modes: Vec<Mode> = Vec::new();
    for cluster in clusters {
        let multiplicity = cluster.len();
        let mut l = cluster.iter().fold(zero, |acc, &x| acc + x) / (multiplicity as f64);
        if cluster.iter().all(|x| x.im == 0.0) {
            l.im = 0.0;
        }
        let m = DMatrix::from_fn(n, n, |i, j| {
            let d = if i == j { l } else { zero };
            Complex::new(a[(i, j)], 0.0) - d
        });
        let svd = m.svd(false, true);
        let vt = svd.v_t.expect("asked for");
        let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
        order.sort_by(|&x, &y| svd.singular_values[x].total_cmp(&svd.singular_values[y]));
        // the eigenspace: the singular values at the cluster's accuracy, at least one and at
        // most the algebraic multiplicity
        let dim = order
            .iter()
            .take(multiplicity)
            .filter(|&&k| svd.singular_values[k] <= tol)
            .count()
            .max(1);
        let mut basis: Vec<Vec<Complex<f64>>> = order[..dim]
            .iter()
            .map(|&k| (0..n).map(|i| vt[(k, i)].conj()).collect())
            .collect();
        eigenspace_pivots(&mut basis, n_coords.min(n));
        for mut shape in basis {
            let largest = |v: &[Complex<f64>]| {
                v.iter()
                    .copied()
                    .max_by(|x, y| x.norm().total_cmp(&y.norm()))
                    .unwrap_or(zero)
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
            modes.push(Mode {
                eigenvalue: (l.re, l.im),
                omega_n: w,
                frequency_hz: w / (2.0 * std::f64::consts::PI),
                // (+ 0.0: an undamped mode's ζ is 0, not −0)
                damping_ratio: (w > 0.0).then(|| -l.re / w + 0.0),
                multiplicity,
                shape: states.iter().cloned().zip(shape).collect(),
            });
        }
    }
    modes.sort_by(|x, y| x.omega_n.total_cmp(&y.omega_n));
    modes
}

/// Gauss–Jordan on a basis of an eigenspace (vectors of length `n`): vector `k` gets its
/// pivot at the largest remaining component (among the first `n_coords`, the displacements,
/// where they move) and that component is cleared from the others, so each vector has a
/// component the others lack (the span, hence the eigenspace, is unchanged; independent).
fn eigenspace_pivots(basis: &mut [Vec<Complex<f64>>], n_coords: usize) {
    let k = basis.len();
    if k < 2 {
        return;
    }
    let mut used: Vec<usize> = Vec::new();
    for p in 0..k {
        let pick = |range: std::ops::Range<usize>, v: &[Complex<f64>]| {
            range
                .filter(|i| !used.contains(i))
                .max_by(|&x, &y| v[x].norm().total_cmp(&v[y].norm()))
        };
        let v = basis[p].clone();
        let vmax = v.iter().map(|c| c.norm()).fold(0.0, f64::max);
        let i = match pick(0..n_coords, &v) {
            Some(i) if v[i].norm() > 1e-6 * vmax => i,
            _ => match pick(0..v.len(), &v) {
                Some(i) => i,
                None => return,
            },
        };
        let piv = v[i];
        if piv.norm() == 0.0 {
            return;
        }
        for c in basis[p].iter_mut() {
            *c /= piv;
        }
        let row = basis[p].clone();
        for (q, other) in basis.iter_mut().enumerate() {
            if q != p {
                let f = other[i];
                for (c, r) in other.iter_mut().zip(&row) {
                    *c -= f * r;
                }
            }
        }
        used.push(i);
    }
}

/// The eigenvalues of `a` by nalgebra's real Schur form with a bounded number of QR sweeps:
/// its `complex_eigenvalues()` iterates without bound and does not return on some matrices
/// (a sleeping top's `A` below its stability threshold, issue 48). Where the sweeps stall the
/// matrix is shifted, `a + σ I` (the same eigenvectors, eigenvalues moved by `σ`, another path
/// for the iteration), and `σ` taken back; NaNs where every try stalls.
pub(crate) fn complex_eigenvalues(a: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let n = a.nrows();
    let scale = a.amax().max(f64::MIN_POSITIVE);
    let sweeps = 100 * n.max(1);
    for shift in [0.0, 1e-3, -2e-3, 0.37, -0.61, 1.7] {
        let sigma = shift * scale;
        let m = a + DMatrix::identity(n, n) * sigma;
        if let Some(schur) = nalgebra::linalg::Schur::try_new(m, f64::EPSILON, sweeps) {
            return schur
                .complex_eigenvalues()
                .iter()
                .map(|l| Complex::new(l.re - sigma, l.im))
                .collect();
        }
    }
    vec![Complex::new(f64::NAN, f64::NAN); n]
}

/// Every eigenvalue of `a`, ascending by `|λ|` (ties by the imaginary part).
pub(crate) fn eigenvalues_of(a: &DMatrix<f64>) -> Vec<(f64, f64)> {
    if a.nrows() == 0 {
        return Vec::new();
    }
    let mut e: Vec<(f64, f64)> = complex_eigenvalues(a)
        .iter()
        .map(|l| (l.re, l.im))
        .collect();
    e.sort_by(|x, y| {
        x.0.hypot(x.1)
            .total_cmp(&y.0.hypot(y.1))
            .then(x.1.total_cmp(&y.1))
    });
    e
}
