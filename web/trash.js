// The campaign's deleted runs and model versions, each with who deleted it,
// when and why, and a Restore button (the undo of a soft delete).

import { api, urls } from './api.js';
import { h, fill } from './forms.js';
import { fmtDate } from './format.js';

/** One deleted item: its link, who deleted it, when and why, and Restore. */
export function deletedRow(item, label, href, restore, onDone, msg, needs = 'supervisor') {
  return h('li', { 'data-testid': 'deleted-row', 'data-id': item.id },
    h('a', { href }, label), ' ',
    h('span', { class: 'muted' }, `deleted by ${item.deleted_by || '?'} at ${fmtDate(item.deleted_at)}${item.delete_reason ? ` — ${item.delete_reason}` : ''} `),
    h('button', {
      type: 'button', class: 'btn small', 'data-testid': 'restore', 'data-needs': needs,
      onclick: () => restore(item.id).then(onDone, (e) => fill(msg, h('p', { class: 'error-text', role: 'alert' }, e.message))),
    }, 'Restore'));
}

/** The "Deleted" section of campaign `id`; `onRestored()` refreshes the rest of the page. */
export function deletedSection(id, onRestored) {
  const host = h('section', { class: 'trash', 'aria-label': 'Deleted runs and models', 'data-testid': 'deleted-section', 'data-section': 'deleted' });
  const msg = h('div', { 'aria-live': 'polite' });
  async function refresh() {
    const [runs, models] = await Promise.all([api.deletedRuns(id), api.deletedModels(id)]);
    const done = () => { refresh(); if (onRestored) onRestored(); };
    fill(host,
      h('h2', { class: 'section-title' }, 'Deleted ', h('span', { class: 'hint' }, 'kept with who, when and why; restore brings an item back into the lists')),
      runs.length || models.length
        ? h('ul', { class: 'plain' },
          runs.map((r) => deletedRow(r, `run ${r.name}`, urls.run(r.id), api.restoreRun, done, msg)),
          models.map((m) => deletedRow(m, `model ${m.name} v${m.version}`, urls.model(m.id), api.restoreModel, done, msg)))
        : h('p', { class: 'empty', 'data-testid': 'nothing-deleted' }, 'Nothing deleted.'),
      msg);
  }
  refresh().catch((e) => fill(host, h('p', { class: 'error-text' }, e.message)));
  return { host, refresh };
}
