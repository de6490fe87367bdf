//! How much memory a model will need, estimated from the scene before building it, so that a
//! model far beyond the machine (6000 free bodies) is refused with a message naming the limit
//! instead of aborting out of memory halfway through.
//!
//! With the dense linear solver every formulation factors a **dense** Newton matrix, and the
//! consistent start always solves the dense `[M G_vᵀ; G_v 0]` by an SVD; both grow as the
//! square of the unknowns:
//!
//! | what | unknowns | dense copies |
//! |---|---|---|
//! | GGL, compliant GGL, index 1 on IDA | `n ≤ nq + nv + 2 nc` | 1 (IDA's Newton matrix) |
//! | decoupled twin on CVODE | `nq + nv` | 2 (Newton matrix and saved Jacobian) |
//! | consistent start (SVD) | `nv + nc` | 4 (matrix, its copy, `U`, `Vᵀ`) |
//!
//! The estimate is the larger of the start and the chosen formulation's matrices, plus about
//! 4 KiB per unknown for the symbolic equations and tapes. With a sparse linear solver
//! (`solve.linear_solver` `sparse`/`klu`, or `auto` from
//! [`LinearSolverKind::AUTO_SPARSE_UNKNOWNS`] unknowns on) the Newton matrix is stored in
//! compressed sparse columns: its term is [`SPARSE_BYTES_PER_UNKNOWN`] per unknown (entries,
//! their row indices and the LU factors' fill), linear in the size instead of quadratic. The
//! consistent start of a large mechanism takes sparse Cholesky factorisations when its joints
//! have full rank ([`crate::thresholds::SPARSE_START_UNKNOWNS`]), but falls back to the dense
//! SVD with redundant joints, which the scene does not tell; the estimate keeps that dense
//! fallback, so it then bounds the size accepted: for planar chains
//! (`nv + nc = 5 N`, `n = 10 N`) its `4 (nv + nc)²` equals the dense Newton matrix's `n²`, for
//! spatial hinge chains (`nv + nc = 11 N`, `n = 23 N`) it is 9 % less. Chains of a few hundred
//! bodies (a 500-link pendulum needs about 0.2 GiB) are far from the limit either way.

use crate::scene::{Dimension, Scene};
use crate::settings::{FormulationKind, LinearSolverKind};

/// Fraction of the available memory a model may plan to use.
pub const MEMORY_FRACTION: f64 = 0.8;

/// Bytes per unknown assumed for the symbolic equations, their derivatives and the tapes.
pub const SYMBOLIC_BYTES_PER_UNKNOWN: f64 = 4096.0;

/// Bytes per unknown of a sparse Newton matrix: its entries (≤ 16 per row on the mechanisms'
/// GGL matrices: a coordinate row holds `q'`, `K(q) v` and `G_qᵀ μ` of the joints at its body;
/// a velocity row `v'`, the force's dependencies and `G_vᵀ λ`) at 8 bytes of value and 8 of
/// row index, twice (SUNDIALS' CSC matrix and the solver's copy), and the LU factors with a
/// fill up to 16 times the matrix's: `16 · 16 · (2 + 16) ≈ 4.6 KiB`, rounded up to 8 KiB.
pub const SPARSE_BYTES_PER_UNKNOWN: f64 = 8192.0;

/// The sizes of a scene's model and the memory its largest dense matrices need.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// Coordinates `q` (upper bound: planar bodies 3, spatial bodies 7).
    pub coordinates: usize,
    /// Velocities `v` (planar bodies 3, spatial bodies 6).
    pub velocities: usize,
    /// Constraint rows (pin 2, planar prismatic 2, planar weld 3, spherical 3, hinge 5, spatial
    /// prismatic 5, spatial weld 6).
    pub constraint_rows: usize,
    /// Unknowns of the matrix that dominates.
    pub unknowns: usize,
    /// What that matrix is, e.g. `the dense Newton matrix of the GGL DAE on IDA`.
    pub what: &'static str,
    /// Bytes needed at the peak (the dominating matrices plus the symbolic part).
    pub bytes: f64,
}

/// Which limit on this process's memory is the tightest (see [`memory_limit`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LimitSource {
    /// The machine's free memory (`/proc/meminfo` `MemAvailable`).
    MemAvailable,
    /// The address-space limit (`ulimit -v`, `RLIMIT_AS`) less the address space in use.
    AddressSpace,
    /// The cgroup's memory limit (`memory.max`, v1 `memory.limit_in_bytes`) less its usage.
    Cgroup,
}

impl LimitSource {
    /// What the limit is and the setting that raises it.
    pub fn describe(self) -> &'static str {
        match self {
            LimitSource::MemAvailable => "/proc/meminfo MemAvailable",
            LimitSource::AddressSpace => {
                "ulimit -v (RLIMIT_AS) less the address space in use; raise ulimit -v"
            }
            LimitSource::Cgroup => {
                "the cgroup's memory limit (memory.max) less its usage; raise the container's memory limit"
            }
        }
    }
}

/// The memory a new allocation may take, and which limit sets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryLimit {
    /// Bytes.
    pub bytes: u64,
    /// The tightest limit.
    pub source: LimitSource,
}

/// Why a model is refused before it is built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SizeError {
    /// The estimate exceeds [`MEMORY_FRACTION`] of the memory available.
    #[error("the model is too large for this machine: {} coordinates, {} velocities and {} constraint rows need ~{} for {} ({} unknowns); this process has {} available ({}; the least of /proc/meminfo MemAvailable, ulimit -v and the cgroup limit); limit: {:.0} % of it (dense matrices grow as the square of the unknowns; solve.linear_solver \"sparse\" stores the Newton matrix sparse, the consistent start stays dense)", .estimate.coordinates, .estimate.velocities, .estimate.constraint_rows, gib(.estimate.bytes), .estimate.what, .estimate.unknowns, gib(*.available as f64), .limit.describe(), MEMORY_FRACTION * 100.0)]
    TooLarge {
        /// The estimate.
        estimate: Box<MemoryEstimate>,
        /// Bytes available.
        available: u64,
        /// The limit that set `available`.
        limit: LimitSource,
    },
    /// Keeping every output row in memory would exceed [`MEMORY_FRACTION`] of the memory
    /// available.
    #[error("{rows} output rows of {columns} columns kept in memory need ~{}; this process has {} available ({}); limit: {:.0} % of it: raise solve.output_step or lower solve.t_end (--t-end), or let the rows stream to a file (bondmech run --out FILE without --table or --plot keeps none)", gib(*.bytes), gib(*.available as f64), .limit.describe(), MEMORY_FRACTION * 100.0)]
    TooManyRows {
        /// Output rows.
        rows: usize,
        /// Columns per row.
        columns: usize,
        /// Bytes they need.
        bytes: f64,
        /// Bytes available.
        available: u64,
        /// The limit that set `available`.
        limit: LimitSource,
    },
}

/// Bytes one kept output row of `columns` values takes: the values, the time, the row's
/// vector header and the allocator's overhead.
pub fn row_bytes(columns: usize) -> f64 {
    8.0 * columns as f64 + 8.0 + 24.0 + 16.0
}

/// Refuses keeping `rows` output rows of `columns` values in memory beyond [`MEMORY_FRACTION`]
/// of `limit` (`None`: no limit known, accepted).
pub fn check_rows_memory(
    rows: usize,
    columns: usize,
    limit: Option<MemoryLimit>,
) -> Result<(), SizeError> {
    let bytes = rows as f64 * row_bytes(columns);
    match limit {
        Some(l) if bytes > MEMORY_FRACTION * l.bytes as f64 => Err(SizeError::TooManyRows {
            rows,
            columns,
            bytes,
            available: l.bytes,
            limit: l.source,
        }),
        _ => Ok(()),
    }
}

fn gib(bytes: f64) -> String {
    format!("{:.1} GiB", bytes / (1u64 << 30) as f64)
}

/// Estimates the memory a scene needs when solved with `formulation` and the scene's own
/// `solve.linear_solver` (see [`estimate_memory_with`]).
pub fn estimate_memory(scene: &Scene, formulation: FormulationKind) -> MemoryEstimate {
    estimate_memory_with(scene, formulation, scene.solve.linear_solver)
}

/// Estimates the memory a scene needs when solved with `formulation` and `linear_solver` (see
/// the module documentation): the consistent start and the Newton matrix of that formulation,
/// dense (`8 n²` bytes, twice for CVODE's saved Jacobian) or sparse
/// ([`SPARSE_BYTES_PER_UNKNOWN`]` · n`) as `linear_solver` resolves for its `n` unknowns. A
/// raw bond graph is estimated from its element count (at most two unknowns per element) and
/// always dense (raw bond graphs use the dense solver).
pub fn estimate_memory_with(
    scene: &Scene,
    formulation: FormulationKind,
    linear_solver: LinearSolverKind,
) -> MemoryEstimate {
    let spatial = scene.dimension == Dimension::Spatial;
    let nb = scene.bodies.len();
    let (mut nq, mut nv) = if spatial {
        (7 * nb, 6 * nb)
    } else {
        (3 * nb, 3 * nb)
    };
    let nc: usize = scene
        .joints
        .iter()
        .map(|j| super::joints::locks(&j.kind, spatial))
        .sum();
    if let Some(elements) = scene
        .bond_graph
        .as_ref()
        .and_then(|g| g.get("elements"))
        .and_then(|e| e.as_array())
    {
        nq = elements.len();
        nv = elements.len();
    }
    let sq = |n: usize| (n as f64) * (n as f64) * 8.0;
    let ggl = nq + nv + 2 * nc;
    let raw = scene.bond_graph.is_some();
    let sparse = |n: usize| !raw && linear_solver.resolve(n).is_some();
    let newton = match (
        formulation == FormulationKind::Decoupled,
        sparse(nq + nv),
        sparse(ggl),
    ) {
        (true, true, _) => (
            nq + nv,
            SPARSE_BYTES_PER_UNKNOWN * (nq + nv) as f64,
            "the sparse Newton matrix and its LU of the decoupled twin on CVODE",
        ),
        (true, false, _) => (
            nq + nv,
            2.0 * sq(nq + nv),
            "the dense Newton matrix and saved Jacobian of the decoupled twin on CVODE",
        ),
        (false, _, true) => (
            ggl,
            SPARSE_BYTES_PER_UNKNOWN * ggl as f64,
            "the sparse Newton matrix and its LU of the DAE on IDA",
        ),
        (false, _, false) => (ggl, sq(ggl), "the dense Newton matrix of the DAE on IDA"),
    };
    let candidates = [
        newton,
        (
            nv + nc,
            4.0 * sq(nv + nc),
            "the SVD of the dense mass–constraint matrix of the consistent start",
        ),
    ];
    let (unknowns, dense, what) =
        candidates
            .into_iter()
            .fold(candidates[0], |a, b| if b.1 > a.1 { b } else { a });
    MemoryEstimate {
        coordinates: nq,
        velocities: nv,
        constraint_rows: nc,
        unknowns,
        what,
        bytes: dense + SYMBOLIC_BYTES_PER_UNKNOWN * ggl as f64,
    }
}

/// The memory available to a new allocation (see [`memory_limit`]); `None` where nothing
/// says (the check is then skipped).
pub fn available_memory() -> Option<u64> {
    memory_limit().map(|l| l.bytes)
}

/// The tightest of the limits on this process's memory: the machine's `MemAvailable`
/// (`/proc/meminfo`), the address-space limit (`ulimit -v`, `RLIMIT_AS`, from
/// `/proc/self/limits`) less the address space in use (`VmSize` of `/proc/self/status`), and
/// the cgroup's limit less its usage (cgroup v2 `memory.max` and `memory.current` of the
/// process's cgroup, or v1 `memory.limit_in_bytes` and `memory.usage_in_bytes`). `None` when
/// none of them is known.
pub fn memory_limit() -> Option<MemoryLimit> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let candidates = [
        read("/proc/meminfo")
            .and_then(|t| meminfo_available(&t))
            .map(|b| (b, LimitSource::MemAvailable)),
        address_space_left(
            read("/proc/self/limits").as_deref(),
            read("/proc/self/status").as_deref(),
        )
        .map(|b| (b, LimitSource::AddressSpace)),
        cgroup_left().map(|b| (b, LimitSource::Cgroup)),
    ];
    candidates
        .into_iter()
        .flatten()
        .min_by_key(|(b, _)| *b)
        .map(|(bytes, source)| MemoryLimit { bytes, source })
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn meminfo_available(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The soft `Max address space` of `/proc/self/limits` less the `VmSize` of
/// `/proc/self/status`; `None` when unlimited or unknown.
pub fn address_space_left(limits: Option<&str>, status: Option<&str>) -> Option<u64> {
    let line = limits?
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft: u64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?; // "unlimited" does not parse
    let used_kib: u64 = status
        .and_then(|s| s.lines().find(|l| l.starts_with("VmSize:")))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    Some(soft.saturating_sub(used_kib.saturating_mul(1024)))
}

/// The process's cgroup memory limit less its usage; `None` when unlimited or unknown.
fn cgroup_left() -> Option<u64> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let number = |t: Option<String>| t.and_then(|t| t.trim().parse::<u64>().ok());
    // cgroup v2: the process's own group (`0::/path` in /proc/self/cgroup), then the root
    let own = read("/proc/self/cgroup").and_then(|t| {
        t.lines()
            .find_map(|l| l.strip_prefix("0::").map(|p| p.trim().to_string()))
    });
    let mut dirs = Vec::new();
    if let Some(p) = own.filter(|p| p != "/") {
        dirs.push(format!("/sys/fs/cgroup{p}"));
    }
    dirs.push("/sys/fs/cgroup".to_string());
    for d in dirs {
        if let Some(max) = number(read(&format!("{d}/memory.max"))) {
            let used = number(read(&format!("{d}/memory.current"))).unwrap_or(0);
            return Some(max.saturating_sub(used));
        }
    }
    // cgroup v1 (an unlimited group reports a number near 2^63)
    let max = number(read("/sys/fs/cgroup/memory/memory.limit_in_bytes"))?;
    if max >= 1 << 62 {
        return None;
    }
    let used = number(read("/sys/fs/cgroup/memory/memory.usage_in_bytes")).unwrap_or(0);
    Some(max.saturating_sub(used))
}

/// Refuses `estimate` when it exceeds [`MEMORY_FRACTION`] of `available` bytes (`None`: no
/// limit known, accepted); the bytes are taken as the machine's `MemAvailable`.
pub fn check_memory(estimate: &MemoryEstimate, available: Option<u64>) -> Result<(), SizeError> {
    check_memory_against(
        estimate,
        available.map(|bytes| MemoryLimit {
            bytes,
            source: LimitSource::MemAvailable,
        }),
    )
}

/// Refuses `estimate` when it exceeds [`MEMORY_FRACTION`] of `limit` (`None`: no limit known,
/// accepted); the message names the limit and the setting that raises it.
pub fn check_memory_against(
    estimate: &MemoryEstimate,
    limit: Option<MemoryLimit>,
) -> Result<(), SizeError> {
    match limit {
        Some(l) if estimate.bytes > MEMORY_FRACTION * l.bytes as f64 => Err(SizeError::TooLarge {
            estimate: Box::new(estimate.clone()),
            available: l.bytes,
            limit: l.source,
        }),
        _ => Ok(()),
    }
}

/// [`check_memory_against`] of the scene's [`estimate_memory`] with `formulation` (and the
/// scene's `solve.linear_solver`) against this process's [`memory_limit`].
/// `Model::new` calls it with the scene's own `solve.formulation`; a
/// caller that solves with another (`--formulation decoupled`) calls it again with that one.
pub fn check_scene_memory(scene: &Scene, formulation: FormulationKind) -> Result<(), SizeError> {
    check_memory_against(&estimate_memory(scene, formulation), memory_limit())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn address_space_limit_less_what_is_in_use() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units\nMax address space         4294967296           unlimited            bytes\n";
        let status = "Name:\tbondmech\nVmSize:\t  1048576 kB\n";
        assert_eq!(
            address_space_left(Some(limits), Some(status)),
            Some(3 << 30)
        );
        let unlimited =
            "Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(address_space_left(Some(unlimited), Some(status)), None);
    }
}
