//! Kinematics of one body: where its points are and how fast they move, as expressions.
//!
//! * Planar body, non-rotating frame at the centre of mass (seed 16.8, Fig. 22–25), the default:
//!   coordinates `(x, y, α)`, velocities `(v_x, v_y, ω)` in the global frame, and for a point `P`
//!   with body coordinates `s`: `r_P = r + R(α) s`, `V_P = V_O + ω × R(α) s`, i.e.
//!   `V_Px = V_Ox − ω (s_x sin α + s_y cos α)`, `V_Py = V_Oy + ω (s_x cos α − s_y sin α)`.
//! * Planar body, body-fixed frame (seed 16.3, Fig. 5–7): velocities `(u, w, ω)` along the body
//!   axes, `(x, y)' = R(α)(u, w)`, and the single MGY between `v_x` and `v_y`:
//!   `m u' = F_x + m ω w`, `m w' = F_y − m ω u`.
//! * Spatial body (seed 16.1–16.2): position `r`, attitude quaternion `e` (never singular, unlike
//!   the Cardan rates that divide by cos θ), global velocity `V`, body angular velocity `ω`;
//!   `e' = ½ e ⊗ (0, ω)`, `R(e)` the rotation of the normalised quaternion, and the Euler
//!   junction structure as the gyroscopic torque `−ω × Jω`.

use crate::expr::{Expr, ExprGraph};

/// How a body's state is represented.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyKinematics {
    /// The fixed body.
    Ground,
    /// Planar body, global (non-rotating) frame.
    PlanarInertial {
        /// slots of x, y
        x: u32,
        /// slot of y
        y: u32,
        /// slot of the angle, or its constant value when the rotation is not modelled
        angle: AngleSlot,
        /// slots of vx, vy, ω (ω absent when the rotation is not modelled)
        vx: u32,
        /// slot of vy
        vy: u32,
        /// slot of ω
        omega: Option<u32>,
    },
    /// Planar body, body-fixed frame (the rotation is always modelled).
    PlanarBodyFixed {
        /// slot of x
        x: u32,
        /// slot of y
        y: u32,
        /// slot of α
        angle: u32,
        /// slot of u (velocity along body x)
        u: u32,
        /// slot of w (velocity along body y)
        w: u32,
        /// slot of ω
        omega: u32,
    },
    /// Spatial point mass (principal moments [0, 0, 0], every used point at its centre):
    /// translation only, `r' = V`, `m V' = F`; no attitude, no rotational states.
    Particle {
        /// slots of x, y, z
        r: [u32; 3],
        /// slots of global velocity
        v: [u32; 3],
    },
    /// Spatial rigid body.
    Spatial {
        /// slots of x, y, z
        r: [u32; 3],
        /// slots of the quaternion e0..e3
        e: [u32; 4],
        /// slots of global velocity
        v: [u32; 3],
        /// slots of body angular velocity
        w: [u32; 3],
    },
}

/// The angle of a planar body: a coordinate, or a constant when nothing needs the rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AngleSlot {
    /// Modelled: the slot of α.
    Coordinate(u32),
    /// Not modelled: α stays at this value.
    Fixed(f64),
}

/// Expressions of a body's point position and velocity (2 or 3 components).
#[derive(Clone, Debug)]
pub struct PointKinematics {
    /// Global position.
    pub position: Vec<Expr>,
    /// Global velocity.
    pub velocity: Vec<Expr>,
}

impl BodyKinematics {
    /// Angle expression of a planar body (constant for ground and unmodelled rotations).
    pub fn planar_angle(&self, g: &mut ExprGraph) -> Expr {
        match self {
            BodyKinematics::Ground => g.zero(),
            BodyKinematics::PlanarInertial { angle, .. } => match angle {
                AngleSlot::Coordinate(s) => g.var(*s),
                AngleSlot::Fixed(a) => g.constant(*a),
            },
            BodyKinematics::PlanarBodyFixed { angle, .. } => g.var(*angle),
            BodyKinematics::Spatial { .. } | BodyKinematics::Particle { .. } => g.zero(),
        }
    }

    /// Angular velocity ω of a planar body.
    pub fn planar_omega(&self, g: &mut ExprGraph) -> Expr {
        match self {
            BodyKinematics::PlanarInertial { omega: Some(w), .. } => g.var(*w),
            BodyKinematics::PlanarBodyFixed { omega, .. } => g.var(*omega),
            _ => g.zero(),
        }
    }

    /// Rotation matrix (row-major 3×3) of a spatial body, from its normalised quaternion:
    /// `R = I + 2/|e|² [[−(e2²+e3²), e1e2−e0e3, e1e3+e0e2], …]`.
    pub fn rotation3(&self, g: &mut ExprGraph) -> [[Expr; 3]; 3] {
        let e = match self {
            BodyKinematics::Spatial { e, .. } => e.map(|s| g.var(s)),
            _ => {
                let (z, o) = (g.zero(), g.one());
                return [[o, z, z], [z, o, z], [z, z, o]];
            }
        };
        let sq: Vec<Expr> = e.iter().map(|&x| g.mul(x, x)).collect();
        let norm2 = g.sum(&sq);
        let two = g.constant(2.0);
        let s = g.div(two, norm2);
        let p = |g: &mut ExprGraph, a: usize, b: usize| g.mul(e[a], e[b]);
        let one = g.one();
        let diag = |g: &mut ExprGraph, a: usize, b: usize| {
            let t = g.add(sq[a], sq[b]);
            let t = g.mul(s, t);
            g.sub(one, t)
        };
        let off = |g: &mut ExprGraph, a: (usize, usize), b: (usize, usize), plus: bool| {
            let x = p(g, a.0, a.1);
            let y = p(g, b.0, b.1);
            let t = if plus { g.add(x, y) } else { g.sub(x, y) };
            g.mul(s, t)
        };
        let r00 = diag(g, 2, 3);
        let r01 = off(g, (1, 2), (0, 3), false);
        let r02 = off(g, (1, 3), (0, 2), true);
        let r10 = off(g, (1, 2), (0, 3), true);
        let r11 = diag(g, 1, 3);
        let r12 = off(g, (2, 3), (0, 1), false);
        let r20 = off(g, (1, 3), (0, 2), false);
        let r21 = off(g, (2, 3), (0, 1), true);
        let r22 = diag(g, 1, 2);
        [[r00, r01, r02], [r10, r11, r12], [r20, r21, r22]]
    }

    /// Position and global velocity of the point with body coordinates `s`
    /// (for ground, `s` are global coordinates and the velocity is zero).
    pub fn point(&self, g: &mut ExprGraph, s: &[f64]) -> PointKinematics {
        match self {
            BodyKinematics::Ground => {
                let position = s.iter().map(|&c| g.constant(c)).collect();
                let velocity = s.iter().map(|_| g.zero()).collect();
                PointKinematics { position, velocity }
            }
            BodyKinematics::PlanarInertial { x, y, vx, vy, .. } => {
                let (rx, ry) = self.rotated2(g, s);
                let (xe, ye) = (g.var(*x), g.var(*y));
                let px = g.add(xe, rx);
                let py = g.add(ye, ry);
                let w = self.planar_omega(g);
                // V_P = V_O + ω × (R s) = (vx − ω ry, vy + ω rx)
                let (vxe, vye) = (g.var(*vx), g.var(*vy));
                planar_point(g, (px, py), (vxe, vye), w, (rx, ry))
            }
            BodyKinematics::PlanarBodyFixed { x, y, u, w, .. } => {
                let (rx, ry) = self.rotated2(g, s);
                let (xe, ye) = (g.var(*x), g.var(*y));
                let px = g.add(xe, rx);
                let py = g.add(ye, ry);
                let (vcx, vcy) = self.centre_velocity_body_fixed(g, *u, *w);
                let om = self.planar_omega(g);
                planar_point(g, (px, py), (vcx, vcy), om, (rx, ry))
            }
            BodyKinematics::Particle { r, v } => {
                // every point of a particle is at its centre (checked when assembling)
                let position = (0..3)
                    .map(|i| {
                        let ri = g.var(r[i]);
                        let si = g.constant(s[i]);
                        g.add(ri, si)
                    })
                    .collect();
                let velocity = v.iter().map(|&k| g.var(k)).collect();
                PointKinematics { position, velocity }
            }
            BodyKinematics::Spatial { r, v, w, .. } => {
                let rot = self.rotation3(g);
                let sc: Vec<Expr> = s.iter().map(|&c| g.constant(c)).collect();
                // ω × s in body axes
                let we: Vec<Expr> = w.iter().map(|&k| g.var(k)).collect();
                let cross = cross3(g, &we, &sc);
                let mut position = Vec::with_capacity(3);
                let mut velocity = Vec::with_capacity(3);
                for i in 0..3 {
                    let rs = g.dot(&rot[i], &sc);
                    let ri = g.var(r[i]);
                    position.push(g.add(ri, rs));
                    let rw = g.dot(&rot[i], &cross);
                    let vi = g.var(v[i]);
                    velocity.push(g.add(vi, rw));
                }
                PointKinematics { position, velocity }
            }
        }
    }

    /// `R(α) s` for a planar body.
    fn rotated2(&self, g: &mut ExprGraph, s: &[f64]) -> (Expr, Expr) {
        let a = self.planar_angle(g);
        if let Some(av) = g.as_const(a) {
            let (sn, cs) = av.sin_cos();
            let rx = g.constant(s[0] * cs - s[1] * sn);
            let ry = g.constant(s[0] * sn + s[1] * cs);
            return (rx, ry);
        }
        let (c, sn) = (g.cos(a), g.sin(a));
        let rx = {
            let t1 = g.scale(s[0], c);
            let t2 = g.scale(s[1], sn);
            g.sub(t1, t2)
        };
        let ry = {
            let t1 = g.scale(s[0], sn);
            let t2 = g.scale(s[1], c);
            g.add(t1, t2)
        };
        (rx, ry)
    }

    /// Global velocity of the centre of a body-fixed-frame planar body: `R(α)(u, w)`.
    fn centre_velocity_body_fixed(&self, g: &mut ExprGraph, u: u32, w: u32) -> (Expr, Expr) {
        let a = self.planar_angle(g);
        let (c, sn) = (g.cos(a), g.sin(a));
        let (ue, we) = (g.var(u), g.var(w));
        let uc = g.mul(ue, c);
        let ws = g.mul(we, sn);
        let us = g.mul(ue, sn);
        let wc = g.mul(we, c);
        (g.sub(uc, ws), g.add(us, wc))
    }

    /// Global velocity of the centre of mass.
    pub fn centre_velocity(&self, g: &mut ExprGraph) -> Vec<Expr> {
        match self {
            BodyKinematics::Ground => vec![],
            BodyKinematics::PlanarInertial { vx, vy, .. } => vec![g.var(*vx), g.var(*vy)],
            BodyKinematics::PlanarBodyFixed { u, w, .. } => {
                let (a, b) = self.centre_velocity_body_fixed(g, *u, *w);
                vec![a, b]
            }
            BodyKinematics::Spatial { v, .. } | BodyKinematics::Particle { v, .. } => {
                v.iter().map(|&k| g.var(k)).collect()
            }
        }
    }

    /// Global position of the centre of mass.
    pub fn centre_position(&self, g: &mut ExprGraph) -> Vec<Expr> {
        match self {
            BodyKinematics::Ground => vec![],
            BodyKinematics::PlanarInertial { x, y, .. }
            | BodyKinematics::PlanarBodyFixed { x, y, .. } => vec![g.var(*x), g.var(*y)],
            BodyKinematics::Spatial { r, .. } | BodyKinematics::Particle { r, .. } => {
                r.iter().map(|&k| g.var(k)).collect()
            }
        }
    }
}

/// `a × b` for 3-vectors of expressions.
pub fn cross3(g: &mut ExprGraph, a: &[Expr], b: &[Expr]) -> Vec<Expr> {
    let mut c = Vec::with_capacity(3);
    for (i, j) in [(1usize, 2usize), (2, 0), (0, 1)] {
        let p = g.mul(a[i], b[j]);
        let q = g.mul(a[j], b[i]);
        c.push(g.sub(p, q));
    }
    c
}

/// Quaternion `e = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)` of the Cardan rotation `R = Ψ Θ Φ` (seed 16.2).
pub fn quaternion_from_cardan(psi: f64, theta: f64, phi: f64) -> [f64; 4] {
    let (sz, cz) = (psi / 2.0).sin_cos();
    let (sy, cy) = (theta / 2.0).sin_cos();
    let (sx, cx) = (phi / 2.0).sin_cos();
    [
        cz * cy * cx + sz * sy * sx,
        cz * cy * sx - sz * sy * cx,
        cz * sy * cx + sz * cy * sx,
        sz * cy * cx - cz * sy * sx,
    ]
}

/// The planar point at `p = (px, py)` of a body whose origin moves with `v = (vx, vy)` and turns
/// at `ω`, its offset rotated into the ground frame `R s = (rx, ry)`:
/// `V_P = V_O + ω × (R s) = (vx − ω ry, vy + ω rx)`.
fn planar_point(
    g: &mut ExprGraph,
    p: (Expr, Expr),
    v: (Expr, Expr),
    w: Expr,
    (rx, ry): (Expr, Expr),
) -> PointKinematics {
    let wry = g.mul(w, ry);
    let wrx = g.mul(w, rx);
    let pvx = g.sub(v.0, wry);
    let pvy = g.add(v.1, wrx);
    PointKinematics {
        position: vec![p.0, p.1],
        velocity: vec![pvx, pvy],
    }
}
