// DOM helpers: element builder, banner, and mapping server errors
// (ErrorBody.field, a JSON path) onto the input whose data-field matches.

import { fmt } from './format.js';

const PROPS = new Set(['value', 'checked', 'disabled', 'selected', 'open', 'indeterminate', 'hidden']);

/** h('input', {type: 'number', onInput: fn, 'data-field': 'x'}, ...children) */
export function h(tag, attrs, ...children) {
  const el = document.createElement(tag);
  if (attrs) {
    for (const [k, v] of Object.entries(attrs)) {
      if (v == null || v === false && !PROPS.has(k)) continue;
      if (k.startsWith('on') && typeof v === 'function') el.addEventListener(k.slice(2).toLowerCase(), v);
      else if (PROPS.has(k)) el[k] = v;
      else if (k === 'class') el.className = v;
      else if (k === 'style' && typeof v === 'object') Object.assign(el.style, v);
      else el.setAttribute(k, v === true ? '' : String(v));
    }
  }
  append(el, children);
  return el;
}

function append(el, children) {
  for (const c of children) {
    if (c == null || c === false) continue;
    if (Array.isArray(c)) append(el, c);
    else if (c instanceof Node) el.appendChild(c);
    else el.appendChild(document.createTextNode(String(c)));
  }
}

/** el.replaceChildren(...) that skips null/false and flattens arrays. */
export function fill(el, ...children) {
  el.replaceChildren();
  append(el, children);
  return el;
}

let uid = 0;
export function nextId(prefix = 'f') {
  uid += 1;
  return `${prefix}-${uid}`;
}

/** A labelled control: <label for>text</label> + control, wrapped in .fld */
export function labelled(text, control, hint) {
  if (!control.id) control.id = nextId();
  return h('div', { class: 'fld' },
    h('label', { for: control.id }, text),
    control,
    hint ? h('span', { class: 'hint' }, hint) : null);
}

/** Parse a number input: '' → null, else Number (NaN kept to be reported). */
export function num(v) {
  if (v == null) return null;
  const s = String(v).trim();
  if (s === '') return null;
  return Number(s);
}

// ---- banner ---------------------------------------------------------------

export function banner(message, kind = 'error') {
  const host = document.getElementById('banner');
  host.replaceChildren();
  if (!message) return;
  host.appendChild(h('div', { class: `banner ${kind}`, role: kind === 'error' ? 'alert' : 'status', 'data-testid': `banner-${kind}` },
    h('span', { class: 'banner-text' }, message),
    h('button', { type: 'button', class: 'link', 'aria-label': 'Dismiss', onClick: () => host.replaceChildren() }, '×')));
}

// A message to show after the next navigation (e.g. "created").
let pending = null;
export function flash(message, kind = 'ok') {
  pending = { message, kind };
}
export function showFlash() {
  if (pending) banner(pending.message, pending.kind);
  pending = null;
}

export function clearBanner() {
  document.getElementById('banner').replaceChildren();
}

// ---- field errors -----------------------------------------------------------

/** `a.b[2].c` → `a.b[2]` → `a.b` → `a` → '' */
export function parentPath(path) {
  const m = path.match(/^(.*?)(\[\d+\]|\.[^.[\]]+)$/);
  return m ? m[1] : '';
}

export function clearErrors(root) {
  root.querySelectorAll('.field-error').forEach((e) => e.remove());
  root.querySelectorAll('.invalid').forEach((e) => {
    e.classList.remove('invalid');
    e.removeAttribute('aria-invalid');
  });
}

function findField(root, path) {
  let p = path;
  while (p) {
    const el = root.querySelector(`[data-field="${CSS.escape(p)}"]`);
    if (el) return el;
    p = parentPath(p);
  }
  return null;
}

/**
 * Show one error next to the element whose data-field is `field` (or its
 * nearest ancestor path), with the message and the limit that was broken.
 */
export function showFieldError(root, field, message, limit) {
  const el = field ? findField(root, field) : null;
  if (!el) return null;
  el.classList.add('invalid');
  el.setAttribute('aria-invalid', 'true');
  const host = el.closest('[data-error-host]') || el.parentElement;
  const text = limit != null ? `${message} (limit ${fmt(limit)})` : message;
  const msg = h('div', { class: 'field-error', role: 'alert', 'data-testid': 'field-error', 'data-for': field }, text);
  if (!el.id) el.id = nextId();
  msg.id = `${el.id}-err`;
  el.setAttribute('aria-describedby', msg.id);
  host.appendChild(msg);
  // Reveal it: open collapsed sections and scroll it into view.
  for (let d = el.closest('details'); d; d = d.parentElement && d.parentElement.closest('details')) d.open = true;
  el.scrollIntoView({ block: 'center', behavior: 'instant' });
  if (typeof el.focus === 'function' && el.matches('input,select,textarea')) el.focus({ preventScroll: true });
  return el;
}

/** Show an ApiError (or Error) on a form: banner + field. */
export function showError(root, err) {
  clearErrors(root);
  const status = err.status ? `${err.status} · ` : '';
  const where = err.field ? ` [${err.field}]` : '';
  banner(`${status}${err.message}${where}`);
  if (err.field) showFieldError(root, err.field, err.message, err.limit);
}

/** Draws the page shown again from the server (after a rename, a restore). */
export function reloadPage() {
  window.dispatchEvent(new Event('seatrial:reload'));
}
