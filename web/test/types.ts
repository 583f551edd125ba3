// SPDX-License-Identifier: LGPL-2.1-or-later
// What a TypeScript page writes against src/index.d.ts; package.test.js type-checks it with
// tsc --strict (it is not run).
import {
  FapState, PfapReceiver, RecoveryReceiver, decodePayload, encodePayload, parseRtp, poseFromFaps, renderFace,
  type Fap, type Packet, type ReceiverEvent,
} from '../src/index.js';

const fap: Fap = { index: 69, amplitude: 40, transition: 2000, curve: 3 };
const packet: Packet = {
  complete: false, coverage: 0, recovery: [],
  phonemes: [{ symbol: 7, duration: 80, f0: 0, stress: false, wordBegin: true, endOfText: false, faps: [fap] }],
};
const result = decodePayload(encodePayload(packet));
if (result.ok) {
  const phonemes: number = result.packet.phonemes.length;
  console.log(phonemes);
} else {
  const where: number = result.offset;
  const what: 'kTruncated' | string = result.error;
  console.log(what, where);
}
const rtp = parseRtp(new Uint8Array(12));
const seq: number = rtp.sequenceNumber;

const state = new FapState();
state.apply(fap, 0);
const amplitude: number = state.amplitude(69, 1_000_000);
const recovery = new RecoveryReceiver({ retryNs: 2e9 });
const r = recovery.receive(packet, seq, 0);
const kind: 'none' | 'recovered' | 'complete' = r.recovery;

const events: ReceiverEvent[] = [];
const receiver = new PfapReceiver({
  clockRate: 44100,
  onEvent: (e) => events.push(e),
  onRequestComplete: ({ ssrc }) => console.log(ssrc),
});
for (const e of receiver.receive(new Uint8Array(0))) console.log(e.phoneme?.name, e.timeNs);
declare const ctx: CanvasRenderingContext2D;
receiver.draw(ctx, 0, { style: 'line' });
renderFace(ctx, poseFromFaps(receiver.faps(0)), { style: 'cartoon', overlay: 'AA' });
console.log(amplitude, kind, receiver.stats.lost, receiver.stateWhole);
