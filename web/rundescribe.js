// What a run is — role, grid speed, excited DOFs, signal, notes. On the run
// page: each value with where it came from (a "user", "plan" or "inferred"
// badge, the inference's reason under it), an edit form that PATCHes
// /api/runs/{id} (only the fields changed), a per-field "↺" that clears a
// user value back to the plan's or the inferred one, and "Confirm inferred"
// that makes the inferred values the supervisor's. In the campaign's runs
// list: role · speed · DOFs in one compact cell.

import { api } from './api.js';
import { DOFS, FAMILY_LABEL, KN, fmt, fmtKn } from './format.js';
import { h, fill, labelled, num, banner, clearErrors, showFieldError } from './forms.js';

export const ROLE_LABEL = { static: 'Static', dynamic: 'Dynamic', recursive: 'Recursive', validation: 'Validation' };
/** Roles a vessel kind's runs can play (server: RunRole::allowed_for). */
export const ROLES_FOR = { rov6: ['static', 'dynamic', 'recursive', 'validation'], dp3: ['dynamic', 'validation'] };
export const RUN_SIGNAL_LABEL = {
  square: 'Square wave', prbs: 'PRBS', multisine: 'Multisine', random_binary: 'Random binary', other: 'Other',
};
const SOURCE_HELP = {
  user: 'said by the supervisor (upload metadata or an edit): wins over the plan and the data',
  plan: 'from the planned experiment the run was matched to',
  inferred: 'inferred from the data: confirm or correct it',
};
const FIELDS = [
  ['role', 'Role'],
  ['grid_speed_mps', 'Grid speed'],
  ['excited_dofs', 'Excited DOFs'],
  ['signal', 'Signal'],
  ['notes', 'Notes'],
];

/** The role a run plays (effective description), or null. */
export function runRole(run) {
  const d = run && run.description;
  return d && d.role ? d.role.value : null;
}

/** The family identification treats a run as, or null. */
export function runFamily(run) {
  const d = run && run.description;
  return d ? d.family || null : null;
}

/** "0.514 m/s (1 kn)" */
export function speedText(mps) {
  return mps == null ? '–' : `${fmt(mps)} m/s (${fmtKn(mps)} kn)`;
}

function valueText(key, v) {
  if (v == null) return '–';
  switch (key) {
    case 'role': return ROLE_LABEL[v] || v;
    case 'grid_speed_mps': return speedText(v);
    case 'excited_dofs': return v.length ? v.join(', ') : 'none';
    case 'signal': return RUN_SIGNAL_LABEL[v] || v;
    default: return String(v);
  }
}

/** "inferred" / "plan" / "user" badge; the reason (if any) as its title. */
export function sourceBadge(f) {
  return h('span', {
    class: `badge src src-${f.source}`, 'data-testid': 'source-badge', 'data-source': f.source,
    title: f.reason ? `${SOURCE_HELP[f.source]}: ${f.reason}` : SOURCE_HELP[f.source],
  }, f.source);
}

/** Role · speed · DOFs for the runs list; inferred values in italics with "?". */
export function describeCell(run) {
  const d = run.description || {};
  const bit = (key, text) => {
    const f = d[key];
    if (!f) return null;
    const inferred = f.source === 'inferred';
    return h('span', {
      class: `desc-bit${inferred ? ' inferred' : ''}`, title: `${f.source}${f.reason ? `: ${f.reason}` : ''}`,
      'data-field': key, 'data-source': f.source,
    }, text(f.value), inferred ? '?' : '');
  };
  const parts = [
    bit('role', (v) => ROLE_LABEL[v] || v),
    bit('grid_speed_mps', (v) => `${fmtKn(v)} kn`),
    bit('excited_dofs', (v) => (v.length ? v.join('+') : 'none')),
  ].filter(Boolean);
  return h('span', {
    class: 'run-desc', 'data-testid': 'run-description', 'data-role': runRole(run) || '',
    'data-role-source': d.role ? d.role.source : '',
  }, parts.length ? parts.flatMap((p, i) => (i ? [' · ', p] : [p])) : h('span', { class: 'muted' }, '–'));
}

/**
 * The description section of the run page. `vessel` gives the DOFs and
 * kind; `onSaved(run)` is called with the run after a successful PATCH.
 */
export function descriptionSection(run0, { vessel, onSaved }) {
  let run = run0;
  let editing = false;
  const host = h('section', { class: 'card run-description', 'data-testid': 'run-description-card', 'aria-label': 'What the run is' });
  const dofs = (vessel && vessel.dofs) || DOFS;
  const roles = ROLES_FOR[vessel && vessel.kind] || ROLES_FOR.rov6;

  async function send(body, form) {
    if (form) clearErrors(form);
    try {
      run = await api.describeRun(run.id, body);
    } catch (err) {
      if (form && err.field && showFieldError(form, err.field, err.message, err.limit)) return false;
      banner(`${err.status ? `${err.status} · ` : ''}${err.message}${err.field ? ` [${err.field}]` : ''}`);
      return false;
    }
    editing = false;
    render();
    if (onSaved) onSaved(run);
    return true;
  }

  function row(key, label) {
    const d = run.description || {};
    const f = d[key];
    const reset = f && f.source === 'user' && key !== 'notes' ? h('button', {
      type: 'button', class: 'link small', 'data-testid': 'desc-reset', 'data-needs': 'supervisor', 'data-field': key,
      title: 'clear the user value: the plan’s or the inferred value applies again',
      onClick: () => send({ [key]: null }),
    }, '↺ back to plan / data') : null;
    return [
      h('dt', null, label),
      h('dd', { 'data-testid': 'desc-field', 'data-field': key, 'data-source': f ? f.source : '' },
        h('span', { class: 'desc-value', 'data-testid': 'desc-value' }, f ? valueText(key, f.value) : '–'),
        f ? [' ', sourceBadge(f)] : h('span', { class: 'muted' }, key === 'notes' ? '' : ' not known'),
        reset ? [' ', reset] : null,
        f && f.reason && f.source !== 'user' ? h('div', { class: 'hint desc-reason', 'data-testid': 'desc-reason' }, f.reason) : null),
    ];
  }

  function form() {
    const d = run.description || {};
    const val = (k) => (d[k] ? d[k].value : null);
    const roleSel = h('select', { 'data-field': 'role', 'data-testid': 'desc-role' },
      val('role') == null ? h('option', { value: '', selected: true }, '– not known –') : null,
      roles.map((r) => h('option', { value: r, selected: val('role') === r }, ROLE_LABEL[r])));
    const speed = val('grid_speed_mps');
    const unitSel = h('select', { 'data-testid': 'desc-speed-unit', 'aria-label': 'Speed unit' },
      h('option', { value: 'kn', selected: true }, 'kn'), h('option', { value: 'm/s' }, 'm/s'));
    const speedIn = h('input', {
      type: 'number', step: 'any', min: '0', class: 'short', 'data-field': 'grid_speed_kn', 'data-testid': 'desc-speed',
      value: speed == null ? '' : String(Number((speed / KN).toFixed(3))),
    });
    unitSel.addEventListener('change', () => {
      const v = num(speedIn.value);
      const kn = unitSel.value === 'kn';
      speedIn.dataset.field = kn ? 'grid_speed_kn' : 'grid_speed_mps';
      if (v != null && Number.isFinite(v)) speedIn.value = String(Number((kn ? v / KN : v * KN).toFixed(3)));
    });
    const excited = new Set(val('excited_dofs') || []);
    const dofBox = h('div', { class: 'checks', 'data-field': 'excited_dofs', 'data-testid': 'desc-dofs', role: 'group', 'aria-label': 'Excited DOFs' },
      dofs.map((dof) => h('label', { class: 'check' }, h('input', { type: 'checkbox', value: dof, checked: excited.has(dof), 'data-testid': 'desc-dof' }), ` ${dof}`)));
    const signalSel = h('select', { 'data-field': 'signal', 'data-testid': 'desc-signal' },
      val('signal') == null ? h('option', { value: '', selected: true }, '– not known –') : null,
      Object.entries(RUN_SIGNAL_LABEL).map(([k, label]) => h('option', { value: k, selected: val('signal') === k }, label)));
    const notesIn = h('textarea', { 'data-field': 'notes', 'data-testid': 'desc-notes', rows: '3', maxlength: '2000' });
    notesIn.value = val('notes') || '';
    const status = h('span', { class: 'hint', role: 'status', 'data-testid': 'desc-status' });

    async function save(ev) {
      ev.preventDefault();
      const body = {};
      if (roleSel.value && roleSel.value !== val('role')) body.role = roleSel.value;
      const v = num(speedIn.value);
      if (v != null) {
        const mps = unitSel.value === 'kn' ? v * KN : v;
        if (!Number.isFinite(v) || speed == null || Math.abs(mps - speed) > 1e-6) body[speedIn.dataset.field] = v;
      }
      const picked = [...dofBox.querySelectorAll('input:checked')].map((c) => c.value);
      const before = val('excited_dofs');
      if (before == null ? picked.length : picked.join() !== [...before].sort((a, b) => dofs.indexOf(a) - dofs.indexOf(b)).join()) body.excited_dofs = picked;
      if (signalSel.value && signalSel.value !== val('signal')) body.signal = signalSel.value;
      const notes = notesIn.value.trim();
      if (notes !== (val('notes') || '')) body.notes = notes || null;
      if (!Object.keys(body).length) { status.textContent = 'Nothing changed.'; return; }
      status.textContent = 'Saving…';
      if (!(await send(body, f))) status.textContent = '';
    }

    const f = h('form', { class: 'form desc-form', novalidate: true, 'data-testid': 'desc-form', 'aria-label': 'Describe the run', onSubmit: save },
      h('div', { class: 'row' },
        labelled('Role', roleSel, 'what identification does with it'),
        h('div', { class: 'fld' }, h('label', { for: speedIn.id || (speedIn.id = `desc-speed-${run.id}`) }, 'Grid speed'),
          h('span', { class: 'with-unit' }, speedIn, unitSel), h('span', { class: 'hint' }, 'the speed it was flown at')),
        labelled('Signal', signalSel)),
      h('div', { class: 'fld', 'data-error-host': '' }, h('span', { class: 'label' }, 'Excited DOFs'), dofBox),
      labelled('Notes', notesIn, 'at most 2000 characters'),
      h('div', { class: 'form-actions' },
        h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'desc-save' }, 'Save'),
        h('button', { type: 'button', class: 'btn', 'data-testid': 'desc-cancel', onClick: () => { editing = false; render(); } }, 'Cancel'),
        status));
    return f;
  }

  function render() {
    const d = run.description || {};
    const inferred = FIELDS.filter(([k]) => d[k] && d[k].source === 'inferred');
    const confirm = inferred.length ? h('button', {
      type: 'button', class: 'btn small', 'data-testid': 'desc-confirm', 'data-needs': 'supervisor',
      title: 'make the inferred values the supervisor’s',
      onClick: () => send(Object.fromEntries(inferred.map(([k]) => [k, d[k].value]))),
    }, `✓ Confirm inferred (${inferred.length})`) : null;
    fill(host,
      h('div', { class: 'desc-head' },
        h('h2', null, 'What the run is ', h('span', { class: 'hint' }, 'the supervisor’s word wins over the plan, the plan over what the data show')),
        editing ? null : h('div', { class: 'actions' }, confirm,
          h('button', { type: 'button', class: 'btn small', 'data-testid': 'desc-edit', 'data-needs': 'supervisor', onClick: () => { editing = true; render(); } }, '✎ Edit'))),
      editing ? form() : h('dl', { class: 'summary desc-list', 'data-testid': 'desc-list' },
        FIELDS.map(([k, label]) => row(k, label)),
        d.family ? [h('dt', null, 'Identified as'), h('dd', { 'data-testid': 'desc-family' }, FAMILY_LABEL[d.family] || d.family)] : null));
  }

  render();
  return host;
}
