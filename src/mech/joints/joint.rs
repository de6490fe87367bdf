//! What every joint kind is written with: the [`Joint`] trait each kind's file implements,
//! the joint's two [`Ends`], the [`RowWriter`] its closure rows `g_k(q)` are written on (the
//! expression arena, the scene's dimension and the initial slot values), the [`Drawing`] its
//! planar fragment is drawn on, and the rows several kinds share (coinciding points, a fixed
//! relative angle or rotation).
//!
//! This module sits below the kinds' files and below the dispatch ([`super::joint_type`]); it
//! knows no kind.

use crate::bond::fragments::{change_frame, pin_to_ground, revolute, PointJunctions};
use crate::bond::model::{BondGraph, ElementId};
use crate::expr::{Expr, ExprGraph};
use crate::mech::body::{AngleSlot, BodyKinematics, PointKinematics};
use crate::mech::error::MechError;

/// The rows of one joint: `(direction, g_k(q))`.
pub(crate) type Rows = Vec<(&'static str, Expr)>;

/// Both ends of a joint: the bodies' kinematics and the points' positions and velocities.
pub(crate) struct Ends {
    pub(crate) ka: BodyKinematics,
    pub(crate) kb: BodyKinematics,
    pub(crate) pa: PointKinematics,
    pub(crate) pb: PointKinematics,
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

/// The coordinate `s(q)` a driver moves along its joint (`drivers[i]`, seed 16.8: a flow
/// source on the joint's relative flow, written as the row `s(q) − s(t) = 0`).
pub(crate) enum DrivenCoordinate {
    /// A relative angle or displacement `s(q)`.
    Linear(Expr),
    /// A turn `φ` about an axis, as `(cos φ, sin φ)` (the row is written smooth through every
    /// turn).
    Turn {
        /// `cos φ`.
        cos: Expr,
        /// `sin φ`.
        sin: Expr,
    },
}

/// What [`Joint::driven_coordinate`] answers: the coordinate, or `None` where the kind takes no
/// driver.
pub(crate) type Driven = Result<Option<DrivenCoordinate>, MechError>;

/// Where a driver is: its joint's two ends, and for the errors its coordinate names the
/// driver's and its joint's JSON paths, the joint's name and its bodies.
pub(crate) struct DriverSite<'a> {
    /// The joint's ends.
    pub(crate) ends: &'a Ends,
    /// `drivers[i]`.
    pub(crate) path: &'a str,
    /// `joints[j]`.
    pub(crate) joint_path: &'a str,
    /// The joint's name.
    pub(crate) joint: &'a str,
    /// The joint's bodies.
    pub(crate) bodies: [&'a str; 2],
}

/// What a joint kind is: one implementation per file, chosen by [`super::joint_type`].
pub(crate) trait Joint {
    /// The closure rows `(direction, g_k(q))` of the joint between `ends`; `path` is the
    /// joint's JSON path (errors name it).
    fn rows(&self, w: &mut RowWriter<'_>, ends: &Ends, path: &str) -> Result<Rows, MechError>;

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

    /// The coordinate a driver of this joint moves, written on `w` between the ends of
    /// `site`; `None` where the kind takes no driver (default).
    fn driven_coordinate(&self, w: &mut RowWriter<'_>, site: &DriverSite<'_>) -> Driven {
        let _ = (w, site);
        Ok(None)
    }
}

/// What a joint's closure rows are written on: the expression arena over the slots
/// `[t, q, v]`, whether the scene is spatial, and the slots' initial values `x0` (rows that
/// keep an initial relative pose are written as `h(q) − h(q(0))`).
pub(crate) struct RowWriter<'a> {
    pub(crate) g: &'a mut ExprGraph,
    pub(crate) spatial: bool,
    pub(crate) x0: &'a [f64],
}

impl RowWriter<'_> {
    /// `P_a − P_b` per axis: the rows of two coinciding points.
    pub(crate) fn coincident(&mut self, ends: &Ends) -> Rows {
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

    /// `α_b − α_a − (α_b0 − α_a0)`, when both angles are modelled (or ground).
    pub(crate) fn relative_angle_row(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
    ) -> Option<Expr> {
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
        let aa = ka.planar_angle(self.g);
        let ab = kb.planar_angle(self.g);
        let rel0 = self.g.eval(ab, self.x0) - self.g.eval(aa, self.x0);
        let d = self.g.sub(ab, aa);
        let c = self.g.constant(rel0);
        Some(self.g.sub(d, c))
    }

    /// Orientation rows of a spatial weld: the skew part of `C = R0ᵀ R_aᵀ R_b`.
    pub(crate) fn relative_rotation_rows(
        &mut self,
        ka: &BodyKinematics,
        kb: &BodyKinematics,
    ) -> Rows {
        let ra = ka.rotation3(self.g);
        let rb = kb.rotation3(self.g);
        let mut rel = [[self.g.zero(); 3]; 3];
        let mut rel0 = [[0.0; 3]; 3];
        for i in 0..3 {
            for k in 0..3 {
                let ca: Vec<Expr> = (0..3).map(|m| ra[m][i]).collect();
                let cb: Vec<Expr> = (0..3).map(|m| rb[m][k]).collect();
                rel[i][k] = self.g.dot(&ca, &cb);
                rel0[i][k] = self.g.eval(rel[i][k], self.x0);
            }
        }
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

/// The unit vector along a joint's `axis` (a non-zero, finite 3D direction), or an error at
/// `<path>.axis`.
pub(crate) fn unit_axis(axis: &[f64], path: &str) -> Result<[f64; 3], MechError> {
    let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
    if axis.len() != 3 || !norm.is_finite() || norm <= 0.0 {
        return Err(MechError::at(
            &format!("{path}.axis"),
            "needs a non-zero 3D direction",
        ));
    }
    Ok([axis[0] / norm, axis[1] / norm, axis[2] / norm])
}

/// An orthonormal pair `(c_1, c_2)` perpendicular to the non-zero vector `a`.
pub(crate) fn perpendicular_pair(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
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
