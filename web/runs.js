// Runs of a campaign, on the campaign page: the upload form (one log, or
// control + nav logs from two unsynchronized computers) with upload progress,
// the coverage of the plan (what must be flown again) and the list of runs
// with their verdict badges.

import { api, uploadRun, urls } from './api.js';
import {
  COVERAGE_HELP, COVERAGE_LABEL, FAMILY_LABEL, VERDICT_ICON, bytes, fmt, fmtDate,
} from './format.js';
import { h, fill, banner, labelled, num, clearErrors, showFieldError } from './forms.js';
import { describeCell } from './rundescribe.js';
import { excludedBadge } from './manage.js';

// ---- shared bits (the run page uses them too) ------------------------------

/** A verdict badge: "✓ surge" in green, "! sway" in amber, "✗ roll" in red. */
export function verdictBadge(v, { text } = {}) {
  const kind = v.verdict || 'insufficient';
  return h('span', {
    class: `badge ${kind}`,
    title: v.reason || kind,
    'data-testid': 'verdict-badge',
    'data-dof': v.dof,
    'data-verdict': kind,
  }, `${VERDICT_ICON[kind] || ''} ${text || v.dof}`);
}

/** One line per DOF: badge, verdict word and the server's reason. */
export function verdictList(verdicts) {
  return h('ul', { class: 'verdicts', 'data-testid': 'verdict-list' }, verdicts.map((v) => h('li', {
    class: `verdict ${v.verdict}`, 'data-testid': 'verdict', 'data-dof': v.dof, 'data-verdict': v.verdict,
  },
  verdictBadge(v),
  h('b', { class: 'verdict-word' }, v.verdict),
  h('span', { class: 'reason', 'data-testid': 'verdict-reason' }, v.reason))));
}

/** The status of a stored run: accepted / rejected / stored (not processed yet). */
export function statusBadge(status, run) {
  const units = (run && run.summary && run.summary.check_units) || [];
  if (status === 'accepted' && units.length) {
    return h('span', {
      class: 'badge check_units status', 'data-testid': 'run-status', 'data-status': 'check_units',
      title: `stored, but the units of ${units.join(', ')} look wrong: fix the log and upload it again`,
    }, '⚠ check units');
  }
  const kind = status === 'accepted' ? 'good' : status === 'rejected' ? 'insufficient' : 'neutral';
  return h('span', { class: `badge ${kind} status`, 'data-testid': 'run-status', 'data-status': status }, status);
}

/** The unit doubts of a run, for the top of its result card (empty: none). */
export function unitWarnings(run) {
  const w = ((run.summary && run.summary.warnings) || []).filter((x) => x.units);
  if (!w.length) return null;
  return h('div', { class: 'units-alert', role: 'alert', 'data-testid': 'units-alert' },
    h('b', null, '⚠ Check the log’s units before anything else'),
    h('ul', null, w.map((x) => h('li', { 'data-testid': 'units-warning', 'data-column': x.column || '' }, x.message))));
}

export function coverageBadge(status) {
  return h('span', { class: `badge cov-${status}`, title: COVERAGE_HELP[status] || status, 'data-testid': 'coverage-status', 'data-status': status },
    COVERAGE_LABEL[status] || status);
}

/** "file, line 42, column tau_K" from a rejected run's error or an ErrorBody. */
export function errorWhere(e, files) {
  if (!e) return '';
  const role = e.file || e.field;
  const f = files && files.find((x) => x.role === role);
  const parts = [];
  if (role) parts.push(f ? `${f.filename} (${role})` : role);
  if (e.line != null) parts.push(`line ${e.line}`);
  if (e.column != null) parts.push(`column ${e.column}`);
  return parts.join(' · ');
}

/**
 * The message without what errorWhere() already shows ("file, line 42,
 * column tau_K: …") and without the API hint on where the bytes are kept.
 */
export function errorText(message) {
  if (!message) return '';
  return message
    .replace(/^(file|control|nav|shared_channel|meta(\.[a-z_]+)?)(, line \d+)?(, column [^:]+)?: /, '')
    .replace(/\s*\(the upload is stored as run [^)]*\)\s*$/, '');
}

/** Links to the stored bytes of a run: one per file. */
export function rawLinks(run, attrs = {}) {
  return run.files.map((f) => h('a', {
    class: 'btn small', href: urls.raw(run.id, run.layout === 'split' ? f.role : null), download: f.filename,
    'data-testid': 'raw-link', 'data-role': f.role, title: `the stored bytes, SHA-256 ${f.sha256}`, ...attrs,
  }, `↓ ${run.layout === 'split' ? `${f.role}: ` : ''}${f.filename}`));
}

// ---- the section -------------------------------------------------------------

/**
 * Builds the Runs section into `host`. Returns {setPlan(plan), destroy()}.
 */
export async function runsSection(host, { campaign, plan: plan0, onRuns = null }) {
  const id = campaign.id;
  let plan = plan0;
  let runs = [];
  let coverage = null;
  let covFilter = 'all';
  const m = { layout: 'single', experiment: '', name: '', shared: 'z', rate: '' };
  let uploading = null; // {abort}

  [runs, coverage] = await Promise.all([
    api.runs(id),
    plan ? api.coverage(id).catch((e) => { if (e.status === 404) return null; throw e; }) : null,
  ]);

  // -- upload form
  const form = h('form', { class: 'card form upload', novalidate: true, 'data-testid': 'upload-form', 'data-needs': 'supervisor', 'aria-label': 'Upload a run', onSubmit: submit });
  const layoutBox = h('div', { class: 'seg', role: 'radiogroup', 'aria-label': 'Log layout' });
  const filesBox = h('div', { class: 'row files' });
  const expSel = h('select', { 'data-field': 'meta.experiment_id', 'data-testid': 'upload-experiment', onChange: (e) => { m.experiment = e.target.value; updateNameHint(); } });
  const nameIn = h('input', { type: 'text', 'data-field': 'meta.name', 'data-testid': 'upload-name', autocomplete: 'off', onInput: (e) => { m.name = e.target.value; } });
  const sharedIn = h('input', { type: 'text', value: m.shared, 'data-field': 'meta.shared_channel', 'data-testid': 'upload-shared', autocomplete: 'off', class: 'short', onInput: (e) => { m.shared = e.target.value; } });
  const rateIn = h('input', { type: 'number', step: 'any', min: '0', 'data-field': 'meta.rate_hz', 'data-testid': 'upload-rate', placeholder: 'log rate', onInput: (e) => { m.rate = e.target.value; } });
  const sharedFld = labelled('Shared channel', sharedIn, 'recorded by both computers');
  const submitBtn = h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'upload-submit' }, 'Upload');
  const cancelBtn = h('button', { type: 'button', class: 'btn', hidden: true, 'data-testid': 'upload-cancel', onClick: () => uploading && uploading.abort() }, 'Cancel');
  const bar = h('progress', { max: '100', value: '0', 'data-testid': 'upload-progress', 'aria-label': 'Upload progress' });
  const barText = h('span', { class: 'progress-text', 'data-testid': 'upload-status', role: 'status', 'aria-live': 'polite' });
  const progressBox = h('div', { class: 'progress-box', hidden: true, 'data-testid': 'upload-progress-box' }, bar, barText);
  const resultBox = h('div', { class: 'upload-result', 'data-testid': 'upload-result', 'aria-live': 'polite' });
  const fileInputs = {};

  function fileInput(role, label, hint) {
    const inp = h('input', { type: 'file', accept: '.csv,.txt,text/csv,text/plain', 'data-field': role, 'data-testid': `upload-${role}`, onChange: updateNameHint });
    fileInputs[role] = inp;
    return h('div', { 'data-error-host': '', class: 'fld-wrap' }, labelled(label, inp, hint));
  }

  function renderLayout() {
    const opt = (value, text) => h('label', { class: `seg-opt${m.layout === value ? ' on' : ''}` },
      h('input', {
        type: 'radio', name: `layout-${id}`, value, checked: m.layout === value, 'data-testid': `upload-layout-${value}`,
        onChange: () => { m.layout = value; renderLayout(); renderFiles(); },
      }), text);
    fill(layoutBox, opt('single', 'One log file'), opt('split', 'Control + nav logs'));
  }

  function renderFiles() {
    for (const k of Object.keys(fileInputs)) delete fileInputs[k];
    if (m.layout === 'single') {
      fill(filesBox, fileInput('file', 'Log (CSV)', 't, inputs, velocities, pose'));
    } else {
      fill(filesBox,
        fileInput('control', 'Control log (CSV)', 't, inputs, shared channel'),
        fileInput('nav', 'Navigation log (CSV)', 't, velocities, pose, shared channel'),
        sharedFld);
    }
    clearErrors(form);
    updateNameHint();
  }

  function renderExperiments() {
    const status = new Map(coverage ? coverage.experiments.map((e) => [e.experiment_id, e.status]) : []);
    if (m.experiment && !(plan && plan.experiments.some((e) => e.id === m.experiment))) m.experiment = '';
    fill(expSel,
      h('option', { value: '', selected: !m.experiment }, plan ? '— not assigned to an experiment —' : '— no plan yet —'),
      plan ? plan.experiments.map((e) => {
        const s = status.get(e.id);
        return h('option', { value: e.id, selected: m.experiment === e.id }, `#${e.seq} ${e.code}${s ? ` · ${COVERAGE_LABEL[s]}` : ''}`);
      }) : null);
    expSel.disabled = !plan;
    updateNameHint();
  }

  function updateNameHint() {
    const e = plan && m.experiment ? plan.experiments.find((x) => x.id === m.experiment) : null;
    const f = fileInputs.file && fileInputs.file.files[0];
    nameIn.placeholder = e ? e.code : f ? f.name : 'experiment code or file name';
  }

  renderLayout();
  renderFiles();
  renderExperiments();
  form.append(
    h('h3', null, 'Upload a run ', h('span', { class: 'hint' }, 'CSV log contract: t, tau_X…, u…, x…; stored verbatim with its SHA-256 before it is checked')),
    layoutBox,
    filesBox,
    h('div', { class: 'row' },
      labelled('Planned experiment', expSel),
      labelled('Name', nameIn),
      labelled('Resample to (Hz)', rateIn, 'optional')),
    h('div', { class: 'form-actions' }, submitBtn, cancelBtn, progressBox),
    resultBox);

  /** Choose an experiment from the coverage table, then pick the file. */
  function uploadFor(eid) {
    m.experiment = eid;
    renderExperiments();
    form.scrollIntoView({ block: 'nearest', behavior: 'instant' });
    const first = fileInputs.file || fileInputs.control;
    if (first) first.focus({ preventScroll: true });
  }

  function setProgress(pct, text) {
    bar.value = pct;
    bar.setAttribute('value', String(pct));
    bar.dataset.pct = String(pct);
    barText.textContent = text;
  }

  async function submit(ev) {
    ev.preventDefault();
    if (uploading) return;
    clearErrors(form);
    fill(resultBox);
    const files = {};
    const roles = m.layout === 'single' ? ['file'] : ['control', 'nav'];
    for (const r of roles) {
      const f = fileInputs[r].files[0];
      if (!f) {
        showFieldError(form, r, `choose the ${r === 'file' ? 'log' : `${r} log`} file`);
        return;
      }
      files[r] = f;
    }
    const meta = {};
    if (m.experiment) meta.experiment_id = m.experiment;
    if (m.name.trim()) meta.name = m.name.trim();
    if (m.layout === 'split' && m.shared.trim() && m.shared.trim() !== 'z') meta.shared_channel = m.shared.trim();
    const rate = num(m.rate);
    if (rate != null) {
      if (!Number.isFinite(rate) || rate <= 0) { showFieldError(form, 'meta.rate_hz', 'a rate in Hz above 0, or empty for the log’s own rate'); return; }
      meta.rate_hz = rate;
    }
    const total = Object.values(files).reduce((a, f) => a + f.size, 0);
    const t0 = performance.now();
    let tSent = null;
    submitBtn.disabled = true;
    cancelBtn.hidden = false;
    progressBox.hidden = false;
    progressBox.classList.remove('processing', 'failed');
    setProgress(0, `Uploading ${bytes(total)}…`);
    const beforeUnload = (e) => { e.preventDefault(); e.returnValue = ''; };
    window.addEventListener('beforeunload', beforeUnload);
    const up = uploadRun(id, { files, meta }, {
      onProgress: (loaded, tot) => {
        const all = tot || total;
        const pct = all > 0 ? Math.min(100, Math.floor((loaded / all) * 100)) : 0;
        setProgress(pct, `Uploading ${bytes(loaded)} of ${bytes(all)} · ${pct} %`);
      },
      onSent: () => {
        tSent = performance.now();
        setProgress(100, `100 % · ${bytes(total)} sent — processing…`);
        progressBox.classList.add('processing');
        cancelBtn.hidden = true;
        barText.prepend(h('span', { class: 'spinner', 'aria-hidden': 'true' }), ' ');
        barText.dataset.state = 'processing';
      },
    });
    uploading = up;
    let run = null;
    let err = null;
    try {
      run = await up.promise;
    } catch (e) {
      err = e;
    } finally {
      uploading = null;
      window.removeEventListener('beforeunload', beforeUnload);
      submitBtn.disabled = false;
      cancelBtn.hidden = true;
      progressBox.classList.remove('processing');
    }
    const secs = (a, b) => (b - a < 1000 ? `${Math.round(b - a)} ms` : `${fmt((b - a) / 1000, 1)} s`);
    const tEnd = performance.now();
    if (run) {
      barText.dataset.state = 'done';
      setProgress(100, `100 % · ${bytes(total)} uploaded in ${secs(t0, tSent || tEnd)}, processed in ${secs(tSent || tEnd, tEnd)}`);
      showAccepted(run);
      for (const inp of Object.values(fileInputs)) inp.value = '';
      m.name = '';
      nameIn.value = '';
    } else {
      barText.dataset.state = 'failed';
      progressBox.classList.add('failed');
      if (err.status === 0 && /cancelled/.test(err.message)) {
        setProgress(0, 'Upload cancelled: nothing was stored.');
      } else {
        setProgress(tSent ? 100 : 0, tSent ? `${bytes(total)} uploaded — not accepted (${err.status})` : `Upload failed (${err.status || 'network'})`);
        showRejected(err, files);
      }
    }
    await refresh().catch((e) => banner(`${e.status ? `${e.status} · ` : ''}${e.message}`));
    if (run && !host.isConnected) banner(`Run “${run.name}” ${run.status}.`, 'ok');
  }

  function showAccepted(run) {
    const v = (run.summary && run.summary.verdicts) || [];
    const units = (run.summary && run.summary.check_units) || [];
    const worst = units.length ? 'weak'
      : v.some((x) => x.verdict === 'insufficient') ? 'insufficient' : v.some((x) => x.verdict === 'weak') ? 'weak' : 'good';
    fill(resultBox, h('div', { class: `result-card ${worst}`, 'data-testid': 'upload-accepted', 'data-run-id': run.id, 'data-check-units': String(units.length > 0) },
      h('div', { class: 'result-head' },
        h('b', null, units.length ? `⚠ Run “${run.name}” stored — check units (${units.join(', ')})` : `✓ Run “${run.name}” ${run.status}`),
        h('a', { class: 'btn small', href: urls.run(run.id), 'data-testid': 'upload-run-link' }, 'Open run page →')),
      unitWarnings(run),
      v.length ? verdictList(v) : h('p', { class: 'muted' }, 'No verdicts.')));
  }

  function showRejected(err, files) {
    const fileRole = err.field && ['file', 'control', 'nav'].includes(err.field) ? err.field : null;
    const f = fileRole ? files[fileRole] : null;
    const where = [];
    if (err.field) where.push(h('span', { class: 'where-file', 'data-testid': 'error-file' }, f ? `${f.name} (${err.field})` : err.field));
    if (err.line != null) where.push(h('span', { class: 'where-line', 'data-testid': 'error-line' }, `line ${err.line}`));
    if (err.column != null) where.push(h('span', { class: 'where-col', 'data-testid': 'error-column' }, `column ${err.column}`));
    const title = err.status === 422 ? 'Rejected: the log is stored but invalid'
      : err.status === 413 ? 'Too large for the server’s upload limit'
        : `Not uploaded (${err.status || 'network error'})`;
    fill(resultBox, h('div', { class: 'upload-error', role: 'alert', 'data-testid': 'upload-error', 'data-status': String(err.status) },
      h('div', { class: 'err-title' }, `✗ ${title}`),
      where.length ? h('div', { class: 'err-where', 'data-testid': 'error-where' }, where) : null,
      h('p', { class: 'err-message', 'data-testid': 'error-message', title: err.message }, where.length ? errorText(err.message) : err.message),
      err.runId ? h('div', { class: 'actions' },
        h('a', { class: 'btn small', href: urls.raw(err.runId, fileRole && fileRole !== 'file' ? fileRole : null), download: f ? f.name : true, 'data-testid': 'error-raw-link' }, '↓ stored raw file'),
        h('a', { class: 'btn small', href: urls.run(err.runId), 'data-testid': 'error-run-link' }, 'Run page →'),
        h('span', { class: 'hint' }, `kept as run ${err.runId}`)) : null));
    // Point at the input too (file / control / nav / meta.*).
    const field = err.field === 'shared_channel' ? 'meta.shared_channel' : err.field;
    if (field) showFieldError(form, field, err.line != null ? `line ${err.line}${err.column ? `, column ${err.column}` : ''}` : err.message, err.limit);
  }

  // -- coverage
  const covBox = h('div', { 'data-section': 'coverage', class: 'card coverage', 'data-testid': 'coverage', 'aria-label': 'Coverage' });

  function renderCoverage() {
    if (!plan) {
      fill(covBox, h('h3', null, 'Coverage'), h('p', { class: 'empty', 'data-testid': 'coverage-empty' }, 'Generate the plan to see which experiments are covered by good runs.'));
      return;
    }
    if (!coverage) {
      fill(covBox, h('h3', null, 'Coverage'), h('p', { class: 'empty' }, 'No coverage for this plan.'));
      return;
    }
    const c = coverage;
    const n = c.experiments.length;
    const toFly = c.repeat + c.missing;
    const counts = { covered: c.covered, weak: c.weak, repeat: c.repeat, missing: c.missing };
    const chip = (key, label, count, cls, title) => h('button', {
      type: 'button', class: `counter ${cls}${covFilter === key ? ' on' : ''}`, 'aria-pressed': String(covFilter === key),
      'data-testid': `coverage-filter-${key}`, title, onClick: () => { covFilter = key; renderCoverage(); },
    }, h('b', { 'data-testid': `count-${key}` }, String(count)), h('span', null, label));
    let headline;
    if (toFly === 0 && c.weak === 0) headline = h('p', { class: 'cov-headline ok', 'data-testid': 'coverage-headline' }, `✓ All ${n} planned experiments are covered by a good run.`);
    else {
      headline = h('p', { class: `cov-headline ${toFly ? 'bad' : 'warn'}`, 'data-testid': 'coverage-headline' },
        toFly ? h('b', null, `${toFly} of ${n} experiment${n === 1 ? '' : 's'} still to fly`) : h('b', null, 'Nothing missing'),
        toFly ? ` — ${c.repeat} to fly again (no usable run), ${c.missing} not flown yet` : '',
        c.weak ? `${toFly ? '; ' : ' — '}${c.weak} weak (usable, consider flying again)` : '',
        c.check_units ? `; ${c.check_units} with units to check (fix the log and upload it again)` : '',
        '.');
    }
    const shown = c.experiments.filter((e) => covFilter === 'all'
      || (covFilter === 'tofly' ? e.status === 'repeat' || e.status === 'missing' : e.status === covFilter));
    const byId = new Map(runs.map((r) => [r.id, r]));
    const rows = shown.map((e) => {
      const last = e.runs[e.runs.length - 1];
      const why = e.status !== 'covered' && last ? last.reason : '';
      return h('tr', { class: `cov-row ${e.status}`, 'data-testid': 'coverage-row', 'data-eid': e.experiment_id, 'data-code': e.code, 'data-status': e.status },
        h('td', { class: 'num' }, e.seq),
        h('td', { class: 'mono nowrap' }, h('a', { href: `#/campaigns/${id}/experiments/${e.experiment_id}`, title: 'the planned schedule' }, e.code)),
        h('td', null, h('span', { class: `fam-tag ${e.family}` }, FAMILY_LABEL[e.family] || e.family)),
        h('td', null, coverageBadge(e.status)),
        h('td', { class: 'cov-runs' },
          e.runs.length ? e.runs.map((r) => h('a', {
            class: `run-chip ${r.verdict}`, href: urls.run(r.run_id), title: `${r.verdict}: ${r.reason}`, 'data-testid': 'coverage-run', 'data-verdict': r.verdict,
          }, `${VERDICT_ICON[r.verdict] || ''} ${r.name}`)) : h('span', { class: 'muted' }, '–'),
          why ? h('div', { class: 'why', 'data-testid': 'coverage-reason' }, why) : null),
        h('td', { class: 'nowrap' }, h('button', {
          type: 'button', class: `btn small${e.status === 'repeat' || e.status === 'missing' ? ' attn' : ''}`, 'data-testid': 'coverage-upload', 'data-needs': 'supervisor',
          title: `upload a run of ${e.code}`, onClick: () => uploadFor(e.experiment_id),
        }, '↑ run')));
    });
    const unassigned = c.unassigned_runs.map((rid) => byId.get(rid)).filter(Boolean);
    fill(covBox,
      h('div', { class: 'cov-head' }, h('h3', null, 'Coverage ', h('span', { class: 'hint' }, `plan v${c.plan_version}`)), headline),
      h('div', { class: 'counters', role: 'group', 'aria-label': 'Filter by coverage', 'data-testid': 'coverage-counters' },
        chip('tofly', 'to fly', toFly, 'tofly', 'fly again + not flown'),
        chip('repeat', COVERAGE_LABEL.repeat, counts.repeat, 'cov-repeat', COVERAGE_HELP.repeat),
        chip('missing', COVERAGE_LABEL.missing, counts.missing, 'cov-missing', COVERAGE_HELP.missing),
        chip('weak', COVERAGE_LABEL.weak, counts.weak, 'cov-weak', COVERAGE_HELP.weak),
        c.check_units ? chip('check_units', COVERAGE_LABEL.check_units, c.check_units, 'cov-check_units', COVERAGE_HELP.check_units) : null,
        chip('covered', COVERAGE_LABEL.covered, counts.covered, 'cov-covered', COVERAGE_HELP.covered),
        chip('all', 'all', n, 'all', 'every planned experiment'),
        h('span', { class: 'muted', 'data-testid': 'coverage-count' }, `${shown.length} of ${n} shown`)),
      h('div', { class: 'table-scroll cov-scroll' },
        h('table', { class: 'grid-table coverage-table', 'data-testid': 'coverage-table' },
          h('thead', null, h('tr', null, h('th', { class: 'num' }, '#'), h('th', null, 'Code'), h('th', null, 'Family'),
            h('th', null, 'Status'), h('th', null, 'Runs (worst verdict over the excited DOFs)'), h('th', null, ''))),
          h('tbody', null, rows.length ? rows : h('tr', null, h('td', { colspan: '6', class: 'empty' }, 'No experiment in this state.'))))),
      unassigned.length ? h('p', { class: 'hint', 'data-testid': 'unassigned-runs' }, `${unassigned.length} run${unassigned.length === 1 ? '' : 's'} not assigned to this plan: `,
        unassigned.map((r, i) => [i ? ', ' : '', h('a', { href: urls.run(r.id) }, r.name)])) : null);
  }

  // -- run list
  const listBox = h('div', { class: 'run-list', 'data-testid': 'run-list', 'data-section': 'runs' });

  // Runs shown per page of the list (a campaign may hold hundreds).
  const PAGE = 20;
  let pageNo = 0;

  function runRow(r, codes) {
    const v = (r.summary && r.summary.verdicts) || [];
    const size = r.files.reduce((a, f) => a + f.size_bytes, 0);
    return h('tr', { 'data-testid': 'run-row', 'data-run-id': r.id, 'data-status': r.status },
      h('td', { class: 'nowrap' }, fmtDate(r.created_at)),
      h('td', null, h('a', { href: urls.run(r.id), 'data-testid': 'run-link' }, r.name)),
      h('td', { class: 'mono nowrap' }, r.experiment_id ? codes.get(r.experiment_id) || h('span', { class: 'muted', title: r.experiment_id }, 'older plan') : h('span', { class: 'muted' }, '–')),
      h('td', { class: 'nowrap' }, describeCell(r)),
      h('td', null, r.layout === 'split' ? 'control + nav' : 'one log'),
      h('td', null, statusBadge(r.status, r), r.excluded ? [' ', excludedBadge(r)] : null),
      h('td', { class: 'badges' }, v.map((x) => verdictBadge(x))),
      h('td', { class: 'num', title: r.files.map((f) => `${f.role}: ${f.filename}, ${f.size_bytes} bytes`).join('\n') }, bytes(size)));
  }

  /** Rejected uploads, apart from the runs, each removable (a soft delete: undo under "Deleted"). */
  function rejectedBox(rejected) {
    if (!rejected.length) return null;
    const msg = h('div', { 'aria-live': 'polite' });
    return h('div', { class: 'rejected-list', 'data-testid': 'rejected-list' },
      h('h3', null, `Rejected uploads (${rejected.length}) `, h('span', { class: 'hint' }, 'invalid files, kept as received; fix and upload again, then remove them')),
      h('ul', { class: 'plain' }, rejected.slice().reverse().map((r) => h('li', { 'data-testid': 'run-row', 'data-run-id': r.id, 'data-status': r.status },
        h('a', { href: urls.run(r.id) }, r.name), ' ',
        h('span', { class: 'error-text', 'data-testid': 'run-error' }, errorWhere(r.error, r.files), r.error && r.error.message ? h('span', { class: 'muted' }, ` — ${errorText(r.error.message)}`) : null), ' ',
        h('button', {
          type: 'button', class: 'btn small danger', 'data-needs': 'supervisor', 'data-testid': 'remove-rejected',
          onclick: () => api.deleteRun(r.id, 'rejected upload removed').then(refresh, (e) => fill(msg, h('p', { class: 'error-text', role: 'alert' }, e.message))),
        }, 'Remove')))),
      msg);
  }

  function renderRuns() {
    const codes = new Map(plan ? plan.experiments.map((e) => [e.id, e.code]) : []);
    const good = runs.filter((r) => r.status !== 'rejected');
    const rejected = runs.filter((r) => r.status === 'rejected');
    if (!runs.length) {
      fill(listBox, h('h3', null, 'Runs'), h('p', { class: 'empty', 'data-testid': 'no-runs' }, 'No runs uploaded yet.'));
      return;
    }
    const pages = Math.max(1, Math.ceil(good.length / PAGE));
    pageNo = Math.min(pageNo, pages - 1);
    const shown = good.slice().reverse().slice(pageNo * PAGE, (pageNo + 1) * PAGE);
    const go = (p) => { pageNo = p; renderRuns(); };
    const pager = pages > 1 ? h('nav', { class: 'pager actions', 'aria-label': 'Pages of runs', 'data-testid': 'runs-pager' },
      h('button', { type: 'button', class: 'btn small', disabled: pageNo === 0, 'data-testid': 'runs-prev', onclick: () => go(pageNo - 1) }, '‹ newer'),
      h('span', { class: 'muted', 'data-testid': 'runs-page' }, `${pageNo * PAGE + 1}–${pageNo * PAGE + shown.length} of ${good.length}`),
      h('button', { type: 'button', class: 'btn small', disabled: pageNo >= pages - 1, 'data-testid': 'runs-next', onclick: () => go(pageNo + 1) }, 'older ›')) : null;
    fill(listBox, h('h3', null, `Runs (${good.length}) `, h('span', { class: 'hint' }, 'newest first · badge colours: green good, amber weak, red insufficient; tap a badge for the reason')),
      good.length ? h('div', { class: 'table-x' },
        h('table', { class: 'grid-table runs-table', 'data-testid': 'runs-table' },
          h('thead', null, h('tr', null, h('th', null, 'Uploaded'), h('th', null, 'Name'), h('th', null, 'Experiment'),
            h('th', { title: 'role · grid speed · excited DOFs; “?”: inferred from the data, confirm on the run page' }, 'What it is'), h('th', null, 'Layout'),
            h('th', null, 'Status'), h('th', null, 'Verdict per DOF'), h('th', { class: 'num' }, 'Size'))),
          h('tbody', null, shown.map((r) => runRow(r, codes))))) : null,
      pager,
      rejectedBox(rejected));
  }

  async function refresh() {
    const [r, c] = await Promise.all([
      api.runs(id),
      plan ? api.coverage(id).catch((e) => { if (e.status === 404) return null; throw e; }) : null,
    ]);
    runs = r;
    coverage = c;
    if (onRuns) onRuns(runs);
    renderRuns();
    renderCoverage();
    renderExperiments();
  }

  renderRuns();
  renderCoverage();
  fill(host,
    h('h2', { class: 'section-title' }, 'Runs ', h('span', { class: 'hint' }, 'upload logs as they come in; the coverage says what must be flown again before the ship moves on')),
    h('div', { class: 'runs-layout' }, h('div', { class: 'runs-left' }, form, listBox), covBox));

  return {
    runs: () => runs,
    async setPlan(p) {
      plan = p;
      await refresh();
    },
    destroy() {},
  };
}
