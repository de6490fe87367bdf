//! What is drawn, in world coordinates: the bodies' shapes, joints, sliders, springs, ground
//! marks and traces, and the projection that fits them into the picture.

use super::*;

/// A shape fixed to a body, in body coordinates (global coordinates on the ground).
pub(super) enum Shape {
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
    pub(super) fn points(&self) -> Vec<[f64; 3]> {
        match self {
            Shape::Line { a, b, .. } => vec![*a, *b],
            Shape::Polygon { pts, .. } => pts.clone(),
            Shape::Dot { at, .. } | Shape::Square { at } | Shape::Block { at, .. } => vec![*at],
        }
    }
}

/// A drawn item.
pub(super) enum Item {
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

pub(super) struct Projection {
    pub(super) right: [f64; 3],
    pub(super) up: [f64; 3],
    pub(super) scale: f64,
    pub(super) origin: [f64; 2],
}

impl Projection {
    pub(super) fn uv(right: [f64; 3], up: [f64; 3], p: [f64; 3]) -> [f64; 2] {
        let d = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        [d(right), d(up)]
    }

    pub(super) fn px(&self, p: [f64; 3]) -> [f64; 2] {
        let [u, v] = Self::uv(self.right, self.up, p);
        [
            self.origin[0] + self.scale * u,
            self.origin[1] - self.scale * v,
        ]
    }
}

/// A body point given by name or coordinates, in body coordinates (global for ground).
pub(super) fn point_coords(scene: &Scene, body: &str, p: &PointRef) -> Result<Vec<f64>> {
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

/// Everything drawn, frame by frame.
pub(super) struct Drawing {
    pub(super) items: Vec<Item>,
    pub(super) plan: FramePlan,
    /// Each body's angle in each frame, unwrapped (planar scenes; empty in space).
    pub(super) angles: Vec<Vec<f64>>,
}

impl Drawing {
    pub(super) fn times(&self) -> &[f64] {
        &self.plan.times
    }

    pub(super) fn pose(&self, k: usize, body: Option<usize>) -> Pose {
        body.map_or(Pose::GROUND, |b| self.plan.poses[k][b])
    }
}

pub(super) fn build_drawing(
    scene: &Scene,
    sol: &Solution,
    opts: &AnimationOptions,
) -> Result<Drawing> {
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
    pub(super) fn world_points(&self) -> Vec<[f64; 3]> {
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
pub(super) fn fit(drawing: &Drawing, view: View, width: f64, height: f64) -> Projection {
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
