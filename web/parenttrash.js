// Deleting a vessel or a campaign from the browser (a soft delete with an
// optional reason, undone by Undo) and the lists of deleted ones with a
// Restore button each. A refused restore (its vessel is deleted) shows the
// server's 409, which names that vessel.

import { api } from './api.js';
import { h, fill, reloadPage } from './forms.js';
import { confirmBox, reasonInput, deletedNote } from './manage.js';
import { deletedRow } from './trash.js';

function errorBox(host, err) {
  fill(host, h('p', { class: 'error-text', role: 'alert', 'data-testid': 'manage-error' }, err.message));
}

/**
 * The delete control of a vessel or campaign page: "Delete …" with a reason,
 * then the "deleted by … — Undo" note; a deleted item shows the note at once.
 * `what` names it ("vessel"), `consequence` says what deleting it does.
 */
export function deleteControl({ what, item, needs, consequence, del, restore }) {
  const host = h('div', { class: 'manage', 'data-testid': `${what}-manage`, 'data-needs': needs });
  const msg = h('div', { 'aria-live': 'polite' });
  const undo = () => restore(item.id).then(() => reloadPage(), (e) => errorBox(msg, e));
  const showDeleted = (now) => fill(host, deletedNote(now, undo), msg);
  if (item.deleted_at) {
    showDeleted(item);
    return host;
  }
  fill(host, h('button', {
    type: 'button', class: 'btn danger small', 'data-testid': `delete-${what}`,
    onclick: () => {
      const why = reasonInput();
      confirmBox(msg, {
        question: `Delete ${what} “${item.name}”? ${consequence} Undo brings it back.`,
        label: `Delete ${what}`,
        extra: why,
        // Re-rendered: a deleted campaign's page drops its new-work controls.
        run: () => del(item.id, why.value).then(() => reloadPage(), (e) => errorBox(msg, e)),
      });
    },
  }, `Delete ${what}…`), msg);
  return host;
}

/** The list page's "Deleted vessels"/"Deleted campaigns" section (hidden when there are none). */
export function deletedListSection({ what, list, href, restore, needs }) {
  const host = h('section', { class: 'trash', 'aria-label': `Deleted ${what}s`, 'data-testid': `deleted-${what}s` });
  const msg = h('div', { 'aria-live': 'polite' });
  async function refresh() {
    const items = await list();
    const done = () => reloadPage();
    fill(host, items.length
      ? [h('details', { 'data-testid': `deleted-${what}s-details` },
        h('summary', null, `Deleted ${what}s (${items.length})`),
        h('ul', { class: 'plain' }, items.map((x) => deletedRow(x, `${what} ${x.name}`, href(x), restore, done, msg, needs)))), msg]
      : []);
  }
  refresh().catch((e) => fill(host, h('p', { class: 'error-text' }, e.message)));
  return host;
}

/** Vessel pages: the control and the list section. */
export const vesselTrash = {
  control: (v) => deleteControl({
    what: 'vessel', item: v, needs: 'engineer',
    consequence: 'It and its campaigns leave the lists; campaigns, runs and models stay readable by id.',
    del: api.deleteVessel, restore: api.restoreVessel,
  }),
  list: () => deletedListSection({ what: 'vessel', list: api.deletedVessels, href: (v) => `#/vessels/${v.id}`, restore: api.restoreVessel, needs: 'engineer' }),
};

/** Campaign pages: the control and the list section. */
export const campaignTrash = {
  control: (c) => deleteControl({
    what: 'campaign', item: c, needs: 'supervisor',
    consequence: 'It leaves the lists; its runs and models stay readable by id, so every model keeps its provenance.',
    del: api.deleteCampaign, restore: api.restoreCampaign,
  }),
  list: () => deletedListSection({ what: 'campaign', list: api.deletedCampaigns, href: (c) => `#/campaigns/${c.id}`, restore: api.restoreCampaign, needs: 'supervisor' }),
};
