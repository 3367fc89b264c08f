// Model page (#/models/{id}): provenance (method, settings, runs, software,
// version and lineage), structure findings and notes, the parameter table with
// standard deviations, the validation on each held-out run (fits, predicted vs
// measured, residual autocorrelation, verdict and findings), the responses
// (Bode over a run's H1, pole-zero, step/impulse, Hankel singular values,
// residual cross-correlation, overlay compare: modelviews.js), exports, and
// the ZOH-discretized Φ, Γ at a chosen sample time.

import { api, urls } from './api.js';
import { fmt, fmtDate, fmtKn } from './format.js';
import { h, fill, labelled, num, clearErrors, showFieldError } from './forms.js';
import { METHOD_LABEL, KIND_LABEL_MODEL, errLine } from './identify.js';
import { predictionPlot, autocorrelationPlot, zoomGroup } from './modelplots.js';
import { exact } from './runplots.js';
import { discoveryPanel } from './discoverpanel.js';
import { deletedBadge, modelManageControls } from './manage.js';
import { modelViewsSection } from './modelviews.js';
import { exportBar, uplotExportable } from './plotexport.js';

/** Export buttons of the live chart `name`. */
const exportOf = (name, title) => exportBar(() => (window.__plots[name] ? uplotExportable(window.__plots[name], title) : null), 'validation-export');

/** Unit of an output channel (the log contract). */
function outUnit(name) {
  if (['u', 'v', 'w'].includes(name)) return 'm/s';
  if (['p', 'q', 'r'].includes(name)) return 'rad/s';
  if (['x', 'y', 'z'].includes(name)) return 'm';
  if (['phi', 'theta', 'psi'].includes(name)) return 'rad';
  return '';
}

/**
 * NRMSE fit (1 perfect, 0 no better than the mean) as a percentage with one
 * decimal, the core's format: "87.3 %", "−41.0 %", "< −1000 %" below −10,
 * "—" when there is none (the prediction diverged, or the output is constant).
 */
export function fitText(v) {
  if (v == null || !Number.isFinite(v)) return '—';
  if (v < -10) return '< −1000 %';
  const p = (v * 100).toFixed(1);
  return `${p === '-0.0' ? '0.0' : p.replace('-', '−')} %`;
}

/** The restart period of a report, e.g. "10 s". */
function restartText(rep) {
  return rep.restart_s != null ? `${Number(rep.restart_s.toFixed(1))} s` : '10 s';
}

/** Tooltip of a restarted fit: how many windows diverged. */
function restartedTitle(c) {
  const w = c.restarted;
  if (!w) return '';
  return w.diverged ? `${w.diverged} of ${w.windows} windows diverged and are left out` : `${w.windows} windows, none diverged`;
}

/** Where a channel's predictions diverged, in the order of the fit columns. */
function divergences(c) {
  const d = c.diverged || {};
  return ['one_step', 'k_step', 'restarted', 'simulation'].map((k) => d[k]).filter(Boolean);
}
const fitClass = (v) => (v == null ? '' : v >= 0.8 ? 'fit-good' : v >= 0.5 ? 'fit-weak' : 'fit-bad');

function speedText(mps) {
  return mps == null ? '–' : `${fmtKn(mps)} kn (${fmt(mps)} m/s)`;
}

function settingText(v) {
  if (v == null) return '–';
  if (Array.isArray(v)) return v.length ? v.map((x) => (typeof x === 'object' ? JSON.stringify(x) : String(x))).join(', ') : '[]';
  if (typeof v === 'object') return JSON.stringify(v);
  return String(v);
}

function matrixTable(rows, { rowNames = [], colNames = [], testid } = {}) {
  return h('table', { class: 'grid-table compact matrix', 'data-testid': testid },
    colNames.length ? h('thead', null, h('tr', null, h('th', null, ''), colNames.map((c) => h('th', { class: 'num mono' }, c)))) : null,
    h('tbody', null, rows.map((r, i) => h('tr', null,
      h('th', { class: 'mono' }, rowNames[i] ?? String(i + 1)),
      r.map((v) => h('td', { class: 'num mono', title: String(v) }, exact(v)))))));
}

const DOF3 = ['surge', 'sway', 'yaw'];
const NU3 = ['u', 'v', 'r'];

/** A DP ship's matrices (Fossen et al. 1995): θ″ with ± std, A″_h, K″, D″, A″, B″ (Bis) and A, B in SI. */
function dpShipSection(dp, inputs) {
  const pm = (label, hint, rows, opts) => h('div', { class: 'dp-matrix' }, h('b', null, label), h('span', { class: 'hint' }, ` ${hint}`), matrixTable(rows, opts));
  const withStd = dp.a_h.map((r, i) => r.map((v, j) => (dp.a_h_std[i][j] ? `${exact(v)} ± ${exact(dp.a_h_std[i][j])}` : exact(v))));
  const kRows = [dp.k.map((v, j) => `${exact(v)} ± ${exact(dp.k_std[j])}`)];
  const textTable = (rows, rowNames, colNames, testid) => h('table', { class: 'grid-table compact matrix', 'data-testid': testid },
    h('thead', null, h('tr', null, h('th', null, ''), colNames.map((c) => h('th', { class: 'num mono' }, c)))),
    h('tbody', null, rows.map((r, i) => h('tr', null, h('th', { class: 'mono' }, rowNames[i]), r.map((v) => h('td', { class: 'num mono' }, v))))));
  return h('section', { class: 'card dp-ship', 'data-testid': 'dp-ship' },
    h('p', { class: 'hint' }, `Momentum form ḣ = A_h·h + T·K·u + b_h, h = M·ν (eq. 35); Bis units: L = ${exact(dp.length_m)} m, time √(L/g) = ${fmt(dp.time_unit_s, 4)} s, forces m·g, moments m·g·L.`),
    h('div', { class: 'matrix-pair' },
      h('div', { class: 'dp-matrix' }, h('b', null, 'A″_h'), h('span', { class: 'hint' }, ' identified (eq. 48), ± std'), textTable(withStd, DOF3, DOF3, 'dp-a-h')),
      h('div', { class: 'dp-matrix' }, h('b', null, 'K″'), h('span', { class: 'hint' }, ' thrust coefficients (eq. 49), ± std'), textTable(kRows, ['K'], inputs, 'dp-k'))),
    h('div', { class: 'matrix-pair' },
      pm('M″', 'known (eq. 30)', dp.m, { rowNames: DOF3, colNames: DOF3, testid: 'dp-m' }),
      pm('D″ = −A″_h M″', 'linear damping', dp.d, { rowNames: DOF3, colNames: DOF3, testid: 'dp-d' }),
      pm('T″', 'thruster configuration (eq. 29)', dp.t_config, { rowNames: DOF3, colNames: inputs, testid: 'dp-t' })),
    h('div', { class: 'matrix-pair' },
      pm('A″ = M″⁻¹A″_h M″', 'ν̇ = Aν + Bu (eq. 51, Bis)', dp.a, { rowNames: NU3, colNames: NU3, testid: 'dp-a' }),
      pm('B″ = M″⁻¹T″K″', '(eq. 52, Bis)', dp.b, { rowNames: NU3, colNames: inputs, testid: 'dp-b' })),
    h('div', { class: 'matrix-pair' },
      pm('A [1/s]', 'SI: ν in m/s, m/s, rad/s', dp.a_si, { rowNames: NU3, colNames: NU3, testid: 'dp-a-si' }),
      pm('B [SI per unit command]', 'm/s², m/s², rad/s²', dp.b_si, { rowNames: NU3, colNames: inputs, testid: 'dp-b-si' })),
    refinementPart(dp));
}

/** What the prediction-error refinement after the staged EKF did, with the EKF's θ″ beside the stored ones. */
function refinementPart(dp) {
  const r = dp.refinement;
  if (!r) return null;
  const facts = [`${r.iterations} step(s)`];
  if (r.variance_ratio != null) facts.push(`innovations' variance ratio ${fmt(r.variance_ratio, 3)}`);
  if (r.held_out_nll_change != null) facts.push(`held-out negative log-likelihood ${r.held_out_nll_change <= 0 ? '' : '+'}${fmt(r.held_out_nll_change, 3)}`);
  const head = r.applied
    ? `θ″ refined after the staged EKF by prediction error on all runs (${facts.join('; ')}); std: Cramér–Rao, inflated where the residuals ask for it.`
    : `θ″ and std are the staged EKF's: ${r.reason || 'the refinement was not taken'}.`;
  const pm = (v, sd) => `${exact(v)} ± ${exact(sd)}`;
  return h('div', { class: 'dp-refinement', 'data-testid': 'dp-refinement', 'data-applied': String(r.applied) },
    h('p', { class: 'hint' }, head),
    r.applied ? h('table', { class: 'grid-table compact', 'data-testid': 'dp-refinement-table' },
      h('thead', null, h('tr', null, h('th', null, 'θ″'), h('th', { class: 'num' }, 'staged EKF'), h('th', { class: 'num' }, 'refined (stored)'), h('th', { class: 'num' }, 'std inflation'))),
      // A thrust-coefficient slot the vessel's layout does not use stays 0 ± 0: not shown.
      h('tbody', null, r.ekf_theta.map((v, i) => (v === 0 && dp.theta[i] === 0 && !r.ekf_theta_std[i]) ? null : h('tr', null,
        h('th', { scope: 'row' }, `θ″${i + 1}`),
        h('td', { class: 'num mono' }, pm(v, r.ekf_theta_std[i])),
        h('td', { class: 'num mono' }, pm(dp.theta[i], dp.theta_std[i])),
        h('td', { class: 'num' }, r.std_inflation[i] == null ? '–' : `×${fmt(r.std_inflation[i], 3)}`))))) : null);
}

/** The model page. Returns a controller whose mount() draws the plots. */
export async function modelPage(view, id) {
  const mv = await api.model(id);
  const { model, document: doc } = mv;
  const [runs, lineage] = await Promise.all([
    api.runs(model.campaign_id).catch(() => []),
    api.lineage(model.lineage_id).catch(() => [model]),
  ]);
  const runName = new Map(runs.map((r) => [r.id, r.name]));
  const runLink = (rid) => h('a', { href: urls.run(rid), 'data-testid': 'provenance-run' }, runName.get(rid) || rid);
  const validation = Array.isArray(mv.validation) ? mv.validation : (mv.validation && mv.validation.runs) || [];
  const parent = model.parent_id ? lineage.find((x) => x.id === model.parent_id) : null;
  const discovery = await discoveryPanel(model);
  const versions = lineage.slice().sort((a, b) => a.version - b.version);

  // ---- provenance -------------------------------------------------------------
  const settings = mv.settings && typeof mv.settings === 'object' ? mv.settings : {};
  const provenance = h('dl', { class: 'summary', 'data-testid': 'provenance' },
    h('dt', null, 'Method'), h('dd', { 'data-testid': 'model-method' }, METHOD_LABEL[model.method] || model.method, h('span', { class: 'muted' }, ` · ${KIND_LABEL_MODEL[model.kind] || model.kind}`)),
    h('dt', null, 'Settings'), h('dd', { 'data-testid': 'model-settings' }, Object.keys(settings).length
      ? h('ul', { class: 'plain' }, Object.entries(settings).map(([k, v]) => h('li', null, h('span', { class: 'mono' }, k), ': ', h('span', { class: 'mono' }, settingText(v)))))
      : 'defaults'),
    h('dt', null, 'Estimation runs'), h('dd', { 'data-testid': 'model-runs' }, mv.run_ids.length ? mv.run_ids.map((r, i) => [i ? ', ' : '', runLink(r)]) : '–'),
    h('dt', null, 'Validation runs'), h('dd', { 'data-testid': 'model-validation-runs' }, mv.validation_run_ids.length ? mv.validation_run_ids.map((r, i) => [i ? ', ' : '', runLink(r)]) : '–'),
    h('dt', null, 'Version'), h('dd', { 'data-testid': 'model-version' }, `v${model.version}`,
      h('span', { class: 'muted' }, ` of lineage ${model.lineage_id}`),
      versions.length > 1 ? h('span', null, ' · versions: ', versions.map((x, i) => [i ? ', ' : '', x.id === model.id ? h('b', null, `v${x.version}`) : h('a', { href: urls.model(x.id) }, `v${x.version}`)])) : null),
    h('dt', null, 'Parent'), h('dd', { 'data-testid': 'model-parent' }, model.parent_id ? h('a', { href: urls.model(model.parent_id) }, parent ? `v${parent.version} · ${parent.name}` : model.parent_id) : 'none (first version)'),
    h('dt', null, 'Software'), h('dd', { class: 'mono', 'data-testid': 'model-software' }, model.software_version),
    h('dt', null, 'Identified'), h('dd', null, fmtDate(model.created_at), model.job_id ? h('span', { class: 'muted' }, ` · job ${model.job_id}`) : null));

  const findings = (doc.structure_findings || []).length
    ? h('ul', { class: 'warnings', 'data-testid': 'structure-findings', role: 'note', 'aria-label': 'Structure findings' },
      doc.structure_findings.map((f) => h('li', null, '⚠ ', f)))
    : h('p', { class: 'hint', 'data-testid': 'structure-findings-none' }, 'No physical-structure findings (M symmetric positive definite, D̄ dissipative where checked).');
  const notes = (doc.notes || []).length
    ? h('ul', { class: 'notes', 'data-testid': 'model-notes' }, doc.notes.map((n) => h('li', null, n)))
    : null;

  // ---- parameters ---------------------------------------------------------------
  const params = doc.parameters || [];
  const speeds = [...new Set(params.map((p) => p.grid_speed_mps).filter((x) => x != null))].sort((a, b) => a - b);
  const pState = { sort: null, dir: 1, group: speeds.length > 1 };
  const pBody = h('tbody');
  const pHead = h('tr');
  const COLS = [
    ['group', 'Group', (p) => p.group], ['symbol', 'Symbol', (p) => p.symbol], ['speed', 'Speed', (p) => p.grid_speed_mps ?? -1],
    ['value', 'Value', (p) => p.value], ['std', '± std', (p) => p.std ?? -1], ['rel', 'std / |value|', (p) => (p.std != null && p.value ? p.std / Math.abs(p.value) : -1)], ['unit', 'Unit', (p) => p.unit],
  ];
  const groupBox = h('input', { type: 'checkbox', checked: pState.group, 'data-testid': 'param-group', onChange: (e) => { pState.group = e.target.checked; renderParams(); } });

  function paramRow(p) {
    const rel = p.std != null && p.value ? p.std / Math.abs(p.value) : null;
    return h('tr', { 'data-testid': 'param-row', class: rel != null && rel > 0.5 ? 'uncertain' : null, title: rel != null && rel > 0.5 ? 'standard deviation above half the estimate' : null },
      h('td', null, p.group),
      h('td', { class: 'mono' }, p.symbol),
      h('td', { class: 'num' }, p.grid_speed_mps == null ? '–' : `${fmtKn(p.grid_speed_mps)} kn`),
      h('td', { class: 'num mono', title: String(p.value) }, exact(p.value)),
      h('td', { class: 'num mono', 'data-testid': 'param-std' }, p.std == null ? '–' : `± ${exact(p.std)}`),
      h('td', { class: 'num' }, rel == null ? '–' : `${fmt(rel * 100, 1)} %`),
      h('td', null, p.unit));
  }

  function renderParams() {
    fill(pHead, COLS.map(([key, label]) => h('th', {
      class: ['value', 'std', 'rel', 'speed'].includes(key) ? 'num' : null,
      'aria-sort': pState.sort === key ? (pState.dir > 0 ? 'ascending' : 'descending') : 'none',
    }, h('button', {
      type: 'button', class: 'sort', 'data-testid': `param-sort-${key}`,
      onClick: () => { if (pState.sort === key) pState.dir = -pState.dir; else { pState.sort = key; pState.dir = 1; } renderParams(); },
    }, label, pState.sort === key ? (pState.dir > 0 ? ' ▲' : ' ▼') : ''))));
    let list = params.slice();
    if (pState.sort) {
      const get = COLS.find((c) => c[0] === pState.sort)[2];
      list.sort((a, b) => { const x = get(a); const y = get(b); return (x < y ? -1 : x > y ? 1 : 0) * pState.dir; });
    }
    if (!pState.group) { fill(pBody, list.map(paramRow)); return; }
    const groups = [...speeds.map((s) => [s, list.filter((p) => p.grid_speed_mps === s)]), [null, list.filter((p) => p.grid_speed_mps == null)]];
    fill(pBody, groups.filter(([, ps]) => ps.length).map(([s, ps]) => [
      h('tr', { class: 'group-head', 'data-testid': 'param-group-head' }, h('th', { colspan: String(COLS.length) }, s == null ? 'Not scheduled on speed' : `Grid point ${speedText(s)}`, h('span', { class: 'hint' }, ` · ${ps.length} parameters`))),
      ps.map(paramRow)]));
  }

  const paramSection = params.length
    ? h('div', null,
      h('div', { class: 'filters' }, h('label', { class: 'check' }, groupBox, ' group by grid speed'), h('span', { class: 'hint' }, 'click a column to sort · rows with std above half the value are marked')),
      h('div', { class: 'table-scroll' }, h('table', { class: 'grid-table compact params-table', 'data-testid': 'param-table' }, h('thead', null, pHead), pBody)))
    : h('p', { class: 'empty', 'data-testid': 'no-params' }, 'This model has no parameter table.');

  // ---- validation -----------------------------------------------------------------
  const views = modelViewsSection(model, doc, { runs, validation });
  const plotJobs = []; // drawn in mount(), when the hosts have a width
  const valSections = validation.map((rv, ri) => {
    const rep = rv.report || {};
    const chans = rep.channels || [];
    const group = zoomGroup();
    const sync = `val-${ri}`;
    const fitRows = chans.map((c) => h('tr', { 'data-testid': 'fit-row', 'data-channel': c.output },
      h('td', { class: 'mono' }, c.output),
      h('td', { class: `num ${fitClass(c.fit_one_step)}`, 'data-testid': 'fit-one-step' }, fitText(c.fit_one_step)),
      h('td', { class: `num ${fitClass(c.fit_k_step)}`, 'data-testid': 'fit-k-step' }, fitText(c.fit_k_step)),
      h('td', { class: `num ${fitClass(c.fit_restarted)}`, 'data-testid': 'fit-restarted', title: restartedTitle(c) }, fitText(c.fit_restarted)),
      h('td', { class: `num ${fitClass(c.fit_simulation)}`, 'data-testid': 'fit-simulation' }, fitText(c.fit_simulation)),
      h('td', null, c.residuals_white ? h('span', { class: 'badge good' }, 'white') : h('span', { class: 'badge weak' }, 'correlated')),
      h('td', { class: 'verdict-text', 'data-testid': 'channel-verdict' }, c.verdict)));
    const diverged = chans.flatMap(divergences);
    const divergenceNote = diverged.length
      ? h('ul', { class: 'warnings', 'data-testid': 'divergences', role: 'note', 'aria-label': 'Divergences' },
        diverged.map((d) => h('li', { 'data-testid': 'divergence', 'data-channel': d.output }, '⚠ ', d.text, ': no fit over what follows')))
      : null;
    const chanBlocks = chans.map((c, ci) => {
      const pvm = h('div', { class: 'plot', 'data-testid': 'pvm-plot', 'data-channel': c.output });
      const acf = h('div', { class: 'plot', 'data-testid': 'acf-plot', 'data-channel': c.output });
      const ac = c.one_step && c.one_step.autocorrelation;
      plotJobs.push(() => {
        if (c.plot && c.plot.time_s && c.plot.time_s.length) predictionPlot(`pvm:${ri}:${ci}`, pvm, c.plot, { k: rep.k, restart: rep.restart_s, unit: `${c.output} [${outUnit(c.output)}]`, sync, group });
        else fill(pvm, h('p', { class: 'empty' }, 'No plot series in the report.'));
        if (ac && ac.lags && ac.lags.length) autocorrelationPlot(`acf:${ri}:${ci}`, acf, ac);
        else fill(acf, h('p', { class: 'empty' }, 'No autocorrelation in the report.'));
      });
      const zc = c.one_step && c.one_step.zero_crossings;
      return h('div', { class: 'channel-block', 'data-testid': 'channel-block', 'data-channel': c.output },
        h('h4', null, h('span', { class: 'mono' }, c.output), ' ', h('span', { class: `badge ${c.residuals_white ? 'good' : 'weak'}` }, c.residuals_white ? 'residuals white' : 'residuals correlated'),
          h('span', { class: 'verdict-line', 'data-testid': 'channel-verdict-line' }, c.verdict)),
        (c.findings || []).length ? h('ul', { class: 'findings', 'data-testid': 'channel-findings' }, c.findings.map((f) => h('li', null, f))) : null,
        h('div', { class: 'plot-grid pvm-grid' },
          h('div', { class: 'plot-card' }, h('h3', null, 'Predicted vs measured ', exportOf(`pvm:${ri}:${ci}`, `${model.name} v${model.version} on ${rv.run_name || rv.run_id}: ${c.output} predicted vs measured`), h('span', { class: 'hint' }, `fit 1-step ${fitText(c.fit_one_step)} · ${rep.k}-step ${fitText(c.fit_k_step)} · restarted ${fitText(c.fit_restarted)} · simulation ${fitText(c.fit_simulation)}`)), pvm),
          h('div', { class: 'plot-card' }, h('h3', null, 'Residual autocorrelation ', exportOf(`acf:${ri}:${ci}`, `${model.name} v${model.version} on ${rv.run_name || rv.run_id}: ${c.output} residual autocorrelation`), h('span', { class: 'hint' },
            ac ? `1-step errors; ${ac.lags_outside.length} lag${ac.lags_outside.length === 1 ? '' : 's'} outside the ${Math.round(ac.confidence * 100)} % band (${fmt(ac.fraction_outside * 100, 1)} %, expected ${fmt(ac.expected_fraction * 100, 1)} %)${zc ? ` · ${zc.count} zero crossings (expected ${fmt(zc.expected, 0)})` : ''}` : '')), acf)));
    });
    return h('section', { class: 'card validation', 'data-testid': 'validation-run', 'data-run-id': rv.run_id, 'aria-label': `Validation on ${rv.run_name || rv.run_id}` },
      h('h3', null, 'Validation on ', h('a', { href: urls.run(rv.run_id) }, rv.run_name || rv.run_id),
        h('span', { class: 'hint' }, ` · ${rep.n_samples} samples at ${exact(rep.sample_time_s)} s · k = ${rep.k} · drag to zoom (all channels follow), double-click to reset`)),
      h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact fit-table', 'data-testid': 'fit-table' },
        h('thead', null, h('tr', null, h('th', null, 'Channel'), h('th', { class: 'num', title: 'NRMSE fit of ŷ(t|t−1): 100 % perfect, 0 % no better than the mean' }, '1-step fit'),
          h('th', { class: 'num', title: `NRMSE fit of ŷ(t|t−${rep.k})` }, `${rep.k}-step fit`),
          h('th', { class: 'num', title: `NRMSE fit of free runs restarted from the measured state every ${restartText(rep)}, over the windows that did not diverge` }, `Restarted ${restartText(rep)} fit`),
          h('th', { class: 'num', title: 'NRMSE fit of the free-run simulation over the whole run' }, 'Simulation fit'),
          h('th', null, 'Residuals'), h('th', null, 'Verdict'))),
        h('tbody', null, fitRows))),
      divergenceNote,
      chanBlocks);
  });

  // ---- exports ----------------------------------------------------------------------
  const fossenReason = model.kind === 'state_space' ? 'A black-box state-space model has no Fossen form (no M, D, g(η)).' : null;
  const exportsBox = h('div', { class: 'actions', role: 'group', 'aria-label': 'Export', 'data-testid': 'exports' },
    h('a', { class: 'btn', href: urls.modelExport(id, 'json'), download: '', 'data-testid': 'export-json' }, '↓ JSON'),
    h('a', { class: 'btn', href: urls.modelExport(id, 'csv'), download: '', 'data-testid': 'export-csv' }, '↓ Parameters CSV'),
    fossenReason
      ? h('button', { type: 'button', class: 'btn', disabled: true, title: fossenReason, 'aria-describedby': 'fossen-reason', 'data-testid': 'export-fossen' }, '↓ Fossen form')
      : h('a', { class: 'btn', href: urls.modelExport(id, 'fossen'), download: '', 'data-testid': 'export-fossen' }, '↓ Fossen form'),
    fossenReason ? h('span', { class: 'hint', id: 'fossen-reason', 'data-testid': 'fossen-reason' }, fossenReason) : null);

  // ---- ZOH ---------------------------------------------------------------------------
  const hIn = h('input', { type: 'number', step: 'any', min: '0', 'data-field': 'h', 'data-testid': 'zoh-h', class: 'short', value: '' });
  const zohOut = h('div', { class: 'zoh-out', 'data-testid': 'zoh-result', 'aria-live': 'polite' });
  const zohForm = h('form', { class: 'row zoh-form', novalidate: true, 'data-testid': 'zoh-form', onSubmit: discretize },
    labelled('Sample time h [s]', hIn, 'e.g. the controller period'),
    h('button', { type: 'submit', class: 'btn', 'data-testid': 'zoh-submit' }, 'Discretize (ZOH)'));

  async function discretize(ev) {
    ev.preventDefault();
    clearErrors(zohForm);
    const hv = num(hIn.value);
    if (hv == null || !Number.isFinite(hv) || hv <= 0) { showFieldError(zohForm, 'h', 'a sample time in seconds above 0'); return; }
    fill(zohOut, h('p', { class: 'loading' }, h('span', { class: 'spinner', 'aria-hidden': 'true' }), 'Discretizing…'));
    try {
      const r = await api.model(id, hv);
      const d = r.discrete;
      if (!d) throw new Error('the server answered without the discretized model');
      const dpm = model.kind === 'dp_ship';
      const states = dpm ? NU3 : doc.outputs;
      fill(zohOut, h('p', { class: 'hint' }, `ν(k+1) = Φ ν(k) + Γ ${dpm ? 'u' : 'γ'}(k), h = ${exact(d.h)} s, zero-order hold on the input${dpm ? ' (ν in m/s, m/s, rad/s; u the thruster commands)' : ''}.`),
        d.points.map((p) => h('div', { class: 'zoh-point', 'data-testid': 'zoh-point' },
          h('h4', null, p.speed_mps != null ? `Grid point ${speedText(p.speed_mps)}` : 'Operating point'),
          h('div', { class: 'matrix-pair' },
            h('div', null, h('b', null, 'Φ'), matrixTable(p.phi, { rowNames: states, colNames: states, testid: 'zoh-phi' })),
            h('div', null, h('b', null, 'Γ'), matrixTable(p.gamma, { rowNames: states, colNames: doc.inputs, testid: 'zoh-gamma' }))))));
    } catch (err) {
      fill(zohOut);
      if (err.field === 'h') showFieldError(zohForm, 'h', err.message, err.limit);
      else fill(zohOut, h('p', { class: 'error-text', role: 'alert', 'data-testid': 'zoh-error' }, errLine(err)));
    }
  }

  fill(view,
    h('nav', { class: 'crumbs muted', 'aria-label': 'Breadcrumb' }, h('a', { href: `#/campaigns/${model.campaign_id}`, 'data-testid': 'model-campaign-link' }, '← campaign')),
    h('div', { class: 'page-head' },
      h('div', null,
        h('h1', { 'data-testid': 'model-title' }, model.name, h('span', { class: 'badge neutral' }, `v${model.version}`), deletedBadge(model)),
        h('div', { class: 'muted' }, `${METHOD_LABEL[model.method] || model.method} · ${(doc.dofs || []).join(', ')} · inputs ${(doc.inputs || []).join(', ')} → outputs ${(doc.outputs || []).join(', ')}`)),
      h('div', null, exportsBox, modelManageControls(model))),
    provenance,
    h('h2', { class: 'section-title' }, 'Findings'),
    findings,
    notes,
    h('h2', { class: 'section-title' }, 'Parameters ', h('span', { class: 'hint' }, `${params.length} estimates with their standard deviations`)),
    paramSection,
    doc.dp_ship ? [h('h2', { class: 'section-title' }, 'DP ship matrices'), dpShipSection(doc.dp_ship, doc.inputs || [])] : null,
    h('h2', { class: 'section-title', id: 'responses' }, 'Responses ', h('span', { class: 'hint' }, 'Bode over the data, poles and zeros, step, Hankel singular values, residual cross-correlation, compare')),
    views.el,
    h('h2', { class: 'section-title' }, 'Validation ', h('span', { class: 'hint' }, 'on runs the model was not fitted to')),
    valSections.length ? valSections : h('p', { class: 'empty', 'data-testid': 'no-validation' }, 'No validation report.'),
    h('h2', { class: 'section-title' }, 'Missing physics ', h('span', { class: 'hint' }, 'where simulation and recordings part, and why')),
    discovery.el,
    h('h2', { class: 'section-title' }, 'Discrete-time model'),
    zohForm,
    zohOut);
  if (params.length) renderParams();

  return {
    key: `model:${id}`,
    mount() { for (const f of plotJobs) f(); views.draw(); },
    destroy() { discovery.destroy(); views.destroy(); },
  };
}
