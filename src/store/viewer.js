/* The trajectory player of a beamsim output directory's index.html
 * (docs/figures.md, "The trajectory player"). beamsim writes this file
 * beside the page as viewer.js, and the data it plays beside it as
 * viewer_data.js (window.beamsimViewerData; its format is described at the
 * top of src/store/viewer_data.c). Plain JavaScript, no library: the page
 * works opened from the disk, with no server.
 *
 * Each side (a run's or a sweep's one, a comparison's two or more) has a
 * canvas; all show the same trial at the same simulated time T, each its
 * last frame at or before T. World to canvas: px = ox + s x, py = oy - s y
 * (y up), s in pixels a metre, the same for every panel of a trial.
 *
 * window.beamsimViewer.drawFrame(trial, k) draws frame k of the trial
 * (trial the index into the data's trials; k the frame of the side with
 * the most frames) and returns what it drew; the page's
 * <pre id="beamsim-viewer-result"> holds that as JSON. Opened as
 * index.html#frame=I,K the page draws that frame when it loads. */
(function () {
  'use strict';
  var root = document.getElementById('beamsim-viewer');
  var result = document.getElementById('beamsim-viewer-result');
  var errors = window.beamsimErrors || (window.beamsimErrors = []);
  if (!root) return;

  function noteErrors() {
    root.setAttribute('data-errors', String(errors.length));
    if (errors.length) root.setAttribute('data-first-error', String(errors[0]));
  }
  window.addEventListener('load', noteErrors);

  var D = window.beamsimViewerData;
  if (!D || D.format !== 'beamsim-viewer-1') {
    errors.push('viewer_data.js: no data of format beamsim-viewer-1');
    root.textContent = 'The trajectories could not be loaded: viewer_data.js is missing.';
    root.setAttribute('data-state', 'failed');
    noteErrors();
    return;
  }

  var WIDTH = 560;
  var COLOR = {
    body: '#E8590C', bodyEdge: '#7A2E06', trail: '#A8400A', ghost: '#9A9A9A',
    pivot: '#333333', side: '#B4B4B4', success: '#2E9E44', propulsion: '#0072B2',
    lateral: '#111111', contact: '#CC0033', text: '#111111'
  };
  /* viridis at 0, 1/8, ..., 1; a beam's colour by its stiffness, the
     softest light, as the videos draw them */
  var VIRIDIS = [[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
                 [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]];
  /* the landscape figures' palette (light where the energy is low) */
  var PALETTE = [[0, [0xE4, 0xEB, 0xE9]], [0.35, [0xBF, 0xCF, 0xCB]],
                 [0.7, [0x7E, 0x9E, 0x99]], [1, [0x2E, 0x4A, 0x47]]];

  function viridis(u) {
    var x = 0.9 * (1 - Math.min(1, Math.max(0, u))) * 8, i = Math.min(7, Math.floor(x)), f = x - i;
    var c = [0, 1, 2].map(function (ch) {
      return Math.round(VIRIDIS[i][ch] + f * (VIRIDIS[i + 1][ch] - VIRIDIS[i][ch]));
    });
    return 'rgb(' + c.join(',') + ')';
  }

  function paletteColor(u) {
    u = Math.min(1, Math.max(0, u));
    for (var i = 1; i < PALETTE.length; i++) {
      if (u <= PALETTE[i][0] || i === PALETTE.length - 1) {
        var a = PALETTE[i - 1], b = PALETTE[i], f = (u - a[0]) / (b[0] - a[0]);
        return [0, 1, 2].map(function (ch) { return Math.round(a[1][ch] + f * (b[1][ch] - a[1][ch])); });
      }
    }
    return PALETTE[0][1];
  }

  /* ---- the data ---------------------------------------------------------------- */

  D.sides.forEach(function (side) {
    side.col = {};
    side.columns.forEach(function (name, i) { side.col[name] = i; });
    side.nBeams = side.columns.filter(function (n) { return /^theta\d+$/.test(n); }).length;
    side.byKey = {};
    side.trajectories.forEach(function (tr) { side.byKey[tr.group + ',' + tr.trial] = tr; });
  });

  function trajectoryOf(side, trial) {
    return side.byKey[trial.group + ',' + trial.trial] || null;
  }

  function bodyExtent(body) {
    if (body.shape === 'capsule') return body.radius + body.length / 2;
    if (body.shape === 'ellipse') return Math.max(body.semi_axes[0], body.semi_axes[1]);
    return body.radius;
  }

  /* The box every panel of a trial shows: the beams' reach, the side
     boundaries, the start and success lines, every frame and the landscape,
     padded by the body's extent. */
  function frameBox(trial) {
    var sc = D.scenes[trial.scene], xs = [], ys = [];
    sc.beams.forEach(function (b) {
      xs.push(b.pivot[0] - b.length, b.pivot[0] + b.length);
      ys.push(b.pivot[1] - b.length, b.pivot[1] + b.length);
    });
    xs.push(-sc.side_x, sc.side_x, sc.body.start[0]);
    ys.push(sc.success_y, sc.body.start[1]);
    D.sides.forEach(function (side) {
      var tr = trajectoryOf(side, trial);
      if (!tr) return;
      tr.frames.forEach(function (f) {
        var x = f[side.col.x], y = f[side.col.y];
        if (x !== null && y !== null && isFinite(x) && isFinite(y)) { xs.push(x); ys.push(y); }
      });
    });
    if (trial.landscape >= 0) {
      var l = D.landscapes[trial.landscape];
      xs.push(l.x0, l.x0 + (l.nx - 1) * l.dx);
      ys.push(l.y0, l.y0 + (l.ny - 1) * l.dy);
    }
    var pad = bodyExtent(sc.body) + 2;
    return [Math.min.apply(null, xs) - pad, Math.max.apply(null, xs) + pad,
            Math.min.apply(null, ys) - pad, Math.max.apply(null, ys) + pad];
  }

  function transformOf(trial) {
    var b = frameBox(trial), bw = b[1] - b[0], bh = b[3] - b[2];
    var h = Math.round(Math.min(720, Math.max(240, WIDTH * bh / bw)));
    var s = Math.min(WIDTH / bw, h / bh);
    return { width: WIDTH, height: h, scale: s,
             ox: WIDTH / 2 - s * (b[0] + b[1]) / 2, oy: h / 2 + s * (b[2] + b[3]) / 2 };
  }

  /* ---- the page ---------------------------------------------------------------- */

  function el(tag, attrs, text) {
    var e = document.createElement(tag);
    Object.keys(attrs || {}).forEach(function (k) { e.setAttribute(k, attrs[k]); });
    if (text !== undefined) e.textContent = text;
    return e;
  }

  var controls = el('div', { 'class': 'viewer-controls' });
  var select = el('select', { id: 'viewer-trial', 'aria-label': 'trial' });
  D.trials.forEach(function (t, i) { select.appendChild(el('option', { value: String(i) }, t.label)); });
  var play = el('button', { id: 'viewer-play', type: 'button' }, 'Play');
  var slider = el('input', { id: 'viewer-time', type: 'range', min: '0', max: '0', value: '0',
                             'aria-label': 'time' });
  var speed = el('select', { id: 'viewer-speed', 'aria-label': 'speed' });
  [0.25, 0.5, 1, 2, 4].forEach(function (v) {
    var o = el('option', { value: String(v) }, v + ' x');
    if (v === 1) o.selected = true;
    speed.appendChild(o);
  });
  var clock = el('span', { id: 'viewer-clock' }, '');
  if (D.trials.length > 1) controls.appendChild(select);
  else controls.appendChild(el('span', {}, D.trials[0].label + ' '));
  [play, slider, speed, clock].forEach(function (e) { controls.appendChild(document.createTextNode(' ')); controls.appendChild(e); });
  root.appendChild(controls);

  var panels = el('div', { 'class': 'viewer-panels' });
  panels.style.display = 'flex';
  panels.style.flexWrap = 'wrap';
  panels.style.gap = '8px';
  var canvases = D.sides.map(function (side, i) {
    var c = el('canvas', { id: 'viewer-side-' + i, width: String(WIDTH), height: '300',
                           'aria-label': side.label });
    c.style.border = '1px solid #ddd';
    panels.appendChild(c);
    return c;
  });
  root.appendChild(panels);
  root.appendChild(el('p', { 'class': 'viewer-legend' },
    'Body orange with its path so far' + (D.sides.length > 1 ? ' (the other sides\u2019 in grey)' : '') +
    '; beams from their pivots, coloured by stiffness (soft light, stiff dark); a red dot where a ' +
    'beam is in contact (a square at its tip); blue arrow the propulsive force, black arrow the ' +
    'lateral random force (where the file records it), one body extent per the larger of F_prop ' +
    'and R_m; dashed grey the side boundaries, dashed green the success line; the landscape ' +
    'E_total beneath where the directory holds its figure.'));

  /* ---- drawing ----------------------------------------------------------------- */

  var landCache = {};
  function landImage(i) {
    if (landCache[i]) return landCache[i];
    var l = D.landscapes[i], c = document.createElement('canvas');
    c.width = l.nx;
    c.height = l.ny;
    var g = c.getContext('2d'), img = g.createImageData(l.nx, l.ny), span = l.e_max - l.e_min;
    for (var j = 0; j < l.ny; j++) {
      for (var k = 0; k < l.nx; k++) {
        var rgb = paletteColor(span > 0 ? (l.e[j * l.nx + k] - l.e_min) / span : 0);
        var p = 4 * ((l.ny - 1 - j) * l.nx + k);
        img.data[p] = rgb[0]; img.data[p + 1] = rgb[1]; img.data[p + 2] = rgb[2]; img.data[p + 3] = 255;
      }
    }
    g.putImageData(img, 0, 0);
    landCache[i] = c;
    return c;
  }

  function arrow(g, x, y, dx, dy, color) {
    var d = Math.hypot(dx, dy);
    if (d < 1) return;
    var ux = dx / d, uy = dy / d, head = Math.min(10, 0.5 * d);
    g.strokeStyle = color;
    g.fillStyle = color;
    g.lineWidth = 2.5;
    g.beginPath();
    g.moveTo(x, y);
    g.lineTo(x + dx - ux * head * 0.8, y + dy - uy * head * 0.8);
    g.stroke();
    g.beginPath();
    g.moveTo(x + dx, y + dy);
    g.lineTo(x + dx - ux * head - uy * head * 0.45, y + dy - uy * head + ux * head * 0.45);
    g.lineTo(x + dx - ux * head + uy * head * 0.45, y + dy - uy * head - ux * head * 0.45);
    g.closePath();
    g.fill();
  }

  /* the last frame of tr at or before time T */
  function frameAt(side, tr, T) {
    var lo = 0, hi = tr.frames.length - 1, ti = side.col.t;
    if (tr.frames[0][ti] > T) return 0;
    while (lo < hi) {
      var mid = (lo + hi + 1) >> 1;
      if (tr.frames[mid][ti] <= T) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  function trail(g, side, tr, j, tf, color, width) {
    g.strokeStyle = color;
    g.lineWidth = width;
    g.beginPath();
    var started = false;
    for (var i = 0; i <= j; i++) {
      var f = tr.frames[i], x = f[side.col.x], y = f[side.col.y];
      if (x === null || y === null) break;
      if (started) g.lineTo(tf.ox + tf.scale * x, tf.oy - tf.scale * y);
      else g.moveTo(tf.ox + tf.scale * x, tf.oy - tf.scale * y);
      started = true;
    }
    g.stroke();
  }

  function drawBody(g, body, px, py, heading, s) {
    g.save();
    g.translate(px, py);
    g.rotate(-heading);
    g.beginPath();
    if (body.shape === 'capsule') {
      var h = body.length / 2 * s, r = body.radius * s;
      g.arc(h, 0, r, -Math.PI / 2, Math.PI / 2);
      g.arc(-h, 0, r, Math.PI / 2, 3 * Math.PI / 2);
      g.closePath();
    } else if (body.shape === 'ellipse') {
      g.ellipse(0, 0, body.semi_axes[0] * s, body.semi_axes[1] * s, 0, 0, 2 * Math.PI);
    } else {
      g.arc(0, 0, body.radius * s, 0, 2 * Math.PI);
    }
    g.fillStyle = COLOR.body;
    g.globalAlpha = 0.85;
    g.fill();
    g.globalAlpha = 1;
    g.strokeStyle = COLOR.bodyEdge;
    g.lineWidth = 1.5;
    g.stroke();
    if (body.shape !== 'disk' || body.rotates) {
      g.beginPath();
      g.moveTo(0, 0);
      g.lineTo(bodyExtent(body) * s, 0);
      g.stroke();
    }
    g.restore();
  }

  function dashed(g, x0, y0, x1, y1, color) {
    g.save();
    g.setLineDash([6, 4]);
    g.strokeStyle = color;
    g.lineWidth = 1.5;
    g.beginPath();
    g.moveTo(x0, y0);
    g.lineTo(x1, y1);
    g.stroke();
    g.restore();
  }

  /* Panel i at time T: what it drew. */
  function drawPanel(i, trial, T, tf) {
    var side = D.sides[i], canvas = canvases[i], g = canvas.getContext('2d');
    var sc = D.scenes[trial.scene], s = tf.scale;
    var px = function (x) { return tf.ox + s * x; }, py = function (y) { return tf.oy - s * y; };
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = '#FFFFFF';
    g.fillRect(0, 0, canvas.width, canvas.height);
    var out = { side: side.label, landscape: false, beams: 0, tips: [], contacts: [] };
    if (trial.landscape >= 0) {
      var l = D.landscapes[trial.landscape];
      g.imageSmoothingEnabled = true;
      g.drawImage(landImage(trial.landscape), px(l.x0 - l.dx / 2), py(l.y0 + (l.ny - 0.5) * l.dy),
                  l.nx * l.dx * s, l.ny * l.dy * s);
      out.landscape = true;
    }
    dashed(g, px(-sc.side_x), 0, px(-sc.side_x), canvas.height, COLOR.side);
    dashed(g, px(sc.side_x), 0, px(sc.side_x), canvas.height, COLOR.side);
    dashed(g, 0, py(sc.success_y), canvas.width, py(sc.success_y), COLOR.success);
    var tr = trajectoryOf(side, trial);
    g.fillStyle = COLOR.text;
    g.font = '13px sans-serif';
    if (!tr) {
      g.fillText(side.label + ': this trial\u2019s trajectory was not kept', 8, 18);
      out.kept = false;
      return out;
    }
    out.kept = true;
    var j = frameAt(side, tr, T), f = tr.frames[j], c = side.col;
    var x = f[c.x], y = f[c.y];
    var heading = c.heading !== undefined && f[c.heading] !== null ? f[c.heading] : sc.body.heading;
    out.frame = j;
    out.row = f[c.row];
    out.t = f[c.t];
    out.ended = j === tr.frames.length - 1 && f[c.t] < T;
    /* the other sides' paths, then this one's */
    D.sides.forEach(function (other, k) {
      var ot = k === i ? null : trajectoryOf(other, trial);
      if (ot) trail(g, other, ot, frameAt(other, ot, T), tf, COLOR.ghost, 1);
    });
    trail(g, side, tr, j, tf, COLOR.trail, 1.5);
    /* beams: stiffness colours, then pivots */
    var kmin = Infinity, kmax = -Infinity;
    sc.beams.forEach(function (b) { kmin = Math.min(kmin, b.stiffness); kmax = Math.max(kmax, b.stiffness); });
    var tips = sc.beams.map(function (b, n) {
      var th = f[c['theta' + (n + 1)]];
      if (th === null || th === undefined) return null;
      var a = b.rest + b.sign * th;
      return [b.pivot[0] + b.length * Math.cos(a), b.pivot[1] + b.length * Math.sin(a)];
    });
    sc.beams.forEach(function (b, n) {
      if (!tips[n]) return;
      /* a white outline keeps a beam apart from the landscape beneath */
      g.strokeStyle = '#FFFFFF';
      g.lineWidth = 5;
      g.beginPath();
      g.moveTo(px(b.pivot[0]), py(b.pivot[1]));
      g.lineTo(px(tips[n][0]), py(tips[n][1]));
      g.stroke();
      g.strokeStyle = viridis(kmax > kmin ? (b.stiffness - kmin) / (kmax - kmin) : 0.5);
      g.lineWidth = 3;
      g.beginPath();
      g.moveTo(px(b.pivot[0]), py(b.pivot[1]));
      g.lineTo(px(tips[n][0]), py(tips[n][1]));
      g.stroke();
      out.beams++;
      out.tips.push([px(tips[n][0]), py(tips[n][1])]);
    });
    g.fillStyle = COLOR.pivot;
    sc.beams.forEach(function (b) {
      g.beginPath();
      g.arc(px(b.pivot[0]), py(b.pivot[1]), 3, 0, 2 * Math.PI);
      g.fill();
    });
    if (x === null || y === null) {
      g.fillStyle = COLOR.text;
      g.fillText(side.label + ': the state is not finite at t = ' + f[c.t] + ' s', 8, 18);
      return out;
    }
    drawBody(g, sc.body, px(x), py(y), heading, s);
    out.body = [px(x), py(y)];
    out.heading = heading;
    /* contacts: the beam's point nearest the centre (docs/model.md section 3) */
    sc.beams.forEach(function (b, n) {
      var flag = f[c['contact' + (n + 1)]];
      if (!flag || !tips[n]) return;
      var ux = (tips[n][0] - b.pivot[0]) / b.length, uy = (tips[n][1] - b.pivot[1]) / b.length;
      var along = Math.min(b.length, Math.max(0, (x - b.pivot[0]) * ux + (y - b.pivot[1]) * uy));
      var q = [px(b.pivot[0] + along * ux), py(b.pivot[1] + along * uy)];
      g.fillStyle = COLOR.contact;
      g.beginPath();
      if (flag === 2) g.rect(q[0] - 4, q[1] - 4, 8, 8);
      else g.arc(q[0], q[1], 4.5, 0, 2 * Math.PI);
      g.fill();
      out.contacts.push([q[0], q[1], flag, n + 1]);
    });
    /* forces: one body extent per the larger of F_prop and R_m */
    var ref = Math.max(sc.f_prop, sc.rm), perN = ref > 0 ? bodyExtent(sc.body) * s / ref : 0;
    out.propulsion = null;
    out.lateral = null;
    if (sc.f_prop > 0) {
      var ph = sc.along === 'heading' ? heading : Math.PI / 2;
      out.propulsion = [perN * sc.f_prop * Math.cos(ph), -perN * sc.f_prop * Math.sin(ph)];
      arrow(g, px(x), py(y), out.propulsion[0], out.propulsion[1], COLOR.propulsion);
    }
    if (c.f_rand !== undefined && f[c.f_rand] !== null) {
      out.lateral = [perN * f[c.f_rand], 0];
      arrow(g, px(x), py(y), out.lateral[0], out.lateral[1], COLOR.lateral);
    }
    g.fillStyle = COLOR.text;
    g.fillText(side.label + '   t = ' + f[c.t].toFixed(3) + ' s' + (out.ended ? ' (ended)' : ''), 8, 18);
    return out;
  }

  /* ---- playing ----------------------------------------------------------------- */

  var state = { trial: -1, k: 0, tf: null, master: null, masterSide: null, playing: false, T: 0, last: 0 };

  function selectTrial(i) {
    var trial = D.trials[i];
    state.trial = i;
    state.tf = transformOf(trial);
    state.master = null;
    D.sides.forEach(function (side) {
      var tr = trajectoryOf(side, trial);
      if (tr && (!state.master || tr.frames.length > state.master.frames.length)) {
        state.master = tr;
        state.masterSide = side;
      }
    });
    canvases.forEach(function (c) { c.width = state.tf.width; c.height = state.tf.height; });
    slider.max = String(state.master.frames.length - 1);
    select.value = String(i);
  }

  function drawFrame(i, k) {
    i = Math.max(0, Math.min(D.trials.length - 1, Math.floor(Number(i) || 0)));
    if (i !== state.trial) selectTrial(i);
    var n = state.master.frames.length;
    k = Math.max(0, Math.min(n - 1, Math.floor(Number(k) || 0)));
    state.k = k;
    state.T = state.master.frames[k][state.masterSide.col.t];
    return render();
  }

  function render() {
    var trial = D.trials[state.trial], tf = state.tf;
    var drawn = { trial: state.trial, group: trial.group, trial_in_group: trial.trial, k: state.k, t: state.T,
                  scale: tf.scale, ox: tf.ox, oy: tf.oy, width: tf.width, height: tf.height,
                  panels: D.sides.map(function (side, i) { return drawPanel(i, trial, state.T, tf); }) };
    slider.value = String(state.k);
    clock.textContent = 't = ' + state.T.toFixed(3) + ' s of ' +
      state.master.frames[state.master.frames.length - 1][state.masterSide.col.t].toFixed(3) + ' s';
    if (result) result.textContent = JSON.stringify(drawn);
    root.setAttribute('data-state', 'drawn');
    noteErrors();
    return drawn;
  }

  function tick(now) {
    if (!state.playing) return;
    var frames = state.master.frames, ti = state.masterSide.col.t;
    state.T += (now - state.last) / 1000 * Number(speed.value);
    state.last = now;
    var end = frames[frames.length - 1][ti];
    if (state.T >= end) { state.T = end; pause(); }
    state.k = frameAt(state.masterSide, state.master, state.T);
    render();
    if (state.playing) window.requestAnimationFrame(tick);
  }

  function start() {
    var frames = state.master.frames;
    if (state.k >= frames.length - 1) drawFrame(state.trial, 0);
    state.playing = true;
    play.textContent = 'Pause';
    state.last = window.performance.now();
    window.requestAnimationFrame(tick);
  }

  function pause() {
    state.playing = false;
    play.textContent = 'Play';
  }

  play.addEventListener('click', function () { if (state.playing) pause(); else start(); });
  slider.addEventListener('input', function () { pause(); drawFrame(state.trial, Number(slider.value)); });
  select.addEventListener('change', function () { pause(); drawFrame(Number(select.value), 0); });

  window.beamsimViewer = { drawFrame: drawFrame, play: start, pause: pause, data: D };

  var asked = /[#&]frame=(\d+),(\d+)/.exec(window.location.hash);
  if (asked) drawFrame(Number(asked[1]), Number(asked[2]));
  else drawFrame(0, 0);
})();
