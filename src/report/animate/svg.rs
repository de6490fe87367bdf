//! The SVG document: elements animated with SMIL on the frames' timing, the time label, the
//! scale bar and axes, and the scripts that seek and control the animation.

use super::*;

pub(super) fn num(v: f64) -> String {
    let s = format!("{v:.1}");
    if s == "-0.0" {
        "0.0".into()
    } else {
        s
    }
}

/// SMIL `<animate>` of one attribute through its per-frame values (nothing when constant).
pub(super) fn animate(out: &mut String, attr: &str, values: &[String], t: &Timing) {
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

pub(super) fn points_attr(pts: &[[f64; 2]]) -> String {
    pts.iter()
        .map(|p| format!("{},{}", num(p[0]), num(p[1])))
        .collect::<Vec<_>>()
        .join(" ")
}

/// An SVG element whose attributes change per frame: `attrs[a] = (name, per-frame values)`.
pub(super) fn element(
    out: &mut String,
    tag: &str,
    style: &str,
    attrs: &[(&str, Vec<String>)],
    t: &Timing,
) {
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
pub(super) fn block_at(c: [f64; 2], d: [f64; 2]) -> Vec<[f64; 2]> {
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
pub(super) fn nice_length(extent: f64) -> f64 {
    let target = extent / 4.0;
    let p = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&l| l <= target)
        .unwrap_or(p)
}

pub(super) fn svg_document(
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
pub(super) const SEEK_SVG: &str = r#"(function () {
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

pub(super) fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Decimals of the time label: about a thousandth of the span.
pub(super) fn clock_digits(span: f64) -> usize {
    if span > 0.0 {
        ((-(span / 1000.0).log10()).ceil()).clamp(2.0, 9.0) as usize
    } else {
        3
    }
}

/// The time label. One clock: the page's script writes the playback clock into `#clock` (the
/// same value as the slider's readout); without scripts (an SVG in an `<img>`), a strip of
/// labels, one per frame, moves under a clip window in step with the frames.
pub(super) fn time_label(s: &mut String, times: &[f64], width: f64, t: &Timing, digits: usize) {
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
pub(super) struct Timing {
    pub(super) dur: f64,
    pub(super) keys: String,
}

impl Timing {
    pub(super) fn new(times: &[f64], speed: f64) -> Timing {
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
                        // nine decimals, without trailing zeros (`0.015`, not `0.015000000`):
                        // the times repeat in every animated element of a large scene
                        _ => {
                            let t = format!("{f:.9}");
                            t.trim_end_matches('0').trim_end_matches('.').to_string()
                        }
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

    pub(super) fn attrs(&self) -> String {
        format!(
            "dur=\"{:.6}s\" repeatCount=\"indefinite\" keyTimes=\"{}\"",
            self.dur, self.keys
        )
    }
}

/// One shape drawn in a body's local picture coordinates (pixels, y down, origin at the
/// body's centre), for a group that the body's pose moves.
pub(super) fn draw_local(s: &mut String, shape: &Shape, scale: f64) {
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
pub(super) fn draw_moving(
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

pub(super) fn draw_item(
    s: &mut String,
    item: &Item,
    drawing: &Drawing,
    proj: &Projection,
    t: &Timing,
) {
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
pub(super) const HTML_SCRIPT: &str = r#"(function () {
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
