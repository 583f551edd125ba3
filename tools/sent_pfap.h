// SPDX-License-Identifier: LGPL-2.1-or-later
// The PFAP packets a server sends (pfap-web to each page, pfap-broadcast to Janus): each
// rtppfappay packet is recorded as sent, through libpfap's receiver (what a lossless receiver
// holds, which the `done` message carries for the page to compare with), then a share of them
// is dropped on purpose (--drop), to show recovery. Fed from the appsink's thread, read from
// the main loop: every member under one lock.
#pragma once

#include <gst/gst.h>
#include <gst/rtp/gstrtpbuffer.h>

#include <cstdint>
#include <mutex>
#include <random>
#include <span>

#include "pfap/payload.h"
#include "pfap/recovery.h"

class SentPfap {
 public:
  // What was sent and dropped so far.
  struct Counts {
    uint64_t packets = 0;
    uint64_t dropped = 0;
    uint64_t phonemes = 0;
    uint64_t phonemes_dropped = 0;
    int last_seqnum = -1;
  };

  // Drops a share `drop` (0 to 1) of the packets, chosen by a generator seeded with `seed`;
  // `ts_offset` is rtppfappay's timestamp-offset, the RTP time of the stream's time 0.
  void configure(double drop, uint32_t seed, uint32_t ts_offset) {
    std::lock_guard lock(mutex_);
    drop_ = drop;
    rng_.seed(seed);
    ts_offset_ = ts_offset;
  }

  // From now on the complete state is never dropped: the stream is ending, and its closing
  // complete state is the last word on the state for a receiver with no way back.
  void keep_closing_state() {
    std::lock_guard lock(mutex_);
    ending_ = true;
  }

  // One RTP packet from rtppfappay (`clock_rate` its clock rate): recorded as sent; true if it
  // is to be sent, false if it is dropped (or is no RTP packet).
  bool take(GstBuffer* buffer, guint clock_rate) {
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    if (!gst_rtp_buffer_map(buffer, GST_MAP_READ, &rtp)) return false;
    const uint16_t seqnum = gst_rtp_buffer_get_seq(&rtp);
    const uint32_t timestamp = gst_rtp_buffer_get_timestamp(&rtp);
    const std::span<const uint8_t> payload(
        static_cast<const uint8_t*>(gst_rtp_buffer_get_payload(&rtp)),
        gst_rtp_buffer_get_payload_len(&rtp));
    std::lock_guard lock(mutex_);
    size_t phonemes = 0;
    const bool decoded = pfap::decode_payload(payload, packet_).ok();
    gst_rtp_buffer_unmap(&rtp);
    if (decoded) {
      const int64_t time_ns = static_cast<int64_t>(gst_util_uint64_scale_int(
          timestamp - ts_offset_, GST_SECOND, static_cast<gint>(clock_rate)));
      sent_.receive(packet_, seqnum, time_ns);
      phonemes = packet_.phonemes.size();
      counts_.phonemes += phonemes;
    }
    ++counts_.packets;
    counts_.last_seqnum = seqnum;
    const bool closing =
        ending_ && decoded && packet_.recovery_kind == pfap::RecoveryKind::kComplete;
    const bool lose = !closing && std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < drop_;
    if (lose) {
      ++counts_.dropped;
      counts_.phonemes_dropped += phonemes;
    }
    return !lose;
  }

  // The counts and the state as sent, read under the lock: `read(counts, state)`.
  template <typename Read>
  void read(Read&& read) const {
    std::lock_guard lock(mutex_);
    read(counts_, sent_.state());
  }

 private:
  mutable std::mutex mutex_;
  std::mt19937 rng_;
  double drop_ = 0.0;
  uint32_t ts_offset_ = 0;
  bool ending_ = false;
  pfap::RecoveryReceiver sent_;
  pfap::Packet packet_;
  Counts counts_;
};
