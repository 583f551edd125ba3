// SPDX-License-Identifier: LGPL-2.1-or-later
// Benchmark (figures printed, nothing timed asserted): the viseme detector's AudioWorklet
// (src/viseme_worklet.js, the example's) in Debian's Chromium, headless (docs/align.md, "In
// Chromium"). A known recording, the five LibriVox readings of pocketsphinx-testdata (24.7 s
// at 16 kHz; without them, espeak-ng's Harvard sentences made now by PFAP_VISEME_DATA speak),
// is played through the detector in AudioContexts at 16 and 48 kHz, in real time: the time
// spent in process() per 128-frame quantum (viseme_worklet_timed.js), the real-time factor,
// and the context's underruns (AudioContext.playbackStats: quanta the output missed). Then
// the same rendered as fast as it goes in an OfflineAudioContext, beside a worklet that only
// copies its input: the wall time, best of 3.
//
//   scripts/bench viseme-worklet
// or, as root (a network namespace with only lo):
//   PFAP_VISEME_DATA=build/tools/pfap-viseme-data tests/web/pfap-web-browser.sh node \
//     web/bench/viseme-worklet.browser.js
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { test } from 'node:test';

import { launchChromium, newPage } from '../test/janus.js';
import { serveSourceRoot } from '../test/viseme_browser.js';
import { readWav } from '../test/wav.js';

const LIBRIVOX = '/usr/share/pocketsphinx/test/data/librivox';
const HARVARD = 'The birch canoe slid on the smooth planks. Glue the sheet to the dark blue background. ' +
  'It is easy to tell the depth of a well. These days a chicken leg is a rare dish.';

// The recording, 16-bit mono, and what it is.
function recording() {
  if (existsSync(LIBRIVOX)) {
    const names = readFileSync(path.join(LIBRIVOX, 'fileids'), 'utf8').split('\n').filter(Boolean);
    const wavs = names.map((n) => readWav(path.join(LIBRIVOX, `${path.basename(n)}.wav`)));
    const samples = new Int16Array(wavs.reduce((n, w) => n + w.samples.length, 0));
    wavs.reduce((at, w) => (samples.set(w.samples, at), at + w.samples.length), 0);
    return { rate: wavs[0].rate, samples, what: `LibriVox, pocketsphinx-testdata's ${wavs.length} readings` };
  }
  const dir = mkdtempSync(path.join(tmpdir(), 'pfap-viseme-bench-'));
  try {
    execFileSync(process.env.PFAP_VISEME_DATA, ['speak', 'en-us+f2', '165', '55', dir, 's'], { input: `${HARVARD}\n` });
    return { ...readWav(path.join(dir, 's-001.wav')), what: 'espeak-ng en-us+f2, four Harvard sentences' };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

// Set up in the page (window.bench): the recording, the model, and play(context, name,
// seconds), which plays the recording's first `seconds` through the timed worklet `name` and
// resolves to the worklet's figures and its count of viseme messages once they have gone
// through.
async function setUp({ pcm64, rate }) {
  const bytes = Uint8Array.from(atob(pcm64), (c) => c.charCodeAt(0));
  const pcm = new Int16Array(bytes.buffer);
  const modelText = await (await fetch('/align/viseme_model.txt')).text();
  const module = '/web/bench/viseme_worklet_timed.js';
  const play = (context, name, seconds = Infinity) => {
    const frames = Math.min(pcm.length, Math.round(seconds * rate));
    const buffer = context.createBuffer(1, frames, rate);
    buffer.getChannelData(0).set(Float32Array.from(pcm.subarray(0, frames), (s) => s / 32768));
    const source = new AudioBufferSourceNode(context, { buffer });
    const node = new AudioWorkletNode(context, name, { processorOptions: { modelText } });
    source.connect(node).connect(context.destination);
    source.start();
    let visemes = 0;
    return new Promise((resolve) => {
      node.port.onmessage = ({ data }) => {
        if (data.type === 'viseme') visemes += 1;
        if (data.type === 'stats') resolve({ ...data, visemes });
      };
    });
  };
  // The recording rendered as fast as it goes through `name`: wall time and the figures.
  const offline = async (contextRate, name) => {
    const length = Math.ceil((pcm.length * contextRate) / rate) + 1024;
    const c = new OfflineAudioContext({ numberOfChannels: 1, length, sampleRate: contextRate });
    await c.audioWorklet.addModule(module);
    const done = play(c, name);
    const t0 = performance.now();
    await c.startRendering();
    return { seconds: (performance.now() - t0) / 1000, ...(await done) };
  };
  window.bench = { pcm, rate, module, play, offline };
}

// The real-time context at `contextRate`, its worklet module added (so that its audio thread
// runs), as window.context.
async function openContext(contextRate) {
  const context = new AudioContext({ sampleRate: contextRate, latencyHint: 'interactive' });
  await context.audioWorklet.addModule(window.bench.module);
  await context.resume();
  window.context = context;
  return { baseLatency: context.baseLatency, outputLatency: context.outputLatency };
}

// Plays through `name` in window.context (the first `seconds` of the recording, null: all of
// it); the worklet's figures, and the audio clock's advance beside the wall clock's.
async function playRealTime({ name, seconds }) {
  const context = window.context;
  window.underrunsBefore = context.playbackStats?.toJSON();
  const wall0 = performance.now();
  const clock0 = context.currentTime;
  const figures = await window.bench.play(context, name, seconds ?? Infinity);
  return { ...figures, wall: (performance.now() - wall0) / 1000, clock: context.currentTime - clock0 };
}

// The underruns since playRealTime began, once playbackStats have caught up (about once a
// second), or null where Chromium has no playbackStats.
async function underrunsSince() {
  await new Promise((r) => setTimeout(r, 1100));
  const before = window.underrunsBefore;
  const after = window.context.playbackStats?.toJSON();
  return before && after ? { events: after.underrunEvents - before.underrunEvents, seconds: after.underrunDuration - before.underrunDuration } : null;
}

// The processor time (ns, from /proc/PID/task/TID/schedstat) of each of Chromium's real-time
// AudioWorklet threads ("Realtime AudioW"orkletThread, in the renderer), by thread.
function audioThreadTimes() {
  const times = new Map();
  for (const pid of readdirSync('/proc').filter((p) => /^\d+$/.test(p))) {
    let tids;
    try { tids = readdirSync(`/proc/${pid}/task`); } catch { continue; }
    for (const tid of tids) {
      try {
        if (!readFileSync(`/proc/${pid}/task/${tid}/comm`, 'utf8').startsWith('Realtime AudioW')) continue;
        times.set(`${pid}/${tid}`, Number(readFileSync(`/proc/${pid}/task/${tid}/schedstat`, 'utf8').split(' ')[0]));
      } catch { /* gone */ }
    }
  }
  return times;
}

// The processor time (s) the real-time audio threads used while `during` ran; and its result.
async function audioThreadSeconds(during) {
  const before = audioThreadTimes();
  const result = await during();
  let ns = 0;
  for (const [thread, t] of audioThreadTimes()) ns += t - (before.get(thread) ?? 0);
  return { cpu: ns / 1e9, result };
}

const fixed = (v, digits) => v.toFixed(digits);

test('the viseme detector\'s AudioWorklet in Chromium: time per quantum, real-time factor, underruns', { timeout: 140000 }, async () => {
  const audio = recording();
  const seconds = audio.samples.length / audio.rate;
  const server = await serveSourceRoot();
  const browser = await launchChromium();
  try {
    const page = await newPage(browser, `${server.url}/web/examples/viseme-detector.html`);
    const pcm64 = Buffer.from(audio.samples.buffer, audio.samples.byteOffset, audio.samples.byteLength).toString('base64');
    await page.evaluate(setUp, { pcm64, rate: audio.rate });
    console.log(`Chromium ${browser.version()}, headless; ${audio.what}: ${fixed(seconds, 1)} s at ${audio.rate} Hz`);
    console.log('| context | quanta | process() a quantum by Date.now(): mean, longest (ms) | real-time audio thread, ' +
      'processor time a second: copy, detector | detector\'s real-time factor (the difference) | underruns while the ' +
      'detector played (events, ms) | audio clock / wall clock (s) | visemes a second | offline, best of 3: copy, ' +
      'detector (s) | offline real-time factor (detector less copy) |');
    console.log('|---|---|---|---|---|---|---|---|---|---|');
    for (const contextRate of [16000, 48000]) {
      const { outputLatency } = await page.evaluate(openContext, contextRate);
      const copy = await audioThreadSeconds(() => page.evaluate(playRealTime, { name: 'pfap-bench-copy', seconds: 5 }));
      await page.evaluate(underrunsSince);
      const detector = await audioThreadSeconds(() => page.evaluate(playRealTime, { name: 'pfap-bench-viseme-detector', seconds: null }));
      const missed = await page.evaluate(underrunsSince);
      await page.evaluate(() => window.context.close());
      const offline = { copy: Infinity, detector: Infinity };
      for (let round = 0; round < 3; round++) {
        offline.copy = Math.min(offline.copy, (await page.evaluate(([r, n]) => window.bench.offline(r, n), [contextRate, 'pfap-bench-copy'])).seconds);
        offline.detector = Math.min(offline.detector, (await page.evaluate(([r, n]) => window.bench.offline(r, n), [contextRate, 'pfap-bench-viseme-detector'])).seconds);
      }
      const r = detector.result;
      const quantumMs = (128 / contextRate) * 1000;
      const share = (m) => m.cpu / m.result.wall;
      console.log(`| ${contextRate / 1000} kHz (output latency ${fixed(outputLatency * 1000, 0)} ms) | ${r.quanta} | ` +
        `${fixed(r.busyMs / r.quanta, 3)}, ${r.slowestMs} (a quantum: ${fixed(quantumMs, 3)}) | ` +
        `${fixed(100 * share(copy), 2)} %, ${fixed(100 * share(detector), 2)} % | ${fixed(share(detector) - share(copy), 4)} | ` +
        `${missed ? `${missed.events}, ${fixed(missed.seconds * 1000, 1)}` : 'not exposed'} | ${fixed(r.clock, 2)} / ${fixed(r.wall, 2)} | ` +
        `${fixed(r.visemes / seconds, 1)} | ${fixed(offline.copy, 3)}, ${fixed(offline.detector, 3)} | ` +
        `${fixed((offline.detector - offline.copy) / seconds, 4)} |`);
    }
    await page.close();
  } finally {
    await browser.close();
    await server.stop();
  }
});
