//! The solver settings every layer names: the formulation, the partitioned formulation's
//! integrator and the linear solver (the scene's `solve` section, the command line's flags,
//! the service's fields and [`crate::solve::SolveOptions`] all use these one enums).
//!
//! A leaf: it imports nothing of bondmech above the SUNDIALS wrapper, so the scene, the
//! mechanism layer and the solvers can all name a setting without importing one another.
//!
//! ```
//! use bondmech::settings::FormulationKind;
//! assert_eq!(FormulationKind::default(), FormulationKind::Dae);
//! assert_eq!(FormulationKind::parse("ode"), Some(FormulationKind::Decoupled));
//! assert_eq!(FormulationKind::from_name("ode"), None);
//! ```

use clap::ValueEnum;

/// How the joints are treated.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    serde::Serialize,
    serde::Deserialize,
    ValueEnum,
    schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum FormulationKind {
    /// The chapter's DAE on IDA, the default: the integral-causality inertias' flows and the
    /// displacements they carry are IDA's differential unknowns; the differential-causality
    /// inertias' flows and accelerations, the dependent displacements and the constraint
    /// efforts are algebraic (index 1 at acceleration level, the constraint rows kept at
    /// position and velocity level, [`crate::solve::formulation::Index1Formulation`]); the partition is the
    /// causality's ([`crate::bond::causality`]), re-chosen when its block degrades. Where
    /// `q' = K(q) v` (3D bodies' quaternions, body-fixed planar frames) the dependent coordinates
    /// are chosen apart from the dependent velocities; with redundant joints the motion is
    /// solved from the independent rows (the redundant ones left out of the dependent block)
    /// and a warning in the summary says which, their reactions taking the redundant rows'
    /// forces as zero; singular passages are handed to the GGL.
    #[default]
    #[value(
        help = "the chapter's DAE on IDA in the causality's partition (index 1; the compliant GGL at singular passages; redundant joints solved from their independent rows); the default"
    )]
    Dae,
    /// Stabilized index-2 DAE (Gear–Gupta–Leimkuhler) on IDA; switches to the compliant form by
    /// itself where the constraints lose rank.
    #[value(
        help = "stabilized index-2 DAE (Gear–Gupta–Leimkuhler) on IDA, compliant at singular configurations"
    )]
    Ggl,
    /// GGL with compliance ε from the start (`g − εμ = 0`, `G v − ελ = 0`).
    #[value(
        name = "compliant_ggl",
        alias = "compliant",
        help = "GGL with compliance from the start"
    )]
    CompliantGgl,
    /// Index 1 at acceleration level with dummy derivatives; the dependent velocities are
    /// re-selected when their block of `G_v` becomes ill-conditioned.
    #[value(
        alias = "index-1",
        help = "acceleration-level index 1 with dummy derivatives, on IDA"
    )]
    Index1,
    /// Joints replaced by stiff springs (the decoupled twin), an ODE on CVODE BDF.
    #[value(
        alias = "ode",
        help = "joints replaced by stiff springs, an ODE on CVODE"
    )]
    Decoupled,
    /// The degrees of freedom as the ODE states (coordinate partitioning): the dependent
    /// coordinates by Newton on `g(q) = 0` in every right-hand side, on CVODE (Adams or BDF)
    /// or ARKODE's explicit Runge–Kutta ([`Integrator`]); the partition is re-chosen when its
    /// block degrades, and singular configurations are handed to the compliant GGL.
    #[value(
        help = "the degrees of freedom as ODE states (dependent coordinates by Newton), on explicit Runge–Kutta or CVODE"
    )]
    Partitioned,
}

impl FormulationKind {
    /// The name used in summaries and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FormulationKind::Dae => "dae",
            FormulationKind::Ggl => "ggl",
            FormulationKind::CompliantGgl => "compliant_ggl",
            FormulationKind::Index1 => "index1",
            FormulationKind::Decoupled => "decoupled",
            FormulationKind::Partitioned => "partitioned",
        }
    }

    /// Parses a name as the command line and the service accept it: a JSON name
    /// ([`Self::from_name`]) or one of the aliases `compliant`, `index-1`, `ode`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "compliant" => Some(FormulationKind::CompliantGgl),
            "index-1" => Some(FormulationKind::Index1),
            "ode" => Some(FormulationKind::Decoupled),
            _ => Self::from_name(s),
        }
    }

    /// Parses a scene's JSON name (`"dae"`, `"ggl"`, `"compliant_ggl"`, `"index1"`,
    /// `"decoupled"`, `"partitioned"`), without the command line's aliases.
    pub fn from_name(s: &str) -> Option<Self> {
        match s {
            "dae" => Some(FormulationKind::Dae),
            "ggl" => Some(FormulationKind::Ggl),
            "compliant_ggl" => Some(FormulationKind::CompliantGgl),
            "index1" => Some(FormulationKind::Index1),
            "decoupled" => Some(FormulationKind::Decoupled),
            "partitioned" => Some(FormulationKind::Partitioned),
            _ => None,
        }
    }
}

/// The integrator of the partitioned formulation (`solve.integrator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Chosen by a stiffness test at the start (see `solve::run::STIFFNESS_LIMIT`): explicit
    /// Runge–Kutta when the reduced ODE is not stiff, CVODE BDF when it is.
    #[default]
    Auto,
    /// CVODE's variable-order Adams–Moulton (orders 1–12).
    Adams,
    /// CVODE's variable-order BDF (orders 1–5), Newton with a difference-quotient Jacobian.
    Bdf,
    /// ARKODE's explicit Runge–Kutta (Tsitouras 5(4) at rtol ≥ 1e-7, Fehlberg 8(7)
    /// below), adaptive.
    Erk,
}

impl Integrator {
    /// The name used in scenes and summaries.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Auto => "auto",
            Integrator::Adams => "adams",
            Integrator::Bdf => "bdf",
            Integrator::Erk => "erk",
        }
    }

    /// Parses `auto`, `adams`, `bdf` or `erk`.
    pub fn parse(s: &str) -> Option<Self> {
        [
            Integrator::Auto,
            Integrator::Adams,
            Integrator::Bdf,
            Integrator::Erk,
        ]
        .into_iter()
        .find(|i| i.name() == s)
    }
}

/// Which linear solver factors the Newton matrix (IDA's `∂F/∂y + cj ∂F/∂y'`, CVODE's
/// `I − γ ∂f/∂y`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LinearSolverKind {
    /// Dense below [`LinearSolverKind::AUTO_SPARSE_UNKNOWNS`] unknowns, faer's sparse LU from
    /// there on. The default.
    #[default]
    Auto,
    /// SUNDIALS' dense LU on the full `n × n` matrix.
    Dense,
    /// faer's sparse LU on the compressed-sparse-column matrix.
    Sparse,
    /// SUNDIALS' KLU (SuiteSparse) on the same sparse matrix.
    Klu,
}

impl LinearSolverKind {
    /// Unknowns from which `auto` picks the sparse LU. Measured with
    /// `cargo bench --bench sparse` (N-link pendulum, GGL, rtol 1e-6, µs per step, median of 5
    /// solves, one run on a 2-core shared machine), dense / faer: 1.04 at 10 unknowns, 1.21 at
    /// 20, 1.55 at 30, 2.4 at 60, 5.2 at 160 (and 62 at 1280). Below 30 the two are within the
    /// noise of the machine, and dense keeps the step sequences small scenes always had.
    pub const AUTO_SPARSE_UNKNOWNS: usize = 30;

    /// Unknowns of the index-1 DAE (the default `dae`, `index1`) from which `auto` factors
    /// its Newton matrix with faer's sparse LU instead of eliminating the dependent blocks
    /// ([`crate::sundials::schur`]: dense blocks `G_qD`, `G_vD` and the saddle
    /// `[M_D G_Dᵀ; G_D 0]` inverted, a dense Schur complement on the degrees of freedom, all
    /// in a dense `n × n` matrix: cubic in the size of a chain). Measured with
    /// `cargo bench --bench sparse` (`BONDMECH_SPARSE_BENCH=dae_crossover`: N-link pendulum,
    /// `dae`, rtol 1e-6, µs per step, median of 5 solves), Schur / faer: see
    /// docs/perf/dae_scale.txt. Every bundled scene (82 unknowns at most: Andrews' squeezer, the
    /// three-four-bar chain) stays below it.
    pub const AUTO_SCHUR_UNKNOWNS: usize = 100;

    /// Whether the index-1 DAE's Newton matrix with `n` unknowns is solved by the Schur
    /// elimination: `auto` below [`Self::AUTO_SCHUR_UNKNOWNS`].
    pub fn index1_schur(self, n: usize) -> bool {
        self == LinearSolverKind::Auto && n < Self::AUTO_SCHUR_UNKNOWNS
    }

    /// The name used in scenes, on the command line and in summaries.
    pub fn name(self) -> &'static str {
        match self {
            LinearSolverKind::Auto => "auto",
            LinearSolverKind::Dense => "dense",
            LinearSolverKind::Sparse => "sparse",
            LinearSolverKind::Klu => "klu",
        }
    }

    /// Parses `auto`, `dense`, `sparse` (alias `faer`) or `klu`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(LinearSolverKind::Auto),
            "dense" => Some(LinearSolverKind::Dense),
            "sparse" | "faer" => Some(LinearSolverKind::Sparse),
            "klu" => Some(LinearSolverKind::Klu),
            _ => None,
        }
    }

    /// The sparse solver to use for `n` unknowns, `None` for the dense one.
    pub fn resolve(self, n: usize) -> Option<crate::sundials::SparseSolver> {
        use crate::sundials::SparseSolver;
        match self {
            LinearSolverKind::Auto if n >= Self::AUTO_SPARSE_UNKNOWNS => Some(SparseSolver::Faer),
            LinearSolverKind::Auto | LinearSolverKind::Dense => None,
            LinearSolverKind::Sparse => Some(SparseSolver::Faer),
            LinearSolverKind::Klu => Some(SparseSolver::Klu),
        }
    }

    /// What [`Self::resolve`] picks for `n` unknowns, by name: `dense`, `faer` or `klu`.
    pub fn resolved_name(self, n: usize) -> &'static str {
        match self.resolve(n) {
            None => "dense",
            Some(crate::sundials::SparseSolver::Faer) => "faer",
            Some(crate::sundials::SparseSolver::Klu) => "klu",
        }
    }
}
