// softsight serve: the rig's control panel (serve --simulate / --board-port). The server runs
// the loop; this page asks it to run a target or a profile (the controlling page only) and to
// STOP (any page, always), and draws what every frame's {"type":"rig"} says: the state, the
// board's answer, and the angle and pressure traces of the last TRACE_S seconds or of the whole
// run (every sample since the page opened, halved in density past MAX_POINTS). Each frame's row
// carries the loop's columns too (target_deg, setpoint_kpa, board_pressure_kpa, ...: the
// server's RigPanel::columns), so the page's CSV has them.
'use strict';

(() => {
  const S = window.softsight;
  const $ = (id) => document.getElementById(id);
  const TRACE_S = 20;
  // An hour at 30 fps is 108 000 samples: past this, every other sample is dropped (the whole
  // run stays, at half the density), so a long run costs a few MB at most.
  const MAX_POINTS = 60000;
  // The traces: parallel arrays.
  const trace = {t: [], target: [], measured: [], setpoint: [], pressure: []};
  let whole = false;  // The whole run, else the last TRACE_S seconds.
  let limits = null;
  S.rig = null;             // The last {"type":"rig"} message.
  S.rigLimits = null;       // The host's and the board's limits (the greeting's "rig").
  S.rigStates = [];         // Every state change: {state, action, vented, t, at (Date.now())}.
  S.rigStopPressedAt = null;  // performance.now() of the last STOP press on this page.
  S.rigStopLatencyMs = [];  // Press -> the first status saying vented and idle, per press.

  S.onRigHello = (rig) => {
    $('rig').hidden = !rig;
    if (!rig) return;
    limits = S.rigLimits = rig;
    // A paused run steps no loop (the server refuses it): STOP is the way to vent.
    $('play').disabled = true;
    $('play').title = "the rig's loop runs on every frame: STOP vents the actuator";
    $('rigtarget').min = Math.ceil(rig.reach_min_deg);
    $('rigtarget').max = Math.floor(rig.reach_max_deg);
    $('riglimits').textContent =
        'host: ' + rig.min_kpa + '..' + rig.max_kpa + ' kPa, slew ' + rig.max_rate_kpa_per_s +
        ' kPa/s, hold ' + rig.hold_s + ' s then vent; target ' + rig.reach_min_deg + '..' +
        rig.reach_max_deg + ' deg' + (rig.model_based ? ' (model-based loop)' : '') + '\n' +
        'board: limit ' + rig.board_limit_kpa + ' kPa, loop ' + rig.loop_hz + ' Hz, watchdog ' +
        rig.watchdog_ms + ' ms, protocol ' + rig.protocol + '\n' + rig.port;
    onRole();
  };

  function onRole() {
    for (const id of ['rigrun', 'rigprofilerun']) $(id).disabled = !S.controls;
  }
  S.onRole = onRole;

  const fixed = (v, d) => (v === null || v === undefined ? '-' : Number(v).toFixed(d));

  S.onRig = (m) => {
    const previous = S.rig;
    S.rig = m;
    if (!previous || previous.state !== m.state || previous.vented !== m.vented) {
      // prev_t: the frame before the change (the last frame of a hold, for one).
      S.rigStates.push({state: m.state, action: m.action, vented: m.vented, t: m.t, hold_left_s: m.hold_left_s,
                        prev_t: previous ? previous.t : null, at: Date.now()});
      if (S.rigStates.length > 200) S.rigStates.splice(0, 100);
    }
    if (S.rigStopPressedAt !== null && m.state === 'idle' && m.vented) {
      S.rigStopLatencyMs.push(performance.now() - S.rigStopPressedAt);
      S.rigStopPressedAt = null;
    }
    const badge = $('rigstate');
    badge.textContent = m.state + (m.state === 'holding' ? ' ' + fixed(m.hold_left_s, 1) + ' s, then vent' : '');
    badge.className = 'badge rig-' + m.state;
    const valves = m.vented ? 'vented' : m.duty > 0.02 ? 'inflating' : m.duty < -0.02 ? 'venting' : 'closed';
    const flags = (m.watchdog ? ' WATCHDOG' : '') + (m.limit ? ' LIMIT' : '');
    $('rigboard').textContent =
        'target ' + fixed(m.target_deg, 1) + ' deg   measured ' + fixed(m.measured_deg, 1) + ' deg   ' + m.action + '\n' +
        'sent ' + fixed(m.setpoint_kpa, 1) + ' kPa   board ' + fixed(m.pressure_kpa, 2) + ' kPa (' + valves +
        ', duty ' + fixed(m.duty, 2) + ')' + flags +
        (m.profile_s !== null ? '\nprofile ' + fixed(m.profile_s, 1) + ' / ' + fixed(m.profile_length_s, 1) + ' s' : '');
    if (trace.t.length && m.t <= trace.t[trace.t.length - 1]) return;  // A STOP's repeat of the frame.
    trace.t.push(m.t); trace.target.push(m.target_deg); trace.measured.push(m.measured_deg);
    trace.setpoint.push(m.setpoint_kpa); trace.pressure.push(m.pressure_kpa);
    if (trace.t.length > MAX_POINTS) for (const k in trace) trace[k] = trace[k].filter((_, j) => j % 2 === 0);
    scheduleTrace();
  };

  // ---- Commands ---------------------------------------------------------------------------
  function stop() {
    S.rigStopPressedAt = performance.now();
    S.send({type: 'rig_stop'});
  }
  $('rigstop').onclick = stop;
  // Escape is STOP wherever the focus is (a text field too): the one key that always works.
  document.addEventListener('keydown', (e) => {
    if (e.key === 'Escape' && S.rigLimits) { stop(); e.preventDefault(); }
  }, true);
  $('rigrun').onclick = () => {
    const value = Number($('rigtarget').value);
    // The server checks it again (0..180, the reach): this only saves a round trip.
    if (!$('rigtarget').value || !Number.isFinite(value)) { S.log('rig: the target is not a number', true); return; }
    S.send({type: 'rig_run', target_deg: value});
  };
  $('rigtarget').addEventListener('keydown', (e) => { if (e.key === 'Enter') $('rigrun').onclick(); });
  $('rigprofilerun').onclick = () => S.send({type: 'rig_profile', text: $('rigprofile').value});
  $('rigspan').onchange = () => { whole = $('rigspan').value === 'whole'; drawTrace(); };

  // ---- Traces -----------------------------------------------------------------------------
  let queued = false;
  function scheduleTrace() {
    if (queued) return;
    queued = true;
    setTimeout(() => { queued = false; drawTrace(); }, 100);  // At most 10 redraws a second.
  }

  function drawTrace() {
    const c = $('rigplot');
    const ctx = c.getContext('2d');
    const w = c.width, h = c.height;
    ctx.fillStyle = '#111'; ctx.fillRect(0, 0, w, h);
    if (!trace.t.length || !limits) return;
    const t1 = trace.t[trace.t.length - 1];
    const t0 = whole ? Math.min(trace.t[0], t1 - 1) : t1 - TRACE_S;
    const x = (t) => 36 + (t - t0) / (t1 - t0) * (w - 42);
    S.rigTrace = {t0, t1, samples: trace.t.length, whole};  // For the test: the span drawn.
    S.changed();
    // The angle lane from 10 deg under the lowest angle in view (rounded to 10) to straight.
    let lowest = 170;
    for (let j = 0; j < trace.t.length; j++) {
      if (trace.t[j] < t0) continue;
      for (const v of [trace.target[j], trace.measured[j]]) if (v !== null && v < lowest) lowest = v;
    }
    const lanes = [
      {title: 'angle [deg]', lo: Math.max(0, Math.floor((lowest - 10) / 10) * 10), hi: 180,
       series: [['target', '#ffd040', true], ['measured', '#50e070', false]]},
      {title: 'pressure [kPa]', lo: 0, hi: Math.max(limits.board_limit_kpa, limits.max_kpa),
       series: [['setpoint', '#50a0ff', true], ['pressure', '#ff5050', false]], lines: [limits.max_kpa, limits.board_limit_kpa]},
    ];
    const laneH = h / lanes.length;
    lanes.forEach((lane, i) => {
      const top = i * laneH;
      const y = (v) => top + laneH - 4 - (Math.min(Math.max(v, lane.lo), lane.hi) - lane.lo) / (lane.hi - lane.lo) * (laneH - 18);
      ctx.strokeStyle = '#333'; ctx.setLineDash([]); ctx.strokeRect(36, top + 2, w - 42, laneH - 4);
      ctx.fillStyle = '#aaa'; ctx.font = '11px sans-serif';
      ctx.fillText(lane.title, 40, top + 12);
      ctx.fillText(String(lane.hi), 2, top + 14); ctx.fillText(String(lane.lo), 2, top + laneH - 4);
      for (const v of lane.lines || []) {  // The host's max_kpa and the board's limit.
        ctx.strokeStyle = '#803030'; ctx.setLineDash([2, 4]);
        ctx.beginPath(); ctx.moveTo(36, y(v)); ctx.lineTo(w - 6, y(v)); ctx.stroke();
      }
      lane.series.forEach(([key, colour, dashed], k) => {
        ctx.strokeStyle = colour; ctx.lineWidth = 1.3; ctx.setLineDash(dashed ? [5, 3] : []);
        ctx.beginPath();
        let drawing = false;
        for (let j = 0; j < trace.t.length; j++) {
          const v = trace[key][j];
          if (trace.t[j] < t0 || v === null) { drawing = false; continue; }
          drawing ? ctx.lineTo(x(trace.t[j]), y(v)) : ctx.moveTo(x(trace.t[j]), y(v));
          drawing = true;
        }
        ctx.stroke();
        ctx.setLineDash([]); ctx.fillStyle = colour;
        ctx.fillText(key, w - 130 + 62 * k, top + 12);
      });
    });
  }
})();
