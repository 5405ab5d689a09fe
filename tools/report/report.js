// The report page's script: lays out the data l6470emu wrote into the page (tools/report_data.hpp)
// and draws it with dygraphs. It computes nothing about the chips: every value shown is in the
// data; this only finds the one under the cursor and formats it.
'use strict';
(function () {
  const D = JSON.parse(document.getElementById('report-data').textContent);
  const S = D.strings, str = (i) => (i < 0 ? '' : S[i]);
  const TICK = D.tick_ns * 1e-9, sec = (t) => t * TICK;
  const STEP_PER_S = Math.pow(2, -28) / TICK;  // SPEED register unit, 2^-28 step/tick
  const app = document.getElementById('app');
  const el = (tag, attrs, ...kids) => {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'class') e.className = v; else if (k.startsWith('on')) e.addEventListener(k.slice(2), v); else e.setAttribute(k, v);
    }
    for (const k of kids) if (k !== null && k !== undefined) e.append(k instanceof Node ? k : String(k));
    return e;
  };
  const fmtS = (t) => sec(t).toFixed(6);
  const hex = (v, digits) => '0x' + v.toString(16).toUpperCase().padStart(digits, '0');
  const undelta = (dt) => { let t = 0; return dt.map((d) => (t += d)); };
  const last = (ticks, t) => { let lo = 0, hi = ticks.length - 1, at = -1;  // last index with ticks[i] <= t
    while (lo <= hi) { const m = (lo + hi) >> 1; if (ticks[m] <= t) { at = m; lo = m + 1; } else hi = m - 1; } return at; };

  // ---- the timeline: entries (runs of repeated frame groups) and summarised gaps, by frame number
  const segs = [];
  for (const [tick, period, reps, first, rows] of D.entries) {
    const lr = rows[rows.length - 1];
    segs.push({first, count: reps * rows.length, start: tick, end: tick + (reps - 1) * period + lr[0] + lr[1], tick, period, reps, rows});
  }
  for (const [from, to, first, frames, commands] of D.gaps) segs.push({first, count: frames, start: from, end: to, gap: true, commands});
  segs.sort((a, b) => a.first - b.first);
  const total = segs.reduce((n, s) => n + s.count, 0);
  if (total !== D.frames) console.error('report: the timeline holds ' + total + ' frames, the trace ' + D.frames);
  const segStarts = segs.map((s) => s.first), segTicks = segs.map((s) => s.start);
  function frameAt(i) {
    const s = segs[last(segStarts, i)];
    const k = i - s.first;
    if (s.gap) return {i, gap: s, tick: s.start + Math.floor((s.end - s.start) * k / Math.max(1, s.count)), dur: 0};
    const rep = Math.floor(k / s.rows.length), row = s.rows[k % s.rows.length];
    return {i, tick: s.tick + rep * s.period + row[0], dur: row[1], mosi: str(row[2]), miso: str(row[3]), flags: row[4],
            texts: row.slice(5).map(str), repeated: s.reps > 1};
  }
  function frameAtTick(t) {  // the last frame starting at or before t (0 when none)
    const j = last(segTicks, t);
    if (j < 0) return 0;
    const s = segs[j];
    if (s.gap) return s.first + Math.min(s.count - 1, Math.floor((t - s.start) * s.count / Math.max(1, s.end - s.start)));
    const rep = s.period > 0 ? Math.min(s.reps - 1, Math.floor((t - s.tick) / s.period)) : 0;
    let r = s.rows.length - 1;
    while (r > 0 && s.tick + rep * s.period + s.rows[r][0] > t) --r;
    const k = rep * s.rows.length + r - (s.tick + rep * s.period + s.rows[r][0] > t ? 1 : 0);
    return s.first + Math.max(0, k);
  }
  const shortName = (text) => text.split(/[ (]/)[0];

  // ---- the chips' series
  const chips = D.chips.map((c) => {
    const st = c.states, ph = c.phase, mo = c.motion;
    return Object.assign(c, {
      st: {t: undelta(st.dt), pos: st.abs_pos, el: st.el_pos, speed: st.speed, status: st.status},
      ph: {t: undelta(ph.dt), a: ph.a, b: ph.b},
      mo: {t: undelta(mo.dt), pos: mo.abs_pos, speed: mo.speed, bits: mo.bits},
      regTicks: c.registers.map((r) => r[0]),
    });
  });
  const nChain = chips.length;
  const cursor = {frame: 0, tick: 0};

  // ---- header
  const counts = D.counts;
  const findingsTotal = counts.diagnostics + counts.sanitizer + counts.divergent_frames + counts.divergent_pins;
  app.append(el('h1', {}, D.title),
    el('p', {class: 'meta'}, `${D.trace.path} (${D.trace.format}) · chain ${D.trace.chain} · ${D.trace.numbering}`),
    ...D.trace.notes.map((n) => el('p', {class: 'meta'}, 'note: ' + n)),
    el('div', {class: 'badges'}, el('span', {id: 'frame-count'}, `${total} frames`), el('span', {}, `${chips.length} chips`),
      el('span', {}, `${fmtS(D.end)} s`), el('span', {}, `${findingsTotal} findings`)));
  if (D.first_divergence) app.append(el('div', {class: 'banner', role: 'alert'}, 'DIVERGED: ' + D.first_divergence +
    ' — from there on the page shows the emulator\'s model of the run, not what the trace holds.'));
  if (D.summarised) app.append(el('div', {class: 'notice'}, 'This run is longer than a page shows one by one: grey ' +
    'spans of the timeline marked "frames summarised" stand for frames counted but not listed, and the series keep per time ' +
    'slice their first, last and extreme samples (docs/report.md, "Size").'));
  app.append(el('nav', {}, ...[['timeline', 'Timeline'], ['chips', 'Chips'], ['findings', `Findings (${findingsTotal})`],
    ['coverage', 'Coverage'], ['campaign', 'Campaign']].filter(([id]) => (id !== 'coverage' || D.coverage) && (id !== 'campaign' || D.campaign))
    .map(([id, t]) => el('a', {href: '#' + id}, t))));

  // ---- timeline section: controls, the lanes chart, the frames around the cursor
  const readout = el('span', {class: 'readout', id: 'cursor-readout', 'aria-live': 'polite'});
  const goTime = el('input', {id: 'goto-time', type: 'text', inputmode: 'decimal', 'aria-label': 'go to time in seconds', placeholder: 't in s'});
  const goFrame = el('input', {id: 'goto-frame', type: 'text', inputmode: 'numeric', 'aria-label': 'go to frame number', placeholder: 'frame #'});
  goTime.addEventListener('keydown', (e) => { if (e.key === 'Enter') setCursorTick(Math.round(parseFloat(goTime.value) / TICK)); });
  goFrame.addEventListener('keydown', (e) => { if (e.key === 'Enter') setCursor(parseInt(goFrame.value, 10) - 1, true); });
  const btn = (label, title, f) => el('button', {type: 'button', title, onclick: f}, label);
  app.append(el('h2', {id: 'timeline'}, 'Timeline'),
    el('div', {class: 'controls'}, goTime, goFrame, btn('−', 'zoom out (-)', () => zoom(2)), btn('+', 'zoom in (+)', () => zoom(0.5)),
      btn('whole run', 'show the whole run (0)', () => setWindow(0, D.shown_to)), readout),
    el('p', {class: 'help'}, '← → previous/next frame · Shift+← → 10 frames · + − zoom around the cursor · 0 whole run · ' +
      'Home/End first/last frame · drag on a chart to zoom, Shift+drag to pan, click to put the cursor there · hover a chip\'s ' +
      'cell for its bytes'));
  const lanesDiv = el('div', {class: 'chart', id: 'lanes', style: `height:${120 + 95 * nChain}px`});
  app.append(lanesDiv);
  const table = el('table', {class: 'frames', id: 'frames'});
  table.append(el('colgroup', {}, el('col', {style: 'width:6.5em'}), el('col', {style: 'width:9.5em'}), el('col', {style: 'width:5em'}),
    el('col', {style: 'width:11%'}), el('col', {style: 'width:11%'}), ...chips.map(() => el('col', {}))));
  table.append(el('thead', {}, el('tr', {}, el('th', {class: 'num'}, 'frame'), el('th', {class: 'num'}, 't (s)'), el('th', {class: 'num'}, 'CS µs'),
    el('th', {}, 'MOSI'), el('th', {}, 'MISO'), ...chips.map((c) => el('th', {}, `chip ${c.number} (${c.variant})`)))));
  const tbody = el('tbody', {});
  table.append(tbody);
  app.append(table);

  function bytesOf(f, c) {  // which MOSI byte chip c decoded and which MISO byte it drove
    const m = f.mosi ? f.mosi.split(' ') : [], s = f.miso ? f.miso.split(' ') : [], len = m.length, k = c.index;
    const j = len >= nChain ? len - nChain + k : (k >= nChain - len ? k - (nChain - len) : -1);
    return `chip ${c.number}: decodes ${j >= 0 ? 'MOSI byte ' + j + ' = ' + m[j] : 'a byte left in the chain'}; ` +
           `drives MISO byte ${k} = ${k < s.length ? s[k] : '(not captured)'}`;
  }
  function renderFrames() {
    tbody.replaceChildren();
    const from = Math.max(0, cursor.frame - 8), to = Math.min(total, from + 17);
    for (let i = from; i < to; ++i) {
      const f = frameAt(i);
      const tr = el('tr', {class: (i === cursor.frame ? 'at ' : '') + (f.gap ? 'gap' : (f.flags & 1 ? 'diverged ' : '') + (f.flags & 2 ? 'diagnostic' : '')),
        'data-frame': i + 1, onclick: () => setCursor(i, false)});
      if (f.gap) {
        tr.append(el('td', {class: 'num'}, i + 1), el('td', {class: 'num'}, fmtS(f.tick)),
          el('td', {colspan: 3 + nChain}, `in a summarised span of ${f.gap.count} frames (${f.gap.commands} commands) from t=${fmtS(f.gap.start)} to ${fmtS(f.gap.end)} s`));
      } else {
        tr.append(el('td', {class: 'num'}, i + 1), el('td', {class: 'num'}, fmtS(f.tick)), el('td', {class: 'num'}, (sec(f.dur) * 1e6).toFixed(2)),
          el('td', {class: 'bytes', title: 'MOSI ' + f.mosi}, f.mosi), el('td', {class: 'bytes', title: 'MISO ' + (f.miso || 'not captured')}, f.miso || '—'),
          ...chips.map((c) => { const t = f.texts[c.index]; return el('td', {class: t.includes(' → ') ? 'ans' : 'cmd', title: bytesOf(f, c) + (t ? '\n' + t : '')}, t); }));
      }
      tbody.append(tr);
    }
  }

  // ---- charts
  const charts = [];
  let syncing = false;
  function addCursor(div) { const c = el('div', {class: 'cursor'}); div.append(c); return c; }
  function placeCursors() {
    for (const {g, line} of charts) {
      const [x0, x1] = g.xAxisRange(), x = sec(cursor.tick);
      line.style.display = x < x0 || x > x1 ? 'none' : 'block';
      line.style.left = g.toDomXCoord(x) + 'px';
    }
  }
  function chart(div, data, opts) {
    const g = new Dygraph(div, data, Object.assign({
      dateWindow: [0, sec(D.shown_to)], animatedZooms: false, labelsSeparateLines: false, legend: 'follow',
      axes: {x: {valueFormatter: (x) => 't=' + x.toFixed(6) + ' s', axisLabelFormatter: (x) => x.toPrecision(6).replace(/\.?0+$/, '') + ' s'}},
      drawCallback: (me, initial) => {
        if (!initial && !syncing) {
          syncing = true;
          const w = me.xAxisRange();
          for (const o of charts) if (o.g !== me) o.g.updateOptions({dateWindow: w});
          syncing = false;
        }
        placeCursors();
      },
      clickCallback: (e, x) => setCursorTick(Math.round(x / TICK), true),
    }, opts));
    charts.push({g, line: addCursor(div)});
    return g;
  }
  function setWindow(t0, t1) {
    syncing = true;
    for (const o of charts) o.g.updateOptions({dateWindow: [sec(t0), sec(t1)]});
    syncing = false;
    placeCursors();
  }
  function zoom(factor) {
    const [x0, x1] = charts[0].g.xAxisRange(), c = sec(cursor.tick);  // the cursor in the middle
    const w = Math.max((x1 - x0) * factor, 4 * TICK), a = Math.max(0, c - w / 2);
    setWindow(a / TICK, (a + w) / TICK);
  }

  // The lanes: per chip BUSY, FLAG, SW (as the emulated chip has them), STCK and STBY (as the trace
  // drove them); above them a row per chip with the frames, drawn under the chart.
  const LANES = ['BUSY', 'FLAG', 'SW', 'STCK', 'STBY'];
  const RIGHT_GAP = 59;  // where the motion charts have their SPEED axis: the time axes line up
  const laneBase = (ci, l) => (nChain - 1 - ci) * LANES.length + (LANES.length - 1 - l);
  const frameRowY = (ci) => nChain * LANES.length + (nChain - 1 - ci) + 0.1;
  {
    const changes = [];  // [tick, series, value]
    chips.forEach((c, ci) => {
      let prev = -1;
      c.mo.t.forEach((t, i) => {
        const b = c.mo.bits[i], v = [(b >> 2) & 1, (b >> 3) & 1, (b >> 4) & 1];
        const key = v.join('');
        if (key !== prev) v.forEach((x, l) => changes.push([t, ci * 5 + l, laneBase(ci, l) + 0.7 * x]));
        prev = key;
      });
      changes.push([0, ci * 5 + 3, laneBase(ci, 3)], [0, ci * 5 + 4, laneBase(ci, 4) + 0.7]);
      for (const [t, pin, level] of c.inputs) {
        const l = pin === 'STCK' ? 3 : pin === 'STBY' ? 4 : -1;
        if (l >= 0) changes.push([t, ci * 5 + l, laneBase(ci, l) + 0.7 * level]);
      }
      for (let l = 0; l < 5; ++l) changes.push([D.shown_to, ci * 5 + l, null]);
    });
    changes.sort((a, b) => a[0] - b[0]);
    const rows = [], lastVal = new Array(nChain * 5).fill(null);
    for (const [t, s, v] of changes) {
      const x = sec(t);
      let row = rows.length && rows[rows.length - 1][0] === x ? rows[rows.length - 1] : null;
      if (!row) { row = [x, ...new Array(nChain * 5).fill(null)]; rows.push(row); }
      row[1 + s] = v === null ? lastVal[s] : v;
      if (v !== null) lastVal[s] = v;
    }
    const labels = ['t'], colors = [];
    chips.forEach((c) => LANES.forEach((l, i) => { labels.push(`chip ${c.number} ${l}`); colors.push(['#0b5394', '#b00020', '#1e6b30', '#5b2a86', '#7a5c00'][i]); }));
    const ticks = [];
    chips.forEach((c, ci) => { LANES.forEach((l, li) => ticks.push({v: laneBase(ci, li) + 0.35, label: `${c.number} ${l}`}));
      ticks.push({v: frameRowY(ci) + 0.4, label: `chip ${c.number}`}); });
    chart(lanesDiv, rows, {
      labels, colors, stepPlot: true, connectSeparatedPoints: true, strokeWidth: 1.5, legend: 'never', rightGap: RIGHT_GAP,
      valueRange: [-0.3, nChain * LANES.length + nChain + 0.2], yAxisLabelWidth: 70,
      axes: {y: {ticker: () => ticks, drawGrid: false}, x: {valueFormatter: (x) => 't=' + x.toFixed(6) + ' s',
        axisLabelFormatter: (x) => x.toPrecision(6).replace(/\.?0+$/, '') + ' s'}},
      underlayCallback: drawFrames,
    });
  }
  function drawFrames(ctx, area, g) {
    const [x0, x1] = g.xAxisRange(), t0 = x0 / TICK, t1 = x1 / TICK, px = area.w / Math.max(1e-9, x1 - x0);
    const X = (t) => g.toDomXCoord(sec(t)), rowTop = (ci) => g.toDomYCoord(frameRowY(ci) + 0.8), rowH = (ci) => g.toDomYCoord(frameRowY(ci)) - rowTop(ci);
    ctx.save();
    ctx.font = '11px system-ui, sans-serif';
    let drawn = 0;
    const marks = [];  // [right edge x, row] of each frame drawn, in time order
    for (let j = Math.max(0, last(segTicks, t0)); j < segs.length && segs[j].start <= t1; ++j) {
      const s = segs[j];
      if (s.end < t0) continue;
      if (s.gap || s.count > 1 && (s.end - s.start) * px * TICK < s.count * 3 || drawn > 20000) {  // too dense: a band
        const a = Math.max(area.x, X(s.start)), b = Math.min(area.x + area.w, Math.max(X(s.end), a + 1));
        chips.forEach((c, ci) => {
          ctx.fillStyle = s.gap ? '#d9d9d9' : '#c9daf0';
          ctx.fillRect(a, rowTop(ci), b - a, rowH(ci));
          if (b - a > 60) { ctx.fillStyle = '#1a1a1a'; ctx.fillText(s.gap ? `${s.count} frames summarised` : `${s.count} frames (${s.reps}×)`, a + 3, rowTop(ci) + rowH(ci) - 4); }
        });
        continue;
      }
      const n = s.rows.length;
      const r0 = s.period > 0 ? Math.max(0, Math.floor((t0 - s.tick) / s.period) - 1) : 0;
      for (let rep = r0; rep < s.reps; ++rep) {
        const base = s.tick + rep * s.period;
        if (base > t1) break;
        for (let r = 0; r < n; ++r) {
          const row = s.rows[r], t = base + row[0], x = X(t), w = Math.max(1, row[1] * TICK * px);
          ++drawn;
          chips.forEach((c, ci) => {
            const text = str(row[5 + c.index]);
            ctx.fillStyle = row[4] & 1 ? '#b00020' : row[4] & 2 ? '#b8860b' : !text ? '#8c8c8c' : text.includes(' → ') ? '#0b5394' : '#9a4a00';
            ctx.fillRect(x, rowTop(ci), w, rowH(ci));
          });
          marks.push([x + w, row]);
        }
      }
    }
    // Labels where there is room before the chip's next label.
    ctx.fillStyle = '#1a1a1a';
    chips.forEach((c, ci) => {
      let next = area.x + area.w;
      for (let i = marks.length - 1; i >= 0; --i) {
        const [x, row] = marks[i], text = str(row[5 + c.index]), room = next - x - 6;
        if (!text) continue;
        next = x - row[1] * TICK * px;
        if (room < 40) continue;
        const label = room > 160 ? text : shortName(text);
        ctx.fillText(label.length * 6 > room ? label.slice(0, Math.floor(room / 6)) : label, x + 2, rowTop(ci) + rowH(ci) - 4);
      }
    });
    // Stimuli (faults, switches, supply...) and findings.
    chips.forEach((c, ci) => {
      for (const [t, , kind, text] of c.stimuli) {
        if (t < t0 || t > t1) continue;
        const x = X(t);
        ctx.strokeStyle = '#b00020'; ctx.setLineDash([4, 3]); ctx.beginPath();
        ctx.moveTo(x, g.toDomYCoord(laneBase(ci, 0) + 0.9)); ctx.lineTo(x, g.toDomYCoord(laneBase(ci, 4) - 0.2)); ctx.stroke();
        ctx.setLineDash([]); ctx.fillStyle = '#b00020'; ctx.fillText('⚡ ' + text, x + 3, g.toDomYCoord(laneBase(ci, 0) + 0.95));
      }
    });
    ctx.fillStyle = '#b00020';
    for (const f of D.findings) {
      if (f[3] < t0 || f[3] > t1) continue;
      const x = X(f[3]), y = g.toDomYCoord(nChain * LANES.length + nChain + 0.15);
      ctx.beginPath(); ctx.moveTo(x - 5, y - 7); ctx.lineTo(x + 5, y - 7); ctx.lineTo(x, y); ctx.fill();
    }
    ctx.restore();
  }

  // ---- per chip: motion, phase drive, registers at the cursor
  app.append(el('h2', {id: 'chips'}, 'Chips'));
  const panels = chips.map((c) => {
    const box = el('section', {class: 'chip', id: `chip-${c.number}`, 'aria-label': `chip ${c.number}`});
    const motionDiv = el('div', {class: 'chart', style: 'height:230px'}), phaseDiv = el('div', {class: 'chart', style: 'height:170px'});
    const regs = el('div', {id: `registers-${c.number}`});
    box.append(el('h3', {}, `chip ${c.number} (${c.variant}, chain index ${c.index})`),
      el('div', {class: 'chipgrid'}, el('div', {}, motionDiv, phaseDiv,
        el('p', {class: 'help'}, `Phase drive: coil A and B as EL_POS walks the sine, in % of full scale (KVAL/TVAL of the motion phase; ` +
          `sampled every ${(sec(D.phase_step) * 1e6).toFixed(1)} µs while moving; docs/report.md)`)), regs));
    app.append(box);
    const m = c.mo;
    chart(motionDiv, m.t.map((t, i) => [sec(t), m.pos[i], m.speed[i] * STEP_PER_S]), {
      labels: ['t', 'ABS_POS', 'SPEED (step/s)'], colors: ['#0b5394', '#9a4a00'], ylabel: `ABS_POS (1/${c.motion.microsteps} step)`,
      y2label: 'step/s', series: {'SPEED (step/s)': {axis: 'y2'}}, strokeWidth: 1.5, yAxisLabelWidth: 70,
      axes: {x: {valueFormatter: (x) => 't=' + x.toFixed(6) + ' s', axisLabelFormatter: (x) => x.toPrecision(6).replace(/\.?0+$/, '') + ' s'},
             y2: {independentTicks: true, axisLabelWidth: 50}},
    });
    const p = c.ph;
    chart(phaseDiv, p.t.map((t, i) => [sec(t), p.a[i] / 10, p.b[i] / 10]).concat([[sec(D.shown_to), p.a[p.a.length - 1] / 10, p.b[p.b.length - 1] / 10]]), {
      labels: ['t', 'coil A %', 'coil B %'], colors: ['#5b2a86', '#1e6b30'], stepPlot: true, valueRange: [-105, 105], yAxisLabelWidth: 70,
      ylabel: 'phase drive %', strokeWidth: 1.5, rightGap: RIGHT_GAP,
    });
    return {c, regs};
  });
  const FIELD_MEANING = {MOT_STATUS: ['stopped', 'accelerating', 'decelerating', 'constant speed'], DIR: ['reverse', 'forward'],
    TH_STATUS: ['normal', 'warning', 'bridge shutdown', 'device shutdown']};
  function statusWords(c, status) {  // the fields that are set, by name ("HiZ FWD MOT_STATUS=3 UVLO")
    return c.status_fields.map(([name, bit, width, low]) => {
      const v = (status >> bit) & ((1 << width) - 1);
      return width > 1 ? (v ? `${name}=${v}` : '') : (low ? v === 0 : v === 1) ? name : '';
    }).filter((w) => w).join(' ');
  }
  function renderRegisters() {
    const f = frameAt(cursor.frame), at = f.gap ? cursor.tick : f.tick + f.dur;
    for (const {c, regs} of panels) {
      const si = Math.max(0, last(c.st.t, at));
      const status = c.st.status[si];
      const values = new Map();  // address -> [name, value text, meaning]
      for (let i = 0; i < c.registers.length && c.registers[i][0] <= at; ++i) {
        const [, addr, name, value, text] = c.registers[i];
        values.set(addr, [str(name), value, str(text)]);
      }
      for (const [addr, name] of c.live_registers) {
        const v = {ABS_POS: c.st.pos[si], EL_POS: c.st.el[si], SPEED: c.st.speed[si], STATUS: status}[name];
        const meaning = {ABS_POS: `${v} microsteps`, EL_POS: `step ${v >> 7}, microstep ${v & 127} of 128`,
          SPEED: `${(Math.abs(v) * STEP_PER_S).toFixed(2)} step/s${v < 0 ? ' (reverse)' : ''}`, STATUS: statusWords(c, v)}[name];
        values.set(addr, [name, name === 'STATUS' ? hex(v, 4) : String(v), meaning, true]);
      }
      const tb = el('tbody', {});
      for (const addr of [...values.keys()].sort((a, b) => a - b)) {
        const [name, value, meaning, live] = values.get(addr);
        tb.append(el('tr', {}, el('td', {}, name), el('td', {}, hex(addr, 2)),
          el('td', {id: `reg-${c.number}-${name}`, class: 'num'}, live ? value : hex(value, 1)), el('td', {}, meaning)));
      }
      const ftb = el('tbody', {});
      for (const [name, bit, width, low] of c.status_fields) {
        const v = (status >> bit) & ((1 << width) - 1), active = width === 1 && (low ? v === 0 : v === 1) && !['DIR', 'HiZ'].includes(name);
        const meaning = FIELD_MEANING[name] ? FIELD_MEANING[name][v] : width === 1 ? (active ? 'active' + (low ? ' (low)' : '') : '') : '';
        ftb.append(el('tr', {class: active ? 'active-field' : ''}, el('td', {}, name), el('td', {class: 'num'}, width > 1 ? `${bit + width - 1}:${bit}` : bit),
          el('td', {class: 'num', id: `field-${c.number}-${name}`}, v), el('td', {}, meaning)));
      }
      const answers = [];  // the chip's last answers before the cursor, as the host read them
      for (let i = cursor.frame, seen = new Set(); i >= 0 && i > cursor.frame - 3000 && answers.length < 4; --i) {
        const g = frameAt(i);
        if (g.gap) { i = g.gap.first; continue; }
        const t = g.texts[c.index];
        if (t.includes(' → ') && !seen.has(t.split(' → ')[0])) { seen.add(t.split(' → ')[0]); answers.push([i, t]); }
      }
      regs.replaceChildren(
        el('p', {class: 'meta'}, `After frame ${cursor.frame + 1} (its CS rising edge, t=${fmtS(at)} s); state sampled at t=${fmtS(c.st.t[si])} s`),
        el('p', {}, 'STATUS ', el('code', {id: `status-${c.number}`}, hex(status, 4))),
        el('table', {class: 'regs'}, el('thead', {}, el('tr', {}, el('th', {}, 'register'), el('th', {}, 'addr'), el('th', {class: 'num'}, 'value'), el('th', {}, 'meaning'))), tb),
        el('h3', {}, 'STATUS fields'),
        el('table', {class: 'regs'}, el('thead', {}, el('tr', {}, el('th', {}, 'field'), el('th', {class: 'num'}, 'bit'), el('th', {class: 'num'}, 'value'), el('th', {}, ''))), ftb),
        el('h3', {}, 'Last answers read'),
        answers.length ? el('ul', {id: `answers-${c.number}`}, ...answers.map(([i, t]) => el('li', {}, el('a', {href: '#', onclick: (e) => { e.preventDefault(); setCursor(i, true); }}, `frame ${i + 1}`), ' ', t)))
                       : el('p', {class: 'meta'}, 'none yet'));
    }
  }

  // ---- the cursor
  function setCursor(i, reveal) {
    if (!total) return;
    cursor.frame = Math.max(0, Math.min(total - 1, i | 0));
    cursor.tick = frameAt(cursor.frame).tick;
    update(reveal);
  }
  function setCursorTick(t, nearest) {
    if (!isFinite(t)) return;
    if (!total) { cursor.tick = Math.max(0, t); update(true); return; }
    let i = frameAtTick(t);
    if (nearest && i + 1 < total && Math.abs(frameAt(i + 1).tick - t) < Math.abs(frameAt(i).tick - t)) ++i;
    setCursor(i, true);
  }
  function update(reveal) {
    const f = frameAt(cursor.frame);
    readout.textContent = `cursor: frame ${cursor.frame + 1} of ${total}, t=${fmtS(cursor.tick)} s` + (f.gap ? ' (summarised span)' : '');
    if (reveal) {
      const [x0, x1] = charts[0].g.xAxisRange(), x = sec(cursor.tick);
      if (x < x0 || x > x1) { const w = x1 - x0; setWindow(Math.max(0, x - w / 2) / TICK, (Math.max(0, x - w / 2) + w) / TICK); }
    }
    renderFrames();
    renderRegisters();
    placeCursors();
  }
  document.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement || e.ctrlKey || e.metaKey || e.altKey) return;
    const step = e.shiftKey ? 10 : 1;
    const keys = {ArrowRight: () => setCursor(cursor.frame + step, true), ArrowLeft: () => setCursor(cursor.frame - step, true),
      Home: () => setCursor(0, true), End: () => setCursor(total - 1, true), '+': () => zoom(0.5), '=': () => zoom(0.5),
      '-': () => zoom(2), '0': () => setWindow(0, D.shown_to)};
    if (keys[e.key]) { keys[e.key](); e.preventDefault(); }
  });

  // ---- findings
  app.append(el('h2', {id: 'findings'}, `Findings: ${counts.diagnostics} protocol diagnostics, ${counts.sanitizer} sanitizer findings, ` +
    `${counts.divergent_frames} divergent frames, ${counts.divergent_pins} divergent pin levels`));
  if (counts.findings_dropped) app.append(el('p', {class: 'notice'}, `${counts.findings_dropped} more not listed (the page keeps the first of each kind).`));
  if (D.findings.length) {
    const tb = el('tbody', {});
    for (const [kind, name, frame, tick, chip, text, detail] of D.findings)
      tb.append(el('tr', {}, el('td', {}, el('span', {class: 'kind ' + kind}, kind)), el('td', {}, name),
        el('td', {class: 'num'}, frame ? el('a', {href: '#timeline', onclick: () => setCursor(frame - 1, true)}, `frame ${frame}`) : '—'),
        el('td', {class: 'num'}, fmtS(tick)), el('td', {}, chip), el('td', {}, text, detail ? el('details', {}, el('summary', {}, 'more'), el('pre', {}, detail)) : null)));
    app.append(el('table', {id: 'findings-table'}, el('thead', {}, el('tr', {}, ...['kind', 'what', 'frame', 't (s)', 'chip', ''].map((h) => el('th', {}, h)))), tb));
  } else {
    app.append(el('p', {}, 'None: the chips decoded every frame cleanly, no sanitizer rule was broken and the emulator reproduces the trace.'));
  }

  // ---- coverage
  if (D.coverage) {
    const cov = D.coverage, pct = (h, t) => (t ? (100 * h / t) : 100).toFixed(1);
    app.append(el('h2', {id: 'coverage'}, `Interface coverage: ${cov.total[0]} of ${cov.total[1]} points (${pct(...cov.total)} %)`));
    for (const v of cov.variants) {
      const tb = el('tbody', {});
      for (const c of v.categories) {
        const p = c.against ? null : pct(c.hit, c.total);
        tb.append(el('tr', {}, el('td', {}, c.name + (c.against ? ' (to avoid)' : '')), el('td', {class: 'num'}, `${c.hit} / ${c.total}`),
          el('td', {}, p === null ? (c.hit_points.join(', ') || 'none') : el('span', {}, el('span', {class: 'barbox'}, el('span', {class: 'bar', style: `width:${p}%`})), p + ' %')),
          el('td', {}, c.against || !c.missing.length ? '' : el('details', {}, el('summary', {}, `${c.missing.length} never hit`), el('p', {}, c.missing.join(', '))))));
      }
      app.append(el('h3', {}, `${v.variant}: ${v.total[0]} / ${v.total[1]} (${pct(...v.total)} %) — positions ${v.positions.join(', ')}`),
        el('table', {}, el('thead', {}, el('tr', {}, ...['category', 'hit', '', 'missing'].map((h) => el('th', {}, h)))), tb));
      if (v.raised_not_observed.length) app.append(el('p', {class: 'notice'}, 'Raised but never seen by the driver: ' + v.raised_not_observed.join(', ')));
    }
  }

  // ---- campaign
  if (D.campaign) {
    const k = D.campaign;
    app.append(el('h2', {id: 'campaign'}, 'Campaign: ' + k.summary), el('p', {class: 'meta'}, `program: ${k.program.join(' ')} · board: ${k.board} · oracle: ${k.oracle} · points: ${k.points}` + (k.complete ? '' : ' · INCOMPLETE (stopped early)')));
    const byChip = new Map();
    for (const r of k.reruns) { const key = `${r.chain} chip ${r.chip}`; if (!byChip.has(key)) byChip.set(key, []); byChip.get(key).push(r); }
    for (const [key, runs] of byChip) {
      const points = [...new Set(runs.map((r) => r.point))], faults = [...new Set(runs.map((r) => r.fault))];
      const tb = el('tbody', {});
      for (const f of faults)
        tb.append(el('tr', {}, el('th', {}, f), ...points.map((p) => {
          const cell = runs.filter((r) => r.fault === f && r.point === p);
          return el('td', {class: cell.length ? 'v-' + cell[0].verdict + (cell.some((r) => r.fails) ? ' fails' : '') : ''},
            ...cell.map((r) => el('a', {href: `#rerun-${r.index}`, title: r.program}, r.verdict + ' ')));
        })));
      app.append(el('h3', {}, key), el('table', {class: 'matrix'}, el('thead', {}, el('tr', {}, el('th', {}, 'fault \\ point'), ...points.map((p) => el('th', {}, p)))), tb));
    }
    const tb = el('tbody', {});
    for (const r of k.reruns)
      tb.append(el('tr', {id: `rerun-${r.index}`, class: 'v-' + r.verdict}, el('td', {class: 'num'}, r.index), el('td', {}, r.fault), el('td', {}, `${r.chain} chip ${r.chip}`),
        el('td', {}, r.point + (r.after ? ` (after ${r.after})` : '')), el('td', {class: 'num'}, fmtS(r.tick)), el('td', {class: r.fails ? 'fails' : ''}, r.verdict),
        el('td', {}, r.flag_read === null ? '—' : r.flag_read ? 'read' : 'never read'), el('td', {}, r.program + (r.failure ? ' — ' + r.failure : '')),
        el('td', {}, el('code', {}, r.command))));
    app.append(el('h3', {}, 'Reruns and the commands that show them again'),
      el('table', {id: 'reruns'}, el('thead', {}, el('tr', {}, ...['#', 'fault', 'chip', 'point', 't (s)', 'verdict', 'flag', 'program', 'reproduce'].map((h) => el('th', {}, h)))), tb));
  }

  window.l6470emuReport = {frames: () => total, traceFrames: () => D.frames, cursor: () => Object.assign({}, cursor),
    setCursor: (i) => setCursor(i, true), setCursorSeconds: (t) => setCursorTick(Math.round(t / TICK)), frame: frameAt,
    window: () => charts[0].g.xAxisRange()};
  setCursor(0, false);
  window.l6470emuReport.readyMs = performance.now();  // since the navigation began: how long the page took to open
})();
