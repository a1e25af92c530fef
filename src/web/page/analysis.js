// softsight serve: the analysis tools, drawn and computed in the page from the results it has
// (Kinovea's and Tracker's): an angle on any three points and a distance between two, each point
// a tracked marker (a click near its ring) or a fixed image point (a click elsewhere); the
// markers' trajectory trails, a click on a trail seeking to that frame. Each tool's value is
// drawn on the picture, plotted over the run under the other measures (the cursor at the frame
// on screen), and a column of the page's CSV. The mm scale: two points clicked a known distance
// apart and that distance typed; the server takes it as the window's `c` does (the config's
// scale_from_points), so the rows, the plots and the tools are in mm from then on.
'use strict';

(() => {
  const S = window.softsight;
  const $ = (id) => document.getElementById(id);
  const TOOL_COLOURS = ['#ff9bf0', '#9bf0ff', '#f0ff9b', '#ffb070'];
  const SNAP_PX = 14;  // A click this close (screen pixels) to a found marker takes the marker.
  const tools = [];    // {kind: 'angle' | 'distance', points: [{marker} | {x, y}], name}
  let placing = null;  // The tool being placed: {kind, points}.
  let trails = false;
  let mmPerPx = null;  // The rows' scale (their chord in mm over px), once known.
  let scannedRows = -1;  // How many rows scale() last looked through, finding none.
  let scaleLine = null;  // The two points of the last scale set from this page, image pixels.
  S.tools = tools;

  function hint(text) { $('toolhint').textContent = text; }

  function startTool(kind) {
    placing = {kind, points: []};
    $('scalebox').hidden = true;
    if (kind === 'scale') {
      hint('click two points a known distance apart (a ruler in the actuator\'s plane, far apart); Esc cancels');
      return;
    }
    hint('click ' + (kind === 'angle' ? 'three points, the vertex second' : 'two points') +
         ' (near a marker: follows it; elsewhere: a fixed point); Esc cancels');
  }
  $('toolscale').onclick = () => startTool('scale');
  // The distance typed: the server checks it (above 0, the points 20 px apart at least).
  function setScale() {
    const mm = Number($('scalemm').value);
    if (!placing || placing.kind !== 'scale' || placing.points.length !== 2) return;
    if (!$('scalemm').value || !(mm > 0)) { S.log('scale: type the distance in mm (above 0)', true); return; }
    const [a, b] = placing.points;
    S.send({type: 'scale', ax: a.x, ay: a.y, bx: b.x, by: b.y, mm});
    scaleLine = placing.points;
    placing = null;
    $('scalebox').hidden = true;
    hint('');
    S.redraw();
  }
  $('scaleset').onclick = setScale;
  $('scalemm').addEventListener('keydown', (e) => { if (e.key === 'Enter') setScale(); });
  $('toolangle').onclick = () => startTool('angle');
  $('tooldistance').onclick = () => startTool('distance');
  $('toolsclear').onclick = () => { tools.length = 0; placing = null; hint(''); S.redraw(); };
  $('trails').onchange = () => { trails = $('trails').checked; S.redraw(); };
  document.addEventListener('keydown', (e) => {
    if (e.key === 'Escape' && placing) { placing = null; hint(''); $('scalebox').hidden = true; S.redraw(); }
  });

  const pointName = (p) => p.marker || '(' + p.x.toFixed(0) + ' ' + p.y.toFixed(0) + ')';
  const fixedName = (p) => p.marker || 'p' + p.x.toFixed(0) + '_' + p.y.toFixed(0);

  // The run's scale: the config's mm per px (the server's status: a scale_mm_per_px, or two
  // points clicked), else from the rows (chord_mm / chord_px, the median of the first ones
  // that have both: a plane's homography, uniform at the body's plane, which is what a metric
  // model measures in).
  function scale() {
    if (S.status && S.status.mm_per_px) return S.status.mm_per_px;
    if (mmPerPx !== null) return mmPerPx;
    const all = S.rowsIn();
    if (all.length === scannedRows) return null;  // No new row since: still no scale.
    scannedRows = all.length;
    const ratios = [];
    for (const row of all) {
      if (row.chord_mm !== null && row.chord_mm !== undefined && row.chord_px > 0) ratios.push(row.chord_mm / row.chord_px);
      if (ratios.length >= 15) break;
    }
    if (ratios.length >= 5) mmPerPx = ratios.sort((a, b) => a - b)[ratios.length >> 1];
    return mmPerPx;
  }

  function pointIn(row, p) {
    if (!p.marker) return [p.x, p.y];
    return row && row[p.marker + '_found'] === 1 ? [row[p.marker + '_x'], row[p.marker + '_y']] : null;
  }

  // The tool's value on `row`: degrees at the middle point, or the distance in mm (px before
  // the run's scale is known, or without one); null when a marker of it is not found.
  function value(tool, row) {
    const ps = tool.points.map((p) => pointIn(row, p));
    if (ps.some((p) => !p)) return null;
    if (tool.kind === 'angle') {
      const [a, b, c] = ps;
      const u = [a[0] - b[0], a[1] - b[1]], v = [c[0] - b[0], c[1] - b[1]];
      const n = Math.hypot(u[0], u[1]) * Math.hypot(v[0], v[1]);
      if (n === 0) return null;
      return Math.acos(Math.min(1, Math.max(-1, (u[0] * v[0] + u[1] * v[1]) / n))) * 180 / Math.PI;
    }
    const d = Math.hypot(ps[0][0] - ps[1][0], ps[0][1] - ps[1][1]);
    const mm = scale();
    return mm ? d * mm : d;
  }
  const unit = (tool) => (tool.kind === 'angle' ? 'deg' : scale() ? 'mm' : 'px');
  S.mmPerPx = scale;
  S.toolValue = (i, frame) => value(tools[i], S.row(frame));

  // A click on the picture (image pixels): a point of the tool being placed, or, with the
  // trails shown, a seek to the frame of the trail point clicked. True when it was taken.
  S.toolClick = (x, y, row, viewScale) => {
    if (placing && placing.kind === 'scale') {
      // Fixed points (a ruler's marks), never a marker.
      placing.points.push({x, y});
      if (placing.points.length < 2) {
        hint('point 1 at (' + x.toFixed(1) + ', ' + y.toFixed(1) + '): click point 2');
      } else {
        hint('their distance:');
        $('scalebox').hidden = false;
        $('scalemm').focus();
      }
      return true;
    }
    if (placing) {
      let point = {x, y};
      for (const name of S.hello.markers) {
        const p = pointIn(row, {marker: name});
        if (p && Math.hypot(p[0] - x, p[1] - y) * viewScale <= SNAP_PX) point = {marker: name};
      }
      placing.points.push(point);
      const needed = placing.kind === 'angle' ? 3 : 2;
      if (placing.points.length < needed) {
        hint(placing.points.length + ' of ' + needed + ' points: ' + placing.points.map(pointName).join(', '));
        return true;
      }
      const tool = placing;
      placing = null;
      tool.colour = TOOL_COLOURS[tools.length % TOOL_COLOURS.length];
      tool.label = tool.kind + ' ' + tool.points.map(pointName).join('-');
      tools.push(tool);
      hint(tool.label + ' [' + unit(tool) + ']');
      S.redraw();
      return true;
    }
    if (trails && S.hello.seekable) {
      let best = null, bestD = 6 / viewScale;
      for (const r of S.rowsIn()) {
        if (r._position < 0) continue;
        for (const name of S.hello.markers) {
          const p = pointIn(r, {marker: name});
          if (!p) continue;
          const d = Math.hypot(p[0] - x, p[1] - y);
          if (d < bestD) { bestD = d; best = r; }
        }
      }
      if (best) { S.send({type: 'seek', position: best._position}); return true; }
    }
    return false;
  };

  // A fixed point of a tool is dragged to move it (a marker's point follows its marker).
  const GRAB_PX = 8;   // A press this close (screen pixels) to a fixed point takes it.
  let moving = null;   // {tool, point}: the fixed point being dragged.
  function fixedPointNear(x, y, viewScale) {
    let best = null, bestD = GRAB_PX;
    for (const tool of tools) {
      for (const point of tool.points) {
        if (point.marker) continue;
        const d = Math.hypot(point.x - x, point.y - y) * viewScale;
        if (d <= bestD) { bestD = d; best = {tool, point}; }
      }
    }
    return best;
  }
  // The picture's mouse (image pixels): true when the press took a fixed point to drag.
  S.toolNear = (x, y, viewScale) => !placing && fixedPointNear(x, y, viewScale) !== null;
  S.toolGrab = (x, y, viewScale) => {
    if (placing) return false;
    moving = fixedPointNear(x, y, viewScale);
    return moving !== null;
  };
  S.toolMove = (x, y) => {
    if (!moving) return;
    moving.point.x = x; moving.point.y = y;
    S.redraw();
  };
  S.toolRelease = () => {
    if (!moving) return;
    const tool = moving.tool;
    moving = null;
    tool.label = tool.kind + ' ' + tool.points.map(pointName).join('-');
    hint(tool.label + ' [' + unit(tool) + ']');
    S.redraw();
  };

  // Drawn over the overlay: the trails, then each tool with its value on the frame on screen.
  S.drawTools = (ctx, row, toView, colours) => {
    // The scale's points (being placed, or the last set here): cyan crosses and the line.
    const marks = placing && placing.kind === 'scale' ? placing.points : scaleLine;
    if (marks && marks.length) {
      ctx.strokeStyle = '#40e0ff'; ctx.lineWidth = 1.5;
      ctx.beginPath();
      for (const p of marks) {
        const [x, y] = toView(p.x, p.y);
        ctx.moveTo(x - 6, y); ctx.lineTo(x + 6, y); ctx.moveTo(x, y - 6); ctx.lineTo(x, y + 6);
      }
      if (marks.length === 2) { ctx.moveTo(...toView(marks[0].x, marks[0].y)); ctx.lineTo(...toView(marks[1].x, marks[1].y)); }
      ctx.stroke();
    }
    S.trailPoints = 0;
    if (trails) {
      S.hello.markers.forEach((name, i) => {
        ctx.strokeStyle = colours[i % colours.length]; ctx.globalAlpha = 0.7; ctx.lineWidth = 1;
        ctx.beginPath();
        let drawing = false, previous = null;
        for (const r of S.rowsIn()) {
          const p = pointIn(r, {marker: name});
          // A gap where the marker was not found or frames are missing (a seek).
          if (!p || (previous !== null && r.frame - previous > 1 && S.hello.seekable)) drawing = false;
          previous = r.frame;
          if (!p) continue;
          const [vx, vy] = toView(p[0], p[1]);
          drawing ? ctx.lineTo(vx, vy) : ctx.moveTo(vx, vy);
          drawing = true;
          S.trailPoints++;
        }
        ctx.stroke();
        ctx.globalAlpha = 1;
      });
    }
    ctx.font = '13px sans-serif';
    for (const tool of tools) {
      const ps = tool.points.map((p) => pointIn(row, p));
      if (ps.some((p) => !p)) continue;
      const vs = ps.map((p) => toView(p[0], p[1]));
      ctx.strokeStyle = ctx.fillStyle = tool.colour; ctx.lineWidth = 2; ctx.setLineDash([6, 3]);
      ctx.beginPath();
      vs.forEach(([x, y], i) => (i ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
      ctx.stroke(); ctx.setLineDash([]);
      for (const [x, y] of vs) { ctx.beginPath(); ctx.arc(x, y, 3, 0, 2 * Math.PI); ctx.fill(); }
      const v = value(tool, row);
      const at = tool.kind === 'angle' ? vs[1] : [(vs[0][0] + vs[1][0]) / 2, (vs[0][1] + vs[1][1]) / 2];
      const text = v === null ? '-' : v.toFixed(tool.kind === 'angle' ? 1 : 2) + (tool.kind === 'angle' ? '\u00b0' : ' ' + unit(tool));
      ctx.fillStyle = 'rgba(0,0,0,0.6)'; ctx.fillRect(at[0] + 8, at[1] + 4, ctx.measureText(text).width + 6, 17);
      ctx.fillStyle = tool.colour; ctx.fillText(text, at[0] + 11, at[1] + 17);
    }
  };

  // Each tool a lane of the plots and a column of the CSV.
  S.toolLanes = () => tools.map((tool, i) => ['tool:' + i, tool.label + ' [' + unit(tool) + ']']);
  S.toolSeries = (key, row) => value(tools[Number(key.slice(5))], row);
  S.toolColumns = () => tools.map((tool) => [tool.kind + '_' + tool.points.map(fixedName).join('_') + '_' + unit(tool),
                                              (row) => value(tool, row)]);
})();
