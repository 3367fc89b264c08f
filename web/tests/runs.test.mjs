// End-to-end test of the runs UI in a real (headless) Chromium: upload logs
// of a simulated ROV through the campaign page, read the verdicts and the
// coverage, and the run page's summary and plots.
//
//   cd web && npm ci && node --test tests/
//
// Env: see harness.mjs; RUNS_SCREENSHOT=/tmp/run.png saves the run page.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { createHash } from 'node:crypto';
import { harness, tid, inked, dragZoom } from './harness.mjs';
import { simulate, csv, ALL_COLUMNS, FORCES, VELS, POSE } from './sim.mjs';
import { SURVEYOR_ROV } from '../templates.js';
import { logDecimate, mergeSorted, DECIMATE_ABOVE } from '../decimate.js';

const H = harness();
let cid; // campaign: Surveyor ROV, 1 kn, dynamic family, force schedules
let plan;

before(async () => {
  await H.start();
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (runs e2e)' });
  assert.equal(v.status, 201);
  // Force schedules: the logged τ can be compared with the planned τ directly.
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: v.json.id, name: 'Runs e2e', grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 5,
    excitation: { quantity: 'force' },
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  const p = await H.api('POST', `/api/campaigns/${cid}/plan`);
  assert.equal(p.status, 201);
  plan = p.json;
});

after(() => H.stop());

const RUN_POST_422 = { method: 'POST', status: 422, path: /^\/api\/campaigns\/[^/]+\/runs$/ };
const sha256 = (s) => createHash('sha256').update(s).digest('hex');

/** Record every state of the progress bar (value, state) from now on. */
async function recordProgress(page) {
  await page.evaluate(() => {
    window.__progress = [];
    const bar = document.querySelector('[data-testid="upload-progress"]');
    const text = document.querySelector('[data-testid="upload-status"]');
    const note = () => window.__progress.push({ pct: Number(bar.getAttribute('value')), state: text.dataset.state || '', text: text.textContent });
    new MutationObserver(note).observe(bar, { attributes: true });
    new MutationObserver(note).observe(text, { attributes: true, childList: true, characterData: true, subtree: true });
  });
}

test('single log for a planned experiment: progress, verdicts, coverage, run page plots and zoom', async () => {
  // Fly DYN-1kn-sway-r1: the planned sway force (20 Hz schedule) logged at
  // 10 Hz from 7 s into the log; surge, heave, pitch, yaw driven with random
  // binary forces; roll left unexcited.
  const exp = plan.experiments.find((e) => e.code === 'DYN-1kn-sway-r1');
  const sched = (await H.api('GET', `/api/campaigns/${cid}/plan/experiments/${exp.id}`)).json;
  const planned = sched.columns.find((c) => c.name === 'tau_Y').values;
  const run = simulate({
    seed: 1, fs: 10, duration: planned.length / sched.sample_rate_hz + 20, amp: [400, 0, 800, 0, 600, 600], clock: 3, noise: 1e-4,
    force: [null, (k) => { const j = (k - 70) * 2; return j >= 0 && j < planned.length ? planned[j] : 0; }],
  });
  const log = csv(run, ALL_COLUMNS);

  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(tid('coverage-table')).waitFor();
    assert.equal(await page.textContent(tid('count-missing')), '6');
    assert.equal(await page.textContent(tid('count-tofly')), '6');
    assert.match(await page.textContent(tid('coverage-headline')), /6 of 6 experiments still to fly/);
    await page.locator(tid('no-runs')).waitFor();

    // "↑ run" on the coverage row picks the experiment in the form.
    await page.click(`${tid('coverage-row')}[data-code="DYN-1kn-sway-r1"] ${tid('coverage-upload')}`);
    assert.equal(await page.inputValue(tid('upload-experiment')), exp.id);
    assert.match(await page.locator(`${tid('upload-experiment')} option:checked`).textContent(), /#2 DYN-1kn-sway-r1 · not flown/);
    await page.setInputFiles(tid('upload-file'), { name: 'sway.csv', mimeType: 'text/csv', buffer: Buffer.from(log) });
    await page.fill(tid('upload-name'), 'sway r1 (e2e)');

    // Throttle the upload (~0.6 s) so the bar moves through several values.
    const cdp = await page.context().newCDPSession(page);
    await cdp.send('Network.enable');
    await cdp.send('Network.emulateNetworkConditions', { offline: false, latency: 0, downloadThroughput: -1, uploadThroughput: 384 * 1024 });
    await recordProgress(page);
    await page.click(tid('upload-submit'));
    await page.locator(tid('upload-accepted')).waitFor();
    await cdp.send('Network.emulateNetworkConditions', { offline: false, latency: 0, downloadThroughput: -1, uploadThroughput: -1 });

    const seen = await page.evaluate(() => window.__progress);
    const pcts = seen.map((s) => s.pct);
    assert.ok(pcts.includes(100), `the bar reached 100 %: ${JSON.stringify(pcts)}`);
    assert.ok(pcts.some((p) => p > 0 && p < 100), `the bar moved through intermediate values: ${JSON.stringify(pcts)}`);
    assert.ok(seen.some((s) => s.state === 'processing' && /processing/.test(s.text)), 'processing… shown after the bytes were sent');
    assert.equal(await page.getAttribute(tid('upload-progress'), 'value'), '100');
    assert.match(await page.textContent(tid('upload-status')), /100 % · 2\d\d(\.\d)? kB uploaded in [\d.]+ m?s, processed in [\d.]+ m?s/);

    // Verdicts: good where it was excited, insufficient (with its reason) for roll.
    const result = page.locator(tid('upload-result'));
    assert.match(await result.textContent(), /Run “sway r1 \(e2e\)” accepted/);
    const good = await result.locator(`${tid('verdict')}[data-verdict="good"]`).count();
    assert.ok(good >= 1, `${good} good verdicts`);
    const sway = result.locator(`${tid('verdict')}[data-dof="sway"]`);
    assert.equal(await sway.getAttribute('data-verdict'), 'good');
    const roll = result.locator(`${tid('verdict')}[data-dof="roll"]`);
    assert.equal(await roll.getAttribute('data-verdict'), 'insufficient');
    assert.match(await roll.locator(tid('verdict-reason')).textContent(), /roll: the input tau_K barely moved/);
    const rollBadge = roll.locator(tid('verdict-badge'));
    assert.equal(await rollBadge.evaluate((e) => getComputedStyle(e).color), 'rgb(163, 35, 27)', 'insufficient is red');
    assert.equal(await result.locator(`${tid('verdict-badge')}[data-dof="sway"]`).evaluate((e) => getComputedStyle(e).color), 'rgb(23, 104, 58)', 'good is green');

    // The run list and the coverage follow (refreshed after the answer).
    await page.locator(`${tid('coverage-row')}[data-code="DYN-1kn-sway-r1"][data-status="covered"]`).waitFor();
    const row = page.locator(tid('run-row'));
    await row.waitFor();
    assert.equal(await row.count(), 1);
    assert.equal(await row.getAttribute('data-status'), 'accepted');
    assert.match(await row.textContent(), /DYN-1kn-sway-r1/);
    assert.equal(await row.locator(`${tid('verdict-badge')}[data-verdict="insufficient"]`).getAttribute('data-dof'), 'roll');
    const covRow = page.locator(`${tid('coverage-row')}[data-code="DYN-1kn-sway-r1"]`);
    assert.equal(await covRow.getAttribute('data-status'), 'covered', 'the planned force was followed: covered');
    assert.match(await covRow.locator(tid('coverage-run')).textContent(), /sway r1 \(e2e\)/);
    assert.equal(await page.textContent(tid('count-covered')), '1');
    assert.equal(await page.textContent(tid('count-missing')), '5');
    assert.match(await page.textContent(tid('coverage-headline')), /5 of 6 experiments still to fly/);
    // Filter: what must be flown.
    await page.click(tid('coverage-filter-missing'));
    const shown = await page.locator(tid('coverage-row')).evaluateAll((rs) => rs.map((r) => [r.dataset.code, r.dataset.status]));
    assert.equal(shown.length, 5);
    assert.ok(shown.every(([code, st]) => st === 'missing' && code !== 'DYN-1kn-sway-r1'), JSON.stringify(shown));
    await page.click(tid('coverage-filter-covered'));
    assert.deepEqual(await page.locator(tid('coverage-row')).evaluateAll((rs) => rs.map((r) => r.dataset.code)), ['DYN-1kn-sway-r1']);
    await page.click(tid('coverage-filter-all'));
    assert.equal(await page.locator(tid('coverage-row')).count(), 6);
    assert.match(await page.locator(`${tid('upload-experiment')} option[value="${exp.id}"]`).textContent(), /covered/);

    // Run page.
    await page.click(tid('upload-run-link'));
    await page.waitForURL(/#\/runs\/[0-9a-f-]{36}$/);
    await page.locator(`${tid('run-sv-plot')} canvas`).waitFor();
    assert.match(await page.textContent(tid('run-title')), /sway r1 \(e2e\)/);
    assert.equal(await page.textContent(tid('run-experiment')), 'DYN-1kn-sway-r1');
    assert.equal(await page.textContent(tid('sha256')), sha256(log));
    assert.equal(await page.textContent(tid('run-rate')), '10 Hz');
    const rawHref = await page.getAttribute(`${tid('files-table')} ${tid('raw-link')}`, 'href');
    assert.equal(await (await page.request.get(H.base + rawHref)).text(), log, 'raw bytes as uploaded');
    const rollCard = page.locator(`${tid('run-verdicts')} ${tid('verdict')}[data-dof="roll"]`);
    assert.equal(await rollCard.getAttribute('data-verdict'), 'insufficient');
    assert.match(await rollCard.textContent(), /tau_K barely moved/);
    assert.ok(await page.locator(`${tid('run-verdicts')} ${tid('verdict')}[data-verdict="good"]`).count() >= 4);

    for (const [plot, words] of [
      ['run-psd-plot', ['tau_X', 'tau_Y', 'tau_N']],
      ['run-coherence-plot', ['sway: tau_Y → v', 'roll: tau_K → p']],
      ['run-h1mag-plot', ['|H1| tau_X → u']],
      ['run-h1phase-plot', ['∠H1 tau_X → u']],
      ['run-sv-plot', ['σᵢ/σ₁ ≥ 0.001', 'σᵢ/σ₁ < 0.001']],
    ]) {
      const canvas = page.locator(`${tid(plot)} canvas`);
      const box = await canvas.boundingBox();
      assert.ok(box && box.width > 300 && box.height > 100, `${plot} size ${JSON.stringify(box)}`);
      const n = await inked(canvas);
      assert.ok(n > 1000, `${plot} looks blank (${n} painted pixels)`);
      const legend = await page.textContent(`${tid(plot)} .u-legend`);
      for (const w of words) assert.ok(legend.includes(w), `${plot} legend lacks ${w}: ${legend}`);
    }
    assert.match(await page.textContent(tid('sv-summary')), /11 of 12 parameters identifiable/);
    assert.match(await page.textContent(tid('deficient-directions')), /tau_K\(t-1\)/);
    assert.equal(await page.getAttribute(tid('adherence-row'), 'data-followed'), 'true');
    assert.match(await page.textContent(tid('adherence-table')), /tau_Y followed the planned tau_Y/);

    // Legend under the cursor: the exact bin, with its frequency.
    const psd = tid('run-psd-plot');
    await page.locator(`${psd} .u-over`).scrollIntoViewIfNeeded();
    const over = await page.locator(`${psd} .u-over`).boundingBox();
    await page.mouse.move(over.x + over.width * 0.5, over.y + over.height / 2);
    const bin = await page.evaluate(() => {
      const u = window.__plots.runPsd;
      return { i: u.cursor.idx, f: u.data[0][u.cursor.idx] };
    });
    const fLegend = await page.locator(`${psd} .u-legend .u-series`).first().locator('.u-value').textContent();
    assert.equal(fLegend, `${Number(bin.f.toPrecision(6))} Hz`);

    // Zoom the PSD: drag shrinks the frequency range, double-click resets.
    const xRange = () => page.evaluate(() => [window.__plots.runPsd.scales.x.min, window.__plots.runPsd.scales.x.max]);
    const [x0, x1] = await xRange();
    const zoomed = await dragZoom(page, psd, 0.3, 0.6);
    const [z0, z1] = await xRange();
    assert.ok(z0 > x0 && z1 < x1 && Math.log(z1 / z0) < 0.5 * Math.log(x1 / x0), `zoom: [${x0}, ${x1}] → [${z0}, ${z1}]`);
    await page.mouse.dblclick(zoomed.x + zoomed.width / 2, zoomed.y + zoomed.height / 2);
    const [r0, r1] = await xRange();
    assert.ok(Math.abs(r0 - x0) < 1e-12 && Math.abs(r1 - x1) < 1e-12, `double-click reset: [${r0}, ${r1}]`);

    // Any input → output pair; the H1 plots follow.
    await page.selectOption(tid('coherence-select'), 'tau_Y→v');
    assert.match(await page.textContent(`${tid('run-coherence-plot')} .u-legend`), /sway: tau_Y → v/);
    assert.equal(await page.evaluate(() => window.__plots.runCoherence.series.length), 2);
    assert.match(await page.textContent(`${tid('run-h1mag-plot')} .u-legend`), /tau_Y → v/);
    // Zooming the H1 magnitude zooms the phase too.
    await dragZoom(page, tid('run-h1mag-plot'), 0.2, 0.5);
    const [m0, m1, p0, p1] = await page.evaluate(() => [window.__plots.runH1mag.scales.x.min, window.__plots.runH1mag.scales.x.max,
      window.__plots.runH1phase.scales.x.min, window.__plots.runH1phase.scales.x.max]);
    assert.ok(m0 > x0 && m1 < x1 && Math.log(m1 / m0) < 0.5 * Math.log(x1 / x0), `H1 zoom: [${m0}, ${m1}]`);
    assert.ok(Math.abs(m0 - p0) < 1e-12 && Math.abs(m1 - p1) < 1e-12, `phase follows: [${m0}, ${m1}] vs [${p0}, ${p1}]`);

    if (process.env.RUNS_SCREENSHOT) {
      const h1 = await page.locator(`${tid('run-h1mag-plot')} .u-over`).boundingBox();
      await page.mouse.dblclick(h1.x + h1.width / 2, h1.y + h1.height / 2);
      await page.evaluate(() => window.scrollTo(0, 0));
      await page.mouse.move(0, 0);
      await page.screenshot({ path: process.env.RUNS_SCREENSHOT, fullPage: true });
    }

    // Back to the campaign through the breadcrumb.
    await page.click(tid('run-campaign-link'));
    await page.locator(tid('coverage-table')).waitFor();
  });
});

test('display decimation of long spectra keeps exact bins, ends and extrema; a zoom window gets every bin', () => {
  // A 4096-sample Welch spectrum: 2049 bins, DC first, with a one-bin spike and notch.
  const f = Array.from({ length: 2049 }, (_, i) => i * (10 / 4096));
  const y = f.map((x, i) => (i === 1500 ? 1e3 : i === 1700 ? 1e-9 : 1 / (1 + x * x)));
  const z = f.map((x, i) => (i % 7 === 0 ? null : Math.sin(i)));
  const keep = logDecimate(f, [y, z]);
  assert.ok(keep.length < 1300 && keep.length > 300, `${keep.length} bins kept`);
  assert.equal(keep[0], 1, 'the DC bin is left out (log axis)');
  assert.equal(keep[keep.length - 1], 2048);
  assert.ok(keep.includes(1500) && keep.includes(1700), 'spike and notch survive');
  assert.ok(keep.every((k, i) => i === 0 || k > keep[i - 1]), 'sorted, unique');
  assert.ok(keep.slice(0, 20).every((k, i) => k === i + 1), 'low-frequency bins are all kept');
  // Zoomed to 1–2 Hz: every bin of the window.
  const win = logDecimate(f, [y, z], { lo: 1, hi: 2 });
  assert.equal(win.length, f.filter((x) => x >= 1 && x <= 2).length);
  assert.ok(win.length <= DECIMATE_ABOVE);
  const both = mergeSorted(keep, win);
  assert.equal(new Set(both).size, both.length);
  assert.ok(win.every((k) => both.includes(k)) && keep.every((k) => both.includes(k)));
  // Short spectra are left alone.
  assert.deepEqual(logDecimate([0, 0.1, 0.2, 0.3], [[1, 2, 3, 4]]), [1, 2, 3]);
});

test('invalid log: 422 names file, line and column, and links the stored raw bytes', async () => {
  const good = csv(simulate({ seed: 3, fs: 10, duration: 60, amp: [1, 1, 1, 1, 1, 1], clock: 2, noise: 0 }), ALL_COLUMNS);
  const lines = good.split('\n');
  // Line 42 of the file (header = 1): text in tau_K, the 5th column.
  const cells = lines[41].split(',');
  cells[4] = 'abc';
  lines[41] = cells.join(',');
  const bad = lines.join('\n');

  await H.withPage([RUN_POST_422], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(tid('upload-form')).waitFor();
    const before = await page.locator(tid('run-row')).count();
    await page.setInputFiles(tid('upload-file'), { name: 'bad.csv', mimeType: 'text/csv', buffer: Buffer.from(bad) });
    await page.click(tid('upload-submit'));
    const err = page.locator(tid('upload-error'));
    await err.waitFor();
    assert.equal(await err.getAttribute('data-status'), '422');
    assert.equal(await err.locator(tid('error-file')).textContent(), 'bad.csv (file)');
    assert.equal(await err.locator(tid('error-line')).textContent(), 'line 42');
    assert.equal(await err.locator(tid('error-column')).textContent(), 'column tau_K');
    assert.match(await err.locator(tid('error-message')).textContent(), /'abc' is not a number/);
    // Prominent: large bold monospace, red frame.
    assert.ok(parseFloat(await err.locator(tid('error-line')).evaluate((e) => getComputedStyle(e).fontSize)) >= 14);
    // The file input is marked too.
    assert.match(await page.textContent(`${tid('field-error')}[data-for="file"]`), /line 42, column tau_K/);
    assert.equal(await page.getAttribute(tid('upload-progress'), 'value'), '100', 'the bytes were sent');
    assert.match(await page.textContent(tid('upload-status')), /not accepted \(422\)/);

    // Nothing is lost: the raw link returns the bytes as uploaded.
    const href = await page.getAttribute(tid('error-raw-link'), 'href');
    assert.match(href, /^\/api\/runs\/[0-9a-f-]{36}\/raw$/);
    const raw = await page.request.get(H.base + href);
    assert.equal(raw.status(), 200);
    assert.equal(await raw.text(), bad);

    // The run list shows the rejected run with where it failed.
    await page.waitForFunction((n) => document.querySelectorAll('[data-testid="run-row"]').length === n + 1, before);
    const row = page.locator(`${tid('run-row')}[data-status="rejected"]`).first();
    assert.match(await row.locator(tid('run-error')).textContent(), /bad\.csv \(file\) · line 42 · column tau_K/);

    // Its run page: the error again, no quality report asked for.
    await page.click(tid('error-run-link'));
    await page.waitForURL(/#\/runs\/[0-9a-f-]{36}$/);
    await page.locator(tid('run-error')).waitFor();
    assert.match(await page.textContent(`${tid('run-error')} ${tid('error-where')}`), /line 42 · column tau_K/);
    assert.equal(await page.getAttribute(tid('run-status'), 'data-status'), 'rejected');
    assert.equal(await page.locator(tid('quality')).count(), 0);
    assert.equal(await page.textContent(tid('sha256')), sha256(bad));
  });
});

test('control + nav logs from unsynchronized computers: alignment offset ≈ 5.3 s on the run page', async () => {
  const run = simulate({ seed: 2, fs: 20, duration: 150, amp: [400, 800, 800, 600, 600, 600], clock: 3, noise: 1e-4 });
  // Controller computer: 10 Hz, its clock 5.3 s ahead of the navigation computer's.
  const control = csv(run, [...FORCES, 'z'], 5.3, 2);
  const nav = csv(run, [...VELS, ...POSE], 0, 1);

  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(tid('upload-form')).waitFor();
    assert.equal(await page.locator(tid('upload-shared')).count(), 0, 'shared channel only for two-file runs');
    await page.getByText('Control + nav logs').click();
    assert.equal(await page.inputValue(tid('upload-shared')), 'z');
    assert.equal(await page.locator(tid('upload-file')).count(), 0);
    await page.setInputFiles(tid('upload-control'), { name: 'ctrl.csv', mimeType: 'text/csv', buffer: Buffer.from(control) });
    await page.setInputFiles(tid('upload-nav'), { name: 'ins.csv', mimeType: 'text/csv', buffer: Buffer.from(nav) });
    await page.fill(tid('upload-name'), 'dive 7 (two computers)');
    await page.click(tid('upload-submit'));
    await page.locator(tid('upload-accepted')).waitFor();
    const row = page.locator(`${tid('run-row')}[data-status="accepted"]`, { hasText: 'dive 7 (two computers)' });
    await row.waitFor();
    assert.match(await row.textContent(), /control \+ nav/);

    await page.click(tid('upload-run-link'));
    await page.waitForURL(/#\/runs\/[0-9a-f-]{36}$/);
    const off = page.locator(tid('alignment-offset'));
    await off.waitFor();
    const offset = Number(await off.getAttribute('data-offset-s'));
    assert.ok(Math.abs(offset - 5.3) < 0.01, `offset ${offset}`);
    assert.match(await off.textContent(), /offset 5\.300 s ± [\d.e−-]+ s/);
    assert.ok(Number(await off.getAttribute('data-std-error-s')) < 0.01);
    assert.equal(await page.getAttribute(tid('alignment-confidence'), 'data-confidence'), 'high');
    assert.match(await page.textContent(tid('alignment')), /shared channel “z”/);
    // Both files, each with its own raw link.
    const links = await page.locator(`${tid('files-table')} ${tid('raw-link')}`).evaluateAll((as) => as.map((a) => a.getAttribute('href')));
    assert.equal(links.length, 2);
    assert.match(links[0], /\/raw\?file=control$/);
    assert.match(links[1], /\/raw\?file=nav$/);
    assert.equal(await (await page.request.get(H.base + links[1])).text(), nav);
    await page.locator(`${tid('run-coherence-plot')} canvas`).waitFor();
    assert.equal(await page.locator(tid('adherence-empty')).count(), 1, 'not assigned: no plan to compare with');
  });
});

test('a log in milliseconds and degrees: the result card says check units, with the doubts on it and no fly-again verdict', async () => {
  const run = simulate({ seed: 4, fs: 10, duration: 60, amp: [400, 800, 800, 0, 600, 600], clock: 3, noise: 1e-4 });
  const lines = csv(run, ALL_COLUMNS).trim().split('\n');
  const header = lines[0].split(',');
  const [t, phi] = [header.indexOf('t'), header.indexOf('phi')];
  const body = lines.slice(1).map((l) => {
    const c = l.split(',').map(Number);
    c[t] *= 1000;
    c[phi] = (c[phi] + 0.2) * 180 / Math.PI * 20;
    return c.join(',');
  });
  const log = [lines[0], ...body].join('\n') + '\n';

  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(tid('upload-form')).waitFor();
    await page.setInputFiles(tid('upload-file'), { name: 'ms_deg.csv', mimeType: 'text/csv', buffer: Buffer.from(log) });
    await page.fill(tid('upload-name'), 'units e2e');
    await page.click(tid('upload-submit'));
    const card = page.locator(tid('upload-accepted'));
    await card.waitFor();
    assert.equal(await card.getAttribute('data-check-units'), 'true');
    assert.match(await card.locator('.result-head b').textContent(), /check units \(t, phi\)/);
    const doubts = await card.locator(tid('units-warning')).allTextContents();
    assert.equal(doubts.length, 2, doubts.join(' | '));
    assert.match(doubts[0], /t looks like milliseconds/);
    assert.match(doubts[1], /phi looks like degrees/);
    const verdicts = await card.locator(tid('verdict')).evaluateAll((els) => els.map((e) => e.dataset.verdict));
    assert.ok(verdicts.length > 0 && verdicts.every((v) => v === 'check_units'), verdicts.join(','));
    assert.doesNotMatch(await card.textContent(), /twice the amplitude|fly it again/);
    // The units alert sits on the card above the verdicts: visible without scrolling the card.
    const [alertBox, listBox] = await Promise.all([card.locator(tid('units-alert')).boundingBox(), card.locator(tid('verdict-list')).boundingBox()]);
    assert.ok(alertBox.y < listBox.y);
    // The runs list marks it too.
    await page.locator(`${tid('run-status')}[data-status="check_units"]`).first().waitFor();
  });
});

test('the campaign page pages its runs 20 at a time: page 2 holds runs 21 and on, counts right', async () => {
  // A campaign of its own with 23 runs, uploaded oldest first (the list is newest first).
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: (await H.api('GET', `/api/campaigns/${cid}`)).json.vessel_id,
    name: 'Pager e2e', grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 6,
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  const pid = c.json.id;
  assert.equal((await H.api('POST', `/api/campaigns/${pid}/plan`)).status, 201);
  const log = csv(simulate({ seed: 31, fs: 10, duration: 60, amp: [300, 300, 300, 300, 300, 300], clock: 2, noise: 1e-4, surge: 0.5 }), ALL_COLUMNS);
  const names = Array.from({ length: 23 }, (_, i) => `pager ${String(i + 1).padStart(2, '0')}`);
  for (const name of names) {
    const form = new FormData();
    form.append('meta', JSON.stringify({ name }));
    form.append('file', new Blob([log], { type: 'text/csv' }), `${name}.csv`);
    const res = await fetch(`${H.base}/api/campaigns/${pid}/runs`, { method: 'POST', body: form });
    assert.equal(res.status, 201, await res.text());
  }
  const total = await H.api('GET', `/api/campaigns/${pid}/runs?limit=1`);
  assert.equal(total.headers.get('x-total-count'), '23');
  await H.withPage([], async (page) => {
    await page.goto(`${H.base}/#/campaigns/${pid}`);
    await page.locator(tid('runs-pager')).waitFor();
    const rowNames = () => page.locator(`${tid('runs-table')} ${tid('run-link')}`).allTextContents();
    assert.equal(await page.textContent(tid('runs-page')), '1–20 of 23');
    assert.match(await page.textContent(`${tid('run-list')} h3`), /^Runs \(23\)/);
    assert.deepEqual(await rowNames(), names.slice(3).reverse(), 'page 1: the 20 newest');
    assert.ok(await page.locator(tid('runs-prev')).isDisabled());
    await page.click(tid('runs-next'));
    await page.waitForFunction(() => document.querySelector('[data-testid="runs-page"]').textContent === '21–23 of 23');
    assert.deepEqual(await rowNames(), names.slice(0, 3).reverse(), 'page 2: runs 21–23 of the list');
    assert.ok(await page.locator(tid('runs-next')).isDisabled());
    await page.click(tid('runs-prev'));
    await page.waitForFunction(() => document.querySelector('[data-testid="runs-page"]').textContent === '1–20 of 23');
  });
});
