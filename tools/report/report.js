// The report page's script: lays out the data l6470emu wrote into the page (tools/report_data.hpp)
// and draws it with dygraphs. It computes nothing about the chips: every value shown is in the
// data; this only finds the one under the cursor and formats it. A run of several chains is a
// section per chain on one time axis: one cursor instant, moved frame by frame on the chain last
// used (its boxes, its charts, its rows); the other chains show their state at that instant.
'use strict';
(function () {
  const D = JSON.parse(document.getElementById('report-data').textContent);
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
  const shortName = (text) => text.split(/[ (]/)[0];
  const several = D.chains.length > 1;
  const cursor = {chain: 0, frame: 0, tick: 0};  // the instant, and the frame of the chain the keys move

  // ---- a chain's timeline: entries (runs of repeated frame groups) and summarised gaps, by frame number
  function timeline(C) {
    const S = C.strings, str = (i) => (i < 0 ? '' : S[i]);
    const segs = [];
    for (const [tick, period, reps, first, rows] of C.entries) {
      const lr = rows[rows.length - 1];
      segs.push({first, count: reps * rows.length, start: tick, end: tick + (reps - 1) * period + lr[0] + lr[1], tick, period, reps, rows});
    }
    for (const [from, to, first, frames, commands] of C.gaps) segs.push({first, count: frames, start: from, end: to, gap: true, commands});
    segs.sort((a, b) => a.first - b.first);
    const total = segs.reduce((n, s) => n + s.count, 0);
    if (total !== C.frames) console.error('report: the timeline of ' + C.name + ' holds ' + total + ' frames, the trace ' + C.frames);
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
    const frameBefore = (t) => (last(segTicks, t) < 0 ? -1 : frameAtTick(t));  // -1: no frame yet
    return {str, segs, total, segTicks, frameAt, frameAtTick, frameBefore};
  }

  // ---- the chips' series
  const chainsOf = D.chains.map((C) => {
    const chips = C.chips.map((c) => {
      const st = c.states, ph = c.phase, mo = c.motion;
      return Object.assign(c, {
        st: {t: undelta(st.dt), pos: st.abs_pos, el: st.el_pos, speed: st.speed, status: st.status},
        ph: {t: undelta(ph.dt), a: ph.a, b: ph.b},
        mo: {t: undelta(mo.dt), pos: mo.abs_pos, speed: mo.speed, bits: mo.bits},
        regTicks: c.registers.map((r) => r[0]),
      });
    });
    return Object.assign(timeline(C), {C, chips});
  });

  // ---- header
  const sum = (f) => D.chains.reduce((n, C) => n + f(C), 0);
  const counts = {diagnostics: sum((C) => C.counts.diagnostics), sanitizer: sum((C) => C.counts.sanitizer),
    divergent_frames: sum((C) => C.counts.divergent_frames), divergent_pins: sum((C) => C.counts.divergent_pins),
    findings_dropped: sum((C) => C.counts.findings_dropped)};
  const findingsTotal = counts.diagnostics + counts.sanitizer + counts.divergent_frames + counts.divergent_pins;
  const allFrames = chainsOf.reduce((n, v) => n + v.total, 0), allChips = sum((C) => C.chips.length);
  const traceLine = (C) => `${C.trace.path} (${C.trace.format}) · chain ${C.trace.chain} · ${C.trace.numbering}`;
  const chainTitle = (C) => C.name + (C.where ? ` (${C.where})` : '');
  app.append(el('h1', {}, D.title));
  if (several) app.append(el('p', {class: 'meta'}, `${D.chains.length} chains, one recording each, on one time axis: ` + D.chains.map(chainTitle).join(', ')));
  else app.append(el('p', {class: 'meta'}, traceLine(D.chains[0])), ...D.chains[0].trace.notes.map((n) => el('p', {class: 'meta'}, 'note: ' + n)));
  app.append(el('div', {class: 'badges'}, el('span', {id: 'frame-count'}, `${allFrames} frames`), el('span', {}, `${allChips} chips`),
    several ? el('span', {id: 'chain-count'}, `${D.chains.length} chains`) : null,
    el('span', {}, `${fmtS(Math.max(...D.chains.map((C) => C.end)))} s`), el('span', {}, `${findingsTotal} findings`)));
  for (const C of D.chains)
    if (C.first_divergence) app.append(el('div', {class: 'banner', role: 'alert'}, 'DIVERGED' + (several ? ` on ${C.name}` : '') + ': ' +
      C.first_divergence + ' — from there on the page shows the emulator\'s model of the run, not what the trace holds.'));
  if (D.chains.some((C) => C.summarised)) app.append(el('div', {class: 'notice'}, 'This run is longer than a page shows one by one: grey ' +
    'spans of the timeline marked "frames summarised" stand for frames counted but not listed, and the series keep per time ' +
    'slice their first, last and extreme samples (docs/report.md, "Size").'));
  const sections = several ? D.chains.map((C, ci) => [`chain${ci}`, C.name]) : [['timeline', 'Timeline'], ['chips', 'Chips']];
  app.append(el('nav', {}, ...[...sections, ['findings', `Findings (${findingsTotal})`], ['coverage', 'Coverage'], ['campaign', 'Campaign']]
    .filter(([id]) => (id !== 'coverage' || D.coverage) && (id !== 'campaign' || D.campaign)).map(([id, t]) => el('a', {href: '#' + id}, t))));

  // ---- charts, all on one time axis: a zoom or pan of one is a zoom or pan of all
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
  function chart(div, data, opts, ci) {
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
      clickCallback: (e, x) => setCursorTick(Math.round(x / TICK), true, ci),
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
  const btn = (label, title, f) => el('button', {type: 'button', title, onclick: f}, label);
  const FIELD_MEANING = {MOT_STATUS: ['stopped', 'accelerating', 'decelerating', 'constant speed'], DIR: ['reverse', 'forward'],
    TH_STATUS: ['normal', 'warning', 'bridge shutdown', 'device shutdown']};
  function statusWords(c, status) {  // the fields that are set, by name ("HiZ FWD MOT_STATUS=3 UVLO")
    return c.status_fields.map(([name, bit, width, low]) => {
      const v = (status >> bit) & ((1 << width) - 1);
      return width > 1 ? (v ? `${name}=${v}` : '') : (low ? v === 0 : v === 1) ? name : '';
    }).filter((w) => w).join(' ');
  }

  // ---- a chain's section: its timeline (controls, the lanes chart, the frames around the
  // cursor) and per chip the motion, the phase drive and the registers at the cursor.
  // Element ids are those of a one-chain page, prefixed "chainK-" (K its place) on a page of several.
  function chainSection(V, ci) {
    const {C, chips, str, segs, segTicks, frameAt} = V;
    const P = several ? `chain${ci}-` : '', nChain = chips.length;
    if (several) {
      const f = C.counts.diagnostics + C.counts.sanitizer + C.counts.divergent_frames + C.counts.divergent_pins;
      app.append(el('h2', {id: `chain${ci}`, class: 'chain'}, `Chain ${chainTitle(C)}`), el('p', {class: 'meta'}, traceLine(C)),
        ...C.trace.notes.map((n) => el('p', {class: 'meta'}, 'note: ' + n)),
        el('div', {class: 'badges'}, el('span', {id: P + 'frame-count'}, `${V.total} frames`), el('span', {}, `${nChain} chip${nChain === 1 ? '' : 's'}`),
          el('span', {}, `${fmtS(C.end)} s`), el('span', {}, `${f} finding${f === 1 ? '' : 's'}`)));
    }
    const readout = el('span', {class: 'readout', id: P + 'cursor-readout', 'aria-live': 'polite'});
    const goTime = el('input', {id: P + 'goto-time', type: 'text', inputmode: 'decimal', 'aria-label': `go to time in seconds${several ? ' on ' + C.name : ''}`, placeholder: 't in s'});
    const goFrame = el('input', {id: P + 'goto-frame', type: 'text', inputmode: 'numeric', 'aria-label': `go to frame number${several ? ' of ' + C.name : ''}`, placeholder: 'frame #'});
    goTime.addEventListener('keydown', (e) => { if (e.key === 'Enter') setCursorTick(Math.round(parseFloat(goTime.value) / TICK), false, ci); });
    goFrame.addEventListener('keydown', (e) => { if (e.key === 'Enter') setCursor(parseInt(goFrame.value, 10) - 1, true, ci); });
    app.append(el(several ? 'h3' : 'h2', {id: P + 'timeline'}, 'Timeline'),
      el('div', {class: 'controls'}, goTime, goFrame, btn('−', 'zoom out (-)', () => zoom(2)), btn('+', 'zoom in (+)', () => zoom(0.5)),
        btn('whole run', 'show the whole run (0)', () => setWindow(0, D.shown_to)), readout),
      el('p', {class: 'help'}, '← → previous/next frame · Shift+← → 10 frames · + − zoom around the cursor · 0 whole run · ' +
        'Home/End first/last frame · drag on a chart to zoom, Shift+drag to pan, click to put the cursor there · hover a chip\'s ' +
        'cell for its bytes' + (several ? ' · the keys move the cursor on the chain last used; the other chains show that instant' : '')));
    const lanesDiv = el('div', {class: 'chart', id: P + 'lanes', style: `height:${120 + 95 * nChain}px`});
    app.append(lanesDiv);
    const table = el('table', {class: 'frames', id: P + 'frames'});
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
    function renderFrames(at) {  // the frames around frame `at` (-1: before the first)
      tbody.replaceChildren();
      const from = Math.max(0, at - 8), to = Math.min(V.total, from + 17);
      for (let i = from; i < to; ++i) {
        const f = frameAt(i);
        const tr = el('tr', {class: (i === at ? 'at ' : '') + (f.gap ? 'gap' : (f.flags & 1 ? 'diverged ' : '') + (f.flags & 2 ? 'diagnostic' : '')),
          'data-frame': i + 1, onclick: () => setCursor(i, false, ci)});
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

    // The lanes: per chip BUSY, FLAG, SW (as the emulated chip has them), STCK and STBY (as the trace
    // drove them); above them a row per chip with the frames, drawn under the chart.
    const LANES = ['BUSY', 'FLAG', 'SW', 'STCK', 'STBY'];
    const RIGHT_GAP = 59;  // where the motion charts have their SPEED axis: the time axes line up
    const laneBase = (k, l) => (nChain - 1 - k) * LANES.length + (LANES.length - 1 - l);
    const frameRowY = (k) => nChain * LANES.length + (nChain - 1 - k) + 0.1;
    {
      const changes = [];  // [tick, series, value]
      chips.forEach((c, k) => {
        let prev = -1;
        c.mo.t.forEach((t, i) => {
          const b = c.mo.bits[i], v = [(b >> 2) & 1, (b >> 3) & 1, (b >> 4) & 1];
          const key = v.join('');
          if (key !== prev) v.forEach((x, l) => changes.push([t, k * 5 + l, laneBase(k, l) + 0.7 * x]));
          prev = key;
        });
        changes.push([0, k * 5 + 3, laneBase(k, 3)], [0, k * 5 + 4, laneBase(k, 4) + 0.7]);
        for (const [t, pin, level] of c.inputs) {
          const l = pin === 'STCK' ? 3 : pin === 'STBY' ? 4 : -1;
          if (l >= 0) changes.push([t, k * 5 + l, laneBase(k, l) + 0.7 * level]);
        }
        for (let l = 0; l < 5; ++l) changes.push([D.shown_to, k * 5 + l, null]);
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
      chips.forEach((c, k) => { LANES.forEach((l, li) => ticks.push({v: laneBase(k, li) + 0.35, label: `${c.number} ${l}`}));
        ticks.push({v: frameRowY(k) + 0.4, label: `chip ${c.number}`}); });
      chart(lanesDiv, rows, {
        labels, colors, stepPlot: true, connectSeparatedPoints: true, strokeWidth: 1.5, legend: 'never', rightGap: RIGHT_GAP,
        valueRange: [-0.3, nChain * LANES.length + nChain + 0.2], yAxisLabelWidth: 70,
        axes: {y: {ticker: () => ticks, drawGrid: false}, x: {valueFormatter: (x) => 't=' + x.toFixed(6) + ' s',
          axisLabelFormatter: (x) => x.toPrecision(6).replace(/\.?0+$/, '') + ' s'}},
        underlayCallback: drawFrames,
      }, ci);
    }
    function drawFrames(ctx, area, g) {
      const [x0, x1] = g.xAxisRange(), t0 = x0 / TICK, t1 = x1 / TICK, px = area.w / Math.max(1e-9, x1 - x0);
      const X = (t) => g.toDomXCoord(sec(t)), rowTop = (k) => g.toDomYCoord(frameRowY(k) + 0.8), rowH = (k) => g.toDomYCoord(frameRowY(k)) - rowTop(k);
      ctx.save();
      ctx.font = '11px system-ui, sans-serif';
      let drawn = 0;
      const marks = [];  // [right edge x, row] of each frame drawn, in time order
      for (let j = Math.max(0, last(segTicks, t0)); j < segs.length && segs[j].start <= t1; ++j) {
        const s = segs[j];
        if (s.end < t0) continue;
        if (s.gap || s.count > 1 && (s.end - s.start) * px * TICK < s.count * 3 || drawn > 20000) {  // too dense: a band
          const a = Math.max(area.x, X(s.start)), b = Math.min(area.x + area.w, Math.max(X(s.end), a + 1));
          chips.forEach((c, k) => {
            ctx.fillStyle = s.gap ? '#d9d9d9' : '#c9daf0';
            ctx.fillRect(a, rowTop(k), b - a, rowH(k));
            if (b - a > 60) { ctx.fillStyle = '#1a1a1a'; ctx.fillText(s.gap ? `${s.count} frames summarised` : `${s.count} frames (${s.reps}×)`, a + 3, rowTop(k) + rowH(k) - 4); }
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
            chips.forEach((c, k) => {
              const text = str(row[5 + c.index]);
              ctx.fillStyle = row[4] & 1 ? '#b00020' : row[4] & 2 ? '#b8860b' : !text ? '#8c8c8c' : text.includes(' → ') ? '#0b5394' : '#9a4a00';
              ctx.fillRect(x, rowTop(k), w, rowH(k));
            });
            marks.push([x + w, row]);
          }
        }
      }
      // Labels where there is room before the chip's next label.
      ctx.fillStyle = '#1a1a1a';
      chips.forEach((c, k) => {
        let next = area.x + area.w;
        for (let i = marks.length - 1; i >= 0; --i) {
          const [x, row] = marks[i], text = str(row[5 + c.index]), room = next - x - 6;
          if (!text) continue;
          next = x - row[1] * TICK * px;
          if (room < 40) continue;
          const label = room > 160 ? text : shortName(text);
          ctx.fillText(label.length * 6 > room ? label.slice(0, Math.floor(room / 6)) : label, x + 2, rowTop(k) + rowH(k) - 4);
        }
      });
      // Stimuli (faults, switches, supply...) and findings.
      chips.forEach((c, k) => {
        for (const [t, , kind, text] of c.stimuli) {
          if (t < t0 || t > t1) continue;
          const x = X(t);
          ctx.strokeStyle = '#b00020'; ctx.setLineDash([4, 3]); ctx.beginPath();
          ctx.moveTo(x, g.toDomYCoord(laneBase(k, 0) + 0.9)); ctx.lineTo(x, g.toDomYCoord(laneBase(k, 4) - 0.2)); ctx.stroke();
          ctx.setLineDash([]); ctx.fillStyle = '#b00020'; ctx.fillText('⚡ ' + text, x + 3, g.toDomYCoord(laneBase(k, 0) + 0.95));
        }
      });
      ctx.fillStyle = '#b00020';
      for (const f of C.findings) {
        if (f[3] < t0 || f[3] > t1) continue;
        const x = X(f[3]), y = g.toDomYCoord(nChain * LANES.length + nChain + 0.15);
        ctx.beginPath(); ctx.moveTo(x - 5, y - 7); ctx.lineTo(x + 5, y - 7); ctx.lineTo(x, y); ctx.fill();
      }
      ctx.restore();
    }

    // Per chip: motion, phase drive, registers at the cursor.
    app.append(el(several ? 'h3' : 'h2', {id: P + 'chips'}, 'Chips'));
    const panels = chips.map((c) => {
      const box = el('section', {class: 'chip', id: `${P}chip-${c.number}`, 'aria-label': `${several ? C.name + ' ' : ''}chip ${c.number}`});
      const motionDiv = el('div', {class: 'chart', style: 'height:230px'}), phaseDiv = el('div', {class: 'chart', style: 'height:170px'});
      const regs = el('div', {id: `${P}registers-${c.number}`});
      box.append(el('h3', {}, `${several ? C.name + ' ' : ''}chip ${c.number} (${c.variant}, chain index ${c.index})`),
        el('div', {class: 'chipgrid'}, el('div', {}, motionDiv, phaseDiv,
          el('p', {class: 'help'}, `Phase drive: coil A and B as EL_POS walks the sine, in % of full scale (KVAL/TVAL of the motion phase; ` +
            `sampled every ${(sec(C.phase_step) * 1e6).toFixed(1)} µs while moving; docs/report.md)`)), regs));
      app.append(box);
      const m = c.mo;
      chart(motionDiv, m.t.map((t, i) => [sec(t), m.pos[i], m.speed[i] * STEP_PER_S]), {
        labels: ['t', 'ABS_POS', 'SPEED (step/s)'], colors: ['#0b5394', '#9a4a00'], ylabel: `ABS_POS (1/${c.motion.microsteps} step)`,
        y2label: 'step/s', series: {'SPEED (step/s)': {axis: 'y2'}}, strokeWidth: 1.5, yAxisLabelWidth: 70,
        axes: {x: {valueFormatter: (x) => 't=' + x.toFixed(6) + ' s', axisLabelFormatter: (x) => x.toPrecision(6).replace(/\.?0+$/, '') + ' s'},
               y2: {independentTicks: true, axisLabelWidth: 50}},
      }, ci);
      const p = c.ph;
      chart(phaseDiv, p.t.map((t, i) => [sec(t), p.a[i] / 10, p.b[i] / 10]).concat([[sec(D.shown_to), p.a[p.a.length - 1] / 10, p.b[p.b.length - 1] / 10]]), {
        labels: ['t', 'coil A %', 'coil B %'], colors: ['#5b2a86', '#1e6b30'], stepPlot: true, valueRange: [-105, 105], yAxisLabelWidth: 70,
        ylabel: 'phase drive %', strokeWidth: 1.5, rightGap: RIGHT_GAP,
      }, ci);
      return {c, regs};
    });
    function renderRegisters(i) {  // after frame i (-1: before the first), or at the cursor's instant when later
      const f = i >= 0 ? frameAt(i) : null;
      const at = !f || f.gap ? cursor.tick : Math.max(cursor.tick, f.tick + f.dur);
      const when = !f ? `Before the first frame, at t=${fmtS(at)} s` : f.gap || at === f.tick + f.dur
        ? `After frame ${i + 1} (its CS rising edge, t=${fmtS(at)} s)` : `At t=${fmtS(at)} s, after frame ${i + 1}`;
      for (const {c, regs} of panels) {
        const si = Math.max(0, last(c.st.t, at));
        const status = c.st.status[si];
        const values = new Map();  // address -> [name, value text, meaning]
        for (let r = 0; r < c.registers.length && c.registers[r][0] <= at; ++r) {
          const [, addr, name, value, text] = c.registers[r];
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
            el('td', {id: `${P}reg-${c.number}-${name}`, class: 'num'}, live ? value : hex(value, 1)), el('td', {}, meaning)));
        }
        const ftb = el('tbody', {});
        for (const [name, bit, width, low] of c.status_fields) {
          const v = (status >> bit) & ((1 << width) - 1), active = width === 1 && (low ? v === 0 : v === 1) && !['DIR', 'HiZ'].includes(name);
          const meaning = FIELD_MEANING[name] ? FIELD_MEANING[name][v] : width === 1 ? (active ? 'active' + (low ? ' (low)' : '') : '') : '';
          ftb.append(el('tr', {class: active ? 'active-field' : ''}, el('td', {}, name), el('td', {class: 'num'}, width > 1 ? `${bit + width - 1}:${bit}` : bit),
            el('td', {class: 'num', id: `${P}field-${c.number}-${name}`}, v), el('td', {}, meaning)));
        }
        const answers = [];  // the chip's last answers before the cursor, as the host read them
        for (let j = i, seen = new Set(); j >= 0 && j > i - 3000 && answers.length < 4; --j) {
          const g = frameAt(j);
          if (g.gap) { j = g.gap.first; continue; }
          const t = g.texts[c.index];
          if (t.includes(' → ') && !seen.has(t.split(' → ')[0])) { seen.add(t.split(' → ')[0]); answers.push([j, t]); }
        }
        regs.replaceChildren(
          el('p', {class: 'meta'}, `${when}; state sampled at t=${fmtS(c.st.t[si])} s`),
          el('p', {}, 'STATUS ', el('code', {id: `${P}status-${c.number}`}, hex(status, 4))),
          el('table', {class: 'regs'}, el('thead', {}, el('tr', {}, el('th', {}, 'register'), el('th', {}, 'addr'), el('th', {class: 'num'}, 'value'), el('th', {}, 'meaning'))), tb),
          el('h3', {}, 'STATUS fields'),
          el('table', {class: 'regs'}, el('thead', {}, el('tr', {}, el('th', {}, 'field'), el('th', {class: 'num'}, 'bit'), el('th', {class: 'num'}, 'value'), el('th', {}, ''))), ftb),
          el('h3', {}, 'Last answers read'),
          answers.length ? el('ul', {id: `${P}answers-${c.number}`}, ...answers.map(([j, t]) => el('li', {}, el('a', {href: '#', onclick: (e) => { e.preventDefault(); setCursor(j, true, ci); }}, `frame ${j + 1}`), ' ', t)))
                         : el('p', {class: 'meta'}, 'none yet'));
      }
    }
    function render() {  // the chain at the cursor: its own frame when its keys move it, else its frame at the instant
      const mine = cursor.chain === ci;
      const i = !V.total ? -1 : mine ? cursor.frame : V.frameBefore(cursor.tick);
      const f = i >= 0 ? frameAt(i) : null;
      readout.textContent = !several ? `cursor: frame ${cursor.frame + 1} of ${V.total}, t=${fmtS(cursor.tick)} s` + (f && f.gap ? ' (summarised span)' : '')
        : `cursor: ${i >= 0 ? `frame ${i + 1} of ${V.total}` : `before the first of ${V.total} frames`}, t=${fmtS(cursor.tick)} s` +
          (f && f.gap ? ' (summarised span)' : '') + (mine ? ' · ← → move here' : '');
      renderFrames(i);
      renderRegisters(i);
    }
    return Object.assign(V, {render});
  }
  const views = chainsOf.map(chainSection);

  // ---- the cursor: frame i of chain ci, or the frame at tick t of it
  function setCursor(i, reveal, ci = cursor.chain) {
    const V = views[ci];
    if (!V.total) return;
    cursor.chain = ci;
    cursor.frame = Math.max(0, Math.min(V.total - 1, i | 0));
    cursor.tick = V.frameAt(cursor.frame).tick;
    update(reveal);
  }
  function setCursorTick(t, nearest, ci = cursor.chain) {
    if (!isFinite(t)) return;
    const V = views[ci];
    if (!V.total) { cursor.chain = ci; cursor.tick = Math.max(0, t); update(true); return; }
    let i = V.frameAtTick(t);
    if (nearest && i + 1 < V.total && Math.abs(V.frameAt(i + 1).tick - t) < Math.abs(V.frameAt(i).tick - t)) ++i;
    setCursor(i, true, ci);
  }
  function update(reveal) {
    if (reveal) {
      const [x0, x1] = charts[0].g.xAxisRange(), x = sec(cursor.tick);
      if (x < x0 || x > x1) { const w = x1 - x0; setWindow(Math.max(0, x - w / 2) / TICK, (Math.max(0, x - w / 2) + w) / TICK); }
    }
    for (const V of views) V.render();
    placeCursors();
  }
  document.addEventListener('keydown', (e) => {
    if (e.target instanceof HTMLInputElement || e.ctrlKey || e.metaKey || e.altKey) return;
    const step = e.shiftKey ? 10 : 1;
    const keys = {ArrowRight: () => setCursor(cursor.frame + step, true), ArrowLeft: () => setCursor(cursor.frame - step, true),
      Home: () => setCursor(0, true), End: () => setCursor(views[cursor.chain].total - 1, true), '+': () => zoom(0.5), '=': () => zoom(0.5),
      '-': () => zoom(2), '0': () => setWindow(0, D.shown_to)};
    if (keys[e.key]) { keys[e.key](); e.preventDefault(); }
  });

  // ---- findings, every chain's in time order
  app.append(el('h2', {id: 'findings'}, `Findings: ${counts.diagnostics} protocol diagnostics, ${counts.sanitizer} sanitizer findings, ` +
    `${counts.divergent_frames} divergent frames, ${counts.divergent_pins} divergent pin levels`));
  if (counts.findings_dropped) app.append(el('p', {class: 'notice'}, `${counts.findings_dropped} more not listed (the page keeps the first of each kind).`));
  const findings = [];
  D.chains.forEach((C, ci) => { for (const f of C.findings) findings.push([ci, f]); });
  findings.sort((a, b) => a[1][3] - b[1][3] || a[0] - b[0]);
  if (findings.length) {
    const tb = el('tbody', {});
    for (const [ci, [kind, name, frame, tick, chip, text, detail]] of findings)
      tb.append(el('tr', {}, el('td', {}, el('span', {class: 'kind ' + kind}, kind)), el('td', {}, name),
        several ? el('td', {}, el('a', {href: `#chain${ci}`}, D.chains[ci].name)) : null,
        el('td', {class: 'num'}, frame ? el('a', {href: several ? `#chain${ci}-timeline` : '#timeline', onclick: () => setCursor(frame - 1, true, ci)}, `frame ${frame}`) : '—'),
        el('td', {class: 'num'}, fmtS(tick)), el('td', {}, chip), el('td', {}, text, detail ? el('details', {}, el('summary', {}, 'more'), el('pre', {}, detail)) : null)));
    app.append(el('table', {id: 'findings-table'}, el('thead', {}, el('tr', {}, ...['kind', 'what', ...(several ? ['chain'] : []), 'frame', 't (s)', 'chip', '']
      .map((h) => el('th', {}, h)))), tb));
  } else {
    app.append(el('p', {}, 'None: the chips decoded every frame cleanly, no sanitizer rule was broken and the emulator reproduces the trace' +
      (several ? 's.' : '.')));
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

  const chainOf = (ci) => (ci === undefined ? cursor.chain : ci);
  window.l6470emuReport = {frames: () => allFrames, traceFrames: () => sum((C) => C.frames), cursor: () => Object.assign({}, cursor),
    chains: () => views.length, chainFrames: (ci) => views[ci].total, chainName: (ci) => D.chains[ci].name,
    setCursor: (i, ci) => setCursor(i, true, chainOf(ci)), setCursorSeconds: (t, ci) => setCursorTick(Math.round(t / TICK), false, chainOf(ci)),
    frame: (i, ci) => views[chainOf(ci)].frameAt(i), window: () => charts[0].g.xAxisRange()};
  const first = Math.max(0, views.findIndex((V) => V.total > 0));
  if (views[first].total) setCursor(0, false, first); else if (several) update(false);
  window.l6470emuReport.readyMs = performance.now();  // since the navigation began: how long the page took to open
})();
