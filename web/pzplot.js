// Pole-zero map drawn on a canvas (uPlot has no scatter on equal axes):
// poles ×, zeros ○, the unit circle of a discrete model (its stability
// limit) or the imaginary axis of a continuous one, equal scales on both
// axes. Exportable like the uPlot charts (PNG, SVG, CSV of the roots).
// Live map: window.__plots.pz (with .data for tests).

import { toCsv } from './plotexport.js';
import { tick } from './plots.js';

const POLE = '#b3261e';
const ZERO = '#1f6fb5';

/** Bounds of the square view: every root and the unit circle (discrete). */
function view(poles, zeros, discrete) {
  const pts = [...poles, ...zeros];
  let r = discrete ? 1.15 : 0;
  for (const p of pts) r = Math.max(r, Math.abs(p.re), Math.abs(p.im));
  if (!(r > 0)) r = 1;
  return r * 1.12;
}

/**
 * Draw the map into `host`. `pz`: {plane, poles: [{re, im}], zeros: [{re, im}]}.
 * Returns the exportable {title, canvas, svg, csv}.
 */
export function poleZeroPlot(host, pz, { title = 'pole-zero map', size = 360 } = {}) {
  const discrete = pz.plane === 'z';
  const R = view(pz.poles, pz.zeros, discrete);
  const css = Math.max(240, Math.min(size, Math.floor(host.clientWidth || size)));
  const ratio = window.devicePixelRatio || 1;
  const canvas = document.createElement('canvas');
  canvas.width = Math.round(css * ratio);
  canvas.height = Math.round(css * ratio);
  canvas.style.width = `${css}px`;
  canvas.style.height = `${css}px`;
  canvas.setAttribute('role', 'img');
  canvas.setAttribute('aria-label', `${title}: ${pz.poles.length} poles, ${pz.zeros.length} zeros`);
  const pad = 42;
  const span = css - 2 * pad;
  const X = (re) => pad + ((re + R) / (2 * R)) * span;
  const Y = (im) => pad + ((R - im) / (2 * R)) * span;
  const ctx = canvas.getContext('2d');
  ctx.scale(ratio, ratio);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, css, css);
  ctx.strokeStyle = '#e3e6ea';
  ctx.lineWidth = 1;
  ctx.font = '10px system-ui, sans-serif';
  ctx.fillStyle = '#445';
  const step = niceStep(R);
  for (let k = -Math.floor(R / step); k * step <= R * (1 + 1e-12); k += 1) {
    const v = k * step;
    ctx.beginPath(); ctx.moveTo(X(v), pad); ctx.lineTo(X(v), pad + span); ctx.stroke();
    ctx.beginPath(); ctx.moveTo(pad, Y(v)); ctx.lineTo(pad + span, Y(v)); ctx.stroke();
    ctx.textAlign = 'center';
    ctx.fillText(tick(Number(v.toPrecision(6))), X(v), pad + span + 12);
    ctx.textAlign = 'right';
    ctx.fillText(tick(Number(v.toPrecision(6))), pad - 4, Y(v) + 3);
  }
  ctx.strokeStyle = '#9aa3ad';
  ctx.strokeRect(pad, pad, span, span);
  ctx.beginPath(); ctx.moveTo(X(0), pad); ctx.lineTo(X(0), pad + span); ctx.moveTo(pad, Y(0)); ctx.lineTo(pad + span, Y(0)); ctx.stroke();
  if (discrete) {
    ctx.strokeStyle = '#2e9e5b';
    ctx.setLineDash([5, 4]);
    ctx.beginPath();
    ctx.arc(X(0), Y(0), (span / (2 * R)), 0, 2 * Math.PI);
    ctx.stroke();
    ctx.setLineDash([]);
  }
  ctx.lineWidth = 1.6;
  ctx.strokeStyle = POLE;
  for (const p of pz.poles) {
    const [x, y] = [X(p.re), Y(p.im)];
    ctx.beginPath(); ctx.moveTo(x - 5, y - 5); ctx.lineTo(x + 5, y + 5); ctx.moveTo(x - 5, y + 5); ctx.lineTo(x + 5, y - 5); ctx.stroke();
  }
  ctx.strokeStyle = ZERO;
  for (const z of pz.zeros) {
    ctx.beginPath(); ctx.arc(X(z.re), Y(z.im), 5, 0, 2 * Math.PI); ctx.stroke();
  }
  const unit = discrete ? '' : ' [rad/s]';
  ctx.fillStyle = '#1c2430';
  ctx.font = '11px system-ui, sans-serif';
  ctx.textAlign = 'center';
  ctx.fillText(`real${unit}`, pad + span / 2, css - 6);
  ctx.save();
  ctx.translate(11, pad + span / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.fillText(`imaginary${unit}`, 0, 0);
  ctx.restore();
  ctx.textAlign = 'left';
  ctx.fillStyle = POLE; ctx.fillText(`× poles (${pz.poles.length})`, pad + 4, pad - 8);
  ctx.fillStyle = ZERO; ctx.fillText(`○ zeros (${pz.zeros.length})`, pad + 100, pad - 8);
  if (discrete) { ctx.fillStyle = '#2e9e5b'; ctx.fillText('unit circle', pad + 190, pad - 8); }
  host.replaceChildren(canvas);

  const svg = () => {
    const s = 360;
    const sx = (re) => pad + ((re + R) / (2 * R)) * (s - 2 * pad);
    const sy = (im) => pad + ((R - im) / (2 * R)) * (s - 2 * pad);
    const marks = [
      ...pz.poles.map((p) => `<path d="M${sx(p.re) - 5} ${sy(p.im) - 5}L${sx(p.re) + 5} ${sy(p.im) + 5}M${sx(p.re) - 5} ${sy(p.im) + 5}L${sx(p.re) + 5} ${sy(p.im) - 5}" stroke="${POLE}" stroke-width="1.6"/>`),
      ...pz.zeros.map((z) => `<circle cx="${sx(z.re)}" cy="${sy(z.im)}" r="5" fill="none" stroke="${ZERO}" stroke-width="1.6"/>`),
    ];
    const circle = discrete ? `<circle cx="${sx(0)}" cy="${sy(0)}" r="${(s - 2 * pad) / (2 * R)}" fill="none" stroke="#2e9e5b" stroke-dasharray="5 4"/>` : '';
    return `<svg xmlns="http://www.w3.org/2000/svg" width="${s}" height="${s}" font-family="system-ui, sans-serif"><rect width="${s}" height="${s}" fill="#fff"/>`
      + `<text x="8" y="16" font-size="12">${title.replace(/[<&]/g, '')}</text>`
      + `<rect x="${pad}" y="${pad}" width="${s - 2 * pad}" height="${s - 2 * pad}" fill="none" stroke="#9aa3ad"/>`
      + `<line x1="${sx(0)}" y1="${pad}" x2="${sx(0)}" y2="${s - pad}" stroke="#9aa3ad"/><line x1="${pad}" y1="${sy(0)}" x2="${s - pad}" y2="${sy(0)}" stroke="#9aa3ad"/>`
      + `${circle}${marks.join('')}<text x="${s / 2}" y="${s - 8}" font-size="11" text-anchor="middle">real${unit}</text>`
      + `<text transform="translate(12 ${s / 2}) rotate(-90)" font-size="11" text-anchor="middle">imaginary${unit}</text>`
      + `<text x="${pad - 4}" y="${pad - 4}" font-size="10" text-anchor="end">${tick(Number(R.toPrecision(4)))}</text></svg>\n`;
  };
  const csv = () => {
    const rows = [...pz.poles.map((p) => ['pole', p]), ...pz.zeros.map((z) => ['zero', z])];
    return toCsv(['kind', `real${unit}`, `imaginary${unit}`, 'natural frequency [rad/s]', 'damping [-]', 'time constant [s]'], [
      rows.map((r) => r[0]), rows.map((r) => r[1].re), rows.map((r) => r[1].im),
      rows.map((r) => r[1].natural_frequency_rad_s), rows.map((r) => r[1].damping), rows.map((r) => r[1].time_constant_s)]);
  };
  const exp = { title, canvas: () => canvas, svg, csv };
  window.__plots = window.__plots || {};
  window.__plots.pz = { data: pz, canvas, export: exp };
  return exp;
}

/** A round grid step of about a quarter of `r`. */
function niceStep(r) {
  const raw = r / 2.5;
  const p = 10 ** Math.floor(Math.log10(raw));
  const m = raw / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}
