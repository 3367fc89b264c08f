// Predicted precision in a real (headless) Chromium, on the demo's supply
// vessel: the campaign page predicts how precisely its plan will determine
// θ″ before it is flown (a `precision` job), shows the table, the weakest
// parameters and how it was predicted, and marks the prediction stale once
// the plan changes.
//
//   cd web && npm ci && node --test tests/precision.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid } from './harness.mjs';

const H = harness({ extraArgs: ['--demo'] });
let cid;

before(async () => {
  await H.start();
  const cs = await H.api('GET', '/api/campaigns');
  const dp = cs.json.find((c) => /Supply vessel/.test(JSON.stringify(c)));
  assert.ok(dp, 'the demo has the DP campaign');
  cid = dp.id;
});

after(() => H.stop());

test('predict the supply vessel plan\'s precision, then see it go stale after a re-plan', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const form = page.getByRole('form', { name: 'Predict precision' });
    await form.waitFor();
    await page.locator(tid('precision-none')).waitFor();
    await page.locator(tid('precision-prior')).selectOption('reference');
    await page.locator(tid('precision-realisations')).fill('4');
    await page.getByRole('button', { name: 'Predict precision' }).click();
    await page.locator(tid('precision-summary')).waitFor({ timeout: 120000 });
    const summary = await page.textContent(tid('precision-summary'));
    assert.match(summary, /\d of 9 parameters determined \(relative std ≤ 10 %\) by 8 runs in \d+\.\d h of ship time · spread of 4 simulated flights · parallel EKF · prior: the source documents’ vessel/);
    assert.equal(await page.locator(`${tid('precision-weakest')} li`).count(), 5);
    assert.match(await page.textContent(tid('precision-weakest')), /θ″\d \(\S+\): ±\S+ Bis \(\S+ % of /);
    assert.equal(await page.locator(tid('precision-row')).count(), 9);
    const stds = await page.locator(`${tid('precision-row')} td:nth-child(4)`).allTextContents();
    assert.ok(stds.every((s) => /^±\S+/.test(s)), `± std on every θ″: ${stds}`);
    assert.equal(await page.locator(tid('precision-stale')).count(), 0);

    // The plan changes: the prediction is kept but marked stale.
    const r = await H.api('POST', `/api/campaigns/${cid}/plan`, { durations: { setup_s: 95 } });
    assert.equal(r.status, 201, JSON.stringify(r.json));
    await page.reload();
    await page.locator(tid('precision-stale')).waitFor();
    assert.match(await page.textContent(tid('precision-stale')), /plan v1; the plan has changed since/);
  });
});
