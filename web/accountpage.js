// #/account: one's own account (change the password), one's personal API
// tokens (create — the secret is shown once —, list, revoke), and for an
// admin the users (create, change role, disable or enable, set a password).
// The server enforces every rule; this page only offers what the role may do.

import { api, ApiError } from './api.js';
import { h, fill, showError, clearErrors } from './forms.js';
import { whoAmI, loginForm } from './account.js';

const ROLES = ['viewer', 'supervisor', 'engineer', 'admin'];
const rank = (role) => ROLES.indexOf(role);

/** Local date and time of an RFC 3339 instant, or an em dash. */
function when(t) {
  if (!t) return '—';
  const d = new Date(t);
  return Number.isNaN(d.getTime()) ? t : d.toLocaleString(undefined, { dateStyle: 'medium', timeStyle: 'short' });
}

function roleSelect(max, value, testid) {
  return h('select', { 'data-testid': testid },
    ...ROLES.filter((r) => rank(r) <= rank(max)).map((r) => h('option', { value: r, selected: r === value }, r)));
}

export async function accountPage(host) {
  const me = await whoAmI();
  if (!me) throw new ApiError({ status: 401, message: 'sign in first' }, 401);
  const local = me.via === 'local';
  host.append(
    h('h1', null, 'Account'),
    h('p', { class: 'hint' }, local
      ? 'Local mode: this loopback address acts as the local admin, without an account or password.'
      : `Signed in as ${me.name}, role ${me.role}.`));
  if (!local) host.append(passwordSection());
  host.append(await tokenSection(me));
  if (me.role === 'admin') host.append(await userSection(me));
}

/**
 * A create form: on submit clears its errors, runs `act()` (errors shown on
 * the fields they name), then resets and calls `refresh()`.
 */
function createForm(attrs, act, refresh, fields, submitLabel, submitId) {
  const form = h('form', {
    class: 'card form', ...attrs,
    onSubmit: async (e) => {
      e.preventDefault();
      clearErrors(form);
      try {
        await act();
        form.reset();
        await refresh();
      } catch (err) {
        showError(form, err);
      }
    },
  },
  ...fields,
  h('div', { class: 'actions' }, h('button', { type: 'submit', class: 'btn primary', 'data-testid': submitId }, submitLabel)));
  return form;
}

function passwordSection() {
  const current = h('input', { type: 'password', name: 'current_password', autocomplete: 'current-password', required: true, 'data-testid': 'pw-current' });
  const next = h('input', { type: 'password', name: 'new_password', autocomplete: 'new-password', minlength: 8, required: true, 'data-testid': 'pw-new' });
  const again = h('input', { type: 'password', autocomplete: 'new-password', minlength: 8, required: true, 'data-testid': 'pw-again' });
  const msg = h('p', { class: 'error-text', role: 'alert', 'data-testid': 'pw-error' });
  const form = h('form', {
    class: 'card form', 'data-testid': 'password-form', 'aria-label': 'Change password',
    onSubmit: async (e) => {
      e.preventDefault();
      fill(msg);
      clearErrors(form);
      if (next.value !== again.value) { fill(msg, 'The new passwords differ.'); return; }
      try {
        await api.changePassword(current.value, next.value);
        // Every session of the account ended: sign in again.
        loginForm(document.getElementById('view'), () => window.dispatchEvent(new HashChangeEvent('hashchange')));
        await whoAmI().catch(() => null);
      } catch (err) {
        if (err instanceof ApiError && err.status === 429) fill(msg, err.message);
        else showError(form, err);
      }
    },
  },
  h('label', null, 'Current password ', current),
  h('label', null, 'New password (8 characters or more) ', next),
  h('label', null, 'New password again ', again),
  h('div', { class: 'actions' }, h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'pw-submit' }, 'Change password')),
  msg);
  return h('section', { 'aria-labelledby': 'pw-h' }, h('h2', { id: 'pw-h' }, 'Password'),
    h('p', { class: 'hint' }, 'Changing it ends every session of your account (sign in again); API tokens stay valid.'),
    form);
}

async function tokenSection(me) {
  const section = h('section', { 'aria-labelledby': 'tok-h', 'data-testid': 'token-section' });
  const list = h('div');
  const shown = h('div', { 'aria-live': 'polite' });
  const refresh = async () => {
    const tokens = await api.tokens();
    fill(list, tokens.length === 0
      ? h('p', { class: 'hint' }, 'No tokens yet.')
      : h('div', { class: 'table-x' }, h('table', { class: 'grid-table', 'data-testid': 'token-table' },
        h('thead', null, h('tr', null, ...['Name', 'Role', 'Starts with', 'Created', 'Last used', 'Expires', 'State', ''].map((t) => h('th', null, t)))),
        h('tbody', null, ...tokens.map((t) => h('tr', { 'data-testid': `token-${t.name}` },
          h('td', null, t.name), h('td', null, t.role), h('td', null, h('code', null, `${t.prefix}…`)),
          h('td', null, when(t.created_at)), h('td', null, when(t.last_used_at)), h('td', null, t.expires_at ? when(t.expires_at) : 'until revoked'),
          h('td', { 'data-testid': 'token-state' }, t.revoked_at ? `revoked ${when(t.revoked_at)}` : 'valid'),
          h('td', null, t.revoked_at ? null : h('button', {
            type: 'button', class: 'btn small danger', 'data-testid': 'token-revoke',
            onClick: async () => {
              if (!window.confirm(`Revoke the token “${t.name}”? Clients using it stop working at once.`)) return;
              await api.revokeToken(t.id);
              await refresh();
            },
          }, 'Revoke'))))))));
  };
  const name = h('input', { type: 'text', required: true, maxlength: 200, placeholder: 'e.g. MPC design laptop', 'data-testid': 'token-name' });
  const role = roleSelect(me.role, me.role, 'token-role');
  const days = h('input', { type: 'number', min: 1, max: 3650, step: 1, placeholder: 'never', 'data-testid': 'token-days' });
  const form = createForm({ 'data-testid': 'token-form', 'aria-label': 'New API token' }, async () => {
    fill(shown);
    const body = { name: name.value, role: role.value };
    if (days.value) body.expires_in_days = Number(days.value);
    const made = await api.createToken(body);
    const code = h('code', { 'data-testid': 'token-secret' }, made.token);
    fill(shown, h('div', { class: 'card notice', role: 'status' },
      h('p', null, h('strong', null, 'Copy this token now: it is not stored and will not be shown again.')),
      h('p', { class: 'secret' }, code, ' ',
        h('button', { type: 'button', class: 'btn small', onClick: () => navigator.clipboard?.writeText(made.token) }, 'Copy')),
      h('p', { class: 'hint' }, 'Use it as ', h('code', null, 'Authorization: Bearer …'), ' in REST clients.')));
  }, refresh, [
    h('label', null, 'Name ', name),
    h('label', null, 'Role (at most yours) ', role),
    h('label', null, 'Expires after (days, empty: never) ', days),
  ], 'Create token', 'token-create');
  await refresh();
  section.append(h('h2', { id: 'tok-h' }, 'Personal API tokens'),
    h('p', { class: 'hint' }, 'For scripts and REST clients (MATLAB, Python). Stored only as a hash; revoke one you no longer use.'),
    shown, list, form);
  return section;
}

async function userSection(me) {
  const section = h('section', { 'aria-labelledby': 'users-h', 'data-testid': 'user-section' });
  const list = h('div');
  const refresh = async () => {
    const users = await api.users();
    fill(list, h('div', { class: 'table-x' }, h('table', { class: 'grid-table', 'data-testid': 'user-table' },
      h('thead', null, h('tr', null, ...['Name', 'Role', 'State', 'Created', ''].map((t) => h('th', null, t)))),
      h('tbody', null, ...users.map((u) => userRow(u, me, refresh))))));
  };
  const name = h('input', { type: 'text', required: true, maxlength: 200, autocomplete: 'off', 'data-testid': 'user-name' });
  const role = roleSelect('admin', 'viewer', 'user-role');
  const password = h('input', { type: 'password', required: true, minlength: 8, autocomplete: 'new-password', 'data-testid': 'user-password' });
  const form = createForm({ 'data-testid': 'user-form', 'aria-label': 'New user' },
    () => api.createUser({ name: name.value, role: role.value, password: password.value }),
    refresh, [
      h('label', null, 'Login name ', name),
      h('label', null, 'Role ', role),
      h('label', null, 'First password (8 characters or more; tell them to change it) ', password),
    ], 'Create user', 'user-create');
  await refresh();
  section.append(h('h2', { id: 'users-h' }, 'Users'),
    h('p', { class: 'hint' }, 'viewer: reads · supervisor: plans, uploads, runs jobs · engineer: also edits models and settings · admin: also users and tokens. Every action is recorded with who did it.'),
    list, form);
  return section;
}

function userRow(u, me, refresh) {
  const msg = h('span', { class: 'error-text', role: 'alert' });
  const act = (fn) => async () => {
    fill(msg);
    try { await fn(); await refresh(); } catch (err) { fill(msg, err.message); }
  };
  const role = roleSelect('admin', u.role, 'user-row-role');
  role.addEventListener('change', act(() => api.changeUser(u.id, { role: role.value })));
  return h('tr', { 'data-testid': `user-${u.name}` },
    h('td', null, u.name, u.id === me.user_id ? ' (you)' : ''),
    h('td', null, role),
    h('td', { 'data-testid': 'user-state' }, u.disabled ? `disabled ${when(u.disabled_at)}` : 'active'),
    h('td', null, when(u.created_at)),
    h('td', { class: 'actions' },
      h('button', {
        type: 'button', class: `btn small${u.disabled ? '' : ' danger'}`, 'data-testid': 'user-toggle',
        onClick: act(() => api.changeUser(u.id, { disabled: !u.disabled })),
      }, u.disabled ? 'Enable' : 'Disable'),
      h('button', {
        type: 'button', class: 'btn small', 'data-testid': 'user-set-password',
        onClick: act(async () => {
          const pw = window.prompt(`New password for ${u.name} (8 characters or more; their sessions end):`);
          if (pw) await api.changeUser(u.id, { password: pw });
        }),
      }, 'Set password'),
      msg));
}
