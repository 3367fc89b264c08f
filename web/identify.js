// Identification on the campaign page: the "Identify" form (method,
// structure, which runs estimate and which are held out for validation), the
// campaign's jobs followed live over Server-Sent Events (progress bar, stage,
// cancel, retry, the model a finished job stored), and the campaign's models.

import { api, urls } from './api.js';
import { FAMILY_LABEL, fmtDate, fmtKn } from './format.js';
import { h, fill, labelled, clearErrors, showFieldError } from './forms.js';
import { runFamily, runRole, sourceBadge } from './rundescribe.js';

export const METHOD_LABEL = {
  lambda_kf: 'λ-filter Kalman (LPV)',
  n4sid: 'N4SID (black box)',
  parallel_ekf: 'Parallel EKF (DP ship)',
  discovery: 'Missing-physics discovery',
  discover: 'Missing-physics discovery',
  precision: 'Predicted precision',
};
/** What each method fits, shown under the method selector. */
export const METHOD_HELP = {
  lambda_kf: 'LPV model on forward speed: restoring forces from the static holds, then M ν̇ + D̄ ν = γ per grid point by the state-variable filter λ(s) = 1/(1+sT) and a Kalman filter over the parameters (thesis sec. 2.5).',
  n4sid: 'Black-box LTI model about the mean operating point by subspace identification (N4SID): a comparison model, no physical parameters.',
  parallel_ekf: 'DP ship (Fossen, Sagatun & Sørensen 1995): state-augmented EKF in parallel over the runs of each manoeuvre, staged SI1 surge → SI2 sway–yaw → SI3 azimuth; M″ and T″ from the vessel profile, A″_h and K″ estimated from position and heading (Bis units); then refined on all runs by prediction error, with std from the Cramér–Rao bound, inflated where the residuals ask for it.',
};
/** The parallel-EKF stage of a DP experiment family. */
const DP_STAGE = { dp_surge: 'SI1', dp_sway_yaw: 'SI2', dp_azimuth: 'SI3' };
/** Methods that fit a vessel kind, the first one the default. */
export const METHODS_FOR = { rov6: ['lambda_kf', 'n4sid'], dp3: ['parallel_ekf', 'n4sid'] };
const STRUCTURES = [
  ['auto', 'auto (coupling proposed from partial coherence)'],
  ['diagonal', 'diagonal (each DOF alone)'],
  ['coupled', 'coupled (every entry free)'],
];
const TERMINAL = new Set(['succeeded', 'failed', 'cancelled', 'interrupted']);
const RETRYABLE = new Set(['failed', 'cancelled', 'interrupted']);
const STATE_CLASS = {
  queued: 'neutral', running: 'weak', succeeded: 'good', failed: 'insufficient', cancelled: 'neutral', interrupted: 'insufficient',
};

export const KIND_LABEL_MODEL = { lpv: 'LPV on forward speed', dp_ship: 'DP ship (momentum form)', state_space: 'state space (black box)' };

/** "422 · message [field]" */
export function errLine(err) {
  return `${err.status ? `${err.status} · ` : ''}${err.message}${err.field ? ` [${err.field}]` : ''}`;
}

export function jobStateBadge(state) {
  return h('span', { class: `badge status ${STATE_CLASS[state] || 'neutral'}`, 'data-testid': 'job-state', 'data-state': state }, state);
}

/**
 * The Identify panel, the jobs and the models of a campaign. `runs` and
 * `plan` are kept current by the campaign page (setRuns, setPlan).
 */
export async function identifySection(host, { campaign, vessel, plan: plan0, runs: runs0 }) {
  const id = campaign.id;
  let plan = plan0;
  let runs = runs0 || [];
  let jobs = [];
  let models = [];
  const streams = new Map(); // job id → EventSource
  const rowState = new Map(); // job id → {bar, text, …} of the rendered row
  let destroyed = false;

  const methods = METHODS_FOR[vessel && vessel.kind] || ['lambda_kf', 'n4sid', 'parallel_ekf'];
  const m = { method: methods[0], structure: 'auto', use: new Map(), holdOut: new Set() };

  [jobs, models] = await Promise.all([api.jobs(id), api.models(id)]);

  // ---- the form ---------------------------------------------------------------
  const form = h('form', { class: 'card form identify', novalidate: true, 'data-testid': 'identify-form', 'data-needs': 'supervisor', 'aria-label': 'Identify a model', onSubmit: submit });
  const methodHelp = h('p', { class: 'hint method-help', 'data-testid': 'identify-method-help', 'aria-live': 'polite' });
  const sweepsIn = h('input', { type: 'number', min: '1', max: '20', step: '1', value: '2', class: 'short', 'data-field': 'settings.sweeps', 'data-testid': 'identify-sweeps' });
  const sweepsFld = labelled('Sweeps', sweepsIn, 'passes through SI1 → SI2 → SI3');
  const refineIn = h('input', { type: 'checkbox', checked: true, 'data-field': 'settings.refine', 'data-testid': 'identify-refine' });
  const refineFld = labelled('Refine', refineIn, 'after the staging, all θ″ jointly on every run by prediction error (off: the paper\'s staging alone)');
  const methodSel = h('select', { 'data-field': 'method', 'data-testid': 'identify-method', onChange: (e) => { m.method = e.target.value; renderStructure(); renderRunsTable(); } },
    methods.map((k) => h('option', { value: k, selected: k === m.method }, METHOD_LABEL[k])));
  const structSel = h('select', { 'data-field': 'settings.structure', 'data-testid': 'identify-structure', onChange: (e) => { m.structure = e.target.value; } },
    STRUCTURES.map(([k, label]) => h('option', { value: k, selected: k === m.structure }, label)));
  const structFld = labelled('Structure', structSel, 'coupling of A and B between DOFs');
  const ctrlIn = h('input', { type: 'number', min: '0', step: 'any', placeholder: 'log rate', class: 'short', 'data-field': 'settings.controller_rate_hz', 'data-testid': 'identify-controller-rate' });
  const ctrlFld = labelled('Controller rate (Hz)', ctrlIn, 'if faster than the log: M and D̄ corrected for the unlogged commands');
  const runsBox = h('div', { class: 'identify-runs', 'data-field': 'run_ids', 'data-error-host': '' });
  const rolesNote = h('p', { class: 'hint', 'data-testid': 'identify-roles', 'data-field': 'settings.validation_run_ids', 'aria-live': 'polite' });
  const startBtn = h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'identify-start' }, 'Start identification');
  const errBox = h('div', { class: 'identify-error', 'data-testid': 'identify-error', 'aria-live': 'assertive' });

  fill(form,
    h('h3', null, 'Identify ', h('span', { class: 'hint' }, 'estimate a model from the accepted runs and validate it on held-out runs')),
    h('div', { class: 'row' }, labelled('Method', methodSel), structFld, ctrlFld, sweepsFld, refineFld),
    methodHelp,
    runsBox,
    rolesNote,
    h('div', { class: 'form-actions' }, startBtn),
    errBox);

  function renderStructure() {
    structFld.hidden = m.method !== 'lambda_kf';
    ctrlFld.hidden = m.method !== 'lambda_kf';
    sweepsFld.hidden = m.method !== 'parallel_ekf';
    refineFld.hidden = m.method !== 'parallel_ekf';
    methodHelp.textContent = METHOD_HELP[m.method] || '';
  }

  /** "estimation", with the EKF stage of a DP manoeuvre. */
  const estimationRole = (r) => (m.method === 'parallel_ekf' && DP_STAGE[runFamily(r)] ? `estimation (${DP_STAGE[runFamily(r)]})` : 'estimation');
  const expOf = (r) => (plan && r.experiment_id ? plan.experiments.find((e) => e.id === r.experiment_id) : null);
  const accepted = () => runs.filter((r) => r.status === 'accepted');

  /**
   * Role of each used run, as the server assigns it (roles.rs): by the
   * run's description — the supervisor's word, else its planned
   * experiment, else inferred from its data.
   */
  function roles() {
    const used = accepted().filter((r) => m.use.get(r.id) !== false);
    const explicit = used.some((r) => m.holdOut.has(r.id));
    const role = new Map();
    for (const r of used) {
      const held = explicit ? m.holdOut.has(r.id) : runRole(r) === 'validation';
      role.set(r.id, held ? 'validation' : runRole(r) === 'static' ? 'static' : 'estimation');
    }
    return { used, explicit, role };
  }

  function renderRunsTable() {
    const acc = accepted();
    if (!acc.length) {
      fill(runsBox, h('p', { class: 'empty', 'data-testid': 'identify-no-runs' }, 'No accepted runs yet: upload the logs of the planned experiments first.'));
      rolesNote.textContent = '';
      startBtn.disabled = true;
      return;
    }
    startBtn.disabled = false;
    const { role, explicit, used } = roles();
    const rows = acc.map((r) => {
      const e = expOf(r);
      const useBox = h('input', {
        type: 'checkbox', checked: m.use.get(r.id) !== false, 'data-field': `run:${r.id}`, 'data-testid': 'identify-use',
        'aria-label': `use run ${r.name}`, onChange: (ev) => { m.use.set(r.id, ev.target.checked); renderRunsTable(); },
      });
      const holdBox = h('input', {
        type: 'checkbox', checked: m.holdOut.has(r.id), disabled: m.use.get(r.id) === false, 'data-testid': 'identify-holdout',
        'aria-label': `hold out run ${r.name} for validation`,
        onChange: (ev) => { if (ev.target.checked) m.holdOut.add(r.id); else m.holdOut.delete(r.id); renderRunsTable(); },
      });
      const rl = role.get(r.id);
      const d = r.description || {};
      const fam = runFamily(r);
      return h('tr', { 'data-testid': 'identify-run', 'data-run-id': r.id, 'data-role': rl || 'unused', class: rl ? `role-${rl}` : 'unused' },
        h('td', null, useBox),
        h('td', null, h('a', { href: urls.run(r.id) }, r.name)),
        h('td', { class: 'mono nowrap' }, e ? e.code : h('span', { class: 'muted' }, '–')),
        h('td', { class: 'nowrap' }, fam ? [h('span', { class: `fam-tag ${fam}` }, FAMILY_LABEL[fam] || fam), ' ', sourceBadge(d.role)] : h('span', { class: 'muted' }, 'not known')),
        h('td', { class: 'num' }, d.grid_speed_mps ? `${fmtKn(d.grid_speed_mps.value)} kn` : '–'),
        h('td', { class: 'nowrap', 'data-testid': 'identify-role' }, rl ? (rl === 'validation' ? (explicit ? 'validation (held out)' : `validation (${d.role ? d.role.source : 'plan'})`) : rl === 'static' ? 'static (restoring)' : estimationRole(r)) : h('span', { class: 'muted' }, 'not used')),
        h('td', null, h('label', { class: 'check' }, holdBox, ' hold out')));
    });
    fill(runsBox, h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact', 'data-testid': 'identify-runs' },
      h('thead', null, h('tr', null, h('th', null, 'Use'), h('th', null, 'Run'), h('th', null, 'Experiment'), h('th', { title: 'the run’s role: said by the supervisor, planned, or inferred from its data (edit it on the run page)' }, 'Family'),
        h('th', { class: 'num' }, 'Speed'), h('th', null, 'Role'), h('th', { title: 'hold these runs out for validation instead of the plan’s validation runs' }, 'Validation'))),
      h('tbody', null, rows))));
    const nVal = [...role.values()].filter((x) => x === 'validation').length;
    const nEst = [...role.values()].filter((x) => x === 'estimation').length;
    rolesNote.textContent = `${used.length} of ${acc.length} accepted runs: ${nEst} to estimate from, ${nVal} held out for validation`
      + `${explicit ? ' (ticked)' : ' (the runs whose role is validation)'}.`
      + (nVal === 0 ? ' No validation run: fly the plan’s validation experiment, set a run’s role to validation on its run page, or tick “hold out” on a run.' : '');
    rolesNote.classList.toggle('error-text', nVal === 0);
  }

  /** Where to show an error `field` of a submitted request on this form. */
  function formField(field, sent) {
    if (!field) return null;
    const mIdx = field.match(/^run_ids\[(\d+)\]/);
    if (mIdx && sent.run_ids[Number(mIdx[1])]) return `run:${sent.run_ids[Number(mIdx[1])]}`;
    const mRun = field.match(/^runs\[([^\]]+)\]/);
    if (mRun) return `run:${mRun[1]}`;
    const mVal = field.match(/^settings\.validation_run_ids\[(\d+)\]/);
    if (mVal && sent.settings.validation_run_ids) return `run:${sent.settings.validation_run_ids[Number(mVal[1])]}`;
    return field;
  }

  async function submit(ev) {
    ev.preventDefault();
    clearErrors(form);
    fill(errBox);
    const { used, explicit } = roles();
    const settings = {};
    if (m.method === 'lambda_kf') {
      settings.structure = m.structure;
      const rate = ctrlIn.value.trim();
      if (rate !== '') settings.controller_rate_hz = Number.isFinite(Number(rate)) ? Number(rate) : rate;
    }
    if (m.method === 'parallel_ekf') {
      const sw = Number(sweepsIn.value);
      settings.sweeps = sweepsIn.value.trim() === '' || !Number.isFinite(sw) ? sweepsIn.value : sw;
      settings.refine = refineIn.checked;
    }
    if (explicit) settings.validation_run_ids = used.filter((r) => m.holdOut.has(r.id)).map((r) => r.id);
    const body = { kind: 'identify', campaign_id: id, run_ids: used.map((r) => r.id), method: m.method, settings };
    startBtn.disabled = true;
    try {
      const job = await api.submitJob(body);
      jobs = [job, ...jobs.filter((j) => j.id !== job.id)];
      renderJobs();
      follow(job);
    } catch (err) {
      fill(errBox, h('div', { class: 'upload-error', role: 'alert', 'data-testid': 'identify-error-text', 'data-status': String(err.status), 'data-field': err.field || '' },
        h('div', { class: 'err-title' }, `✗ Not started (${err.status || 'network error'})`),
        err.field ? h('div', { class: 'err-where' }, h('span', { 'data-testid': 'identify-error-field' }, err.field)) : null,
        h('p', { class: 'err-message' }, err.message)));
      const f = formField(err.field, body);
      if (f) showFieldError(form, f, err.message, err.limit);
    } finally {
      startBtn.disabled = !accepted().length;
    }
  }

  // ---- jobs ---------------------------------------------------------------------
  const jobsBox = h('div', { 'data-section': 'jobs', class: 'card jobs', 'data-testid': 'jobs', 'aria-label': 'Identification jobs' });

  function progressText(j) {
    const pct = `${Math.round((j.progress || 0) * 100)} %`;
    return j.stage ? `${pct} · ${j.stage}` : pct;
  }

  function jobRow(j) {
    const bar = h('progress', { max: '1', value: j.progress || 0, 'data-testid': 'job-progress', 'aria-label': `Progress of job ${j.id.slice(-6)}` });
    const text = h('span', { class: 'progress-text', 'data-testid': 'job-stage', role: 'status', 'aria-live': 'polite' }, progressText(j));
    const state = h('span', null, jobStateBadge(j.state));
    const actions = h('span', { class: 'actions' });
    const msg = h('div', { class: 'job-msg', 'data-testid': 'job-message' });
    const req = j.request || {};
    const settings = req.settings || {};
    const tr = h('tr', { 'data-testid': 'job-row', 'data-job-id': j.id, 'data-state': j.state },
      h('td', { class: 'nowrap' }, fmtDate(j.created_at)),
      h('td', null, METHOD_LABEL[req.method] || req.method || METHOD_LABEL[j.kind] || j.kind,
        settings.structure ? h('span', { class: 'muted' }, ` · ${settings.structure}`) : null,
        h('div', { class: 'hint' }, `${(req.run_ids || []).length} runs${settings.validation_run_ids ? `, ${settings.validation_run_ids.length} held out` : ''}${j.attempts > 1 ? ` · attempt ${j.attempts}` : ''}`)),
      h('td', null, state),
      h('td', { class: 'job-progress' }, h('div', { class: 'progress-box' }, bar, text), msg),
      h('td', { class: 'nowrap' }, actions));
    const r = { tr, bar, text, state, actions, msg, job: j };
    rowState.set(j.id, r);
    updateRow(r, j);
    return tr;
  }

  function updateRow(r, j0) {
    // A job that succeeded is complete, whatever its last progress report said.
    const j = j0.state === 'succeeded' ? { ...j0, progress: 1 } : j0;
    r.job = j;
    r.tr.dataset.state = j.state;
    // Never backwards within one attempt (a retry, queued again, starts over).
    const p = r.lastState === j.state ? Math.max(r.bar.value, j.progress || 0) : j.progress || 0;
    r.lastState = j.state;
    r.bar.value = p;
    r.bar.setAttribute('value', String(p));
    r.text.textContent = progressText({ ...j, progress: p });
    fill(r.state, jobStateBadge(j.state), j.cancel_requested && !TERMINAL.has(j.state) ? h('span', { class: 'hint' }, ' cancelling…') : null);
    const acts = [];
    if (!TERMINAL.has(j.state)) {
      acts.push(h('button', { type: 'button', class: 'btn small', 'data-testid': 'job-cancel', 'data-needs': 'supervisor', disabled: !!j.cancel_requested, onClick: () => cancel(j.id) }, 'Cancel'));
    }
    if (RETRYABLE.has(j.state)) {
      acts.push(h('button', { type: 'button', class: 'btn small', 'data-testid': 'job-retry', 'data-needs': 'supervisor', onClick: () => retry(j.id) }, 'Retry'));
    }
    if (j.state === 'succeeded' && j.result && j.result.discrepancy_id) {
      acts.push(h('a', { class: 'btn small primary', href: urls.discrepancy(j.result.discrepancy_id), 'data-testid': 'job-report-link' }, 'Open report →'));
      if (j.result.augmented_model_id) acts.push(h('a', { class: 'btn small', href: urls.model(j.result.augmented_model_id), 'data-testid': 'job-model-link' }, 'Augmented model →'));
    } else if (j.state === 'succeeded' && j.result && j.result.model_id) {
      acts.push(h('a', { class: 'btn small primary', href: urls.model(j.result.model_id), 'data-testid': 'job-model-link' }, 'Open model →'));
    }
    fill(r.actions, acts);
    if (j.error && (j.state === 'failed' || j.state === 'interrupted')) {
      fill(r.msg, h('span', { class: 'error-text', role: 'alert', 'data-testid': 'job-error' }, j.error.message, j.error.field ? h('span', { class: 'mono' }, ` [${j.error.field}]`) : null));
    } else if (!r.msg.querySelector('[data-keep]')) fill(r.msg);
  }

  function rowError(jid, err) {
    const r = rowState.get(jid);
    if (r) fill(r.msg, h('span', { class: 'error-text', role: 'alert', 'data-testid': 'job-action-error', 'data-keep': '' }, errLine(err)));
  }

  function renderJobs() {
    rowState.clear();
    if (!jobs.length) {
      fill(jobsBox, h('h3', null, 'Jobs'), h('p', { class: 'empty', 'data-testid': 'no-jobs' }, 'No identification started yet.'));
      return;
    }
    fill(jobsBox, h('h3', null, `Jobs (${jobs.length}) `, h('span', { class: 'hint' }, 'newest first; progress follows live')),
      h('div', { class: 'table-x' }, h('table', { class: 'grid-table jobs-table', 'data-testid': 'jobs-table' },
        h('thead', null, h('tr', null, h('th', null, 'Submitted'), h('th', null, 'Method'), h('th', null, 'State'), h('th', null, 'Progress'), h('th', null, ''))),
        h('tbody', null, jobs.map(jobRow)))));
  }

  function replaceJob(j) {
    jobs = jobs.map((x) => (x.id === j.id ? j : x));
    const r = rowState.get(j.id);
    if (r) updateRow(r, j);
  }

  /** Follow a job over SSE until it ends, then read its result. */
  function follow(j) {
    if (TERMINAL.has(j.state) || streams.has(j.id) || destroyed) return;
    const es = new EventSource(urls.jobEvents(j.id));
    streams.set(j.id, es);
    let ended = false;
    es.onmessage = (e) => {
      let ev;
      try { ev = JSON.parse(e.data); } catch { return; }
      const cur = jobs.find((x) => x.id === j.id) || j;
      replaceJob({ ...cur, state: ev.state || cur.state, progress: ev.progress ?? cur.progress, stage: ev.stage ?? cur.stage });
      if (TERMINAL.has(ev.state)) {
        ended = true;
        es.close();
        streams.delete(j.id);
        settle(j.id);
      }
    };
    es.onerror = () => {
      if (ended) return;
      // The stream broke before a terminal state: read the job and follow again.
      es.close();
      streams.delete(j.id);
      if (destroyed) return;
      api.job(j.id).then((fresh) => {
        replaceJob(fresh);
        if (TERMINAL.has(fresh.state)) settle(j.id, fresh);
        else setTimeout(() => follow(fresh), 1000);
      }).catch((err) => rowError(j.id, err));
    };
  }

  async function settle(jid, fresh) {
    try {
      const j = fresh || await api.job(jid);
      if (destroyed) return;
      replaceJob(j);
      if (j.state === 'succeeded') await refreshModels();
    } catch (err) {
      rowError(jid, err);
    }
  }

  async function cancel(jid) {
    try {
      const j = await api.cancelJob(jid);
      replaceJob(j);
      if (TERMINAL.has(j.state)) {
        const es = streams.get(jid);
        if (es) { es.close(); streams.delete(jid); }
      }
    } catch (err) {
      rowError(jid, err);
      api.job(jid).then(replaceJob).catch(() => {});
    }
  }

  async function retry(jid) {
    try {
      const j = await api.retryJob(jid);
      replaceJob(j);
      follow(j);
    } catch (err) {
      rowError(jid, err);
    }
  }

  // ---- models -------------------------------------------------------------------
  const modelsBox = h('div', { 'data-section': 'models', class: 'card models', 'data-testid': 'models', 'aria-label': 'Models' });

  function renderModels() {
    if (!models.length) {
      fill(modelsBox, h('h3', null, 'Models'), h('p', { class: 'empty', 'data-testid': 'no-models' }, 'No model identified yet.'));
      return;
    }
    const byId = new Map(models.map((x) => [x.id, x]));
    fill(modelsBox, h('h3', null, `Models (${models.length}) `, h('span', { class: 'hint' }, 'newest first')),
      h('div', { class: 'table-x' }, h('table', { class: 'grid-table models-table', 'data-testid': 'models-table' },
        h('thead', null, h('tr', null, h('th', null, 'Model'), h('th', null, 'Version'), h('th', null, 'Method'), h('th', null, 'Kind'), h('th', null, 'Created'), h('th', null, 'Software'))),
        h('tbody', null, models.map((x) => {
          const parent = x.parent_id ? byId.get(x.parent_id) : null;
          return h('tr', { 'data-testid': 'model-row', 'data-model-id': x.id },
            h('td', null, h('a', { href: urls.model(x.id), 'data-testid': 'model-link' }, x.name)),
            h('td', { class: 'nowrap' }, `v${x.version}`, h('div', { class: 'hint', title: `lineage ${x.lineage_id}` },
              x.parent_id ? ['from ', h('a', { href: urls.model(x.parent_id) }, parent ? `v${parent.version}` : 'parent')] : `lineage ${x.lineage_id.slice(-6)}`)),
            h('td', null, METHOD_LABEL[x.method] || x.method),
            h('td', null, KIND_LABEL_MODEL[x.kind] || x.kind),
            h('td', { class: 'nowrap' }, fmtDate(x.created_at)),
            h('td', { class: 'mono' }, x.software_version));
        })))));
  }

  async function refreshModels() {
    models = await api.models(id);
    if (!destroyed) renderModels();
  }

  renderStructure();
  renderRunsTable();
  renderJobs();
  renderModels();
  for (const j of jobs) follow(j);

  fill(host,
    h('h2', { class: 'section-title' }, 'Identification ', h('span', { class: 'hint' }, 'background jobs: leave the page and come back, they keep running')),
    h('div', { class: 'runs-layout' }, form, h('div', { class: 'runs-left' }, jobsBox, modelsBox)));

  return {
    setPlan(p) { plan = p; renderRunsTable(); },
    setRuns(r) { runs = r || []; renderRunsTable(); },
    destroy() {
      destroyed = true;
      for (const es of streams.values()) es.close();
      streams.clear();
    },
  };
}
