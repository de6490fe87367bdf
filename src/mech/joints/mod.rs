//! Joints as types: each kind is one file holding a type that implements `Joint`, and
//! `joint_type` is the one dispatch from the scene's [`JointKind`] to it.
//!
//! A kind owns, in its file: its closure rows `g_k(q) = 0` over the bodies' coordinates (seed
//! 16.5, 16.7), its planar bond-graph fragment (the chapter's, when it draws one; otherwise
//! [`crate::mech::annotate`] draws the closure's rate as a modulated sum `Σ_j (∂ġ_k/∂v_j) f_j`
//! of the inertias' junction flows into an `Sf = 0`), how many rows it locks, which of its
//! bodies need a modelled rotation, whether its reaction carries a moment, and the glyph it is
//! drawn with. The scene side of a kind (its
//! `"type"` and own fields) is [`crate::scene::joint_kind`].
//!
//! The closure of a row is what its constraint junction in the bond graph integrates: the
//! junction's flow constraint is `d/dt g_k = G_k v`, which [`crate::bond::mechanics`] checks
//! at build time. The twin ([`crate::bond::decouple`]) opens every constraint junction and puts
//! in a C of compliance `1/k` whose displacement is the row's closure `g_k`, so each kind's
//! twin spring is `k·g_k` along its own rows.
//!
//! Each joint's reaction (its force and moment on the second body) is read from the
//! multipliers of its rows ([`JointReaction`]).

mod gear;
mod hinge;
mod prismatic;
mod rack_pinion;
mod revolute;
mod slot;
mod spherical;
mod universal;
mod weld;

use super::body::{BodyKinematics, PointKinematics};
use super::geometry::Geometry;
use super::reactions::JointReaction;
use super::system::ConstraintRow;
use super::MechError;
use crate::bond::fragments::{change_frame, pin_to_ground, revolute, PointJunctions};
use crate::bond::model::{BondGraph, ElementId};
use crate::expr::Expr;
use crate::scene::JointKind;

/// The rows of one joint: `(direction, g_k(q))`.
type Rows = Vec<(&'static str, Expr)>;

/// Both ends of a joint: the bodies' kinematics and the points' positions and velocities.
pub(super) struct Ends {
    pub(super) ka: BodyKinematics,
    pub(super) kb: BodyKinematics,
    pub(super) pa: PointKinematics,
    pub(super) pb: PointKinematics,
}

/// How a joint is drawn in pictures and animations.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Glyph {
    /// A pin (planar revolute): a dot on the joint point.
    Pin,
    /// A ball joint: a dot.
    Ball,
    /// A weld: a square.
    Weld,
    /// A rail along `axis` (the first body's frame) with a block on the second body's point.
    Slider {
        /// The rail's direction in the first body's frame.
        axis: Vec<f64>,
    },
    /// A spatial hinge about `axis` (the first body's frame).
    Hinge {
        /// The hinge axis in the first body's frame.
        axis: Vec<f64>,
    },
}

/// What a joint kind is: one implementation per file, chosen by [`joint_type`].
pub(super) trait Joint {
    /// The closure rows `(direction, g_k(q))` of the joint between `ends`; `path` is the
    /// joint's JSON path (errors name it).
    fn rows(&self, geo: &mut Geometry<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError>;

    /// How many rows the joint locks (at most; for size estimates).
    fn locks(&self, spatial: bool) -> usize;

    /// Whether the reaction has moment columns (the joint fixes a relative rotation).
    fn transmits_moment(&self) -> bool;

    /// Whether body `end` (0 or 1) needs its rotation modelled (a planar body's angle even
    /// when it has no inertia; a spatial body not a point mass).
    fn needs_rotation(&self, end: usize, spatial: bool) -> bool {
        let _ = (end, spatial);
        false
    }

    /// The planar fragment the seed draws for the joint (16.5, 16.7, Fig. 29), named
    /// `<joint>.<direction>` so that its constraint junctions carry the rows' closures;
    /// nothing when the joint's rows are drawn as modulated sums of their rates.
    fn draw(&self, d: &mut Drawing<'_>) -> Result<(), MechError> {
        let _ = d;
        Ok(())
    }

    /// How the joint is drawn.
    fn glyph(&self) -> Glyph;
}

/// The one dispatch from a scene's joint kind to its type.
pub(super) fn joint_type(kind: &JointKind) -> Box<dyn Joint + '_> {
    match kind {
        JointKind::Revolute => Box::new(revolute::Revolute),
        JointKind::Spherical => Box::new(spherical::Spherical),
        JointKind::Hinge { axis } => Box::new(hinge::Hinge { axis }),
        JointKind::Prismatic { axis } => Box::new(prismatic::Prismatic { axis }),
        JointKind::Weld => Box::new(weld::Weld),
        JointKind::Universal { axes } => Box::new(universal::Universal { axes }),
        JointKind::Gear { ratio } => Box::new(gear::Gear { ratio: *ratio }),
        JointKind::Slot { axis } => Box::new(slot::Slot { axis }),
        JointKind::RackPinion { radius, axis } => Box::new(rack_pinion::RackPinion {
            radius: *radius,
            axis,
        }),
    }
}

/// How a joint of kind `kind` is drawn.
pub fn glyph(kind: &JointKind) -> Glyph {
    joint_type(kind).glyph()
}

/// Rows a joint of kind `kind` locks (at most), planar or `spatial`.
pub(super) fn locks(kind: &JointKind, spatial: bool) -> usize {
    joint_type(kind).locks(spatial)
}

/// Whether a joint of kind `kind` needs body `end`'s rotation modelled.
pub(super) fn needs_rotation(kind: &JointKind, end: usize, spatial: bool) -> bool {
    joint_type(kind).needs_rotation(end, spatial)
}

/// What a joint's planar fragment is drawn from: the graph, the joint's name and JSON path,
/// its bodies' point junctions (each in its body's frame; `None` for ground), the angle
/// variable of each body drawn in its body-fixed frame, each body's ω junction, and whether
/// the joints [`crate::mech::annotate`] completes are left open.
pub(crate) struct Drawing<'a> {
    pub(crate) g: &'a mut BondGraph,
    pub(crate) name: &'a str,
    pub(crate) path: &'a str,
    pub(crate) bodies: [&'a str; 2],
    pub(crate) points: [Option<PointJunctions>; 2],
    pub(crate) frames: [Option<String>; 2],
    pub(crate) omegas: [Option<ElementId>; 2],
    pub(crate) open: bool,
}

/// A joint's two ends in one frame: the first moving point, the other (`None`: ground), the
/// index (0 or 1) of the body each belongs to, and whether the ground is the first body.
pub(crate) struct DrawnEnds {
    pub(crate) p1: PointJunctions,
    pub(crate) p2: Option<PointJunctions>,
    pub(crate) b1: usize,
    pub(crate) b2: Option<usize>,
    pub(crate) ground_first: bool,
}

impl Drawing<'_> {
    /// The joint draws itself: [`Joint::draw`] of its kind.
    pub(crate) fn draw(&mut self, kind: &JointKind) -> Result<(), MechError> {
        joint_type(kind).draw(self)
    }

    /// The two points in one frame (see [`common_frame`]; `global` forces the global frame);
    /// with `pin`, a point pinned to the ground stays in its body's frame (a pin to ground is
    /// `Sf = 0` in any frame).
    pub(crate) fn ends(&mut self, global: bool, pin: bool) -> Result<DrawnEnds, MechError> {
        let [pa, pb] = self.points.clone();
        let (pa, pb) = if pin && (pa.is_none() || pb.is_none()) {
            (pa, pb)
        } else {
            common_frame(
                self.g,
                self.name,
                self.bodies,
                [pa, pb],
                self.frames.clone(),
                global,
            )
        };
        let ground_first = pa.is_none();
        match (pa, pb) {
            (None, Some(p)) => Ok(DrawnEnds {
                p1: p,
                p2: None,
                b1: 1,
                b2: None,
                ground_first,
            }),
            (Some(p), None) => Ok(DrawnEnds {
                p1: p,
                p2: None,
                b1: 0,
                b2: None,
                ground_first,
            }),
            (Some(a), Some(b)) => Ok(DrawnEnds {
                p1: a,
                p2: Some(b),
                b1: 0,
                b2: Some(1),
                ground_first,
            }),
            (None, None) => Err(MechError::at(
                self.path,
                "a joint between ground and ground",
            )),
        }
    }

    /// A pin's fragment on drawn ends: two 1-junctions equating the points' velocities
    /// (16.5, Fig. 16), or `Sf = 0` on a point pinned to the ground (16.7).
    pub(crate) fn pin(&mut self, e: &DrawnEnds) {
        match &e.p2 {
            None => pin_to_ground(self.g, self.name, &e.p1, e.ground_first),
            Some(p2) => revolute(self.g, self.name, &e.p1, p2),
        }
    }
}

/// Brings the two points of a joint or spring into one frame, so that its 1-junctions equate
/// components along the same axes (seed 16.4–16.5, Fig. 9–10 and 15): between two
/// body-fixed bars (`frames`: each body's angle variable when it is body-fixed) the point of
/// the first is changed into the frame of the second through the MTF pair [`change_frame`]
/// modulated by the relative angle `α_b − α_a` (`<name>.<body a>.<point>.in_<body b>`);
/// otherwise (`global`, or one side non-rotating or ground) each body-fixed point is changed
/// into the global frame with the angle `−α` (`<name>.<body>.<point>.in_global`). Points of
/// non-rotating bodies are global already.
pub(crate) fn common_frame(
    g: &mut BondGraph,
    name: &str,
    bodies: [&str; 2],
    points: [Option<PointJunctions>; 2],
    frames: [Option<String>; 2],
    global: bool,
) -> (Option<PointJunctions>, Option<PointJunctions>) {
    let [fa, fb] = frames;
    let [pa, pb] = points;
    match (pa, pb, fa, fb) {
        (Some(pa), Some(pb), Some(aa), Some(ab)) if !global => {
            let n = format!("{name}.{}.in_{}", pa.name, bodies[1]);
            let pa = change_frame(g, &n, &pa, &format!("{ab} - {aa}"));
            (Some(pa), Some(pb))
        }
        (pa, pb, fa, fb) => {
            let mut to_global = |p: Option<PointJunctions>, f: Option<String>| match (p, f) {
                (Some(p), Some(a)) => Some(change_frame(
                    g,
                    &format!("{name}.{}.in_global", p.name),
                    &p,
                    &format!("-{a}"),
                )),
                (p, _) => p,
            };
            let pa = to_global(pa, fa);
            (pa, to_global(pb, fb))
        }
    }
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
            let joint = joint_type(&j.kind);
            let rows = joint.rows(self, &ends, &path)?;
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

    /// `P_a − P_b` per axis: the rows of two coinciding points.
    pub(super) fn coincident(&mut self, ends: &Ends) -> Rows {
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
