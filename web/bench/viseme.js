// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme detector's speed in Node: a WAV file (default: 10 s of a seeded noisy chirp at
// 48 kHz, resampled as a page's AudioContext gives it) pushed in 128-sample blocks, as an
// AudioWorklet's render quanta. Prints the real-time factor (processor time over audio time),
// best of 3 runs. Run: node bench/viseme.js [FILE.wav] (docs/align.md, "A viseme detector");
// PFAP_VISEME_MODEL=FILE: another model than align/viseme_model.txt, to compare them.
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { VisemeDetector, parseVisemeModel } from '../src/index.js';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const modelFile = process.env.PFAP_VISEME_MODEL ?? path.join(root, 'align', 'viseme_model.txt');
const model = parseVisemeModel(readFileSync(modelFile, 'utf8'));

function audio() {
  const file = process.argv[2];
  if (file === undefined) {
    const rate = 48000;
    let seed = 30;
    const random = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648) - 0.5;
    return { rate, samples: Float32Array.from({ length: rate * 10 }, (_, i) => 0.3 * Math.sin(2 * Math.PI * (200 + (i % rate) / 40) * i / rate) + 0.05 * random()) };
  }
  const b = readFileSync(file);
  let at = 12;
  while (b.toString('latin1', at, at + 4) !== 'data') at += 8 + b.readUInt32LE(at + 4);
  const n = b.readUInt32LE(at + 4) / 2;
  return { rate: b.readUInt32LE(24), samples: Float32Array.from({ length: n }, (_, i) => b.readInt16LE(at + 8 + 2 * i) / 32768) };
}

const { rate, samples } = audio();
let best = Infinity;
let runs = 0;
for (let round = 0; round < 3; round++) {
  const start = process.cpuUsage();
  const detector = new VisemeDetector(rate, { model });
  runs = 0;
  for (let i = 0; i < samples.length; i += 128) runs += detector.push(samples.subarray(i, i + 128)).length;
  runs += detector.finish().length;
  const used = process.cpuUsage(start);
  best = Math.min(best, (used.user + used.system) / 1e6);
}
const seconds = samples.length / rate;
console.log(`${seconds.toFixed(1)} s at ${rate} Hz in 128-sample blocks: ${best.toFixed(3)} s of processor time, real-time factor ${(best / seconds).toFixed(4)} (${(100 * best / seconds).toFixed(2)} % of a core); ${runs} runs`);
