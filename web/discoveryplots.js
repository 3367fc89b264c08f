// uPlot chart of a discovery report: the recording against the baseline's
// and the augmented model's free-run simulations, for one DOF of one
// validation run. Live charts: window.__plots['disc:<point>:<i>'].

import uPlot from '/node_modules/uplot/dist/uPlot.esm.js';
import { axisBase, autoSize, register, tick } from './plots.js';
import { exact } from './runplots.js';

const COLORS = { measured: '#1c2430', before: '#b3261e', after: '#2e9e5b' };
const clean = (xs) => (xs || []).map((v) => (v != null && Number.isFinite(v) ? v : null));

/** series {t, measured, before, after}: simulation before and after discovery. */
export function beforeAfterPlot(name, host, series, { unit = '', sync, group, height = 220 } = {}) {
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    scales: { x: { time: false } },
    series: [
      { label: 't', value: (u, v) => (v == null ? '–' : `${exact(v)} s`) },
      { label: 'recorded', stroke: COLORS.measured, width: 1.4 },
      { label: 'baseline (simulated)', stroke: COLORS.before, width: 1, dash: [6, 3] },
      { label: 'with discovered physics', stroke: COLORS.after, width: 1.3 },
    ].map((s, i) => (i === 0 ? s : { ...s, points: { show: false }, value: (u, v) => exact(v) })),
    axes: [
      { ...axisBase, label: 'time [s]', labelSize: 18, size: 36 },
      { ...axisBase, label: unit, labelSize: 16, size: 62, values: (self, ticks) => ticks.map((v) => tick(v)) },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 }, sync: sync ? { key: sync, setSeries: true } : undefined },
    legend: { live: true },
    hooks: { setScale: group ? [group.hook] : [] },
  };
  const data = [series.t, clean(series.measured), clean(series.before), clean(series.after)];
  host.replaceChildren();
  const u = new uPlot(opts, data, host);
  if (group) group.add(u);
  return register(name, u, autoSize(u, host, height));
}
