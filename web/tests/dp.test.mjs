// End-to-end DP identification in a real (headless) Chromium, on the demo:
// the supply vessel's planned SI1–SI3 manoeuvres and validation run, flown
// by the DP ship truth when the service seeds its demo (`--demo`), are
// identified by the parallel EKF from the campaign page; the model page
// shows θ″ with ± std, the DP matrices, and x, y, ψ validation plots.
//
//   cd web && npm ci && node --test tests/dp.test.mjs
//
// Env: see harness.mjs; DP_SCREENSHOT=/tmp/dp.png saves the model page.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { harness, tid, inked } from './harness.mjs';
import { SUPPLY_VESSEL } from '../templates.js';

const H = harness({ extraArgs: ['--demo'] });
let cid;

before(async () => {
  await H.start();
  const cs = await H.api('GET', '/api/campaigns');
  assert.equal(cs.status, 200);
  const dp = cs.json.find((c) => /Supply vessel/.test(JSON.stringify(c)));
  assert.ok(dp, `the demo has the DP campaign: ${JSON.stringify(cs.json).slice(0, 300)}`);
  cid = dp.id;
  const runs = await H.api('GET', `/api/campaigns/${cid}/runs`);
  assert.equal(runs.json.filter((r) => r.status === 'accepted').length, 8, 'six manoeuvres and two validation runs were flown');
});

after(() => H.stop());

test('the vessel form declares shaft-speed logs and a logged azimuth angle; the page says how each column is read', async () => {
  const VESSEL_422 = { method: 'POST', status: 422, path: /^\/api\/vessels$/ };
  await H.withPage([VESSEL_422], async (page) => {
    await page.goto(`${H.base}/#/vessels/new`);
    await page.click(tid('template-dp'));
    await page.fill(tid('vessel-name'), 'Supply vessel, shaft speeds and a turning azimuth');
    await page.selectOption(tid('heading-unit'), 'deg');
    await page.fill('[data-field="dp_prior.length_m"]', '76.2');
    // The port main propeller's column is its shaft speed.
    await page.selectOption(tid('thruster-signal-1'), 'shaft_speed');
    await page.fill('[data-field="inputs.thrusters[0].signal.rated_rpm"]', '150');
    // The bow azimuth (T column (0, 1, 0.3373) = pushing to starboard) logs α.
    await page.check(tid('thruster-angle-6'));
    await page.selectOption('[data-field="inputs.thrusters[5].logged_angle.unit"]', 'deg');
    // A position its T column cannot come from: the server's 422 is shown on T.
    await page.fill('[data-field="inputs.thrusters[5].logged_angle.x_m"]', '10');
    await page.fill('[data-field="inputs.thrusters[5].logged_angle.y_m"]', '0');
    await page.click(tid('create-vessel'));
    const err = page.locator(`${tid('field-error')}[data-for="inputs.configuration"]`);
    await err.waitFor();
    assert.match(await err.textContent(), /column thr_6: thruster .bow azimuth thruster. logs its angle/);
    // Where it is: x = 0.3373 L forward on the centreline.
    await page.fill('[data-field="inputs.thrusters[5].logged_angle.x_m"]', '25.70');
    await page.click(tid('create-vessel'));
    await page.waitForURL(/#\/vessels\/[0-9a-f-]{36}$/);
    const id = page.url().split('/').pop();
    const v = await H.api('GET', `/api/vessels/${id}`);
    assert.equal(v.status, 200);
    const prof = v.json.profile;
    const th = prof.inputs.thrusters;
    assert.deepEqual(th[0].signal, { kind: 'shaft_speed', rated_rpm: 150 });
    assert.deepEqual(th[5].logged_angle, { unit: 'deg', x_m: 25.7, y_m: 0 });
    assert.equal(th[2].signal?.kind ?? 'command', 'command');
    assert.equal(prof.heading_unit, 'deg');
    assert.equal(prof.dp_prior.length_m, 76.2);
    const rows = await page.locator(`${tid('thruster-rows')} tr`).allTextContents();
    assert.match(rows[0], /shaft speed n, u = \|n\|n \/ \(150 rpm\)²/);
    assert.match(rows[5], /azi_6 logged in degrees, at x = 25\.70* m, y = 0 m/);
    assert.match(rows[4], /command u/);
    assert.equal(await page.textContent(tid('heading-unit')), 'degrees');
    assert.match(await page.textContent(tid('ship-length')), /^76\.20* m$/);
    // Copied as a new vessel, the form carries both declarations over.
    await page.goto(`${H.base}/#/vessels/new?from=${id}`);
    assert.equal(await page.inputValue('[data-field="inputs.thrusters[0].signal.rated_rpm"]'), '150');
    assert.ok(await page.isChecked(tid('thruster-angle-6')));
    assert.equal(await page.inputValue('[data-field="inputs.thrusters[5].logged_angle.x_m"]'), '25.7');
  });
});

test('a DP vessel logging forces τ is offered no azimuth manoeuvre; one with an azimuth is', async () => {
  const tau = { ...SUPPLY_VESSEL, name: 'Supply vessel logging τ', inputs: { kind: 'generalized_forces' } };
  const made = await H.api('POST', '/api/vessels', tau);
  assert.equal(made.status, 201, JSON.stringify(made.json));
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/new?vessel=${made.json.id}`);
    await page.locator(tid('family-dp_surge')).waitFor();
    assert.equal(await page.locator(tid('family-dp_azimuth')).count(), 0);
    assert.ok(await page.isChecked(tid('family-dp_sway_yaw')));
    const withAzimuth = await H.api('POST', '/api/vessels', { ...SUPPLY_VESSEL, name: 'Supply vessel with its azimuth' });
    assert.equal(withAzimuth.status, 201);
    await page.goto(`${H.base}/#/campaigns/new?vessel=${withAzimuth.json.id}`);
    await page.locator(tid('family-dp_azimuth')).waitFor();
    assert.ok(await page.isChecked(tid('family-dp_azimuth')));
  });
});

test('identify the demo supply vessel by the parallel EKF and read its model page', async () => {
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    const form = page.getByRole('form', { name: 'Identify a model' });
    await form.waitFor();
    const methods = await page.locator(`${tid('identify-method')} option`).evaluateAll((os) => os.map((o) => o.value));
    assert.deepEqual(methods, ['parallel_ekf', 'n4sid']);
    assert.match(await page.textContent(tid('identify-method-help')), /SI1 surge → SI2 sway–yaw → SI3 azimuth/);
    // The prediction-error refinement is on by default and can be turned off (staging alone).
    assert.ok(await page.locator(tid('identify-refine')).isVisible());
    assert.ok(await page.locator(tid('identify-refine')).isChecked());
    const roles = await page.locator(tid('identify-role')).allTextContents();
    assert.deepEqual(roles.filter((r) => /SI/.test(r)).sort(), ['estimation (SI1)', 'estimation (SI1)', 'estimation (SI2)', 'estimation (SI2)', 'estimation (SI3)', 'estimation (SI3)']);
    assert.match(await page.textContent(tid('identify-roles')), /8 of 8 accepted runs: 6 to estimate from, 2 held out/);
    await page.getByRole('button', { name: 'Start identification' }).click();
    const row = page.locator(tid('job-row')).first();
    await page.locator(`${tid('job-row')}[data-state="succeeded"]`).waitFor({ timeout: 120000 });

    await row.getByRole('link', { name: /Open model/ }).click();
    await page.waitForURL(/#\/models\/[0-9a-f-]{36}$/);
    await page.locator(tid('param-table')).waitFor();
    assert.match(await page.textContent(tid('model-method')), /Parallel EKF \(DP ship\)/);
    assert.equal(await page.locator(tid('param-row')).count(), 9);
    const symbols = await page.locator(`${tid('param-row')} td:nth-child(2)`).allTextContents();
    assert.match(symbols.join(' '), /θ″1 \(A_h11\).*θ″9 \(K6\)/);
    const stds = await page.locator(tid('param-std')).allTextContents();
    assert.ok(stds.every((s) => /^± \S+/.test(s)), `± std on every θ″: ${stds}`);
    // The DP matrices.
    for (const t of ['dp-a-h', 'dp-k', 'dp-m', 'dp-d', 'dp-t', 'dp-a', 'dp-b', 'dp-a-si', 'dp-b-si']) {
      assert.equal(await page.locator(tid(t)).count(), 1, t);
    }
    assert.match(await page.textContent(tid('dp-a-h')), /±/);
    // The refinement after the staging: what it did, and the staged EKF's θ″ beside the stored ones.
    const ref = page.locator(tid('dp-refinement'));
    assert.equal(await ref.count(), 1);
    if (await ref.getAttribute('data-applied') === 'true') {
      assert.match(await ref.textContent(), /refined after the staged EKF by prediction error.*step/);
      assert.equal(await page.locator(`${tid('dp-refinement-table')} tbody tr`).count(), 9);
    } else {
      assert.match(await ref.textContent(), /are the staged EKF's: \S/);
    }
    assert.equal(await page.locator(`${tid('dp-b')} td`).count(), 18);
    // Validation of x, y, ψ with plots drawn.
    const chans = await page.locator(tid('fit-row')).evaluateAll((rs) => rs.map((r) => r.dataset.channel));
    assert.deepEqual(chans, ['x', 'y', 'psi', 'x', 'y', 'psi']);
    for (const ch of ['x', 'psi']) {
      const c = page.locator(`${tid('pvm-plot')}[data-channel="${ch}"] canvas >> nth=0`);
      await c.waitFor();
      await c.scrollIntoViewIfNeeded();
      assert.ok(await inked(c) > 1000, `${ch} plot looks blank`);
    }
    // Fossen export is available; ZOH gives ν(k+1) = Φν + Γu.
    const href = await page.getAttribute(tid('export-fossen'), 'href');
    const res = await page.request.get(H.base + href);
    assert.equal(res.status(), 200);
    assert.equal((await res.json()).K.length, 6);
    await page.getByLabel('Sample time h [s]').fill('1');
    await page.getByRole('button', { name: 'Discretize (ZOH)' }).click();
    await page.locator(tid('zoh-point')).first().waitFor();
    assert.equal(await page.locator(`${tid('zoh-gamma')} td`).count(), 18);
    if (process.env.DP_SCREENSHOT) await page.screenshot({ path: process.env.DP_SCREENSHOT, fullPage: true });
  });
});

test('the supply vessel page draws its thruster layout from T', async () => {
  const c = await H.api('GET', `/api/campaigns/${cid}`);
  assert.equal(c.status, 200);
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/vessels/${c.json.vessel_id}`);
    await page.locator(tid('thruster-layout')).waitFor();
    const marks = await page.locator(tid('thruster-mark')).evaluateAll((gs) => gs.map((g) => ({
      n: Number(g.dataset.thruster), x: g.dataset.x === '' ? null : Number(g.dataset.x), y: Number(g.dataset.y),
    })));
    assert.equal(marks.length, 6, 'all six thrusters push in the horizontal plane');
    const at = (n) => marks.find((m) => m.n === n);
    // Mains: x is open in T, the offset is y = −N/X: port (y < 0) and starboard.
    assert.equal(at(1).x, null);
    assert.ok(Math.abs(at(1).y + 0.0472) < 1e-9 && Math.abs(at(2).y - 0.0472) < 1e-9, JSON.stringify(marks));
    // Tunnels and the azimuth on the centreline at x = N/Y: two aft, two forward.
    assert.ok(Math.abs(at(3).x + 0.4108) < 1e-9 && Math.abs(at(4).x + 0.3858) < 1e-9);
    assert.ok(Math.abs(at(5).x - 0.4554) < 1e-9 && Math.abs(at(6).x - 0.3373) < 1e-9);
    // Drawn where they are: the bow tunnel right of (forward of) the aft ones.
    const cxOf = (n) => page.locator(`${tid('thruster-mark')}[data-thruster="${n}"] circle`).getAttribute('cx').then(Number);
    assert.ok(await cxOf(5) > await cxOf(3));
    const rows = await page.locator(`${tid('thruster-positions')} tbody tr`).allTextContents();
    assert.equal(rows.length, 6);
    assert.match(rows[0], /at the stern .*y = −N \/ X/);
    assert.match(rows[4], /on the centreline, x = N \/ Y/);
  });
});
