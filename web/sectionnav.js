// A page's section bar: one button per section (`[key, label]`) that
// scrolls to the element of the page marked `data-section="key"`. Buttons,
// not `#` anchors: the hash is the router's. The bar sticks under the header
// and wraps on a phone.

import { h } from './forms.js';

export function sectionNav(sections) {
  return h('nav', { class: 'section-nav', 'aria-label': 'Sections of this page', 'data-testid': 'section-nav' },
    sections.map(([key, label]) => h('button', {
      type: 'button', class: 'btn small', 'data-testid': `goto-${key}`,
      onclick: () => {
        const el = document.querySelector(`[data-section="${key}"]`);
        if (el) el.scrollIntoView({ block: 'start' });
      },
    }, label)));
}
