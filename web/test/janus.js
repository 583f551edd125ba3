// SPDX-License-Identifier: LGPL-2.1-or-later
// What the broadcast's browser test (janus-broadcast.browser.js) and its benchmark
// (../bench/janus-viewers.browser.js) share: Janus with the project's configuration
// (scripts/janus-config), the viewer page served as scripts/broadcast serves it, the sender,
// Debian's chromium and the viewers. All run inside the network namespace that
// tests/web/janus-broadcast.sh makes (its ports are the namespace's own).
import { execFileSync, spawn } from 'node:child_process';
import { createReadStream, existsSync, mkdtempSync, readdirSync, readFileSync, readlinkSync, rmSync, statSync } from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { chromium } from 'playwright-core';

const webDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const sourceRoot = process.env.PFAP_SOURCE_ROOT ?? path.resolve(webDir, '..');
export const JANUS_PORT = 8088;
export const AUDIO_PORT = 5002;
export const DATA_PORT = 5004;
// rtppfappay's complete-recovery-interval (its default): a late joiner is whole within it.
export const COMPLETE_INTERVAL_MS = 1000;

// Stops a child with SIGTERM (as Ctrl-C would); resolves to its exit status, or to the signal
// that ended it (SIGKILL after 10 s if SIGTERM did not).
export function stop(child) {
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

/** Runs `file`; its stdout collects in `.out`, its stderr in `.log`. */
export function run(file, args) {
  const child = spawn(file, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  child.out = '';
  child.log = '';
  child.stdout.on('data', (d) => { child.out += d; });
  child.stderr.on('data', (d) => { child.log += d; });
  return child;
}

/** Resolves to the exit status of `child` once it has ended. */
export function exited(child) {
  return new Promise((resolve) => (child.exitCode !== null ? resolve(child.exitCode) : child.once('exit', resolve)));
}

/**
 * A process's or thread's `stat` file (`/proc/PID/stat`, `/proc/PID/task/TID/stat`): its name,
 * its parent's pid and the CPU time (user and system, s) it has used. The name is between
 * parentheses and may hold any character, ") " and digits included: the fields follow the last ")".
 */
export function procStat(file) {
  const stat = readFileSync(file, 'utf8');
  const close = stat.lastIndexOf(')');
  const fields = stat.slice(close + 2).split(' ');  // from the state, the third field
  return {
    name: stat.slice(stat.indexOf('(') + 1, close),
    ppid: fields[1],
    cpu: (Number(fields[11]) + Number(fields[12])) / 100,  // utime, stime in clock ticks (USER_HZ 100)
  };
}

/** CPU time (user and system, s) that process `pid` has used. */
export function cpuSeconds(pid) {
  return procStat(`/proc/${pid}/stat`).cpu;
}

// The sockets of process `pid` by inode: 'tcp ESTABLISHED' and the like, 'udp', 'unix', 'netlink'.
function socketsOf(pid) {
  const tcpStates = { '01': 'ESTABLISHED', '06': 'TIME_WAIT', '08': 'CLOSE_WAIT', '0A': 'LISTEN' };
  const sockets = {};
  for (const proto of ['tcp', 'udp', 'unix', 'netlink']) {
    for (const line of readFileSync(`/proc/${pid}/net/${proto}`, 'utf8').split('\n').slice(1)) {
      const f = line.trim().split(/\s+/);
      if (f.length < 8) continue;
      const inode = { unix: f[6], netlink: f[8] }[proto] ?? f[9];
      sockets[inode] = proto === 'tcp' ? `tcp ${tcpStates[f[3]] ?? f[3]}` : proto;
    }
  }
  return sockets;
}

/** What the fds of process `pid` are (sockets by protocol and state), for a failure's message. */
export function describeFds(pid) {
  const sockets = socketsOf(pid);
  return readdirSync(`/proc/${pid}/fd`).map((fd) => {
    try {
      const target = readlinkSync(`/proc/${pid}/fd/${fd}`);
      return sockets[target.match(/^socket:\[(\d+)\]$/)?.[1]] ?? target;
    } catch {
      return '?';
    }
  });
}

/**
 * The open file descriptors and threads of process `pid`. The fds leave out TCP connections
 * that the peer has closed (CLOSE_WAIT): those are Janus's long polls, each held until Janus
 * answers it (30 s at most) after the page that asked has gone. Without `pipes`, they leave out
 * pipes too: a sender's pfaptts holds one from pfap-espeak while a sentence is synthesized
 * (docs/tts.md), so how many it holds depends on the moment.
 */
export function resources(pid, { pipes = true } = {}) {
  const fds = describeFds(pid)
    .filter((d) => d !== 'tcp CLOSE_WAIT' && (pipes || !d.startsWith('pipe:'))).length;
  return { fds, threads: readdirSync(`/proc/${pid}/task`).length };
}

/**
 * Resolves to the resources of process `pid` once they are back at `baseline` (Janus frees a
 * session's handle, its ICE thread and sockets, a little after the viewer leaves), or to the
 * last reading after `timeoutMs`.
 */
export async function settledResources(pid, baseline, timeoutMs = 10000) {
  let now = resources(pid);
  for (let waited = 0; waited < timeoutMs && (now.fds > baseline.fds || now.threads > baseline.threads); waited += 200) {
    await new Promise((r) => setTimeout(r, 200));
    now = resources(pid);
  }
  return now;
}

/** Starts Janus in a temporary directory; resolves once its API answers. */
export async function startJanus() {
  const tmp = mkdtempSync(path.join(os.tmpdir(), 'pfap-janus-'));
  execFileSync(path.join(sourceRoot, 'scripts', 'janus-config'), [path.join(tmp, 'janus'), String(JANUS_PORT),
    String(AUDIO_PORT), String(DATA_PORT), process.env.PFAP_JANUS_ICE_ADDRESS]);
  const janus = run('janus', ['-F', path.join(tmp, 'janus'), '-C', path.join(tmp, 'janus', 'janus.jcfg')]);
  janus.cleanup = () => rmSync(tmp, { recursive: true, force: true });
  for (let i = 0; i < 100; ++i) {
    try {
      if ((await fetch(`http://127.0.0.1:${JANUS_PORT}/janus/info`)).ok) return janus;
    } catch {
      // not yet
    }
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error(`Janus does not answer:\n${janus.out}${janus.log}`);
}

/** The sender, saying `text` with `args` (--drop=P, --seed=S). */
export function startSender(text, args = []) {
  return run(process.env.PFAP_BROADCAST, [`--audio-port=${AUDIO_PORT}`, `--data-port=${DATA_PORT}`, `--text=${text}`, ...args]);
}

// The viewer page and what it imports, as scripts/broadcast serves them.
const served = {
  '/src/': path.join(webDir, 'src'),
  '/live/': path.join(webDir, 'live'),
  '/broadcast/': path.join(webDir, 'broadcast'),
  '/janus-gateway/': '/usr/share/javascript/janus-gateway',
  '/webrtc-adapter/': '/usr/share/javascript/webrtc-adapter',
};
const types = { '.html': 'text/html', '.js': 'text/javascript' };

/** Serves the viewer page on a free port of 127.0.0.1. */
export function servePages() {
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

/** Debian's chromium, headless, allowed to play sound unasked. */
export function launchChromium() {
  return chromium.launch({
    executablePath: process.env.PFAP_CHROMIUM ?? '/usr/bin/chromium',
    args: [
      '--no-sandbox',  // as root (the namespace needs it)
      '--autoplay-policy=no-user-gesture-required',
      '--allow-loopback-in-peer-connection',  // pfap-web's ICE is on 127.0.0.1
      '--disable-features=WebRtcHideLocalIpsWithMdns',
    ],
  });
}

/** A new blank page of `browser`, its console and failed loads kept in `.messages`. */
export async function blankPage(browser) {
  const page = await browser.newPage({ viewport: { width: 640, height: 720 } });
  const messages = [];
  page.on('console', (m) => messages.push(m.text()));
  page.on('response', (r) => r.status() >= 400 && messages.push(`${r.status()} ${r.url()}`));
  page.messages = messages;
  return page;
}

/**
 * Opens `url` in `page` (by default a new blank page of `browser`); `timeout` bounds the load
 * (ms; playwright's 30 s by default).
 */
export async function newPage(browser, url, { timeout, page } = {}) {
  page ??= await blankPage(browser);
  await page.goto(url, { timeout });
  return page;
}

/** Resolves once the viewer page receives the mountpoint's data stream. */
export async function watching(page, janus, { timeout = 30000 } = {}) {
  await page.waitForFunction(() => window.pfapStats?.dataOpen, null, { timeout, polling: 100 })
    .catch((e) => { throw new Error(`${e.message}\npage: ${page.messages.join('\n')}\njanus: ${janus.out}${janus.log}`); });
}

/**
 * Opens a viewer page (in `page`, a blank page made beforehand, if given); resolves once it
 * receives the mountpoint's data stream (`timeout` bounds each, ms).
 */
export async function openViewer(browser, pageServer, janus, options = {}) {
  const { port } = pageServer.address();
  const page = await newPage(browser, `http://127.0.0.1:${port}/broadcast/?janus=http://127.0.0.1:${JANUS_PORT}/janus`, options);
  await watching(page, janus, options);
  return page;
}

/**
 * Resolves once the viewer page has received `phonemes` phonemes of the stream. The tests time
 * what they do mid-speech by it, not by the clock: a loaded machine's sender can take seconds
 * to begin (a fresh root's sanitizer build once had not sent its first packet 2.5 s in).
 */
export async function received(page, phonemes, { timeout = 30000 } = {}) {
  await page.waitForFunction((n) => window.pfapStats.phonemes >= n, phonemes, { timeout, polling: 50 })
    .catch(async (e) => {
      // The page's figures but its level and frames, as figures() gives them.
      const stats = await page.evaluate(() => {
        const { envelope, frames, ...rest } = window.pfapStats;
        return JSON.stringify(rest);
      });
      throw new Error(`${e.message}\n${stats}`);
    });
}

/**
 * Waits until the page has the sender's state at the end and has played the audio past the
 * last phoneme (pfap-web's page and the viewer page alike); its figures (lip sync measured).
 * The page then leaves as a viewer closing the tab does: navigating away runs its unload
 * handlers (janus.js destroys its session with Janus there), which closing it alone does not.
 */
export async function figures(page, { timeout = 30000 } = {}) {
  // With a figures file asked for, also the played level and the frames of the stream's first
  // 1.5 s of drawing (the first syllable: docs/web.md), and the whole of them with the clock's
  // record, to look at each lip-sync error afterwards ("Lost clocks").
  const withStart = Boolean(process.env.PFAP_BROADCAST_OUT || process.env.PFAP_BENCH_OUT);
  const read = () => page.evaluate((withStart) => {
    const s = window.pfapStats;
    s.measureLipSync();
    const { envelope, frames, ...rest } = s;
    const from = s.start?.trace[0]?.t;
    if (withStart && from !== undefined) {
      const within = (e) => e.t >= from - 300 && e.t < from + 1500;
      rest.start = { ...s.start, envelope: envelope.filter(within), frames: frames.filter(within) };
    }
    if (withStart) Object.assign(rest, { envelope, frames });
    return rest;
  }, withStart);
  try {
    await page.waitForFunction(() => window.pfapStats.done >= 1 && window.pfapStats.streamNs > window.pfapStats.endNs + 3e8,
      null, { timeout, polling: 100 });
    return await read();
  } catch (e) {
    throw new Error(`${e.message}\n${JSON.stringify(await read())}\npage: ${page.messages.join('\n')}`);
  } finally {
    await page.goto('about:blank').catch(() => {});
    await page.close();
  }
}
