// bondmech playground (GET /): the page draws only what the service returns — /v1/run's rows
// as polylines, /v1/animate's SVG, /v1/graph's SVG — and inserts every text that comes from a
// scene as text (textContent), never as markup. Requests go to this origin only.
'use strict';
(function () {
  var $ = function (id) { return document.getElementById(id); };
  var picker = $('scene-picker'), editor = $('editor'), problems = $('problems');
  var validity = $('validity'), sceneName = $('scene-name'), runError = $('run-error');
  var runButton = $('run'), compareButton = $('compare'), cancelButton = $('cancel');
  var progress = $('progress'), status = $('status'), summary = $('summary');
  var plot = $('plot'), plotColumns = $('plot-columns'), csvButton = $('csv');
  var animation = $('animation'), time = $('time'), play = $('play'), readout = $('time-readout');
  var graph = $('graph'), verdict = $('verdict');
  var SVG_NS = 'http://www.w3.org/2000/svg';

  var state = {
    run: null,        // {columns, rows, summary, error, partial}
    twin: null,       // the decoupled twin's {columns, rows} after compare
    controller: null, // the AbortController of the work in progress
    validation: 0,    // sequence number of the latest validation request
    anim: null        // {svg, t0, t1, speed, duration, digits} or, in 3D, {view, t0, t1, digits}
  };

  function clear(el) { while (el.firstChild) el.removeChild(el.firstChild); }
  function el(tag, text, cls) {
    var e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = String(text);
    if (cls) e.className = cls;
    return e;
  }
  function svgEl(tag, attrs, text) {
    var e = document.createElementNS(SVG_NS, tag);
    for (var k in attrs) if (Object.prototype.hasOwnProperty.call(attrs, k)) e.setAttribute(k, String(attrs[k]));
    if (text !== undefined) e.textContent = String(text);
    return e;
  }
  function hint(target, text) { clear(target); target.appendChild(el('p', text, 'hint')); }
  function setStatus(text) { status.textContent = text; }
  function num(x, digits) {
    if (x === null || x === undefined) return '—';
    if (typeof x !== 'number') return String(x);
    if (x === 0) return '0';
    var a = Math.abs(x);
    return (a >= 1e4 || a < 1e-3) ? x.toExponential(digits || 3) : x.toPrecision(digits || 4);
  }

  // ---------------------------------------------------------------- requests (same origin)
  function post(path, body, signal) {
    return fetch(path, {
      method: 'POST', body: body, signal: signal,
      headers: { 'Content-Type': 'application/json' }, credentials: 'same-origin'
    });
  }
  function solveQuery(extra) {
    var q = new URLSearchParams();
    var f = $('formulation').value, rtol = $('rtol').value.trim(), tEnd = $('t_end').value.trim();
    if (f) q.set('formulation', f);
    if (rtol) q.set('rtol', rtol);
    if (tEnd) q.set('t_end', tEnd);
    for (var k in (extra || {})) q.set(k, extra[k]);
    var s = q.toString();
    return s ? '?' + s : '';
  }
  // A problem+json answer as one readable text (detail, then each path: message).
  function problemText(p) {
    if (!p) return 'the request failed';
    var lines = [(p.title ? p.title + ': ' : '') + (p.detail || '')];
    (p.errors || []).forEach(function (e) {
      lines.push((e.path ? e.path + ': ' : '') + e.message);
    });
    return lines.join('\n');
  }
  function readProblem(r) {
    return r.text().then(function (t) {
      try { return JSON.parse(t); } catch (e) { return { title: 'HTTP ' + r.status, detail: t }; }
    });
  }

  // ---------------------------------------------------------------- scenes and validation
  function loadScenes() {
    return fetch('/v1/scenes').then(function (r) { return r.json(); }).then(function (names) {
      names.forEach(function (n) {
        var o = el('option', n);
        o.value = n;
        picker.appendChild(o);
      });
      picker.value = names.indexOf('double_pendulum') >= 0 ? 'double_pendulum' : names[0];
      return loadScene(picker.value);
    });
  }
  // the picker names the scene in the editor: "edited" once its text is no longer the file's
  var edited = el('option', '(edited)');
  edited.value = '';
  edited.disabled = true;
  var loaded = { name: null, text: null };
  function loadScene(name) {
    return fetch('/v1/scenes/' + encodeURIComponent(name)).then(function (r) { return r.text(); })
      .then(function (text) {
        loaded = { name: name, text: text };
        editor.value = text;
        editor.dispatchEvent(new Event('input'));
      });
  }
  var validateTimer = null;
  function onEdit() {
    var name = '';
    try { var doc = JSON.parse(editor.value); name = (doc && typeof doc.name === 'string') ? doc.name : ''; }
    catch (e) { name = ''; }
    sceneName.textContent = name;
    if (editor.value === loaded.text) {
      if (edited.parentNode) picker.removeChild(edited);
      picker.value = loaded.name;
    } else {
      if (!edited.parentNode) picker.appendChild(edited);
      picker.value = '';
    }
    if (validateTimer) clearTimeout(validateTimer);
    validateTimer = setTimeout(validate, 120);
  }
  function validate() {
    var seq = ++state.validation;
    post('/v1/validate', editor.value).then(function (r) { return r.json(); }).then(function (v) {
      if (seq !== state.validation) return; // a newer edit is being checked
      showProblems(v);
    }).catch(function () { /* the next edit checks again */ });
  }
  function showProblems(v) {
    clear(problems);
    problems.dataset.valid = v.valid ? 'true' : 'false';
    editor.classList.toggle('invalid', !v.valid);
    validity.className = 'validity ' + (v.valid ? 'ok' : 'bad');
    validity.textContent = v.valid ? 'none: the scene is valid' : v.errors.length + ' found';
    (v.errors || []).forEach(function (e) {
      var li = el('li');
      if (e.path) { li.appendChild(el('code', e.path)); li.appendChild(document.createTextNode(': ')); }
      var where = (v.line !== undefined) ? ' (line ' + v.line + ', column ' + v.column + ')' : '';
      li.appendChild(document.createTextNode(e.message + where));
      problems.appendChild(li);
    });
  }

  // ---------------------------------------------------------------- run (NDJSON stream)
  function begin() {
    if (state.controller) state.controller.abort();
    state.controller = new AbortController();
    cancelButton.disabled = false;
    progress.value = 0;
    runError.hidden = true;
    runError.textContent = '';
    return state.controller.signal;
  }
  function end(signal) {
    if (state.controller && state.controller.signal === signal) {
      state.controller = null;
      cancelButton.disabled = true;
    }
  }
  function showError(text) {
    runError.hidden = false;
    runError.textContent = text;
  }
  // Reads /v1/run?format=ndjson: {columns, rows: n}, one row array per output time, then
  // {summary} or {error}; progress is the share of the n rows received.
  function streamRun(body, signal) {
    var run = { columns: null, rows: [], summary: null, error: null, expected: 0 };
    return post('/v1/run' + solveQuery({ format: 'ndjson' }), body, signal).then(function (r) {
      if (!r.ok) {
        return readProblem(r).then(function (p) {
          run.error = p;
          if (p.columns) run.columns = p.columns;
          if (p.rows) run.rows = p.rows;
          return run;
        });
      }
      var reader = r.body.getReader(), decoder = new TextDecoder(), buffer = '', lastDraw = performance.now();
      function line(text) {
        if (!text.trim()) return;
        var v = JSON.parse(text);
        if (Array.isArray(v)) run.rows.push(v);
        else if (v.columns) { run.columns = v.columns; run.expected = v.rows; }
        else if (v.summary) run.summary = v.summary;
        else if (v.error) run.error = v.error;
      }
      function pump() {
        return reader.read().then(function (chunk) {
          if (chunk.done) { line(buffer); return run; }
          buffer += decoder.decode(chunk.value, { stream: true });
          var parts = buffer.split('\n');
          buffer = parts.pop();
          parts.forEach(line);
          if (run.expected) {
            progress.value = run.rows.length / run.expected;
            setStatus('solving: ' + run.rows.length + ' of ' + run.expected + ' rows');
          }
          // a long run is plotted as it goes (at most every 0.3 s)
          var now = performance.now();
          if (run.columns && run.rows.length && now - lastDraw > 300) {
            lastDraw = now;
            if (!run.listed) { fillColumns(run); run.listed = true; }
            state.run = run;
            drawPlot();
          }
          return pump();
        });
      }
      return pump();
    });
  }

  function sceneDoc() { try { return JSON.parse(editor.value); } catch (e) { return null; } }

  function doRun() {
    var signal = begin(), body = editor.value, started = performance.now();
    var doc = sceneDoc();
    var hasBodies = !!(doc && Array.isArray(doc.bodies) && doc.bodies.length);
    state.twin = null;
    hint(verdict, 'compare runs the DAE and its decoupled twin');
    setStatus('solving…');
    document.body.dataset.state = 'running';
    var graphDone = loadGraph(body, signal);
    // nothing of the previous run stays on show
    state.run = null;
    clear(summary);
    summary.appendChild(el('dt', 'status'));
    summary.appendChild(el('dd', 'solving…'));
    hint(plot, 'solving…');
    csvButton.disabled = true;
    resetTime();
    hint(animation, hasBodies ? 'the motion is drawn once the run has finished'
      : 'no animation: a raw bond graph has no geometry to draw');
    var runDone = streamRun(body, signal).then(function (run) {
      state.run = run;
      showSummary(run);
      fillColumns(run);
      drawPlot();
      csvButton.disabled = !run.columns;
      if (run.error) {
        var rows = run.rows.length;
        showError(problemText(run.error) + (rows ? '\n\n' + rows + ' rows computed before it stopped are shown in the plot and the summary.' : ''));
      }
      return run;
    });
    // the animation solves again on the server (at the output times it needs): asked once the
    // run has succeeded, so a failing or cancelled run costs one solve only
    var animDone = runDone.then(function (run) {
      if (!hasBodies) return null;
      if (run.error) { hint(animation, 'no animation: the run did not finish'); return null; }
      return loadAnimation(body, signal);
    });
    return Promise.all([runDone, animDone, graphDone]).then(function (all) {
      var ms = Math.round(performance.now() - started);
      var run = all[0];
      setStatus(run.error ? 'failed after ' + ms + ' ms' : 'done in ' + ms + ' ms');
      progress.value = run.error ? progress.value : 1;
      document.body.dataset.state = run.error ? 'failed' : 'done';
      document.body.dataset.runMs = String(ms);
    }).catch(function (e) {
      if (e && e.name === 'AbortError') { setStatus('cancelled'); document.body.dataset.state = 'cancelled'; }
      else { showError(String(e)); setStatus('failed'); document.body.dataset.state = 'failed'; }
    }).then(function () { end(signal); });
  }

  function showSummary(run) {
    clear(summary);
    var s = run.summary || {};
    function row(k, v, cls) { summary.appendChild(el('dt', k)); summary.appendChild(el('dd', v, cls)); }
    if (run.error) row('status', 'failed: ' + (run.error.title || 'error'), 'warn');
    if (!run.summary) {
      row('rows', run.rows.length + (run.expected ? ' of ' + run.expected : '') + ' (partial)');
      if (run.rows.length) row('t reached', num(run.rows[run.rows.length - 1][0]));
      return;
    }
    row('formulation', s.formulation + (s.solver ? ' (' + s.solver + ')' : ''));
    row('states', (s.states || []).length + ': ' + (s.states || []).join(', '));
    row('steps', s.steps);
    row('CPU', num(s.cpu_seconds * 1e3, 3) + ' ms');
    row('energy drift', s.energy_drift === null || s.energy_drift === undefined ? (s.energy_check || '—') : num(s.energy_drift) + ' J');
    row('constraint error', num(s.max_constraint_error));
    row('rows', run.rows.length);
    row('completed', s.completed ? 'yes (t = ' + num(s.t_reached) + ')' : 'no: ' + (s.stopped_by || ''));
    var w = s.warnings || [];
    row('warnings', w.length ? w.join('\n') : 'none', w.length ? 'warn' : '');
  }

  // ---------------------------------------------------------------- plot
  var PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2'];
  function fillColumns(run) {
    var keep = {};
    Array.prototype.forEach.call(plotColumns.selectedOptions, function (o) { keep[o.value] = true; });
    clear(plotColumns);
    if (!run.columns) return;
    var names = run.columns.slice(1), any = false;
    names.forEach(function (n) { if (keep[n]) any = true; });
    names.forEach(function (n, i) {
      var o = el('option', n);
      o.value = n;
      o.selected = any ? !!keep[n] : i < 2;
      plotColumns.appendChild(o);
    });
  }
  // Round tick values (1-2-5 steps), about five over [lo, hi].
  function ticks(lo, hi) {
    var raw = (hi - lo) / 5, p = Math.pow(10, Math.floor(Math.log10(raw))), f = raw / p;
    var step = (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p, out = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) {
      out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
    }
    return out;
  }
  function tickLabel(v) { return (Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-3)) ? v.toExponential(1) : String(+v.toPrecision(6)); }
  function drawPlot() {
    clear(plot);
    var run = state.run;
    if (!run || !run.columns || !run.rows.length) { hint(plot, run && run.error ? 'no rows to plot' : 'run a scene to plot it'); return; }
    var chosen = Array.prototype.map.call(plotColumns.selectedOptions, function (o) { return o.value; });
    if (!chosen.length) { hint(plot, 'choose columns to plot'); return; }
    var W = 900, H = 300, L = 70, R = 170, T = 12, B = 36;
    var series = [];
    chosen.forEach(function (name, i) {
      var k = run.columns.indexOf(name);
      if (k > 0) series.push({ name: name, rows: run.rows, k: k, colour: PALETTE[i % PALETTE.length], dash: '' });
      if (state.twin) {
        var kt = state.twin.columns.indexOf(name);
        if (kt > 0) series.push({ name: name + ' (twin)', rows: state.twin.rows, k: kt, colour: PALETTE[i % PALETTE.length], dash: '6 4', twin: true });
      }
    });
    var tmin = Infinity, tmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    series.forEach(function (s) {
      s.rows.forEach(function (r) {
        var t = r[0], y = r[s.k];
        if (isFinite(t)) { tmin = Math.min(tmin, t); tmax = Math.max(tmax, t); }
        if (isFinite(y)) { ymin = Math.min(ymin, y); ymax = Math.max(ymax, y); }
      });
    });
    if (!(tmax > tmin)) tmax = tmin + 1;
    if (!(ymax > ymin)) { ymax += 0.5; ymin -= 0.5; }
    var X = function (t) { return L + (t - tmin) / (tmax - tmin) * (W - L - R); };
    var Y = function (y) { return T + (ymax - y) / (ymax - ymin) * (H - T - B); };
    var svg = svgEl('svg', { viewBox: '0 0 ' + W + ' ' + H, width: W, height: H, role: 'img', 'font-size': 12 });
    svg.appendChild(svgEl('rect', { x: L, y: T, width: W - L - R, height: H - T - B, fill: '#fbfbfd', stroke: '#ccd' }));
    ticks(ymin, ymax).forEach(function (ty) {
      svg.appendChild(svgEl('line', { x1: L, x2: W - R, y1: Y(ty), y2: Y(ty), stroke: '#e3e6ec' }));
      svg.appendChild(svgEl('text', { x: L - 6, y: Y(ty) + 4, 'text-anchor': 'end', fill: '#445' }, tickLabel(ty)));
    });
    ticks(tmin, tmax).forEach(function (tt) {
      svg.appendChild(svgEl('line', { x1: X(tt), x2: X(tt), y1: T, y2: H - B, stroke: '#eef0f4' }));
      svg.appendChild(svgEl('text', { x: X(tt), y: H - B + 16, 'text-anchor': 'middle', fill: '#445' }, tickLabel(tt)));
    });
    svg.appendChild(svgEl('text', { x: (L + W - R) / 2, y: H - 4, 'text-anchor': 'middle', fill: '#223' }, 't (s)'));
    series.forEach(function (s, j) {
      var pts = [];
      s.rows.forEach(function (r) {
        if (isFinite(r[0]) && isFinite(r[s.k])) pts.push(X(r[0]).toFixed(1) + ',' + Y(r[s.k]).toFixed(1));
      });
      var attrs = { points: pts.join(' '), fill: 'none', stroke: s.colour, 'stroke-width': s.twin ? 2.5 : 1.8, 'class': s.twin ? 'series twin' : 'series' };
      if (s.dash) attrs['stroke-dasharray'] = s.dash;
      if (s.twin) attrs['stroke-opacity'] = 0.75;
      svg.appendChild(svgEl('polyline', attrs));
      var ly = T + 14 + 18 * j;
      var key = { x1: W - R + 10, x2: W - R + 34, y1: ly - 4, y2: ly - 4, stroke: s.colour, 'stroke-width': 2 };
      if (s.dash) key['stroke-dasharray'] = s.dash;
      svg.appendChild(svgEl('line', key));
      svg.appendChild(svgEl('text', { x: W - R + 40, y: ly, fill: '#223' }, s.name));
    });
    plot.appendChild(svg);
  }

  // ---------------------------------------------------------------- SVG from the service
  // Parsed as XML, then stripped of anything active (scripts, foreign content, event
  // attributes, links out of the document) before it is adopted into the page.
  function safeSvg(text) {
    var doc = new DOMParser().parseFromString(text, 'image/svg+xml');
    var root = doc.documentElement;
    if (!root || root.nodeName !== 'svg' || doc.getElementsByTagName('parsererror').length) return null;
    Array.prototype.slice.call(root.querySelectorAll('script, foreignObject, iframe, object, embed, a'))
      .forEach(function (n) {
        if (n.nodeName === 'a') { while (n.firstChild) n.parentNode.insertBefore(n.firstChild, n); }
        n.parentNode.removeChild(n);
      });
    [root].concat(Array.prototype.slice.call(root.querySelectorAll('*'))).forEach(function (n) {
      Array.prototype.slice.call(n.attributes).forEach(function (a) {
        var name = a.name.toLowerCase();
        if (name.indexOf('on') === 0 || name === 'style' ||
            ((name === 'href' || name === 'xlink:href') && a.value.charAt(0) !== '#')) {
          n.removeAttribute(a.name);
        }
      });
    });
    return document.importNode(root, true);
  }

  function spatial(body) {
    try { var d = JSON.parse(body); return !!d && d.dimension === 3; } catch (e) { return false; }
  }
  // a spatial scene: the 3D view (shaded bodies on a canvas that orbits and zooms), drawn by
  // the renderer `bondmech animate --out FILE.html` inlines, served as /view3d.js
  function animateQuery(format, formulation) {
    var q = new URLSearchParams(solveQuery().slice(1));
    q.set('format', format);
    if (formulation) q.set('formulation', formulation);
    return '/v1/animate?' + q.toString();
  }
  function loadAnimation3d(body, signal) {
    hint(animation, 'drawing the motion…');
    resetTime();
    return post(animateQuery('view3d'), body, signal).then(function (r) {
      if (!r.ok) return readProblem(r).then(function (p) { hint(animation, 'no animation: ' + problemText(p)); });
      return r.json().then(function (data) {
        clear(animation);
        if (typeof window.bondmechView3d !== 'function') {
          hint(animation, 'no animation: the 3D renderer (/view3d.js) did not load');
          return;
        }
        var canvas = document.createElement('canvas');
        canvas.className = 'bondmech-view3d';
        canvas.setAttribute('data-view', '3d');
        canvas.setAttribute('aria-label', 'the 3D view of the motion');
        animation.appendChild(canvas);
        animation.appendChild(el('p', 'the 3D view: drag to orbit, wheel to zoom', 'hint view3d-note'));
        var a = { t0: data.t[0], t1: data.t[data.t.length - 1], digits: data.digits || 2 };
        a.view = window.bondmechView3d(data, {
          canvas: canvas,
          fit: function (c) {
            var w = Math.max(320, Math.floor(animation.clientWidth || 640));
            c.width = w; c.height = Math.round(0.62 * w);
          },
          onTime: function (t) { if (state.anim === a) showTime(t); },
          autoplay: false
        });
        state.anim = a;
        time.min = a.t0; time.max = a.t1; time.step = 'any'; time.disabled = false; play.disabled = false;
        seek(a.t0);
      });
    });
  }
  function loadAnimation(body, signal) {
    if (spatial(body)) return loadAnimation3d(body, signal);
    hint(animation, 'drawing the motion…');
    resetTime();
    return post('/v1/animate' + solveQuery(), body, signal).then(function (r) {
      if (!r.ok) return readProblem(r).then(function (p) { hint(animation, 'no animation: ' + problemText(p)); });
      return r.text().then(function (text) {
        var svg = safeSvg(text);
        clear(animation);
        if (!svg) { hint(animation, 'no animation: the service sent no SVG'); return; }
        svg.removeAttribute('width');
        svg.removeAttribute('height');
        animation.appendChild(svg);
        var clock = svg.querySelector('#clock'), strip = svg.querySelector('#strip');
        if (clock) clock.setAttribute('display', 'inline');
        if (strip) strip.setAttribute('display', 'none');
        var a = {
          svg: svg, clock: clock,
          t0: +svg.getAttribute('data-t0'), t1: +svg.getAttribute('data-t-end'),
          speed: +svg.getAttribute('data-speed'), duration: +svg.getAttribute('data-duration'),
          digits: +svg.getAttribute('data-digits') || 2
        };
        state.anim = a;
        time.min = a.t0; time.max = a.t1; time.step = 'any'; time.disabled = false; play.disabled = false;
        seek(a.t0);
        // the SMIL timeline of a new <svg> starts at its first frame: seek again then
        requestAnimationFrame(function () { if (state.anim === a && a.svg.animationsPaused()) seek(+time.value); });
      });
    });
  }
  function resetTime() {
    if (state.anim && state.anim.view) state.anim.view.destroy();
    state.anim = null;
    time.disabled = true; play.disabled = true; play.textContent = 'play';
    readout.textContent = '';
  }
  function showTime(t) {
    var a = state.anim;
    var text = 't = ' + t.toFixed(a.digits) + ' s';
    time.value = t;
    readout.textContent = text;
    if (a.clock) a.clock.textContent = text;
  }
  function seek(t) {
    var a = state.anim;
    if (!a) return;
    if (a.view) { a.view.seek(t); play.textContent = 'play'; return; }
    var tau = Math.min(Math.max((t - a.t0) / a.speed, 0), a.duration * (1 - 1e-9));
    a.svg.pauseAnimations();
    a.svg.setCurrentTime(tau);
    play.textContent = 'play';
    showTime(a.t0 + tau * a.speed);
    seekTwin(a.t0 + tau * a.speed);
  }
  // the twin's picture (after compare) stays paused, set to the time of the DAE's
  function seekTwin(t) {
    var w = state.anim && state.anim.twin;
    if (!w) return;
    w.svg.pauseAnimations();
    w.svg.setCurrentTime(Math.min(Math.max((t - w.t0) / w.speed, 0), w.duration * (1 - 1e-9)));
  }
  function tick() {
    var a = state.anim;
    if (a && a.svg && !a.svg.animationsPaused()) {
      var t = a.t0 + (a.svg.getCurrentTime() % a.duration) * a.speed;
      showTime(t);
      seekTwin(t);
    }
    requestAnimationFrame(tick);
  }
  // The decoupled twin's motion drawn over the DAE's, faded, on the same slider: its ids
  // renamed (the two pictures share the page), its background and labels left out.
  function loadTwinAnimation(body, signal) {
    var a = state.anim;
    if (!a) return Promise.resolve();
    if (a.view) {
      // in 3D the twin's bodies are drawn faded under the DAE's, by the same renderer
      return post(animateQuery('view3d', 'decoupled'), body, signal).then(function (r) {
        if (!r.ok || state.anim !== a) return null;
        return r.json().then(function (data) {
          if (state.anim !== a) return;
          a.view.ghost(data);
          animation.appendChild(el('p', 'faded: the decoupled twin, on the same clock', 'hint twin-note'));
        });
      });
    }
    return post(animateQuery('svg', 'decoupled'), body, signal).then(function (r) {
      if (!r.ok || state.anim !== a) return null;
      return r.text().then(function (text) {
        var svg = safeSvg(text);
        if (!svg || state.anim !== a) return;
        var ids = {};
        Array.prototype.forEach.call(svg.querySelectorAll('[id]'), function (n) {
          ids[n.id] = 'twin-' + n.id;
          n.id = ids[n.id];
        });
        Array.prototype.forEach.call(svg.querySelectorAll('*'), function (n) {
          Array.prototype.slice.call(n.attributes).forEach(function (at) {
            var v = at.value.replace(/url\(#([^)]+)\)/g, function (m, id) { return ids[id] ? 'url(#' + ids[id] + ')' : m; });
            if (v !== at.value) n.setAttribute(at.name, v);
          });
        });
        Array.prototype.slice.call(svg.querySelectorAll(':scope > rect, text, title')).forEach(function (n) {
          n.parentNode.removeChild(n);
        });
        svg.removeAttribute('width');
        svg.removeAttribute('height');
        svg.setAttribute('class', 'bondmech-animation twin-overlay');
        animation.appendChild(svg);
        a.twin = {
          svg: svg, t0: +svg.getAttribute('data-t0'), speed: +svg.getAttribute('data-speed'),
          duration: +svg.getAttribute('data-duration')
        };
        animation.appendChild(el('p', 'faded: the decoupled twin, on the same clock', 'hint twin-note'));
        seekTwin(+time.value);
        requestAnimationFrame(function () { seekTwin(+time.value); });
      });
    });
  }

  // ---------------------------------------------------------------- bond graph, zoom and pan
  var view = null; // {x, y, w, h, base}
  function loadGraph(body, signal) {
    hint(graph, 'drawing the bond graph…');
    view = null;
    return post('/v1/graph?format=svg', body, signal).then(function (r) {
      if (!r.ok) return readProblem(r).then(function (p) { hint(graph, 'no bond graph: ' + problemText(p)); });
      return r.text().then(function (text) {
        var svg = safeSvg(text);
        clear(graph);
        if (!svg) { hint(graph, 'no bond graph: the service sent no SVG'); return; }
        var vb = (svg.getAttribute('viewBox') || '').split(/[\s,]+/).map(Number);
        if (vb.length !== 4 || vb.some(isNaN)) vb = [0, 0, 100, 100];
        svg.removeAttribute('width');
        svg.removeAttribute('height');
        svg.setAttribute('preserveAspectRatio', 'xMidYMid meet');
        view = { x: vb[0], y: vb[1], w: vb[2], h: vb[3], base: vb.slice() };
        graph.appendChild(svg);
        applyView();
      });
    });
  }
  function applyView() {
    var svg = graph.querySelector('svg');
    if (svg && view) svg.setAttribute('viewBox', [view.x, view.y, view.w, view.h].join(' '));
  }
  function zoom(factor, cx, cy) {
    if (!view) return;
    var fx = cx === undefined ? 0.5 : cx, fy = cy === undefined ? 0.5 : cy;
    var px = view.x + fx * view.w, py = view.y + fy * view.h;
    view.w *= factor; view.h *= factor;
    view.x = px - fx * view.w; view.y = py - fy * view.h;
    applyView();
  }
  var drag = null;
  graph.addEventListener('wheel', function (e) {
    if (!view) return;
    e.preventDefault();
    var r = graph.getBoundingClientRect();
    zoom(e.deltaY > 0 ? 1.15 : 1 / 1.15, (e.clientX - r.left) / r.width, (e.clientY - r.top) / r.height);
  }, { passive: false });
  graph.addEventListener('pointerdown', function (e) {
    if (!view) return;
    e.preventDefault(); // a drag pans, it does not select the labels
    drag = { x: e.clientX, y: e.clientY, vx: view.x, vy: view.y };
    graph.setPointerCapture(e.pointerId);
    graph.classList.add('dragging');
  });
  graph.addEventListener('pointermove', function (e) {
    if (!drag || !view) return;
    var r = graph.getBoundingClientRect();
    var s = Math.max(view.w / r.width, view.h / r.height);
    view.x = drag.vx - (e.clientX - drag.x) * s;
    view.y = drag.vy - (e.clientY - drag.y) * s;
    applyView();
  });
  function endDrag() { drag = null; graph.classList.remove('dragging'); }
  graph.addEventListener('pointerup', endDrag);
  graph.addEventListener('pointercancel', endDrag);
  $('graph-zoom-in').addEventListener('click', function () { zoom(1 / 1.4); });
  $('graph-zoom-out').addEventListener('click', function () { zoom(1.4); });
  $('graph-reset').addEventListener('click', function () {
    if (view) { view.x = view.base[0]; view.y = view.base[1]; view.w = view.base[2]; view.h = view.base[3]; applyView(); }
  });

  // ---------------------------------------------------------------- compare
  function doCompare() {
    var signal = begin(), body = editor.value, started = performance.now();
    setStatus('comparing the DAE and the decoupled twin…');
    hint(verdict, 'comparing…');
    document.body.dataset.state = 'comparing';
    var needRun = !state.run || state.run.error || state.run.source !== body;
    var runDone = needRun ? doRunInner(body, signal) : Promise.resolve(state.run);
    var cmp = post('/v1/compare' + solveQuery(), body, signal).then(function (r) {
      return r.ok ? r.json() : readProblem(r).then(function (p) { return { problem: p }; });
    });
    var q = new URLSearchParams(solveQuery().slice(1));
    q.set('formulation', 'decoupled');
    var twin = post('/v1/run?' + q.toString(), body, signal).then(function (r) {
      return r.ok ? r.json() : null;
    });
    var twinAnim = runDone.then(function (run) {
      return run && !run.error ? loadTwinAnimation(body, signal) : null;
    });
    return Promise.all([cmp, twin, runDone, twinAnim]).then(function (all) {
      var c = all[0];
      clear(verdict);
      if (c.problem) {
        verdict.appendChild(el('span', 'no verdict: ' + problemText(c.problem), 'warn'));
      } else {
        var v = c.verdict || {};
        verdict.appendChild(el('strong', 'recommended: ' + v.recommended));
        verdict.appendChild(document.createTextNode(
          '\n' + (v.reason || '') +
          '\nlargest position difference ' + num(v.max_position_difference) + ' m (tolerance ' + num(v.position_tolerance) + ' m)' +
          (c.position && c.position.column ? ', in ' + c.position.column + ' at t = ' + num(c.position.t) : '') +
          '\nCPU ratio (twin / DAE) ' + num(v.cpu_ratio, 3) + ', steps ratio ' + num(v.steps_ratio, 3) +
          '\nthe plot overlays the twin (dashed) on the DAE (solid); the animation, faded'));
      }
      state.twin = all[1] && all[1].columns ? all[1] : null;
      drawPlot();
      var ms = Math.round(performance.now() - started);
      setStatus('compared in ' + ms + ' ms');
      document.body.dataset.state = c.problem ? 'failed' : 'compared';
    }).catch(function (e) {
      if (e && e.name === 'AbortError') { setStatus('cancelled'); document.body.dataset.state = 'cancelled'; }
      else { showError(String(e)); setStatus('failed'); document.body.dataset.state = 'failed'; }
    }).then(function () { end(signal); });
  }
  // the run's panels for compare, without resetting the verdict
  function doRunInner(body, signal) {
    var doc = sceneDoc();
    var hasBodies = !!(doc && Array.isArray(doc.bodies) && doc.bodies.length);
    var runDone = streamRun(body, signal);
    var anim = runDone.then(function (run) {
      return hasBodies && !run.error ? loadAnimation(body, signal) : null;
    });
    return Promise.all([runDone, anim, loadGraph(body, signal)]).then(function (all) {
      var run = all[0];
      run.source = body;
      state.run = run;
      showSummary(run);
      fillColumns(run);
      csvButton.disabled = !run.columns;
      return run;
    });
  }

  // ---------------------------------------------------------------- CSV download
  function downloadCsv() {
    var body = editor.value;
    setStatus('writing the CSV…');
    post('/v1/run' + solveQuery({ format: 'csv' }), body).then(function (r) {
      if (!r.ok) return readProblem(r).then(function (p) { showError(problemText(p)); });
      return r.blob().then(function (b) {
        var a = document.createElement('a');
        var doc = sceneDoc();
        a.href = URL.createObjectURL(b);
        a.download = ((doc && typeof doc.name === 'string' && doc.name.replace(/[^A-Za-z0-9_.-]+/g, '_')) || 'run') + '.csv';
        document.body.appendChild(a);
        a.click();
        document.body.removeChild(a);
        setTimeout(function () { URL.revokeObjectURL(a.href); }, 10000);
        setStatus('CSV written');
      });
    }).catch(function (e) { showError(String(e)); });
  }

  // ---------------------------------------------------------------- wiring
  picker.addEventListener('change', function () { if (picker.value) loadScene(picker.value); });
  editor.addEventListener('input', onEdit);
  runButton.addEventListener('click', function () {
    doRun().then(function () { if (state.run) state.run.source = editor.value; });
  });
  compareButton.addEventListener('click', doCompare);
  cancelButton.addEventListener('click', function () {
    if (state.controller) state.controller.abort();
  });
  csvButton.addEventListener('click', downloadCsv);
  plotColumns.addEventListener('change', drawPlot);
  time.addEventListener('input', function () { seek(+time.value); });
  play.addEventListener('click', function () {
    var a = state.anim;
    if (!a) return;
    if (a.view) {
      if (a.view.playing()) a.view.pause(); else a.view.play();
      play.textContent = a.view.playing() ? 'pause' : 'play';
      return;
    }
    if (a.svg.animationsPaused()) { a.svg.unpauseAnimations(); play.textContent = 'pause'; }
    else { a.svg.pauseAnimations(); play.textContent = 'play'; }
  });
  requestAnimationFrame(tick);
  hint(plot, 'run a scene to plot it');
  hint(graph, 'run a scene to draw its bond graph');
  loadScenes().then(function () { document.body.dataset.ready = 'true'; })
    .catch(function (e) { showError('cannot load the scenes: ' + e); });
}());
