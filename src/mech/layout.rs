//! The bodies' states (seed 16.1–16.3, 16.8): the generalized coordinates, velocities and
//! inertias each scene body needs, and the coordinate rates `q' = K(q) v`.
//!
//! Only what the scene needs is modelled: a planar body whose rotation nothing depends on
//! keeps its angle fixed and carries no rotational coordinate; a spatial body of principal
//! moments `[0, 0, 0]` is a point mass with translation only. Coordinates come first in the
//! slot layout `[t, q, v]`, velocities after all of them. A spatial body's attitude is its
//! Euler-parameter quaternion `e` with `e' = ½ e ⊗ (0, ω)` (the Cardan angles of 16.2 are
//! outputs only).

use super::body::{quaternion_from_cardan, AngleSlot, BodyKinematics};
use super::coordinates::{coord, planar_inertia, Geometry};
use super::error::MechError;
use super::joints;
use crate::expr::Expr;
use crate::scene::{BodyFrame, Inertia, LoadKind, PointRef};

/// Planned slots of one body, before the coordinate count is known.
pub(super) enum Plan {
    Planar {
        angle: bool,
        body_fixed: bool,
    },
    Spatial,
    /// Spatial point mass: translation only.
    SpatialParticle,
}

impl Geometry<'_> {
    /// Which planar bodies need their rotation modelled.
    pub(super) fn plan(&self) -> Result<Vec<Plan>, MechError> {
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
            for (k, b) in j.bodies.iter().enumerate() {
                if joints::needs_rotation(&j.kind, k, false) {
                    if let Some(i) = self.body_index(b, &path)? {
                        need[i] = true;
                    }
                }
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
                if is_particle(&j.bodies[k]) && joints::needs_rotation(&j.kind, k, true) {
                    return Err(MechError::at(
                        &format!("joints[{ji}].bodies[{k}]"),
                        format!(
                            "body '{}' is a point mass (inertia [0, 0, 0]) with no rotation; a {} joint fixes its rotation (use spherical)",
                            j.bodies[k],
                            j.kind.type_name()
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

    /// Allocates the slots of every body: coordinates, velocities, inertias, kinematics.
    pub(super) fn allocate(&mut self, plans: &[Plan]) -> Result<(), MechError> {
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
        for (bi, (b, plan)) in self.scene.bodies.iter().zip(plans).enumerate() {
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
        Ok(())
    }

    /// `K(q) v`, coordinate by coordinate.
    pub(super) fn kinematics(&mut self) -> Vec<Expr> {
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
}
