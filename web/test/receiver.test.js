// SPDX-License-Identifier: LGPL-2.1-or-later
// PfapReceiver on RTP packets: the seeded sessions of the recovery vectors (libpfap's sender,
// seeded loss) wrapped in RTP, plus what a network adds: malformed packets, duplicates, late
// packets, a timestamp that wraps, a new SSRC. Events come with their times in the stream's
// clock, the FAP state is libpfap's after every packet, and bad packets are dropped, counted
// and warned about at the 1st, 2nd, 4th... of a kind.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import path from 'node:path';

import { createCanvas } from '@napi-rs/canvas';

import { PfapReceiver, decodePayload, encodePayload, makeRtp, renderFace } from '../src/index.js';
import { exportVectors, fromHex, sourceRoot } from './libpfap.js';

const RATE = 44100;
const TICK_NS = 1e9 / RATE;
const setups = exportVectors(['recovery']);

function ticks(timeNs) {
  return Math.round((timeNs * RATE) / 1e9);
}

test('received sessions give every phoneme at its time and libpfap\'s FAP state', () => {
  let phonemesCompared = 0;
  for (const setup of setups) {
    const requests = [];
    const receiver = new PfapReceiver({ payloadType: 96, onRequestComplete: (r) => requests.push(r) });
    const base = 0xffff0000; // the timestamp wraps within the first seconds
    let lastEnd = -Infinity;
    for (const p of setup.packets) {
      const payload = fromHex(p.payload);
      if (p.lostUnknownBefore) receiver.lostUnknown();
      const events = receiver.receive(makeRtp({ payloadType: 96, sequenceNumber: p.sequenceNumber, timestamp: (base + ticks(p.timeNs)) >>> 0, ssrc: 1234, payload }));
      const phonemes = events.filter((e) => e.kind === 'phoneme');
      const first = setup.packets[0];
      // Stream time: from the first packet's timestamp, on the RTP clock.
      const packetNs = p.timeNs - first.timeNs;
      if (phonemes.length > 0) {
        assert.ok(Math.abs(phonemes[0].timeNs - packetNs) <= TICK_NS, `${phonemes[0].timeNs} for ${packetNs}`);
        assert.ok(phonemes[0].timeNs >= lastEnd - TICK_NS, 'phonemes go back in time');
        const last = phonemes[phonemes.length - 1];
        lastEnd = last.timeNs + last.phoneme.duration * 1e6;
      }
      for (const e of events) assert.equal(e.uncertain, !p.result.stateWhole);
      const settled = [];
      for (let f = 3; f <= 74; ++f) settled.push(receiver.recovery.state.settled(f));
      assert.deepStrictEqual(settled, p.settled);
      // The face brought to each phoneme's time holds libpfap's settled state after it (the
      // sessions' phonemes last 40 ms or more, so no later one shares its time).
      const phonemeSettled = phonemes.map((e) => {
        receiver.advance(e.timeNs);
        const s = [];
        for (let f = 3; f <= 74; ++f) s.push(receiver.animator.state.settled(f));
        return s;
      });
      assert.deepStrictEqual(phonemeSettled, p.phonemeSettled, `packet ${p.sequenceNumber}`);
      phonemesCompared += phonemeSettled.length;
    }
    const lost = setup.packets.reduce((n, p) => n + p.result.lost, 0);
    assert.equal(receiver.stats.lost, lost);
    assert.equal(receiver.stats.packets, setup.packets.length);
    assert.equal(requests.length, receiver.stats.requests);
  }
  assert.ok(phonemesCompared > 3000, `${phonemesCompared} phonemes`);
});

function phonemePacket(symbol, faps = []) {
  return encodePayload({ complete: false, coverage: 0, recovery: [], phonemes: [{ symbol, duration: 100, f0: 200, stress: false, wordBegin: true, endOfText: false, faps }] });
}

test('bad packets are dropped, counted and warned about, and the stream goes on', () => {
  const warnings = [];
  const receiver = new PfapReceiver({ onWarning: (w) => warnings.push(w) });
  const rtp = (seq, payload, ssrc = 7) => makeRtp({ payloadType: 96, sequenceNumber: seq, timestamp: seq * 4410, ssrc, payload });
  const complete = encodePayload({ complete: true, coverage: 0, recovery: [{ index: 69, amplitude: 40, transition: 0, curve: 1 }], phonemes: [] });
  assert.equal(receiver.receive(rtp(1, complete)).length, 1, 'a changed complete state is an event');
  assert.equal(receiver.stateWhole, true);
  for (let i = 0; i < 5; ++i) assert.deepEqual(receiver.receive(new Uint8Array([0x40, 1, 2])), []);
  for (let i = 0; i < 3; ++i) assert.deepEqual(receiver.receive(rtp(2, new Uint8Array([0x60]))), []);
  const events = receiver.receive(rtp(2, phonemePacket(1, [{ index: 3, amplitude: 100, transition: 0, curve: 1 }])));
  assert.equal(events.length, 1);
  assert.equal(events[0].phoneme.name, 'AA');
  assert.equal(events[0].timeNs, 100_000_000, 'stream time: 4410 ticks after the first packet');
  assert.deepEqual(receiver.receive(rtp(2, phonemePacket(2))), [], 'a duplicate is dropped');
  assert.deepEqual(receiver.receive(rtp(1, phonemePacket(2))), [], 'a late packet is dropped');
  assert.equal(receiver.receive(rtp(3, phonemePacket(3))).length, 1);
  assert.deepEqual(
    { ...receiver.stats },
    { packets: 8, malformedRtp: 5, malformedPayload: 3, otherPayloadType: 0, late: 2, phonemes: 2, faps: 1, lost: 0, gaps: 0, recovered: 0, completeStates: 1, requests: 0 },
  );
  // 1st, 2nd and 4th of 5 malformed RTP packets; 1st and 2nd of 3 payloads; 1st and 2nd late.
  assert.equal(warnings.filter((w) => w.includes('malformed RTP')).length, 3);
  assert.equal(warnings.filter((w) => w.includes('kReservedRecoveryType at byte 0')).length, 2);
  assert.equal(warnings.filter((w) => w.includes('late')).length, 2);
  // The mouth is open mid-phoneme, the bookmark holds, the expression shows.
  const faps = receiver.faps(250_000_000);
  assert.ok(faps[3] > 100, `jaw ${faps[3]}`);
  assert.equal(receiver.animator.state.settled(3), 100);
  assert.equal(receiver.pose(250_000_000).expressions[0], 40 / 63);
});

test('a new SSRC is a new stream: uncertain, asking for a complete state, until one comes', () => {
  const requests = [];
  const receiver = new PfapReceiver({ onRequestComplete: (r) => requests.push(r) });
  const rtp = (seq, payload, ssrc) => makeRtp({ payloadType: 96, sequenceNumber: seq, timestamp: 1000 + seq, ssrc, payload });
  let events = receiver.receive(rtp(500, phonemePacket(1), 99));
  assert.equal(events[0].uncertain, true, 'joined mid-stream');
  assert.deepEqual(requests, [{ sequenceNumber: 500, ssrc: 99 }]);
  receiver.receive(rtp(501, encodePayload({ complete: true, coverage: 0, recovery: [], phonemes: [] }), 99));
  events = receiver.receive(rtp(502, phonemePacket(1), 99));
  assert.equal(events[0].uncertain, false);
  events = receiver.receive(rtp(10, phonemePacket(1), 100));
  assert.equal(events[0].uncertain, true, 'another sender');
  assert.equal(events[0].timeNs, 0, 'its own stream time');
  assert.equal(requests.length, 2);
});

// A receiver given a complete state, then AA from 0 to 100 ms and M with a smile from 100 ms,
// both packets at once, ahead of their time, as a sender with a delay sends them.
function smileAfterAa() {
  const receiver = new PfapReceiver();
  const rtp = (seq, timestamp, payload) => makeRtp({ payloadType: 96, sequenceNumber: seq, timestamp, ssrc: 5, payload });
  receiver.receive(rtp(1, 0, encodePayload({ complete: true, coverage: 0, recovery: [], phonemes: [] })));
  receiver.receive(rtp(2, 0, phonemePacket(1)));
  receiver.receive(rtp(3, 4410, phonemePacket(22, [{ index: 12, amplitude: 300, transition: 0, curve: 1 }])));
  return receiver;
}

test('the face takes each event when its time comes, not when its packet does', () => {
  const receiver = smileAfterAa();
  assert.equal(receiver.faps(50_000_000)[12], 0, 'the smile is not there before its phoneme');
  assert.equal(receiver.animator.describe(50_000_000), 'AA');
  assert.equal(receiver.faps(150_000_000)[12], 300);
  assert.match(receiver.animator.describe(150_000_000), /^M 12:300/);
});

test('draw() draws where the face would differ from the canvas, and the canvas always shows the face', () => {
  const receiver = smileAfterAa();
  const canvas = createCanvas(64, 48);
  const ctx = canvas.getContext('2d');
  // What the canvas holds is the face at timeNs, as renderFace draws it on a fresh canvas.
  const showsFace = (c, timeNs, style) => {
    const fresh = createCanvas(c.width, c.height);
    renderFace(fresh.getContext('2d'), receiver.pose(timeNs), { style });
    const pixels = (x) => Buffer.from(x.getContext('2d').getImageData(0, 0, x.width, x.height).data);
    return pixels(c).equals(pixels(fresh));
  };
  const frameNs = 16_666_667;
  assert.equal(receiver.draw(ctx, 50_000_000), true, 'the first draw');
  assert.ok(showsFace(canvas, 50_000_000));
  assert.equal(receiver.draw(ctx, 150_000_000), true, 'the smile came');
  assert.ok(showsFace(canvas, 150_000_000));
  // Long after the speech the face is still: frame after frame nothing is drawn.
  const still = 5e9;
  assert.equal(receiver.draw(ctx, still), true);
  assert.equal(receiver.draw(ctx, still + frameNs), false);
  assert.equal(receiver.draw(ctx, still + 2 * frameNs), false);
  assert.ok(showsFace(canvas, still + 2 * frameNs));
  // Other options draw; the same again does not.
  assert.equal(receiver.draw(ctx, still, { style: 'line' }), true);
  assert.ok(showsFace(canvas, still, 'line'));
  assert.equal(receiver.draw(ctx, still, { style: 'line' }), false);
  assert.equal(receiver.draw(ctx, still, { overlay: true }), true);
  assert.equal(receiver.draw(ctx, still, { overlay: true }), false);
  assert.equal(receiver.draw(ctx, still), true, 'the overlay goes');
  assert.ok(showsFace(canvas, still));
  // Resizing a canvas clears it: the next draw draws.
  canvas.width = 80;
  assert.equal(receiver.draw(ctx, still + 3 * frameNs), true, 'the canvas resized');
  assert.ok(showsFace(canvas, still));
  canvas.height = 60;
  assert.equal(receiver.draw(ctx, still + 4 * frameNs), true, 'the canvas resized');
  assert.equal(receiver.draw(ctx, still + 5 * frameNs), false);
  // Another canvas gets its face; force draws anyway.
  const other = createCanvas(64, 48);
  assert.equal(receiver.draw(other.getContext('2d'), still), true, 'another canvas');
  assert.ok(showsFace(other, still));
  assert.equal(receiver.draw(other.getContext('2d'), still), false);
  other.getContext('2d').clearRect(0, 0, 64, 48);
  assert.equal(receiver.draw(other.getContext('2d'), still, { force: true }), true, 'forced');
  assert.ok(showsFace(other, still));
});

test('a receiver nobody draws keeps at most 4096 events for the face', () => {
  const receiver = new PfapReceiver();
  for (let seq = 0; seq < 5000; ++seq) {
    receiver.receive(makeRtp({ payloadType: 96, sequenceNumber: seq, timestamp: seq * 4410, ssrc: 5, payload: phonemePacket(1, [{ index: 3, amplitude: seq, transition: 0, curve: 1 }]) }));
  }
  assert.equal(receiver.pendingEvents, 4096);
  // The oldest went to the face in order: FAP 3 holds the last of them.
  assert.equal(receiver.animator.state.settled(3), 5000 - 4096 - 1);
});

test('hostile packets never throw, and every one is counted', () => {
  const payloads = exportVectors(['payloads', path.join(sourceRoot, 'tests/fuzz/corpus/fuzz_payload')]);
  const rtps = exportVectors(['rtp']);
  const receiver = new PfapReceiver();
  let sequenceNumber = 0;
  let events = 0;
  // Arbitrary RTP packets, then the mutated payloads in well-formed RTP (a new SSRC now and
  // then, sequence numbers jumping).
  for (const { bytes } of rtps) events += receiver.receive(fromHex(bytes)).length;
  const refusedRtp = rtps.filter((r) => r.rtp === null).length;
  for (const [i, record] of [...payloads.mutated, ...payloads.arbitrary].entries()) {
    sequenceNumber += i % 17 === 0 ? 1000 : 1;
    const bytes = makeRtp({ payloadType: 96, sequenceNumber, timestamp: sequenceNumber * 441, ssrc: 1 + Math.floor(i / 3000), payload: fromHex(record.bytes) });
    events += receiver.receive(bytes).length;
  }
  const s = receiver.stats;
  assert.equal(s.malformedRtp, refusedRtp);
  assert.equal(s.packets, rtps.length - refusedRtp + payloads.mutated.length + payloads.arbitrary.length);
  const malformed = [...rtps.filter((r) => r.rtp !== null).map((r) => r.rtp.payload), ...[...payloads.mutated, ...payloads.arbitrary].map((r) => r.bytes)]
    .filter((hex) => !decodePayload(fromHex(hex)).ok).length;
  assert.equal(s.malformedPayload, malformed);
  assert.ok(events > 5000, `${events} events`);
  receiver.draw(createCanvas(64, 48).getContext('2d'), 1e12, { overlay: true });
});
