// A planning job (precision, design) submitted from a campaign-page
// section: submit, follow with monotone progress, show the failure with
// its field, and reload the section's result when it succeeds.

import { api } from './api.js';
import { h, fill } from './forms.js';
import { errLine, jobStateBadge } from './identify.js';

/** A runner for one section: `testid` prefixes its progress and error
 * elements (`<testid>-progress`, `<testid>-error`); `onDone` reloads the
 * result. `submit(body)` starts a job; `destroy()` stops polling. */
export function planJobRunner({ testid, status, startBtn, onDone }) {
  let destroyed = false;
  let timer = null;
  let shown = 0; // never goes backwards within a job

  const error = (text) => fill(status, h('p', { class: 'error-text', role: 'alert', 'data-testid': `${testid}-error` }, text));

  function follow(jid) {
    const tick = async () => {
      if (destroyed) return;
      let job;
      try {
        job = await api.job(jid);
      } catch (err) {
        fill(status, h('p', { class: 'error-text', role: 'alert' }, errLine(err)));
        startBtn.disabled = false;
        return;
      }
      shown = Math.max(shown, job.progress || 0);
      fill(status, h('p', null, jobStateBadge(job.state), ' ',
        h('progress', { max: '1', value: String(shown), 'data-testid': `${testid}-progress` }), ' ',
        h('span', { class: 'muted' }, job.stage || '')));
      if (job.state === 'succeeded') {
        startBtn.disabled = false;
        fill(status);
        await onDone();
      } else if (['failed', 'cancelled', 'interrupted'].includes(job.state)) {
        startBtn.disabled = false;
        const e = job.error || {};
        error(`${job.state}: ${e.message || ''}${e.field ? ` [${e.field}]` : ''}`);
      } else {
        timer = setTimeout(tick, 400);
      }
    };
    tick();
  }

  return {
    async submit(body) {
      startBtn.disabled = true;
      shown = 0;
      try {
        const job = await api.submitJob(body);
        follow(job.id);
      } catch (err) {
        error(errLine(err));
        startBtn.disabled = false;
      }
    },
    error,
    destroy() { destroyed = true; if (timer) clearTimeout(timer); },
  };
}

/** A prior <select> value (`profile`, `reference`, `model:<id>`) into a
 * job body's `settings.prior` and `model_id`. */
export function withPrior(body, value) {
  if (value.startsWith('model:')) {
    body.settings.prior = 'model';
    body.model_id = value.slice(6);
  } else {
    body.settings.prior = value;
  }
  return body;
}

const PRIOR_OPTION = {
  profile: 'the vessel profile\u2019s rough numbers',
  reference: 'the source documents\u2019 vessel',
};

/** The prior <select> of a planning form: the profile, the reference
 * vessel and the campaign's stored models that `keep` accepts. */
export async function priorSelect(campaignId, testid, keep) {
  const models = (await api.models(campaignId).catch(() => [])).filter((m) => !m.deleted_at && keep(m));
  return h('select', { 'data-field': 'settings.prior', 'data-testid': testid },
    Object.entries(PRIOR_OPTION).map(([v, label]) => h('option', { value: v }, label)),
    models.map((m) => h('option', { value: `model:${m.id}` }, `model ${m.name} v${m.version}`)));
}

/** The newest result of a succeeded `kind` job of the campaign through
 * `get(id)`, or null when none has run (no 404 asked for on every view). */
export async function newestResult(campaignId, kind, get) {
  const jobs = await api.jobs(campaignId).catch(() => []);
  if (!jobs.some((j) => j.kind === kind && j.state === 'succeeded')) return null;
  try {
    return await get(campaignId);
  } catch (e) {
    if (e.status !== 404) throw e;
    return null;
  }
}
