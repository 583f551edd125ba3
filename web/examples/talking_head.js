// SPDX-License-Identifier: LGPL-2.1-or-later
// A talking head in a page from RTP packets, with no server behind it: the packets of
// docs/examples/hello.pfap are made here (encodePayload, makeRtp), as a sender would send
// them, and handed to a PfapReceiver at their times; each animation frame draws the face at
// the stream time. A live page gets its packets from the network instead (a WebRTC data
// channel, a WebSocket) and maps stream time to its audio clock. talking-head.html uses it;
// serve web/ (for example `python3 -m http.server -d web`) and open examples/talking-head.html.
import { PfapReceiver, encodePayload, findAlphabet, findSymbol, makeRtp } from '../src/index.js';

const CLOCK_RATE = 44100;
const arpabet = findAlphabet('x-pfap-arpabet');

// docs/examples/hello.pfap: start ms, phoneme, duration ms, f0 Hz, flags (W word begin, S
// stress, E end of text), bookmarks as [FAP, amplitude, transition ms, curve].
const HELLO = [
  [0, 'HH', 60, 118, 'W', [[69, 30, 400, 3]]],
  [60, 'AH', 70, 124, '', [[3, 160, 70, 1]]],
  [130, 'L', 60, 128, '', [[3, 80, 60, 1], [4, -40, 60, 1]]],
  [190, 'OW', 170, 136, 'S', [[3, 140, 100, 3], [16, 120, 100, 3], [17, 120, 100, 3]]],
  [360, 'D', 50, 130, 'W', [[3, 60, 50, 1], [4, -20, 50, 1], [16, 0, 50, 1], [17, 0, 50, 1]]],
  [410, 'EH', 110, 126, 'S', [[3, 200, 80, 1], [6, 60, 80, 1], [7, 60, 80, 1]]],
  [520, 'R', 140, 112, 'E', [[3, 90, 120, 1], [6, 0, 120, 1], [7, 0, 120, 1], [16, 80, 120, 3], [17, 80, 120, 3]]],
  [1020, 'HH', 60, 120, 'W', [[3, 100, 60, 1], [16, 0, 60, 1], [17, 0, 60, 1], [31, 80, 300, 3], [32, 80, 300, 3]]],
  [1080, 'AW', 190, 132, 'S', [[3, 260, 90, 3], [16, 60, 190, 1], [17, 60, 190, 1]]],
  [1270, 'AA', 120, 128, 'W', [[3, 240, 60, 1], [16, 0, 60, 1], [17, 0, 60, 1]]],
  [1390, 'R', 80, 124, '', [[3, 120, 80, 1], [16, 70, 80, 1]]],
  [1470, 'Y', 60, 140, 'W', [[3, 60, 60, 1], [6, 80, 60, 1], [7, 80, 60, 1], [16, 0, 60, 1]]],
  [1530, 'UW', 200, 168, 'SE', [[3, 40, 120, 3], [6, 0, 120, 3], [7, 0, 120, 3], [16, 160, 120, 3], [17, 160, 120, 3], [31, 0, 400, 3], [32, 0, 400, 3], [69, 0, 800, 3]]],
];

/**
 * The RTP packets of the hello session: a complete state, then one packet per word (phonemes
 * contiguous, each sentence's first with the marker bit), each with the stream time it is
 * due at.
 * @param {{ssrc?: number, firstSequenceNumber?: number}} [options]
 * @returns {{timeMs: number, bytes: Uint8Array}[]}
 */
export function helloPackets({ ssrc = 0x5eed, firstSequenceNumber = 1000 } = {}) {
  let sequenceNumber = firstSequenceNumber;
  const rtp = (timeMs, marker, packet) => ({
    timeMs,
    bytes: makeRtp({ marker, payloadType: 96, sequenceNumber: sequenceNumber++ & 0xffff, timestamp: Math.round((timeMs * CLOCK_RATE) / 1000), ssrc, payload: encodePayload(packet) }),
  });
  const out = [rtp(0, false, { complete: true, coverage: 0, recovery: [], phonemes: [] })];
  let word = [];
  let sentenceStart = true;
  const flush = () => {
    if (word.length === 0) return;
    out.push(rtp(word[0][0], sentenceStart, { complete: false, coverage: 0, recovery: [], phonemes: word.map(toPhoneme) }));
    sentenceStart = word[word.length - 1][4].includes('E');
    word = [];
  };
  for (const entry of HELLO) {
    if (entry[4].includes('W')) flush();
    word.push(entry);
  }
  flush();
  return out;
}

function toPhoneme([, name, duration, f0, flags, bookmarks]) {
  return {
    symbol: findSymbol(arpabet, name),
    duration,
    f0,
    stress: flags.includes('S'),
    wordBegin: flags.includes('W'),
    endOfText: flags.includes('E'),
    faps: bookmarks.map(([index, amplitude, transition, curve]) => ({ index, amplitude, transition, curve })),
  };
}

/**
 * Plays the hello session on `canvas` over and over: each packet handed to the receiver
 * 100 ms before it is due (a sender's packetization delay), each frame drawn at the stream
 * time; a new SSRC each round, so the receiver starts afresh.
 * @param {HTMLCanvasElement} canvas
 * @param {{style?: 'cartoon'|'line', overlay?: boolean, now?: () => number,
 *          requestFrame?: (callback: () => void) => void, rounds?: number}} [options]
 * @returns {PfapReceiver} the receiver of the current round (for its stats and events)
 */
export function play(canvas, options = {}) {
  const now = options.now ?? (() => performance.now());
  const requestFrame = options.requestFrame ?? ((callback) => requestAnimationFrame(callback));
  const ctx = canvas.getContext('2d');
  const roundMs = 2500;
  let round = 0;
  let start = now();
  let packets = helloPackets({ ssrc: round + 1 });
  let next = 0;
  const receiver = new PfapReceiver({ clockRate: CLOCK_RATE, onWarning: (w) => console.warn(w) });
  const frame = () => {
    let streamMs = now() - start;
    if (streamMs >= roundMs) {
      if (options.rounds !== undefined && round + 1 >= options.rounds) return;
      ++round;
      start += roundMs;
      streamMs -= roundMs;
      packets = helloPackets({ ssrc: round + 1 });
      next = 0;
    }
    while (next < packets.length && packets[next].timeMs <= streamMs + 100) receiver.receive(packets[next++].bytes);
    receiver.draw(ctx, Math.round(streamMs * 1e6), { style: options.style, overlay: options.overlay });
    requestFrame(frame);
  };
  frame();
  return receiver;
}
