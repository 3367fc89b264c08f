// Vessels: list, one vessel, and the create form (from a template).

import { api } from './api.js';
import { renameControl } from './rename.js';
import { vesselTrash } from './parenttrash.js';
import { thrusterLayout } from './thrusterlayout.js';
import { signalText, angleText, signalCell, angleCell, collectSignal } from './thrustersignals.js';
import { deletedBadge } from './manage.js';
import {
  DOFS, KIND_LABEL, dofUnits, fmt, fmtDate, fmtU, knots, FAMILY_LABEL,
} from './format.js';
import {
  h, fill, labelled, num, showError, clearErrors, clearBanner, showFieldError, banner, flash,
} from './forms.js';
import { SURVEYOR_ROV, SUPPLY_VESSEL, BLANK_ROV } from './templates.js';

const LIMIT_COLS = [
  { key: 'max_velocity', label: 'Max velocity', unit: (u) => u.velocity, required: true },
  { key: 'max_force', label: 'Max force', unit: (u) => u.force, required: true },
  { key: 'max_force_rate', label: 'Max force rate', unit: (u) => u.force_rate, required: true },
  { key: 'max_accel', label: 'Max accel', unit: (u) => u.accel, required: false },
  { key: 'time_constant_s', label: 'Time constant', unit: () => 's', required: true },
];
const THRUSTER_KINDS = ['main', 'tunnel', 'azimuth'];

function inputsText(v) {
  if (!v.inputs || v.inputs.kind === 'generalized_forces') return 'generalized forces τ';
  return `${v.inputs.thrusters.length} thrusters`;
}

// ---- list -----------------------------------------------------------------

export async function vesselList(view) {
  const vessels = await api.vessels();
  fill(view, 
    h('div', { class: 'page-head' },
      h('h1', null, 'Vessels'),
      h('a', { class: 'btn primary', href: '#/vessels/new', 'data-testid': 'new-vessel', 'data-needs': 'engineer' }, '+ New vessel')),
    vessels.length === 0
      ? h('p', { class: 'empty' }, 'No vessels yet. Create one from a template.')
      : h('table', { class: 'grid-table', 'data-testid': 'vessel-table' },
        h('thead', null, h('tr', null,
          h('th', null, 'Name'), h('th', null, 'Kind'), h('th', null, 'DOFs'), h('th', null, 'Inputs'),
          h('th', { class: 'num' }, 'Max speed'), h('th', { class: 'num' }, 'Controller'),
          h('th', { class: 'num' }, 'Logger'), h('th', null, 'Created'))),
        h('tbody', null, vessels.map((v) => {
          const vmax = v.limits && v.limits.surge ? v.limits.surge.max_velocity : null;
          return h('tr', { 'data-testid': 'vessel-row' },
            h('td', null, h('a', { href: `#/vessels/${v.id}` }, v.name)),
            h('td', null, KIND_LABEL[v.kind] || v.kind),
            h('td', null, v.dofs.join(', ')),
            h('td', null, inputsText(v)),
            h('td', { class: 'num' }, vmax == null ? '–' : `${fmt(knots(vmax), 2)} kn · ${fmt(vmax)} m/s`),
            h('td', { class: 'num' }, `${fmt(v.controller_rate_hz)} Hz`),
            h('td', { class: 'num' }, `${fmt(v.logger_rate_hz)} Hz`),
            h('td', null, fmtDate(v.created_at)));
        }))),
    vesselTrash.list());
}

// ---- one vessel -------------------------------------------------------------

export function limitsTable(v) {
  return h('table', { class: 'grid-table compact', 'data-testid': 'limits-table' },
    h('thead', null, h('tr', null, h('th', null, 'DOF'),
      LIMIT_COLS.map((c) => h('th', { class: 'num' }, c.label)))),
    h('tbody', null, v.dofs.map((d) => {
      const l = v.limits[d] || {};
      const u = dofUnits(d);
      return h('tr', null, h('th', { scope: 'row' }, d),
        LIMIT_COLS.map((c) => h('td', { class: 'num' }, l[c.key] == null ? '–' : fmtU(l[c.key], c.unit(u)))));
    })));
}

/** The declared autopilot's gains, or null without one. */
export function autopilotTable(v, {
  title = 'Autopilot',
  hint = 'The team’s own loops: simulated flights of the plan (predicted precision, experiment design) fly through them.',
  testid = 'autopilot-table',
  heading = 'h2',
} = {}) {
  const a = v.autopilot;
  if (!a) return null;
  const gain = (x, unit) => (x == null ? '–' : `${fmt(x)} ${unit}`);
  const ff = a.restoring_feed_forward;
  return h('div', { 'data-testid': testid },
    h(heading, null, title),
    h('p', { class: 'hint' }, hint),
    h('table', { class: 'grid-table' },
      h('thead', null, h('tr', null, h('th', null, 'DOF'), h('th', null, 'Loop'), h('th', null, 'K_p'), h('th', null, 'K_i'), h('th', null, 'K_d'))),
      h('tbody', null, v.dofs.filter((d) => a.loops[d]).map((d) => {
        const l = a.loops[d];
        const u = dofUnits(d);
        const att = l.kd != null;
        return h('tr', null, h('th', { scope: 'row' }, d),
          h('td', null, att ? 'attitude PD' : 'velocity PI'),
          h('td', null, gain(l.kp, att ? `${u.force}/rad` : `${u.force}/(${u.velocity})`)),
          h('td', null, gain(l.ki ?? 0, att ? `${u.force}/(rad·s)` : `${u.force}/${u.velocity.split('/')[0]}`)),
          h('td', null, att ? gain(l.kd, `${u.force}/(${u.velocity})`) : '–'));
      }))),
    ff ? h('p', null, `Restoring feed-forward ĝ(η): W − B = ${fmtU(ff.w_minus_b, 'N')}, z_G W − z_B B = ${fmtU(ff.zg_w_minus_zb_b, 'N·m')}`)
      : h('p', { class: 'hint' }, 'No restoring feed-forward.'));
}

export function thrusterTables(v) {
  if (!v.inputs || v.inputs.kind !== 'thrusters') return null;
  const th = v.inputs.thrusters;
  return h('div', { class: 'cols' },
    h('table', { class: 'grid-table compact' },
      h('caption', null, 'Thrusters'),
      h('thead', null, h('tr', null, h('th', null, '#'), h('th', null, 'Name'), h('th', null, 'Kind'),
        h('th', { class: 'num' }, 'Max command'), h('th', { class: 'num' }, 'Max rate'), h('th', null, 'Logged as'), h('th', null, 'Angle'))),
      h('tbody', { 'data-testid': 'thruster-rows' }, th.map((t, i) => h('tr', null, h('td', null, `thr_${i + 1}`), h('td', null, t.name),
        h('td', null, t.kind), h('td', { class: 'num' }, fmt(t.max_command)), h('td', { class: 'num' }, `${fmt(t.max_rate)} /s`),
        h('td', null, signalText(t.signal)), h('td', null, angleText(t, i)))))),
    h('table', { class: 'grid-table compact tmatrix' },
      h('caption', null, 'Configuration matrix T (rows: DOFs, columns: thrusters)'),
      h('thead', null, h('tr', null, h('th', null, ''), th.map((_, i) => h('th', { class: 'num' }, `thr_${i + 1}`)))),
      h('tbody', null, v.inputs.configuration.map((row, r) => h('tr', null, h('th', { scope: 'row' }, v.dofs[r]),
        row.map((x) => h('td', { class: 'num' }, String(Number(x.toFixed(4))).replace('-', '−'))))))));
}

export async function vesselPage(view, id) {
  const [v, campaigns] = await Promise.all([api.vessel(id), api.campaigns(id)]);
  fill(view, 
    h('div', { class: 'page-head' },
      h('h1', { 'data-testid': 'vessel-title' }, v.name, h('span', { class: 'tag' }, KIND_LABEL[v.kind] || v.kind), deletedBadge(v)),
      h('div', { class: 'actions' },
        renameControl({ what: 'vessel', name: v.name, needs: 'engineer', save: (n) => api.renameVessel(v.id, n) }),
        h('a', { class: 'btn', href: `#/vessels/new?from=${encodeURIComponent(v.id)}`, 'data-needs': 'engineer' }, 'Copy as new vessel'),
        h('a', { class: 'btn primary', href: `#/campaigns/new?vessel=${encodeURIComponent(v.id)}`, 'data-testid': 'new-campaign-for-vessel', 'data-needs': 'supervisor' }, '+ New campaign'))),
    vesselTrash.control(v),
    h('dl', { class: 'summary' },
      h('dt', null, 'DOFs'), h('dd', null, v.dofs.join(', ')),
      h('dt', null, 'Max forward speed'), h('dd', null, v.limits.surge ? `${fmt(knots(v.limits.surge.max_velocity), 2)} kn (${fmt(v.limits.surge.max_velocity)} m/s)` : '–'),
      h('dt', null, 'Inputs'), h('dd', null, inputsText(v)),
      h('dt', null, 'Controller rate'), h('dd', null, `${fmt(v.controller_rate_hz)} Hz`),
      h('dt', null, 'Logger rate'), h('dd', null, `${fmt(v.logger_rate_hz)} Hz`),
      h('dt', null, 'Heading ψ logged in'), h('dd', { 'data-testid': 'heading-unit' }, v.heading_unit === 'deg' ? 'degrees' : 'radians'),
      v.kind === 'dp3' ? [h('dt', null, 'Ship length L'), h('dd', { 'data-testid': 'ship-length' }, v.dp_prior ? fmtU(v.dp_prior.length_m, 'm') : 'not given (no prior)')] : null,
      h('dt', null, 'Created'), h('dd', null, fmtDate(v.created_at)),
      h('dt', null, 'Id'), h('dd', { class: 'mono' }, v.id)),
    h('h2', null, 'Limits'),
    limitsTable(v),
    autopilotTable(v),
    thrusterTables(v),
    thrusterLayout(v),
    h('h2', null, 'Campaigns'),
    campaigns.length === 0 ? h('p', { class: 'empty' }, 'No campaigns for this vessel yet.')
      : h('ul', { class: 'plain' }, campaigns.map((c) => h('li', null,
        h('a', { href: `#/campaigns/${c.id}` }, c.name), ' · ',
        c.families.map((f) => FAMILY_LABEL[f] || f).join(', ')))));
}

// ---- create form -------------------------------------------------------------

function clone(x) {
  return JSON.parse(JSON.stringify(x));
}

/** Form model from a profile: the T matrix is kept per DOF so DOF toggles keep values. */
function modelFrom(profile) {
  const p = clone(profile);
  const m = {
    name: p.name || '',
    kind: p.kind || 'rov6',
    dofs: DOFS.filter((d) => (p.dofs || []).includes(d)),
    controller_rate_hz: p.controller_rate_hz ?? null,
    logger_rate_hz: p.logger_rate_hz ?? null,
    limits: {},
    inputKind: p.inputs && p.inputs.kind === 'thrusters' ? 'thrusters' : 'generalized_forces',
    thrusters: [],
    tmatrix: {},
    headingUnit: p.heading_unit === 'deg' ? 'deg' : 'rad',
    // The DP prior: the form edits L; M″ (inertia_bis) is carried over.
    dpPrior: p.dp_prior ?? null,
    lengthM: p.dp_prior?.length_m ?? null,
    autopilotOn: p.autopilot != null,
    autopilot: {},
    feedForward: {
      w_minus_b: p.autopilot?.restoring_feed_forward?.w_minus_b ?? null,
      zg_w_minus_zb_b: p.autopilot?.restoring_feed_forward?.zg_w_minus_zb_b ?? null,
    },
  };
  for (const d of DOFS) {
    const l = (p.autopilot?.loops || {})[d] || {};
    m.autopilot[d] = { kp: l.kp ?? null, ki: l.ki ?? null, kd: l.kd ?? null };
  }
  for (const d of DOFS) {
    const l = (p.limits || {})[d] || {};
    m.limits[d] = Object.fromEntries(LIMIT_COLS.map((c) => [c.key, l[c.key] ?? null]));
  }
  if (m.inputKind === 'thrusters') {
    m.thrusters = p.inputs.thrusters.map((t) => ({ ...t }));
    (p.dofs || []).forEach((d, r) => { m.tmatrix[d] = [...(p.inputs.configuration[r] || [])]; });
  }
  return m;
}

async function templates() {
  const t = { rov: SURVEYOR_ROV, dp: SUPPLY_VESSEL, blank: BLANK_ROV };
  try {
    const vessels = await api.vessels();
    const live = (name, kind) => vessels.find((v) => v.name === name && v.kind === kind);
    const r = live(SURVEYOR_ROV.name, 'rov6');
    const d = live(SUPPLY_VESSEL.name, 'dp3');
    if (r) t.rov = r;
    if (d) t.dp = d;
  } catch { /* embedded templates */ }
  return t;
}

export async function vesselForm(view, query) {
  const tpl = await templates();
  let start = BLANK_ROV;
  if (query.get('from')) start = await api.vessel(query.get('from'));
  let m = modelFrom(start);
  if (query.get('from')) m.name = `${m.name} (copy)`;

  const form = h('form', { class: 'card form', 'data-testid': 'vessel-form', novalidate: true, 'aria-label': 'New vessel' });
  const sections = h('div');
  form.append(sections,
    h('div', { class: 'form-actions' },
      h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'create-vessel', 'data-needs': 'engineer' }, 'Create vessel'),
      h('a', { class: 'btn', href: '#/vessels' }, 'Cancel')));

  const load = (p, label) => {
    m = modelFrom(p);
    clearErrors(form);
    clearBanner();
    render();
    tplState.textContent = `Loaded template: ${label}`;
  };
  const tplState = h('span', { class: 'hint', 'aria-live': 'polite' });

  fill(view, 
    h('div', { class: 'page-head' }, h('h1', null, 'New vessel')),
    h('div', { class: 'template-bar', role: 'group', 'aria-label': 'Start from a template' },
      h('span', { class: 'muted' }, 'Start from:'),
      h('button', { type: 'button', class: 'btn', 'data-testid': 'template-rov', onClick: () => load(tpl.rov, 'Surveyor ROV') }, 'Surveyor ROV (6-DOF)'),
      h('button', { type: 'button', class: 'btn', 'data-testid': 'template-dp', onClick: () => load(tpl.dp, 'Supply vessel') }, 'Supply vessel (DP, Fossen 1995)'),
      h('button', { type: 'button', class: 'btn', 'data-testid': 'template-blank', onClick: () => load(BLANK_ROV, 'blank ROV') }, 'blank ROV'),
      tplState),
    form);

  const numInput = (value, field, label, onSet, extra = {}) => h('input', {
    type: 'number', step: 'any', value: value == null ? '' : String(value), 'data-field': field,
    'aria-label': label, ...extra,
    onInput: (e) => onSet(num(e.target.value)),
  });

  function render() {
    fill(sections, general(), dofsBox(), limitsBox(), autopilotBox(), inputsBox());
  }

  function general() {
    const name = h('input', { type: 'text', value: m.name, 'data-field': 'name', 'data-testid': 'vessel-name', required: true, autocomplete: 'off', onInput: (e) => { m.name = e.target.value; } });
    const kind = h('select', { 'data-field': 'kind', 'data-testid': 'vessel-kind', onChange: (e) => setKind(e.target.value) },
      Object.entries(KIND_LABEL).map(([k, l]) => h('option', { value: k, selected: k === m.kind }, l)));
    const ctl = numInput(m.controller_rate_hz, 'controller_rate_hz', 'Controller rate (Hz)', (x) => { m.controller_rate_hz = x; });
    const log = numInput(m.logger_rate_hz, 'logger_rate_hz', 'Logger rate (Hz)', (x) => { m.logger_rate_hz = x; });
    const psi = h('select', { 'data-field': 'heading_unit', 'data-testid': 'heading-unit', onChange: (e) => { m.headingUnit = e.target.value; } },
      [['rad', 'radians'], ['deg', 'degrees']].map(([k, l]) => h('option', { value: k, selected: m.headingUnit === k }, l)));
    return h('fieldset', null, h('legend', null, 'Vessel'),
      h('div', { class: 'row' },
        labelled('Name', name),
        labelled('Kind', kind),
        labelled('Controller rate [Hz]', ctl, 'references are fed at this rate'),
        labelled('Logger rate [Hz]', log),
        labelled('Heading ψ logged in', psi)),
      m.kind === 'dp3' ? h('div', { class: 'row' },
        labelled('Ship length L [m]', numInput(m.lengthM, 'dp_prior.length_m', 'Ship length L (m)', (x) => { m.lengthM = x; }, { placeholder: 'none', 'data-testid': 'ship-length' }),
          'Bis units (T″, K″) and a logged azimuth angle need it; without it the EKF starts from the data')) : null);
  }

  function setKind(kind) {
    m.kind = kind;
    if (kind === 'dp3') {
      m.dofs = ['surge', 'sway', 'yaw'];
      if (m.inputKind !== 'thrusters') {
        m.inputKind = 'thrusters';
        if (m.thrusters.length === 0) addThruster();
      }
    } else {
      m.dofs = [...DOFS];
      m.inputKind = 'generalized_forces';
    }
    render();
  }

  function dofsBox() {
    return h('fieldset', { 'data-field': 'dofs', 'data-error-host': '' }, h('legend', null, 'Modeled DOFs'),
      h('div', { class: 'checks' }, DOFS.map((d, i) => h('label', { class: 'check' },
        h('input', {
          type: 'checkbox', checked: m.dofs.includes(d), 'data-field': `dofs[${m.dofs.indexOf(d)}]`, 'data-testid': `dof-${d}`, value: d,
          onChange: (e) => {
            const on = new Set(m.dofs);
            if (e.target.checked) on.add(d); else on.delete(d);
            m.dofs = DOFS.filter((x) => on.has(x));
            render();
          },
        }), ` ${d}`, i === 0 ? h('span', { class: 'hint' }, ' (scheduling variable)') : null))));
  }

  function limitsBox() {
    const rows = m.dofs.map((d) => {
      const u = dofUnits(d);
      const l = m.limits[d];
      return h('tr', { 'data-field': `limits.${d}` },
        h('th', { scope: 'row' }, d),
        LIMIT_COLS.map((c) => {
          const inp = numInput(l[c.key], `limits.${d}.${c.key}`, `${d} ${c.label} (${c.unit(u)})`, (x) => {
            l[c.key] = x;
            if (d === 'surge' && c.key === 'max_velocity') knHint.textContent = x ? `= ${fmt(knots(x), 2)} kn` : '';
          }, { placeholder: c.required ? '' : 'none' });
          const knHint = h('span', { class: 'hint' });
          if (d === 'surge' && c.key === 'max_velocity' && l[c.key]) knHint.textContent = `= ${fmt(knots(l[c.key]), 2)} kn`;
          return h('td', { 'data-error-host': '' }, h('div', { class: 'unit-input' }, inp, h('span', { class: 'unit' }, c.unit(u))),
            d === 'surge' && c.key === 'max_velocity' ? knHint : null);
        }));
    });
    return h('fieldset', { 'data-field': 'limits', 'data-error-host': '' }, h('legend', null, 'Limits per DOF (SI, as given by the pilots)'),
      h('table', { class: 'grid-table edit', 'data-testid': 'limits-editor' },
        h('thead', null, h('tr', null, h('th', null, 'DOF'), LIMIT_COLS.map((c) => h('th', null, c.label, c.required ? '' : ' (opt.)')))),
        h('tbody', null, rows)),
      h('p', { class: 'hint' }, 'Surge max velocity is the vessel’s top forward speed: no grid speed may exceed it. Max accel slew-limits velocity references; the time constant T ≈ m/d sets PRBS clocks and settling times.'));
  }

  function autopilotBox() {
    if (m.kind !== 'rov6') return null;
    const on = h('input', {
      type: 'checkbox', checked: m.autopilotOn, 'data-testid': 'autopilot-on',
      onChange: (e) => { m.autopilotOn = e.target.checked; render(); },
    });
    const head = h('label', { class: 'check' }, on, ' Declare the ROV’s autopilot (its gains), so simulated flights of the plan fly through it');
    if (!m.autopilotOn) {
      return h('fieldset', { 'data-field': 'autopilot', 'data-error-host': '' }, h('legend', null, 'Autopilot (optional)'), head,
        h('p', { class: 'hint' }, 'Without it, predictions fly generic PI loops designed from the limits; how stiffly the real loops hold each DOF decides how much sensor noise becomes thrust, and so the spread of the estimates.'));
    }
    const rows = m.dofs.map((d) => {
      const g = m.autopilot[d];
      const att = d === 'roll' || d === 'pitch';
      const base = `autopilot.loops.${d}`;
      const cell = (key, label) => h('td', { 'data-error-host': '' },
        numInput(g[key], `${base}.${key}`, `${d} ${label}`, (x) => { g[key] = x; }, { min: '0', placeholder: key === 'kp' ? '' : (key === 'kd' ? 'velocity loop' : '0') }));
      return h('tr', { 'data-field': base },
        h('th', { scope: 'row' }, d),
        cell('kp', 'K_p'), cell('ki', 'K_i'),
        att ? cell('kd', 'K_d') : h('td', null, '–'));
    });
    const ff = (key, label, unit) => labelled(`${label} [${unit}]`,
      numInput(m.feedForward[key], `autopilot.restoring_feed_forward.${key}`, label, (x) => { m.feedForward[key] = x; }, { placeholder: 'none' }));
    return h('fieldset', { 'data-field': 'autopilot', 'data-error-host': '', 'data-testid': 'autopilot-editor' }, h('legend', null, 'Autopilot (optional)'), head,
      h('table', { class: 'grid-table edit' },
        h('thead', null, h('tr', null, h('th', null, 'DOF'), h('th', null, 'K_p'), h('th', null, 'K_i (opt.)'), h('th', null, 'K_d (roll, pitch)'))),
        h('tbody', null, rows)),
      h('p', { class: 'hint' }, 'Velocity loops: τ = K_p (ν_ref − ν) + K_i ∫(ν_ref − ν) dt (N per m/s, N·m per rad/s). With K_d, roll or pitch holds attitude: τ = K_p (η_ref − η) + K_d (ω_ref − ω) + K_i ∫(η_ref − η) dt (N·m per rad).'),
      h('div', { class: 'row' },
        ff('w_minus_b', 'Feed-forward W − B', 'N'),
        ff('zg_w_minus_zb_b', 'Feed-forward z_G W − z_B B', 'N·m')));
  }

  function addThruster() {
    m.thrusters.push({ name: `thruster ${m.thrusters.length + 1}`, kind: 'tunnel', max_command: 1, max_rate: 0.1 });
    for (const d of DOFS) {
      if (!m.tmatrix[d]) m.tmatrix[d] = [];
      m.tmatrix[d].length = m.thrusters.length;
      m.tmatrix[d] = Array.from(m.tmatrix[d], (x) => x ?? 0);
    }
  }

  function removeThruster(i) {
    m.thrusters.splice(i, 1);
    for (const d of DOFS) if (m.tmatrix[d]) m.tmatrix[d].splice(i, 1);
  }

  function inputsBox() {
    const sel = h('select', {
      'data-field': 'inputs.kind', 'data-testid': 'inputs-kind',
      onChange: (e) => {
        m.inputKind = e.target.value;
        if (m.inputKind === 'thrusters' && m.thrusters.length === 0) addThruster();
        render();
      },
    },
    h('option', { value: 'generalized_forces', selected: m.inputKind === 'generalized_forces' }, 'Generalized forces τ per DOF'),
    h('option', { value: 'thrusters', selected: m.inputKind === 'thrusters' }, 'Thruster commands u (τ = T K u)'));
    const box = h('fieldset', { 'data-field': 'inputs', 'data-error-host': '' }, h('legend', null, 'Input channels'), labelled('Actuation', sel));
    if (m.inputKind !== 'thrusters') return box;

    const trows = m.thrusters.map((t, i) => h('tr', { 'data-field': `inputs.thrusters[${i}]` },
      h('td', { class: 'mono' }, `thr_${i + 1}`),
      h('td', { 'data-error-host': '' }, h('input', { type: 'text', value: t.name, 'data-field': `inputs.thrusters[${i}].name`, 'aria-label': `Thruster ${i + 1} name`, onInput: (e) => { t.name = e.target.value; } })),
      h('td', { 'data-error-host': '' }, h('select', { 'data-field': `inputs.thrusters[${i}].kind`, 'aria-label': `Thruster ${i + 1} kind`, onChange: (e) => { t.kind = e.target.value; render(); } },
        THRUSTER_KINDS.map((k) => h('option', { value: k, selected: k === t.kind }, k)))),
      h('td', { 'data-error-host': '' }, numInput(t.max_command, `inputs.thrusters[${i}].max_command`, `Thruster ${i + 1} max command`, (x) => { t.max_command = x; })),
      h('td', { 'data-error-host': '' }, h('div', { class: 'unit-input' }, numInput(t.max_rate, `inputs.thrusters[${i}].max_rate`, `Thruster ${i + 1} max rate (per s)`, (x) => { t.max_rate = x; }), h('span', { class: 'unit' }, '/s'))),
      signalCell(t, i, numInput, render),
      angleCell(t, i, numInput, render),
      h('td', null, h('button', { type: 'button', class: 'btn small', 'aria-label': `Remove thruster ${i + 1}`, onClick: () => { removeThruster(i); render(); } }, '−'))));

    const mrows = m.dofs.map((d, r) => h('tr', { 'data-field': `inputs.configuration[${r}]` },
      h('th', { scope: 'row' }, d),
      m.thrusters.map((_, c) => h('td', { 'data-error-host': '' }, numInput(m.tmatrix[d][c], `inputs.configuration[${r}][${c}]`, `T ${d} thr_${c + 1}`, (x) => { m.tmatrix[d][c] = x; }, { class: 'cell' })))));

    box.append(
      h('table', { class: 'grid-table edit', 'data-field': 'inputs.thrusters', 'data-testid': 'thruster-editor' },
        h('caption', null, 'Thrusters (column order of T)'),
        h('thead', null, h('tr', null, h('th', null, 'Col'), h('th', null, 'Name'), h('th', null, 'Kind'), h('th', null, 'Max command'), h('th', null, 'Max rate'), h('th', null, 'Logged as'), h('th', null, 'Azimuth angle'), h('th', null, ''))),
        h('tbody', null, trows)),
      h('button', { type: 'button', class: 'btn small', 'data-testid': 'add-thruster', onClick: () => { addThruster(); render(); } }, '+ thruster'),
      h('table', { class: 'grid-table edit tmatrix', 'data-field': 'inputs.configuration', 'data-testid': 'tmatrix-editor' },
        h('caption', null, 'Configuration matrix T (rows: modeled DOFs, columns: thrusters)'),
        h('thead', null, h('tr', null, h('th', null, ''), m.thrusters.map((t, c) => h('th', { title: t.name }, `thr_${c + 1}`)))),
        h('tbody', null, mrows)));
    return box;
  }

  function collect() {
    const errs = [];
    const need = (x, field) => {
      if (x == null) errs.push({ field, message: 'required' });
      else if (!Number.isFinite(x)) errs.push({ field, message: 'not a number' });
      return x;
    };
    const body = {
      name: m.name.trim(),
      kind: m.kind,
      dofs: [...m.dofs],
      inputs: { kind: 'generalized_forces' },
      limits: {},
      controller_rate_hz: need(m.controller_rate_hz, 'controller_rate_hz'),
      logger_rate_hz: need(m.logger_rate_hz, 'logger_rate_hz'),
    };
    for (const d of m.dofs) {
      const l = {};
      for (const c of LIMIT_COLS) {
        const x = m.limits[d][c.key];
        if (c.required) l[c.key] = need(x, `limits.${d}.${c.key}`);
        else if (x != null) l[c.key] = need(x, `limits.${d}.${c.key}`);
      }
      body.limits[d] = l;
    }
    if (m.headingUnit === 'deg') body.heading_unit = 'deg';
    if (m.kind === 'dp3' && m.lengthM != null) {
      body.dp_prior = { ...(m.dpPrior ?? {}), length_m: need(m.lengthM, 'dp_prior.length_m') };
    }
    if (m.kind === 'rov6' && m.autopilotOn) {
      const loops = {};
      for (const d of m.dofs) {
        const g = m.autopilot[d];
        const base = `autopilot.loops.${d}`;
        const l = { kp: need(g.kp, `${base}.kp`) };
        if (g.ki != null) l.ki = need(g.ki, `${base}.ki`);
        if ((d === 'roll' || d === 'pitch') && g.kd != null) l.kd = need(g.kd, `${base}.kd`);
        loops[d] = l;
      }
      body.autopilot = { loops };
      const f = m.feedForward;
      if (f.w_minus_b != null || f.zg_w_minus_zb_b != null) {
        body.autopilot.restoring_feed_forward = {
          w_minus_b: need(f.w_minus_b, 'autopilot.restoring_feed_forward.w_minus_b'),
          zg_w_minus_zb_b: need(f.zg_w_minus_zb_b, 'autopilot.restoring_feed_forward.zg_w_minus_zb_b'),
        };
      }
    }
    if (m.inputKind === 'thrusters') {
      body.inputs = {
        kind: 'thrusters',
        thrusters: m.thrusters.map((t, i) => ({
          name: t.name, kind: t.kind,
          max_command: need(t.max_command, `inputs.thrusters[${i}].max_command`),
          max_rate: need(t.max_rate, `inputs.thrusters[${i}].max_rate`),
          ...collectSignal(t, i, need),
        })),
        configuration: m.dofs.map((d, r) => m.thrusters.map((_, c) => need(m.tmatrix[d][c], `inputs.configuration[${r}][${c}]`))),
      };
    }
    return { body, errs };
  }

  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    clearErrors(form);
    clearBanner();
    const { body, errs } = collect();
    if (errs.length) {
      errs.slice().reverse().forEach((x) => showFieldError(form, x.field, x.message));
      banner(`${errs.length} field${errs.length > 1 ? 's' : ''} to fix before submitting`);
      return;
    }
    const btn = form.querySelector('[data-testid="create-vessel"]');
    btn.disabled = true;
    try {
      const v = await api.createVessel(body);
      flash(`Vessel “${v.name}” created.`);
      location.hash = `#/vessels/${v.id}`;
    } catch (err) {
      showError(form, err);
    } finally {
      btn.disabled = false;
    }
  });

  render();
}
