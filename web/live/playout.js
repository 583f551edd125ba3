// SPDX-License-Identifier: LGPL-2.1-or-later
// The clock of a page that draws a face in time with the speech it plays (docs/web.md,
// Timing): which running time of the sender's audio is heard at a given moment. Shared by
// pfap-web's page (live.js) and the broadcast page (../broadcast/broadcast.js).
//
// The page plays the speech through Web Audio and taps it (tap.js); its readings of the audio
// receiver's synchronization source say roughly which running time is heard, the played
// level found in the level the sender sent (clock.js) says exactly, and between matches the
// jitter buffer's stretching (getStats) is followed.
import { SentLevel, matchLevels } from './clock.js';

// The value of `history` ([from, value], in order) at heard time t.
const valueAt = (history, t, otherwise) => {
  for (let i = history.length - 1; i >= 0; --i) if (history[i][0] <= t) return history[i][1];
  return history.length > 0 ? history[0][1] : otherwise;
};
const remember = (history, from, value) => {
  if (history.length === 0 || history.at(-1)[1] !== value) history.push([from, value]);
  if (history.length > 1000) history.splice(0, 500);
};

export class PlayoutClock {
  /**
   * @param {{envelope: {t: number, rms: number}[], audioClockRate?: number, searchMs?: number,
   *   firstSearchMs?: number}} options `envelope` receives the tap's level of what is heard
   *   (1 ms blocks, performance time); the first match searches ±firstSearchMs around the
   *   readings, later ones ±searchMs around the last match, and ±lostSearchMs after 300 ms of
   *   sound heard without a match (the clock is lost: NetEq's concealment when packets come
   *   late moves the audio by more than the search, and getStats' stretch counts leave it
   *   out).
   */
  constructor({ envelope, audioClockRate = 48000, searchMs = 50, firstSearchMs = searchMs, lostSearchMs = 150 }) {
    this.envelope = envelope;
    this.audioClockRate = audioClockRate;
    this.searchMs = searchMs;
    this.firstSearchMs = firstSearchMs;
    this.lostSearchMs = lostSearchMs;
    this.context = null;
    this.reset();
  }

  /** A new stream: what was known of the last one goes. */
  reset() {
    this.sent = new SentLevel();
    this.readings = [];  // [heard from, running time less heard time]
    this.stretches = [];  // [heard from, samples removed less inserted]
    this.matched = null;  // {m: running time less heard time, stretch: the stretch then}
    this.corrections = [];  // {t: heard time, lag: ms}
    this.misses = 0;  // tap messages since the last match whose window held sound
    // The stream's start, for the figures (docs/web.md, the first syllable): the running time
    // each of the first frames was drawn at and whether it rested on a match.
    this.startTrace = [];
  }

  /**
   * Plays `stream` through an AudioContext at 48 kHz (Opus's rate: nothing resamples between
   * WebRTC and the tap), tapped. Returns the context; it runs after a gesture on the page
   * unless the browser allows autoplay.
   */
  play(stream) {
    this.context?.close();  // a page that plays a new track (a new session) plays it alone
    this.context = new AudioContext({ latencyHint: 'interactive', sampleRate: 48000 });
    const source = this.context.createMediaStreamSource(stream);
    source.connect(this.context.destination);
    this.context.audioWorklet.addModule(new URL('./tap.js', import.meta.url)).then(() => {
      const tap = new AudioWorkletNode(this.context, 'pfap-tap');
      source.connect(tap);
      tap.port.onmessage = (m) => {
        // AudioContext time to performance time, at the output (what is heard when).
        const { contextTime, performanceTime } = this.context.getOutputTimestamp();
        const data = m.data;
        for (let i = 0; i < data.length; i += 2) {
          this.envelope.push({ t: performanceTime + (data[i] - contextTime) * 1000, rms: data[i + 1] });
        }
        if (this.envelope.length > 200000) this.envelope.splice(0, 100000);
        this.matchHeard();
      };
    });
    this.context.resume();
    return this.context;
  }

  /** The output's latency, which the synchronization source's timestamp is before the sound. */
  latencyMs() {
    return (this.context.baseLatency + (this.context.outputLatency || 0)) * 1000;
  }

  /** A reading: the audio of running time `runningMs` is heard from performance time `heardFrom`. */
  reading(heardFrom, runningMs) {
    remember(this.readings, heardFrom, runningMs - heardFrom);
  }

  /**
   * Follows the jitter buffer's stretching (getStats of `receiver`, an RTCRtpReceiver), from
   * when it is heard: a poll sees a change some time in the 25 ms before it, which is heard
   * the output's latency later. `onStats` sees each inbound-rtp report.
   */
  followStretching(receiver, onStats = () => {}) {
    setInterval(async () => {
      if (!this.context) return;
      const polled = performance.now();
      (await receiver.getStats()).forEach((v) => {
        if (v.type !== 'inbound-rtp') return;
        const net = (v.removedSamplesForAcceleration ?? 0) - (v.insertedSamplesForDeceleration ?? 0);
        remember(this.stretches, polled - 12.5 + this.latencyMs(), net);
        onStats(v, polled);
      });
    }, 25);
  }

  /** Running time (ms) less performance time, at performance time t; null before any reading. */
  mappingAt(t) {
    if (!this.matched) return valueAt(this.readings, t, null);
    return this.matched.m + (valueAt(this.stretches, t, 0) - this.matched.stretch) / (this.audioClockRate / 1000);
  }

  /** The running time (ms) heard at performance time `now`, or null before any reading. */
  runningMs(now) {
    const m = this.mappingAt(now);
    if (m === null) return null;
    if (this.startTrace.length < 120) this.startTrace.push({ t: now, ms: now + m, matched: this.matched !== null });
    return now + m;
  }

  // The last 150 ms of the audio played, found in the sender's level (clock.js).
  matchHeard() {
    const env = this.envelope;
    if (env.length === 0 || this.readings.length === 0) return;
    const newest = env.at(-1).t;
    const heard = [];
    for (let i = env.length - 1; i >= 0 && env[i].t >= newest - 150; --i) {
      heard.push({ x: env[i].t + this.mappingAt(env[i].t), rms: env[i].rms });
    }
    const searchMs = !this.matched ? this.firstSearchMs : this.misses >= 30 ? this.lostSearchMs : this.searchMs;
    const lag = matchLevels(heard.reverse(), (ms) => this.sent.at(ms), { searchMs });
    if (lag === null) {
      const peak = heard.reduce((m, h) => Math.max(m, h.rms), 0);
      if (this.matched && peak > 1e-3 && heard.filter((h) => h.rms > peak * 0.1).length >= 20) ++this.misses;
      return;
    }
    this.misses = 0;
    this.matched = { m: this.mappingAt(newest) + lag, stretch: valueAt(this.stretches, newest, 0) };
    // Each match's correction, for the figures (docs/web.md).
    this.corrections.push({ t: newest, lag });
    if (this.corrections.length > 2000) this.corrections.splice(0, 1000);
  }
}

/**
 * Which phoneme is drawn when, for the lip-sync measurement (live.js, lipSyncErrors): each
 * frame drawn at stream time `ns` is recorded in `frames` with whether its phoneme presses
 * the lips.
 */
export class DrawnPhonemes {
  constructor(frames) {
    this.frames = frames;
    this.phonemes = [];  // {timeNs, pressed}
    this.drawn = 0;  // the phoneme drawn last
  }

  add(timeNs, pressed) {
    this.phonemes.push({ timeNs, pressed });
  }

  /** A new stream, whose times start again. */
  reset() {
    this.phonemes = [];
    this.drawn = 0;
  }

  frame(now, ns) {
    const { phonemes } = this;
    while (this.drawn + 1 < phonemes.length && phonemes[this.drawn + 1].timeNs <= ns) ++this.drawn;
    const pressed = this.drawn < phonemes.length && phonemes[this.drawn].timeNs <= ns && phonemes[this.drawn].pressed;
    this.frames.push({ t: now, pressed });
    if (this.frames.length > 20000) this.frames.splice(0, 10000);
  }
}

/**
 * Draws the face at each animation frame at the stream time `streamNs(now)` gives (null: not
 * yet), and keeps what the browser tests read: which phoneme each frame draws (`drawn`, a
 * DrawnPhonemes), `stats.streamNs` and `stats.endNs`.
 */
export function drawInTime({ receiver, canvas, stats, streamNs, drawn }) {
  const ctx = canvas.getContext('2d');
  const frame = (now) => {
    const ns = streamNs(now);
    if (ns !== null) {
      stats.streamNs = ns;
      stats.endNs = receiver.animator.endNs;
      receiver.draw(ctx, ns, { style: 'cartoon' });
      drawn.frame(now, ns);
    }
    requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
}

/** The receiver's counts, into `stats` and the page's table (a cell with each key as its id). */
export function showCounts(receiver, stats) {
  const s = receiver.stats;
  Object.assign(stats, { packets: s.packets, lost: s.lost, recovered: s.recovered, complete: s.completeStates, late: s.late });
  for (const key of ['phonemes', 'packets', 'lost', 'late', 'recovered', 'complete', 'uncertain']) {
    document.getElementById(key).textContent = String(stats[key]);
  }
  document.getElementById('matches').textContent = stats.sender ? (stats.fapStateMatchesSender ? 'yes' : 'no') : '-';
}
