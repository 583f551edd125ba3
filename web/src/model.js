// SPDX-License-Identifier: LGPL-2.1-or-later
// The TtsFAPInterface data as draft-ietf-avt-rtp-pfap-00 carries it (lib/include/pfap/model.h).

/** Nanoseconds in a millisecond: times are ns, durations and transitions ms. */
export const NS_PER_MS = 1_000_000;
/** The lowest FAP index a descriptor carries (FAPind 3..74, docs/format.md). */
export const MIN_FAP_INDEX = 3;
/** The highest FAP index: 74, expression 6. */
export const MAX_FAP_INDEX = 74;
/** FAP indexes 69..74 carry the MPEG-4 expressions 1..6: index = 68 + expression. */
export const FIRST_EXPRESSION_INDEX = 69;
/** Arrays indexed by FAP index have this length. */
export const FAP_COUNT = MAX_FAP_INDEX + 1;
/** The largest |amplitude| a FAP descriptor carries (22 bits), in the FAP's own units. */
export const MAX_AMPLITUDE = 2529600;
/** The longest transition a FAP descriptor carries (14 bits), ms. */
export const MAX_TRANSITION_MS = 16383;
/** The longest phoneme a descriptor carries (12 bits), ms. */
export const MAX_PHONEME_DURATION_MS = 4095;
/** The highest f0 on the wire (8 bits of 2 Hz), Hz. */
export const MAX_F0_HZ = 510;

/** Curves (C): 1 linear, 2 triangle, 3 spline. */
export const Curve = Object.freeze({ LINEAR: 1, TRIANGLE: 2, SPLINE: 3 });

/** The prevPackets values the 3-bit PP field can signal, by PP - 1. */
export const COVERAGE_STEPS = Object.freeze([1, 2, 4, 7, 15, 25, 40]);

function isInt(v, lo, hi) {
  return Number.isInteger(v) && v >= lo && v <= hi;
}

/**
 * Whether `fap` holds values the wire can carry.
 * @param {import('./index.js').Fap} fap
 */
export function isValidFap(fap) {
  return (
    fap !== null &&
    typeof fap === 'object' &&
    isInt(fap.index, MIN_FAP_INDEX, MAX_FAP_INDEX) &&
    isInt(fap.amplitude, -MAX_AMPLITUDE, MAX_AMPLITUDE) &&
    isInt(fap.transition, 0, MAX_TRANSITION_MS) &&
    isInt(fap.curve, 1, 3)
  );
}

/**
 * Whether `phoneme` holds values the wire can carry (f0 in Hz, any whole number: the encoder
 * rounds it with f0Code) and a list of FAPs.
 * @param {import('./index.js').Phoneme} phoneme
 */
export function isValidPhoneme(phoneme) {
  return (
    phoneme !== null &&
    typeof phoneme === 'object' &&
    isInt(phoneme.symbol, 0, 255) &&
    isInt(phoneme.duration, 0, MAX_PHONEME_DURATION_MS) &&
    isInt(phoneme.f0, 0, Number.MAX_SAFE_INTEGER) &&
    Array.isArray(phoneme.faps)
  );
}

/**
 * The f0 code for a frequency in Hz: nearest 2 Hz step, halves rounded up, saturating at
 * 510 Hz (code 255), as pfap::f0_code.
 * @param {number} hz a whole number of Hz, 0 or more
 */
export function f0Code(hz) {
  return Math.floor((Math.min(hz, MAX_F0_HZ) + 1) / 2);
}
