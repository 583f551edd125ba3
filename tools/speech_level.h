// SPDX-License-Identifier: LGPL-2.1-or-later
// The speech's level that a page finds in the audio it plays to know which time it hears
// (docs/web.md, Timing): the RMS of each millisecond of 48 kHz S16 mono, in S16 units. Sent by
// pfap-web (on its WebSocket) and pfap-broadcast (on Janus's data stream), each in its own
// message; add_speech_level_probe() takes it from a pad for both.
#pragma once

#include <gst/gst.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pad_time.h"

class SpeechLevel {
 public:
  static constexpr int kSamplesPerLevel = 48;  // 1 ms at 48 kHz
  static constexpr size_t kLevelsPerMessage = 50;

  // Adds `samples`; calls `full()` each time kLevelsPerMessage levels are waiting (it takes
  // them with take()).
  template <typename Full>
  void add(std::span<const int16_t> samples, Full&& full) {
    for (int16_t sample : samples) {
      sum_ += static_cast<double>(sample) * sample;
      if (++count_ == kSamplesPerLevel) {
        levels_.push_back(std::lround(std::sqrt(sum_ / kSamplesPerLevel)));
        sum_ = 0.0;
        count_ = 0;
        if (levels_.size() == kLevelsPerMessage) full();
      }
    }
  }

  // The levels waiting, which go: each is the RMS of the millisecond after the one before.
  std::vector<int64_t> take() { return std::exchange(levels_, {}); }
  bool empty() const { return levels_.empty(); }

 private:
  std::vector<int64_t> levels_;
  double sum_ = 0.0;
  int count_ = 0;
};

// The levels as the pages read them (web/live/clock.js): one byte a level, the code
// round(kLevelCodesPerOctave × log2(1 + rms)) (at most 240 for S16's 32767; a step is 4.4 % of
// the level, well within what the page's correlation tells apart).
constexpr double kLevelCodesPerOctave = 16.0;

inline std::vector<uint8_t> level_codes(std::span<const int64_t> levels) {
  std::vector<uint8_t> codes;
  codes.reserve(levels.size());
  for (int64_t rms : levels) {
    const double code =
        std::round(kLevelCodesPerOctave * std::log2(1.0 + std::max<int64_t>(rms, 0)));
    codes.push_back(static_cast<uint8_t>(std::min(code, 255.0)));
  }
  return codes;
}

// The codes in base64, for pfap-web's "envelope" on its WebSocket, a JSON text channel
// (decodeLevels). Half the bytes of the levels as a JSON array of integers.
inline std::string encode_levels(std::span<const int64_t> levels) {
  const std::vector<uint8_t> codes = level_codes(levels);
  gchar* base64 = g_base64_encode(codes.data(), codes.size());
  std::string out = base64;
  g_free(base64);
  return out;
}

// A level message on pfap-broadcast's data stream (docs/web.md, "The level message"; read by
// decodeLevelMessage in web/live/clock.js): a 12-byte header, big-endian, then the codes.
//   byte 0      kLevelMessageType, whose top two bits (RTP's version, 0) and value ('{' is
//               0x7b) tell it from the stream's RTP packets and JSON messages
//   byte 1      0
//   bytes 2-3   the number of levels, 1 to 65535
//   bytes 4-7   the SSRC of the PFAP stream
//   bytes 8-11  the PFAP timestamp of the first level's millisecond
//   bytes 12-   one code a millisecond
constexpr uint8_t kLevelMessageType = 0x01;
constexpr size_t kLevelHeaderSize = 12;
static_assert(SpeechLevel::kLevelsPerMessage <= 0xffff, "a level message's count has 16 bits");

// `levels` holds at most kLevelsPerMessage levels, as the probe below gives them.
inline std::vector<uint8_t> level_message(uint32_t ssrc, uint32_t timestamp,
                                          std::span<const int64_t> levels) {
  std::vector<uint8_t> message = {kLevelMessageType, 0};
  message.reserve(kLevelHeaderSize + levels.size());
  auto put = [&](uint32_t value, int bytes) {
    for (int shift = 8 * (bytes - 1); shift >= 0; shift -= 8) {
      message.push_back(static_cast<uint8_t>(value >> shift));
    }
  };
  put(static_cast<uint32_t>(levels.size()), 2);
  put(ssrc, 4);
  put(timestamp, 4);
  const std::vector<uint8_t> codes = level_codes(levels);
  message.insert(message.end(), codes.begin(), codes.end());
  return message;
}

// What the probe gives on: `levels[i]` is the RMS of the ms from running time start + i ms.
using SpeechLevelSend = std::function<void(GstClockTime start, std::vector<int64_t> levels)>;

// Takes the level of the S16 mono 48 kHz audio passing `pad` and calls `send` on its streaming
// thread with each kLevelsPerMessage ms of it, and the rest at EOS; silent batches are not
// sent. The running times are the pad's.
inline void add_speech_level_probe(GstPad* pad, SpeechLevelSend send) {
  struct Probe {
    SpeechLevelSend send;
    GstClockTime start = GST_CLOCK_TIME_NONE;  // running time of the first level waiting
    SpeechLevel level;

    void send_waiting() {
      if (level.empty()) return;
      std::vector<int64_t> levels = level.take();
      const GstClockTime batch_start = start;
      start += levels.size() * GST_MSECOND;
      if (std::any_of(levels.begin(), levels.end(), [](int64_t v) { return v != 0; })) {
        send(batch_start, std::move(levels));
      }
    }
  };
  auto on_buffer_or_eos = [](GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    auto& p = *static_cast<Probe*>(data);
    if ((info->type & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) != 0) {
      if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) == GST_EVENT_EOS) p.send_waiting();
      return GST_PAD_PROBE_OK;
    }
    GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
    if (p.start == GST_CLOCK_TIME_NONE) {
      const GstClockTime running = running_time_of(pad, buffer);
      if (running == GST_CLOCK_TIME_NONE) return GST_PAD_PROBE_OK;
      p.start = running;
    }
    GstMapInfo map;
    if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return GST_PAD_PROBE_OK;
    p.level.add({reinterpret_cast<const int16_t*>(map.data), map.size / 2},
                [&] { p.send_waiting(); });
    gst_buffer_unmap(buffer, &map);
    return GST_PAD_PROBE_OK;
  };
  auto* probe = new Probe;
  probe->send = std::move(send);
  gst_pad_add_probe(
      pad, GstPadProbeType(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM),
      on_buffer_or_eos, probe, [](gpointer data) { delete static_cast<Probe*>(data); });
}
