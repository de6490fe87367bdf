//! Which rows become frames: the rows nearest the animation's clock, plus those needed so that
//! no body turns more than [`MAX_TURN_DEGREES`] or moves more than [`MAX_MOVE_FRACTION`] of its
//! size between two frames; the frames as drawn, in JSON.

use super::*;

/// The most a body may turn between two frames (degrees).
pub const MAX_TURN_DEGREES: f64 = 15.0;
/// The most a body's centre may move between two frames, as a fraction of the body's size.
pub const MAX_MOVE_FRACTION: f64 = 0.1;

/// Each body's size: the largest distance of its points from its centre of mass; a body
/// without points (or a point mass) takes the largest size in the scene (at least 1 cm).
pub(super) fn body_sizes(scene: &Scene) -> Vec<f64> {
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

/// How many parts the interval between poses `a` and `b` must be cut into so that no body
/// turns more than [`MAX_TURN_DEGREES`] or moves more than [`MAX_MOVE_FRACTION`] of its size
/// in one part (1: the interval is fine as it is).
pub(super) fn parts_needed(a: &[Pose], b: &[Pose], sizes: &[f64]) -> usize {
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

/// The frames of an animation: their times and every body's pose in each.
#[derive(Clone)]
pub(super) struct FramePlan {
    pub(super) times: Vec<f64>,
    pub(super) poses: Vec<Vec<Pose>>,
    /// Frames that are not rows of the solution (poses interpolated between two rows).
    pub(super) interpolated: usize,
    /// Seconds of motion per second of playback.
    pub(super) speed: f64,
    /// Whether the speed was lowered from 1 so that the motion can be followed.
    pub(super) slowed: bool,
}

/// The solution's rows at distinct, increasing times (an event row at a time already seen is
/// left out) and every body's pose in each.
pub(super) fn row_poses(sol: &Solution, cols: &[PoseColumns]) -> (Vec<usize>, Vec<Vec<Pose>>) {
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
pub(super) fn nice_floor(x: f64) -> f64 {
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
pub(super) fn plan_frames(
    scene: &Scene,
    sol: &Solution,
    opts: &AnimationOptions,
) -> Result<FramePlan> {
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
