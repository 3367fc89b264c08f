// The engineer's plot views in a real (headless) Chromium, on the demo's
// Surveyor ROV campaign identified by the λ-filter (LPV) and N4SID: the run
// page's time plot of every channel (select a window → its statistics),
// and on the model page the Bode over a run's H1 with coherence, the
// pole-zero map, step/impulse, Hankel singular values, the input–residual
// cross-correlation and the overlay compare of several models (zoomed to a
// window selected on the run page). Each plot
// is drawn (canvas inked, series present) and its PNG button downloads a
// PNG (magic bytes); SVG and CSV downloads are checked on one plot each.
// No sideways scroll at 1440 px; at 390 px nothing of these views reaches
// past the window (the page header is wider than a phone: not theirs). Screenshots go to
// $VIEWS_SHOTS (default /tmp/views-shots).
//
//   cd web && npm ci && node --test tests/views.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { harness, tid, inked, waitJob as waitFor } from './harness.mjs';

const SHOTS = process.env.VIEWS_SHOTS || '/tmp/views-shots';
const H = harness({ extraArgs: ['--demo'] });
let lpv;
let n4;
let valRun;

const waitJob = (id, seconds) => waitFor(H, id, seconds);

async function identify(cid, method) {
  const j = await H.api('POST', '/api/jobs', { kind: 'identify', campaign_id: cid, method });
  assert.equal(j.status, 202, JSON.stringify(j.json));
  const done = await waitJob(j.json.id, 240);
  assert.equal(done.state, 'succeeded', JSON.stringify(done));
  return done.result.model_id;
}

before(async () => {
  mkdirSync(SHOTS, { recursive: true });
  await H.start();
  const cs = await H.api('GET', '/api/campaigns');
  const rov = cs.json.find((c) => /Surveyor/.test(JSON.stringify(c)));
  assert.ok(rov, 'the demo has the Surveyor campaign');
  lpv = await identify(rov.id, 'lambda_kf');
  n4 = await identify(rov.id, 'n4sid');
  const m = await H.api('GET', `/api/models/${lpv}`);
  valRun = m.json.validation_run_ids[0];
  assert.ok(valRun, 'a run is held out for validation');
});

after(() => H.stop());

/** Click the `kind` export button inside `scope`; the downloaded bytes. */
async function exported(page, scope, kind = 'png') {
  const btn = scope.locator(`[data-export="${kind}"]`).first();
  await btn.scrollIntoViewIfNeeded();
  const [dl] = await Promise.all([page.waitForEvent('download'), btn.click()]);
  const file = await dl.path();
  return { name: dl.suggestedFilename(), bytes: readFileSync(file) };
}

const PNG_MAGIC = [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];
function assertPng(f, what) {
  assert.match(f.name, /\.png$/, `${what}: ${f.name}`);
  assert.deepEqual([...f.bytes.subarray(0, 8)], PNG_MAGIC, `${what}: PNG magic bytes`);
  assert.ok(f.bytes.length > 1000, `${what}: ${f.bytes.length} bytes`);
}

/** Series count and drawn points of the live uPlot chart `name`. */
function chartInfo(page, name) {
  return page.evaluate((n) => {
    const u = window.__plots[n];
    if (!u || !u.data) return null;
    return { series: u.series.length - 1, points: u.data[0].length, values: u.data.slice(1).map((s) => s.filter((v) => v != null).length) };
  }, name);
}

async function noSideScroll(page, what) {
  const [sw, cw] = await page.evaluate(() => [document.documentElement.scrollWidth, document.documentElement.clientWidth]);
  assert.ok(sw <= cw + 1, `${what}: page ${sw} px wide in a ${cw} px window`);
}

/**
 * Nothing of the section `sel` reaches past the window's right edge, but
 * inside its own horizontal scroller (a wide table in .table-x). (At 390 px
 * the page header itself is wider than the phone: not these views'.)
 */
async function sectionFits(page, sel, what) {
  const over = await page.evaluate((s) => {
    const cw = document.documentElement.clientWidth;
    const root = document.querySelector(s);
    const scrolls = (el) => {
      for (let p = el.parentElement; p && p !== root.parentElement; p = p.parentElement) {
        if (/(auto|scroll|hidden)/.test(getComputedStyle(p).overflowX)) return true;
      }
      return false;
    };
    return [...root.querySelectorAll('*')].filter((el) => {
      const r = el.getBoundingClientRect();
      return r.width > 0 && r.right > cw + 1 && !scrolls(el);
    }).slice(0, 5).map((el) => `${el.tagName}.${el.className} ${el.dataset.testid || ''} right=${Math.round(el.getBoundingClientRect().right)}`);
  }, sel);
  assert.deepEqual(over, [], `${what}: reaches past the window`);
}

test('run page: time plot of every channel, a selected window and its statistics, exports', async () => {
  await H.withPage([], async (page) => {
    await page.setViewportSize({ width: 1440, height: 1000 });
    await page.goto(`${H.base}/#/runs/${valRun}`);
    const strip = page.locator(tid('trace-plot')).first();
    await strip.locator('canvas').waitFor();
    const units = await page.locator(tid('trace-plot')).evaluateAll((ps) => ps.map((p) => p.dataset.unit));
    for (const u of ['N', 'm/s']) assert.ok(units.includes(u), `a strip in ${u}: ${units}`);
    const forces = await chartInfo(page, 'trace:N');
    assert.ok(forces && forces.series >= 3 && forces.values.every((v) => v > 100), JSON.stringify(forces));
    assert.ok(await inked(strip.locator('canvas')) > 1000, 'the strip is drawn');
    assert.match(await page.textContent(tid('traces-status')), /channels · .* samples at 10 Hz/);
    // Select a window by dragging across the velocity strip.
    const vel = page.locator(`${tid('trace-plot')}[data-unit="m/s"] .u-over`);
    await vel.scrollIntoViewIfNeeded();
    const box = await vel.boundingBox();
    await page.mouse.move(box.x + box.width * 0.3, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width * 0.5, box.y + box.height / 2, { steps: 6 });
    await page.mouse.up();
    const table = page.locator(tid('window-stats-table'));
    await table.waitFor();
    assert.match(await page.textContent(tid('window-range')), /^Window \d/);
    const row = await table.locator('tr[data-channel="u"] td').allTextContents();
    assert.equal(row[1], 'm/s');
    assert.ok(row.slice(2, 7).every((x) => /^−?\d/.test(x)), `stats of u: ${row}`);
    assert.doesNotMatch(await page.textContent(tid('run-traces')), /NaN|Infinity|e\+?3\d/);
    await page.locator(tid('run-traces')).screenshot({ path: path.join(SHOTS, 'run-time-plot.png') });
    await page.locator(tid('window-stats')).screenshot({ path: path.join(SHOTS, 'run-window-stats.png') });
    // Zoom into the window: every sample, same window.
    await page.locator(tid('window-zoom')).click();
    await page.waitForFunction(() => /every sample shown/.test(document.querySelector('[data-testid="traces-status"]').textContent));
    const card = page.locator('.trace-card').first();
    assertPng(await exported(page, card, 'png'), 'time plot');
    const svg = await exported(page, card, 'svg');
    assert.match(svg.bytes.toString('utf8'), /^<svg[^>]*xmlns="http:\/\/www.w3.org\/2000\/svg"/);
    assert.match(svg.bytes.toString('utf8'), /<path d="M/);
    const csv = (await exported(page, card, 'csv')).bytes.toString('utf8').split('\n');
    assert.match(csv[0], /^time \[s\],\S+ \[N(·m)?\]/, csv[0]);
    assert.ok(csv.length > 20 && /^\d/.test(csv[1]), csv.slice(0, 3).join(' / '));
    // The quality plots export too.
    assertPng(await exported(page, page.locator(tid('runPsd-export'))), 'PSD');
    await noSideScroll(page, 'run page at 1440 px');
    await page.setViewportSize({ width: 390, height: 900 });
    await page.waitForTimeout(400);
    await sectionFits(page, tid('run-traces'), 'time plot at 390 px');
    await sectionFits(page, tid('window-stats'), 'window statistics at 390 px');
    await page.locator(tid('run-traces')).screenshot({ path: path.join(SHOTS, 'run-time-plot-390px.png') });
  });
});

test('model page: Bode over H1, pole-zero, step, Hankel, residual cross-correlation, compare; each exports a PNG', async () => {
  await H.withPage([], async (page) => {
    await page.setViewportSize({ width: 1440, height: 1000 });
    await page.goto(`${H.base}/#/models/${lpv}`);
    const views = page.locator(tid('model-views'));
    await views.waitFor();
    await page.locator(`${tid('bode-coherence-plot')} canvas`).waitFor();
    // Bode: model and the run's H1, coherence below.
    const mag = await chartInfo(page, 'bodeMag');
    assert.equal(mag.series, 2, 'model and H1');
    assert.ok(mag.values.every((v) => v > 20), JSON.stringify(mag));
    const coh = await chartInfo(page, 'bodeCoherence');
    assert.ok(coh.values[0] > 20, JSON.stringify(coh));
    assert.match(await page.textContent(tid('bode-note')), /empirical H1/);
    // Pole-zero: every pole of the point drawn, in the s plane.
    await page.locator(`${tid('pz-plot')} canvas`).waitFor();
    const pz = await page.evaluate(() => ({ poles: window.__plots.pz.data.poles.length, plane: window.__plots.pz.data.plane }));
    assert.ok(pz.poles >= 1 && pz.plane === 's', JSON.stringify(pz));
    assert.ok(await inked(page.locator(`${tid('pz-plot')} canvas`)) > 1000);
    assert.match(await page.textContent(tid('pz-stability')), /stable/i);
    // Pole text: 4 significant digits with units (rad/s for the roots and ωn, s for τ).
    const poleText = await page.textContent(tid('pz-note'));
    assert.match(poleText, /Poles: −?\d[\d.]* (?:[+−] [\d.]+j )?rad\/s \(/, poleText);
    assert.match(poleText, /τ \d[\d.]* s/, poleText);
    for (const n of poleText.match(/\d+\.\d+/g) || []) {
      assert.ok(n.replace('.', '').replace(/^0+/, '').length <= 4, `4 significant digits: ${n} in ${poleText}`);
    }
    // Step: every output of the chosen input; then the impulse.
    await page.locator(`${tid('step-plot')} canvas`).waitFor();
    const step = await chartInfo(page, 'step');
    assert.ok(step.series >= 1 && step.values[0] > 100, JSON.stringify(step));
    // Hankel, cross-correlation, compare.
    await page.locator(`${tid('hankel-plot')} canvas`).waitFor();
    const hsv = await chartInfo(page, 'hankel');
    assert.ok(hsv.values[0] >= 1, JSON.stringify(hsv));
    await page.locator(`${tid('xcorr-plot')} canvas`).waitFor();
    const xc = await chartInfo(page, 'xcorr');
    assert.equal(xc.series, 3, 'r(τ) and the ± band');
    assert.match(await page.textContent(tid('xcorr-note')), /99 % band/);
    await page.locator(`${tid('compare-plot')} canvas`).waitFor({ timeout: 60000 });
    const cmp = await chartInfo(page, 'compare');
    assert.ok(cmp.series >= 3, `measured and two models: ${JSON.stringify(cmp)}`);
    assert.ok(await page.locator(tid('compare-row')).count() >= 2);
    // Each compared model's input–residual cross-correlation with its band.
    await page.locator(`${tid('compare-xcorr-plot')} canvas`).first().waitFor();
    const models = await page.locator(tid('compare-row')).count();
    assert.equal(await page.locator(tid('compare-xcorr-plot')).count(), models);
    const cx = await chartInfo(page, 'compareXcorr0');
    assert.equal(cx.series, 3, 'r(τ) and the ± band');
    assert.match(await page.locator(tid('compare-xcorr-note')).first().textContent(), /99 % band/);
    // A window selected on the run page is offered here: the models are validated on it.
    await page.evaluate((rid) => sessionStorage.setItem(`seatrial.window.${rid}`, JSON.stringify({ from_s: 100, to_s: 150 })), valRun);
    await page.locator(tid('compare-go')).click();
    await page.locator(tid('compare-window')).click();
    await page.waitForFunction(() => /Validated on 100(\.0+)?–150/.test(document.querySelector('[data-testid="compare-window-note"]')?.textContent || ''));
    assert.equal(await page.inputValue(tid('compare-from')), '100');
    const x = await page.evaluate(() => { const t = window.__plots.compare.data[0]; return [t[0], t[t.length - 1]]; });
    assert.ok(x[0] >= 100 - 1e-6 && x[1] <= 150 + 1e-6 && x[1] - x[0] > 40, `compare drawn on the window: ${x}`);
    await page.locator(`${tid('compare-xcorr-plot')} canvas`).first().waitFor();
    const xcard = page.locator(tid('compare-xcorr'));
    await xcard.scrollIntoViewIfNeeded();
    await xcard.screenshot({ path: path.join(SHOTS, 'model-compare-xcorr-window.png') });
    assertPng(await exported(page, xcard, 'png'), 'compare cross-correlation');
    const text = await views.textContent();
    assert.doesNotMatch(text, /NaN|Infinity|undefined|e\+?3\d\b/, 'no absurd numbers');

    const shots = [['bode-card', 'bode'], ['pz-card', 'pole-zero'], ['step-card', 'step'], ['hankel-card', 'hankel-lpv'], ['xcorr-card', 'residual-xcorr'], ['compare-card', 'compare']];
    for (const [id, name] of shots) {
      const card = page.locator(tid(id));
      await card.scrollIntoViewIfNeeded();
      await card.screenshot({ path: path.join(SHOTS, `model-${name}.png`) });
      assertPng(await exported(page, card, 'png'), id);
    }
    // The pole-zero map's CSV lists the roots with units; the Bode's SVG is vector.
    const pzCsv = (await exported(page, page.locator(tid('pz-card')), 'csv')).bytes.toString('utf8');
    assert.match(pzCsv.split('\n')[0], /^kind,real \[rad\/s\],imaginary \[rad\/s\]/);
    assert.match(pzCsv, /\npole,/);
    assert.match((await exported(page, page.locator(tid('bode-card')), 'svg')).bytes.toString('utf8'), /^<svg/);
    // Impulse instead of step.
    await page.locator(tid('views-step-kind')).selectOption('impulse');
    await page.waitForFunction(() => /Unit impulse of/.test(document.querySelector('[data-testid="step-note"]').textContent));
    assert.ok((await chartInfo(page, 'step')).values[0] > 100, 'the impulse is drawn');
    await page.screenshot({ path: path.join(SHOTS, 'model-page-responses.png'), fullPage: false });
    await noSideScroll(page, 'model page at 1440 px');
    await page.setViewportSize({ width: 390, height: 900 });
    await page.waitForTimeout(400);
    await sectionFits(page, tid('model-views'), 'responses at 390 px');
    await page.locator(tid('bode-card')).scrollIntoViewIfNeeded();
    await page.locator(tid('bode-card')).screenshot({ path: path.join(SHOTS, 'model-bode-390px.png') });
  });
});

test('N4SID model: subspace singular values with the chosen order, z-plane poles inside the unit circle', async () => {
  await H.withPage([], async (page) => {
    await page.setViewportSize({ width: 1440, height: 1000 });
    await page.goto(`${H.base}/#/models/${n4}`);
    await page.locator(`${tid('hankel-plot')} canvas`).waitFor();
    const hsv = await chartInfo(page, 'hankel');
    assert.equal(hsv.series, 2, 'kept and beyond the order');
    assert.match(await page.textContent(tid('hankel-note')), /chose order \d+/);
    await page.locator(`${tid('pz-plot')} canvas`).waitFor();
    const pz = await page.evaluate(() => window.__plots.pz.data);
    assert.equal(pz.plane, 'z');
    assert.ok(pz.poles.every((p) => Math.hypot(p.re, p.im) < 1), 'stable: inside the unit circle');
    for (const [id, name] of [['hankel-card', 'hankel-n4sid'], ['pz-card', 'pole-zero-n4sid'], ['bode-card', 'bode-n4sid']]) {
      const card = page.locator(tid(id));
      await card.scrollIntoViewIfNeeded();
      await card.screenshot({ path: path.join(SHOTS, `model-${name}.png`) });
      assertPng(await exported(page, card, 'png'), id);
    }
  });
});
