// Run page (#/runs/{id}): what was uploaded (files, SHA-256, raw bytes), what
// the run is (role, grid speed, excited DOFs, signal: the supervisor's, the
// plan's or inferred, editable), how it was read (rate, duration, gaps,
// warnings, clock alignment of two-file runs), the verdict per DOF with its
// reason, the time plot of every recorded channel (runtraces.js), and the
// quality report's plots (each exportable as PNG, SVG, CSV):
// PSDs, coherence, H1 magnitude and phase, regressor singular values, plan
// adherence.

import { api, urls } from './api.js';
import { bandText, bytes, fmt, fmtDate, secs } from './format.js';
import { h, fill } from './forms.js';
import { PALETTE, psdUnit } from './plots.js';
import { spectrumPlot, singularValuePlot, syncX, exact } from './runplots.js';
import { verdictBadge, statusBadge, coverageBadge, errorWhere, errorText, rawLinks, unitWarnings } from './runs.js';
import { runOffsetPanel } from './offsetpanel.js';
import { descriptionSection } from './rundescribe.js';
import { deletedBadge, excludedBadge, runManageSection } from './manage.js';
import { renameControl } from './rename.js';
import { runTracesSection } from './runtraces.js';
import { exportBar, uplotExportable } from './plotexport.js';

/** Export buttons of the live chart `name`, titled for the run. */
const exportOf = (name, title) => exportBar(() => (window.__plots[name] ? uplotExportable(window.__plots[name], title()) : null), `${name}-export`);

const GOOD_COHERENCE = 0.8; // server: quality::verdict::GOOD_COHERENCE (the reasons quote it)

/** Unit of a log column (the log contract), for axis labels. */
function colUnit(name) {
  if (/^tau_[XYZ](_T)?$/.test(name)) return 'N';
  if (/^tau_[KMN](_T)?$/.test(name)) return 'N·m';
  if (['u', 'v', 'w'].includes(name)) return 'm/s';
  if (['p', 'q', 'r'].includes(name)) return 'rad/s';
  if (/^thr_\d+$/.test(name)) return '1';
  return '';
}

function evidenceLine(v) {
  const e = v.evidence || {};
  const bits = [];
  if (e.pe_order != null) bits.push(`PE order ${e.pe_order >= 24 ? '≥ ' : ''}${e.pe_order}`);
  if (e.median_coherence != null) bits.push(`median coherence ${fmt(e.median_coherence)}`);
  if (e.good_coherence_span_hz) bits.push(`coherence ≥ ${GOOD_COHERENCE} over ${bandText(e.good_coherence_span_hz)}`);
  if (e.usable_band_hz) bits.push(`usable band ${bandText(e.usable_band_hz)}`);
  if (e.identifiable != null && e.n_columns != null) bits.push(`${e.identifiable}/${e.n_columns} regressor parameters identifiable`);
  if (e.plan_followed != null) bits.push(e.plan_followed ? 'plan followed' : 'plan NOT followed');
  if (e.nyquist_warning) bits.push('power near Nyquist');
  const deficient = e.in_deficient_direction ?? e.input_deficient;
  if (deficient) bits.push('in a deficient regressor direction');
  return bits.join(' · ');
}

/** Verdict cards; DOFs the run does not excite (by its description) are dimmed: nothing was asked of them. */
function verdictCards(verdicts, excited) {
  return h('div', { class: 'verdict-cards', 'data-testid': 'run-verdicts' }, verdicts.map((v) => {
    const aside = excited && !excited.includes(v.dof);
    return h('div', {
      class: `verdict-card ${v.verdict}${aside ? ' not-excited' : ''}`, 'data-testid': 'verdict', 'data-dof': v.dof, 'data-verdict': v.verdict,
    },
    h('div', { class: 'vc-head' }, verdictBadge(v, { text: `${v.dof}: ${v.verdict}` }), h('span', { class: 'mono muted' }, `${v.input} → ${v.output}`)),
    aside ? h('p', { class: 'hint', 'data-testid': 'verdict-aside' }, `${v.dof} is not among the DOFs this run excites: its verdict is no fault of the run`) : null,
    h('p', { class: 'reason', 'data-testid': 'verdict-reason' }, v.reason),
    h('p', { class: 'evidence hint' }, evidenceLine(v)));
  }));
}

function gapsText(gaps) {
  if (!gaps || !gaps.length) return 'none';
  const bridged = gaps.filter((g) => g.bridged).length;
  const missing = gaps.reduce((a, g) => a + (g.missing_samples || 0), 0);
  return `${gaps.length} (${missing} samples missing; ${bridged} bridged by interpolation, ${gaps.length - bridged} split the log)`;
}

function perFile(obj, fn) {
  if (!obj) return '–';
  const keys = Object.keys(obj);
  if (keys.length === 1 && keys[0] === 'file') return fn(obj.file);
  return keys.map((k) => `${k}: ${fn(obj[k])}`).join(' · ');
}

function gapList(gaps) {
  if (!gaps) return null;
  const all = Object.entries(gaps).flatMap(([f, gs]) => (gs || []).map((g) => ({ f, ...g })));
  if (!all.length) return null;
  return h('details', { class: 'sub' }, h('summary', null, `${all.length} gap${all.length === 1 ? '' : 's'}`),
    h('table', { class: 'grid-table compact' },
      h('thead', null, h('tr', null, h('th', null, 'File'), h('th', { class: 'num' }, 'From [s]'), h('th', { class: 'num' }, 'To [s]'), h('th', { class: 'num' }, 'Missing samples'), h('th', null, 'Bridged'))),
      h('tbody', null, all.slice(0, 200).map((g) => h('tr', null, h('td', null, g.f), h('td', { class: 'num' }, exact(g.start_t)), h('td', { class: 'num' }, exact(g.end_t)),
        h('td', { class: 'num' }, g.missing_samples), h('td', null, g.bridged ? 'yes (interpolated)' : 'no (split)'))))));
}

function alignmentBox(al) {
  const o = al.offset || {};
  const conf = o.confidence || 'low';
  const cls = conf === 'high' ? 'good' : conf === 'medium' ? 'weak' : 'insufficient';
  return h('div', { class: 'card alignment', 'data-testid': 'alignment' },
    h('p', { class: 'hint' }, `Clock offset of the two computers: navigation time + offset = control time, found on the shared channel “${al.shared_channel}”.`),
    h('div', { class: 'offset-line' },
      h('span', { class: 'offset', 'data-testid': 'alignment-offset', 'data-offset-s': String(o.offset_s), 'data-std-error-s': String(o.std_error_s) },
        `offset ${fmt(o.offset_s)} s`, h('span', { class: 'pm' }, ` ± ${exact(o.std_error_s)} s`)),
      h('span', { class: `badge ${cls}`, 'data-testid': 'alignment-confidence', 'data-confidence': conf, title: 'how much to trust the offset' }, `${conf} confidence`)),
    h('dl', { class: 'summary inline' },
      h('dt', null, 'Correlation'), h('dd', null, exact(o.correlation)),
      h('dt', null, 'Peak ratio'), h('dd', { title: 'evidence of the peak over the best other offset; near 1 another offset fits as well' }, exact(o.peak_ratio)),
      h('dt', null, 'Residual'), h('dd', null, `${exact(o.residual_rms)} RMS (${fmt((o.residual_relative || 0) * 100, 3)} % of the channel’s spread)`),
      h('dt', null, 'Overlap'), h('dd', null, `${secs(o.overlap_s)} (control clock ${fmt(al.overlap_start_s)}–${fmt(al.overlap_end_s)} s)`),
      h('dt', null, 'Rates'), h('dd', null, `control ${exact(al.control_rate_hz)} Hz · nav ${exact(al.nav_rate_hz)} Hz → merged ${exact(al.rate_hz)} Hz`)),
    al.warnings && al.warnings.length ? h('ul', { class: 'warnings' }, al.warnings.map((w) => h('li', null, '⚠ ', w))) : null);
}

function filesTable(run) {
  return h('table', { class: 'grid-table compact files-table', 'data-testid': 'files-table' },
    h('thead', null, h('tr', null, h('th', null, 'Role'), h('th', null, 'File'), h('th', { class: 'num' }, 'Size'), h('th', null, 'SHA-256'), h('th', null, ''))),
    h('tbody', null, run.files.map((f) => h('tr', { 'data-role': f.role },
      h('td', null, f.role),
      h('td', { class: 'mono' }, f.filename),
      h('td', { class: 'num', title: `${f.size_bytes} bytes` }, bytes(f.size_bytes)),
      h('td', { class: 'mono sha', 'data-testid': 'sha256' }, f.sha256),
      h('td', null, h('a', { class: 'btn small', href: urls.raw(run.id, run.layout === 'split' ? f.role : null), download: f.filename, 'data-testid': 'raw-link', 'data-role': f.role }, '↓ raw'))))));
}

function warningsList(ws) {
  if (!ws || !ws.length) return null;
  return h('ul', { class: 'warnings', 'data-testid': 'run-warnings' }, ws.map((w) => h('li', null, '⚠ ',
    h('span', { class: 'muted' }, `[${w.file}${w.column ? ` · ${w.column}` : ''}] `), w.message)));
}

function adherenceTable(rows) {
  if (!rows || !rows.length) {
    return h('p', { class: 'empty', 'data-testid': 'adherence-empty' }, 'No planned schedule to compare with: the run is not assigned to an experiment of the plan.');
  }
  return h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact', 'data-testid': 'adherence-table' },
    h('thead', null, h('tr', null, h('th', null, 'Log column'), h('th', null, 'Planned'), h('th', null, 'Followed'),
      h('th', { class: 'num', title: 'time of the schedule’s start in the log' }, 'Start [s]'), h('th', { class: 'num' }, 'Correlation'),
      h('th', { class: 'num', title: 'std of log / std of schedule' }, 'Amplitude ratio'), h('th', { class: 'num' }, 'NRMSE'),
      h('th', { class: 'num', title: 'share of the schedule on valid log samples' }, 'Coverage'), h('th', null, 'Finding'))),
    h('tbody', null, rows.map((a) => h('tr', { 'data-testid': 'adherence-row', 'data-followed': String(a.followed) },
      h('td', { class: 'mono' }, a.log_column),
      h('td', { class: 'mono' }, a.schedule_column),
      h('td', null, h('span', { class: `badge ${a.followed ? 'good' : 'weak'}` }, a.followed ? '✓ yes' : '! no')),
      h('td', { class: 'num' }, exact(a.lag_s)),
      h('td', { class: 'num' }, exact(a.correlation)),
      h('td', { class: 'num' }, exact(a.amplitude_ratio)),
      h('td', { class: 'num' }, exact(a.nrmse)),
      h('td', { class: 'num' }, `${fmt(a.coverage * 100, 1)} %`),
      h('td', { class: 'finding' }, a.message))))));
}

/** The run page. Returns a controller; `mount()` draws the plots once the page is in the document. */
export async function runPage(view, rid) {
  const run = await api.run(rid);
  // The report can be several MB: ask for it now, draw it after the page shows.
  const qualityP = run.status === 'accepted' ? api.quality(rid).then((q) => ({ q }), (err) => ({ err })) : null;
  const [campaign, coverage] = await Promise.all([
    api.campaign(run.campaign_id).catch(() => null),
    run.experiment_id ? api.coverage(run.campaign_id).catch(() => null) : null,
  ]);
  const exp = coverage && run.experiment_id ? coverage.experiments.find((e) => e.experiment_id === run.experiment_id) : null;
  const vessel = campaign ? await api.vessel(campaign.vessel_id).catch(() => null) : null;
  const s = run.summary || {};
  const qualityHost = h('section', { class: 'quality', 'data-testid': 'quality', 'aria-label': 'Quality report' });
  const traces = run.status === 'accepted' ? runTracesSection(run) : null;
  let destroyed = false;

  fill(view,
    h('div', { class: 'page-head' },
      h('div', null,
        h('h1', { 'data-testid': 'run-title' }, run.name, statusBadge(run.status, run), excludedBadge(run), deletedBadge(run)),
        h('div', { class: 'muted' },
          'Run of ', campaign ? h('a', { href: `#/campaigns/${campaign.id}`, 'data-testid': 'run-campaign-link' }, campaign.name) : run.campaign_id,
          run.experiment_id ? [' · experiment ',
            exp ? h('a', { class: 'mono', href: `#/campaigns/${run.campaign_id}/experiments/${run.experiment_id}`, 'data-testid': 'run-experiment' }, exp.code) : h('span', { title: run.experiment_id }, 'of an older plan'),
            exp ? [' ', coverageBadge(exp.status)] : null] : ' · not assigned to an experiment',
          ` · ${run.layout === 'split' ? 'control + nav logs' : 'one log'} · uploaded ${fmtDate(run.created_at)}`)),
      h('div', { class: 'actions' }, renameControl({ what: 'run', name: run.name, needs: 'supervisor', save: (n) => api.renameRun(run.id, n) }), rawLinks(run),
        run.status === 'accepted' ? h('a', { class: 'btn small', href: urls.quality(run.id), target: '_blank', rel: 'noopener', 'data-testid': 'quality-json-link' }, 'Quality JSON') : null)),

    run.status === 'rejected' ? h('div', { class: 'upload-error big', role: 'alert', 'data-testid': 'run-error' },
      h('div', { class: 'err-title' }, '✗ Rejected: the log is stored but invalid'),
      h('div', { class: 'err-where', 'data-testid': 'error-where' }, errorWhere(run.error, run.files)),
      h('p', { class: 'err-message', 'data-testid': 'error-message' }, run.error && errorText(run.error.message)),
      h('p', { class: 'hint' }, 'Fix the file and upload it again; the bytes above are kept as received.')) : null,
    run.status === 'stored' ? h('p', { class: 'empty' }, 'Stored, not processed yet.') : null,
    run.status === 'accepted' ? unitWarnings(run) : null,

    descriptionSection(run, { vessel }),
    runManageSection(run),

    s.verdicts && s.verdicts.length ? [h('h2', null, 'Verdict per DOF ', h('span', { class: 'hint' }, 'green good · amber weak · red insufficient — the reason says what to do')), verdictCards(s.verdicts, run.description && run.description.excited_dofs ? run.description.excited_dofs.value : null)] : null,

    h('div', { class: 'run-cols' },
      h('div', null,
        h('h2', null, 'Summary'),
        h('dl', { class: 'summary', 'data-testid': 'run-summary' },
          s.sample_rate_hz != null ? [h('dt', null, 'Sample rate'), h('dd', { 'data-testid': 'run-rate' }, `${exact(s.sample_rate_hz)} Hz`)] : null,
          s.duration_s != null ? [h('dt', null, 'Duration'), h('dd', { 'data-testid': 'run-duration' }, `${secs(s.duration_s)}`, s.valid_duration_s != null && Math.abs(s.valid_duration_s - s.duration_s) > 1e-6 ? ` (${secs(s.valid_duration_s)} valid)` : ' (all valid)')] : null,
          s.rows ? [h('dt', null, 'Rows'), h('dd', null, perFile(s.rows, (n) => String(n)))] : null,
          s.gaps ? [h('dt', null, 'Gaps'), h('dd', { 'data-testid': 'run-gaps' }, perFile(s.gaps, gapsText), gapList(s.gaps))] : null,
          s.ignored_columns ? [h('dt', null, 'Ignored columns'), h('dd', null, perFile(s.ignored_columns, (c) => (c && c.length ? c.join(', ') : 'none')))] : null,
          h('dt', null, 'Files'), h('dd', null, filesTable(run))),
        // Alignment warnings are shown with the alignment.
        warningsList((s.warnings || []).filter((x) => !(s.alignment && x.file === 'alignment')))),
      run.layout === 'split' ? h('div', null, h('h2', null, 'Alignment'), runOffsetPanel(run), s.alignment ? alignmentBox(s.alignment) : null) : null),

    traces ? traces.el : null,
    run.status === 'accepted' ? qualityHost : null);

  async function mount() {
    if (traces) traces.draw();
    if (!qualityP) return;
    fill(qualityHost, h('p', { class: 'loading', 'data-testid': 'quality-loading' }, h('span', { class: 'spinner', 'aria-hidden': 'true' }), 'Loading the quality report…'));
    const { q, err } = await qualityP;
    if (destroyed) return;
    if (err) {
      fill(qualityHost, h('p', { class: 'error-text' }, `Quality report: ${err.status ? `${err.status} · ` : ''}${err.message}`));
      return;
    }
    renderQuality(q);
  }

  function renderQuality(q) {
    const f = q.freqs_hz;
    const w = q.welch;
    const psdHost = h('div', { class: 'plot', 'data-testid': 'run-psd-plot' });
    const cohHost = h('div', { class: 'plot', 'data-testid': 'run-coherence-plot' });
    const magHost = h('div', { class: 'plot', 'data-testid': 'run-h1mag-plot' });
    const phHost = h('div', { class: 'plot', 'data-testid': 'run-h1phase-plot' });
    const svHost = h('div', { class: 'plot', 'data-testid': 'run-sv-plot' });
    const decim = h('span', { class: 'hint', 'data-testid': 'decimation-note' });
    const pairKey = (p) => `${p.input}→${p.output}`;
    const dofPairs = q.dofs.map((d) => q.pairs.find((p) => p.input === d.input && p.output === d.output)).filter(Boolean);
    const inputByName = new Map(q.inputs.map((x, i) => [x.name, { ...x, i }]));
    const dofOf = new Map(q.dofs.map((d) => [pairKey(d), d]));
    let psdSel = 'inputs';
    let cohSel = 'dofs';
    let h1Sel = dofPairs.length ? pairKey(dofPairs[0]) : q.pairs.length ? pairKey(q.pairs[0]) : '';

    const pairOptions = (extra) => [extra, ...q.pairs.map((p) => {
      const d = dofOf.get(pairKey(p));
      return h('option', { value: pairKey(p) }, `${p.input} → ${p.output}${d ? ` (${d.dof})` : ''}`);
    })];
    const psdSelect = h('select', { 'data-testid': 'psd-select', 'aria-label': 'Spectra of', onChange: (e) => { psdSel = e.target.value; drawPsd(); } },
      h('option', { value: 'inputs' }, `inputs (${q.inputs.length})`), h('option', { value: 'outputs' }, `outputs (${q.outputs.length})`));
    const cohSelect = h('select', { 'data-testid': 'coherence-select', 'aria-label': 'Coherence of', onChange: (e) => { cohSel = e.target.value; drawCoherence(); if (cohSel !== 'dofs') { h1Sel = cohSel; h1Select.value = h1Sel; drawH1(); } } },
      pairOptions(h('option', { value: 'dofs' }, `each DOF’s input → output (${dofPairs.length})`)));
    const h1Select = h('select', { 'data-testid': 'h1-select', 'aria-label': 'H1 of', onChange: (e) => { h1Sel = e.target.value; drawH1(); } }, pairOptions(null));
    h1Select.value = h1Sel;

    function note() {
      const parts = [psdHost, cohHost, magHost].filter((x) => x.dataset.shown && Number(x.dataset.shown) < Number(x.dataset.bins));
      decim.textContent = parts.length ? `long spectra: ${parts[0].dataset.shown} of ${parts[0].dataset.bins} bins drawn (log-spaced, extrema kept); zoom in to draw every bin — legends show exact bin values` : '';
    }

    function drawPsd() {
      const list = psdSel === 'inputs' ? q.inputs : q.outputs;
      const bands = psdSel === 'inputs' && list.length <= 2 ? list.map((x, i) => (x.usable_band_hz ? { range: x.usable_band_hz, color: PALETTE[i % PALETTE.length] } : null)).filter(Boolean) : [];
      spectrumPlot('runPsd', psdHost, {
        freqs: f,
        y: { log: true, label: 'PSD' },
        bands,
        series: list.map((x) => ({
          label: `${x.name} [${psdUnit(colUnit(x.name))}]`,
          values: x.psd,
        })),
      });
      note();
    }

    function drawCoherence() {
      const pairs = cohSel === 'dofs' ? dofPairs : q.pairs.filter((p) => pairKey(p) === cohSel);
      const one = pairs.length === 1 ? inputByName.get(pairs[0].input) : null;
      spectrumPlot('runCoherence', cohHost, {
        freqs: f,
        y: { range: [0, 1.02], label: 'coherence γ²' },
        lines: [{ y: GOOD_COHERENCE, label: `good ≥ ${GOOD_COHERENCE}`, color: '#1f7a45' }],
        bands: one && one.usable_band_hz ? [{ range: one.usable_band_hz }] : [],
        series: pairs.map((p) => {
          const d = dofOf.get(pairKey(p));
          return { label: `${d ? `${d.dof}: ` : ''}${p.input} → ${p.output}`, values: p.coherence };
        }),
      });
      note();
    }

    function drawH1() {
      const p = q.pairs.find((x) => pairKey(x) === h1Sel);
      if (!p) { magHost.replaceChildren(); phHost.replaceChildren(); return; }
      const unit = `${colUnit(p.output) || '1'} per ${colUnit(p.input) || '1'}`;
      const mag = spectrumPlot('runH1mag', magHost, {
        freqs: f,
        height: 200,
        y: { label: '|H1| [dB]' },
        series: [{
          label: `|H1| ${p.input} → ${p.output} [dB re 1 ${unit}]`,
          values: p.h1_magnitude_db,
          format: (v) => (v == null ? '−∞ dB' : `${exact(v)} dB`),
          color: '#1f6fb5',
        }],
      });
      const deg = p.h1_phase_unwrapped_rad.map((r) => (r == null ? null : (r * 180) / Math.PI));
      const ph = spectrumPlot('runH1phase', phHost, {
        freqs: f,
        height: 200,
        y: { label: 'phase [°]' },
        series: [{
          label: `∠H1 ${p.input} → ${p.output} [°] (unwrapped)`,
          values: deg,
          format: (v) => (v == null ? '–' : `${exact(v)}° (${exact((v * Math.PI) / 180)} rad)`),
          color: '#d1495b',
        }],
      });
      syncX(mag, ph);
      note();
    }

    const reg = q.regressor;
    const dirs = reg.deficient_directions || [];
    fill(qualityHost,
      h('h2', null, 'Quality report ', h('span', { class: 'hint', 'data-testid': 'welch' },
        `Welch: ${w.nperseg}-sample segments (${secs(w.segment_s)}), ${w.n_segments} averaged, resolution ${exact(w.df_hz)} Hz · ${q.n_valid_samples} of ${q.n_samples} samples valid`)),
      h('p', { class: 'hint' }, 'Drag to zoom a frequency range · double-click to reset · click a legend entry to hide/show. ', decim),
      h('div', { class: 'plot-grid' },
        h('div', { class: 'plot-card' },
          h('h3', null, 'Power spectral density ', psdSelect, exportOf('runPsd', () => `${run.name} PSD of ${psdSel}`)),
          h('p', { class: 'hint' }, q.inputs.map((x) => `${x.name}: PE ${x.pe_order >= x.pe_cap ? '≥ ' : ''}${x.pe_order}, band ${bandText(x.usable_band_hz)}${x.nyquist && x.nyquist.warning ? ' ⚠ Nyquist' : ''}`).join(' · ')),
          psdHost),
        h('div', { class: 'plot-card' },
          h('h3', null, 'Coherence ', cohSelect, exportOf('runCoherence', () => `${run.name} coherence`)),
          h('p', { class: 'hint' }, `γ² of input and output: near 1 where the output is explained linearly by the input. Line: ${GOOD_COHERENCE}.`),
          cohHost),
        h('div', { class: 'plot-card' },
          h('h3', null, 'Frequency response H1 ', h1Select, exportOf('runH1mag', () => `${run.name} H1 magnitude ${h1Sel}`), exportOf('runH1phase', () => `${run.name} H1 phase ${h1Sel}`)),
          h('p', { class: 'hint' }, 'H1 = Pxy / Pxx; magnitude and unwrapped phase, zoom either — the other follows.'),
          magHost, phHost),
        h('div', { class: 'plot-card' },
          h('h3', null, 'Regressor singular values', exportOf('runSv', () => `${run.name} regressor singular values`)),
          h('p', { class: 'hint', 'data-testid': 'sv-summary' },
            `${reg.identifiable} of ${reg.n_columns} parameters identifiable (σᵢ/σ₁ above ${exact(reg.threshold)}) · ARX, ${reg.lags} lag${reg.lags === 1 ? '' : 's'}, ${reg.n_rows} rows`),
          svHost,
          dirs.length ? h('table', { class: 'grid-table compact', 'data-testid': 'deficient-directions' },
            h('caption', null, 'Deficient directions: columns the data cannot tell apart'),
            h('thead', null, h('tr', null, h('th', { class: 'num' }, 'σᵢ/σ₁'), h('th', null, 'Columns (weight)'))),
            h('tbody', null, dirs.map((d) => h('tr', null, h('td', { class: 'num' }, exact(d.singular_value)),
              h('td', { class: 'mono' }, d.columns.map((c) => `${c.column} (${fmt(c.weight)})`).join(', ')))))) : null)),
      h('h2', null, 'Plan adherence ', exp ? h('span', { class: 'hint' }, `against ${exp.code}`) : null),
      adherenceTable(q.adherence));

    drawPsd();
    drawCoherence();
    drawH1();
    singularValuePlot('runSv', svHost, reg);
  }

  return {
    key: `run:${rid}`,
    mount,
    destroy() { destroyed = true; if (traces) traces.destroy(); },
  };
}
