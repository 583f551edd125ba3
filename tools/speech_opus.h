// SPDX-License-Identifier: LGPL-2.1-or-later
// The Opus encoder of the speech that pfap-web sends to each page and pfap-broadcast to Janus:
// 20 ms frames at complexity 5. The encoder's instructions are 0.59× those of 10 ms frames at
// complexity 10, with half the packets to protect and send, for the same lip sync
// (docs/performance.md, "pfap-web: sessions per server"); 5 is what libwebrtc gives Opus on
// phones, and below 5 Opus drops its pitch pre-filter.
#pragma once

#include <gst/gst.h>

#include <string>

constexpr GstClockTime kOpusFrame = 20 * GST_MSECOND;

// The launch description of the encoder, for 48 kHz S16 mono in.
inline std::string opus_encoder_description() {
  return "opusenc frame-size=" + std::to_string(kOpusFrame / GST_MSECOND) + " complexity=5";
}
