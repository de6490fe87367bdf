//! The columns a run writes and the names expressions may use: each body's standard columns
//! (`bar.x`, `bar.angle`, the spatial `psi`, `theta`, `phi`, `qw…qz`), its points
//! (`bar.A.x`, `bar.A.vy`), `energy`, the requested outputs and the scene's events — all as
//! expressions over the state layout `[t, q, v]`.

use std::collections::HashMap;

use super::body::BodyKinematics;
use super::error::MechError;
use super::system::{EventFunction, OutputColumn};
use crate::expr::{Expr, ExprGraph};
use crate::scene::{Dimension, Scene};

/// Builds columns over an expression arena for the bodies `kin` of `scene`.
pub(super) struct Columns<'a> {
    pub(super) g: &'a mut ExprGraph,
    pub(super) scene: &'a Scene,
    pub(super) kin: &'a [BodyKinematics],
    /// Number of coordinates.
    pub(super) nq: usize,
    /// Number of velocities.
    pub(super) nv: usize,
}

impl Columns<'_> {
    fn dim(&self) -> usize {
        if matches!(self.scene.dimension, Dimension::Spatial) {
            3
        } else {
            2
        }
    }

    /// The names an expression in a load or an output may use: `t` and every standard column
    /// and point coordinate (`crank.angle`, `bar2.A.x`, `bar2.A.vy`, …).
    pub(super) fn name_table(&mut self) -> Result<HashMap<String, Expr>, MechError> {
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
                let p = k.point(self.g, &pc);
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
        let g = &mut *self.g;
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

    pub(super) fn outputs(
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
        // the names so far, so that a repeated output is found without a scan (40 000 outputs)
        let mut have: std::collections::HashSet<String> =
            cols.iter().map(|c| c.name.clone()).collect();
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
                    if !have.insert(o.clone()) {
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
                        have.insert(n.clone());
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

    /// The scene's events as functions over the event layout `[t, q, v, reactions]`: `when`
    /// may name `t`, any standard column or point coordinate/velocity, `energy`, and any
    /// joint's reaction column and any driver's column (`motor.torque`).
    pub(super) fn events(
        &mut self,
        names: &HashMap<String, Expr>,
        energy: Expr,
        reaction_columns: &[String],
    ) -> Result<Vec<EventFunction>, MechError> {
        let base = 1 + self.nq + self.nv;
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

    /// The mechanical energy `T + V_stored + V_gravity`: the kinetic energy `½ Σ_j M_j v_j²`
    /// of the inertias, the energy `stored` in the bond graph's capacitors (the springs), and
    /// the weight's potential `−Σ_b m_b g·r_b`. Returns `(energy, kinetic)`.
    pub(super) fn energy(&mut self, mass: &[f64], stored: Expr) -> (Expr, Expr) {
        let mut terms = Vec::new();
        for (j, &m) in mass.iter().enumerate() {
            if m != 0.0 {
                let v = self.g.var((1 + self.nq + j) as u32);
                let v2 = self.g.mul(v, v);
                terms.push(self.g.scale(0.5 * m, v2));
            }
        }
        let kinetic = self.g.sum(&terms);
        let grav: Vec<f64> = (0..self.dim())
            .map(|k| self.scene.gravity.get(k).copied().unwrap_or(0.0))
            .collect();
        let mut potential = vec![kinetic, stored];
        if grav.iter().any(|&x| x != 0.0) {
            for (b, k) in self.scene.bodies.iter().zip(self.kin) {
                let r = k.centre_position(self.g);
                let w: Vec<Expr> = grav
                    .iter()
                    .map(|&gk| self.g.constant(-b.mass * gk))
                    .collect();
                potential.push(self.g.dot(&w, &r));
            }
        }
        (self.g.sum(&potential), kinetic)
    }
}
