// SPDX-License-Identifier: LGPL-2.1-or-later
// The pages' clock (web/live/playout.js) without a browser: the tap's level of what is heard
// put in `envelope` by hand, the synchronization source's readings given, matchHeard() called
// as each tap message would. A clock that the audio has left by more than its search (NetEq's
// concealment under load) finds it again.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { lipSyncErrors } from '../live/live.js';
import { DrawnPhonemes, PlayoutClock } from '../live/playout.js';

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

test('a clock that has matched stays on the sound: no match moves it by a period of the level', () => {
  // The level's modulation (a period of 18.8 ms here) makes near ties at whole periods from the
  // sound; before, the second match of the stream's first syllable moved the clock 37 ms and
  // the next two took 80 ms to bring it back (in pages, 10 to 12 ms, a pitch period).
  const clock = new PlayoutClock({ envelope: [] });
  sending(clock, 3000);
  clock.reading(0, 0);
  hear(clock, 0, 2000, () => 0);
  const [first, ...rest] = clock.corrections;
  assert.ok(Math.abs(first.lag) < 2, JSON.stringify(first));
  assert.ok(rest.length > 100 && rest.every((c) => Math.abs(c.lag) < 2), JSON.stringify(rest.filter((c) => Math.abs(c.lag) >= 2)));
  assert.ok(Math.abs(clock.runningMs(1990) - 1990) < 1, `${clock.runningMs(1990)}`);
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

// -- A stream's start (docs/web.md, "The first syllable") -----------------------------------
// The events a stream's start produces in a page, ms by ms of performance time: the audio of
// running time r is heard at r + heardAt, after silence; the tap renders RENDER_AHEAD_MS before
// it is heard and posts every 10 ms; the readings put the audio `readingsOffMs` ahead of the
// sound (through Janus, the estimate from the clock messages: 35 to 200 ms ahead at the start,
// measured); frames every 16.7 ms draw the phoneme at clock.runningMs(now). The "pa"s' p
// starts as its onset sounds, at running time PA_MS + k × 337.
const RENDER_AHEAD_MS = 30;  // what the pages' AudioContext showed (42 ms of latency)
const FRAME_MS = 1000 / 60;
const PA_MS = 49;
const paLevel = (ms) => (ms < PA_MS ? 0 : level(ms - PA_MS));

function startOfStream({ heardAt, readingsOffMs, hearFromMs = 0, sentFromMs = 0, untilMs = 1500, resetAtMs = null }) {
  const clock = new PlayoutClock({ envelope: [], firstSearchMs: 150 });
  const sending = () => clock.sent.add(sentFromMs * 1e6, Array.from({ length: 8000 }, (_, i) => paLevel(sentFromMs + i)));
  sending();
  const frames = [];
  const drawn = new DrawnPhonemes(frames);
  for (let k = 0; k < 20; ++k) {
    drawn.add((PA_MS + k * 337 - 20) * 1e6, false);  // the pause before
    drawn.add((PA_MS + k * 337) * 1e6, true);  // p
    drawn.add((PA_MS + k * 337 + 30) * 1e6, false);  // a
  }
  let nextFrame = heardAt + hearFromMs - 300;
  for (let now = heardAt + hearFromMs - 500; now < heardAt + untilMs; ++now) {
    // The tap: the block heard at now + RENDER_AHEAD_MS (silence before the stream's audio).
    // The stream's first message (its level) comes as it begins: the clock starts over.
    if (now === heardAt + resetAtMs) {
      clock.reset();
      sending();
    }
    const t = now + RENDER_AHEAD_MS;
    const running = t - heardAt;
    clock.envelope.push({ t, rms: running < hearFromMs ? 0 : paLevel(running) / 32768 });
    if (now % 10 === 0) clock.matchHeard();
    // The synchronization source's reading: the audio handed to playout now is heard now on.
    if (running >= hearFromMs) clock.reading(now, now - heardAt + readingsOffMs);
    if (now >= nextFrame) {
      nextFrame += FRAME_MS;
      const ms = clock.runningMs(now);
      if (ms !== null) drawn.frame(now, Math.round(ms * 1e6));
    }
  }
  return { clock, frames };
}

// Each onset heard after silence (running time PA_MS + k × 337 heard at heardAt + that) and the
// first frame that draws the lips pressed for it: ms after the onset (negative: early).
function pressedAfterOnsets(frames, heardAt, fromMs = 0) {
  const errors = [];
  for (let k = 0; k < 4; ++k) {
    const onset = heardAt + PA_MS + k * 337;
    if (onset < heardAt + fromMs) continue;
    const closure = frames.find((f, i) => f.pressed && !frames[i - 1]?.pressed && Math.abs(f.t - onset) < 150);
    errors.push(closure ? closure.t - onset : null);
  }
  return errors;
}

test('a stream\'s first syllable is drawn with its sound, whatever the readings say before the first match', () => {
  // Through Janus the estimate put the audio 35 to 200 ms ahead at a stream's start, and the
  // first "pa" was drawn 27 to 61 ms early, before the level's first match.
  for (const readingsOffMs of [65, 200, -40, 0]) {
    const heardAt = 2000;
    const { frames } = startOfStream({ heardAt, readingsOffMs });
    const errors = pressedAfterOnsets(frames, heardAt);
    for (const e of errors) {
      assert.ok(e !== null && e >= 0 && e <= FRAME_MS + 1, `readings ${readingsOffMs} ms off: first frames pressed ${errors.map((x) => x?.toFixed(1))} ms after the onsets`);
    }
  }
});

test('a stream whose first message comes 20 ms before its sound is heard is drawn with its sound', () => {
  // The sender's first level message leaves with its first audio (its queue is empty then):
  // the page starts the stream over shortly before the sound, after a silence of its own.
  const heardAt = 2000;
  const { clock, frames } = startOfStream({ heardAt, readingsOffMs: 65, resetAtMs: -20 });
  assert.ok(clock.firstSound !== null);
  const errors = pressedAfterOnsets(frames, heardAt);
  for (const e of errors) assert.ok(e !== null && e >= 0 && e <= FRAME_MS + 1, `${errors.map((x) => x?.toFixed(1))}`);
});

test('a late joiner, whose level begins 1 s after what it hears first, draws from the level\'s match', () => {
  // It hears the stream from running time 1000 on, after its own silence, and the level it
  // received begins at 2000 (sent ahead): the first sound it hears is not the first it was
  // sent, so it draws nothing by the readings (70 ms ahead) and waits for the match.
  const heardAt = 2000;
  const { clock, frames } = startOfStream({ heardAt, readingsOffMs: 70, hearFromMs: 1000, sentFromMs: 2000, untilMs: 3500 });
  assert.equal(clock.firstSound, null);
  const firstMatch = clock.corrections[0];
  assert.ok(firstMatch && firstMatch.t > heardAt + 2000, JSON.stringify(clock.corrections.slice(0, 2)));
  assert.ok(frames.length > 0 && frames[0].t >= firstMatch.t - RENDER_AHEAD_MS - 11, `first frame at ${frames[0]?.t}, match at ${firstMatch.t}`);
  for (const [k, onset] of [2071, 2408, 2745, 3082].entries()) {
    const closure = frames.find((f, i) => f.pressed && !frames[i - 1]?.pressed && Math.abs(f.t - (heardAt + onset)) < 150);
    assert.ok(closure && closure.t - (heardAt + onset) >= 0 && closure.t - (heardAt + onset) <= FRAME_MS + 1, `onset ${k}: ${closure?.t}`);
  }
});

// -- A stall mid-speech (docs/web.md, "Lost clocks") ----------------------------------------
// Under load NetEq runs dry and conceals until packets come, then plays them late: the audio is
// heard later by as long as it concealed. getStats' inbound-rtp says so as it happens
// (concealedSamples; silentConcealedSamples takes over once NetEq has faded to silence). What
// runs logged: 131.6 ms of concealment over four polls, none silent, and the next match's
// correction -131.6 ms; 43.4 ms concealed and 86.8 ms silent, correction -86.9 ms (the silent
// part, when silence was not followed).
const LATENCY_MS = 40;  // the output's latency: NetEq's output at t is heard at t + LATENCY_MS
const SAMPLES_PER_MS = 48;

// Hears running time t - delay(t) at each ms t of [fromMs, toMs) as hear() does, and polls
// getStats every 25 ms: `counters(outputMs)` gives the inbound-rtp report of NetEq's output up to
// performance time outputMs (what is heard LATENCY_MS later).
function hearPolled(clock, fromMs, toMs, delay, counters) {
  for (let t = fromMs; t < toMs; ++t) {
    clock.envelope.push({ t, rms: delay(t) === null ? 0 : level(t - delay(t)) / 32768 });
    if (t % 10 === 9) clock.matchHeard();
    if (t % 25 === 0) clock.statsPolled(counters(t - LATENCY_MS), t - LATENCY_MS, LATENCY_MS);
  }
}

// A stall heard over [fromMs, fromMs + ms): concealment (heard as nothing here), then the audio
// ms later. Concealment before the stream's audio (`before` ms, the silence played before any
// audio came) counts as concealment too.
function stall({ fromMs, ms, before = 5000, silentAfterMs = Infinity, lostPackets = 0 }) {
  const delay = (t) => (t < fromMs ? 0 : t < fromMs + ms ? null : lostPackets > 0 ? 0 : ms);
  const counters = (outputMs) => {
    const heard = outputMs + LATENCY_MS;
    const concealed = Math.max(0, Math.min(heard, fromMs + ms) - fromMs);
    const silent = Math.max(0, concealed - silentAfterMs);
    return {
      jitterBufferEmittedCount: Math.max(0, heard - concealed) * SAMPLES_PER_MS,
      concealedSamples: (before + concealed) * SAMPLES_PER_MS, silentConcealedSamples: (before + silent) * SAMPLES_PER_MS,
      packetsLost: heard >= fromMs + ms ? lostPackets : 0, removedSamplesForAcceleration: 0, insertedSamplesForDeceleration: 0,
    };
  };
  return { delay, counters };
}

test('a stall mid-speech delays the clock as getStats counts it, before the next match', () => {
  for (const silentAfterMs of [Infinity, 40]) stalled(silentAfterMs);
});

function stalled(silentAfterMs) {
  const clock = new PlayoutClock({ envelope: [] });
  sending(clock, 8000);
  clock.reading(0, 30);
  const { delay, counters } = stall({ fromMs: 2030, ms: 130, silentAfterMs });  // in the vowel of the 7th "pa"
  hearPolled(clock, 0, 2030, delay, counters);
  assert.ok(Math.abs(clock.runningMs(2000) - 2000) < 2, `before the stall: ${clock.runningMs(2000)}`);
  const matches = clock.corrections.length;
  // From when the stall is heard to the next syllable: the audio is 130 ms late. (No match
  // comes before it: the windows hold the stall.)
  for (let t = 2030; t < 2700; ++t) {
    hearPolled(clock, t, t + 1, delay, counters);
    if (t >= 2160 + 30 && t < 2500) {
      assert.ok(Math.abs(clock.runningMs(t) - (t - 130)) < 3, `silent after ${silentAfterMs} ms, at ${t}: the clock says ${clock.runningMs(t).toFixed(1)}, the sound ${t - 130}`);
    }
  }
  // The matches after it agree.
  const after = clock.corrections.slice(matches).filter((c) => c.t > 2160);
  assert.ok(after.length > 0 && after.every((c) => Math.abs(c.lag) < 3), JSON.stringify(after.slice(0, 5)));
}

test('a stall before the first poll after the first match delays the clock', () => {
  // Under load a page's polls come up to 130 ms apart (a run here: the first match at 2199, the
  // polls at 2146 and 2279, 59 ms of concealment between them, the next match -68.9 ms). Here:
  // the first "pa" matched, then no poll for 250 ms, and a 60 ms stall in the silence after it.
  const clock = new PlayoutClock({ envelope: [] });
  sending(clock, 8000);
  clock.reading(0, 0);
  const { delay, counters } = stall({ fromMs: 200, ms: 60 });
  let matchedAt = null;
  for (let t = 0; t < 1000; ++t) {
    clock.envelope.push({ t, rms: delay(t) === null ? 0 : level(t - delay(t)) / 32768 });
    if (t % 10 === 9) clock.matchHeard();
    if (matchedAt === null && clock.matched !== null) matchedAt = t;
    if (t % 25 === 0 && (matchedAt === null || t > 250)) clock.statsPolled(counters(t - LATENCY_MS), t - LATENCY_MS, LATENCY_MS);
    // Up to the next syllable's match: the clock 60 ms behind where it was.
    if (t >= 300 && t < 397) {
      assert.ok(Math.abs(clock.runningMs(t) - (t - 60)) < 3, `first match at ${matchedAt}; at ${t} the clock says ${clock.runningMs(t).toFixed(1)}, the sound ${t - 60}`);
    }
  }
  assert.ok(matchedAt !== null && matchedAt < 100, `first match at ${matchedAt}`);
});

test('a lost packet moves no clock; at a stream\'s end the clock stops, then runs on past it', () => {
  // A lost packet (20 ms concealed, packetsLost 1): the next is played on time.
  let clock = new PlayoutClock({ envelope: [] });
  sending(clock, 8000);
  clock.reading(0, 0);
  const lost = stall({ fromMs: 2030, ms: 20, lostPackets: 1 });
  hearPolled(clock, 0, 2400, lost.delay, lost.counters);
  for (const t of [2100, 2200, 2300]) assert.ok(Math.abs(clock.runningMs(t) - t) < 2, `at ${t}: ${clock.runningMs(t)}`);
  // The stream ends: NetEq conceals, fading to silence (silentConcealedSamples) within 140 ms
  // in Chromium. The clock stops, and once the silence has gone on for 500 ms with no audio
  // decoded it runs on, 140 ms behind, so that the face gets past the end.
  clock = new PlayoutClock({ envelope: [] });
  sending(clock, 3000);
  clock.reading(0, 0);
  const end = stall({ fromMs: 3000, ms: 1e9, silentAfterMs: 140 });
  hearPolled(clock, 0, 4500, end.delay, end.counters);
  assert.ok(Math.abs(clock.runningMs(3400) - (3000 - 30)) < 30, `the clock stops: ${clock.runningMs(3400)}`);
  assert.ok(Math.abs(clock.runningMs(4000) - (4000 - 140)) < 30, `${clock.runningMs(4000)}`);
  assert.ok(Math.abs(clock.runningMs(4400) - clock.runningMs(3900) - 500) < 1, `${clock.runningMs(3900)}, ${clock.runningMs(4400)}`);
});

// -- The measurement (live.js, lipSyncErrors) -------------------------------------------------
// espeak-ng's "pa.": the p's burst from its onset, a long vowel, a pause (the closure of the
// next p) to the next onset 337 ms later.
const espeakPa = (ms) => {
  const k = ((ms % 337) + 337) % 337;
  if (k < 30) return 1500;
  return k < 290 ? Math.round(8000 * Math.exp(-(k - 30) / 150) * (1 + 0.3 * Math.sin(k / 3))) : 0;
};

// The case a benchmark run showed (docs/web.md, Lost clocks): NetEq ran dry late in a "pa"'s
// vowel, concealed for 117 ms (faded to silence here), and played the rest of the vowel 117 ms
// late; the played level came back after 30 ms under 1 % and lipSyncErrors took that for an
// onset, paired with the next "pa"'s frame (+145 ms there). `followed`: whether getStats'
// counts show the stall (the clock follows it); if not, the clock is lost until a wide search.
function stalledInVowel(followed) {
  const clock = new PlayoutClock({ envelope: [] });
  clock.sent.add(0, Array.from({ length: 8000 }, (_, i) => espeakPa(i)));
  clock.reading(0, 0);
  const frames = [];
  const drawn = new DrawnPhonemes(frames);
  for (let k = 0; k < 20; ++k) {
    drawn.add((k * 337 - 20) * 1e6, false);
    drawn.add(k * 337 * 1e6, true);  // p
    drawn.add((k * 337 + 30) * 1e6, false);  // a
  }
  const onset = 4 * 337;
  const { delay, counters } = stall({ fromMs: onset + 200, ms: 117 });
  const quiet = (outputMs) => ({ ...counters(outputMs), concealedSamples: 5000 * SAMPLES_PER_MS });
  let nextFrame = 0;
  for (let t = 0; t < 3000; ++t) {
    clock.envelope.push({ t, rms: delay(t) === null ? 0 : espeakPa(t - delay(t)) / 32768 });
    if (t % 10 === 9) clock.matchHeard();
    if (t % 25 === 0) clock.statsPolled((followed ? counters : quiet)(t - LATENCY_MS), t - LATENCY_MS, LATENCY_MS);
    if (t >= nextFrame) {
      nextFrame += FRAME_MS;
      const ms = clock.runningMs(t);
      if (ms !== null) drawn.frame(t, Math.round(ms * 1e6));
    }
  }
  return { clock, frames, returnedAt: onset + 200 + 117, next: 5 * 337 + 117 };
}

test('lipSyncErrors: a vowel that a stall cut and that came back is no onset', () => {
  const { clock, frames, returnedAt } = stalledInVowel(true);
  // The played audio's onsets alone: the vowel's return among them, paired with the next p
  // (137 ms after it and more: paired within 200 ms here).
  const played = lipSyncErrors(clock.envelope, frames, { windowMs: 200 });
  const returned = played.filter((e) => e > 100);
  assert.equal(returned.length, 1, `${played}`);
  // Where the matches put its return, the sender's level was sounding: it counts no more, and
  // every other onset counts as before, each drawn within a frame after its sound (the clock
  // followed the stall, and no match moved it by a period of the level).
  assert.ok(Math.abs(clock.matchedRunningMs(returnedAt) - (returnedAt - 117)) < 3, `${clock.matchedRunningMs(returnedAt)}`);
  const errors = lipSyncErrors(clock.envelope, frames, { windowMs: 200, sent: clock.sentForMeasurement() });
  assert.deepEqual(errors, played.filter((e) => e !== returned[0]));
  assert.equal(errors.length, 8);
  assert.ok(errors.every((e) => e >= 0 && e <= FRAME_MS + 1), `${errors}`);
});

test('lipSyncErrors: a lost clock is still measured, at the next syllable', () => {
  // The same stall, which the counts do not show: the clock runs early until a wide search
  // finds the audio again. The vowel's
  // return is still no onset (the match that found the audio says where it was); the next "pa"
  // is drawn early and counted so.
  const { clock, frames, next } = stalledInVowel(false);
  const played = lipSyncErrors(clock.envelope, frames);
  const errors = lipSyncErrors(clock.envelope, frames, { sent: clock.sentForMeasurement() });
  assert.equal(errors.length, played.length - 1, `${played} against ${errors}`);
  assert.equal(errors.length, 8);
  const early = errors.filter((e) => e < -50);
  assert.equal(early.length, 1, `${errors}`);
  assert.ok(errors.every((e) => e < -50 || (e >= 0 && e <= FRAME_MS + 1)), `${errors}`);
  assert.ok(frames.some((f, i) => f.pressed && !frames[i - 1].pressed && Math.abs(f.t - (next + early[0])) < 0.01));
});
