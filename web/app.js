// seatrial planner: hash router and page shell.
//   #/vessels  #/vessels/new[?from=id]  #/vessels/{id}
//   #/campaigns  #/campaigns/new[?vessel=id]  #/campaigns/{id}[/experiments/{eid}]
//   #/runs/{id}  #/models/{id}  #/discrepancies/{id}  #/account

import { api, ApiError } from './api.js';
import { h, fill, banner, clearBanner, showFlash } from './forms.js';
import { vesselList, vesselPage, vesselForm } from './vessels.js';
import { campaignList, campaignForm } from './campaigns.js';
import { campaignPage } from './plan.js';
import { runPage } from './runpage.js';
import { modelPage } from './modelpage.js';
import { discoveryPage } from './discoverypage.js';
import { destroyPlots } from './plots.js';
import { whoAmI, loginForm } from './account.js';
import { accountPage } from './accountpage.js';
import { installTouchHelp } from './help.js';

const view = document.getElementById('view');
let current = null; // controller of the page shown (campaign page), if any
let seq = 0;

function parse() {
  const raw = location.hash.replace(/^#\/?/, '');
  const [path, qs] = raw.split('?');
  const parts = path.split('/').filter(Boolean).map(decodeURIComponent);
  return { parts, query: new URLSearchParams(qs || '') };
}

/** The page's `data-page-*` attributes (e.g. a deleted campaign) moved onto #view, for style.css. */
function pageState(from) {
  for (const a of [...view.attributes]) if (a.name.startsWith('data-page-')) view.removeAttribute(a.name);
  if (from) for (const a of [...from.attributes]) if (a.name.startsWith('data-page-')) view.setAttribute(a.name, a.value);
}

async function route() {
  const { parts, query } = parse();
  const my = ++seq;
  const section = parts[0] || 'campaigns';
  const navSection = ['runs', 'models', 'discrepancies'].includes(section) ? 'campaigns' : section; // runs and models live in their campaign
  document.querySelectorAll('[data-nav]').forEach((a) => a.classList.toggle('active', a.dataset.nav === navSection));

  // Experiment routes of the campaign already shown: no reload.
  if (section === 'campaigns' && parts[1] && parts[1] !== 'new' && current && current.key === `campaign:${parts[1]}`) {
    await current.select(parts[2] === 'experiments' ? parts[3] : null);
    return;
  }
  if (current && current.destroy) current.destroy();
  current = null;
  destroyPlots();
  clearBanner();
  fill(view, h('p', { class: 'loading' }, h('span', { class: 'spinner', 'aria-hidden': 'true' }), 'Loading…'));
  pageState(null);
  const target = h('div');
  try {
    let ctl = null;
    if (section === 'vessels') {
      if (!parts[1]) await vesselList(target);
      else if (parts[1] === 'new') await vesselForm(target, query);
      else await vesselPage(target, parts[1]);
    } else if (section === 'campaigns') {
      if (!parts[1]) await campaignList(target);
      else if (parts[1] === 'new') await campaignForm(target, query);
      else ctl = await campaignPage(target, parts[1]);
    } else if (section === 'runs' && parts[1]) {
      ctl = await runPage(target, parts[1]);
    } else if (section === 'models' && parts[1]) {
      ctl = await modelPage(target, parts[1]);
    } else if (section === 'discrepancies' && parts[1]) {
      ctl = await discoveryPage(target, parts[1]);
    } else if (section === 'account') {
      await accountPage(target);
    } else {
      target.append(h('h1', null, 'Not found'), h('p', null, h('a', { href: '#/campaigns' }, 'Campaigns')));
    }
    if (my !== seq) { if (ctl && ctl.destroy) ctl.destroy(); return; }
    fill(view, ...target.childNodes);
    pageState(target);
    current = ctl;
    showFlash();
    const h1 = view.querySelector('h1');
    document.title = `${h1 ? `${h1.firstChild.textContent} · ` : ''}seatrial planner`;
    if (ctl && ctl.mount) await ctl.mount(); // plots need the page in the document
    if (ctl && parts[2] === 'experiments' && parts[3]) await ctl.select(parts[3]);
  } catch (err) {
    if (my !== seq) return;
    // Signed out (or the session ended): sign in, then show the page asked for.
    if (err instanceof ApiError && err.status === 401) {
      await whoAmI().catch(() => null);
      loginForm(view, route);
      return;
    }
    if (!(err instanceof ApiError)) console.error(err); // a bug, not an API answer
    fill(view, h('h1', null, 'Could not load this page'), h('p', { class: 'error-text' }, err.message));
    banner(`${err.status ? `${err.status} · ` : ''}${err.message}`);
  }
}

async function health() {
  const el = document.getElementById('health');
  try {
    const x = await api.health();
    el.textContent = `● ${x.status} · v${x.version}`;
    el.className = 'health ok';
  } catch (err) {
    el.textContent = `● ${err.message}`;
    el.className = 'health bad';
  }
}

window.addEventListener('hashchange', route);
// A page asks to be drawn again (forms.js reloadPage), even the campaign shown.
window.addEventListener('seatrial:reload', () => {
  if (current && current.destroy) current.destroy();
  current = null;
  route();
});
installTouchHelp();
if (!location.hash) history.replaceState(null, '', '#/campaigns');
// Who is signed in decides what is shown: the sign-in form, or the page
// with the controls of the role.
whoAmI().then(
  (me) => (me ? route() : loginForm(view, route)),
  () => route(), // the page shows what is wrong
);
health();
