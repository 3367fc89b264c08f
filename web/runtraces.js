// Time plot of a run (#/runs/{id}, "Recorded channels"): every logged
// channel, one strip per unit (forces, moments, velocities, rates, pose,
// commands) sharing the time axis and the cursor. Drag on a strip selects a
// window: its statistics (mean, std, RMS, min, max over every sample) are
// shown, it can be zoomed into (re-read at full resolution) and it is kept
// for the model page's overlay compare of this run. Long runs come as each
// bucket's minimum and maximum (the envelope). Each strip exports PNG,
// SVG, CSV. Live charts: window.__plots['trace:<unit>'].

import uPlot from '/node_modules/uplot/dist/uPlot.esm.js';
import { api } from './api.js';
import { h, fill } from './forms.js';
import { fmt, unitLabel } from './format.js';
import { PALETTE, axisBase, autoSize, register, tick } from './plots.js';
import { exact } from './runplots.js';
import { exportBar, uplotExportable } from './plotexport.js';

/** Where the window chosen on a run page is kept for the compare view. */
export function selectedWindow(runId) {
  try {
    const w = JSON.parse(sessionStorage.getItem(`seatrial.window.${runId}`) || 'null');
    return w && Number.isFinite(w.from_s) && Number.isFinite(w.to_s) ? w : null;
  } catch { return null; }
}
function keepWindow(runId, w) {
  if (w) sessionStorage.setItem(`seatrial.window.${runId}`, JSON.stringify(w));
  else sessionStorage.removeItem(`seatrial.window.${runId}`);
}

const GROUP_LABEL = {
  N: 'forces [N]', 'N·m': 'moments [N·m]', 'm/s': 'velocities [m/s]', 'rad/s': 'angular rates [rad/s]', m: 'position [m]', rad: 'attitude and heading [rad]', '-': 'commands and other channels [–]',
};

/** The section: a host the caller mounts, then `draw()`. */
export function runTracesSection(run) {
  const host = h('div', { class: 'trace-strips', 'data-testid': 'run-traces' });
  const status = h('p', { class: 'hint', 'data-testid': 'traces-status' }, 'Loading the recorded channels…');
  const statsHost = h('div', { 'data-testid': 'window-stats' });
  const sync = `traces-${run.id}`;
  let charts = [];
  let current = null; // the answer drawn
  let busy = false;

  async function load(from, to) {
    const q = new URLSearchParams({ points: '1600' });
    if (from != null) q.set('from_s', String(from));
    if (to != null) q.set('to_s', String(to));
    return api.runTraces(run.id, q.toString());
  }

  function describe(tr) {
    const [a, b] = tr.window_s;
    status.textContent = `${tr.channels.length} channels · ${fmt(a)}–${fmt(b)} s · ${tr.n_samples} samples at ${exact(tr.sample_rate_hz)} Hz`
      + (tr.stride > 1 ? ` · shown as min/max of every ${tr.stride} samples (zoom in for every sample)` : ' · every sample shown')
      + ' · drag across a strip to select a window, double-click to reset';
  }

  function statsTable(tr, w) {
    return h('div', { class: 'card window-card' },
      h('div', { class: 'window-head' },
        h('b', { 'data-testid': 'window-range' }, `Window ${fmt(w.from_s)}–${fmt(w.to_s)} s (${fmt(w.to_s - w.from_s)} s, ${tr.n_samples} samples)`),
        h('span', { class: 'actions' },
          h('button', { type: 'button', class: 'btn small', 'data-testid': 'window-zoom', onClick: () => zoomTo(w) }, 'Zoom to window'),
          h('button', { type: 'button', class: 'btn small', 'data-testid': 'window-clear', onClick: () => { keepWindow(run.id, null); fill(statsHost); redraw(null); } }, 'Clear'))),
      h('p', { class: 'hint' }, 'Kept for this run: the model page’s “Compare models on a run” can show the same window.'),
      h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact', 'data-testid': 'window-stats-table' },
        h('thead', null, h('tr', null, ['Channel', 'Unit', 'Mean', 'Std', 'RMS', 'Min', 'Max', 'Valid samples'].map((c, i) => h('th', { class: i > 1 ? 'num' : null }, c)))),
        h('tbody', null, tr.channels.map((c) => h('tr', { 'data-channel': c.name },
          h('td', { class: 'mono' }, c.name), h('td', null, unitLabel(c.unit)),
          ['mean', 'std', 'rms', 'min', 'max'].map((k) => h('td', { class: 'num' }, c.stats[k] == null ? '–' : exact(c.stats[k]))),
          h('td', { class: 'num' }, String(c.stats.n))))))));
  }

  async function select(from, to) {
    if (busy || !(to > from)) return;
    busy = true;
    try {
      const tr = await load(from, to);
      const w = { from_s: tr.window_s[0], to_s: tr.window_s[1] };
      keepWindow(run.id, w);
      fill(statsHost, statsTable(tr, w));
    } catch (e) {
      fill(statsHost, h('p', { class: 'error-text' }, `Window: ${e.message}`));
    } finally { busy = false; }
  }

  async function zoomTo(w) {
    try { redraw(await load(w.from_s, w.to_s)); } catch (e) { status.textContent = `Recorded channels: ${e.message}`; }
  }

  async function redraw(tr) {
    if (!tr) tr = await load();
    current = tr;
    describe(tr);
    for (const u of charts) if (u.__stop) u.__stop();
    charts = [];
    const units = [...new Set(tr.channels.map((c) => c.unit))];
    const order = Object.keys(GROUP_LABEL);
    units.sort((a, b) => (order.indexOf(a) + 99 * (order.indexOf(a) < 0)) - (order.indexOf(b) + 99 * (order.indexOf(b) < 0)));
    let busyScale = false;
    const follow = (u, key) => {
      if (key !== 'x' || busyScale) return;
      busyScale = true;
      try { for (const o of charts) if (o !== u && o.scales && o.scales.x) o.setScale('x', { min: u.scales.x.min, max: u.scales.x.max }); } finally { busyScale = false; }
    };
    fill(host, units.map((unit) => {
      const cols = tr.channels.filter((c) => c.unit === unit);
      const strip = h('div', { class: 'plot', 'data-testid': 'trace-plot', 'data-unit': unit });
      let chart = null;
      const title = `${run.name} — ${GROUP_LABEL[unit] || unitLabel(unit)}`;
      const card = h('div', { class: 'plot-card trace-card' },
        h('h3', null, GROUP_LABEL[unit] || unitLabel(unit), ' ', exportBar(() => (chart ? uplotExportable(chart, title, { xLabel: 'time [s]' }) : null), 'trace-export')),
        strip);
      queueMicrotask(() => {
        const opts = {
          width: Math.max(280, Math.floor(strip.clientWidth)),
          height: 170,
          scales: { x: { time: false }, y: { range: (u, mn, mx) => (mn == null || mx == null || !(mx - mn > 1e-12) ? [(mn ?? 0) - 1, (mx ?? 0) + 1] : uPlot.rangeNum(mn, mx, 0.08, true)) } },
          series: [
            { label: 't [s]', value: (u, v) => (v == null ? '–' : `${fmt(v, 2)} s`) },
            ...cols.map((c, i) => ({ label: `${c.name} [${unitLabel(c.unit) || '–'}]`, stroke: PALETTE[(tr.channels.indexOf(c)) % PALETTE.length], width: 1, points: { show: false }, spanGaps: false, value: (u, v) => (v == null ? '–' : exact(v)), _i: i })),
          ],
          axes: [
            { ...axisBase, label: 'time [s]', labelSize: 18, size: 34 },
            { ...axisBase, label: unitLabel(unit) || '–', labelSize: 16, size: 58, values: (self, ticks) => ticks.map((v) => tick(v)) },
          ],
          cursor: { drag: { x: true, y: false, setScale: false }, sync: { key: sync }, points: { size: 4 } },
          legend: { live: true },
          hooks: {
            setScale: [follow],
            setSelect: [(u) => {
              if (u.select.width < 3) return;
              const a = u.posToVal(u.select.left, 'x');
              const b = u.posToVal(u.select.left + u.select.width, 'x');
              select(a, b);
            }],
          },
        };
        const data = [tr.time_s, ...cols.map((c) => c.values)];
        strip.replaceChildren();
        chart = new uPlot(opts, data, strip);
        strip.addEventListener('dblclick', () => { if (current && (current.window_s[0] > current.record_s[0] || current.window_s[1] < current.record_s[1])) redraw(null); });
        charts.push(register(`trace:${unit}`, chart, autoSize(chart, strip, 170)));
      });
      return card;
    }));
  }

  const el = h('section', { class: 'traces', 'aria-label': 'Recorded channels' },
    h('h2', null, 'Recorded channels ', h('span', { class: 'hint' }, 'every logged input and output over time')),
    status, statsHost, host);

  return {
    el,
    async draw() {
      try {
        await redraw(null);
        const w = selectedWindow(run.id);
        if (w) select(w.from_s, w.to_s);
      } catch (e) {
        status.textContent = `Recorded channels: ${e.status ? `${e.status} · ` : ''}${e.message}`;
      }
    },
    destroy() { for (const u of charts) if (u.__stop) u.__stop(); },
  };
}
