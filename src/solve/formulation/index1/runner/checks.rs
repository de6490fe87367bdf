//! The index-1 runner's checks of its partition: the examination of a row at an output or
//! at one of IDA's steps (the dependent block's grip, the redundant rows, the dependent
//! coordinates), the step watch, the energy invariant's trigger, the re-choice and the
//! hand-over — each decision asked of [`crate::partition::PartitionPolicy`].

use super::*;
use crate::partition::thresholds::HANDOVER_LOOK_GROWTH;
use crate::solve::formulation::shared::joints_in_words;

impl<'a> Index1<'a> {
    /// Restarts the run at `t` (state `x = [q, v]`) with a fresh choice, and says so in the
    /// routine re-selection warning (`what`: what was chosen again, and why).
    pub(super) fn reselect_at(
        &mut self,
        t: f64,
        x: &[f64],
        what: &str,
        summary: &mut Summary,
    ) -> Result<Option<Next<'a>>, SolveError> {
        self.restart_from(t, x)?;
        let kind = reselection_warning(&summary.formulation);
        summary.routine_warning(&kind, format!("{kind} at t = {t:.6} — {what}"));
        Ok(Some(Next::Restart(t)))
    }

    /// `[q, v]` of IDA's state `y` at `t`, the dependent coordinates and velocities completed
    /// (at scale with the running partition's symbolic block LUs, and the numeric LU of
    /// `G_v[:, D]` left for the examination of the same row: a fresh symbolic analysis of each
    /// block at every examined step was 7 % of the 128-link pendulum's run).
    pub(super) fn completed(&mut self, t: f64, y: &[f64]) -> Vec<f64> {
        let (nq, nv, _) = self.tapes.dims;
        let mut x = y[..nq + nv].to_vec();
        complete_dependent(
            &self.tapes,
            (&self.dependent, &self.coordinates, &self.rows),
            t,
            &mut x,
            &mut self.block_lus,
        );
        x
    }

    /// The examination of the partition at the IDA step `(t, x)`, `x = [q, v]` completed, that
    /// the watch asked for ([`Formulation::watch_step`]): `scheduled`, the configuration has
    /// moved [`EXAMINE_MOTION`] since the last examination — the redundant rows, the approach
    /// of a singular configuration (hand-over), the dependent velocities' and coordinates'
    /// blocks, each re-chosen where a fresh choice is [`INDEX1_RESELECT_GAIN`] times better;
    /// `alert`, the step watch's grip estimate rose ([`Self::rechoose_at_step`]).
    pub(super) fn examine_step(
        &mut self,
        t: f64,
        x: &[f64],
        (scheduled, alert): (bool, bool),
        summary: &mut Summary,
    ) -> Result<Option<Next<'a>>, SolveError> {
        if scheduled {
            self.examined_q.clear();
            self.examined_q.extend_from_slice(&x[..self.nq()]);
            if let Some(next) = self.examine(t, x, summary)? {
                return Ok(Some(next));
            }
        }
        if alert {
            if let Some(next) = self.rechoose_at_step(t, x, "the block's grip degraded", summary)? {
                return Ok(Some(next));
            }
            // the block holds (no better one yet): look again when it has degraded further
            self.grip.alert *= GRIP_RECHECK;
        }
        Ok(None)
    }

    /// The step watch's grip estimate at `(t, y)` ([`BlockGrip`]), on its schedule: whether it
    /// rose above the alert.
    pub(super) fn grip_alert(&mut self, t: f64, y: &[f64]) -> bool {
        if self.grip.constant {
            return false;
        }
        self.grip.since += 1;
        if self.grip.since < self.grip.next {
            return false;
        }
        self.grip.since = 0;
        let rho = self
            .grip
            .estimate(&self.tapes, (&self.dependent, &self.rows), t, y);
        // far below the alert the block cannot reach it in a few steps of a smooth motion
        let margin = if 2.0 * rho < self.grip.alert {
            4
        } else if 1.25 * rho < self.grip.alert {
            2
        } else {
            1
        };
        self.grip.next = self.grip.every * margin;
        rho > self.grip.alert
    }

    /// The dependent coordinates' block at `(t, x)` where they are chosen apart from the
    /// velocities (`None` otherwise): its grip `μ(D_q)`, and whether a fresh choice is
    /// [`INDEX1_RESELECT_GAIN`] times better gripped (looked for only where `search(μ)`).
    pub(super) fn coordinates_grip(
        &self,
        t: f64,
        x: &[f64],
        search: impl Fn(f64) -> bool,
    ) -> Option<(f64, bool)> {
        if self.coordinates == self.dependent {
            return None;
        }
        let mut gq = if self.rows.len() == self.tapes.dims.2 {
            JointRows::new(&self.tapes.gq, t, x)
        } else {
            JointRows::from_dense(rows_of(&self.tapes.gq.matrix(t, x), &self.rows))
        };
        let cond_q = gq.dependent_condition(&self.coordinates);
        let better = search(cond_q)
            && select_dependent(
                gq.dense(),
                &crate::partition::preferred_coordinates(&self.sys),
            )
            .is_some_and(|b| PartitionPolicy::should_reselect(gq.dependent_condition(&b), cond_q));
        Some((cond_q, better))
    }

    /// Whether the blocks are read by their non-zeros ([`SPARSE_GRIP_ROWS`] joint rows or more,
    /// every row): an examination at an IDA step then reads the step's row uncompleted.
    pub(super) fn at_scale(&self) -> bool {
        let nc = self.tapes.dims.2;
        nc >= SPARSE_GRIP_ROWS && self.rows.len() == nc
    }

    /// The consistent state a run restarts or hands over from at `(t, x)`: at scale `x`'s
    /// dependent coordinates and velocities completed first (an examination at a step reads
    /// IDA's row as it is), then projected ([`consistent_state_from`]).
    pub(super) fn restart_state(
        &mut self,
        t: f64,
        x: &[f64],
    ) -> Result<ConsistentState, SolveError> {
        if self.at_scale() {
            let xc = self.completed(t, x);
            return Ok(consistent_state_from(&self.sys, &self.tapes, t, &xc)?);
        }
        Ok(consistent_state_from(&self.sys, &self.tapes, t, x)?)
    }

    /// Whether a scheduled examination at IDA's step `(t, y)` can change nothing, so that
    /// neither the completion of the dependent unknowns nor the singular values it takes are
    /// needed. On the dense path without redundant joints, every check of [`Self::examine`]
    /// acts only where the dependent block's grip `μ(D)` exceeds a threshold: the fresh
    /// choice's `max(INDEX1_CHECK_CONDITION, GRIP_RECHECK μ_kept)` (`μ_kept`: the grip last
    /// found with no better block), the hand-over's `2 μ_start` (`μ_start` at least half
    /// [`INDEX1_CHECK_CONDITION`]); and, where the coordinates are chosen apart, the
    /// coordinates' `μ(D_q)` exceeds theirs. [`crate::partition::dependent_condition_bound`] bounds
    /// `μ` from above at a few products' cost; it is taken at IDA's `y` (its dependent unknowns
    /// within the Newton tolerance of the completed ones) with the margin [`MOOT_MARGIN`]. A
    /// smooth mechanism far from any singular configuration is examined every
    /// [`EXAMINE_MOTION`] of motion, up to every other step (the peers' slider-crank, `μ ≈
    /// 10–13`, 361 times in 912 steps at rtol 1e-8; two singular value decompositions and a
    /// completion each took as much as IDA's whole step). Between full bounds, the velocities'
    /// block is bounded from the last one's factors and how far `G_v` has moved since
    /// ([`dependent_condition_bound_factors`]: Weyl's perturbation bound), a tape evaluation
    /// and a norm.
    pub(super) fn examination_moot(&mut self, t: f64, y: &[f64]) -> bool {
        let (nq, nv, nc) = self.tapes.dims;
        if self.redundant.is_some() || nc >= SPARSE_GRIP_ROWS || self.rows.len() != nc {
            return false;
        }
        let x = &y[..nq + nv];
        let bufs = &mut self.moot_buffers;
        if bufs.gv_work.0.is_empty() {
            bufs.gv_work = self.tapes.gv.workspace();
            bufs.gq_work = self.tapes.gq.workspace();
        }
        // the velocities' block: from the factors at the last full bound where G_v has moved
        // little since ([`dependent_condition_bound_factors`]), else a full bound (its factors
        // kept for the next steps)
        let (tapes, dependent, reference) =
            (&self.tapes, &self.dependent, &mut self.moot_reference);
        let mut velocities_below = |threshold: f64| {
            tapes
                .gv
                .matrix_into(t, x, (&mut bufs.vars, &mut bufs.gv_work), &mut bufs.gv);
            let gv = &bufs.gv;
            if let Some((g0, a, b)) = reference.as_ref() {
                let moved = gv
                    .iter()
                    .zip(g0.iter())
                    .map(|(p, q)| (p - q) * (p - q))
                    .sum::<f64>()
                    .sqrt();
                if moved * b < 1.0 && MOOT_MARGIN * (a + moved) / (1.0 / b - moved) <= threshold {
                    return true;
                }
            }
            match dependent_condition_bound_factors(gv, dependent) {
                Some((a, b)) => {
                    let holds = MOOT_MARGIN * a * b <= threshold;
                    *reference = Some((gv.clone(), a, b));
                    holds
                }
                None => false,
            }
        };
        let fresh = PartitionPolicy::check_threshold(self.kept_grip.0);
        let velocities = if self.hands_over {
            fresh.min(2.0 * self.watch.block)
        } else {
            fresh
        };
        let coordinates = PartitionPolicy::check_threshold(self.kept_grip.1);
        if !velocities_below(velocities) {
            return false;
        }
        if self.coordinates == self.dependent {
            return true;
        }
        let bufs = &mut self.moot_buffers;
        self.tapes
            .gq
            .matrix_into(t, x, (&mut bufs.vars, &mut bufs.gq_work), &mut bufs.gq);
        MOOT_MARGIN * dependent_condition_bound(&bufs.gq, &self.coordinates) <= coordinates
    }

    /// A restart at `(t, x)`: the consistent state there, and `x` as the row it starts from.
    pub(super) fn restart_from(&mut self, t: f64, x: &[f64]) -> Result<(), SolveError> {
        self.reselections += 1;
        self.state = self.restart_state(t, x)?;
        let xs = self.state_x();
        self.x.copy_from_slice(&xs);
        self.restarted_at = Some(t);
        Ok(())
    }

    /// The partition's checks at `(t, x)` ([`Self::examine_step`], `scheduled`).
    pub(super) fn examine(
        &mut self,
        t: f64,
        x: &[f64],
        summary: &mut Summary,
    ) -> Result<Option<Next<'a>>, SolveError> {
        let nq = self.nq();
        // G_v at this step, evaluated once for every check below (dense, or by its
        // non-zeros at scale: every measure then linear in the size of a chain)
        // (at scale, with the LU of G_v[:, D] the completion of this row factored, and G_v's
        // non-zeros where the step watch evaluated them for it)
        let lu = self
            .block_lus
            .last
            .take()
            .filter(|(tl, xl, _)| *tl == t && xl[..] == x[..]);
        let step_gv = self.block_lus.last_gv.take().filter(|_| lu.is_some());
        let gv = match step_gv {
            Some(entries) if self.at_scale() => {
                let (_, nv, nc) = self.tapes.dims;
                JointRows::from_entries((nc, nv), entries)
            }
            _ => self.gv_at(t, x),
        };
        let mut gv = gv.with_hints(std::mem::take(&mut self.hints));
        // the block's smallest singular value where its kept factors answered since it was
        // computed (the block is then the same, bit for bit)
        let generation = self.block_lus.v.factored;
        if let (Some(_), Some((g, smallest))) = (&lu, self.block_lus.smallest) {
            if g == generation {
                gv = gv.with_block_smallest(&self.dependent, smallest);
            }
        }
        let cond = gv.dependent_condition_with(&self.dependent, lu.as_ref().map(|l| &*l.2));
        if lu.is_some() {
            self.block_lus.smallest = gv
                .block_smallest(&self.dependent)
                .map(|smallest| (generation, smallest));
        }
        // when no block can be INDEX1_RESELECT_GAIN times better conditioned than the bound
        // allows, no fresh choice (a causality assignment) can replace this one
        let possible = PartitionPolicy::worth_checking(cond, self.kept_grip.0)
            .then(|| !gv.no_block_much_better(cond, INDEX1_RESELECT_GAIN));
        self.hints = gv.hints();
        // the causality's preference at this step (a graph assignment), assigned at most once
        let mut preferred: Option<Vec<bool>> = None;
        // redundant joints: the rows left out must keep holding the rank (the self-stress
        // turns with the mechanism: a parallel third crank's rows trade places as it passes
        // the horizontal)
        if let Some((grip, fresh)) = self.fresher_rows(t, x) {
            let what = format!("independent joint rows (grip {grip:.1e}, fresh {fresh:.1e})");
            return self.reselect_at(t, x, &what, summary);
        }
        if self.hands_over && cond > HANDOVER_LOOK_GROWTH * self.watch.block {
            // the partition degrades: are the joints approaching a singular configuration?
            let kappa = gv.joint_condition_number(&self.sys.mass);
            // best ≤ cond: a fresh choice only matters above the hand-over's threshold
            let best = if PartitionPolicy::beyond_hand_over(cond) {
                let p = preferred.get_or_insert_with(|| self.causal.preferred_at(t, &x[..nq]));
                select_dependent(gv.dense(), p)
                    .map_or(f64::INFINITY, |b| gv.dependent_condition(&b))
                    .min(cond)
            } else {
                cond
            };
            // (with redundant joints κ is that of the independent rows chosen, which varies as
            // the self-stress turns — Bricard's rises 37× in its first second while every
            // block stays regular —: there the blocks alone decide)
            let rise_counts = self.redundant.is_none();
            let decision = PartitionPolicy::hand_over(rise_counts, kappa, self.watch.joints, best);
            if decision == Decision::HandOver {
                let why = format!(
                    "the joints approach a singular configuration: κ(G_v M⁺ G_vᵀ) = {kappa:.1e} ({:.1e} at t = {}), the best dependent block's condition {best:.1e}",
                    self.watch.joints, self.watch.t0
                );
                return Ok(Some(Next::HandOver(self.hand_over_from(t, x, &why)?)));
            }
        }
        if let Some(possible) = possible {
            let better = possible
                .then(|| {
                    let p = preferred.get_or_insert_with(|| self.causal.preferred_at(t, &x[..nq]));
                    select_dependent(gv.dense(), p)
                })
                .flatten();
            if let Some(b) = better {
                if b != self.dependent
                    && PartitionPolicy::should_reselect(gv.dependent_condition(&b), cond)
                {
                    let what = format!("dependent velocities (condition {cond:.1e})");
                    return self.reselect_at(t, x, &what, summary);
                }
            }
            self.kept_grip.0 = cond;
        }
        // the dependent coordinates, where they are chosen apart from the velocities
        if let Some((cond_q, better)) = self.coordinates_grip(t, x, |c| {
            PartitionPolicy::worth_checking(c, self.kept_grip.1)
        }) {
            if better {
                let what = format!("dependent coordinates (condition {cond_q:.1e})");
                return self.reselect_at(t, x, &what, summary);
            }
            if PartitionPolicy::worth_checking(cond_q, self.kept_grip.1) {
                self.kept_grip.1 = cond_q;
            }
        }
        Ok(None)
    }

    /// The energy watch at IDA's step `(t, y)` (read on the watch's own schedule,
    /// [`ENERGY_READS`]): where the energy's drift, projected to the end of the run, exceeds
    /// [`ENERGY_DRIFT_TRIGGER`] × what the tolerances promise, the run gives the energy lost
    /// back (scaling the velocities, at a step where the mechanism moves) and keeps it from
    /// here on as an invariant (restarting at `t`).
    ///
    /// The energy is read off the row completed to rounding. Read off the step as IDA holds it
    /// (its dependent unknowns on the joints to the Newton tolerance only), the spherical
    /// pendulum at rtol 1.4e-9 read a drift of 9.7e-7 J at t = 1.66 that the completed row does
    /// not have, switched the invariant on, and stormed (16 812 error-test failures, 48× the
    /// GGL's error): a fifth of the five-bar's integration in completions is the price.
    pub(super) fn energy_check(
        &mut self,
        t: f64,
        y: &[f64],
        summary: &mut Summary,
    ) -> Result<Option<Next<'a>>, SolveError> {
        let mut x = self.completed(t, y);
        let Some(w) = self.energy_watch.as_mut() else {
            return Ok(None);
        };
        let (e, kinetic) = w.read(t, &x);
        let scale = w.e_start.abs().max(w.kinetic_max);
        // what the tolerances promise: rtol of the energy, atol on each coordinate and velocity
        let promise = self.opts.rtol * scale + self.opts.atol * w.gradient_max;
        let drift = e - w.e_start;
        // the drift is linear in time (BDF's damping): projected to the end of the run, read
        // from a tenth of the run on (the first steps' errors are no trend)
        let (t0, t_end) = (
            w.t_start,
            self.opts.output_times.last().copied().unwrap_or(t),
        );
        let elapsed = t - t0;
        if elapsed
            .partial_cmp(&(ENERGY_TREND_FRACTION * (t_end - t0)))
            .is_none_or(|o| o.is_lt())
            || !e.is_finite()
        {
            return Ok(None);
        }
        let projected = drift.abs() * (t_end - t0) / elapsed;
        if projected
            .partial_cmp(&(ENERGY_DRIFT_TRIGGER * promise))
            .is_none_or(|o| o.is_le())
        {
            return Ok(None);
        }
        // the energy lost so far is given back by scaling the velocities (the joints' rows
        // `G_v v = 0` are linear in v: the scaled state is on them), at a step where the
        // mechanism moves well (a turning point would need a large factor): until then, wait
        let potential = e - kinetic;
        let factor2 = (w.e_start - potential) / kinetic;
        if !(kinetic >= 0.25 * w.kinetic_max && (0.5..2.0).contains(&factor2)) {
            // the next steps read again, so the energy is taken back as soon as the mechanism
            // moves, not a read spacing later ([`ENERGY_READS`])
            w.pending = true;
            return Ok(None);
        }
        let e_start = w.e_start;
        let nq = self.nq();
        let factor = factor2.sqrt();
        for v in &mut x[nq..] {
            *v *= factor;
        }
        self.energy_watch = None;
        self.energy_e0 = Some(e_start);
        summary.energy_invariant = true;
        self.state = consistent_state_from(&self.sys, &self.tapes, t, &x)?;
        summary.warnings.push(format!(
            "{}: the energy is kept as an invariant from t = {t:.6} on (it had drifted {drift:.2e} J since the start, {projected:.2e} J by t = {t_end} at that rate: more than {ENERGY_DRIFT_TRIGGER} × {promise:.2e} J, what the tolerances promise)",
            summary.formulation
        ));
        Ok(Some(Next::Restart(t)))
    }

    /// `[q, v]` of the consistent state a restart starts from.
    pub(super) fn state_x(&self) -> Vec<f64> {
        self.state.q.iter().chain(&self.state.v).copied().collect()
    }

    /// Where the joints are redundant and a fresh set of independent rows holds the rank
    /// [`REDUNDANT_ROWS_GAIN`] times better than the running one at `(t, x)`: the running and
    /// the fresh set's grip ([`redundant_row_grip`]). `None`: keep the rows.
    pub(super) fn fresher_rows(&self, t: f64, x: &[f64]) -> Option<(f64, f64)> {
        let (d, _) = self.redundant.as_ref()?;
        let full = self.tapes.gv.matrix(t, x);
        // (the self-stress once for the three questions)
        let stress = crate::partition::SelfStress::new(&full, *d);
        let grip = stress.as_ref().map_or(0.0, |s| s.grip(&self.rows));
        let stress = stress?;
        let fresh = stress.independent_rows(&[]).filter(|f| *f != self.rows)?;
        let fresh_grip = stress.grip(&fresh);
        PartitionPolicy::fresher_rows(grip, fresh_grip).then_some((grip, fresh_grip))
    }

    /// The re-choice at an IDA step `(t, x)`, `x = [q, v]`: a fresh choice of dependent
    /// velocities (or coordinates) [`INDEX1_RESELECT_GAIN`] times better conditioned than the
    /// running one restarts the run there; where none exists and the best block is not
    /// regular (condition above [`DAE_HANDOVER_CONDITION`]), `dae` hands over to the GGL
    /// there. `None`: keep the block.
    pub(super) fn rechoose_at_step(
        &mut self,
        t: f64,
        x: &[f64],
        why: &str,
        summary: &mut Summary,
    ) -> Result<Option<Next<'a>>, SolveError> {
        let nq = self.nq();
        let mut gv = self.gv_at(t, x);
        let cond = gv.dependent_condition(&self.dependent);
        let best = select_dependent(gv.dense(), &self.causal.preferred_at(t, &x[..nq]));
        let best_cond = best
            .as_ref()
            .map_or(f64::INFINITY, |b| gv.dependent_condition(b));
        let mut restart = |me: &mut Self, what: &str, c: f64| -> Result<Next<'a>, SolveError> {
            me.reselections += 1;
            me.state = me.restart_state(t, x)?;
            let xs = me.state_x();
            me.x.copy_from_slice(&xs);
            me.restarted_at = Some(t);
            let kind = reselection_warning(&summary.formulation);
            summary.routine_warning(
                &kind,
                format!(
                    "{kind} at t = {t:.6} between outputs — dependent {what} ({why}; condition {c:.1e})"
                ),
            );
            Ok(Next::Restart(t))
        };
        // redundant joints: the rows left out may have lost their grip (the self-stress turned)
        if let Some((grip, _)) = self.fresher_rows(t, x) {
            return restart(self, "joint rows", grip).map(Some);
        }
        let changed = best.as_ref().is_some_and(|b| *b != self.dependent);
        let decision = PartitionPolicy::at_step(changed, best_cond, cond, self.hands_over);
        if decision == Decision::Rechoose {
            return restart(self, "velocities", cond).map(Some);
        }
        // the dependent coordinates, where they are chosen apart from the velocities
        if let Some((cond_q, true)) = self.coordinates_grip(t, x, |_| true) {
            return restart(self, "coordinates", cond_q).map(Some);
        }
        let best_cond = best_cond.min(cond);
        if decision == Decision::HandOver {
            let why = format!(
                "no regular set of dependent velocities at t = {t:.6} ({why}): the best dependent block's condition is {best_cond:.1e}"
            );
            return Ok(Some(Next::HandOver(self.hand_over_from(t, x, &why)?)));
        }
        Ok(None)
    }

    /// What degraded where IDA's steps stop at `t` (state `x = [q, v]`, error `e`): the
    /// dependent block, its condition, the joints whose rows lose rank.
    pub(super) fn stall_cause(&self, t: f64, x: &[f64], e: &SolverError) -> String {
        let cond = self.gv_at(t, x).dependent_condition(&self.dependent);
        let c = joint_conditioning(&self.tapes.gv.matrix(t, x), &self.sys.mass, &self.sys.rows);
        let (_, dependent) = self.causal.names(&self.dependent);
        let joints = if PartitionPolicy::names_singular(c.condition) {
            format!(
                "the joints [{}] are near a singular configuration (κ(G_v M⁺ G_vᵀ) = {:.1e}): the dae and ggl formulations pass singular configurations",
                joints_in_words(&c.joints),
                c.condition
            )
        } else {
            // a regular configuration: what failed is IDA's Newton iteration itself (Andrews'
            // squeezer at rtol 1e-11, atol 1e-13 from rest: a kinematic row's residual stays
            // at c_j times the coordinate's rounding, 7e-10, through every iteration)
            format!(
                "the joints are regularly placed there (κ(G_v M⁺ G_vᵀ) = {:.1e}), so IDA's Newton iteration failed at the step size these tolerances need: a looser atol or rtol, or the ggl or partitioned formulation, may pass",
                c.condition
            )
        };
        format!(
            "{}: IDA failed at t = {t:.6} ({e}); the dependent block [{}] has condition {cond:.1e} there and no better block exists; {joints}",
            self.opts.formulation.name(),
            dependent.join(", "),
        )
    }
}
