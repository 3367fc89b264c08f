// End-to-end missing-physics discovery in a real (headless) Chromium, on the
// demo: the Surveyor campaign flown by the ROV truth (which has a metacentric
// righting moment) is identified by the λ-filter method, whose linear model
// fails in roll and pitch; from the model page a discovery job is started
// and followed, the report page opens by itself and shows the summary, the
// effects across the grid, per grid speed the located misfit, ranked
// hypotheses, named terms, before/after fits and simulations; the augmented
// model is one click away and is version 2 of the model.
//
//   cd web && npm ci && node --test tests/discovery.test.mjs
//
// Env: see harness.mjs; DISCOVERY_SCREENSHOT=/tmp/report.png saves the report.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid, inked, waitJob as waitFor } from './harness.mjs';

const H = harness({ extraArgs: ['--demo'] });
let mid;

const waitJob = (id, seconds) => waitFor(H, id, seconds);

before(async () => {
  await H.start();
  const cs = await H.api('GET', '/api/campaigns');
  const rov = cs.json.find((c) => /Surveyor/.test(JSON.stringify(c)));
  assert.ok(rov, 'the demo has the Surveyor campaign');
  // The baseline without g(η) and constant loads: the righting moment is
  // then missing from it (the default λ model estimates it itself).
  const j = await H.api('POST', '/api/jobs', {
    kind: 'identify',
    campaign_id: rov.id,
    method: 'lambda_kf',
    settings: { estimate_restoring: false, constant_loads: false },
  });
  assert.equal(j.status, 202, JSON.stringify(j.json));
  const done = await waitJob(j.json.id, 120);
  assert.equal(done.state, 'succeeded', JSON.stringify(done));
  mid = done.result.model_id;
});

after(() => H.stop());

test('discover the demo ROV\'s missing restoring from the model page and read the report', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/models/${mid}`);
    const panel = page.locator(tid('discovery-panel'));
    await panel.waitFor();
    assert.match(await panel.textContent(), /No discovery run on this model yet/);
    await page.getByRole('button', { name: 'Discover missing physics' }).click();
    await page.locator(tid('discover-progress')).waitFor();
    // Done: the report page opens by itself.
    await page.waitForURL(/#\/discrepancies\/[0-9a-f-]{36}$/, { timeout: 180000 });
    await page.locator(tid('discovery-summary')).waitFor();
    const summary = await page.textContent(tid('discovery-summary'));
    assert.match(summary, /restoring cos θ sin φ in roll: named at every grid speed/, summary);
    assert.match(summary, /restoring sin θ in pitch/, summary);
    const effects = await page.locator(tid('effect-row')).allTextContents();
    assert.ok(effects.some((e) => /roll/.test(e)) && effects.some((e) => /pitch/.test(e)), effects.join('\n'));

    // The first grid speed is open: location, hypotheses, findings, before/after.
    const point = page.locator(tid('discovery-point')).first();
    assert.ok(await point.evaluate((d) => d.open));
    assert.ok(await point.locator(tid('location-row')).count() === 6);
    assert.ok(await point.locator(tid('hypothesis-row')).count() > 1);
    const labels = await point.locator(tid('finding-label')).allTextContents();
    assert.ok(labels.some((l) => /roll/.test(l)), labels.join(', '));
    assert.match(await point.locator(tid('finding-estimates')).first().textContent(), /±/);
    const roll = point.locator(`${tid('before-after-row')}[data-dof="roll"]`);
    // Fits print with a true minus sign (and "‹ −1000 %" below −1000 %).
    const pct = async (t) => parseFloat((await roll.locator(tid(t)).textContent()).replace(/\u2212/g, '-').replace(/[^0-9.-]/g, ''));
    const [b, a] = [await pct('free-run-before'), await pct('free-run-after')];
    assert.ok(a > 50 && a - b > 30, `roll free-run fit ${b} % → ${a} %`);
    const plot = point.locator(`${tid('before-after-plot')}[data-dof="roll"] canvas >> nth=0`);
    await plot.waitFor();
    await plot.scrollIntoViewIfNeeded();
    assert.ok(await inked(plot) > 1000, 'the before/after plot looks blank');
    // A closed grid speed draws its plots when opened.
    const second = page.locator(tid('discovery-point')).nth(1);
    await second.locator('summary').click();
    await second.locator(`${tid('before-after-plot')} canvas >> nth=0`).waitFor();
    if (process.env.DISCOVERY_SCREENSHOT) await page.screenshot({ path: process.env.DISCOVERY_SCREENSHOT, fullPage: true });

    // The augmented model, one click away: version 2, discovered terms with ±.
    await page.getByRole('link', { name: /Open augmented model v2/ }).click();
    await page.waitForURL(/#\/models\/[0-9a-f-]{36}$/);
    await page.locator(tid('param-table')).waitFor();
    assert.match(await page.textContent(tid('model-method')), /Missing-physics discovery/);
    assert.match(await page.textContent(tid('model-parent')), /v1/);
    const groups = await page.locator(`${tid('param-row')} td:first-child`).allTextContents();
    assert.ok(groups.some((g) => /^discovered: restoring/.test(g)), 'discovered terms in the parameter table');
    assert.match(await page.textContent(tid('discover-origin')), /produced by/);
    // Back on the examined model the report is listed.
    await page.goto(`${H.base}/#/models/${mid}`);
    await page.locator(tid('discover-report-link')).first().waitFor();
  });
});

test('a discovery is cancelled from its panel, its progress never going backwards', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/models/${mid}`);
    await page.locator(tid('discovery-panel')).waitFor();
    // Record every value the bar shows.
    await page.evaluate(() => {
      window.shown = [];
      new MutationObserver(() => {
        const bar = document.querySelector('[data-testid="discover-progress"]');
        if (bar) window.shown.push(bar.value);
      }).observe(document.body, { subtree: true, childList: true, characterData: true });
    });
    await page.getByRole('button', { name: 'Discover missing physics' }).click();
    await page.locator(tid('discover-cancel')).click();
    const jobs = await H.api('GET', '/api/jobs');
    const job = jobs.json.filter((j) => j.kind === 'discover').sort((a, b) => (a.id < b.id ? 1 : -1))[0];
    const done = await waitJob(job.id, 120);
    assert.equal(done.state, 'cancelled', JSON.stringify(done));
    await page.locator(`${tid('discover-status')} >> text=cancelled`).first().waitFor();
    assert.equal(await page.locator(tid('discover-cancel')).count(), 0, 'no cancel once the job ended');
    const shown = await page.evaluate(() => window.shown);
    assert.ok(shown.every((v, i) => i === 0 || v >= shown[i - 1]), `progress went backwards: ${shown}`);
  });
});
