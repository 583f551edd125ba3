// SPDX-License-Identifier: LGPL-2.1-or-later
// The talking head broadcast through Janus (docs/web.md): Debian's janus with the project's
// configuration (scripts/janus-config), tools/pfap-broadcast as the sender, and Debian's
// chromium, headless, driven by playwright-core, as the viewers; their window.pfapStats say
// what arrived.
//
// Run by tests/web/janus-broadcast.sh inside a network namespace of its own (lo and a veth
// pair for Janus's ICE, PFAP_JANUS_ICE_ADDRESS), with PFAP_BROADCAST (the sender),
// PFAP_SOURCE_ROOT and GST_PLUGIN_PATH set. PFAP_BROADCAST_OUT=FILE writes every page's figures there.
import assert from 'node:assert/strict';
import { execFileSync, spawn } from 'node:child_process';
import { createReadStream, existsSync, mkdtempSync, rmSync, statSync, writeFileSync } from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';

import { chromium } from 'playwright-core';

const webDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const sourceRoot = process.env.PFAP_SOURCE_ROOT ?? path.resolve(webDir, '..');
const CHROMIUM = process.env.PFAP_CHROMIUM ?? '/usr/bin/chromium';
// The namespace is the test's own: fixed ports cannot collide with anyone's.
const JANUS_PORT = 8088;
const AUDIO_PORT = 5002;
const DATA_PORT = 5004;
// Sharp onsets after silence for the lip-sync measurement (each "pa" sounds as its closed
// lips open), and four bookmarks for the FAP state to repair.
const TEXT = 'pa. pa. <FAP 2 1 40 0 0 800 3> pa. pa. <FAP 48 6000 400 2> pa. pa. ' +
  '<FAP 2 6 50 0 0 300 2> pa. pa. <FAP 2 1 50 0 0 800 3> pa. pa. ' +
  'And now, for those who joined late, <FAP 48 -4000 400 2> a few more words, to be whole with.';
// rtppfappay's complete-recovery-interval (its default): a late joiner is whole within it.
const COMPLETE_INTERVAL_MS = 1000;

let browser;
let janus;
let pageServer;
let tmp;

// The viewer page and what it imports, as scripts/broadcast serves them.
const served = {
  '/src/': path.join(webDir, 'src'),
  '/live/': path.join(webDir, 'live'),
  '/broadcast/': path.join(webDir, 'broadcast'),
  '/janus-gateway/': '/usr/share/javascript/janus-gateway',
  '/webrtc-adapter/': '/usr/share/javascript/webrtc-adapter',
};
const types = { '.html': 'text/html', '.js': 'text/javascript' };

function servePages() {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://127.0.0.1');
    const prefix = Object.keys(served).find((p) => url.pathname.startsWith(p));
    let file = prefix && path.join(served[prefix], path.normalize(url.pathname.slice(prefix.length)));
    if (file && existsSync(file) && statSync(file).isDirectory()) file = path.join(file, 'index.html');
    if (!file || !file.startsWith(served[prefix]) || !existsSync(file)) {
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, { 'Content-Type': types[path.extname(file)] ?? 'application/octet-stream' });
    createReadStream(file).pipe(res);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

// Stops a child with SIGTERM (as Ctrl-C would); resolves to its exit status, or to the signal
// that ended it (SIGKILL after 10 s if SIGTERM did not).
function stop(child) {
  return new Promise((resolve) => {
    if (child.exitCode !== null || child.signalCode !== null) {
      resolve(child.exitCode ?? child.signalCode);
      return;
    }
    const kill = setTimeout(() => child.kill('SIGKILL'), 10000);
    child.once('exit', (code, signal) => {
      clearTimeout(kill);
      resolve(code ?? signal);
    });
    child.kill('SIGTERM');
  });
}

function run(file, args) {
  const child = spawn(file, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  child.out = '';
  child.log = '';
  child.stdout.on('data', (d) => { child.out += d; });
  child.stderr.on('data', (d) => { child.log += d; });
  return child;
}

async function janusAnswers() {
  for (let i = 0; i < 100; ++i) {
    try {
      if ((await fetch(`http://127.0.0.1:${JANUS_PORT}/janus/info`)).ok) return;
    } catch {
      // not yet
    }
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error(`Janus does not answer:\n${janus.out}${janus.log}`);
}

before(async () => {
  tmp = mkdtempSync(path.join(os.tmpdir(), 'pfap-janus-'));
  execFileSync(path.join(sourceRoot, 'scripts', 'janus-config'),
    [path.join(tmp, 'janus'), String(JANUS_PORT), String(AUDIO_PORT), String(DATA_PORT), process.env.PFAP_JANUS_ICE_ADDRESS]);
  janus = run('janus', ['-F', path.join(tmp, 'janus'), '-C', path.join(tmp, 'janus', 'janus.jcfg')]);
  pageServer = await servePages();
  browser = await chromium.launch({
    executablePath: CHROMIUM,
    args: [
      '--no-sandbox',  // as root (the namespace needs it)
      '--autoplay-policy=no-user-gesture-required',
      '--disable-features=WebRtcHideLocalIpsWithMdns',
    ],
  });
  await janusAnswers();
});

after(async () => {
  await browser?.close();
  pageServer?.close();
  if (janus) {
    // Janus stops cleanly on SIGTERM, as on Ctrl-C.
    const status = await stop(janus);
    assert.equal(status, 0, `janus stopped by SIGTERM:\n${janus.log}`);
  }
  if (tmp) rmSync(tmp, { recursive: true, force: true });
});

// Opens a viewer page; resolves once it receives the mountpoint's data stream.
async function openViewer() {
  const page = await browser.newPage({ viewport: { width: 640, height: 720 } });
  const messages = [];
  page.on('console', (m) => messages.push(m.text()));
  page.on('response', (r) => r.status() >= 400 && messages.push(`${r.status()} ${r.url()}`));
  page.messages = messages;
  const { port } = pageServer.address();
  await page.goto(`http://127.0.0.1:${port}/broadcast/?janus=http://127.0.0.1:${JANUS_PORT}/janus`);
  await page.waitForFunction(() => window.pfapStats?.dataOpen, null, { timeout: 20000, polling: 100 })
    .catch((e) => { throw new Error(`${e.message}\npage: ${messages.join('\n')}\njanus: ${janus.out}${janus.log}`); });
  return page;
}

// Waits until the page has the sender's closing state and has played the audio past the last
// phoneme; its figures.
async function figures(page) {
  try {
    await page.waitForFunction(() => window.pfapStats.done >= 1 && window.pfapStats.streamNs > window.pfapStats.endNs + 3e8,
      null, { timeout: 30000, polling: 100 });
    return await page.evaluate(() => {
      const s = window.pfapStats;
      s.measureLipSync();
      const { envelope, frames, ...rest } = s;
      return rest;
    });
  } catch (e) {
    const s = await page.evaluate(() => { const { envelope, frames, ...rest } = window.pfapStats; return rest; });
    throw new Error(`${e.message}\n${JSON.stringify(s)}\npage: ${page.messages.join('\n')}`);
  } finally {
    await page.close();
  }
}

test('three viewers through Janus, a tenth of the PFAP datagrams dropped before it: each whole and in lip sync; a late joiner whole within a complete-state interval', async () => {
  const viewers = await Promise.all([openViewer(), openViewer(), openViewer()]);
  const sender = run(process.env.PFAP_BROADCAST, [`--audio-port=${AUDIO_PORT}`, `--data-port=${DATA_PORT}`,
    `--text=${TEXT}`, '--drop=0.1', '--seed=3']);
  // A fourth joins 2 s into the speech.
  await new Promise((r) => setTimeout(r, 2000));
  const late = await openViewer();
  const all = await Promise.all([...viewers, late].map(figures));
  const exit = await new Promise((resolve) => (sender.exitCode !== null ? resolve(sender.exitCode) : sender.once('exit', resolve)));
  assert.equal(exit, 0, sender.log);
  const sent = JSON.parse(sender.out.trim().split('\n').at(-1));
  if (process.env.PFAP_BROADCAST_OUT) writeFileSync(process.env.PFAP_BROADCAST_OUT, JSON.stringify({ sent, pages: all }));

  assert.ok(sent.dropped > 0, 'some PFAP datagrams dropped');
  for (const [i, s] of all.entries()) {
    const which = `page ${i + 1}: ${JSON.stringify(s)}`;
    assert.deepEqual(s.sender.settled, sent.settled, which);
    assert.equal(s.fapStateMatchesSender, true, which);
    assert.equal(s.streams, 1, which);
    assert.ok(s.matched, `the played level found in the sender's: ${which}`);
    if (i === 3) continue;
    // Every phoneme Janus had to relay: all but those of the datagrams dropped before it.
    assert.equal(s.phonemes, sent.phonemes - sent.phonemesDropped, which);
    assert.equal(s.packets, sent.packets - sent.dropped, which);
    assert.ok(s.lost > 0, which);
    // Whole from the stream's first complete state that arrives (with this seed the opening
    // one is among those dropped: the pages wait for the next).
    assert.ok(s.wholeAfterMs !== null, which);
    // Sanity only (the figures go to docs/web.md): most onsets paired, their median a few
    // frames from the sound at most.
    const errors = s.lipSyncErrorsMs;
    assert.ok(errors.length >= 4, `onsets paired (of 10): ${which}`);
    const median = [...errors].sort((a, b) => a - b)[Math.floor(errors.length / 2)];
    assert.ok(median >= -20 && median <= 40, `median lip sync error ${median} ms: ${which}`);
  }
  // The late joiner: joined mid-stream, whole from the first complete state, which comes
  // within an interval of stream time (and the packet it goes before) of its first packet.
  const s = all[3];
  assert.ok(s.phonemes > 0 && s.phonemes < sent.phonemes - sent.phonemesDropped, JSON.stringify(s));
  assert.ok(s.wholeAfterMs !== null && s.wholeAfterMs <= COMPLETE_INTERVAL_MS + 500, `whole after ${s.wholeAfterMs} ms`);
});
