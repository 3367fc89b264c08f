// Accounts in the UI: who is signed in (name and role in the header, a
// sign-out button), the sign-in form shown when the service requires
// credentials and nobody is signed in, and the role on <body data-role>:
// style.css hides the write controls (marked data-needs="supervisor" …)
// the role may not use. The server enforces the roles either way.

import { api, ApiError } from './api.js';
import { h, fill } from './forms.js';

let me = null;

/** Who is signed in: the /api/auth/me answer, or null (401). */
export async function whoAmI() {
  try {
    me = await api.me();
  } catch (err) {
    if (!(err instanceof ApiError) || err.status !== 401) throw err;
    me = null;
  }
  show();
  return me;
}

function show() {
  const el = document.getElementById('account');
  if (me) document.body.dataset.role = me.role;
  else delete document.body.dataset.role;
  if (!el) return;
  if (!me) { fill(el); el.hidden = true; return; }
  el.hidden = false;
  const local = me.via === 'local';
  fill(el,
    h('a', { href: '#/account', 'data-testid': 'account-name', title: 'your account: password, API tokens' + (me.role === 'admin' ? ', users' : '') }, local ? 'local' : me.name),
    ' · ',
    h('span', { class: 'badge neutral', 'data-testid': 'account-role', title: local ? 'local mode: no sign-in on this loopback address' : 'your role' }, me.role),
    local ? null : h('button', { type: 'button', class: 'btn small', 'data-testid': 'logout', onClick: logout }, 'Sign out'));
}

async function logout() {
  await api.logout();
  me = null;
  show();
  loginForm(document.getElementById('view'), () => window.dispatchEvent(new HashChangeEvent('hashchange')));
}

/** The sign-in form in `host`; `done()` after signing in. */
export function loginForm(host, done) {
  const name = h('input', { type: 'text', name: 'username', autocomplete: 'username', required: true, 'data-testid': 'login-name' });
  const password = h('input', { type: 'password', name: 'password', autocomplete: 'current-password', required: true, 'data-testid': 'login-password' });
  const msg = h('p', { class: 'error-text', role: 'alert', 'data-testid': 'login-error' });
  const submit = h('button', { type: 'submit', class: 'btn primary', 'data-testid': 'login-submit' }, 'Sign in');
  const form = h('form', {
    class: 'card form login', 'data-testid': 'login-form', 'aria-label': 'Sign in',
    onSubmit: async (e) => {
      e.preventDefault();
      submit.disabled = true;
      fill(msg);
      try {
        me = await api.login(name.value, password.value);
        show();
        done();
      } catch (err) {
        fill(msg, err.status === 401 ? 'Wrong name or password.' : err.message);
        password.select();
      } finally {
        submit.disabled = false;
      }
    },
  },
  h('label', null, 'Name ', name),
  h('label', null, 'Password ', password),
  h('div', { class: 'actions' }, submit),
  msg);
  fill(host, h('h1', null, 'Sign in'), h('p', { class: 'hint' }, 'This service requires an account. Ask an admin for one.'), form);
  document.title = 'Sign in · seatrial planner';
  name.focus();
}
