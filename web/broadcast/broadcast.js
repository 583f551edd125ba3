// SPDX-License-Identifier: LGPL-2.1-or-later
// The viewer page of the talking head broadcast through Janus (docs/web.md, "Broadcast
// through Janus"): it watches mountpoint 1 of Janus's streaming plugin with Janus's JavaScript
// library (the global Janus, from libjs-janus-gateway), plays its Opus audio, hands the PFAP
// RTP packets of its data stream to a PfapReceiver and draws the face at the PFAP time of the
// audio being played, with pfap-web's clock (../live/playout.js).
//
// Janus gives each viewer audio RTP timestamps of its own, so they say nothing of PFAP time.
// The sender (tools/pfap-broadcast.cc) puts what the page needs on the data stream, beside the
// PFAP packets: the speech's level by PFAP timestamp, ahead of the audio, as binary level
// messages (a first byte of 1, docs/web.md, "The level message"), and as JSON messages (a first
// byte of '{'; no RTP packet starts with either) the PFAP timestamp of the audio as it leaves
// ("clock") and the state as sent at the end ("done"). The first estimate of which PFAP
// time is heard comes from the clock messages and the jitter buffer's delay; the level found
// in the audio played makes it exact, as in pfap-web.
//
// The estimate only says where the level's first match searches: until that match the face
// is drawn from the stream's first sound heard, put at the first sound sent (playout.js).
//
// window.pfapStats holds the figures the browser test reads.
import { PfapReceiver, Viseme, parseRtp } from '../src/index.js';
import { LEVEL_MESSAGE_TYPE, decodeLevelMessage } from '../live/clock.js';
import { lipSyncErrors } from '../live/live.js';
import { DrawnPhonemes, PlayoutClock, drawInTime, showCounts } from '../live/playout.js';

const MOUNTPOINT = 1;
const PFAP_CLOCK_RATE = 44100;
const AUDIO_CLOCK_RATE = 48000;
const JSON_FIRST_BYTE = 0x7b;  // '{': RTP version 1, never an RTP (version 2) packet

export function start({ canvas, audio, status, janusServer }) {
  const stats = {
    phonemes: 0, packets: 0, lost: 0, recovered: 0, complete: 0, uncertain: 0, late: 0,
    lipSyncErrorsMs: [], fapStateMatchesSender: false, sender: null, done: 0, streams: 0,
    wholeAfterMs: null,  // stream time from the first packet to a whole FAP state
    malformed: 0,  // JSON and level messages dropped (PfapReceiver counts the RTP packets it drops)
    reconnects: 0,  // sessions with Janus lost and watched again
    connected: false, dataOpen: false, matched: false, streamNs: 0, endNs: 0,
    envelope: [], frames: [],
  };
  window.pfapStats = stats;
  // The first estimate may be off by the jitter buffer's delay misjudged, and by the page's
  // own delays under load: the first match searches as wide as a lost clock's.
  const clock = new PlayoutClock({ envelope: stats.envelope, audioClockRate: AUDIO_CLOCK_RATE, firstSearchMs: 150 });
  const drawnPhonemes = new DrawnPhonemes(stats.frames);
  const decoder = new TextDecoder();
  let handle = null;
  let audioReceiver = null;
  let jitterBufferMs = 0;  // the audio's delay in the jitter buffer, lately

  // The stream of one SSRC: PFAP timestamps as ms from the first one seen (`ref`).
  let stream = null;
  const newStream = (ssrc, timestamp) => {
    stream = { ssrc, ref: timestamp, firstPfapMs: null, clocks: [], firstReading: null, estimates: [] };
    clock.reset();
    drawnPhonemes.reset();
    stats.sender = null;
    stats.fapStateMatchesSender = false;
    stats.wholeAfterMs = null;
    ++stats.streams;
  };
  const msOf = (timestamp) => ((timestamp - stream.ref) | 0) / (PFAP_CLOCK_RATE / 1000);
  const streamOf = (ssrc, timestamp) => {
    if (!stream || stream.ssrc !== ssrc) newStream(ssrc, timestamp);
  };

  const receiver = new PfapReceiver({
    clockRate: PFAP_CLOCK_RATE,
    onEvent: (e) => {
      if (e.kind === 'phoneme') {
        ++stats.phonemes;
        drawnPhonemes.add(e.timeNs, e.phoneme.viseme === Viseme.PBM);
      }
      if (e.uncertain) ++stats.uncertain;
    },
    onWarning: (w) => console.warn(w),
  });

  const show = () => showCounts(receiver, stats);

  // The sender's state at the end of its stream: every packet has come before it (one port,
  // one ordered channel), and the stream ends with a complete state.
  const compare = () => {
    const state = receiver.recovery.state;
    stats.fapStateMatchesSender = stats.sender.settled.every((v, i) => state.settled(i + 3) === v);
  };

  // Dropped whole and counted; the stream goes on.
  const malformed = (e) => {
    if ((++stats.malformed & (stats.malformed - 1)) === 0) console.warn(`dropped malformed message ${stats.malformed}: ${e.message}`);
  };

  const onMessage = (bytes) => {
    if (bytes[0] === LEVEL_MESSAGE_TYPE) {
      let m;
      try {
        m = decodeLevelMessage(bytes);
      } catch (e) {
        malformed(e);
        return;
      }
      streamOf(m.ssrc, m.timestamp);
      clock.sent.add(msOf(m.timestamp) * 1e6, m.levels);
    } else if (bytes[0] === JSON_FIRST_BYTE) {
      let m;
      try {
        m = JSON.parse(decoder.decode(bytes));
        if (!Number.isInteger(m.ssrc)) throw new Error('no ssrc');
      } catch (e) {
        malformed(e);
        return;
      }
      streamOf(m.ssrc, m.timestamp ?? 0);
      if (m.type === 'clock') {
        stream.clocks.push({ arrived: performance.now(), ms: msOf(m.timestamp) });
        if (stream.clocks.length > 100) stream.clocks.splice(0, 50);
      } else if (m.type === 'done') {
        ++stats.done;
        stats.sender = m;
        compare();
      }
    } else {
      let rtp = null;
      try {
        rtp = parseRtp(bytes);
        streamOf(rtp.ssrc, rtp.timestamp);
        if (stream.firstPfapMs === null) stream.firstPfapMs = msOf(rtp.timestamp);
      } catch {
        // the receiver counts and warns about it
      }
      receiver.receive(bytes);
      if (rtp && stats.wholeAfterMs === null && receiver.stateWhole) {
        stats.wholeAfterMs = msOf(rtp.timestamp) - stream.firstPfapMs;
      }
    }
    show();
  };

  // Which PFAP ms the audio handed to playout at performance time t is: the audio left the
  // sender with a clock message, came about when it did, and waited in the jitter buffer.
  const estimateMs = (t) => {
    const arrived = t - jitterBufferMs;
    const c = stream.clocks.findLast((k) => k.arrived <= arrived) ?? stream.clocks[0];
    return c === undefined ? null : c.ms + (arrived - c.arrived);
  };

  // The PFAP stream time of the audio heard at performance time `now`, or null before the
  // audio and the PFAP stream have both begun.
  function streamNs(now) {
    if (!stream || stream.firstPfapMs === null || !audioReceiver || !clock.context) return null;
    // The readings, while they are used (playout.js: until the level's first match, and at it
    // for the figures).
    if (clock.readingsUsed() || !stats.matched) {
      const source = audioReceiver.getSynchronizationSources()[0];
      if (!source) return null;
      // Janus's timestamps, from an origin of their own: ms since the first reading of the
      // stream, put at PFAP time by the estimate until the level has been matched (the readings
      // say where the first match searches; the face waits for the sound).
      stream.firstReading ??= source.rtpTimestamp;
      const rtpMs = ((source.rtpTimestamp - stream.firstReading) >>> 0) / (AUDIO_CLOCK_RATE / 1000);
      const handedAt = source.timestamp - performance.timeOrigin;
      if (!clock.matched) {
        const estimate = estimateMs(handedAt);
        if (estimate === null) return null;
        stream.base = estimate - rtpMs;
        // For the figures (docs/web.md, "The first syllable").
        if (stream.estimates.length < 120) {
          stream.estimates.push({ t: now, handedAt, rtpMs, jitterBufferMs, latencyMs: clock.latencyMs(), estimate });
        }
      }
      // The chunk it names is heard from its timestamp plus the output's latency on.
      const heardFrom = handedAt + clock.latencyMs();
      clock.reading(heardFrom, rtpMs + stream.base);
      if (!stats.matched && clock.matched) {
        // How far the first estimate was from the level's match (docs/web.md).
        stats.estimateOffMs = rtpMs + stream.base - heardFrom - clock.mappingAt(heardFrom);
        stats.firstMatchAt = now;
        stats.jitterBufferMs = jitterBufferMs;
      }
    }
    stats.matched = clock.matched !== null;
    const running = clock.runningMs(now);
    return running === null ? null : Math.round((running - stream.firstPfapMs) * 1e6);
  }

  drawInTime({ receiver, canvas, stats, streamNs, drawn: drawnPhonemes });
  stats.measureLipSync = () => {
    stats.corrections = clock.corrections;
    stats.polls = clock.polls;
    // The stream's start (docs/web.md, "The first syllable").
    stats.start = {
      trace: clock.startTrace, firstSound: clock.firstSound, estimates: stream?.estimates,
      clocks: stream?.clocks.slice(0, 10), firstPfapMs: stream?.firstPfapMs, phonemes: drawnPhonemes.phonemes.slice(0, 6),
    };
    stats.lipSyncErrorsMs = lipSyncErrors(stats.envelope, stats.frames, { sent: clock.sentForMeasurement() });
    // For the figures: the played audio's onsets alone, as measured before the sender's level
    // was asked (docs/web.md, Lost clocks).
    stats.lipSyncErrorsPlayedMs = lipSyncErrors(stats.envelope, stats.frames);
    stats.clock = clock.record();
  };

  const onTrack = (track, mid, on) => {
    if (!on || track.kind !== 'audio' || audioReceiver) return;
    audioReceiver = handle.webrtcStuff.pc.getReceivers().find((r) => r.track === track);
    const media = new MediaStream([track]);
    // Chromium feeds a remote track to Web Audio only while a media element plays it; the
    // element is muted, the speech heard through the AudioContext, whose tap sees it too.
    audio.srcObject = media;
    audio.play().catch((e) => console.warn(e));
    const context = clock.play(media);
    let last = null;
    clock.followStretching(audioReceiver, (v) => {
      if (last && v.jitterBufferEmittedCount > last.jitterBufferEmittedCount) {
        jitterBufferMs = (v.jitterBufferDelay - last.jitterBufferDelay) /
          (v.jitterBufferEmittedCount - last.jitterBufferEmittedCount) * 1000;
      }
      last = v;
    });
    // Browsers start an AudioContext only after a gesture on the page, unless allowed to.
    for (const gesture of ['pointerdown', 'keydown']) document.addEventListener(gesture, () => context.resume());
  };

  const fail = (what) => (e) => {
    status.textContent = `${what}: ${typeof e === 'string' ? e : JSON.stringify(e)}`;
    console.warn(status.textContent);
  };

  // Watches the mountpoint; when the session with Janus is lost (Janus restarted), watches it
  // again a second later, as a new stream: a new audio track, whose timestamps Janus starts
  // afresh.
  const Janus = window.Janus;
  const watch = () => {
    const janus = new Janus({
      server: janusServer,
      error: (e) => {
        fail('Janus')(e);
        if (handle) {
          handle = null;
          audioReceiver = null;
          stream = null;
          stats.dataOpen = false;
          ++stats.reconnects;
        }
        setTimeout(watch, 1000);
      },
      success: () => janus.attach({
        plugin: 'janus.plugin.streaming',
        error: fail('streaming plugin'),
        success: (h) => {
          handle = h;
          handle.send({ message: { request: 'watch', id: MOUNTPOINT } });
        },
        onmessage: (message, jsep) => {
          if (message.error) fail('watch')(message.error);
          if (!jsep) return;
          handle.createAnswer({
            jsep,
            tracks: [{ type: 'data' }],
            success: (answer) => handle.send({ message: { request: 'start' }, jsep: answer }),
            error: fail('answer'),
          });
        },
        iceState: (state) => {
          status.textContent = state;
          stats.connected = state === 'connected' || state === 'completed';
        },
        onremotetrack: onTrack,
        ondataopen: (label) => {
          handle.webrtcStuff.dataChannel[label].binaryType = 'arraybuffer';
          stats.dataOpen = true;
        },
        ondata: (data) => onMessage(new Uint8Array(data)),
      }),
    });
  };
  Janus.init({ debug: false, callback: watch });
}
