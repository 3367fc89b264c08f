// Discovery report page (#/discrepancies/{id}): what missing-physics discovery
// found on a model — the story in sentences, the effects across the grid, and
// per grid speed where the model and the recordings part, the ranked
// hypotheses with their evidence, the chosen terms with their estimates, the
// before/after fits and simulations on held-out runs, look-alikes with the
// experiment that would separate them, and what stays unexplained. The
// augmented model (the examined model's next version) is one click away.

import { api, urls } from './api.js';
import { fmt, fmtDate, fmtKn, dofUnits } from './format.js';
import { h, fill } from './forms.js';
import { fitText } from './modelpage.js';
import { zoomGroup } from './modelplots.js';
import { beforeAfterPlot } from './discoveryplots.js';
import { exact } from './runplots.js';

const fitClass = (v) => (v == null ? '' : v >= 0.8 ? 'fit-good' : v >= 0.5 ? 'fit-weak' : 'fit-bad');
const speedText = (mps) => `${fmtKn(mps)} kn (${fmt(mps)} m/s)`;
const VERDICT = { chosen: ['good', 'chosen'], not_confirmed: ['weak', 'not confirmed on held-out runs'], not_significant: ['neutral', 'not significant'] };

/** "value ± std" of an estimate {name, value, std}. */
function estimateText(e) {
  return `${e.name} = ${exact(e.value)}${e.std != null && Number.isFinite(e.std) ? ` ± ${exact(e.std)}` : ''}`;
}

function fitCell(v, testid) {
  return h('td', { class: `num ${fitClass(v)}`, 'data-testid': testid }, fitText(v));
}

function whiteText(w) {
  if (!w) return '–';
  return `${w.lags_outside}/${w.lags} lags outside ±${fmt(w.bound, 3)} · ${w.zero_crossings} zero crossings (expected ${fmt(w.expected_zero_crossings[0], 0)}–${fmt(w.expected_zero_crossings[1], 0)})`;
}

function locationSection(loc) {
  const rows = (loc.per_dof || []).map((d) => h('tr', { 'data-testid': 'location-row', 'data-dof': d.dof, class: d.parts ? 'parts' : null },
    h('td', null, d.dof, d.parts ? h('span', { class: 'badge weak' }, 'misfit') : null),
    fitCell(d.fits.one_step), fitCell(d.fits.k_step), fitCell(d.fits.free_run),
    h('td', { class: 'num mono' }, exact(d.free_run_bias)),
    h('td', { class: 'hint' }, whiteText(d.whiteness))));
  return h('div', { class: 'card', 'data-testid': 'location' },
    h('h4', null, 'Where the baseline and the recordings part'),
    (loc.sentences || []).length ? h('ul', { 'data-testid': 'location-sentences' }, loc.sentences.map((s) => h('li', null, s))) : h('p', { class: 'hint' }, 'Nothing stands out.'),
    h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact' },
      h('thead', null, h('tr', null, h('th', null, 'DOF'), h('th', { class: 'num' }, '1-step'), h('th', { class: 'num' }, `${loc.k_step}-step`), h('th', { class: 'num' }, 'free run'),
        h('th', { class: 'num', title: 'mean of measured − simulated' }, 'free-run bias'), h('th', null, '1-step residual whiteness'))),
      h('tbody', null, rows))));
}

function hypothesesSection(hyps) {
  return h('div', { class: 'card', 'data-testid': 'hypotheses' },
    h('h4', null, 'Hypotheses, ranked ', h('span', { class: 'hint' }, 'ΔBIC < 0 favours the term; z its significance; size its force against the command in its DOF (RMS); gain the held-out free-run fit it adds')),
    h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact' },
      h('thead', null, h('tr', null, h('th', null, '#'), h('th', null, 'Hypothesis'), h('th', null, 'Verdict'), h('th', { class: 'num' }, 'ΔBIC'), h('th', { class: 'num' }, 'z'), h('th', { class: 'num', title: 'RMS of its force over RMS of the command in its DOF' }, 'size'), h('th', { class: 'num' }, 'held-out gain'), h('th', null, 'Estimates'))),
      h('tbody', null, hyps.map((x, i) => {
        const [cls, text] = VERDICT[x.verdict] || ['neutral', x.verdict];
        return h('tr', { 'data-testid': 'hypothesis-row', 'data-verdict': x.verdict },
          h('td', { class: 'num' }, String(i + 1)),
          h('td', null, x.label, h('div', { class: 'hint' }, `step ${x.step}`)),
          h('td', null, h('span', { class: `badge ${cls}` }, text)),
          h('td', { class: 'num mono' }, fmt(x.delta_bic, 1)),
          h('td', { class: 'num mono' }, fmt(x.z, 1)),
          h('td', { class: 'num mono', 'data-testid': 'hypothesis-size' }, x.force_share == null ? '–' : `${fmt(100 * x.force_share, 2)} %`),
          h('td', { class: 'num mono' }, x.cv_gain == null ? '–' : fmt(x.cv_gain, 3)),
          h('td', { class: 'mono small' }, [...(x.coefficients || []), ...(x.shape ? [x.shape] : [])].map(estimateText).join('; ')));
      })))));
}

function findingsSection(findings, carried) {
  if (!findings.length) {
    return h('p', { class: 'hint', 'data-testid': 'no-findings' }, carried.length
      ? `No further term was chosen at this speed; the model's ${carried.length} discovered term(s) were kept.`
      : 'No term was chosen at this speed.');
  }
  return h('div', { class: 'card', 'data-testid': 'findings' },
    h('h4', null, 'Named'),
    findings.map((f) => h('div', { class: 'finding', 'data-testid': 'finding' },
      h('p', null, h('b', { 'data-testid': 'finding-label' }, f.label), ' — ', f.effect_text),
      h('p', { class: 'mono small', 'data-testid': 'finding-estimates' }, [...(f.coefficients || []), ...(f.shape ? [f.shape] : [])].map(estimateText).join('; ')),
      (f.evidence || []).length ? h('ul', { class: 'evidence' }, f.evidence.map((e) => h('li', null, e))) : null)));
}

function beforeAfterTable(rows) {
  return h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact', 'data-testid': 'before-after' },
    h('thead', null,
      h('tr', null, h('th', null, ''), h('th', { colspan: '3' }, 'Before (baseline)'), h('th', { colspan: '3' }, 'After (with discovered physics)'), h('th', null, 'Residual whiteness before → after')),
      h('tr', null, h('th', null, 'DOF'), ['1-step', 'k-step', 'free run', '1-step', 'k-step', 'free run'].map((x) => h('th', { class: 'num' }, x)), h('th', null, ''))),
    h('tbody', null, rows.map((c) => h('tr', { 'data-testid': 'before-after-row', 'data-dof': c.dof },
      h('td', null, c.dof),
      fitCell(c.before.one_step), fitCell(c.before.k_step), fitCell(c.before.free_run, 'free-run-before'),
      fitCell(c.after.one_step), fitCell(c.after.k_step), fitCell(c.after.free_run, 'free-run-after'),
      h('td', { class: 'hint' }, `${c.whiteness_before.lags_outside} → ${c.whiteness_after.lags_outside} lags outside; ${c.whiteness_before.zero_crossings} → ${c.whiteness_after.zero_crossings} zero crossings`))))));
}

/** Same proposal: both are the service's serialisation of one type. */
const sameProposal = (a, b) => JSON.stringify(a) === JSON.stringify(b);

/**
 * "Add to the plan": the proposal joins the campaign's deciding runs (a
 * re-plan; the plan's own runs keep their ids) and is flown one run per
 * heading after them; the next-dive proposal puts it right after validation.
 */
function addToPlanButton(campaignId, experiment) {
  const out = h('span', { class: 'hint', 'data-testid': 'deciding-added', role: 'status' });
  const btn = h('button', { class: 'btn', type: 'button', 'data-testid': 'add-deciding' }, 'Add to the plan');
  btn.addEventListener('click', async () => {
    btn.disabled = true;
    out.textContent = 'Re-planning…';
    try {
      const c = await api.campaign(campaignId);
      const list = Array.isArray(c.deciding) ? c.deciding : [];
      if (list.some((x) => sameProposal(x, experiment))) {
        out.textContent = 'Already in the plan.';
        return;
      }
      const r = await api.replan(campaignId, { deciding: [...list, experiment] });
      const codes = (r.experiments || []).filter((e) => e.separates).map((e) => e.code);
      fill(out, `Added to plan v${r.version}: `, codes.join(', '), ' · ',
        h('a', { href: `#/campaigns/${campaignId}` }, 'open the plan'));
    } catch (e) {
      out.textContent = `Not added: ${e.message}`;
      btn.disabled = false;
    }
  });
  return [btn, ' ', out];
}

function ambiguitySection(ambs, campaignId) {
  if (!ambs.length) return null;
  return h('div', { class: 'card', 'data-testid': 'ambiguities' },
    h('h4', null, 'Look-alikes the data cannot separate'),
    ambs.map((a) => h('div', { class: 'ambiguity', 'data-testid': 'ambiguity' },
      h('p', null, a.text),
      a.experiment ? h('p', { class: 'deciding', 'data-testid': 'deciding-experiment' }, h('b', null, 'Deciding experiment: '), a.experiment.instruction,
        ` (${a.experiment.headings_deg.length} heading${a.experiment.headings_deg.length > 1 ? 's' : ''} × ${fmt(a.experiment.duration_s)} s) `,
        ...addToPlanButton(campaignId, a.experiment)) : null)));
}

function unexplainedSection(list) {
  if (!list.length) return null;
  return h('div', { class: 'card', 'data-testid': 'unexplained' },
    h('h4', null, 'Unexplained ', h('span', { class: 'hint' }, 'residual structure no candidate explains, with where it lives')),
    h('ul', null, list.map((u) => h('li', null, u.text))));
}

/** The report page. Returns a controller whose mount() draws the open plots. */
export async function discoveryPage(view, id) {
  const d = await api.discrepancy(id);
  const rep = d.report || {};
  const base = d.model;
  const aug = d.augmented_model;
  const runName = (rid) => (d.run_names && d.run_names[rid]) || rid;
  const drawn = new Set();
  let mounted = false;

  const pointSections = (rep.points || []).map((p, pi) => {
    const r = p.report;
    const plots = h('div', { class: 'plot-grid pvm-grid' });
    const group = zoomGroup();
    const draw = () => {
      if (drawn.has(pi) || !mounted) return;
      drawn.add(pi);
      fill(plots, (r.plots || []).map((s, i) => {
        const host = h('div', { class: 'plot', 'data-testid': 'before-after-plot', 'data-dof': s.dof });
        return h('div', { class: 'plot-card' }, h('h3', null, `${s.dof} `, h('span', { class: 'hint' }, s.run)), host);
      }));
      (r.plots || []).forEach((s, i) => {
        const host = plots.querySelectorAll('[data-testid="before-after-plot"]')[i];
        const unit = `${s.dof} velocity [${dofUnits(s.dof).velocity}]`;
        beforeAfterPlot(`disc:${pi}:${i}`, host, s, { unit, sync: `disc-${pi}`, group });
      });
    };
    const det = h('details', { class: 'card discovery-point', 'data-testid': 'discovery-point', 'data-speed': String(p.grid_speed_mps), open: pi === 0 },
      h('summary', null, h('b', null, `At ${speedText(p.grid_speed_mps)}`),
        h('span', { class: 'hint' }, ` · ${r.findings.length} named · fitted on ${p.estimation_run_ids.length} run(s), judged on ${p.validation_run_ids.length} held out`)),
      (r.summary || []).length ? h('ul', { class: 'notes' }, r.summary.map((s) => h('li', null, s))) : null,
      h('p', { class: 'hint' }, 'Fitted on: ', p.estimation_run_ids.map((x, i) => [i ? ', ' : '', h('a', { href: urls.run(x) }, runName(x))]),
        ' · held out: ', p.validation_run_ids.map((x, i) => [i ? ', ' : '', h('a', { href: urls.run(x) }, runName(x))])),
      locationSection(r.location || {}),
      hypothesesSection(r.hypotheses || []),
      findingsSection(r.findings || [], r.carried || []),
      h('div', { class: 'card' },
        h('h4', null, 'Before / after on held-out runs'),
        beforeAfterTable(r.validation || []),
        h('p', { class: 'hint' }, 'Free-run simulations on the recorded inputs; drag to zoom (all DOFs follow), double-click to reset.'),
        plots),
      ambiguitySection(r.ambiguities || [], d.discrepancy.campaign_id),
      unexplainedSection(r.unexplained || []));
    det.addEventListener('toggle', () => { if (det.open) draw(); });
    return { det, draw, open: pi === 0 };
  });

  const effects = rep.effects || [];
  const effectsTable = effects.length
    ? h('div', { class: 'table-x' }, h('table', { class: 'grid-table compact', 'data-testid': 'effects-table' },
      h('thead', null, h('tr', null, h('th', null, 'Effect'), h('th', null, 'Grid speeds'),
        h('th', { title: 'What the findings of the grid speeds that chose it gain, added alone to the baseline, on the held-out runs: the 1-step, k-step, 10 s restarted and whole-run free-run fits (each clamped to [−1, 1]) summed, less the baseline\u2019s; the speeds that gain count (a force the campaign shares is held at every speed: all of them count). Effects are ranked by it, then by the speeds that chose them, then by the held-out gain' }, 'Held-out advantage'),
        h('th', { title: 'Held-out free-run fit gained where it was chosen, given the terms chosen before it there (1 − NRMSE summed over channels and speeds)' }, 'Held-out gain'),
        h('th', null, 'First coefficient per speed (± std)'),
        h('th', { title: 'The model with every finding, or else each grid speed\u2019s findings added one speed at a time, is kept only where the held-out runs are better with them than without and no worse anywhere' }, 'In the stored model'))),
      h('tbody', null, effects.map((e) => h('tr', { 'data-testid': 'effect-row', 'data-unconfirmed': e.unconfirmed ? 'true' : 'false' },
        h('td', null, e.unconfirmed
          ? [h('span', null, e.label), ' ', h('span', { class: 'badge weak', 'data-testid': 'effect-unconfirmed', title: 'Tried, not confirmed: the held-out runs did not favour it at any grid speed that chose it; not a finding' }, 'not confirmed')]
          : h('b', null, e.label)),
        h('td', null, e.grid_speeds_mps.length
          ? e.grid_speeds_mps.map((s) => `${fmtKn(s)} kn`).join(', ')
          : (e.campaign_estimate ? 'the whole campaign' : '—')),
        h('td', { class: 'num mono', 'data-testid': 'effect-advantage' },
          fmt(e.held_out_advantage ?? 0, 3)),
        h('td', { class: 'num mono', 'data-testid': 'effect-evidence' }, fmt((e.held_out_gains || []).reduce((a, b) => a + b, 0), 3)),
        h('td', { class: 'mono small', 'data-testid': 'effect-coefficients' },
          e.magnitudes.map((m) => `${exact(m[0])}${m[1] != null ? ` ± ${exact(m[1])}` : ''}`).join('; '),
          e.campaign_estimate
            ? h('div', { title: e.campaign_estimate.text }, `campaign: ${e.campaign_estimate.coefficients
              .map((c) => `${c.name} ${exact(c.value)}${c.std != null ? ` ± ${exact(c.std)}` : ''}`).join(', ')}`)
            : null),
        h('td', { class: 'small', 'data-testid': 'effect-kept', 'data-kept': e.kept == null ? '' : String(e.kept) },
          e.kept == null ? '—' : h('span', { class: `badge ${e.kept ? 'good' : 'neutral'}` }, e.kept ? 'kept' : 'left out'),
          e.held_out_verdict ? h('div', { class: 'hint' }, e.held_out_verdict) : null))))))
    : h('p', { class: 'empty', 'data-testid': 'no-effects' }, 'Nothing named: the model explains the recordings within the evidence.');

  fill(view,
    h('nav', { class: 'crumbs muted', 'aria-label': 'Breadcrumb' },
      h('a', { href: `#/campaigns/${d.discrepancy.campaign_id}` }, '← campaign'), ' · ',
      h('a', { href: urls.model(base.id), 'data-testid': 'report-model-link' }, `model ${base.name} v${base.version}`)),
    h('div', { class: 'page-head' },
      h('div', null,
        h('h1', { 'data-testid': 'report-title' }, 'Missing physics ', h('span', { class: 'badge neutral' }, `${base.name} v${base.version}`)),
        h('div', { class: 'muted' }, `${fmtDate(d.discrepancy.created_at)} · software ${d.discrepancy.software_version}${d.discrepancy.job_id ? ` · job ${d.discrepancy.job_id}` : ''}`)),
      h('div', { class: 'actions' },
        aug
          ? h('a', { class: 'btn primary', href: urls.model(aug.id), 'data-testid': 'augmented-model-link' }, `Open augmented model v${aug.version} →`)
          : h('span', { class: 'hint', 'data-testid': 'no-augmented-model' }, 'No new model version: nothing was named.'))),
    h('h2', { class: 'section-title' }, 'Summary'),
    h('ul', { class: 'notes', 'data-testid': 'discovery-summary' }, (rep.summary || []).map((s) => h('li', null, s))),
    h('h2', { class: 'section-title' }, 'Effects across the grid'),
    effectsTable,
    h('h2', { class: 'section-title' }, 'Per grid speed'),
    pointSections.map((s) => s.det),
    (rep.skipped || []).length ? h('p', { class: 'hint', 'data-testid': 'skipped' }, `Not examined: ${rep.skipped.join('; ')}`) : null);

  return {
    key: `discrepancy:${id}`,
    mount() { mounted = true; for (const s of pointSections) if (s.det.open) s.draw(); },
    destroy() {},
  };
}
