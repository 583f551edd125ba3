// SPDX-License-Identifier: LGPL-2.1-or-later
// FapState against pfap::FapState: after seeded bookmarks on the same FAPs (transitions
// interrupting each other, at the same time, of every curve), amplitudes at and around the
// times where curves change are equal to the last bit, as are settled values, at-rest and
// recovery entries.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { FapState } from '../src/index.js';
import { exportVectors } from './libpfap.js';

test('amplitudes, settled values and recovery entries equal libpfap\'s', () => {
  const runs = exportVectors(['curves']);
  assert.equal(runs.length, 200);
  let samples = 0;
  let fractional = 0;
  for (const run of runs) {
    const state = new FapState();
    for (const step of run) {
      state.apply(step.apply, step.startNs);
      for (const s of step.samples) {
        const where = `FAP ${s.index} at ${s.timeNs} after ${JSON.stringify(step.apply)} at ${step.startNs}`;
        const amplitude = state.amplitude(s.index, s.timeNs);
        // === rather than Object.is: C++ writes no sign of a zero.
        assert.ok(amplitude === s.amplitude, `${where}: ${amplitude}, libpfap ${s.amplitude}`);
        assert.equal(state.settled(s.index), s.settled, where);
        assert.equal(state.atRest(s.index, s.timeNs), s.atRest, where);
        assert.deepStrictEqual(state.recoveryEntry(s.index, Math.max(s.timeNs, step.startNs)), s.recoveryEntry, where);
        ++samples;
        fractional += Number.isInteger(amplitude) ? 0 : 1;
      }
    }
  }
  assert.equal(samples, 200 * 40 * 11 * 3);
  // Mid-transition values are compared, not only whole ones.
  assert.ok(fractional > samples / 10, `${fractional} fractional amplitudes`);
});

test('the starting amplitude is rounded halves away from zero', () => {
  const state = new FapState();
  state.apply({ index: 3, amplitude: -5, transition: 10, curve: 1 }, 0);
  // At 5 ms, halfway: -2.5, which rounds to -3 (std::lround), not -2 (Math.round).
  state.apply({ index: 3, amplitude: 100, transition: 0, curve: 2 }, 5_000_000);
  assert.equal(state.amplitude(3, 5_000_000 - 1), -3);
  assert.equal(state.settled(3), -5);
});
