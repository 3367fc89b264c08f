// Managing runs and models in a real (headless) Chromium: a run is excluded
// from identification with a reason and included again; vessel, campaign,
// run and model are renamed; a run a model was built from is deleted (soft,
// with a reason), undone on the spot, deleted again and restored from the
// campaign's "Deleted" section while the model keeps its provenance; a model
// version another was derived from is deleted only with its derived versions
// and undone; a rejected upload is listed apart and removed — each checked
// against the API.
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

test('vessel, campaign, run and model are renamed in the page', async () => {
  const c = await H.api('GET', `/api/campaigns/${cid}`);
  const vid = c.json.vessel_id;
  const mid = await identify();
  const ALLOW = [{ method: 'PATCH', status: 422, path: /^\/api\/vessels\// }];
  await H.withPage(ALLOW, async (page) => {
    const rename = async (hash, title, name) => {
      await page.goto(`${H.base}/${hash}`);
      await page.locator(tid('rename')).first().click();
      await page.fill(tid('rename-input'), name);
      await page.click(tid('rename-save'));
      await page.waitForFunction(([sel, n]) => document.querySelector(sel)?.textContent.includes(n), [title, name]);
    };
    // An empty name: the server's 422 is shown, nothing changes.
    await page.goto(`${H.base}/#/vessels/${vid}`);
    await page.click(tid('rename'));
    await page.fill(tid('rename-input'), ' ');
    await page.click(tid('rename-save'));
    await page.locator(tid('rename-error')).waitFor();
    assert.match(await page.textContent(tid('rename-error')), /name/);
    await page.click(tid('rename-cancel'));
    await rename(`#/vessels/${vid}`, 'h1', 'Surveyor (renamed)');
    assert.equal((await H.api('GET', `/api/vessels/${vid}`)).json.profile.name, 'Surveyor (renamed)');
    await rename(`#/campaigns/${cid}`, tid('campaign-title'), 'Manage e2e (renamed)');
    assert.equal((await H.api('GET', `/api/campaigns/${cid}`)).json.spec.name, 'Manage e2e (renamed)');
    await rename(`#/runs/${runs[1]}`, tid('run-title'), 'dynamic 22 (renamed)');
    assert.equal((await H.api('GET', `/api/runs/${runs[1]}`)).json.name, 'dynamic 22 (renamed)');
    await rename(`#/models/${mid}`, tid('model-title'), 'N4SID (renamed)');
    assert.equal((await H.api('GET', `/api/models/${mid}`)).json.model.name, 'N4SID (renamed)');
  });
});

test('a run a model was built from is deleted with a reason and undone; models keep their provenance', async () => {
  const models = await H.api('GET', `/api/models?campaign_id=${cid}`);
  const mid = models.json[0].id;
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/runs/${runs[0]}`);
    await page.click(tid('delete-run'));
    await page.click(tid('confirm-no'));
    assert.equal(await page.locator(tid('confirm-box')).count(), 0);
    await page.click(tid('delete-run'));
    await page.fill(tid('delete-reason'), 'depth sensor drifted');
    await page.click(tid('confirm-yes'));
    await page.locator(tid('deleted-note')).waitFor();
    assert.match(await page.textContent(tid('deleted-note')), /depth sensor drifted/);
    let r = await H.api('GET', `/api/runs/${runs[0]}`);
    assert.equal(r.json.delete_reason, 'depth sensor drifted');
    assert.ok(r.json.deleted_at);
    // The model built from it still names it.
    const m = await H.api('GET', `/api/models/${mid}`);
    assert.ok([...m.json.run_ids, ...m.json.validation_run_ids].includes(runs[0]));
    // Undo on the spot.
    await page.click(tid('undo-delete'));
    await page.locator(tid('delete-run')).waitFor();
    r = await H.api('GET', `/api/runs/${runs[0]}`);
    assert.equal(r.json.deleted_at, null);

    // Deleted again, it leaves the campaign's list and is restored from its "Deleted" section.
    await page.click(tid('delete-run'));
    await page.click(tid('confirm-yes'));
    await page.locator(tid('deleted-note')).waitFor();
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(`${tid('deleted-row')}[data-id="${runs[0]}"]`).waitFor();
    assert.equal(await page.locator(`${tid('run-row')}[data-run-id="${runs[0]}"]`).count(), 0);
    await page.click(`${tid('deleted-row')}[data-id="${runs[0]}"] ${tid('restore')}`);
    await page.locator(`${tid('run-row')}[data-run-id="${runs[0]}"]`).waitFor();
    assert.equal((await H.api('GET', `/api/runs/${runs[0]}`)).json.deleted_at, null);
  });
});

test('a model version is deleted with its derived versions, and undone', async () => {
  const v1 = await identify();
  const v2 = await identify();
  const m2 = await H.api('GET', `/api/models/${v2}`);
  assert.equal(m2.json.model.parent_id, v1);
  const ALLOW = [{ method: 'DELETE', status: 409, path: /^\/api\/models\// }];
  await H.withPage(ALLOW, async (page) => {
    // v1: v2 was derived from it, so only with the derived versions.
    await page.goto(`${H.base}/#/models/${v1}`);
    await page.click(tid('delete-model'));
    await page.click(tid('confirm-yes'));
    await page.locator(tid('manage-error')).waitFor();
    assert.match(await page.textContent(tid('manage-error')), new RegExp(v2));
    assert.equal((await H.api('GET', `/api/models/${v1}`)).json.model.deleted_at, null);
    await page.click(tid('delete-model-cascade'));
    await page.click(tid('confirm-yes'));
    await page.locator(tid('deleted-note')).waitFor();
    const gone = await H.api('GET', `/api/models?campaign_id=${cid}`);
    assert.ok(!gone.json.some((m) => m.id === v1 || m.id === v2));
    assert.ok((await H.api('GET', `/api/models/${v2}`)).json.model.deleted_at);
    // Undo restores both.
    await page.click(tid('undo-delete'));
    await page.locator(tid('delete-model')).waitFor();
    for (const v of [v1, v2]) assert.equal((await H.api('GET', `/api/models/${v}`)).json.model.deleted_at, null);
  });
});

test('a rejected upload is listed apart and removed', async () => {
  const r = await H.api('GET', `/api/campaigns/${cid}/runs?status=rejected`);
  assert.equal(r.json.length, 0);
  const bad = await uploadRun(H, cid, 't,u\n0,x\n', { name: 'garbled' }).catch((e) => e);
  const rejected = (await H.api('GET', `/api/campaigns/${cid}/runs?status=rejected`)).json;
  assert.equal(rejected.length, 1, String(bad));
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const row = page.locator(`${tid('rejected-list')} [data-run-id="${rejected[0].id}"]`);
    await row.waitFor();
    await row.locator(tid('remove-rejected')).click();
    await page.locator(tid('rejected-list')).waitFor({ state: 'detached' });
    assert.ok((await H.api('GET', `/api/runs/${rejected[0].id}`)).json.deleted_at);
  });
});
