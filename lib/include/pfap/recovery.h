// SPDX-License-Identifier: LGPL-2.1-or-later
// FAP loss recovery (draft sections 6.1, 6.4 and 8): what a sender puts in each packet so that
// a receiver that lost packets ends up with the same FAP state, and how a receiver uses it.
//
// Both sides judge by settled values (what each FAP holds once its transition is over,
// FapState::settled): after a gap that a packet's coverage spans, the receiver's settled
// values equal a lossless receiver's. docs/format.md ("Recovery") gives the reasons.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pfap/fap_state.h"
#include "pfap/model.h"
#include "pfap/payload.h"

namespace pfap {

// The sender's side: remembers which FAPs the last `depth` packets bookmarked and the FAP
// state all packets built, and writes recovery entries from them.
class RecoverySender {
 public:
  // depth: 0 (no dynamic recovery) or one of kCoverageSteps.
  explicit RecoverySender(unsigned depth);

  // Adds dynamic recovery to a data packet about to be sent with timestamp `time_ns`
  // (nothing when depth is 0): C=0, PP = depth, one entry per FAP bookmarked in the covered
  // packets whose effect is not over. If the entries do not fit in `room` bytes, the
  // coverage shrinks to the largest step whose entries fit (PP says so); if none fits, the
  // packet goes without recovery.
  void add_dynamic(Packet& packet, int64_t time_ns, size_t room) const;

  // A complete-recovery packet of the state at `time_ns`: every FAP whose settled value is
  // not 0. False, with `out` unusable, when it needs more than `room` bytes: a receiver
  // takes every FAP left out for 0, so a complete state is never cut (72 FAPs take 433).
  bool make_complete(Packet& out, int64_t time_ns, size_t room) const;

  // Changes the depth mid-stream, keeping the FAP state. The coverage a packet claims never
  // reaches further back than the packets the sender still holds since the stream began,
  // so after a deeper depth it grows one packet at a time.
  void set_depth(unsigned depth);

  // Records a packet as sent: data (its phonemes' FAPs, the first phoneme starting at
  // `time_ns`) or recovery only. Every packet counts towards the coverage.
  void sent(const Packet& packet, int64_t time_ns);

  void reset();

  // A FAP a sent packet bookmarked, with its start, kept while the packet is within the
  // depth.
  struct SentFap {
    Fap fap;
    int64_t start_ns;
  };

 private:
  unsigned depth_;
  std::vector<std::vector<SentFap>> window_;  // the last `depth` packets, oldest first
  // The window holds every packet since the stream began: there is nothing older to cover.
  bool whole_history_ = true;
  FapState state_;
};

// What a receiver did with one packet (RecoveryReceiver::receive).
struct ReceiveResult {
  enum class Recovery : uint8_t {
    kNone,       // nothing to apply: no loss, or loss without recovery information
    kRecovered,  // dynamic entries applied after a covered gap
    kComplete,   // a complete state replaced everything
  } recovery = Recovery::kNone;
  bool changed = false;           // kComplete: some settled value differs from before
  bool state_whole = true;        // false while the FAP state may be wrong
  bool request_complete = false;  // ask the sender for a complete state: after a loss the
                                  // coverage did not span, on joining mid-stream, and
                                  // again each retry interval while not whole
  uint32_t lost = 0;              // packets missing before this one
};

// The receiver's side: sequence numbers, recovery and the FAP state.
class RecoveryReceiver {
 public:
  // retry_ns: how long after a request for a complete state, in packet time, the receiver
  // asks again if it is still not whole (the request or the answer may be lost).
  explicit RecoveryReceiver(int64_t retry_ns = 1'000'000'000) : retry_ns_(retry_ns) {}

  // `seqnum` is the RTP sequence number, `time_ns` the packet's time. Applies complete or
  // dynamic recovery when it is due, then the packet's own bookmarks at their phonemes'
  // starts. Loss is counted from sequence numbers, packets in order (after a jitterbuffer);
  // a sequence number that goes back (duplicate, late or restarted) counts no loss.
  ReceiveResult receive(const Packet& packet, uint16_t seqnum, int64_t time_ns);
  // A loss whose size is unknown (a packet-lost event without a sequence number, as
  // rtpulpfecdec sends for what it could not rebuild after renumbering): no coverage can be
  // known to span it, so the state is not whole until a complete state, and the next packet
  // asks for one.
  void lost_unknown();
  const FapState& state() const { return state_; }
  bool state_whole() const { return whole_; }
  // Back to no packet seen. A receiver that may have joined mid-stream is not whole until
  // its first complete state, and asks for one with its first packet.
  void reset(bool joined_mid_stream);

 private:
  int64_t retry_ns_;
  FapState state_;
  std::optional<uint16_t> last_seqnum_;
  bool whole_ = true;
  std::optional<int64_t> last_request_ns_;  // since the state broke
};

}  // namespace pfap
