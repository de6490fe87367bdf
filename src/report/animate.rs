//! Animations of a solved motion (`bondmech animate`): one self-contained file, an SVG animated
//! with SMIL or an HTML page with the same SVG inline and a few lines of script for its
//! controls. Nothing is fetched from the network.
//!
//! What is drawn, from the scene and the solution's columns (`b.x, b.y, b.angle` for a planar
//! body; `b.x, b.y, b.z` and the attitude — the quaternion `b.qw…b.qz`, or else the Cardan
//! angles `b.psi, b.theta, b.phi` — for a spatial one):
//! - each body as arms from its centre of mass to each of its points (a bar between its two end
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
//! Frames are sampled from the solution at `t₀ + k·Δ` (linear interpolation between its rows),
//! with `Δ ≈ speed / fps` chosen so that the last frame is the last row; the animation lasts
//! `(t_end − t₀) / speed` seconds and loops. Appending `#t=0.7` (or `?t=0.7`) to the file's URL
//! opens it paused at t = 0.7 s of the motion.

use std::fmt::Write;

use crate::scene::{Body, Dimension, Inertia, JointKind, PointRef, Scene, GROUND};
use crate::solve::Solution;
use crate::{Error, Result};

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
    /// Seconds of motion per second of playback (> 0; 0.5 is slow motion).
    pub speed: f64,
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
            speed: 1.0,
            view: None,
            width: 800,
            height: 600,
            source: "the solution".into(),
        }
    }
}

/// The largest number of frames an animation may have.
pub const MAX_FRAMES: usize = 20_000;

const BODY_COLOURS: [&str; 6] = [
    "#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#7f7f7f", "#bcbd22",
];
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
    let need = |b: &str, c: &str| {
        col(format!("{b}.{c}")).ok_or_else(|| {
            Error::Options(format!(
                "{source}: no column `{b}.{c}` for body `{b}` (a CSV written by `bondmech run` for this scene has it)"
            ))
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
                return Err(Error::Options(format!(
                    "{source}: no attitude columns for body `{n}` (`{n}.qw,{n}.qx,{n}.qy,{n}.qz` or `{n}.psi,{n}.theta,{n}.phi`)"
                )));
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

/// The solution's row at time `t` (linear interpolation; clamped to its time span).
fn sample(sol: &Solution, t: f64) -> Vec<f64> {
    let k = sol.times.partition_point(|&s| s <= t);
    if k == 0 {
        return sol.rows[0].clone();
    }
    if k >= sol.times.len() {
        return sol.rows[sol.times.len() - 1].clone();
    }
    let (t0, t1) = (sol.times[k - 1], sol.times[k]);
    let a = (t - t0) / (t1 - t0);
    sol.rows[k - 1]
        .iter()
        .zip(&sol.rows[k])
        .map(|(x, y)| x + a * (y - x))
        .collect()
}

/// A drawn item; `pts[frame][vertex]` are world points.
enum Item {
    /// A body's arm or a spring (`dashed`).
    Line {
        pts: Vec<[[f64; 3]; 2]>,
        colour: String,
        width: f64,
        dashed: bool,
    },
    /// A body's outline through its points.
    Polygon {
        pts: Vec<Vec<[f64; 3]>>,
        colour: String,
    },
    /// A filled dot with a dark outline (centres of mass, point masses, joints, markers).
    Dot {
        pts: Vec<[f64; 3]>,
        radius: f64,
        fill: String,
        stroke: bool,
    },
    /// A weld: a small dark square.
    Square { pts: Vec<[f64; 3]> },
    /// A slider block at `pts[k].1` aligned with the rail through `pts[k].0` (screen space).
    Block { pts: Vec<([f64; 3], [f64; 3])> },
    /// A ground mark under a fixed point.
    Ground { at: [f64; 3] },
    /// A requested point's path: the faint trace (all frames).
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
            .ok_or_else(|| Error::Options(format!("body `{body}` has no point `{n}`"))),
    }
}

/// Frame times: `t₀ + k (t_end − t₀)/n`, `n ≈ (t_end − t₀)·fps/speed`.
fn frame_times(sol: &Solution, opts: &AnimationOptions) -> Result<Vec<f64>> {
    let (t0, t1) = (sol.times[0], sol.times[sol.times.len() - 1]);
    let span = t1 - t0;
    if span <= 0.0 {
        return Ok(vec![t0]);
    }
    let n = (span * opts.fps / opts.speed).round().max(1.0);
    if n >= MAX_FRAMES as f64 {
        return Err(Error::Options(format!(
            "--fps {} at --speed {} gives {n} frames for {span} s of motion (at most {MAX_FRAMES}): lower --fps or raise --speed",
            opts.fps, opts.speed
        )));
    }
    let n = n as usize;
    Ok((0..=n).map(|k| t0 + span * k as f64 / n as f64).collect())
}

/// Everything drawn, frame by frame.
struct Drawing {
    items: Vec<Item>,
    times: Vec<f64>,
}

fn build_drawing(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<Drawing> {
    if scene.bodies.is_empty() {
        return Err(Error::Options(
            "animate needs a scene with bodies (a raw bond graph has no geometry to draw)".into(),
        ));
    }
    if sol.times.is_empty() {
        return Err(Error::Options(format!(
            "{}: no rows to animate",
            opts.source
        )));
    }
    let cols = pose_columns(scene, sol, &opts.source)?;
    let times = frame_times(sol, opts)?;
    let poses: Vec<Vec<Pose>> = times
        .iter()
        .map(|&t| {
            let row = sample(sol, t);
            cols.iter().map(|c| pose(c, &row)).collect()
        })
        .collect();
    let body_pose = |k: usize, name: &str| -> Pose {
        scene.body_index(name).map_or(Pose::GROUND, |i| poses[k][i])
    };
    let track = |name: &str, p: &[f64]| -> Vec<[f64; 3]> {
        (0..times.len())
            .map(|k| body_pose(k, name).apply(p))
            .collect()
    };
    let mut items = Vec::new();
    // bodies: translucent outline, arms, centre
    for (bi, b) in scene.bodies.iter().enumerate() {
        let colour = BODY_COLOURS[bi % BODY_COLOURS.len()].to_string();
        if b.points.len() >= 3 {
            items.push(Item::Polygon {
                pts: (0..times.len())
                    .map(|k| {
                        b.points
                            .iter()
                            .map(|(_, p)| poses[k][bi].apply(p))
                            .collect()
                    })
                    .collect(),
                colour: colour.clone(),
            });
        }
        let centre = track(&b.name, &[0.0; 3]);
        for (_, p) in &b.points {
            let end = track(&b.name, p);
            if p.iter().all(|&c| c == 0.0) {
                continue;
            }
            items.push(Item::Line {
                pts: centre.iter().zip(&end).map(|(a, e)| [*a, *e]).collect(),
                colour: colour.clone(),
                width: 7.0,
                dashed: false,
            });
        }
        let (radius, fill) = if is_point_mass(b) {
            (9.0, colour.clone())
        } else {
            (3.5, INK.to_string())
        };
        items.push(Item::Dot {
            pts: centre,
            radius,
            fill,
            stroke: false,
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
        items.push(Item::Line {
            pts: a.iter().zip(&e).map(|(a, e)| [*a, *e]).collect(),
            colour: "#555".into(),
            width: 2.0,
            dashed: true,
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
    let scale = scene
        .bodies
        .iter()
        .flat_map(|b| {
            b.points
                .iter()
                .map(|(_, p)| p.iter().map(|c| c * c).sum::<f64>().sqrt())
        })
        .fold(0.0f64, f64::max)
        .max(0.05);
    for j in &scene.joints {
        let [b1, b2] = [&j.bodies[0], &j.bodies[1]];
        let p1 = point_coords(scene, b1, &j.points[0])?;
        let p2 = point_coords(scene, b2, &j.points[1])?;
        let w1 = track(b1, &p1);
        let w2 = track(b2, &p2);
        if let JointKind::Prismatic { axis } = &j.kind {
            let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
            let unit: Vec<f64> = axis.iter().map(|a| a / n).collect();
            // travel along the rail, in the first body's frame
            let s: Vec<f64> = (0..times.len())
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
            let end = |s: f64| -> Vec<f64> {
                p1.iter()
                    .zip(unit.iter().chain([0.0; 3].iter()))
                    .map(|(p, u)| p + s * u)
                    .collect()
            };
            let (ra, rb) = (track(b1, &end(lo - pad)), track(b1, &end(hi + pad)));
            if b1 == GROUND {
                // the rail's end nearer its anchor point is where it meets the ground
                let near = if (lo - pad).abs() <= (hi + pad).abs() {
                    ra[0]
                } else {
                    rb[0]
                };
                items.push(Item::Ground { at: near });
            }
            items.push(Item::Line {
                pts: ra.iter().zip(&rb).map(|(a, e)| [*a, *e]).collect(),
                colour: INK.into(),
                width: 2.5,
                dashed: false,
            });
            items.push(Item::Block {
                pts: (0..times.len())
                    .map(|k| {
                        let d = body_pose(k, b1).direction(&unit);
                        (d, w2[k])
                    })
                    .collect(),
            });
        } else if matches!(j.kind, JointKind::Weld) {
            items.push(Item::Square { pts: w2 });
        } else {
            items.push(Item::Dot {
                pts: if b2 == GROUND { w1 } else { w2 },
                radius: 5.0,
                fill: "white".into(),
                stroke: true,
            });
        }
        let slider = matches!(j.kind, JointKind::Prismatic { .. });
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
        // the trace through every row of the solution, the marker at the frames
        let bi = scene.body_index(b).expect("a body of the scene");
        items.push(Item::Trace {
            pts: sol
                .rows
                .iter()
                .map(|row| pose(&cols[bi], row).apply(coords))
                .collect(),
            colour: colour.clone(),
        });
        items.push(Item::Dot {
            pts: track(b, coords),
            radius: 6.0,
            fill: colour,
            stroke: false,
        });
    }
    // traces first (under everything), then the rest in order
    items.sort_by_key(|i| !matches!(i, Item::Trace { .. } | Item::Ground { .. }));
    Ok(Drawing { items, times })
}

impl Drawing {
    fn world_points(&self) -> impl Iterator<Item = [f64; 3]> + '_ {
        self.items
            .iter()
            .flat_map(|i| -> Box<dyn Iterator<Item = [f64; 3]>> {
                match i {
                    Item::Line { pts, .. } => Box::new(pts.iter().flat_map(|l| l.iter().copied())),
                    Item::Polygon { pts, .. } => Box::new(pts.iter().flatten().copied()),
                    Item::Dot { pts, .. } | Item::Square { pts } | Item::Trace { pts, .. } => {
                        Box::new(pts.iter().copied())
                    }
                    Item::Block { pts } => Box::new(pts.iter().map(|p| p.1)),
                    Item::Ground { at } => Box::new(std::iter::once(*at)),
                }
            })
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
fn animate(out: &mut String, attr: &str, values: &[String], dur: f64) {
    if values.windows(2).all(|w| w[0] == w[1]) {
        return;
    }
    let _ = write!(
        out,
        "<animate attributeName=\"{attr}\" dur=\"{dur:.6}s\" repeatCount=\"indefinite\" values=\"{}\"/>",
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
fn element(out: &mut String, tag: &str, style: &str, attrs: &[(&str, Vec<String>)], dur: f64) {
    let _ = write!(out, "<{tag} {style}");
    for (name, values) in attrs {
        let _ = write!(out, " {name}=\"{}\"", values[0]);
    }
    out.push('>');
    for (name, values) in attrs {
        animate(out, name, values, dur);
    }
    let _ = writeln!(out, "</{tag}>");
}

fn block_corners(proj: &Projection, dir: [f64; 3], at: [f64; 3]) -> Vec<[f64; 2]> {
    let c = proj.px(at);
    let tip = proj.px([at[0] + dir[0], at[1] + dir[1], at[2] + dir[2]]);
    let (mut dx, mut dy) = (tip[0] - c[0], tip[1] - c[1]);
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
    let n = drawing.times.len();
    let (t0, t1) = (drawing.times[0], drawing.times[n - 1]);
    let dur = ((t1 - t0) / opts.speed).max(1e-6);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"bondmech-animation\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" \
         data-scale=\"{}\" data-origin=\"{} {}\" data-right=\"{} {} {}\" data-up=\"{} {} {}\" data-view=\"{}\" \
         data-t0=\"{t0}\" data-t-end=\"{t1}\" data-speed=\"{}\" data-duration=\"{dur:.6}\" font-family=\"Helvetica, Arial, sans-serif\">",
        opts.width, opts.height, opts.width, opts.height,
        proj.scale, proj.origin[0], proj.origin[1],
        proj.right[0], proj.right[1], proj.right[2], proj.up[0], proj.up[1], proj.up[2],
        view.as_str(), opts.speed
    );
    let _ = writeln!(
        s,
        "<title>{} — bondmech animation ({} view)</title>",
        xml(&scene.name),
        view.as_str()
    );
    let _ = writeln!(s, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    for item in &drawing.items {
        draw_item(&mut s, item, &proj, dur);
    }
    // labels: scene name and view, time, scale bar, axes
    let _ = writeln!(
        s,
        "<text x=\"16\" y=\"26\" font-size=\"17\" fill=\"{INK}\">{} <tspan fill=\"#777\" font-size=\"13\">({} view, ×{} speed)</tspan></text>",
        xml(&scene.name),
        view.as_str(),
        opts.speed
    );
    time_label(&mut s, &drawing.times, w, dur);
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
  var m = /[?#&]t=([-+0-9.eE]+)/.exec(location.href);
  if (!m) return;
  var t0 = +s.getAttribute('data-t0'), sp = +s.getAttribute('data-speed');
  var d = +s.getAttribute('data-duration');
  var tau = Math.min(Math.max((parseFloat(m[1]) - t0) / sp, 0), d * (1 - 1e-9));
  s.pauseAnimations();
  s.setCurrentTime(tau);
})();"#;

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The time label: a strip of labels, one per frame, moved under a clip window.
fn time_label(s: &mut String, times: &[f64], width: f64, dur: f64) {
    let n = times.len();
    let (x, y, lh) = (width - 20.0, 28.0, 24.0);
    let _ = writeln!(
        s,
        "<clipPath id=\"tclip\"><rect x=\"{}\" y=\"{}\" width=\"160\" height=\"{lh}\"/></clipPath>",
        x - 160.0,
        y - 19.0
    );
    let _ = write!(
        s,
        "<g clip-path=\"url(#tclip)\" font-size=\"18\" fill=\"{INK}\" text-anchor=\"end\"><g>"
    );
    if n > 1 {
        // label k shows from half a frame before frame k to half a frame after it
        let key: Vec<String> = (0..n)
            .map(|k| {
                if k == 0 {
                    "0".into()
                } else {
                    format!("{:.6}", (k as f64 - 0.5) / (n - 1) as f64)
                }
            })
            .collect();
        let vals: Vec<String> = (0..n).map(|k| format!("0 {}", -(k as f64) * lh)).collect();
        let _ = write!(
            s,
            "<animateTransform attributeName=\"transform\" type=\"translate\" calcMode=\"discrete\" dur=\"{dur:.6}s\" repeatCount=\"indefinite\" keyTimes=\"{}\" values=\"{}\"/>",
            key.join(";"),
            vals.join(";")
        );
    }
    let digits = if times.len() > 1 && (times[1] - times[0]) < 0.01 {
        3
    } else {
        2
    };
    for (k, t) in times.iter().enumerate() {
        let _ = write!(
            s,
            "<text x=\"{x}\" y=\"{}\">t = {t:.digits$} s</text>",
            num(y + k as f64 * lh)
        );
    }
    let _ = writeln!(s, "</g></g>");
}

fn draw_item(s: &mut String, item: &Item, proj: &Projection, dur: f64) {
    let f = |p: [f64; 3]| proj.px(p);
    match item {
        Item::Line {
            pts,
            colour,
            width,
            dashed,
        } => {
            let ends: Vec<[[f64; 2]; 2]> = pts.iter().map(|l| [f(l[0]), f(l[1])]).collect();
            let v = |i: usize, c: usize| ends.iter().map(|e| num(e[i][c])).collect();
            let dash = if *dashed {
                " stroke-dasharray=\"6 4\""
            } else {
                ""
            };
            element(
                s,
                "line",
                &format!(
                    "stroke=\"{colour}\" stroke-width=\"{width}\" stroke-linecap=\"round\"{dash}"
                ),
                &[
                    ("x1", v(0, 0)),
                    ("y1", v(0, 1)),
                    ("x2", v(1, 0)),
                    ("y2", v(1, 1)),
                ],
                dur,
            );
        }
        Item::Polygon { pts, colour } => {
            let v: Vec<String> = pts
                .iter()
                .map(|poly| points_attr(&poly.iter().map(|&p| f(p)).collect::<Vec<_>>()))
                .collect();
            element(
                s,
                "polygon",
                &format!("fill=\"{colour}\" fill-opacity=\"0.18\" stroke=\"{colour}\" stroke-width=\"1.5\""),
                &[("points", v)],
                dur,
            );
        }
        Item::Dot {
            pts,
            radius,
            fill,
            stroke,
        } => {
            let c: Vec<[f64; 2]> = pts.iter().map(|&p| f(p)).collect();
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
                    ("cx", c.iter().map(|p| num(p[0])).collect()),
                    ("cy", c.iter().map(|p| num(p[1])).collect()),
                ],
                dur,
            );
        }
        Item::Square { pts } => {
            let c: Vec<[f64; 2]> = pts.iter().map(|&p| f(p)).collect();
            element(
                s,
                "rect",
                &format!("width=\"10\" height=\"10\" fill=\"{INK}\""),
                &[
                    ("x", c.iter().map(|p| num(p[0] - 5.0)).collect()),
                    ("y", c.iter().map(|p| num(p[1] - 5.0)).collect()),
                ],
                dur,
            );
        }
        Item::Block { pts } => {
            let v: Vec<String> = pts
                .iter()
                .map(|&(d, at)| points_attr(&block_corners(proj, d, at)))
                .collect();
            element(
                s,
                "polygon",
                &format!("fill=\"#ddd\" stroke=\"{INK}\" stroke-width=\"2\""),
                &[("points", v)],
                dur,
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
  var readout = document.getElementById('readout');
  slider.min = t0; slider.max = t1; slider.step = (t1 - t0) / 1000 || 1;
  function show(t) { slider.value = t; readout.textContent = 't = ' + t.toFixed(3) + ' s'; }
  function seek(t) {
    var tau = Math.min(Math.max((t - t0) / sp, 0), d * (1 - 1e-9));
    s.pauseAnimations(); s.setCurrentTime(tau); button.textContent = 'play'; show(t0 + tau * sp);
  }
  button.onclick = function () {
    if (s.animationsPaused()) { s.unpauseAnimations(); button.textContent = 'pause'; }
    else { s.pauseAnimations(); button.textContent = 'play'; }
  };
  slider.oninput = function () { seek(+slider.value); };
  function tick() {
    if (!s.animationsPaused()) show(t0 + (s.getCurrentTime() % d) * sp);
    requestAnimationFrame(tick);
  }
  var m = /[?#&]t=([-+0-9.eE]+)/.exec(location.href);
  if (m) seek(parseFloat(m[1])); else button.textContent = 'pause';
  requestAnimationFrame(tick);
})();"#;

/// Renders the animation of `sol` (a solution of `scene`, solved or read from a CSV that
/// `bondmech run` wrote) as one self-contained SVG or HTML document.
pub fn animation(
    scene: &Scene,
    sol: &Solution,
    opts: &AnimationOptions,
    format: AnimationFormat,
) -> Result<String> {
    if !(opts.fps > 0.0 && opts.fps.is_finite()) {
        return Err(Error::Options(format!(
            "--fps: must be > 0 (got {})",
            opts.fps
        )));
    }
    if !(opts.speed > 0.0 && opts.speed.is_finite()) {
        return Err(Error::Options(format!(
            "--speed: must be > 0 (got {})",
            opts.speed
        )));
    }
    let view = opts.view.unwrap_or(match scene.dimension {
        Dimension::Planar => View::Xy,
        Dimension::Spatial => View::Iso,
    });
    if scene.dimension == Dimension::Planar && view != View::Xy {
        return Err(Error::Options(format!(
            "--view {}: a planar scene has only the xy view",
            view.as_str()
        )));
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

    #[test]
    fn frames_end_on_the_last_row_and_sample_linearly() {
        let sol = Solution {
            columns: vec!["a".into()],
            times: vec![0.0, 1.0, 3.0],
            rows: vec![vec![0.0], vec![2.0], vec![0.0]],
            summary: Default::default(),
        };
        let opts = AnimationOptions {
            fps: 2.0,
            ..Default::default()
        };
        let t = frame_times(&sol, &opts).unwrap();
        assert_eq!(t, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]);
        assert_eq!(sample(&sol, 0.5), vec![1.0]);
        assert_eq!(sample(&sol, 2.0), vec![1.0]);
        assert_eq!(sample(&sol, 9.0), vec![0.0]);
        let e = frame_times(
            &sol,
            &AnimationOptions {
                fps: 1e5,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("lower --fps"), "{e}");
    }

    #[test]
    fn nice_lengths_are_one_two_five() {
        assert_eq!(nice_length(4.0), 1.0);
        assert_eq!(nice_length(9.0), 2.0);
        assert_eq!(nice_length(2.2), 0.5);
    }
}
