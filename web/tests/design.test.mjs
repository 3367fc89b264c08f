// Experiment design in a real (headless) Chromium: on a two-speed Surveyor
// campaign the page designs the campaign for precision per ship-hour (a
// `design` job), shows the ship-hour ratio to today's rules, the per-DOF
// choices and the trade-off plot, and adopts the design by re-planning —
// after which the plan is a new version and the design is marked stale.
//
//   cd web && npm ci && node --test tests/design.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { SURVEYOR_ROV } from '../templates.js';
import { harness, tid } from './harness.mjs';

const H = harness();
let cid;

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Design ROV' });
  assert.equal(v.status, 201, JSON.stringify(v.json));
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Designed trial', seed: 11,
    grid: { unit: 'kn', speeds: [0, 1.5] },
    families: ['static', 'dynamic', 'recursive', 'validation'],
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  const p = await H.api('POST', `/api/campaigns/${cid}/plan`);
  assert.equal(p.status, 201, JSON.stringify(p.json));
});

after(() => H.stop());

test('design the campaign for its ship hours, read the trade-off, adopt it', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.getByRole('form', { name: 'Design campaign' }).waitFor();
    await page.locator(tid('design-none')).waitFor();
    await page.locator(tid('design-prior')).selectOption('reference');
    await page.getByRole('button', { name: 'Design campaign' }).click();
    await page.locator(tid('design-summary')).waitFor({ timeout: 120000 });
    const summary = await page.textContent(tid('design-summary'));
    assert.match(summary, /^Within \d+\.\d+ h: the design flies \d+\.\d+ h with every std ×0\.\d+ of the current plan’s \(geometric mean\)\. Today’s rules need \d+\.\d h for the same precision: \d+\.\d× the ship time/);
    const ratio = Number((await page.textContent(tid('design-ratio'))).replace('×', ''));
    assert.ok(ratio > 1, `the design saves ship time: ${ratio}`);
    assert.equal(await page.locator(tid('design-choice')).count(), 6);
    const plot = page.locator(tid('design-plot'));
    assert.ok(await plot.locator('polyline.designed').count() === 1);
    assert.ok(await plot.locator('polyline.rule').count() === 1);
    assert.ok(await plot.locator('circle.designed').count() >= 2);
    await plot.locator(tid('design-plot-chosen')).waitFor();
    assert.equal(await page.locator(tid('design-stale')).count(), 0);

    // Adopt: the campaign is re-planned with the design; the page redraws
    // with plan v2 and the design is kept, marked stale.
    await page.locator(tid('design-adopt')).click();
    await page.locator(tid('design-stale')).waitFor();
    assert.match(await page.textContent(tid('design-stale')), /plan v1; the plan has changed since/);
    const plan = await H.api('GET', `/api/campaigns/${cid}/plan`);
    assert.equal(plan.json.version, 2);
    const d = await H.api('GET', `/api/campaigns/${cid}/design`);
    assert.ok(Math.abs(plan.json.totals.total_time_s / 3600 - d.json.design.design.hours) < 1e-9);
  });
});

test('propose the next dive before any run is flown, and open its run sheet', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.getByRole('form', { name: 'Propose next dive' }).waitFor();
    await page.locator(tid('next-dive-none')).waitFor();
    await page.locator(tid('next-dive-prior')).selectOption('reference');
    await page.locator(tid('next-dive-hours')).fill('1.5');
    await page.getByRole('button', { name: 'Propose next dive' }).click();
    await page.locator(tid('next-dive-summary')).waitFor({ timeout: 120000 });
    assert.match(await page.textContent(tid('next-dive-summary')),
      /^0 flown runs counted: stds not yet identifiable the whole plan’s now; \d+ runs? in \d\.\d\d h of the 1\.5 h dive bring them to ×\d\.\d+/);
    const codes = await page.locator(`${tid('next-dive-row')} td:nth-child(2)`).allTextContents();
    assert.ok(codes.length >= 2, codes.join());
    assert.match(codes[0], /^VAL-/);
    assert.match(await page.locator(`${tid('next-dive-row')} td:nth-child(5)`).first().textContent(), /no validation run has been flown/);
    // The run sheet lists the proposal in its order.
    const href = await page.locator(tid('next-dive-sheet')).getAttribute('href');
    const sheet = await page.request.get(`${H.base}${href}`);
    assert.equal(sheet.status(), 200);
    const html = await sheet.text();
    assert.match(html, /<h1>Next dive: Designed trial<\/h1>/);
    let at = 0;
    for (const c of codes) {
      const i = html.indexOf(c, at);
      assert.ok(i >= 0, `${c} in order on the run sheet`);
      at = i;
    }
  });
});
