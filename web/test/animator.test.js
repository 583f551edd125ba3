// Animator and face model against pfapface's (face::Animator, face::pose_from_faps): seeded
// phonemes (x-pfap-arpabet, unknown symbols, no alphabet), FAPs, recovered and complete states
// give the same FAP values and overlay text (poses: renderer.test.js).
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { Animator, findAlphabet } from '../src/index.js';
import { exportVectors } from './libpfap.js';

// Math.sin and friends may differ from glibc's in the last bit; everything else is exact.
const EPSILON = 1e-9;

function near(actual, expected, where) {
  assert.ok(Math.abs(actual - expected) <= EPSILON * Math.max(1, Math.abs(expected)), `${where}: ${actual}, C++ ${expected}`);
}

test('FAP values over time equal face::Animator\'s', () => {
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
