// uPlot charts: the schedule (time plot of every reference column) and the
// PSD of the excited columns. Every live chart is reachable for tests and
// debugging as window.__plots.{schedule,psd} (run plots: see runplots.js).

import uPlot from '/node_modules/uplot/dist/uPlot.esm.js';
import { fmt, unitLabel } from './format.js';

export const PALETTE = ['#1f6fb5', '#d1495b', '#2e9e5b', '#8a5cc2', '#e08a1e', '#1aa3b5', '#8c564b', '#c2549d', '#6b7280', '#9aa31b'];

window.__plots = window.__plots || {};

/** Axis tick label: short, no float noise, real minus sign. */
export function tick(v) {
  if (v == null) return '';
  if (v === 0) return '0';
  const a = Math.abs(v);
  const s = a >= 1e5 || a < 1e-3 ? v.toExponential(1).replace('e+', 'e') : String(Number(v.toPrecision(6)));
  return s.replace('-', '\u2212');
}

/** Unit of a one-sided PSD of a signal in `u`: (m/s)²/Hz, N²/Hz, 1/Hz. */
export function psdUnit(u) {
  if (!u || u === '1') return '1/Hz';
  return /[/·]/.test(u) ? `(${u})²/Hz` : `${u}²/Hz`;
}

export function hexA(hex, a) {
  const n = parseInt(hex.slice(1), 16);
  return `rgba(${(n >> 16) & 255},${(n >> 8) & 255},${n & 255},${a})`;
}

/** Keep a chart as wide as its host. */
export function autoSize(u, host, height) {
  let last = 0;
  let raf = 0;
  const ro = new ResizeObserver(() => {
    cancelAnimationFrame(raf);
    raf = requestAnimationFrame(() => {
      const w = Math.floor(host.clientWidth);
      if (w > 0 && w !== last) {
        last = w;
        u.setSize({ width: w, height });
      }
    });
  });
  ro.observe(host);
  return () => { cancelAnimationFrame(raf); ro.disconnect(); };
}

export function register(name, u, stop) {
  const old = window.__plots[name];
  if (old && old !== u && old.__stop) old.__stop();
  u.__stop = () => {
    stop();
    u.destroy();
    if (window.__plots[name] === u) delete window.__plots[name];
  };
  window.__plots[name] = u;
  return u;
}

export const axisBase = {
  stroke: '#445',
  grid: { stroke: '#e3e6ea', width: 1 },
  ticks: { stroke: '#c9ced6', width: 1 },
  font: '11px system-ui, sans-serif',
  labelFont: '11px system-ui, sans-serif',
};

/**
 * Time plot of a schedule: one series per column, one y scale per unit.
 * Drag to zoom a time range, double-click to reset, click legend entries
 * to toggle series.
 */
export function schedulePlot(host, sched, { excited = new Set(), limits = {}, height = 300 } = {}) {
  const cols = sched.columns;
  const units = [...new Set(cols.map((c) => c.unit))];
  const scales = { x: { time: false } };
  units.forEach((unit) => {
    // A unit whose columns are all held flat would get uPlot's [0, 100]:
    // show ± the largest channel limit instead, so "0" reads as "held".
    const lim = Math.max(0, ...cols.filter((c) => c.unit === unit).map((c) => Math.abs(limits[c.name] || 0)));
    scales[unit] = {
      auto: true,
      range: (u, min, max) => {
        if (min == null || max == null) return [-1, 1];
        if (max - min > 1e-12) return uPlot.rangeNum(min, max, 0.08, true);
        const pad = lim > 0 ? lim : Math.max(Math.abs(min) * 0.5, 1);
        return [Math.min(min, 0) - pad * (min > 0 ? 0 : 1), Math.max(max, 0) + pad * (max < 0 ? 0 : 1)];
      },
    };
  });
  const series = [
    { label: 't', value: (u, v) => (v == null ? '–' : `${fmt(v, 2)} s`) },
    ...cols.map((c, i) => ({
      label: c.unit === '1' ? c.name : `${c.name} [${unitLabel(c.unit)}]`,
      scale: c.unit,
      stroke: PALETTE[i % PALETTE.length],
      width: excited.has(c.name) ? 1.6 : 1,
      dash: excited.has(c.name) ? undefined : [5, 3],
      value: (u, v) => (v == null ? '–' : fmt(v)),
      points: { show: false },
    })),
  ];
  const axes = [
    { ...axisBase, label: 'time [s]', labelSize: 18, size: 36 },
    ...units.map((u, i) => ({
      ...axisBase,
      scale: u,
      side: i % 2 === 0 ? 3 : 1,
      label: u === '1' ? 'command (normalized)' : unitLabel(u),
      labelSize: 16,
      size: 56,
      grid: i === 0 ? axisBase.grid : { show: false },
      values: (self, ticks) => ticks.map((v) => tick(v)),
    })),
  ];
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    scales,
    series,
    axes,
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 } },
    legend: { live: true },
  };
  const data = [sched.t, ...cols.map((c) => c.values)];
  host.replaceChildren();
  const u = new uPlot(opts, data, host);
  return register('schedule', u, autoSize(u, host, height));
}

/**
 * PSD of the excited columns, log-log. Shades each channel's usable band and
 * marks the logger's Nyquist frequency.
 */
export function psdPlot(host, spectra, { bands = {}, nyquistHz = null, units = {}, height = 240 } = {}) {
  if (!spectra.length) { host.replaceChildren(); return null; }
  // Shared frequency axis without the DC bin (log scale). Spectra of one
  // experiment share their frequencies; if not, align them on the first one.
  const f0 = spectra[0].freqs_hz;
  const keep = f0.map((f, i) => (f > 0 ? i : -1)).filter((i) => i >= 0);
  const x = keep.map((i) => f0[i]);
  let peak = 0;
  const ys = spectra.map((s) => {
    const same = s.freqs_hz.length === f0.length;
    return keep.map((i) => {
      const v = same ? s.psd[i] : null;
      if (v != null && v > peak) peak = v;
      return v != null && v > 0 ? v : null;
    });
  });
  const floor = peak > 0 ? peak * 1e-7 : 1e-12;
  const series = [
    { label: 'f', value: (u, v) => (v == null ? '–' : `${fmt(v)} Hz`) },
    ...spectra.map((s, i) => ({
      label: `${s.name} [${psdUnit(units[s.name])}]`,
      stroke: PALETTE[i % PALETTE.length],
      width: 1.25,
      value: (u, v) => (v == null ? '–' : fmt(v)),
      points: { show: false },
      _color: PALETTE[i % PALETTE.length],
      _band: spectra.length <= 2 ? bands[s.name] || null : null,
    })),
  ];
  const clip = (u, fn) => {
    const { ctx } = u;
    const { top, height: hgt, left, width } = u.bbox;
    ctx.save();
    ctx.beginPath();
    ctx.rect(left, top, width, hgt);
    ctx.clip();
    fn(ctx, top, hgt);
    ctx.restore();
  };
  // Under the grid and lines: each channel's usable band.
  const shade = (u) => clip(u, (ctx, top, hgt) => {
    u.series.forEach((s, i) => {
      if (i === 0 || !s.show || !s._band) return;
      const [lo, hi] = s._band;
      const x0 = u.valToPos(lo, 'x', true);
      const x1 = u.valToPos(hi, 'x', true);
      ctx.fillStyle = hexA(s._color, 0.09);
      ctx.fillRect(x0, top, Math.max(x1 - x0, 2 * uPlot.pxRatio), hgt);
    });
  });
  // Over everything: the logger's Nyquist frequency.
  const nyquist = (u) => clip(u, (ctx, top, hgt) => {
    if (!nyquistHz) return;
    const px = uPlot.pxRatio;
    const xn = u.valToPos(nyquistHz, 'x', true);
    ctx.strokeStyle = '#6b7280';
    ctx.setLineDash([4 * px, 3 * px]);
    ctx.lineWidth = px;
    ctx.beginPath();
    ctx.moveTo(xn, top);
    ctx.lineTo(xn, top + hgt);
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.font = `${10 * px}px system-ui, sans-serif`;
    ctx.textAlign = 'right';
    const label = `logger Nyquist ${fmt(nyquistHz)} Hz`;
    const tw = ctx.measureText(label).width;
    ctx.fillStyle = 'rgba(255,255,255,.9)';
    ctx.fillRect(xn - 6 * px - tw, top + 2 * px, tw + 4 * px, 13 * px);
    ctx.fillStyle = '#374151';
    ctx.fillText(label, xn - 4 * px, top + 12 * px);
  });
  const opts = {
    width: Math.max(300, Math.floor(host.clientWidth)),
    height,
    scales: {
      x: { time: false, distr: 3 },
      y: { distr: 3, range: (u, min, max) => uPlot.rangeLog(Math.max(min ?? floor, floor), Math.max(max ?? 1, floor * 10), 10, true) },
    },
    series,
    axes: [
      { ...axisBase, label: 'frequency [Hz]', labelSize: 18, size: 36, values: (self, ticks) => ticks.map((v) => tick(v)) },
      { ...axisBase, label: 'PSD', labelSize: 16, size: 62, values: (self, ticks) => ticks.map((v) => (v == null ? '' : v.toExponential(0).replace('e+', 'e'))) },
    ],
    cursor: { drag: { x: true, y: false, setScale: true }, points: { size: 5 } },
    legend: { live: true },
    hooks: { drawClear: [shade], draw: [nyquist] },
  };
  host.replaceChildren();
  const u = new uPlot(opts, [x, ...ys], host);
  return register('psd', u, autoSize(u, host, height));
}

export function destroyPlots() {
  for (const k of Object.keys(window.__plots)) {
    const u = window.__plots[k];
    if (u && u.__stop) u.__stop();
  }
}
