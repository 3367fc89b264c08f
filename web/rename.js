// Renaming from the browser: a "Rename" button beside a page's title opens
// an inline form with the current name; Save PATCHes it through `save` and
// redraws the page, a 422 (empty, too long) is shown under the field.

import { h, fill, reloadPage } from './forms.js';

/**
 * The rename control of a page. `what` names the thing ("vessel"), `needs`
 * the least role that may rename it (hidden below it), `save(name)` the
 * PATCH (a promise).
 */
export function renameControl({ what, name, needs, save }) {
  const host = h('span', { class: 'rename', 'data-needs': needs });
  function closed() {
    fill(host, h('button', {
      type: 'button', class: 'btn small', 'data-testid': 'rename', 'aria-label': `Rename this ${what}`, onclick: opened,
    }, 'Rename'));
  }
  function opened() {
    const input = h('input', {
      type: 'text', value: name, maxlength: 200, required: true, 'aria-label': `New name of the ${what}`, 'data-testid': 'rename-input',
    });
    const msg = h('span', { 'aria-live': 'polite' });
    const form = h('form', {
      class: 'rename-form actions', 'data-testid': 'rename-form',
      onsubmit: (ev) => {
        ev.preventDefault();
        save(input.value).then(() => reloadPage(), (e) => {
          fill(msg, h('span', { class: 'error-text', role: 'alert', 'data-testid': 'rename-error' }, e.message));
        });
      },
    }, input,
    h('button', { type: 'submit', class: 'btn small primary', 'data-testid': 'rename-save' }, 'Save'),
    h('button', { type: 'button', class: 'btn small', 'data-testid': 'rename-cancel', onclick: closed }, 'Cancel'), msg);
    fill(host, form);
    input.focus();
    input.select();
  }
  closed();
  return host;
}
