// Campaigns: list and the create form (grid editor, families, excitation).

import { api } from './api.js';
import { campaignTrash } from './parenttrash.js';
import {
  DOFS, FAMILIES, FAMILY_LABEL, KIND_LABEL, KN, SIGNALS, SIGNAL_LABEL, dofUnits, fmt, fmtDate, fmtShort, knots,
} from './format.js';
import {
  h, fill, labelled, num, showError, clearErrors, clearBanner, showFieldError, banner, flash,
} from './forms.js';

export const DURATIONS = [
  { key: 'static_hold_s', label: 'Static hold', def: 20, help: 'hold after steady state (thesis ≥ 20 s)' },
  { key: 'dynamic_s', label: 'Dynamic run', def: 30, help: 'minimum length (thesis ≥ 30 s)' },
  { key: 'recursive_s', label: 'Recursive run', def: 100, help: 'minimum length (thesis ≥ 100 s)' },
  { key: 'validation_s', label: 'Validation run', def: 300, help: 'length (thesis ≥ 300 s)' },
  { key: 'dp_manoeuvre_s', label: 'DP manoeuvre', def: 600, help: 'minimum length (≈ 600 samples)' },
  { key: 'setup_s', label: 'Set-up between runs', def: 60, help: 'counted in the total trial time' },
];

export function gridText(c) {
  const s = c.grid.speeds;
  if (s.length === 0) return '–';
  const list = s.length <= 4 ? s.map((x) => fmtShort(x)).join(', ') : `${fmtShort(s[0])} … ${fmtShort(s[s.length - 1])}`;
  return `${list} ${c.grid.unit} (${s.length})`;
}

// ---- list -----------------------------------------------------------------

/**
 * The families a vessel can fly: its kind's, without the azimuth manoeuvre
 * (SI3) when it has no azimuth thruster — a vessel logging forces τ
 * determines every θ″ from SI1 and SI2.
 */
function familiesFor(v) {
  const azimuth = v.inputs?.kind === 'thrusters' && v.inputs.thrusters.some((t) => t.kind === 'azimuth');
  return (FAMILIES[v.kind] || []).filter((f) => f !== 'dp_azimuth' || azimuth);
}

export async function campaignList(view) {
  const [campaigns, vessels] = await Promise.all([api.campaigns(), api.vessels()]);
  const byId = new Map(vessels.map((v) => [v.id, v]));
  fill(view, 
    h('div', { class: 'page-head' },
      h('h1', null, 'Campaigns'),
      h('a', { class: 'btn primary', href: '#/campaigns/new', 'data-testid': 'new-campaign', 'data-needs': 'supervisor' }, '+ New campaign')),
    campaigns.length === 0
      ? h('p', { class: 'empty' }, vessels.length === 0
        ? h('span', null, 'No vessels yet: ', h('a', { href: '#/vessels/new' }, 'create a vessel'), ' first.')
        : 'No campaigns yet.')
      : h('table', { class: 'grid-table', 'data-testid': 'campaign-table' },
        h('thead', null, h('tr', null, h('th', null, 'Name'), h('th', null, 'Vessel'), h('th', null, 'Grid'),
          h('th', null, 'Families'), h('th', { class: 'num' }, 'Reps'), h('th', { class: 'num' }, 'Seed'), h('th', null, 'Created'))),
        h('tbody', null, campaigns.slice().reverse().map((c) => {
          const v = byId.get(c.vessel_id);
          return h('tr', { 'data-testid': 'campaign-row' },
            h('td', null, h('a', { href: `#/campaigns/${c.id}` }, c.name)),
            h('td', null, v ? h('a', { href: `#/vessels/${v.id}` }, v.name) : c.vessel_id),
            h('td', null, gridText(c)),
            h('td', null, c.families.map((f) => FAMILY_LABEL[f] || f).join(', ')),
            h('td', { class: 'num' }, c.repetitions ?? '–'),
            h('td', { class: 'num mono' }, c.seed ?? '–'),
            h('td', null, fmtDate(c.created_at)));
        }))),
    campaignTrash.list());
}

// ---- create form -------------------------------------------------------------

function round6(x) {
  return Number(x.toFixed(6));
}

export async function campaignForm(view, query) {
  const vessels = await api.vessels();
  if (vessels.length === 0) {
    fill(view, h('h1', null, 'New campaign'),
      h('p', { class: 'empty' }, 'A campaign is planned for a vessel: ', h('a', { href: '#/vessels/new' }, 'create a vessel'), ' first.'));
    return;
  }
  const pre = query.get('vessel');
  const m = {
    vessel: vessels.find((v) => v.id === pre) || vessels[vessels.length - 1],
    name: '',
    unit: 'kn',
    speeds: [],
    families: new Set(),
    repetitions: '',
    signal: 'prbs',
    quantity: 'velocity',
    fraction: 0.5,
    perDof: {},
    durations: Object.fromEntries(DURATIONS.map((d) => [d.key, d.def])),
    seed: '',
    fill: { from: '', to: '', step: '' },
  };
  const setVessel = (v) => {
    m.vessel = v;
    m.families = new Set(familiesFor(v));
    for (const d of DOFS) if (!m.perDof[d]) m.perDof[d] = { signal: '', amplitude: null, clock_period_s: null, prbs_order: null };
  };
  setVessel(m.vessel);

  const form = h('form', { class: 'card form', novalidate: true, 'data-testid': 'campaign-form', 'aria-label': 'New campaign' });
  const body = h('div');
  form.append(body, h('div', { class: 'form-actions' },
    h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'create-campaign', 'data-needs': 'supervisor' }, 'Create campaign'),
    h('a', { class: 'btn', href: '#/campaigns' }, 'Cancel'),
    h('span', { class: 'hint' }, 'The server dry-runs the plan: every limit violation is reported on its field.')));
  fill(view, h('div', { class: 'page-head' }, h('h1', null, 'New campaign')), form);

  const numInput = (value, field, label, onSet, extra = {}) => h('input', {
    type: 'number', step: 'any', value: value == null ? '' : String(value), 'data-field': field, 'aria-label': label, ...extra,
    onInput: (e) => onSet(num(e.target.value)),
  });

  const gridBox = h('fieldset', { 'data-field': 'grid', 'data-error-host': '', 'data-testid': 'grid-editor' });
  const famBox = h('fieldset', { 'data-field': 'families', 'data-error-host': '' });
  const excBox = h('fieldset', { 'data-field': 'excitation', 'data-error-host': '' });
  const repsHost = h('div', { class: 'fld-host' });

  function render() {
    fill(body, generalBox(), gridBox, famBox, excBox, durationsBox(), seedBox());
    renderGrid();
    renderFamilies();
    renderExcitation();
  }

  function generalBox() {
    const sel = h('select', {
      'data-field': 'vessel_id', 'data-testid': 'campaign-vessel',
      onChange: (e) => { setVessel(vessels.find((v) => v.id === e.target.value)); renderGrid(); renderFamilies(); renderExcitation(); renderReps(); },
    }, vessels.map((v) => h('option', { value: v.id, selected: v === m.vessel }, `${v.name} — ${KIND_LABEL[v.kind] || v.kind}`)));
    const name = h('input', { type: 'text', value: m.name, 'data-field': 'name', 'data-testid': 'campaign-name', autocomplete: 'off', placeholder: 'e.g. Stril Explorer, March', onInput: (e) => { m.name = e.target.value; } });
    renderReps();
    return h('fieldset', null, h('legend', null, 'Campaign'),
      h('div', { class: 'row' }, labelled('Vessel', sel), labelled('Name', name, null), repsHost));
  }

  function renderReps() {
    const dp = m.vessel.kind === 'dp3';
    const reps = h('input', {
      type: 'number', min: '1', step: '1', value: m.repetitions, 'data-field': 'repetitions', 'data-testid': 'campaign-repetitions',
      placeholder: dp ? '2 (default)' : '1 (default)', onInput: (e) => { m.repetitions = e.target.value; },
    });
    fill(repsHost, labelled('Repetitions per grid point × DOF', reps, dp ? 'DP: N ≥ 2 for the parallel EKF' : null));
  }

  // -- grid editor
  function renderGrid() {
    const vmax = m.vessel.limits.surge ? m.vessel.limits.surge.max_velocity : null;
    const toMps = (x) => (m.unit === 'kn' ? x * KN : x);
    const other = (x) => (m.unit === 'kn' ? `${fmt(x * KN)} m/s` : `${fmt(knots(x), 2)} kn`);
    const unitSel = h('select', {
      id: 'grid-unit', 'data-field': 'grid.unit', 'data-testid': 'grid-unit',
      onChange: (e) => { m.unit = e.target.value; renderGrid(); },
    }, ['kn', 'm/s'].map((u) => h('option', { value: u, selected: u === m.unit }, u)));

    const rows = m.speeds.map((s, i) => {
      const conv = h('span', { class: 'conv' });
      const upd = () => {
        const v = num(m.speeds[i]);
        conv.textContent = v == null || !Number.isFinite(v) ? '' : `= ${other(v)}`;
        conv.classList.toggle('over', v != null && vmax != null && toMps(v) > vmax + 1e-12);
        conv.title = conv.classList.contains('over') ? 'above the vessel’s maximum forward speed' : '';
      };
      const inp = h('input', {
        type: 'number', step: 'any', min: '0', value: s, 'data-field': `grid.speeds[${i}]`, 'data-testid': 'grid-speed',
        'aria-label': `Grid speed ${i + 1} (${m.unit})`,
        onInput: (e) => { m.speeds[i] = e.target.value; upd(); },
      });
      upd();
      return h('li', { class: 'speed-row', 'data-error-host': '' },
        h('span', { class: 'idx' }, `${i + 1}`), inp, h('span', { class: 'unit' }, m.unit), conv,
        h('button', { type: 'button', class: 'btn small', 'aria-label': `Remove speed ${i + 1}`, 'data-testid': 'grid-remove', onClick: () => { m.speeds.splice(i, 1); renderGrid(); } }, '−'));
    });

    const f = m.fill;
    const fillIn = (k, label) => h('input', {
      type: 'number', step: 'any', value: f[k], id: `grid-${k}`, 'data-testid': `grid-${k}`, 'aria-label': `Fill ${label} (${m.unit})`,
      onInput: (e) => { f[k] = e.target.value; },
    });
    const doFill = () => {
      const a = num(f.from); const b = num(f.to); const st = num(f.step);
      clearErrors(gridBox);
      if (![a, b, st].every((x) => x != null && Number.isFinite(x)) || st <= 0 || b < a) {
        showFieldError(gridBox, 'grid.fill', 'give from ≤ to and a step > 0');
        return;
      }
      const n = Math.floor((b - a) / st + 1e-9) + 1;
      if (n > 200) { showFieldError(gridBox, 'grid.fill', `${n} points: at most 200`); return; }
      m.speeds = Array.from({ length: n }, (_, i) => String(round6(a + i * st)));
      renderGrid();
    };

    fill(gridBox, 
      h('legend', null, 'Speed grid (LPV scheduling variable)'),
      h('div', { class: 'row' },
        labelled('Unit', unitSel),
        h('div', { class: 'fill', role: 'group', 'aria-label': 'Fill range', 'data-field': 'grid.fill', 'data-error-host': '' },
          h('span', { class: 'muted' }, 'Fill range'),
          fillIn('from', 'from'), h('span', null, 'to'), fillIn('to', 'to'), h('span', null, 'step'), fillIn('step', 'step'),
          h('span', { class: 'unit' }, m.unit),
          h('button', { type: 'button', class: 'btn', 'data-testid': 'grid-fill', onClick: doFill }, 'Fill')),
        vmax != null ? h('span', { class: 'hint max' }, `vessel max forward speed ${fmt(knots(vmax), 2)} kn (${fmt(vmax)} m/s)`) : null),
      h('ol', { class: 'speeds', 'data-field': 'grid.speeds', 'data-testid': 'grid-speeds', 'data-error-host': '' }, rows),
      h('div', { class: 'row' },
        h('button', {
          type: 'button', class: 'btn small', 'data-testid': 'grid-add',
          onClick: () => {
            const last = num(m.speeds[m.speeds.length - 1]);
            const prev = num(m.speeds[m.speeds.length - 2]);
            const step = last != null && prev != null ? last - prev : 0.5;
            m.speeds.push(last == null ? '' : String(round6(last + (step > 0 ? step : 0.5))));
            renderGrid();
            const all = gridBox.querySelectorAll('[data-testid="grid-speed"]');
            all[all.length - 1].focus();
          },
        }, '+ speed'),
        h('span', { class: 'hint' }, `${m.speeds.length} point${m.speeds.length === 1 ? '' : 's'}, ascending; 1 kn = 1852/3600 m/s`)));
  }

  function renderFamilies() {
    const fams = familiesFor(m.vessel);
    fill(famBox, h('legend', null, `Experiment families (${KIND_LABEL[m.vessel.kind]})`),
      h('div', { class: 'checks' }, fams.map((f) => h('label', { class: 'check' },
        h('input', {
          type: 'checkbox', value: f, checked: m.families.has(f), 'data-testid': `family-${f}`,
          onChange: (e) => { if (e.target.checked) m.families.add(f); else m.families.delete(f); },
        }), ` ${FAMILY_LABEL[f] || f}`))));
  }

  function renderExcitation() {
    const v = m.vessel;
    const signal = h('select', { 'data-field': 'excitation.signal', 'data-testid': 'exc-signal', onChange: (e) => { m.signal = e.target.value; } },
      SIGNALS.map((s) => h('option', { value: s, selected: s === m.signal }, SIGNAL_LABEL[s])));
    const quantity = h('select', { 'data-field': 'excitation.quantity', 'data-testid': 'exc-quantity', onChange: (e) => { m.quantity = e.target.value; renderExcitation(); } },
      h('option', { value: 'velocity', selected: m.quantity === 'velocity' }, 'velocity references'),
      h('option', { value: 'force', selected: m.quantity === 'force' }, 'open-loop forces'));
    const frac = numInput(m.fraction, 'excitation.amplitude_fraction', 'Amplitude fraction', (x) => { m.fraction = x; renderDefaults(); }, { min: '0', max: '1', 'data-testid': 'exc-fraction' });

    const ampUnit = (d) => {
      if (d === 'surge') return 'm/s';
      const u = dofUnits(d);
      return m.quantity === 'force' ? u.force : u.velocity;
    };
    const defAmp = (d) => {
      const l = v.limits[d];
      if (!l) return null;
      if (d === 'surge') return 0.3 * KN;
      const f = m.fraction != null && Number.isFinite(m.fraction) ? m.fraction : 0.5;
      return f * (m.quantity === 'force' ? l.max_force : l.max_velocity);
    };
    const ampInputs = [];
    const renderDefaults = () => ampInputs.forEach(([d, inp]) => {
      const a = defAmp(d);
      inp.placeholder = a == null ? 'default' : fmt(a);
    });
    const rows = v.dofs.map((d) => {
      const o = m.perDof[d];
      const base = `excitation.per_dof.${d}`;
      const amp = numInput(o.amplitude, `${base}.amplitude`, `${d} amplitude (${ampUnit(d)})`, (x) => { o.amplitude = x; });
      ampInputs.push([d, amp]);
      return h('tr', { 'data-field': base },
        h('th', { scope: 'row' }, d),
        h('td', { 'data-error-host': '' }, h('select', { 'data-field': `${base}.signal`, 'aria-label': `${d} signal`, onChange: (e) => { o.signal = e.target.value; } },
          h('option', { value: '', selected: !o.signal }, 'default'),
          SIGNALS.map((s) => h('option', { value: s, selected: s === o.signal }, SIGNAL_LABEL[s])))),
        h('td', { 'data-error-host': '' }, h('div', { class: 'unit-input' }, amp, h('span', { class: 'unit' }, ampUnit(d)))),
        h('td', { 'data-error-host': '' }, h('div', { class: 'unit-input' }, numInput(o.clock_period_s, `${base}.clock_period_s`, `${d} clock period (s)`, (x) => { o.clock_period_s = x; }, { placeholder: 'auto' }), h('span', { class: 'unit' }, 's'))),
        h('td', { 'data-error-host': '' }, numInput(o.prbs_order, `${base}.prbs_order`, `${d} PRBS order`, (x) => { o.prbs_order = x; }, { placeholder: 'auto', min: '3', max: '24', step: '1' })));
    });
    renderDefaults();
    fill(excBox, h('legend', null, 'Excitation'),
      h('div', { class: 'row' },
        labelled('Signal', signal),
        labelled('Quantity (non-surge DOFs)', quantity, 'surge is always a speed reference u_ref'),
        labelled('Amplitude fraction of limit', frac, 'in (0, 1]')),
      h('details', { class: 'sub' }, h('summary', null, 'Per-DOF overrides'),
        h('table', { class: 'grid-table edit', 'data-field': 'excitation.per_dof', 'data-testid': 'per-dof-editor' },
          h('thead', null, h('tr', null, h('th', null, 'DOF'), h('th', null, 'Signal'), h('th', null, 'Amplitude'), h('th', null, 'Clock period'), h('th', null, 'PRBS order (3–24)'))),
          h('tbody', null, rows)),
        h('p', { class: 'hint' }, 'Empty = default. Placeholders show the default amplitude (surge: 0.3 kn speed excursion about the grid speed). The clock period is the PRBS / random-binary chip length, or the square wave’s half period.')));
  }

  function durationsBox() {
    return h('details', { class: 'card-sub', 'data-field': 'durations', 'data-error-host': '' },
      h('summary', null, 'Durations'),
      h('div', { class: 'row' }, DURATIONS.map((d) => labelled(`${d.label} [s]`,
        numInput(m.durations[d.key], `durations.${d.key}`, null, (x) => { m.durations[d.key] = x; }, { min: '0' }), d.help))));
  }

  function seedBox() {
    const seed = h('input', {
      type: 'text', inputmode: 'numeric', pattern: '[0-9]*', value: m.seed, 'data-field': 'seed', 'data-testid': 'campaign-seed',
      placeholder: 'server default', autocomplete: 'off', onInput: (e) => { m.seed = e.target.value.trim(); },
    });
    return h('fieldset', null, h('legend', null, 'Reproducibility'),
      h('div', { class: 'row' }, labelled('Seed', seed, 'every pseudo-random sequence is a pure function of it')));
  }

  function collect() {
    const errs = [];
    const speeds = m.speeds.map((s, i) => {
      const x = num(s);
      if (x == null) errs.push({ field: `grid.speeds[${i}]`, message: 'required' });
      else if (!Number.isFinite(x)) errs.push({ field: `grid.speeds[${i}]`, message: 'not a number' });
      return x;
    });
    const fams = familiesFor(m.vessel).filter((f) => m.families.has(f));
    // Server paths index the submitted array: families[i] is the i-th checked box.
    famBox.querySelectorAll('input[type=checkbox]').forEach((cb) => {
      const i = fams.indexOf(cb.value);
      if (i >= 0) cb.setAttribute('data-field', `families[${i}]`);
      else cb.removeAttribute('data-field');
    });
    const perDof = {};
    for (const d of m.vessel.dofs) {
      const o = m.perDof[d];
      const e = {};
      if (o.signal) e.signal = o.signal;
      for (const k of ['amplitude', 'clock_period_s', 'prbs_order']) {
        if (o[k] == null) continue;
        if (!Number.isFinite(o[k])) errs.push({ field: `excitation.per_dof.${d}.${k}`, message: 'not a number' });
        e[k] = o[k];
      }
      if (Object.keys(e).length) perDof[d] = e;
    }
    const excitation = { signal: m.signal, quantity: m.quantity, per_dof: perDof };
    if (m.fraction != null) excitation.amplitude_fraction = m.fraction;
    const durations = {};
    for (const d of DURATIONS) {
      const x = m.durations[d.key];
      if (x == null) continue;
      if (!Number.isFinite(x)) errs.push({ field: `durations.${d.key}`, message: 'not a number' });
      durations[d.key] = x;
    }
    const b = {
      vessel_id: m.vessel.id, name: m.name.trim(), grid: { unit: m.unit, speeds }, families: fams, excitation, durations,
    };
    if (String(m.repetitions).trim() !== '') {
      const r = Number(m.repetitions);
      if (!Number.isInteger(r)) errs.push({ field: 'repetitions', message: 'must be a whole number' });
      b.repetitions = r;
    }
    let raw = JSON.stringify(b);
    if (m.seed !== '') {
      // Seeds are u64: splice the digits in so values beyond 2^53 stay exact.
      if (!/^\d{1,20}$/.test(m.seed)) errs.push({ field: 'seed', message: 'a whole number ≥ 0' });
      else raw = `${raw.slice(0, -1)},"seed":${m.seed}}`;
    }
    return { raw, errs };
  }

  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    clearErrors(form);
    clearBanner();
    const { raw, errs } = collect();
    if (errs.length) {
      errs.slice().reverse().forEach((x) => showFieldError(form, x.field, x.message));
      banner(`${errs.length} field${errs.length > 1 ? 's' : ''} to fix before submitting`);
      return;
    }
    const btn = form.querySelector('[data-testid="create-campaign"]');
    btn.disabled = true;
    try {
      const c = await api.createCampaign(null, raw);
      flash(`Campaign “${c.name}” created. Generate its plan.`);
      location.hash = `#/campaigns/${c.id}`;
    } catch (err) {
      showError(form, err);
    } finally {
      btn.disabled = false;
    }
  });

  render();
}
