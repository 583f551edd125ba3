// SPDX-License-Identifier: LGPL-2.1-or-later
// The frame-level viseme detector of align/viseme_detector.{h,cc} in JavaScript, step by
// step the same (tests/web checks that both give the same visemes on the same audio): any
// rate resampled to 16 kHz, 13 MFCCs of a 25 ms window every 10 ms, c1..c12 less their
// running mean over the stream, a small network over the model's frames before (16 in today's) and 4 after
// (align/viseme_model.txt), smoothed into runs of the 15 Oculus visemes. At most 60 ms of audio ahead. docs/align.md, "A viseme detector".

/** The alphabet of the detector's phonemes: symbol k is Oculus viseme k (= MPEG-4 viseme k). */
export const OCULUS_VISEME_ALPHABET = 'x-pfap-oculus-viseme';
/** The Oculus visemes by symbol. */
export const OCULUS_VISEMES = Object.freeze(
  ['sil', 'PP', 'FF', 'TH', 'DD', 'kk', 'CH', 'SS', 'nn', 'RR', 'aa', 'E', 'ih', 'oh', 'ou']);

/** The alphabet as an Animator takes it ({name, symbols}): each symbol shows its viseme. */
export const OCULUS_VISEME_TABLE = Object.freeze({
  name: OCULUS_VISEME_ALPHABET,
  symbols: Object.freeze(OCULUS_VISEMES.map((name, viseme) => Object.freeze({ name, viseme }))),
});

const RATE = 16000;
const HOP = 160;
const WINDOW = 400;
const WINDOW_LEAD = 120;
const MFCCS = 13;
const MIN_RATE = 8000;
const MAX_RATE = 192000;
const FFT = 512;
const BINS = FFT / 2 + 1;
const BANDS = 26;
const LOW_HZ = 100;
const HIGH_HZ = 7600;
const LOG_FLOOR = 1e-10;
const CUTOFF = 0.45;
const ZERO_CROSSINGS = 16;
const AHEAD = 4;
const MAX_PAST = 100;  // frames before; the model file says how many
const MAX_HIDDEN = 1024;  // a hidden layer's units at most
const VISEMES = 15;
const SMOOTH = 1;
const HEADER = 7;
const KIND = 2;  // 2: with the cepstral mean's prior
const NORMALIZATION = 2 * MFCCS + (MFCCS - 1);  // means, scales, cepstral prior
const CEPSTRAL_PRIOR_FRAMES = 100;
const CEPSTRAL_MEAN_FRAMES = 300;
const CEPSTRAL_SOUND_C0 = -35;

/** Audio after a frame's end that settles it, in ms (kVisemeLookaheadMs). */
export const VISEME_LOOKAHEAD_MS =
  ((WINDOW - WINDOW_LEAD - HOP) * 1000) / RATE + (AHEAD + SMOOTH) * 10 + 2.25;

const f32 = Math.fround;
const gcd = (a, b) => (b === 0 ? a : gcd(b, a % b));
const mel = (hz) => 2595 * Math.log10(1 + hz / 700);
const hz = (m) => 700 * (10 ** (m / 2595) - 1);

class Resampler {
  constructor(rate) {
    rate = Math.min(Math.max(rate, MIN_RATE), MAX_RATE);
    this.passthrough = rate === RATE;
    if (this.passthrough) return;
    const g = gcd(rate, RATE);
    this.up = RATE / g;
    this.down = rate / g;
    const f = (2 * CUTOFF * Math.min(rate, RATE)) / rate;
    this.half = Math.ceil(ZERO_CROSSINGS / f);
    this.table = new Float32Array(this.up * 2 * this.half);
    for (let p = 0; p < this.up; p++) {
      const frac = p / this.up;
      for (let t = 0; t < 2 * this.half; t++) {
        const x = t - this.half + 1 - frac;
        const s = x === 0 ? 1 : Math.sin(Math.PI * f * x) / (Math.PI * f * x);
        const w = 0.5 * (1 + Math.cos((Math.PI * x) / this.half));
        this.table[p * 2 * this.half + t] = f * s * w;
      }
    }
    this.input = [];
    this.inStart = 0;
    this.next = 0;
  }

  push(samples, out) {
    if (this.passthrough) {
      for (const s of samples) out.push(f32(s));
      return;
    }
    for (const s of samples) this.input.push(f32(s));
    const have = this.inStart + this.input.length;
    const { up, down, half, table } = this;
    for (;;) {
      const pos = this.next * down;
      const centre = Math.floor(pos / up);
      if (centre + half >= have) break;
      const base = (pos % up) * 2 * half;
      let sum = 0;
      for (let t = 0; t < 2 * half; t++) {
        const i = centre + 1 + t;
        if (i < half) continue;
        sum += table[base + t] * this.input[i - half - this.inStart];
      }
      out.push(f32(sum));
      this.next++;
    }
    const centre = Math.floor((this.next * down) / up);
    const keepFrom = centre + 1 > half ? centre + 1 - half : 0;
    if (keepFrom > this.inStart + Math.floor(this.input.length / 2)) {
      const drop = Math.min(keepFrom - this.inStart, this.input.length);
      this.input.splice(0, drop);
      this.inStart += drop;
    }
  }

  finish(out) {
    if (this.passthrough) return;
    const wanted = Math.ceil(((this.inStart + this.input.length) * this.up) / this.down);
    const rest = [];
    this.push(new Float32Array(this.half + 1), rest);
    const first = this.next - rest.length;
    if (wanted > first) out.push(...rest.slice(0, Math.min(rest.length, wanted - first)));
  }
}

// An in-place radix-2 FFT of FFT points (re, im: Float64Array).
function fft(re, im) {
  for (let i = 1, j = 0; i < FFT; i++) {
    let bit = FFT >> 1;
    for (; (j & bit) !== 0; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) {
      [re[i], re[j]] = [re[j], re[i]];
      [im[i], im[j]] = [im[j], im[i]];
    }
  }
  for (let len = 2; len <= FFT; len <<= 1) {
    const angle = (-2 * Math.PI) / len;
    for (let i = 0; i < FFT; i += len) {
      for (let k = 0; k < len / 2; k++) {
        const wr = Math.cos(angle * k);
        const wi = Math.sin(angle * k);
        const a = i + k;
        const b = a + len / 2;
        const vr = re[b] * wr - im[b] * wi;
        const vi = re[b] * wi + im[b] * wr;
        re[b] = re[a] - vr;
        im[b] = im[a] - vi;
        re[a] += vr;
        im[a] += vi;
      }
    }
  }
}

const tables = (() => {
  const window = new Float32Array(WINDOW);
  for (let i = 0; i < WINDOW; i++) window[i] = 0.5 - 0.5 * Math.cos((2 * Math.PI * i) / (WINDOW - 1));
  const melRows = new Float32Array(BANDS * BINS);
  const edges = [];
  for (let b = 0; b < BANDS + 2; b++) {
    edges.push(hz(mel(LOW_HZ) + ((mel(HIGH_HZ) - mel(LOW_HZ)) * b) / (BANDS + 1)));
  }
  for (let b = 0; b < BANDS; b++) {
    for (let k = 0; k < BINS; k++) {
      const f = (k * RATE) / FFT;
      let w = 0;
      if (f > edges[b] && f <= edges[b + 1]) w = (f - edges[b]) / (edges[b + 1] - edges[b]);
      if (f > edges[b + 1] && f < edges[b + 2]) w = (edges[b + 2] - f) / (edges[b + 2] - edges[b + 1]);
      melRows[b * BINS + k] = w;
    }
  }
  const dct = new Float32Array(MFCCS * BANDS);
  for (let i = 0; i < MFCCS; i++) {
    const scale = Math.sqrt((i === 0 ? 1 : 2) / BANDS);
    for (let j = 0; j < BANDS; j++) dct[i * BANDS + j] = scale * Math.cos((Math.PI * i * (j + 0.5)) / BANDS);
  }
  return { window, melRows, dct };
})();

class MfccFrames {
  constructor() {
    this.buffer = new Array(WINDOW_LEAD).fill(0);
    this.at = 0;  // frame `frames`'s window starts here
    this.frames = 0;
    this.samples = 0;
    this.re = new Float64Array(FFT);
    this.im = new Float64Array(FFT);
  }

  frame(out) {
    const { window, melRows, dct } = tables;
    const { re, im } = this;
    re.fill(0);
    im.fill(0);
    for (let i = 0; i < WINDOW; i++) re[i] = this.buffer[this.at + i] * window[i];
    fft(re, im);
    const power = new Float64Array(BINS);
    for (let k = 0; k < BINS; k++) power[k] = re[k] * re[k] + im[k] * im[k];
    const logmel = new Float64Array(BANDS);
    for (let b = 0; b < BANDS; b++) {
      let e = 0;
      for (let k = 0; k < BINS; k++) e += melRows[b * BINS + k] * power[k];
      logmel[b] = Math.log(Math.max(e, LOG_FLOOR));
    }
    for (let i = 0; i < MFCCS; i++) {
      let c = 0;
      for (let j = 0; j < BANDS; j++) c += dct[i * BANDS + j] * logmel[j];
      out.push(f32(c));
    }
    this.at += HOP;
    this.frames++;
  }

  push(samples, out) {
    for (let i = 0; i < samples.length; i++) this.buffer.push(samples[i]);
    this.samples += samples.length;
    while (this.buffer.length - this.at >= WINDOW) this.frame(out);
    this.buffer.splice(0, this.at);
    this.at = 0;
  }

  finish(out) {
    const total = Math.ceil(this.samples / HOP);
    while (this.frames < total) {
      while (this.buffer.length < this.at + WINDOW) this.buffer.push(0);
      this.frame(out);
    }
  }
}

// A running mean of c1..c12 over the frames of sound, taken from each frame (CepstralMean).
class CepstralMean {
  constructor(prior) {
    this.prior = Float64Array.from(prior);
    this.mean = Float64Array.from(prior);
    this.soundFrames = 0;
  }

  apply(coefficients) {
    for (let at = 0; at + MFCCS <= coefficients.length; at += MFCCS) {
      if (coefficients[at] > CEPSTRAL_SOUND_C0) {
        const alpha = 1 / Math.min(CEPSTRAL_PRIOR_FRAMES + this.soundFrames, CEPSTRAL_MEAN_FRAMES);
        for (let i = 1; i < MFCCS; i++) this.mean[i - 1] += alpha * (coefficients[at + i] - this.mean[i - 1]);
        this.soundFrames++;
      }
      for (let i = 1; i < MFCCS; i++) {
        coefficients[at + i] = f32(coefficients[at + i] - this.mean[i - 1] + this.prior[i - 1]);
      }
    }
  }
}

const SILENCE_FRAME = (() => {
  const out = [];
  new MfccFrames().push(new Float32Array(WINDOW), out);
  return out.slice(0, MFCCS);
})();

/**
 * The network of align/viseme_model.txt, from the file's text.
 * @param {string} text
 */
export function parseVisemeModel(text) {
  const numbers = text
    .replace(/\/\/[^\n]*/g, '')
    .split(',')
    .map((s) => s.trim())
    .filter((s) => s !== '')
    .map(Number);
  const [kind, mfccs, past, ahead, hidden1, hidden2, visemes] = numbers;
  const inputs = (past + 1 + AHEAD) * MFCCS;
  const want = HEADER + NORMALIZATION + hidden1 * (inputs + 1) + hidden2 * (hidden1 + 1) + VISEMES * (hidden2 + 1);
  const whole = (n, low, high) => Number.isInteger(n) && n >= low && n <= high;
  if (kind !== KIND || mfccs !== MFCCS || !whole(past, 0, MAX_PAST) || ahead !== AHEAD || visemes !== VISEMES ||
      !whole(hidden1, 1, MAX_HIDDEN) || !whole(hidden2, 1, MAX_HIDDEN) ||
      numbers.length !== want || numbers.some((n) => !Number.isFinite(n))) {
    throw new Error('not a viseme model of this version (align/viseme_model.txt)');
  }
  return { past, inputs, hidden1, hidden2, params: Float32Array.from(numbers.slice(HEADER)) };
}

// Each layer's output, kept from frame to frame: the audio thread allocates nothing a frame.
const scratch = {
  x: new Float32Array((MAX_PAST + 1 + AHEAD) * MFCCS),
  h1: new Float32Array(MAX_HIDDEN),
  h2: new Float32Array(MAX_HIDDEN),
  logits: new Float32Array(VISEMES),
};

function probabilities(model, context, out) {
  const { params, inputs, hidden1, hidden2 } = model;
  let p = NORMALIZATION;
  const { x, h1, h2, logits } = scratch;
  for (let i = 0; i < inputs; i++) {
    x[i] = f32(context[i] - params[i % MFCCS]) * params[MFCCS + (i % MFCCS)];
  }
  const layer = (input, nIn, nOut, relu, result) => {
    const b = p + nIn * nOut;
    for (let r = 0, w = p; r < nOut; r++, w += nIn) {
      let sum = params[b + r];
      for (let c = 0; c < nIn; c++) sum += params[w + c] * input[c];
      result[r] = relu ? Math.max(0, sum) : sum;
    }
    p += nIn * nOut + nOut;
  };
  layer(x, inputs, hidden1, true, h1);
  layer(h1, hidden1, hidden2, true, h2);
  layer(h2, hidden2, VISEMES, false, logits);
  let top = -Infinity;
  for (let v = 0; v < VISEMES; v++) top = Math.max(top, logits[v]);
  let sum = 0;
  for (let v = 0; v < VISEMES; v++) {
    out[v] = f32(Math.exp(logits[v] - top));
    sum += out[v];
  }
  for (let v = 0; v < VISEMES; v++) out[v] = f32(out[v] / sum);
}

/**
 * The viseme detector, streaming: push audio as it comes, take the runs it settles. A run is
 * {start, frames, viseme}: 10 ms frames from the stream's first sample, an Oculus viseme.
 */
export class VisemeDetector {
  /**
   * @param {number} rate the audio's sample rate (8000..192000 Hz; outside, the nearest)
   * @param {object} options model (parseVisemeModel's), maxRunFrames (0: runs whole; else
   *   longer runs in pieces), switchMargin, minRunFrames (the smoothing), trace (an array
   *   each frame's probabilities are appended to)
   */
  constructor(rate, { model, maxRunFrames = 0, switchMargin = 0.1, minRunFrames = 2, trace = null } = {}) {
    if (!model) throw new Error('VisemeDetector needs a model (parseVisemeModel)');
    this.model = model;
    this.maxRunFrames = maxRunFrames;
    this.switchMargin = f32(switchMargin);
    this.minRunFrames = minRunFrames;
    this.traceTo = trace;
    this.resampler = new Resampler(rate);
    this.mfcc = new MfccFrames();
    this.cepstralMean = new CepstralMean(model.params.subarray(2 * MFCCS, NORMALIZATION));
    this.context = [];
    for (let k = 0; k < model.past; k++) this.context.push(...SILENCE_FRAME);
    this.frameProbabilities = new Float32Array(VISEMES);  // the last frame's, copied out
    this.classified = 0;
    this.probs = [];
    this.decided = 0;
    this.shown = 0;
    this.held = 0;
    this.open = { start: 0, frames: 0, viseme: 0 };
  }

  /** Frames settled so far. */
  get frames() { return this.decided; }

  /**
   * @param {Float32Array|number[]} samples -1..1
   * @returns {{start:number, frames:number, viseme:number}[]} the runs settled
   */
  push(samples) {
    const out = [];
    const resampled = [];
    this.resampler.push(samples, resampled);
    const coefficients = [];
    this.mfcc.push(resampled, coefficients);
    this.cepstralMean.apply(coefficients);
    this.takeFrames(coefficients, out);
    return out;
  }

  /** The stream ends: the rest of the runs. */
  finish() {
    const out = [];
    const resampled = [];
    this.resampler.finish(resampled);
    const coefficients = [];
    this.mfcc.push(resampled, coefficients);
    this.mfcc.finish(coefficients);
    this.cepstralMean.apply(coefficients);
    this.takeFrames(coefficients, out);
    while (this.classified < this.mfcc.frames) this.takeFrames(SILENCE_FRAME, out);
    while (this.decided < this.classified) this.decide(out);
    if (this.open.frames > 0) out.push(this.open);
    this.open = { start: this.decided, frames: 0, viseme: this.shown };
    return out;
  }

  takeFrames(coefficients, out) {
    for (let at = 0; at < coefficients.length; at += MFCCS) {
      for (let i = 0; i < MFCCS; i++) this.context.push(coefficients[at + i]);
      if (this.context.length < this.model.inputs) continue;
      const p = this.frameProbabilities;
      probabilities(this.model, this.context, p);
      if (this.traceTo) this.traceTo.push(...p);
      this.probs.push(...p);
      this.classified++;
      if (this.classified > SMOOTH) this.decide(out);
      this.context.splice(0, MFCCS);
    }
  }

  decide(out) {
    const first = this.classified - this.probs.length / VISEMES;
    const from = Math.max(first, this.decided >= SMOOTH ? this.decided - SMOOTH : 0);
    const to = Math.min(this.classified, this.decided + SMOOTH + 1);
    const mean = new Float32Array(VISEMES);
    for (let k = from; k < to; k++) {
      for (let v = 0; v < VISEMES; v++) mean[v] = f32(mean[v] + this.probs[(k - first) * VISEMES + v]);
    }
    let best = 0;
    for (let v = 1; v < VISEMES; v++) if (mean[v] > mean[best]) best = v;
    const margin = f32(this.switchMargin * (to - from));
    if (best !== this.shown && mean[best] > f32(mean[this.shown] + margin) && this.held >= this.minRunFrames) {
      if (this.open.frames > 0) out.push(this.open);
      this.shown = best;
      this.open = { start: this.decided, frames: 0, viseme: best };
      this.held = 0;
    }
    if (this.open.frames === 0) this.open = { start: this.decided, frames: 0, viseme: this.shown };
    this.open.frames++;
    this.held++;
    if (this.maxRunFrames > 0 && this.open.frames >= this.maxRunFrames) {
      out.push(this.open);
      this.open = { start: this.decided + 1, frames: 0, viseme: this.shown };
    }
    this.decided++;
    const keepFrom = this.decided >= SMOOTH ? this.decided - SMOOTH : 0;
    if (keepFrom > first) this.probs.splice(0, (keepFrom - first) * VISEMES);
  }
}
