//! Joints: each kind owns its position-level closure rows `g_k(q) = 0` (seed 16.5, 16.7).
//!
//! The closure of a row is what its constraint junction in the bond graph integrates: the
//! junction's flow constraint is `d/dt g_k = G_k v`, which [`crate::bond::mechanics`] checks
//! at build time. The rows of a joint, by kind:
//!
//! * [`revolute`]: a revolute (planar pin) or spherical joint, the points coincide,
//!   `P_a − P_b = 0` per axis (Fig. 16's 1-junctions `V_A1 = V_A2`);
//! * [`hinge`]: a spatial hinge, the points coincide and the axis is shared;
//! * [`prismatic`]: the second point stays on the first body's line, the relative rotation fixed;
//! * [`weld`]: the points coincide and the relative rotation is fixed.
//!
//! Each joint's reaction (its force and moment on the second body) is read from the
//! multipliers of its rows ([`JointReaction`]).

mod hinge;
mod prismatic;
mod revolute;
mod weld;

use super::body::{BodyKinematics, PointKinematics};
use super::geometry::Geometry;
use super::reactions::{transmits_moment, JointReaction};
use super::system::ConstraintRow;
use super::MechError;
use crate::expr::Expr;
use crate::scene::JointKind;

/// The rows of one joint: `(direction, g_k(q))`.
type Rows = Vec<(&'static str, Expr)>;

/// Both ends of a joint: the bodies' kinematics and the points' positions and velocities.
struct Ends {
    ka: BodyKinematics,
    kb: BodyKinematics,
    pa: PointKinematics,
    pb: PointKinematics,
}

impl Geometry<'_> {
    /// Every joint's closure rows, their names, and how its reaction is read.
    #[allow(clippy::type_complexity)]
    pub(super) fn joints(
        &mut self,
    ) -> Result<(Vec<Expr>, Vec<ConstraintRow>, Vec<JointReaction>), MechError> {
        let mut g_rows = Vec::new();
        let mut meta = Vec::new();
        let mut reactions = Vec::new();
        for (ji, j) in self.scene.joints.iter().enumerate() {
            let first_row = g_rows.len();
            let path = format!("joints[{ji}]");
            let ends = Ends {
                pa: self.point(&j.bodies[0], &j.points[0], &format!("{path}.points[0]"))?,
                pb: self.point(&j.bodies[1], &j.points[1], &format!("{path}.points[1]"))?,
                ka: self.kin_of(&j.bodies[0], &path)?,
                kb: self.kin_of(&j.bodies[1], &path)?,
            };
            let rows = match &j.kind {
                JointKind::Hinge { axis } => self.hinge(&ends, axis, &path)?,
                JointKind::Revolute | JointKind::Spherical => {
                    self.revolute(&ends, &j.kind, &path)?
                }
                JointKind::Prismatic { axis } => self.prismatic(&ends, axis, &path)?,
                JointKind::Weld => self.weld(&ends),
            };
            for (dir, e) in rows {
                g_rows.push(e);
                meta.push(ConstraintRow {
                    joint: j.name.clone(),
                    direction: dir.to_string(),
                });
            }
            let rows = first_row..g_rows.len();
            reactions.push(self.joint_reaction(&j.name, &j.kind, &ends, rows));
        }
        Ok((g_rows, meta, reactions))
    }

    /// `P_a − P_b` per axis: the rows of two coinciding points.
    fn coincident(&mut self, ends: &Ends) -> Rows {
        let axes = ["x", "y", "z"];
        (0..ends.pa.position.len())
            .map(|k| {
                (
                    axes[k],
                    self.g.sub(ends.pa.position[k], ends.pb.position[k]),
                )
            })
            .collect()
    }

    /// How joint `j`'s reaction is read: the carrier body (second, or first when the second
    /// is ground), its velocities, `B = ∂(V_P, ω)/∂v_b` and the lever `P_1 − P_2`.
    fn joint_reaction(
        &mut self,
        name: &str,
        kind: &JointKind,
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
            moment: transmits_moment(kind),
            basis,
            lever,
        }
    }
}

/// An orthonormal pair `(c_1, c_2)` perpendicular to the non-zero vector `a`.
/// The unit vector along a joint's `axis` (a non-zero, finite 3D direction), or an error at
/// `<path>.axis`.
pub(super) fn unit_axis(axis: &[f64], path: &str) -> Result<[f64; 3], MechError> {
    let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
    if axis.len() != 3 || !norm.is_finite() || norm <= 0.0 {
        return Err(MechError::at(
            &format!("{path}.axis"),
            "needs a non-zero 3D direction",
        ));
    }
    Ok([axis[0] / norm, axis[1] / norm, axis[2] / norm])
}

pub(super) fn perpendicular_pair(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
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
