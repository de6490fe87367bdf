//! The SUNDIALS integrators set up once: IDA for every implicit formulation
//! ([`DaeFormulation`]: the residual and the exact Jacobian `∂F/∂y + c_j ∂F/∂y'` as callbacks)
//! and CVODE BDF for every explicit ODE with its exact Jacobian ([`ExplicitOde`]: the decoupled
//! twin, a raw graph without differential storages), each with a dense or sparse (faer, KLU)
//! linear solver as [`SolveOptions::linear_solver`] resolves for the size, and the options the
//! formulations share.

use std::sync::Arc;

use crate::dae::{ExplicitOde, Workspace};
use crate::solve::formulation::DaeFormulation;
use crate::solve::SolveError;
use crate::solve::SolveOptions;
use crate::sundials::schur::{SchurPartition, SchurSplit};
use crate::sundials::{
    CscPattern, Cvode, CvodeOptions, DenseMatrixMut, Ida, IdaOptions, Multistep, ResidualFn,
    SparseMatrixMut,
};

/// IDA's residual callback `r = F(t, y, y')` over a handle on `f` with a workspace of its own,
/// and a second handle with its workspace for the Jacobian callback.
fn residual_of(f: &Arc<dyn DaeFormulation>) -> (ResidualFn, Arc<dyn DaeFormulation>, Workspace) {
    let (f1, f2) = (f.clone(), f.clone());
    let mut ws1 = f1.workspace();
    let ws2 = f2.workspace();
    let residual: ResidualFn = Box::new(move |t: f64, y: &[f64], yp: &[f64], r: &mut [f64]| {
        f1.residual(&mut ws1, t, y, yp, r);
        Ok(())
    });
    (residual, f2, ws2)
}

/// IDA on formulation `f` from `(t0, y0, y0')`, with per-unknown absolute tolerances `atol`.
pub(crate) fn make_ida(
    f: Arc<dyn DaeFormulation>,
    atol: Vec<f64>,
    t0: f64,
    y0: &[f64],
    yp0: &[f64],
    opts: &SolveOptions,
) -> Result<Ida, SolveError> {
    let mut ida_opts = ida_options(atol, f.id().to_vec(), opts);
    ida_opts.sparse_ordering = opts.sparse_ordering.unwrap_or_else(|| f.sparse_ordering());
    let (residual, f2, mut ws2) = residual_of(&f);
    if let Some(kind) = opts.linear_solver.resolve(f.len()) {
        let structure = f.structure();
        let pattern = CscPattern::new(f.len(), structure.iter().copied())?;
        // each entry's place among the values, found once: the formulation puts its entries
        // in the order of its structure, and an entry put out of that order is searched for
        // (a binary search per entry and Jacobian was half the assembly of the 128-link
        // pendulum's index-1 DAE, 6 400 entries)
        let slots: Vec<(usize, usize, usize)> = structure
            .iter()
            .map(|&(r, c)| (r, c, pattern.position(r, c).unwrap_or(usize::MAX)))
            .collect();
        // the formulations that write their entries at the slots themselves (no call per
        // entry: the index-1 DAE's, a third of its assembly at N = 256)
        let places: Vec<usize> = slots.iter().map(|s| s.2).collect();
        let jacobian = Box::new(
            move |t: f64, cj: f64, y: &[f64], yp: &[f64], jm: &mut SparseMatrixMut<'_>| {
                let into = (&places[..], jm.values_mut());
                if f2.jacobian_into_slots(&mut ws2, (t, cj), (y, yp), into) {
                    return Ok(());
                }
                let mut k = 0;
                f2.jacobian(&mut ws2, t, cj, y, yp, &mut |r, c, v| {
                    match slots.get(k) {
                        Some(&(r0, c0, slot)) if r0 == r && c0 == c && slot != usize::MAX => {
                            jm.add_at(slot, v)
                        }
                        _ => jm.add(r, c, v),
                    }
                    k += 1;
                });
                Ok(())
            },
        );
        return Ok(Ida::new_sparse(
            t0, y0, yp0, residual, jacobian, pattern, kind, &ida_opts,
        )?);
    }
    let jacobian = Box::new(
        move |t: f64, cj: f64, y: &[f64], yp: &[f64], jm: &mut DenseMatrixMut<'_>| {
            jm.fill_zero();
            f2.jacobian(&mut ws2, t, cj, y, yp, &mut |r, c, v| jm.add(r, c, v));
            Ok(())
        },
    );
    Ok(Ida::new(t0, y0, yp0, residual, Some(jacobian), &ida_opts)?)
}

/// IDA on formulation `f` as [`make_ida`], its Newton matrix solved by eliminating the
/// dependent blocks of `split` (block lower triangular in that order) and factoring the Schur
/// complement on its outer set ([`crate::sundials::schur`]). `None` when the Jacobian's structure does not have
/// that shape (the caller then uses [`make_ida`]).
pub(crate) fn make_ida_schur(
    f: Arc<dyn DaeFormulation>,
    split: SchurSplit,
    atol: Vec<f64>,
    t0: f64,
    (y0, yp0): (&[f64], &[f64]),
    opts: &SolveOptions,
) -> Option<Result<Ida, SolveError>> {
    let partition = SchurPartition::from_split(f.len(), &split, f.structure()).ok()?;
    let ida_opts = ida_options(atol, f.id().to_vec(), opts);
    let (residual, f2, mut ws2) = residual_of(&f);
    // the matrix arrives zeroed (IDA and the trampoline clear it)
    let jacobian = Box::new(
        move |t: f64, cj: f64, y: &[f64], yp: &[f64], jm: &mut DenseMatrixMut<'_>| {
            f2.jacobian(&mut ws2, t, cj, y, yp, &mut |r, c, v| jm.add(r, c, v));
            Ok(())
        },
    );
    Some(
        Ida::new_schur(t0, y0, yp0, residual, jacobian, partition, &ida_opts)
            .map_err(SolveError::from),
    )
}

/// IDA's default `IDASetDeltaCjLSetup` for bondmech's formulations: a fresh Jacobian and
/// factorisation whenever `c_j = α/h` changes (IDA keeps `h` fixed over stretches of steps, so
/// this is at step-size and order changes only), instead of SUNDIALS' 0.25.
///
/// With a stale `c_j` the Newton matrix of a DAE is wrong in more than the `c_j ∂F/∂y'` part
/// IDA's correction scaling `2/(1 + c_j/c_j,old)` compensates: the constraint rows (GGL) and
/// the acceleration-level rows (index 1) are not proportional to `c_j`. The modified Newton
/// iteration then converges slowly, and IDA's convergence test, which reuses the rate of the
/// previous step, accepts iterates with a left-over error of the order of the error test's
/// bound, in the same direction step after step. Measured on the heavy top (scenes/heavy_top.json,
/// rtol 1e-10, 5 s): GGL 3.9e-7 → 7.8e-8 attitude error, 303 → 0 Newton convergence failures,
/// 34 008 → 26 980 steps; index 1 1.2e-6 → 1.1e-7, 1726 → 3 failures; on the A01 pendulum
/// (rtol 1e-9, 2000 s) GGL 2.6e-2 → 3.7e-3 m (with [`crate::sundials`]' masked norm),
/// 13 839 → 0 failures. Not dearer on the peers' problems (`dae`, rtol 1e-6 … 1e-10, test
/// profile): 1.6–1.9× the Jacobians, a third fewer residuals, no convergence failures (40–101
/// before), 7–15 % less CPU at each rtol.
pub(crate) const IDA_DELTA_CJ: f64 = 0.0;

/// IDA options shared by the formulations: the algebraic unknowns (id 0) are suppressed from
/// the error test, and the first step is bounded.
fn ida_options(atol: Vec<f64>, id: Vec<f64>, opts: &SolveOptions) -> IdaOptions {
    IdaOptions {
        rtol: opts.rtol,
        atol,
        max_steps: Some(u64::MAX),
        max_total_steps: opts.max_steps,
        max_wall_clock: opts.max_wall_clock,
        id: Some(id),
        suppress_alg: true,
        stop_time: opts.output_times.last().copied(),
        // IDA's own first-step guess divides by ‖y'₀‖ weighted with atol; with tight atol and
        // states starting at zero it falls to ~1e-15 s, where the index-2 Newton matrix (which
        // scales like 1/h²) is numerically singular and the first step fails (measured:
        // slider-crank at rtol 1e-11). A modest first step is cut by the error test if too big.
        init_step: Some(match opts.output_times.get(1) {
            Some(t1) => 1e-4f64.min(0.1 * (t1 - opts.output_times[0]).abs()),
            None => 1e-4,
        }),
        delta_cj_lsetup: Some(opts.ida_delta_cj.unwrap_or(IDA_DELTA_CJ)),
        ..IdaOptions::default()
    }
}

/// CVODE BDF (Newton, exact Jacobian) on `y' = f(t, y)` from `(t0, y0)`.
pub(crate) fn make_cvode(
    ode: Arc<ExplicitOde>,
    t0: f64,
    y0: &[f64],
    cv_opts: &CvodeOptions,
    opts: &SolveOptions,
) -> Result<Cvode, SolveError> {
    let (o1, o2) = (ode.clone(), ode.clone());
    let mut ws1 = o1.workspace();
    let mut ws2 = o2.workspace();
    let rhs = Box::new(move |t: f64, y: &[f64], yd: &mut [f64]| {
        o1.rhs(&mut ws1, t, y, yd);
        Ok(())
    });
    if let Some(kind) = opts.linear_solver.resolve(ode.n) {
        let pattern = CscPattern::new(ode.n, ode.structure())?;
        let jac = Box::new(
            move |t: f64, y: &[f64], _fy: &[f64], jm: &mut SparseMatrixMut<'_>| {
                o2.jacobian(&mut ws2, t, y, |r, c, v| jm.add(r, c, v));
                Ok(())
            },
        );
        return Ok(Cvode::new_sparse(
            Multistep::Bdf,
            t0,
            y0,
            rhs,
            jac,
            pattern,
            kind,
            cv_opts,
        )?);
    }
    let jac = Box::new(
        move |t: f64, y: &[f64], _fy: &[f64], jm: &mut DenseMatrixMut<'_>| {
            jm.fill_zero();
            o2.jacobian(&mut ws2, t, y, |r, c, v| jm.add(r, c, v));
            Ok(())
        },
    );
    Ok(Cvode::new(Multistep::Bdf, t0, y0, rhs, Some(jac), cv_opts)?)
}
