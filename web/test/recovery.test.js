// SPDX-License-Identifier: LGPL-2.1-or-later
// RecoveryReceiver against pfap::RecoveryReceiver on the seeded speech sessions of
// tests/common/speech_session.h, packetized, sent with dynamic recovery of depths 0..40 and
// complete states, lost at seeded places (runs longer than the coverage among them, and
// losses of unknown size): the same results, the same settled state after every received
// packet, the same amplitudes at every received phoneme's start and middle.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { RecoveryReceiver, decodePayload } from '../src/index.js';
import { exportVectors, fromHex } from './libpfap.js';

test('seeded sessions with seeded loss leave the same FAP state as in libpfap', () => {
  const setups = exportVectors(['recovery']);
  assert.equal(setups.length, 8);
  const seen = { none: 0, recovered: 0, complete: 0, notWhole: 0, requests: 0 };
  let compared = 0;
  for (const setup of setups) {
    const receiver = new RecoveryReceiver();
    for (const p of setup.packets) {
      const where = `seed ${setup.seed} depth ${setup.depth} packet ${p.sequenceNumber}`;
      const decoded = decodePayload(fromHex(p.payload));
      assert.ok(decoded.ok, where);
      if (p.lostUnknownBefore) receiver.lostUnknown();
      const result = receiver.receive(decoded.packet, p.sequenceNumber, p.timeNs);
      assert.deepStrictEqual(result, p.result, where);
      const settled = [];
      for (let f = 3; f <= 74; ++f) settled.push(receiver.state.settled(f));
      assert.deepStrictEqual(settled, p.settled, where);
      for (const [index, timeNs, amplitude] of p.amplitudes) {
        const a = receiver.state.amplitude(index, timeNs);
        assert.ok(a === amplitude, `${where}: FAP ${index} at ${timeNs}: ${a}, libpfap ${amplitude}`);
      }
      ++seen[result.recovery];
      seen.notWhole += result.stateWhole ? 0 : 1;
      seen.requests += result.requestComplete ? 1 : 0;
      ++compared;
    }
  }
  // Every branch of the receiver was taken.
  assert.ok(compared > 1000, `${compared} packets`);
  for (const [what, count] of Object.entries(seen)) assert.ok(count > 0, `no packet with ${what}`);
});
