// The 3D view of a spatial scene: a small canvas renderer written for bondmech (no library,
// nothing loaded from the network). One copy serves both faces: `bondmech animate --out
// FILE.html` inlines it in its page, and the playground (`bondmech serve`, GET /) loads it as
// /view3d.js and draws the data of `POST /v1/animate?format=view3d` with it.
//
// bondmechView3d(D, ui) draws the scene data D ({bodies, joints, t, poses, traces, gravity,
// extent, speed, digits}) on ui.canvas and returns {t0, t1, seek(t), play(), pause(),
// playing(), redraw(), resize(), preset(name), ghost(data2), destroy()}; ghost draws a second motion of the same
// bodies faded under the first (the playground's compare). ui: canvas (required); fit(canvas) sizes it (called on
// window resize too); frames, labels: checkboxes (body frames off, labels on without them);
// onTime(t, text) after every drawing; start (time), autoplay (bool); grid (bool): the ground
// as a grid under the lowest point of the motion; preset: iso, front, side or top.
var bondmechView3d = function (D, ui) {
  'use strict';
  var cv = ui.canvas, g = cv.getContext('2d');
  var T = D.t, nb = D.bodies.length, t0 = T[0], t1 = T[T.length - 1];
  function fit() { if (ui.fit) ui.fit(cv); }
  function onResize() { fit(); draw(); }
  fit(); window.addEventListener('resize', onResize);
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
  // each body's pose at time t in the data S (D, or the ghost): centre along a line, attitude
  // by slerp between frames
  function posesOf(S, t) {
    var T = S.t, k = 0, lo = 0, hi = T.length - 1;
    if (t <= T[0]) k = 0; else if (t >= T[T.length - 1]) k = T.length - 2; else {
      while (hi - lo > 1) { var m = (lo + hi) >> 1; if (T[m] <= t) lo = m; else hi = m; }
      k = lo;
    }
    if (T.length < 2) k = 0;
    var k2 = Math.min(k + 1, T.length - 1), span = T[k2] - T[k];
    var s = span > 0 ? Math.min(Math.max((t - T[k]) / span, 0), 1) : 0;
    var out = [];
    for (var b = 0; b < nb; b++) {
      var A = S.poses[k], B = S.poses[k2], o = 7 * b;
      var r = [0, 1, 2].map(function (i) { return A[o + i] + s * (B[o + i] - A[o + i]); });
      var q = slerp(A.slice(o + 3, o + 7), B.slice(o + 3, o + 7), s);
      out.push({ r: r, q: q });
    }
    return out;
  }
  function poses(t) { return posesOf(D, t); }
  // the camera: orbit about the scene's centre, up against gravity
  var up = dot(D.gravity, D.gravity) > 0 ? norm(mul(D.gravity, -1)) : [0, 0, 1];
  var side = Math.abs(up[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
  var e1 = norm(sub(side, mul(up, dot(side, up)))), e2 = cross(up, e1);
  var yaw = 0.8, pitch = 0.45, zoom = 1;
  var centre = [0, 0, 0], cn = 0;
  for (var k = 0; k < D.poses.length; k += Math.max(1, Math.floor(D.poses.length / 50)))
    for (var b = 0; b < nb; b++) { centre = add(centre, D.poses[k].slice(7 * b, 7 * b + 3)); cn++; }
  centre = mul(centre, 1 / Math.max(cn, 1));
  // the radius the motion sweeps about that centre (every frame's points), and its lowest
  // height along `up` (where ui.grid draws the ground)
  var reach = 0.05, low = Infinity;
  for (var k = 0; k < D.poses.length; k++)
    for (var b = 0; b < nb; b++) {
      var r0 = D.poses[k].slice(7 * b, 7 * b + 3), q0 = D.poses[k].slice(7 * b + 3, 7 * b + 7);
      var d0 = sub(r0, centre); reach = Math.max(reach, Math.sqrt(dot(d0, d0)));
      low = Math.min(low, dot(r0, up));
      D.bodies[b].points.forEach(function (pt) {
        var w1 = add(r0, rot(q0, pt[1])), d1 = sub(w1, centre);
        reach = Math.max(reach, Math.sqrt(dot(d1, d1)));
        low = Math.min(low, dot(w1, up));
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
  var t = ui.start === undefined ? t0 : Math.min(Math.max(ui.start, t0), t1);
  var playing = !!ui.autoplay, last = null, alive = true;
  // a second motion of the same bodies (the decoupled twin), drawn faded under the first
  var ghost = null;
  // the bodies' faces at poses P (boxes and rods), unlit and unsorted
  function bodyFaces(P, faces) {
    D.bodies.forEach(function (B, b) {
      var p = P[b], ax = [rot(p.q, [1, 0, 0]), rot(p.q, [0, 1, 0]), rot(p.q, [0, 0, 1])];
      box(faces, p.r, ax[0], ax[1], ax[2], B.half[0], B.half[1], B.half[2], B.colour);
      B.points.forEach(function (pt) { rod(faces, p.r, add(p.r, rot(p.q, pt[1])), B.rod, B.colour); });
    });
  }
  // painter's algorithm: far faces first, lit by a light over the viewer's shoulder
  function paint(c, faces) {
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
  }
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
    if (ui.grid && isFinite(low)) {
      // the ground: a square grid under the lowest point of the motion, across the view
      var ext = 1.3 * reach, raw = ext / 5, p10 = Math.pow(10, Math.floor(Math.log10(raw))), fr = raw / p10;
      var step = (fr < 1.5 ? 1 : fr < 3.5 ? 2 : fr < 7.5 ? 5 : 10) * p10;
      var base = add(sub(centre, mul(up, dot(centre, up))), mul(up, low - 0.02 * reach));
      var m = Math.ceil(ext / step);
      g.strokeStyle = '#d5dbe5'; g.lineWidth = 1;
      for (var i = -m; i <= m; i++) {
        [[e1, e2], [e2, e1]].forEach(function (ax) {
          var a = project(c, add(base, add(mul(ax[0], i * step), mul(ax[1], -m * step))));
          var b2 = project(c, add(base, add(mul(ax[0], i * step), mul(ax[1], m * step))));
          g.beginPath(); g.moveTo(a[0], a[1]); g.lineTo(b2[0], b2[1]); g.stroke();
        });
      }
    }
    if (ghost) {
      var gf = [];
      bodyFaces(posesOf(ghost, t), gf);
      g.globalAlpha = 0.3; paint(c, gf); g.globalAlpha = 1;
    }
    bodyFaces(P, faces);
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
    paint(c, faces);
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
    if (ui.frames && ui.frames.checked) D.bodies.forEach(function (B, b) {
      var o = project(c, P[b].r), L = 0.15 * D.extent;
      ['#d62728', '#2ca02c', '#1f77b4'].forEach(function (col, i) {
        var e = [0, 0, 0]; e[i] = 1; var s = project(c, add(P[b].r, mul(rot(P[b].q, e), L)));
        g.strokeStyle = col; g.lineWidth = 2; g.beginPath(); g.moveTo(o[0], o[1]); g.lineTo(s[0], s[1]); g.stroke();
      });
    });
    if (!ui.labels || ui.labels.checked) D.bodies.forEach(function (B, b) {
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
    if (ui.onTime) ui.onTime(t, 't = ' + t.toFixed(D.digits) + ' s');
  }
  var drag = null;
  function down(e) { drag = [e.clientX, e.clientY, yaw, pitch]; }
  function up() { drag = null; }
  function move(e) {
    if (!drag) return;
    yaw = drag[2] - 0.01 * (e.clientX - drag[0]);
    pitch = Math.max(-1.5, Math.min(1.5, drag[3] + 0.01 * (e.clientY - drag[1])));
    draw();
  }
  function wheel(e) { e.preventDefault(); zoom *= Math.exp(-0.001 * e.deltaY); draw(); }
  cv.addEventListener('mousedown', down);
  window.addEventListener('mouseup', up);
  window.addEventListener('mousemove', move);
  cv.addEventListener('wheel', wheel);
  function tick(now) {
    if (!alive) return;
    if (playing) {
      if (last !== null) { t += (now - last) / 1000 * D.speed; if (t > t1) t = t0 + (t - t1) % Math.max(t1 - t0, 1e-9); }
      last = now; draw();
    }
    requestAnimationFrame(tick);
  }
  draw();
  requestAnimationFrame(tick);
  return {
    t0: t0, t1: t1, digits: D.digits,
    seek: function (s) { playing = false; t = Math.min(Math.max(s, t0), t1); draw(); },
    play: function () { playing = true; last = null; },
    pause: function () { playing = false; },
    playing: function () { return playing; },
    redraw: function () { draw(); },
    resize: function () { fit(); draw(); },
    // a view preset: iso, front, side or top
    preset: function (name) {
      var v = { iso: [0.8, 0.45], front: [0, 0], side: [Math.PI / 2, 0], top: [0, 1.5] }[name];
      if (v) { yaw = v[0]; pitch = v[1]; zoom = 1; draw(); }
    },
    // G: data of the same scene's bodies (the decoupled twin's motion), or null
    ghost: function (G) { ghost = G && G.poses && G.poses.length && G.poses[0].length === 7 * nb ? G : null; draw(); },
    destroy: function () {
      alive = false; playing = false;
      window.removeEventListener('resize', onResize);
      window.removeEventListener('mouseup', up);
      window.removeEventListener('mousemove', move);
    }
  };
};
