// The model page's "Responses" (#/models/{id}): what an engineer checks a
// model with. For a chosen operating point (LPV grid speed) and input →
// output channel: Bode of the model over a run's empirical H1 with the
// coherence below, the pole-zero map (unit circle for a discrete model),
// step and impulse responses; the Hankel singular values (for an N4SID
// model the subspace singular values that chose its order); the
// input–residual cross-correlation of a validation run with its 99 %
// band; and the overlay of several models on a chosen run. Every plot
// has PNG, SVG and CSV buttons.

import { api } from './api.js';
import { h, fill } from './forms.js';
import { fmt, fmtKn, fmtSig } from './format.js';
import { spectrumPlot, syncX, exact } from './runplots.js';
import { exportBar, uplotExportable } from './plotexport.js';
import { poleZeroPlot } from './pzplot.js';
import { timeResponsePlot, singularBarsPlot, crossCorrelationPlot } from './responseplots.js';
import { compareSection } from './comparepanel.js';

const pairKey = (c) => `${c.input}→${c.output}`;
const speedText = (s) => (s == null ? 'the model' : `${fmtKn(s)} kn (${fmt(s)} m/s)`);

/** A card with a title, export buttons for each of `charts` (functions → exportable) and a body. */
export function plotCard(title, testid, body, exportables, hint, labels = []) {
  return h('div', { class: 'plot-card', 'data-testid': testid },
    h('h3', null, title, ' ', exportables.map((get, i) => exportBar(get, `${testid}-export${exportables.length > 1 ? `-${i}` : ''}`, labels[i]))),
    hint ? h('p', { class: 'hint' }, hint) : null,
    body);
}

/** Diverged responses in words (never as numbers). */
function divergedNote(chs) {
  const d = chs.filter((c) => c.diverged_at_s != null);
  return d.length ? h('p', { class: 'warnings', 'data-testid': 'step-diverged' }, d.map((c) => `⚠ ${c.input} → ${c.output} diverged at t = ${fmt(c.diverged_at_s)} s: the model is unstable there; not drawn beyond`).join(' · ')) : null;
}

export function modelViewsSection(model, doc, { runs = [], validation = [] } = {}) {
  const accepted = runs.filter((r) => r.status === 'accepted');
  const ioPairs = (doc.inputs || []).flatMap((i) => (doc.outputs || []).map((o) => ({ input: i, output: o })));
  // Default channel: the first "diagonal" pair (γ_X → u …), else the first.
  const diag = ioPairs.find((p, k) => k % ((doc.outputs || []).length + 1) === 0) || ioPairs[0];
  const state = { point: 0, pair: diag ? pairKey(diag) : '', run: (validation[0] && validation[0].run_id) || (accepted[0] && accepted[0].id) || '', kind: 'step' };
  const cache = {};
  const exps = {};
  let destroyed = false;

  const pointSelect = h('select', { 'data-testid': 'views-point', 'aria-label': 'Operating point', onChange: (e) => { state.point = Number(e.target.value); drawAll(); } });
  const pairSelect = h('select', { 'data-testid': 'views-channel', 'aria-label': 'Channel', onChange: (e) => { state.pair = e.target.value; drawAll(); } },
    ioPairs.map((p) => h('option', { value: pairKey(p) }, `${p.input} → ${p.output}`)));
  pairSelect.value = state.pair;
  const runSelect = h('select', { 'data-testid': 'views-run', 'aria-label': 'Run for the empirical H1', onChange: (e) => { state.run = e.target.value; drawBode(); } },
    h('option', { value: '' }, 'no run (model only)'), accepted.map((r) => h('option', { value: r.id }, r.name)));
  runSelect.value = state.run;
  const kindSelect = h('select', { 'data-testid': 'views-step-kind', 'aria-label': 'Response', onChange: (e) => { state.kind = e.target.value; drawStep(); } },
    h('option', { value: 'step' }, 'step'), h('option', { value: 'impulse' }, 'impulse'));

  const magHost = h('div', { class: 'plot', 'data-testid': 'bode-mag-plot' });
  const phHost = h('div', { class: 'plot', 'data-testid': 'bode-phase-plot' });
  const cohHost = h('div', { class: 'plot', 'data-testid': 'bode-coherence-plot' });
  const bodeNote = h('p', { class: 'hint', 'data-testid': 'bode-note' });
  const pzHost = h('div', { class: 'plot pz', 'data-testid': 'pz-plot' });
  const pzNote = h('div', { class: 'hint', 'data-testid': 'pz-note' });
  const stepHost = h('div', { class: 'plot', 'data-testid': 'step-plot' });
  const stepNote = h('div', { 'data-testid': 'step-note' });
  const hsvHost = h('div', { class: 'plot', 'data-testid': 'hankel-plot' });
  const hsvNote = h('p', { class: 'hint', 'data-testid': 'hankel-note' });
  const xcHost = h('div', { class: 'plot', 'data-testid': 'xcorr-plot' });
  const xcNote = h('p', { class: 'hint', 'data-testid': 'xcorr-note' });
  const u = (name) => () => (window.__plots[name] ? uplotExportable(window.__plots[name], exps[name] || `${model.name} ${name}`) : null);

  // ---- Bode ----------------------------------------------------------------
  async function drawBode() {
    const key = `fr:${state.run}`;
    try {
      cache[key] = cache[key] || await api.frequencyResponse(model.id, state.run || null);
    } catch (e) { fill(bodeNote, `Bode: ${e.message}`); return; }
    if (destroyed) return;
    const fr = cache[key];
    const pt = fr.points[Math.min(state.point, fr.points.length - 1)];
    const ch = pt.channels.find((c) => pairKey(c) === state.pair) || pt.channels[0];
    if (!ch) return;
    const emp = fr.run ? fr.run.channels.find((c) => c.model_input === ch.input && c.output === ch.output) : null;
    const title = `${model.name} v${model.version} ${ch.input} → ${ch.output} at ${speedText(pt.grid_speed_mps)}`;
    exps.bodeMag = `Bode magnitude — ${title}`;
    exps.bodePhase = `Bode phase — ${title}`;
    exps.bodeCoherence = `Coherence — ${fr.run ? fr.run.run_name : ''} ${ch.input} → ${ch.output}`;
    const mag = spectrumPlot('bodeMag', magHost, {
      freqs: fr.freqs_hz, height: 220, y: { label: `|H| [dB re 1 ${ch.unit}]` },
      series: [
        { label: `model |H| [dB]`, values: ch.magnitude_db, color: '#1f6fb5', width: 1.8 },
        ...(emp ? [{ label: `H1 of ${fr.run.run_name} (${emp.input} → ${emp.output}) [dB]`, values: emp.magnitude_db, color: '#e08a1e', dash: [3, 2] }] : []),
      ],
    });
    const ph = spectrumPlot('bodePhase', phHost, {
      freqs: fr.freqs_hz, height: 200, y: { label: 'phase [°]' },
      series: [
        { label: 'model ∠H [°]', values: ch.phase_deg, color: '#1f6fb5', width: 1.8 },
        ...(emp ? [{ label: `∠H1 of ${fr.run.run_name} [°]`, values: emp.phase_deg, color: '#e08a1e', dash: [3, 2] }] : []),
      ],
    });
    syncX(mag, ph);
    if (emp) {
      const coh = spectrumPlot('bodeCoherence', cohHost, {
        freqs: fr.freqs_hz, height: 160, y: { range: [0, 1.02], label: 'coherence γ² [-]' },
        lines: [{ y: 0.8, label: 'good ≥ 0.8', color: '#1f7a45' }],
        series: [{ label: `γ² ${emp.input} → ${emp.output}`, values: emp.coherence, color: '#2e9e5b' }],
      });
      syncX(mag, coh);
      fill(bodeNote, `Model at ${speedText(pt.grid_speed_mps)} over the empirical H1 = Pxy/Pxx of ${fr.run.run_name}${fr.run.grid_speed_mps != null ? ` (run at ${speedText(fr.run.grid_speed_mps)})` : ''}; trust H1 where the coherence is high.`);
    } else {
      if (window.__plots.bodeCoherence) window.__plots.bodeCoherence.__stop();
      fill(cohHost, h('p', { class: 'empty' }, fr.run ? `${fr.run.run_name} has no spectrum for ${ch.input} → ${ch.output}.` : 'Choose a run to see its empirical H1 and coherence.'));
      fill(bodeNote, `Model at ${speedText(pt.grid_speed_mps)}${fr.sample_time_s ? ` (discrete, h = ${exact(fr.sample_time_s)} s: up to Nyquist ${exact(0.5 / fr.sample_time_s)} Hz)` : ''}.`);
    }
  }

  // ---- pole-zero -----------------------------------------------------------
  async function drawPz() {
    try { cache.pz = cache.pz || await api.poles(model.id); } catch (e) { fill(pzNote, `Poles: ${e.message}`); return; }
    if (destroyed) return;
    const m = cache.pz.points[Math.min(state.point, cache.pz.points.length - 1)];
    const ch = m.channels.find((c) => pairKey(c) === state.pair) || m.channels[0];
    const title = `Pole-zero map — ${model.name} v${model.version} at ${speedText(m.grid_speed_mps)}, zeros of ${ch ? `${ch.input} → ${ch.output}` : '–'}`;
    exps.pz = poleZeroPlot(pzHost, { plane: m.plane, poles: m.poles, zeros: ch ? ch.zeros : [] }, { title });
    // 4 significant digits with units: s in rad/s (z is dimensionless), ωn in rad/s, τ in s, ζ without.
    const unit = m.plane === 'z' ? '' : ' rad/s';
    const rootText = (r) => {
      const about = [
        r.im && r.natural_frequency_rad_s != null ? `ωn ${fmtSig(r.natural_frequency_rad_s)} rad/s` : null,
        r.im && r.damping != null ? `ζ ${fmtSig(r.damping)}` : null,
        r.time_constant_s != null ? `τ ${fmtSig(r.time_constant_s)} s` : null,
      ].filter(Boolean);
      return `${fmtSig(r.re)}${r.im ? ` ${r.im < 0 ? '−' : '+'} ${fmtSig(Math.abs(r.im))}j` : ''}${unit}${about.length ? ` (${about.join(', ')})` : ''}`;
    };
    fill(pzNote,
      h('p', null, m.plane === 'z' ? `z plane (discrete, h = ${exact(m.sample_time_s)} s): stable inside the unit circle. ` : 's plane [rad/s]: stable left of the imaginary axis. ',
        h('b', { 'data-testid': 'pz-stability' }, m.stable ? 'All poles stable.' : 'Unstable: a pole is outside the stability region.')),
      h('p', null, `Poles: ${m.poles.map(rootText).join(', ') || 'none'}`),
      h('p', null, ch && ch.no_transfer ? `${ch.input} does not reach ${ch.output} in this model.` : `Zeros of ${ch ? `${ch.input} → ${ch.output}` : '–'}: ${ch && ch.zeros.length ? ch.zeros.map(rootText).join(', ') : 'none (finite)'}`),
      h('p', null, cache.pz.zeros_are));
  }

  // ---- step / impulse --------------------------------------------------------
  async function drawStep() {
    const key = `step:${state.kind}`;
    try { cache[key] = cache[key] || await api.stepResponse(model.id, state.kind); } catch (e) { fill(stepNote, h('p', { class: 'error-text' }, `Step: ${e.message}`)); return; }
    if (destroyed) return;
    const r = cache[key];
    const pt = r.points[Math.min(state.point, r.points.length - 1)];
    const [inp] = state.pair.split('→');
    const chs = pt.channels.filter((c) => c.input === inp);
    exps.step = `${state.kind === 'step' ? 'Step' : 'Impulse'} response — ${model.name} v${model.version}, input ${inp}, at ${speedText(pt.grid_speed_mps)}`;
    timeResponsePlot(stepHost, pt.time_s, chs.map((c) => ({ label: `${c.output} [${c.unit}]`, values: c.values, width: pairKey(c) === state.pair ? 2 : 1 })), {
      yLabel: `per unit ${inp} [unit in legend]`,
    });
    fill(stepNote, h('p', { class: 'hint' }, `Unit ${state.kind} of ${inp} at t = 0 from rest, every output.`), divergedNote(chs));
  }

  // ---- Hankel singular values ------------------------------------------------
  async function drawHankel() {
    try { cache.hsv = cache.hsv || await api.hankel(model.id); } catch (e) { fill(hsvNote, `Hankel: ${e.message}`); return; }
    if (destroyed) return;
    const hv = cache.hsv;
    const pt = hv.points[Math.min(state.point, hv.points.length - 1)];
    if (hv.subspace && hv.subspace.values.length) {
      exps.hankel = `Subspace singular values — ${model.name} v${model.version} (order ${hv.subspace.order})`;
      singularBarsPlot(hsvHost, hv.subspace.values, { order: hv.subspace.order, label: 'σᵢ of W₁OᵢW₂', yLabel: 'singular value [-]' });
      fill(hsvNote, `N4SID chose order ${hv.subspace.order} at the gap in these values; bars beyond it are taken as noise.${pt.values.length ? ` Hankel singular values of the model: ${pt.values.map((v) => exact(v)).join(', ')}.` : pt.undefined ? ` ${pt.undefined}.` : ''}`);
    } else if (pt.values.length) {
      exps.hankel = `Hankel singular values — ${model.name} v${model.version} at ${speedText(pt.grid_speed_mps)}`;
      singularBarsPlot(hsvHost, pt.values, { label: 'Hankel σᵢ', yLabel: 'Hankel singular value' });
      fill(hsvNote, `At ${speedText(pt.grid_speed_mps)} (${pt.sample_time_s ? `discrete, h = ${exact(pt.sample_time_s)} s` : 'continuous'}): states with small σ carry little input → output energy.`);
    } else {
      if (window.__plots.hankel) window.__plots.hankel.__stop();
      fill(hsvHost, h('p', { class: 'empty' }, `No Hankel singular values at ${speedText(pt.grid_speed_mps)}: ${pt.undefined || 'no states'}.`));
      fill(hsvNote, '');
    }
  }

  // ---- input–residual cross-correlation ---------------------------------------
  const xcRun = h('select', { 'data-testid': 'xcorr-run', 'aria-label': 'Validation run', onChange: () => { fillXcChannels(); drawXcorr(); } }, validation.map((rv, i) => h('option', { value: String(i) }, rv.run_name || rv.run_id)));
  const xcChan = h('select', { 'data-testid': 'xcorr-channel', 'aria-label': 'Output and input', onChange: () => drawXcorr() });
  function fillXcChannels() {
    const rv = validation[Number(xcRun.value) || 0];
    const opts = ((rv && rv.report.channels) || []).flatMap((c, ci) => (c.input_correlations || []).map((cc, k) => h('option', { value: `${ci}:${k}` }, `${cc.input} → residual of ${c.output}${cc.leak ? ' (leak)' : ''}`)));
    fill(xcChan, opts);
    const [, out] = state.pair.split('→');
    const pick = opts.find((o) => o.textContent.includes(`residual of ${out}`));
    if (pick) xcChan.value = pick.value;
  }
  function drawXcorr() {
    const rv = validation[Number(xcRun.value) || 0];
    if (!rv) { fill(xcHost, h('p', { class: 'empty' }, 'No validation run: hold a run out when identifying to see the residual cross-correlation.')); return; }
    const [ci, k] = (xcChan.value || '0:0').split(':').map(Number);
    const c = rv.report.channels[ci];
    const cc = c && c.input_correlations[k];
    if (!cc) { fill(xcHost, h('p', { class: 'empty' }, 'No cross-correlation in this report.')); return; }
    exps.xcorr = `Input–residual cross-correlation — ${model.name} v${model.version} on ${rv.run_name}: ${cc.input} → residual of ${c.output}`;
    crossCorrelationPlot(xcHost, cc, { confidence: rv.report.confidence, h: rv.report.sample_time_s });
    fill(xcNote, `1-step residual of ${c.output} against ${cc.input} on ${rv.run_name}: ${cc.lags_outside.length} of ${cc.lags.length} lags outside the ${Math.round(rv.report.confidence * 100)} % band ±${fmtSig(cc.bound, 3)}. `
      + (cc.leak ? `The input reaches the residual (peak r = ${fmtSig(cc.peak_value, 3)} at lag ${cc.peak_lag}): a missed coupling or delay.` : cc.feedback ? 'Only negative lags exceed the band: feedback from a controller, expected in closed loop.' : 'No leak: the model explains what this input does.'));
  }

  // ---- layout --------------------------------------------------------------------
  const lpv = doc.lpv ? doc.lpv.points : null;
  fill(pointSelect, (lpv && lpv.length ? lpv.map((p, i) => h('option', { value: String(i) }, `${fmtKn(p.speed_mps)} kn (${fmt(p.speed_mps)} m/s)`)) : [h('option', { value: '0' }, 'the model')]));
  const compare = compareSection(model, { runs: accepted, defaultRun: state.run });

  const el = h('section', { class: 'model-views', 'data-testid': 'model-views', 'aria-label': 'Responses' },
    h('div', { class: 'filters views-controls' },
      h('label', null, 'Operating point ', pointSelect),
      h('label', null, 'Channel ', pairSelect),
      h('label', null, 'Run for H1 ', runSelect)),
    h('div', { class: 'plot-grid' },
      plotCard('Bode', 'bode-card', [magHost, phHost, cohHost, bodeNote], [u('bodeMag'), u('bodePhase'), u('bodeCoherence')],
        'Magnitude, phase and the run’s coherence; zoom one, the others follow.', ['magnitude', 'phase', 'coherence']),
      plotCard('Pole-zero map', 'pz-card', [pzHost, pzNote], [() => exps.pz || null]),
      plotCard(h('span', null, 'Step / impulse ', kindSelect), 'step-card', [stepHost, stepNote], [u('step')]),
      plotCard('Hankel singular values', 'hankel-card', [hsvHost, hsvNote], [u('hankel')], 'Log scale: a clear drop says how many states the data support.'),
      plotCard(h('span', null, 'Input–residual cross-correlation ', xcRun, ' ', xcChan), 'xcorr-card', [xcHost, xcNote], [u('xcorr')],
        'As MATLAB resid: outside the band at τ ≥ 0 the input still explains the residual.')),
    compare.el);

  function drawAll() {
    drawBode();
    drawPz();
    drawStep();
    drawHankel();
  }

  return {
    el,
    draw() {
      drawAll();
      fillXcChannels();
      drawXcorr();
      compare.draw();
    },
    destroy() { destroyed = true; },
  };
}

