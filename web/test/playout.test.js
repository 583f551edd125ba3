// SPDX-License-Identifier: LGPL-2.1-or-later
// The pages' clock (web/live/playout.js) without a browser: the tap's level of what is heard
// put in `envelope` by hand, the synchronization source's readings given, matchHeard() called
// as each tap message would. A clock that the audio has left by more than its search (NetEq's
// concealment under load) finds it again.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { PlayoutClock } from '../live/playout.js';

// "pa. pa. pa.": a sharp onset every 337 ms, a vowel that decays, silence between (S16 RMS).
const level = (ms) => {
  const k = ((ms % 337) + 337) % 337;
  return k < 120 ? Math.round(8000 * Math.exp(-k / 60) * (1 + 0.3 * Math.sin(k / 3))) : 0;
};

// Hears running time t - delay(t) at each ms t of [fromMs, toMs) (performance time = running
// time here, less the delay), calling matchHeard every 10 ms as the tap's messages do.
function hear(clock, fromMs, toMs, delay) {
  for (let t = fromMs; t < toMs; ++t) {
    clock.envelope.push({ t, rms: level(t - delay(t)) / 32768 });
    if (t % 10 === 9) clock.matchHeard();
  }
}

function sending(clock, ms) {
  clock.sent.add(0, Array.from({ length: ms }, (_, i) => level(i)));
}

test('the clock matches the level, and finds it again in one match after the audio moved by 120 ms', () => {
  // (With the search of ±50 ms it had before, it crept there by matches of up to 50 ms, and
  // in pages under load did not get there at all: docs/web.md, Lost clocks.)
  const clock = new PlayoutClock({ envelope: [] });
  sending(clock, 8000);
  // The readings put the audio 30 ms off; the level corrects it.
  clock.reading(0, 30);
  hear(clock, 0, 2000, () => 0);
  assert.ok(Math.abs(clock.runningMs(1900) - 1900) < 2, `${clock.runningMs(1900)}`);
  // Concealment: from 2 s on the audio is heard 120 ms later, which no stretch count says.
  hear(clock, 2000, 5000, () => 120);
  assert.ok(Math.abs(clock.runningMs(4900) - (4900 - 120)) < 2, `${clock.runningMs(4900)}`);
  assert.ok(clock.corrections.some((c) => Math.abs(c.lag + 120) < 2), JSON.stringify(clock.corrections.slice(-5)));
});

test('silence does not count as lost: no match, no wider search', () => {
  const clock = new PlayoutClock({ envelope: [] });
  sending(clock, 8000);
  clock.reading(0, 0);
  hear(clock, 0, 1000, () => 0);
  for (let t = 1000; t < 2000; ++t) {
    clock.envelope.push({ t, rms: 0 });
    if (t % 10 === 9) clock.matchHeard();
  }
  assert.equal(clock.misses, 0);
});
