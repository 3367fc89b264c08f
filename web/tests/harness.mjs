// Browser-test harness (the same as planner.test.mjs): start the service on a
// free port with a fresh database and this web folder, launch headless
// Chromium, and run each scenario on a fresh page that fails on page errors,
// console errors and unexpected HTTP errors.
//
// Env: SEATRIAL_BIN (default <repo>/target/release/seatrial),
//      CHROMIUM (default /usr/bin/chromium).

import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const WEB = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
export const REPO = path.resolve(WEB, '..');
const BIN = process.env.SEATRIAL_BIN || path.join(REPO, 'target/release/seatrial');
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const ARGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic',
];

export const tid = (id) => `[data-testid="${id}"]`;

/** Signs in through the page's sign-in form (a server requiring credentials). */
export async function signIn(h, page, name, password) {
  await page.goto(`${h.base}/#/campaigns`);
  await page.locator(tid('login-form')).waitFor();
  await page.fill(tid('login-name'), name);
  await page.fill(tid('login-password'), password);
  await page.click(tid('login-submit'));
  await page.locator(tid('account-role')).waitFor();
}

/** `extraArgs`: more server flags, e.g. ['--demo']. */
export function harness({ extraArgs = [] } = {}) {
  // `headers`: sent with every h.api call (credentials, when the server requires them).
  const h = { base: null, browser: null, serverLog: '', headers: {} };
  let server;
  let tmp;

  const kill = () => {
    if (server && server.exitCode === null && server.signalCode === null) server.kill('SIGKILL');
  };
  process.on('exit', kill);

  function startServer() {
    tmp = mkdtempSync(path.join(tmpdir(), 'seatrial-web-'));
    assert.ok(existsSync(BIN), `seatrial binary not found at ${BIN} (cargo build --release, or set SEATRIAL_BIN)`);
    server = spawn(BIN, ['--db', path.join(tmp, 'db.sqlite'), '--listen', '127.0.0.1:0', '--web-dir', WEB, ...extraArgs], {
      stdio: ['ignore', 'pipe', 'pipe'],
    });
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => reject(new Error(`server did not start in 20 s:\n${h.serverLog}`)), 20000);
      let buf = '';
      server.stdout.on('data', (d) => {
        h.serverLog += d;
        buf += d;
        // eslint-disable-next-line no-control-regex
        const m = buf.replace(/\x1b\[[0-9;]*m/g, '').match(/seatrial listening on (http:\/\/[^\s/]+)/);
        if (m) { clearTimeout(timer); resolve(m[1]); }
      });
      server.stderr.on('data', (d) => { h.serverLog += d; });
      server.on('exit', (code, sig) => { clearTimeout(timer); reject(new Error(`server exited (${code ?? sig}):\n${h.serverLog}`)); });
      server.on('error', (e) => { clearTimeout(timer); reject(e); });
    });
  }

  h.start = async () => {
    h.base = await startServer();
    h.browser = await chromium.launch({ executablePath: CHROMIUM, args: ARGS, headless: true });
  };

  h.stop = async () => {
    if (h.browser) await h.browser.close().catch(() => {});
    if (server && server.exitCode === null && server.signalCode === null) {
      const gone = new Promise((r) => server.once('exit', r));
      server.kill('SIGTERM');
      await Promise.race([gone, new Promise((r) => setTimeout(r, 3000))]);
      kill();
    }
    if (tmp) rmSync(tmp, { recursive: true, force: true });
  };

  /** JSON API call from node (test set-up). */
  h.api = async (method, p, body) => {
    const res = await fetch(h.base + p, {
      method,
      headers: { ...h.headers, ...(body === undefined ? {} : { 'content-type': 'application/json' }) },
      body: body === undefined ? undefined : JSON.stringify(body),
    });
    const text = await res.text();
    return { status: res.status, json: text ? JSON.parse(text) : null, headers: res.headers };
  };

  /**
   * A fresh page recording page errors, console errors and HTTP errors;
   * `allow` lists the HTTP errors the scenario expects ({method, status, path}).
   */
  h.withPage = async (allow, fn) => {
    const context = await h.browser.newContext({ viewport: { width: 1600, height: 1000 }, acceptDownloads: true });
    const page = await context.newPage();
    page.setDefaultTimeout(10000);
    const problems = [];
    page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
    page.on('console', (m) => {
      if (m.type() === 'error' && !/^Failed to load resource: the server responded with a status of/.test(m.text())) {
        problems.push(`console.error: ${m.text()}`);
      }
    });
    page.on('response', (r) => {
      if (r.status() < 400) return;
      const { pathname } = new URL(r.url());
      const method = r.request().method();
      if (!allow.some((a) => a.method === method && a.status === r.status() && a.path.test(pathname))) {
        problems.push(`HTTP ${r.status()} ${method} ${pathname}`);
      }
    });
    try {
      await fn(page);
      assert.deepEqual(problems, [], 'no page errors, console errors or unexpected HTTP errors');
    } catch (e) {
      if (problems.length) e.message += `\npage problems:\n  ${problems.join('\n  ')}`;
      e.message += `\nserver log (tail):\n${h.serverLog.slice(-1500)}`;
      throw e;
    } finally {
      await context.close();
    }
  };

  return h;
}

/** Painted (non-transparent) pixels of a canvas. */
export function inked(locator) {
  return locator.evaluate((c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n += 1;
    return n;
  });
}

/** Drag across the middle of a uPlot chart from fraction a to b of its width. */
export async function dragZoom(page, hostSel, a, b) {
  const loc = page.locator(`${hostSel} .u-over`);
  await loc.scrollIntoViewIfNeeded();
  const over = await loc.boundingBox();
  const y = over.y + over.height / 2;
  await page.mouse.move(over.x + over.width * a, y);
  await page.mouse.down();
  await page.mouse.move(over.x + over.width * ((a + b) / 2), y, { steps: 5 });
  await page.mouse.move(over.x + over.width * b, y, { steps: 5 });
  await page.mouse.up();
  return over;
}

/** Poll job `id` until it ends (at most `seconds`); its JSON. */
export async function waitJob(h, id, seconds) {
  for (let i = 0; i < seconds * 5; i += 1) {
    const j = await h.api('GET', `/api/jobs/${id}`);
    if (['succeeded', 'failed', 'cancelled', 'interrupted'].includes(j.json.state)) return j.json;
    await new Promise((r) => setTimeout(r, 200));
  }
  throw new Error(`job ${id} did not finish in ${seconds} s`);
}

/** Upload a one-file run through the API (test set-up); asserts it was accepted. */
export async function uploadRun(h, campaignId, log, meta) {
  const form = new FormData();
  form.append('meta', JSON.stringify(meta));
  form.append('file', new Blob([log], { type: 'text/csv' }), `${meta.name || 'run'}.csv`);
  const res = await fetch(`${h.base}/api/campaigns/${campaignId}/runs`, { method: 'POST', body: form });
  const json = await res.json();
  assert.equal(res.status, 201, JSON.stringify(json));
  assert.equal(json.status, 'accepted', JSON.stringify(json));
  return json;
}
