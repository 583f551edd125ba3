// SPDX-License-Identifier: LGPL-2.1-or-later
// RTP fixed header (RFC 3550 section 5.1), read as strictly as GStreamer's gst_rtp_buffer_map:
// version 2, not an RTCP packet type, the CSRCs, the extension and the padding all inside the packet.

const HEADER_BYTES = 12;

/**
 * Thrown by parseRtp for a packet that is not RTP.
 */
export class RtpError extends Error {
  constructor(message) {
    super(message);
    this.name = 'RtpError';
  }
}

/**
 * The fields of an RTP packet and its payload (a view into `bytes`, not a copy).
 * @param {Uint8Array} bytes one whole RTP packet
 * @returns {{marker: boolean, payloadType: number, sequenceNumber: number, timestamp: number,
 *            ssrc: number, payload: Uint8Array}}
 * @throws {RtpError} when the header is malformed
 */
export function parseRtp(bytes) {
  const size = bytes.length;
  if (size < HEADER_BYTES) throw new RtpError(`RTP packet of ${size} bytes: shorter than its header`);
  const first = bytes[0];
  if (first >> 6 !== 2) throw new RtpError(`RTP version ${first >> 6}, not 2`);
  // Marker and payload type 72..76 make the second byte 200..204, RTCP's packet types
  // (RFC 5761 section 4): GStreamer refuses such a packet as RTP, and so do we.
  if (bytes[1] >= 200 && bytes[1] <= 204) throw new RtpError(`RTP second byte ${bytes[1]}: an RTCP packet type`);
  const payloadType = bytes[1] & 0x7f;
  let headerBytes = HEADER_BYTES + 4 * (first & 0x0f);
  if (size < headerBytes) throw new RtpError('RTP CSRC list past the end of the packet');
  if (first & 0x10) {
    if (size < headerBytes + 4) throw new RtpError('RTP header extension past the end of the packet');
    headerBytes += 4 + 4 * ((bytes[headerBytes + 2] << 8) | bytes[headerBytes + 3]);
    if (size < headerBytes) throw new RtpError('RTP header extension past the end of the packet');
  }
  // The last byte counts the padding, itself included.
  const padding = first & 0x20 ? bytes[size - 1] : 0;
  if (size < headerBytes + padding) throw new RtpError('RTP padding longer than the payload');
  return {
    marker: (bytes[1] & 0x80) !== 0,
    payloadType,
    sequenceNumber: (bytes[2] << 8) | bytes[3],
    timestamp: ((bytes[4] << 24) | (bytes[5] << 16) | (bytes[6] << 8) | bytes[7]) >>> 0,
    ssrc: ((bytes[8] << 24) | (bytes[9] << 16) | (bytes[10] << 8) | bytes[11]) >>> 0,
    payload: bytes.subarray(headerBytes, size - padding),
  };
}

/**
 * An RTP packet with a fixed header (no CSRC, extension or padding) around `payload`.
 * @param {{marker?: boolean, payloadType: number, sequenceNumber: number, timestamp: number,
 *          ssrc: number, payload: Uint8Array}} fields
 * @returns {Uint8Array}
 */
export function makeRtp(fields) {
  const out = new Uint8Array(HEADER_BYTES + fields.payload.length);
  const view = new DataView(out.buffer);
  out[0] = 0x80;
  out[1] = (fields.marker ? 0x80 : 0) | (fields.payloadType & 0x7f);
  view.setUint16(2, fields.sequenceNumber & 0xffff);
  view.setUint32(4, fields.timestamp >>> 0);
  view.setUint32(8, fields.ssrc >>> 0);
  out.set(fields.payload, HEADER_BYTES);
  return out;
}
