//! Scene → [`MultibodySystem`]: bodies become coordinates and inertias, joints become
//! constraint rows, springs, dampers, loads and gravity become generalized forces.
//!
//! A force `F` (global frame) applied at a point `P` contributes `Q_j += F · ∂V_P/∂v_j` (virtual
//! power; exact because `V_P` is linear in `v`). A torque `τ` on a planar body contributes to `ω`.
//! Only what the scene needs is modelled: a planar body whose rotation nothing depends on keeps
//! its angle fixed and carries no rotational coordinate.

use std::collections::HashMap;

use super::body::{cross3, quaternion_from_cardan, AngleSlot, BodyKinematics, PointKinematics};
use super::reactions::{transmits_moment, JointReaction};
use super::system::{
    ConstraintRow, Coordinate, EventFunction, LoadTerm, MultibodySystem, OutputColumn,
};
use super::MechError;
use crate::expr::{Expr, ExprGraph};
use crate::scene::{
    BodyFrame, Dimension, Inertia, JointKind, LoadKind, LoadValue, PointRef, Scene,
};

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

/// Builds the multibody system of a scene (planar or spatial).
pub fn assemble(scene: &Scene) -> Result<MultibodySystem, MechError> {
    Assembler::new(scene)?.run()
}

struct Assembler<'a> {
    scene: &'a Scene,
    spatial: bool,
    g: ExprGraph,
    coords: Vec<Coordinate>,
    vels: Vec<Coordinate>,
    mass: Vec<f64>,
    /// per scene body
    kin: Vec<BodyKinematics>,
    warnings: Vec<String>,
    /// Loads given as expressions, one term per component.
    load_terms: Vec<LoadTerm>,
}

/// Planned slots of one body, before the coordinate count is known.
enum Plan {
    Planar {
        angle: bool,
        body_fixed: bool,
    },
    Spatial,
    /// Spatial point mass: translation only.
    SpatialParticle,
}

impl<'a> Assembler<'a> {
    fn new(scene: &'a Scene) -> Result<Self, MechError> {
        Ok(Assembler {
            scene,
            spatial: matches!(scene.dimension, Dimension::Spatial),
            g: ExprGraph::new(),
            coords: Vec::new(),
            vels: Vec::new(),
            mass: Vec::new(),
            kin: Vec::new(),
            warnings: Vec::new(),
            load_terms: Vec::new(),
        })
    }

    fn dim(&self) -> usize {
        if self.spatial {
            3
        } else {
            2
        }
    }

    /// Point coordinates of a reference on body `body` ("ground" or a scene body).
    fn point_coords(&self, body: &str, p: &PointRef, path: &str) -> Result<Vec<f64>, MechError> {
        match p {
            PointRef::Coords(c) => Ok(c.clone()),
            PointRef::Named(n) => {
                let b = self
                    .scene
                    .bodies
                    .iter()
                    .find(|b| b.name == body)
                    .ok_or_else(|| MechError::at(path, format!("unknown body '{body}'")))?;
                b.points
                    .iter()
                    .find(|(pn, _)| pn == n)
                    .map(|(_, c)| c.clone())
                    .ok_or_else(|| MechError::at(path, format!("body '{body}' has no point '{n}'")))
            }
        }
    }

    fn body_index(&self, name: &str, path: &str) -> Result<Option<usize>, MechError> {
        if name == "ground" {
            return Ok(None);
        }
        self.scene
            .bodies
            .iter()
            .position(|b| b.name == name)
            .map(Some)
            .ok_or_else(|| MechError::at(path, format!("unknown body '{name}'")))
    }

    /// Which planar bodies need their rotation modelled.
    fn plan(&self) -> Result<Vec<Plan>, MechError> {
        let s = self.scene;
        if self.spatial {
            return self.spatial_plan();
        }
        let mut need: Vec<bool> = s
            .bodies
            .iter()
            .map(|b| {
                matches!(b.frame, BodyFrame::BodyFixed)
                    || planar_inertia(&b.inertia) > 0.0
                    || b.angular_velocity.first().copied().unwrap_or(0.0) != 0.0
            })
            .collect();
        let mut mark = |this: &Self, body: &str, p: &PointRef, path: &str| {
            if let Ok(Some(i)) = this.body_index(body, path) {
                if let Ok(c) = this.point_coords(body, p, path) {
                    if c.iter().any(|&x| x != 0.0) {
                        need[i] = true;
                    }
                }
            }
        };
        for (ji, j) in s.joints.iter().enumerate() {
            for k in 0..2 {
                mark(
                    self,
                    &j.bodies[k],
                    &j.points[k],
                    &format!("joints[{ji}].points[{k}]"),
                );
            }
        }
        for (si, sp) in s.springs.iter().enumerate() {
            for k in 0..2 {
                mark(
                    self,
                    &sp.bodies[k],
                    &sp.points[k],
                    &format!("springs[{si}].points[{k}]"),
                );
            }
        }
        for (li, l) in s.loads.iter().enumerate() {
            if let Some(p) = &l.point {
                mark(self, &l.body, p, &format!("loads[{li}].point"));
            }
        }
        for (oi, o) in s.outputs.iter().enumerate() {
            let mut parts = o.splitn(3, '.');
            if let (Some(b), Some(p)) = (parts.next(), parts.next()) {
                if !matches!(p, "x" | "y" | "angle" | "vx" | "vy" | "omega") {
                    mark(
                        self,
                        b,
                        &PointRef::Named(p.to_string()),
                        &format!("outputs[{oi}]"),
                    );
                }
            }
        }
        for (li, l) in s.loads.iter().enumerate() {
            if matches!(l.kind, LoadKind::Torque) {
                if let Some(i) = self.body_index(&l.body, &format!("loads[{li}].body"))? {
                    need[i] = true;
                }
            }
        }
        for (ji, j) in s.joints.iter().enumerate() {
            let path = format!("joints[{ji}].bodies");
            match j.kind {
                JointKind::Prismatic { .. } => {
                    if let Some(i) = self.body_index(&j.bodies[0], &path)? {
                        need[i] = true;
                    }
                }
                JointKind::Weld => {
                    for b in &j.bodies {
                        if let Some(i) = self.body_index(b, &path)? {
                            need[i] = true;
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(s.bodies
            .iter()
            .zip(need)
            .map(|(b, angle)| Plan::Planar {
                angle,
                body_fixed: matches!(b.frame, BodyFrame::BodyFixed),
            })
            .collect())
    }

    /// Spatial bodies: a body with principal moments `[0, 0, 0]` is a point mass and carries
    /// translation only; every point a joint, spring, load or output uses on it must be at its
    /// centre (a massless rotation would make the mass matrix singular), no torque may act on
    /// it, and hinges and welds (which fix a rotation) cannot attach to it.
    fn spatial_plan(&self) -> Result<Vec<Plan>, MechError> {
        let s = self.scene;
        let particle: Vec<bool> = s
            .bodies
            .iter()
            .map(|b| matches!(b.inertia, Inertia::Principal(j) if j.iter().all(|&x| x == 0.0)))
            .collect();
        let is_particle = |name: &str| {
            s.bodies
                .iter()
                .position(|b| b.name == name)
                .is_some_and(|i| particle[i])
        };
        let check = |body: &str, p: &PointRef, path: &str| -> Result<(), MechError> {
            if !is_particle(body) {
                return Ok(());
            }
            let c = self.point_coords(body, p, path)?;
            if c.iter().any(|&x| x != 0.0) {
                return Err(MechError::at(
                    path,
                    format!(
                        "body '{body}' is a point mass (inertia [0, 0, 0]) and has no rotation, so its points must be at its centre [0, 0, 0] (got {c:?}); give it principal moments of inertia to use off-centre points"
                    ),
                ));
            }
            Ok(())
        };
        for (ji, j) in s.joints.iter().enumerate() {
            for k in 0..2 {
                check(
                    &j.bodies[k],
                    &j.points[k],
                    &format!("joints[{ji}].points[{k}]"),
                )?;
                if is_particle(&j.bodies[k])
                    && matches!(j.kind, JointKind::Hinge { .. } | JointKind::Weld)
                {
                    return Err(MechError::at(
                        &format!("joints[{ji}].bodies[{k}]"),
                        format!(
                            "body '{}' is a point mass (inertia [0, 0, 0]) with no rotation; a hinge or weld cannot fix it (use spherical)",
                            j.bodies[k]
                        ),
                    ));
                }
            }
        }
        for (si, sp) in s.springs.iter().enumerate() {
            for k in 0..2 {
                check(
                    &sp.bodies[k],
                    &sp.points[k],
                    &format!("springs[{si}].points[{k}]"),
                )?;
            }
        }
        for (li, l) in s.loads.iter().enumerate() {
            if let Some(p) = &l.point {
                check(&l.body, p, &format!("loads[{li}].point"))?;
            }
            if matches!(l.kind, LoadKind::Torque) && is_particle(&l.body) {
                return Err(MechError::at(
                    &format!("loads[{li}].body"),
                    format!(
                        "body '{}' is a point mass (inertia [0, 0, 0]); a torque cannot act on it",
                        l.body
                    ),
                ));
            }
        }
        for (oi, o) in s.outputs.iter().enumerate() {
            if let Some((b, p)) = o.split_once('.') {
                let p = p.split('.').next().unwrap_or(p);
                if s.bodies
                    .iter()
                    .any(|bb| bb.name == b && bb.point(p).is_some())
                {
                    check(
                        b,
                        &PointRef::Named(p.to_string()),
                        &format!("outputs[{oi}]"),
                    )?;
                }
            }
        }
        for (bi, b) in s.bodies.iter().enumerate() {
            if particle[bi] && b.angular_velocity.iter().any(|&w| w != 0.0) {
                return Err(MechError::at(
                    &format!("bodies[{bi}].angular_velocity"),
                    "a point mass (inertia [0, 0, 0]) has no rotation",
                ));
            }
        }
        Ok(particle
            .into_iter()
            .map(|p| {
                if p {
                    Plan::SpatialParticle
                } else {
                    Plan::Spatial
                }
            })
            .collect())
    }

    fn run(mut self) -> Result<MultibodySystem, MechError> {
        let plans = self.plan()?;
        // Count coordinates first so velocity slots follow all coordinates.
        let nq: usize = plans
            .iter()
            .map(|p| match p {
                Plan::Planar { angle, .. } => 2 + usize::from(*angle),
                Plan::Spatial => 7,
                Plan::SpatialParticle => 3,
            })
            .sum();
        let mut qi = 0u32;
        let mut vi = 0u32;
        let qslot = |qi: &mut u32| {
            *qi += 1;
            *qi
        };
        let vslot = |vi: &mut u32| {
            *vi += 1;
            nq as u32 + *vi
        };
        for (bi, (b, plan)) in self.scene.bodies.iter().zip(&plans).enumerate() {
            let path = format!("bodies[{bi}]");
            let vel = |k: usize| b.velocity.get(k).copied().unwrap_or(0.0);
            let pos = |k: usize| b.position.get(k).copied().unwrap_or(0.0);
            match plan {
                Plan::Planar { angle, body_fixed } => {
                    let j = planar_inertia(&b.inertia);
                    let w0 = b.angular_velocity.first().copied().unwrap_or(0.0);
                    let (x, y) = (qslot(&mut qi), qslot(&mut qi));
                    self.coords.push(coord(&b.name, "x", pos(0)));
                    self.coords.push(coord(&b.name, "y", pos(1)));
                    let a = if *angle {
                        self.coords.push(coord(&b.name, "angle", b.angle));
                        AngleSlot::Coordinate(qslot(&mut qi))
                    } else {
                        AngleSlot::Fixed(b.angle)
                    };
                    if *angle && j == 0.0 {
                        self.warnings.push(format!(
                            "{path} '{}': no rotational inertia; its angle is a kinematic variable fixed by the joints",
                            b.name
                        ));
                    }
                    let (v0x, v0y) = if *body_fixed {
                        let (s, c) = b.angle.sin_cos();
                        (c * vel(0) + s * vel(1), -s * vel(0) + c * vel(1))
                    } else {
                        (vel(0), vel(1))
                    };
                    let names = if *body_fixed {
                        ["u", "w"]
                    } else {
                        ["vx", "vy"]
                    };
                    let (sx, sy) = (vslot(&mut vi), vslot(&mut vi));
                    self.vels.push(coord(&b.name, names[0], v0x));
                    self.vels.push(coord(&b.name, names[1], v0y));
                    self.mass.extend([b.mass, b.mass]);
                    let om = if *angle {
                        self.vels.push(coord(&b.name, "omega", w0));
                        self.mass.push(j);
                        Some(vslot(&mut vi))
                    } else {
                        None
                    };
                    self.kin.push(if *body_fixed {
                        let AngleSlot::Coordinate(a) = a else {
                            return Err(MechError::at(&path, "body-fixed frame needs its angle"));
                        };
                        BodyKinematics::PlanarBodyFixed {
                            x,
                            y,
                            angle: a,
                            u: sx,
                            w: sy,
                            omega: om.unwrap_or(0),
                        }
                    } else {
                        BodyKinematics::PlanarInertial {
                            x,
                            y,
                            angle: a,
                            vx: sx,
                            vy: sy,
                            omega: om,
                        }
                    });
                }
                Plan::SpatialParticle => {
                    let r = [qslot(&mut qi), qslot(&mut qi), qslot(&mut qi)];
                    for (k, n) in ["x", "y", "z"].iter().enumerate() {
                        self.coords.push(coord(&b.name, n, pos(k)));
                    }
                    let v = [vslot(&mut vi), vslot(&mut vi), vslot(&mut vi)];
                    for (k, n) in ["vx", "vy", "vz"].iter().enumerate() {
                        self.vels.push(coord(&b.name, n, vel(k)));
                    }
                    self.mass.extend([b.mass, b.mass, b.mass]);
                    self.kin.push(BodyKinematics::Particle { r, v });
                }
                Plan::Spatial => {
                    let jj = match &b.inertia {
                        Inertia::Principal(j) => *j,
                        Inertia::Planar(j) => [*j; 3],
                    };
                    let r = [qslot(&mut qi), qslot(&mut qi), qslot(&mut qi)];
                    for (k, n) in ["x", "y", "z"].iter().enumerate() {
                        self.coords.push(coord(&b.name, n, pos(k)));
                    }
                    let e0 = quaternion_from_cardan(b.cardan[0], b.cardan[1], b.cardan[2]);
                    let e = [
                        qslot(&mut qi),
                        qslot(&mut qi),
                        qslot(&mut qi),
                        qslot(&mut qi),
                    ];
                    for (k, val) in e0.iter().enumerate() {
                        self.coords.push(coord(&b.name, &format!("e{k}"), *val));
                    }
                    let v = [vslot(&mut vi), vslot(&mut vi), vslot(&mut vi)];
                    for (k, n) in ["vx", "vy", "vz"].iter().enumerate() {
                        self.vels.push(coord(&b.name, n, vel(k)));
                    }
                    let w = [vslot(&mut vi), vslot(&mut vi), vslot(&mut vi)];
                    for (k, n) in ["wx", "wy", "wz"].iter().enumerate() {
                        let w0 = b.angular_velocity.get(k).copied().unwrap_or(0.0);
                        self.vels.push(coord(&b.name, n, w0));
                    }
                    self.mass
                        .extend([b.mass, b.mass, b.mass, jj[0], jj[1], jj[2]]);
                    self.kin.push(BodyKinematics::Spatial { r, e, v, w });
                }
            }
        }
        debug_assert_eq!(qi as usize, nq);
        let nv = self.vels.len();

        let kinematics = self.kinematics();
        let mut forces: Vec<Expr> = (0..nv).map(|_| self.g.zero()).collect();
        let mut potential = Vec::new();
        self.gravity(&mut forces, &mut potential);
        self.gyroscopic(&mut forces);
        let names = self.name_table()?;
        self.springs(&mut forces, &mut potential)?;
        self.loads(&mut forces, &names)?;
        let (constraints, rows, reactions) = self.joints()?;
        let kinetic = self.kinetic_energy();
        let pot = self.g.sum(&potential);
        let energy = self.g.add(kinetic, pot);
        let outputs = self.outputs(&names, energy)?;
        let events = self.events(&names, energy, &reactions)?;
        self.connectivity();

        let mut sys = MultibodySystem {
            graph: self.g,
            coords: self.coords,
            velocities: self.vels,
            mass: self.mass,
            kinematics,
            forces,
            constraints,
            rows,
            energy,
            kinetic,
            outputs,
            warnings: self.warnings,
            load_terms: self.load_terms,
            body_size: body_size(self.scene),
            reaction_outputs: self.scene.outputs.iter().any(|o| o == "reactions"),
            reactions,
            events,
            energy_exchange: energy_exchange(self.scene),
            bodies: self
                .scene
                .bodies
                .iter()
                .map(|b| b.name.clone())
                .zip(self.kin.iter().cloned())
                .collect(),
            names: {
                let mut v: Vec<(String, Expr)> = names.into_iter().collect();
                v.sort_by(|a, b| a.0.cmp(&b.0));
                v
            },
            flow_rows: Vec::new(),
            source: super::system::EquationSource::Assembled("assembled".into()),
            bond_graph: None,
        };
        let names: Vec<String> = self.scene.joints.iter().map(|j| j.name.clone()).collect();
        for v in sys.initial_violation(&names) {
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
        Ok(sys)
    }

    /// `K(q) v`, coordinate by coordinate.
    fn kinematics(&mut self) -> Vec<Expr> {
        let mut out = Vec::with_capacity(self.coords.len());
        let kin = self.kin.clone();
        for k in &kin {
            match k {
                BodyKinematics::Ground => {}
                BodyKinematics::PlanarInertial { vx, vy, omega, .. } => {
                    out.push(self.g.var(*vx));
                    out.push(self.g.var(*vy));
                    if let Some(w) = omega {
                        out.push(self.g.var(*w));
                    }
                }
                BodyKinematics::PlanarBodyFixed { omega, .. } => {
                    let v = k.centre_velocity(&mut self.g);
                    out.extend(v);
                    out.push(self.g.var(*omega));
                }
                BodyKinematics::Particle { v, .. } => {
                    for s in v {
                        out.push(self.g.var(*s));
                    }
                }
                BodyKinematics::Spatial { e, v, w, .. } => {
                    for s in v {
                        out.push(self.g.var(*s));
                    }
                    // e' = ½ e ⊗ (0, ω)
                    let ee: Vec<Expr> = e.iter().map(|&s| self.g.var(s)).collect();
                    let ww: Vec<Expr> = w.iter().map(|&s| self.g.var(s)).collect();
                    let g = &mut self.g;
                    let terms: [[(f64, usize, usize); 3]; 4] = [
                        [(-1.0, 1, 0), (-1.0, 2, 1), (-1.0, 3, 2)],
                        [(1.0, 0, 0), (1.0, 2, 2), (-1.0, 3, 1)],
                        [(1.0, 0, 1), (1.0, 3, 0), (-1.0, 1, 2)],
                        [(1.0, 0, 2), (1.0, 1, 1), (-1.0, 2, 0)],
                    ];
                    for row in terms {
                        let parts: Vec<Expr> = row
                            .iter()
                            .map(|&(c, a, b)| {
                                let p = g.mul(ee[a], ww[b]);
                                g.scale(0.5 * c, p)
                            })
                            .collect();
                        out.push(g.sum(&parts));
                    }
                }
            }
        }
        out
    }

    /// Adds `F · ∂V/∂v_j` to every generalized force.
    ///
    /// Only the velocities `V` mentions are visited (once per force, not once per velocity of
    /// the whole system: gravity on 6000 free bodies would otherwise take 10⁸ dependency walks).
    fn apply_force(&mut self, forces: &mut [Expr], velocity: &[Expr], f: &[Expr]) {
        let first = (1 + self.coords.len()) as u32;
        let mut slots: Vec<u32> = velocity
            .iter()
            .flat_map(|&vk| self.g.vars(vk))
            .filter(|&s| s >= first && ((s - first) as usize) < forces.len())
            .collect();
        slots.sort_unstable();
        slots.dedup();
        for slot in slots {
            let j = (slot - first) as usize;
            let fj = &mut forces[j];
            let mut terms = vec![*fj];
            for (vk, fk) in velocity.iter().zip(f) {
                if self.g.depends_on(*vk, slot) {
                    let d = self.g.diff(*vk, slot);
                    terms.push(self.g.mul(d, *fk));
                }
            }
            *fj = self.g.sum(&terms);
        }
    }

    fn gravity(&mut self, forces: &mut [Expr], potential: &mut Vec<Expr>) {
        let grav: Vec<f64> = (0..self.dim())
            .map(|k| self.scene.gravity.get(k).copied().unwrap_or(0.0))
            .collect();
        if grav.iter().all(|&x| x == 0.0) {
            return;
        }
        for bi in 0..self.kin.len() {
            let m = self.scene.bodies[bi].mass;
            let k = self.kin[bi].clone();
            let v = k.centre_velocity(&mut self.g);
            let r = k.centre_position(&mut self.g);
            let f: Vec<Expr> = grav.iter().map(|&gk| self.g.constant(m * gk)).collect();
            self.apply_force(forces, &v, &f);
            // V = −m g·r
            let gr: Vec<Expr> = grav.iter().map(|&gk| self.g.constant(-m * gk)).collect();
            potential.push(self.g.dot(&gr, &r));
        }
    }

    /// The gyroscopic terms: the MGY of a body-fixed planar frame (16.3) and the Euler
    /// junction structure `−ω × Jω` of a spatial body (16.1).
    fn gyroscopic(&mut self, forces: &mut [Expr]) {
        let nq = self.coords.len() as u32;
        for bi in 0..self.kin.len() {
            match self.kin[bi].clone() {
                BodyKinematics::PlanarBodyFixed { u, w, omega, .. } => {
                    let m = self.scene.bodies[bi].mass;
                    let (ue, we, om) = (self.g.var(u), self.g.var(w), self.g.var(omega));
                    let mw = self.g.mul(om, we);
                    let mw = self.g.scale(m, mw);
                    let mu = self.g.mul(om, ue);
                    let mu = self.g.scale(-m, mu);
                    let (iu, iw) = ((u - 1 - nq) as usize, (w - 1 - nq) as usize);
                    forces[iu] = self.g.add(forces[iu], mw);
                    forces[iw] = self.g.add(forces[iw], mu);
                }
                BodyKinematics::Spatial { w, .. } => {
                    let Inertia::Principal(j) = self.scene.bodies[bi].inertia else {
                        continue;
                    };
                    let we: Vec<Expr> = w.iter().map(|&s| self.g.var(s)).collect();
                    let jw: Vec<Expr> = (0..3).map(|k| self.g.scale(j[k], we[k])).collect();
                    let c = cross3(&mut self.g, &we, &jw);
                    for k in 0..3 {
                        let idx = (w[k] - 1 - nq) as usize;
                        forces[idx] = self.g.sub(forces[idx], c[k]);
                    }
                }
                _ => {}
            }
        }
    }

    fn kinetic_energy(&mut self) -> Expr {
        let nq = self.coords.len();
        let mut terms = Vec::new();
        for (j, &m) in self.mass.clone().iter().enumerate() {
            if m == 0.0 {
                continue;
            }
            let v = self.g.var((1 + nq + j) as u32);
            let v2 = self.g.mul(v, v);
            terms.push(self.g.scale(0.5 * m, v2));
        }
        self.g.sum(&terms)
    }

    fn kin_of(&self, body: &str, path: &str) -> Result<BodyKinematics, MechError> {
        Ok(match self.body_index(body, path)? {
            None => BodyKinematics::Ground,
            Some(i) => self.kin[i].clone(),
        })
    }

    fn point(
        &mut self,
        body: &str,
        p: &PointRef,
        path: &str,
    ) -> Result<PointKinematics, MechError> {
        let c = self.point_coords(body, p, path)?;
        if c.len() != self.dim() {
            return Err(MechError::at(
                path,
                format!("point needs {} coordinates, got {}", self.dim(), c.len()),
            ));
        }
        let k = self.kin_of(body, path)?;
        Ok(k.point(&mut self.g, &c))
    }

    fn springs(&mut self, forces: &mut [Expr], potential: &mut Vec<Expr>) -> Result<(), MechError> {
        for (si, sp) in self.scene.springs.iter().enumerate() {
            let path = format!("springs[{si}]");
            let pa = self.point(&sp.bodies[0], &sp.points[0], &format!("{path}.points[0]"))?;
            let pb = self.point(&sp.bodies[1], &sp.points[1], &format!("{path}.points[1]"))?;
            let x0 = self.initial_slots();
            let g = &mut self.g;
            let d: Vec<Expr> = (0..pa.position.len())
                .map(|k| g.sub(pb.position[k], pa.position[k]))
                .collect();
            let dv: Vec<Expr> = (0..pa.velocity.len())
                .map(|k| g.sub(pb.velocity[k], pa.velocity[k]))
                .collect();
            let l0 = match sp.rest_length {
                Some(l) => l,
                None => {
                    // initial distance
                    let dd = g.dot(&d, &d);
                    g.eval(dd, &x0).sqrt()
                }
            };
            let (k, c) = (sp.stiffness, sp.damping);
            // Force on b: zero rest length → F = −k d − c ḋ; otherwise along the spring axis,
            // F = −(k (L − L0) + c L') d / L with L' = d·ḋ / L.
            let fb: Vec<Expr> = if l0 == 0.0 {
                let dd = g.dot(&d, &d);
                potential.push(g.scale(0.5 * k, dd));
                (0..d.len())
                    .map(|i| {
                        let a = g.scale(-k, d[i]);
                        let b = g.scale(-c, dv[i]);
                        g.add(a, b)
                    })
                    .collect()
            } else {
                let dd = g.dot(&d, &d);
                let len = g.sqrt(dd);
                let l0e = g.constant(l0);
                let stretch = g.sub(len, l0e);
                let s2 = g.mul(stretch, stretch);
                potential.push(g.scale(0.5 * k, s2));
                let ddv = g.dot(&d, &dv);
                let rate = g.div(ddv, len);
                let a = g.scale(k, stretch);
                let b = g.scale(c, rate);
                let mag = g.add(a, b);
                let coef = g.div(mag, len);
                let coef = g.neg(coef);
                d.iter().map(|&di| g.mul(coef, di)).collect()
            };
            let fa: Vec<Expr> = fb.iter().map(|&f| self.g.neg(f)).collect();
            self.apply_force(forces, &pb.velocity, &fb);
            self.apply_force(forces, &pa.velocity, &fa);
        }
        Ok(())
    }

    fn initial_slots(&self) -> Vec<f64> {
        let mut x = vec![0.0];
        x.extend(self.coords.iter().map(|c| c.initial));
        x.extend(self.vels.iter().map(|c| c.initial));
        x
    }

    /// The names an expression in a load or an output may use: `t` and every standard column
    /// and point coordinate (`crank.angle`, `bar2.A.x`, `bar2.A.vy`, …).
    fn name_table(&mut self) -> Result<HashMap<String, Expr>, MechError> {
        let mut names = HashMap::new();
        names.insert("t".to_string(), self.g.var(0));
        for bi in 0..self.kin.len() {
            let b = &self.scene.bodies[bi];
            let k = self.kin[bi].clone();
            for (n, e) in self.body_columns(&b.name.clone(), &k) {
                names.insert(n, e.0);
            }
            let pts = b.points.clone();
            let bname = b.name.clone();
            for (pn, pc) in pts {
                if pc.len() != self.dim() {
                    continue;
                }
                let p = k.point(&mut self.g, &pc);
                let axes = ["x", "y", "z"];
                for (i, e) in p.position.iter().enumerate() {
                    names.insert(format!("{bname}.{pn}.{}", axes[i]), *e);
                }
                for (i, e) in p.velocity.iter().enumerate() {
                    names.insert(format!("{bname}.{pn}.v{}", axes[i]), *e);
                }
            }
        }
        Ok(names)
    }

    /// Standard columns of a body: (name, (expr, unwrap)).
    fn body_columns(&mut self, b: &str, k: &BodyKinematics) -> Vec<(String, (Expr, bool))> {
        let mut cols = Vec::new();
        let g = &mut self.g;
        let r = k.centre_position(g);
        let v = k.centre_velocity(g);
        let axes = ["x", "y", "z"];
        for (i, e) in r.iter().enumerate() {
            cols.push((format!("{b}.{}", axes[i]), (*e, false)));
        }
        match k {
            BodyKinematics::Spatial { w, e, .. } => {
                for (i, e) in v.iter().enumerate() {
                    cols.push((format!("{b}.v{}", axes[i]), (*e, false)));
                }
                let we: Vec<Expr> = w.iter().map(|&s| g.var(s)).collect();
                for (i, n) in ["wx", "wy", "wz"].iter().enumerate() {
                    cols.push((format!("{b}.{n}"), (we[i], false)));
                }
                let rot = k.rotation3(g);
                for (i, n) in ["wX", "wY", "wZ"].iter().enumerate() {
                    let e = g.dot(&rot[i], &we);
                    cols.push((format!("{b}.{n}"), (e, false)));
                }
                // Cardan angles of R = Ψ Θ Φ (seed 16.2): ψ = atan2(R21, R11),
                // θ = atan2(−R31, √(R11² + R21²)), φ = atan2(R32, R33).
                let psi = g.atan2(rot[1][0], rot[0][0]);
                let a = g.mul(rot[0][0], rot[0][0]);
                let bb = g.mul(rot[1][0], rot[1][0]);
                let h = g.add(a, bb);
                let h = g.sqrt(h);
                let m31 = g.neg(rot[2][0]);
                let theta = g.atan2(m31, h);
                let phi = g.atan2(rot[2][1], rot[2][2]);
                cols.push((format!("{b}.psi"), (psi, true)));
                cols.push((format!("{b}.theta"), (theta, false)));
                cols.push((format!("{b}.phi"), (phi, true)));
                // the attitude quaternion R = R(q), q = e / |e| (the integrated Euler
                // parameters, normalised): continuous, no gimbal lock
                let ev: Vec<Expr> = e.iter().map(|&s| g.var(s)).collect();
                let sq: Vec<Expr> = ev.iter().map(|&x| g.mul(x, x)).collect();
                let n2 = g.sum(&sq);
                let norm = g.sqrt(n2);
                for (i, n) in ["qw", "qx", "qy", "qz"].iter().enumerate() {
                    let q = g.div(ev[i], norm);
                    cols.push((format!("{b}.{n}"), (q, false)));
                }
            }
            BodyKinematics::Particle { .. } => {
                for (i, e) in v.iter().enumerate() {
                    cols.push((format!("{b}.v{}", axes[i]), (*e, false)));
                }
            }
            _ => {
                let a = k.planar_angle(g);
                let w = k.planar_omega(g);
                cols.push((format!("{b}.angle"), (a, false)));
                cols.push((format!("{b}.vx"), (v[0], false)));
                cols.push((format!("{b}.vy"), (v[1], false)));
                cols.push((format!("{b}.omega"), (w, false)));
            }
        }
        cols
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

    fn loads(
        &mut self,
        forces: &mut [Expr],
        names: &HashMap<String, Expr>,
    ) -> Result<(), MechError> {
        for (li, l) in self.scene.loads.iter().enumerate() {
            let path = format!("loads[{li}]");
            let Some(bi) = self.body_index(&l.body, &format!("{path}.body"))? else {
                continue; // a load on the ground does nothing
            };
            match l.kind {
                LoadKind::Force => {
                    let n = self.dim();
                    let f = self.value_exprs(&l.name, &l.value, n, names, &path)?;
                    let p = match &l.point {
                        Some(p) => self.point(&l.body, p, &format!("{path}.point"))?,
                        None => {
                            let k = self.kin[bi].clone();
                            PointKinematics {
                                position: k.centre_position(&mut self.g),
                                velocity: k.centre_velocity(&mut self.g),
                            }
                        }
                    };
                    self.apply_force(forces, &p.velocity, &f);
                }
                LoadKind::Torque => {
                    let n = if self.spatial { 3 } else { 1 };
                    let tau = self.value_exprs(&l.name, &l.value, n, names, &path)?;
                    let nq = self.coords.len() as u32;
                    match self.kin[bi].clone() {
                        BodyKinematics::Spatial { w, .. } => {
                            // body torque = Rᵀ τ (seed 16.2: forces back with (ΨΘΦ)ᵀ)
                            let rot = self.kin[bi].rotation3(&mut self.g);
                            for k in 0..3 {
                                let col: Vec<Expr> = (0..3).map(|i| rot[i][k]).collect();
                                let tb = self.g.dot(&col, &tau);
                                let idx = (w[k] - 1 - nq) as usize;
                                forces[idx] = self.g.add(forces[idx], tb);
                            }
                        }
                        BodyKinematics::PlanarInertial { omega: Some(w), .. }
                        | BodyKinematics::PlanarBodyFixed { omega: w, .. } => {
                            let idx = (w - 1 - nq) as usize;
                            forces[idx] = self.g.add(forces[idx], tau[0]);
                        }
                        _ => {
                            return Err(MechError::at(
                                &format!("{path}.body"),
                                format!("body '{}' has no modelled rotation", l.body),
                            ))
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The scene's events as functions over the event layout `[t, q, v, reactions]`: `when`
    /// may name `t`, any standard column or point coordinate/velocity, `energy`, and any
    /// joint's reaction column.
    fn events(
        &mut self,
        names: &HashMap<String, Expr>,
        energy: Expr,
        reactions: &[JointReaction],
    ) -> Result<Vec<EventFunction>, MechError> {
        let base = 1 + self.coords.len() + self.vels.len();
        let reaction_columns: Vec<String> = reactions.iter().flat_map(|r| r.columns()).collect();
        let mut out = Vec::with_capacity(self.scene.events.len());
        let placeholders: Vec<Expr> = (0..reaction_columns.len())
            .map(|k| self.g.var((base + k) as u32))
            .collect();
        for (ei, ev) in self.scene.events.iter().enumerate() {
            let mut resolve = |name: &str| {
                if name == "energy" {
                    return Some(energy);
                }
                if let Some(e) = names.get(name) {
                    return Some(*e);
                }
                let k = reaction_columns.iter().position(|c| c == name)?;
                Some(placeholders[k])
            };
            let expr = self.g.parse(&ev.when, &mut resolve).map_err(|e| {
                MechError::at(
                    &format!("events[{ei}].when"),
                    format!(
                        "{e} in \"{}\" (an event may use t, body columns such as bar.angle, points such as bar.A.x or bar.A.vy, energy, and reaction columns such as pivot.Fy)",
                        ev.when
                    ),
                )
            })?;
            let uses_reactions = self.g.vars(expr).iter().any(|&s| s as usize >= base);
            out.push(EventFunction {
                name: ev.name.clone(),
                when: ev.when.clone(),
                expr,
                direction: ev.direction,
                action: ev.action,
                uses_reactions,
            });
        }
        Ok(out)
    }

    /// How joint `j`'s reaction is read: the carrier body (second, or first when the second
    /// is ground), its velocities, `B = ∂(V_P, ω)/∂v_b` and the lever `P_1 − P_2`.
    #[allow(clippy::too_many_arguments)]
    fn joint_reaction(
        &mut self,
        name: &str,
        kind: &JointKind,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
        pa: &PointKinematics,
        pb: &PointKinematics,
        rows: std::ops::Range<usize>,
    ) -> JointReaction {
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
            moment: transmits_moment(kind),
            basis,
            lever,
        }
    }

    #[allow(clippy::type_complexity)]
    fn joints(&mut self) -> Result<(Vec<Expr>, Vec<ConstraintRow>, Vec<JointReaction>), MechError> {
        let mut g_rows = Vec::new();
        let mut meta = Vec::new();
        let mut reactions = Vec::new();
        let axes = ["x", "y", "z"];
        for (ji, j) in self.scene.joints.iter().enumerate() {
            let first_row = g_rows.len();
            let path = format!("joints[{ji}]");
            let pa = self.point(&j.bodies[0], &j.points[0], &format!("{path}.points[0]"))?;
            let pb = self.point(&j.bodies[1], &j.points[1], &format!("{path}.points[1]"))?;
            let ka = self.kin_of(&j.bodies[0], &path)?;
            let kb = self.kin_of(&j.bodies[1], &path)?;
            let row = |dir: &str| ConstraintRow {
                joint: j.name.clone(),
                direction: dir.to_string(),
            };
            match &j.kind {
                JointKind::Hinge { axis } => {
                    if !self.spatial {
                        return Err(MechError::at(
                            &format!("{path}.axis"),
                            "a planar revolute pins about z and takes no axis",
                        ));
                    }
                    for (k, axis) in axes.iter().enumerate() {
                        g_rows.push(self.g.sub(pa.position[k], pb.position[k]));
                        meta.push(row(axis));
                    }
                    for (dir, e) in self.hinge_rows(&ka, &kb, axis, &path)? {
                        g_rows.push(e);
                        meta.push(row(dir));
                    }
                }
                JointKind::Revolute | JointKind::Spherical => {
                    if self.spatial && matches!(j.kind, JointKind::Revolute) {
                        return Err(MechError::at(
                            &format!("{path}.axis"),
                            "a revolute joint in 3D is a hinge and needs an axis; use spherical for a ball joint",
                        ));
                    }
                    for (k, axis) in axes.iter().enumerate().take(pa.position.len()) {
                        g_rows.push(self.g.sub(pa.position[k], pb.position[k]));
                        meta.push(row(axis));
                    }
                }
                JointKind::Prismatic { axis } if self.spatial => {
                    for (dir, e) in self.spatial_prismatic_rows(&ka, &kb, &pa, &pb, axis, &path)? {
                        g_rows.push(e);
                        meta.push(row(dir));
                    }
                }
                JointKind::Prismatic { axis } => {
                    // n = R(α_a)·perp(u); n·(P_b − P_a) = 0
                    let norm = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
                    let perp = [-axis[1] / norm, axis[0] / norm];
                    let n = ka.point(&mut self.g, &perp);
                    let origin = ka.point(&mut self.g, &[0.0, 0.0]);
                    let g = &mut self.g;
                    let nx = if matches!(ka, BodyKinematics::Ground) {
                        [g.constant(perp[0]), g.constant(perp[1])]
                    } else {
                        [
                            g.sub(n.position[0], origin.position[0]),
                            g.sub(n.position[1], origin.position[1]),
                        ]
                    };
                    let d = [
                        g.sub(pb.position[0], pa.position[0]),
                        g.sub(pb.position[1], pa.position[1]),
                    ];
                    g_rows.push(g.dot(&nx, &d));
                    meta.push(row("normal"));
                    if let Some(e) = self.relative_angle_row(&ka, &kb) {
                        g_rows.push(e);
                        meta.push(row("angle"));
                    }
                }
                JointKind::Weld => {
                    for (k, axis) in axes.iter().enumerate().take(pa.position.len()) {
                        g_rows.push(self.g.sub(pa.position[k], pb.position[k]));
                        meta.push(row(axis));
                    }
                    if self.spatial {
                        for (dir, e) in self.relative_rotation_rows(&ka, &kb) {
                            g_rows.push(e);
                            meta.push(row(dir));
                        }
                    } else if let Some(e) = self.relative_angle_row(&ka, &kb) {
                        g_rows.push(e);
                        meta.push(row("angle"));
                    }
                }
            }
            let rows = first_row..g_rows.len();
            reactions.push(self.joint_reaction(&j.name, &j.kind, &ka, &kb, &pa, &pb, rows));
        }
        Ok((g_rows, meta, reactions))
    }

    /// `α_b − α_a − (α_b0 − α_a0)`, when both angles are modelled (or ground).
    fn relative_angle_row(&mut self, ka: &BodyKinematics, kb: &BodyKinematics) -> Option<Expr> {
        let modelled = |k: &BodyKinematics| {
            matches!(
                k,
                BodyKinematics::Ground
                    | BodyKinematics::PlanarBodyFixed { .. }
                    | BodyKinematics::PlanarInertial {
                        angle: AngleSlot::Coordinate(_),
                        ..
                    }
            )
        };
        if !modelled(ka) || !modelled(kb) {
            return None;
        }
        let aa = ka.planar_angle(&mut self.g);
        let ab = kb.planar_angle(&mut self.g);
        let x0 = self.initial_slots();
        let rel0 = self.g.eval(ab, &x0) - self.g.eval(aa, &x0);
        let d = self.g.sub(ab, aa);
        let c = self.g.constant(rel0);
        Some(self.g.sub(d, c))
    }

    /// The two orientation rows of a spatial hinge: with `a = R_a â` the hinge axis (`â` the
    /// unit `axis` in body a's frame) and `c_1, c_2` an orthonormal pair perpendicular to the
    /// axis as body b sees it initially (`R_b(0)ᵀ R_a(0) â`), the rows are `a · (R_b c_1) = 0`
    /// and `a · (R_b c_2) = 0` (dimensionless: about the small relative rotation angles).
    fn hinge_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
        axis: &[f64],
        path: &str,
    ) -> Result<Vec<(&'static str, Expr)>, MechError> {
        let u = unit_axis(axis, path)?;
        let ra = ka.rotation3(&mut self.g);
        let rb = kb.rotation3(&mut self.g);
        let x0 = self.initial_slots();
        let ev = |g: &ExprGraph, r: &[[Expr; 3]; 3]| -> [[f64; 3]; 3] {
            let mut m = [[0.0; 3]; 3];
            for i in 0..3 {
                for k in 0..3 {
                    m[i][k] = g.eval(r[i][k], &x0);
                }
            }
            m
        };
        let (ra0, rb0) = (ev(&self.g, &ra), ev(&self.g, &rb));
        // global axis at t = 0, then seen from body b
        let ag: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|k| ra0[i][k] * u[k]).sum())
            .collect();
        let ab: [f64; 3] = std::array::from_fn(|k| (0..3).map(|i| rb0[i][k] * ag[i]).sum::<f64>());
        let (c1, c2) = perpendicular_pair(ab);
        let ue: Vec<Expr> = u.iter().map(|&c| self.g.constant(c)).collect();
        let a: Vec<Expr> = (0..3).map(|i| self.g.dot(&ra[i], &ue)).collect();
        let mut out = Vec::with_capacity(2);
        for (dir, c) in [("axis1", c1), ("axis2", c2)] {
            let ce: Vec<Expr> = c.iter().map(|&x| self.g.constant(x)).collect();
            let bc: Vec<Expr> = (0..3).map(|i| self.g.dot(&rb[i], &ce)).collect();
            out.push((dir, self.g.dot(&a, &bc)));
        }
        Ok(out)
    }

    /// Rows of a spatial prismatic joint: with `d = P_b − P_a` and `c_1, c_2` an orthonormal pair
    /// perpendicular to `axis` in body a's frame, `(R_a c_1)·d = 0` and `(R_a c_2)·d = 0` (body b's
    /// point stays on the line through `P_a` along `R_a axis`), plus the three rows of a weld
    /// fixing the relative rotation (left out when body b is a point mass, which has none).
    fn spatial_prismatic_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
        pa: &PointKinematics,
        pb: &PointKinematics,
        axis: &[f64],
        path: &str,
    ) -> Result<Vec<(&'static str, Expr)>, MechError> {
        let axis = unit_axis(axis, path)?;
        if matches!(ka, BodyKinematics::Particle { .. }) {
            return Err(MechError::at(
                &format!("{path}.bodies[0]"),
                "the first body of a prismatic joint carries the axis and needs a rotation; a point mass (inertia [0, 0, 0]) has none (list it second)",
            ));
        }
        let (c1, c2) = perpendicular_pair(axis);
        let ra = ka.rotation3(&mut self.g);
        let d: Vec<Expr> = (0..3)
            .map(|k| self.g.sub(pb.position[k], pa.position[k]))
            .collect();
        let mut out = Vec::with_capacity(5);
        for (dir, c) in [("normal1", c1), ("normal2", c2)] {
            let ce: Vec<Expr> = c.iter().map(|&x| self.g.constant(x)).collect();
            let n: Vec<Expr> = (0..3).map(|i| self.g.dot(&ra[i], &ce)).collect();
            out.push((dir, self.g.dot(&n, &d)));
        }
        if !matches!(kb, BodyKinematics::Particle { .. }) {
            out.extend(self.relative_rotation_rows(ka, kb));
        }
        Ok(out)
    }

    /// Orientation rows of a spatial weld: the skew part of `C = R0ᵀ R_aᵀ R_b`.
    fn relative_rotation_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
    ) -> Vec<(&'static str, Expr)> {
        let ra = ka.rotation3(&mut self.g);
        let rb = kb.rotation3(&mut self.g);
        let x0 = self.initial_slots();
        let mut rel = [[self.g.zero(); 3]; 3];
        let mut rel0 = [[0.0; 3]; 3];
        for i in 0..3 {
            for k in 0..3 {
                let ca: Vec<Expr> = (0..3).map(|m| ra[m][i]).collect();
                let cb: Vec<Expr> = (0..3).map(|m| rb[m][k]).collect();
                rel[i][k] = self.g.dot(&ca, &cb);
                rel0[i][k] = self.g.eval(rel[i][k], &x0);
            }
        }
        // C = rel0ᵀ rel
        let mut c = [[self.g.zero(); 3]; 3];
        for i in 0..3 {
            for k in 0..3 {
                let terms: Vec<Expr> = (0..3)
                    .map(|m| self.g.scale(rel0[m][i], rel[m][k]))
                    .collect();
                c[i][k] = self.g.sum(&terms);
            }
        }
        let mut out = Vec::new();
        for (dir, (a0, a1), (p, q)) in [
            ("rx", (2, 1), (1, 2)),
            ("ry", (0, 2), (2, 0)),
            ("rz", (1, 0), (0, 1)),
        ] {
            let d = self.g.sub(c[a0][a1], c[p][q]);
            out.push((dir, self.g.scale(0.5, d)));
        }
        out
    }

    fn outputs(
        &mut self,
        names: &HashMap<String, Expr>,
        energy: Expr,
    ) -> Result<Vec<OutputColumn>, MechError> {
        let mut cols = Vec::new();
        for bi in 0..self.kin.len() {
            let b = self.scene.bodies[bi].name.clone();
            let k = self.kin[bi].clone();
            for (name, (expr, unwrap)) in self.body_columns(&b, &k) {
                cols.push(OutputColumn { name, expr, unwrap });
            }
        }
        let axes = ["x", "y", "z"];
        for (oi, o) in self.scene.outputs.iter().enumerate() {
            match o.as_str() {
                "energy" => cols.push(OutputColumn {
                    name: "energy".into(),
                    expr: energy,
                    unwrap: false,
                }),
                "constraint_error" | "reactions" => {}
                _ => {
                    if cols.iter().any(|c| &c.name == o) {
                        continue;
                    }
                    if let Some(e) = names.get(o) {
                        cols.push(OutputColumn {
                            name: o.clone(),
                            expr: *e,
                            unwrap: false,
                        });
                        continue;
                    }
                    let found: Vec<usize> = (0..self.dim())
                        .filter(|k| names.contains_key(&format!("{o}.{}", axes[*k])))
                        .collect();
                    if found.len() != self.dim() {
                        return Err(MechError::at(
                            &format!("outputs[{oi}]"),
                            format!("unknown output '{o}' (expected 'energy', 'constraint_error', a standard column or BODY.POINT)"),
                        ));
                    }
                    for axis in axes.iter().take(self.dim()) {
                        let n = format!("{o}.{axis}");
                        cols.push(OutputColumn {
                            expr: names[&n],
                            name: n,
                            unwrap: false,
                        });
                    }
                }
            }
        }
        Ok(cols)
    }

    /// Warn about bodies nothing connects to.
    fn connectivity(&mut self) {
        let s = self.scene;
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
}

fn coord(body: &str, what: &str, initial: f64) -> Coordinate {
    Coordinate {
        name: format!("{body}.{what}"),
        initial,
    }
}

/// An orthonormal pair `(c_1, c_2)` perpendicular to the non-zero vector `a`.
/// The unit vector along a joint's `axis` (a non-zero, finite 3D direction), or an error at
/// `<path>.axis`.
fn unit_axis(axis: &[f64], path: &str) -> Result<[f64; 3], MechError> {
    let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
    if axis.len() != 3 || !norm.is_finite() || norm <= 0.0 {
        return Err(MechError::at(
            &format!("{path}.axis"),
            "needs a non-zero 3D direction",
        ));
    }
    Ok([axis[0] / norm, axis[1] / norm, axis[2] / norm])
}

fn perpendicular_pair(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let a = [a[0] / n, a[1] / n, a[2] / n];
    // start from the global axis least aligned with a
    let k = (0..3)
        .min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let d = e[0] * a[0] + e[1] * a[1] + e[2] * a[2];
    let mut c1 = [e[0] - d * a[0], e[1] - d * a[1], e[2] - d * a[2]];
    let n1 = (c1[0] * c1[0] + c1[1] * c1[1] + c1[2] * c1[2]).sqrt();
    for x in &mut c1 {
        *x /= n1;
    }
    let c2 = [
        a[1] * c1[2] - a[2] * c1[1],
        a[2] * c1[0] - a[0] * c1[2],
        a[0] * c1[1] - a[1] * c1[0],
    ];
    (c1, c2)
}

fn planar_inertia(i: &Inertia) -> f64 {
    match i {
        Inertia::Planar(j) => *j,
        Inertia::Principal(j) => j[2],
    }
}

/// The first damper or load of `scene` that exchanges energy with the mechanism, named by its
/// JSON path: the energy column (kinetic + gravity + springs) is conserved only without them.
fn energy_exchange(scene: &Scene) -> Option<String> {
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
