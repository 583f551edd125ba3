// SPDX-License-Identifier: LGPL-2.1-or-later
// A face over time, as pfapface's pfap::face::Animator (face/src/animator.cc, docs/face.md): the
// FAP state of every bookmark, the mouth shapes of the phonemes (visemes, with
// coarticulation) and the expressions, as the amplitude of every FAP at any time.

import { FapState } from './fap_state.js';
import { addExpressions, fapValues, poseFromFaps } from './face_model.js';
import { MAX_FAP_INDEX, MIN_FAP_INDEX, NS_PER_MS } from './model.js';
import { Viseme, findPhoneme } from './phoneme_table.js';

// A mouth shape: [open_jaw (FAP 3), lower_t_midlip (4; 8, 9 by 0.7), raise_b_midlip (5; 10,
// 11 by 0.7), stretch_corner (6, 7, 53, 54), raise_corner (12, 13, 59, 60), push_lip (16, 17)].
const CLOSED = Object.freeze([0, 0, 0, 0, 0, 0]);
const VISEME_SHAPES = Object.freeze({
  [Viseme.NONE]: CLOSED,
  [Viseme.PBM]: [0, 30, 30, 0, 0, 40],
  [Viseme.FV]: [70, -40, 110, 0, 0, 0],
  [Viseme.TH]: [150, -20, 0, 20, 0, 0],
  [Viseme.TD]: [130, 0, 0, 40, 0, 0],
  [Viseme.KG]: [190, 0, 0, 30, 0, 0],
  [Viseme.CH]: [110, 0, 0, -160, 0, 180],
  [Viseme.SZ]: [50, -30, 0, 90, 20, 0],
  [Viseme.NL]: [160, 0, 0, 30, 0, 0],
  [Viseme.R]: [120, 0, 0, -110, 0, 120],
  [Viseme.A]: [430, -20, 0, 40, 0, 0],
  [Viseme.E]: [290, -20, 0, 130, 20, 0],
  [Viseme.I]: [170, -20, 0, 200, 50, 0],
  [Viseme.Q]: [380, 0, 0, -150, 0, 120],
  [Viseme.U]: [120, 0, 0, -230, 0, 240],
});
/** The mouth of a phoneme whose viseme is unknown, at its widest. */
const GENERIC_MOUTH = Object.freeze([250, 0, 0, 40, 0, 0]);

/**
 * The mouth shape of an MPEG-4 viseme, as 6 FAP displacements (see VISEME_SHAPES).
 * @param {number} viseme
 * @returns {readonly number[]}
 */
export function visemeShape(viseme) {
  return VISEME_SHAPES[viseme] ?? CLOSED;
}

/** How long the mouth takes from one shape to the next: at most this, at most half the phoneme. */
export const MOUTH_EASE_NS = 80_000_000;

function blend(from, to, u) {
  return from.map((a, i) => a + (to[i] - a) * u);
}

function ease(u) {
  u = Math.min(Math.max(u, 0.0), 1.0);
  return u * u * (3 - 2 * u);
}

/**
 * pfapface's animator: applies phoneme, recovered and complete events at their times and
 * gives the FAP values and the face's pose at any time after, with the mouth moving between
 * visemes (coarticulation) and a generic mouth for symbols it does not know.
 */
export class Animator {
  /**
   * @param {import('./index.js').PhonemeAlphabet | null} [alphabet] the phoneme symbols'
   *   alphabet; null: every phoneme opens and closes a generic mouth
   */
  constructor(alphabet = null) {
    this.alphabet = alphabet;
    this._state = new FapState();
    this.reset();
  }

  /** The neutral face with no events (the alphabet stays). */
  reset() {
    this._state.reset();
    this._sound = { from: CLOSED, to: CLOSED, generic: false, startNs: 0, endNs: 0, name: '' };
    this._lastNs = 0;
    this._endNs = 0;
  }

  /** The time of the last event applied (0 before any). */
  get lastNs() {
    return this._lastNs;
  }

  /** When the last phoneme is over and the last transition has ended. */
  get endNs() {
    return this._endNs;
  }

  /** The FAP state of the bookmarks (without mouth and expressions). */
  get state() {
    return this._state;
  }

  /**
   * Applies one event at `timeNs`: a phoneme's mouth and FAPs, a recovered state's entries,
   * or a complete state (every FAP to 0, then its entries). An earlier time than the last is
   * taken as the last. Returns false for a phoneme with no known mouth shape.
   * @param {{kind: 'phoneme'|'recovered'|'complete', phoneme?: {symbol: number, duration: number},
   *          faps: import('./index.js').Fap[]}} event
   * @param {number} timeNs
   */
  apply(event, timeNs) {
    timeNs = Math.max(timeNs, this._lastNs);
    this._lastNs = timeNs;
    if (event.kind === 'complete') this._state.reset();
    for (const fap of event.faps) {
      this._state.apply(fap, timeNs);
      this._endNs = Math.max(this._endNs, timeNs + fap.transition * NS_PER_MS);
    }
    if (event.kind !== 'phoneme') return true;

    const info = this.alphabet !== null ? findPhoneme(this.alphabet, event.phoneme.symbol) : null;
    this._sound = {
      from: this._mouth(timeNs),
      to: info !== null ? visemeShape(info.viseme) : GENERIC_MOUTH,
      generic: info === null,
      startNs: timeNs,
      endNs: timeNs + event.phoneme.duration * NS_PER_MS,
      name: info !== null ? info.name : `#${event.phoneme.symbol}`,
    };
    this._endNs = Math.max(this._endNs, this._sound.endNs);
    return info !== null;
  }

  _mouth(timeNs) {
    const s = this._sound;
    const length = s.endNs - s.startNs;
    const during = (t) => {
      // Integer division, as the C++ int64 `length / 2`.
      const span = Math.min(MOUTH_EASE_NS, Math.trunc(length / 2));
      const u = span > 0 ? ease((t - s.startNs) / span) : 1.0;
      let target = s.to;
      if (s.generic) {
        const x = length > 0 ? (t - s.startNs) / length : 1.0;
        target = blend(CLOSED, s.to, Math.sin(Math.PI * Math.min(Math.max(x, 0.0), 1.0)));
      }
      return blend(s.from, target, u);
    };
    if (timeNs < s.endNs) return during(Math.max(timeNs, s.startNs));
    const u = ease((timeNs - s.endNs) / MOUTH_EASE_NS);
    return blend(during(s.endNs), CLOSED, u);
  }

  /**
   * Every FAP's amplitude at `timeNs`, at or after the last event: bookmarks plus the
   * phoneme's mouth plus the expressions' displacements.
   * @param {number} timeNs
   * @returns {Float64Array} indexed by FAP number
   */
  faps(timeNs) {
    const f = fapValues();
    for (let i = MIN_FAP_INDEX; i <= MAX_FAP_INDEX; ++i) f[i] = this._state.amplitude(i, timeNs);
    const [openJaw, lowerTMidlip, raiseBMidlip, stretchCorner, raiseCorner, pushLip] = this._mouth(timeNs);
    f[3] += openJaw;
    f[4] += lowerTMidlip;
    f[8] += 0.7 * lowerTMidlip;
    f[9] += 0.7 * lowerTMidlip;
    f[5] += raiseBMidlip;
    f[10] += 0.7 * raiseBMidlip;
    f[11] += 0.7 * raiseBMidlip;
    for (const i of [6, 7, 53, 54]) f[i] += stretchCorner;
    for (const i of [12, 13, 59, 60]) f[i] += raiseCorner;
    f[16] += pushLip;
    f[17] += pushLip;
    addExpressions(f);
    return f;
  }

  /**
   * The face's shapes at `timeNs`, for a renderer.
   * @param {number} timeNs
   */
  pose(timeNs) {
    return poseFromFaps(this.faps(timeNs));
  }

  /**
   * What a debug overlay shows: the phoneme sounding (or "pause") and every FAP whose
   * bookmarked amplitude is not 0, as "index:amplitude".
   * @param {number} timeNs
   */
  describe(timeNs) {
    const s = this._sound;
    let text = timeNs >= s.startNs && timeNs < s.endNs ? s.name : 'pause';
    for (let i = MIN_FAP_INDEX; i <= MAX_FAP_INDEX; ++i) {
      const a = this._state.amplitude(i, timeNs);
      const rounded = (a < 0 ? -Math.round(-a) : Math.round(a)) + 0;
      if (rounded !== 0) text += ` ${i}:${rounded}`;
    }
    return text;
  }
}
