// Design for precision per ship-hour on the campaign page: a `design` job
// chooses each DOF's excitation, the run lengths, repetitions and
// estimation families that buy the most precision within a budget of ship
// hours; the section shows the choice, the trade-off of precision against
// hours beside today's rule-based plan, and adopts the design by
// re-planning (GET /api/campaigns/{id}/design).

import { api } from './api.js';
import { fmt, fmtSig, fmtDate, unitLabel } from './format.js';
import { h, fill, labelled } from './forms.js';
import { errLine } from './identify.js';
import { newestResult, planJobRunner, priorSelect, withPrior } from './planjob.js';

const SIGNAL = { prbs: 'PRBS', square: 'square wave', multisine: 'multisine', random_binary: 'random binary' };
const SVG = 'http://www.w3.org/2000/svg';

function s(tag, attrs, ...kids) {
  const el = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) el.setAttribute(k, String(v));
  for (const k of kids.flat()) if (k != null) el.append(typeof k === 'string' ? document.createTextNode(k) : k);
  return el;
}

/** Precision (geometric-mean std relative to the current plan) against
 * ship hours: the designed front, the rule-based plan repeated, and the
 * two points that matter. Log-scaled hours. */
export function tradeOffPlot(d) {
  const W = 560, H = 280, L = 56, R = 16, T = 16, B = 44;
  const pts = [...d.designed_front, ...d.rule_front, d.design, d.current];
  const hs = pts.map((p) => p.hours), ys = pts.map((p) => p.relative_std);
  const x0 = Math.log(Math.min(...hs) * 0.9), x1 = Math.log(Math.max(...hs) * 1.1);
  const y0 = 0, y1 = Math.max(...ys) * 1.1;
  const X = (hrs) => L + (W - L - R) * (Math.log(hrs) - x0) / (x1 - x0);
  const Y = (y) => T + (H - T - B) * (1 - (y - y0) / (y1 - y0));
  const line = (front, cls) => s('polyline', { class: cls, points: front.map((p) => `${X(p.hours).toFixed(1)},${Y(p.relative_std).toFixed(1)}`).join(' '), fill: 'none' });
  const dots = (front, cls) => front.map((p) => s('circle', { class: cls, cx: X(p.hours).toFixed(1), cy: Y(p.relative_std).toFixed(1), r: 3 },
    s('title', null, `${fmt(p.hours, 2)} h: std ×${fmtSig(p.relative_std, 3)} · dynamic ${fmt(p.dynamic_s, 0)} s, recursive ${fmt(p.recursive_s, 0)} s, ×${p.repetitions}, ${p.families.join(' + ')}`)));
  const xt = [];
  for (let e = Math.floor(Math.log10(Math.exp(x0))); e <= Math.ceil(Math.log10(Math.exp(x1))); e++) {
    for (const m of [1, 2, 5]) {
      const v = m * 10 ** e;
      if (Math.log(v) >= x0 && Math.log(v) <= x1) xt.push(v);
    }
  }
  const yt = [];
  const step = y1 > 1.2 ? 0.5 : 0.2;
  for (let v = 0; v <= y1; v += step) yt.push(v);
  return s('svg', { viewBox: `0 0 ${W} ${H}`, class: 'tradeoff', role: 'img', 'aria-label': 'Precision against ship hours', 'data-testid': 'design-plot' },
    xt.map((v) => s('g', null, s('line', { class: 'grid', x1: X(v), x2: X(v), y1: T, y2: H - B }), s('text', { x: X(v), y: H - B + 16, 'text-anchor': 'middle' }, `${v}`))),
    yt.map((v) => s('g', null, s('line', { class: 'grid', x1: L, x2: W - R, y1: Y(v), y2: Y(v) }), s('text', { x: L - 6, y: Y(v) + 4, 'text-anchor': 'end' }, fmt(v, 1)))),
    s('text', { x: (L + W - R) / 2, y: H - 6, 'text-anchor': 'middle' }, 'ship hours (h, log scale)'),
    s('text', { x: 14, y: (T + H - B) / 2, 'text-anchor': 'middle', transform: `rotate(-90 14 ${(T + H - B) / 2})` }, 'std relative to current plan'),
    line(d.rule_front, 'rule'), dots(d.rule_front, 'rule'),
    line(d.designed_front, 'designed'), dots(d.designed_front, 'designed'),
    s('circle', { class: 'current', cx: X(d.current.hours), cy: Y(d.current.relative_std), r: 6, 'data-testid': 'design-plot-current' }, s('title', null, 'current plan')),
    s('circle', { class: 'chosen', cx: X(d.design.hours), cy: Y(d.design.relative_std), r: 6, 'data-testid': 'design-plot-chosen' }, s('title', null, 'design within the budget')),
    s('g', { class: 'legend' },
      s('line', { class: 'designed', x1: W - 190, x2: W - 170, y1: T + 8, y2: T + 8 }), s('text', { x: W - 164, y: T + 12 }, 'designed'),
      s('line', { class: 'rule', x1: W - 190, x2: W - 170, y1: T + 26, y2: T + 26 }), s('text', { x: W - 164, y: T + 30 }, 'today\u2019s rules, repeated'),
      s('circle', { class: 'current', cx: W - 180, cy: T + 44, r: 5 }), s('text', { x: W - 164, y: T + 48 }, 'current plan'),
      s('circle', { class: 'chosen', cx: W - 180, cy: T + 62, r: 5 }), s('text', { x: W - 164, y: T + 66 }, 'design within the budget')));
}

/** The Experiment design section. `setPlan` refreshes it after a re-plan. */
export async function designSection(host, { campaign, plan: plan0, onAdopt }) {
  const id = campaign.id;
  let plan = plan0;
  let stored = null;

  const priorSel = await priorSelect(id, 'design-prior', (m) => m.kind === 'lpv');
  const budgetIn = h('input', { type: 'number', min: '0.1', max: '720', step: '0.1', class: 'short', placeholder: 'plan\u2019s', 'data-field': 'settings.budget_hours', 'data-testid': 'design-budget' });
  const startBtn = h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'design-start' }, 'Design campaign');
  const status = h('div', { class: 'precision-status', 'data-testid': 'design-status', 'aria-live': 'polite' });
  const result = h('div', { class: 'design-result', 'data-testid': 'design-result' });
  const form = h('form', { class: 'card form', novalidate: true, 'data-needs': 'supervisor', 'data-testid': 'design-form', 'aria-label': 'Design campaign', onSubmit: submit },
    h('div', { class: 'row' },
      labelled('Prior', priorSel, 'the vessel the candidate plans are flown with in simulation'),
      labelled('Budget (h)', budgetIn, 'ship hours for runs and set-up; empty: the current plan\u2019s')),
    h('div', { class: 'form-actions' }, startBtn),
    status);
  const runner = planJobRunner({ testid: 'design', status, startBtn, onDone: () => load() });

  fill(host,
    h('h2', { class: 'section-title', 'data-section': 'design' }, 'Experiment design ',
      h('span', { class: 'hint' }, 'the excitation, lengths and repetitions that buy the most precision per ship-hour')),
    form,
    result);

  async function load() {
    stored = await newestResult(id, 'design', api.design);
    render();
  }

  async function submit(ev) {
    ev.preventDefault();
    const body = withPrior({ kind: 'design', campaign_id: id, settings: {} }, priorSel.value);
    if (budgetIn.value !== '') body.settings.budget_hours = Number(budgetIn.value);
    await runner.submit(body);
  }

  async function adopt(btn) {
    const sp = stored.design.spec;
    btn.disabled = true;
    try {
      const p = await api.replan(id, { families: sp.families, repetitions: sp.repetitions, excitation: sp.excitation, durations: sp.durations });
      if (onAdopt) await onAdopt(p);
    } catch (err) {
      runner.error(errLine(err));
    } finally {
      btn.disabled = false;
    }
  }

  function render() {
    if (!plan) {
      fill(result, h('p', { class: 'empty' }, 'Generate a plan first: the design is compared with it.'));
      startBtn.disabled = true;
      return;
    }
    startBtn.disabled = false;
    if (!stored) {
      fill(result, h('p', { class: 'empty', 'data-testid': 'design-none' }, 'No design yet. \u201cDesign campaign\u201d flies candidate plans in simulation and ranks them by the information they give the identification (seconds to a minute).'));
      return;
    }
    const d = stored.design;
    const fam = (p) => p.families.join(' + ');
    fill(result,
      stored.current ? null : h('p', { class: 'banner warn', role: 'status', 'data-testid': 'design-stale' },
        `This design was compared with plan v${stored.plan_version}; the plan has changed since.`),
      h('p', { 'data-testid': 'design-summary' },
        'Within ', h('strong', null, `${fmt(d.budget_hours, 2)} h`), ': the design flies ',
        h('strong', null, `${fmt(d.design.hours, 2)} h`), ` with every std \u00d7${fmtSig(d.design.relative_std, 2)} of the current plan\u2019s (geometric mean). `,
        'Today\u2019s rules need ', h('strong', null, `${fmt(d.rule_hours_for_equal_precision, 1)} h`), ' for the same precision: ',
        h('strong', { 'data-testid': 'design-ratio' }, `${fmt(d.hours_ratio, 1)}\u00d7`), ' the ship time',
        d.extrapolated ? ' (extrapolated beyond four repetitions)' : '', '.'),
      h('div', { class: 'table-wrap' },
        h('table', { class: 'grid-table', 'data-testid': 'design-choices' },
          h('thead', null, h('tr', null, ['DOF', 'Signal', 'Amplitude', 'Clock', 'Information per hour'].map((t) => h('th', null, t)))),
          h('tbody', null, d.choices.map((c) => h('tr', { 'data-testid': 'design-choice' },
            h('td', null, c.dof),
            h('td', null, SIGNAL[c.signal] || c.signal),
            h('td', { class: 'num' }, c.amplitude == null ? 'planner\u2019s' : `${fmtSig(c.amplitude, 3)} ${unitLabel(c.unit)}`),
            h('td', { class: 'num' }, c.clock_period_s == null ? 'planner\u2019s' : `${fmtSig(c.clock_period_s, 3)} s`),
            h('td', { class: 'num' }, c.gain > 1.0005 ? `\u00d7${fmtSig(c.gain, 3)}` : 'unchanged')))))),
      h('p', null, `Dynamic runs ${fmt(d.design.dynamic_s, 0)} s, recursive runs ${fmt(d.design.recursive_s, 0)} s, \u00d7${d.design.repetitions}, estimation from ${fam(d.design)}; static and validation runs as planned.`),
      h('div', { class: 'form-actions', 'data-needs': 'supervisor' },
        h('button', { type: 'button', class: 'btn', 'data-testid': 'design-adopt', disabled: !stored.current, onClick: (ev) => adopt(ev.currentTarget) }, 'Adopt design (re-plan)')),
      h('h3', null, 'Precision against ship hours'),
      tradeOffPlot(d),
      h('details', { class: 'sub' }, h('summary', null, 'Trade-off points'),
        h('div', { class: 'table-wrap' },
          h('table', { class: 'grid-table', 'data-testid': 'design-front' },
            h('thead', null, h('tr', null, ['', 'Ship hours', 'Std vs current', 'Dynamic', 'Recursive', 'Repetitions', 'Estimation runs'].map((t) => h('th', null, t)))),
            h('tbody', null, [...d.designed_front.map((p) => ['designed', p]), ...d.rule_front.map((p) => ['rules', p])].map(([k, p]) => h('tr', null,
              h('td', null, k), h('td', { class: 'num' }, `${fmt(p.hours, 2)} h`), h('td', { class: 'num' }, `\u00d7${fmtSig(p.relative_std, 3)}`),
              h('td', { class: 'num' }, `${fmt(p.dynamic_s, 0)} s`), h('td', { class: 'num' }, `${fmt(p.recursive_s, 0)} s`),
              h('td', { class: 'num' }, String(p.repetitions)), h('td', null, fam(p)))))))),
      h('details', { class: 'sub' }, h('summary', null, 'How it was designed'),
        h('ul', null, d.notes.map((n) => h('li', null, n)),
          h('li', { class: 'muted' }, `plan v${stored.plan_version}, ${fmtDate(stored.finished_at)}; ${d.candidates} candidate plans, ${d.flights} simulated runs`))));
  }

  await load();

  return {
    setPlan(p) { plan = p; render(); load().catch(() => {}); },
    destroy() { runner.destroy(); },
  };
}
