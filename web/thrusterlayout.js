// Thruster layout of a vessel seen from above, drawn from its configuration
// matrix T alone: a column (X, Y, N) of T is a force direction (X, Y) and a
// yaw moment N = x·Y − y·X, so T fixes one coordinate of each thruster's
// position. Thrusters that push mostly sideways (tunnels, azimuths) are
// placed on the centreline at x = N / Y; those that push mostly ahead
// (mains) at the stern with the transverse offset y = −N / X. A sign error
// in T shows at once: a bow tunnel drawn aft, a port propeller to starboard.
//
// Frame: body axes, x forward (drawn to the right), y to starboard (drawn
// down), in the units of T's moment row (metres, or ship lengths L in the
// paper's Bis system).

import { h } from './forms.js';
import { fmt } from './format.js';

const SVG = 'http://www.w3.org/2000/svg';

function s(tag, attrs, ...children) {
  const el = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) el.setAttribute(k, String(v));
  for (const c of children) {
    if (c == null) continue;
    el.appendChild(typeof c === 'string' ? document.createTextNode(c) : c);
  }
  return el;
}

/**
 * Inferred plan-view geometry of each thruster from T: `{index, name, kind,
 * X, Y, N, x, y, how}`; `x`/`y` null when T leaves them open. `how` says in
 * words how the position was found. Null when the vessel has no thrusters
 * or T has no surge, sway or yaw row.
 */
export function inferLayout(v) {
  if (!v.inputs || v.inputs.kind !== 'thrusters') return null;
  const T = v.inputs.configuration;
  const row = (dof) => {
    const r = v.dofs.indexOf(dof);
    return r < 0 ? null : T[r];
  };
  const [rx, ry, rn] = [row('surge'), row('sway'), row('yaw')];
  if (!rx && !ry) return null;
  return v.inputs.thrusters.map((t, c) => {
    const X = rx ? rx[c] : 0;
    const Y = ry ? ry[c] : 0;
    const N = rn ? rn[c] : 0;
    const base = { index: c + 1, name: t.name, kind: t.kind, X, Y, N };
    if (Math.hypot(X, Y) < 1e-12) {
      return { ...base, x: null, y: null, how: 'no force in surge or sway: not in the plan view' };
    }
    if (Math.abs(Y) >= Math.abs(X)) {
      return { ...base, x: N / Y, y: 0, how: 'on the centreline, x = N / Y' };
    }
    return { ...base, x: null, y: -N / X, how: 'at the stern (T leaves x open), y = −N / X' };
  });
}

/** The layout drawing with its table of inferred positions, or null. */
export function thrusterLayout(v) {
  const items = inferLayout(v);
  if (!items) return null;
  const placed = items.filter((t) => t.x != null || t.y != null);
  const extent = Math.max(1e-9, ...placed.map((t) => Math.abs(t.x ?? 0)), ...placed.map((t) => 3 * Math.abs(t.y ?? 0)));
  // Hull: a little longer than the farthest thruster, beam a fifth of it.
  const half = extent * 1.15;
  const beam = Math.max(half * 0.4, 2.4 * Math.max(0, ...placed.map((t) => Math.abs(t.y ?? 0))));
  const W = 520;
  const Hh = 240;
  const scale = Math.min((W - 80) / (2 * half), (Hh - 60) / (beam + 0.6 * half));
  const cx = W / 2;
  const cy = Hh / 2;
  const P = (x, y) => [cx + x * scale, cy + y * scale];
  const [sx, sy] = P(-half, -beam / 2);
  const [bx] = P(half, 0);
  const [shx] = P(half - beam, 0);
  const [, by1] = P(0, beam / 2);
  const hull = s('path', {
    d: `M ${sx} ${sy} L ${shx} ${sy} L ${bx} ${cy} L ${shx} ${by1} L ${sx} ${by1} Z`,
    fill: '#eef3f8', stroke: '#4a6a8a', 'stroke-width': 1.5,
  });
  const arrowLen = 0.22 * half * scale;
  const marks = placed.map((t) => {
    const x = t.x ?? -half * 0.9;
    const [px, py] = P(x, t.y ?? 0);
    const n = Math.hypot(t.X, t.Y);
    const [dx, dy] = [(t.X / n) * arrowLen, (t.Y / n) * arrowLen];
    return s('g', { 'data-testid': 'thruster-mark', 'data-thruster': t.index, 'data-x': t.x ?? '', 'data-y': t.y ?? '' },
      s('title', null, `thr_${t.index} ${t.name} (${t.kind}): force (${fmt(t.X)}, ${fmt(t.Y)}), N = ${fmt(t.N)}; ${t.how}`),
      s('circle', { cx: px, cy: py, r: 5, fill: '#1f6fb5' }),
      s('line', { x1: px, y1: py, x2: px + dx, y2: py + dy, stroke: '#1f6fb5', 'stroke-width': 2, 'marker-end': 'url(#thr-arrow)' }),
      s('text', { x: px + 7, y: py - 7, 'font-size': 12, fill: '#1b2b3a' }, `thr_${t.index}`));
  });
  const svg = s('svg', {
    viewBox: `0 0 ${W} ${Hh}`, width: W, height: Hh, role: 'img',
    'aria-label': `Thruster layout from T: ${placed.length} of ${items.length} thrusters in the plan view`,
    'data-testid': 'thruster-layout',
  },
  s('defs', null, s('marker', { id: 'thr-arrow', viewBox: '0 0 10 10', refX: 8, refY: 5, markerWidth: 6, markerHeight: 6, orient: 'auto-start-reverse' },
    s('path', { d: 'M 0 0 L 10 5 L 0 10 z', fill: '#1f6fb5' }))),
  hull,
  s('line', { x1: cx - half * scale, y1: cy, x2: cx + half * scale, y2: cy, stroke: '#9fb3c8', 'stroke-dasharray': '4 4' }),
  s('text', { x: bx - 4, y: cy - 8, 'font-size': 11, 'text-anchor': 'end', fill: '#4a6a8a' }, 'bow'),
  s('text', { x: cx, y: Hh - 8, 'font-size': 11, 'text-anchor': 'middle', fill: '#4a6a8a' }, 'x forward →, y to starboard ↓ (body axes)'),
  ...marks);
  return h('figure', { class: 'thruster-layout' },
    svg,
    h('figcaption', null,
      'Thruster layout drawn from the configuration matrix T (arrows: force directions). ',
      'T fixes one coordinate of each position; the other is assumed as the table says. ',
      'x and y are in the units of T’s yaw row: metres, or ship lengths L in the Bis system.'),
    h('table', { class: 'grid-table compact', 'data-testid': 'thruster-positions' },
      h('thead', null, h('tr', null, h('th', null, '#'), h('th', null, 'Name'),
        h('th', { class: 'num' }, 'x'), h('th', { class: 'num' }, 'y'), h('th', null, 'How'))),
      h('tbody', null, items.map((t) => h('tr', null,
        h('td', null, `thr_${t.index}`), h('td', null, t.name),
        h('td', { class: 'num' }, t.x == null ? '–' : fmt(t.x)),
        h('td', { class: 'num' }, t.y == null ? '–' : fmt(t.y)),
        h('td', null, t.how))))));
}
