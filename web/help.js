// Help that a finger can reach: the explanations of domain terms live in
// `title` attributes (badges, coverage chips, column heads), which only a
// mouse hover shows. A tap (or click) on such an element — one that is not
// itself a link, button or field — opens the same text in a small popover
// under it; a second tap, a tap elsewhere or Escape closes it.

const POP_ID = 'help-pop';

function close() {
  const pop = document.getElementById(POP_ID);
  if (pop) pop.remove();
}

function open(el, text) {
  close();
  const pop = document.createElement('div');
  pop.id = POP_ID;
  pop.className = 'help-pop';
  pop.setAttribute('role', 'tooltip');
  pop.dataset.testid = 'help-pop';
  pop.textContent = text;
  document.body.appendChild(pop);
  const r = el.getBoundingClientRect();
  const w = Math.min(320, window.innerWidth - 16);
  pop.style.maxWidth = `${w}px`;
  const left = Math.max(8, Math.min(r.left + window.scrollX, window.scrollX + window.innerWidth - w - 8));
  pop.style.left = `${left}px`;
  pop.style.top = `${r.bottom + window.scrollY + 4}px`;
  pop.helpFor = el;
}

/** Installs the tap handler once for the whole page. */
export function installTouchHelp() {
  document.addEventListener('click', (ev) => {
    const target = ev.target instanceof Element ? ev.target : null;
    const pop = document.getElementById(POP_ID);
    const el = target && target.closest('[title]');
    if (!el || el.closest('a, button, input, select, textarea, label, summary') || !el.getAttribute('title')) {
      if (pop && !(target && target.closest(`#${POP_ID}`))) close();
      return;
    }
    if (pop && pop.helpFor === el) { close(); return; }
    open(el, el.getAttribute('title'));
  });
  document.addEventListener('keydown', (ev) => { if (ev.key === 'Escape') close(); });
  window.addEventListener('hashchange', close);
}
