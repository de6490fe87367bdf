//! The assembled oracle: generalized forces of a mechanism written directly from its bodies
//! (absolute coordinates, virtual power), independently of the bond graph the solver reads
//! them from. It was bondmech's equation path before the bond graph became the model
//! (`mech/assemble.rs`); it lives here as the reference the graph's equations are checked
//! against at random states.
//!
//! A force `F` (global frame) applied at a point `P` contributes `Q_j += F · ∂V_P/∂v_j`
//! (exact because `V_P` is linear in `v`); gravity `m g` at every centre; the gyroscopic
//! terms of a body-fixed planar frame (`m ω w`, `−m ω u`) and of a spatial body
//! (`−ω × J ω`); springs `F = −k d − c ḋ` (zero rest length) or along their axis; a torque on a
//! spatial body as `Rᵀ τ`. The potential energy `−Σ m g·r + Σ ½ k δ²` too.
#![allow(dead_code)]

use bondmech::expr::{Expr, ExprGraph};
use bondmech::mech::body::{cross3, BodyKinematics, PointKinematics};
use bondmech::mech::MultibodySystem;
use bondmech::scene::{Inertia, LoadKind, LoadValue, PointRef, Scene};
use std::collections::HashMap;

/// The oracle's forces `Q` and potential energy of `scene`, over the geometry `sys`
/// ([`bondmech::mech::geometry::geometry`]) and its expression arena.
pub fn assembled(scene: &Scene) -> (MultibodySystem, Expr) {
    let mut sys = bondmech::mech::geometry::geometry(scene).unwrap();
    let mut a = Oracle {
        scene,
        spatial: matches!(scene.dimension, bondmech::scene::Dimension::Spatial),
        nq: sys.nq(),
        nv: sys.nv(),
        kin: sys.bodies.iter().map(|(_, k)| k.clone()).collect(),
        names: sys.names.iter().cloned().collect(),
        x0: {
            let mut x = vec![0.0];
            x.extend(sys.initial_state());
            x
        },
        g: std::mem::take(&mut sys.graph),
    };
    let mut forces: Vec<Expr> = (0..a.nv).map(|_| a.g.zero()).collect();
    let mut potential = Vec::new();
    a.gravity(&mut forces, &mut potential);
    a.gyroscopic(&mut forces);
    a.springs(&mut forces, &mut potential);
    a.loads(&mut forces);
    let pot = a.g.sum(&potential);
    sys.graph = a.g;
    sys.forces = forces;
    (sys, pot)
}

struct Oracle<'a> {
    scene: &'a Scene,
    spatial: bool,
    nq: usize,
    nv: usize,
    kin: Vec<BodyKinematics>,
    names: HashMap<String, Expr>,
    x0: Vec<f64>,
    g: ExprGraph,
}

impl Oracle<'_> {
    fn dim(&self) -> usize {
        if self.spatial {
            3
        } else {
            2
        }
    }

    fn point(&mut self, body: &str, p: &PointRef) -> PointKinematics {
        let c: Vec<f64> = match p {
            PointRef::Coords(c) => c.clone(),
            PointRef::Named(n) => self
                .scene
                .bodies
                .iter()
                .find(|b| b.name == body)
                .and_then(|b| b.points.iter().find(|(pn, _)| pn == n))
                .map(|(_, c)| c.clone())
                .unwrap(),
        };
        let k = match self.scene.bodies.iter().position(|b| b.name == body) {
            None => BodyKinematics::Ground,
            Some(i) => self.kin[i].clone(),
        };
        k.point(&mut self.g, &c)
    }

    fn initial_slots(&self) -> Vec<f64> {
        self.x0.clone()
    }

    /// Adds `F · ∂V/∂v_j` to every generalized force.
    ///
    /// Only the velocities `V` mentions are visited (once per force, not once per velocity of
    /// the whole system: gravity on 6000 free bodies would otherwise take 10⁸ dependency walks).
    fn apply_force(&mut self, forces: &mut [Expr], velocity: &[Expr], f: &[Expr]) {
        let first = (1 + self.nq) as u32;
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
        let nq = self.nq as u32;
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

    fn springs(&mut self, forces: &mut [Expr], potential: &mut Vec<Expr>) {
        for sp in self.scene.springs.iter() {
            let pa = self.point(&sp.bodies[0], &sp.points[0]);
            let pb = self.point(&sp.bodies[1], &sp.points[1]);
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
    }

    /// Forces and torques of the loads (constant, tabulated or expressions of the scene's names).
    fn loads(&mut self, forces: &mut [Expr]) {
        for l in self.scene.loads.iter() {
            let Some(bi) = self.scene.bodies.iter().position(|b| b.name == l.body) else {
                continue;
            };
            let n = match l.kind {
                LoadKind::Force => self.dim(),
                LoadKind::Torque if self.spatial => 3,
                LoadKind::Torque => 1,
            };
            let f = self.value(&l.value, n);
            match l.kind {
                LoadKind::Force => {
                    let p = match &l.point {
                        Some(p) => self.point(&l.body, p),
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
                    let nq = self.nq as u32;
                    match self.kin[bi].clone() {
                        BodyKinematics::Spatial { w, .. } => {
                            // body torque = Rᵀ τ
                            let rot = self.kin[bi].rotation3(&mut self.g);
                            for k in 0..3 {
                                let col: Vec<Expr> = (0..3).map(|i| rot[i][k]).collect();
                                let tb = self.g.dot(&col, &f);
                                let idx = (w[k] - 1 - nq) as usize;
                                forces[idx] = self.g.add(forces[idx], tb);
                            }
                        }
                        BodyKinematics::PlanarInertial { omega: Some(w), .. }
                        | BodyKinematics::PlanarBodyFixed { omega: w, .. } => {
                            let idx = (w - 1 - nq) as usize;
                            forces[idx] = self.g.add(forces[idx], f[0]);
                        }
                        _ => panic!("load '{}' on a body without rotation", l.name),
                    }
                }
            }
        }
    }

    fn value(&mut self, value: &LoadValue, n: usize) -> Vec<Expr> {
        match value {
            LoadValue::Const(v) => v.iter().map(|&c| self.g.constant(c)).collect(),
            LoadValue::Table { t, v } => (0..n)
                .map(|k| {
                    let col: Vec<f64> = v.iter().map(|row| row[k]).collect();
                    let tv = self.g.var(0);
                    self.g.table(t, &col, tv)
                })
                .collect(),
            LoadValue::Expr(src) => src
                .iter()
                .map(|s| {
                    let names = &self.names;
                    self.g
                        .parse(s, &mut |name| names.get(name).copied())
                        .unwrap()
                })
                .collect(),
        }
    }
}
