// SPDX-License-Identifier: LGPL-2.1-or-later
// The clock of a page that draws a face in time with the speech it plays (docs/web.md,
// Timing): which running time of the sender's audio is heard at a given moment. Shared by
// pfap-web's page (live.js) and the broadcast page (../broadcast/broadcast.js).
//
// The page plays the speech through Web Audio and taps it (tap.js); its readings of the audio
// receiver's synchronization source say roughly which running time is heard, the played
// level found in the level the sender sent (clock.js) says exactly, and between matches the
// jitter buffer's stretching and the concealment that delays the audio (getStats) are followed.
import { AnimationFrames } from '../src/index.js';
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

// The stream's first sound (PlayoutClock.findFirstSound): a level of 100 in S16 RMS units
// (-50 dBFS), which a "pa"'s p passes within 2 ms of its onset, after 100 ms under it.
const FIRST_SOUND_RMS = 100;
const FIRST_SOUND_QUIET_MS = 100;
// The audio's packet duration (the senders' Opus frames): what NetEq conceals for a lost packet.
const PACKET_S = 0.02;
// How much better than the peak the clock is on another lag must score for a match to move
// the clock there (matchLevels' holdMargin): above the near ties of a voiced level's pitch
// periods seen in pages (0.001 to 0.014), below what a real move scored (0.13 and more).
const HOLD_MARGIN = 0.03;
// Silent concealment for longer than this, with no audio decoded, is the audio's end, not a stall.
const SILENT_END_MS = 500;

export class PlayoutClock {
  /**
   * @param {{envelope: {t: number, rms: number}[], audioClockRate?: number, searchMs?: number,
   *   firstSearchMs?: number, lostSearchMs?: number, firstSoundSearchMs?: number}} options
   *   `envelope` receives the tap's level of what is heard (1 ms blocks, performance time);
   *   the first match searches ±firstSearchMs around the readings, later ones ±searchMs around
   *   the last match, and ±lostSearchMs after 300 ms of sound heard without a match (the clock
   *   is lost: the audio moved by more than the search, by what getStats does not count). Until the first match the clock
   *   draws from the stream's first sound, if it lies within ±firstSoundSearchMs of where the
   *   readings put it (findFirstSound), and not at all without it.
   */
  constructor({
    envelope, audioClockRate = 48000, searchMs = 50, firstSearchMs = searchMs, lostSearchMs = 150, firstSoundSearchMs = 500,
  }) {
    this.envelope = envelope;
    this.audioClockRate = audioClockRate;
    this.searchMs = searchMs;
    this.firstSearchMs = firstSearchMs;
    this.lostSearchMs = lostSearchMs;
    this.firstSoundSearchMs = firstSoundSearchMs;
    this.context = null;
    this.reset();
  }

  /** A new stream: what was known of the last one goes. */
  reset() {
    this.sent = new SentLevel();
    this.readings = [];  // [heard from, running time less heard time]
    this.stretches = [];  // [heard from, samples removed less inserted less concealed late]
    this.concealedLate = 0;  // samples of concealment that delayed the audio, from the first match on
    this.counted = null;  // the last poll's concealment counts
    this.silentRun = 0;  // samples of silent concealment since audio was last decoded
    this.matched = null;  // {m: running time less heard time, stretch: the stretch then}
    // The stream's first sound heard put at the first sound sent: the mapping from the sound
    // until the level's first match ({m, stretch} as `matched`, and `t`, when it is heard).
    this.firstSound = null;
    this.firstSoundTried = false;  // the first sound heard since the reset has been looked at
    this.scannedTo = this.envelope.at(-1)?.t ?? -Infinity;  // heard since the reset: after this
    this.corrections = [];  // each match: {t: heard time, lag: ms, m, stretch: as `matched`}
    this.resetAt = this.scannedTo;  // heard before this: another stream's
    this.misses = 0;  // tap messages since the last match whose window held sound
    this.polls = [];  // getStats' inbound-rtp counters at each poll, for the figures
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

  /**
   * Whether the synchronization source's readings are still used: until the level's first
   * match (they say where it searches, and where the stream's first sound was sent); after it
   * the matches and getStats' counts say all. A page reads them only while they are used:
   * getSynchronizationSources() waits for WebRTC's worker thread, and under load took 7 % of
   * a page's main thread, called at each frame (docs/web.md).
   */
  readingsUsed() {
    return this.matched === null;
  }

  /** A reading: the audio of running time `runningMs` is heard from performance time `heardFrom`. */
  reading(heardFrom, runningMs) {
    remember(this.readings, heardFrom, runningMs - heardFrom);
  }

  /**
   * Follows the jitter buffer's stretching (getStats of `receiver`, an RTCRtpReceiver), from
   * when it is heard: a poll sees a change some time in the 25 ms before it, which is heard
   * the output's latency later. `onStats` sees each inbound-rtp report. A new receiver (the
   * page watches again) replaces the last: two series of counts would mix.
   */
  followStretching(receiver, onStats = () => {}) {
    clearInterval(this.polling);
    this.polling = setInterval(async () => {
      if (!this.context) return;
      const polled = performance.now();
      (await receiver.getStats()).forEach((v) => {
        if (v.type !== 'inbound-rtp') return;
        this.statsPolled(v, polled, this.latencyMs());
        onStats(v, polled);
      });
    }, 25);
  }

  /**
   * One poll's inbound-rtp report `v`, taken at performance time `polled` (followStretching).
   * Besides the stretching, the concealment that delays the audio (docs/web.md, Lost clocks):
   * when NetEq runs dry it conceals until packets come and then plays them, as late as it
   * concealed. Counted from the last poll before the level's first match on: concealedSamples
   * also holds the silence played before any audio came, and under load a poll can come 130 ms
   * after the one before it, a stall between them lost to a count started after the match. Not
   * a lost packet's (packetsLost), after which the next is played on time. NetEq fades a long
   * concealment to silence (silentConcealedSamples): past SILENT_END_MS of it with no audio
   * decoded, the audio has ended (the stream's end, Janus gone) and the silence is taken back,
   * so that the clock runs on past the end.
   */
  statsPolled(v, polled, latencyMs) {
    const counts = {
      concealed: v.concealedSamples ?? 0, silent: v.silentConcealedSamples ?? 0, lost: v.packetsLost ?? 0,
      decoded: v.jitterBufferEmittedCount ?? 0,
    };
    if (this.matched !== null) {
      const d = Object.fromEntries(Object.entries(counts).map(([k, n]) => [k, n - (this.counted?.[k] ?? n)]));
      // Fewer than before: a new receiver, whose counts start again.
      if (Object.values(d).every((n) => n >= 0)) {
        const end = SILENT_END_MS * (this.audioClockRate / 1000);
        const before = this.silentRun;
        this.silentRun = d.decoded > 0 ? 0 : before + d.silent;
        let late = Math.max(0, d.concealed - d.lost * this.audioClockRate * PACKET_S);
        if (this.silentRun > end) late -= before > end ? d.silent : before + d.silent;
        this.concealedLate += late;
      }
    }
    this.counted = counts;
    const net = (v.removedSamplesForAcceleration ?? 0) - (v.insertedSamplesForDeceleration ?? 0) - this.concealedLate;
    remember(this.stretches, polled - 12.5 + latencyMs, net);
    this.polls.push({
      t: polled, concealed: v.concealedSamples, silentConcealed: v.silentConcealedSamples, events: v.concealmentEvents,
      received: v.totalSamplesReceived, duration: v.totalSamplesDuration, jbDelay: v.jitterBufferDelay,
      jbEmitted: v.jitterBufferEmittedCount, net, packets: v.packetsReceived, lost: v.packetsLost,
    });
    if (this.polls.length > 4000) this.polls.splice(0, 2000);
  }

  /**
   * Running time (ms) less performance time, at performance time t, as the sound says: from the
   * last match, else from the stream's first sound; null before either. The readings alone
   * are not enough to draw by: through Janus they put a stream's start tens to hundreds of ms
   * ahead of its sound (docs/web.md, "The first syllable").
   */
  mappingAt(t) {
    const from = this.matched ?? this.firstSound;
    if (!from) return null;
    return from.m + (valueAt(this.stretches, t, 0) - from.stretch) / (this.audioClockRate / 1000);
  }

  /** The running time (ms) heard at performance time `now`, or null until the sound says. */
  runningMs(now) {
    const m = this.mappingAt(now);
    if (m === null) return null;
    if (this.startTrace.length < 120) this.startTrace.push({ t: now, ms: now + m, matched: this.matched !== null });
    return now + m;
  }

  /**
   * The running time (ms) heard at performance time t as the level's matches say, not as the
   * clock drew it: by the first match after t (its window, the 150 ms heard before it, holds t
   * unless the clock was lost, and then it is the match that found the audio again), carried
   * back over the stretching and concealment followed between; else by the last match. Null
   * without a match, or for a time heard before the stream began. Off by as much as the audio
   * jumped between t and that match by what getStats does not count (20 ms, seen under load).
   */
  matchedRunningMs(t) {
    if (t <= this.resetAt) return null;
    const match = this.corrections.find((c) => c.t >= t) ?? this.corrections.at(-1);
    if (!match) return null;
    return t + match.m + (valueAt(this.stretches, t, 0) - match.stretch) / (this.audioClockRate / 1000);
  }

  /**
   * What the figures keep of the clock, to look at each lip-sync error afterwards (docs/web.md,
   * "Lost clocks"): its matches, what it followed of getStats, the sender's level.
   */
  record() {
    const sent = this.sent.segments.map(({ startMs, levels }) => ({ startMs, levels: Array.from(levels) }));
    return { matches: this.corrections, stretches: this.stretches, resetAt: this.resetAt, sent };
  }

  /** What lipSyncErrors (live.js) takes of the sender: its level and where the matches put the sound heard. */
  sentForMeasurement() {
    return { levelAt: (ms) => this.sent.at(ms), peak: this.sent.peak(), runningMsAt: (t) => this.matchedRunningMs(t) };
  }

  // The first match searches around the readings, later ones around the last match.
  searchMappingAt(t) {
    return this.matched ? this.mappingAt(t) : valueAt(this.readings, t, null);
  }

  // The stream's first sound: the first block heard since the reset at FIRST_SOUND_RMS or more,
  // after at least FIRST_SOUND_QUIET_MS of blocks under it (heard before the reset too: the
  // sender's first message leaves with its first audio), put at the first millisecond of the
  // sender's level at FIRST_SOUND_RMS or more, if that lies within ±firstSoundSearchMs of where
  // the readings put it. A page that came in mid-sound (a late joiner) has none and waits for
  // the level's match; so does one whose level holds no sound 1 s after it heard some.
  findFirstSound() {
    const env = this.envelope;
    let i = env.length;
    while (i > 0 && env[i - 1].t > this.scannedTo) --i;
    for (; i < env.length; ++i) {
      const { t, rms } = env[i];
      if (rms * 32768 >= FIRST_SOUND_RMS) {
        const reading = valueAt(this.readings, t, null);
        const sentMs = this.sent.firstAtLeast(FIRST_SOUND_RMS);
        if (sentMs === null && env.at(-1).t - t < 1000) return;  // its level may yet come
        this.firstSoundTried = true;
        let j = i - 1;
        while (j >= 0 && env[j].t >= t - FIRST_SOUND_QUIET_MS && env[j].rms * 32768 < FIRST_SOUND_RMS) --j;
        const quiet = j >= 0 && env[j].t < t - FIRST_SOUND_QUIET_MS;
        if (quiet && sentMs !== null && Math.abs(sentMs - (t + reading)) <= this.firstSoundSearchMs) {
          this.firstSound = { m: sentMs - t, stretch: valueAt(this.stretches, t, 0), t };
        }
        return;
      }
      this.scannedTo = t;
    }
  }

  // The last 150 ms of the audio played, found in the sender's level (clock.js).
  matchHeard() {
    const env = this.envelope;
    if (env.length === 0 || this.readings.length === 0) return;
    if (!this.firstSoundTried) this.findFirstSound();
    const newest = env.at(-1).t;
    const heard = [];
    for (let i = env.length - 1; i >= 0 && env[i].t >= newest - 150; --i) {
      heard.push({ x: env[i].t + this.searchMappingAt(env[i].t), rms: env[i].rms });
    }
    const searchMs = !this.matched ? this.firstSearchMs : this.misses >= 30 ? this.lostSearchMs : this.searchMs;
    // A clock that has matched and is not lost stays on its peak unless another is clearly
    // better: not one pitch period off on a near tie (matchLevels).
    const holdMargin = this.matched && this.misses < 30 ? HOLD_MARGIN : 0;
    const lag = matchLevels(heard.reverse(), this.sent, { searchMs, holdMargin });
    if (lag === null) {
      const peak = heard.reduce((m, h) => Math.max(m, h.rms), 0);
      if (this.matched && peak > 1e-3 && heard.filter((h) => h.rms > peak * 0.1).length >= 20) ++this.misses;
      return;
    }
    this.misses = 0;
    this.matched = { m: this.searchMappingAt(newest) + lag, stretch: valueAt(this.stretches, newest, 0) };
    // Each match, for the figures (docs/web.md) and matchedRunningMs.
    this.corrections.push({ t: newest, lag, ...this.matched });
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
 * Draws the face at each animation frame at the stream time `streamNs(t)` gives (null: not
 * yet) for the moment t the frame shows (AnimationFrames), and keeps what the browser tests
 * read: which phoneme each frame draws (`drawn`, a DrawnPhonemes, at the frame's own time),
 * `stats.streamNs` and `stats.endNs`.
 */
export function drawInTime({ receiver, canvas, stats, streamNs, drawn }) {
  const ctx = canvas.getContext('2d');
  const frames = new AnimationFrames();
  const frame = (now) => {
    const ns = streamNs(frames.drawTime(now));
    if (ns !== null) {
      stats.streamNs = ns;
      stats.endNs = receiver.animator.endNs;
      // The face is drawn again only where it changed (PfapReceiver.draw): in the pauses and
      // after the speech nothing is drawn, and Chromium composites nothing new.
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
