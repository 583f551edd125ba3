// SPDX-License-Identifier: LGPL-2.1-or-later
// The one RTP packet builder of the tests, benchmarks and fuzz harnesses: a payload and the
// header fields in, an RTP GstBuffer out.
#pragma once

#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>

#include <algorithm>
#include <cstdint>
#include <span>

namespace pfap::testing {

struct RtpHeader {
  guint16 seqnum = 0;
  guint32 timestamp = 0;  // on the stream's RTP clock
  guint32 ssrc = 0x5eed;
  bool marker = false;
  guint8 payload_type = 96;
};

// An RTP packet of `payload` with `header`, and `pts` as its buffer PTS.
inline GstBuffer* rtp_packet(std::span<const uint8_t> payload, const RtpHeader& header,
                             GstClockTime pts) {
  GstBuffer* buffer = gst_rtp_buffer_new_allocate(static_cast<guint>(payload.size()), 0, 0);
  GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
  if (!gst_rtp_buffer_map(buffer, GST_MAP_WRITE, &rtp)) g_error("cannot map a new RTP buffer");
  gst_rtp_buffer_set_payload_type(&rtp, header.payload_type);
  gst_rtp_buffer_set_ssrc(&rtp, header.ssrc);
  gst_rtp_buffer_set_seq(&rtp, header.seqnum);
  gst_rtp_buffer_set_timestamp(&rtp, header.timestamp);
  gst_rtp_buffer_set_marker(&rtp, header.marker);
  std::copy(payload.begin(), payload.end(),
            static_cast<uint8_t*>(gst_rtp_buffer_get_payload(&rtp)));
  gst_rtp_buffer_unmap(&rtp);
  GST_BUFFER_PTS(buffer) = pts;
  return buffer;
}

}  // namespace pfap::testing
