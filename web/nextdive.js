// The next dive on the campaign page: after a dive's runs are uploaded and
// scored, a `next_dive` job counts what was flown (good and weak runs) and
// proposes the planned runs that buy the most precision per hour for the
// next dive; the section shows them in order with why, and links their
// printable run sheet (GET /api/campaigns/{id}/next-dive[/runsheet]).

import { api } from './api.js';
import { fmt, fmtSig, fmtDate, hms } from './format.js';
import { h, fill, labelled } from './forms.js';
import { newestResult, planJobRunner, priorSelect, withPrior } from './planjob.js';

function times(r) {
  return r == null ? 'not yet identifiable' : `\u00d7${fmtSig(r, 3)}`;
}

/** The Next dive section. `setPlan` refreshes it after a re-plan. */
export async function nextDiveSection(host, { campaign, plan: plan0 }) {
  const id = campaign.id;
  let plan = plan0;
  let stored = null;

  const priorSel = await priorSelect(id, 'next-dive-prior', (m) => m.kind === 'lpv');
  const hoursIn = h('input', { type: 'number', min: '0.1', max: '48', step: '0.1', value: '4', class: 'short', 'data-field': 'settings.dive_hours', 'data-testid': 'next-dive-hours' });
  const startBtn = h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'next-dive-start' }, 'Propose next dive');
  const status = h('div', { class: 'precision-status', 'data-testid': 'next-dive-status', 'aria-live': 'polite' });
  const result = h('div', { class: 'next-dive-result', 'data-testid': 'next-dive-result' });
  const form = h('form', { class: 'card form', novalidate: true, 'data-needs': 'supervisor', 'aria-label': 'Propose next dive', onSubmit: submit },
    h('div', { class: 'row' },
      labelled('Prior', priorSel, 'the vessel the candidate runs are flown with in simulation'),
      labelled('Dive (h)', hoursIn, 'hours for runs and set-up')),
    h('div', { class: 'form-actions' }, startBtn),
    status);
  const runner = planJobRunner({ testid: 'next-dive', status, startBtn, onDone: () => load() });

  fill(host,
    h('h2', { class: 'section-title', 'data-section': 'next-dive' }, 'Next dive ',
      h('span', { class: 'hint' }, 'after each dive: what was flown counts, and the runs that buy the most precision come next')),
    form,
    result);

  async function load() {
    stored = await newestResult(id, 'next_dive', api.nextDive);
    render();
  }

  async function submit(ev) {
    ev.preventDefault();
    const body = withPrior({ kind: 'next_dive', campaign_id: id, settings: { dive_hours: Number(hoursIn.value || 4) } }, priorSel.value);
    await runner.submit(body);
  }

  function render() {
    if (!plan) {
      fill(result, h('p', { class: 'empty' }, 'Generate a plan first: the next dive is drawn from it.'));
      startBtn.disabled = true;
      return;
    }
    startBtn.disabled = false;
    if (!stored) {
      fill(result, h('p', { class: 'empty', 'data-testid': 'next-dive-none' }, 'No proposal yet. Upload the dive\u2019s runs, then \u201cPropose next dive\u201d.'));
      return;
    }
    const p = stored.proposal;
    fill(result,
      stored.current ? null : h('p', { class: 'banner warn', role: 'status', 'data-testid': 'next-dive-stale' },
        `This proposal was drawn from plan v${stored.plan_version}; the plan has changed since. Propose again.`),
      h('p', { 'data-testid': 'next-dive-summary' },
        `${p.flown_runs} flown run${p.flown_runs === 1 ? '' : 's'} counted: stds ${times(p.relative_std_now)} the whole plan\u2019s now; `,
        h('strong', null, `${p.proposed.length} run${p.proposed.length === 1 ? '' : 's'} in ${fmt(p.hours, 2)} h`),
        ` of the ${fmt(p.dive_hours, 1)} h dive bring them to ${times(p.relative_std_after)}`,
        p.left_for_later ? `; ${p.left_for_later} planned run${p.left_for_later === 1 ? '' : 's'} left for later` : '',
        p.uncovered_speeds_mps.length ? `; still no data at ${p.uncovered_speeds_mps.map((s) => `${fmt(s, 2)} m/s`).join(', ')}` : '',
        '.'),
      p.proposed.length ? h('p', null, h('a', { class: 'btn', href: api.nextDiveSheetUrl(id), target: '_blank', rel: 'noopener', 'data-testid': 'next-dive-sheet' }, 'Run sheet of the next dive')) : null,
      h('div', { class: 'table-wrap' },
        h('table', { class: 'grid-table', 'data-testid': 'next-dive-table' },
          h('thead', null, h('tr', null, ['#', 'Run', 'Length', 'Stds after', 'Why'].map((t) => h('th', null, t)))),
          h('tbody', null, p.proposed.map((r, i) => h('tr', { 'data-testid': 'next-dive-row' },
            h('td', { class: 'num' }, String(i + 1)),
            h('td', { class: 'mono' }, r.code),
            h('td', { class: 'num' }, hms(r.duration_s)),
            h('td', { class: 'num' }, r.relative_std_after > 0 ? `\u00d7${fmtSig(r.relative_std_after, 3)}` : '\u2013'),
            h('td', null, r.reason)))))),
      h('details', { class: 'sub' }, h('summary', null, 'How it was proposed'),
        h('ul', null, p.notes.map((n) => h('li', null, n)),
          h('li', { class: 'muted' }, `plan v${stored.plan_version}, ${fmtDate(stored.finished_at)}`))));
  }

  await load();

  return {
    setPlan(p) { plan = p; render(); load().catch(() => {}); },
    destroy() { runner.destroy(); },
  };
}
