//! A spatial scene's HTML page: the 3D view of [`super::super::view3d`] fed with the frames.

use super::*;

/// The 3D view's frames, traced points, playback speed, whether it was slowed, and the
/// clock's digits, for [`super::view3d`].
pub(super) struct View3d {
    pub(super) frames: Vec<FramePose>,
    pub(super) traces: Vec<(String, Vec<[f64; 3]>)>,
    pub(super) speed: f64,
    pub(super) slowed: bool,
    pub(super) digits: usize,
}

pub(super) fn view3d(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<View3d> {
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
pub(super) fn page_3d(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<String> {
    let v = view3d(scene, sol, opts)?;
    crate::report::view3d::page(scene, &v.frames, &v.traces, v.speed, v.slowed, v.digits)
}

/// The data of the 3D view of a spatial scene, as JSON (the page of `bondmech animate --out
/// FILE.html` draws it; the playground fetches it from `POST /v1/animate?format=view3d` and
/// draws it with the same renderer, [`view3d_script`]): bodies (name, colour, box half-sizes,
/// points), joints, the frames' times and every body's pose per frame (`x y z qw qx qy qz`),
/// traced points, gravity, playback speed. A planar scene is refused (its view is the SVG).
pub fn view3d_json(scene: &Scene, sol: &Solution, opts: &AnimationOptions) -> Result<String> {
    check_options(opts)?;
    let v = view3d(scene, sol, opts)?;
    crate::report::view3d::data(scene, &v.frames, &v.traces, v.speed, v.digits)
}

/// The 3D view's renderer, `bondmechView3d(data, ui)` (JavaScript, no library), as the
/// playground serves it at `/view3d.js`.
pub fn view3d_script() -> &'static str {
    crate::report::view3d::VIEW_JS
}
