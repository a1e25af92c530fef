// softsight serve: a second run beside the one served, in sync on its timeline. A CSV of
// another run (a recording, `softsight track -o`, a page's "save CSV": the CSV's columns) is
// read in the page (nothing is sent); each row is matched to the frame on screen by its time
// (time_s, within half a frame), so the two runs share the timeline, the seek and the playback.
// Drawn: the other run's markers (dashed squares) and base-middle-tip lines on the picture, its
// numbers under the readout, and its curve (dashed, white) in every lane of the plots, the
// analysis tools' lanes included (a tool's markers are looked up in its rows).
'use strict';

(() => {
  const S = window.softsight;
  const $ = (id) => document.getElementById(id);
  let other = null;  // {name, rows: [row] by time, times: [time_s]}
  S.compare = null;  // For the test: {name, rows}.

  // One CSV line's fields (the CSV's values have no quotes or commas, but a name might).
  function fields(line) {
    const out = [];
    let field = '', quoted = false;
    for (let i = 0; i < line.length; i++) {
      const c = line[i];
      if (quoted) {
        if (c === '"' && line[i + 1] === '"') { field += '"'; i++; } else if (c === '"') quoted = false; else field += c;
      } else if (c === '"') quoted = true;
      else if (c === ',') { out.push(field); field = ''; } else field += c;
    }
    out.push(field);
    return out;
  }

  // The rows of a CSV with frame and time_s columns: numbers as numbers, empty fields absent.
  function parse(text) {
    const lines = text.split(/\r?\n/).filter((l) => l.length > 0 && l[0] !== '#');
    if (lines.length < 2) throw new Error('no rows');
    const header = fields(lines[0]);
    if (!header.includes('frame') || !header.includes('time_s')) throw new Error('no frame and time_s columns');
    const rows = [];
    for (const line of lines.slice(1)) {
      const values = fields(line), row = {};
      header.forEach((name, i) => {
        const v = values[i];
        if (v === undefined || v === '') return;
        const n = Number(v);
        row[name] = Number.isFinite(n) ? n : v;
      });
      if (Number.isFinite(row.time_s)) rows.push(row);
    }
    rows.sort((a, b) => a.time_s - b.time_s);
    return rows;
  }

  // The other run's row at time `t`: the nearest within half a frame period, else none.
  function rowAt(t) {
    if (!other || t === undefined || t === null) return null;
    const times = other.times;
    let lo = 0, hi = times.length - 1;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (times[mid] < t) lo = mid + 1; else hi = mid; }
    let best = lo;
    if (lo > 0 && Math.abs(times[lo - 1] - t) < Math.abs(times[lo] - t)) best = lo - 1;
    const half = 0.5 / ((S.hello && S.hello.fps) || 30);
    return Math.abs(times[best] - t) <= half + 1e-9 ? other.rows[best] : null;
  }
  S.compareRow = (frame) => { const row = S.row(frame); return row ? rowAt(row.time_s) : null; };

  $('comparefile').onchange = () => {
    const file = $('comparefile').files[0];
    if (!file) return;
    file.text().then((text) => {
      try {
        const rows = parse(text);
        other = {name: file.name, rows, times: rows.map((r) => r.time_s)};
        S.compare = {name: file.name, rows: rows.length};
        $('comparename').textContent = file.name + ' (' + rows.length + ' rows)';
        $('compareclear').hidden = false;
        S.log('compare: ' + file.name + ', ' + rows.length + ' rows, in step with this run by time');
      } catch (e) {
        S.log('compare: ' + file.name + ' is not a softsight CSV (' + e.message + ')', true);
      }
      $('comparefile').value = '';
      S.redraw();
    });
  };
  $('compareclear').onclick = () => {
    other = null; S.compare = null;
    $('comparename').textContent = ''; $('compareclear').hidden = true; $('comparereadout').textContent = '';
    S.redraw();
  };

  const fmt = (v, d) => (v === null || v === undefined ? '-' : Number(v).toFixed(d));

  // On the picture, over the served run's overlay: the other run's markers at this time.
  S.drawCompare = (ctx, row, toView, colours) => {
    S.compareDrawn = 0;
    const r = other && row ? rowAt(row.time_s) : null;
    $('comparereadout').textContent = !other ? '' : !r ? 'compare ' + other.name + ': no row at t ' + fmt(row && row.time_s, 3) + ' s'
      : 'compare ' + other.name + ': frame ' + r.frame + '  angle ' + fmt(r.angle_deg, 2) + ' deg   tip ' +
        fmt(r.tip_disp_mm !== undefined ? r.tip_disp_mm : r.tip_disp_px, 1) + (r.tip_disp_mm !== undefined ? ' mm' : ' px');
    if (!r || !S.hello) return;
    ctx.setLineDash([3, 3]); ctx.lineWidth = 1.5;
    const points = S.hello.triple.map((name) => (r[name + '_found'] === 1 ? toView(r[name + '_x'], r[name + '_y']) : null));
    if (points.every((p) => p)) {
      ctx.strokeStyle = 'rgba(255,255,255,0.6)';
      ctx.beginPath(); points.forEach(([x, y], i) => (i ? ctx.lineTo(x, y) : ctx.moveTo(x, y))); ctx.stroke();
    }
    S.hello.markers.forEach((name, i) => {
      if (r[name + '_found'] !== 1) return;
      const [x, y] = toView(r[name + '_x'], r[name + '_y']);
      ctx.strokeStyle = colours[i % colours.length];
      ctx.strokeRect(x - 8, y - 8, 16, 16);
      S.compareDrawn++;
    });
    ctx.setLineDash([]);
  };

  // In a lane of the plots (its x and y): the other run's curve of `key`, dashed white.
  S.drawCompareLane = (ctx, key, x, y, series, t0, t1) => {
    if (!other) return 0;
    ctx.strokeStyle = 'rgba(255,255,255,0.75)'; ctx.lineWidth = 1; ctx.setLineDash([4, 3]);
    ctx.beginPath();
    let drawing = false, drawn = 0, previous = null;
    for (const r of other.rows) {
      const v = series(r, key);
      if (v === null || v === undefined || r.time_s < t0 || r.time_s > t1 ||
          (previous !== null && r.frame - previous > 1)) drawing = false;
      previous = r.frame;
      if (v === null || v === undefined || r.time_s < t0 || r.time_s > t1) continue;
      drawing ? ctx.lineTo(x(r.time_s), y(v)) : ctx.moveTo(x(r.time_s), y(v));
      drawing = true;
      drawn++;
    }
    ctx.stroke(); ctx.setLineDash([]);
    return drawn;
  };
})();
