// Jobs that wait: a server with no job workers (queue only) keeps every
// identification queued, so cancelling from the campaign page is
// deterministic — a queued job is cancelled at once — and Retry queues it
// again. The computing side is in models.test.mjs.
//
// Env: see harness.mjs.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid, uploadRun } from './harness.mjs';
import { simulate, csv, ALL_COLUMNS } from './sim.mjs';
import { SURVEYOR_ROV } from '../templates.js';

process.env.SEATRIAL_JOB_WORKERS = '0';

const H = harness();
let cid;

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (queue e2e)' });
  assert.equal(v.status, 201);
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Queue e2e', grid: { unit: 'kn', speeds: [1, 2] }, families: ['dynamic', 'validation'], seed: 3,
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  const plan = (await H.api('POST', `/api/campaigns/${cid}/plan`)).json;
  const amp = [300, 600, 600, 300, 300, 300];
  for (const [i, e] of [plan.experiments.find((x) => x.code === 'DYN-1kn-surge-r1'), plan.experiments.find((x) => x.family === 'validation')].entries()) {
    const run = simulate({ seed: 20 + i, fs: 10, duration: 60, amp, clock: 2, noise: 1e-4 });
    await uploadRun(H, cid, csv(run, ALL_COLUMNS), { experiment_id: e.id, name: e.code });
  }
});

after(() => H.stop());

test('a queued job is cancelled from the campaign page at once; Retry queues it again', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.getByRole('form', { name: 'Identify a model' }).waitFor();
    await page.getByLabel('Method').selectOption('n4sid');
    assert.equal(await page.getByLabel('Structure').isVisible(), false, 'structure is a λ-filter setting');
    await page.getByRole('button', { name: 'Start identification' }).click();
    const row = page.locator(tid('job-row')).first();
    await row.waitFor();
    assert.equal(await row.getAttribute('data-state'), 'queued');
    assert.match(await row.textContent(), /N4SID \(black box\)/);
    assert.equal(await row.locator(tid('job-progress')).getAttribute('value'), '0');
    assert.equal(await row.getByRole('button', { name: 'Retry' }).count(), 0);

    await row.getByRole('button', { name: 'Cancel' }).click();
    await page.locator(`${tid('job-row')}[data-state="cancelled"]`).waitFor();
    assert.match(await row.locator(tid('job-state')).textContent(), /cancelled/);
    assert.equal(await row.getByRole('button', { name: 'Cancel' }).count(), 0);
    const jid = await row.getAttribute('data-job-id');
    assert.equal((await H.api('GET', `/api/jobs/${jid}`)).json.state, 'cancelled');

    // Retry: queued again (and cancellable again).
    await row.getByRole('button', { name: 'Retry' }).click();
    await page.locator(`${tid('job-row')}[data-state="queued"]`).waitFor();
    assert.equal((await H.api('GET', `/api/jobs/${jid}`)).json.state, 'queued');
    await row.getByRole('button', { name: 'Cancel' }).click();
    await page.locator(`${tid('job-row')}[data-state="cancelled"]`).waitFor();

    // A reload lists the job from the server in the same state.
    await page.reload();
    await page.locator(`${tid('job-row')}[data-job-id="${jid}"][data-state="cancelled"]`).waitFor();
    assert.equal(await page.locator(tid('no-models')).count(), 1);
  });
});
