// SPDX-License-Identifier: LGPL-2.1-or-later
// parseRtp against gst_rtp_buffer_map on 20000 seeded packets, well formed and not: the same
// packets refused, the same fields and payload read from the rest.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { RtpError, makeRtp, parseRtp } from '../src/index.js';
import { exportVectors, fromHex, toHex } from './libpfap.js';

test('parseRtp accepts and reads what gst_rtp_buffer_map does', () => {
  const vectors = exportVectors(['rtp']);
  assert.equal(vectors.length, 20000);
  let refused = 0;
  for (const { bytes, rtp } of vectors) {
    if (rtp === null) {
      ++refused;
      assert.throws(() => parseRtp(fromHex(bytes)), RtpError, bytes);
      continue;
    }
    const parsed = parseRtp(fromHex(bytes));
    assert.deepStrictEqual({ ...parsed, payload: toHex(parsed.payload) }, rtp, bytes);
  }
  // Both kinds are there in numbers.
  assert.ok(refused > 2000 && refused < 18000, `${refused} refused`);
});

test('makeRtp writes what parseRtp reads', () => {
  const fields = { marker: true, payloadType: 96, sequenceNumber: 65535, timestamp: 0xfffffffe, ssrc: 0x89abcdef, payload: new Uint8Array([1, 2, 3]) };
  assert.deepStrictEqual(parseRtp(makeRtp(fields)), fields);
});
