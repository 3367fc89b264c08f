// End-to-end test of the planner UI in a real (headless) Chromium.
//
// Starts the service itself on a free port with a fresh database, serves
// this web folder, and walks the planner like an engineer would.
//
//   cd web && npm ci && node --test tests/
//
// Env: SEATRIAL_BIN (default <repo>/target/release/seatrial),
//      CHROMIUM (default /usr/bin/chromium),
//      PLANNER_SCREENSHOT=/tmp/planner.png to save the plan page with an
//      experiment plotted.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { SURVEYOR_ROV } from '../templates.js';
import { harness, tid } from './harness.mjs';

// Server, browser and the page-problem recorder are shared with runs.test.mjs.
// `allow` lists the HTTP errors a scenario expects, e.g. the 404 of GET …/plan
// before a campaign is planned or the 422 of an impossible campaign.
const H = harness();
before(H.start);
after(H.stop);
const withPage = (allow, fn) => H.withPage(allow, fn);

const PLAN_404 = { method: 'GET', status: 404, path: /^\/api\/campaigns\/[^/]+\/plan$/ };

async function rows(page) {
  return page.locator(tid('plan-row')).count();
}

async function waitRows(page, n) {
  await page.waitForFunction((k) => document.querySelectorAll('[data-testid="plan-row"]').length === k, n);
}

async function createVesselFromTemplate(page, template, name) {
  await page.goto(`${H.base}/`);
  await page.click(tid('nav-vessels'));
  await page.click(tid('new-vessel'));
  await page.click(tid(template));
  await page.fill(tid('vessel-name'), name);
  await page.click(tid('create-vessel'));
  await page.waitForURL(/#\/vessels\/[0-9a-f-]{36}$/);
  await page.locator('h1', { hasText: name }).waitFor();
  return page.url().split('/').pop();
}

test('ROV: vessel from template → campaign on a filled grid → plan → experiment plot, zoom, CSV', async () => {
  await withPage([PLAN_404], async (page) => {
    // Vessel through the form, from the Surveyor template.
    await page.goto(`${H.base}/`);
    await page.click(tid('nav-vessels'));
    await page.click(tid('new-vessel'));
    await page.click(tid('template-rov'));
    assert.equal(await page.inputValue('[data-field="limits.surge.max_velocity"]'), String(SURVEYOR_ROV.limits.surge.max_velocity));
    assert.equal(await page.locator('[data-testid="limits-editor"] tbody tr').count(), 6);
    await page.fill(tid('vessel-name'), 'Surveyor ROV (e2e)');
    await page.click(tid('create-vessel'));
    await page.waitForURL(/#\/vessels\/[0-9a-f-]{36}$/);
    await page.locator('h1', { hasText: 'Surveyor ROV (e2e)' }).waitFor();

    // Campaign: 0.5 … 3.5 kn with the fill-range helper, static + dynamic.
    await page.click(tid('new-campaign-for-vessel'));
    await page.fill(tid('campaign-name'), 'LPV grid 0.5–3.5 kn');
    await page.selectOption(tid('grid-unit'), 'kn');
    await page.fill(tid('grid-from'), '0.5');
    await page.fill(tid('grid-to'), '3.5');
    await page.fill(tid('grid-step'), '0.5');
    await page.click(tid('grid-fill'));
    const speeds = await page.locator(tid('grid-speed')).evaluateAll((els) => els.map((e) => e.value));
    assert.deepEqual(speeds, ['0.5', '1', '1.5', '2', '2.5', '3', '3.5']);
    assert.match(await page.locator('.speed-row .conv').first().textContent(), /= 0\.257 m\/s/);
    await page.check(tid('family-static'));
    await page.check(tid('family-dynamic'));
    await page.uncheck(tid('family-recursive'));
    await page.uncheck(tid('family-validation'));
    await page.click(tid('create-campaign'));
    await page.waitForURL(/#\/campaigns\/[0-9a-f-]{36}$/);
    await page.locator(tid('no-plan')).waitFor();

    // Generate the plan: 7 × 11 static + 7 × 6 dynamic. The POST is held
    // back a little so the loading indicator can be seen.
    await page.route('**/api/campaigns/*/plan', async (route) => {
      if (route.request().method() === 'POST') await new Promise((r) => setTimeout(r, 400));
      await route.continue();
    });
    await page.click(tid('generate-plan'));
    await page.locator(tid('plan-loading')).waitFor({ state: 'visible' });
    assert.equal(await page.locator(tid('generate-plan')).isDisabled(), true);
    await waitRows(page, 119);
    await page.unroute('**/api/campaigns/*/plan');
    assert.equal(await page.textContent(tid('total-experiments')), '119');
    assert.match(await page.textContent(tid('total-time')), /^\d+:\d\d:\d\d$/);
    // The indicator goes once the answer is drawn (waitFor fails after its timeout).
    await page.locator(tid('plan-loading')).waitFor({ state: 'hidden' });
    await page.selectOption(tid('filter-family'), 'dynamic');
    assert.equal(await rows(page), 42);
    await page.selectOption(tid('filter-family'), 'static');
    assert.equal(await rows(page), 77);
    await page.selectOption(tid('filter-speed'), { index: 3 }); // 1.5 kn
    assert.equal(await rows(page), 11);
    await page.selectOption(tid('filter-family'), '');
    await page.selectOption(tid('filter-speed'), '');
    assert.equal(await rows(page), 119);

    // Re-planning the unchanged campaign stores nothing: still version 1.
    const firstId = await page.locator(tid('plan-row')).first().getAttribute('data-eid');
    await page.click(tid('generate-plan'));
    await page.locator(tid('banner-ok')).filter({ hasText: 'Plan v1 unchanged' }).waitFor();
    assert.match(await page.textContent(tid('plan-totals')), /Plan v1/);
    assert.equal(await page.locator(tid('plan-changes')).count(), 0);
    assert.equal(await page.locator(tid('plan-row')).first().getAttribute('data-eid'), firstId);

    // A re-plan with a second repetition (through the API): the page shows
    // version 2 and what changed against version 1.
    const status = await page.evaluate(async () => {
      const id = location.hash.split('/')[2];
      const r = await fetch(`/api/campaigns/${id}/plan`, {
        method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify({ repetitions: 2 }),
      });
      return r.status;
    });
    assert.equal(status, 201);
    await page.reload();
    await waitRows(page, 238);
    assert.match(await page.textContent(tid('plan-totals')), /Plan v2/);
    assert.match(await page.textContent(tid('plan-changes')), /119 added, 0 removed, 0 changed, 119 unchanged against v1/);
    assert.equal(await page.locator(`[data-testid="plan-row"][data-eid="${firstId}"]`).count(), 1);

    // Open a dynamic sway experiment.
    await page.click('[data-testid="plan-row"][data-code="DYN-1.5kn-sway-r1"]');
    await page.waitForURL(/\/experiments\/[0-9a-f-]{36}$/);
    const plot = page.locator(`${tid('schedule-plot')} .uplot`);
    await plot.waitFor();
    const canvas = page.locator(`${tid('schedule-plot')} canvas`);
    const box = await canvas.boundingBox();
    assert.ok(box && box.width > 300 && box.height > 100, `canvas size ${JSON.stringify(box)}`);
    const inked = await canvas.evaluate((c) => {
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n += 1;
      return n;
    });
    assert.ok(inked > 1000, `schedule canvas looks blank (${inked} painted pixels)`);
    const legend = await page.textContent(`${tid('schedule-plot')} .u-legend`);
    for (const col of ['u_ref', 'v_ref', 'w_ref', 'p_ref', 'q_ref', 'r_ref']) assert.ok(legend.includes(col), `legend lacks ${col}: ${legend}`);
    assert.ok(await page.locator(`${tid('psd-plot')} canvas`).count() > 0, 'PSD plot drawn');
    assert.match(await page.textContent(tid('instruction')), /1\.5 kn/);
    assert.ok((await page.textContent(tid('channel-table'))).includes('PRBS'));

    // Zoom: drag over the middle of the plot, the x range shrinks; double-click resets.
    const xRange = () => page.evaluate(() => {
      const u = window.__plots.schedule;
      return [u.scales.x.min, u.scales.x.max];
    });
    const [x0, x1] = await xRange();
    const over = await page.locator(`${tid('schedule-plot')} .u-over`).boundingBox();
    const y = over.y + over.height / 2;
    await page.mouse.move(over.x + over.width * 0.3, y);
    await page.mouse.down();
    await page.mouse.move(over.x + over.width * 0.45, y, { steps: 5 });
    await page.mouse.move(over.x + over.width * 0.6, y, { steps: 5 });
    await page.mouse.up();
    const [z0, z1] = await xRange();
    assert.ok(z1 - z0 < (x1 - x0) * 0.5, `zoom did not shrink the x range: [${x0}, ${x1}] → [${z0}, ${z1}]`);
    assert.ok(z0 > x0 && z1 < x1, 'zoomed range lies inside the full range');
    await page.mouse.dblclick(over.x + over.width / 2, y);
    const [r0, r1] = await xRange();
    assert.ok(Math.abs(r0 - x0) < 1e-9 && Math.abs(r1 - x1) < 1e-9, `double-click did not reset: [${r0}, ${r1}]`);

    // Legend toggle hides a series.
    await page.locator(`${tid('schedule-plot')} .u-legend .u-series`, { hasText: 'w_ref' }).click();
    assert.equal(await page.evaluate(() => window.__plots.schedule.series.find((s) => s.label.startsWith('w_ref')).show), false);

    if (process.env.PLANNER_SCREENSHOT) await page.screenshot({ path: process.env.PLANNER_SCREENSHOT, fullPage: true });

    // CSV download: header and one row per schedule sample.
    const samples = await page.evaluate(() => window.__plots.schedule.data[0].length);
    const [download] = await Promise.all([page.waitForEvent('download'), page.click(tid('download-csv'))]);
    assert.match(download.suggestedFilename(), /DYN-1\.5kn-sway-r1\.csv$/);
    const csv = readFileSync(await download.path(), 'utf8').trim().split(/\r?\n/);
    assert.ok(csv[0].startsWith('t,u_ref,v_ref'), `CSV header: ${csv[0]}`);
    assert.equal(csv.length - 1, samples);
    assert.ok(samples > 100);

    // The other exports answer.
    const json = await page.getAttribute(tid('download-json'), 'href');
    const sched = await (await page.request.get(H.base + json)).json();
    assert.equal(sched.t.length, samples);
    const sheet = await page.getAttribute(tid('runsheet-link'), 'href');
    assert.equal(await page.getAttribute(tid('runsheet-link'), 'target'), '_blank');
    const res = await page.request.get(H.base + sheet);
    assert.equal(res.status(), 200);
    assert.match(res.headers()['content-type'], /text\/html/);

  });
});

test('DP: supply vessel template, three decoupled manoeuvres, N = 2 at 0 m/s → 6 experiments', async () => {
  await withPage([PLAN_404], async (page) => {
    await createVesselFromTemplate(page, 'template-dp', 'Supply vessel (e2e)');
    assert.ok((await page.textContent(tid('limits-table'))).includes('yaw'));
    await page.click(tid('new-campaign-for-vessel'));
    await page.fill(tid('campaign-name'), 'DP SI1→SI2→SI3');
    await page.selectOption(tid('grid-unit'), 'm/s');
    await page.click(tid('grid-add'));
    await page.fill('[data-field="grid.speeds[0]"]', '0');
    for (const f of ['dp_surge', 'dp_sway_yaw', 'dp_azimuth']) await page.check(tid(`family-${f}`));
    await page.uncheck(tid('family-validation'));
    await page.fill(tid('campaign-repetitions'), '2');
    await page.click(tid('create-campaign'));
    await page.waitForURL(/#\/campaigns\/[0-9a-f-]{36}$/);
    await page.click(tid('generate-plan'));
    await waitRows(page, 6);
    assert.equal(await page.textContent(tid('total-experiments')), '6');
    const fams = await page.locator(tid('plan-row')).evaluateAll((rs) => rs.map((r) => r.dataset.family));
    assert.deepEqual(fams, ['dp_surge', 'dp_surge', 'dp_sway_yaw', 'dp_sway_yaw', 'dp_azimuth', 'dp_azimuth']);

    // A sway–yaw manoeuvre drives the tunnel thrusters.
    await page.locator(tid('plan-row')).nth(2).click();
    await page.locator(`${tid('schedule-plot')} .uplot`).waitFor();
    assert.ok((await page.textContent(`${tid('schedule-plot')} .u-legend`)).includes('thr_3'));
    assert.ok((await page.textContent(tid('channel-table'))).includes('aft tunnel'));
  });
});

test('impossible grid: 5 kn above the ROV’s 4.3 kn shows the server’s 422 on that speed', async () => {
  const CAMPAIGN_422 = { method: 'POST', status: 422, path: /^\/api\/campaigns$/ };
  await withPage([CAMPAIGN_422, PLAN_404], async (page) => {
    const res = await page.request.post(`${H.base}/api/vessels`, { data: { ...SURVEYOR_ROV, name: 'Surveyor ROV (422)' } });
    assert.equal(res.status(), 201);
    const vessel = await res.json();
    await page.goto(`${H.base}/#/campaigns/new?vessel=${vessel.id}`);
    await page.fill(tid('campaign-name'), 'too fast');
    await page.selectOption(tid('grid-unit'), 'kn');
    await page.fill(tid('grid-from'), '0.5');
    await page.fill(tid('grid-to'), '1.5');
    await page.fill(tid('grid-step'), '0.5');
    await page.click(tid('grid-fill'));
    await page.fill('[data-field="grid.speeds[2]"]', '5');
    await page.click(tid('create-campaign'));

    const err = page.locator('[data-testid="field-error"][data-for="grid.speeds[2]"]');
    await err.waitFor();
    const text = await err.textContent();
    assert.match(text, /5 kn .* above the vessel's maximum forward speed/);
    assert.match(text, /limit 2\.212/);
    const input = page.locator('[data-field="grid.speeds[2]"]');
    assert.equal(await input.getAttribute('aria-invalid'), 'true');
    assert.ok((await input.getAttribute('class')).includes('invalid'));
    // The message sits in the same grid row as the offending speed.
    assert.equal(await err.evaluate((e) => e.closest('li').querySelector('input').dataset.field), 'grid.speeds[2]');
    assert.match(await page.textContent(tid('banner-error')), /422 · .*grid\.speeds\[2\]/);
    assert.match(page.url(), /#\/campaigns\/new/);
    assert.equal(await page.locator('.field-error').count(), 1);

    // Fixing it clears the error and creates the campaign.
    await page.fill('[data-field="grid.speeds[2]"]', '1.5');
    await page.click(tid('create-campaign'));
    await page.waitForURL(/#\/campaigns\/[0-9a-f-]{36}$/);
    await page.locator(tid('no-plan')).waitFor();
    assert.equal(await page.locator('.field-error').count(), 0);
  });
});

test('ROV autopilot: declared in the form, a negative rate gain is the server’s 422 on that cell, then stored, shown and copied', async () => {
  const VESSEL_422 = { method: 'POST', status: 422, path: /^\/api\/vessels$/ };
  await withPage([VESSEL_422], async (page) => {
    await page.goto(`${H.base}/`);
    await page.click(tid('nav-vessels'));
    await page.click(tid('new-vessel'));
    await page.click(tid('template-rov'));
    await page.fill(tid('vessel-name'), 'Surveyor ROV (autopilot)');
    assert.equal(await page.locator(tid('autopilot-editor')).count(), 0);
    await page.check(tid('autopilot-on'));
    const gains = {
      surge: [900, 180], sway: [1200, 320], heave: [1500, 400], roll: [420, 0, 310], pitch: [650, 0, 480], yaw: [300, 80],
    };
    for (const [d, [kp, ki, kd]] of Object.entries(gains)) {
      await page.fill(`[data-field="autopilot.loops.${d}.kp"]`, String(kp));
      await page.fill(`[data-field="autopilot.loops.${d}.ki"]`, String(ki));
      if (kd != null) await page.fill(`[data-field="autopilot.loops.${d}.kd"]`, String(kd));
    }
    // Yaw has no attitude loop: no K_d cell in the form; the server's 422
    // names the field when a client sends one anyway.
    assert.equal(await page.locator('[data-field="autopilot.loops.yaw.kd"]').count(), 0);
    await page.fill('[data-field="autopilot.restoring_feed_forward.w_minus_b"]', '45');
    // One feed-forward term without the other is caught before sending.
    await page.click(tid('create-vessel'));
    const missing = page.locator('[data-testid="field-error"][data-for="autopilot.restoring_feed_forward.zg_w_minus_zb_b"]');
    await missing.waitFor();
    assert.match(await missing.textContent(), /required/);
    await page.fill('[data-field="autopilot.restoring_feed_forward.zg_w_minus_zb_b"]', '1200');
    // A negative gain is the server's 422 on that cell.
    await page.fill('[data-field="autopilot.loops.pitch.kd"]', '-5');
    await page.click(tid('create-vessel'));
    const err = page.locator('[data-testid="field-error"][data-for="autopilot.loops.pitch.kd"]');
    await err.waitFor();
    assert.match(await err.textContent(), /gain between 0 and/);
    await page.fill('[data-field="autopilot.loops.pitch.kd"]', '480');
    await page.click(tid('create-vessel'));
    await page.waitForURL(/#\/vessels\/[0-9a-f-]{36}$/);
    const table = page.locator(tid('autopilot-table'));
    await table.waitFor();
    const text = await table.textContent();
    assert.match(text, /roll.*attitude PD.*420/);
    assert.match(text, /yaw.*velocity PI.*300/);
    assert.match(text, /W − B = 45/);
    const id = page.url().split('/').pop();
    const stored = await (await page.request.get(`${H.base}/api/vessels/${id}`)).json();
    assert.deepEqual(stored.profile.autopilot.loops.pitch, { kp: 650, ki: 0, kd: 480 });
    assert.deepEqual(stored.profile.autopilot.loops.surge, { kp: 900, ki: 180 });
    // Copy as new keeps it.
    await page.click('a:has-text("Copy as new vessel")');
    await page.locator(tid('autopilot-editor')).waitFor();
    assert.equal(await page.inputValue('[data-field="autopilot.loops.roll.kd"]'), '310');
  });
});
