// Deleting vessels and campaigns in a real (headless) Chromium: a campaign
// is deleted with a reason and undone on its page, deleted again and
// restored from the campaign list's "Deleted campaigns"; a vessel is deleted
// (its campaigns leave the list with it), a campaign under it cannot be
// restored (the 409 names the vessel), and the vessel is restored from the
// vessel list — each checked against the API. SEATRIAL_SHOTS=<dir> keeps
// screenshots of the views.
//
//   cd web && npm ci && node --test tests/trash.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { mkdirSync } from 'node:fs';
import { harness, tid } from './harness.mjs';
import { SURVEYOR_ROV } from '../templates.js';

const H = harness();
let vid;
let cid;
let other;

/** A screenshot when SEATRIAL_SHOTS names a folder. */
async function shot(page, name) {
  const dir = process.env.SEATRIAL_SHOTS;
  if (!dir) return;
  mkdirSync(dir, { recursive: true });
  await page.screenshot({ path: path.join(dir, `${name}.png`), fullPage: true });
}

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (trash e2e)' });
  vid = v.json.id;
  const o = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Otter ROV' });
  assert.equal(o.status, 201);
  for (const name of ['Trash e2e', 'Keeps']) {
    const c = await H.api('POST', '/api/campaigns', {
      vessel_id: vid, name, grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 4,
    });
    assert.equal(c.status, 201, JSON.stringify(c.json));
    assert.equal((await H.api('POST', `/api/campaigns/${c.json.id}/plan`)).status, 201);
    if (name === 'Keeps') other = c.json.id; else cid = c.json.id;
  }
});

after(() => H.stop());

test('a campaign is deleted with a reason, undone, deleted again and restored from the list', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.click(tid('delete-campaign'));
    await page.fill(tid('delete-reason'), 'wrong grid');
    await shot(page, 'campaign-delete-confirm');
    await page.click(tid('confirm-yes'));
    await page.locator(tid('deleted-note')).waitFor();
    assert.match(await page.textContent(tid('deleted-note')), /wrong grid/);
    await shot(page, 'campaign-deleted-undo');
    // Read-only while deleted: no plan, upload or identify controls.
    for (const t of ['generate-plan', 'upload-form', 'identify-form']) {
      assert.equal(await page.locator(tid(t)).isVisible(), false, `${t} hidden on a deleted campaign`);
    }
    let r = await H.api('GET', `/api/campaigns/${cid}`);
    assert.equal(r.json.delete_reason, 'wrong grid');
    r = await H.api('GET', '/api/campaigns');
    assert.deepEqual(r.json.map((c) => c.id), [other]);
    // Undo on the spot.
    await page.click(tid('undo-delete'));
    await page.locator(tid('delete-campaign')).waitFor();
    await page.locator(tid('generate-plan')).waitFor();
    r = await H.api('GET', `/api/campaigns/${cid}`);
    assert.equal(r.json.deleted_at, null);
    // Deleted again, then restored from the campaign list.
    await page.click(tid('delete-campaign'));
    await page.click(tid('confirm-yes'));
    await page.locator(tid('deleted-note')).waitFor();
    await page.goto(`${H.base}/#/campaigns`);
    await page.locator(tid('campaign-table')).waitFor();
    assert.equal(await page.locator(tid('campaign-row')).count(), 1);
    await page.click(`${tid('deleted-campaigns-details')} summary`);
    await shot(page, 'campaigns-deleted-list');
    await page.locator(`${tid('deleted-row')}[data-id="${cid}"] ${tid('restore')}`).click();
    await page.locator(tid('campaign-row')).nth(1).waitFor();
    assert.equal(await page.locator(tid('campaign-row')).count(), 2);
    r = await H.api('GET', '/api/campaigns?deleted=true');
    assert.deepEqual(r.json, []);
  });
});

test('a vessel is deleted with its campaigns out of the lists; a campaign under it is not restored before it', async () => {
  await H.withPage([{ method: 'POST', status: 409, path: /^\/api\/campaigns\/[^/]+\/restore$/ }], async (page) => {
    assert.equal((await H.api('DELETE', `/api/campaigns/${cid}`)).status, 200);
    await page.goto(`${H.base}/#/vessels/${vid}`);
    await page.click(tid('delete-vessel'));
    await page.fill(tid('delete-reason'), 'sold');
    await page.click(tid('confirm-yes'));
    await page.locator(tid('deleted-note')).waitFor();
    assert.match(await page.textContent(tid('deleted-note')), /sold/);
    await shot(page, 'vessel-deleted-undo');
    let r = await H.api('GET', '/api/campaigns');
    assert.deepEqual(r.json, [], 'the vessel’s campaigns leave the list');
    // The deleted campaign cannot come back while its vessel is deleted.
    await page.goto(`${H.base}/#/campaigns`);
    await page.click(`${tid('deleted-campaigns-details')} summary`);
    await page.locator(`${tid('deleted-row')}[data-id="${cid}"] ${tid('restore')}`).click();
    await page.locator('.trash .error-text').waitFor();
    const msg = await page.textContent('.trash .error-text');
    assert.match(msg, /vessel 'Surveyor ROV \(trash e2e\)'/);
    assert.ok(msg.includes(vid), msg);
    // The vessel list leaves it out and restores it.
    await page.goto(`${H.base}/#/vessels`);
    await page.locator(tid('vessel-table')).waitFor();
    assert.equal(await page.locator(tid('vessel-row')).count(), 1);
    await page.click(`${tid('deleted-vessels-details')} summary`);
    await shot(page, 'vessels-deleted-list');
    await page.locator(`${tid('deleted-row')}[data-id="${vid}"] ${tid('restore')}`).click();
    await page.locator(tid('vessel-row')).nth(1).waitFor();
    r = await H.api('GET', '/api/campaigns');
    assert.deepEqual(r.json.map((c) => c.id), [other]);
    // The vessel page's Undo works too.
    await page.goto(`${H.base}/#/vessels/${vid}`);
    await page.click(tid('delete-vessel'));
    await page.click(tid('confirm-yes'));
    await page.click(tid('undo-delete'));
    await page.locator(tid('delete-vessel')).waitFor();
    r = await H.api('GET', `/api/vessels/${vid}`);
    assert.equal(r.json.deleted_at, null);
  });
});
