//! The 3D view of a spatial scene (`bondmech animate SCENE.json --out FILE.html`): one
//! self-contained HTML page with a small canvas renderer written for bondmech (no library,
//! nothing loaded from the network).
//!
//! - every body is a shaded box sized from its principal inertia (the uniform box of the same
//!   mass and inertia: `a² = 6 (J_y + J_z − J_x) / m`, …, at least a twentieth of the scene),
//!   with a rod to each of its points; faces are depth-sorted (painter's algorithm) and lit
//!   by a light fixed to the camera;
//! - hinges are drawn as their axis (a dark bar through the joint point), sliders as their rail,
//!   ball joints and welds as dots; the world axes at the origin; body frames on demand (the
//!   `frames` box); body names as labels (the `labels` box);
//! - the camera orbits with the mouse (drag) and zooms with the wheel; "up" on the screen is
//!   against gravity (z when there is none);
//! - the motion is the frames [`super::animate`] picks (no body turning more than 15° between
//!   two of them); between frames each body's pose is interpolated (its centre along a straight
//!   line, its attitude by quaternion slerp), so bodies stay rigid at any playback speed;
//! - one clock for the label, the slider and its readout; `#t=T` opens it paused at T.

use std::fmt::Write;

use super::error::{ReportError, Result};
use super::palette::body_colour;
use crate::mech::joints::{glyph, Glyph};
use crate::scene::{Inertia, PointRef, Scene, GROUND};

/// A number for the page's JSON (finite, shortest round trip).
fn n(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        "0".into()
    }
}

fn v3(p: &[f64]) -> String {
    format!(
        "[{},{},{}]",
        n(p.first().copied().unwrap_or(0.0)),
        n(p.get(1).copied().unwrap_or(0.0)),
        n(p.get(2).copied().unwrap_or(0.0))
    )
}

fn json_str(s: &str) -> String {
    serde_json::Value::from(s).to_string()
}

/// One frame of the 3D view: its time and each body's centre and attitude quaternion
/// `[w, x, y, z]`.
pub(crate) struct FramePose {
    pub(crate) t: f64,
    pub(crate) poses: Vec<([f64; 3], [f64; 4])>,
}

/// The page for `scene`: `frames` (times and each body's pose per frame), `traces` (requested
/// points' paths over every row: name and world points), playback `speed`, `digits` of the
/// clock.
pub(crate) fn page(
    scene: &Scene,
    frames: &[FramePose],
    traces: &[(String, Vec<[f64; 3]>)],
    speed: f64,
    slowed: bool,
    digits: usize,
) -> Result<String> {
    let s = data(scene, frames, traces, speed, digits)?;
    let note = if slowed {
        format!(
            " — played at ×{speed}: slowed so that no body turns more than 15° per frame (--speed to change)"
        )
    } else {
        format!(" — ×{speed} speed")
    };
    let title = xml(&scene.name);
    // a name holding `</script>` must not end the data block: `<` only occurs inside the
    // JSON's strings, where `<\/` is the same text
    let s = s.replace("</", "<\\/");
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{title} — bondmech 3D</title>\n\
<style>body{{margin:0;font-family:Helvetica,Arial,sans-serif;background:#fff}}#bar{{padding:6px 12px;font-size:14px}}\
#bar input[type=range]{{width:420px;vertical-align:middle}}#bar button{{width:5em}}canvas{{display:block;cursor:grab}}\
#head{{position:absolute;left:12px;top:8px;font-size:17px;color:#222}}#head span{{display:block;font-size:13px;color:#777}}\
#clock{{position:absolute;right:16px;top:8px;font-size:18px;color:#222}}</style></head>\n<body>\n\
<div id=\"head\">{title}<span>{note}; drag to orbit, wheel to zoom</span></div><span id=\"clock\">t = 0 s</span>\n\
<canvas id=\"view\" width=\"800\" height=\"600\"></canvas>\n\
<div id=\"bar\"><button id=\"play\">play</button> <input id=\"time\" type=\"range\"> <span id=\"readout\"></span> \
<label><input id=\"frames\" type=\"checkbox\"> frames</label> <label><input id=\"labels\" type=\"checkbox\" checked> labels</label></div>\n\
<script id=\"scene-data\" type=\"application/json\">{s}</script>\n<script>\n{VIEW_JS}\n{PAGE_JS}\n</script>\n</body></html>\n"
    ))
}

/// The scene data the renderer draws, as JSON: `{"bodies": [{name, colour, half, rod,
/// points}], "joints": [{name, kind, b1, p1, b2, p2, axis}], "t": [...], "poses": [[x y z qw qx
/// qy qz per body] per frame], "traces": [{name, pts}], "gravity", "extent", "speed", "digits",
/// "name"}` — the body of `POST /v1/animate?format=view3d`.
pub(crate) fn data(
    scene: &Scene,
    frames: &[FramePose],
    traces: &[(String, Vec<[f64; 3]>)],
    speed: f64,
    digits: usize,
) -> Result<String> {
    if frames.is_empty() {
        return Err(ReportError::NoFrames);
    }
    // scene extent, for sizes
    let mut extent = 0.0f64;
    for f in frames {
        for (r, _) in &f.poses {
            extent = extent.max(r.iter().map(|c| c.abs()).fold(0.0, f64::max));
        }
    }
    for b in &scene.bodies {
        for (_, p) in &b.points {
            extent = extent.max(p.iter().map(|c| c.abs()).fold(0.0, f64::max));
        }
    }
    let extent = extent.max(0.1);
    let mut s = String::new();
    s.push_str("{\"bodies\":[");
    for (i, b) in scene.bodies.iter().enumerate() {
        let size = b
            .points
            .iter()
            .map(|(_, p)| p.iter().map(|c| c * c).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        let floor = (0.05 * extent).max(0.12 * size);
        let half = match b.inertia {
            Inertia::Principal(j) if b.mass > 0.0 => {
                let e = |a: f64, b2: f64, c: f64| {
                    let sq = 6.0 * (b2 + c - a) / b.mass;
                    if sq > 0.0 {
                        0.5 * sq.sqrt()
                    } else {
                        0.0
                    }
                };
                [
                    e(j[0], j[1], j[2]),
                    e(j[1], j[2], j[0]),
                    e(j[2], j[0], j[1]),
                ]
                .map(|h| h.max(0.5 * floor))
            }
            _ => [0.5 * floor; 3],
        };
        if i > 0 {
            s.push(',');
        }
        let pts: Vec<String> = b
            .points
            .iter()
            .map(|(k, p)| format!("[{},{}]", json_str(k), v3(p)))
            .collect();
        let _ = write!(
            s,
            "{{\"name\":{},\"colour\":{},\"half\":{},\"rod\":{},\"points\":[{}]}}",
            json_str(&b.name),
            json_str(&body_colour(i)),
            v3(&half),
            n(0.3 * floor),
            pts.join(",")
        );
    }
    s.push_str("],\"joints\":[");
    let point = |body: &str, p: &PointRef| -> Vec<f64> {
        match p {
            PointRef::Coords(c) => c.clone(),
            PointRef::Named(name) => scene
                .bodies
                .iter()
                .find(|b| b.name == body)
                .and_then(|b| b.point(name))
                .map(<[f64]>::to_vec)
                .unwrap_or_default(),
        }
    };
    for (k, j) in scene.joints.iter().enumerate() {
        let [b1, b2] = [&j.bodies[0], &j.bodies[1]];
        let (kind, axis) = match glyph(&j.kind) {
            Glyph::Hinge { axis } => ("hinge", axis),
            Glyph::Slider { axis } => ("slider", axis),
            Glyph::Weld => ("weld", vec![0.0; 3]),
            _ => ("ball", vec![0.0; 3]),
        };
        let idx = |b: &str| {
            if b == GROUND {
                -1
            } else {
                scene.body_index(b).map_or(-1, |i| i as i64)
            }
        };
        if k > 0 {
            s.push(',');
        }
        let _ = write!(
            s,
            "{{\"name\":{},\"kind\":\"{kind}\",\"b1\":{},\"p1\":{},\"b2\":{},\"p2\":{},\"axis\":{}}}",
            json_str(&j.name),
            idx(b1),
            v3(&point(b1, &j.points[0])),
            idx(b2),
            v3(&point(b2, &j.points[1])),
            v3(&axis)
        );
    }
    s.push_str("],\"t\":[");
    s.push_str(&frames.iter().map(|f| n(f.t)).collect::<Vec<_>>().join(","));
    // poses: per frame, per body: x y z qw qx qy qz
    s.push_str("],\"poses\":[");
    for (k, f) in frames.iter().enumerate() {
        if k > 0 {
            s.push(',');
        }
        let flat: Vec<String> = f
            .poses
            .iter()
            .flat_map(|(r, q)| r.iter().chain(q.iter()).map(|v| n(*v)).collect::<Vec<_>>())
            .collect();
        let _ = write!(s, "[{}]", flat.join(","));
    }
    s.push_str("],\"traces\":[");
    for (k, (name, pts)) in traces.iter().enumerate() {
        if k > 0 {
            s.push(',');
        }
        let p: Vec<String> = pts.iter().map(|p| v3(p)).collect();
        let _ = write!(
            s,
            "{{\"name\":{},\"pts\":[{}]}}",
            json_str(name),
            p.join(",")
        );
    }
    let g = &scene.gravity;
    let _ = write!(
        s,
        "],\"gravity\":{},\"extent\":{},\"speed\":{},\"digits\":{digits},\"name\":{}}}",
        v3(g),
        n(extent),
        n(speed),
        json_str(&scene.name)
    );
    Ok(s)
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The renderer (written for bondmech; no library).
/// The renderer (written for bondmech; no library): `bondmechView3d(data, ui)`, shared with the
/// playground, which serves it as `/view3d.js`.
pub(crate) const VIEW_JS: &str = include_str!("assets/view3d.js");

/// The standalone page's wiring: its slider, button, clock, check boxes and `#t=T`.
const PAGE_JS: &str = r#"(function () {
  var $ = function (id) { return document.getElementById(id); };
  var D = JSON.parse($('scene-data').textContent);
  var slider = $('time'), readout = $('readout'), clock = $('clock'), button = $('play');
  var m = /[?#&]t=([-+0-9.eE]+)/.exec(location.href);
  var v = bondmechView3d(D, {
    canvas: $('view'), frames: $('frames'), labels: $('labels'),
    fit: function (cv) { cv.width = Math.max(400, window.innerWidth); cv.height = Math.max(300, window.innerHeight - 44); },
    onTime: function (t, text) { clock.textContent = text; readout.textContent = text; slider.value = t; },
    start: m ? parseFloat(m[1]) : undefined, autoplay: !m
  });
  slider.min = v.t0; slider.max = v.t1; slider.step = 'any';
  slider.oninput = function () { v.seek(+slider.value); button.textContent = 'play'; };
  button.onclick = function () {
    if (v.playing()) v.pause(); else v.play();
    button.textContent = v.playing() ? 'pause' : 'play';
  };
  $('frames').onchange = v.redraw; $('labels').onchange = v.redraw;
  button.textContent = v.playing() ? 'pause' : 'play';
})();"#;
