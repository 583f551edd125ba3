// SPDX-License-Identifier: LGPL-2.1-or-later
// AnimationFrames: each frame draws the middle of its time on show, half the display's frame
// interval after its requestAnimationFrame time.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { AnimationFrames } from '../src/index.js';

const near = (actual, expected, where) => assert.ok(Math.abs(actual - expected) < 1e-9, `${where}: ${actual}, not ${expected}`);

test('a frame draws half a display frame after its time: 60 Hz before two frames have come, then the display\'s', () => {
  const frames = new AnimationFrames();
  near(frames.drawTime(1000), 1000 + 1000 / 120, 'the first frame');
  // A display at 144 Hz.
  const interval = 1000 / 144;
  for (let i = 1; i <= 10; ++i) near(frames.drawTime(1000 + i * interval), 1000 + (i + 0.5) * interval, `frame ${i}`);
  near(frames.intervalMs(), interval, 'the interval');
});

test('frames missed under load do not move the interval; a display that changes its rate does, once most frames have it', () => {
  const frames = new AnimationFrames();
  let t = 0;
  const step = (ms) => frames.drawTime((t += ms));
  for (let i = 0; i < 40; ++i) step(1000 / 60);
  // Late frames, two and three display frames apart, a few among many.
  for (let i = 0; i < 5; ++i) {
    near(step(1000 / 30), t + 1000 / 120, `a late frame ${i}`);
    step(1000 / 60);
    step(1000 / 60);
  }
  near(step(50), t + 1000 / 120, 'a frame three display frames late');
  // The page moved to a 120 Hz display: after half of the kept intervals, the new one.
  for (let i = 0; i < 16; ++i) step(1000 / 120);
  near(frames.intervalMs(), 1000 / 120, 'the interval at 120 Hz');
});

test('a frame at the same time as the last, or earlier, leaves the interval as it was', () => {
  const frames = new AnimationFrames();
  frames.drawTime(0);
  frames.drawTime(20);
  near(frames.drawTime(20), 30, 'the same time');
  near(frames.drawTime(10), 20, 'an earlier time');
  near(frames.intervalMs(), 20, 'the interval');
});
