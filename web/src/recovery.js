// SPDX-License-Identifier: LGPL-2.1-or-later
// The receiver's side of FAP loss recovery (draft sections 6.1, 6.4 and 8), as
// pfap::RecoveryReceiver (lib/src/recovery.cc): loss from sequence numbers, dynamic recovery
// applied only after a gap its coverage spans, complete states, and whether the FAP state is
// whole. docs/format.md ("Recovery") gives the reasons.

import { FapState } from './fap_state.js';
import { MAX_FAP_INDEX, MIN_FAP_INDEX, NS_PER_MS } from './model.js';

/**
 * The receiver's side of FAP loss recovery, as pfap::RecoveryReceiver: loss from sequence
 * numbers, recovery applied when its coverage spans the gap, complete states.
 */
export class RecoveryReceiver {
  /**
   * @param {{retryNs?: number}} [options] retryNs: how long after a request for a complete
   *   state, in packet time, the receiver asks again while still not whole (default 1 s)
   */
  constructor(options = {}) {
    this.retryNs = options.retryNs ?? 1_000_000_000;
    /** The FAP state all packets received so far built. */
    this.state = new FapState();
    this._lastSequenceNumber = null;
    this._whole = true;
    this._lastRequestNs = null; // since the state broke
  }

  /** False while the FAP state may be wrong (a loss no recovery spanned, or a mid-stream join). */
  get stateWhole() {
    return this._whole;
  }

  /**
   * Applies complete or dynamic recovery when it is due, then the packet's own bookmarks at
   * their phonemes' starts (the packet's time plus the durations before them). Packets in
   * order (after a jitter buffer); a sequence number that goes back counts no loss.
   * @param {import('./index.js').Packet} packet a decoded packet
   * @param {number} sequenceNumber its RTP sequence number
   * @param {number} timeNs its time (the first phoneme's start), ns
   * @returns {import('./index.js').ReceiveResult}
   */
  receive(packet, sequenceNumber, timeNs) {
    /** @type {import('./index.js').ReceiveResult} */
    const result = { recovery: 'none', changed: false, stateWhole: true, requestComplete: false, lost: 0 };
    if (this._lastSequenceNumber !== null) {
      const gap = (sequenceNumber - this._lastSequenceNumber - 1) & 0xffff;
      result.lost = gap < 0x8000 ? gap : 0;
    }
    this._lastSequenceNumber = sequenceNumber & 0xffff;

    const state = this.state;
    if (packet.complete) {
      const before = new Int32Array(MAX_FAP_INDEX + 1);
      for (let f = MIN_FAP_INDEX; f <= MAX_FAP_INDEX; ++f) before[f] = state.settled(f);
      state.reset();
      for (const entry of packet.recovery) state.apply(entry, timeNs);
      for (let f = MIN_FAP_INDEX; f <= MAX_FAP_INDEX && !result.changed; ++f) {
        result.changed = state.settled(f) !== before[f];
      }
      this._whole = true;
      result.recovery = 'complete';
    } else if (result.lost > 0) {
      // Recovery information is applied only after a loss, so nothing is applied twice.
      if (packet.coverage > 0 && packet.coverage >= result.lost) {
        for (const entry of packet.recovery) state.apply(entry, timeNs);
        result.recovery = 'recovered';
      } else if (this._whole) {
        this._whole = false;
        this._lastRequestNs = null;
      }
    }
    if (this._whole) {
      this._lastRequestNs = null;
    } else if (this._lastRequestNs === null || timeNs - this._lastRequestNs >= this.retryNs) {
      result.requestComplete = true;
      this._lastRequestNs = timeNs;
    }

    let startNs = timeNs;
    for (const phoneme of packet.phonemes) {
      for (const fap of phoneme.faps) state.apply(fap, startNs);
      startNs += phoneme.duration * NS_PER_MS;
    }
    result.stateWhole = this._whole;
    return result;
  }

  /**
   * A loss whose size is unknown: the state is not whole until a complete state, and the
   * next packet asks for one.
   */
  lostUnknown() {
    if (!this._whole) return;
    this._whole = false;
    this._lastRequestNs = null;
  }

  /**
   * Back to no packet seen. A receiver that may have joined mid-stream is not whole until
   * its first complete state, and asks for one with its first packet.
   * @param {boolean} joinedMidStream
   */
  reset(joinedMidStream) {
    this.state.reset();
    this._lastSequenceNumber = null;
    this._whole = !joinedMidStream;
    this._lastRequestNs = null;
  }
}
