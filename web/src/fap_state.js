// SPDX-License-Identifier: LGPL-2.1-or-later
// The amplitude of every FAP over time at a receiver (draft section 5), as pfap::FapState
// (lib/src/fap_state.cc) computes it, operation for operation, so that amplitudes agree with
// libpfap's to the last bit. docs/format.md ("FAP amplitude over time") gives the rules:
//   C=1 linear:   v(t) = s + (a - s) * u                 u = (t - start) / T in [0, 1]
//   C=2 triangle: v(t) = s + (a - s) * 2u                 for u < 1/2, then
//                 v(t) = a + (p - a) * (2u - 1)           back to p, what the FAP held before
//   C=3 spline:   v(t) = s + (a - s) * u^2 * (3 - 2u)
// s is the amplitude reached at the bookmark's start, rounded to a whole unit (halves away
// from zero). Times are nanoseconds (Numbers: exact up to 2^53 ns, 104 days).

import { Curve, FAP_COUNT, MAX_FAP_INDEX, MIN_FAP_INDEX, NS_PER_MS } from './model.js';

// Nearest integer, halves away from zero (std::lround); never -0.
function roundHalfAway(x) {
  return (x < 0 ? -Math.round(-x) : Math.round(x)) + 0;
}

function checkIndex(index) {
  if (!Number.isInteger(index) || index < MIN_FAP_INDEX || index > MAX_FAP_INDEX) {
    throw new RangeError(`FAP index ${index} outside ${MIN_FAP_INDEX}..${MAX_FAP_INDEX}`);
  }
}

/**
 * The receiver's FAP state, as pfap::FapState: each FAP's transition (start, target, curve)
 * and the value it has at any time after its start.
 */
export class FapState {
  constructor() {
    // Per FAP index, struct-of-arrays: amplitude when the transition started, its target,
    // what the FAP holds once it is over (the target, or for a triangle what it held
    // before), start and length in ns, curve.
    this._from = new Float64Array(FAP_COUNT);
    this._target = new Float64Array(FAP_COUNT);
    this._settled = new Int32Array(FAP_COUNT);
    this._startNs = new Float64Array(FAP_COUNT);
    this._durationNs = new Float64Array(FAP_COUNT);
    this._curve = new Uint8Array(FAP_COUNT).fill(Curve.LINEAR);
  }

  /**
   * Starts the transition of `fap` at `startNs`. Bookmarks for one FAP must come in
   * non-decreasing start order.
   * @param {import('./index.js').Fap} fap
   * @param {number} startNs
   */
  apply(fap, startNs) {
    const i = fap.index;
    checkIndex(i);
    // Whatever the FAP has reached at the start covers all three starting amplitudes.
    const from = roundHalfAway(this.amplitude(i, startNs));
    // A triangle is an excursion: the FAP keeps holding what it held before.
    if (fap.curve !== Curve.TRIANGLE) this._settled[i] = fap.amplitude;
    this._from[i] = from;
    this._target[i] = fap.amplitude;
    this._startNs[i] = startNs;
    this._durationNs[i] = fap.transition * NS_PER_MS;
    this._curve[i] = fap.curve;
  }

  /**
   * The amplitude of FAP `index` at `timeNs`, for times at or after the start of the last
   * bookmark applied to it (earlier times give that bookmark's starting amplitude).
   * @param {number} index
   * @param {number} timeNs
   * @returns {number}
   */
  amplitude(index, timeNs) {
    checkIndex(index);
    const start = this._startNs[index];
    const from = this._from[index];
    if (timeNs < start) return from;
    const elapsed = timeNs - start;
    const duration = this._durationNs[index];
    if (elapsed >= duration) return this._settled[index];
    const u = elapsed / duration;
    const target = this._target[index];
    switch (this._curve[index]) {
      case Curve.TRIANGLE:
        return u < 0.5 ? from + (target - from) * 2.0 * u : target + (this._settled[index] - target) * (2.0 * u - 1.0);
      case Curve.SPLINE:
        return from + (target - from) * u * u * (3.0 - 2.0 * u);
      default:
        return from + (target - from) * u;
    }
  }

  /**
   * What FAP `index` holds once its transition is over (a triangle's p).
   * @param {number} index
   */
  settled(index) {
    checkIndex(index);
    return this._settled[index];
  }

  /**
   * Whether FAP `index` has no transition running at `timeNs`.
   * @param {number} index
   * @param {number} timeNs
   */
  atRest(index, timeNs) {
    checkIndex(index);
    return timeNs - this._startNs[index] >= this._durationNs[index];
  }

  /**
   * The recovery entry that brings a receiver to this FAP's settled value from `timeNs` on
   * (pfap::FapState::recovery_entry): a running linear or spline transition's target and the
   * time left, rounded up; else the settled value at once.
   * @param {number} index
   * @param {number} timeNs
   * @returns {import('./index.js').Fap}
   */
  recoveryEntry(index, timeNs) {
    if (this.atRest(index, timeNs) || this._curve[index] === Curve.TRIANGLE) {
      return { index, amplitude: this._settled[index], transition: 0, curve: Curve.LINEAR };
    }
    const start = this._startNs[index];
    const leftNs = start + this._durationNs[index] - Math.max(timeNs, start);
    return { index, amplitude: this._target[index], transition: Math.ceil(leftNs / NS_PER_MS), curve: /** @type {import('./index.js').Fap['curve']} */ (this._curve[index]) };
  }

  /** Every FAP back to 0 with no transition running, as after construction. */
  reset() {
    this._from.fill(0);
    this._target.fill(0);
    this._settled.fill(0);
    this._startNs.fill(0);
    this._durationNs.fill(0);
    this._curve.fill(Curve.LINEAR);
  }
}
