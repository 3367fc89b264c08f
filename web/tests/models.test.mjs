// End-to-end test of identification in a real (headless) Chromium: runs of a
// simulated ROV uploaded for a planned campaign (estimation runs at two grid
// speeds, one validation run), an identification started from the campaign
// page and followed live to completion, the model page (parameters with ±,
// fits, predicted-vs-measured and autocorrelation plots, exports, ZOH), and
// errors: a refused request and a failed job. Cancelling: models-queue.test.mjs.
//
//   cd web && npm ci && node --test tests/models.test.mjs
//
// Env: see harness.mjs; MODELS_SCREENSHOT=/tmp/model.png saves the model page.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid, inked, dragZoom, uploadRun } from './harness.mjs';
import { simulate, csv, ALL_COLUMNS, D } from './sim.mjs';
import { SURVEYOR_ROV } from '../templates.js';

const KN = 1852 / 3600;
const H = harness();
let cid;
let plan;
const uploaded = []; // {id, code}

const upload = (log, meta) => uploadRun(H, cid, log, meta);

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (models e2e)' });
  assert.equal(v.status, 201);
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Models e2e', grid: { unit: 'kn', speeds: [1, 2] }, families: ['dynamic', 'validation'], seed: 11,
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  const p = await H.api('POST', `/api/campaigns/${cid}/plan`);
  assert.equal(p.status, 201);
  plan = p.json;

  // Estimation: two runs at each grid speed, every DOF driven by random-binary forces.
  const amp = [300, 600, 600, 300, 300, 300];
  let seed = 100;
  for (const code of ['DYN-1kn-surge-r1', 'DYN-1kn-sway-r1', 'DYN-2kn-surge-r1', 'DYN-2kn-sway-r1']) {
    const e = plan.experiments.find((x) => x.code === code);
    assert.ok(e, `planned ${code}: ${plan.experiments.map((x) => x.code).join(' ')}`);
    seed += 1;
    const run = simulate({ seed, fs: 10, duration: 180, amp, clock: 2, noise: 1e-4, surge: e.grid_speed_mps });
    const r = await upload(csv(run, ALL_COLUMNS), { experiment_id: e.id, name: code });
    uploaded.push({ id: r.id, code });
  }
  // Validation: 360 s stepping the forward speed from 1 kn to 2 kn half way.
  const val = plan.experiments.find((x) => x.family === 'validation');
  assert.ok(val, 'a validation experiment is planned');
  const n = 3600;
  const run = simulate({
    seed: 7, fs: 10, duration: 360, amp, clock: 2, noise: 1e-4, surge: 1 * KN,
    force: [(k) => (k < n / 2 ? 1 : 2) * KN * D[0] + ((Math.floor(k / 20) * 7919) % 2 ? 300 : -300)],
  });
  const r = await upload(csv(run, ALL_COLUMNS), { experiment_id: val.id, name: val.code });
  uploaded.push({ id: r.id, code: val.code });
});

after(() => H.stop());

/** Record every value the progress bar of a job row takes from now on. */
async function recordProgress(page) {
  await page.evaluate(() => {
    window.__jobProgress = [];
    const table = document.querySelector('[data-testid="jobs"]');
    new MutationObserver(() => {
      const bar = table.querySelector('[data-testid="job-row"] [data-testid="job-progress"]');
      const row = table.querySelector('[data-testid="job-row"]');
      if (bar) window.__jobProgress.push({ v: Number(bar.getAttribute('value')), state: row.dataset.state });
    }).observe(table, { attributes: true, childList: true, subtree: true, characterData: true });
  });
}

test('identify from the campaign page, follow the job, read the model page', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const form = page.getByRole('form', { name: 'Identify a model' });
    await form.waitFor();
    // Only the methods of a ROV.
    const methods = await page.locator(`${tid('identify-method')} option`).evaluateAll((os) => os.map((o) => o.value));
    assert.deepEqual(methods, ['lambda_kf', 'n4sid']);
    // Every accepted run is used; the plan's validation run is held out.
    const roles = await page.locator(tid('identify-run')).evaluateAll((rs) => rs.map((r) => [r.dataset.runId, r.dataset.role]));
    assert.equal(roles.length, 5);
    const valId = uploaded.find((u) => u.code.startsWith('VAL')).id;
    assert.deepEqual(roles.filter(([, r]) => r === 'validation').map(([id]) => id), [valId]);
    assert.match(await page.textContent(tid('identify-roles')), /5 of 5 accepted runs: 4 to estimate from, 1 held out for validation/);
    assert.equal(await page.locator(tid('no-jobs')).count(), 1);

    await page.getByLabel('Method').selectOption('lambda_kf');
    await page.getByLabel('Structure').selectOption('diagonal');
    await recordProgress(page);
    await page.getByRole('button', { name: 'Start identification' }).click();
    const row = page.locator(tid('job-row')).first();
    await row.waitFor();
    await page.locator(`${tid('job-row')}[data-state="succeeded"]`).waitFor({ timeout: 180000 });
    const seen = await page.evaluate(() => window.__jobProgress);
    assert.equal(await row.locator(tid('job-progress')).getAttribute('value'), '1', 'the bar is full');
    assert.ok(seen.some((s) => s.state === 'running' || s.state === 'queued'), `followed live: ${JSON.stringify(seen.slice(0, 20))}`);
    assert.match(await row.locator(tid('job-stage')).textContent(), /^100 %/);
    assert.match(await row.locator(tid('job-state')).textContent(), /succeeded/);
    // The models list followed.
    await page.locator(tid('model-row')).waitFor();
    assert.equal(await page.locator(tid('model-row')).count(), 1);
    assert.match(await page.textContent(tid('models-table')), /v1/);

    // The model page.
    await row.getByRole('link', { name: /Open model/ }).click();
    await page.waitForURL(/#\/models\/[0-9a-f-]{36}$/);
    await page.locator(tid('param-table')).waitFor();
    assert.match(await page.textContent(tid('model-method')), /λ-filter Kalman \(LPV\)/);
    assert.match(await page.textContent(tid('model-settings')), /structure: diagonal/);
    assert.equal(await page.locator(`${tid('model-runs')} ${tid('provenance-run')}`).count(), 4);
    assert.match(await page.textContent(tid('model-validation-runs')), /VAL-r1/);
    assert.match(await page.textContent(tid('model-version')), /^v1/);
    const nParams = await page.locator(tid('param-row')).count();
    assert.ok(nParams >= 12, `${nParams} parameter rows`);
    const stds = await page.locator(tid('param-std')).allTextContents();
    assert.ok(stds.some((s) => /^± \S+/.test(s)), `± std shown: ${stds.slice(0, 5)}`);
    // Grouped by grid speed (two grid points, and the campaign-wide g(η)),
    // and sortable.
    assert.equal(await page.locator(tid('param-group-head')).count(), 3);
    await page.getByRole('button', { name: /^Value/ }).click();
    await page.getByLabel('group by grid speed').uncheck();
    const values = await page.locator(`${tid('param-row')} td:nth-child(4)`).evaluateAll((tds) => tds.map((t) => Number(t.title)));
    assert.ok(values.every((v, i) => i === 0 || v >= values[i - 1]), 'sorted by value');

    // Validation: fits as numbers, plots drawn.
    const fitTable = page.locator(tid('fit-table'));
    assert.ok(await fitTable.locator(tid('fit-row')).count() >= 6);
    const fits = await fitTable.locator(`${tid('fit-one-step')}, ${tid('fit-k-step')}, ${tid('fit-restarted')}, ${tid('fit-simulation')}`).allTextContents();
    assert.ok(fits.some((f) => /^−?\d+(\.\d)? %$/.test(f)), `fits: ${fits}`);
    // One format: a percentage with one decimal, or "—" where there is no fit.
    assert.ok(fits.every((f) => /^(−?\d+\.\d %|< −1000 %|—)$/.test(f)), `fits: ${fits}`);
    const restarted = await fitTable.locator(tid('fit-restarted')).allTextContents();
    assert.ok(restarted.length >= 6 && restarted.every((f) => /^(−?\d+\.\d %|< −1000 %)$/.test(f)), `restarted fits: ${restarted}`);
    assert.match(await fitTable.locator('thead').textContent(), /Restarted 10 s fit/);
    const pvm = page.locator(`${tid('pvm-plot')}[data-channel="u"] canvas`);
    const acf = page.locator(`${tid('acf-plot')}[data-channel="u"] canvas`);
    await pvm.waitFor();
    await acf.waitFor();
    for (const c of [pvm, acf]) {
      await c.scrollIntoViewIfNeeded();
      const n = await inked(c);
      assert.ok(n > 1000, `plot looks blank (${n} painted pixels)`);
    }
    assert.match(await page.textContent(`${tid('pvm-plot')}[data-channel="u"] .u-legend`), /measured.*1-step.*-step.*restarted 10 s.*simulated/s);
    assert.match(await page.textContent(`${tid('acf-plot')}[data-channel="u"] .u-legend`), /r\(lag\).*bound/s);
    // Zooming one channel zooms the others of the run.
    const xr = (k) => page.evaluate((key) => [window.__plots[key].scales.x.min, window.__plots[key].scales.x.max], k);
    const [a0, a1] = await xr('pvm:0:0');
    await dragZoom(page, `${tid('pvm-plot')}[data-channel="u"]`, 0.3, 0.6);
    const [z0, z1] = await xr('pvm:0:0');
    const [o0, o1] = await xr('pvm:0:1');
    assert.ok(z0 > a0 && z1 < a1, `zoomed: [${a0}, ${a1}] → [${z0}, ${z1}]`);
    assert.ok(Math.abs(o0 - z0) < 1e-9 && Math.abs(o1 - z1) < 1e-9, `the next channel follows: [${o0}, ${o1}]`);

    // Exports: links that answer 200.
    for (const t of ['export-json', 'export-csv', 'export-fossen']) {
      const href = await page.getAttribute(tid(t), 'href');
      assert.ok(href, `${t} is a link for an LPV model`);
      const res = await page.request.get(H.base + href);
      assert.equal(res.status(), 200, `${t} ${href}`);
    }
    const csvText = await (await page.request.get(H.base + await page.getAttribute(tid('export-csv'), 'href'))).text();
    assert.ok(csvText.split('\n').length > nParams / 2, 'the CSV holds the parameter table');

    // ZOH at h = 0.05 s: Φ, Γ per grid point.
    await page.getByLabel('Sample time h [s]').fill('0.05');
    await page.getByRole('button', { name: 'Discretize (ZOH)' }).click();
    await page.locator(tid('zoh-point')).first().waitFor();
    assert.equal(await page.locator(tid('zoh-point')).count(), 2);
    assert.ok(await page.locator(`${tid('zoh-phi')} td`).count() >= 36);

    if (process.env.MODELS_SCREENSHOT) {
      await page.evaluate(() => window.scrollTo(0, 0));
      await page.screenshot({ path: process.env.MODELS_SCREENSHOT, fullPage: true });
    }

    // Back to the campaign: the finished job still links its model.
    await page.click(tid('model-campaign-link'));
    await page.locator(`${tid('job-row')}[data-state="succeeded"] ${tid('job-model-link')}`).waitFor();
  });
});

test('bad answers are shown: a refused request names its field next to the form, a failed job says why', async () => {
  await H.withPage([{ method: 'POST', status: 422, path: /^\/api\/jobs$/ }], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.getByRole('form', { name: 'Identify a model' }).waitFor();

    // A request the server refuses at submission: a method this server does
    // not know (sent as if chosen) answers 422 naming `method`.
    await page.route('**/api/jobs', (route) => (route.request().method() === 'POST'
      ? route.continue({ postData: JSON.stringify({ ...JSON.parse(route.request().postData()), method: 'no_such_method' }) })
      : route.continue()));
    const before = await page.locator(tid('job-row')).count();
    await page.getByRole('button', { name: 'Start identification' }).click();
    const err = page.locator(tid('identify-error-text'));
    await err.waitFor();
    assert.equal(await err.getAttribute('data-status'), '422');
    assert.equal(await err.locator(tid('identify-error-field')).textContent(), 'method');
    assert.match(await err.textContent(), /unknown method 'no_such_method'/);
    const fieldErr = page.locator(`${tid('field-error')}[data-for="method"]`);
    assert.match(await fieldErr.textContent(), /unknown method/);
    assert.equal(await page.getByLabel('Method').getAttribute('aria-invalid'), 'true');
    assert.equal(await page.locator(tid('job-row')).count(), before, 'nothing was queued');
    await page.unroute('**/api/jobs');

    // A job that fails: every run held out leaves nothing to estimate from.
    for (const box of await page.locator(tid('identify-holdout')).all()) await box.check();
    assert.match(await page.textContent(tid('identify-roles')), /0 to estimate from, 5 held out/);
    await page.getByRole('button', { name: 'Start identification' }).click();
    assert.equal(await page.locator(tid('field-error')).count(), 0, 'the previous error is cleared');
    const row = page.locator(tid('job-row')).first();
    await page.locator(`${tid('job-row')}:first-child[data-state="failed"]`).waitFor({ timeout: 60000 });
    assert.match(await row.locator(tid('job-error')).textContent(), /no estimation run.*\[run_ids\]/);
    assert.equal(await row.getByRole('button', { name: 'Retry' }).count(), 1);
    assert.equal(await row.getByRole('button', { name: 'Cancel' }).count(), 0);
  });
});
