//! Every threshold that decides a partition, a re-selection, a hand-over, a singular passage,
//! the energy invariant or a rank under them (the initial projection's, the block LU's), each
//! with the reason for its value; and [`PartitionPolicy`], the one
//! place the runners and `linearize` ask (`equilibrium` chooses no partition: it solves
//! every joint row for `q` and `λ`) (the comparisons are the ones the
//! runners made themselves, in the same order, so the numbers are unchanged).

// ---- The causality's partition in the index-1 runners: when its conditioning is checked and re-chosen ----

/// The dependent block's `μ(D)` ([`crate::partition::dependent_condition`]) above which a fresh selection of dependent velocities is
/// considered at the output times (between them the step watch of
/// `solve/formulation/index1/runner.rs` examines IDA's steps).
pub const INDEX1_CHECK_CONDITION: f64 = 10.0;

/// The fresh selection replaces the current one when its condition is this many times smaller.
/// The check happens at output times only, so it must fire well before the block is singular:
/// the condition grows like `1/|cos θ|` as a dependent coordinate loses its grip (measured on a
/// bead sliding along a pendulum bar: the dependent bead translation must change near the
/// vertical, and a threshold of 1e4 on the current set alone let IDA run into the singular
/// block between outputs).
pub const INDEX1_RESELECT_GAIN: f64 = 10.0;

// ---- The index-1 (`dae`) runner: re-selection at the steps, redundant rows, the hand-over to the GGL, the energy invariant ----

/// The rise of the joints' condition number `κ(G_v M⁺ G_vᵀ)` over its value at the start above
/// which the `dae` formulation hands the rest of the run to the GGL (checked at the outputs
/// where the dependent block's condition has doubled). Measured on the bundled scenes: the
/// slider-crank's κ varies by 1.9× over its turns, Andrews' by 1.6×, the four-bar's by 2.9×;
/// the three-four-bar chain's rises 18× an output step before its alignment (κ peak 8e3).
pub const DAE_HANDOVER_RISE: f64 = 10.0;

/// The condition number of the best-conditioned dependent block `G_v[:, D]` above which the
/// `dae` formulation hands the rest of the run to the GGL (which passes singular configurations
/// with its compliant form and reports them): every partition is then degrading, as near a
/// singular configuration of the joints (a four-bar chain's alignment; a slider-crank's dead
/// centre is not one: the crank angle stays a regular state there).
pub const DAE_HANDOVER_CONDITION: f64 = 1e3;

/// How much better a fresh set of independent joint rows must hold the rank
/// ([`redundant_row_grip`](crate::partition::redundant_row_grip)) than the running one for a restart with it: the grip of the rows
/// left out falls like `|sin φ|` as the self-stress turns away from them, and a fresh set is
/// taken while the running one still holds a quarter of it.
pub const REDUNDANT_ROWS_GAIN: f64 = 4.0;

/// Growth of the dependent block's pivot-ratio estimate over its value at the start of a
/// segment above which the step watch examines a step.
pub const GRIP_GROWTH: f64 = 3.0;

/// The pivot-ratio estimate above which the step watch examines a step in any case (a block of
/// unit rows starts at 1; the examination's `μ` is then about 10).
pub const GRIP_ALERT: f64 = 4.0;

/// The factor by which the alert rises when an examination keeps the block (no block
/// [`STEP_RESELECT_GAIN`] times better yet): the next look comes after a further degradation.
pub const GRIP_RECHECK: f64 = 1.5;

/// At an IDA step, a fresh choice replaces the running dependent velocities when its condition
/// `μ` is this many times smaller. Smaller than the outputs' [`INDEX1_RESELECT_GAIN`]: between
/// outputs the block is watched at every step, so the switch need not wait for a block 10×
/// worse, and the dependent unknowns (algebraic, out of IDA's error test) amplify the
/// independent ones' error by about `μ`. Measured on `scenes/bead_slot_through_pivot.json`
/// (rtol 1e-10, atol 1e-8, outputs 0.03 … 0.5 s): a switch at `μ ≈ 30` (gain 10) left
/// 0.8–19e-6 of error against the polar reference, at `μ ≈ 10` (gain 3) 1.9–2.0e-7, the
/// GGL's 1e-7.
pub const STEP_RESELECT_GAIN: f64 = 3.0;

/// How far any coordinate moves (rad, m; the largest change of `q` over its entries) between
/// two examinations of the partition: the dependent block's grip `μ(D)`, the dependent
/// coordinates' block, the redundant rows' and the approach of a singular configuration,
/// which all depend on the configuration only. The examinations run at IDA's accepted steps
/// (the watch, `Formulation::watch_step`), so when they happen no longer follows the
/// output times asked for, and their cost follows the motion, not the outputs: Bricard's
/// mechanism (10 s, outputs every 0.01 s, about 1200 steps) examined its partition at each of
/// its 1000 outputs, two thirds of its integration's CPU (dense singular values and a
/// causality assignment each time).
pub const EXAMINE_MOTION: f64 = 0.02;

/// The margin by which `Index1::examination_moot`'s bound on `μ(D)` at IDA's step must stay
/// below the examination's thresholds (at least [`INDEX1_CHECK_CONDITION`]): IDA's dependent
/// unknowns satisfy the joints' rows to its Newton tolerance, which moves `μ` by a relative
/// amount of that order, far below 1 %.
pub const MOOT_MARGIN: f64 = 1.01;

/// Joint rows up to which the step watch factors `G_v[:, D]` at every internal step (an LU of
/// at most 16 × 16: a few hundred flops, against the residuals and Newton solves of a step);
/// above, every `⌈nc / 16⌉²`-th step, so that the watch costs `O(nc)` per step on average.
pub const GRIP_EVERY_STEP_ROWS: usize = 16;

/// How many built formulations a run keeps (`Index1::built`).
pub const BUILT_KEPT: usize = 8;

/// Fraction of the run after which the energy's drift is read as a trend
/// ([`ENERGY_DRIFT_TRIGGER`]).
pub const ENERGY_TREND_FRACTION: f64 = 0.1;

/// Factor on `rtol × E_scale + atol × |∇E|₁` by which the energy, its drift so far projected
/// linearly to the end of the run, of a conservative mechanism may drift before
/// the default DAE keeps it as an invariant ([`crate::solve::formulation::EnergyInvariant`]), `E_scale` the
/// larger of `|E₀|` and the largest kinetic energy met, plus atol × the largest `Σ |∂E/∂x_i|`
/// (what the tolerances promise of the energy). BDF damps an undamped oscillation a
/// little at every step (a one-signed energy error of about rtol per unit time); over a few
/// periods it stays within the tolerance's promise and the invariant would only cost steps
/// (measured: 1.4–1.8× on the bundled 5 s scenes), over hundreds of periods it becomes a phase
/// error (IFToMM A01: 1.35e-2 m after 2000 s at rtol 1e-9 without the invariant).
pub const ENERGY_DRIFT_TRIGGER: f64 = 300.0;

/// How many times over a run the energy watch reads the energy at IDA's steps (the first IDA
/// step at or after each of `t₀ + k (t_end − t₀) / ENERGY_READS`). Read at the outputs
/// instead, the IFToMM A01 pendulum (2000 s, rtol 1e-9) asked for at 8 output times switched
/// the invariant on at t = 1000 and ended 2.1e-3 m off, where one output every 10 s switched it
/// on at t = 200 and ended 9.7e-5 m off: the outputs decided the method. Each read completes
/// the row to rounding (the energy read off IDA's step as it is misled the watch:
/// `energy_check`) and evaluates the energy's tape, so with 1000 reads a short run read at most
/// of its steps (a five-bar over 1 s: 745 of 990 steps, 20 M instructions, a sixth of its
/// integration). The trend the trigger projects needs far fewer; once it has fired at a step
/// where the mechanism barely moves, the watch reads at every step until it moves (else the
/// switch waits a whole spacing: A01 over 2000 s at t = 240 instead of 200). A01 over 2000 s at
/// rtol 1e-9: 1000 reads switched at t = 202.0008 and ended 1.15e-4 m off; 100 reads switch at
/// 200.31 and end 1.24e-4 m off, whatever the output grid.
pub const ENERGY_READS: f64 = 100.0;

// ---- The GGL runner: singular passages (the compliant switch) and its error test ----

/// `κ(G_v M⁺ G_vᵀ)` above which a failed plain-GGL step is taken as a singular passage. Measured
/// on the four-bar chains (N = 1, 3, 10) at the last accepted step before the failure:
/// κ ≈ 4e7 … 3e9 (further from the alignment at tighter tolerances); upright they have κ ≈ 10.
pub const SINGULAR_CONDITION: f64 = 1e4;

/// Where a singular passage was met, plain GGL would resume at the first output where κ has
/// fallen below this, if [`RESUME_PLAIN_GGL`] were set.
pub const REGULAR_CONDITION: f64 = 1e5;

/// Whether plain GGL resumes after a singular passage once the joints are well-conditioned.
/// Measured on the four-bar chains over 20 s (test profile), compliant to the end against
/// resuming (which then detects and reports every alignment, 19–21 passages):
/// N = 1, rtol 5e-9: 14 741 steps / 0.24 s against 15 723 / 0.30 s; N = 3, rtol 1e-9:
/// 27 507 / 1.59 s against 31 093 / 2.06 s (each switch restarts IDA at order 1 with small
/// steps), with errors of the same size; so resuming is not cheaper and stays off.
pub const RESUME_PLAIN_GGL: bool = false;

/// `κ(G_v[:, D])` above which the GGL keeps every velocity in its error test: the dependent
/// velocities are then ill-determined by the joints (near a singular configuration), and
/// leaving them out lets the step grow past what the independent ones can tell.
pub const GGL_ERROR_TEST_SINGULAR: f64 = 1e3;

/// `κ(G_v M⁺ G_vᵀ)` at an output time above which a local maximum of κ, met while the
/// compliant GGL runs, is recorded as a singular passage. Measured on the four-bar chains
/// (output step 0.05 s): upright κ ≈ 10, at the output nearest an alignment κ ≳ 1e3.
pub const PASSAGE_CONDITION: f64 = 300.0;

/// Singular passages handled per solve before a failure is reported as such (a guard against
/// restarting forever at a configuration the compliant GGL cannot pass either).
pub const MAX_SINGULAR_PASSAGES: usize = 10_000;

// ---- The partitioned runner: re-partition, singular partitions, stiffness, the causality kept ----

/// Condition estimate of the dependent block `G_v[:, D]` (largest over smallest pivot of its
/// LU) above which the right-hand side asks for a new partition (or [`REPARTITION_GROWTH`] times the
/// estimate at the start of the segment, if larger).
pub const REPARTITION_CONDITION: f64 = 20.0;

/// Growth of the re-choice threshold over the segment's starting estimate (and over the
/// last threshold when a re-choice kept the partition).
pub const REPARTITION_GROWTH: f64 = 3.0;

/// Condition number of the best partition's dependent blocks above which no partition is
/// taken as well conditioned: the compliant GGL carries the mechanism through. Relative to a
/// mechanism whose best partition starts at [`TYPICAL_CONDITION`]; the thresholds scale with
/// the starting condition where it is larger (units: the Andrews squeezer, in metres and
/// radians over millimetre levers, starts at 7e2 and is regular).
pub const SINGULAR_PARTITION: f64 = 60.0;

/// The compliant GGL hands the mechanism back at the first output where the best partition's
/// condition number is below this (scaled like [`SINGULAR_PARTITION`]).
pub const REGULAR_PARTITION: f64 = 30.0;

/// The starting condition number below which [`SINGULAR_PARTITION`] and
/// [`REGULAR_PARTITION`] apply as they are (measured: planar pendulums, four-bars and
/// slider-cranks start between 1 and 5).
pub const TYPICAL_CONDITION: f64 = 5.0;

/// `Integrator::Auto` takes BDF when `ρ̂ · Δt_out` exceeds this, where `ρ̂` is the infinity
/// norm of the reduced ODE's Jacobian at the start (an upper bound of its spectral radius, by
/// difference quotients) and `Δt_out` the mean output interval: an explicit method would then
/// need more than about this many steps per output interval for stability alone.
pub const STIFFNESS_LIMIT: f64 = 500.0;

/// Failed segments from the same output after which the compliant GGL takes the passage.
pub const MAX_RETRIES: usize = 2;

/// How much better conditioned the numeric partition must be at the start for the causality's
/// to be set aside there.
pub const CAUSALITY_KEPT_GAIN: f64 = 10.0;

/// Crossings of one switching function between two outputs after which it is released to
/// the literal operation (a sliding mode, e.g. Coulomb friction at rest: each mode pushes the
/// state back across the zero).
pub const MAX_SWITCHINGS_PER_OUTPUT: u32 = 50;

// ---- The partitioned Newton's branch test ----

/// Largest Newton correction after the tangent predictor, as a fraction of the prediction,
/// that a right-hand side accepts (see [`PartitionError::Branch`](crate::partition::PartitionError::Branch)).
pub const BRANCH_FRACTION: f64 = 0.5;

// ---- The joints' conditioning (singular configurations) and its sparse path ----

/// Eigenvalues up to this multiple of the smallest one span the near-null space.
pub const NEAR_NULL_RATIO: f64 = 100.0;

/// Share of an eigenvector's largest entry above which a row counts as involved.
pub const INVOLVED_SHARE: f64 = 0.05;

/// Joint rows from which [`joint_condition_number`](crate::partition::joint_condition_number) takes the sparse path
/// ([`sparse_joint_condition_number`](crate::partition::sparse_joint_condition_number)); below it the dense eigenvalues cost little. Measured
/// on four-bar chains (`cargo bench --bench sparse`, `BONDMECH_SPARSE_BENCH=monitor`): the
/// sparse path breaks even between 32 and 50 rows, is 1.4× cheaper at 62 and 5× at 242.
pub const SPARSE_CONDITION_ROWS: usize = 60;

/// Relative accuracy of `λ_min` and `λ_max` on the sparse path (Lanczos residual bound).
pub const SPARSE_CONDITION_TOL: f64 = 1e-10;

/// Lanczos steps for each extreme eigenvalue on the sparse path before it gives up (and the
/// dense eigenvalues decide).
pub const SPARSE_CONDITION_ITERATIONS: usize = 200;

// ---- The dependent block's grip at scale (sparse path) ----

/// Joint rows from which [`JointRows`](crate::partition::JointRows) reads `G_v` by its non-zeros and measures the dependent
/// block's grip by sparse Cholesky factors and Lanczos iterations (linear in the size of a
/// chain) instead of dense singular values (cubic): the size from which the joints' condition
/// monitor takes its sparse path ([`SPARSE_CONDITION_ROWS`]). Measured
/// on the N-link pendulum (`cargo bench --bench sparse`, `BONDMECH_SPARSE_BENCH=dae`): at
/// N = 64 (128 rows) the dense singular values at the outputs took three quarters of the run.
pub const SPARSE_GRIP_ROWS: usize = SPARSE_CONDITION_ROWS;

/// Relative accuracy of the smallest eigenvalues of `G_v G_vᵀ` and `G_D G_Dᵀ` on the sparse
/// path (the Lanczos residual bound, [`crate::dae::gram::lanczos_largest`] on the inverse): the
/// checks compare `μ(D)` and `κ(G_v)` with thresholds a factor 2 or 10 apart. The small
/// eigenvalues are well separated; a few steps suffice.
pub const SPARSE_GRIP_TOL: f64 = 1e-3;

/// Relative accuracy of `λ_max(G_v G_vᵀ)` on the sparse path (plain Lanczos from below: the
/// Ritz value is a lower bound). The top of a chain's spectrum is clustered, and resolving it
/// costs steps that grow with the chain (measured on the N-link pendulum at N = 256: 102 steps
/// for 1e-3, 10 for 1e-2, where the value found was 0.3 % below the top); `μ(D) ∝ √λ_max` is
/// then within 0.5 %.
pub const SPARSE_GRIP_TOP_TOL: f64 = 1e-2;

/// Lanczos steps for `λ_max(G_v G_vᵀ)` on the sparse path, after which the Ritz value is taken
/// as it is (a lower bound of `λ_max`; its deficit on a clustered top falls with the steps'
/// square): with the chain nearly straight (the joint rows along it decoupled from the
/// rotations) the residual test took steps enough to cost a tenth of the run at N = 32 (perf:
/// `top_eigenvalue` and the tridiagonal bisections 8 %). The re-selection's test
/// `μ(D) > INDEX1_RESELECT_GAIN κ(G_v)` does not depend on it: `λ_max` divides out of the ratio.
pub const SPARSE_GRIP_TOP_STEPS: usize = 16;

/// Lanczos steps for `λ_max(G_v G_vᵀ)` from the previous output's Ritz vector
/// ([`JointRows::with_hints`](crate::partition::JointRows::with_hints)): the Krylov space holds that vector, so the Ritz value is at
/// least its Rayleigh quotient at the new state — as close to the top as the last estimate
/// was where the motion between outputs is smooth — and the steps refine it. On the N-link
/// pendulum the 16 cold steps at every output were 6 % of the run at N = 128.
pub const SPARSE_GRIP_TOP_WARM_STEPS: usize = 4;

/// Lanczos steps per eigenvalue on the sparse path before the dense singular values decide.
pub const SPARSE_GRIP_ITERATIONS: usize = 200;

// ---- The `dae` runner's look at the joints when its block degrades ----

/// Growth of the dependent block's condition over the one the step watch last kept above
/// which the `dae` formulation asks whether the joints approach a singular configuration
/// (`κ(G_v M⁺ G_vᵀ)` against [`DAE_HANDOVER_RISE`]): the block degrades before the joints do.
pub const HANDOVER_LOOK_GROWTH: f64 = 2.0;

// ---- linearize ----

/// The dependent block's condition at and above which `linearize` refuses the operating point
/// as singular (the value it has always used): the state matrix applies `G_D⁻¹`, which at a
/// condition of 1e10 amplifies the rounding of the Jacobians' entries (1e-16 relative) to 1e-6,
/// rounding noise in the linear model's sixth digit.
pub const LINEARIZE_SINGULAR_CONDITION: f64 = 1e10;

/// What a check of the partition decides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decision {
    /// Go on with the partition in use.
    Keep,
    /// Choose the dependent unknowns again (a fresh selection is much better conditioned).
    Rechoose,
    /// Hand the rest of the run to the GGL (no regular partition is near).
    HandOver,
    /// The configuration is singular for this partition (no regular block to switch to).
    Singular,
}

/// The one place the runners, `linearize` and the GGL's error-test choice ask whether to keep,
/// re-choose or hand over a partition, and whether the joints are singular. Each method is the
/// comparison the runner made itself, with the threshold above (`μ` a dependent block's
/// condition [`crate::partition::dependent_condition`], `κ` the joints'
/// [`crate::partition::joint_condition_number`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct PartitionPolicy;

impl PartitionPolicy {
    /// Whether the block in use (condition `cond`) is worth a look at an output: `μ >`
    /// [`INDEX1_CHECK_CONDITION`] and `μ >` [`GRIP_RECHECK`] × the condition last kept.
    pub fn worth_checking(cond: f64, kept: f64) -> bool {
        cond > INDEX1_CHECK_CONDITION && cond > GRIP_RECHECK * kept
    }

    /// The condition above which the block in use is looked at again:
    /// `max(`[`INDEX1_CHECK_CONDITION`]`, `[`GRIP_RECHECK`]` × kept)`.
    pub fn check_threshold(kept: f64) -> f64 {
        INDEX1_CHECK_CONDITION.max(GRIP_RECHECK * kept)
    }

    /// The causality's block (condition `best` of a fresh choice, `cond` its own) is kept
    /// against a fresh choice: `best ×` [`INDEX1_RESELECT_GAIN`] `≥ cond`.
    pub fn keeps_against(best: f64, cond: f64) -> bool {
        best * INDEX1_RESELECT_GAIN >= cond
    }

    /// The redundant rows in use (grip `grip`) hold against a fresh choice of grip `fresh`:
    /// [`REDUNDANT_ROWS_GAIN`] `× grip ≥ fresh`.
    pub fn rows_hold(grip: f64, fresh: f64) -> bool {
        REDUNDANT_ROWS_GAIN * grip >= fresh
    }

    /// The partitioned formulation keeps the causality's partition (condition `k`) at the
    /// start: `k ≤` [`REPARTITION_CONDITION`], or no fresh choice (condition `best()`) with
    /// `best ×` [`CAUSALITY_KEPT_GAIN`] `< k`.
    pub fn causality_kept(k: f64, best: impl FnOnce() -> Option<f64>) -> bool {
        k <= REPARTITION_CONDITION || best().is_none_or(|b| b * CAUSALITY_KEPT_GAIN >= k)
    }

    /// Whether a block of condition `cond` is good enough to keep without looking further:
    /// `μ ≤` [`INDEX1_CHECK_CONDITION`].
    pub fn well_conditioned(cond: f64) -> bool {
        cond <= INDEX1_CHECK_CONDITION
    }

    /// Re-choose at an output: a fresh block of condition `best` with `best ×`
    /// [`INDEX1_RESELECT_GAIN`] `< cond`.
    pub fn should_reselect(best: f64, cond: f64) -> bool {
        best * INDEX1_RESELECT_GAIN < cond
    }

    /// Re-choose between outputs (at IDA's steps): `best ×` [`STEP_RESELECT_GAIN`] `< cond`.
    pub fn should_reselect_at_step(best: f64, cond: f64) -> bool {
        best * STEP_RESELECT_GAIN < cond
    }

    /// The redundant rows in use (grip `grip`) give way to a fresh choice of grip `fresh`:
    /// `fresh >` [`REDUNDANT_ROWS_GAIN`] `× grip`.
    pub fn fresher_rows(grip: f64, fresh: f64) -> bool {
        fresh > REDUNDANT_ROWS_GAIN * grip
    }

    /// Whether the best block (condition `best`) is beyond the hand-over: `best >`
    /// [`DAE_HANDOVER_CONDITION`].
    pub fn beyond_hand_over(best: f64) -> bool {
        best > DAE_HANDOVER_CONDITION
    }

    /// The `dae` formulation's hand-over at an output: the joints' `κ` has risen more than
    /// [`DAE_HANDOVER_RISE`] times over its start value `kappa0` (where `rise_counts`: no
    /// redundant joints), or the best block is beyond the hand-over.
    pub fn hand_over(rise_counts: bool, kappa: f64, kappa0: f64, best: f64) -> Decision {
        let rise = rise_counts && kappa > DAE_HANDOVER_RISE * kappa0;
        if rise || Self::beyond_hand_over(best) {
            Decision::HandOver
        } else {
            Decision::Keep
        }
    }

    /// The decision at one of IDA's steps: re-choose where a different block (`changed`) is
    /// [`STEP_RESELECT_GAIN`] times better, hand over (where the formulation `hands_over`)
    /// where even the best block, `min(best, cond)`, is beyond the hand-over.
    pub fn at_step(changed: bool, best: f64, cond: f64, hands_over: bool) -> Decision {
        if changed && Self::should_reselect_at_step(best, cond) {
            Decision::Rechoose
        } else if hands_over && Self::beyond_hand_over(best.min(cond)) {
            Decision::HandOver
        } else {
            Decision::Keep
        }
    }

    /// The GGL's dependent velocities left out of its error test (block of condition `cond`;
    /// `other` the condition of a fresh, different block, asked only where `cond` is above
    /// [`INDEX1_CHECK_CONDITION`]): re-chosen where the fresh block is [`INDEX1_RESELECT_GAIN`]
    /// times better and below [`GGL_ERROR_TEST_SINGULAR`], none where `cond` is above it.
    pub fn error_test_block(cond: f64, other: impl FnOnce() -> Option<f64>) -> Decision {
        if Self::well_conditioned(cond) {
            return Decision::Keep;
        }
        match other() {
            Some(cb) if Self::should_reselect(cb, cond) && cb < GGL_ERROR_TEST_SINGULAR => {
                Decision::Rechoose
            }
            _ if cond > GGL_ERROR_TEST_SINGULAR => Decision::Singular,
            _ => Decision::Keep,
        }
    }

    /// A block the GGL's error test may leave out: `μ <` [`GGL_ERROR_TEST_SINGULAR`].
    pub fn error_test_regular(cond: f64) -> bool {
        cond < GGL_ERROR_TEST_SINGULAR
    }

    /// The GGL's singular passage begins: `κ >` [`SINGULAR_CONDITION`].
    pub fn is_singular(kappa: f64) -> bool {
        kappa > SINGULAR_CONDITION
    }

    /// A stall is named a singular configuration: `κ ≥` [`SINGULAR_CONDITION`].
    pub fn names_singular(kappa: f64) -> bool {
        kappa >= SINGULAR_CONDITION
    }

    /// The GGL's singular passage is over: `κ <` [`REGULAR_CONDITION`].
    pub fn is_regular(kappa: f64) -> bool {
        kappa < REGULAR_CONDITION
    }

    /// A partitioned block of condition `k` is usable (relative to the mechanism's `scale`):
    /// `k ≤` [`SINGULAR_PARTITION`] `× scale`.
    pub fn partition_usable(k: f64, scale: f64) -> bool {
        k <= SINGULAR_PARTITION * scale
    }

    /// A partitioned block of condition `k` is regular again: `k <` [`REGULAR_PARTITION`]
    /// `× scale`.
    pub fn partition_regular(k: f64, scale: f64) -> bool {
        k < REGULAR_PARTITION * scale
    }

    /// `linearize` accepts an operating point whose dependent block has condition `cond`:
    /// not NaN and below [`LINEARIZE_SINGULAR_CONDITION`].
    pub fn linearizable(cond: f64) -> bool {
        !(cond.is_nan() || cond >= LINEARIZE_SINGULAR_CONDITION)
    }
}

/// The largest dependent block (rows) whose amplification is computed at every step: a dense
/// LU of `r × r` per step is below a tenth of a step's cost up to here (the N-link chains beyond
/// keep IDA's plain weights; their blocks are triangular and amplify by at most the links'
/// length ratios).
pub const AMPLIFIED_ROWS: usize = 48;

/// The output rows' completion (Newton on `g(q_I, q_D) = 0` for the dependent coordinates) stops
/// once every joint row is within this fraction of the largest coordinate: rounding, a few ulps of
/// the configuration's scale.
pub const COMPLETION_TOLERANCE: f64 = 1e-15;

/// Speeds and accelerations (in the scene's units) below which a mechanism counts as at rest at
/// the start, where the energy invariant's multiplier has no grip (`dE/dμ` vanishes at rest).
pub const AT_REST: f64 = 1e-12;

// ---- The causality's numeric rank (`bond/rank.rs`): which inertias the junction structure makes dependent ----

/// Entries below `CAUSALITY_RANK_TOLERANCE × (largest entry of the matrix)` count as zero in
/// the causality's elimination of the flow constraints on the inertia flows (`bond/rank.rs`):
/// it decides which inertias get differential causality at a configuration (what `graph
/// --causality` draws, the partition every solver starts from). The constraint rows' entries
/// are ±1 and the transformers' moduli (lever arms of order one): a modulus that vanishes at a
/// dead centre falls below 1e-9 only within ~1e-9 rad of it, where any partition but one
/// through the vanishing column is as good; rounding in the eliminated rows stays near 1e-15.
pub const CAUSALITY_RANK_TOLERANCE: f64 = 1e-9;

// ---- The initial projection and the block LU (`dae/`): rank tests that decide which rows and pivots are kept ----

/// Relative threshold below which a singular value counts as zero in the initial projection's
/// rank tests (`dae/init.rs`): `σ ≤ RANK_TOL · σ_max`. Double precision tells apart about
/// 1e-16 relative; a joint Jacobian assembled from lengths and angles of order one carries
/// rounding of some 1e-14 in its smallest singular values at a regular configuration, so 1e-9
/// leaves five orders of margin below a regular rank while a redundant joint's row (exactly
/// dependent, rounded) falls well under it.
pub const RANK_TOL: f64 = 1e-9;

/// Size `nv + nc` from which the initial projection's velocity and acceleration steps use
/// sparse Cholesky factorisations instead of dense SVDs (below it the SVDs cost little and
/// keep every small scene's start bit for bit as it was).
pub const SPARSE_START_UNKNOWNS: usize = 200;

/// Largest `κ(G_v G_vᵀ)` (estimated) for which the initial projection's sparse path trusts
/// `G_v` to have full row rank; beyond it the SVD decides the rank (redundant joints). The
/// Cholesky of `G_v G_vᵀ` loses `log10 κ` digits: at 1e12 four remain, enough for a start
/// projected again by IDA's own consistent initialisation.
pub const SPARSE_START_CONDITION: f64 = 1e12;

/// Largest growth of the block LU's pivot ratio (`dae/block_lu.rs`) over the planned one
/// before the pivot order is re-chosen at the current values: a factor two leaves the planned
/// order within one bit of the best one's stability, and re-planning costs a symbolic pass.
pub const REPLAN_GROWTH: f64 = 2.0;

/// Lanczos steps on `A` for the first, rough `λ_max` of the sparse Gram matrix's extreme
/// eigenvalues (`dae/gram.rs`; its Ritz value is a lower bound; the shift that follows need only
/// exceed `λ_max`).
pub const ROUGH_STEPS: usize = 20;
