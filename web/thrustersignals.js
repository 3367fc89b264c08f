// What a thruster's log column holds (its `signal`: command, shaft speed,
// pitch or thrust, read into the command u) and an azimuth's logged angle
// α(t) with its position: shown on the vessel page, edited in the form.

import { fmt, fmtU } from './format.js';
import { h } from './forms.js';

/** Signals a logger records, with the parameters each needs. */
export const SIGNALS = [
  { kind: 'command', label: 'command u', params: [] },
  { kind: 'shaft_speed', label: 'shaft speed n', params: [{ key: 'rated_rpm', label: 'rated n', unit: 'rpm' }] },
  { kind: 'pitch', label: 'pitch p', params: [{ key: 'zero_thrust', label: 'p₀ (zero thrust)', unit: '' }, { key: 'full_ahead', label: 'p full ahead', unit: '' }] },
  { kind: 'thrust', label: 'thrust f', params: [{ key: 'rated_n', label: 'rated f', unit: 'N' }] },
];

/** The signal in words, with how u is read from it. */
export function signalText(s) {
  switch (s?.kind ?? 'command') {
    case 'shaft_speed': return `shaft speed n, u = |n|n / (${fmt(s.rated_rpm)} rpm)²`;
    case 'pitch': return `pitch p, u = |p − p₀|(p − p₀) / (p_full − p₀)², p₀ = ${fmt(s.zero_thrust)}, p_full = ${fmt(s.full_ahead)}`;
    case 'thrust': return `thrust f, u = f / ${fmtU(s.rated_n, 'N')}`;
    default: return 'command u';
  }
}

/** An azimuth's angle: logged (column azi_j, unit, position) or fixed in T. */
export function angleText(t, i) {
  const a = t.logged_angle;
  if (a) return `azi_${i + 1} logged in ${a.unit === 'deg' ? 'degrees' : 'radians'}, at x = ${fmtU(a.x_m, 'm')}, y = ${fmtU(a.y_m, 'm')}`;
  return t.kind === 'azimuth' ? 'fixed, as in T' : '–';
}

/**
 * Form cell: the signal select and its parameters. `numInput(value, field,
 * label, onSet)` builds a number input; `render` redraws the form.
 */
export function signalCell(t, i, numInput, render) {
  const s = t.signal ?? { kind: 'command' };
  const spec = SIGNALS.find((x) => x.kind === s.kind) ?? SIGNALS[0];
  const base = `inputs.thrusters[${i}].signal`;
  const sel = h('select', {
    'data-field': `${base}.kind`, 'data-testid': `thruster-signal-${i + 1}`, 'aria-label': `Thruster ${i + 1} logged signal`,
    onChange: (e) => { t.signal = { kind: e.target.value }; render(); },
  }, SIGNALS.map((x) => h('option', { value: x.kind, selected: x.kind === spec.kind }, x.label)));
  return h('td', { 'data-error-host': '' },
    h('div', { class: 'row tight' }, sel,
      spec.params.map((p) => h('div', { class: 'unit-input' },
        numInput(s[p.key], `${base}.${p.key}`, `Thruster ${i + 1} ${p.label}${p.unit ? ` (${p.unit})` : ''}`, (x) => { t.signal[p.key] = x; }, { placeholder: p.label }),
        p.unit ? h('span', { class: 'unit' }, p.unit) : null))));
}

/** Form cell: for an azimuth, whether α is logged, its unit and position. */
export function angleCell(t, i, numInput, render) {
  if (t.kind !== 'azimuth') return h('td', { class: 'muted' }, '–');
  const base = `inputs.thrusters[${i}].logged_angle`;
  const on = h('input', {
    type: 'checkbox', checked: t.logged_angle != null, 'data-testid': `thruster-angle-${i + 1}`,
    onChange: (e) => { t.logged_angle = e.target.checked ? { unit: 'deg', x_m: null, y_m: null } : undefined; render(); },
  });
  const head = h('label', { class: 'check' }, on, ` α logged (azi_${i + 1})`);
  const a = t.logged_angle;
  if (!a) return h('td', { 'data-error-host': '' }, head);
  const unit = h('select', {
    'data-field': `${base}.unit`, 'aria-label': `Thruster ${i + 1} angle unit`,
    onChange: (e) => { a.unit = e.target.value; },
  }, [['deg', '°'], ['rad', 'rad']].map(([k, l]) => h('option', { value: k, selected: a.unit === k }, l)));
  const pos = (key, label) => h('div', { class: 'unit-input' },
    numInput(a[key], `${base}.${key}`, `Thruster ${i + 1} ${label} (m)`, (x) => { a[key] = x; }, { placeholder: label }),
    h('span', { class: 'unit' }, 'm'));
  return h('td', { 'data-error-host': '', 'data-field': base },
    head, h('div', { class: 'row tight' }, unit, pos('x_m', 'x forward'), pos('y_m', 'y starboard')));
}

/**
 * The thruster's `signal` and `logged_angle` for the request body (absent
 * when the column is the command and the angle is fixed). `need(x, field)`
 * records a missing or non-numeric field.
 */
export function collectSignal(t, i, need) {
  const out = {};
  const s = t.signal;
  if (s && s.kind !== 'command') {
    const spec = SIGNALS.find((x) => x.kind === s.kind);
    out.signal = { kind: s.kind };
    for (const p of spec?.params ?? []) out.signal[p.key] = need(s[p.key], `inputs.thrusters[${i}].signal.${p.key}`);
  }
  const a = t.logged_angle;
  if (t.kind === 'azimuth' && a) {
    out.logged_angle = {
      unit: a.unit ?? 'rad',
      x_m: need(a.x_m, `inputs.thrusters[${i}].logged_angle.x_m`),
      y_m: need(a.y_m, `inputs.thrusters[${i}].logged_angle.y_m`),
    };
  }
  return out;
}
