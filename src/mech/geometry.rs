//! A mechanism's geometry: the bodies' states (module `layout`), the joints' closures (module
//! `joints`, one file per joint kind), the names expressions may use and the load terms,
//! the slot layout `[t, q, v]` — everything the bond graph's moduli, closures and outputs
//! are written from. The dynamics (`M`, `Q`, the joints' flow rows) are not here: they are
//! read off the bond graph ([`crate::mech::annotate`]).

use std::collections::HashMap;

use super::body::BodyKinematics;
use super::columns::Columns;
use super::coordinates::Geometry;
use super::error::MechError;
use super::joints::{joint_type, DrivenCoordinate, DriverSite, Ends, RowWriter};
use super::layout::Plan;
use super::reactions::JointReaction;
use super::system::{ConstraintRow, DriverOutput, EquationSource, LoadTerm, MultibodySystem};
use crate::expr::Expr;
use crate::scene::{LoadValue, Scene};

/// Initial joint violations above this norm are reported as warnings.
pub const INITIAL_VIOLATION_WARNING: f64 = 1e-9;

/// Size of a scene's bodies (m): the largest distance of a body point from its centre of mass,
/// or the scene's [`length_scale`](crate::scene::validate::length_scale) when no body has points
/// away from its centre; 0 when neither exists.
fn body_size(scene: &Scene) -> f64 {
    let arm = scene
        .bodies
        .iter()
        .flat_map(|b| &b.points)
        .map(|(_, c)| c.iter().map(|x| x * x).sum::<f64>().sqrt())
        .filter(|a| a.is_finite())
        .fold(0.0, f64::max);
    if arm > 0.0 {
        arm
    } else {
        crate::scene::validate::length_scale(scene).unwrap_or(0.0)
    }
}

/// The geometry of `scene` as a [`MultibodySystem`]: coordinates, velocities, the bodies'
/// inertias, `K(q) v`, the joints' closures and reactions, the names; its forces, energy,
/// outputs and events are left empty (zero). [`crate::mech::build`] completes it from the
/// bond graph; a test can check the graph's equations against a separate assembly on it.
pub fn geometry(scene: &Scene) -> Result<MultibodySystem, MechError> {
    Geometry::new(scene).system().map(|(sys, _)| sys)
}

/// The system of a scene's geometry, its forces still zero, and the names expressions may use.
pub(super) type GeometrySystem = (MultibodySystem, HashMap<String, Expr>);

impl Geometry<'_> {
    /// The geometry of the scene as a [`MultibodySystem`] whose inertias, forces, energy,
    /// outputs and events are still to be filled in (from the bond graph, then
    /// [`Columns`]), with the names expressions may use.
    pub(super) fn system(mut self) -> Result<GeometrySystem, MechError> {
        let plans: Vec<Plan> = self.plan()?;
        self.allocate(&plans)?;
        let nv = self.vels.len();
        let kinematics = self.kinematics();
        let names = Columns {
            g: &mut self.g,
            scene: self.scene,
            kin: &self.kin,
            nq: self.coords.len(),
            nv,
        }
        .name_table()?;
        self.load_terms(&names)?;
        let (mut constraints, mut rows, reactions) = self.joints()?;
        let drivers = self.drivers(&mut constraints, &mut rows)?;
        self.connectivity();
        let zero = self.g.zero();
        let mut sys = MultibodySystem {
            graph: self.g,
            coords: self.coords,
            velocities: self.vels,
            given_velocities: Vec::new(),
            mass: self.mass,
            mass_symbols: Vec::new(),
            kinematics,
            forces: vec![zero; nv],
            constraints,
            rows,
            energy: zero,
            kinetic: zero,
            outputs: Vec::new(),
            warnings: self.warnings,
            load_terms: self.load_terms,
            body_size: body_size(self.scene),
            reaction_outputs: self.scene.outputs.iter().any(|o| o == "reactions"),
            reactions,
            events: Vec::new(),
            drivers,
            energy_exchange: energy_exchange(self.scene),
            bodies: self
                .scene
                .bodies
                .iter()
                .map(|b| b.name.clone())
                .zip(self.kin.iter().cloned())
                .collect(),
            names: {
                let mut v: Vec<(String, Expr)> =
                    names.iter().map(|(n, e)| (n.clone(), *e)).collect();
                v.sort_by(|a, b| a.0.cmp(&b.0));
                v
            },
            flow_rows: Vec::new(),
            source: EquationSource::Assembled("geometry only".into()),
            inertias: Vec::new(),
            bond_graph: None,
        };
        let joint_names: Vec<String> = self.scene.joints.iter().map(|j| j.name.clone()).collect();
        for v in sys.initial_violation_at(self.scene.solve.t_start, &joint_names) {
            if let Some(d) = sys.drivers.iter().find(|d| d.name == v.joint) {
                if v.norm > INITIAL_VIOLATION_WARNING {
                    sys.warnings.push(format!(
                        "drivers[{}] '{}': the initial configuration is {:.3e} away from the prescribed {} at t = {}; the solver projects it onto the driver before starting",
                        d.index,
                        d.name,
                        v.norm,
                        self.scene.drivers[d.index].kind.key(),
                        self.scene.solve.t_start
                    ));
                }
                continue;
            }
            if v.norm > INITIAL_VIOLATION_WARNING {
                sys.warnings.push(format!(
                    "joints[{}] '{}': the initial configuration violates the joint by {:.3e} ({}); the solver projects it onto the joint before starting",
                    v.index,
                    v.joint,
                    v.norm,
                    v.rows
                        .iter()
                        .map(|(d, r)| format!("{d} {r:.3e}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
        Ok((sys, names))
    }

    /// The loads' value expressions, one term per component (to name a load whose value is
    /// not finite); the loads themselves act through the bond graph's effort sources.
    fn load_terms(&mut self, names: &HashMap<String, Expr>) -> Result<(), MechError> {
        for (li, l) in self.scene.loads.iter().enumerate() {
            let path = format!("loads[{li}]");
            let Some(bi) = self.body_index(&l.body, &format!("{path}.body"))? else {
                continue; // a load on the ground does nothing
            };
            let n = match l.kind {
                crate::scene::LoadKind::Force => self.dim(),
                crate::scene::LoadKind::Torque if self.spatial => 3,
                crate::scene::LoadKind::Torque => {
                    if !matches!(
                        self.kin[bi],
                        BodyKinematics::PlanarInertial { omega: Some(_), .. }
                            | BodyKinematics::PlanarBodyFixed { .. }
                    ) {
                        return Err(MechError::at(
                            &format!("{path}.body"),
                            format!("body '{}' has no modelled rotation", l.body),
                        ));
                    }
                    1
                }
            };
            self.value_exprs(&l.name, &l.value, n, names, &path)?;
        }
        Ok(())
    }

    fn value_exprs(
        &mut self,
        load_name: &str,
        value: &LoadValue,
        n: usize,
        names: &HashMap<String, Expr>,
        path: &str,
    ) -> Result<Vec<Expr>, MechError> {
        match value {
            LoadValue::Const(v) => {
                if v.len() != n {
                    return Err(MechError::at(
                        &format!("{path}.value"),
                        format!("needs {n} components, got {}", v.len()),
                    ));
                }
                Ok(v.iter().map(|&c| self.g.constant(c)).collect())
            }
            LoadValue::Table { t, v } => {
                let mut out = Vec::with_capacity(n);
                for k in 0..n {
                    let col: Vec<f64> = v
                        .iter()
                        .map(|row| row.get(k).copied().unwrap_or(f64::NAN))
                        .collect();
                    if col.iter().any(|x| !x.is_finite()) {
                        return Err(MechError::at(
                            &format!("{path}.value.table.v"),
                            format!("every sample needs {n} finite components"),
                        ));
                    }
                    let tv = self.g.var(0);
                    out.push(self.g.table(t, &col, tv));
                }
                Ok(out)
            }
            LoadValue::Expr(src) => {
                if src.len() != n {
                    return Err(MechError::at(
                        &format!("{path}.value"),
                        format!("needs {n} expressions, got {}", src.len()),
                    ));
                }
                let mut out = Vec::with_capacity(n);
                for (k, s) in src.iter().enumerate() {
                    let p = if n == 1 {
                        format!("{path}.value")
                    } else {
                        format!("{path}.value[{k}]")
                    };
                    let mut resolve = |name: &str| names.get(name).copied();
                    let e = self.g.parse(s, &mut resolve).map_err(|e| {
                        MechError::at(&p, format!("{e} in {}", crate::expr::excerpt(s, e.pos())))
                    })?;
                    self.load_terms.push(LoadTerm {
                        path: p,
                        load: load_name.to_string(),
                        source: s.clone(),
                        expr: e,
                    });
                    out.push(e);
                }
                Ok(out)
            }
        }
    }

    /// Warn about bodies nothing connects to, and about spatial bodies with some (not all)
    /// principal moments 0: no inertia about that axis, so their rotation about it is fixed by
    /// the joints alone (a slender rod's spin) — legal, and singular if nothing fixes it.
    fn connectivity(&mut self) {
        let s = self.scene;
        for (bi, b) in s.bodies.iter().enumerate() {
            if let crate::scene::Inertia::Principal(js) = b.inertia {
                let zero: Vec<&str> = js
                    .iter()
                    .zip(["x", "y", "z"])
                    .filter(|(j, _)| **j == 0.0)
                    .map(|(_, a)| a)
                    .collect();
                if !zero.is_empty() && zero.len() < 3 {
                    self.warnings.push(format!(
                        "bodies[{bi}].inertia: '{}' has no inertia about its {} axis (principal moments {js:?}): a singular inertia, its angular acceleration about that axis is fixed by the joints alone (a slender rod's spin) and undetermined if they leave it free",
                        b.name,
                        zero.join(" and ")
                    ));
                }
            }
        }
        for (bi, b) in s.bodies.iter().enumerate() {
            let used = s.joints.iter().any(|j| j.bodies.contains(&b.name))
                || s.springs.iter().any(|j| j.bodies.contains(&b.name))
                || s.loads.iter().any(|l| l.body == b.name);
            if !used && s.bodies.len() > 1 {
                self.warnings.push(format!(
                    "bodies[{bi}] '{}' is not connected to anything (it only falls or drifts)",
                    b.name
                ));
            }
        }
    }

    /// Every joint's closure rows, their names, and how its reaction is read.
    #[allow(clippy::type_complexity)]
    fn joints(&mut self) -> Result<(Vec<Expr>, Vec<ConstraintRow>, Vec<JointReaction>), MechError> {
        let mut g_rows = Vec::new();
        let mut meta = Vec::new();
        let mut reactions = Vec::new();
        let x0 = self.initial_slots();
        for (ji, j) in self.scene.joints.iter().enumerate() {
            let first_row = g_rows.len();
            let path = format!("joints[{ji}]");
            let ends = Ends {
                pa: self.point(&j.bodies[0], &j.points[0], &format!("{path}.points[0]"))?,
                pb: self.point(&j.bodies[1], &j.points[1], &format!("{path}.points[1]"))?,
                ka: self.kin_of(&j.bodies[0], &path)?,
                kb: self.kin_of(&j.bodies[1], &path)?,
            };
            let joint = joint_type(&j.kind);
            let mut w = RowWriter {
                g: &mut self.g,
                spatial: self.spatial,
                x0: &x0,
            };
            let rows = joint.rows(&mut w, &ends, &path)?;
            for (dir, e) in rows {
                g_rows.push(e);
                meta.push(ConstraintRow {
                    joint: j.name.clone(),
                    direction: dir.to_string(),
                });
            }
            let rows = first_row..g_rows.len();
            reactions.push(self.joint_reaction(&j.name, joint.transmits_moment(), &ends, rows));
        }
        Ok((g_rows, meta, reactions))
    }

    /// Every driver's row `g = s(q) − s(t)` appended to the joints' rows (direction `angle`
    /// or `displacement`, named after the driver), with its columns. The driven coordinate
    /// `s(q)` is the joint kind's ([`super::joints::Joint::driven_coordinate`]: a planar pin's
    /// `α_b − α_a`, a prismatic joint's `(P_b − P_a)·(R_a â)`, a spatial hinge's rotation `φ`
    /// about its axis from the initial relative pose); a turn is written
    /// `g = atan2(sin(φ − s), cos(φ − s))` (smooth through every turn). A rate
    /// driver `ṡ = w` (a constant) prescribes `s(t) = s(q₀) + w (t − t_start)`.
    fn drivers(
        &mut self,
        g_rows: &mut Vec<Expr>,
        meta: &mut Vec<ConstraintRow>,
    ) -> Result<Vec<DriverOutput>, MechError> {
        let mut out = Vec::new();
        let x0 = {
            let mut x = self.initial_slots();
            x[0] = self.scene.solve.t_start;
            x
        };
        for (di, d) in self.scene.drivers.iter().enumerate() {
            let path = format!("drivers[{di}]");
            let (ji, j) = driven_joint(self.scene, di)?;
            let jpath = format!("joints[{ji}]");
            let ends = Ends {
                pa: self.point(&j.bodies[0], &j.points[0], &format!("{jpath}.points[0]"))?,
                pb: self.point(&j.bodies[1], &j.points[1], &format!("{jpath}.points[1]"))?,
                ka: self.kin_of(&j.bodies[0], &jpath)?,
                kb: self.kin_of(&j.bodies[1], &jpath)?,
            };
            let vpath = format!("{path}.{}", d.kind.key());
            // the prescribed value, an expression of t alone
            let tv = self.g.var(0);
            let value = self
                .g
                .parse(&d.value, &mut |n: &str| (n == "t").then_some(tv))
                .map_err(|e| {
                    MechError::at(
                        &vpath,
                        format!(
                            "{e} in {} (a driver's value is an expression of t and the scene's inputs)",
                            crate::expr::excerpt(&d.value, e.pos())
                        ),
                    )
                })?;
            // the driven coordinate s(q), as the joint's kind defines it
            let site = DriverSite {
                ends: &ends,
                path: &path,
                joint_path: &jpath,
                joint: &j.name,
                bodies: [&j.bodies[0], &j.bodies[1]],
            };
            let mut w = RowWriter {
                g: &mut self.g,
                spatial: self.spatial,
                x0: &x0,
            };
            let coordinate = joint_type(&j.kind)
                .driven_coordinate(&mut w, &site)?
                .ok_or_else(|| {
                    MechError::at(
                        &format!("{path}.joint"),
                        format!(
                            "joint '{}' is a {} joint: only revolute and prismatic joints take a driver",
                            j.name,
                            j.kind.type_name()
                        ),
                    )
                })?;
            let g = &mut self.g;
            // s(t): the value, or for a rate the coordinate at the start plus ∫_{t_start}^{t} ṡ
            // (the flow source integrated, in closed form: exact rows and derivatives)
            let s_t = if d.kind.is_rate() {
                let prim = g.antiderivative(value, 0).map_err(|e| {
                    MechError::at(
                        &vpath,
                        format!(
                            "the prescribed {} \"{}\" is integrated to the joint's coordinate, and {e}; give the motion as the {} instead",
                            d.kind.key(),
                            d.value,
                            if d.kind.is_rotation() { "angle" } else { "displacement" }
                        ),
                    )
                })?;
                let s0 = match &coordinate {
                    DrivenCoordinate::Linear(e) => g.eval(*e, &x0),
                    DrivenCoordinate::Turn { .. } => 0.0,
                };
                let t0 = g.constant(self.scene.solve.t_start);
                let at_start = g.substitute(prim, &[(0, t0)]);
                let swept = g.sub(prim, at_start);
                let s0 = g.constant(s0);
                g.add(s0, swept)
            } else {
                value
            };
            let rate = g.diff(s_t, 0);
            let row = match coordinate {
                DrivenCoordinate::Linear(e) => g.sub(e, s_t),
                DrivenCoordinate::Turn { cos, sin } => {
                    let (cs, ss) = (g.cos(s_t), g.sin(s_t));
                    let a = g.mul(sin, cs);
                    let b = g.mul(cos, ss);
                    let y = g.sub(a, b);
                    let a = g.mul(cos, cs);
                    let b = g.mul(sin, ss);
                    let x = g.add(a, b);
                    g.atan2(y, x)
                }
            };
            let direction = if d.kind.is_rotation() {
                "angle"
            } else {
                "displacement"
            };
            out.push(DriverOutput {
                name: d.name.clone(),
                index: di,
                joint: d.joint.clone(),
                row: g_rows.len(),
                effort: d.kind.effort(),
                rate,
            });
            g_rows.push(row);
            meta.push(ConstraintRow {
                joint: d.name.clone(),
                direction: direction.to_string(),
            });
        }
        Ok(out)
    }

    /// How joint `j`'s reaction is read: the carrier body (second, or first when the second
    /// is ground), its velocities, `B = ∂(V_P, ω)/∂v_b` and the lever `P_1 − P_2`.
    fn joint_reaction(
        &mut self,
        name: &str,
        moment: bool,
        ends: &Ends,
        rows: std::ops::Range<usize>,
    ) -> JointReaction {
        let (ka, kb, pa, pb) = (&ends.ka, &ends.kb, &ends.pa, &ends.pb);
        let flip = matches!(kb, BodyKinematics::Ground);
        let (k, p) = if flip { (ka, pa) } else { (kb, pb) };
        let nq = self.coords.len() as u32;
        let g = &mut self.g;
        let (slots, omega): (Vec<u32>, Vec<Expr>) = match k {
            BodyKinematics::Ground => (vec![], vec![]),
            BodyKinematics::PlanarInertial { vx, vy, omega, .. } => match omega {
                Some(w) => (vec![*vx, *vy, *w], vec![g.var(*w)]),
                None => (vec![*vx, *vy], vec![]),
            },
            BodyKinematics::PlanarBodyFixed { u, w, omega, .. } => {
                (vec![*u, *w, *omega], vec![g.var(*omega)])
            }
            BodyKinematics::Particle { v, .. } => (v.to_vec(), vec![]),
            BodyKinematics::Spatial { v, w, .. } => {
                let rot = k.rotation3(g);
                let we: Vec<Expr> = w.iter().map(|&s| g.var(s)).collect();
                let om = (0..3).map(|i| g.dot(&rot[i], &we)).collect();
                (v.iter().chain(w).copied().collect(), om)
            }
        };
        let mut basis = Vec::new();
        for &e in p.velocity.iter().chain(&omega) {
            for &s in &slots {
                basis.push(g.diff(e, s));
            }
        }
        let lever = (0..pa.position.len())
            .map(|i| g.sub(pa.position[i], pb.position[i]))
            .collect();
        JointReaction {
            joint: name.to_string(),
            rows: rows.collect(),
            velocities: slots.iter().map(|&s| (s - 1 - nq) as usize).collect(),
            dim: pa.position.len(),
            rotations: omega.len(),
            flip,
            moment,
            basis,
            lever,
        }
    }
}

/// The first damper or load of `scene` that exchanges energy with the mechanism, named by its
/// JSON path: the energy column (kinetic + gravity + springs) is conserved only without them.
pub(super) fn energy_exchange(scene: &Scene) -> Option<String> {
    if let Some((i, d)) = scene.drivers.iter().enumerate().next() {
        return Some(format!(
            "drivers[{i}] ('{}') prescribes joint '{}' and does work ({}.power)",
            d.name, d.joint, d.name
        ));
    }
    if let Some((i, l)) = scene.loads.iter().enumerate().next() {
        return Some(format!("loads[{i}] ('{}') does work", l.name));
    }
    scene
        .springs
        .iter()
        .enumerate()
        .find(|(_, s)| s.damping != 0.0)
        .map(|(i, s)| format!("springs[{i}] ('{}') has damping {}", s.name, s.damping))
}

/// The joint `scene.drivers[di]` drives and its index, or an error at `drivers[di].joint`.
pub(crate) fn driven_joint(
    scene: &crate::scene::Scene,
    di: usize,
) -> Result<(usize, &crate::scene::Joint), MechError> {
    let d = &scene.drivers[di];
    scene
        .joints
        .iter()
        .enumerate()
        .find(|(_, j)| j.name == d.joint)
        .ok_or_else(|| {
            MechError::at(
                &format!("drivers[{di}].joint"),
                format!("no joint named '{}'", d.joint),
            )
        })
}
