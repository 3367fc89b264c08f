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
let reportUrl;

const waitJob = (id, seconds) => waitFor(H, id, seconds);

before(async () => {
  await H.start();
  const cs = await H.api('GET', '/api/campaigns');
  const rov = cs.json.find((c) => /Surveyor/.test(JSON.stringify(c)));
  assert.ok(rov, 'the demo has the Surveyor campaign');
  // The baseline without g(η), constant loads and C(δ)δ: the righting
  // moment is then missing from it (the default λ model estimates it
  // itself), and no second-order force is built from the roll and pitch
  // inertia that such a baseline gets wrong.
  const j = await H.api('POST', '/api/jobs', {
    kind: 'identify',
    campaign_id: rov.id,
    method: 'lambda_kf',
    settings: { estimate_restoring: false, constant_loads: false, coriolis_second_order: false, symmetric_inertia: false, quadratic_damping: false, extend_above_grid: false },
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
    reportUrl = page.url();
    await page.locator(tid('discovery-summary')).waitFor();
    const summary = await page.textContent(tid('discovery-summary'));
    assert.match(summary, /restoring cos θ sin φ in roll: named at every grid speed/, summary);
    assert.match(summary, /restoring sin θ in pitch/, summary);
    const effects = await page.locator(tid('effect-row')).allTextContents();
    assert.ok(effects.some((e) => /roll/.test(e)) && effects.some((e) => /pitch/.test(e)), effects.join('\n'));
    // Ranked by what their speeds' findings gain alone on the held-out
    // runs, then by the speeds that chose them, then by held-out gain.
    const num = async (t) => (await page.locator(tid(t)).allTextContents()).map((x) => parseFloat(x.replace(/\u2212/g, '-')));
    const [advantages, gains] = [await num('effect-advantage'), await num('effect-evidence')];
    const speeds = (await page.locator(`${tid('effect-row')} td:nth-child(2)`).allTextContents()).map((t) => t.split(',').length);
    const after = (i) => advantages[i] < advantages[i - 1]
      || (advantages[i] === advantages[i - 1] && (speeds[i] < speeds[i - 1] || (speeds[i] === speeds[i - 1] && gains[i] <= gains[i - 1])));
    assert.ok(advantages[0] > 0 && gains.every((g, i) => g > 0 && (i === 0 || after(i))),
      `advantages ${advantages.join(', ')}, gains ${gains.join(', ')} at ${speeds.join(', ')} speeds`);
    // Each effect says whether the stored model keeps it, and why.
    const kept = await page.locator(tid('effect-kept')).evaluateAll((xs) => xs.map((x) => x.dataset.kept));
    assert.ok(kept.length === effects.length && kept.every((k) => k === 'true' || k === 'false') && kept.includes('true'), kept.join(', '));
    assert.match(await page.locator(tid('effect-kept')).first().textContent(), /on the held-out runs/);

    // The first grid speed is open: location, hypotheses, findings, before/after.
    const point = page.locator(tid('discovery-point')).first();
    assert.ok(await point.evaluate((d) => d.open));
    assert.ok(await point.locator(tid('location-row')).count() === 6);
    assert.ok(await point.locator(tid('hypothesis-row')).count() > 1);
    // Each hypothesis shows the size of its force against the command, in %.
    const sizes = await point.locator(tid('hypothesis-size')).allTextContents();
    assert.ok(sizes.length > 1 && sizes.every((t) => /^[0-9.e\u2212-]+ %$/.test(t)), sizes.join(', '));
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
    // Discovery on the augmented model continues from its terms: they are
    // kept, not named again.
    await page.getByRole('button', { name: 'Discover missing physics' }).click();
    await page.waitForURL((u) => /#\/discrepancies\/[0-9a-f-]{36}$/.test(u.toString()) && u.toString() !== reportUrl, { timeout: 180000 });
    await page.locator(tid('discovery-summary')).waitFor();
    const again = await page.textContent(tid('discovery-summary'));
    assert.match(again, /(Nothing found beyond|Continued from) the terms the model carries \(.*restoring/, again);
    assert.doesNotMatch(again, /restoring cos θ sin φ in roll: named/, again);
    assert.match(await page.locator(tid('discovery-point')).first().textContent(), /Started from the terms the model carries/);
    // Back on the examined model the report is listed.
    await page.goto(`${H.base}/#/models/${mid}`);
    await page.locator(tid('discover-report-link')).first().waitFor();
  });
});

test('a look-alike\'s deciding experiment is added to the plan from the report', async () => {
  assert.ok(reportUrl, 'the first test opened a report');
  const did = reportUrl.split('/').pop();
  const d = await H.api('GET', `/api/discrepancies/${did}`);
  const cid = d.json.discrepancy.campaign_id;
  const c = await H.api('GET', `/api/campaigns/${cid}`);
  const v = await H.api('GET', `/api/vessels/${c.json.vessel_id}`);
  const profile = v.json.profile || v.json;
  // A proposal as discovery writes one: every force column, sway excited.
  const channels = profile.dofs.map((dof) => {
    const l = profile.limits[dof];
    const excited = dof === 'sway';
    return {
      column: { surge: 'tau_X', sway: 'tau_Y', heave: 'tau_Z', roll: 'tau_K', pitch: 'tau_M', yaw: 'tau_N' }[dof],
      unit: ['roll', 'pitch', 'yaw'].includes(dof) ? 'N·m' : 'N',
      dof,
      excited,
      waveform: excited ? { shape: 'square', period_s: 10 * l.time_constant_s } : { shape: 'constant' },
      offset: dof === 'surge' ? 0.3 * l.max_force : 0,
      amplitude: excited ? 0.5 * l.max_force : 0,
      limit: l.max_force,
      rate_limit: l.max_force_rate,
    };
  });
  const experiment = {
    separates: ['quadratic damping (sway)', 'Coriolis from M'],
    family: 'dynamic', dof: 'sway', signal: 'square', grid_speed_mps: 0.5,
    headings_deg: [0, 90], duration_s: 90, channels, predicted_separation_sigma: 5,
    instruction: 'a sway square wave at a steady surge offset',
  };
  const before = await H.api('GET', `/api/campaigns/${cid}/plan`);
  await H.withPage([], async (page) => {
    // The report as the service sends it, with one look-alike pair added
    // at the first grid speed (the demo's data separate all of theirs).
    await page.route(`**/api/discrepancies/${did}`, async (route) => {
      const response = await route.fetch();
      const json = await response.json();
      json.report.points[0].report.ambiguities = [{
        chosen: { effect: 'quadratic_damping', dof: 'sway' },
        alternative: { effect: 'coriolis' }, cv_gains: [0.01, 0.009],
        text: 'Sway quadratic damping and Coriolis explain the held-out runs about equally.',
        experiment,
      }];
      await route.fulfill({ response, json });
    });
    await page.goto(reportUrl);
    const amb = page.locator(tid('ambiguity')).first();
    await amb.waitFor();
    assert.match(await amb.textContent(), /2 headings × 90 s/);
    await amb.locator(tid('add-deciding')).click();
    await amb.locator(`${tid('deciding-added')} >> text=Added to plan`).waitFor();
    assert.match(await amb.locator(tid('deciding-added')).textContent(), /DEC1-sway-000, DEC1-sway-090/);
    // Twice: nothing new.
    await page.reload();
    await page.locator(tid('add-deciding')).first().click();
    await page.locator(`${tid('deciding-added')} >> text=Already in the plan`).waitFor();
    // On the plan: after the plan's own runs, tagged, the rest unchanged.
    await page.unroute(`**/api/discrepancies/${did}`);
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(`${tid('plan-row')}[data-code="DEC1-sway-090"] ${tid('deciding-tag')}`).waitFor();
  });
  const after = await H.api('GET', `/api/campaigns/${cid}/plan`);
  const ids = (p) => p.json.experiments.map((e) => `${e.code}:${e.id}`);
  assert.deepEqual(ids(after).slice(0, before.json.experiments.length), ids(before));
  assert.deepEqual(after.json.experiments.slice(-2).map((e) => e.code), ['DEC1-sway-000', 'DEC1-sway-090']);
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
