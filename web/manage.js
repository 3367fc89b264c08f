// Managing stored data from the browser: exclude a run from identification
// (with a reason) or include it again, delete a run or a model version (a
// soft delete, with an optional reason) and undo it, rename a model.
// Deleting asks for confirmation in the page; a 409 from the server (a
// version derived from the model, a job working on it) is shown as it is,
// naming what stands in the way.

import { api } from './api.js';
import { h, fill, reloadPage } from './forms.js';
import { fmtDate } from './format.js';
import { renameControl } from './rename.js';

function errorBox(host, err) {
  fill(host, h('p', { class: 'error-text', role: 'alert', 'data-testid': 'manage-error' }, err.message));
}

/** Asks in the page before `run()`; `label` says what goes. */
export function confirmBox(host, { question, label, run, extra }) {
  const box = h('div', { class: 'confirm-box', role: 'alertdialog', 'aria-label': question, 'data-testid': 'confirm-box' },
    h('p', null, question),
    extra || null,
    h('div', { class: 'actions' },
      h('button', { type: 'button', class: 'btn danger', 'data-testid': 'confirm-yes', onclick: run }, label),
      h('button', { type: 'button', class: 'btn', 'data-testid': 'confirm-no', onclick: () => fill(host) }, 'Cancel')));
  fill(host, box);
  box.querySelector('[data-testid="confirm-no"]').focus();
}

/** Excluded badge for lists and titles. */
export function excludedBadge(run) {
  return run.excluded
    ? h('span', { class: 'badge weak', title: run.excluded_reason || '', 'data-testid': 'run-excluded' }, 'excluded')
    : null;
}

/** Run page: exclude/include and delete. */
export function runManageSection(run) {
  const host = h('section', { class: 'manage', 'aria-label': 'Manage this run', 'data-testid': 'run-manage', 'data-needs': 'supervisor' });
  const msg = h('div', { 'aria-live': 'polite' });
  function render(r) {
    const reason = h('input', {
      type: 'text', maxlength: 2000, placeholder: 'why (e.g. thruster 2 failed)', 'aria-label': 'Reason for excluding', 'data-testid': 'exclude-reason',
    });
    const toggle = r.excluded
      ? h('div', { class: 'actions' },
        h('span', { 'data-testid': 'excluded-note' }, excludedBadge(r), ` left out of identification: ${r.excluded_reason || ''}`),
        h('button', {
          type: 'button', class: 'btn', 'data-testid': 'include-run',
          onclick: () => api.describeRun(r.id, { excluded: false }).then(render, (e) => errorBox(msg, e)),
        }, 'Include again'))
      : h('form', {
        class: 'actions', 'data-testid': 'exclude-form',
        onsubmit: (ev) => {
          ev.preventDefault();
          api.describeRun(r.id, { excluded: true, excluded_reason: reason.value }).then(render, (e) => errorBox(msg, e));
        },
      }, reason, h('button', { type: 'submit', class: 'btn', 'data-testid': 'exclude-run' }, 'Exclude from identification'));
    const del = h('button', {
      type: 'button', class: 'btn danger', 'data-testid': 'delete-run',
      onclick: () => {
        const why = reasonInput();
        confirmBox(msg, {
          question: `Delete run “${r.name}”? It leaves the lists and identification; models built from it keep their provenance, and Undo brings it back.`,
          label: 'Delete run',
          extra: why,
          run: () => api.deleteRun(r.id, why.value).then(reloadPage, (e) => errorBox(msg, e)),
        });
      },
    }, 'Delete run…');
    if (r.deleted_at) {
      fill(host, h('h2', null, 'Manage'), deletedNote(r, () => api.restoreRun(r.id).then(reloadPage, (e) => errorBox(msg, e))), msg);
    } else {
      fill(host, h('h2', null, 'Manage ', h('span', { class: 'hint' }, 'an excluded run stays listed; identification leaves it out unless a job names it')),
        toggle, h('div', { class: 'actions' }, del), msg);
    }
    fill(msg);
  }
  render(run);
  return host;
}

/** The reason field of a delete confirmation. */
export function reasonInput() {
  return h('input', {
    type: 'text', maxlength: 2000, placeholder: 'why (optional, kept in the audit trail)', 'aria-label': 'Reason for deleting', 'data-testid': 'delete-reason',
  });
}

/** "Deleted by … at …: why" with the Undo button (`restore`). */
export function deletedNote(item, restore) {
  return h('div', { class: 'deleted-note', role: 'status', 'data-testid': 'deleted-note' },
    h('span', { class: 'badge bad' }, 'deleted'),
    ` by ${item.deleted_by || '?'} at ${fmtDate(item.deleted_at)}${item.delete_reason ? ` — ${item.delete_reason}` : ''} `,
    h('button', { type: 'button', class: 'btn', 'data-testid': 'undo-delete', onclick: restore }, 'Undo (restore)'));
}

/** "deleted" badge for titles. */
export function deletedBadge(item) {
  return item.deleted_at ? h('span', { class: 'badge bad', 'data-testid': 'deleted-badge' }, 'deleted') : null;
}

/** Model page: rename, delete this version (with the versions derived from it, if asked) and undo. */
export function modelManageControls(model) {
  const host = h('div', { class: 'manage', 'data-testid': 'model-manage', 'data-needs': 'engineer' });
  const msg = h('div', { 'aria-live': 'polite' });
  const undo = (ids) => Promise.all(ids.map((id) => api.restoreModel(id)))
    .then(() => reloadPage(), (e) => errorBox(msg, e));
  const done = async (d) => {
    const now = await api.model(model.id).then((v) => v.model, () => model);
    fill(host, deletedNote(now, () => undo(d.deleted)),
      d.deleted.length > 1 ? h('p', { class: 'hint', 'data-testid': 'deleted-count' }, `${d.deleted.length} versions deleted; Undo restores them all`) : null, msg);
  };
  const del = (cascade, why) => api.deleteModel(model.id, cascade, why).then(done, (e) => {
    errorBox(msg, e);
    if (e.status === 409 && /cascade/.test(e.message)) {
      msg.append(h('button', {
        type: 'button', class: 'btn danger', 'data-testid': 'delete-model-cascade',
        onclick: () => confirmBox(msg, {
          question: `Delete v${model.version} and every version derived from it?`,
          label: 'Delete them all',
          run: () => del(true, why),
        }),
      }, 'Delete with the derived versions…'));
    }
  });
  if (model.deleted_at) {
    fill(host, deletedNote(model, () => undo([model.id])), msg);
    return host;
  }
  fill(host,
    renameControl({ what: 'model', name: model.name, needs: 'engineer', save: (n) => api.renameModel(model.id, n) }),
    ' ',
    h('button', {
      type: 'button', class: 'btn danger small', 'data-testid': 'delete-model',
      onclick: () => {
        const why = reasonInput();
        confirmBox(msg, {
          question: `Delete model “${model.name}” v${model.version}? It leaves the lists; Undo brings it back. The runs stay.`,
          label: 'Delete version',
          extra: why,
          run: () => del(false, why.value),
        });
      },
    }, 'Delete version…'),
    msg);
  return host;
}
