// The "Missing physics" panel of a model page: start a discovery job on the
// model (its own runs, held-out runs kept held out), follow its progress
// (never backwards), cancel it, open the report when it is done; earlier
// reports on the model; for an augmented model, the report that produced it.

import { api, urls } from './api.js';
import { fmtDate } from './format.js';
import { h, fill } from './forms.js';
import { errLine, jobStateBadge } from './identify.js';

const TERMINAL = new Set(['succeeded', 'failed', 'cancelled', 'interrupted']);

export async function discoveryPanel(model) {
  const box = h('section', { class: 'card', 'data-testid': 'discovery-panel', 'aria-label': 'Missing-physics discovery' });
  let timer = null;
  let destroyed = false;
  const [reports, parentReports] = await Promise.all([
    api.discrepancies(model.id).catch(() => []),
    model.parent_id ? api.discrepancies(model.parent_id).catch(() => []) : Promise.resolve([]),
  ]);
  const origin = parentReports.find((r) => r.augmented_model_id === model.id);
  const status = h('div', { class: 'job-msg', 'data-testid': 'discover-status', role: 'status', 'aria-live': 'polite' });
  const physical = model.kind === 'lpv';
  const start = h('button', {
    type: 'button', class: 'btn primary', 'data-testid': 'discover-start', 'data-needs': 'supervisor', disabled: !physical,
    title: physical ? 'Simulate the model on its runs, locate the misfit, name the left-out physics, store the augmented model as the next version' : 'Discovery augments a physical LPV model (M, D̄); this one has none',
    onClick: run,
  }, 'Discover missing physics');

  async function run() {
    start.disabled = true;
    fill(status, h('span', { class: 'spinner', 'aria-hidden': 'true' }), ' submitting…');
    let job;
    try {
      job = await api.submitJob({ kind: 'discover', model_id: model.id, campaign_id: model.campaign_id });
    } catch (err) {
      start.disabled = false;
      fill(status, h('span', { class: 'error-text', role: 'alert', 'data-testid': 'discover-error' }, errLine(err)));
      return;
    }
    const bar = h('progress', { max: '1', value: 0, 'data-testid': 'discover-progress' });
    const text = h('span', { class: 'progress-text', 'data-testid': 'discover-stage' }, 'queued');
    const state = h('span');
    const cancel = h('button', {
      type: 'button', class: 'btn small danger', 'data-testid': 'discover-cancel', 'data-needs': 'supervisor',
      onClick: () => {
        cancel.disabled = true;
        api.cancelJob(job.id).catch((err) => {
          cancel.disabled = false;
          state.append(h('span', { class: 'error-text', role: 'alert' }, ` ${errLine(err)}`));
        });
      },
    }, 'Cancel');
    let lastState = null;
    fill(status, h('div', { class: 'progress-box' }, bar, text), state, ' ', cancel);
    const poll = async () => {
      if (destroyed) return;
      try {
        job = await api.job(job.id);
      } catch (err) {
        fill(status, h('span', { class: 'error-text', role: 'alert' }, errLine(err)));
        return;
      }
      // Never backwards within one attempt (a retry starts over).
      const p = job.state === 'succeeded' ? 1 : job.progress || 0;
      bar.value = job.state === lastState ? Math.max(bar.value, p) : p;
      lastState = job.state;
      text.textContent = `${Math.round(bar.value * 100)} %${job.stage ? ` · ${job.stage}` : ''}`;
      fill(state, jobStateBadge(job.state));
      if (!TERMINAL.has(job.state)) { timer = setTimeout(poll, 400); return; }
      cancel.remove();
      start.disabled = false;
      if (job.state === 'succeeded' && job.result && job.result.discrepancy_id) {
        location.hash = urls.discrepancy(job.result.discrepancy_id);
      } else if (job.error) {
        fill(status, h('span', { class: 'error-text', role: 'alert', 'data-testid': 'discover-error' }, job.error.message, job.error.field ? h('span', { class: 'mono' }, ` [${job.error.field}]`) : null));
      }
    };
    poll();
  }

  fill(box,
    h('p', { class: 'hint' }, 'Simulates this model on its estimation and held-out runs (free run and k-step), locates where it parts from the recordings (DOF, time, frequency band, operating condition), tests a library of left-out physics — quadratic damping, Coriolis, restoring, tether, current, missing coupling, actuator lag, delay, saturation, dead zone — and stores the augmented model as the next version when a term earns its place on held-out data.'),
    origin ? h('p', { 'data-testid': 'discover-origin' }, 'This model was produced by ', h('a', { href: urls.discrepancy(origin.id) }, `the discovery report of ${fmtDate(origin.created_at)}`), ' on its parent.') : null,
    h('div', { class: 'actions' }, start),
    status,
    reports.length
      ? h('ul', { class: 'plain', 'data-testid': 'discover-reports' }, reports.map((r) => h('li', null,
        h('a', { href: urls.discrepancy(r.id), 'data-testid': 'discover-report-link' }, `Report of ${fmtDate(r.created_at)}`),
        h('span', { class: 'hint' }, ` · ${r.summary[0] || ''}`),
        r.augmented_model_id ? [' · ', h('a', { href: urls.model(r.augmented_model_id) }, 'augmented model')] : null)))
      : h('p', { class: 'hint', 'data-testid': 'discover-none' }, 'No discovery run on this model yet.'));

  return { el: box, destroy() { destroyed = true; if (timer) clearTimeout(timer); } };
}
