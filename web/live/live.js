// SPDX-License-Identifier: LGPL-2.1-or-later
// The page of tools/pfap-web (docs/web.md): a WebRTC session with the server, the speech
// played from its audio track, the PFAP packets of its data channel handed to a PfapReceiver,
// and the face drawn at each animation frame at the PFAP time of the audio being played.
//
// Timing: the server stamps the audio and the PFAP packets from one running time r, as
// audioTimestampOffset + r * 48000 and pfapTimestampOffset + r * 44100 (mod 2^32), and says
// both offsets once ('timing'). The audio receiver's synchronization source gives the RTP
// timestamp of the audio last played and when, which says roughly which running time is heard
// now; the level of the audio played, found in the level the server sends ('envelope',
// clock.js), says exactly. From it the PfapReceiver's stream time (ns since the first PFAP
// packet's timestamp).
//
// window.pfapStats holds the figures the browser test reads.
import { PfapReceiver, Viseme, parseRtp } from '../src/index.js';
import { decodeLevels } from './clock.js';
import { DrawnPhonemes, PlayoutClock, drawInTime, showCounts } from './playout.js';

// How far from the running time the level's matches put a played onset the sender's silence
// may end (lipSyncErrors). In runs of the Janus test and the benchmark the played onsets of
// syllables came within 3 ms of the sender's as a rule and up to 12.7 ms after it; a p that a
// stall cut at its start and that came back, 16.7 to 28.6 ms after it; a vowel, 46 ms and more.
const SENT_ONSET_MARGIN_MS = 15;

/**
 * Lip sync measured against the sound: each speech onset (the level passing 3 % of the
 * peak) after at least `silenceMs` of silence (under 1 %) in the played audio, paired with
 * the nearest frame within `windowMs` that began drawing lips pressed for p, b or m (the
 * first frame of such a phoneme after one of another): a "pa" sounds as its lips open, at
 * the start of its p, whose closure is the silence before it. The errors are frame time
 * minus onset time.
 *
 * With `sent` (PlayoutClock.sentForMeasurement), an onset counts only if it is one of the
 * sender's too: its level under 1 % of its peak for `silenceMs` up to a moment within
 * SENT_ONSET_MARGIN_MS of the running time the level's matches put the onset at. A vowel that
 * a stall cut and that came back is an onset of the audio played, not of the audio sent: no
 * syllable starts there (docs/web.md, "Lost clocks"). An onset the matches do not place (none,
 * or another stream's) counts.
 * @param {{t: number, rms: number}[]} envelope played audio, 1 ms blocks, performance time
 * @param {{t: number, pressed: boolean}[]} frames drawn frames, performance time
 * @param {{silenceMs?: number, windowMs?: number, sent?: {levelAt: (ms: number) => number,
 *   peak: number, runningMsAt: (t: number) => number|null}}} [options]
 * @returns {number[]} ms
 */
export function lipSyncErrors(envelope, frames, { silenceMs = 30, windowMs = 150, sent = null } = {}) {
  const peak = envelope.reduce((m, e) => Math.max(m, e.rms), 0);
  const sentOnsetAt = (ms) => {
    let quietMs = 0;  // the sender's level under 1 % of its peak for the quietMs before k
    for (let k = Math.floor(ms - SENT_ONSET_MARGIN_MS - silenceMs); k <= ms + SENT_ONSET_MARGIN_MS; ++k) {
      if (quietMs >= silenceMs && k >= ms - SENT_ONSET_MARGIN_MS) return true;
      quietMs = sent.levelAt(k) < sent.peak * 0.01 ? quietMs + 1 : 0;
    }
    return false;
  };
  const sentOnsetNear = (t) => {
    const ms = sent?.runningMsAt(t) ?? null;
    return ms === null || sentOnsetAt(ms);
  };
  const onsets = [];
  let quietSince = -Infinity;
  let quiet = true;
  for (const e of envelope) {
    if (e.rms < peak * 0.01) {
      if (!quiet) quietSince = e.t;
      quiet = true;
    } else if (e.rms > peak * 0.03) {
      if (quiet && e.t - quietSince >= silenceMs && sentOnsetNear(e.t)) onsets.push(e.t);
      quiet = false;
    }
  }
  const closures = [];
  for (let i = 1; i < frames.length; ++i) {
    if (!frames[i - 1].pressed && frames[i].pressed) closures.push(frames[i].t);
  }
  const errors = [];
  for (const onset of onsets) {
    const near = closures.filter((t) => Math.abs(t - onset) <= windowMs);
    if (near.length === 0) continue;
    const best = near.reduce((a, b) => (Math.abs(a - onset) <= Math.abs(b - onset) ? a : b));
    errors.push(Math.round((best - onset) * 100) / 100);
  }
  return errors;
}

export function start({ canvas, audio, form, input, status, saying }) {
  const stats = {
    phonemes: 0,
    packets: 0,
    lost: 0,
    recovered: 0,
    complete: 0,
    uncertain: 0,
    late: 0,
    lipSyncErrorsMs: [],
    fapStateMatchesSender: false,
    sender: null,
    texts: 0,
    done: 0,
    connected: false,
    problem: null,
    streamNs: 0,
    endNs: 0,
    envelope: [],
    frames: [],
  };
  window.pfapStats = stats;
  const ws = new WebSocket(`ws://${location.host}/ws`);
  const send = (m) => ws.readyState === WebSocket.OPEN && ws.send(JSON.stringify(m));
  const pc = new RTCPeerConnection({ iceServers: [] });
  let timing = null;
  let firstPfapTimestamp = null;
  let lastSequenceNumber = null;
  let audioReceiver = null;
  let audioContext = null;
  // The running time heard: from the synchronization source's readings until the played
  // audio's level has been found in the sender's, then from that match and the jitter
  // buffer's stretching since (playout.js, docs/web.md).
  const clock = new PlayoutClock({ envelope: stats.envelope });
  const drawnPhonemes = new DrawnPhonemes(stats.frames);

  const receiver = new PfapReceiver({
    clockRate: 44100,
    onEvent: (e) => {
      if (e.kind === 'phoneme') {
        ++stats.phonemes;
        drawnPhonemes.add(e.timeNs, e.phoneme.viseme === Viseme.PBM);
      }
      if (e.uncertain) ++stats.uncertain;
    },
    onRequestComplete: () => send({ type: 'complete' }),
    onWarning: (w) => console.warn(w),
  });

  const show = () => showCounts(receiver, stats);

  // The sender's FAP state after a text: equal to ours once every packet, or the recovery
  // of those lost, has come. Packets lost at the end have nothing after them to recover
  // them: then the page asks for a complete state (again until one comes).
  const compare = ({ repair }) => {
    const sender = stats.sender;
    if (!sender) return;
    const state = receiver.recovery.state;
    stats.fapStateMatchesSender = sender.settled.every((v, i) => state.settled(i + 3) === v);
    const behind = () => lastSequenceNumber !== sender.lastSequenceNumber;
    if (repair && (behind() || !receiver.stateWhole)) {
      // The message may overtake the last packets (they come another way): they have a
      // while to arrive before they count as lost.
      setTimeout(() => {
        if (stats.sender !== sender) return;
        if (behind()) receiver.lostUnknown();
        if (!receiver.stateWhole) send({ type: 'complete' });
      }, 300);
    }
    show();
  };

  pc.ontrack = (e) => {
    audioReceiver = e.receiver;
    const stream = e.streams[0] ?? new MediaStream([e.track]);
    // Chromium feeds a remote track to Web Audio only while a media element plays it; the
    // element is muted, the speech heard through the AudioContext, whose tap sees it too.
    audio.srcObject = stream;
    audioContext = clock.play(stream);
    clock.followStretching(audioReceiver);
    // The server starts the audio when it is played (tools/pfap-web.cc, start_when_ready).
    // Browsers start an AudioContext only after a gesture on the page, unless allowed to.
    const running = new Promise((resolve) => {
      if (audioContext.state === 'running') resolve();
      audioContext.onstatechange = () => audioContext.state === 'running' && resolve();
    });
    for (const gesture of ['pointerdown', 'keydown']) document.addEventListener(gesture, () => audioContext.resume());
    Promise.all([audio.play(), running]).then(() => send({ type: 'playing' }), (e) => console.warn(e));
  };
  pc.ondatachannel = (e) => {
    e.channel.binaryType = 'arraybuffer';
    e.channel.onmessage = (m) => {
      const bytes = new Uint8Array(m.data);
      try {
        const rtp = parseRtp(bytes);
        if (firstPfapTimestamp === null) firstPfapTimestamp = rtp.timestamp;
        // The newest, as the receiver sees it: a packet overtaken by later ones is not.
        const ahead = (rtp.sequenceNumber - (lastSequenceNumber ?? rtp.sequenceNumber - 1)) & 0xffff;
        if (ahead > 0 && ahead < 0x8000) lastSequenceNumber = rtp.sequenceNumber;
      } catch {
        // the receiver counts and warns about it
      }
      receiver.receive(bytes);
      if (stats.sender) compare({ repair: false });
      show();
    };
  };
  pc.onicecandidate = (e) => {
    if (e.candidate) send({ type: 'ice', candidate: e.candidate.candidate, sdpMLineIndex: e.candidate.sdpMLineIndex });
  };
  // What went wrong stays on the page: the server's reason, or why ICE failed.
  let problem = null;
  const fail = (text) => {
    problem = text;
    stats.problem = text;
    status.textContent = text;
  };
  pc.onconnectionstatechange = () => {
    stats.connected = pc.connectionState === 'connected';
    if (!problem) status.textContent = pc.connectionState;
  };
  pc.oniceconnectionstatechange = () => {
    if (pc.iceConnectionState === 'failed') {
      fail(
          'failed: no network path to the server (ICE failed; docs/web.md, "When the page does not connect")');
    }
  };

  ws.onmessage = async (event) => {
    const m = JSON.parse(event.data);
    if (m.type === 'timing') {
      timing = m;
      // The server's STUN server: a browser that hides its addresses behind mDNS names learns
      // its loopback address from it (tools/pfap-web-stun.h). Set before the offer comes.
      if (m.stunPort) pc.setConfiguration({iceServers: [{urls: `stun:127.0.0.1:${m.stunPort}`}]});
      const text = new URLSearchParams(location.search).get('text');
      if (text) send({ type: 'say', text });
    } else if (m.type === 'offer') {
      await pc.setRemoteDescription({ type: 'offer', sdp: m.sdp });
      const answer = await pc.createAnswer();
      await pc.setLocalDescription(answer);
      send({ type: 'answer', sdp: answer.sdp });
    } else if (m.type === 'ice') {
      await pc.addIceCandidate({ candidate: m.candidate, sdpMLineIndex: m.sdpMLineIndex });
    } else if (m.type === 'envelope') {
      clock.sent.add(m.runningTimeNs, decodeLevels(m.level));
    } else if (m.type === 'saying') {
      ++stats.texts;
      stats.sender = null;
      saying.textContent = `Saying: ${m.text}`;
    } else if (m.type === 'error') {
      fail(`closed by the server: ${m.message}`);
    } else if (m.type === 'done' || (m.type === 'state' && stats.sender)) {
      // The sender's state at the end of a text, then after each complete state asked for
      // (one asked for mid-text is compared at the text's end).
      if (m.type === 'done') ++stats.done;
      stats.sender = m;
      compare({ repair: true });
    }
  };
  ws.onclose = () => {
    if (!problem) status.textContent = 'disconnected';
  };

  form.onsubmit = (e) => {
    e.preventDefault();
    if (input.value.trim()) send({ type: 'say', text: input.value });
  };

  // The PFAP stream time of the audio heard at performance time `now`, or null before the
  // audio and the PFAP stream have both begun.
  function streamNs(now) {
    if (!timing || firstPfapTimestamp === null || !audioReceiver || !audioContext) return null;
    if (clock.readingsUsed()) {
      const source = audioReceiver.getSynchronizationSources()[0];
      if (!source) return null;
      // The chunk it names is heard from its timestamp plus the latency on; until then the
      // readings before hold (they differ when the jitter buffer stretches the audio).
      const heardFrom = source.timestamp - performance.timeOrigin + clock.latencyMs();
      const rtpMs = ((source.rtpTimestamp - timing.audioTimestampOffset) >>> 0) / timing.audioClockRate * 1000;
      clock.reading(heardFrom, rtpMs);
    }
    const running = clock.runningMs(now);
    if (running === null) return null;  // not before the sound says (playout.js)
    const first = ((firstPfapTimestamp - timing.pfapTimestampOffset) >>> 0) / timing.pfapClockRate;
    return Math.round((running / 1000 - first) * 1e9);
  }

  drawInTime({ receiver, canvas, stats, streamNs, drawn: drawnPhonemes });
  // What reached the page's audio, for a test's failure message: the RTP packets and bytes
  // received, the energy decoded from them (0: the server sent silence), the AudioContext's
  // state and how many levels its tap measured (none: it heard nothing at all).
  stats.receivedAudio = async () => {
    const received = { context: audioContext?.state ?? null, levels: stats.envelope.length };
    for (const r of audioReceiver ? (await audioReceiver.getStats()).values() : []) {
      if (r.type === 'inbound-rtp') {
        Object.assign(received, { packets: r.packetsReceived, bytes: r.bytesReceived, energy: r.totalAudioEnergy });
      }
    }
    return received;
  };
  stats.measureLipSync = () => {
    stats.lipSyncErrorsMs = lipSyncErrors(stats.envelope, stats.frames, { sent: clock.sentForMeasurement() });
    stats.lipSyncErrorsPlayedMs = lipSyncErrors(stats.envelope, stats.frames);  // for the figures (docs/web.md)
    stats.clock = clock.record();  // for the figures (docs/web.md)
  };
}
