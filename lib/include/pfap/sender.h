// SPDX-License-Identifier: LGPL-2.1-or-later
// The sending side of a PFAP stream: phonemes in, packets out, with loss recovery.
//
// pfap::Sender owns the packetizer (how phonemes are grouped), the recovery sender (the FAP
// state and the dynamic recovery of each data packet) and the complete-state schedule: the
// stream's first data packet is preceded by a complete-recovery packet (C=1), and so is the
// first data packet after each `complete_interval_ns` of stream time and after a request. A
// GStreamer payloader (rtppfappay) is glue around it, as rtppfapdepay is around
// pfap::RecoveryReceiver. docs/recovery.md gives the reasons for the schedule.
//
// The interval is measured in stream time that moves forward: the data packets' durations
// and the gaps between them. Input whose times go back (a new segment, or a source with bad
// timestamps) moves this clock by nothing at the jump, so however the timestamps run there
// is at most one complete packet per interval of sent speech, plus one per request.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pfap/model.h"
#include "pfap/packetizer.h"
#include "pfap/payload.h"
#include "pfap/recovery.h"

namespace pfap {

// The defaults are rtppfappay's.
struct SenderConfig {
  size_t max_payload_size = PacketizerConfig{}.max_payload_size;
  // 100 ms: below rtpbin's default jitterbuffer latency of 200 ms, so a live receiver still
  // gets each phoneme in time to show it in lip sync with the audio.
  int64_t max_delay_ns = PacketizerConfig{}.max_delay_ns;
  // 0 or one of kCoverageSteps. 4: a burst of up to 4 lost packets (400 ms of speech in
  // 100 ms packets) needs no complete state, for 6 bytes per FAP still in effect in the 4
  // packets before.
  unsigned recovery_depth = 4;
  // 0: only at the stream's start and on request. 1 s: late joiners of shared RTSP media on
  // GStreamer 1.22 have no request path (rtsp-server does not necessarily pass on a new
  // joiner's PLI) and wait for the periodic packet.
  int64_t complete_interval_ns = 1'000'000'000;

  bool operator==(const SenderConfig&) const = default;
};

// A packet to send. Valid until the next call to the Sender.
struct OutgoingPacket {
  enum class Kind : uint8_t {
    kData,              // phonemes and their FAPs, with dynamic recovery
    kComplete,          // complete recovery (C=1) of the state at pts_ns
    kCompleteTooLarge,  // a complete state due but larger than max_payload_size: not to be
                        // sent (a receiver would take every FAP left out for 0); it counts
                        // as sent for the schedule, so the fault shows once per interval
  };
  Kind kind = Kind::kData;
  const Packet* packet = nullptr;
  int64_t pts_ns = 0;       // data: the first phoneme's start; complete: the state's time
  int64_t duration_ns = 0;  // data: the phonemes' total duration; complete: 0
  bool marker = false;      // data: the first phoneme starts a sentence (RTP M bit)
  bool oversized = false;   // data: one phoneme whose FAPs alone exceed max_payload_size
  size_t max_payload_size = 0;  // the limit the packet was made for
};

class Sender {
 public:
  explicit Sender(const SenderConfig& config = {});

  // New settings. max_payload_size and max_delay_ns apply from the next packet started (a
  // packet keeps the limits it began with), recovery_depth from the next data packet (a
  // deeper one grows one packet at a time: no packet claims coverage of packets the sender
  // no longer holds), complete_interval_ns at once.
  void configure(const SenderConfig& config);
  const SenderConfig& config() const { return config_; }

  // Adds a phoneme and the FAPs that start with it. The packets it finishes come from next(),
  // which the caller calls until it returns nullptr before the next push or drain.
  void push(const TimedPhoneme& phoneme, std::span<const Fap> faps);
  // Finishes the pending packet: no later phoneme may join it (end of stream, a gap, new caps
  // or segment).
  void drain();

  // The next packet to send, or nullptr when none is ready. Every packet returned counts as
  // sent (it takes a sequence number whatever becomes of it). `requested`: a receiver asked
  // for the complete state, so one goes before the next data packet.
  const OutgoingPacket* next(bool requested);
  // A complete packet of the state where the stream is now (the end of the last data packet),
  // for an idle sender answering a request; nullptr before the stream's first data packet,
  // which a complete packet precedes anyway.
  const OutgoingPacket* complete_now();

  // Whether a data packet was sent since the stream began.
  bool started() const { return position_.has_value(); }
  // Forgets the stream (the pending packet, the FAP state, the schedule): the next data
  // packet starts a new stream, after a complete packet.
  void reset();

 private:
  const OutgoingPacket* complete_at(int64_t time_ns);
  void apply_packetizer_config();

  SenderConfig config_;
  Packetizer packetizer_;
  RecoverySender recovery_;
  unsigned recovery_depth_;
  std::vector<PlannedPacket> planned_;  // finished, not yet returned by next()
  size_t next_planned_ = 0;
  bool complete_checked_ = false;  // whether planned_[next_planned_] had its complete check
  // The end of the last data packet (start + duration): where the stream is now. None until
  // the stream's first data packet.
  std::optional<int64_t> position_;
  // Stream time that moved forward since the stream began, and its value at the last
  // complete packet: the interval's clock.
  int64_t forward_ns_ = 0;
  int64_t last_complete_ns_ = 0;
  Packet complete_;
  OutgoingPacket out_;
};

}  // namespace pfap
