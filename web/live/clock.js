// SPDX-License-Identifier: LGPL-2.1-or-later
// Which running time of the server's pipeline the page is hearing (docs/web.md, Timing).
//
// The audio receiver's synchronization source says which RTP timestamp was last handed to
// playout and when, but what lies after it is the browser's and differs per session: the
// jitter buffer's leftover of decoded audio (its reading names the packet just decoded, not
// the first sample handed out), which changes each time it stretches or squeezes the audio,
// and the queue between WebRTC's 10 ms chunks and Web Audio's render quanta. The server sends
// the level of the speech it sends (the RMS of each millisecond, by running time); the page
// finds the level of what it plays in it, and so learns the remaining lag.

/** Codes per octave of the sender's level (tools/speech_level.h, level_codes). */
export const LEVEL_CODES_PER_OCTAVE = 16;

/** One level's code (one byte) back to RMS in S16 units, within 2.2 % of the sender's. */
const levelOfCode = (code) => 2 ** (code / LEVEL_CODES_PER_OCTAVE) - 1;

/**
 * The levels of pfap-web's "envelope": base64, one byte a millisecond, the code
 * round(16 × log2(1 + rms)), back to RMS in S16 units (within 2.2 % of the sender's).
 * Throws a TypeError if `base64` is not a string and a DOMException if it is not base64.
 * @param {string} base64
 * @returns {Float64Array}
 */
export function decodeLevels(base64) {
  if (typeof base64 !== 'string') throw new TypeError('level: not a base64 string');
  const bytes = atob(base64);
  const levels = new Float64Array(bytes.length);
  for (let i = 0; i < bytes.length; ++i) levels[i] = levelOfCode(bytes.charCodeAt(i));
  return levels;
}

/** The first byte of a level message (tools/speech_level.h, kLevelMessageType). */
export const LEVEL_MESSAGE_TYPE = 0x01;
const LEVEL_HEADER_SIZE = 12;

/**
 * A level message of pfap-broadcast's data stream (docs/web.md, "The level message"): a 12-byte
 * header (the type, 0, the count, the SSRC, the PFAP timestamp of the first level; big-endian)
 * and one code a millisecond, decoded as decodeLevels' codes. Throws a RangeError for a message
 * that is not exactly one whole level message, so that it is dropped whole.
 * @param {Uint8Array} bytes
 * @returns {{ssrc: number, timestamp: number, levels: Float64Array}}
 */
export function decodeLevelMessage(bytes) {
  if (bytes.length < LEVEL_HEADER_SIZE) throw new RangeError(`level message: ${bytes.length} bytes, shorter than its header`);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (bytes[0] !== LEVEL_MESSAGE_TYPE || bytes[1] !== 0) throw new RangeError('level message: not one (type or reserved byte)');
  const count = view.getUint16(2);
  if (count === 0 || bytes.length !== LEVEL_HEADER_SIZE + count) {
    throw new RangeError(`level message: ${count} levels in ${bytes.length - LEVEL_HEADER_SIZE} bytes`);
  }
  const levels = new Float64Array(count);
  for (let i = 0; i < count; ++i) levels[i] = levelOfCode(bytes[LEVEL_HEADER_SIZE + i]);
  return { ssrc: view.getUint32(4), timestamp: view.getUint32(8), levels };
}

// A segment's level at running time `ms` (not before its start): between two blocks' starts
// interpolated, 0 past its last block. Its last block leads to the first of `after` (the next
// segment) where that starts at its end, as the sender's messages follow one another (within
// half a block: a running time's ms, from its ns, and a sum of them differ in the last bits),
// and toward 0 where nothing follows.
function levelIn({ startMs, levels }, ms, after) {
  const x = ms - startMs;
  const k = Math.floor(x);
  if (k >= levels.length) return 0;
  const follows = after !== undefined && Math.abs(after.startMs - (startMs + levels.length)) < 0.5;
  const next = k + 1 < levels.length ? levels[k + 1] : follows ? after.levels[0] : 0;
  return levels[k] + (next - levels[k]) * (x - k);
}

/**
 * The sender's level by running time, from the server's "envelope" messages (decodeLevels).
 */
export class SentLevel {
  constructor({ keepMs = 30000 } = {}) {
    this.keepMs = keepMs;
    this.segments = [];  // {startMs, levels}, in running time order
    this.found = null;  // the index of the segment found last
  }

  /** A message: `levels[i]` is the RMS of the ms from runningTimeNs / 1e6 + i. */
  add(runningTimeNs, levels) {
    const startMs = runningTimeNs / 1e6;
    this.segments.push({ startMs, levels: Float64Array.from(levels) });
    this.segments.sort((a, b) => a.startMs - b.startMs);
    const newest = this.segments.at(-1).startMs;
    while (this.segments.length > 1 && this.segments[0].startMs < newest - this.keepMs) this.segments.shift();
    this.found = null;
  }

  /** The highest level sent (kept), 0 before any. */
  peak() {
    return this.segments.reduce((m, { levels }) => levels.reduce((n, v) => Math.max(n, v), m), 0);
  }

  /** The first running time (ms) whose level is `rms` or more, or null. */
  firstAtLeast(rms) {
    for (const { startMs, levels } of this.segments) {
      const k = levels.findIndex((v) => v >= rms);
      if (k >= 0) return startMs + k;
    }
    return null;
  }

  /** The level at running time `ms` (between two blocks' starts, interpolated), 0 where none was sent. */
  at(ms) {
    // Lookups come in runs of nearby times: the segment found last first.
    const near = this.found ?? this.segments.length - 1;
    const i = this.segments[near] && this.segments[near].startMs <= ms &&
      (near + 1 >= this.segments.length || ms < this.segments[near + 1].startMs)
      ? near : this.segments.findLastIndex((seg) => seg.startMs <= ms);
    if (i < 0) return 0;
    this.found = i;
    return levelIn(this.segments[i], ms, this.segments[i + 1]);
  }

  /**
   * at(ms + lag) for `count` lags from `firstLag` in 1 ms steps, into out[offset + j × stride]
   * for the j-th: the same values, with one segment search, not one a lag.
   */
  sampleLags(ms, firstLag, count, out, offset = 0, stride = 1) {
    const { segments } = this;
    // The last segment that starts at or before the first time (at's), -1 if none does.
    let lo = 0;
    let hi = segments.length;
    const first = ms + firstLag;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (segments[mid].startMs <= first) lo = mid + 1;
      else hi = mid;
    }
    let s = lo - 1;
    let nextStart = s + 1 < segments.length ? segments[s + 1].startMs : Infinity;
    for (let j = 0; j < count; ++j) {
      const t = ms + (firstLag + j);
      if (t >= nextStart) {
        while (s + 1 < segments.length && segments[s + 1].startMs <= t) ++s;
        nextStart = s + 1 < segments.length ? segments[s + 1].startMs : Infinity;
      }
      out[offset + j * stride] = s >= 0 ? levelIn(segments[s], t, segments[s + 1]) : 0;
    }
  }
}

/**
 * The lag by which the played audio's level best matches the sender's: each heard 1 ms block,
 * put at running time `x` by the synchronization source, was sent at x + lag. Searched in
 * 1 ms steps within ±searchMs (Pearson correlation of the two levels), refined between steps
 * by a parabola. Null unless the window holds at least `minSpeechMs` of sound, the best
 * correlation reaches `minCorrelation` and lies inside the search range.
 *
 * With `holdMargin`, the lag is the correlation's peak that lag 0 lies on (climbed to from
 * there) unless another scores more than `holdMargin` higher. A voiced level rises and falls
 * with its pitch period, so its correlation peaks every 10 ms or so, nearly as high: in the
 * pages a clock that was right moved by one such period at a match and back at a later one
 * (scores 0.001 to 0.014 apart), and drew a "pa" 12 ms late meanwhile (docs/web.md, "Lost
 * clocks"). A clock that has matched passes it; the audio moved by what getStats did not
 * count scores far higher where it went (0.13 to 0.41 more in those pages).
 *
 * The sums are SentLevel.at's values and the correlation's, in the same order, so the lag is
 * the same to the bit; what it saves is the lookups: each block walks the sender's segments
 * once over its lags, not a search and a call for each.
 * @param {{x: number, rms: number}[]} heard
 * @param {SentLevel} sent
 * @returns {number|null} ms
 */
export function matchLevels(heard, sent, { searchMs = 50, minCorrelation = 0.9, minSpeechMs = 20, holdMargin = 0 } = {}) {
  const n = heard.length;
  let peak = 0;
  for (const h of heard) peak = Math.max(peak, h.rms);
  let speech = 0;
  for (const h of heard) if (h.rms > peak * 0.1) ++speech;
  if (peak === 0 || speech < minSpeechMs) return null;
  let sumA = 0;
  for (const h of heard) sumA += h.rms;
  const meanA = sumA / n;
  const lags = 2 * searchMs + 1;
  const { a, b, scores } = scratch(n, lags);
  let varA = 0;
  for (let i = 0; i < n; ++i) {
    a[i] = heard[i].rms - meanA;
    varA += a[i] ** 2;
  }
  // b[j × n + i]: the sent level at heard block i's x + lag j (j = 0 is -searchMs).
  for (let i = 0; i < n; ++i) sent.sampleLags(heard[i].x, -searchMs, lags, b, i, n);
  for (let j = 0; j < lags; ++j) {
    const row = j * n;
    let sumB = 0;
    for (let i = 0; i < n; ++i) sumB += b[row + i];
    const meanB = sumB / n;
    let cov = 0;
    let varB = 0;
    for (let i = 0; i < n; ++i) {
      const d = b[row + i] - meanB;
      cov += a[i] * d;
      varB += d ** 2;
    }
    scores[j] = varB > 0 ? cov / Math.sqrt(varA * varB) : -1;
  }
  let best = 0;
  for (let j = 1; j < lags; ++j) if (scores[j] > scores[best]) best = j;
  if (scores[best] < minCorrelation || best === 0 || best === lags - 1) return null;
  if (holdMargin > 0) {
    let held = searchMs;  // lag 0
    const up = scores[held + 1] > scores[held] ? 1 : -1;
    while (held + up > 0 && held + up < lags - 1 && scores[held + up] > scores[held]) held += up;
    if (scores[best] - scores[held] <= holdMargin && scores[held] >= minCorrelation) best = held;
  }
  const [l, c, r] = [scores[best - 1], scores[best], scores[best + 1]];
  const curvature = l - 2 * c + r;
  const step = curvature < 0 ? Math.max(-0.5, Math.min(0.5, (l - r) / (2 * curvature))) : 0;
  return best - searchMs + step;
}

// matchLevels' buffers, kept from one match to the next (a match every 10 ms: no garbage).
let buffers = { a: new Float64Array(0), b: new Float64Array(0), scores: new Float64Array(0) };
function scratch(n, lags) {
  if (buffers.a.length < n || buffers.b.length < n * lags || buffers.scores.length < lags) {
    buffers = { a: new Float64Array(n), b: new Float64Array(n * lags), scores: new Float64Array(lags) };
  }
  return buffers;
}
