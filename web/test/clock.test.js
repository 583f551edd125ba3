// SPDX-License-Identifier: LGPL-2.1-or-later
// The page's audio clock (web/live/clock.js): the played audio's level found in the level the
// server sent, at a lag known to the test; nothing found where nothing tells.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { LEVEL_MESSAGE_TYPE, SentLevel, decodeLevelMessage, decodeLevels, matchLevels } from '../live/clock.js';

// "pa. pa. pa.": a sharp onset every 337 ms, a vowel that decays, silence between (S16 RMS).
function speech(ms) {
  return Array.from({ length: ms }, (_, i) => {
    const k = i % 337;
    return k < 120 ? Math.round(8000 * Math.exp(-k / 60) * (1 + 0.3 * Math.sin(k / 3))) : 0;
  });
}

// What the page heard of `levels` sent from running time `startMs`: the window [fromMs,
// toMs) of running time, each block put by a clock that is `lagMs` behind (x + lag is the
// running time it was sent at), its level scaled and slightly noisy, as Opus leaves it.
function heardOf(levels, startMs, fromMs, toMs, lagMs) {
  const sent = new SentLevel();
  sent.add(startMs * 1e6, levels);
  const heard = [];
  for (let x = fromMs; x < toMs; ++x) {
    heard.push({ x: x - lagMs, rms: (sent.at(x) / 32768) * (1 + 0.02 * Math.sin(x * 7.1)) });
  }
  return heard;
}

test('SentLevel: the level at a running time, interpolated, 0 where nothing was sent', () => {
  const sent = new SentLevel();
  sent.add(10e6, [100, 200, 300]);
  sent.add(20e6, [50]);
  assert.equal(sent.at(10), 100);
  assert.equal(sent.at(11.5), 250);
  assert.equal(sent.at(12.5), 150);  // toward the 0 after the last block
  assert.equal(sent.at(9.9), 0);
  assert.equal(sent.at(13), 0);
  assert.equal(sent.at(20), 50);
});

test('SentLevel: the last ms of a message leads to the next one where it follows right after', () => {
  const sent = new SentLevel();
  sent.add(30333333, [100, 200]);
  sent.add(32333333, [400, 500]);  // 30.333333 + 2 is 32.333332999999996 in doubles
  sent.add(35000000, [800]);  // a message lost before it
  const near = (a, b) => assert.ok(Math.abs(a - b) < 1e-6, `${a} against ${b}`);
  near(sent.at(31.833333), 300);  // not 100, toward 0
  near(sent.at(33.833333), 250);  // a gap after: toward 0
  near(sent.at(35.5), 400);  // nothing after: toward 0
  const lags = new Float64Array(4);
  sent.sampleLags(31.833333, 0, 4, lags);
  [300, 450, 250, 0].forEach((v, j) => near(lags[j], v));
});

test('SentLevel keeps the last 30 s', () => {
  const sent = new SentLevel();
  sent.add(0, [1]);
  sent.add(31000e6, [2]);
  assert.equal(sent.at(0), 0);
  assert.equal(sent.at(31000), 2);
});

test('SentLevel.firstAtLeast: the first ms of any message at a level, null before any', () => {
  const sent = new SentLevel();
  assert.equal(sent.firstAtLeast(100), null);
  sent.add(50e6, [0, 20, 99]);
  assert.equal(sent.firstAtLeast(100), null);
  sent.add(60e6, [0, 0, 150, 4000]);
  sent.add(20e6, [0, 0, 0, 0, 0, 0, 0, 0]);  // earlier, silent
  assert.equal(sent.firstAtLeast(100), 62);
  assert.equal(sent.firstAtLeast(20), 51);
});

test('matchLevels finds the lag at an onset, to a fraction of a millisecond', () => {
  const levels = speech(2000);
  const sent = new SentLevel();
  sent.add(1000e6, levels);
  for (const lag of [-37.5, -12.3, 0, 4.6, 21]) {
    // 150 ms ending 40 ms into the third onset (at 674 ms), as the page has it then.
    const found = matchLevels(heardOf(levels, 1000, 1000 + 674 - 110, 1000 + 674 + 40, lag), sent);
    assert.ok(found !== null && Math.abs(found - lag) < 0.5, `lag ${lag}: found ${found}`);
  }
});

test('matchLevels says nothing in silence, nor beyond its search range', () => {
  const levels = speech(2000);
  const sent = new SentLevel();
  sent.add(0, levels);
  assert.equal(matchLevels(heardOf(levels, 0, 150, 300, 5), sent), null);  // silence
  assert.equal(matchLevels(heardOf(levels, 0, 564, 714, 80), sent), null);
  // Nothing sent there: no match.
  assert.equal(matchLevels(heardOf(levels, 0, 564, 714, 5), new SentLevel()), null);
});

test('matchLevels with holdMargin stays on the peak lag 0 lies on against a near tie a pitch period away, and moves where the level says', () => {
  // A vowel whose level rises and falls with a 10 ms pitch period: its correlation peaks every
  // 10 ms, nearly as high.
  const voiced = (ms) => {
    const k = ((ms % 337) + 337) % 337;
    return k < 200 ? Math.round(6000 * Math.exp(-k / 400) * (1 + 0.6 * Math.cos((2 * Math.PI * k) / 10))) : 0;
  };
  const sent = new SentLevel();
  sent.add(0, Array.from({ length: 3000 }, (_, i) => voiced(i)));
  const heard = (fromMs, level) => Array.from({ length: 150 }, (_, i) => ({ x: fromMs + i, rms: level(fromMs + i) / 32768 }));
  // Mid-vowel, blurred a little toward one period later: a near tie.
  const blurred = heard(714, (x) => 0.48 * sent.at(x) + 0.52 * sent.at(x + 10));
  const moved = matchLevels(blurred, sent);
  assert.ok(Math.abs(moved - 10) < 0.5, `without holdMargin ${moved}`);
  const held = matchLevels(blurred, sent, { holdMargin: 0.03 });
  assert.ok(Math.abs(held) < 0.5, `with holdMargin ${held}`);
  // The audio moved: over an onset by a period or more, or mid-vowel by other than a period.
  for (const [fromMs, lag] of [[574, 10], [574, -10], [574, 12], [574, 25], [714, 12], [714, -4]]) {
    const found = matchLevels(heard(fromMs, (x) => sent.at(x + lag)), sent, { holdMargin: 0.03 });
    assert.ok(found !== null && Math.abs(found - lag) < 0.5, `from ${fromMs}, lag ${lag}: found ${found}`);
  }
});

// The sender's code (tools/speech_level.h, encode_levels), for the round trip below.
function encodeLevels(levels) {
  const codes = levels.map((rms) => Math.min(255, Math.round(16 * Math.log2(1 + Math.max(rms, 0)))));
  return Buffer.from(codes).toString('base64');
}

test('decodeLevels: one byte a millisecond, 16 codes an octave, base64', () => {
  // Codes 0, 16, 160, 240 and 255: RMS 0, 1, 1023, 32767 and 2^(255/16) - 1.
  assert.deepEqual(Array.from(decodeLevels('ABCg8P8=')), [0, 1, 1023, 32767, 2 ** (255 / 16) - 1]);
  assert.deepEqual(Array.from(decodeLevels('')), []);
  for (const rms of [1, 7, 100, 2500, 8000, 32767]) {
    const back = decodeLevels(encodeLevels([rms]))[0];
    assert.ok(Math.abs(back - rms) <= 0.022 * rms + 0.5, `${rms}: ${back}`);
  }
  assert.throws(() => decodeLevels([1, 2, 3]), TypeError);
  assert.throws(() => decodeLevels(undefined), TypeError);
  assert.throws(() => decodeLevels('not base64!'));
});

// tools/speech_level.h's level_message(0x11223344, 0xfffffff0, {0, 1, 1023, 32767}), as
// tests/web/test_speech_level.cc holds it.
const LEVEL_MESSAGE = [1, 0, 0, 4, 0x11, 0x22, 0x33, 0x44, 0xff, 0xff, 0xff, 0xf0, 0, 16, 160, 240];

test("decodeLevelMessage: the header's SSRC, timestamp and count, then the codes as decodeLevels reads them", () => {
  assert.equal(LEVEL_MESSAGE_TYPE, 1);
  const m = decodeLevelMessage(Uint8Array.from(LEVEL_MESSAGE));
  assert.equal(m.ssrc, 0x11223344);
  assert.equal(m.timestamp, 0xfffffff0);
  assert.deepEqual(Array.from(m.levels), [0, 1, 1023, 32767]);
  // A view into a larger buffer (as a data channel's may be) is read from its own start.
  const larger = new Uint8Array(40).fill(0xaa);
  larger.set(LEVEL_MESSAGE, 7);
  assert.deepEqual(decodeLevelMessage(larger.subarray(7, 7 + LEVEL_MESSAGE.length)), m);
  // The first byte tells it from RTP (version 2: 0x80 to 0xbf) and JSON ('{').
  assert.ok(LEVEL_MESSAGE_TYPE >> 6 !== 2 && LEVEL_MESSAGE_TYPE !== '{'.charCodeAt(0));
});

test('decodeLevelMessage throws for any message that is not exactly one level message', () => {
  const bad = {
    'empty': [],
    'a header cut short': LEVEL_MESSAGE.slice(0, 11),
    'levels cut short': LEVEL_MESSAGE.slice(0, -1),
    'a byte too many': [...LEVEL_MESSAGE, 0],
    'no levels': [1, 0, 0, 0, 0x11, 0x22, 0x33, 0x44, 0, 0, 0, 0],
    'another type': [2, ...LEVEL_MESSAGE.slice(1)],
    'the reserved byte set': [1, 1, ...LEVEL_MESSAGE.slice(2)],
    'a count of 65535 and 4 levels': [1, 0, 0xff, 0xff, ...LEVEL_MESSAGE.slice(4)],
  };
  for (const [what, bytes] of Object.entries(bad)) {
    assert.throws(() => decodeLevelMessage(Uint8Array.from(bytes)), RangeError, what);
  }
});

test('matchLevels finds the same lag in the level as the sender codes it', () => {
  const levels = speech(2000);
  const sent = new SentLevel();
  sent.add(1000e6, decodeLevels(encodeLevels(levels)));
  for (const lag of [-37.5, -12.3, 0, 4.6, 21]) {
    const found = matchLevels(heardOf(levels, 1000, 1000 + 674 - 110, 1000 + 674 + 40, lag), sent);
    assert.ok(found !== null && Math.abs(found - lag) < 0.5, `lag ${lag}: found ${found}`);
  }
});

// matchLevels as it was before it sampled the sent level a block at a time (ba4fbdd): a
// lookup a lag. The reference for the test below.
function matchLevelsByLookup(heard, sentAt, { searchMs = 50, minCorrelation = 0.9, minSpeechMs = 20 } = {}) {
  const peak = heard.reduce((m, h) => Math.max(m, h.rms), 0);
  if (peak === 0 || heard.filter((h) => h.rms > peak * 0.1).length < minSpeechMs) return null;
  const n = heard.length;
  const meanA = heard.reduce((s, h) => s + h.rms, 0) / n;
  let varA = 0;
  for (const h of heard) varA += (h.rms - meanA) ** 2;
  const b = new Float64Array(n);
  const correlation = (lag) => {
    let sumB = 0;
    for (let i = 0; i < n; ++i) {
      b[i] = sentAt(heard[i].x + lag);
      sumB += b[i];
    }
    const meanB = sumB / n;
    let cov = 0;
    let varB = 0;
    for (let i = 0; i < n; ++i) {
      cov += (heard[i].rms - meanA) * (b[i] - meanB);
      varB += (b[i] - meanB) ** 2;
    }
    return varB > 0 ? cov / Math.sqrt(varA * varB) : -1;
  };
  const scores = [];
  for (let lag = -searchMs; lag <= searchMs; ++lag) scores.push(correlation(lag));
  let best = 0;
  for (let i = 1; i < scores.length; ++i) if (scores[i] > scores[best]) best = i;
  if (scores[best] < minCorrelation || best === 0 || best === scores.length - 1) return null;
  const [l, c, r] = [scores[best - 1], scores[best], scores[best + 1]];
  const curvature = l - 2 * c + r;
  const step = curvature < 0 ? Math.max(-0.5, Math.min(0.5, (l - r) / (2 * curvature))) : 0;
  return best - searchMs + step;
}

// A deterministic generator (xorshift32), for noise the test can repeat.
function random(seed) {
  let s = seed >>> 0 || 1;
  return () => {
    s ^= s << 13;
    s ^= s >>> 17;
    s ^= s << 5;
    return (s >>> 0) / 2 ** 32;
  };
}

test('matchLevels finds the lag a lookup a lag found, on stretched, noisy, lost and cut levels', () => {
  const rand = random(28);
  const levels = speech(6000);
  const sent = new SentLevel();
  // As the pages get it: 20 ms messages from a running time off the ms grid, coded, out of
  // order at times, one lost (a gap), one sent twice.
  const startMs = 5000.123457;
  const messages = [];
  for (let k = 0; k < levels.length; k += 20) messages.push(k);
  for (let k = 0; k + 1 < messages.length; k += 7) [messages[k], messages[k + 1]] = [messages[k + 1], messages[k]];
  for (const k of messages) {
    if (k === 1340) continue;
    sent.add((startMs + k) * 1e6, decodeLevels(encodeLevels(levels.slice(k, k + 20))));
    if (k === 2000) sent.add((startMs + k) * 1e6, decodeLevels(encodeLevels(levels.slice(k, k + 20))));
  }
  let compared = 0;
  let found = 0;
  for (let end = 400; end < 5800; end += 40) {
    // 150 blocks of 1 ms heard, put by a mapping that the stretching moves at one block and
    // that is off by up to ±140 ms (a lost clock's), on a performance-time grid off the sent.
    const lag = (rand() - 0.5) * 280;
    const stretchAt = Math.floor(rand() * 150);
    const stretch = rand() < 0.5 ? 0 : (rand() - 0.5) * 12;
    const heard = [];
    for (let i = 0; i < 150; ++i) {
      const t = end - 150 + i + 1e-9 * Math.floor(rand() * 1000);
      const moved = i >= stretchAt ? stretch : 0;
      const ms = startMs + t + moved;
      heard.push({ x: ms - lag + 0.37, rms: (sent.at(ms) / 32768) * (1 + 0.1 * (rand() - 0.5)) + 1e-4 * rand() });
    }
    for (const searchMs of [50, 150]) {
      const before = matchLevelsByLookup(heard, (ms) => sent.at(ms), { searchMs });
      const after = matchLevels(heard, sent, { searchMs });
      assert.ok(before === after || Math.abs(before - after) <= 1e-9, `window ending ${end}, ±${searchMs}: ${before} then ${after}`);
      ++compared;
      if (after !== null) ++found;
    }
  }
  // Both searches, in speech and in silence, found and not.
  assert.equal(compared, 270);
assert.ok(found > 50 && found < compared - 50, `${found} found of ${compared}`);
});
