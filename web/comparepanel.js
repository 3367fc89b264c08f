// Overlay compare (model page): several models of the campaign validated
// on one chosen run (GET /api/models/compare), their predictions drawn over
// the measurement for one output, with each model's fits and divergences
// in words, and each model's input–residual cross-correlation. The
// validation runs on the whole run or a window of it: typed in, taken from
// the run page's selection, or from a range zoomed on the plot here.
// Live chart: window.__plots.compare.

import { api, urls } from './api.js';
import { h, fill } from './forms.js';
import { fmt } from './format.js';
import { PALETTE } from './plots.js';
import { timeResponsePlot } from './responseplots.js';
import { exportBar, uplotExportable } from './plotexport.js';
import { selectedWindow } from './runtraces.js';
import { fitText } from './modelpage.js';
import { compareXcorrSection } from './comparexcorr.js';

const SERIES = { simulated: 'free-run simulation', k_step: 'k-step prediction', one_step: '1-step prediction', restarted: 'restarted free runs' };
const FIT = { simulated: 'fit_simulation', k_step: 'fit_k_step', one_step: 'fit_one_step', restarted: 'fit_restarted' };
const DIV = { simulated: 'simulation', k_step: 'k_step', one_step: 'one_step', restarted: 'restarted' };

export function compareSection(model, { runs = [], defaultRun = '' } = {}) {
  const state = { result: null, title: '' };
  const runSelect = h('select', { 'data-testid': 'compare-run', 'aria-label': 'Run to compare on' }, runs.map((r) => h('option', { value: r.id }, r.name)));
  if (defaultRun) runSelect.value = defaultRun;
  const seriesSelect = h('select', { 'data-testid': 'compare-series', 'aria-label': 'Prediction', onChange: () => drawPlot() },
    Object.entries(SERIES).map(([k, v]) => h('option', { value: k }, v)));
  const outSelect = h('select', { 'data-testid': 'compare-output', 'aria-label': 'Output', onChange: () => drawPlot() });
  const modelsHost = h('div', { class: 'compare-models', 'data-testid': 'compare-models' });
  const plotHost = h('div', { class: 'plot', 'data-testid': 'compare-plot' });
  const note = h('div', { 'data-testid': 'compare-note' });
  const windowHost = h('div', { class: 'actions' });
  const fromInput = h('input', { type: 'number', step: 'any', min: 0, placeholder: 'start', 'data-testid': 'compare-from', 'aria-label': 'Window start [s]', class: 'num-input' });
  const toInput = h('input', { type: 'number', step: 'any', min: 0, placeholder: 'end', 'data-testid': 'compare-to', 'aria-label': 'Window end [s]', class: 'num-input' });
  const go = h('button', { type: 'button', class: 'btn', 'data-testid': 'compare-go', onClick: () => run() }, 'Compare');
  const xcorr = compareXcorrSection();
  const setWindow = (w) => {
    fromInput.value = w ? String(Number(w.from_s.toFixed(3))) : '';
    toInput.value = w ? String(Number(w.to_s.toFixed(3))) : '';
    run();
  };
  const num = (el) => (el.value.trim() === '' ? null : Number(el.value));

  async function loadModels() {
    const all = await api.models(model.campaign_id).catch(() => [model]);
    const list = (Array.isArray(all) ? all : [model]).filter((m) => m.vessel_id === model.vessel_id || m.id === model.id);
    if (!list.some((m) => m.id === model.id)) list.unshift(model);
    const others = list.filter((m) => m.id !== model.id).slice(0, 2).map((m) => m.id);
    fill(modelsHost, list.slice(0, 12).map((m) => h('label', { class: 'check' },
      h('input', { type: 'checkbox', value: m.id, 'data-testid': 'compare-model', checked: m.id === model.id || others.includes(m.id) }),
      ` ${m.name} v${m.version}`, h('span', { class: 'muted' }, ` · ${m.method}`))));
  }

  async function run() {
    const ids = [...modelsHost.querySelectorAll('input:checked')].map((i) => i.value).slice(0, 6);
    if (!ids.length || !runSelect.value) { fill(note, h('p', { class: 'error-text' }, 'Choose a run and at least one model.')); return; }
    go.disabled = true;
    fill(note, h('p', { class: 'loading' }, h('span', { class: 'spinner', 'aria-hidden': 'true' }), 'Validating the models on the run…'));
    try {
      state.result = await api.compare(ids, runSelect.value, { from_s: num(fromInput), to_s: num(toInput) });
      // a = b when one model is asked: show it once.
      if (ids.length === 1) state.result.models = state.result.models.slice(0, 1);
      const outs = state.result.models[0].report.channels.map((c) => c.output);
      fill(outSelect, outs.map((o) => h('option', { value: o }, o)));
      drawPlot();
    } catch (e) {
      fill(note, h('p', { class: 'error-text', 'data-testid': 'compare-error' }, `Compare: ${e.status ? `${e.status} · ` : ''}${e.message}`));
    } finally { go.disabled = false; }
  }

  function drawPlot() {
    const r = state.result;
    if (!r) return;
    const key = seriesSelect.value;
    const out = outSelect.value;
    const chans = r.models.map((m) => m.report.channels.find((c) => c.output === out));
    const first = chans.find(Boolean);
    if (!first) return;
    // A subspace model reports y − y₀ (its operating point removed); the
    // reference is the logged output of a physical model's report when
    // there is one, and each model's curve moves by the difference of the
    // two "measured" series, so every curve is drawn in logged units.
    const refIdx = Math.max(0, r.models.findIndex((m, i) => chans[i] && m.model.method !== 'n4sid'));
    const ref = (chans[refIdx] || first).plot;
    const onRef = (c) => {
      const v = (c && c.plot[key]) || ref.time_s.map(() => null);
      if (!c || c.plot.measured.length !== ref.measured.length) return v;
      return v.map((x, k) => (x == null || ref.measured[k] == null || c.plot.measured[k] == null ? x : x + ref.measured[k] - c.plot.measured[k]));
    };
    const plot = ref;
    const series = [{ label: `measured ${out}`, values: plot.measured, color: '#1c2430', width: 1.4 },
      ...r.models.map((m, i) => ({
        label: `${m.model.name} v${m.model.version} (${SERIES[key]})`,
        values: onRef(chans[i]),
        color: PALETTE[(i + 0) % PALETTE.length], width: 1.2,
      }))];
    state.title = `Compare on ${r.run_name}: ${out}, ${SERIES[key]}`;
    // The report's times count from the window's start: drawn in log time, as the run page.
    const t = plot.time_s.map((x) => x + r.window_s[0]);
    const u = timeResponsePlot(plotHost, t, series, { yLabel: out, name: 'compare', height: 260 });
    const w = selectedWindow(r.run_id);
    fill(windowHost,
      h('span', { class: 'hint', 'data-testid': 'compare-window-note' }, `Validated on ${fmt(r.window_s[0])}–${fmt(r.window_s[1])} s of ${r.run_name}.`),
      w ? h('button', { type: 'button', class: 'btn small', 'data-testid': 'compare-window', onClick: () => setWindow(w) },
        `Use the window selected on the run page (${fmt(w.from_s)}–${fmt(w.to_s)} s)`) : null,
      h('button', { type: 'button', class: 'btn small', 'data-testid': 'compare-zoomed', title: 'Drag on the plot to zoom, then validate on what is shown', onClick: () => setWindow({ from_s: u.scales.x.min, to_s: u.scales.x.max }) }, 'Validate on the zoomed range'),
      fromInput.value || toInput.value ? h('button', { type: 'button', class: 'btn small', 'data-testid': 'compare-whole', onClick: () => setWindow(null) }, 'Whole run') : null);
    xcorr.draw(r, out);
    fill(note,
      h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact', 'data-testid': 'compare-table' },
        h('thead', null, h('tr', null, h('th', null, 'Model'), h('th', { class: 'num' }, '1-step fit'), h('th', { class: 'num' }, 'k-step fit'), h('th', { class: 'num' }, 'Restarted fit'), h('th', { class: 'num' }, 'Simulation fit'), h('th', null, `${out}: ${SERIES[key]}`))),
        h('tbody', null, r.models.map((m, i) => {
          const c = chans[i];
          const d = c && c.diverged && c.diverged[DIV[key]];
          return h('tr', { 'data-testid': 'compare-row' },
            h('td', null, h('a', { href: urls.model(m.model.id) }, `${m.model.name} v${m.model.version}`), m.run_used_for_estimation ? h('span', { class: 'badge weak', title: 'the run was among its estimation runs: its fits flatter it' }, ' estimated on this run') : null),
            ['fit_one_step', 'fit_k_step', 'fit_restarted', 'fit_simulation'].map((f) => h('td', { class: `num${FIT[key] === f ? ' strong' : ''}` }, c ? fitText(c[f]) : '—')),
            h('td', { 'data-testid': 'compare-divergence' }, d ? `⚠ ${d.text}` : 'no divergence'));
        })))));
  }

  const el = h('div', { class: 'plot-card compare-card', 'data-testid': 'compare-card' },
    h('h3', null, 'Compare models on a run ', exportBar(() => (window.__plots.compare ? uplotExportable(window.__plots.compare, state.title) : null), 'compare-card-export')),
    h('div', { class: 'filters' }, h('label', null, 'Run ', runSelect), h('label', null, 'Show ', seriesSelect), h('label', null, 'Output ', outSelect),
      h('label', null, 'Window [s] ', fromInput, ' – ', toInput), go),
    modelsHost, windowHost, plotHost, note, xcorr.el);

  return {
    el,
    async draw() { await loadModels(); if (runs.length) run(); },
  };
}
