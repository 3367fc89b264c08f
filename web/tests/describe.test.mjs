// Runs described without a plan, in a real (headless) Chromium, on the demo:
// a log of the Surveyor campaign uploaded again without any metadata (as
// another team's run) is described from its data — each field with an
// "inferred" badge and its reason; the supervisor corrects its role to
// validation on the run page (the badge becomes "user"), the campaign's
// runs list and Identify panel follow, and an identification started from
// the campaign page holds the run out and succeeds.
//
//   cd web && npm ci && node --test tests/describe.test.mjs
//
// Env: see harness.mjs; DESCRIBE_SCREENSHOT=/tmp/describe.png saves the run page.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid } from './harness.mjs';

const H = harness({ extraArgs: ['--demo'] });
let cid;
let rid; // the re-uploaded run, described by inference only
let code; // the demo experiment it flew

before(async () => {
  await H.start();
  const cs = await H.api('GET', '/api/campaigns');
  const rov = cs.json.find((c) => /Surveyor/.test(JSON.stringify(c)));
  assert.ok(rov, 'the demo has the Surveyor campaign');
  cid = rov.id;
  // Another team's run: the bytes of a demo run at 1.5 kn, uploaded without metadata.
  const runs = (await H.api('GET', `/api/campaigns/${cid}/runs`)).json;
  const src = runs.find((r) => r.name === 'DYN-1.5kn-sway-r1');
  assert.ok(src, `a demo sway run: ${runs.slice(0, 5).map((r) => r.name).join(', ')}`);
  code = src.name;
  const bytes = await (await fetch(`${H.base}/api/runs/${src.id}/raw`)).text();
  const form = new FormData();
  form.append('file', new Blob([bytes], { type: 'text/csv' }), 'team-b-dive-7.csv');
  const res = await fetch(`${H.base}/api/campaigns/${cid}/runs`, { method: 'POST', body: form });
  const run = await res.json();
  assert.equal(res.status, 201, JSON.stringify(run));
  rid = run.id;
  assert.equal(run.description.role.source, 'inferred');
  assert.equal(run.description.role.value, 'dynamic');
});

after(() => H.stop());

const PATCH_422 = { method: 'PATCH', status: 422, path: /^\/api\/runs\/[^/]+$/ };

test('an inferred role is corrected on the run page, and identification uses it', async () => {
  await H.withPage([PATCH_422], async (page) => {
    await page.goto(`${H.base}/#/runs/${rid}`);
    const card = page.locator(tid('run-description-card'));
    await card.waitFor();
    const field = (k) => card.locator(`${tid('desc-field')}[data-field="${k}"]`);
    // Everything inferred from the data, each with its reason.
    for (const k of ['role', 'grid_speed_mps', 'excited_dofs', 'signal']) {
      assert.equal(await field(k).getAttribute('data-source'), 'inferred', k);
      assert.equal(await field(k).locator(tid('source-badge')).textContent(), 'inferred', k);
      assert.ok((await field(k).locator(tid('desc-reason')).textContent()).length > 20, k);
    }
    assert.equal(await field('role').locator(tid('desc-value')).textContent(), 'Dynamic');
    assert.match(await field('grid_speed_mps').locator(tid('desc-value')).textContent(), /\(1\.5 kn\)/);
    assert.match(await field('grid_speed_mps').locator(tid('desc-reason')).textContent(), /mean forward speed .* the grid point/);
    assert.equal(await field('excited_dofs').locator(tid('desc-value')).textContent(), 'sway');
    assert.match(await card.locator(tid('desc-confirm')).textContent(), /Confirm inferred \(4\)/);

    // Correct the role: validation; add a note.
    await card.locator(tid('desc-edit')).click();
    const form = card.locator(tid('desc-form'));
    await form.waitFor();
    assert.equal(await form.locator(tid('desc-role')).inputValue(), 'dynamic');
    assert.equal(await form.locator(tid('desc-speed')).inputValue(), '1.5');
    assert.deepEqual(await form.locator(`${tid('desc-dof')}:checked`).evaluateAll((cs) => cs.map((c) => c.value)), ['sway']);
    await form.locator(tid('desc-role')).selectOption('validation');
    await form.locator(tid('desc-notes')).fill('flown by team B, held out');
    // A speed over the vessel's limit is refused next to the field.
    await form.locator(tid('desc-speed')).fill('9');
    await form.locator(tid('desc-save')).click();
    const err = form.locator(tid('field-error'));
    await err.waitFor();
    assert.equal(await err.getAttribute('data-for'), 'grid_speed_kn');
    assert.match(await err.textContent(), /maximum forward speed/);
    await form.locator(tid('desc-speed')).fill('1.5');
    await form.locator(tid('desc-save')).click();
    await field('role').locator(`${tid('source-badge')}[data-source="user"]`).waitFor();
    assert.equal(await field('role').locator(tid('desc-value')).textContent(), 'Validation');
    assert.equal(await field('role').locator(tid('desc-reason')).count(), 0, 'a user value needs no reason');
    assert.equal(await field('grid_speed_mps').getAttribute('data-source'), 'inferred', 'unchanged fields stay inferred');
    assert.equal(await field('notes').locator(tid('desc-value')).textContent(), 'flown by team B, held out');
    assert.equal(await card.locator(tid('desc-family')).textContent(), 'Validation');
    const saved = await H.api('GET', `/api/runs/${rid}`);
    assert.equal(saved.json.description.role.source, 'user');
    if (process.env.DESCRIBE_SCREENSHOT) await page.screenshot({ path: process.env.DESCRIBE_SCREENSHOT, fullPage: true });

    // The campaign page: the runs list and the Identify panel follow.
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const desc = page.locator(`${tid('run-row')}[data-run-id="${rid}"] ${tid('run-description')}`);
    await desc.waitFor();
    assert.equal(await desc.getAttribute('data-role'), 'validation');
    assert.equal(await desc.getAttribute('data-role-source'), 'user');
    assert.match(await desc.textContent(), /Validation · 1\.5 kn\? · sway\?/);
    const mine = page.locator(`${tid('identify-run')}[data-run-id="${rid}"]`);
    assert.equal(await mine.getAttribute('data-role'), 'validation');
    assert.match(await mine.locator(tid('identify-role')).textContent(), /validation \(user\)/);
    assert.match(await page.textContent(tid('identify-roles')), /2 held out for validation/);

    // The log is 10 Hz; its controller ran at 20 Hz.
    await page.fill(tid('identify-controller-rate'), '20');
    await page.getByRole('button', { name: 'Start identification' }).click();
    await page.locator(`${tid('job-row')}[data-state="succeeded"]`).waitFor({ timeout: 180000 });
    const jobs = (await H.api('GET', `/api/jobs?campaign_id=${cid}`)).json;
    const job = jobs.find((j) => j.state === 'succeeded');
    const model = (await H.api('GET', `/api/models/${job.result.model_id}`)).json;
    assert.ok(model.validation_run_ids.includes(rid), `held out: ${model.validation_run_ids}`);
    assert.ok(!model.run_ids.includes(rid), 'not fitted to');
    assert.ok(model.run_ids.length > 0, 'estimation runs');
    assert.equal(model.settings.controller_rate_hz, 20);
    assert.ok(model.document.notes.some((n) => /controller at 2\.00× the log rate/.test(n)), model.document.notes.join('\n'));
    assert.ok(code, 'the source run');
  });
});
