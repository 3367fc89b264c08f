// Predicted precision on the campaign page: before the runs are flown, the
// plan is flown in simulation with a prior model and identified as the
// campaign will be; the table says how precisely each parameter will come
// out (GET /api/campaigns/{id}/precision, computed by a `precision` job).

import { api } from './api.js';
import { fmt, fmtSig, fmtDate, unitLabel } from './format.js';
import { h, fill, labelled } from './forms.js';
import { newestResult, planJobRunner, priorSelect, withPrior } from './planjob.js';
import { autopilotTable } from './vessels.js';

const PRIOR_LABEL = {
  profile: 'the vessel profile\u2019s rough numbers',
  reference: 'the source documents\u2019 vessel',
  model: 'a stored model',
};

function priorText(p) {
  if (!p) return '–';
  if (p.kind === 'model') return `model ${p.model_id.slice(0, 8)}… v${p.version}`;
  return PRIOR_LABEL[p.kind] || p.kind;
}

function pct(r) {
  return r == null ? '–' : `${fmtSig(100 * r, 2)} %`;
}

/** The Predicted precision section. `setPlan` refreshes it after a re-plan. */
export async function precisionSection(host, { campaign, plan: plan0 }) {
  const id = campaign.id;
  let plan = plan0;
  let stored = null;

  const priorSel = await priorSelect(id, 'precision-prior', (m) => m.kind !== 'state_space');
  const seedIn = h('input', { type: 'number', min: '0', step: '1', value: '1', class: 'short', 'data-field': 'settings.seed', 'data-testid': 'precision-seed' });
  const realIn = h('input', { type: 'number', min: '1', max: '100', step: '1', value: '20', class: 'short', 'data-field': 'settings.realisations', 'data-testid': 'precision-realisations' });
  const startBtn = h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'precision-start' }, 'Predict precision');
  const status = h('div', { class: 'precision-status', 'data-testid': 'precision-status', 'aria-live': 'polite' });
  const result = h('div', { class: 'precision-result', 'data-testid': 'precision-result' });
  const form = h('form', { class: 'card form', novalidate: true, 'data-needs': 'supervisor', 'data-testid': 'precision-form', 'aria-label': 'Predict precision', onSubmit: submit },
    h('div', { class: 'row' },
      labelled('Prior', priorSel, 'the vessel the plan is flown with in simulation'),
      labelled('Noise seed', seedIn, 'of the simulated sensor noise'),
      labelled('Realisations', realIn, 'flights of the plan in simulation; the predicted std is their spread')),
    h('div', { class: 'form-actions' }, startBtn),
    status);

  const runner = planJobRunner({ testid: 'precision', status, startBtn, onDone: () => load() });

  fill(host,
    h('h2', { class: 'section-title', 'data-section': 'precision' }, 'Predicted precision ',
      h('span', { class: 'hint' }, 'before the ship leaves port: how precisely this plan will determine each parameter')),
    form,
    result);

  async function load() {
    stored = await newestResult(id, 'precision', api.precision);
    render();
  }

  async function submit(ev) {
    ev.preventDefault();
    const body = { kind: 'precision', campaign_id: id, settings: { seed: Number(seedIn.value || 1), realisations: Number(realIn.value || 20) } };
    await runner.submit(withPrior(body, priorSel.value));
  }

  function render() {
    if (!plan) {
      fill(result, h('p', { class: 'empty' }, 'Generate a plan first: the prediction flies it.'));
      startBtn.disabled = true;
      return;
    }
    startBtn.disabled = false;
    if (!stored) {
      fill(result, h('p', { class: 'empty', 'data-testid': 'precision-none' }, 'No prediction yet. \u201cPredict precision\u201d flies the plan with the prior and identifies it (seconds to a minute).'));
      return;
    }
    const p = stored.prediction;
    const groups = [...new Set(p.parameters.map((r) => r.group))];
    const groupSel = h('select', { 'data-testid': 'precision-group', onChange: () => renderRows() },
      h('option', { value: '' }, `all groups (${p.total})`),
      groups.map((g) => h('option', { value: g }, `${g} (${p.parameters.filter((r) => r.group === g).length})`)));
    const tbody = h('tbody');
    function renderRows() {
      const g = groupSel.value;
      fill(tbody, p.parameters.filter((r) => !g || r.group === g).map((r) => h('tr', { class: r.determined ? '' : 'weak', 'data-testid': 'precision-row' },
        h('td', { class: 'mono' }, r.symbol),
        h('td', { class: 'num' }, r.grid_speed_mps == null ? '–' : `${fmt(r.grid_speed_mps, 2)} m/s`),
        h('td', { class: 'num' }, `${fmtSig(r.expected_value, 4)} ${unitLabel(r.unit)}`),
        h('td', { class: 'num' }, r.predicted_std == null ? '–' : `±${fmtSig(r.predicted_std, 2)} ${unitLabel(r.unit)}`),
        h('td', { class: 'num', title: r.relative_to ? `relative to ${r.relative_to}` : '' }, pct(r.relative_std)),
        h('td', { class: 'num' }, r.reported_std == null ? '–' : `±${fmtSig(r.reported_std, 2)} ${unitLabel(r.unit)}`,
          r.structure_limited ? h('span', { class: 'badge status weak', title: 'the model\u2019s structure, not the noise, limits this parameter: more runs of this plan will not sharpen it', 'data-testid': 'precision-limited' }, 'structure') : null),
        h('td', null, r.determined ? 'yes' : h('strong', null, 'no')))));
    }
    renderRows();
    fill(result,
      stored.current ? null : h('p', { class: 'banner warn', role: 'status', 'data-testid': 'precision-stale' },
        `This prediction is for plan v${stored.plan_version}; the plan has changed since. Predict again.`),
      h('p', { 'data-testid': 'precision-summary' },
        h('strong', null, `${p.determined} of ${p.total}`), ' parameters determined (relative std \u2264 10 %) by ',
        `${p.runs} runs in ${fmt(p.ship_hours, 1)} h of ship time`,
        ` \u00b7 spread of ${p.realisations} simulated flight${p.realisations === 1 ? '' : 's'}`,
        ` \u00b7 ${p.method === 'parallel_ekf' ? 'parallel EKF' : '\u03bb-filter'} \u00b7 prior: ${priorText(p.prior)}`,
        p.geometric_mean_relative_std != null ? ` \u00b7 geometric mean relative std ${pct(p.geometric_mean_relative_std)}` : '',
        h('span', { class: 'muted' }, ` \u00b7 plan v${stored.plan_version}, ${fmtDate(stored.finished_at)}`)),
      (() => {
        const limited = p.parameters.filter((r) => r.structure_limited).length;
        return limited ? h('p', { class: 'hint', 'data-testid': 'precision-structure' },
          `${limited} parameter${limited === 1 ? ' is' : 's are'} limited by the model\u2019s structure rather than the noise: the identification will report a std over 3\u00d7 the spread; more runs of this plan will not sharpen ${limited === 1 ? 'it' : 'them'}.`) : null;
      })(),
      stored.inferred_autopilot ? autopilotTable(
        { autopilot: stored.inferred_autopilot.autopilot, dofs: stored.inferred_autopilot.loops.map((l) => l.dof) },
        {
          title: 'Autopilot inferred from the flown runs',
          hint: 'The vessel profile declares no autopilot, so the prediction flew the plan through the loops fitted to the flown runs (their commands against their planned references). To keep them, copy them into the vessel profile (Copy as new vessel → Autopilot).',
          testid: 'precision-autopilot',
          heading: 'h3',
        },
      ) : null,
      h('h3', null, 'Weakest'),
      h('ol', { 'data-testid': 'precision-weakest' }, p.weakest.map((w) => h('li', null, w))),
      h('details', { class: 'sub', open: p.total <= 40 },
        h('summary', null, `Every parameter (${p.total})`),
        h('div', { class: 'row' }, labelled('Group', groupSel)),
        h('div', { class: 'table-wrap' },
          h('table', { class: 'grid-table', 'data-testid': 'precision-table' },
            h('thead', null, h('tr', null, ['Parameter', 'Grid speed', 'Expected', 'Predicted std', 'Relative', 'Will be reported', 'Determined'].map((t) => h('th', null, t)))),
            tbody))),
      h('details', { class: 'sub' }, h('summary', null, 'How it was predicted'),
        h('ul', null, p.notes.map((n) => h('li', null, n)))));
  }

  await load();

  return {
    setPlan(p) { plan = p; render(); load().catch(() => {}); },
    destroy() { runner.destroy(); },
  };
}
