// SPDX-License-Identifier: LGPL-2.1-or-later
// PFAP payload decoder and encoder, bit-exact to draft-ietf-avt-rtp-pfap-00 section 6 and to
// libpfap's pfap::decode_payload / pfap::encode_payload (lib/src/payload.cc): the same checks
// in the same order, so the same status and byte offset for every bad payload. docs/format.md
// has the bit layout and the table of statuses.

import {
  COVERAGE_STEPS, MAX_AMPLITUDE, MAX_FAP_INDEX, MIN_FAP_INDEX, f0Code, isValidFap, isValidPhoneme,
} from './model.js';

const PACKET_DESCRIPTOR_BYTES = 1;
const PHONEME_DESCRIPTOR_BYTES = 4;
const FAP_DESCRIPTOR_BYTES = 6; // also a recovery entry

// InfoBits, by the place they stand in.
const NEXT_PHONEME = 0b00;
const NEXT_FAP = 0b01;
const END_OF_PACKET = 0b10;
const END_OF_TEXT = 0b11; // phoneme descriptors only
const NEXT_RECOVERY = 0b00;
const END_OF_RECOVERY = 0b11;

const RECOVERY_TYPE_NONE = 0b00;
const RECOVERY_TYPE_1 = 0b01;

/** The statuses of docs/format.md's table, as pfap::DecodeStatus names them. */
export const DecodeError = Object.freeze({
  TRUNCATED: 'kTruncated',
  RESERVED_RECOVERY_TYPE: 'kReservedRecoveryType',
  RESERVED_INFO_BITS: 'kReservedInfoBits',
  MISSING_COVERAGE: 'kMissingCoverage',
  FAP_INDEX_OUT_OF_RANGE: 'kFapIndexOutOfRange',
  AMPLITUDE_OUT_OF_RANGE: 'kAmplitudeOutOfRange',
  CURVE_ZERO: 'kCurveZero',
  MISSING_FINAL_PHONEME: 'kMissingFinalPhoneme',
  TRAILING_BYTES: 'kTrailingBytes',
  DATA_IN_COMPLETE_RECOVERY: 'kDataInCompleteRecovery',
  UNTERMINATED_RECOVERY: 'kUnterminatedRecovery',
  EMPTY_PACKET: 'kEmptyPacket',
});

// A FAP descriptor or recovery entry at `pos` (48 bits: FAPind 7, s 1, amplitude 22,
// transition 14, C 2, IB 2): the FAP, or the status of its first bad field. The InfoBits are
// the caller's.
/**
 * @param {Uint8Array} data
 * @param {number} pos
 * @returns {import('./index.js').Fap | import('./index.js').DecodeErrorName}
 */
function unpackFap(data, pos) {
  const b0 = data[pos];
  const b3 = data[pos + 3];
  const b5 = data[pos + 5];
  const index = b0 >> 1;
  const magnitude = (data[pos + 1] << 14) | (data[pos + 2] << 6) | (b3 >> 2);
  const curve = (b5 >> 2) & 0b11;
  if (index < MIN_FAP_INDEX || index > MAX_FAP_INDEX) return DecodeError.FAP_INDEX_OUT_OF_RANGE;
  if (magnitude > MAX_AMPLITUDE) return DecodeError.AMPLITUDE_OUT_OF_RANGE;
  if (curve === 0) return DecodeError.CURVE_ZERO;
  return {
    index,
    amplitude: b0 & 1 && magnitude !== 0 ? -magnitude : magnitude, // negative zero is 0
    transition: ((b3 & 0b11) << 12) | (data[pos + 4] << 4) | (b5 >> 4),
    curve: /** @type {import('./index.js').Fap['curve']} */ (curve),
  };
}

/**
 * Decodes and validates a whole payload. Reads nothing outside `payload`; time is linear in
 * its size. A bad payload gives the status of docs/format.md's table and the byte offset of
 * the descriptor at fault, as pfap::decode_payload.
 * @param {Uint8Array} payload
 * @returns {import('./index.js').DecodeResult}
 */
export function decodePayload(payload) {
  const data = payload;
  const size = data.length;
  /** @type {(error: import('./index.js').DecodeErrorName, offset: number) => import('./index.js').DecodeResult} */
  const fail = (error, offset) => ({ ok: false, error, offset });

  if (size === 0) return fail(DecodeError.TRUNCATED, 0);
  const complete = data[0] >> 7;
  const type = (data[0] >> 5) & 0b11;
  const pp = (data[0] >> 2) & 0b111;
  let next = data[0] & 0b11;
  if (type !== RECOVERY_TYPE_NONE && type !== RECOVERY_TYPE_1) return fail(DecodeError.RESERVED_RECOVERY_TYPE, 0);
  if (next === 0b11) return fail(DecodeError.RESERVED_INFO_BITS, 0);
  let coverage = 0;
  if (complete) {
    if (next !== END_OF_PACKET) return fail(DecodeError.DATA_IN_COMPLETE_RECOVERY, 0);
  } else if (pp !== 0) {
    coverage = COVERAGE_STEPS[pp - 1];
  } else if (type === RECOVERY_TYPE_1) {
    return fail(DecodeError.MISSING_COVERAGE, 0);
  }

  const recovery = [];
  let pos = PACKET_DESCRIPTOR_BYTES;
  if (type === RECOVERY_TYPE_1) {
    for (let infoBits = NEXT_RECOVERY; infoBits !== END_OF_RECOVERY; pos += FAP_DESCRIPTOR_BYTES) {
      if (pos === size) return fail(DecodeError.UNTERMINATED_RECOVERY, pos);
      if (size - pos < FAP_DESCRIPTOR_BYTES) return fail(DecodeError.TRUNCATED, pos);
      infoBits = data[pos + 5] & 0b11;
      if (infoBits !== NEXT_RECOVERY && infoBits !== END_OF_RECOVERY) {
        return fail(DecodeError.RESERVED_INFO_BITS, pos);
      }
      const entry = unpackFap(data, pos);
      if (typeof entry === 'string') return fail(entry, pos);
      recovery.push(entry);
    }
  }

  if (next === END_OF_PACKET && !complete && recovery.length === 0) return fail(DecodeError.EMPTY_PACKET, 0);
  const phonemes = [];
  let faps = [];
  while (next !== END_OF_PACKET) {
    if (pos === size) return fail(DecodeError.MISSING_FINAL_PHONEME, pos);
    if (next === NEXT_PHONEME) {
      if (size - pos < PHONEME_DESCRIPTOR_BYTES) return fail(DecodeError.TRUNCATED, pos);
      const b2 = data[pos + 2];
      const b3 = data[pos + 3];
      next = b3 & 0b11;
      phonemes.push({
        symbol: data[pos],
        duration: (data[pos + 1] << 4) | (b2 >> 4),
        f0: 2 * (((b2 & 0x0f) << 4) | (b3 >> 4)),
        stress: (b3 & 0b1000) !== 0,
        wordBegin: (b3 & 0b100) !== 0,
        endOfText: next === END_OF_TEXT,
        faps,
      });
      faps = [];
      if (next === END_OF_TEXT) next = END_OF_PACKET;
      pos += PHONEME_DESCRIPTOR_BYTES;
    } else {
      if (size - pos < FAP_DESCRIPTOR_BYTES) return fail(DecodeError.TRUNCATED, pos);
      next = data[pos + 5] & 0b11;
      if (next !== NEXT_PHONEME && next !== NEXT_FAP) return fail(DecodeError.RESERVED_INFO_BITS, pos);
      const fap = unpackFap(data, pos);
      if (typeof fap === 'string') return fail(fap, pos);
      faps.push(fap);
      pos += FAP_DESCRIPTOR_BYTES;
    }
  }
  if (pos !== size) return fail(DecodeError.TRAILING_BYTES, pos);
  return { ok: true, packet: { complete: complete === 1, coverage, recovery, phonemes } };
}

/**
 * Thrown by encodePayload for a packet the wire cannot carry; `status` is the
 * pfap::EncodeStatus name (kInvalidFap, kInvalidPhoneme, kInvalidCoverage, kEndOfTextNotLast,
 * kDataInCompleteRecovery, kRecoveryWithoutKind, kEmptyPacket).
 */
export class EncodeError extends Error {
  constructor(status, message) {
    super(message);
    this.name = 'EncodeError';
    this.status = status;
  }
}

// The checks of pfap::encode_payload, in its order.
function check(packet) {
  const recovery = packet.recovery ?? [];
  const phonemes = packet.phonemes ?? [];
  const coverage = packet.coverage ?? 0;
  if (packet.complete) {
    if (phonemes.length > 0) {
      throw new EncodeError('kDataInCompleteRecovery', 'a complete recovery packet holds no phonemes or FAPs');
    }
  } else if (coverage !== 0) {
    if (!COVERAGE_STEPS.includes(coverage)) {
      throw new EncodeError('kInvalidCoverage', `coverage ${coverage} is not one of ${COVERAGE_STEPS.join(', ')}`);
    }
    if (recovery.length === 0 && phonemes.length === 0) throw new EncodeError('kEmptyPacket', 'empty packet');
  } else {
    if (recovery.length > 0) {
      throw new EncodeError('kRecoveryWithoutKind', 'recovery entries need a coverage (or complete)');
    }
    if (phonemes.length === 0) throw new EncodeError('kEmptyPacket', 'empty packet');
  }
  phonemes.forEach((p, i) => {
    if (!isValidPhoneme(p)) throw new EncodeError('kInvalidPhoneme', `phoneme ${i} has a field out of range`);
    if (p.endOfText && i + 1 !== phonemes.length) {
      throw new EncodeError('kEndOfTextNotLast', `end of text on phoneme ${i}, not the last`);
    }
  });
  for (const fap of recovery) {
    if (!isValidFap(fap)) throw new EncodeError('kInvalidFap', `recovery entry out of range: ${JSON.stringify(fap)}`);
  }
  for (const p of phonemes) {
    for (const fap of p.faps) {
      if (!isValidFap(fap)) throw new EncodeError('kInvalidFap', `FAP out of range: ${JSON.stringify(fap)}`);
    }
  }
}

function writeFap(out, pos, fap, infoBits) {
  const magnitude = Math.abs(fap.amplitude);
  out[pos] = (fap.index << 1) | (fap.amplitude < 0 ? 1 : 0);
  out[pos + 1] = magnitude >> 14;
  out[pos + 2] = (magnitude >> 6) & 0xff;
  out[pos + 3] = ((magnitude & 0x3f) << 2) | (fap.transition >> 12);
  out[pos + 4] = (fap.transition >> 4) & 0xff;
  out[pos + 5] = ((fap.transition & 0x0f) << 4) | (fap.curve << 2) | infoBits;
}

/**
 * The payload of `packet`, as pfap::encode_payload writes it. f0 is in Hz and goes on the
 * wire as pfap::f0_code does (nearest 2 Hz step, halves up, at most 510 Hz).
 * @param {import('./index.js').Packet} packet
 * @returns {Uint8Array}
 * @throws {EncodeError} when a field is out of range or the packet's parts do not go together
 */
export function encodePayload(packet) {
  check(packet);
  const recovery = packet.recovery ?? [];
  const phonemes = packet.phonemes ?? [];
  let faps = 0;
  for (const p of phonemes) faps += p.faps.length;
  const out = new Uint8Array(
    PACKET_DESCRIPTOR_BYTES + FAP_DESCRIPTOR_BYTES * (recovery.length + faps) + PHONEME_DESCRIPTOR_BYTES * phonemes.length,
  );
  // What follows phoneme i-1 (or the packet descriptor, for i = 0).
  const announce = (i) => (i === phonemes.length ? END_OF_PACKET : phonemes[i].faps.length > 0 ? NEXT_FAP : NEXT_PHONEME);

  const complete = packet.complete ? 1 : 0;
  const type = recovery.length === 0 ? RECOVERY_TYPE_NONE : RECOVERY_TYPE_1;
  const pp = complete ? 0 : COVERAGE_STEPS.indexOf(packet.coverage ?? 0) + 1;
  out[0] = (complete << 7) | (type << 5) | (pp << 2) | announce(0);
  let pos = PACKET_DESCRIPTOR_BYTES;
  recovery.forEach((entry, i) => {
    writeFap(out, pos, entry, i + 1 === recovery.length ? END_OF_RECOVERY : NEXT_RECOVERY);
    pos += FAP_DESCRIPTOR_BYTES;
  });
  phonemes.forEach((p, i) => {
    p.faps.forEach((fap, k) => {
      writeFap(out, pos, fap, k + 1 === p.faps.length ? NEXT_PHONEME : NEXT_FAP);
      pos += FAP_DESCRIPTOR_BYTES;
    });
    const code = f0Code(p.f0);
    out[pos] = p.symbol;
    out[pos + 1] = p.duration >> 4;
    out[pos + 2] = ((p.duration & 0x0f) << 4) | (code >> 4);
    out[pos + 3] =
      ((code & 0x0f) << 4) | (p.stress ? 0b1000 : 0) | (p.wordBegin ? 0b100 : 0) | (p.endOfText ? END_OF_TEXT : announce(i + 1));
    pos += PHONEME_DESCRIPTOR_BYTES;
  });
  return out;
}
