// Campaign page: summary, plan generation, totals, the filterable plan
// table, and one experiment (channels, schedule plot, PSD, exports).

import { api, urls } from './api.js';
import { renameControl } from './rename.js';
import { deletedSection } from './trash.js';
import { campaignTrash } from './parenttrash.js';
import { deletedBadge } from './manage.js';
import { sectionNav } from './sectionnav.js';
import { precisionSection } from './precision.js';
import { designSection } from './design.js';
import { nextDiveSection } from './nextdive.js';
import {
  FAMILY_LABEL, KIND_LABEL, SIGNAL_LABEL, bandText, describeWaveform, fmt, fmtDate, fmtKn, hms,
  peText, secs, unitLabel,
} from './format.js';
import { h, fill, banner, clearBanner, reloadPage } from './forms.js';
import { DURATIONS, gridText } from './campaigns.js';
import { schedulePlot, psdPlot, destroyPlots } from './plots.js';
import { runsSection } from './runs.js';
import { identifySection } from './identify.js';
import { campaignOffsetPanel } from './offsetpanel.js';

const isExcitedWithAnalysis = (c) => c.excited && c.analysis;

function peTitle(c) {
  const a = c.analysis;
  const ok = a.pe_order >= a.pe_required;
  return `${c.column}: PE order ${a.pe_order >= a.pe_cap ? '≥ ' : ''}${a.pe_order}, required ${a.pe_required}${ok ? '' : ' — NOT persistently exciting enough'}`;
}

/** PE order vs required per excited channel; identical channels collapse into one chip. */
function peChips(e) {
  const chans = e.channels.filter(isExcitedWithAnalysis);
  const same = chans.length > 2 && chans.every((c) => peText(c.analysis) === peText(chans[0].analysis));
  const ok = (c) => c.analysis.pe_order >= c.analysis.pe_required;
  if (same) {
    return h('span', { class: `chip ${chans.every(ok) ? 'ok' : 'bad'}`, title: chans.map(peTitle).join('\n') },
      `${chans.length} ch ${peText(chans[0].analysis)}`);
  }
  return chans.map((c) => h('span', { class: `chip ${ok(c) ? 'ok' : 'bad'}`, title: peTitle(c) }, `${c.column} ${peText(c.analysis)}`));
}

function bandOf(e) {
  const bands = e.channels.filter(isExcitedWithAnalysis).map((c) => c.analysis.band_hz).filter(Boolean);
  if (!bands.length) return { text: '–', title: '' };
  const lo = Math.min(...bands.map((b) => b[0]));
  const hi = Math.max(...bands.map((b) => b[1]));
  const title = e.channels.filter(isExcitedWithAnalysis).map((c) => `${c.column}: ${bandText(c.analysis.band_hz)}`).join('\n');
  return { text: bandText([lo, hi]), title };
}

function dofsText(e, vessel) {
  if (vessel && e.dofs.length === vessel.dofs.length && e.dofs.length > 2) return `all (${e.dofs.length})`;
  return e.dofs.join(', ');
}

function excitationText(c) {
  const x = c.excitation || {};
  const parts = [];
  if (x.signal) parts.push(SIGNAL_LABEL[x.signal] || x.signal);
  if (x.quantity) parts.push(x.quantity === 'force' ? 'open-loop forces' : 'velocity references');
  if (x.amplitude_fraction != null) parts.push(`amplitude ${fmt(x.amplitude_fraction * 100, 1)} % of limits`);
  const over = Object.entries(x.per_dof || {}).map(([d, o]) => {
    const bits = [];
    if (o.signal) bits.push(SIGNAL_LABEL[o.signal] || o.signal);
    if (o.amplitude != null) bits.push(`±${fmt(o.amplitude)}`);
    if (o.clock_period_s != null) bits.push(`Tc ${fmt(o.clock_period_s)} s`);
    if (o.prbs_order != null) bits.push(`n=${o.prbs_order}`);
    return `${d}: ${bits.join(' ')}`;
  });
  if (over.length) parts.push(`overrides — ${over.join('; ')}`);
  return parts.join(' · ') || 'defaults';
}

/** "3 added, 3 removed, 1 changed, 17 unchanged; 1 run no longer matched" */
function changeWords(ch) {
  const n = ch.counts;
  const runs = ch.unmatched_runs.length;
  const tail = runs ? `; ${runs} run${runs === 1 ? '' : 's'} no longer matched` : '';
  return `${n.added} added, ${n.removed} removed, ${n.changed} changed, ${n.unchanged} unchanged against v${ch.previous_version}${tail}`;
}

/** What this plan version changed against the previous one (none for v1). */
function changesPanel(ch) {
  if (!ch) return null;
  const list = (label, items) => (items.length
    ? h('li', null, `${label}: `, h('span', { class: 'mono' }, items.map((e) => e.code).join(', ')))
    : null);
  return h('details', { class: 'plan-changes', 'data-testid': 'plan-changes' },
    h('summary', null, changeWords(ch)),
    h('ul', null,
      list('added', ch.added),
      list('removed', ch.removed),
      list('changed (new schedule, new id)', ch.changed),
      ch.unmatched_runs.map((r) => h('li', { 'data-testid': 'unmatched-run' },
        `run “${r.name}” was flown for ${r.code}, which was ${r.reason}`,
        r.replaced_by ? ' (fly the new schedule again)' : ''))));
}

/** The campaign page. Returns a controller the router reuses for experiment routes. */
export async function campaignPage(view, id) {
  const campaign = await api.campaign(id);
  const [vessel, plan0] = await Promise.all([
    api.vessel(campaign.vessel_id).catch(() => null),
    api.plan(id).catch((e) => { if (e.status === 404) return null; throw e; }),
  ]);
  let plan = plan0;
  let selected = null;
  const filters = { family: '', speed: '', warn: false };

  const genBtn = h('button', { type: 'button', class: 'btn primary', 'data-testid': 'generate-plan', 'data-needs': 'supervisor', onClick: generate }, plan ? 'Regenerate plan' : 'Generate plan');
  const loading = h('span', { class: 'loading', hidden: true, role: 'status', 'aria-live': 'polite', 'data-testid': 'plan-loading' }, h('span', { class: 'spinner', 'aria-hidden': 'true' }), 'Generating plan…');
  const exportLinks = h('span', { class: 'actions' });
  const planHost = h('section', { class: 'plan', 'aria-label': 'Plan' });
  const planTitle = h('h2', { class: 'section-title', 'data-section': 'plan' }, 'Plan');
  const trash = deletedSection(id, () => reloadPage());
  const runsHost = h('section', { class: 'runs', 'aria-label': 'Runs', 'data-testid': 'runs-section' });
  const identifyHost = h('section', { class: 'identification', 'aria-label': 'Identification', 'data-testid': 'identify-section' });
  const precisionHost = h('section', { class: 'precision', 'aria-label': 'Predicted precision', 'data-testid': 'precision-section' });
  let precision = null; // the Predicted precision section's controller
  const designHost = h('section', { class: 'design', 'aria-label': 'Experiment design', 'data-testid': 'design-section' });
  let design = null; // the Experiment design section's controller
  const nextDiveHost = h('section', { class: 'next-dive', 'aria-label': 'Next dive', 'data-testid': 'next-dive-section' });
  let nextDive = null; // the Next dive section's controller
  let runs = null; // the Runs section's controller
  let ident = null; // the Identification section's controller

  const c = campaign;
  const durs = c.durations || {};
  // A deleted campaign is read-only: no new plan, upload, job or discovery
  // (the server answers 409); style.css hides those controls.
  if (c.deleted_at) view.setAttribute('data-page-deleted', '');
  fill(view, 
    h('div', { class: 'page-head' },
      h('div', null,
        h('h1', { 'data-testid': 'campaign-title' }, c.name, deletedBadge(c)),
        h('div', { class: 'muted' }, 'Campaign for ', vessel ? h('a', { href: `#/vessels/${vessel.id}` }, vessel.name) : c.vessel_id,
          vessel ? ` · ${KIND_LABEL[vessel.kind] || vessel.kind}` : '', ` · created ${fmtDate(c.created_at)}`)),
      h('div', { class: 'actions' }, renameControl({ what: 'campaign', name: c.name, needs: 'supervisor', save: (n) => api.renameCampaign(c.id, n) }), loading, exportLinks, genBtn)),
    campaignTrash.control(c),
    h('dl', { class: 'summary', 'data-testid': 'campaign-summary' },
      h('dt', null, 'Grid'), h('dd', null, gridText(c), h('span', { class: 'muted' }, ` = ${c.grid_speeds_mps.map((x) => fmt(x)).join(', ')} m/s`)),
      h('dt', null, 'Families'), h('dd', null, c.families.map((f) => FAMILY_LABEL[f] || f).join(', ')),
      h('dt', null, 'Repetitions'), h('dd', null, c.repetitions ?? `default (${vessel && vessel.kind === 'dp3' ? 2 : 1})`),
      h('dt', null, 'Excitation'), h('dd', null, excitationText(c)),
      h('dt', null, 'Durations'), h('dd', null, DURATIONS.filter((d) => durs[d.key] != null).map((d) => `${d.label.toLowerCase()} ${fmt(durs[d.key])} s`).join(' · ') || 'defaults'),
      h('dt', null, 'Seed'), h('dd', { class: 'mono' }, c.seed ?? 'default')),
    sectionNav([['runs', 'Runs'], ['coverage', 'Coverage'], ['jobs', 'Jobs'], ['models', 'Models'], ['precision', 'Precision'], ['design', 'Design'], ['next-dive', 'Next dive'], ['plan', 'Plan'], ['deleted', 'Deleted']]),
    runsHost,
    campaignOffsetPanel(c.id),
    identifyHost,
    precisionHost,
    designHost,
    nextDiveHost,
    planTitle,
    planHost,
    trash.host);

  // Every section that shows the plan follows a new version.
  async function planChanged() {
    selected = null;
    if (location.hash !== `#/campaigns/${id}`) history.replaceState(null, '', `#/campaigns/${id}`);
    renderPlan();
    if (runs) await runs.setPlan(plan);
    if (ident) ident.setPlan(plan);
    if (precision) precision.setPlan(plan);
    if (design) design.setPlan(plan);
    if (nextDive) nextDive.setPlan(plan);
  }

  async function generate() {
    genBtn.disabled = true;
    loading.hidden = false;
    clearBanner();
    const t0 = performance.now();
    try {
      plan = await api.generatePlan(id);
      const took = `${fmt((performance.now() - t0) / 1000, 1)} s`;
      if (plan.created === false) banner(`Plan v${plan.version} unchanged: the inputs give the same plan, nothing stored (${took}).`, 'ok');
      else if (plan.changes) banner(`Plan v${plan.version} generated: ${changeWords(plan.changes)} (${took}).`, 'ok');
      else banner(`Plan v${plan.version} generated: ${plan.totals.experiments} experiments in ${took}.`, 'ok');
      await planChanged();
    } catch (err) {
      banner(`${err.status ? `${err.status} · ` : ''}${err.message}${err.field ? ` [${err.field}]` : ''}`);
    } finally {
      genBtn.disabled = false;
      loading.hidden = true;
      genBtn.textContent = plan ? 'Regenerate plan' : 'Generate plan';
    }
  }

  // ---- plan ---------------------------------------------------------------
  let tbody;
  let countEl;
  let detail;

  function renderPlan() {
    destroyPlots();
    fill(exportLinks);
    if (!plan) {
      fill(planHost, h('p', { class: 'empty', 'data-testid': 'no-plan' }, 'Not planned yet. “Generate plan” builds every schedule (deterministic for the seed).'));
      return;
    }
    exportLinks.append(
      h('a', { class: 'btn', href: urls.runSheet(id), target: '_blank', rel: 'noopener', 'data-testid': 'runsheet-link' }, 'Run sheet'),
      h('a', { class: 'btn', href: urls.planJson(id), target: '_blank', rel: 'noopener', 'data-testid': 'plan-json-link' }, 'Plan JSON'));
    const t = plan.totals;
    const fams = Object.keys(t.per_family);
    const order = ['static', 'dynamic', 'recursive', 'dp_surge', 'dp_sway_yaw', 'dp_azimuth', 'validation'];
    fams.sort((a, b) => order.indexOf(a) - order.indexOf(b));

    const famSel = h('select', { id: 'filter-family', 'data-testid': 'filter-family', onChange: (e) => { filters.family = e.target.value; renderRows(); } },
      h('option', { value: '' }, 'all families'),
      fams.map((f) => h('option', { value: f, selected: filters.family === f }, `${FAMILY_LABEL[f] || f} (${t.per_family[f]})`)));
    const speeds = c.grid_speeds_mps;
    const hasSpan = plan.experiments.some((e) => e.grid_index == null);
    const spdSel = h('select', { id: 'filter-speed', 'data-testid': 'filter-speed', onChange: (e) => { filters.speed = e.target.value; renderRows(); } },
      h('option', { value: '' }, 'all speeds'),
      speeds.map((s, i) => h('option', { value: String(i), selected: filters.speed === String(i) }, `${fmtKn(s)} kn (${fmt(s)} m/s)`)),
      hasSpan ? h('option', { value: 'span', selected: filters.speed === 'span' }, 'spanning the grid') : null);
    const warnBox = h('input', { type: 'checkbox', id: 'filter-warn', checked: filters.warn, onChange: (e) => { filters.warn = e.target.checked; renderRows(); } });
    countEl = h('span', { class: 'muted', 'data-testid': 'plan-count' });
    tbody = h('tbody');
    detail = h('section', { class: 'experiment card', 'data-testid': 'experiment-panel', 'aria-label': 'Experiment', 'aria-live': 'polite' },
      h('p', { class: 'empty' }, 'Select an experiment to see its schedule.'));

    fill(planHost, 
      h('div', { class: 'totals', 'data-testid': 'plan-totals' },
        h('div', { class: 'tot' }, h('b', null, `Plan v${plan.version}`), h('span', { class: 'muted' }, fmtDate(plan.created_at))),
        h('div', { class: 'tot' }, h('b', { 'data-testid': 'total-experiments' }, String(t.experiments)), h('span', null, 'experiments')),
        fams.map((f) => h('div', { class: 'tot fam' }, h('b', null, String(t.per_family[f])), h('span', null, FAMILY_LABEL[f] || f))),
        h('div', { class: 'tot' }, h('b', null, hms(t.run_time_s)), h('span', null, 'run time')),
        h('div', { class: 'tot' }, h('b', null, hms(t.setup_time_s)), h('span', null, 'set-up')),
        h('div', { class: 'tot main' }, h('b', { 'data-testid': 'total-time' }, hms(t.total_time_s)), h('span', null, 'total trial time'))),
      changesPanel(plan.changes),
      h('div', { class: 'plan-layout' },
        h('div', { class: 'plan-list' },
          h('div', { class: 'filters', role: 'group', 'aria-label': 'Filter experiments' },
            h('label', { for: 'filter-family' }, 'Family'), famSel,
            h('label', { for: 'filter-speed' }, 'Grid speed'), spdSel,
            h('label', { class: 'check' }, warnBox, ' with warnings'),
            countEl),
          h('div', { class: 'table-scroll' },
            h('table', { class: 'grid-table plan-table', 'data-testid': 'plan-table' },
              h('thead', null, h('tr', null,
                h('th', { class: 'num' }, '#'), h('th', null, 'Code'), h('th', null, 'Family'),
                h('th', { class: 'num' }, 'kn'), h('th', { class: 'num' }, 'm/s'), h('th', null, 'Excited'),
                h('th', { class: 'num' }, 'Duration'), h('th', { title: 'persistence-of-excitation order / required, per excited channel' }, 'PE order / req.'),
                h('th', null, 'Usable band'), h('th', { title: 'warnings' }, '⚠'))),
              tbody))),
        detail));
    renderRows();
  }

  function renderRows() {
    const rows = [];
    let n = 0;
    for (const e of plan.experiments) {
      if (filters.family && e.family !== filters.family) continue;
      if (filters.speed === 'span' && e.grid_index != null) continue;
      if (filters.speed && filters.speed !== 'span' && String(e.grid_index) !== filters.speed) continue;
      if (filters.warn && !e.warnings.length) continue;
      n += 1;
      const band = bandOf(e);
      const open = () => { location.hash = `#/campaigns/${id}/experiments/${e.id}`; };
      rows.push(h('tr', {
        'data-testid': 'plan-row', 'data-eid': e.id, 'data-family': e.family, 'data-code': e.code, tabindex: '0',
        class: selected === e.id ? 'selected' : null, 'aria-selected': selected === e.id ? 'true' : 'false',
        onClick: open, onKeydown: (ev) => { if (ev.key === 'Enter' || ev.key === ' ') { ev.preventDefault(); open(); } },
      },
      h('td', { class: 'num' }, e.seq),
      h('td', { class: 'mono' }, e.code),
      h('td', null, h('span', { class: `fam-tag ${e.family}` }, FAMILY_LABEL[e.family] || e.family),
        e.separates ? [' ', h('span', { class: 'badge neutral', 'data-testid': 'deciding-tag', title: `separates ${e.separates[0]} from ${e.separates[1]}` }, 'deciding')] : null),
      h('td', { class: 'num' }, e.grid_speed_mps == null ? '–' : fmtKn(e.grid_speed_mps)),
      h('td', { class: 'num' }, e.grid_speed_mps == null ? '–' : fmt(e.grid_speed_mps)),
      h('td', { class: 'nowrap' }, dofsText(e, vessel), e.sign != null ? ` ${e.sign > 0 ? '+' : '−'}` : ''),
      h('td', { class: 'num' }, secs(e.duration_s)),
      h('td', { class: 'pe' }, peChips(e)),
      h('td', { class: 'num', title: band.title }, band.text),
      h('td', { class: 'warn' }, e.warnings.length ? h('span', { class: 'warn-icon', title: e.warnings.join('\n'), 'aria-label': `${e.warnings.length} warning(s): ${e.warnings.join('; ')}` }, `⚠${e.warnings.length > 1 ? e.warnings.length : ''}`) : '')));
    }
    fill(tbody, ...rows);
    countEl.textContent = `${n} of ${plan.experiments.length} shown`;
  }

  // ---- one experiment -------------------------------------------------------
  async function select(eidSel) {
    if (!plan) return;
    selected = eidSel || null;
    tbody.querySelectorAll('tr.selected').forEach((r) => { r.classList.remove('selected'); r.setAttribute('aria-selected', 'false'); });
    destroyPlots();
    if (!selected) {
      fill(detail, h('p', { class: 'empty' }, 'Select an experiment to see its schedule.'));
      return;
    }
    const row = tbody.querySelector(`tr[data-eid="${CSS.escape(selected)}"]`);
    if (row) { row.classList.add('selected'); row.setAttribute('aria-selected', 'true'); row.scrollIntoView({ block: 'nearest' }); }
    fill(detail, h('p', { class: 'loading' }, h('span', { class: 'spinner', 'aria-hidden': 'true' }), 'Loading schedule…'));
    let s;
    try {
      s = await api.experiment(id, selected);
    } catch (err) {
      if (selected === eidSel) fill(detail, h('p', { class: 'error-text' }, `${err.status || ''} ${err.message}`));
      return;
    }
    if (selected !== eidSel) return; // another row was chosen meanwhile
    renderExperiment(s);
  }

  function renderExperiment(s) {
    const e = s.experiment;
    const thr = vessel && vessel.inputs && vessel.inputs.kind === 'thrusters' ? vessel.inputs.thrusters : [];
    const excited = new Set(e.channels.filter((ch) => ch.excited).map((ch) => ch.column));
    const units = Object.fromEntries(s.columns.map((col) => [col.name, col.unit]));
    const bands = Object.fromEntries(e.channels.filter(isExcitedWithAnalysis).map((ch) => [ch.column, ch.analysis.band_hz]));
    const schedHost = h('div', { class: 'plot', 'data-testid': 'schedule-plot' });
    const psdHost = h('div', { class: 'plot', 'data-testid': 'psd-plot' });
    const csvName = `${String(e.seq).padStart(3, '0')}_${e.code}.csv`;

    const chanRows = e.channels.map((ch) => {
      const a = ch.analysis;
      const who = ch.thruster != null ? (thr[ch.thruster] ? thr[ch.thruster].name : `thruster ${ch.thruster + 1}`) : (ch.dof || '');
      const u = unitLabel(ch.unit);
      const stats = a ? [
        `peak deviation ${fmt(a.peak_deviation)} ${u}`,
        `max slew ${fmt(a.max_slew)} ${u}/s`,
        `power above logger Nyquist ${fmt(a.power_above_logger_nyquist * 100)} %`,
      ].join('\n') : '';
      return h('tr', { class: ch.excited ? 'excited' : 'held' },
        h('td', { class: 'nowrap' },
          ch.excited ? h('span', { class: 'dot on', title: 'excited' }, '● ') : h('span', { class: 'dot', title: 'held at the operating point' }, '○ '),
          h('span', { class: 'mono' }, ch.column), ' ', h('span', { class: 'muted', title: who }, who.length > 14 ? `${who.slice(0, 13)}…` : who)),
        h('td', { class: 'nowrap' }, u),
        h('td', { class: 'wave' }, describeWaveform(ch.waveform, ch.unit)),
        h('td', { class: 'num' }, (ch.waveform && ch.waveform.shape === 'staircase') || (!ch.excited && !ch.amplitude) ? '–' : `±${fmt(ch.amplitude)}`),
        h('td', { class: 'num' }, fmt(ch.offset)),
        h('td', { class: 'num' }, `±${fmt(ch.limit)}`),
        h('td', { class: 'num' }, ch.rate_limit == null ? '–' : `${fmt(ch.rate_limit)}/s`),
        h('td', { class: 'pe', title: stats }, a ? h('span', { class: `chip ${a.pe_order >= a.pe_required ? 'ok' : 'bad'}`, title: peTitle(ch) }, peText(a)) : ''),
        h('td', { class: 'num', title: stats }, a ? bandText(a.band_hz) : ''));
    });

    fill(detail, 
      h('div', { class: 'exp-head' },
        h('h2', { 'data-testid': 'experiment-code' }, h('span', { class: 'mono' }, e.code)),
        h('span', { class: `fam-tag ${e.family}` }, FAMILY_LABEL[e.family] || e.family),
        h('div', { class: 'actions' },
          h('a', { class: 'btn', href: urls.scheduleCsv(id, e.id), download: csvName, 'data-testid': 'download-csv' }, '↓ Download CSV'),
          h('a', { class: 'btn', href: urls.experimentJson(id, e.id), target: '_blank', rel: 'noopener', 'data-testid': 'download-json' }, 'JSON'),
          h('a', { class: 'btn', href: `#/campaigns/${id}`, 'aria-label': 'Close experiment' }, '×'))),
      h('div', { class: 'meta' },
        h('span', null, `#${e.seq}`),
        h('span', null, e.grid_speed_mps == null ? 'spans the grid' : `${fmtKn(e.grid_speed_mps)} kn = ${fmt(e.grid_speed_mps)} m/s`),
        h('span', null, `excites ${e.dofs.join(', ')}`),
        h('span', null, `repetition ${e.repetition}`),
        h('span', null, `${secs(e.duration_s)} (${hms(e.duration_s)})`),
        h('span', null, `${fmt(s.sample_rate_hz)} Hz · ${s.t.length} samples`)),
      h('p', { class: 'instruction', 'data-testid': 'instruction' }, e.instruction),
      e.warnings.length ? h('ul', { class: 'warnings', 'data-testid': 'warnings' }, e.warnings.map((w) => h('li', null, '⚠ ', w))) : null,
      h('div', { class: 'table-x' },
        h('table', { class: 'grid-table compact', 'data-testid': 'channel-table' },
          h('thead', null, h('tr', null,
            h('th', null, 'Column · DOF / thruster'), h('th', null, 'Unit'), h('th', null, 'Waveform'),
            h('th', { class: 'num' }, 'Amplitude'), h('th', { class: 'num' }, 'Offset'), h('th', { class: 'num' }, 'Limit'),
            h('th', { class: 'num' }, 'Rate limit'), h('th', { title: 'persistence-of-excitation order / required (hover for peak, slew, power above Nyquist)' }, 'PE / req.'),
            h('th', { class: 'num' }, 'Usable band'))),
          h('tbody', null, chanRows))),
      h('h3', null, 'Schedule ', h('span', { class: 'hint' }, 'drag to zoom a time range · double-click to reset · click a legend entry to hide/show')),
      schedHost,
      s.spectra.length ? h('h3', null, 'Power spectral density ', h('span', { class: 'hint' }, 'excited columns, Hann periodogram; shaded: usable band (within 10 dB of the peak)')) : null,
      s.spectra.length ? psdHost : null);

    const limits = Object.fromEntries(e.channels.map((ch) => [ch.column, ch.limit]));
    schedulePlot(schedHost, s, { excited, limits });
    if (s.spectra.length) {
      psdPlot(psdHost, s.spectra, { bands, units, nyquistHz: vessel ? vessel.logger_rate_hz / 2 : null });
    }
  }

  renderPlan();
  runs = await runsSection(runsHost, { campaign, plan, onRuns: (r) => { if (ident) ident.setRuns(r); } });
  try {
    ident = await identifySection(identifyHost, { campaign, vessel, plan, runs: runs.runs() });
  } catch (err) {
    // The rest of the page stays usable; the answer is shown where the section would be.
    fill(identifyHost, h('h2', { class: 'section-title' }, 'Identification'),
      h('p', { class: 'error-text', role: 'alert', 'data-testid': 'identify-load-error' }, `Could not load jobs and models: ${err.status ? `${err.status} · ` : ''}${err.message}`));
  }
  try {
    design = await designSection(designHost, {
      campaign,
      plan,
      // The campaign's settings changed too: the whole page is redrawn.
      onAdopt: () => reloadPage(),
    });
  } catch (err) {
    fill(designHost, h('h2', { class: 'section-title' }, 'Experiment design'),
      h('p', { class: 'error-text', role: 'alert' }, `Could not load the design: ${err.status ? `${err.status} · ` : ''}${err.message}`));
  }
  try {
    nextDive = await nextDiveSection(nextDiveHost, { campaign, plan });
  } catch (err) {
    fill(nextDiveHost, h('h2', { class: 'section-title' }, 'Next dive'),
      h('p', { class: 'error-text', role: 'alert' }, `Could not load the proposal: ${err.status ? `${err.status} · ` : ''}${err.message}`));
  }
  try {
    precision = await precisionSection(precisionHost, { campaign, plan });
  } catch (err) {
    fill(precisionHost, h('h2', { class: 'section-title' }, 'Predicted precision'),
      h('p', { class: 'error-text', role: 'alert' }, `Could not load the prediction: ${err.status ? `${err.status} · ` : ''}${err.message}`));
  }

  return {
    key: `campaign:${id}`,
    select,
    destroy() {
      destroyPlots();
      runs.destroy();
      if (ident) ident.destroy();
      if (precision) precision.destroy();
      if (design) design.destroy();
      if (nextDive) nextDive.destroy();
    },
  };
}
