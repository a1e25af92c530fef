// softsight serve: the page. Frames come as JPEG (binary WebSocket messages), each frame's
// result as JSON (its CSV row); the overlay, the timeline and the plots are drawn here from
// the results. Everything the page asks of the run is a small JSON message the server checks.
'use strict';

const $ = (id) => document.getElementById(id);
const view = $('view'), view2 = $('view2'), timeline = $('timeline'), plot = $('plot');
const COLOURS = ['#ff5050', '#50a0ff', '#50e070', '#ffd040', '#e070ff', '#40e0e0', '#ffa040', '#c0c0c0', '#ff80c0'];
const PLOTS = [['angle_deg', 'angle [deg]'], ['radius', 'radius'], ['tip_disp', 'bending distance'], ['arc_length', 'arc length']];

// State, also read by the browser test (tests/browser/serve_browser_test.py).
const S = window.softsight = {
  hello: null, status: null, controls: false, pages: 0,
  framesShown: 0, results: 0, shownFrame: -1, shownPosition: -1,
  latencies: [], sameClockLatencies: [], messages: [], errors: [], closed: null,
  clockOffsetMs: 0, bestRttMs: Infinity,
};
const rows = new Map();      // frame -> its row (the CSV's columns)
let sortedFrames = null;     // Cache of rows' keys in order, for the plots.
let image = null;            // The ImageBitmap on screen.
let image2 = null;           // The second video's (serve --compare), at the same position.
let imageFrame = -1;
let scale = 1;               // Canvas pixels per image pixel, the whole image in view.
// Zoom and pan: `zoom` times the fitted size, the view's top left at image point (ox, oy)
// (pixel edges: the image spans 0..width). k = scale * zoom: CSS pixels per image pixel.
let zoom = 1, ox = 0, oy = 0;
const MAX_ZOOM = 16;
let pending = null, decoding = false;  // Newest-wins decoding of frames.
let ws = null;

// Waiters on the page's state (the browser test's waits, so it need not poll): each predicate
// is checked at once, after every message handled and after every redraw of the picture.
const waiters = new Set();
function changed() { for (const check of [...waiters]) check(); }
S.changed = changed;
// A promise of the predicate's first true value, or of null after `timeoutMs`.
S.when = (predicate, timeoutMs) => new Promise((resolve) => {
  let timer = null;
  const check = () => {
    let value = false;
    try { value = predicate(); } catch (e) { value = false; }
    if (!value) return;
    waiters.delete(check); clearTimeout(timer); resolve(value);
  };
  waiters.add(check);
  timer = setTimeout(() => { waiters.delete(check); resolve(null); }, timeoutMs);
  check();
});

function send(message) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(message));
}

function log(text, error) {
  const li = document.createElement('li');
  li.textContent = text;
  if (error) li.className = 'error';
  $('log').prepend(li);
  while ($('log').children.length > 100) $('log').lastChild.remove();
  (error ? S.errors : S.messages).push(text);
}

function connect() {
  const token = new URLSearchParams(location.search).get('token');
  const url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws' +
              (token ? '?token=' + encodeURIComponent(token) : '');
  ws = new WebSocket(url);
  ws.binaryType = 'arraybuffer';
  ws.onmessage = (event) => {
    if (typeof event.data === 'string') onText(JSON.parse(event.data));
    else onFrame(event.data);
    changed();
  };
  ws.onclose = (event) => {
    S.closed = event.code;
    $('role').textContent = 'disconnected';
    $('role').className = 'badge';
    log('connection closed (' + event.code + (event.reason ? ': ' + event.reason : '') + ')', true);
    changed();
  };
  // A few pings at once (the offset comes from the fastest round trip), then one every 2 s.
  ws.onopen = () => {
    for (let i = 0; i < 5; i++) setTimeout(ping, 100 * i);
    setInterval(ping, 2000);
  };
}

function ping() { send({type: 'ping', t: Date.now()}); }

function onText(m) {
  switch (m.type) {
    case 'hello': onHello(m); break;
    case 'role':
      S.controls = m.controls; S.pages = m.pages;
      $('role').textContent = m.controls ? 'you control the run' : 'read-only: another page controls the run';
      $('role').className = 'badge ' + (m.controls ? 'controls' : 'readonly');
      $('take').hidden = m.controls;
      if (S.onRole) S.onRole();
      break;
    case 'result':
      rows.set(m.frame, Object.assign({_position: m.position}, m.row));
      sortedFrames = null;
      S.results++;
      if (m.edit || m.frame === imageFrame) { drawView(); showReadout(m.frame); }
      break;
    case 'status': onStatus(m); break;
    case 'mask': S.mask = m; if (m.frame === imageFrame) drawView(); break;
    case 'configs': {
      S.configs = m.names;
      const select = $('configs'), chosen = select.value;
      select.innerHTML = '';
      for (const name of m.names) select.add(new Option(name, name));
      if (m.names.includes(chosen)) select.value = chosen;
      break;
    }
    case 'rig': if (S.onRig) S.onRig(m); break;  // rig.js
    case 'message': log(m.message, false); break;
    case 'error': log(m.message, true); break;
    case 'pong': {
      const now = Date.now(), rtt = now - m.t;
      if (rtt <= S.bestRttMs) { S.bestRttMs = rtt; S.clockOffsetMs = m.server_ms - (m.t + now) / 2; }
      break;
    }
  }
}

function onHello(m) {
  S.hello = m;
  $('source').textContent = m.source + (m.live ? ' (camera)' : '');
  const body = $('markers').tBodies[0];
  body.innerHTML = '';
  m.markers.forEach((name, i) => {
    const tr = body.insertRow();
    tr.innerHTML = '<td><span class="swatch"></span></td><td></td><td></td><td></td><td></td>';
    tr.cells[0].firstChild.style.background = COLOURS[i % COLOURS.length];
    tr.cells[1].textContent = (i + 1) + ' ' + name;
    tr.onclick = () => send({type: 'marker', index: i});
  });
  for (const id of ['back', 'fwd']) $(id).disabled = !m.seekable;
  view2.hidden = !m.compare;  // A second video beside the first (serve --compare).
  if (m.compare) view2.title = m.compare + ' at the same position, zoomed and panned with the first';
  if (S.onRigHello) S.onRigHello(m.rig);  // rig.js: the control panel, when there is a rig.
  send({type: 'list_configs'});
}

function onStatus(m) {
  const rescaled = !S.status || S.status.mm_per_px !== m.mm_per_px;
  S.status = m;
  if (rescaled) { drawView(); showReadout(imageFrame); schedulePlot(); }
  const lat = recentLatency();
  $('status').textContent =
      (m.paused ? 'PAUSED  ' : '') + (m.ended ? 'END  ' : '') + (m.recording ? 'REC  ' : '') +
      'fps ' + m.fps.toFixed(1) + '   dropped ' + m.dropped + '   skipped for this page ' + m.skipped +
      '   capture->result ' + m.latency_ms.toFixed(1) + ' ms   capture->page ' +
      (lat === null ? '-' : lat.toFixed(0) + ' ms') + '   pages ' + m.pages +
      (m.mm_per_px ? '   scale ' + m.mm_per_px.toFixed(4) + ' mm/px' : '');
  $('play').textContent = m.paused || m.ended ? 'play' : 'pause';
  $('speed').value = String(+m.speed.toFixed(2));
  $('record').textContent = m.recording ? 'stop recording' : 'record';
  const names = S.hello ? S.hello.markers : [];
  $('active').textContent = 'active: ' + (names[m.active] || '-') + ' (' + m.method + ')  hsv h ' +
      m.hsv[0] + '-' + m.hsv[1] + ' s ' + m.hsv[2] + '-' + m.hsv[3] + ' v ' + m.hsv[4] + '-' + m.hsv[5] +
      (m.undo ? '   undo: ' + m.undo : '');
  [...$('markers').tBodies[0].rows].forEach((tr, i) => tr.classList.toggle('active', i === m.active));
  showRanges(m);
  $('where').textContent = m.length > 0 ? 'frame ' + m.position + ' / ' + (m.length - 1) : '';
  drawTimeline();
}

function recentLatency() {
  const l = S.latencies.slice(-30).sort((a, b) => a - b);
  return l.length ? l[Math.floor(l.length / 2)] : null;
}

// Binary: [header length, 4 bytes LE][header JSON][JPEG][the second video's JPEG, when the
// header has compare_bytes].
function onFrame(buffer) {
  const size = new DataView(buffer).getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, size)));
  const second = header.compare_bytes || 0, end = buffer.byteLength - second;
  pending = {header, blob: new Blob([new Uint8Array(buffer, 4 + size, end - 4 - size)], {type: 'image/jpeg'}),
             second: second ? new Blob([new Uint8Array(buffer, end, second)], {type: 'image/jpeg'}) : null};
  if (!decoding) decodeNext();
}

async function decodeNext() {
  decoding = true;
  while (pending) {
    const {header, blob, second} = pending;
    pending = null;
    try {
      const bitmap = await createImageBitmap(blob);
      if (second) {
        const bitmap2 = await createImageBitmap(second);
        if (image2) image2.close();
        image2 = bitmap2;
        S.compareVideoFrame = header.compare_frame;
      }
      if (image) image.close();
      image = bitmap;
      imageFrame = header.frame;
      S.shownMask = header.mask;
      S.shownFrame = header.frame;
      S.shownPosition = header.position;
      drawView();
      showReadout(header.frame);
      S.framesShown++;
      changed();  // (drawView ran before the count and the latency.)
      // Capture to the picture on the page, in the server's clock (offset from the pings).
      if (!header.replay) {
        S.latencies.push(Date.now() + S.clockOffsetMs - header.captured_ms);
        // Without the offset: exact when the page runs on the server's computer (one clock).
        S.sameClockLatencies.push(Date.now() - header.captured_ms);
      }
      if (S.latencies.length > 2000) { S.latencies.splice(0, 1000); S.sameClockLatencies.splice(0, 1000); }
    } catch (e) {
      log('a frame did not decode: ' + e, true);
    }
  }
  decoding = false;
  schedulePlot();
}

function fmt(v, digits) { return v === null || v === undefined ? '-' : Number(v).toFixed(digits); }

// The run's lengths in mm: the rows' own _mm columns, or (rows from before a scale was set
// on a page) their px times the config's scale. True once any is known.
function inMm() {
  if (S.status && S.status.mm_per_px) return true;
  const last = sortedFrames && sortedFrames.length ? rows.get(sortedFrames[sortedFrames.length - 1]) : null;
  return !!last && last.radius_mm !== undefined;
}
// A length measure of `row` (radius, arc_length, tip_disp, chord), in mm when inMm().
function length_(row, key) {
  const mm = row[key + '_mm'];
  if (mm !== undefined) return mm;
  const px = row[key + '_px'], scale = S.status && S.status.mm_per_px;
  return scale && px !== null && px !== undefined ? px * scale : px;
}
S.lengthOf = (frame, key) => { const row = rows.get(frame); return row ? length_(row, key) : null; };

function showReadout(frame) {
  const row = rows.get(frame);
  if (!row || !S.hello) return;
  const u = row.radius_mm !== undefined || (S.status && S.status.mm_per_px) ? 'mm' : 'px';
  $('readout').textContent = 'frame ' + frame + '  t ' + fmt(row.time_s, 3) + ' s   angle ' +
      fmt(row.angle_deg, 2) + ' deg   R ' + fmt(length_(row, 'radius'), 1) + ' ' + u + '   L ' +
      fmt(length_(row, 'arc_length'), 1) + ' ' + u + '   tip ' + fmt(length_(row, 'tip_disp'), 1) + ' ' + u;
  const body = $('markers').tBodies[0];
  S.hello.markers.forEach((name, i) => {
    const tr = body.rows[i];
    if (!tr) return;
    const found = row[name + '_found'] === 1;
    tr.cells[2].textContent = found ? fmt(row[name + '_x'], 1) : '';
    tr.cells[3].textContent = found ? fmt(row[name + '_y'], 1) : '';
    tr.cells[4].textContent = row[name + '_status'] || (found ? 'found' : 'not found');
  });
}

// ---- The picture and its overlay --------------------------------------------------------
function fitView() {
  if (!image) return;
  // At most the image's own size (the plots stay on screen under it), less on a narrow window.
  // With a second video beside it, each takes half.
  const room = window.innerWidth - 400;
  const width = Math.min(image.width, Math.max(320, view2.hidden ? room : room / 2 - 6));
  scale = width / image.width;
  const ratio = window.devicePixelRatio || 1;
  const w = Math.round(image.width * scale), h = Math.round(image.height * scale);
  if (view.width !== Math.round(w * ratio) || view.style.width !== w + 'px') {
    // Canvas pixels at the screen's own density: the overlay stays crisp.
    for (const v of [view, view2]) {
      v.width = Math.round(w * ratio); v.height = Math.round(h * ratio);
      v.style.width = w + 'px'; v.style.height = h + 'px';
    }
    for (const c of [timeline, plot]) {
      c.width = Math.round(w * ratio); c.style.width = w + 'px';
      c.height = Math.round((c === plot ? 240 : 28) * ratio); c.style.height = (c === plot ? 240 : 28) + 'px';
    }
  }
}

// Draws on `c` in the CSS pixels it is shown at, whatever its backing store's size.
function cssContext(c) {
  const ctx = c.getContext('2d');
  if (c.clientWidth > 0 && c.clientHeight > 0) {
    ctx.setTransform(c.width / c.clientWidth, 0, 0, c.height / c.clientHeight, 0, 0);
  }
  return ctx;
}

// Pixel centres are at integers: image pixel (x, y) is at ((x + 0.5 - ox) k, (y + 0.5 - oy) k)
// in the view, whatever the zoom: every click and every overlay goes through these two.
const viewScale = () => scale * zoom;
const toView = (x, y) => [(x + 0.5 - ox) * viewScale(), (y + 0.5 - oy) * viewScale()];
const toImage = (vx, vy) => [vx / viewScale() + ox - 0.5, vy / viewScale() + oy - 0.5];

// Keeps the view inside the image (no empty margin at any zoom).
function clampPan() {
  if (!image) return;
  ox = Math.min(Math.max(ox, 0), image.width - image.width / zoom);
  oy = Math.min(Math.max(oy, 0), image.height - image.height / zoom);
}
// Zooms by `factor` about the view point (vx, vy) (CSS pixels): the image point under it stays.
function zoomAt(vx, vy, factor) {
  if (!image) return;
  const ex = vx / viewScale() + ox, ey = vy / viewScale() + oy;  // Pixel-edge coordinates.
  zoom = Math.min(MAX_ZOOM, Math.max(1, zoom * factor));
  ox = ex - vx / viewScale(); oy = ey - vy / viewScale();
  clampPan();
  showZoom();
  drawView();
}
function resetZoom() { zoom = 1; ox = 0; oy = 0; showZoom(); drawView(); }
function showZoom() {
  $('zoomtext').textContent = zoom > 1.001 ? zoom.toFixed(zoom < 10 ? 2 : 1) + 'x' : '';
  $('zoomreset').disabled = zoom <= 1.001;
}

function markerPoint(row, name) {
  return row && row[name + '_found'] === 1 ? [row[name + '_x'], row[name + '_y']] : null;
}

function drawView() {
  if (!image) return;
  fitView();
  const ctx = cssContext(view);
  clampPan();
  // Zoomed in, the pixels are shown as they are (square), not blurred into each other.
  ctx.imageSmoothingEnabled = zoom < 2;
  ctx.drawImage(image, ox, oy, image.width / zoom, image.height / zoom, 0, 0, image.width * scale, image.height * scale);
  const row = rows.get(imageFrame);
  if (S.shownMask) drawCandidates(ctx);
  else if (row && S.hello) drawOverlay(ctx, row);
  if (row && S.hello && S.drawTools) S.drawTools(ctx, row, toView, COLOURS, viewScale());
  // The second video at the same zoom and pan; another run's CSV (compare.js) drawn over it,
  // or over the first without one.
  let ctx2 = null;
  if (image2 && !view2.hidden) {
    ctx2 = cssContext(view2);
    ctx2.imageSmoothingEnabled = zoom < 2;
    ctx2.drawImage(image2, ox * image2.width / image.width, oy * image2.height / image.height,
                   image2.width / zoom, image2.height / zoom, 0, 0, image.width * scale, image.height * scale);
  }
  if (S.drawCompare) S.drawCompare(ctx2 || ctx, row, toView, COLOURS);  // compare.js: another run.
  if (drag && drag.moved) {
    ctx.strokeStyle = '#ffff00'; ctx.setLineDash([4, 3]); ctx.lineWidth = 1.5;
    ctx.strokeRect(drag.x0, drag.y0, drag.x1 - drag.x0, drag.y1 - drag.y0);
    ctx.setLineDash([]);
  }
  changed();
}

function drawOverlay(ctx, row) {
  const [b, m, t] = S.hello.triple.map((name) => markerPoint(row, name));
  if (b && m && t) {
    ctx.strokeStyle = 'rgba(255,255,255,0.8)'; ctx.lineWidth = 1.5;
    ctx.beginPath();
    for (const [i, p] of [b, m, t].entries()) {
      const [x, y] = toView(p[0], p[1]);
      i ? ctx.lineTo(x, y) : ctx.moveTo(x, y);
    }
    ctx.stroke();
    drawArc(ctx, b, m, t);
  }
  S.hello.markers.forEach((name, i) => {
    const p = markerPoint(row, name);
    if (!p) return;
    const [x, y] = toView(p[0], p[1]);
    ctx.strokeStyle = COLOURS[i % COLOURS.length]; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.arc(x, y, 10, 0, 2 * Math.PI); ctx.stroke();
    ctx.fillStyle = '#fff'; ctx.font = '12px sans-serif';
    ctx.fillText(name, x + 13, y - 8);
  });
}

// The mask view: each candidate blob of the active marker, green chosen, yellow fitting, red
// rejected, with its verdict and what it was judged on; the search region dashed.
const VERDICT_COLOURS = {chosen: '#40ff40', fits: '#ffd040'};
function drawCandidates(ctx) {
  const m = S.mask;
  if (!m || m.frame !== imageFrame) return;
  ctx.font = '11px sans-serif'; ctx.lineWidth = 1.5;
  if (m.region) {
    const [x, y] = toView(m.region[0] - 0.5, m.region[1] - 0.5);
    ctx.strokeStyle = '#80c0ff'; ctx.setLineDash([4, 3]);
    ctx.strokeRect(x, y, m.region[2] * viewScale(), m.region[3] * viewScale());
    ctx.setLineDash([]); ctx.fillStyle = '#80c0ff'; ctx.fillText('searched', x + 3, y + m.region[3] * viewScale() - 4);
  }
  for (const c of m.candidates) {
    const [x, y] = toView(c.x, c.y);
    const r = Math.max(4, Math.sqrt(c.area / Math.PI) * viewScale() + 3);
    ctx.strokeStyle = ctx.fillStyle = VERDICT_COLOURS[c.verdict] || '#ff5050';
    ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI); ctx.stroke();
    ctx.fillText(c.verdict + ' ' + c.area.toFixed(0) + ' px\u00b2 circ ' + c.circularity.toFixed(2) +
                 ' misfit ' + c.misfit.toFixed(2), x + r + 3, y + 4);
  }
  S.candidatesDrawn = m.candidates.length;
}

// ---- The HSV sliders of the active marker ---------------------------------------------------
let sliding = -1, slideSent = 0;
function showRanges(m) {
  for (let i = 0; i < 6; i++) if (i !== sliding) $('hsv' + i).value = m.hsv[i];
  for (let k = 0; k < 3; k++) $('hsvt' + k).textContent = m.hsv[2 * k] + '-' + m.hsv[2 * k + 1] + (k === 0 && m.hsv[0] > m.hsv[1] ? ' (wraps through red)' : '');
  $('maskview').checked = m.mask_view;
}
for (let i = 0; i < 6; i++) {
  const slider = $('hsv' + i);
  const sendValue = () => send({type: 'hsv', index: i, value: Number(slider.value)});
  // While dragged: at most ~12 ranges a second (each re-tracks the frame on screen).
  slider.addEventListener('input', () => {
    sliding = i;
    if (Date.now() - slideSent > 80) { slideSent = Date.now(); sendValue(); }
  });
  slider.addEventListener('change', () => { sliding = -1; sendValue(); });
}
$('maskview').onchange = () => send({type: 'mask_view', on: $('maskview').checked});

// The circle through base, middle and tip, drawn from base to tip through the middle.
function drawArc(ctx, b, m, t) {
  const d = 2 * (b[0] * (m[1] - t[1]) + m[0] * (t[1] - b[1]) + t[0] * (b[1] - m[1]));
  if (Math.abs(d) < 1e-6) return;
  const sq = (p) => p[0] * p[0] + p[1] * p[1];
  const cx = (sq(b) * (m[1] - t[1]) + sq(m) * (t[1] - b[1]) + sq(t) * (b[1] - m[1])) / d;
  const cy = (sq(b) * (t[0] - m[0]) + sq(m) * (b[0] - t[0]) + sq(t) * (m[0] - b[0])) / d;
  const r = Math.hypot(b[0] - cx, b[1] - cy);
  if (r > 1e4) return;
  const a = (p) => Math.atan2(p[1] - cy, p[0] - cx);
  const ab = a(b), am = a(m), at = a(t);
  const norm = (x) => ((x % (2 * Math.PI)) + 2 * Math.PI) % (2 * Math.PI);
  const ccw = norm(am - ab) < norm(at - ab);  // The middle lies on the way from base to tip.
  const [vx, vy] = toView(cx, cy);
  ctx.strokeStyle = 'rgba(255,220,0,0.9)'; ctx.lineWidth = 1.5;
  ctx.beginPath(); ctx.arc(vx, vy, r * viewScale(), ab, at, !ccw); ctx.stroke();
}

// ---- Mouse on the picture: click picks a colour, a drag reselects ---------------------------
// The wheel zooms about the pointer, a right (or middle) drag pans, "whole image" (z) resets.
let drag = null, panning = null, movingPoint = false;
// The pointer in the view's CSS pixels (k per image pixel), from where it is on screen.
// (`on`: the second video's canvas, the same size and mapping, for its wheel and pan.)
function viewPoint(event, on = view) {
  const rect = on.getBoundingClientRect();
  return [(event.clientX - rect.left) * on.clientWidth / rect.width,
          (event.clientY - rect.top) * on.clientHeight / rect.height];
}
let pointer = null;  // The last view point the mouse was at (the keys zoom about it).
// The wheel and the right or middle drag on either picture zoom and pan both.
for (const canvas of [view, view2]) {
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const [x, y] = viewPoint(e, canvas);
    // One notch (100 px of deltaY) is a factor of sqrt(2); a touchpad's small steps zoom smoothly.
    const delta = e.deltaMode === 1 ? e.deltaY * 33 : e.deltaY;
    zoomAt(x, y, Math.pow(2, -delta / 200));
  }, {passive: false});
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
}
view2.addEventListener('mousedown', (e) => {
  if (e.button === 0) return;
  e.preventDefault();
  const [x, y] = viewPoint(e);  // Only the moves count: in the first picture's pixels alike.
  panning = {x, y, ox, oy};
});
view.addEventListener('mousedown', (e) => {
  const [x, y] = viewPoint(e);
  if (e.button !== 0) {
    e.preventDefault();
    panning = {x, y, ox, oy};
    return;
  }
  // A press on a fixed point of an angle or distance tool drags it (analysis.js).
  if (S.toolGrab && S.toolGrab(...toImage(x, y), viewScale())) { movingPoint = true; return; }
  drag = {x0: x, y0: y, x1: x, y1: y, moved: false};
});
view.addEventListener('mouseleave', () => { pointer = null; });
window.addEventListener('mousemove', (e) => {
  if (movingPoint && image) {
    const [x, y] = toImage(...viewPoint(e));
    S.toolMove(Math.min(Math.max(x, 0), image.width - 1), Math.min(Math.max(y, 0), image.height - 1));
    return;
  }
  if (!panning) return;
  const [x, y] = viewPoint(e);
  ox = panning.ox - (x - panning.x) / viewScale();
  oy = panning.oy - (y - panning.y) / viewScale();
  clampPan();
  drawView();
});
view.addEventListener('mousemove', (e) => {
  pointer = viewPoint(e);
  if (!drag) {
    view.style.cursor = movingPoint || (S.toolNear && S.toolNear(...toImage(...pointer), viewScale())) ? 'move' : '';
    return;
  }
  [drag.x1, drag.y1] = viewPoint(e);
  drag.moved = drag.moved || Math.hypot(drag.x1 - drag.x0, drag.y1 - drag.y0) > 4;
  if (drag.moved) drawView();
});
window.addEventListener('mouseup', (e) => {
  if (panning) { panning = null; return; }
  if (movingPoint) { movingPoint = false; S.toolRelease(); schedulePlot(); return; }
  if (!drag || !image) { drag = null; return; }
  const d = drag;
  drag = null;
  const clamp = (v, hi) => Math.min(Math.max(v, 0), hi);
  if (!d.moved) {
    const [x, y] = toImage(d.x0, d.y0);
    // A point of an analysis tool, or a click on a trail (analysis.js), before a colour pick.
    if (S.toolClick && S.toolClick(x, y, rows.get(imageFrame), viewScale())) { drawView(); schedulePlot(); return; }
    const at = {x: clamp(x, image.width - 1), y: clamp(y, image.height - 1)};
    // In the mask view (as the window's): a click adds the colours there to the active
    // marker's ranges, a shift-click takes them out; elsewhere a click picks a colour afresh.
    if (S.status && S.status.mask_view) send(Object.assign({type: 'range', grow: !e.shiftKey}, at));
    else send(Object.assign({type: 'pick'}, at));
    return;
  }
  // Whole pixels covered by the box (pixel edges: the view's point plus half a pixel).
  const [ax, ay] = toImage(Math.min(d.x0, d.x1), Math.min(d.y0, d.y1));
  const [bx, by] = toImage(Math.max(d.x0, d.x1), Math.max(d.y0, d.y1));
  const x0 = clamp(Math.round(ax + 0.5), image.width - 1), y0 = clamp(Math.round(ay + 0.5), image.height - 1);
  const x1 = clamp(Math.round(bx + 0.5), image.width), y1 = clamp(Math.round(by + 0.5), image.height);
  send({type: 'select', x: x0, y: y0, w: x1 - x0, h: y1 - y0});
  drawView();
});

// ---- Transport ------------------------------------------------------------------------------
$('play').onclick = () => send({type: S.status && (S.status.paused || S.status.ended) ? 'play' : 'pause'});
$('back').onclick = () => send({type: 'step', delta: -1});
$('fwd').onclick = () => send({type: 'step', delta: 1});
$('speed').onchange = () => send({type: 'speed', value: Number($('speed').value)});
$('method').onclick = () => send({type: 'method'});
$('undo').onclick = () => send({type: 'undo'});
$('reset').onclick = () => send({type: 'reset_reference'});
$('record').onclick = () => send({type: 'record'});
$('save').onclick = () => send({type: 'save', name: $('savename').value});
$('load').onclick = () => { if ($('configs').value) send({type: 'load', name: $('configs').value}); };
$('configs').addEventListener('focus', () => send({type: 'list_configs'}));
$('take').onclick = () => send({type: 'take_control'});
$('zoomreset').onclick = resetZoom;

// Files made in the page, from what it has: the picture with its overlay, and the results.
function download(name, blob) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
$('png').onclick = () => view.toBlob((blob) => download('softsight-frame-' + imageFrame + '.png', blob));
// The CSV's own columns (the rows are its rows), in frame order; empty fields where absent.
S.csvText = () => {
  const frames = [...rows.keys()].sort((a, b) => a - b);
  if (!frames.length) return '';
  // The columns of the row that has most (a scale set on a page adds the _mm ones: rows from
  // before it leave them empty).
  let widest = rows.get(frames[0]);
  for (const f of frames) if (Object.keys(rows.get(f)).length > Object.keys(widest).length) widest = rows.get(f);
  const columns = Object.keys(widest).filter((c) => c !== '_position');
  const tools = S.toolColumns ? S.toolColumns() : [];  // The analysis tools' values after them.
  const field = (v) => (v === null || v === undefined ? '' : String(v));
  const line = (row) => columns.map((c) => field(row[c])).concat(tools.map(([, value]) => field(value(row)))).join(',');
  return [columns.concat(tools.map(([name]) => name)).join(',')].concat(frames.map((f) => line(rows.get(f)))).join('\n') + '\n';
};
$('csv').onclick = () => download('softsight-page.csv', new Blob([S.csvText()], {type: 'text/csv'}));

function length() { return S.status && S.status.length > 0 ? S.status.length : 0; }
// The timeline's x (CSS pixels) of a position, and back: positions spread over the whole width.
function positionX(p) { return length() > 1 ? p / (length() - 1) * (timeline.clientWidth - 1) : 0; }
function positionAt(x) {
  return Math.min(length() - 1, Math.max(0, Math.round(x / (timeline.clientWidth - 1) * (length() - 1))));
}
S.positionX = positionX;
let scrubbing = false, lastScrub = 0;
function scrub(e, force) {
  if (!length()) return;
  const x = e.clientX - timeline.getBoundingClientRect().left;
  const now = Date.now();
  if (!force && now - lastScrub < 100) return;
  lastScrub = now;
  send({type: 'seek', position: positionAt(x)});
}
timeline.addEventListener('mousedown', (e) => { scrubbing = true; scrub(e, true); });
timeline.addEventListener('mousemove', (e) => { if (scrubbing) scrub(e, false); });
timeline.addEventListener('mouseup', (e) => { if (scrubbing) scrub(e, true); scrubbing = false; });

function drawTimeline() {
  const ctx = cssContext(timeline);
  const w = timeline.clientWidth, h = timeline.clientHeight;
  ctx.fillStyle = '#222'; ctx.fillRect(0, 0, w, h);
  if (!length() || !S.hello) return;
  ctx.fillStyle = '#ff5050';
  for (const [, row] of rows) {
    if (row._position < 0) continue;
    if (S.hello.markers.some((name) => row[name + '_found'] !== 1)) ctx.fillRect(positionX(row._position), h - 8, 1, 8);
  }
  ctx.fillStyle = '#fff';
  ctx.fillRect(positionX(S.status.position) - 1, 0, 3, h);
}

document.addEventListener('keydown', (e) => {
  if (e.target.tagName === 'INPUT' || e.target.tagName === 'TEXTAREA') return;
  const keys = {' ': () => $('play').onclick(), '.': () => send({type: 'step', delta: 1}),
    ',': () => send({type: 'step', delta: -1}), 'm': () => send({type: 'method'}),
    'u': () => send({type: 'undo'}), 'b': () => send({type: 'reset_reference'}),
    'r': () => send({type: 'record'}),
    '+': () => zoomKey(Math.SQRT2), '=': () => zoomKey(Math.SQRT2), '-': () => zoomKey(Math.SQRT1_2),
    'z': resetZoom,
    'v': () => send({type: 'mask_view', on: !(S.status && S.status.mask_view)}),
    ']': () => seekBy(1), '[': () => seekBy(-1), 'ArrowRight': () => seekBy(1), 'ArrowLeft': () => seekBy(-1),
    'Home': () => send({type: 'seek', position: 0}), 'End': () => length() && send({type: 'seek', position: length() - 1})};
  if (keys[e.key]) { keys[e.key](); e.preventDefault(); return; }
  if (e.key >= '1' && e.key <= '9') send({type: 'marker', index: Number(e.key) - 1});
});
// The keys zoom about the pointer when it is on the picture, else about the picture's centre.
function zoomKey(factor) {
  const [x, y] = pointer || [view.clientWidth / 2, view.clientHeight / 2];
  zoomAt(x, y, factor);
}
function seekBy(seconds) {
  if (!S.status || !length()) return;
  const fps = S.hello.fps || 30;
  send({type: 'seek', position: Math.min(length() - 1, Math.max(0, S.status.position + Math.round(seconds * fps)))});
}

// ---- Plots of the run against time, with the cursor at the frame on screen -------------------
let plotQueued = false, plotDrawn = 0;
function schedulePlot() {
  if (plotQueued) return;
  plotQueued = true;
  // At most ~8 redraws a second: a long run has many points, the picture comes first.
  setTimeout(() => { plotQueued = false; drawPlot(); }, Math.max(0, 120 - (Date.now() - plotDrawn)));
}

function series(row, key) {
  if (key === 'angle_deg') return row.angle_deg;
  if (key.startsWith('tool:')) return S.toolSeries(key, row);
  return length_(row, key);
}

function drawPlot() {
  plotDrawn = Date.now();
  const ctx = cssContext(plot);
  const w = plot.clientWidth, h = plot.clientHeight;
  ctx.fillStyle = '#111'; ctx.fillRect(0, 0, w, h);
  if (!sortedFrames) sortedFrames = [...rows.keys()].sort((a, b) => a - b);
  if (sortedFrames.length < 1) return;
  const times = sortedFrames.map((f) => rows.get(f).time_s);
  // A file's whole run, under its timeline; a camera's, from the first result received.
  const whole = length() > 1 && S.hello.fps > 0;
  const t0 = whole ? 0 : times[0];
  const t1 = whole ? (length() - 1) / S.hello.fps : Math.max(times[times.length - 1], t0 + 1e-3);
  const lanes = PLOTS.concat(S.toolLanes ? S.toolLanes() : []);  // An analysis tool's lane each.
  const laneH = h / lanes.length;
  const x = (t) => 40 + (t - t0) / (t1 - t0) * (w - 50);
  let compared = 0;  // Points of another run drawn (compare.js).
  lanes.forEach(([key, label], lane) => {
    const values = sortedFrames.map((f) => series(rows.get(f), key));
    const finite = values.filter((v) => v !== null && v !== undefined);
    const top = lane * laneH;
    ctx.fillStyle = '#aaa'; ctx.font = '11px sans-serif';
    const own = key === 'angle_deg' || key.startsWith('tool:');  // Their labels carry the unit.
    ctx.fillText(label + (own ? '' : inMm() ? ' [mm]' : ' [px]'), 44, top + 12);
    ctx.strokeStyle = '#333'; ctx.strokeRect(40, top + 2, w - 50, laneH - 4);
    if (!finite.length) return;
    // The 2nd to 98th percentile: a near-straight actuator's radius (tens of thousands of px
    // for a frame or two) does not flatten the rest of the run; beyond, the curve is clipped.
    const sorted = finite.slice().sort((a, b) => a - b);
    let lo = sorted[Math.floor(0.02 * (sorted.length - 1))], hi = sorted[Math.ceil(0.98 * (sorted.length - 1))];
    // At least one unit tall: a constant arc length's rounding is not drawn as a signal.
    if (hi - lo < 1) { const mid = (hi + lo) / 2; lo = mid - 0.5; hi = mid + 0.5; }
    const y = (v) => top + laneH - 4 - (Math.min(Math.max(v, lo), hi) - lo) / (hi - lo) * (laneH - 20);
    ctx.fillText(hi.toFixed(1), 2, top + 14); ctx.fillText(lo.toFixed(1), 2, top + laneH - 4);
    ctx.strokeStyle = ctx.fillStyle = COLOURS[lane]; ctx.lineWidth = 1.2; ctx.beginPath();
    let drawing = false;
    values.forEach((v, i) => {
      // A gap where the value is absent (a marker not found) or frames were not received (a
      // seek jumped over them), never a line through it.
      if (v === null || v === undefined) { drawing = false; return; }
      // (A camera's dropped frames are no gap: its frames come as they can.)
      if (i > 0 && S.hello.seekable && sortedFrames[i] - sortedFrames[i - 1] > 1) drawing = false;
      if (!drawing) ctx.fillRect(x(times[i]) - 1, y(v) - 1, 3, 3);  // A lone point shows too.
      drawing ? ctx.lineTo(x(times[i]), y(v)) : ctx.moveTo(x(times[i]), y(v));
      drawing = true;
    });
    ctx.stroke();
    if (S.drawCompareLane) compared += S.drawCompareLane(ctx, key, x, y, series, t0, t1);
  });
  S.comparePlotted = compared;
  const shown = rows.get(imageFrame);
  if (shown) { ctx.fillStyle = '#fff'; ctx.fillRect(x(shown.time_s), 0, 1, h); }
  plot._t0 = t0; plot._t1 = t1;
  changed();
}
plot.addEventListener('click', (e) => {
  if (!length() || !S.hello || plot._t0 === undefined) return;
  const w = plot.clientWidth;
  const t = plot._t0 + (e.clientX - plot.getBoundingClientRect().left - 40) / (w - 50) * (plot._t1 - plot._t0);
  let best = null;
  for (const [, row] of rows) {
    if (row._position >= 0 && (best === null || Math.abs(row.time_s - t) < Math.abs(best.time_s - t))) best = row;
  }
  if (best) send({type: 'seek', position: best._position});
});

// For the browser test: where an image pixel is on the screen, and a raw message to send.
// Where image pixel (x, y) is on the screen, from the picture's place and size alone.
S.clientPoint = (x, y) => {
  const r = view.getBoundingClientRect();
  const [vx, vy] = toView(x, y);
  return [r.left + vx * r.width / view.clientWidth, r.top + vy * r.height / view.clientHeight];
};
// The image point (pixel centres at integers) under a point of the screen, and the zoom.
S.imagePoint = (clientX, clientY) => toImage(...viewPoint({clientX, clientY}));
S.zoom = () => ({zoom, ox, oy, k: viewScale()});
S.sendRaw = (text) => ws.send(text);
S.send = send;
S.log = log;
S.row = (frame) => rows.get(frame) || null;
// Every row received, in frame order (analysis.js: trails, the run's scale).
let rowsInOrder = null;  // Rebuilt only when a row came since (sortedFrames reset).
S.rowsIn = () => {
  if (!sortedFrames) { sortedFrames = [...rows.keys()].sort((a, b) => a - b); rowsInOrder = null; }
  if (!rowsInOrder || rowsInOrder.length !== sortedFrames.length) rowsInOrder = sortedFrames.map((f) => rows.get(f));
  return rowsInOrder;
};
S.redraw = () => { drawView(); schedulePlot(); };

window.addEventListener('resize', () => { drawView(); drawTimeline(); schedulePlot(); });
connect();
