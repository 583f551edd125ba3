// SPDX-License-Identifier: LGPL-2.1-or-later
// examples/talking_head.js, the page's logic, run in Node: its packets decode into the hello
// session's phonemes at their times, and play() draws the face over two rounds (a new SSRC
// each) on @napi-rs/canvas with a fake clock.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { createCanvas } from '@napi-rs/canvas';

import { helloPackets, play } from '../examples/talking_head.js';
import { PfapReceiver } from '../src/index.js';

test('the hello packets give the session\'s phonemes at their times', () => {
  const receiver = new PfapReceiver();
  const events = helloPackets().flatMap((p) => receiver.receive(p.bytes));
  const phonemes = events.filter((e) => e.kind === 'phoneme');
  assert.deepEqual(phonemes.map((e) => e.phoneme.name), ['HH', 'AH', 'L', 'OW', 'D', 'EH', 'R', 'HH', 'AW', 'AA', 'R', 'Y', 'UW']);
  assert.deepEqual(phonemes.map((e) => e.timeNs / 1e6), [0, 60, 130, 190, 360, 410, 520, 1020, 1080, 1270, 1390, 1470, 1530]);
  assert.deepEqual(phonemes.filter((e) => e.sentenceStart).map((e) => e.timeNs / 1e6), [0, 1020]);
  assert.ok(events.every((e) => !e.uncertain), 'the complete state comes first');
  assert.equal(receiver.stats.malformedPayload + receiver.stats.malformedRtp + receiver.stats.lost, 0);
});

test('play() draws every frame of two rounds, the mouth moving', () => {
  const canvas = createCanvas(160, 120);
  let clock = 0;
  const frames = [];
  const pending = [];
  const receiver = play(canvas, { now: () => clock, requestFrame: (f) => pending.push(f), rounds: 2 });
  const mouth = () => canvas.getContext('2d').getImageData(70, 80, 20, 10).data.join(',');
  frames.push(mouth());
  // 25 frames a second for two rounds of 2.5 s, then the loop stops.
  while (pending.length > 0) {
    clock += 40;
    pending.shift()();
    frames.push(mouth());
  }
  // A call every 40 ms from 0 to 5 s: the one at 5 s ends the loop.
  assert.equal(frames.length, 126);
  assert.ok(new Set(frames).size > 10, `${new Set(frames).size} different mouths`);
  // The receiver saw the second round's packets as a new stream, all of them.
  assert.equal(receiver.stats.phonemes, 26);
  assert.equal(receiver.stats.completeStates, 2);
});
