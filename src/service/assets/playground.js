// bondmech playground (GET /): the page draws only what the service returns — /v1/run's rows
// as polylines (and the animation drawn from those same rows), /v1/graph's SVG, the
// equilibrium and the linear model of /v1/equilibrium and /v1/linearize — and inserts every
// text that comes from a scene as text (textContent), never as markup. Requests go to this
// origin only.
'use strict';
(function () {
  var $ = function (id) { return document.getElementById(id); };
  var picker = $('scene-picker'), editor = $('editor'), gutter = $('editor-gutter'), problems = $('problems');
  var validity = $('validity'), sceneName = $('scene-name'), runError = $('run-error');
  var runButton = $('run'), compareButton = $('compare'), cancelButton = $('cancel');
  var eqButton = $('equilibrium'), linButton = $('linearize');
  var progress = $('progress'), status = $('status'), summary = $('summary');
  var plot = $('plot'), plotColumns = $('plot-columns'), plotSearch = $('plot-search'), csvButton = $('csv');
  var plotReadout = $('plot-readout'), plotReset = $('plot-reset');
  var animation = $('animation'), time = $('time'), play = $('play'), readout = $('time-readout');
  var graph = $('graph'), verdict = $('verdict');
  var eqResult = $('equilibrium-result'), modesBox = $('modes'), bodeBox = $('bode');
  var presets = $('view-presets');
  var SVG_NS = 'http://www.w3.org/2000/svg';

  var state = {
    run: null,        // {columns, rows, summary, error, animation, source}
    twin: null,       // the decoupled twin's {columns, rows} after compare
    controller: null, // the AbortController of the work in progress
    validation: 0,    // sequence number of the latest validation request
    anim: null,       // {svg, t0, t1, speed, duration, digits} or, in 3D, {view, t0, t1, digits}
    zoom: null,       // [t0, t1] of the plot, or null for the whole run
    fields: {},       // toolbar field -> its problem text
    problems: [],     // the scene's problems as shown: {line, column, text}
    mode: null        // the mode animation in progress
  };

  function clear(e) { while (e.firstChild) e.removeChild(e.firstChild); }
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
    return (a >= 1e4 || a < 1e-3) ? x.toExponential(digits || 3) : String(+x.toPrecision(digits || 4));
  }

  // ---------------------------------------------------------------- units of the run's columns
  // by the last part of the name, as `bondmech run --plot` groups them
  var QUANTITIES = [
    [['x', 'y', 'z'], 'position', 'm'],
    [['angle', 'psi', 'theta', 'phi', 'rx', 'ry', 'rz'], 'angle', 'rad'],
    [['vx', 'vy', 'vz'], 'velocity', 'm/s'],
    [['omega', 'wx', 'wy', 'wz', 'wX', 'wY', 'wZ'], 'angular velocity', 'rad/s'],
    [['qw', 'qx', 'qy', 'qz'], 'attitude quaternion', '1'],
    [['energy', 'kinetic_energy', 'potential_energy'], 'energy', 'J'],
    [['constraint_error'], 'largest |g(q)|', 'm, rad'],
    [['Fx', 'Fy', 'Fz', 'force'], 'force', 'N'],
    [['Mx', 'My', 'Mz', 'torque'], 'moment', 'N·m'],
    [['power'], 'power', 'W']
  ];
  function quantity(name) {
    var last = name.split('.').pop();
    for (var i = 0; i < QUANTITIES.length; i++) {
      if (QUANTITIES[i][0].indexOf(last) >= 0) return { name: QUANTITIES[i][1], unit: QUANTITIES[i][2] };
    }
    return { name: 'value', unit: '' };
  }
  function unitOf(name) { return quantity(name).unit; }
  function withUnit(name) { var u = unitOf(name); return u ? name + ' (' + u + ')' : name; }

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
  // A problem+json answer as one readable text: the title, then each `path: message` once (the
  // detail of an invalid scene repeats them, so it is left out when they are listed).
  function problemText(p) {
    if (!p) return 'the request failed';
    var errs = p.errors || [];
    if (errs.length) {
      return [p.title || 'error'].concat(errs.map(function (e) {
        return (e.path ? e.path + ': ' : '') + e.message;
      })).join('\n');
    }
    return (p.title ? p.title + ': ' : '') + (p.detail || '');
  }
  function readProblem(r) {
    return r.text().then(function (t) {
      try { return JSON.parse(t); } catch (e) { return { title: 'HTTP ' + r.status, detail: t }; }
    });
  }

  // ---------------------------------------------------------------- where a JSON path is in the text
  // A small JSON reader that records where every value starts and ends, by the path the
  // validation names it (`bodies[0].mass`, `solve.t_end`); it stops quietly at a syntax error.
  function locate(text) {
    var at = {}, i = 0, n = text.length;
    function ws() { while (i < n && /\s/.test(text[i])) i++; }
    function str() {
      var s = i; i++;
      while (i < n && text[i] !== '"') { if (text[i] === '\\') i++; i++; }
      i++;
      try { return JSON.parse(text.slice(s, i)); } catch (e) { throw e; }
    }
    function value(path) {
      ws();
      var start = i;
      if (text[i] === '{') {
        i++; ws();
        if (text[i] === '}') { i++; } else {
          for (;;) {
            ws();
            if (text[i] !== '"') throw new Error('key');
            var kstart = i, key = str();
            ws(); if (text[i] !== ':') throw new Error(':'); i++;
            var p = path ? path + '.' + key : key;
            at[p + '#key'] = kstart;
            value(p);
            ws();
            if (text[i] === ',') { i++; continue; }
            if (text[i] === '}') { i++; break; }
            throw new Error('}');
          }
        }
      } else if (text[i] === '[') {
        i++; ws();
        if (text[i] === ']') { i++; } else {
          for (var k = 0; ; k++) {
            value(path + '[' + k + ']');
            ws();
            if (text[i] === ',') { i++; continue; }
            if (text[i] === ']') { i++; break; }
            throw new Error(']');
          }
        }
      } else if (text[i] === '"') {
        str();
      } else {
        while (i < n && /[^\s,\]}]/.test(text[i])) i++;
        if (i === start) throw new Error('value');
      }
      at[path] = { start: start, end: i };
    }
    try { value(''); } catch (e) { /* a syntax error: what was read so far */ }
    return at;
  }
  function lineCol(text, offset) {
    var line = 1, last = -1;
    for (var k = 0; k < offset && k < text.length; k++) if (text.charCodeAt(k) === 10) { line++; last = k; }
    return { line: line, column: offset - last };
  }
  // The place of a problem's path: the path itself, or the longest part of it that is in the text.
  function placeOf(path, text, at) {
    var p = path;
    while (p) {
      var hit = at[p];
      if (hit) {
        var s = at[p + '#key'] !== undefined ? at[p + '#key'] : hit.start;
        var lc = lineCol(text, s);
        return { start: s, end: hit.end, line: lc.line, column: lc.column };
      }
      var cut = Math.max(p.lastIndexOf('.'), p.lastIndexOf('['));
      if (cut <= 0) break;
      p = p.slice(0, cut);
    }
    return null;
  }
  // The names beside the indices of a path: joints[1] -> joints[1] "knee".
  function namedPath(path, doc) {
    var parts = [], node = doc, re = /([^.[\]]+)|\[(\d+)\]/g, m, out = '';
    while ((m = re.exec(path)) !== null) parts.push(m);
    parts.forEach(function (m2) {
      if (m2[1] !== undefined) {
        out += (out ? '.' : '') + m2[1];
        node = node && typeof node === 'object' ? node[m2[1]] : undefined;
      } else {
        var k = +m2[2];
        out += '[' + k + ']';
        node = Array.isArray(node) ? node[k] : undefined;
        if (node && typeof node === 'object' && typeof node.name === 'string') out += ' "' + node.name + '"';
      }
    });
    return out;
  }

  // ---------------------------------------------------------------- the editor's gutter
  var gutterLines = 0;
  function drawGutter() {
    var lines = editor.value.split('\n').length;
    var marks = {};
    state.problems.forEach(function (p) { if (p.line) (marks[p.line] = marks[p.line] || []).push(p); });
    clear(gutter);
    var frag = document.createDocumentFragment();
    for (var k = 1; k <= lines; k++) {
      var d = el('div', k);
      if (marks[k]) {
        d.className = 'mark';
        d.dataset.line = String(k);
        d.title = marks[k].map(function (p) { return 'line ' + p.line + ', column ' + p.column + ': ' + p.text; }).join('\n');
        d.addEventListener('click', selectProblem.bind(null, marks[k][0]));
      }
      frag.appendChild(d);
    }
    gutter.appendChild(frag);
    gutterLines = lines;
    gutter.scrollTop = editor.scrollTop;
  }
  editor.addEventListener('scroll', function () { gutter.scrollTop = editor.scrollTop; });
  function selectProblem(p) {
    if (!p) return;
    var text = editor.value;
    var start = p.start, end = p.end;
    if (start === undefined) {
      // a line and a column: select that line
      var lines = text.split('\n'), off = 0;
      for (var k = 0; k < p.line - 1 && k < lines.length; k++) off += lines[k].length + 1;
      start = off + Math.max(0, (p.column || 1) - 1);
      end = off + (lines[p.line - 1] || '').length;
      if (end <= start) end = Math.min(text.length, start + 1);
    }
    editor.focus();
    editor.setSelectionRange(start, end);
    var lh = 16;
    editor.scrollTop = Math.max(0, (p.line - 1) * lh - editor.clientHeight / 3);
    gutter.scrollTop = editor.scrollTop;
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
        editor.scrollTop = 0;
        editor.dispatchEvent(new Event('input'));
        preview();
      });
  }
  var validateTimer = null;
  function onEdit() {
    var doc = sceneDoc();
    sceneName.textContent = (doc && typeof doc.name === 'string') ? doc.name : '';
    if (editor.value === loaded.text) {
      if (edited.parentNode) picker.removeChild(edited);
      picker.value = loaded.name;
    } else {
      if (!edited.parentNode) picker.appendChild(edited);
      picker.value = '';
    }
    // a failure shown for the text before this edit is no longer about the text on show, and
    // the results on show say they are of the text before the edits
    hideError();
    markStale();
    if (!state.controller && /^(not run|failed|comparison failed)/.test(status.textContent)) setStatus('');
    if (editor.value.split('\n').length !== gutterLines) drawGutter();
    if (validateTimer) clearTimeout(validateTimer);
    validateTimer = setTimeout(validate, 120);
  }
  function markStale() {
    var stale = !!(state.run && state.run.source !== undefined && state.run.source !== editor.value);
    document.body.classList.toggle('stale', stale);
    var note = $('stale-note');
    if (stale && !note) {
      note = el('p', 'these results are of the scene before your edits: run again', 'stale-note');
      note.id = 'stale-note';
      summary.parentNode.insertBefore(note, summary);
      Array.prototype.forEach.call(summary.querySelectorAll('dd.warn'), function (d) {
        if (/^failed: /.test(d.textContent)) d.textContent = d.textContent.replace(/^failed: /, 'the run before your edits stopped: ');
      });
    } else if (!stale && note) {
      note.parentNode.removeChild(note);
    }
  }
  function validate() {
    var seq = ++state.validation, text = editor.value;
    post('/v1/validate', text).then(function (r) { return r.json(); }).then(function (v) {
      if (seq !== state.validation) return; // a newer edit is being checked
      showProblems(v, text);
    }).catch(function () { /* the next edit checks again */ });
  }
  var lastValidation = { valid: true, errors: [] };
  function showProblems(v, text) {
    if (v) { lastValidation = v; v.text = text; }
    v = lastValidation;
    text = text === undefined ? editor.value : text;
    clear(problems);
    var doc = sceneDoc(), at = locate(text), list = [];
    (v.errors || []).forEach(function (e) {
      var place = null;
      if (v.line !== undefined) {
        place = { line: v.line, column: v.column };
      } else if (e.path) {
        place = placeOf(e.path, text, at);
      }
      list.push({ path: e.path, message: e.message, place: place });
    });
    var fieldNames = Object.keys(state.fields).filter(function (k) { return state.fields[k]; });
    var valid = !!v.valid && !fieldNames.length;
    problems.dataset.valid = v.valid ? 'true' : 'false';
    editor.classList.toggle('invalid', !v.valid);
    $('editor-wrap').classList.toggle('invalid', !v.valid);
    validity.className = 'validity ' + (valid ? 'ok' : 'bad');
    var count = list.length + fieldNames.length;
    validity.textContent = valid ? 'none: the scene is valid' : count + ' found';
    state.problems = [];
    list.forEach(function (e) {
      var li = el('li');
      // the command line's own line, for whoever compares (the names are added beside it)
      li.dataset.text = (e.path ? e.path + ': ' : '') + e.message + (v.line !== undefined ? ' (line ' + v.line + ', column ' + v.column + ')' : '');
      if (e.path) {
        // the path with the names beside its indices: joints[1] "knee".bodies[0]
        li.appendChild(el('code', doc ? namedPath(e.path, doc) : e.path));
        li.appendChild(document.createTextNode(': '));
      }
      li.appendChild(document.createTextNode(e.message));
      if (e.place) {
        if (!/\bline \d+/.test(e.message)) li.appendChild(el('span', ' (line ' + e.place.line + ', column ' + e.place.column + ')', 'where'));
        li.dataset.line = String(e.place.line);
        var p = { line: e.place.line, column: e.place.column, start: e.place.start, end: e.place.end, text: (e.path ? e.path + ': ' : '') + e.message };
        state.problems.push(p);
        li.addEventListener('click', selectProblem.bind(null, p));
        li.title = 'select it in the editor';
      }
      problems.appendChild(li);
    });
    fieldNames.forEach(function (k) {
      var li = el('li');
      li.dataset.text = state.fields[k];
      li.dataset.field = k;
      li.appendChild(el('code', k));
      li.appendChild(document.createTextNode(': ' + state.fields[k].replace(/^[^:]*: /, '') + ' (the toolbar field)'));
      li.addEventListener('click', function () { $(k).focus(); $(k).select(); });
      problems.appendChild(li);
    });
    drawGutter();
  }

  // ---------------------------------------------------------------- toolbar fields
  function checkField(id) {
    var input = $(id), s = input.value.trim(), msg = '';
    if (s) {
      var x = Number(s);
      if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(s) || !isFinite(x)) msg = id + ": not a number ('" + s + "')";
      else if (!(x > 0)) msg = id + ': must be > 0 (got ' + s + ')';
      else if (id === 'rtol' && x >= 1) msg = 'rtol: must be below 1 (got ' + s + ')';
    }
    setField(id, msg);
  }
  function setField(id, msg) {
    var input = $(id);
    state.fields[id] = msg;
    input.classList.toggle('bad', !!msg);
    input.setAttribute('aria-invalid', msg ? 'true' : 'false');
    input.title = msg;
    $(id + '-problem').textContent = msg;
    showProblems();
  }
  // a problem the service names a query parameter of: flagged at its field
  function flagParameter(p) {
    if (p && (p.parameter === 'rtol' || p.parameter === 't_end')) setField(p.parameter, p.detail || problemText(p));
  }
  // Broken JSON is not sent: the page says where it breaks (the validation's message, or the
  // browser's parser's position as a line and column).
  function jsonOk() {
    var text = editor.value;
    try { JSON.parse(text); return true; } catch (e) {
      var v = lastValidation, msg;
      if (v && v.text === text && v.line !== undefined) {
        msg = (v.errors || []).map(function (x) { return x.message; }).join('; ') + ' (line ' + v.line + ', column ' + v.column + ')';
      } else {
        var m = /position (\d+)/.exec(e.message), lc = m ? lineCol(text, +m[1]) : null;
        msg = e.message + (lc ? ' (line ' + lc.line + ', column ' + lc.column + ')' : '');
      }
      showError('the scene is not valid JSON: ' + msg);
      setStatus('not run: the scene is not valid JSON');
      document.body.dataset.state = 'failed';
      return false;
    }
  }
  function fieldsOk() {
    if (!jsonOk()) return false;
    var bad = Object.keys(state.fields).filter(function (k) { return state.fields[k]; });
    if (bad.length) {
      showError(bad.map(function (k) { return state.fields[k]; }).join('\n'));
      $(bad[0]).focus();
      return false;
    }
    return true;
  }

  // ---------------------------------------------------------------- work in progress
  function begin(what) {
    if (state.controller) state.controller.abort();
    state.controller = new AbortController();
    state.controller.what = what;
    cancelButton.disabled = false;
    progress.value = 0;
    hideError();
    return state.controller.signal;
  }
  // whether the work of `signal` is still the page's (work started without one always is)
  function current(signal) { return signal === undefined || !!(state.controller && state.controller.signal === signal); }
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
  function hideError() {
    runError.hidden = true;
    runError.textContent = '';
  }
  // After a cancel: nothing may still say it is working.
  function cancelled() {
    setStatus('cancelled');
    document.body.dataset.state = 'cancelled';
    Array.prototype.forEach.call(summary.querySelectorAll('dd'), function (d) {
      if (/solving…/.test(d.textContent)) d.textContent = 'cancelled';
    });
    if (/solving…|drawing/.test(plot.textContent) && !plot.querySelector('svg')) hint(plot, 'cancelled: nothing to plot');
    if (!animation.querySelector('svg, canvas') || /the motion is drawn/.test(animation.textContent)) {
      if (!animation.querySelector('svg.bondmech-animation, canvas')) hint(animation, 'cancelled: no animation');
    }
    if (/comparing…/.test(verdict.textContent)) hint(verdict, 'cancelled');
    [eqResult, modesBox].forEach(function (b) { if (/…/.test(b.textContent)) hint(b, 'cancelled'); });
    if (/solving…/.test(graph.textContent)) hint(graph, 'cancelled');
  }
  function failed(e, signal) {
    if (!current(signal) && !(e && e.name === 'AbortError')) return;
    if (e && e.name === 'AbortError') { if (current(signal)) cancelled(); return; }
    showError(String(e));
    setStatus('failed');
    document.body.dataset.state = 'failed';
  }

  // ---------------------------------------------------------------- clearing results
  function clearResults() {
    if (state.controller) { state.controller.abort(); state.controller = null; cancelButton.disabled = true; }
    state.run = null;
    state.twin = null;
    state.zoom = null;
    collapseSet = false;
    markStale();
    stopMode();
    hideError();
    clear(summary);
    hint(verdict, 'compare runs the DAE and its decoupled twin');
    hint(plot, 'run a scene to plot it');
    plotReadout.textContent = '';
    clear(plotColumns);
    csvButton.disabled = true;
    plotReset.disabled = true;
    resetTime();
    hint(animation, 'run a scene to see its motion');
    hint(graph, 'run a scene to draw its bond graph');
    hint(eqResult, 'equilibrium finds the rest posture nearest the scene\'s configuration');
    hint(modesBox, 'linearize lists the modes about the equilibrium');
    clear(bodeBox);
    progress.value = 0;
    setStatus('');
    document.body.dataset.state = '';
  }

  // ---------------------------------------------------------------- run (NDJSON stream)
  // Reads /v1/run?format=ndjson: {columns, rows: n}, one row array per output time, the
  // animation drawn from those rows (when asked), then {summary} or {error}; progress is the
  // share of the n rows received.
  function streamRun(body, signal, animate) {
    var run = { columns: null, rows: [], summary: null, error: null, expected: 0, animation: null };
    var extra = { format: 'ndjson' };
    if (animate) extra.animate = animate;
    return post('/v1/run' + solveQuery(extra), body, signal).then(function (r) {
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
        else if (v.animation) run.animation = v.animation;
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
          if (run.expected && current(signal)) {
            progress.value = run.rows.length / run.expected;
            setStatus(run.rows.length < run.expected ? 'solving: ' + run.rows.length + ' of ' + run.expected + ' rows'
              : 'drawing the motion…');
          }
          // a long run is plotted as it goes (at most every 0.3 s)
          var now = performance.now();
          if (run.columns && run.rows.length && now - lastDraw > 300 && current(signal)) {
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
  function bodiesOf(doc) { return !!(doc && Array.isArray(doc.bodies) && doc.bodies.length); }
  function animateKind(doc) { return bodiesOf(doc) ? (doc.dimension === 3 ? 'view3d' : 'svg') : null; }

  function doRun() {
    if (!fieldsOk()) return Promise.resolve();
    var signal = begin('run'), body = editor.value, started = performance.now();
    var doc = sceneDoc();
    state.twin = null;
    hint(verdict, 'compare runs the DAE and its decoupled twin');
    setStatus('solving…');
    document.body.dataset.state = 'running';
    // nothing of the previous run stays on show
    state.run = null;
    state.zoom = null;
    clear(summary);
    summary.appendChild(el('dt', 'status'));
    summary.appendChild(el('dd', 'solving…'));
    hint(plot, 'solving…');
    plotReadout.textContent = '';
    csvButton.disabled = true;
    resetTime();
    hint(animation, !doc ? 'no animation: the scene is not valid JSON'
      : bodiesOf(doc) ? 'the motion is drawn once the run has finished'
        : 'no animation: a raw bond graph has no geometry to draw');
    var graphDone = loadGraph(body, signal);
    var runDone = runPanels(body, signal, doc).then(function (run) {
      if (run.error && current(signal)) {
        var rows = run.rows.length;
        flagParameter(run.error);
        showError(problemText(run.error) + (rows ? '\n\n' + rows + ' rows computed before it stopped are shown in the plot and the summary.' : ''));
      }
      return run;
    });
    return Promise.all([runDone, graphDone]).then(function (all) {
      if (!current(signal)) return;
      var ms = Math.round(performance.now() - started);
      var run = all[0];
      setStatus(run.error ? 'failed after ' + ms + ' ms' : 'done in ' + ms + ' ms');
      progress.value = run.error ? progress.value : 1;
      document.body.dataset.state = run.error ? 'failed' : 'done';
      document.body.dataset.runMs = String(ms);
    }).catch(function (e) { failed(e, signal); }).then(function () { end(signal); });
  }
  // The run's own panels: summary, plot, the animation drawn from the run's rows.
  function runPanels(body, signal, doc) {
    var kind = animateKind(doc), t0 = performance.now();
    return streamRun(body, signal, kind).then(function (run) {
      if (!current(signal)) return run;
      // the page's own clock of the phases (read by the browser test)
      document.body.dataset.streamMs = String(Math.round(performance.now() - t0));
      run.source = body;
      state.run = run;
      showSummary(run);
      fillColumns(run);
      drawPlot();
      csvButton.disabled = !run.columns;
      if (kind) {
        if (run.error) hint(animation, 'no animation: the run did not finish');
        else if (!run.animation) hint(animation, 'no animation: the service sent none');
        else if (run.animation.error) hint(animation, 'no animation: ' + problemText(run.animation.error));
        else showAnimation(run.animation);
        document.body.dataset.animationMs = String(Math.round(performance.now() - t0));
      }
      return run;
    });
  }

  // ---------------------------------------------------------------- summary, in words
  var STATE_COORD = { I_J: 'angle', I_x: 'x', I_y: 'y', I_z: 'z' };
  function coordinateOf(s) {
    var m = /^(.*)\.(I_[A-Za-z]+)$/.exec(s);
    if (m && STATE_COORD[m[2]]) return m[1] + '.' + STATE_COORD[m[2]];
    // a spatial body's rotational inertia about its own axis: the body turning about it
    m = /^(.*)\.I_(?:3|J)_([xyz])$/.exec(s);
    if (m) return m[1] + ' turning about its ' + m[2] + ' axis';
    return s;
  }
  function showSummary(run) {
    clear(summary);
    document.body.classList.remove('stale');
    if ($('stale-note')) $('stale-note').parentNode.removeChild($('stale-note'));
    var s = run.summary || {};
    function row(k, v, cls) {
      summary.appendChild(el('dt', k));
      var d = v instanceof Node ? v : el('dd', v, cls);
      if (v instanceof Node && cls) d.className = cls;
      summary.appendChild(d);
      return d;
    }
    if (run.error) row('status', 'failed: ' + (run.error.title || 'error'), 'warn');
    if (!run.summary) {
      row('rows', run.rows.length + (run.expected ? ' of ' + run.expected : '') + ' (partial)');
      if (run.rows.length) row('t reached', num(run.rows[run.rows.length - 1][0]) + ' s');
      return;
    }
    var coords = (s.states || []).map(coordinateOf);
    var dof = s.dof !== undefined ? s.dof : coords.length;
    // many coordinates: the first few and the last, all of them in the tooltip
    var listed = coords.length > 10 ? coords.slice(0, 6).concat(['…', coords[coords.length - 1]]) : coords;
    var statesRow = row('states', s.kinematic_analysis ? 'no degree of freedom left by the drivers: a kinematic analysis'
      : dof + ' DOF' + (coords.length ? ': ' + listed.join(', ') : ''));
    if (listed !== coords) statesRow.title = coords.join(', ');
    row('formulation', s.formulation + (s.solver ? ', solved by ' + s.solver : '') + (s.linear_solver ? ' (' + s.linear_solver + ' linear solver)' : ''));
    row('steps', s.steps + ' steps, ' + s.nonlinear_iterations + ' Newton iterations');
    row('CPU', num(s.cpu_seconds * 1e3, 3) + ' ms');
    if (s.energy_check === 'conserved') {
      row('energy drift', num(s.energy_drift) + ' of the energy\'s scale (the scene conserves energy)');
    } else {
      row('energy drift', 'not measured: the scene does not conserve energy' + (s.energy_note ? ' (' + s.energy_note + ')' : ''));
    }
    if (s.driver_work !== null && s.driver_work !== undefined) row('drivers\' work', num(s.driver_work) + ' J');
    row('constraint error', 'at most ' + num(s.max_constraint_error) + ' (m, rad)');
    row('rows', run.rows.length + ' rows');
    row('completed', s.completed ? 'yes, to t = ' + num(s.t_reached) + ' s' : 'no: stopped at t = ' + num(s.t_reached) + ' s by ' + (s.stopped_by || 'the solver'));
    var w = s.warnings || [];
    if (w.length) {
      var dd = el('dd', null, 'warn'), ul = el('ul');
      ul.id = 'warnings';
      w.forEach(function (x) { ul.appendChild(el('li', x)); });
      dd.appendChild(ul);
      row('warnings', dd);
    } else {
      row('warnings', 'none');
    }
  }

  // ---------------------------------------------------------------- plot
  // the bodies' colours of the animation (`report::palette::body_colour`, its first 20)
  var BODY_COLOURS = ['#1f77b4', '#2ca02c', '#9467bd', '#8c564b', '#bcbd22', '#17becf', '#ff7f0e', '#7f7f7f',
    '#393b79', '#637939', '#8c6d31', '#843c39', '#7b4173', '#5254a3', '#6b6ecf', '#9c9ede', '#b5cf6b', '#e7ba52',
    '#ad494a', '#ce6dbd'];
  var PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2'];
  function chosenColumns() {
    return Array.prototype.filter.call(plotColumns.querySelectorAll('input[type=checkbox]'), function (c) { return c.checked; })
      .map(function (c) { return c.value; });
  }
  // angles (or else the first coordinates) and energy by default
  function defaultColumns(names) {
    var angles = names.filter(function (n) { return /\.(angle|psi|theta|phi)$/.test(n); });
    var pick = angles.length ? angles.slice(0, 6) : names.filter(function (n) { return !/constraint_error/.test(n); }).slice(0, 2);
    if (names.indexOf('energy') >= 0) pick.push('energy');
    return pick;
  }
  function fillColumns(run) {
    var keep = {}, any = false;
    chosenColumns().forEach(function (n) { keep[n] = true; });
    clear(plotColumns);
    if (!run.columns) return;
    var names = run.columns.slice(1), have = {};
    names.forEach(function (n) { have[n] = true; });
    // the choice is kept for a run of the same columns (a scene re-run), else the defaults
    var kept = Object.keys(keep);
    any = kept.length > 0 && kept.every(function (n) { return have[n]; });
    var defaults = {};
    defaultColumns(names).forEach(function (n) { defaults[n] = true; });
    var frag = document.createDocumentFragment();
    names.forEach(function (n) {
      var label = el('label'), box = el('input');
      box.type = 'checkbox';
      box.value = n;
      box.checked = any ? !!keep[n] : !!defaults[n];
      label.appendChild(box);
      label.appendChild(document.createTextNode(n));
      var u = unitOf(n);
      if (u) label.appendChild(el('span', '(' + u + ')', 'unit'));
      label.dataset.name = n.toLowerCase();
      frag.appendChild(label);
    });
    plotColumns.appendChild(frag);
    filterColumns();
  }
  function filterColumns() {
    var q = plotSearch.value.trim().toLowerCase();
    Array.prototype.forEach.call(plotColumns.children, function (l) {
      l.hidden = !!q && l.dataset.name.indexOf(q) < 0;
    });
  }
  // Round tick values (1-2-5 steps), about `count` over [lo, hi].
  function ticks(lo, hi, count) {
    var raw = (hi - lo) / (count || 5), p = Math.pow(10, Math.floor(Math.log10(raw))), f = raw / p;
    var step = (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p, out = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) {
      out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
    }
    return out;
  }
  // a tick's label with as many decimals as the spacing of the ticks needs (`step`)
  function tickLabel(v, step) {
    if (step > 0 && v !== 0) {
      var decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
      if (Math.abs(v) < 1e4 && decimals <= 9 && (Math.abs(v) >= 1e-3 || decimals <= 4)) return v.toFixed(decimals);
    }
    return (Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-3)) ? v.toExponential(1) : String(+v.toPrecision(6));
  }
  function tickStep(list) { return list.length > 1 ? list[1] - list[0] : 0; }
  // the twin's value of column k at time t (its rows are at the same output times; else linear)
  function twinAt(rows, k, t, hintIndex) {
    var r = rows[hintIndex];
    if (r && r[0] === t) return r[k];
    var lo = 0, hi = rows.length - 1;
    if (hi < 0 || t < rows[0][0] || t > rows[hi][0]) return NaN;
    while (hi - lo > 1) { var mid = (lo + hi) >> 1; if (rows[mid][0] <= t) lo = mid; else hi = mid; }
    var a = rows[lo], b = rows[hi];
    return b[0] > a[0] ? a[k] + (b[k] - a[k]) * (t - a[0]) / (b[0] - a[0]) : a[k];
  }
  var plotGeom = null; // {L, R, W, X0, X1, t0, t1, panels: [{T, H}], svg}
  function drawPlot() {
    clear(plot);
    plotGeom = null;
    var run = state.run;
    if (!run || !run.columns || !run.rows.length) { hint(plot, run && run.error ? 'no rows to plot' : 'run a scene to plot it'); return; }
    var chosen = chosenColumns().filter(function (n) { return run.columns.indexOf(n) > 0; });
    if (!chosen.length) { hint(plot, 'choose columns to plot'); return; }
    var twin = state.twin;
    // one panel per unit; with a twin, a panel of the differences DAE − twin per unit
    var groups = [], byUnit = {};
    chosen.forEach(function (name, i) {
      var q = quantity(name), key = q.unit + '|' + q.name;
      if (!byUnit[key]) { byUnit[key] = { q: q, series: [] }; groups.push(byUnit[key]); }
      var k = run.columns.indexOf(name), colour = PALETTE[i % PALETTE.length];
      byUnit[key].series.push({ name: name, rows: run.rows, k: k, colour: colour, cls: 'series' });
      if (twin) {
        var kt = twin.columns.indexOf(name);
        if (kt > 0) byUnit[key].series.push({ name: name + ' (twin)', rows: twin.rows, k: kt, colour: colour, dash: '6 4', cls: 'series twin', twin: true });
      }
    });
    var panels = groups.map(function (g) {
      var label = g.series.length === 1 || g.series.every(function (s) { return s.name.replace(/ \(twin\)$/, '') === g.series[0].name; })
        ? g.series[0].name + (g.q.unit ? ' (' + g.q.unit + ')' : '') : g.q.name + (g.q.unit ? ' (' + g.q.unit + ')' : '');
      return { label: label, unit: g.q.unit, series: g.series };
    });
    if (twin) {
      groups.forEach(function (g) {
        var diff = [];
        g.series.forEach(function (s) {
          if (s.twin) return;
          var kt = twin.columns.indexOf(s.name);
          if (kt <= 0) return;
          var rows = run.rows.map(function (r, j) { return [r[0], r[s.k] - twinAt(twin.rows, kt, r[0], j)]; });
          diff.push({ name: s.name + ' DAE − twin', rows: rows, k: 1, colour: s.colour, cls: 'series difference' });
        });
        if (diff.length) panels.push({ label: 'DAE − twin (' + (g.q.unit || '1') + ')', unit: g.q.unit, series: diff, difference: true });
      });
    }
    var tAll0 = Infinity, tAll1 = -Infinity;
    run.rows.forEach(function (r) { if (isFinite(r[0])) { tAll0 = Math.min(tAll0, r[0]); tAll1 = Math.max(tAll1, r[0]); } });
    if (!(tAll1 > tAll0)) tAll1 = tAll0 + 1;
    var t0 = state.zoom ? state.zoom[0] : tAll0, t1 = state.zoom ? state.zoom[1] : tAll1;
    var W = 900, L = 78, R = 200, PH = Math.max(130, Math.min(220, 560 / panels.length)), GAP = 26, TOP = 10, B = 34;
    var H = TOP + panels.length * PH + (panels.length - 1) * GAP + B;
    var X = function (t) { return L + (t - t0) / (t1 - t0) * (W - L - R); };
    var svg = svgEl('svg', { viewBox: '0 0 ' + W + ' ' + H, width: W, height: H, role: 'img', 'font-size': 13, 'aria-label': 'time plot' });
    var defs = svgEl('defs', {}), clip = svgEl('clipPath', { id: 'plot-clip' });
    clip.appendChild(svgEl('rect', { x: L, y: 0, width: W - L - R, height: H }));
    defs.appendChild(clip);
    svg.appendChild(defs);
    var geomPanels = [];
    panels.forEach(function (p, j) {
      var T = TOP + j * (PH + GAP), Hp = PH;
      var ymin = Infinity, ymax = -Infinity;
      p.series.forEach(function (s) {
        s.rows.forEach(function (r) {
          var t = r[0], y = r[s.k];
          if (t >= t0 && t <= t1 && isFinite(y)) { ymin = Math.min(ymin, y); ymax = Math.max(ymax, y); }
        });
      });
      if (!isFinite(ymin)) { ymin = -1; ymax = 1; }
      if (!(ymax > ymin)) { var pad = Math.abs(ymax) * 0.01 || 0.5; ymax += pad; ymin -= pad; }
      var span = ymax - ymin; ymin -= 0.04 * span; ymax += 0.04 * span;
      var Y = function (y) { return T + (ymax - y) / (ymax - ymin) * Hp; };
      var g = svgEl('g', { 'class': 'panel', 'data-unit': p.unit });
      g.appendChild(svgEl('rect', { x: L, y: T, width: W - L - R, height: Hp, fill: p.difference ? '#fdfaf5' : '#fbfbfd', stroke: '#ccd' }));
      var yt = ticks(ymin, ymax, 4), ys = tickStep(yt);
      // values that vary by less than a ten-thousandth of their size: drawn about an offset
      // (the axis says so), so that the tick labels stay short
      var mid = (ymin + ymax) / 2, offset = 0, axisLabel = p.label;
      if (ys > 0 && Math.abs(mid) / ys > 1e4) {
        offset = Number(mid.toPrecision(Math.max(1, Math.ceil(Math.log10(Math.abs(mid) / ys)) - 2)));
        axisLabel = p.label + ' − (' + String(offset) + ')';
      }
      yt.forEach(function (ty) {
        g.appendChild(svgEl('line', { x1: L, x2: W - R, y1: Y(ty), y2: Y(ty), stroke: '#e3e6ec' }));
        g.appendChild(svgEl('text', { x: L - 6, y: Y(ty) + 4, 'text-anchor': 'end', fill: '#445' }, tickLabel(offset ? (Math.abs(ty - offset) < 1e-6 * ys ? 0 : Number((ty - offset).toPrecision(6))) : ty, ys)));
      });
      ticks(t0, t1, 8).forEach(function (tt) {
        g.appendChild(svgEl('line', { x1: X(tt), x2: X(tt), y1: T, y2: T + Hp, stroke: '#eef0f4' }));
        if (j === panels.length - 1) g.appendChild(svgEl('text', { x: X(tt), y: T + Hp + 16, 'text-anchor': 'middle', fill: '#445' }, tickLabel(tt)));
      });
      // the axis label, with its unit
      g.appendChild(svgEl('text', { 'class': 'axis-label', x: 14, y: T + Hp / 2, 'text-anchor': 'middle', fill: '#223',
        transform: 'rotate(-90 14 ' + (T + Hp / 2) + ')' }, axisLabel));
      var stride = Math.max(1, Math.floor(run.rows.length / 3000));
      p.series.forEach(function (s, m) {
        var pts = [];
        for (var q = 0; q < s.rows.length; q += stride) {
          var r = s.rows[q];
          if (isFinite(r[0]) && isFinite(r[s.k]) && r[0] >= t0 - (t1 - t0) * 0.01 && r[0] <= t1 + (t1 - t0) * 0.01) pts.push(X(r[0]).toFixed(1) + ',' + Y(r[s.k]).toFixed(1));
        }
        var attrs = { points: pts.join(' '), fill: 'none', stroke: s.colour, 'stroke-width': s.twin ? 2.5 : 1.8, 'class': s.cls, 'clip-path': 'url(#plot-clip)', 'data-column': s.name };
        if (s.dash) attrs['stroke-dasharray'] = s.dash;
        if (s.twin) attrs['stroke-opacity'] = 0.8;
        g.appendChild(svgEl('polyline', attrs));
        var ly = T + 14 + 17 * m;
        if (ly < T + Hp) {
          var key = { x1: W - R + 10, x2: W - R + 34, y1: ly - 4, y2: ly - 4, stroke: s.colour, 'stroke-width': 2 };
          if (s.dash) key['stroke-dasharray'] = s.dash;
          g.appendChild(svgEl('line', key));
          g.appendChild(svgEl('text', { x: W - R + 40, y: ly, fill: '#223', 'font-size': 12 }, s.name));
        }
      });
      svg.appendChild(g);
      geomPanels.push({ T: T, H: Hp, Y: Y, series: p.series, label: p.label });
    });
    svg.appendChild(svgEl('text', { x: (L + W - R) / 2, y: H - 4, 'text-anchor': 'middle', fill: '#223', 'class': 'axis-label' }, 'time t (s)'));
    var cursor = svgEl('line', { 'class': 'cursor', x1: 0, x2: 0, y1: TOP, y2: H - B, stroke: '#e6007e', 'stroke-width': 1.5, display: 'none' });
    var hover = svgEl('line', { 'class': 'hover', x1: 0, x2: 0, y1: TOP, y2: H - B, stroke: '#889', 'stroke-dasharray': '3 3', display: 'none' });
    var brush = svgEl('rect', { 'class': 'brush', x: 0, y: TOP, width: 0, height: H - B - TOP, fill: 'rgba(47,111,222,0.15)', display: 'none' });
    svg.appendChild(cursor);
    svg.appendChild(hover);
    svg.appendChild(brush);
    plot.appendChild(svg);
    plotGeom = { W: W, L: L, R: R, H: H, t0: t0, t1: t1, X: X, panels: geomPanels, svg: svg, cursor: cursor, hover: hover, brush: brush, rows: run.rows };
    plotReset.disabled = !state.zoom;
    if (!time.disabled) plotCursor(+time.value);
  }
  function plotCursor(t) {
    if (!plotGeom) return;
    var x = plotGeom.X(t);
    var inside = t >= plotGeom.t0 && t <= plotGeom.t1;
    plotGeom.cursor.setAttribute('x1', x);
    plotGeom.cursor.setAttribute('x2', x);
    plotGeom.cursor.setAttribute('display', inside ? 'inline' : 'none');
    plotGeom.cursor.setAttribute('data-t', String(t));
  }
  function plotTimeAt(e) {
    var r = plotGeom.svg.getBoundingClientRect();
    var x = (e.clientX - r.left) / r.width * plotGeom.W;
    return { x: x, t: plotGeom.t0 + (x - plotGeom.L) / (plotGeom.W - plotGeom.L - plotGeom.R) * (plotGeom.t1 - plotGeom.t0) };
  }
  function nearestRow(rows, t) {
    var lo = 0, hi = rows.length - 1;
    while (hi - lo > 1) { var mid = (lo + hi) >> 1; if (rows[mid][0] <= t) lo = mid; else hi = mid; }
    return Math.abs(rows[hi][0] - t) < Math.abs(rows[lo][0] - t) ? hi : lo;
  }
  var plotDrag = null;
  plot.addEventListener('pointermove', function (e) {
    if (!plotGeom) return;
    var p = plotTimeAt(e);
    if (plotDrag) {
      var a = Math.min(plotDrag.x, p.x), b = Math.max(plotDrag.x, p.x);
      a = Math.max(a, plotGeom.L); b = Math.min(b, plotGeom.W - plotGeom.R);
      plotGeom.brush.setAttribute('x', a);
      plotGeom.brush.setAttribute('width', Math.max(0, b - a));
      plotGeom.brush.setAttribute('display', 'inline');
    }
    if (p.t < plotGeom.t0 || p.t > plotGeom.t1) { plotGeom.hover.setAttribute('display', 'none'); return; }
    var k = nearestRow(plotGeom.rows, p.t), row = plotGeom.rows[k], t = row[0];
    plotGeom.hover.setAttribute('x1', plotGeom.X(t));
    plotGeom.hover.setAttribute('x2', plotGeom.X(t));
    plotGeom.hover.setAttribute('display', 'inline');
    var parts = ['t = ' + num(t, 4) + ' s'];
    plotGeom.panels.forEach(function (pn) {
      pn.series.forEach(function (s) {
        var j = s.rows === plotGeom.rows ? k : nearestRow(s.rows, t);
        parts.push(s.name + ' = ' + num(s.rows[j][s.k], 5) + (unitOf(s.name.split(' ')[0]) ? ' ' + unitOf(s.name.split(' ')[0]) : ''));
      });
    });
    plotReadout.textContent = parts.join('   ');
  });
  plot.addEventListener('pointerleave', function () {
    if (plotGeom) plotGeom.hover.setAttribute('display', 'none');
  });
  plot.addEventListener('pointerdown', function (e) {
    if (!plotGeom) return;
    e.preventDefault();
    plotDrag = { x: plotTimeAt(e).x, t: plotTimeAt(e).t };
    plot.setPointerCapture(e.pointerId);
  });
  plot.addEventListener('pointerup', function (e) {
    if (!plotGeom || !plotDrag) { plotDrag = null; return; }
    var p = plotTimeAt(e), d = plotDrag;
    plotDrag = null;
    plotGeom.brush.setAttribute('display', 'none');
    var ta = Math.max(Math.min(d.t, p.t), plotGeom.t0), tb = Math.min(Math.max(d.t, p.t), plotGeom.t1);
    if (Math.abs(p.x - d.x) > 8 && tb > ta) {
      state.zoom = [ta, tb];
      drawPlot();
    } else if (!time.disabled && p.t >= plotGeom.t0 && p.t <= plotGeom.t1) {
      seek(p.t); // a click sets the time
    }
  });
  plotReset.addEventListener('click', function () { state.zoom = null; drawPlot(); });
  plotColumns.addEventListener('change', drawPlot);
  plotSearch.addEventListener('input', filterColumns);

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

  // ---------------------------------------------------------------- animation (from the run's rows)
  function showAnimation(a) {
    if (a.format === 'view3d') return show3d(a.data);
    return showSvgAnimation(a.svg);
  }
  function show3d(data) {
    clear(animation);
    resetTime();
    if (typeof window.bondmechView3d !== 'function') {
      hint(animation, 'no animation: the 3D renderer (/view3d.js) did not load');
      return;
    }
    var canvas = document.createElement('canvas');
    canvas.className = 'bondmech-view3d';
    canvas.setAttribute('data-view', '3d');
    canvas.setAttribute('aria-label', 'the 3D view of the motion');
    animation.appendChild(canvas);
    animation.appendChild(el('p', 'the 3D view: drag to orbit, wheel to zoom; the grid is the ground, under the lowest point of the motion', 'hint view3d-note'));
    var a = { t0: data.t[0], t1: data.t[data.t.length - 1], digits: data.digits || 2 };
    a.view = window.bondmechView3d(data, {
      canvas: canvas,
      grid: true,
      fit: function (c) {
        var full = document.fullscreenElement === $('animation-panel');
        var w = Math.max(320, Math.floor(animation.clientWidth || 640));
        c.width = w;
        c.height = full ? Math.max(300, Math.floor(window.innerHeight - 140)) : Math.round(0.62 * w);
      },
      onTime: function (t) { if (state.anim === a) showTime(t); },
      autoplay: false
    });
    state.anim = a;
    presets.hidden = false;
    time.min = a.t0; time.max = a.t1; time.step = 'any'; time.disabled = false; play.disabled = false;
    seek(a.t0);
  }
  function showSvgAnimation(text) {
    var svg = safeSvg(text);
    clear(animation);
    resetTime();
    if (!svg) { hint(animation, 'no animation: the service sent no SVG'); return; }
    svg.removeAttribute('width');
    svg.removeAttribute('height');
    // the note on a slowed playback names the command line's flag: on the page, say it plainly
    Array.prototype.forEach.call(svg.querySelectorAll('text.note'), function (n) {
      var m = /played at ×([0-9.e-]+)/.exec(n.textContent);
      if (m) n.textContent = 'played at ×' + m[1] + ' (slowed so that the motion can be followed; the slider goes through it at any pace)';
    });
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
  }
  function resetTime() {
    if (state.anim && state.anim.view) state.anim.view.destroy();
    state.anim = null;
    presets.hidden = true;
    time.disabled = true; play.disabled = true; play.textContent = 'play';
    time.value = time.min;
    readout.textContent = '';
    if (plotGeom) plotGeom.cursor.setAttribute('display', 'none');
  }
  function showTime(t) {
    var a = state.anim;
    var text = 't = ' + t.toFixed(a.digits) + ' s';
    time.value = t;
    readout.textContent = text;
    if (a.clock) a.clock.textContent = text;
    plotCursor(t);
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
    if (state.mode) modeFrame();
    requestAnimationFrame(tick);
  }
  // The decoupled twin's motion drawn over the DAE's, faded, on the same slider: its ids
  // renamed (the two pictures share the page), its background and labels left out.
  function showTwinAnimation(tw) {
    var a = state.anim;
    if (!a || !tw || tw.error) return;
    if (a.view) {
      if (tw.format !== 'view3d') return;
      a.view.ghost(tw.data);
      animation.appendChild(el('p', 'faded: the decoupled twin, on the same clock', 'hint twin-note'));
      return;
    }
    var svg = safeSvg(tw.svg || '');
    if (!svg) return;
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
  }
  presets.addEventListener('click', function (e) {
    var v = e.target && e.target.dataset && e.target.dataset.view;
    if (v && state.anim && state.anim.view && state.anim.view.preset) state.anim.view.preset(v);
  });
  $('fullscreen').addEventListener('click', function () {
    var panel = $('animation-panel');
    if (document.fullscreenElement) { document.exitFullscreen().catch(function () {}); return; }
    if (panel.requestFullscreen) panel.requestFullscreen().catch(function () { setStatus('fullscreen is not allowed here'); });
  });
  document.addEventListener('fullscreenchange', function () {
    $('fullscreen').textContent = document.fullscreenElement ? 'exit fullscreen' : 'fullscreen';
    if (state.anim && state.anim.view && state.anim.view.resize) state.anim.view.resize();
  });

  // ---------------------------------------------------------------- a planar posture, drawn here
  // The bodies of a planar scene in the pose `coords` (`b.x`, `b.y`, `b.angle`): a bar from the
  // centre to each point, the polygon of three points or more, joints as rings, ground marks.
  function postureSvg(doc, coords, cls) {
    var bodies = doc.bodies || [];
    var world = function (b, p) {
      var x = coords[b.name + '.x'], y = coords[b.name + '.y'], a = coords[b.name + '.angle'] || 0;
      if (x === undefined || y === undefined) return null;
      var c = Math.cos(a), s = Math.sin(a);
      return [x + c * p[0] - s * p[1], y + s * p[0] + c * p[1]];
    };
    var pts = [], shapes = [];
    bodies.forEach(function (b, i) {
      var centre = world(b, [0, 0]);
      if (!centre) return;
      var names = Object.keys(b.points || {}), ws = names.map(function (n) { return world(b, b.points[n]); });
      shapes.push({ body: b, centre: centre, pts: ws, colour: BODY_COLOURS[i % BODY_COLOURS.length] });
      pts.push(centre);
      ws.forEach(function (w) { pts.push(w); });
    });
    var joints = [];
    (doc.joints || []).forEach(function (j) {
      var at = null, ground = false;
      (j.bodies || []).forEach(function (bn, k) {
        var p = (j.points || [])[k];
        if (bn === 'ground') { ground = true; if (Array.isArray(p)) at = at || p; return; }
        var b = bodies.filter(function (x) { return x.name === bn; })[0];
        if (!b || at) return;
        var local = typeof p === 'string' ? (b.points || {})[p] : Array.isArray(p) ? p : [0, 0];
        if (local) at = world(b, local);
      });
      if (at && isFinite(at[0]) && isFinite(at[1])) { joints.push({ at: at, ground: ground }); pts.push(at); }
    });
    if (!pts.length) return null;
    var x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    pts.forEach(function (p) { x0 = Math.min(x0, p[0]); x1 = Math.max(x1, p[0]); y0 = Math.min(y0, p[1]); y1 = Math.max(y1, p[1]); });
    return { shapes: shapes, joints: joints, box: [x0, x1, y0, y1], cls: cls };
  }
  function drawPosture(target, pose, box, extra) {
    var W = 420, H = 300, pad = 24;
    var bx = box || pose.box, sx = bx[1] - bx[0] || 1, sy = bx[3] - bx[2] || 1;
    var s = Math.min((W - 2 * pad) / sx, (H - 2 * pad) / sy);
    var ox = W / 2 - s * (bx[0] + bx[1]) / 2, oy = H / 2 + s * (bx[2] + bx[3]) / 2;
    var P = function (p) { return [ox + s * p[0], oy - s * p[1]]; };
    var svg = target.tagName === 'svg' ? target : svgEl('svg', { viewBox: '0 0 ' + W + ' ' + H, role: 'img', 'font-size': 12, 'class': 'posture-svg' });
    clear(svg);
    svg.appendChild(svgEl('rect', { x: 0, y: 0, width: W, height: H, fill: '#fbfbfd' }));
    (extra || []).concat([pose]).forEach(function (ps, layer) {
      var faded = layer < (extra || []).length;
      var g = svgEl('g', { opacity: faded ? 0.25 : 1, 'class': faded ? 'rest' : 'bodies' });
      ps.joints.forEach(function (j) {
        if (!j.ground) return;
        var q = P(j.at);
        g.appendChild(svgEl('path', { d: 'M' + (q[0] - 9) + ' ' + (q[1] + 12) + 'h18M' + q[0] + ' ' + q[1] + 'l-7 12M' + q[0] + ' ' + q[1] + 'l7 12', stroke: '#555', fill: 'none' }));
      });
      ps.shapes.forEach(function (sh) {
        var bg = svgEl('g', { 'class': 'body', 'data-body': sh.body.name });
        var c = P(sh.centre);
        if (sh.pts.length >= 3) bg.appendChild(svgEl('polygon', { points: sh.pts.map(function (p) { var q = P(p); return q[0].toFixed(1) + ',' + q[1].toFixed(1); }).join(' '), fill: sh.colour, 'fill-opacity': 0.2, stroke: 'none' }));
        sh.pts.forEach(function (p) {
          var q = P(p);
          bg.appendChild(svgEl('line', { x1: c[0], y1: c[1], x2: q[0], y2: q[1], stroke: sh.colour, 'stroke-width': 5, 'stroke-linecap': 'round' }));
        });
        bg.appendChild(svgEl('circle', { cx: c[0], cy: c[1], r: 3.5, fill: '#222' }));
        if (!faded) bg.appendChild(svgEl('text', { x: c[0] + 7, y: c[1] - 7, fill: '#223' }, sh.body.name));
        g.appendChild(bg);
      });
      ps.joints.forEach(function (j) {
        var q = P(j.at);
        g.appendChild(svgEl('circle', { cx: q[0], cy: q[1], r: 4.5, fill: '#fff', stroke: '#222', 'stroke-width': 1.8 }));
      });
      svg.appendChild(g);
    });
    if (target.tagName !== 'svg') { clear(target); target.appendChild(svg); }
    return svg;
  }
  // Before the first run: the scene as written (planar scenes whose bodies give their positions).
  function preview() {
    var doc = sceneDoc();
    if (!doc || !bodiesOf(doc) || doc.dimension === 3 || state.run) return;
    var coords = {};
    doc.bodies.forEach(function (b) {
      if (Array.isArray(b.position)) { coords[b.name + '.x'] = +b.position[0]; coords[b.name + '.y'] = +b.position[1]; }
      coords[b.name + '.angle'] = typeof b.angle === 'number' ? b.angle : 0;
    });
    var pose = postureSvg(doc, coords);
    if (!pose || !pose.shapes.length) return;
    clear(animation);
    var box = el('div', null, 'posture preview');
    drawPosture(box, pose);
    animation.appendChild(box);
    animation.appendChild(el('p', 'the scene as written, before a run: run it to see its motion', 'hint twin-note'));
  }

  // ---------------------------------------------------------------- equilibrium
  function doEquilibrium() {
    if (!jsonOk()) return Promise.resolve();
    var signal = begin('equilibrium'), body = editor.value, doc = sceneDoc();
    setStatus('finding the equilibrium…');
    document.body.dataset.state = 'analysing';
    hint(eqResult, 'finding the equilibrium…');
    return post('/v1/equilibrium', body, signal).then(function (r) {
      return r.ok ? r.json() : readProblem(r).then(function (p) { return { problem: p }; });
    }).then(function (eq) {
      if (!current(signal)) return;
      showEquilibrium(eq, doc);
      setStatus(eq.problem ? 'no equilibrium' : 'equilibrium found');
      document.body.dataset.state = eq.problem ? 'failed' : 'analysed';
    }).catch(function (e) { failed(e, signal); }).then(function () { end(signal); });
  }
  function showEquilibrium(eq, doc) {
    stopMode();
    clear(eqResult);
    if (eq.problem) {
      eqResult.appendChild(el('p', 'no equilibrium: ' + problemText(eq.problem), 'unstable'));
      return;
    }
    var head = el('p');
    head.appendChild(el('span', eq.stability || (eq.stable ? 'stable' : 'not stable'), eq.stable ? 'stable' : 'unstable'));
    head.appendChild(document.createTextNode(eq.converged ? ' equilibrium: converged in ' + eq.iterations + ' iterations (residual ' + num(eq.residual) + ')'
      : ' — the search did not converge (residual ' + num(eq.residual) + ')'));
    eqResult.appendChild(head);
    var coords = eq.coordinates || {};
    if (doc && bodiesOf(doc) && doc.dimension !== 3) {
      var pose = postureSvg(doc, coords);
      if (pose && pose.shapes.length) {
        var pic = el('div', null, 'posture');
        drawPosture(pic, pose);
        eqResult.appendChild(pic);
      }
    }
    var t = el('table'), hr = el('tr');
    ['coordinate', 'value', 'unit'].forEach(function (h) { hr.appendChild(el('th', h)); });
    var thead = el('thead'); thead.appendChild(hr); t.appendChild(thead);
    var tb = el('tbody');
    Object.keys(coords).forEach(function (k) {
      var tr = el('tr');
      tr.appendChild(el('td', k));
      tr.appendChild(el('td', num(coords[k], 6)));
      tr.appendChild(el('td', unitOf(k)));
      tb.appendChild(tr);
    });
    Object.keys(eq.drivers || {}).forEach(function (k) {
      var tr = el('tr');
      tr.appendChild(el('td', k));
      tr.appendChild(el('td', num(eq.drivers[k], 6)));
      tr.appendChild(el('td', unitOf(k)));
      tb.appendChild(tr);
    });
    t.appendChild(tb);
    eqResult.appendChild(t);
    if (eq.stiffness_eigenvalues && eq.stiffness_eigenvalues.length) {
      eqResult.appendChild(el('p', 'ω² of the reduced stiffness: ' + eq.stiffness_eigenvalues.map(function (x) { return num(x, 4); }).join(', ') + ' (1/s²)', 'hint'));
    }
  }

  // ---------------------------------------------------------------- linearize: modes and Bode
  function poseOutputs(doc) {
    var out = [];
    (doc.bodies || []).forEach(function (b) { out.push(b.name + '.x', b.name + '.y', b.name + '.angle'); });
    return out;
  }
  // For a planar scene without inputs, the Bode plot needs one: a torque `u` on the first body,
  // added to the request (zero at the operating point: the modes are the scene's).
  function withTorqueInput(doc) {
    var d = JSON.parse(JSON.stringify(doc));
    var name = 'u';
    while ((d.inputs || []).some(function (i) { return i.name === name; }) || (d.bodies || []).some(function (b) { return b.name === name; })) name += '_';
    d.inputs = [{ name: name }];
    d.loads = (d.loads || []).concat([{ type: 'torque', body: d.bodies[0].name, value: name }]);
    return { doc: d, input: name, body: d.bodies[0].name };
  }
  function doLinearize() {
    if (!jsonOk()) return Promise.resolve();
    var signal = begin('linearize'), body = editor.value, doc = sceneDoc();
    setStatus('linearizing…');
    document.body.dataset.state = 'analysing';
    stopMode();
    hint(modesBox, 'linearizing…');
    clear(bodeBox);
    var planar = doc && bodiesOf(doc) && doc.dimension !== 3;
    var q = planar ? '?output=' + encodeURIComponent(poseOutputs(doc).join(',')) : '';
    var json = function (r) { return r.ok ? r.json() : readProblem(r).then(function (p) { return { problem: p }; }); };
    var main = post('/v1/linearize' + q, body, signal).then(json);
    var hasInputs = doc && Array.isArray(doc.inputs) && doc.inputs.length;
    var added = null, bode;
    if (hasInputs || !planar) {
      bode = main.then(function (lm) { return { lm: lm, outputs: null }; });
    } else {
      added = withTorqueInput(doc);
      bode = post('/v1/linearize', JSON.stringify(added.doc), signal).then(json).then(function (lm) { return { lm: lm }; });
    }
    return Promise.all([main, bode]).then(function (all) {
      if (!current(signal)) return;
      var lm = all[0];
      showModes(lm, doc);
      showBode(all[1].lm, added, lm);
      setStatus(lm.problem ? 'no linear model' : 'linearized');
      document.body.dataset.state = lm.problem ? 'failed' : 'analysed';
    }).catch(function (e) { failed(e, signal); }).then(function () { end(signal); });
  }
  function showModes(lm, doc) {
    clear(modesBox);
    if (lm.problem) { modesBox.appendChild(el('p', 'no linear model: ' + problemText(lm.problem), 'unstable')); return; }
    var head = el('p', (lm.equilibrium ? 'about the equilibrium' : 'about t = ' + num(lm.t) + ' s (not an equilibrium)') +
      ': ' + lm.states.length + ' states (' + lm.states.join(', ') + ')');
    modesBox.appendChild(head);
    (lm.notes || []).forEach(function (n) { modesBox.appendChild(el('p', n, 'hint')); });
    if (!lm.modes.length) { modesBox.appendChild(el('p', 'no modes: the operating point is not an equilibrium', 'hint')); return; }
    var t = el('table'), thead = el('thead'), hr = el('tr');
    ['mode', 'frequency (Hz)', 'damping ratio', 'shape'].forEach(function (h) { hr.appendChild(el('th', h)); });
    thead.appendChild(hr); t.appendChild(thead);
    var tb = el('tbody');
    var ndisp = Math.max(1, Math.floor(lm.states.length / 2));
    lm.modes.forEach(function (m, i) {
      var tr = el('tr');
      tr.dataset.frequency = String(m.frequency_hz);
      tr.dataset.mode = String(i);
      tr.appendChild(el('td', String(i + 1)));
      tr.appendChild(el('td', num(m.frequency_hz, 4), 'frequency'));
      // a damping ratio at rounding level (an undamped mode's 1e-16) reads as 0
      tr.appendChild(el('td', m.damping_ratio === null ? '—' : Math.abs(m.damping_ratio) < 1e-12 ? '0' : num(m.damping_ratio, 3)));
      var shape = lm.states.slice(0, ndisp).filter(function (s) { return m.shape[s]; }).map(function (s) {
        var c = m.shape[s], mag = Math.hypot(c[0], c[1]), sign = c[0] < 0 ? -1 : 1;
        return s + ' ' + num(sign * mag, 3);
      });
      tr.appendChild(el('td', shape.join(', ')));
      tr.title = 'click to animate this mode';
      tr.addEventListener('click', function () {
        Array.prototype.forEach.call(tb.children, function (r) { r.classList.toggle('selected', r === tr); });
        startMode(lm, m, doc);
      });
      tb.appendChild(tr);
    });
    t.appendChild(tb);
    modesBox.appendChild(t);
    modesBox.appendChild(el('p', 'click a mode to see it move (about the rest posture, amplitude exaggerated)', 'hint'));
  }
  // A mode's motion: the operating point plus Re(C v e^{iωτ}) on the pose outputs, played at
  // one cycle per 1.6 s whatever its frequency.
  function startMode(lm, m, doc) {
    stopMode();
    if (!doc || !bodiesOf(doc) || doc.dimension === 3) { setStatus('mode animation: planar scenes only'); return; }
    var outs = lm.outputs, v = lm.states.map(function (s) { return m.shape[s] || [0, 0]; });
    var y = outs.map(function (o, i) {
      var re = 0, im = 0;
      lm.C[i].forEach(function (c, j) { re += c * v[j][0]; im += c * v[j][1]; });
      return [re, im];
    });
    var op = lm.operating_point || {};
    var base = {};
    outs.forEach(function (o) { base[o] = op[o] !== undefined ? op[o] : 0; });
    var maxA = 0, maxX = 0;
    outs.forEach(function (o, i) {
      var mag = Math.hypot(y[i][0], y[i][1]);
      if (/\.angle$/.test(o)) maxA = Math.max(maxA, mag); else maxX = Math.max(maxX, mag);
    });
    var rest = postureSvg(doc, base);
    if (!rest) return;
    var size = Math.max(rest.box[1] - rest.box[0], rest.box[3] - rest.box[2]) || 1;
    var amp = maxA > 0 ? 0.35 / maxA : maxX > 0 ? 0.12 * size / maxX : 0;
    var target = eqResult.querySelector('.mode-view');
    if (!target) {
      target = el('div', null, 'posture mode-view');
      eqResult.insertBefore(target, eqResult.firstChild);
    }
    var box = rest.box.slice();
    var pad = 0.45 * size;
    box = [box[0] - pad, box[1] + pad, box[2] - pad, box[3] + pad];
    var caption = eqResult.querySelector('.mode-caption') || el('p', null, 'hint mode-caption');
    caption.textContent = 'mode at ' + num(m.frequency_hz, 4) + ' Hz, about the rest posture (faded), amplitude exaggerated, one cycle per 1.6 s';
    eqResult.insertBefore(caption, target.nextSibling);
    state.mode = { lm: lm, outs: outs, y: y, base: base, amp: amp, doc: doc, rest: rest, box: box, target: target, start: performance.now(), svg: null };
    modeFrame();
  }
  function modeFrame() {
    var M = state.mode;
    var phase = 2 * Math.PI * ((performance.now() - M.start) / 1600);
    var c = Math.cos(phase), s = Math.sin(phase), coords = {};
    M.outs.forEach(function (o, i) { coords[o] = M.base[o] + M.amp * (M.y[i][0] * c - M.y[i][1] * s); });
    var pose = postureSvg(M.doc, coords);
    if (!M.svg) { clear(M.target); M.svg = drawPosture(M.target, pose, M.box, [M.rest]); M.svg.setAttribute('class', 'posture-svg mode-svg'); }
    else drawPosture(M.svg, pose, M.box, [M.rest]);
    M.svg.setAttribute('data-phase', String(phase));
  }
  function stopMode() {
    state.mode = null;
    Array.prototype.forEach.call(eqResult.querySelectorAll('.mode-view, .mode-caption'), function (n) { n.parentNode.removeChild(n); });
  }

  // complex arithmetic for H(iω) = C (iωI − A)⁻¹ B + D
  function solveComplex(Mr, Mi, br, bi) {
    var n = br.length, i, j, k;
    var ar = Mr.map(function (r) { return r.slice(); }), ai = Mi.map(function (r) { return r.slice(); });
    var xr = br.slice(), xi = bi.slice();
    for (k = 0; k < n; k++) {
      var p = k, best = 0;
      for (i = k; i < n; i++) { var m = Math.hypot(ar[i][k], ai[i][k]); if (m > best) { best = m; p = i; } }
      if (best === 0) return null;
      if (p !== k) {
        var t = ar[p]; ar[p] = ar[k]; ar[k] = t; t = ai[p]; ai[p] = ai[k]; ai[k] = t;
        t = xr[p]; xr[p] = xr[k]; xr[k] = t; t = xi[p]; xi[p] = xi[k]; xi[k] = t;
      }
      var dr = ar[k][k], di = ai[k][k], dd = dr * dr + di * di;
      for (i = k + 1; i < n; i++) {
        // f = a[i][k] / a[k][k]
        var fr = (ar[i][k] * dr + ai[i][k] * di) / dd, fi = (ai[i][k] * dr - ar[i][k] * di) / dd;
        if (fr === 0 && fi === 0) continue;
        for (j = k; j < n; j++) {
          ar[i][j] -= fr * ar[k][j] - fi * ai[k][j];
          ai[i][j] -= fr * ai[k][j] + fi * ar[k][j];
        }
        xr[i] -= fr * xr[k] - fi * xi[k];
        xi[i] -= fr * xi[k] + fi * xr[k];
      }
    }
    for (k = n - 1; k >= 0; k--) {
      var sr = xr[k], si = xi[k];
      for (j = k + 1; j < n; j++) { sr -= ar[k][j] * xr[j] - ai[k][j] * xi[j]; si -= ar[k][j] * xi[j] + ai[k][j] * xr[j]; }
      var er = ar[k][k], ei = ai[k][k], ee = er * er + ei * ei;
      xr[k] = (sr * er + si * ei) / ee; xi[k] = (si * er - sr * ei) / ee;
    }
    return [xr, xi];
  }
  function showBode(lm, added, modal) {
    clear(bodeBox);
    if (!lm || lm.problem) { if (lm && lm.problem) bodeBox.appendChild(el('p', 'no Bode plot: ' + problemText(lm.problem), 'hint')); return; }
    var n = lm.states.length, nu = lm.inputs.length;
    if (!nu) { bodeBox.appendChild(el('p', 'no Bode plot: the scene has no inputs ("inputs", §22 of the scene format)', 'hint')); return; }
    if (n > 80) { bodeBox.appendChild(el('p', 'no Bode plot on the page for ' + n + ' states: `bondmech linearize --bode` draws it', 'hint')); return; }
    // the outputs: the displacement states (the first half of the states), at most four
    var ndisp = Math.max(1, Math.floor(n / 2));
    var outRows = [];
    lm.outputs.forEach(function (o, i) { if (lm.states.indexOf(o) >= 0 && lm.states.indexOf(o) < ndisp && outRows.length < 4) outRows.push(i); });
    if (!outRows.length) outRows = lm.outputs.slice(0, 4).map(function (o, i) { return i; });
    var freqs = (modal && !modal.problem ? modal.modes : lm.modes).map(function (m) { return m.frequency_hz; }).filter(function (f) { return f > 0 && isFinite(f); });
    var lo = freqs.length ? Math.pow(10, Math.floor(Math.log10(Math.min.apply(null, freqs))) - 1) : 0.01;
    var hi = freqs.length ? Math.pow(10, Math.ceil(Math.log10(Math.max.apply(null, freqs))) + 1) : 100;
    var decades = Math.log10(hi / lo), N = Math.round(150 * decades), EPS = 1e-3;
    var series = [];
    outRows.forEach(function (i) { for (var u = 0; u < nu; u++) series.push({ out: i, inp: u, pts: [] }); });
    for (var s = 0; s <= N; s++) {
      var f = lo * Math.pow(10, decades * s / N), w = 2 * Math.PI * f;
      // s = (ε + i)·2πf, ε = 1e-3: a hair right of the imaginary axis, so that an undamped
      // resonance is a finite peak and the phase turns the way a little damping turns it
      var Mr = lm.A.map(function (r, i) { return r.map(function (a, j) { return (i === j ? EPS * w : 0) - a; }); });
      var Mi = lm.A.map(function (r, i) { return r.map(function (a, j) { return i === j ? w : 0; }); });
      var cols = [];
      for (var u = 0; u < nu; u++) {
        var x = solveComplex(Mr, Mi, lm.B.map(function (r) { return r[u]; }), lm.B.map(function () { return 0; }));
        cols.push(x);
      }
      series.forEach(function (sr) {
        var x = cols[sr.inp];
        if (!x) return;
        var re = lm.D[sr.out][sr.inp], im = 0;
        lm.C[sr.out].forEach(function (c, j) { re += c * x[0][j]; im += c * x[1][j]; });
        var db = 20 * Math.log10(Math.hypot(re, im)), deg = Math.atan2(im, re) * 180 / Math.PI;
        var prev = sr.pts.length ? sr.pts[sr.pts.length - 1][2] : null;
        if (prev !== null) deg += 360 * Math.round((prev - deg) / 360);
        if (isFinite(db) && isFinite(deg)) sr.pts.push([f, db, deg]);
      });
    }
    var W = 640, L = 70, R = 170, T = 24, PH = 150, GAP = 30, B = 36, H = T + 2 * PH + GAP + B;
    var X = function (f) { return L + Math.log10(f / lo) / decades * (W - L - R); };
    var svg = svgEl('svg', { viewBox: '0 0 ' + W + ' ' + H, role: 'img', 'font-size': 12, 'aria-label': 'Bode plot', 'class': 'bode' });
    var inputName = added ? 'torque ' + added.input + ' on ' + added.body + ' (N·m, added for this plot)' : lm.inputs.join(', ');
    svg.appendChild(svgEl('text', { x: L, y: 14, fill: '#223' }, 'Bode plot: input ' + inputName));
    svg.appendChild(svgEl('text', { x: W - R + 10, y: T + 2 * PH + GAP - 4, fill: '#778', 'font-size': 10 }, 'at s = (0.001 + i)·2πf'));
    [['magnitude (dB)', 1], ['phase (deg)', 2]].forEach(function (spec, p) {
      var top = T + p * (PH + GAP), k = spec[1], ymin = Infinity, ymax = -Infinity;
      series.forEach(function (sr) { sr.pts.forEach(function (q) { ymin = Math.min(ymin, q[k]); ymax = Math.max(ymax, q[k]); }); });
      if (!isFinite(ymin)) { ymin = -1; ymax = 1; }
      if (!(ymax > ymin)) { ymax += 1; ymin -= 1; }
      var Y = function (y) { return top + (ymax - y) / (ymax - ymin) * PH; };
      svg.appendChild(svgEl('rect', { x: L, y: top, width: W - L - R, height: PH, fill: '#fbfbfd', stroke: '#ccd' }));
      ticks(ymin, ymax, 4).forEach(function (ty) {
        svg.appendChild(svgEl('line', { x1: L, x2: W - R, y1: Y(ty), y2: Y(ty), stroke: '#e3e6ec' }));
        svg.appendChild(svgEl('text', { x: L - 6, y: Y(ty) + 4, 'text-anchor': 'end', fill: '#445' }, tickLabel(ty)));
      });
      for (var d = Math.round(Math.log10(lo)); d <= Math.round(Math.log10(hi)); d++) {
        var fx = X(Math.pow(10, d));
        svg.appendChild(svgEl('line', { x1: fx, x2: fx, y1: top, y2: top + PH, stroke: '#e3e6ec' }));
        if (p === 1) svg.appendChild(svgEl('text', { x: fx, y: top + PH + 15, 'text-anchor': 'middle', fill: '#445' }, tickLabel(Math.pow(10, d))));
      }
      freqs.forEach(function (f) {
        svg.appendChild(svgEl('line', { x1: X(f), x2: X(f), y1: top, y2: top + PH, stroke: '#e6007e', 'stroke-dasharray': '4 3', 'class': 'mode-mark', 'data-frequency': f }));
        if (p === 0) svg.appendChild(svgEl('text', { x: X(f) + 3, y: top + 12 + 12 * (freqs.indexOf(f) % 2), fill: '#e6007e', 'font-size': 11 }, num(f, 3) + ' Hz'));
      });
      svg.appendChild(svgEl('text', { x: 14, y: top + PH / 2, 'text-anchor': 'middle', fill: '#223', transform: 'rotate(-90 14 ' + (top + PH / 2) + ')', 'class': 'axis-label' }, spec[0]));
      series.forEach(function (sr, j) {
        svg.appendChild(svgEl('polyline', { points: sr.pts.map(function (q) { return X(q[0]).toFixed(1) + ',' + Y(q[k]).toFixed(1); }).join(' '),
          fill: 'none', stroke: PALETTE[j % PALETTE.length], 'stroke-width': 1.6, 'class': 'bode-curve' }));
      });
    });
    series.forEach(function (sr, j) {
      var ly = T + 12 + 16 * j;
      svg.appendChild(svgEl('line', { x1: W - R + 10, x2: W - R + 30, y1: ly - 4, y2: ly - 4, stroke: PALETTE[j % PALETTE.length], 'stroke-width': 2 }));
      svg.appendChild(svgEl('text', { x: W - R + 36, y: ly, fill: '#223' }, lm.outputs[sr.out] + (nu > 1 ? ' / ' + lm.inputs[sr.inp] : '')));
    });
    svg.appendChild(svgEl('text', { x: (L + W - R) / 2, y: H - 4, 'text-anchor': 'middle', fill: '#223', 'class': 'axis-label' }, 'frequency f (Hz)'));
    bodeBox.appendChild(svg);
  }

  // ---------------------------------------------------------------- bond graph, zoom and pan
  var view = null; // {x, y, w, h, base}
  // many bodies: one node per body (and per joint) unless asked otherwise
  var collapseBox = $('graph-collapse'), collapseSet = false;
  function loadGraph(body, signal) {
    hint(graph, 'drawing the bond graph…');
    view = null;
    var doc = sceneDoc();
    if (!collapseSet) collapseBox.checked = !!(doc && Array.isArray(doc.bodies) && doc.bodies.length > 12);
    return post('/v1/graph?format=svg&collapse=' + (collapseBox.checked ? 'true' : 'false'), body, signal).then(function (r) {
      if (!current(signal)) return null;
      if (!r.ok) return readProblem(r).then(function (p) { if (current(signal)) hint(graph, 'no bond graph: ' + problemText(p)); });
      return r.text().then(function (text) {
        if (!current(signal)) return;
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
        // a long, thin graph (a chain of many bodies): open on its first part at a readable size
        var r2 = graph.getBoundingClientRect(), aspect = vb[2] / vb[3], box = r2.width / Math.max(r2.height, 1);
        if (aspect > 3 * box) { view.h = vb[3] * 2; view.w = view.h * box; view.y = vb[1] - 0.5 * vb[3]; }
        else if (1 / aspect > 3 / box) { view.w = vb[2] * 2; view.h = view.w / box; view.x = vb[0] - 0.5 * vb[2]; }
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
  collapseBox.addEventListener('change', function () {
    collapseSet = true;
    if (state.run && state.run.source === editor.value) loadGraph(editor.value, state.controller ? state.controller.signal : undefined);
  });
  $('graph-zoom-in').addEventListener('click', function () { zoom(1 / 1.4); });
  $('graph-zoom-out').addEventListener('click', function () { zoom(1.4); });
  $('graph-reset').addEventListener('click', function () {
    if (view) { view.x = view.base[0]; view.y = view.base[1]; view.w = view.base[2]; view.h = view.base[3]; applyView(); }
  });

  // ---------------------------------------------------------------- compare
  // One request for the comparison: /v1/compare?format=ndjson solves the DAE and the twin once
  // each, with progress, and sends the twin's rows and its motion drawn from them.
  function doCompare() {
    if (!fieldsOk()) return Promise.resolve();
    var signal = begin('compare'), body = editor.value, started = performance.now(), doc = sceneDoc();
    setStatus('comparing the DAE and the decoupled twin…');
    hint(verdict, 'comparing…');
    document.body.dataset.state = 'comparing';
    state.twin = null;
    var needRun = !state.run || state.run.error || state.run.source !== body;
    var runDone = needRun ? Promise.all([runPanels(body, signal, doc), loadGraph(body, signal)]).then(function (a) { return a[0]; })
      : Promise.resolve(state.run);
    var kind = animateKind(doc);
    var extra = { format: 'ndjson' };
    if (kind) extra.animate = kind;
    var result = { compare: null, twin: null, twinAnimation: null, error: null };
    var cmp = post('/v1/compare' + solveQuery(extra), body, signal).then(function (r) {
      if (!r.ok) return readProblem(r).then(function (p) { result.error = p; return result; });
      var reader = r.body.getReader(), decoder = new TextDecoder(), buffer = '';
      function line(text) {
        if (!text.trim()) return;
        var v = JSON.parse(text);
        if (v.progress) {
          var p = v.progress, share = p.of ? p.rows / p.of : 0;
          if (current(signal)) {
            progress.value = (p.solve === 'twin' ? 0.5 : 0) + 0.5 * share;
            setStatus('comparing: ' + (p.solve === 'twin' ? 'the decoupled twin' : 'the DAE') + ', ' + p.rows + ' of ' + p.of + ' rows');
          }
        } else if (v.twin) result.twin = v.twin;
        else if (v.twin_animation) result.twinAnimation = v.twin_animation;
        else if (v.compare) result.compare = v.compare;
        else if (v.error) result.error = v.error;
      }
      function pump() {
        return reader.read().then(function (chunk) {
          if (chunk.done) { line(buffer); return result; }
          buffer += decoder.decode(chunk.value, { stream: true });
          var parts = buffer.split('\n');
          buffer = parts.pop();
          parts.forEach(line);
          return pump();
        });
      }
      return pump();
    });
    return Promise.all([cmp, runDone]).then(function (all) {
      if (!current(signal)) return;
      var res = all[0], run = all[1];
      clear(verdict);
      if (res.error || !res.compare) {
        flagParameter(res.error);
        verdict.appendChild(el('span', 'no verdict: ' + problemText(res.error), 'warn'));
      } else {
        var c = res.compare, v = c.verdict || {};
        verdict.appendChild(el('strong', 'recommended: ' + v.recommended));
        verdict.appendChild(document.createTextNode(
          '\n' + (v.reason || '') +
          '\nlargest position difference ' + num(v.max_position_difference) + ' m (tolerance ' + num(v.position_tolerance) + ' m)' +
          (c.position && c.position.column ? ', in ' + c.position.column + ' at t = ' + num(c.position.t) + ' s' : '') +
          '\nCPU ratio (twin / DAE) ' + num(v.cpu_ratio, 3) + ', steps ratio ' + num(v.steps_ratio, 3) +
          '\nthe plot overlays the twin (dashed) on the DAE (solid) and shows DAE − twin; the animation, faded'));
      }
      state.twin = res.twin && res.twin.columns ? res.twin : null;
      if (run && !run.error && res.twinAnimation) showTwinAnimation(res.twinAnimation);
      drawPlot();
      var ms = Math.round(performance.now() - started);
      setStatus((res.error ? 'comparison failed after ' : 'compared in ') + ms + ' ms');
      progress.value = 1;
      document.body.dataset.state = res.error || !res.compare ? 'failed' : 'compared';
    }).catch(function (e) { failed(e, signal); }).then(function () { end(signal); });
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
  picker.addEventListener('change', function () {
    if (!picker.value) return;
    clearResults();
    loadScene(picker.value);
  });
  editor.addEventListener('input', onEdit);
  runButton.addEventListener('click', doRun);
  compareButton.addEventListener('click', doCompare);
  eqButton.addEventListener('click', doEquilibrium);
  linButton.addEventListener('click', doLinearize);
  cancelButton.addEventListener('click', function () {
    if (state.controller) { state.controller.abort(); state.controller = null; cancelButton.disabled = true; cancelled(); }
  });
  csvButton.addEventListener('click', downloadCsv);
  ['rtol', 't_end'].forEach(function (id) {
    $(id).addEventListener('input', function () { checkField(id); });
    $(id).addEventListener('change', function () { checkField(id); });
  });
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
