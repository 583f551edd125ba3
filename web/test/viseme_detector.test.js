// SPDX-License-Identifier: LGPL-2.1-or-later
// The viseme detector in JavaScript (src/viseme_detector.js) against the C++ one
// (align/viseme_detector.h, through tools/pfap-viseme-data trace): on espeak-ng's speech at
// 22050 Hz and the same at 48 kHz and 16 kHz, in 20 ms blocks, every frame's probabilities
// within float tolerance and the same runs. Needs PFAP_VISEME_DATA (tests/web/meson.build).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';

import { OCULUS_VISEMES, VISEME_LOOKAHEAD_MS, VisemeDetector, parseVisemeModel } from '../src/index.js';
import { readWav, writeWav } from './wav.js';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const tool = process.env.PFAP_VISEME_DATA;
const model = parseVisemeModel(readFileSync(path.join(root, 'align', 'viseme_model.txt'), 'utf8'));
// Float32 weights, float in C++ and double here: the probabilities differ in the 6th digit.
const TOLERANCE = 1e-4;

function detect({ rate, samples }, withModel = model) {
  const trace = [];
  const detector = new VisemeDetector(rate, { model: withModel, trace });
  const runs = [];
  const block = Math.floor(rate / 50);
  const floats = Float32Array.from(samples, (s) => s / 32768);
  for (let i = 0; i < floats.length; i += block) runs.push(...detector.push(floats.subarray(i, i + block)));
  runs.push(...detector.finish());
  return { trace, runs: runs.map((r) => [r.start, r.frames, r.viseme]) };
}

test('the JavaScript detector gives the C++ one\'s visemes on the same audio', { skip: tool === undefined && 'PFAP_VISEME_DATA not set' }, () => {
  const dir = mkdtempSync(path.join(tmpdir(), 'pfap-viseme-'));
  try {
    execFileSync(tool, ['speak', 'en-us+f2', '165', '55', dir, 's'], {
      input: 'The birch canoe slid on the smooth planks. Glue the sheet to the dark blue background.\n',
    });
    const spoken = readWav(path.join(dir, 's-001.wav'));
    // The same at 48 kHz and 16 kHz (linear interpolation: any audio will do here), clipped
    // 12 dB louder at 48 kHz.
    const at = (rate, gain) => Int16Array.from({ length: Math.floor((spoken.samples.length * rate) / spoken.rate) }, (_, i) => {
      const x = (i * spoken.rate) / rate;
      const k = Math.floor(x);
      const y = spoken.samples[k] + (x - k) * ((spoken.samples[k + 1] ?? 0) - spoken.samples[k]);
      return Math.max(-32768, Math.min(32767, Math.round(y * gain)));
    });
    writeWav(path.join(dir, 'r48.wav'), 48000, at(48000, 4));
    writeWav(path.join(dir, 'r16.wav'), 16000, at(16000, 1));
    for (const name of ['s-001', 'r48', 'r16']) {
      const wav = path.join(dir, `${name}.wav`);
      execFileSync(tool, ['trace', wav, path.join(dir, `${name}.json`)]);
      const cpp = JSON.parse(readFileSync(path.join(dir, `${name}.json`), 'utf8'));
      const js = detect(readWav(wav));
      assert.equal(js.trace.length, cpp.probabilities.length, `${name}: frames`);
      let worst = 0;
      js.trace.forEach((p, i) => { worst = Math.max(worst, Math.abs(p - cpp.probabilities[i])); });
      assert.ok(worst <= TOLERANCE, `${name}: probabilities differ by ${worst}`);
      assert.deepEqual(js.runs, cpp.runs, `${name}: runs`);
      assert.ok(new Set(js.runs.map((r) => r[2])).size >= 6, `${name}: only ${js.runs.length} runs`);
    }
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

// align/viseme_model.txt with `extra` more frames of past whose weights are 0: the same
// network, if the context is fed oldest first as the file says.
function withMorePast(text, extra) {
  const n = text.replace(/\/\/[^\n]*/g, '').split(',').map((s) => s.trim()).filter((s) => s !== '');
  const [past, hidden1] = [Number(n[2]), Number(n[4])];
  const inputs = (past + 1 + 4) * 13;
  const layer1 = 7 + 26 + 12;
  n[2] = String(past + extra);
  for (let r = hidden1 - 1; r >= 0; r--) n.splice(layer1 + r * inputs, 0, ...new Array(extra * 13).fill('0'));
  return n.join(',\n');
}

test('a model\'s own past context, in C++ and JavaScript alike', { skip: tool === undefined && 'PFAP_VISEME_DATA not set' }, () => {
  const dir = mkdtempSync(path.join(tmpdir(), 'pfap-viseme-'));
  try {
    execFileSync(tool, ['speak', 'en-us+f2', '165', '55', dir, 's'], { input: 'Glue the sheet to the dark blue background.\n' });
    const file = path.join(dir, 'longer.txt');
    writeFileSync(file, withMorePast(readFileSync(path.join(root, 'align', 'viseme_model.txt'), 'utf8'), 16));
    const longer = parseVisemeModel(readFileSync(file, 'utf8'));
    assert.equal(longer.past, model.past + 16);
    const wav = path.join(dir, 's-001.wav');
    execFileSync(tool, ['trace', wav, path.join(dir, 's.json')], { env: { ...process.env, PFAP_VISEME_MODEL: file } });
    const cpp = JSON.parse(readFileSync(path.join(dir, 's.json'), 'utf8'));
    const js = detect(readWav(wav), longer);
    assert.deepEqual(js.trace, detect(readWav(wav)).trace);  // the same network
    assert.equal(js.trace.length, cpp.probabilities.length);
    js.trace.forEach((p, i) => assert.ok(Math.abs(p - cpp.probabilities[i]) <= TOLERANCE, `frame ${Math.floor(i / 15)}`));
    assert.deepEqual(js.runs, cpp.runs);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

test('the model file is checked, and the detector declares at most 60 ms ahead', () => {
  assert.ok(VISEME_LOOKAHEAD_MS <= 60);
  assert.equal(OCULUS_VISEMES.length, 15);
  assert.throws(() => parseVisemeModel('2, 13, 8, 4, 2, 2, 15'), /not a viseme model/);
  // A kind-1 model (before the cepstral mean) is refused.
  const kind1 = `1, 13, 8, 4, 2, 2, 15, ${new Array(26 + 12 + 2 * 170 + 2 * 3 + 15 * 3).fill(0).join(', ')}`;
  assert.throws(() => parseVisemeModel(kind1), /not a viseme model/);
  assert.doesNotThrow(() => parseVisemeModel(kind1.replace(/^1/, '2')));
  assert.throws(() => parseVisemeModel('// nothing'), /not a viseme model/);
  // The past context is the file's, whole frames up to 100; the frames ahead are fixed.
  for (const past of [0, 24, 8.5, 101, -1]) {
    const layers = 2 * ((Math.max(past, 0) + 5) * 13 + 1) + 2 * 3 + 15 * 3;
    const text = `2, 13, ${past}, 4, 2, 2, 15, ${new Array(26 + 12 + layers).fill(0).join(', ')}`;
    if (Number.isInteger(past) && past >= 0 && past <= 100) assert.equal(parseVisemeModel(text).past, past);
    else assert.throws(() => parseVisemeModel(text), /not a viseme model/);
  }
  assert.throws(() => new VisemeDetector(16000), /needs a model/);
  // Silence: one pause run covering every frame, at any rate.
  for (const rate of [8000, 44100]) {
    const detector = new VisemeDetector(rate, { model });
    const runs = [...detector.push(new Float32Array(rate)), ...detector.finish()];
    assert.deepEqual(runs, [{ start: 0, frames: 100, viseme: 0 }]);
  }
});
