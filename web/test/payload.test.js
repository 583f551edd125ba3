// SPDX-License-Identifier: LGPL-2.1-or-later
// The decoder against pfap::decode_payload on the fuzz corpus and on seeded valid, mutated and
// arbitrary payloads: same status, same offset, same packet. The encoder against
// pfap::decode_payload: every JS-encoded packet decodes in C++ to the packet it was made of.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';

import { COVERAGE_STEPS, EncodeError, decodePayload, encodePayload } from '../src/index.js';
import { exportVectors, fromHex, random, sourceRoot } from './libpfap.js';

const vectors = exportVectors(['payloads', path.join(sourceRoot, 'tests/fuzz/corpus/fuzz_payload')]);

// What decodePayload should give for a record of export_vectors.
function expected(record) {
  return record.status === 'kOk'
    ? { ok: true, packet: record.packet }
    : { ok: false, error: record.status, offset: record.offset };
}

function agreesOnAll(records) {
  let mismatches = 0;
  for (const record of records) {
    const actual = decodePayload(fromHex(record.bytes));
    try {
      assert.deepStrictEqual(actual, expected(record));
    } catch (e) {
      if (++mismatches <= 3) console.log(`# ${record.bytes}: ${e.message}`);
    }
  }
  assert.equal(mismatches, 0, `${mismatches} of ${records.length} payloads decode otherwise than in libpfap`);
}

test('the fuzz corpus decodes as in libpfap', () => {
  assert.ok(vectors.corpus.length >= 20, `only ${vectors.corpus.length} corpus files`);
  agreesOnAll(vectors.corpus);
});

test('15000 seeded valid payloads decode as in libpfap', () => {
  assert.equal(vectors.valid.length, 15000);
  assert.ok(vectors.valid.every((r) => r.status === 'kOk'));
  agreesOnAll(vectors.valid);
});

test('15000 seeded mutated payloads decode as in libpfap, every status among them', () => {
  assert.equal(vectors.mutated.length, 15000);
  agreesOnAll(vectors.mutated);
  const statuses = new Set([...vectors.mutated, ...vectors.arbitrary, ...vectors.corpus].map((r) => r.status));
  // Every status of docs/format.md's table is exercised, so each is compared at least once.
  for (const status of [
    'kOk', 'kTruncated', 'kReservedRecoveryType', 'kReservedInfoBits', 'kMissingCoverage',
    'kFapIndexOutOfRange', 'kAmplitudeOutOfRange', 'kCurveZero', 'kMissingFinalPhoneme',
    'kTrailingBytes', 'kDataInCompleteRecovery', 'kUnterminatedRecovery', 'kEmptyPacket',
  ]) {
    assert.ok(statuses.has(status), `no payload with ${status}`);
  }
});

test('5000 seeded arbitrary byte strings decode as in libpfap', () => {
  agreesOnAll(vectors.arbitrary);
});

test('a valid payload re-encodes to its own bytes', () => {
  for (const record of vectors.valid) {
    assert.equal(Buffer.from(encodePayload(record.packet)).toString('hex'), record.bytes);
  }
});

// Any packet encodePayload takes, from a seeded generator of the JS side.
function randomPacket(r) {
  const fap = () => ({
    index: r.int(3, 74),
    amplitude: r.chance(0.1) ? (r.chance(0.5) ? 2529600 : -2529600) : r.int(-2529600, 2529600),
    transition: r.chance(0.1) ? 16383 : r.int(0, 16383),
    curve: r.int(1, 3),
  });
  const faps = (n) => Array.from({ length: n }, fap);
  const kind = r.int(0, 2);
  if (kind === 2) return { complete: true, coverage: 0, recovery: faps(r.int(0, 4)), phonemes: [] };
  const coverage = kind === 1 ? COVERAGE_STEPS[r.int(0, 6)] : 0;
  const recovery = kind === 1 ? faps(r.int(0, 4)) : [];
  const n = r.int(recovery.length === 0 ? 1 : 0, 6);
  const phonemes = Array.from({ length: n }, (_, i) => ({
    symbol: r.int(0, 255),
    duration: r.chance(0.05) ? 4095 : r.int(0, 400),
    f0: 2 * r.int(0, 255),
    stress: r.chance(0.3),
    wordBegin: r.chance(0.3),
    endOfText: i + 1 === n && r.chance(0.3),
    faps: faps(r.chance(0.5) ? 0 : r.int(1, 3)),
  }));
  return { complete: false, coverage, recovery, phonemes };
}

test('10000 packets encoded in JS decode in libpfap to the same packets', () => {
  const r = random(17);
  const packets = Array.from({ length: 10000 }, () => randomPacket(r));
  const encoded = packets.map(encodePayload);
  // Length-prefixed, as `export_vectors decode` reads them.
  const total = encoded.reduce((n, b) => n + 4 + b.length, 0);
  const input = new Uint8Array(total);
  let pos = 0;
  for (const b of encoded) {
    new DataView(input.buffer).setUint32(pos, b.length);
    input.set(b, pos + 4);
    pos += 4 + b.length;
  }
  const decoded = exportVectors(['decode'], input);
  assert.equal(decoded.length, packets.length);
  decoded.forEach((record, i) => {
    assert.equal(record.status, 'kOk', `packet ${i}: ${record.status} at ${record.offset}`);
    assert.deepStrictEqual(record.packet, packets[i]);
  });
});

test('the encoder refuses what the wire cannot carry, with pfap::EncodeStatus names', () => {
  const phoneme = { symbol: 1, duration: 80, f0: 200, stress: false, wordBegin: false, endOfText: false, faps: [] };
  const fap = { index: 3, amplitude: 10, transition: 100, curve: 1 };
  const cases = [
    [{ complete: false, coverage: 0, recovery: [], phonemes: [] }, 'kEmptyPacket'],
    [{ complete: false, coverage: 4, recovery: [], phonemes: [] }, 'kEmptyPacket'],
    [{ complete: false, coverage: 3, recovery: [fap], phonemes: [] }, 'kInvalidCoverage'],
    [{ complete: false, coverage: 0, recovery: [fap], phonemes: [phoneme] }, 'kRecoveryWithoutKind'],
    [{ complete: true, coverage: 0, recovery: [], phonemes: [phoneme] }, 'kDataInCompleteRecovery'],
    [{ complete: false, coverage: 0, recovery: [], phonemes: [{ ...phoneme, endOfText: true }, phoneme] }, 'kEndOfTextNotLast'],
    [{ complete: false, coverage: 0, recovery: [], phonemes: [{ ...phoneme, duration: 4096 }] }, 'kInvalidPhoneme'],
    [{ complete: false, coverage: 0, recovery: [], phonemes: [{ ...phoneme, symbol: 256 }] }, 'kInvalidPhoneme'],
    [{ complete: false, coverage: 0, recovery: [], phonemes: [{ ...phoneme, faps: [{ ...fap, index: 2 }] }] }, 'kInvalidFap'],
    [{ complete: false, coverage: 0, recovery: [], phonemes: [{ ...phoneme, faps: [{ ...fap, curve: 0 }] }] }, 'kInvalidFap'],
    [{ complete: false, coverage: 0, recovery: [], phonemes: [{ ...phoneme, faps: [{ ...fap, amplitude: 1.5 }] }] }, 'kInvalidFap'],
    [{ complete: false, coverage: 1, recovery: [{ ...fap, transition: 16384 }], phonemes: [] }, 'kInvalidFap'],
  ];
  for (const [packet, status] of cases) {
    assert.throws(() => encodePayload(packet), (e) => e instanceof EncodeError && e.status === status, status);
  }
});

test('f0 goes on the wire as pfap::f0_code: nearest 2 Hz, halves up, at most 510 Hz', () => {
  const f0After = (hz) => {
    const bytes = encodePayload({ complete: false, coverage: 0, recovery: [], phonemes: [{ symbol: 0, duration: 1, f0: hz, stress: false, wordBegin: false, endOfText: false, faps: [] }] });
    return decodePayload(bytes).packet.phonemes[0].f0;
  };
  assert.deepEqual([0, 1, 2, 3, 509, 510, 511, 2000].map(f0After), [0, 2, 2, 4, 510, 510, 510, 510]);
});
