// SPDX-License-Identifier: LGPL-2.1-or-later
// A PFAP receiver for a page or a Node program: RTP packets in (Uint8Array), events with their
// times in the stream's clock out, and the face at any time. The same steps as rtppfapdepay
// (gst/pfap/gstrtppfapdepay.cc) followed by pfapface's animator: RTP header, payload decoder,
// recovery receiver, then phoneme and state events.

import { Animator } from './animator.js';
import { poseFromFaps } from './face_model.js';
import { NS_PER_MS } from './model.js';
import { decodePayload } from './payload.js';
import { ARPABET_ALPHABET, findAlphabet, findPhoneme } from './phoneme_table.js';
import { RecoveryReceiver } from './recovery.js';
import { renderFace } from './renderer.js';
import { RtpError, parseRtp } from './rtp.js';

/** The draft's default RTP clock (section 7). */
export const DEFAULT_CLOCK_RATE = 44100;

// Events not yet drawn are kept for the face until a draw reaches their time; a program that
// never draws applies the oldest beyond this many, so that memory stays bounded.
const MAX_PENDING_EVENTS = 4096;

// 1st, 2nd, 4th, 8th... occurrence: per-item warnings rate-limited as rtppfapdepay's.
function warnAt(count) {
  return count > 0 && (count & (count - 1)) === 0;
}

// RTP ticks from the stream's first timestamp to ns, exact for any stream length: whole
// seconds and the rest apart, so that no product leaves the doubles' exact integers.
function ticksToNs(ticks, clockRate) {
  const seconds = Math.floor(ticks / clockRate);
  const rest = ticks - seconds * clockRate;
  return seconds * 1e9 + Math.round((rest * 1e9) / clockRate);
}

/**
 * The whole receiver: RTP packets in (receive), events with their stream times out (onEvent),
 * and the talking head at any stream time (faps, pose, draw), as rtppfapdepay ! pfapface.
 */
export class PfapReceiver {
  /**
   * @param {import('./index.js').PfapReceiverOptions} [options]
   */
  constructor(options = {}) {
    this.clockRate = options.clockRate ?? DEFAULT_CLOCK_RATE;
    this.payloadType = options.payloadType ?? null;
    const alphabetName = options.alphabet === undefined ? ARPABET_ALPHABET : options.alphabet;
    this.alphabet = alphabetName === null ? null : findAlphabet(alphabetName);
    this.onEvent = options.onEvent ?? null;
    this.onRequestComplete = options.onRequestComplete ?? null;
    this.onWarning = options.onWarning ?? null;
    this.recovery = new RecoveryReceiver({ retryNs: options.retryNs });
    this.animator = new Animator(this.alphabet);
    this._pending = []; // events received whose time the face has not reached, oldest first
    this._drawn = null; // what the last draw() put on its canvas: {ctx, width, height, style, overlay, faps}
    /** Counters, as rtppfapdepay's stats property. */
    this.stats = {
      packets: 0, malformedRtp: 0, malformedPayload: 0, otherPayloadType: 0, late: 0, phonemes: 0,
      faps: 0, lost: 0, gaps: 0, recovered: 0, completeStates: 0, requests: 0,
    };
    this._ssrc = null;
    this._lastSequenceNumber = null;
    this._extTimestamp = 0; // the last timestamp, unwrapped, in ticks since the SSRC's first
    this._lastTimestamp = 0;
  }

  /** False while the FAP state may be wrong (after a loss no recovery spanned, or a join). */
  get stateWhole() {
    return this.recovery.stateWhole;
  }

  /** How many events received the face has not reached yet (advance() takes them). */
  get pendingEvents() {
    return this._pending.length;
  }

  _warn(kind, message) {
    const count = ++this.stats[kind];
    if (this.onWarning && warnAt(count)) this.onWarning(`${message} (${count} so far)`);
  }

  /**
   * Takes one RTP packet; returns the events it gives, in order (also passed to onEvent). The
   * face takes them when advance(), faps(), pose() or draw() reach their times.
   * A malformed packet gives none and is counted (stats) and warned about (onWarning, at the
   * 1st, 2nd, 4th... of a kind); the stream goes on.
   * @param {Uint8Array} bytes
   * @returns {import('./index.js').ReceiverEvent[]}
   */
  receive(bytes) {
    let rtp;
    try {
      rtp = parseRtp(bytes);
    } catch (e) {
      if (!(e instanceof RtpError)) throw e;
      this._warn('malformedRtp', `dropped a malformed RTP packet: ${e.message}`);
      return [];
    }
    if (this.payloadType !== null && rtp.payloadType !== this.payloadType) {
      this._warn('otherPayloadType', `dropped a packet of payload type ${rtp.payloadType}`);
      return [];
    }
    const decoded = decodePayload(rtp.payload);
    ++this.stats.packets;
    if (decoded.ok === false) {
      this._warn(
        'malformedPayload',
        `dropped malformed payload of packet ${rtp.sequenceNumber}: ${decoded.error} at byte ${decoded.offset}`,
      );
      return [];
    }

    // A new SSRC is a new sender, or one restarted: it owes nothing to the last one, and the
    // receiver takes itself for joined mid-stream until a complete state.
    if (rtp.ssrc !== this._ssrc) {
      this._ssrc = rtp.ssrc;
      this.recovery.reset(true);
      this.animator.reset();
      this._pending.length = 0;
      this._lastSequenceNumber = null;
      this._lastTimestamp = rtp.timestamp;
      this._extTimestamp = 0;
    } else if (((rtp.sequenceNumber - this._lastSequenceNumber) & 0xffff) >= 0x8000 || rtp.sequenceNumber === this._lastSequenceNumber) {
      // No jitter buffer in front: a duplicate, or a packet overtaken by a later one, is past.
      this._warn('late', `dropped late or duplicate packet ${rtp.sequenceNumber}`);
      return [];
    }
    this._lastSequenceNumber = rtp.sequenceNumber;
    this._extTimestamp += (rtp.timestamp - this._lastTimestamp) | 0; // signed 32-bit step
    this._lastTimestamp = rtp.timestamp;
    const timeNs = ticksToNs(this._extTimestamp, this.clockRate);

    const packet = decoded.packet;
    const r = this.recovery.receive(packet, rtp.sequenceNumber, timeNs);
    const uncertain = !r.stateWhole;
    const events = [];
    // Packets come ahead of their time (the sender's packetizing delay, the page's buffering):
    // the face takes each event when a draw reaches its time, as pfapface takes each buffer
    // when its frame's time comes.
    const emit = (event) => {
      this._pending.push(event);
      events.push(event);
      if (this.onEvent) this.onEvent(event);
    };
    // An unchanged complete state changes nothing: a lossless stream comes out as it was sent.
    if (r.recovery === 'recovered' || (r.recovery === 'complete' && r.changed)) {
      emit({ kind: r.recovery, timeNs, sentenceStart: false, uncertain, faps: packet.recovery });
    }
    let startNs = timeNs;
    packet.phonemes.forEach((p, i) => {
      const info = this.alphabet !== null ? findPhoneme(this.alphabet, p.symbol) : null;
      emit({
        kind: 'phoneme',
        timeNs: startNs,
        sentenceStart: i === 0 && rtp.marker,
        uncertain,
        faps: p.faps,
        phoneme: {
          symbol: p.symbol, duration: p.duration, f0: p.f0, stress: p.stress, wordBegin: p.wordBegin,
          endOfText: p.endOfText, name: info?.name ?? null, viseme: info?.viseme ?? null,
        },
      });
      startNs += p.duration * NS_PER_MS;
    });

    const s = this.stats;
    s.phonemes += packet.phonemes.length;
    for (const p of packet.phonemes) s.faps += p.faps.length;
    s.lost += r.lost;
    s.gaps += r.lost > 0 ? 1 : 0;
    s.recovered += r.recovery === 'recovered' ? 1 : 0;
    s.completeStates += r.recovery === 'complete' ? 1 : 0;
    const excess = this._pending.length - MAX_PENDING_EVENTS;
    if (excess > 0) {
      for (const e of this._pending.splice(0, excess)) this.animator.apply(e, e.timeNs);
    }
    if (r.requestComplete) {
      ++s.requests;
      if (this.onRequestComplete) this.onRequestComplete({ sequenceNumber: rtp.sequenceNumber, ssrc: rtp.ssrc });
    }
    return events;
  }

  /** A loss whose size is unknown: the state is uncertain until a complete state. */
  lostUnknown() {
    this.recovery.lostUnknown();
  }

  /**
   * Brings the face to `timeNs` (stream time): applies, in order, every event received whose
   * time has come. faps(), pose() and draw() do it first.
   * @param {number} timeNs
   */
  advance(timeNs) {
    let n = 0;
    while (n < this._pending.length && this._pending[n].timeNs <= timeNs) {
      this.animator.apply(this._pending[n], this._pending[n].timeNs);
      ++n;
    }
    if (n > 0) this._pending.splice(0, n);
  }

  /**
   * Every FAP's amplitude at `timeNs` (stream time), mouth and expressions included.
   * @param {number} timeNs
   */
  faps(timeNs) {
    this.advance(timeNs);
    return this.animator.faps(timeNs);
  }

  /**
   * The face's shapes at `timeNs`.
   * @param {number} timeNs
   */
  pose(timeNs) {
    this.advance(timeNs);
    return this.animator.pose(timeNs);
  }

  /**
   * Draws the face at `timeNs` on a canvas 2D context, in `style` ('cartoon' or 'line'), with
   * pfapface's debug overlay (the phoneme sounding and the FAPs not at 0) when `overlay`.
   * Returns whether it drew: the face is drawn again only where it would differ from the one
   * the last draw left on this context (other FAPs, style or overlay text, another context, or
   * the canvas resized, which clears it), so that a page drawing at every animation frame
   * leaves the canvas alone in the pauses and Chromium composites nothing new. `force` draws
   * anyway, for a page that draws on the canvas itself between calls.
   * @param {CanvasRenderingContext2D} ctx
   * @param {number} timeNs
   * @param {{style?: 'cartoon'|'line', overlay?: boolean, force?: boolean}} [options]
   * @returns {boolean}
   */
  draw(ctx, timeNs, options = {}) {
    const faps = this.faps(timeNs);
    const overlay = options.overlay ? this.animator.describe(timeNs) : '';
    const { width, height } = ctx.canvas;
    const last = this._drawn;
    if (!options.force && last !== null && last.ctx === ctx && last.width === width && last.height === height
        && last.style === options.style && last.overlay === overlay && faps.every((v, i) => v === last.faps[i])) {
      return false;
    }
    renderFace(ctx, poseFromFaps(faps), { style: options.style, overlay });
    this._drawn = { ctx, width, height, style: options.style, overlay, faps };
    return true;
  }

  /** Back to no packet seen. */
  reset() {
    this.recovery.reset(true);
    this.animator.reset();
    this._pending.length = 0;
    this._ssrc = null;
    this._lastSequenceNumber = null;
  }
}
