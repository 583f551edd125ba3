// SPDX-License-Identifier: LGPL-2.1-or-later
// Animator and face model against pfapface's (pfap::face::Animator,
// pfap::face::pose_from_faps): seeded phonemes (x-pfap-arpabet, unknown symbols, no alphabet),
// FAPs, recovered and complete states give the same FAP values and overlay text (poses:
// renderer.test.js); the phoneme table is libpfap's.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { Animator, findAlphabet, findPhoneme, findSymbol } from '../src/index.js';
import { exportVectors } from './libpfap.js';

// Math.sin and friends may differ from glibc's in the last bit; everything else is exact.
const EPSILON = 1e-9;

function near(actual, expected, where) {
  assert.ok(Math.abs(actual - expected) <= EPSILON * Math.max(1, Math.abs(expected)), `${where}: ${actual}, C++ ${expected}`);
}

test('FAP values over time equal pfap::face::Animator\'s', () => {
  const runs = exportVectors(['animator']);
  assert.equal(runs.length, 20);
  let unknown = 0;
  for (const [r, run] of runs.entries()) {
    const animator = new Animator(run.alphabet === null ? null : findAlphabet(run.alphabet));
    for (const [s, step] of run.steps.entries()) {
      const known = animator.apply({ kind: step.kind, phoneme: { symbol: step.symbol, duration: step.duration }, faps: step.faps }, step.timeNs);
      assert.equal(known, step.known, `run ${r} step ${s}`);
      unknown += known ? 0 : 1;
      assert.equal(animator.endNs, step.endNs);
      for (const sample of step.samples) {
        const faps = animator.faps(sample.timeNs);
        sample.faps.forEach((v, i) => near(faps[i], v, `run ${r} step ${s} at ${sample.timeNs} FAP ${i}`));
        assert.equal(animator.describe(sample.timeNs), sample.describe);
      }
    }
  }
  assert.ok(unknown > 0, 'no phoneme without a viseme');
});

test('x-pfap-arpabet names and visemes equal libpfap\'s, symbol by symbol', () => {
  const table = exportVectors(['alphabet']);
  const alphabet = findAlphabet('x-pfap-arpabet');
  assert.equal(table.length, 256);
  table.forEach((expected, symbol) => {
    assert.deepStrictEqual(findPhoneme(alphabet, symbol), expected, `symbol ${symbol}`);
    if (expected !== null) assert.equal(findSymbol(alphabet, expected.name), symbol);
  });
  assert.equal(table.filter((p) => p !== null).length, 40);
  assert.equal(findAlphabet('x-unknown'), null);
});
