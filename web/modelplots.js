// uPlot charts of a model's validation: predicted versus measured output over
// time (measured, 1-step, k-step, free runs restarted every 10 s, free-run
// simulation) and the residual autocorrelation with its confidence band. A
// prediction that diverged stops where it left the plausible range (null from
// there on). The series come decimated from the server. Plots of one
// validation run share the cursor and the zoom.
// Live charts: window.__plots['pvm:<run>:<channel>'], ['acf:<run>:<channel>'].

import uPlot from '/node_modules/uplot/dist/uPlot.esm.js';
import { axisBase, autoSize, register, tick } from './plots.js';
import { exact } from './runplots.js';

const COLORS = { measured: '#1c2430', one: '#1f6fb5', k: '#e08a1e', restarted: '#8e44ad', sim: '#2e9e5b', bound: '#b3261e' };

const clean = (xs) => xs.map((v) => (v != null && Number.isFinite(v) ? v : null));

/** A group of time plots whose x range moves together (drag-zoom, double-click reset). */
export function zoomGroup() {
  const members = [];
  let busy = false;
  return {
    add(u) { members.push(u); },
    hook: (u, key) => {
      if (key !== 'x' || busy) return;
      busy = true;
      try {
        for (const o of members) {
          if (o !== u && o.scales && o.scales.x) o.setScale('x', { min: u.scales.x.min, max: u.scales.x.max });
        }
      } finally { busy = false; }
    },
  };
}

/**
 * Measured vs predicted for one channel.
 *   plot  {time_s, measured, one_step, k_step, restarted, simulated}
 *   k     the k-step horizon (legend)
 *   restart  the restart period (s) of the restarted free runs (legend)
 *   sync  cursor sync key shared by the channels of one run
 */
export function predictionPlot(name, host, plot, { k, restart, unit = '', sync, group, height = 220 } = {}) {
  const series = [
    { label: 't', value: (u, v) => (v == null ? '–' : `${exact(v)} s`) },
    { label: 'measured', stroke: COLORS.measured, width: 1.4 },
    { label: '1-step', stroke: COLORS.one, width: 1 },
    { label: `${k || 'k'}-step`, stroke: COLORS.k, width: 1, dash: [6, 3] },
    { label: `restarted ${restart != null ? `${Number(restart.toFixed(1))} s` : ''}`.trim(), stroke: COLORS.restarted, width: 1, dash: [2, 2] },
    { label: 'simulated', stroke: COLORS.sim, width: 1.2 },
  ].map((s, i) => (i === 0 ? s : { ...s, points: { show: false }, spanGaps: false, value: (u, v) => exact(v) }));
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    scales: {
      x: { time: false },
      y: { range: (u, min, max) => (min == null || max == null || !(max - min > 1e-12) ? [(min ?? 0) - 1, (max ?? 0) + 1] : uPlot.rangeNum(min, max, 0.08, true)) },
    },
    series,
    axes: [
      { ...axisBase, label: 'time [s]', labelSize: 18, size: 36 },
      { ...axisBase, label: unit, labelSize: 16, size: 62, values: (self, ticks) => ticks.map((v) => tick(v)) },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 }, sync: sync ? { key: sync, setSeries: true } : undefined },
    legend: { live: true },
    hooks: { setScale: group ? [group.hook] : [] },
  };
  const none = plot.time_s.map(() => null);
  const data = [plot.time_s, clean(plot.measured), clean(plot.one_step), clean(plot.k_step), clean(plot.restarted || none), clean(plot.simulated)];
  host.replaceChildren();
  const u = new uPlot(opts, data, host);
  if (group) group.add(u);
  return register(name, u, autoSize(u, host, height));
}

/** Normalized residual autocorrelation r(lag) as stems, with ± its bound per lag. */
export function autocorrelationPlot(name, host, ac, { height = 200 } = {}) {
  const lags = ac.lags;
  const bars = uPlot.paths && uPlot.paths.bars ? uPlot.paths.bars({ size: [0.35, 6] }) : undefined;
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    scales: {
      x: { time: false, range: (u, min, max) => [(min ?? 0) - 0.5, (max ?? 1) + 0.5] },
      y: { range: (u, min, max) => [Math.min(-0.2, (min ?? 0) * 1.1), 1.05] },
    },
    series: [
      { label: 'lag', value: (u, v) => (v == null ? '–' : `${v} samples`) },
      { label: 'r(lag)', stroke: COLORS.one, fill: 'rgba(31,111,181,.35)', width: 1, paths: bars, points: { show: !bars, size: 5 }, value: (u, v) => exact(v) },
      { label: `+bound (${Math.round((ac.confidence || 0.95) * 100)} %)`, stroke: COLORS.bound, width: 1, dash: [5, 4], points: { show: false }, value: (u, v) => exact(v) },
      { label: '−bound', stroke: COLORS.bound, width: 1, dash: [5, 4], points: { show: false }, value: (u, v) => exact(v) },
    ],
    axes: [
      { ...axisBase, label: 'lag [samples]', labelSize: 18, size: 36 },
      { ...axisBase, label: 'autocorrelation', labelSize: 16, size: 52, values: (self, ticks) => ticks.map((v) => tick(v)) },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 } },
    legend: { live: true },
  };
  // Lag 0 has no bound (r(0) = 1 by definition).
  const b = ac.bounds.map((v, i) => (i === 0 || v == null ? null : v));
  const data = [lags, clean(ac.values), b, b.map((v) => (v == null ? null : -v))];
  host.replaceChildren();
  const u = new uPlot(opts, data, host);
  return register(name, u, autoSize(u, host, height));
}
