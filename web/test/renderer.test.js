// SPDX-License-Identifier: LGPL-2.1-or-later
// The canvas renderer against pfapface's cairo renderer: for face states (neutral, the 14
// visemes, the 6 expressions, head turned, tilted and nodding, eyes, brows, cheeks, jaw), the
// poses are equal and the frames drawn by renderFace on @napi-rs/canvas (Skia) match
// pfap::face::render's (cairo) in both styles, 320x240, within this tolerance:
//   - mean absolute difference over all pixels and channels at most MEAN_TOLERANCE levels;
//   - at most FAR_SHARE of the pixels differ by more than FAR_LEVELS in some channel.
// The two libraries anti-alias edges differently, so edge pixels differ by a few levels and
// a few dozen by more. A feature that is not where pfapface draws it makes more pixels far:
// a test below shows that the bounds refuse the neighbouring states (lips pressed instead of
// closed, eyes shut or turned, another viseme).
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { after, test } from 'node:test';

import { addExpressions, poseFromFaps, renderFace } from '../src/index.js';
import { exportVectors } from './libpfap.js';

const MEAN_TOLERANCE = 1.0;
const FAR_LEVELS = 64;
const FAR_SHARE = 0.0005;
const WIDTH = 320;
const HEIGHT = 240;

let createCanvas;
try {
  ({ createCanvas } = await import('@napi-rs/canvas'));
} catch (e) {
  throw new Error(`@napi-rs/canvas is missing (${e.message}): run scripts/web-deps`);
}

const dir = mkdtempSync(path.join(tmpdir(), 'pfap-render-'));
after(() => rmSync(dir, { recursive: true, force: true }));
const states = exportVectors(['render', dir]);

function flat(points) {
  return points.flatMap((p) => [p.x, p.y]);
}

// How far a JS frame (RGBA) is from a cairo frame (BGRx).
function compare(rgba, bgrx) {
  let sum = 0;
  let far = 0;
  for (let i = 0; i < WIDTH * HEIGHT; ++i) {
    const d = [
      Math.abs(rgba[4 * i] - bgrx[4 * i + 2]),
      Math.abs(rgba[4 * i + 1] - bgrx[4 * i + 1]),
      Math.abs(rgba[4 * i + 2] - bgrx[4 * i]),
    ];
    sum += d[0] + d[1] + d[2];
    if (Math.max(...d) > FAR_LEVELS) ++far;
  }
  return { mean: sum / (3 * WIDTH * HEIGHT), farShare: far / (WIDTH * HEIGHT) };
}

function draw(pose, style) {
  const canvas = createCanvas(WIDTH, HEIGHT);
  const ctx = canvas.getContext('2d');
  renderFace(ctx, pose, { style });
  return ctx.getImageData(0, 0, WIDTH, HEIGHT).data;
}

function poseOf(faps) {
  const f = Float64Array.from(faps);
  addExpressions(f);
  return poseFromFaps(f);
}

test('poses equal pfap::face::pose_from_faps\'s', () => {
  assert.equal(states.length, 29);
  for (const state of states) {
    const pose = poseOf(state.faps);
    const actual = {
      roll: pose.roll,
      outline: flat(pose.outline),
      outerLips: flat(pose.outerLips),
      innerLips: flat(pose.innerLips),
      eyes: pose.eyes.flatMap((e) => [e.center.x, e.center.y, e.halfWidth, e.upperLid, e.lowerLid, e.pupil.x, e.pupil.y]),
    };
    for (const [key, expected] of Object.entries(state.pose)) {
      const values = Array.isArray(expected) ? expected : [expected];
      const got = Array.isArray(actual[key]) ? actual[key] : [actual[key]];
      values.forEach((v, i) => assert.ok(Math.abs(got[i] - v) < 1e-12, `${state.name} ${key}[${i}]: ${got[i]}, C++ ${v}`));
    }
  }
});

for (const style of ['cartoon', 'line']) {
  test(`${style} frames match pfapface's within the tolerance`, () => {
    const report = [];
    for (const state of states) {
      const cairo = readFileSync(path.join(dir, `${state.name}-${style}.bgrx`));
      const { mean, farShare } = compare(draw(poseOf(state.faps), style), cairo);
      report.push(`${state.name} ${mean.toFixed(2)} ${(100 * farShare).toFixed(3)}%`);
      assert.ok(mean <= MEAN_TOLERANCE && farShare <= FAR_SHARE, `${state.name}: mean ${mean}, ${100 * farShare} % far`);
    }
    console.log(`# ${style}: ${report.join(', ')}`);
  });
}

test('the bounds refuse a face in a neighbouring state', () => {
  const faps = (name) => states.find((s) => s.name === name).faps;
  // Each pair: the state drawn in JS, the state pfapface drew. viseme1 presses the lips by
  // 30 units (under a pixel at this size), gaze turns the eyes, blink shuts them.
  for (const [drawn, drewCairo] of [['neutral', 'viseme1'], ['neutral', 'blink'], ['neutral', 'gaze'], ['viseme4', 'viseme8'], ['viseme10', 'viseme13']]) {
    for (const style of ['cartoon', 'line']) {
      const cairo = readFileSync(path.join(dir, `${drewCairo}-${style}.bgrx`));
      const { mean, farShare } = compare(draw(poseOf(faps(drawn)), style), cairo);
      assert.ok(mean > MEAN_TOLERANCE || farShare > FAR_SHARE, `${drawn} passes for ${drewCairo} (${style}): mean ${mean}, ${farShare} far`);
    }
  }
});
