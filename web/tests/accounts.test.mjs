// The account page in a real (headless) Chromium against a server that
// requires credentials: an admin creates a user, a personal API token
// (shown once, then usable over REST, then revoked) and changes the
// password (signed out, signs in with the new one); the new user sees no
// Users section; five wrong passwords make the sign-in form say to wait.
//
//   cd web && npm ci && node --test tests/accounts.test.mjs

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { harness, tid, signIn as signInAs } from './harness.mjs';

const signIn = (page, name, password) => signInAs(H, page, name, password);

const ADMIN_PASSWORD = 'account-admin-pw';
const secrets = mkdtempSync(path.join(tmpdir(), 'seatrial-accounts-'));
const passwordFile = path.join(secrets, 'admin-password');
writeFileSync(passwordFile, `${ADMIN_PASSWORD}\n`);
const H = harness({ extraArgs: ['--auth', 'required', '--admin-password-file', passwordFile] });

const ME_401 = { method: 'GET', status: 401, path: /^\/api\/auth\/me$/ };
const LOGIN_401 = { method: 'POST', status: 401, path: /^\/api\/auth\/login$/ };
const LOGIN_429 = { method: 'POST', status: 429, path: /^\/api\/auth\/login$/ };
const GET_401 = { method: 'GET', status: 401, path: /^\/api\// };

before(async () => { await H.start(); });
after(async () => {
  await H.stop();
  rmSync(secrets, { recursive: true, force: true });
});


test('an admin manages users and tokens and changes the password on the account page', async () => {
  await H.withPage([ME_401, GET_401], async (page) => {
    await signIn(page, 'admin', ADMIN_PASSWORD);
    await page.click(tid('account-name'));
    await page.locator(tid('user-section')).waitFor();
    // A new user.
    await page.fill(tid('user-name'), 'pia');
    await page.selectOption(tid('user-role'), 'supervisor');
    await page.fill(tid('user-password'), 'pia-password');
    await page.click(tid('user-create'));
    await page.locator(tid('user-pia')).waitFor();
    // A token: shown once, works over REST, then revoked.
    await page.fill(tid('token-name'), 'laptop');
    await page.selectOption(tid('token-role'), 'viewer');
    await page.click(tid('token-create'));
    const secret = (await page.textContent(tid('token-secret'))).trim();
    assert.match(secret, /^st_/);
    await page.locator(tid('token-laptop')).waitFor();
    H.headers = { authorization: `Bearer ${secret}` };
    const withToken = await H.api('GET', '/api/auth/me');
    assert.equal(withToken.status, 200, JSON.stringify(withToken.json));
    assert.equal(withToken.json.role, 'viewer');
    page.once('dialog', (d) => d.accept());
    await page.click(`${tid('token-laptop')} ${tid('token-revoke')}`);
    // (The row says "until revoked" from the start: wait for its state cell.)
    await page.locator(`${tid('token-laptop')} ${tid('token-state')}:text-matches("^revoked")`).waitFor();
    const revoked = await H.api('GET', '/api/auth/me');
    H.headers = {};
    assert.equal(revoked.status, 401);
    if (process.env.ACCOUNT_SCREENSHOT) await page.screenshot({ path: process.env.ACCOUNT_SCREENSHOT, fullPage: true });
    // Disable, then enable, the new user.
    await page.click(`${tid('user-pia')} ${tid('user-toggle')}`);
    await page.locator(`${tid('user-pia')} ${tid('user-state')}:text-matches("^disabled")`).waitFor();
    await page.click(`${tid('user-pia')} ${tid('user-toggle')}`);
    await page.locator(`${tid('user-pia')} ${tid('user-state')}:text-is("active")`).waitFor();
    // No sideways scroll on a phone.
    await page.setViewportSize({ width: 390, height: 800 });
    const wide = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    assert.ok(wide <= 0, `the page scrolls sideways by ${wide} px at 390 px`);
    await page.setViewportSize({ width: 1280, height: 900 });
    // Change the password: signed out, the new one works.
    await page.fill(tid('pw-current'), ADMIN_PASSWORD);
    await page.fill(tid('pw-new'), 'a-new-admin-password');
    await page.fill(tid('pw-again'), 'a-new-admin-password');
    await page.click(tid('pw-submit'));
    await page.locator(tid('login-form')).waitFor();
    await page.fill(tid('login-name'), 'admin');
    await page.fill(tid('login-password'), 'a-new-admin-password');
    await page.click(tid('login-submit'));
    await page.locator(tid('account-role')).waitFor();
  });
});

test('a supervisor has no Users section; repeated wrong passwords are told to wait', async () => {
  await H.withPage([ME_401, GET_401, LOGIN_401, LOGIN_429], async (page) => {
    await signIn(page, 'pia', 'pia-password');
    await page.click(tid('account-name'));
    await page.locator(tid('token-section')).waitFor();
    assert.equal(await page.locator(tid('user-section')).count(), 0);
    await page.click(tid('logout'));
    await page.locator(tid('login-form')).waitFor();
    for (let i = 0; i < 6; i++) {
      await page.fill(tid('login-name'), 'pia');
      await page.fill(tid('login-password'), 'wrong-password');
      await Promise.all([
        page.waitForResponse((r) => r.url().endsWith('/api/auth/login')),
        page.click(tid('login-submit')),
      ]);
      await page.locator(`${tid('login-error')}:not(:empty)`).waitFor();
    }
    const text = await page.textContent(tid('login-error'));
    assert.match(text, /failed sign-ins for 'pia'; try again in \d+ s/);
  });
});
