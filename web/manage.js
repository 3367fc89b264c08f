// Managing stored data from the browser: exclude a run from identification
// (with a reason) or include it again, delete a run, delete a model version.
// Deleting asks for confirmation in the page; a 409 from the server (a model
// built from the run, a version derived from the model) is shown as it is,
// naming what stands in the way.

import { api } from './api.js';
import { h, fill } from './forms.js';

function errorBox(host, err) {
  fill(host, h('p', { class: 'error-text', role: 'alert', 'data-testid': 'manage-error' }, err.message));
}

/** Asks in the page before `run()`; `label` says what goes. */
function confirmBox(host, { question, label, run, extra }) {
  const box = h('div', { class: 'confirm-box', role: 'alertdialog', 'aria-label': question, 'data-testid': 'confirm-box' },
    h('p', null, question),
    h('div', { class: 'actions' },
      h('button', { type: 'button', class: 'btn danger', 'data-testid': 'confirm-yes', onclick: run }, label),
      h('button', { type: 'button', class: 'btn', 'data-testid': 'confirm-no', onclick: () => fill(host) }, 'Cancel')),
    extra || null);
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
      onclick: () => confirmBox(msg, {
        question: `Delete run “${r.name}” and its stored files? This cannot be undone.`,
        label: 'Delete run',
        run: () => api.deleteRun(r.id).then(() => { location.hash = `#/campaigns/${r.campaign_id}`; }, (e) => errorBox(msg, e)),
      }),
    }, 'Delete run…');
    fill(host, h('h2', null, 'Manage ', h('span', { class: 'hint' }, 'an excluded run stays listed; identification leaves it out unless a job names it')),
      toggle, h('div', { class: 'actions' }, del), msg);
    fill(msg);
  }
  render(run);
  return host;
}

/** Model page: delete this version (with the versions derived from it, if asked). */
export function modelDeleteControl(model) {
  const msg = h('div', { 'aria-live': 'polite' });
  const gone = () => { location.hash = `#/campaigns/${model.campaign_id}`; };
  const del = (cascade) => api.deleteModel(model.id, cascade).then(gone, (e) => {
    errorBox(msg, e);
    if (e.status === 409 && /cascade/.test(e.message)) {
      msg.append(h('button', {
        type: 'button', class: 'btn danger', 'data-testid': 'delete-model-cascade',
        onclick: () => confirmBox(msg, {
          question: `Delete v${model.version} and every version derived from it?`,
          label: 'Delete them all',
          run: () => del(true),
        }),
      }, 'Delete with the derived versions…'));
    }
  });
  return h('div', { class: 'manage', 'data-testid': 'model-manage', 'data-needs': 'engineer' },
    h('button', {
      type: 'button', class: 'btn danger small', 'data-testid': 'delete-model',
      onclick: () => confirmBox(msg, {
        question: `Delete model “${model.name}” v${model.version} with its discovery reports? The runs stay.`,
        label: 'Delete version',
        run: () => del(false),
      }),
    }, 'Delete version…'),
    msg);
}
