// Clock offsets of two-file runs (navigation time + offset = control time).
// Run page: the offset the run was merged with, where it came from, ± σ, its
// own estimate when another was used, and a form to set or clear the run's
// offset by hand (the server re-processes the run). Campaign page: the
// offset pooled from the informative runs (runs used, left out), the
// campaign's offset set by hand with a set/clear form, and per run the
// offset its report used and the one a job uses now.

import { api, urls } from './api.js';
import { h, fill, flash } from './forms.js';

const SOURCE = {
  user_run: { text: 'set by hand for this run', cls: 'good' },
  user_campaign: { text: 'set by hand for the campaign', cls: 'good' },
  own: { text: 'this run’s own estimate', cls: 'good' },
  pooled: { text: 'the campaign’s pooled offset', cls: 'good' },
  weak_own: { text: 'own estimate, NOT informative', cls: 'insufficient' },
};

/** `7.43002 ± 0.00050 s`: the digits the σ supports (as the server prints). */
export function offsetText(offset, std) {
  if (offset == null) return '–';
  if (std == null || !(std > 0) || !Number.isFinite(std)) return `${offset.toFixed(3)} s`;
  const d = Math.min(6, Math.max(3, Math.ceil(-Math.log10(std)) + 1));
  return `${offset.toFixed(d)} ± ${std.toFixed(d)} s`;
}

function sourceBadge(source, testid) {
  const s = SOURCE[source] || { text: source, cls: 'weak' };
  return h('span', { class: `badge ${s.cls}`, 'data-testid': testid, 'data-source': source }, s.text);
}

function errText(err) {
  return `${err.status ? `${err.status} · ` : ''}${err.message}${err.field ? ` [${err.field}]` : ''}`;
}

/**
 * The set/clear form. `save(value | null)` talks to the server and resolves
 * when done; errors are shown next to the form, naming the field.
 */
function offsetForm(label, current, save, prefix) {
  const input = h('input', {
    type: 'number', step: 'any', inputmode: 'decimal', class: 'num', 'data-testid': `${prefix}-input`,
    'aria-label': label, placeholder: 'seconds', value: current != null ? String(current) : '',
  });
  const msg = h('span', { class: 'error-text', role: 'alert', 'data-testid': `${prefix}-error` });
  const busy = (on) => { setBtn.disabled = on; clearBtn.disabled = on || current == null; };
  async function submit(value) {
    fill(msg);
    busy(true);
    try {
      await save(value);
    } catch (err) {
      fill(msg, errText(err));
      busy(false);
    }
  }
  const setBtn = h('button', {
    type: 'submit', class: 'btn small primary', 'data-testid': `${prefix}-set`,
  }, 'Set');
  const clearBtn = h('button', {
    type: 'button', class: 'btn small', 'data-testid': `${prefix}-clear`, disabled: current == null,
    onClick: () => submit(null),
  }, 'Clear');
  return h('form', {
    class: 'offset-form', 'data-testid': `${prefix}-form`,
    // A campaign's offset re-aligns every run: an engineer's setting.
    'data-needs': prefix === 'campaign-offset' ? 'engineer' : 'supervisor',
    onSubmit: (e) => {
      e.preventDefault();
      const raw = input.value.trim();
      // An empty or unparsable field goes to the server as text: it names the field.
      submit(raw === '' || !Number.isFinite(Number(raw)) ? raw : Number(raw));
    },
  }, h('label', null, `${label} `, input, ' s '), setBtn, ' ', clearBtn, ' ', msg);
}

/** Run page: the alignment's offset panel (two-file runs; `null` otherwise). */
export function runOffsetPanel(run) {
  if (run.layout !== 'split') return null;
  const al = (run.summary || {}).alignment;
  const own = al && al.offset;
  const byHand = al && al.offset_source === 'user_run' ? al.offset_used_s : null;
  const save = async (value) => {
    await api.setRunClockOffset(run.id, value);
    flash(value == null ? 'Run offset cleared; the run was re-processed.' : `Run offset set to ${value} s; the run was re-processed.`);
    window.dispatchEvent(new HashChangeEvent('hashchange'));
  };
  return h('div', { class: 'card offset-panel', 'data-testid': 'offset-panel' },
    al ? h('div', { class: 'offset-line' },
      h('span', { class: 'offset', 'data-testid': 'offset-used', 'data-offset-s': String(al.offset_used_s) },
        `merged with ${offsetText(al.offset_used_s, al.offset_used_std_s)}`),
      sourceBadge(al.offset_source, 'offset-source'))
      : h('p', { class: 'hint' }, 'No offset was applied: the run was rejected. Setting one by hand re-processes the run with it.'),
    al && al.pooled && al.offset_source !== 'pooled'
      ? h('p', { class: 'hint', 'data-testid': 'offset-pooled' }, `Campaign’s pooled offset: ${offsetText(al.pooled.offset_s, al.pooled.std_s)} from ${al.pooled.runs} run(s).`) : null,
    al && own && al.offset_source !== 'own'
      ? h('p', { class: 'hint', 'data-testid': 'offset-own' }, `Own estimate: ${offsetText(own.offset_s, own.std_error_s)} — ${own.reason}.`) : null,
    offsetForm('Set this run’s offset by hand:', byHand, save, 'run-offset'));
}

function runsTable(view) {
  if (!view.runs.length) return null;
  const name = new Map(view.runs.map((r) => [r.run_id, r.name]));
  const used = (u) => (u ? [offsetText(u.offset_s, u.std_s), ' ', sourceBadge(u.source)] : '–');
  return [
    h('table', { class: 'grid-table compact', 'data-testid': 'campaign-offset-runs' },
      h('thead', null, h('tr', null, h('th', null, 'Run'), h('th', null, 'Own estimate'),
        h('th', { title: 'the offset its stored alignment and quality reports were made with' }, 'Report made with'),
        h('th', { title: 'the offset an identification job reads it with now' }, 'Jobs use now'))),
      h('tbody', null, view.runs.map((r) => h('tr', { 'data-testid': 'campaign-offset-run', 'data-run-id': r.run_id },
        h('td', null, h('a', { href: urls.run(r.run_id) }, r.name)),
        h('td', { title: r.own ? r.own.reason : '' }, r.own ? [offsetText(r.own.offset_s, r.own.std_s), r.own.informative ? '' : ' (not informative)'] : '–'),
        h('td', null, used(r.at_upload)),
        h('td', { 'data-testid': 'offset-now', 'data-source': r.now ? r.now.source : '' }, used(r.now)))))),
    view.pooled && view.pooled.runs_rejected.length
      ? h('p', { class: 'hint' }, 'Left out of the pool: ', view.pooled.runs_rejected.map((x) => `${name.get(x.run_id) || x.run_id} (${offsetText(x.offset_s, x.std_s)}, z = ${x.z.toFixed(1)})`).join('; ')) : null,
  ];
}

/** Campaign page: the campaign's clock offset; hidden while it has no two-file run. */
export function campaignOffsetPanel(campaignId) {
  const box = h('section', { class: 'offset-campaign', 'data-testid': 'campaign-offset', 'aria-label': 'Clock offset', hidden: true });
  function render(view) {
    box.hidden = !view.runs.length && view.clock_offset_s == null;
    const p = view.pooled;
    const save = async (value) => render(await api.setCampaignClockOffset(campaignId, value));
    fill(box,
      h('h2', { class: 'section-title' }, 'Clock offset of two-file runs'),
      h('p', { class: 'hint' }, 'Navigation time + offset = control time. Every run consistent with the campaign uses the offset pooled from the informative runs (its own estimate included), a run left out of the pool its own estimate; one set by hand for the campaign overrides both in jobs from now on (stored run reports are not recomputed).'),
      h('div', { class: 'offset-line' },
        h('span', { class: 'offset', 'data-testid': 'campaign-offset-pooled', 'data-offset-s': p ? String(p.offset_s) : '' },
          p ? `pooled ${offsetText(p.offset_s, p.std_s)}` : 'no informative run yet'),
        p ? h('span', { class: 'hint' }, ` from ${p.runs_used.length} run(s)${p.runs_uninformative.length ? `; ${p.runs_uninformative.length} not informative` : ''}`) : null),
      p && p.warnings.length ? h('ul', { class: 'warnings' }, p.warnings.map((w) => h('li', null, '⚠ ', w))) : null,
      offsetForm('Campaign offset set by hand:', view.clock_offset_s, save, 'campaign-offset'),
      runsTable(view));
  }
  api.campaignClockOffset(campaignId).then(render, (err) => {
    box.hidden = false;
    fill(box, h('p', { class: 'error-text', role: 'alert' }, `Clock offset: ${errText(err)}`));
  });
  return box;
}
