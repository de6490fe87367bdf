//! Animations of a solved motion (`bondmech animate`): one self-contained file, an SVG animated
//! with SMIL or an HTML page with the same SVG inline and a few lines of script for its
//! controls. Nothing is fetched from the network.
//!
//! What is drawn, from the scene and the solution's columns (`b.x, b.y, b.angle` for a planar
//! body; `b.x, b.y, b.z` and the attitude — the quaternion `b.qw…b.qz`, or else the Cardan
//! angles `b.psi, b.theta, b.phi` — for a spatial one):
//! - each body (colours from [`body_colour`], which do not repeat within 60 bodies) as arms
//!   from its centre of mass to each of its points (a bar between its two end
//!   points), a translucent polygon through its points when it has three or more, a dot at the
//!   centre of mass; a point mass (no rotational inertia) as a large dot;
//! - joints as circles at the joint point (a weld as a square), a slider as a block on its rail
//!   (the rail is fixed to the slider's first body and spans the travel), springs as dashed
//!   lines, ground attachments with a hatched ground mark;
//! - the path of every requested body point (`"outputs": ["bar2.A"]`) as a faint trace, with a
//!   marker at the point's current position;
//! - a time label, a scale bar and the view's axes.
//!
//! 3D scenes are drawn in an orthographic view (`xy`, `xz`, `yz`, or isometric `iso`: x towards
//! the lower left, y towards the lower right, z up). A point `p` of the world maps to the pixel
//! `(ox + s·(r·p), oy − s·(u·p))`, where `r` and `u` are the view's right and up directions; the
//! root `<svg>` element states them as `data-right`, `data-up`, `data-scale` and `data-origin`,
//! so other tools (and the tests) can locate any point in the picture.
//!
//! The frames are rows of the solution: those nearest to `t₀ + k·speed/fps`, plus the rows
//! needed so that no body turns more than [`MAX_TURN_DEGREES`] or moves more than
//! [`MAX_MOVE_FRACTION`] of its size between two frames (poses interpolated between rows that
//! are further apart; [`denser_output_times`] tells a caller that can solve again which times
//! avoid that). A planar body is one SVG group moved by its pose (SMIL interpolates its centre
//! and angle), so it stays rigid between frames; a spatial scene's HTML page is the 3D view of
//! [`super::view3d`]. The animation lasts `(t_end − t₀) / speed` seconds and loops; without a
//! given speed, fast motions are slowed and the picture says so. Appending `#t=0.7` (or
//! `?t=0.7`) to the file's URL opens it paused at t = 0.7 s of the motion; [`frames_json`]
//! gives the frames exactly as drawn.

pub use super::palette::body_colour;
use super::view3d::FramePose;
use std::fmt::Write;

use super::error::{ReportError, Result};
use crate::mech::joints::{glyph, Glyph};
use crate::scene::{Body, Dimension, Inertia, PointRef, Scene, GROUND};
use crate::solve::Solution;

/// The orthographic view of the animation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Looking down the z axis: x right, y up (the plane of a planar scene).
    Xy,
    /// Looking along +y: x right, z up.
    Xz,
    /// Looking along −x: y right, z up.
    Yz,
    /// Isometric, from (1, 1, 1): x to the lower left, y to the lower right, z up.
    Iso,
}

impl View {
    /// The view's name (`xy`, `xz`, `yz`, `iso`).
    pub fn as_str(self) -> &'static str {
        match self {
            View::Xy => "xy",
            View::Xz => "xz",
            View::Yz => "yz",
            View::Iso => "iso",
        }
    }

    /// Parses a view name.
    pub fn parse(name: &str) -> Option<View> {
        [View::Xy, View::Xz, View::Yz, View::Iso]
            .into_iter()
            .find(|v| v.as_str() == name)
    }

    /// The screen's right and up directions in world coordinates (orthonormal).
    pub fn axes(self) -> ([f64; 3], [f64; 3]) {
        match self {
            View::Xy => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            View::Xz => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            View::Yz => ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            View::Iso => {
                let (a, b) = (1.0 / 2f64.sqrt(), 1.0 / 6f64.sqrt());
                ([-a, a, 0.0], [-b, -b, 2.0 * b])
            }
        }
    }
}

/// The file format of an animation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationFormat {
    /// An SVG animated with SMIL (opens in any browser; `#t=T` pauses it at time T).
    Svg,
    /// An HTML page with the SVG inline, a play/pause button and a time slider.
    Html,
}

/// How to animate.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationOptions {
    /// Frames per second of playback (> 0).
    pub fps: f64,
    /// Seconds of motion per second of playback (> 0; 0.5 is slow motion); `None`: 1, or
    /// slower (a 1-2-5 value) when a body would turn more than [`MAX_TURN_DEGREES`] in one
    /// frame of playback — the page says so.
    pub speed: Option<f64>,
    /// The view; `None`: `xy` for a planar scene, `iso` for a spatial one.
    pub view: Option<View>,
    /// Picture width in pixels.
    pub width: u32,
    /// Picture height in pixels.
    pub height: u32,
    /// Where the solution came from (a file name), for error messages.
    pub source: String,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        AnimationOptions {
            fps: 30.0,
            speed: None,
            view: None,
            width: 800,
            height: 600,
            source: "the solution".into(),
        }
    }
}

/// The largest number of frames an animation may have.
pub const MAX_FRAMES: usize = 20_000;

/// Trace colours; the first is the marker colour the tests look for.
pub const TRACE_COLOURS: [(u8, u8, u8); 3] = [(230, 0, 126), (255, 127, 14), (214, 39, 40)];
const INK: &str = "#222";

/// Where each body's pose is in the solution's columns.
enum Attitude {
    Planar(Option<usize>),
    Quaternion([usize; 4]),
    Cardan([usize; 3]),
    Fixed,
}

struct PoseColumns {
    position: [Option<usize>; 3],
    attitude: Attitude,
}

/// A rigid pose: centre `r` and rotation `rot` (body → world).
#[derive(Clone, Copy)]
struct Pose {
    r: [f64; 3],
    rot: [[f64; 3]; 3],
}

impl Pose {
    const GROUND: Pose = Pose {
        r: [0.0; 3],
        rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    fn apply(&self, p: &[f64]) -> [f64; 3] {
        let p3 = to3(p);
        let mut w = self.r;
        for (i, wi) in w.iter_mut().enumerate() {
            *wi += (0..3).map(|j| self.rot[i][j] * p3[j]).sum::<f64>();
        }
        w
    }

    /// A direction given in body coordinates, in the world.
    fn direction(&self, d: &[f64]) -> [f64; 3] {
        let o = Pose {
            r: [0.0; 3],
            rot: self.rot,
        };
        o.apply(d)
    }
}

/// A planar or spatial point as three coordinates (z = 0 in the plane).
fn to3(p: &[f64]) -> [f64; 3] {
    [
        p.first().copied().unwrap_or(0.0),
        p.get(1).copied().unwrap_or(0.0),
        p.get(2).copied().unwrap_or(0.0),
    ]
}

fn is_point_mass(b: &Body) -> bool {
    match b.inertia {
        Inertia::Planar(j) => j == 0.0,
        Inertia::Principal(j) => j.iter().all(|&v| v == 0.0),
    }
}

fn pose_columns(scene: &Scene, sol: &Solution, source: &str) -> Result<Vec<PoseColumns>> {
    let col = |name: String| sol.columns.iter().position(|c| *c == name);
    let need = |b: &str, c: &'static str| {
        col(format!("{b}.{c}")).ok_or_else(|| ReportError::MissingColumn {
            origin: source.to_string(),
            body: b.to_string(),
            column: c,
        })
    };
    let spatial = scene.dimension == Dimension::Spatial;
    scene
        .bodies
        .iter()
        .map(|b| {
            let n = &b.name;
            let position = [
                Some(need(n, "x")?),
                Some(need(n, "y")?),
                if spatial { Some(need(n, "z")?) } else { None },
            ];
            let attitude = if !spatial {
                let angle = col(format!("{n}.angle"));
                if angle.is_none() && !b.points.is_empty() {
                    need(n, "angle")?;
                }
                Attitude::Planar(angle)
            } else if let (Some(w), Some(x), Some(y), Some(z)) = (
                col(format!("{n}.qw")),
                col(format!("{n}.qx")),
                col(format!("{n}.qy")),
                col(format!("{n}.qz")),
            ) {
                Attitude::Quaternion([w, x, y, z])
            } else if let (Some(a), Some(t), Some(f)) = (
                col(format!("{n}.psi")),
                col(format!("{n}.theta")),
                col(format!("{n}.phi")),
            ) {
                Attitude::Cardan([a, t, f])
            } else if is_point_mass(b) {
                Attitude::Fixed
            } else {
                return Err(ReportError::MissingAttitude {
                    origin: source.to_string(),
                    body: n.clone(),
                });
            };
            Ok(PoseColumns { position, attitude })
        })
        .collect()
}

fn pose(cols: &PoseColumns, row: &[f64]) -> Pose {
    let v = |i: Option<usize>| i.map_or(0.0, |i| row[i]);
    let r = cols.position.map(v);
    let rot = match cols.attitude {
        Attitude::Planar(a) => {
            let (s, c) = v(a).sin_cos();
            [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
        }
        Attitude::Quaternion(q) => {
            let [mut w, mut x, mut y, mut z] = q.map(|i| row[i]);
            let n = (w * w + x * x + y * y + z * z).sqrt();
            if n > 0.0 {
                (w, x, y, z) = (w / n, x / n, y / n, z / n);
            }
            [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - w * z),
                    2.0 * (x * z + w * y),
                ],
                [
                    2.0 * (x * y + w * z),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - w * x),
                ],
                [
                    2.0 * (x * z - w * y),
                    2.0 * (y * z + w * x),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ]
        }
        Attitude::Cardan([a, t, f]) => {
            // seed 16.2: R = Rz(ψ) Ry(θ) Rx(φ)
            let (s1, c1) = row[a].sin_cos();
            let (s2, c2) = row[t].sin_cos();
            let (s3, c3) = row[f].sin_cos();
            [
                [c1 * c2, c1 * s2 * s3 - s1 * c3, c1 * s2 * c3 + s1 * s3],
                [s1 * c2, s1 * s2 * s3 + c1 * c3, s1 * s2 * c3 - c1 * s3],
                [-s2, c2 * s3, c2 * c3],
            ]
        }
        Attitude::Fixed => Pose::GROUND.rot,
    };
    Pose { r, rot }
}

/// A shape fixed to a body, in body coordinates (global coordinates on the ground).
enum Shape {
    /// An arm, a bar or a rail.
    Line {
        a: [f64; 3],
        b: [f64; 3],
        colour: String,
        width: f64,
    },
    /// The body's outline through its points.
    Polygon { pts: Vec<[f64; 3]>, colour: String },
    /// A filled dot (centres of mass, point masses, joints, markers).
    Dot {
        at: [f64; 3],
        radius: f64,
        fill: String,
        stroke: bool,
    },
    /// A weld: a small dark square.
    Square { at: [f64; 3] },
    /// A slider block at `at`, aligned with the direction `dir` (both in body coordinates).
    Block { dir: [f64; 3], at: [f64; 3] },
}

impl Shape {
    fn points(&self) -> Vec<[f64; 3]> {
        match self {
            Shape::Line { a, b, .. } => vec![*a, *b],
            Shape::Polygon { pts, .. } => pts.clone(),
            Shape::Dot { at, .. } | Shape::Square { at } | Shape::Block { at, .. } => vec![*at],
        }
    }
}

/// A drawn item.
enum Item {
    /// Shapes that move with a body (`body: None`: fixed to the ground): drawn in the body's
    /// coordinates and moved by its pose, so that they stay rigid between frames.
    Rigid {
        body: Option<usize>,
        shapes: Vec<Shape>,
    },
    /// A spring: a dashed line between two points, `pts[frame]`.
    Spring { pts: Vec<[[f64; 3]; 2]> },
    /// A ground mark under a fixed point.
    Ground { at: [f64; 3] },
    /// A requested point's path: the faint trace (all rows).
    Trace { pts: Vec<[f64; 3]>, colour: String },
}

struct Projection {
    right: [f64; 3],
    up: [f64; 3],
    scale: f64,
    origin: [f64; 2],
}

impl Projection {
    fn uv(right: [f64; 3], up: [f64; 3], p: [f64; 3]) -> [f64; 2] {
        let d = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        [d(right), d(up)]
    }

    fn px(&self, p: [f64; 3]) -> [f64; 2] {
        let [u, v] = Self::uv(self.right, self.up, p);
        [
            self.origin[0] + self.scale * u,
            self.origin[1] - self.scale * v,
        ]
    }
}

/// A body point given by name or coordinates, in body coordinates (global for ground).
fn point_coords(scene: &Scene, body: &str, p: &PointRef) -> Result<Vec<f64>> {
    match p {
        PointRef::Coords(c) => Ok(c.clone()),
        PointRef::Named(n) => scene
            .bodies
            .iter()
            .find(|b| b.name == body)
            .and_then(|b| b.point(n))
            .map(<[f64]>::to_vec)
            .ok_or_else(|| ReportError::MissingPoint {
                body: body.to_string(),
                point: n.to_string(),
            }),
    }
}

/// The most a body may turn between two frames (degrees).
pub const MAX_TURN_DEGREES: f64 = 15.0;
/// The most a body's centre may move between two frames, as a fraction of the body's size.
pub const MAX_MOVE_FRACTION: f64 = 0.1;

/// Each body's size: the largest distance of its points from its centre of mass; a body
/// without points (or a point mass) takes the largest size in the scene (at least 1 cm).
fn body_sizes(scene: &Scene) -> Vec<f64> {
    let own: Vec<f64> = scene
        .bodies
        .iter()
        .map(|b| {
            b.points
                .iter()
                .map(|(_, p)| p.iter().map(|c| c * c).sum::<f64>().sqrt())
                .fold(0.0, f64::max)
        })
        .collect();
    let largest = own.iter().copied().fold(0.01f64, f64::max);
    own.into_iter()
        .map(|s| if s > 0.0 { s } else { largest })
        .collect()
}

/// The angle (rad) of the rotation from `a` to `b`.
fn turn_angle(a: &Pose, b: &Pose) -> f64 {
    // tr(Aᵀ B) = 1 + 2 cos θ; the sine form keeps small angles accurate
    let m = |i: usize, j: usize| (0..3).map(|l| a.rot[l][i] * b.rot[l][j]).sum::<f64>();
    let trace = m(0, 0) + m(1, 1) + m(2, 2);
    let s = [m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1)];
    let sin = 0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    sin.atan2(0.5 * (trace - 1.0))
}

/// How many parts the interval between poses `a` and `b` must be cut into so that no body
/// turns more than [`MAX_TURN_DEGREES`] or moves more than [`MAX_MOVE_FRACTION`] of its size
/// in one part (1: the interval is fine as it is).
fn parts_needed(a: &[Pose], b: &[Pose], sizes: &[f64]) -> usize {
    let mut parts = 1.0f64;
    for ((pa, pb), size) in a.iter().zip(b).zip(sizes) {
        let turn = turn_angle(pa, pb).to_degrees() / MAX_TURN_DEGREES;
        let d = (0..3)
            .map(|i| (pb.r[i] - pa.r[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let moved = d / (MAX_MOVE_FRACTION * size);
        // a hair below the limit counts as within it
        parts = parts
            .max((turn * (1.0 - 1e-9)).ceil())
            .max((moved * (1.0 - 1e-9)).ceil());
    }
    if parts.is_finite() {
        parts.max(1.0) as usize
    } else {
        1
    }
}

/// The planar angle of each body over the frames, unwrapped (continuous).
fn planar_angles(poses: &[Vec<Pose>]) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(poses.len());
    for (k, frame) in poses.iter().enumerate() {
        let row = frame
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let a = p.rot[1][0].atan2(p.rot[0][0]);
                match k {
                    0 => a,
                    _ => {
                        let prev = out[k - 1][i];
                        let tau = std::f64::consts::TAU;
                        a + tau * ((prev - a) / tau).round()
                    }
                }
            })
            .collect();
        out.push(row);
    }
    out
}

/// The pose a fraction `a` of the way from `p` to `q`: the centre along the straight line,
/// the attitude along the shortest rotation (planar: the angle, linearly).
fn interpolate_pose(p: &Pose, q: &Pose, a: f64) -> Pose {
    use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
    let r = std::array::from_fn(|i| p.r[i] + a * (q.r[i] - p.r[i]));
    let m = |x: &Pose| Matrix3::from_fn(|i, j| x.rot[i][j]);
    let qp = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m(p)));
    let qq = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m(q)));
    let qs = qp.try_slerp(&qq, a, 1e-12).unwrap_or(qp);
    let rm = qs.to_rotation_matrix();
    Pose {
        r,
        rot: std::array::from_fn(|i| std::array::from_fn(|j| rm[(i, j)])),
    }
}

/// The frames of an animation: their times and every body's pose in each.
#[derive(Clone)]
struct FramePlan {
    times: Vec<f64>,
    poses: Vec<Vec<Pose>>,
    /// Frames that are not rows of the solution (poses interpolated between two rows).
    interpolated: usize,
    /// Seconds of motion per second of playback.
    speed: f64,
    /// Whether the speed was lowered from 1 so that the motion can be followed.
    slowed: bool,
}

/// The solution's rows at distinct, increasing times (an event row at a time already seen is
/// left out) and every body's pose in each.
fn row_poses(sol: &Solution, cols: &[PoseColumns]) -> (Vec<usize>, Vec<Vec<Pose>>) {
    let mut keep = Vec::with_capacity(sol.times.len());
    for (k, &t) in sol.times.iter().enumerate() {
        if keep.last().is_none_or(|&j: &usize| t > sol.times[j]) && t.is_finite() {
            keep.push(k);
        }
    }
    let poses = keep
        .iter()
        .map(|&k| cols.iter().map(|c| pose(c, &sol.rows[k])).collect())
        .collect();
    (keep, poses)
}

/// A 1, 2 or 5 × 10ⁿ not above `x`.
fn nice_floor(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&v| v <= x * (1.0 + 1e-12))
        .unwrap_or(p)
}

/// Picks the frames from the solution's rows: the rows nearest to `t₀ + k·speed/fps`, plus
/// the rows needed so that no body turns more than [`MAX_TURN_DEGREES`] or moves more than
/// [`MAX_MOVE_FRACTION`] of its size between two frames; where two neighbouring rows are
/// already further apart, frames between them get poses interpolated between the rows (each
/// body's pose, never its points). Without a given speed, playback is slowed (to a 1-2-5
/// value, at most 1) until no body turns more than the limit in one frame of playback, but
/// not below a playback of 10 minutes.
fn plan_frames(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<FramePlan> {
    let cols = pose_columns(scene, sol, &opts.source)?;
    let sizes = body_sizes(scene);
    let (rows, poses) = row_poses(sol, &cols);
    let times: Vec<f64> = rows.iter().map(|&k| sol.times[k]).collect();
    let n = times.len();
    if n == 0 {
        return Err(ReportError::NoRows {
            origin: opts.source.clone(),
            purpose: "at finite times to animate",
        });
    }
    let (t0, t1) = (times[0], times[n - 1]);
    let span = t1 - t0;
    // playback speed
    let (speed, slowed) = match opts.speed {
        Some(s) => (s, false),
        None => {
            // the fastest motion over the rows, in "limits per second of motion"
            let mut rate = 0.0f64;
            for k in 1..n {
                let dt = times[k] - times[k - 1];
                let turn = poses[k - 1]
                    .iter()
                    .zip(&poses[k])
                    .map(|(a, b)| turn_angle(a, b).to_degrees() / MAX_TURN_DEGREES)
                    .filter(|v| v.is_finite())
                    .fold(0.0, f64::max);
                if dt > 0.0 {
                    rate = rate.max(turn / dt);
                }
            }
            // one frame of playback covers speed/fps seconds of motion: rate·speed/fps ≤ 1
            let fit = if rate > 0.0 { opts.fps / rate } else { 1.0 };
            let floor = if span > 0.0 { span / 600.0 } else { 1.0 };
            let s = nice_floor(fit.min(1.0)).max(floor.min(1.0));
            (s, s < 1.0)
        }
    };
    if span <= 0.0 {
        return Ok(FramePlan {
            times: vec![t0],
            poses: vec![poses[0].clone()],
            interpolated: 0,
            speed,
            slowed,
        });
    }
    let grid = (span * opts.fps / speed).round().max(1.0);
    if grid >= MAX_FRAMES as f64 {
        return Err(ReportError::TooManyFrames {
            fps: opts.fps,
            speed,
            frames: grid,
            span,
            max: MAX_FRAMES,
        });
    }
    // the rows nearest to the playback grid
    let mut chosen: Vec<usize> = Vec::with_capacity(grid as usize + 1);
    for k in 0..=grid as usize {
        let t = t0 + span * k as f64 / grid;
        let j = times.partition_point(|&s| s < t);
        let best = if j == 0 {
            0
        } else if j >= n {
            n - 1
        } else if (times[j] - t).abs() <= (t - times[j - 1]).abs() {
            j
        } else {
            j - 1
        };
        if chosen.last() != Some(&best) {
            chosen.push(best);
        }
    }
    if chosen.last() != Some(&(n - 1)) {
        chosen.push(n - 1);
    }
    // more rows where the motion needs them, then interpolated poses where rows are too far apart
    let mut out_t = vec![times[chosen[0]]];
    let mut out_p = vec![poses[chosen[0]].clone()];
    let mut interpolated = 0;
    for w in chosen.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mut last = a;
        for j in a + 1..=b {
            // take row j-1 when going on to row j would break the limits
            if j - 1 > last && parts_needed(&poses[last], &poses[j], &sizes) > 1 {
                out_t.push(times[j - 1]);
                out_p.push(poses[j - 1].clone());
                last = j - 1;
            }
            if j == b || parts_needed(&poses[last], &poses[j], &sizes) > 1 {
                let parts = parts_needed(&poses[last], &poses[j], &sizes);
                for m in 1..parts {
                    let f = m as f64 / parts as f64;
                    out_t.push(times[last] + f * (times[j] - times[last]));
                    out_p.push(
                        poses[last]
                            .iter()
                            .zip(&poses[j])
                            .map(|(p, q)| interpolate_pose(p, q, f))
                            .collect(),
                    );
                    interpolated += 1;
                }
                out_t.push(times[j]);
                out_p.push(poses[j].clone());
                last = j;
            }
        }
    }
    if out_t.len() > MAX_FRAMES {
        return Err(ReportError::TooFastToAnimate {
            origin: opts.source.clone(),
            frames: out_t.len(),
            max: MAX_FRAMES,
            max_turn_degrees: MAX_TURN_DEGREES,
        });
    }
    Ok(FramePlan {
        times: out_t,
        poses: out_p,
        interpolated,
        speed,
        slowed,
    })
}

/// Output times at which the solution's rows are close enough for the animation (no body
/// turning more than [`MAX_TURN_DEGREES`] or moving more than [`MAX_MOVE_FRACTION`] of its size
/// from one row to the next), or `None` when its rows already are. A caller that can solve again
/// (as `bondmech animate` does) asks for these times, so that every frame is a row of the
/// solution rather than a pose interpolated between two rows.
pub fn denser_output_times(scene: &Scene, sol: &Solution) -> Result<Option<Vec<f64>>> {
    let cols = pose_columns(scene, sol, "the solution")?;
    let sizes = body_sizes(scene);
    let (rows, poses) = row_poses(sol, &cols);
    let mut out = Vec::with_capacity(rows.len());
    let mut denser = false;
    for (i, &k) in rows.iter().enumerate() {
        if i > 0 {
            let parts = parts_needed(&poses[i - 1], &poses[i], &sizes);
            let (ta, tb) = (sol.times[rows[i - 1]], sol.times[k]);
            for m in 1..parts {
                denser = true;
                out.push(ta + (tb - ta) * m as f64 / parts as f64);
            }
        }
        out.push(sol.times[k]);
    }
    Ok(denser.then_some(out))
}

fn quaternion(p: &Pose) -> [f64; 4] {
    use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
    let m = Matrix3::from_fn(|i, j| p.rot[i][j]);
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    [q.w, q.i, q.j, q.k]
}

/// The 3D view's frames, traced points, playback speed, whether it was slowed, and the
/// clock's digits, for [`super::view3d`].
struct View3d {
    frames: Vec<FramePose>,
    traces: Vec<(String, Vec<[f64; 3]>)>,
    speed: f64,
    slowed: bool,
    digits: usize,
}

fn view3d(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<View3d> {
    if scene.dimension != Dimension::Spatial {
        return Err(ReportError::NotSpatial);
    }
    if scene.bodies.is_empty() || sol.times.is_empty() {
        return Err(ReportError::NothingToDraw);
    }
    let cols = pose_columns(scene, sol, &opts.source)?;
    let plan = plan_frames(scene, sol, opts)?;
    let frames: Vec<FramePose> = plan
        .times
        .iter()
        .zip(&plan.poses)
        .map(|(&t, poses)| FramePose {
            t,
            poses: poses.iter().map(|p| (p.r, quaternion(p))).collect(),
        })
        .collect();
    let mut traces = Vec::new();
    for o in &scene.outputs {
        let Some((b, p)) = o.split_once('.') else {
            continue;
        };
        let (Some(bi), Some(coords)) = (
            scene.body_index(b),
            scene
                .bodies
                .iter()
                .find(|x| x.name == b)
                .and_then(|x| x.point(p)),
        ) else {
            continue;
        };
        traces.push((
            o.clone(),
            sol.rows
                .iter()
                .map(|row| pose(&cols[bi], row).apply(coords))
                .collect(),
        ));
    }
    let span = plan.times[plan.times.len() - 1] - plan.times[0];
    Ok(View3d {
        frames,
        traces,
        speed: plan.speed,
        slowed: plan.slowed,
        digits: clock_digits(span),
    })
}

/// The 3D page of a spatial scene ([`super::view3d`]).
fn page_3d(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<String> {
    let v = view3d(scene, sol, opts)?;
    super::view3d::page(scene, &v.frames, &v.traces, v.speed, v.slowed, v.digits)
}

/// The data of the 3D view of a spatial scene, as JSON (the page of `bondmech animate --out
/// FILE.html` draws it; the playground fetches it from `POST /v1/animate?format=view3d` and
/// draws it with the same renderer, [`view3d_script`]): bodies (name, colour, box half-sizes,
/// points), joints, the frames' times and every body's pose per frame (`x y z qw qx qy qz`),
/// traced points, gravity, playback speed. A planar scene is refused (its view is the SVG).
pub fn view3d_json(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<String> {
    check_options(opts)?;
    let v = view3d(scene, sol, opts)?;
    super::view3d::data(scene, &v.frames, &v.traces, v.speed, v.digits)
}

/// The 3D view's renderer, `bondmechView3d(data, ui)` (JavaScript, no library), as the
/// playground serves it at `/view3d.js`.
pub fn view3d_script() -> &'static str {
    super::view3d::VIEW_JS
}

/// One frame as drawn: its time and the world coordinates of every body's named points.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Frame {
    /// Time of the motion (s).
    pub t: f64,
    /// `"body.point"` → `[x, y]` (planar) or `[x, y, z]` (spatial), in the scene's order.
    pub points: serde_json::Map<String, serde_json::Value>,
}

/// The frames of the animation exactly as drawn (`bondmech animate --frames FILE.json`):
/// `{"frames": [{"t": …, "points": {"body.point": [x, y(, z)], …}}, …]}`, every body's named
/// points in every frame.
pub fn frames_json(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<String> {
    check_options(opts)?;
    if scene.bodies.is_empty() {
        return Err(ReportError::NoGeometry);
    }
    let plan = plan_frames(scene, sol, opts)?;
    let dims = match scene.dimension {
        Dimension::Planar => 2,
        Dimension::Spatial => 3,
    };
    let frames: Vec<Frame> = plan
        .times
        .iter()
        .zip(&plan.poses)
        .map(|(&t, poses)| {
            let mut points = serde_json::Map::new();
            for (b, pose) in scene.bodies.iter().zip(poses) {
                for (name, p) in &b.points {
                    let w = pose.apply(p);
                    points.insert(
                        format!("{}.{name}", b.name),
                        serde_json::Value::from(w[..dims].to_vec()),
                    );
                }
            }
            Frame { t, points }
        })
        .collect();
    let doc = serde_json::json!({
        "scene": scene.name,
        "speed": plan.speed,
        "interpolated_frames": plan.interpolated,
        "frames": frames,
    });
    Ok(serde_json::to_string(&doc).expect("frames serialise") + "\n")
}

/// Everything drawn, frame by frame.
struct Drawing {
    items: Vec<Item>,
    plan: FramePlan,
    /// Each body's angle in each frame, unwrapped (planar scenes; empty in space).
    angles: Vec<Vec<f64>>,
}

impl Drawing {
    fn times(&self) -> &[f64] {
        &self.plan.times
    }

    fn pose(&self, k: usize, body: Option<usize>) -> Pose {
        body.map_or(Pose::GROUND, |b| self.plan.poses[k][b])
    }
}

fn build_drawing(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<Drawing> {
    if scene.bodies.is_empty() {
        return Err(ReportError::NoGeometry);
    }
    if sol.times.is_empty() {
        return Err(ReportError::NoRows {
            origin: opts.source.clone(),
            purpose: "to animate",
        });
    }
    let cols = pose_columns(scene, sol, &opts.source)?;
    let plan = plan_frames(scene, sol, opts)?;
    let frames = plan.times.len();
    let index = |name: &str| scene.body_index(name);
    let body_pose =
        |k: usize, name: &str| -> Pose { index(name).map_or(Pose::GROUND, |i| plan.poses[k][i]) };
    let track = |name: &str, p: &[f64]| -> Vec<[f64; 3]> {
        (0..frames).map(|k| body_pose(k, name).apply(p)).collect()
    };
    let mut items = Vec::new();
    // bodies: translucent outline, arms, centre
    for (bi, b) in scene.bodies.iter().enumerate() {
        let colour = body_colour(bi);
        let mut shapes = Vec::new();
        if b.points.len() >= 3 {
            shapes.push(Shape::Polygon {
                pts: b.points.iter().map(|(_, p)| to3(p)).collect(),
                colour: colour.clone(),
            });
        }
        for (_, p) in &b.points {
            if p.iter().all(|&c| c == 0.0) {
                continue;
            }
            shapes.push(Shape::Line {
                a: [0.0; 3],
                b: to3(p),
                colour: colour.clone(),
                width: 7.0,
            });
        }
        let (radius, fill) = if is_point_mass(b) {
            (9.0, colour.clone())
        } else {
            (3.5, INK.to_string())
        };
        shapes.push(Shape::Dot {
            at: [0.0; 3],
            radius,
            fill,
            stroke: false,
        });
        items.push(Item::Rigid {
            body: Some(bi),
            shapes,
        });
    }
    // springs
    for s in &scene.springs {
        let a = track(
            &s.bodies[0],
            &point_coords(scene, &s.bodies[0], &s.points[0])?,
        );
        let e = track(
            &s.bodies[1],
            &point_coords(scene, &s.bodies[1], &s.points[1])?,
        );
        items.push(Item::Spring {
            pts: a.iter().zip(&e).map(|(a, e)| [*a, *e]).collect(),
        });
        for (i, b) in s.bodies.iter().enumerate() {
            if b == GROUND {
                items.push(Item::Ground {
                    at: to3(&point_coords(scene, b, &s.points[i])?),
                });
            }
        }
    }
    // joints (drawn over the bodies)
    let scale = body_sizes(scene).into_iter().fold(0.05f64, f64::max);
    for j in &scene.joints {
        let [b1, b2] = [&j.bodies[0], &j.bodies[1]];
        let p1 = point_coords(scene, b1, &j.points[0])?;
        let p2 = point_coords(scene, b2, &j.points[1])?;
        let glyph = glyph(&j.kind);
        if let Glyph::Slider { axis } = &glyph {
            let w1 = track(b1, &p1);
            let w2 = track(b2, &p2);
            let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
            let unit: Vec<f64> = axis.iter().map(|a| a / n).collect();
            // travel along the rail, in the first body's frame
            let s: Vec<f64> = (0..frames)
                .map(|k| {
                    let d = body_pose(k, b1).direction(&unit);
                    (0..3).map(|i| d[i] * (w2[k][i] - w1[k][i])).sum()
                })
                .collect();
            let (lo, hi) = s
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                    (l.min(v), h.max(v))
                });
            let pad = 0.15 * (hi - lo) + 0.25 * scale;
            let end = |s: f64| -> [f64; 3] {
                let e: Vec<f64> = p1
                    .iter()
                    .zip(unit.iter().chain([0.0; 3].iter()))
                    .map(|(p, u)| p + s * u)
                    .collect();
                to3(&e)
            };
            let (ra, rb) = (end(lo - pad), end(hi + pad));
            if b1 == GROUND {
                // the rail's end nearer its anchor point is where it meets the ground
                let near = if (lo - pad).abs() <= (hi + pad).abs() {
                    ra
                } else {
                    rb
                };
                items.push(Item::Ground { at: near });
            }
            items.push(Item::Rigid {
                body: index(b1),
                shapes: vec![Shape::Line {
                    a: ra,
                    b: rb,
                    colour: INK.into(),
                    width: 2.5,
                }],
            });
            // the block turns with the rail: its direction in the second body's frame is fixed
            let d_world = body_pose(0, b1).direction(&unit);
            let r2 = body_pose(0, b2).rot;
            let dir = std::array::from_fn(|i| (0..3).map(|l| r2[l][i] * d_world[l]).sum());
            items.push(Item::Rigid {
                body: index(b2),
                shapes: vec![Shape::Block { dir, at: to3(&p2) }],
            });
        } else {
            let (body, at) = if b2 == GROUND {
                (index(b1), to3(&p1))
            } else {
                (index(b2), to3(&p2))
            };
            let shape = if matches!(glyph, Glyph::Weld) {
                Shape::Square { at }
            } else {
                Shape::Dot {
                    at,
                    radius: 5.0,
                    fill: "white".into(),
                    stroke: true,
                }
            };
            items.push(Item::Rigid {
                body,
                shapes: vec![shape],
            });
        }
        let slider = matches!(glyph, Glyph::Slider { .. });
        for (i, b) in [b1, b2].into_iter().enumerate() {
            if b == GROUND && !(slider && i == 0) {
                let at = if i == 0 { &p1 } else { &p2 };
                items.push(Item::Ground { at: to3(at) });
            }
        }
    }
    // traces of the requested body points
    let mut n_traces = 0;
    for o in &scene.outputs {
        let Some((b, p)) = o.split_once('.') else {
            continue;
        };
        let Some(coords) = scene
            .bodies
            .iter()
            .find(|x| x.name == b)
            .and_then(|x| x.point(p))
        else {
            continue;
        };
        let (r, g, bl) = TRACE_COLOURS[n_traces % TRACE_COLOURS.len()];
        n_traces += 1;
        let colour = format!("rgb({r},{g},{bl})");
        // the trace through every row of the solution, the marker on the body
        let bi = scene.body_index(b).expect("a body of the scene");
        items.push(Item::Trace {
            pts: sol
                .rows
                .iter()
                .map(|row| pose(&cols[bi], row).apply(coords))
                .collect(),
            colour: colour.clone(),
        });
        items.push(Item::Rigid {
            body: Some(bi),
            shapes: vec![Shape::Dot {
                at: to3(coords),
                radius: 6.0,
                fill: colour,
                stroke: false,
            }],
        });
    }
    // traces first (under everything), then the rest in order
    items.sort_by_key(|i| !matches!(i, Item::Trace { .. } | Item::Ground { .. }));
    let angles = match scene.dimension {
        Dimension::Planar => planar_angles(&plan.poses),
        Dimension::Spatial => Vec::new(),
    };
    Ok(Drawing {
        items,
        plan,
        angles,
    })
}

impl Drawing {
    fn world_points(&self) -> Vec<[f64; 3]> {
        let mut out = Vec::new();
        for i in &self.items {
            match i {
                Item::Rigid { body, shapes } => {
                    for k in 0..self.times().len() {
                        let pose = self.pose(k, *body);
                        for s in shapes {
                            out.extend(s.points().iter().map(|p| pose.apply(p)));
                        }
                    }
                }
                Item::Spring { pts } => out.extend(pts.iter().flat_map(|l| l.iter().copied())),
                Item::Trace { pts, .. } => out.extend(pts.iter().copied()),
                Item::Ground { at } => out.push(*at),
            }
        }
        out
    }
}

/// Fits the drawing into the picture (margins for the labels), keeping the aspect ratio.
fn fit(drawing: &Drawing, view: View, width: f64, height: f64) -> Projection {
    let (right, up) = view.axes();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in drawing.world_points() {
        let uv = Projection::uv(right, up, p);
        for i in 0..2 {
            if uv[i].is_finite() {
                lo[i] = lo[i].min(uv[i]);
                hi[i] = hi[i].max(uv[i]);
            }
        }
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([-1.0, -1.0], [1.0, 1.0]);
    }
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-6);
    let du = (hi[0] - lo[0]).max(0.2 * extent);
    let dv = (hi[1] - lo[1]).max(0.2 * extent);
    let (mx, top, bottom) = (40.0, 50.0, 60.0);
    let scale = ((width - 2.0 * mx) / du).min((height - top - bottom) / dv);
    let cu = 0.5 * (lo[0] + hi[0]);
    let cv = 0.5 * (lo[1] + hi[1]);
    Projection {
        right,
        up,
        scale,
        origin: [
            0.5 * width - scale * cu,
            top + 0.5 * (height - top - bottom) + scale * cv,
        ],
    }
}

fn num(v: f64) -> String {
    let s = format!("{v:.1}");
    if s == "-0.0" {
        "0.0".into()
    } else {
        s
    }
}

/// SMIL `<animate>` of one attribute through its per-frame values (nothing when constant).
fn animate(out: &mut String, attr: &str, values: &[String], t: &Timing) {
    if values.windows(2).all(|w| w[0] == w[1]) {
        return;
    }
    let _ = write!(
        out,
        "<animate attributeName=\"{attr}\" {} values=\"{}\"/>",
        t.attrs(),
        values.join(";")
    );
}

fn points_attr(pts: &[[f64; 2]]) -> String {
    pts.iter()
        .map(|p| format!("{},{}", num(p[0]), num(p[1])))
        .collect::<Vec<_>>()
        .join(" ")
}

/// An SVG element whose attributes change per frame: `attrs[a] = (name, per-frame values)`.
fn element(out: &mut String, tag: &str, style: &str, attrs: &[(&str, Vec<String>)], t: &Timing) {
    let _ = write!(out, "<{tag} {style}");
    for (name, values) in attrs {
        let _ = write!(out, " {name}=\"{}\"", values[0]);
    }
    out.push('>');
    for (name, values) in attrs {
        animate(out, name, values, t);
    }
    let _ = writeln!(out, "</{tag}>");
}

/// The corners of a slider block centred at pixel `c`, its long side along the screen
/// direction `d`.
fn block_at(c: [f64; 2], d: [f64; 2]) -> Vec<[f64; 2]> {
    let (mut dx, mut dy) = (d[0], d[1]);
    let n = (dx * dx + dy * dy).sqrt();
    if n > 1e-9 {
        (dx, dy) = (dx / n, dy / n);
    } else {
        (dx, dy) = (1.0, 0.0);
    }
    let (a, b) = (11.0, 7.0);
    [(a, b), (a, -b), (-a, -b), (-a, b)]
        .iter()
        .map(|&(s, t)| [c[0] + s * dx - t * dy, c[1] + s * dy + t * dx])
        .collect()
}

/// A length of 1, 2 or 5 × 10ⁿ m that is about a quarter of `extent`.
fn nice_length(extent: f64) -> f64 {
    let target = extent / 4.0;
    let p = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&l| l <= target)
        .unwrap_or(p)
}

fn svg_document(
    scene: &Scene,
    drawing: &Drawing,
    opts: &AnimationOptions,
    view: View,
    seek_script: bool,
) -> String {
    let (w, h) = (opts.width as f64, opts.height as f64);
    let proj = fit(drawing, view, w, h);
    let times = drawing.times();
    let n = times.len();
    let (t0, t1) = (times[0], times[n - 1]);
    let speed = drawing.plan.speed;
    let timing = Timing::new(times, speed);
    let dur = timing.dur;
    let digits = clock_digits(t1 - t0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"bondmech-animation\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" \
         data-scale=\"{}\" data-origin=\"{} {}\" data-right=\"{} {} {}\" data-up=\"{} {} {}\" data-view=\"{}\" \
         data-t0=\"{t0}\" data-t-end=\"{t1}\" data-speed=\"{}\" data-duration=\"{dur:.6}\" data-digits=\"{digits}\" data-frames=\"{n}\" font-family=\"Helvetica, Arial, sans-serif\">",
        opts.width, opts.height, opts.width, opts.height,
        proj.scale, proj.origin[0], proj.origin[1],
        proj.right[0], proj.right[1], proj.right[2], proj.up[0], proj.up[1], proj.up[2],
        view.as_str(), speed
    );
    let _ = writeln!(
        s,
        "<title>{} — bondmech animation ({} view)</title>",
        xml(&scene.name),
        view.as_str()
    );
    let _ = writeln!(s, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    for item in &drawing.items {
        draw_item(&mut s, item, drawing, &proj, &timing);
    }
    // labels: scene name and view, time, scale bar, axes
    let _ = writeln!(
        s,
        "<text x=\"16\" y=\"26\" font-size=\"17\" fill=\"{INK}\">{} <tspan fill=\"#777\" font-size=\"13\">({} view, ×{} speed)</tspan></text>",
        xml(&scene.name),
        view.as_str(),
        speed
    );
    if drawing.plan.slowed {
        let _ = writeln!(
            s,
            "<text class=\"note\" x=\"16\" y=\"44\" font-size=\"12\" fill=\"#777\">played at ×{speed}: slowed so that no body turns more than {MAX_TURN_DEGREES}° per frame at {} frames/s (--speed to change)</text>",
            opts.fps
        );
    }
    time_label(&mut s, times, w, &timing, digits);
    let extent = (w - 80.0) / proj.scale;
    let bar = nice_length(extent);
    let px = bar * proj.scale;
    let _ = writeln!(
        s,
        "<g stroke=\"{INK}\" stroke-width=\"2\"><line x1=\"20\" y1=\"{y}\" x2=\"{x2}\" y2=\"{y}\"/><line x1=\"20\" y1=\"{a}\" x2=\"20\" y2=\"{b}\"/><line x1=\"{x2}\" y1=\"{a}\" x2=\"{x2}\" y2=\"{b}\"/></g>\
         <text x=\"{tx}\" y=\"{ty}\" font-size=\"13\" text-anchor=\"middle\" fill=\"{INK}\">{bar} m</text>",
        y = num(h - 20.0),
        x2 = num(20.0 + px),
        a = num(h - 25.0),
        b = num(h - 15.0),
        tx = num(20.0 + px / 2.0),
        ty = num(h - 28.0),
    );
    let (cx, cy) = (w - 50.0, h - 35.0);
    for (i, name) in ["x", "y", "z"].iter().enumerate() {
        let mut e = [0.0; 3];
        e[i] = 1.0;
        let [u, v] = Projection::uv(proj.right, proj.up, e);
        if u.abs() + v.abs() < 1e-9 {
            continue;
        }
        let (ex, ey) = (cx + 25.0 * u, cy - 25.0 * v);
        let _ = writeln!(
            s,
            "<line x1=\"{cx}\" y1=\"{cy}\" x2=\"{}\" y2=\"{}\" stroke=\"#777\" stroke-width=\"1.5\"/><text x=\"{}\" y=\"{}\" font-size=\"12\" fill=\"#555\" text-anchor=\"middle\">{name}</text>",
            num(ex),
            num(ey),
            num(cx + 35.0 * u),
            num(cy - 35.0 * v + 4.0)
        );
    }
    if seek_script {
        let _ = writeln!(s, "<script><![CDATA[\n{SEEK_SVG}\n]]></script>");
    }
    s.push_str("</svg>\n");
    s
}

/// Pauses a standalone SVG at `#t=T` / `?t=T` (seconds of motion).
const SEEK_SVG: &str = r#"(function () {
  var s = document.documentElement;
  var t0 = +s.getAttribute('data-t0'), sp = +s.getAttribute('data-speed');
  var d = +s.getAttribute('data-duration'), digits = +s.getAttribute('data-digits');
  var clock = document.getElementById('clock'), strip = document.getElementById('strip');
  clock.setAttribute('display', 'inline'); strip.setAttribute('display', 'none');
  // one clock: the label shows the playback clock of the animations
  function show() {
    clock.textContent = 't = ' + (t0 + (s.getCurrentTime() % d) * sp).toFixed(digits) + ' s';
  }
  var m = /[?#&]t=([-+0-9.eE]+)/.exec(location.href);
  // a standalone SVG opened at a time stays paused there (a pause before the timeline starts
  // can be lost, so it is checked at every frame)
  function target() { return Math.min(Math.max((parseFloat(m[1]) - t0) / sp, 0), d * (1 - 1e-9)); }
  function tick() {
    if (m && (!s.animationsPaused() || Math.abs(s.getCurrentTime() - target()) > 1e-6)) seek();
    show();
    requestAnimationFrame(tick);
  }
  function seek() {
    s.pauseAnimations();
    s.setCurrentTime(target());
    show();
  }
  // seek now and again once the document has loaded (a pause before the timeline starts is lost)
  if (m) {
    seek();
    window.addEventListener('load', seek);
    setTimeout(seek, 50);
  }
  tick();
})();"#;

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Decimals of the time label: about a thousandth of the span.
fn clock_digits(span: f64) -> usize {
    if span > 0.0 {
        ((-(span / 1000.0).log10()).ceil()).clamp(2.0, 9.0) as usize
    } else {
        3
    }
}

/// The time label. One clock: the page's script writes the playback clock into `#clock` (the
/// same value as the slider's readout); without scripts (an SVG in an `<img>`), a strip of
/// labels, one per frame, moves under a clip window in step with the frames.
fn time_label(s: &mut String, times: &[f64], width: f64, t: &Timing, digits: usize) {
    let n = times.len();
    let (x, y, lh) = (width - 20.0, 28.0, 24.0);
    let _ = writeln!(
        s,
        "<text id=\"clock\" x=\"{x}\" y=\"{y}\" font-size=\"18\" fill=\"{INK}\" text-anchor=\"end\" display=\"none\">t = {:.digits$} s</text>",
        times[0]
    );
    let _ = writeln!(
        s,
        "<clipPath id=\"tclip\"><rect x=\"{}\" y=\"{}\" width=\"200\" height=\"{lh}\"/></clipPath>",
        x - 200.0,
        y - 19.0
    );
    let _ = write!(
        s,
        "<g id=\"strip\" clip-path=\"url(#tclip)\" font-size=\"18\" fill=\"{INK}\" text-anchor=\"end\"><g>"
    );
    if n > 1 {
        // label k shows from frame k until frame k + 1
        let vals: Vec<String> = (0..n).map(|k| format!("0 {}", -(k as f64) * lh)).collect();
        let _ = write!(
            s,
            "<animateTransform attributeName=\"transform\" type=\"translate\" calcMode=\"discrete\" {} values=\"{}\"/>",
            t.attrs(),
            vals.join(";")
        );
    }
    for (k, tk) in times.iter().enumerate() {
        let _ = write!(
            s,
            "<text x=\"{x}\" y=\"{}\">t = {tk:.digits$} s</text>",
            num(y + k as f64 * lh)
        );
    }
    let _ = writeln!(s, "</g></g>");
}

/// How the SMIL animations of a document are timed: its duration and the frames' key times.
struct Timing {
    dur: f64,
    keys: String,
}

impl Timing {
    fn new(times: &[f64], speed: f64) -> Timing {
        let n = times.len();
        let (t0, t1) = (times[0], times[n - 1]);
        let span = t1 - t0;
        let keys = if n > 1 {
            let mut prev = -1.0;
            times
                .iter()
                .enumerate()
                .map(|(k, &t)| {
                    let mut f = if k == n - 1 { 1.0 } else { (t - t0) / span };
                    // key times strictly increase (printed with 9 digits)
                    if f <= prev {
                        f = prev + 1e-9;
                    }
                    prev = f;
                    match k {
                        0 => "0".to_string(),
                        _ if k == n - 1 => "1".to_string(),
                        _ => format!("{f:.9}"),
                    }
                })
                .collect::<Vec<_>>()
                .join(";")
        } else {
            String::new()
        };
        Timing {
            dur: (span / speed).max(1e-6),
            keys,
        }
    }

    fn attrs(&self) -> String {
        format!(
            "dur=\"{:.6}s\" repeatCount=\"indefinite\" keyTimes=\"{}\"",
            self.dur, self.keys
        )
    }
}

/// One shape drawn in a body's local picture coordinates (pixels, y down, origin at the
/// body's centre), for a group that the body's pose moves.
fn draw_local(s: &mut String, shape: &Shape, scale: f64) {
    let l = |p: [f64; 3]| [scale * p[0], -scale * p[1]];
    match shape {
        Shape::Line {
            a,
            b,
            colour,
            width,
        } => {
            let (a, b) = (l(*a), l(*b));
            let _ = writeln!(
                s,
                "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{colour}\" stroke-width=\"{width}\" stroke-linecap=\"round\"/>",
                num(a[0]), num(a[1]), num(b[0]), num(b[1])
            );
        }
        Shape::Polygon { pts, colour } => {
            let p: Vec<[f64; 2]> = pts.iter().map(|&p| l(p)).collect();
            let _ = writeln!(
                s,
                "<polygon points=\"{}\" fill=\"{colour}\" fill-opacity=\"0.18\" stroke=\"{colour}\" stroke-width=\"1.5\"/>",
                points_attr(&p)
            );
        }
        Shape::Dot {
            at,
            radius,
            fill,
            stroke,
        } => {
            let c = l(*at);
            let st = if *stroke {
                format!(" stroke=\"{INK}\" stroke-width=\"2\"")
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "<circle cx=\"{}\" cy=\"{}\" r=\"{radius}\" fill=\"{fill}\"{st}/>",
                num(c[0]),
                num(c[1])
            );
        }
        Shape::Square { at } => {
            let c = l(*at);
            let _ = writeln!(
                s,
                "<rect x=\"{}\" y=\"{}\" width=\"10\" height=\"10\" fill=\"{INK}\"/>",
                num(c[0] - 5.0),
                num(c[1] - 5.0)
            );
        }
        Shape::Block { dir, at } => {
            let c = l(*at);
            let d = [dir[0], -dir[1]];
            let _ = writeln!(
                s,
                "<polygon points=\"{}\" fill=\"#ddd\" stroke=\"{INK}\" stroke-width=\"2\"/>",
                points_attr(&block_at(c, d))
            );
        }
    }
}

/// One shape whose points are moved frame by frame (a spatial scene's bodies: the projection of
/// a turning body is not a transform of one flat picture).
fn draw_moving(
    s: &mut String,
    shape: &Shape,
    px: &[[f64; 3]],
    dirs: &[[f64; 3]],
    proj: &Projection,
    t: &Timing,
) {
    // px[k * n + v]: vertex v of the shape in frame k (world), n vertices
    let n = shape.points().len();
    let frames = px.len() / n.max(1);
    let at = |k: usize, v: usize| proj.px(px[k * n + v]);
    match shape {
        Shape::Line { colour, width, .. } => {
            let v = |i: usize, c: usize| (0..frames).map(|k| num(at(k, i)[c])).collect();
            element(
                s,
                "line",
                &format!("stroke=\"{colour}\" stroke-width=\"{width}\" stroke-linecap=\"round\""),
                &[
                    ("x1", v(0, 0)),
                    ("y1", v(0, 1)),
                    ("x2", v(1, 0)),
                    ("y2", v(1, 1)),
                ],
                t,
            );
        }
        Shape::Polygon { colour, .. } => {
            let v: Vec<String> = (0..frames)
                .map(|k| points_attr(&(0..n).map(|i| at(k, i)).collect::<Vec<_>>()))
                .collect();
            element(
                s,
                "polygon",
                &format!("fill=\"{colour}\" fill-opacity=\"0.18\" stroke=\"{colour}\" stroke-width=\"1.5\""),
                &[("points", v)],
                t,
            );
        }
        Shape::Dot {
            radius,
            fill,
            stroke,
            ..
        } => {
            let style = if *stroke {
                format!("r=\"{radius}\" fill=\"{fill}\" stroke=\"{INK}\" stroke-width=\"2\"")
            } else {
                format!("r=\"{radius}\" fill=\"{fill}\"")
            };
            element(
                s,
                "circle",
                &style,
                &[
                    ("cx", (0..frames).map(|k| num(at(k, 0)[0])).collect()),
                    ("cy", (0..frames).map(|k| num(at(k, 0)[1])).collect()),
                ],
                t,
            );
        }
        Shape::Square { .. } => element(
            s,
            "rect",
            &format!("width=\"10\" height=\"10\" fill=\"{INK}\""),
            &[
                ("x", (0..frames).map(|k| num(at(k, 0)[0] - 5.0)).collect()),
                ("y", (0..frames).map(|k| num(at(k, 0)[1] - 5.0)).collect()),
            ],
            t,
        ),
        Shape::Block { .. } => {
            let v: Vec<String> = (0..frames)
                .map(|k| {
                    let c = at(k, 0);
                    let w = px[k * n];
                    let tip = proj.px([w[0] + dirs[k][0], w[1] + dirs[k][1], w[2] + dirs[k][2]]);
                    points_attr(&block_at(c, [tip[0] - c[0], tip[1] - c[1]]))
                })
                .collect();
            element(
                s,
                "polygon",
                &format!("fill=\"#ddd\" stroke=\"{INK}\" stroke-width=\"2\""),
                &[("points", v)],
                t,
            );
        }
    }
}

fn draw_item(s: &mut String, item: &Item, drawing: &Drawing, proj: &Projection, t: &Timing) {
    let f = |p: [f64; 3]| proj.px(p);
    let frames = drawing.times().len();
    match item {
        Item::Rigid { body, shapes } => {
            let planar = !drawing.angles.is_empty();
            match (body, planar) {
                (None, _) => {
                    // fixed to the ground: world coordinates, drawn once
                    let o = f([0.0; 3]);
                    let _ = writeln!(
                        s,
                        "<g transform=\"translate({} {})\">",
                        num(o[0]),
                        num(o[1])
                    );
                    for sh in shapes {
                        draw_local(s, sh, proj.scale);
                    }
                    s.push_str("</g>\n");
                }
                (Some(b), true) => {
                    // a rigid group: translated to the centre, turned by the body's angle; SMIL
                    // interpolates the pose between frames, so the body stays rigid in between
                    let centre: Vec<[f64; 2]> = (0..frames)
                        .map(|k| f(drawing.plan.poses[k][*b].r))
                        .collect();
                    let deg: Vec<f64> = (0..frames)
                        .map(|k| -drawing.angles[k][*b].to_degrees())
                        .collect();
                    let _ = write!(
                        s,
                        "<g class=\"body\" data-body=\"{b}\" transform=\"translate({} {}) rotate({:.4})\">",
                        num(centre[0][0]),
                        num(centre[0][1]),
                        deg[0]
                    );
                    if frames > 1 {
                        let tr: Vec<String> = centre
                            .iter()
                            .map(|c| format!("{:.2} {:.2}", c[0], c[1]))
                            .collect();
                        let rot: Vec<String> = deg.iter().map(|d| format!("{d:.4}")).collect();
                        let _ = write!(
                            s,
                            "<animateTransform attributeName=\"transform\" type=\"translate\" {} values=\"{}\"/>\
                             <animateTransform attributeName=\"transform\" type=\"rotate\" additive=\"sum\" {} values=\"{}\"/>",
                            t.attrs(),
                            tr.join(";"),
                            t.attrs(),
                            rot.join(";")
                        );
                    }
                    s.push('\n');
                    for sh in shapes {
                        draw_local(s, sh, proj.scale);
                    }
                    s.push_str("</g>\n");
                }
                (Some(b), false) => {
                    for sh in shapes {
                        let pts = sh.points();
                        let mut px = Vec::with_capacity(pts.len() * frames);
                        let mut dirs = Vec::with_capacity(frames);
                        for k in 0..frames {
                            let pose = drawing.plan.poses[k][*b];
                            px.extend(pts.iter().map(|p| pose.apply(p)));
                            if let Shape::Block { dir, .. } = sh {
                                dirs.push(pose.direction(dir));
                            }
                        }
                        draw_moving(s, sh, &px, &dirs, proj, t);
                    }
                }
            }
        }
        Item::Spring { pts } => {
            let ends: Vec<[[f64; 2]; 2]> = pts.iter().map(|l| [f(l[0]), f(l[1])]).collect();
            let v = |i: usize, c: usize| ends.iter().map(|e| num(e[i][c])).collect();
            element(
                s,
                "line",
                "stroke=\"#555\" stroke-width=\"2\" stroke-linecap=\"round\" stroke-dasharray=\"6 4\"",
                &[("x1", v(0, 0)), ("y1", v(0, 1)), ("x2", v(1, 0)), ("y2", v(1, 1))],
                t,
            );
        }
        Item::Ground { at } => {
            let [x, y] = f(*at);
            let mut d = format!(
                "M{} {} L{} {} L{} {} Z M{} {} L{} {}",
                num(x),
                num(y),
                num(x - 9.0),
                num(y + 14.0),
                num(x + 9.0),
                num(y + 14.0),
                num(x - 15.0),
                num(y + 14.0),
                num(x + 15.0),
                num(y + 14.0)
            );
            for i in 0..5 {
                let hx = x - 13.0 + 7.0 * i as f64;
                let _ = write!(
                    d,
                    " M{} {} L{} {}",
                    num(hx),
                    num(y + 14.0),
                    num(hx - 5.0),
                    num(y + 20.0)
                );
            }
            let _ = writeln!(
                s,
                "<path d=\"{d}\" fill=\"#eee\" stroke=\"{INK}\" stroke-width=\"1.5\"/>"
            );
        }
        Item::Trace { pts, colour } => {
            let p: Vec<[f64; 2]> = pts.iter().map(|&p| f(p)).collect();
            let _ = writeln!(
                s,
                "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-opacity=\"0.35\" stroke-width=\"1.5\"/>",
                points_attr(&p)
            );
        }
    }
}

/// The controls of the HTML page: play/pause, a time slider, and `#t=T` / `?t=T` on load.
const HTML_SCRIPT: &str = r#"(function () {
  var s = document.querySelector('svg.bondmech-animation');
  var t0 = +s.getAttribute('data-t0'), t1 = +s.getAttribute('data-t-end');
  var sp = +s.getAttribute('data-speed'), d = +s.getAttribute('data-duration');
  var button = document.getElementById('play'), slider = document.getElementById('time');
  var readout = document.getElementById('readout'), digits = +s.getAttribute('data-digits');
  var clock = document.getElementById('clock'), strip = document.getElementById('strip');
  clock.setAttribute('display', 'inline'); strip.setAttribute('display', 'none');
  slider.min = t0; slider.max = t1; slider.step = 'any';
  // one clock: the label in the picture, the slider and its readout show the same time
  function show(t) {
    var text = 't = ' + t.toFixed(digits) + ' s';
    slider.value = t; readout.textContent = text; clock.textContent = text;
  }
  function seek(t) {
    var tau = Math.min(Math.max((t - t0) / sp, 0), d * (1 - 1e-9));
    s.pauseAnimations(); s.setCurrentTime(tau); button.textContent = 'play'; show(t0 + tau * sp);
  }
  var pinned = false, pinnedAt = 0;
  button.onclick = function () {
    pinned = false;
    if (s.animationsPaused()) { s.unpauseAnimations(); button.textContent = 'pause'; }
    else { s.pauseAnimations(); button.textContent = 'play'; }
  };
  slider.oninput = function () { pinned = false; seek(+slider.value); };
  function tick() {
    // opened at a time: stay there until played (a pause before the timeline starts is lost)
    if (pinned && (!s.animationsPaused()
        || Math.abs(t0 + s.getCurrentTime() * sp - Math.min(Math.max(pinnedAt, t0), t1)) > 1e-6 * (1 + Math.abs(t1)))) {
      seek(pinnedAt);
    }
    if (!s.animationsPaused()) show(t0 + (s.getCurrentTime() % d) * sp);
    requestAnimationFrame(tick);
  }
  var m = /[?#&]t=([-+0-9.eE]+)/.exec(location.href);
  // seek once the document (and its SMIL timeline) has started: a pause before it is lost
  function start() {
    if (m) { pinned = true; pinnedAt = parseFloat(m[1]); seek(pinnedAt); }
    else button.textContent = 'pause';
    requestAnimationFrame(tick);
  }
  if (document.readyState === 'complete') start(); else window.addEventListener('load', start);
})();"#;

/// Refuses a frame rate or speed that is not a positive number.
fn check_options(opts: &AnimationOptions) -> Result<()> {
    if !(opts.fps > 0.0 && opts.fps.is_finite()) {
        return Err(ReportError::NotPositive {
            option: "--fps",
            value: opts.fps,
        });
    }
    if let Some(speed) = opts.speed {
        if !(speed > 0.0 && speed.is_finite()) {
            return Err(ReportError::NotPositive {
                option: "--speed",
                value: speed,
            });
        }
    }
    Ok(())
}

/// Renders the animation of `sol` (a solution of `scene`, solved or read from a CSV that
/// `bondmech run` wrote) as one self-contained SVG or HTML document.
pub fn animation(
    scene: &Scene,
    sol: &Solution,
    opts: &AnimationOptions,
    format: AnimationFormat,
) -> Result<String> {
    check_options(opts)?;
    let view = opts.view.unwrap_or(match scene.dimension {
        Dimension::Planar => View::Xy,
        Dimension::Spatial => View::Iso,
    });
    if scene.dimension == Dimension::Planar && view != View::Xy {
        return Err(ReportError::PlanarView {
            view: view.as_str(),
        });
    }
    if format == AnimationFormat::Html && scene.dimension == Dimension::Spatial {
        return page_3d(scene, sol, opts);
    }
    let drawing = build_drawing(scene, sol, opts)?;
    Ok(match format {
        AnimationFormat::Svg => {
            let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
            s.push_str(&svg_document(scene, &drawing, opts, view, true));
            s
        }
        AnimationFormat::Html => format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{} — bondmech</title>\n\
             <style>body{{margin:0;font-family:Helvetica,Arial,sans-serif}}#controls{{padding:6px 12px}}\
             #controls button{{width:5em}}#controls input{{width:520px;vertical-align:middle}}</style></head>\n<body>\n{}\
             <div id=\"controls\"><button id=\"play\">play</button> <input id=\"time\" type=\"range\"> <span id=\"readout\"></span></div>\n\
             <script>\n{HTML_SCRIPT}\n</script>\n</body></html>\n",
            xml(&scene.name),
            svg_document(scene, &drawing, opts, view, false)
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_are_orthonormal_and_right_handed() {
        for v in [View::Xy, View::Xz, View::Yz, View::Iso] {
            let (r, u) = v.axes();
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            assert!((dot(r, r) - 1.0).abs() < 1e-15 && (dot(u, u) - 1.0).abs() < 1e-15);
            assert!(dot(r, u).abs() < 1e-15);
            assert_eq!(View::parse(v.as_str()), Some(v));
        }
        // iso: the viewer sits on the (1, 1, 1) diagonal, z up on the screen
        let (r, u) = View::Iso.axes();
        let towards_viewer = [
            r[1] * u[2] - r[2] * u[1],
            r[2] * u[0] - r[0] * u[2],
            r[0] * u[1] - r[1] * u[0],
        ];
        for c in towards_viewer {
            assert!((c - 1.0 / 3f64.sqrt()).abs() < 1e-15);
        }
    }

    fn planar(angle: f64, x: f64) -> Pose {
        let (sn, c) = angle.sin_cos();
        Pose {
            r: [x, 0.0, 0.0],
            rot: [[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    #[test]
    fn intervals_are_cut_so_that_no_body_turns_more_than_15_degrees() {
        let a = [planar(0.0, 0.0)];
        assert_eq!(
            parts_needed(&a, &[planar(14f64.to_radians(), 0.0)], &[1.0]),
            1
        );
        assert_eq!(
            parts_needed(&a, &[planar(15f64.to_radians(), 0.0)], &[1.0]),
            1
        );
        assert_eq!(
            parts_needed(&a, &[planar(16f64.to_radians(), 0.0)], &[1.0]),
            2
        );
        assert_eq!(
            parts_needed(&a, &[planar(-100f64.to_radians(), 0.0)], &[1.0]),
            7
        );
        // or move more than a tenth of its size: 0.35 m for a body of 1 m is 4 parts
        assert_eq!(parts_needed(&a, &[planar(0.0, 0.35)], &[1.0]), 4);
        assert!((turn_angle(&a[0], &planar(0.3, 0.0)) - 0.3).abs() < 1e-15);
        // halfway between two poses: the angle halfway, the body rigid
        let m = interpolate_pose(&a[0], &planar(1.0, 2.0), 0.5);
        assert!((turn_angle(&a[0], &m) - 0.5).abs() < 1e-12 && (m.r[0] - 1.0).abs() < 1e-15);
        // unwrapped angles go on past ±π
        let frames: Vec<Vec<Pose>> = (0..10).map(|k| vec![planar(k as f64, 0.0)]).collect();
        let un = planar_angles(&frames);
        for (k, a) in un.iter().enumerate() {
            assert!((a[0] - k as f64).abs() < 1e-12, "{k}: {}", a[0]);
        }
        assert_eq!(nice_floor(0.07), 0.05);
        assert_eq!(nice_floor(1.0), 1.0);
        assert_eq!(nice_floor(0.3), 0.2);
    }

    #[test]
    fn the_palette_does_not_repeat_within_sixty_bodies() {
        let c: std::collections::BTreeSet<String> = (0..60).map(body_colour).collect();
        assert_eq!(c.len(), 60);
        assert_eq!(body_colour(1), "#2ca02c");
    }

    #[test]
    fn nice_lengths_are_one_two_five() {
        assert_eq!(nice_length(4.0), 1.0);
        assert_eq!(nice_length(9.0), 2.0);
        assert_eq!(nice_length(2.2), 0.5);
    }
}
