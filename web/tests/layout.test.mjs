// Layout in a real (headless) Chromium: no page scrolls sideways on a
// 390 px phone or a 1440 px laptop (document width ≤ window width, with the
// elements that stick out named on failure); the campaign page has its
// section bar and pages its run list; help for domain terms (title
// attributes) opens on a tap.
//
//   cd web && npm ci && node --test tests/layout.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid, uploadRun } from './harness.mjs';
import { simulate, csv, ALL_COLUMNS } from './sim.mjs';
import { SURVEYOR_ROV } from '../templates.js';

const KN = 1852 / 3600;
const H = harness();
const ids = {};

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (layout e2e)' });
  ids.vessel = v.json.id;
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Layout e2e', grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 5,
  });
  ids.campaign = c.json.id;
  const plan = await H.api('POST', `/api/campaigns/${ids.campaign}/plan`);
  ids.experiment = plan.json.experiments[0].id;
  const amp = [300, 600, 600, 300, 300, 300];
  const runs = [];
  for (const [seed, role] of [[31, 'dynamic'], [32, 'dynamic'], [33, 'validation']]) {
    const run = simulate({ seed, fs: 10, duration: role === 'validation' ? 320 : 180, amp, clock: 2, noise: 1e-4, surge: 1 * KN });
    runs.push((await uploadRun(H, ids.campaign, csv(run, ALL_COLUMNS), { name: `${role} ${seed} with a rather long name to wrap`, role, grid_speed_kn: 1 })).id);
  }
  ids.run = runs[0];
  const j = await H.api('POST', '/api/jobs', { kind: 'identify', campaign_id: ids.campaign, method: 'n4sid' });
  for (let i = 0; i < 1200; i += 1) {
    const s = await H.api('GET', `/api/jobs/${j.json.id}`);
    if (s.json.state === 'succeeded') { ids.model = s.json.result.model_id; break; }
    assert.ok(!['failed', 'cancelled', 'interrupted'].includes(s.json.state), JSON.stringify(s.json));
    await new Promise((r) => { setTimeout(r, 100); });
  }
  assert.ok(ids.model, 'identification did not finish in 120 s');
});

after(() => H.stop());

const PAGES = () => [
  ['vessels', '#/vessels', 'h1'],
  ['new vessel', '#/vessels/new', 'form'],
  ['vessel', `#/vessels/${ids.vessel}`, 'h1'],
  ['campaigns', '#/campaigns', 'h1'],
  ['new campaign', '#/campaigns/new', 'form'],
  ['campaign', `#/campaigns/${ids.campaign}`, tid('run-row')],
  ['experiment', `#/campaigns/${ids.campaign}/experiments/${ids.experiment}`, tid('experiment-code')],
  ['run', `#/runs/${ids.run}`, tid('run-title')],
  ['model', `#/models/${ids.model}`, tid('model-title')],
];

for (const [width, height] of [[390, 844], [1440, 900]]) {
  test(`no page scrolls sideways at ${width} px`, async () => {
    const context = await H.browser.newContext({ viewport: { width, height }, hasTouch: width < 500, isMobile: width < 500 });
    const page = await context.newPage();
    page.setDefaultTimeout(15000);
    const wide = [];
    try {
      for (const [name, hash, ready] of PAGES()) {
        await page.goto(`${H.base}/${hash}`);
        await page.locator(ready).first().waitFor();
        await page.waitForTimeout(400); // plots size themselves after a frame
        // Against the viewport's width: a phone browser widens its layout
        // viewport (innerWidth) to content that overflows.
        const m = await page.evaluate((w) => {
          const out = [];
          for (const el of document.querySelectorAll('body *')) {
            const r = el.getBoundingClientRect();
            if (r.width && r.right > w + 1 && !el.closest('.table-x, .table-scroll, .cov-scroll, [data-scroll-x]')) {
              out.push(`${el.tagName.toLowerCase()}${el.dataset.testid ? `[${el.dataset.testid}]` : ''}.${el.className || ''} right=${Math.round(r.right)}`);
            }
          }
          return { scroll: document.documentElement.scrollWidth, inner: w, out: out.slice(0, 6) };
        }, width);
        if (m.scroll > m.inner) wide.push(`${name} (${hash}): scrollWidth ${m.scroll} > ${m.inner}: ${m.out.join(' | ')}`);
      }
    } finally {
      await context.close();
    }
    assert.deepEqual(wide, [], 'pages wider than the window');
  });
}

test('the campaign page has a section bar, and help opens on a tap', async () => {
  const context = await H.browser.newContext({ viewport: { width: 390, height: 844 }, hasTouch: true, isMobile: true });
  const page = await context.newPage();
  page.setDefaultTimeout(15000);
  try {
    await page.goto(`${H.base}/#/campaigns/${ids.campaign}`);
    await page.locator(tid('section-nav')).waitFor();
    for (const key of ['runs', 'coverage', 'jobs', 'models', 'plan', 'deleted']) {
      assert.equal(await page.locator(`[data-section="${key}"]`).count(), 1, key);
    }
    await page.tap(tid('goto-models'));
    await page.waitForFunction(() => {
      const r = document.querySelector('[data-section="models"]').getBoundingClientRect();
      return r.top >= 0 && r.top < window.innerHeight;
    });
    // A verdict badge explains itself on a tap.
    const badge = page.locator(tid('verdict-badge')).first();
    const title = await badge.getAttribute('title');
    await badge.scrollIntoViewIfNeeded();
    await badge.tap();
    await page.locator(tid('help-pop')).waitFor();
    assert.equal(await page.textContent(tid('help-pop')), title);
    await page.tap('h1');
    await page.locator(tid('help-pop')).waitFor({ state: 'detached' });
  } finally {
    await context.close();
  }
});
