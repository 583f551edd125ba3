// SPDX-License-Identifier: LGPL-2.1-or-later
// Plans PFAP packets from a stream of phonemes and the FAPs that start with them.
//
// Rules (draft sections 6 and 7):
//  - a phoneme is never separated from the FAPs before it;
//  - every packet ends with a phoneme;
//  - a packet starts at each sentence start (so the RTP M bit can be set) and ends at end
//    of text;
//  - the phonemes in one packet are contiguous in time: a gap starts a new packet;
//  - a packet's payload stays within max_payload_size, except a single phoneme whose FAPs
//    alone do not fit, which goes alone and is flagged `oversized`;
//  - no phoneme waits longer than max_delay_ns of stream time for its packet: a phoneme
//    joins a packet only if it starts less than max_delay_ns after the packet's first one,
//    and a packet whose phonemes reach max_delay_ns is finished at once. After a gap the
//    pending packet waits for the next push or a drain(), so a live caller drains on a
//    timer.
//
// Words: a packet is "finished" when no phoneme may join it and it moves to the output;
// drain() finishes the pending packet, drop() forgets it. "Complete" means only complete
// recovery (C=1), which pfap::Sender adds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pfap/model.h"
#include "pfap/payload.h"

namespace pfap {

inline constexpr uint32_t kDefaultClockRate = 44100;

// A stream time in nanoseconds as an RTP timestamp on a `clock_rate` clock, rounded to the
// nearest tick and wrapped to 32 bits; time 0 is timestamp 0.
uint32_t rtp_ticks(int64_t time_ns, uint32_t clock_rate);

struct PacketizerConfig {
  size_t max_payload_size = 1400 - 12;  // GStreamer's default MTU less the RTP header
  int64_t max_delay_ns = 100'000'000;
};

struct TimedPhoneme {
  int64_t start_ns = 0;  // start in stream time
  Phoneme phoneme;
  bool sentence_start = false;  // first phoneme of a sentence: starts a packet, sets M
};

struct PlannedPacket {
  int64_t start_ns = 0;        // the first phoneme's start
  bool marker = false;         // the first phoneme starts a sentence
  bool oversized = false;      // one phoneme with more FAPs than max_payload_size holds
  Packet packet;
};

class Packetizer {
 public:
  explicit Packetizer(const PacketizerConfig& config);

  // Adds a phoneme and the FAPs that start with it; appends any packets it finishes.
  void push(const TimedPhoneme& phoneme, std::span<const Fap> faps,
            std::vector<PlannedPacket>& out);
  // Finishes the pending packet, if any, and appends it: no later phoneme may join it (EOS,
  // GAP, or a caller-side timeout).
  void drain(std::vector<PlannedPacket>& out);
  // Forgets the pending packet (GStreamer's FLUSH).
  void drop();
  // Takes back the packets in `sent` (and clears it) once the caller is done with them: their
  // vectors hold the next packets, so that a steady stream stops allocating.
  void recycle(std::vector<PlannedPacket>& sent);

  bool has_pending() const { return !pending_.packet.phonemes.empty(); }
  const PacketizerConfig& config() const { return config_; }

 private:
  // Moves the pending packet to `out` and starts an empty one, in recycled storage if any.
  void finish(std::vector<PlannedPacket>& out);

  PacketizerConfig config_;
  PlannedPacket pending_;
  std::vector<Packet> spare_;  // recycled, cleared
  size_t pending_size_ = 0;
  int64_t pending_end_ns_ = 0;  // where the next contiguous phoneme starts
};

}  // namespace pfap
