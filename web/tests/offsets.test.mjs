// Clock offsets of two-file runs in a real (headless) Chromium: a strong run
// and a run at steady depth are uploaded; the weak run's page says it was
// merged with the campaign's pooled offset; the supervisor sets and clears
// its offset by hand; the campaign page shows the pooled offset and takes a
// campaign offset, with the field named on a bad value.
//
//   cd web && npm ci && node --test tests/offsets.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid } from './harness.mjs';
import { simulate, csv, FORCES, VELS, POSE, Rng } from './sim.mjs';
import { SURVEYOR_ROV } from '../templates.js';

const H = harness();
const TRUTH = 7.43; // control stamps = nav stamps + 7.43 s
let cid;
let weakId;

async function uploadSplit(name, control, nav) {
  const form = new FormData();
  form.append('meta', JSON.stringify({ name }));
  form.append('control', new Blob([control], { type: 'text/csv' }), 'control.csv');
  form.append('nav', new Blob([nav], { type: 'text/csv' }), 'nav.csv');
  const res = await fetch(`${H.base}/api/campaigns/${cid}/runs`, { method: 'POST', body: form });
  const json = await res.json();
  assert.equal(res.status, 201, JSON.stringify(json));
  return json;
}

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (offsets e2e)' });
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Two computers', grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 5,
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  assert.equal((await H.api('POST', `/api/campaigns/${cid}/plan`)).status, 201);
  const strong = simulate({ seed: 1, fs: 20, duration: 300, amp: [400, 800, 800, 600, 600, 600], clock: 3, noise: 1e-4 });
  await uploadSplit('dive', csv(strong, [...FORCES, 'z'], TRUTH, 2), csv(strong, [...VELS, ...POSE], 0, 1));
  // Steady depth: a 5 mm drift and 2 cm of independent noise per sensor.
  const weak = simulate({ seed: 2, fs: 20, duration: 300, amp: [400, 800, 0, 0, 0, 600], clock: 3, noise: 1e-4 });
  const rng = new Rng(9);
  const depth = () => Float64Array.from(weak.t, (t) => 20 + 0.005 * Math.sin(t / 110) + 0.02 * rng.normal());
  weak.eta[2] = depth();
  const control = csv(weak, [...FORCES, 'z'], TRUTH, 2);
  weak.eta[2] = depth();
  const run = await uploadSplit('hold', control, csv(weak, [...VELS, ...POSE], 0, 1));
  weakId = run.id;
});

after(() => H.stop());

const PUT_422 = { method: 'PUT', status: 422, path: /\/clock-offset$/ };

test('a weak run says it was merged with the pooled offset; its offset is set and cleared by hand', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/runs/${weakId}`);
    const used = page.locator(tid('offset-used'));
    await used.waitFor();
    assert.ok(Math.abs(Number(await used.getAttribute('data-offset-s')) - TRUTH) < 0.05);
    assert.match(await used.textContent(), /merged with 7\.43\d* ± [\d.]+ s/);
    assert.equal(await page.getAttribute(tid('offset-source'), 'data-source'), 'pooled');
    assert.match(await page.textContent(tid('offset-own')), /Own estimate: .* not informative|flat correlation|ambiguous|broad peak/);

    await page.fill(tid('run-offset-input'), '7.5');
    await page.click(tid('run-offset-set'));
    await page.locator(`${tid('offset-source')}[data-source="user_run"]`).waitFor();
    assert.match(await page.textContent(tid('offset-used')), /merged with 7\.500 s/);
    assert.equal(await page.inputValue(tid('run-offset-input')), '7.5');
    await page.click(tid('run-offset-clear'));
    await page.locator(`${tid('offset-source')}[data-source="pooled"]`).waitFor();
  });
});

test('the campaign page shows the pooled offset and takes a campaign offset', async () => {
  await H.withPage([PUT_422], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const pooled = page.locator(tid('campaign-offset-pooled'));
    await pooled.waitFor();
    assert.ok(Math.abs(Number(await pooled.getAttribute('data-offset-s')) - TRUTH) < 0.05);
    assert.equal(await page.locator(tid('campaign-offset-run')).count(), 2);
    const now = page.locator(`${tid('campaign-offset-run')}[data-run-id="${weakId}"] ${tid('offset-now')}`);
    assert.equal(await now.getAttribute('data-source'), 'pooled');

    await page.fill(tid('campaign-offset-input'), '100000');
    await page.click(tid('campaign-offset-set'));
    await page.locator(tid('campaign-offset-error')).filter({ hasText: 'clock_offset_s' }).waitFor();
    await page.fill(tid('campaign-offset-input'), '7.42');
    await page.click(tid('campaign-offset-set'));
    await page.locator(`${tid('offset-now')}[data-source="user_campaign"]`).first().waitFor();
    assert.equal(await page.locator(`${tid('offset-now')}[data-source="user_campaign"]`).count(), 2);
    await page.click(tid('campaign-offset-clear'));
    await page.locator(`${tid('campaign-offset-run')}[data-run-id="${weakId}"] ${tid('offset-now')}[data-source="pooled"]`).waitFor();
  });
});
