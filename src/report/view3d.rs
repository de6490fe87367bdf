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
    let note = if slowed {
        format!(
            " — played at ×{speed}: slowed so that no body turns more than 15° per frame (--speed to change)"
        )
    } else {
        format!(" — ×{speed} speed")
    };
    let title = xml(&scene.name);
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
<script id=\"scene-data\" type=\"application/json\">{s}</script>\n<script>\n{VIEW_JS}\n</script>\n</body></html>\n"
    ))
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The renderer (written for bondmech; no library).
const VIEW_JS: &str = r#"(function () {
  var D = JSON.parse(document.getElementById('scene-data').textContent);
  var cv = document.getElementById('view'), g = cv.getContext('2d');
  var slider = document.getElementById('time'), readout = document.getElementById('readout');
  var clock = document.getElementById('clock'), button = document.getElementById('play');
  var showFrames = document.getElementById('frames'), showLabels = document.getElementById('labels');
  var T = D.t, nb = D.bodies.length, t0 = T[0], t1 = T[T.length - 1];
  function fit() { cv.width = Math.max(400, window.innerWidth); cv.height = Math.max(300, window.innerHeight - 44); }
  fit(); window.addEventListener('resize', function () { fit(); draw(); });
  // vectors
  function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function mul(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { var l = Math.sqrt(dot(a, a)) || 1; return mul(a, 1 / l); }
  function rot(q, v) { // rotate v by the unit quaternion q = [w, x, y, z]
    var u = [q[1], q[2], q[3]], w = q[0];
    var t = mul(cross(u, v), 2);
    return add(add(v, mul(t, w)), cross(u, t));
  }
  function slerp(a, b, s) {
    var d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0) { b = b.map(function (x) { return -x; }); d = -d; }
    if (d > 0.9995) {
      var r = a.map(function (x, i) { return x + s * (b[i] - x); });
      var l = Math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
      return r.map(function (x) { return x / l; });
    }
    var th = Math.acos(d), sn = Math.sin(th);
    var wa = Math.sin((1 - s) * th) / sn, wb = Math.sin(s * th) / sn;
    return a.map(function (x, i) { return wa * x + wb * b[i]; });
  }
  // each body's pose at time t: centre along a line, attitude by slerp between frames
  function poses(t) {
    var k = 0, lo = 0, hi = T.length - 1;
    if (t <= t0) k = 0; else if (t >= t1) k = T.length - 2; else {
      while (hi - lo > 1) { var m = (lo + hi) >> 1; if (T[m] <= t) lo = m; else hi = m; }
      k = lo;
    }
    if (T.length < 2) k = 0;
    var k2 = Math.min(k + 1, T.length - 1), span = T[k2] - T[k];
    var s = span > 0 ? Math.min(Math.max((t - T[k]) / span, 0), 1) : 0;
    var out = [];
    for (var b = 0; b < nb; b++) {
      var A = D.poses[k], B = D.poses[k2], o = 7 * b;
      var r = [0, 1, 2].map(function (i) { return A[o + i] + s * (B[o + i] - A[o + i]); });
      var q = slerp(A.slice(o + 3, o + 7), B.slice(o + 3, o + 7), s);
      out.push({ r: r, q: q });
    }
    return out;
  }
  // the camera: orbit about the scene's centre, up against gravity
  var up = dot(D.gravity, D.gravity) > 0 ? norm(mul(D.gravity, -1)) : [0, 0, 1];
  var side = Math.abs(up[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
  var e1 = norm(sub(side, mul(up, dot(side, up)))), e2 = cross(up, e1);
  var yaw = 0.8, pitch = 0.45, zoom = 1;
  var centre = [0, 0, 0], cn = 0;
  for (var k = 0; k < D.poses.length; k += Math.max(1, Math.floor(D.poses.length / 50)))
    for (var b = 0; b < nb; b++) { centre = add(centre, D.poses[k].slice(7 * b, 7 * b + 3)); cn++; }
  centre = mul(centre, 1 / Math.max(cn, 1));
  // the radius the motion sweeps about that centre (every frame's points)
  var reach = 0.05;
  for (var k = 0; k < D.poses.length; k++)
    for (var b = 0; b < nb; b++) {
      var r0 = D.poses[k].slice(7 * b, 7 * b + 3), q0 = D.poses[k].slice(7 * b + 3, 7 * b + 7);
      var d0 = sub(r0, centre); reach = Math.max(reach, Math.sqrt(dot(d0, d0)));
      D.bodies[b].points.forEach(function (pt) {
        var d1 = sub(add(r0, rot(q0, pt[1])), centre); reach = Math.max(reach, Math.sqrt(dot(d1, d1)));
      });
    }
  function camera() {
    var f = add(add(mul(e1, Math.cos(pitch) * Math.cos(yaw)), mul(e2, Math.cos(pitch) * Math.sin(yaw))), mul(up, Math.sin(pitch)));
    var right = norm(cross(up, f)), u = cross(f, right);
    var scale = zoom * Math.min(cv.width, cv.height) / (2.3 * reach);
    return { f: f, right: right, up: u, scale: scale };
  }
  function project(c, p) {
    var d = sub(p, centre);
    return [cv.width / 2 + c.scale * dot(d, c.right), cv.height / 2 - c.scale * dot(d, c.up), dot(d, c.f)];
  }
  function shade(hex, k) {
    var v = parseInt(hex.slice(1), 16), r = v >> 16, gg = (v >> 8) & 255, bl = v & 255;
    k = 0.35 + 0.65 * Math.max(0, k);
    return 'rgb(' + Math.round(r * k) + ',' + Math.round(gg * k) + ',' + Math.round(bl * k) + ')';
  }
  // a box from the centre c, half-extents along the unit axes (u, v, w)
  function box(faces, c, u, v, w, hu, hv, hw, colour) {
    var corner = function (a, b, d) { return add(add(add(c, mul(u, a * hu)), mul(v, b * hv)), mul(w, d * hw)); };
    var quads = [[[1,-1,-1],[1,1,-1],[1,1,1],[1,-1,1],u], [[-1,-1,-1],[-1,-1,1],[-1,1,1],[-1,1,-1],mul(u,-1)],
                 [[-1,1,-1],[-1,1,1],[1,1,1],[1,1,-1],v], [[-1,-1,-1],[1,-1,-1],[1,-1,1],[-1,-1,1],mul(v,-1)],
                 [[-1,-1,1],[1,-1,1],[1,1,1],[-1,1,1],w], [[-1,-1,-1],[-1,1,-1],[1,1,-1],[1,-1,-1],mul(w,-1)]];
    quads.forEach(function (q) {
      faces.push({ pts: q.slice(0, 4).map(function (s) { return corner(s[0], s[1], s[2]); }), n: q[4], colour: colour });
    });
  }
  function rod(faces, a, b, r, colour) {
    var d = sub(b, a), l = Math.sqrt(dot(d, d));
    if (l < 1e-12) return;
    var u = mul(d, 1 / l), s0 = Math.abs(u[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
    var v = norm(cross(u, s0)), w = cross(u, v);
    box(faces, mul(add(a, b), 0.5), u, v, w, l / 2, r, r, colour);
  }
  var t = t0, playing = true, pinned = false, last = null;
  function draw() {
    var c = camera(), P = poses(t), faces = [], marks = [];
    g.fillStyle = '#fff'; g.fillRect(0, 0, cv.width, cv.height);
    // traces (faint, under everything)
    D.traces.forEach(function (tr, i) {
      g.strokeStyle = ['rgba(230,0,126,0.35)', 'rgba(255,127,14,0.35)', 'rgba(214,39,40,0.35)'][i % 3];
      g.lineWidth = 1.5; g.beginPath();
      tr.pts.forEach(function (p, k) { var s = project(c, p); if (k) g.lineTo(s[0], s[1]); else g.moveTo(s[0], s[1]); });
      g.stroke();
    });
    D.bodies.forEach(function (B, b) {
      var p = P[b], ax = [rot(p.q, [1, 0, 0]), rot(p.q, [0, 1, 0]), rot(p.q, [0, 0, 1])];
      box(faces, p.r, ax[0], ax[1], ax[2], B.half[0], B.half[1], B.half[2], B.colour);
      B.points.forEach(function (pt) { rod(faces, p.r, add(p.r, rot(p.q, pt[1])), B.rod, B.colour); });
    });
    var world = function (b, pt) { return b < 0 ? pt : add(P[b].r, rot(P[b].q, pt)); };
    var dir = function (b, a) { return b < 0 ? a : rot(P[b].q, a); };
    D.joints.forEach(function (J) {
      var at = J.b2 >= 0 ? world(J.b2, J.p2) : world(J.b1, J.p1);
      if (J.kind === 'hinge' || J.kind === 'slider') {
        var a = norm(dir(J.b1, J.axis)), L = (J.kind === 'hinge' ? 0.12 : 0.5) * D.extent;
        var base = J.kind === 'hinge' ? at : world(J.b1, J.p1);
        rod(faces, sub(base, mul(a, L)), add(base, mul(a, L)), 0.012 * D.extent, '#333333');
      }
      marks.push({ p: at, kind: J.kind });
    });
    // painter's algorithm: far faces first, lit by a light over the viewer's shoulder
    var light = norm(add(add(c.f, mul(c.up, 0.6)), mul(c.right, -0.3)));
    faces.forEach(function (f) {
      f.s = f.pts.map(function (p) { return project(c, p); });
      f.z = (f.s[0][2] + f.s[1][2] + f.s[2][2] + f.s[3][2]) / 4;
    });
    faces.sort(function (a, b) { return a.z - b.z; });
    faces.forEach(function (f) {
      if (dot(f.n, c.f) <= 0) return; // facing away
      g.fillStyle = shade(f.colour, dot(f.n, light));
      g.strokeStyle = 'rgba(0,0,0,0.25)'; g.lineWidth = 0.7;
      g.beginPath(); f.s.forEach(function (s, i) { if (i) g.lineTo(s[0], s[1]); else g.moveTo(s[0], s[1]); });
      g.closePath(); g.fill(); g.stroke();
    });
    marks.forEach(function (m) {
      var s = project(c, m.p);
      g.fillStyle = m.kind === 'weld' ? '#222' : '#fff'; g.strokeStyle = '#222'; g.lineWidth = 2;
      g.beginPath(); g.arc(s[0], s[1], 5, 0, 2 * Math.PI); g.fill(); g.stroke();
    });
    // markers of the traced points
    D.traces.forEach(function (tr, i) {
      var parts = tr.name.split('.'), b = -1;
      D.bodies.forEach(function (B, k) { if (B.name === parts[0]) b = k; });
      if (b < 0) return;
      var pt = null; D.bodies[b].points.forEach(function (p) { if (p[0] === parts[1]) pt = p[1]; });
      if (!pt) return;
      var s = project(c, world(b, pt));
      g.fillStyle = ['rgb(230,0,126)', 'rgb(255,127,14)', 'rgb(214,39,40)'][i % 3];
      g.beginPath(); g.arc(s[0], s[1], 6, 0, 2 * Math.PI); g.fill();
    });
    if (showFrames.checked) D.bodies.forEach(function (B, b) {
      var o = project(c, P[b].r), L = 0.15 * D.extent;
      ['#d62728', '#2ca02c', '#1f77b4'].forEach(function (col, i) {
        var e = [0, 0, 0]; e[i] = 1; var s = project(c, add(P[b].r, mul(rot(P[b].q, e), L)));
        g.strokeStyle = col; g.lineWidth = 2; g.beginPath(); g.moveTo(o[0], o[1]); g.lineTo(s[0], s[1]); g.stroke();
      });
    });
    if (showLabels.checked) D.bodies.forEach(function (B, b) {
      var s = project(c, P[b].r);
      g.font = '13px Helvetica, Arial, sans-serif'; g.fillStyle = '#111';
      g.fillText(B.name, s[0] + 10, s[1] - 10);
    });
    // world axes at the origin
    var o = project(c, [0, 0, 0]), L = 0.25 * D.extent;
    ['x', 'y', 'z'].forEach(function (name, i) {
      var e = [0, 0, 0]; e[i] = L; var s = project(c, e);
      g.strokeStyle = '#777'; g.lineWidth = 1.5; g.beginPath(); g.moveTo(o[0], o[1]); g.lineTo(s[0], s[1]); g.stroke();
      g.fillStyle = '#555'; g.font = '12px Helvetica, Arial, sans-serif'; g.fillText(name, s[0] + 3, s[1] - 3);
    });
    var text = 't = ' + t.toFixed(D.digits) + ' s';
    clock.textContent = text; readout.textContent = text; slider.value = t;
  }
  slider.min = t0; slider.max = t1; slider.step = 'any';
  slider.oninput = function () { pinned = false; playing = false; button.textContent = 'play'; t = +slider.value; draw(); };
  button.onclick = function () { pinned = false; playing = !playing; button.textContent = playing ? 'pause' : 'play'; last = null; };
  showFrames.onchange = draw; showLabels.onchange = draw;
  var drag = null;
  cv.onmousedown = function (e) { drag = [e.clientX, e.clientY, yaw, pitch]; };
  window.onmouseup = function () { drag = null; };
  window.onmousemove = function (e) {
    if (!drag) return;
    yaw = drag[2] - 0.01 * (e.clientX - drag[0]);
    pitch = Math.max(-1.5, Math.min(1.5, drag[3] + 0.01 * (e.clientY - drag[1])));
    draw();
  };
  cv.onwheel = function (e) { e.preventDefault(); zoom *= Math.exp(-0.001 * e.deltaY); draw(); };
  function tick(now) {
    if (playing && !pinned) {
      if (last !== null) { t += (now - last) / 1000 * D.speed; if (t > t1) t = t0 + (t - t1) % Math.max(t1 - t0, 1e-9); }
      last = now; draw();
    }
    requestAnimationFrame(tick);
  }
  var m = /[?#&]t=([-+0-9.eE]+)/.exec(location.href);
  if (m) { pinned = true; playing = false; t = Math.min(Math.max(parseFloat(m[1]), t0), t1); }
  button.textContent = playing ? 'pause' : 'play';
  draw();
  requestAnimationFrame(tick);
})();"#;
