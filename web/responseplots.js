// uPlot charts of a model's responses: step/impulse over time, the
// Hankel singular values as log-scale bars, the input–residual
// cross-correlation as stems with its confidence band, and the overlay of
// several models' predictions on one run.
// Live charts: window.__plots.{step, hankel, xcorr, compare, compareXcorr<i>}.

import uPlot from '/node_modules/uplot/dist/uPlot.esm.js';
import { PALETTE, axisBase, autoSize, register, tick } from './plots.js';
import { exact } from './runplots.js';

const clean = (xs) => xs.map((v) => (v != null && Number.isFinite(v) ? v : null));
const linRange = (u, min, max) => (min == null || max == null || !(max - min > 1e-12) ? [(min ?? 0) - 1, (max ?? 0) + 1] : uPlot.rangeNum(min, max, 0.08, true));
const logTicks = (self, ticks) => ticks.map((v) => (v == null ? '' : v.toExponential(0).replace('e+', 'e').replace('-', '\u2212')));

/** One series per response: `series` [{label, values}], time in s. */
export function timeResponsePlot(host, time, series, { yLabel, height = 240, name = 'step' } = {}) {
  const opts = {
    width: Math.max(280, Math.floor(host.clientWidth)),
    height,
    scales: { x: { time: false }, y: { range: linRange } },
    series: [
      { label: 'time [s]', value: (u, v) => (v == null ? '–' : `${exact(v)} s`) },
      ...series.map((s, i) => ({ label: s.label, stroke: s.color || PALETTE[i % PALETTE.length], width: s.width || 1.4, dash: s.dash, points: { show: false }, spanGaps: false, value: (u, v) => exact(v) })),
    ],
    axes: [
      { ...axisBase, label: 'time [s]', labelSize: 18, size: 34 },
      { ...axisBase, label: yLabel, labelSize: 16, size: 62, values: (self, ticks) => ticks.map((v) => tick(v)) },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 } },
    legend: { live: true },
  };
  host.replaceChildren();
  const u = new uPlot(opts, [time, ...series.map((s) => clean(s.values))], host);
  return register(name, u, autoSize(u, host, height));
}

/**
 * Singular values σᵢ as bars on a log scale; `marks` colours the first
 * `order` bars (the kept states) apart from the rest.
 */
export function singularBarsPlot(host, values, { order = null, label = 'σᵢ', yLabel = 'singular value', height = 230, name = 'hankel' } = {}) {
  const x = values.map((_, i) => i + 1);
  const positive = values.filter((v) => v > 0);
  const floor = positive.length ? Math.min(...positive) / 3 : 1e-12;
  const kept = values.map((v, i) => (order == null || i < order ? Math.max(v, floor) : null));
  const rest = values.map((v, i) => (order != null && i >= order ? Math.max(v, floor) : null));
  const bars = uPlot.paths.bars({ size: [0.6, 40] });
  const opts = {
    width: Math.max(280, Math.floor(host.clientWidth)),
    height,
    scales: {
      x: { time: false, range: (u, mn, mx) => [0.4, values.length + 0.6] },
      y: { distr: 3, range: (u, mn, mx) => uPlot.rangeLog(floor, Math.max(...values, floor * 10), 10, true) },
    },
    series: [
      { label: 'i', value: (u, v) => (v == null ? '–' : `σ${v}`) },
      { label: order != null ? `${label}, kept (order ${order})` : label, stroke: '#1f6fb5', fill: 'rgba(31,111,181,.55)', width: 1, paths: bars, points: { show: false }, value: (u, v, si, idx) => (idx == null || kept[idx] == null ? '–' : exact(values[idx])) },
      ...(order != null ? [{ label: `${label} beyond the order`, stroke: '#9aa3ad', fill: 'rgba(154,163,173,.55)', width: 1, paths: bars, points: { show: false }, value: (u, v, si, idx) => (idx == null || rest[idx] == null ? '–' : exact(values[idx])) }] : []),
    ],
    axes: [
      { ...axisBase, label: 'index i', labelSize: 18, size: 34, incrs: [1, 2, 5, 10, 20, 50], values: (self, ticks) => ticks.map((v) => (Number.isInteger(v) ? String(v) : '')) },
      { ...axisBase, label: yLabel, labelSize: 16, size: 62, values: logTicks },
    ],
    cursor: { points: { show: false } },
    legend: { live: true },
  };
  host.replaceChildren();
  const u = new uPlot(opts, order != null ? [x, kept, rest] : [x, kept], host);
  return register(name, u, autoSize(u, host, height));
}

/** Cross-correlation r(τ) as stems with ± its pointwise bound. */
export function crossCorrelationPlot(host, cc, { confidence = 0.99, height = 220, h = null, name = 'xcorr' } = {}) {
  const bars = uPlot.paths.bars({ size: [0.3, 6] });
  const b = cc.lags.map(() => cc.bound);
  const pct = Math.round(confidence * 100);
  const opts = {
    width: Math.max(280, Math.floor(host.clientWidth)),
    height,
    scales: { x: { time: false }, y: { range: (u, mn, mx) => { const a = Math.max(Math.abs(mn ?? 0), Math.abs(mx ?? 0), cc.bound * 1.5); return [-a * 1.1, a * 1.1]; } } },
    series: [
      { label: 'lag τ', value: (u, v) => (v == null ? '–' : `${v} samples${h ? ` (${exact(v * h)} s)` : ''}`) },
      { label: `r(τ) ${cc.input} → residual`, stroke: '#1f6fb5', fill: 'rgba(31,111,181,.45)', width: 1, paths: bars, points: { show: false }, value: (u, v) => exact(v) },
      { label: `+${pct} % bound`, stroke: '#b3261e', width: 1, dash: [5, 4], points: { show: false }, value: (u, v) => exact(v) },
      { label: `−${pct} % bound`, stroke: '#b3261e', width: 1, dash: [5, 4], points: { show: false }, value: (u, v) => exact(v) },
    ],
    axes: [
      { ...axisBase, label: 'lag τ [samples] (τ > 0: residual after the input)', labelSize: 18, size: 34 },
      { ...axisBase, label: 'cross-correlation [-]', labelSize: 16, size: 56, values: (self, ticks) => ticks.map((v) => tick(v)) },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 } },
    legend: { live: true },
  };
  host.replaceChildren();
  const u = new uPlot(opts, [cc.lags, clean(cc.values), b, b.map((v) => -v)], host);
  return register(name, u, autoSize(u, host, height));
}
