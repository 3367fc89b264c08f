// uPlot charts of a run's quality report: spectra on a log frequency axis
// (input/output PSDs, coherence, H1 magnitude and phase) and the regressor's
// singular values. Long spectra are decimated for display (decimate.js) and
// re-densified inside a zoomed range; legends always show the exact bin
// under the cursor. Live charts: window.__plots.{runPsd, runCoherence,
// runH1mag, runH1phase, runSv}.

import uPlot from '/node_modules/uplot/dist/uPlot.esm.js';
import { PALETTE, axisBase, autoSize, register, tick, hexA } from './plots.js';
import { logDecimate, mergeSorted } from './decimate.js';

const MINUS = '\u2212';

/** A bin's value with 6 significant digits: what the report holds, not a rounded display. */
export function exact(v) {
  if (v == null || typeof v !== 'number' || Number.isNaN(v)) return '–';
  if (!Number.isFinite(v)) return v > 0 ? '∞' : `${MINUS}∞`;
  if (v === 0) return '0';
  const a = Math.abs(v);
  const s = a >= 1e6 || a < 1e-3 ? v.toExponential(5).replace(/\.?0+e/, 'e').replace('e+', 'e') : String(Number(v.toPrecision(6)));
  return s.replace(/-/g, MINUS);
}

/**
 * Labels of a log frequency axis: 1-2-5 per decade when a decade is wide
 * enough, else decades only (grid lines stay at every tick).
 */
function logLabels(self, splits, axisIdx) {
  const key = self.axes[axisIdx].scale;
  const decade = Math.abs(self.valToPos(10, key) - self.valToPos(1, key));
  const marks = decade >= 700 ? [1, 2, 3, 4, 5, 6, 7, 8, 9] : decade >= 150 ? [1, 2, 5] : decade >= 60 ? [1, 3] : [1];
  return splits.map((v) => {
    if (v == null || !(v > 0)) return null;
    const m = v / 10 ** Math.floor(Math.log10(v) + 1e-9);
    return marks.some((k) => Math.abs(m - k) < 1e-6) ? v : null;
  });
}

const logTicks = (self, ticks) => ticks.map((v) => (v == null ? '' : v.toExponential(0).replace('e+', 'e').replace('-', MINUS)));

/** Draw inside the plotting area only. */
function clip(u, fn) {
  const { ctx } = u;
  const { top, height, left, width } = u.bbox;
  ctx.save();
  ctx.beginPath();
  ctx.rect(left, top, width, height);
  ctx.clip();
  fn(ctx, top, height, left, width);
  ctx.restore();
}

/** Dashed horizontal reference lines with a label, e.g. a threshold. */
function drawHLines(u, lines, scale = 'y') {
  if (!lines || !lines.length) return;
  clip(u, (ctx, top, hgt, left, width) => {
    const px = uPlot.pxRatio;
    for (const l of lines) {
      const y = u.valToPos(l.y, scale, true);
      if (!Number.isFinite(y) || y < top || y > top + hgt) continue;
      ctx.strokeStyle = l.color || '#b3261e';
      ctx.lineWidth = px;
      ctx.setLineDash([5 * px, 4 * px]);
      ctx.beginPath();
      ctx.moveTo(left, y);
      ctx.lineTo(left + width, y);
      ctx.stroke();
      ctx.setLineDash([]);
      if (l.label) {
        ctx.font = `${10 * px}px system-ui, sans-serif`;
        ctx.textAlign = 'right';
        const tw = ctx.measureText(l.label).width;
        const ty = y - 4 * px < top + 12 * px ? y + 13 * px : y - 4 * px;
        ctx.fillStyle = 'rgba(255,255,255,.85)';
        ctx.fillRect(left + width - 6 * px - tw, ty - 10 * px, tw + 4 * px, 13 * px);
        ctx.fillStyle = l.color || '#b3261e';
        ctx.fillText(l.label, left + width - 4 * px, ty);
      }
    }
  });
}

/** Shaded frequency bands under the lines, e.g. an input's usable band. */
function drawBands(u, bands) {
  if (!bands || !bands.length) return;
  clip(u, (ctx, top, hgt) => {
    for (const b of bands) {
      const x0 = u.valToPos(b.range[0], 'x', true);
      const x1 = u.valToPos(b.range[1], 'x', true);
      ctx.fillStyle = hexA(b.color || '#1f6fb5', 0.1);
      ctx.fillRect(x0, top, Math.max(x1 - x0, 2 * uPlot.pxRatio), hgt);
    }
  });
}

/**
 * A spectrum plot on a log frequency axis.
 *   freqs   the report's frequency grid (the DC bin is left out)
 *   series  [{label, values, color?, dash?, format?(v) → legend text of a bin's value}]
 *   y       {log?, range?: [min, max], label, floor?}
 *   lines   horizontal reference lines [{y, label, color}]
 *   bands   shaded bands [{range: [lo, hi], color}]
 * Drag to zoom a frequency range (denser bins are drawn there), double-click
 * to reset, click a legend entry to hide/show.
 */
export function spectrumPlot(name, host, { freqs, series, y = {}, lines = [], bands = [], height = 240, onScale = null }) {
  const ys = series.map((s) => s.values);
  const base = logDecimate(freqs, ys);
  const positive = freqs.filter((f) => f > 0).length;
  const state = { keep: base };
  const clean = y.log
    ? (v) => (v != null && Number.isFinite(v) && v > 0 ? v : null)
    : (v) => (v != null && Number.isFinite(v) ? v : null);
  const build = (keep) => [keep.map((i) => freqs[i]), ...series.map((s) => keep.map((i) => clean(s.values[i])))];

  let lo = Infinity;
  let hi = -Infinity;
  for (const s of series) {
    for (const v of s.values) {
      const c = clean(v);
      if (c == null) continue;
      if (c < lo) lo = c;
      if (c > hi) hi = c;
    }
  }
  const floor = y.floor != null ? y.floor : (hi > 0 ? hi * 1e-8 : 1e-12);
  const yScale = y.range
    ? { auto: false, range: () => y.range }
    : y.log
      ? { distr: 3, range: (u, min, max) => uPlot.rangeLog(Math.max(min ?? floor, floor), Math.max(max ?? 1, floor * 10), 10, true) }
      : { range: (u, min, max) => (min == null || max == null || !(max - min > 1e-12) ? [(min ?? 0) - 1, (max ?? 0) + 1] : uPlot.rangeNum(min, max, 0.08, true)) };

  const at = (idx) => (idx == null ? null : state.keep[idx]);
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    // x: exactly the spectrum's bins, not padded to whole decades.
    scales: { x: { time: false, distr: 3, range: (u, min, max) => [min, max] }, y: yScale },
    series: [
      { label: 'f', value: (u, v, si, idx) => (at(idx) == null ? '–' : `${exact(freqs[at(idx)])} Hz`) },
      ...series.map((s, i) => {
        const color = s.color || PALETTE[i % PALETTE.length];
        return {
          label: s.label,
          stroke: color,
          width: s.width || 1.25,
          dash: s.dash,
          show: s.show !== false,
          points: { show: false },
          spanGaps: false,
          value: (u, v, si, idx) => (at(idx) == null ? '–' : (s.format || exact)(s.values[at(idx)])),
        };
      }),
    ],
    axes: [
      { ...axisBase, label: 'frequency [Hz]', labelSize: 18, size: 36, filter: logLabels, values: (self, ticks) => ticks.map((v) => tick(v)) },
      { ...axisBase, label: y.label || '', labelSize: 16, size: 62, values: y.log ? logTicks : (self, ticks) => ticks.map((v) => tick(v)) },
    ],
    // Every series reports the bin under the cursor (uPlot would skip to the
    // nearest non-null one): the legend reads as one exact row of the report.
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 }, dataIdx: (self, si, hovered) => hovered },
    legend: { live: true },
    hooks: {
      drawClear: [(u) => drawBands(u, bands)],
      draw: [(u) => drawHLines(u, lines)],
      setScale: [(u, key) => {
        if (key !== 'x') return;
        if (onScale) onScale(u.scales.x.min, u.scales.x.max);
        if (base.length >= positive) return; // every bin is drawn already
        // Zoomed: draw every bin of the window (or a finer decimation of it).
        const { min, max } = u.scales.x;
        const keep = mergeSorted(base, logDecimate(freqs, ys, { lo: min, hi: max }));
        if (keep.length === state.keep.length && keep.every((k, i) => k === state.keep[i])) return;
        queueMicrotask(() => {
          state.keep = keep;
          u.setData(build(keep), false);
        });
      }],
    },
  };
  host.replaceChildren();
  const u = new uPlot(opts, build(base), host);
  u.__decimated = { shown: base.length, bins: positive };
  host.dataset.bins = String(positive);
  host.dataset.shown = String(base.length);
  return register(name, u, autoSize(u, host, height));
}

/** Keep the x range of two plots in step (zoom one, the other follows). */
export function syncX(a, b) {
  let busy = false;
  const follow = (from, to) => from.hooks.setScale.push((u, key) => {
    if (key !== 'x' || busy || !to || !to.scales) return;
    busy = true;
    try { to.setScale('x', { min: u.scales.x.min, max: u.scales.x.max }); } finally { busy = false; }
  });
  // hooks were given at construction; uPlot reads u.hooks at call time.
  follow(a, b);
  follow(b, a);
}

/**
 * Normalized singular values σᵢ/σ₁ of the regressor, log y, with the
 * identifiability threshold: points above it in blue, below in red.
 */
export function singularValuePlot(name, host, reg, { height = 220 } = {}) {
  const sv = reg.singular_values;
  const n = sv.length;
  const x = sv.map((_, i) => i + 1);
  const positive = sv.filter((v) => v > 0);
  const floor = Math.min(reg.threshold / 10, positive.length ? Math.min(...positive) / 3 : reg.threshold / 10);
  const above = sv.map((v) => (v >= reg.threshold && v > 0 ? v : null));
  const below = sv.map((v) => (v < reg.threshold ? Math.max(v, floor) : null));
  const value = (u, v, si, idx) => {
    if (idx == null) return '–';
    const s = sv[idx];
    if ((si === 1) !== (s >= reg.threshold)) return '–';
    return exact(s);
  };
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    scales: {
      x: { time: false, range: (u, min, max) => [Math.min(min ?? 1, 1) - 0.5, Math.max(max ?? n, n) + 0.5] },
      y: { distr: 3, range: (u, min, max) => uPlot.rangeLog(Math.max(Math.min(min ?? floor, reg.threshold), floor), 1, 10, true) },
    },
    series: [
      { label: 'i', value: (u, v, si, idx) => (idx == null ? '–' : `σ${idx + 1}`) },
      { label: `σᵢ/σ₁ ≥ ${exact(reg.threshold)} (identifiable)`, stroke: '#1f6fb5', width: 1, points: { show: true, size: 7, fill: '#1f6fb5' }, value },
      { label: `σᵢ/σ₁ < ${exact(reg.threshold)}`, stroke: '#b3261e', width: 0, points: { show: true, size: 8, fill: '#b3261e' }, paths: () => null, value },
    ],
    axes: [
      { ...axisBase, label: 'singular value index', labelSize: 18, size: 36, incrs: [1, 2, 5, 10, 20, 50, 100], values: (self, ticks) => ticks.map((v) => (Number.isInteger(v) ? String(v) : '')) },
      { ...axisBase, label: 'σᵢ / σ₁', labelSize: 16, size: 62, values: logTicks },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 7 }, dataIdx: (self, si, hovered) => hovered },
    legend: { live: true },
    hooks: { draw: [(u) => drawHLines(u, [{ y: reg.threshold, label: `threshold ${exact(reg.threshold)}` }])] },
  };
  host.replaceChildren();
  const u = new uPlot(opts, [x, above, below], host);
  return register(name, u, autoSize(u, host, height));
}
