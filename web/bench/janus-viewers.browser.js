// SPDX-License-Identifier: LGPL-2.1-or-later
// Benchmark (figures printed, nothing timed asserted): N viewers of one talking head through
// Janus beside N sessions of pfap-web, in one run on this machine (docs/web.md, "Broadcast
// through Janus: measured"). N is PFAP_VIEWERS (20). For each side it prints the server's CPU
// time for one text said to every viewer (Janus's with 1 viewer and with N, in all and during
// the speech alone; pfap-web's with N sessions) and for each page whether it is whole and its
// lip-sync errors (median, 95th percentile of |error|, ms).
//
//   sudo PFAP_VIEWERS=20 PFAP_TIMEOUT=900 PFAP_BROADCAST=build/tools/pfap-broadcast \
//     PFAP_WEB=build/tools/pfap-web GST_PLUGIN_PATH=build/gst:build/ext \
//     tests/web/janus-broadcast.sh node web/bench/janus-viewers.browser.js
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

import {
  cpuSeconds, exited, figures, launchChromium, newPage, openViewer, run, servePages, startJanus, startSender, stop,
} from '../test/janus.js';

const webDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const VIEWERS = Number(process.env.PFAP_VIEWERS ?? 20);
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
  const result = await during();
  const wall = (performance.now() - t0) / 1000;
  clearInterval(poll);
  try { last = cpuSeconds(pid); } catch { /* ended */ }
  return { cpu: last - start, wall, result };
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
  const lines = [];
  try {
    // Janus: once with one viewer, once with N.
    const janus = await startJanus();
    const pageServer = await servePages();
    // Janus's CPU time over the whole (the viewers' sessions set up, the speech relayed) and
    // over the speech alone (the sender's run, in real time).
    const broadcast = async (count) => {
      const whole = await measured(janus.pid, async () => {
        const pages = await inBatches(count, 5, () => openViewer(browser, pageServer, janus));
        const sender = startSender(TEXT);
        const speech = await measured(janus.pid, () => exited(sender));
        const all = await Promise.all(pages.map((p) => figures(p, { timeout: 120000 })));
        return { all, speech, sent: JSON.parse(sender.out.trim().split('\n').at(-1)) };
      });
      return { cpu: whole.cpu, wall: whole.wall, ...whole.result };
    };
    const one = await broadcast(1);
    const many = await broadcast(VIEWERS);
    pageServer.close();
    await stop(janus);
    janus.cleanup();
    const whole = (sent) => (s) => s.phonemes === sent.phonemes && s.fapStateMatchesSender && s.streams === 1;
    out.janus = { one, many };

    // pfap-web: N sessions, each its own pipeline.
    const server = run(process.env.PFAP_WEB, ['--port=0', `--web-dir=${webDir}`, `--text=${TEXT}`]);
    const url = await new Promise((resolve, reject) => {
      server.on('exit', (code) => reject(new Error(`pfap-web exited (${code}): ${server.log}`)));
      server.stdout.on('data', () => {
        const m = /open (http:\S+)/.exec(server.out);
        if (m) resolve(m[1]);
      });
    });
    const web = await measured(server.pid, async () => {
      const pages = await inBatches(VIEWERS, 5, () => newPage(browser, url));
      return Promise.all(pages.map((p) => figures(p, { timeout: 120000 })));
    });
    await stop(server);
    out.pfapWeb = web;

    const ms = (seconds) => `${(1000 * seconds).toFixed(1)} ms`;
    const janusPerViewer = (many.cpu - one.cpu) / (VIEWERS - 1);
    const relayPerViewer = (many.speech.cpu - one.speech.cpu) / (VIEWERS - 1);
    const webPerViewer = web.cpu / VIEWERS;
    lines.push(
      `the text: ${one.speech.wall.toFixed(1)} s of speech (the sender's run), ${one.sent.packets} PFAP packets`,
      `Janus, 1 viewer: ${ms(one.cpu)} of CPU in all, ${ms(one.speech.cpu)} during the speech`,
      `Janus, ${VIEWERS} viewers: ${ms(many.cpu)} of CPU in all, ${ms(many.speech.cpu)} during the speech ` +
        `(${(100 * many.speech.cpu / many.speech.wall).toFixed(2)} % of a core)`,
      `Janus per added viewer: ${ms(janusPerViewer)} in all (session set up and the text relayed), ` +
        `${ms(relayPerViewer)} during the speech`,
      `pfap-web, ${VIEWERS} sessions: ${ms(web.cpu)} of CPU in all, ${ms(webPerViewer)} per session (set up, the text spoken and sent)`,
      `pfap-web per session / Janus per added viewer: ${(webPerViewer / janusPerViewer).toFixed(1)}`,
      ...pageRows('Janus viewer', many.all, whole(many.sent)),
      ...pageRows('pfap-web page', web.result, (s) => s.phonemes === s.sender.phonemes && s.fapStateMatchesSender),
    );
    // pfap-web's pages never pair a stream's first onset (its audio starts with the speech, so
    // no measured silence comes before it); the Janus viewers hear silence before the sender
    // starts, and pair it. Both are printed: every onset, and all but the first.
    const summary = (label, pages, from) => {
      const e = pages.flatMap((s) => s.lipSyncErrorsMs.slice(from));
      const worst = Math.max(...pages.map((s) => percentile(s.lipSyncErrorsMs.slice(from).map(Math.abs), 0.95)));
      return `${label}: ${e.length} onsets paired, min ${fixed(Math.min(...e))}, median ${fixed(percentile(e, 0.5))}, ` +
        `max ${fixed(Math.max(...e))} ms, |error| p95 ${fixed(percentile(e.map(Math.abs), 0.95))} ms, worst page's p95 ${fixed(worst)} ms`;
    };
    lines.push(summary('Janus, every onset', many.all, 0), summary('Janus, the first onset left out', many.all, 1),
      summary('pfap-web, every onset', web.result, 0));
  } finally {
    await browser.close();
    for (const line of lines) console.log(line);
    if (process.env.PFAP_BENCH_OUT) writeFileSync(process.env.PFAP_BENCH_OUT, JSON.stringify({ ...out, lines }));
  }
});
