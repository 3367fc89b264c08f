// Managing runs and models in a real (headless) Chromium: a run is excluded
// from identification with a reason and included again, a run a model was
// built from is kept (the 409 names the model), a model version another was
// derived from is deleted only with its derived versions, and a run is
// deleted after confirmation — each checked against the API.
//
//   cd web && npm ci && node --test tests/manage.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid, uploadRun } from './harness.mjs';
import { simulate, csv, ALL_COLUMNS } from './sim.mjs';
import { SURVEYOR_ROV } from '../templates.js';

const KN = 1852 / 3600;
const H = harness();
let cid;
const runs = []; // ids: two estimation runs, one validation run

async function identify() {
  const r = await H.api('POST', '/api/jobs', { kind: 'identify', campaign_id: cid, method: 'n4sid' });
  assert.equal(r.status, 202, JSON.stringify(r.json));
  for (let i = 0; i < 1200; i += 1) {
    const j = await H.api('GET', `/api/jobs/${r.json.id}`);
    if (['succeeded', 'failed', 'cancelled', 'interrupted'].includes(j.json.state)) {
      assert.equal(j.json.state, 'succeeded', JSON.stringify(j.json));
      return j.json.result.model_id;
    }
    await new Promise((res) => { setTimeout(res, 100); });
  }
  throw new Error('identification did not finish in 120 s');
}

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (manage e2e)' });
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Manage e2e', grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 4,
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  assert.equal((await H.api('POST', `/api/campaigns/${cid}/plan`)).status, 201);
  const amp = [300, 600, 600, 300, 300, 300];
  for (const [seed, role] of [[21, 'dynamic'], [22, 'dynamic'], [23, 'validation']]) {
    const run = simulate({ seed, fs: 10, duration: role === 'validation' ? 320 : 180, amp, clock: 2, noise: 1e-4, surge: 1 * KN });
    const r = await uploadRun(H, cid, csv(run, ALL_COLUMNS), { name: `${role} ${seed}`, role, grid_speed_kn: 1 });
    runs.push(r.id);
  }
});

after(() => H.stop());

test('a run is excluded with a reason, included again, and marked in the campaign list', async () => {
  await H.withPage([{ method: 'PATCH', status: 422, path: /^\/api\/runs\// }], async (page) => {
    await page.goto(`${H.base}/#/runs/${runs[0]}`);
    await page.locator(tid('run-manage')).waitFor();
    // No reason: the server's 422 is shown.
    await page.click(tid('exclude-run'));
    await page.locator(tid('manage-error')).waitFor();
    assert.match(await page.textContent(tid('manage-error')), /excluded_reason|why/);
    await page.fill(tid('exclude-reason'), 'thruster 2 tripped at 40 s');
    await page.click(tid('exclude-run'));
    await page.locator(tid('excluded-note')).waitFor();
    let r = await H.api('GET', `/api/runs/${runs[0]}`);
    assert.equal(r.json.excluded, true);
    assert.equal(r.json.excluded_reason, 'thruster 2 tripped at 40 s');

    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const row = page.locator(`${tid('run-row')}[data-run-id="${runs[0]}"]`);
    await row.locator(tid('run-excluded')).waitFor();
    assert.equal(await page.locator(`${tid('run-row')} ${tid('run-excluded')}`).count(), 1);

    await page.goto(`${H.base}/#/runs/${runs[0]}`);
    await page.click(tid('include-run'));
    await page.locator(tid('exclude-form')).waitFor();
    r = await H.api('GET', `/api/runs/${runs[0]}`);
    assert.equal(r.json.excluded, false);
    assert.equal(r.json.excluded_reason, null);
  });
});

test('a model version is deleted with its derived versions, then a run after confirmation', async () => {
  const v1 = await identify();
  const v2 = await identify();
  const m2 = await H.api('GET', `/api/models/${v2}`);
  assert.equal(m2.json.model.parent_id, v1);
  const ALLOW = [
    { method: 'DELETE', status: 409, path: /^\/api\/(runs|models)\// },
  ];
  await H.withPage(ALLOW, async (page) => {
    // The run the models were built from is kept: the 409 names them.
    await page.goto(`${H.base}/#/runs/${runs[0]}`);
    await page.click(tid('delete-run'));
    await page.click(tid('confirm-no'));
    assert.equal(await page.locator(tid('confirm-box')).count(), 0);
    await page.click(tid('delete-run'));
    await page.click(tid('confirm-yes'));
    await page.locator(tid('manage-error')).waitFor();
    assert.match(await page.textContent(tid('manage-error')), new RegExp(v1));
    assert.equal((await H.api('GET', `/api/runs/${runs[0]}`)).status, 200);

    // v1: v2 was derived from it, so only with the derived versions.
    await page.goto(`${H.base}/#/models/${v1}`);
    await page.click(tid('delete-model'));
    await page.click(tid('confirm-yes'));
    await page.locator(tid('manage-error')).waitFor();
    assert.match(await page.textContent(tid('manage-error')), new RegExp(v2));
    assert.equal((await H.api('GET', `/api/models/${v1}`)).status, 200);
    await page.click(tid('delete-model-cascade'));
    await page.click(tid('confirm-yes'));
    await page.waitForFunction((c) => location.hash === `#/campaigns/${c}`, cid);
    assert.equal((await H.api('GET', `/api/models/${v1}`)).status, 404);
    assert.equal((await H.api('GET', `/api/models/${v2}`)).status, 404);

    // Now nothing is built from the run: it goes, and the campaign page shows the rest.
    await page.goto(`${H.base}/#/runs/${runs[0]}`);
    await page.click(tid('delete-run'));
    await page.click(tid('confirm-yes'));
    await page.waitForFunction((c) => location.hash === `#/campaigns/${c}`, cid);
    assert.equal((await H.api('GET', `/api/runs/${runs[0]}`)).status, 404);
    const list = await H.api('GET', `/api/campaigns/${cid}/runs`);
    assert.deepEqual(list.json.map((r) => r.id), runs.slice(1));
    await page.locator(tid('run-row')).first().waitFor();
    assert.equal(await page.locator(tid('run-row')).count(), 2);
  });
});
