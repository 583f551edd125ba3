// SPDX-License-Identifier: LGPL-2.1-or-later
// Benchmark (figures printed, nothing timed asserted): N viewers of one talking head through
// Janus beside N sessions of pfap-web, in one run on this machine (docs/web.md, "Broadcast
// through Janus: measured"). N is PFAP_VIEWERS (20). For each side it prints the server's CPU
// time for one text said to every viewer (Janus's with 1 viewer and with N, in all and during
// the speech alone; pfap-web's with N sessions), Chromium's by process kind and the
// renderers' by thread, and for each page whether it is whole and its lip-sync errors
// (median, 95th percentile of |error|, ms). PFAP_PROFILE=1 adds where one page's main thread
// spends the speech; PFAP_BENCH_OUT=FILE keeps every page's figures there.
//
//   sudo PFAP_VIEWERS=20 PFAP_TIMEOUT=900 PFAP_BROADCAST=build/tools/pfap-broadcast \
//     PFAP_WEB=build/tools/pfap-web GST_PLUGIN_PATH=build/gst:build/ext \
//     tests/web/janus-broadcast.sh node web/bench/janus-viewers.browser.js
import { readFileSync, readdirSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

import {
  cpuSeconds, exited, figures, launchChromium, newPage, openViewer, procStat, run, servePages, startJanus, startSender,
  stop,
} from '../test/janus.js';

const webDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const VIEWERS = Number(process.env.PFAP_VIEWERS ?? 20);
// How long a page may take to load: at N = 20 on this machine one took over 30 s (playwright's default).
const LOAD_TIMEOUT_MS = 120000;
// As pfap-web's browser test measures lip sync: sharp onsets after silence.
const TEXT = 'pa. pa. pa. pa. pa. pa. pa. pa. pa. pa.';

const percentile = (values, p) => {
  const sorted = [...values].sort((a, b) => a - b);
  return sorted.length ? sorted[Math.min(sorted.length - 1, Math.ceil(p * sorted.length) - 1)] : NaN;
};
const fixed = (v) => (Number.isFinite(v) ? v.toFixed(1) : '-');

// Opens `count` pages `batch` at a time.
async function inBatches(count, batch, open) {
  const pages = [];
  for (let i = 0; i < count; i += batch) {
    pages.push(...await Promise.all(Array.from({ length: Math.min(batch, count - i) }, open)));
  }
  return pages;
}

// The CPU time `pid` uses while `during` runs, read every 200 ms (a process that ends keeps
// its last reading); and the wall time.
async function measured(pid, during) {
  const start = cpuSeconds(pid);
  let last = start;
  const poll = setInterval(() => { try { last = cpuSeconds(pid); } catch { /* ended */ } }, 200);
  const t0 = performance.now();
  // A run that fails half-way stops reading too: the interval would keep node running.
  const result = await during().finally(() => clearInterval(poll));
  const wall = (performance.now() - t0) / 1000;
  try { last = cpuSeconds(pid); } catch { /* ended */ }
  return { cpu: last - start, wall, result };
}

// Chromium's processes (descendants of this node process) by kind: the browser, renderers
// (one a page), the GPU process, and utility processes by service (audio, network, ...).
function chromiumKinds() {
  const parent = {};
  const kind = {};
  for (const pid of readdirSync('/proc').filter((d) => /^\d+$/.test(d))) {
    try {
      parent[pid] = procStat(`/proc/${pid}/stat`).ppid;
      // Chromium rewrites its processes' titles: the arguments, space separated.
      const args = readFileSync(`/proc/${pid}/cmdline`, 'utf8').split(/[\0 ]/);
      if (!/chrom/.test(args[0])) continue;
      const type = args.find((a) => a.startsWith('--type='))?.slice(7) ?? 'browser';
      const service = args.find((a) => a.startsWith('--utility-sub-type='))?.slice(19).split('.')[0];
      kind[pid] = type === 'utility' && service ? service : type;
    } catch {
      // gone
    }
  }
  const ours = (pid) => {
    for (let p = pid; p && p !== '0' && p !== '1'; p = parent[p]) if (p === String(process.pid)) return true;
    return false;
  };
  return Object.fromEntries(Object.entries(kind).filter(([pid]) => ours(pid)));
}

// The CPU time (s) of each thread of process `pid`, by thread name (digits left out).
function threadSeconds(pid) {
  const threads = {};
  for (const tid of readdirSync(`/proc/${pid}/task`)) {
    const { name, cpu } = procStat(`/proc/${pid}/task/${tid}/stat`);
    threads[tid] = { name: name.replace(/\d+/g, ''), cpu };
  }
  return threads;
}

// The CPU time of Chromium's processes by kind while `during` runs, read every 200 ms (a
// process that ends, a closed page's renderer, keeps its last reading), and of the renderers'
// threads by name; and the wall time.
async function chromiumCpu(during) {
  const first = {};
  const last = {};
  const kinds = {};
  const read = () => {
    for (const [pid, k] of Object.entries(chromiumKinds())) {
      try {
        const ts = k === 'renderer' ? threadSeconds(pid) : { [pid]: { name: '', cpu: cpuSeconds(pid) } };
        for (const [tid, { name, cpu }] of Object.entries(ts)) {
          first[tid] ??= cpu;
          last[tid] = cpu;
          kinds[tid] = k === 'renderer' ? `renderer ${name}` : k;
        }
      } catch {
        // ended
      }
    }
  };
  read();
  const poll = setInterval(read, 200);
  const t0 = performance.now();
  const result = await during().finally(() => clearInterval(poll));
  const wall = (performance.now() - t0) / 1000;
  const byKind = {};
  for (const [id, k] of Object.entries(kinds)) {
    byKind[k] ??= { count: 0, cpu: 0 };
    byKind[k].count += 1;
    byKind[k].cpu += last[id] - first[id];
  }
  return { wall, byKind, result };
}

// Chromium's CPU by process kind (how many) and the renderers' by thread name, the busiest
// first; what used under 0.05 s left out.
const kindRow = (label, { wall, byKind }) => `${label}, Chromium's CPU over ${wall.toFixed(1)} s: ` +
  Object.entries(byKind).filter(([, { cpu }]) => cpu >= 0.05).sort((a, b) => b[1].cpu - a[1].cpu)
    .map(([k, { count, cpu }]) => `${k} ${cpu.toFixed(2)} s (${count})`).join(', ');

// With PFAP_PROFILE set: where one page's main thread spends its time while `during` runs
// (CDP: the renderer's task and script durations, and V8's sampling profile by function).
async function profiled(page, during) {
  if (!process.env.PFAP_PROFILE) return { result: await during(), lines: [] };
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Performance.enable');
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 500 });
  const metrics = async () => Object.fromEntries((await cdp.send('Performance.getMetrics')).metrics.map((m) => [m.name, m.value]));
  const before = await metrics();
  await cdp.send('Profiler.start');
  const t0 = performance.now();
  const result = await during();
  const wall = (performance.now() - t0) / 1000;
  const { profile } = await cdp.send('Profiler.stop');
  const after = await metrics();
  const self = {};
  const byId = Object.fromEntries(profile.nodes.map((n) => [n.id, n]));
  profile.samples.forEach((id, i) => {
    const { functionName, url, lineNumber } = byId[id].callFrame;
    const key = `${functionName || '(anonymous)'} ${url.split('/').at(-1)}:${lineNumber + 1}`;
    self[key] = (self[key] ?? 0) + profile.timeDeltas[i] / 1000;
  });
  const d = (k) => (after[k] - before[k]).toFixed(2);
  const lines = [
    `one page's main thread over ${wall.toFixed(1)} s: tasks ${d('TaskDuration')} s, script ${d('ScriptDuration')} s, ` +
      `layout ${d('LayoutDuration')} s, style ${d('RecalcStyleDuration')} s`,
    ...Object.entries(self).sort((a, b) => b[1] - a[1]).slice(0, 15).map(([k, ms]) => `  ${ms.toFixed(0)} ms ${k}`),
  ];
  await cdp.detach();
  return { result, lines };
}

function pageRows(label, pages, whole) {
  return pages.map((s, i) => {
    const errors = s.lipSyncErrorsMs;
    return `${label} ${i + 1}: whole ${whole(s) ? 'yes' : 'NO'}, onsets paired ${errors.length}, ` +
      `median ${fixed(percentile(errors, 0.5))} ms, |error| p95 ${fixed(percentile(errors.map(Math.abs), 0.95))} ms`;
  });
}

test(`${VIEWERS} viewers through Janus beside ${VIEWERS} pfap-web sessions`, { timeout: 3600e3 }, async () => {
  const browser = await launchChromium();
  const out = { viewers: VIEWERS };
  const lines = [`load average at the start: ${os.loadavg().map((l) => l.toFixed(1)).join(', ')}`];
  let janus = null;
  let pageServer = null;
  let server = null;
  try {
    // Janus: once with one viewer, once with N.
    janus = await startJanus();
    pageServer = await servePages();
    // Janus's CPU time over the whole (the viewers' sessions set up, the speech relayed) and
    // over the speech alone (the sender's run, in real time).
    const broadcast = async (count) => {
      const whole = await measured(janus.pid, async () => {
        const pages = await inBatches(count, 5, () => openViewer(browser, pageServer, janus, { timeout: LOAD_TIMEOUT_MS }));
        const sender = startSender(TEXT);
        const { result: speech, lines: profile } = await profiled(pages[0], () => measured(janus.pid, () => exited(sender)));
        lines.push(...profile);
        const all = await Promise.all(pages.map((p) => figures(p, { timeout: 120000 })));
        return { all, speech, sent: JSON.parse(sender.out.trim().split('\n').at(-1)) };
      });
      return { cpu: whole.cpu, wall: whole.wall, ...whole.result };
    };
    const one = await broadcast(1);
    const manyKinds = await chromiumCpu(() => broadcast(VIEWERS));
    const many = manyKinds.result;
    await stop(janus);
    janus.cleanup();
    out.janusLog = `${janus.out}${janus.log}`.slice(-20000);  // its warnings, for the figures file
    const whole = (sent) => (s) => s.phonemes === sent.phonemes && s.fapStateMatchesSender && s.streams === 1;
    out.janus = { one, many, chromium: manyKinds.byKind };
    const ms = (seconds) => `${(1000 * seconds).toFixed(1)} ms`;
    const janusPerViewer = (many.cpu - one.cpu) / (VIEWERS - 1);
    const relayPerViewer = (many.speech.cpu - one.speech.cpu) / (VIEWERS - 1);
    // pfap-web's pages never pair a stream's first onset (its audio starts with the speech, so
    // no measured silence comes before it); the Janus viewers hear silence before the sender
    // starts, and pair it. Both are printed: every onset, and all but the first.
    const summary = (label, pages, from) => {
      const e = pages.flatMap((s) => s.lipSyncErrorsMs.slice(from));
      const p95s = pages.map((s) => percentile(s.lipSyncErrorsMs.slice(from).map(Math.abs), 0.95));
      const within = p95s.filter((p) => p <= 20).length;
      return `${label}: ${e.length} onsets paired, min ${fixed(Math.min(...e))}, median ${fixed(percentile(e, 0.5))}, ` +
        `max ${fixed(Math.max(...e))} ms, |error| p95 ${fixed(percentile(e.map(Math.abs), 0.95))} ms, worst page's p95 ` +
        `${fixed(Math.max(...p95s))} ms, pages with p95 <= 20 ms: ${within} of ${pages.length}`;
    };
    // The Janus half's figures first: they stand even if the pfap-web half fails.
    lines.push(
      `the text: ${one.speech.wall.toFixed(1)} s of speech (the sender's run), ${one.sent.packets} PFAP packets; ` +
        `with ${VIEWERS} viewers the sender's run took ${many.speech.wall.toFixed(1)} s`,
      `Janus, 1 viewer: ${ms(one.cpu)} of CPU in all, ${ms(one.speech.cpu)} during the speech`,
      `Janus, ${VIEWERS} viewers: ${ms(many.cpu)} of CPU in all, ${ms(many.speech.cpu)} during the speech ` +
        `(${(100 * many.speech.cpu / many.speech.wall).toFixed(2)} % of a core)`,
      `Janus per added viewer: ${ms(janusPerViewer)} in all (session set up and the text relayed), ` +
        `${ms(relayPerViewer)} during the speech`,
      kindRow(`Janus, ${VIEWERS} viewers`, manyKinds),
      ...pageRows('Janus viewer', many.all, whole(many.sent)),
      summary('Janus, every onset', many.all, 0), summary('Janus, the first onset left out', many.all, 1),
    );

    // pfap-web: N sessions, each its own pipeline.
    server = run(process.env.PFAP_WEB, ['--port=0', `--web-dir=${webDir}`, `--text=${TEXT}`]);
    const url = await new Promise((resolve, reject) => {
      server.on('exit', (code) => reject(new Error(`pfap-web exited (${code}): ${server.log}`)));
      server.stdout.on('data', () => {
        const m = /open (http:\S+)/.exec(server.out);
        if (m) resolve(m[1]);
      });
    });
    const webKinds = await chromiumCpu(() => measured(server.pid, async () => {
      const pages = await inBatches(VIEWERS, 5, () => newPage(browser, url, { timeout: LOAD_TIMEOUT_MS }));
      return Promise.all(pages.map((p) => figures(p, { timeout: 120000 })));
    }));
    const web = webKinds.result;
    await stop(server);
    out.pfapWeb = { ...web, chromium: webKinds.byKind };

    const webPerViewer = web.cpu / VIEWERS;
    lines.push(
      `pfap-web, ${VIEWERS} sessions: ${ms(web.cpu)} of CPU in all, ${ms(webPerViewer)} per session (set up, the text spoken and sent)`,
      `pfap-web per session / Janus per added viewer: ${(webPerViewer / janusPerViewer).toFixed(1)}`,
      kindRow(`pfap-web, ${VIEWERS} pages`, webKinds),
      ...pageRows('pfap-web page', web.result, (s) => s.phonemes === s.sender.phonemes && s.fapStateMatchesSender),
    );
    lines.push(summary('pfap-web, every onset', web.result, 0),
      `load average at the end: ${os.loadavg().map((l) => l.toFixed(1)).join(', ')}`);
  } finally {
    await browser.close();
    // A run that failed half-way (a page's figures not in time) stops its servers too: their
    // pipes and the pages' server would keep node waiting for the harness's timeout.
    pageServer?.close();
    if (server) await stop(server);
    if (janus && janus.exitCode === null && janus.signalCode === null) {
      await stop(janus);
      janus.cleanup();
    }
    for (const line of lines) console.log(line);
    if (process.env.PFAP_BENCH_OUT) writeFileSync(process.env.PFAP_BENCH_OUT, JSON.stringify({ ...out, lines }));
  }
});
