// Input–residual cross-correlation of every compared model on the compared
// run (or window): for the output shown and a chosen input, one stem plot
// per model with its 99 % band — the model page's plot, side by side.
// Live charts: window.__plots.compareXcorr<i>.

import { h, fill } from './forms.js';
import { crossCorrelationPlot } from './responseplots.js';
import { exportBar, uplotExportable } from './plotexport.js';
import { fmtSig } from './format.js';

/** The section; `draw(result, output)` redraws it for a comparison. */
export function compareXcorrSection() {
  const state = { result: null, output: null };
  const inputSelect = h('select', { 'data-testid': 'compare-xcorr-input', 'aria-label': 'Input', onChange: () => drawPlots() });
  const plots = h('div', { class: 'compare-xcorr-plots', 'data-testid': 'compare-xcorr' });
  const el = h('div', { class: 'compare-xcorr' },
    h('h4', null, 'Input–residual cross-correlation ', h('span', { class: 'hint' }, 'of the 1-step residual; outside the band the input still explains the residual')),
    h('div', { class: 'filters' }, h('label', null, 'Input ', inputSelect)),
    plots);

  function chanOf(m) {
    return m.report.channels.find((c) => c.output === state.output);
  }

  function drawPlots() {
    const r = state.result;
    Object.keys(window.__plots || {}).filter((k) => k.startsWith('compareXcorr')).forEach((k) => window.__plots[k].__stop());
    if (!r) return;
    const input = inputSelect.value;
    fill(plots, r.models.map((m, i) => {
      const c = chanOf(m);
      const cc = c && (c.input_correlations || []).find((x) => x.input === input);
      const title = `Input–residual cross-correlation — ${m.model.name} v${m.model.version} on ${r.run_name}: ${input} → residual of ${state.output}`;
      const host = h('div', { class: 'plot', 'data-testid': 'compare-xcorr-plot' });
      const card = h('div', { class: 'plot-card' },
        h('h5', null, `${m.model.name} v${m.model.version} `, exportBar(() => (window.__plots[`compareXcorr${i}`] ? uplotExportable(window.__plots[`compareXcorr${i}`], title) : null), `compare-xcorr-export-${i}`)),
        host,
        h('p', { class: 'hint', 'data-testid': 'compare-xcorr-note' }, cc
          ? `${cc.lags_outside.length} of ${cc.lags.length} lags outside the ${Math.round(m.report.confidence * 100)} % band ±${fmtSig(cc.bound, 3)}${cc.leak ? ` — the input reaches the residual (peak r = ${fmtSig(cc.peak_value, 3)} at lag ${cc.peak_lag})` : cc.feedback ? ' — only negative lags: feedback, expected in closed loop' : ' — no leak'}.`
          : `No cross-correlation of ${input} with this model’s residual of ${state.output}.`));
      if (cc) requestAnimationFrame(() => crossCorrelationPlot(host, cc, { confidence: m.report.confidence, h: m.report.sample_time_s, height: 180, name: `compareXcorr${i}` }));
      return card;
    }));
  }

  return {
    el,
    draw(result, output) {
      state.result = result;
      state.output = output;
      const inputs = [...new Set(result.models.flatMap((m) => ((chanOf(m) || {}).input_correlations || []).map((x) => x.input)))];
      const keep = inputSelect.value;
      fill(inputSelect, inputs.map((x) => h('option', { value: x }, x)));
      if (inputs.includes(keep)) inputSelect.value = keep;
      drawPlots();
    },
  };
}
