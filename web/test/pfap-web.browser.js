// SPDX-License-Identifier: LGPL-2.1-or-later
// tools/pfap-web in a real browser: Debian's chromium, headless, driven by playwright-core,
// opens the page; the server speaks over WebRTC (Opus audio, PFAP RTP packets on an
// unreliable data channel) and the page's window.pfapStats says what arrived.
//
// Run by tests/web/pfap-web-browser.sh inside a network namespace with only lo (so ICE can
// only use 127.0.0.1), with PFAP_WEB (the server) and GST_PLUGIN_PATH set.
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';

import { chromium } from 'playwright-core';

const webDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const CHROMIUM = process.env.PFAP_CHROMIUM ?? '/usr/bin/chromium';
// Sharp onsets after silence: each "pa" sounds as its closed lips open.
const ONSETS_TEXT = 'pa. pa. pa. pa. pa. pa. pa. pa. pa. pa.';
const LOSS_TEXT =
  'Hello! <FAP 2 1 40 0 0 800 3> I am a talking head. <FAP 48 6000 400 2> My voice comes ' +
  'over WebRTC, <FAP 2 6 50 0 0 300 2> my face on a data channel. <FAP 2 1 50 0 0 800 3> Bye!';

let browser;

before(async () => {
  browser = await chromium.launch({
    executablePath: CHROMIUM,
    args: [
      '--no-sandbox',  // as root (the namespace needs it)
      '--autoplay-policy=no-user-gesture-required',
      '--allow-loopback-in-peer-connection',  // the namespace has only lo
      '--disable-features=WebRtcHideLocalIpsWithMdns',
      '--use-fake-ui-for-media-stream',
    ],
  });
});

after(async () => {
  await browser?.close();
});

// Stops pfap-web with SIGTERM (as Ctrl-C would); resolves to its exit status, or to the
// signal that ended it (SIGKILL after 10 s if SIGTERM did not).
function stop(server) {
  return new Promise((resolve) => {
    if (server.exitCode !== null || server.signalCode !== null) {
      resolve(server.exitCode ?? server.signalCode);
      return;
    }
    const kill = setTimeout(() => server.kill('SIGKILL'), 10000);
    server.once('exit', (code, signal) => {
      clearTimeout(kill);
      resolve(code ?? signal);
    });
    server.kill('SIGTERM');
  });
}

// Starts pfap-web on a free port; resolves to {url, stop, log}.
function startServer(args) {
  const server = spawn(process.env.PFAP_WEB, ['--port=0', `--web-dir=${webDir}`, ...args], {
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  let log = '';
  server.stderr.on('data', (d) => { log += d; });
  return new Promise((resolve, reject) => {
    server.on('exit', (code) => reject(new Error(`pfap-web exited (${code}): ${log}`)));
    server.stdout.on('data', (d) => {
      log += d;
      const m = /open (http:\S+)/.exec(log);
      if (m) resolve({ url: m[1], stop: () => stop(server), log: () => log });
    });
  });
}

// Opens the page, waits until the server has said its text, the audio played it to its end,
// and the page's FAP state settled (equal to the sender's, or the time is up); returns the
// page's figures.
async function openPage(url, { screenshot, next } = {}) {
  const page = await browser.newPage({ viewport: { width: 640, height: 720 } });
  const messages = [];
  page.on('console', (m) => messages.push(m.text()));
  try {
    await page.goto(url);
    if (screenshot) {
      await page.waitForFunction(() => window.pfapStats?.phonemes >= 20, null, { timeout: 20000 });
      await page.locator('body').screenshot({ path: screenshot });
    }
    // Its packets go ahead of the audio: the end is when the audio has played past the last.
    await page.waitForFunction(() => window.pfapStats?.done >= 1 && window.pfapStats.streamNs > window.pfapStats.endNs + 3e8,
      null, { timeout: 30000, polling: 100 });
    await page.waitForFunction(() => window.pfapStats.fapStateMatchesSender, null, { timeout: 5000, polling: 100 })
      .catch(() => {});
    if (next) {
      // Something new to say, typed into the page's box.
      await page.fill('#say', next);
      await page.click('#go');
      await page.waitForFunction(() => window.pfapStats.done >= 2 && window.pfapStats.streamNs > window.pfapStats.endNs + 3e8,
        null, { timeout: 30000, polling: 100 });
      await page.waitForFunction(() => window.pfapStats.fapStateMatchesSender, null, { timeout: 5000, polling: 100 })
        .catch(() => {});
    }
    return await page.evaluate(() => {
      const s = window.pfapStats;
      s.measureLipSync();
      return s;
    });
  } catch (e) {
    // The page's figures but its level and frames, with the loudest level it played (0: it
    // played silence, as when the server's mixer dropped a text's audio as late) and what
    // reached its audio.
    const stats = await page.evaluate(async () => {
      const { envelope = [], frames, ...rest } = window.pfapStats ?? {};
      return JSON.stringify({
        ...rest,
        loudestPlayed: envelope.reduce((m, e) => Math.max(m, e.rms), 0),
        receivedAudio: await window.pfapStats?.receivedAudio(),
      });
    }).catch(() => 'none');
    throw new Error(`${e.message}\nstats: ${stats}\npage: ${messages.join('\n')}`);
  } finally {
    await page.close();
  }
}

// Starts a server with `args`, opens `pages` pages on it at once; their figures.
async function sessions(args, { pages = 1, screenshot, next } = {}) {
  const server = await startServer(args);
  let all;
  try {
    all = await Promise.all(Array.from({ length: pages }, (_, i) =>
      openPage(server.url, { screenshot: i === 0 ? screenshot : undefined, next: i === 0 ? next : undefined })));
  } catch (e) {
    await server.stop();
    throw new Error(`${e.message}\nserver: ${server.log()}`);
  }
  // A clean stop: sessions closed, pipelines stopped, exit status 0 (and, in the sanitizer
  // build, nothing leaked).
  assert.equal(await server.stop(), 0, `pfap-web stopped by SIGTERM:\n${server.log()}`);
  return all;
}

test('every phoneme arrives, in lip sync with the sound', async () => {
  const [s] = await sessions([`--text=${ONSETS_TEXT}`]);
  assert.equal(s.sender.dropped, 0);
  assert.ok(s.sender.phonemes > 0);
  assert.equal(s.phonemes, s.sender.phonemes, 'every phoneme the server sent');
  assert.equal(s.packets, s.sender.packets);
  assert.equal(s.lost, 0);
  // Uncertain events only when the unordered channel delivered a packet after a later one (as
  // the stream's first data packet overtaking its first complete state would: docs/web.md).
  assert.ok(s.uncertain === 0 || s.late > 0, `uncertain ${s.uncertain}, late ${s.late}`);
  assert.equal(s.fapStateMatchesSender, true);
  // The lip-sync figures go to docs/web.md (PFAP_LIPSYNC_OUT collects them); here only
  // sanity: most onsets found, none beyond the pairing window, and their median no further
  // than a few frames from the sound (per run it was +3 to +11 ms, docs/web.md).
  if (process.env.PFAP_LIPSYNC_OUT) writeFileSync(process.env.PFAP_LIPSYNC_OUT, JSON.stringify(s));
  const errors = s.lipSyncErrorsMs;
  assert.ok(errors.length >= 5, `onsets paired (of 10): ${JSON.stringify(errors)}`);
  for (const e of errors) assert.ok(Math.abs(e) <= 150, `lip sync error ${e} ms`);
  const median = [...errors].sort((a, b) => a - b)[Math.floor(errors.length / 2)];
  assert.ok(median >= -20 && median <= 40, `median lip sync error ${median} ms: ${JSON.stringify(errors)}`);
});

test('with a tenth of the PFAP messages dropped the FAP state is repaired', async () => {
  const [s] = await sessions([`--text=${LOSS_TEXT}`, '--drop=0.1', '--seed=7'], {
    screenshot: process.env.PFAP_SCREENSHOT,
  });
  assert.ok(s.sender.dropped > 0, 'some messages dropped');
  assert.ok(s.lost > 0);
  assert.equal(s.fapStateMatchesSender, true, JSON.stringify(s));
});

test('three browsers at once each get their own whole session; one says something new', async () => {
  const all = await sessions(['--text=One, two, three.'], { pages: 3, next: 'Four <FAP 2 1 40 0 0 300 1> five.' });
  assert.equal(all[0].done, 2);
  assert.equal(all[0].texts, 2);
  for (const s of all) {
    assert.equal(s.sender.dropped, 0);
    assert.equal(s.phonemes, s.sender.phonemes);
    assert.equal(s.lost, 0);
    assert.equal(s.fapStateMatchesSender, true);
  }
});

// Exactly the README's line, `chromium --allow-loopback-in-peer-connection URL` (headless,
// and --no-sandbox as root): Chromium hides its host candidates behind mDNS names here, and
// on a machine with only lo it gathered none the server could reach, so the page said
// "connecting" for ever. The server's STUN server gives it one (docs/web.md).
test('the README\'s chromium line connects, and speaks after a click', async () => {
  const readme = await chromium.launch({
    executablePath: CHROMIUM,
    args: ['--no-sandbox', '--allow-loopback-in-peer-connection'],
  });
  const server = await startServer(['--text=One, two.']);
  try {
    const page = await readme.newPage();
    await page.goto(server.url);
    await page
        .waitForFunction(() => window.pfapStats?.connected, null, {timeout: 20000, polling: 100})
        .catch(async (e) => {
          throw new Error(`${e.message}\nstatus: ${await page.textContent('#status')}\nserver: ${
              server.log()}`);
        });
    await page.click('canvas');  // the gesture that lets the page play sound
    await page.waitForFunction(
        () => window.pfapStats.done >= 1, null, {timeout: 20000, polling: 100});
    const s = await page.evaluate(() => window.pfapStats);
    assert.ok(s.phonemes > 0);
    assert.equal(s.phonemes, s.sender.phonemes);
  } finally {
    await readme.close();
    assert.equal(await server.stop(), 0, server.log());
  }
});

test('a page the server refuses says why', async () => {
  const server = await startServer(['--max-sessions=1']);
  const pages = [];
  try {
    for (let i = 0; i < 2; ++i) {
      const page = await browser.newPage();
      pages.push(page);
      await page.goto(server.url);
      await page.waitForFunction(() => window.pfapStats, null, {timeout: 10000});
    }
    await pages[1].waitForFunction(
        () => window.pfapStats.problem, null, {timeout: 10000, polling: 100});
    assert.match(
        await pages[1].textContent('#status'),
        /^closed by the server: the server is full: 1 sessions at once/);
  } finally {
    for (const page of pages) await page.close();
    assert.equal(await server.stop(), 0, server.log());
  }
});
