// Accounts in a real (headless) Chromium against a server that requires
// credentials (--auth required, the first admin's password from a file):
// the sign-in form, the user and role in the header, a viewer's pages
// without write controls (and a write refused by the server), sign-out.
//
//   cd web && npm ci && node --test tests/auth.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { harness, tid, signIn as signInAs } from './harness.mjs';

const signIn = (page, name, password) => signInAs(H, page, name, password);
import { SURVEYOR_ROV } from '../templates.js';

const ADMIN_PASSWORD = 'browser-admin-pw';
const secrets = mkdtempSync(path.join(tmpdir(), 'seatrial-auth-'));
const passwordFile = path.join(secrets, 'admin-password');
writeFileSync(passwordFile, `${ADMIN_PASSWORD}\n`);
const H = harness({ extraArgs: ['--auth', 'required', '--admin-password-file', passwordFile] });
let cid;
let vid;

// The sign-in answers 401 to the first /api/auth/me, and to the pages' reads before it.
const ME_401 = { method: 'GET', status: 401, path: /^\/api\/auth\/me$/ };
const LOGIN_401 = { method: 'POST', status: 401, path: /^\/api\/auth\/login$/ };
const GET_401 = { method: 'GET', status: 401, path: /^\/api\// };

before(async () => {
  await H.start();
  // Set-up through the API as the admin: a viewer account and a planned campaign.
  const login = await H.api('POST', '/api/auth/login', { name: 'admin', password: ADMIN_PASSWORD });
  assert.equal(login.status, 200, JSON.stringify(login.json));
  const cookie = login.headers.get('set-cookie').split(';')[0];
  H.headers = { cookie, 'x-seatrial-csrf': '1' };
  const u = await H.api('POST', '/api/users', { name: 'vera', role: 'viewer', password: 'vera-password' });
  assert.equal(u.status, 201, JSON.stringify(u.json));
  const v = await H.api('POST', '/api/vessels', { ...SURVEYOR_ROV, name: 'Surveyor ROV (auth e2e)' });
  assert.equal(v.status, 201, JSON.stringify(v.json));
  vid = v.json.id;
  const c = await H.api('POST', '/api/campaigns', {
    vessel_id: vid, name: 'Auth e2e', grid: { unit: 'kn', speeds: [1] }, families: ['dynamic'], seed: 4,
  });
  assert.equal(c.status, 201, JSON.stringify(c.json));
  cid = c.json.id;
  assert.equal((await H.api('POST', `/api/campaigns/${cid}/plan`)).status, 201);
  H.headers = {};
  assert.equal((await H.api('GET', '/api/vessels')).status, 401, 'no credentials, no reads');
});

after(async () => {
  await H.stop();
  rmSync(secrets, { recursive: true, force: true });
});

/** A write control that is on the page (rendered) but not shown. */
async function hiddenControl(page, id) {
  const loc = page.locator(tid(id));
  assert.ok(await loc.count() > 0, `${id} is rendered`);
  assert.equal(await loc.first().isVisible(), false, `${id} hidden for a viewer`);
}


test('the sign-in form refuses a wrong password, then signs the admin in with every control', async () => {
  await H.withPage([ME_401, LOGIN_401, GET_401], async (page) => {
    await page.goto(`${H.base}/#/campaigns`);
    await page.locator(tid('login-form')).waitFor();
    assert.equal(await page.locator(tid('account')).isVisible(), false);
    await page.fill(tid('login-name'), 'admin');
    await page.fill(tid('login-password'), 'not-the-password');
    await page.click(tid('login-submit'));
    await page.locator(`${tid('login-error')}:has-text("Wrong name or password")`).waitFor();
    await page.fill(tid('login-password'), ADMIN_PASSWORD);
    await page.click(tid('login-submit'));
    await page.locator(tid('new-campaign')).waitFor();
    assert.equal(await page.textContent(tid('account-name')), 'admin');
    assert.equal(await page.textContent(tid('account-role')), 'admin');
    // The cookie is HttpOnly: the page's script cannot read it.
    assert.equal(await page.evaluate(() => document.cookie), '');
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(tid('generate-plan')).waitFor();
    assert.equal(await page.locator(tid('upload-form')).isVisible(), true);
  });
});

test('a viewer sees the pages without write controls, a write is refused, and signs out', async () => {
  const refused = { method: 'POST', status: 403, path: /^\/api\/vessels$/ };
  await H.withPage([ME_401, GET_401, refused], async (page) => {
    await signIn(page, 'vera', 'vera-password');
    assert.equal(await page.textContent(tid('account-name')), 'vera');
    assert.equal(await page.textContent(tid('account-role')), 'viewer');
    // Lists and pages are there; the write controls are not.
    await page.locator(`text=Auth e2e`).first().waitFor();
    await hiddenControl(page, 'new-campaign');
    await page.goto(`${H.base}/#/campaigns/${cid}`);
    await page.locator(tid('identify-section')).waitFor();
    await page.locator('h1').first().waitFor();
    for (const id of ['generate-plan', 'upload-form', 'identify-form']) await hiddenControl(page, id);
    if (process.env.AUTH_SCREENSHOT) await page.screenshot({ path: process.env.AUTH_SCREENSHOT });
    await page.goto(`${H.base}/#/vessels`);
    await page.locator(`text=Surveyor ROV (auth e2e)`).first().waitFor();
    await hiddenControl(page, 'new-vessel');
    await page.goto(`${H.base}/#/vessels/${vid}`);
    await page.locator('h1').first().waitFor();
    await hiddenControl(page, 'new-campaign-for-vessel');
    // A write from the viewer's page, as the UI would send it: refused by role.
    const answer = await page.evaluate(async () => {
      const res = await fetch('/api/vessels', {
        method: 'POST',
        headers: { 'content-type': 'application/json', 'x-seatrial-csrf': '1' },
        body: JSON.stringify({ name: 'not allowed' }),
      });
      return { status: res.status, body: await res.json() };
    });
    assert.equal(answer.status, 403, JSON.stringify(answer));
    assert.equal(answer.body.field, 'role');
    // Sign out: back to the form, and the session no longer reads.
    await page.click(tid('logout'));
    await page.locator(tid('login-form')).waitFor();
    assert.equal(await page.locator(tid('account')).isVisible(), false);
    const me = await page.evaluate(async () => (await fetch('/api/auth/me')).status);
    assert.equal(me, 401);
  });
});
