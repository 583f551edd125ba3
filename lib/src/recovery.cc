// SPDX-License-Identifier: LGPL-2.1-or-later
#include "pfap/recovery.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <cassert>

namespace pfap {
namespace {

// Entries for the FAPs the packets bookmarked whose effect is not over at `time_ns`, one
// per FAP index in index order, written from the sender's state.
void entries_for(std::span<const std::vector<RecoverySender::SentFap>> packets,
                 const FapState& state, int64_t time_ns, std::vector<Fap>& out) {
  // A triangle that is over changed nothing a FAP holds (FapState): the draft leaves it out.
  std::bitset<kFapCount> in_effect;
  // The indexes in effect, as found: a few per packet, so sorting them costs less than
  // walking every FAP index.
  std::array<uint8_t, kFapCount> indexes;
  size_t count = 0;
  for (const auto& packet : packets) {
    for (const RecoverySender::SentFap& b : packet) {
      const bool over = time_ns - b.start_ns >= int64_t{b.fap.transition_ms} * kNsPerMs;
      if ((b.fap.curve == Curve::kTriangle && over) || in_effect[b.fap.index]) continue;
      in_effect[b.fap.index] = true;
      indexes[count++] = b.fap.index;
    }
  }
  std::sort(indexes.begin(), indexes.begin() + count);
  out.clear();
  out.reserve(count);  // one allocation per packet at most, not one per doubling
  for (size_t i = 0; i < count; ++i) out.push_back(state.recovery_entry(indexes[i], time_ns));
}

}  // namespace

RecoverySender::RecoverySender(unsigned depth) : depth_(depth) {
  assert(depth == 0 || is_valid_coverage(depth));
}

void RecoverySender::add_dynamic(Packet& packet, int64_t time_ns, size_t room) const {
  if (depth_ == 0) return;
  // The deepest coverage whose entries fit; a shallower one covers a subset of the packets,
  // so its entries are never more.
  for (int step = static_cast<int>(std::size(kCoverageSteps)) - 1; step >= 0; --step) {
    const unsigned coverage = kCoverageSteps[step];
    if (coverage > depth_ || (!whole_history_ && coverage > window_.size())) continue;
    const size_t covered = std::min<size_t>(coverage, window_.size());
    entries_for(std::span(window_).last(covered), state_, time_ns, packet.recovery);
    if (packet.recovery.size() * kFapDescriptorBytes <= room) {
      packet.recovery_kind = RecoveryKind::kDynamic;
      packet.covered_packets = static_cast<uint8_t>(coverage);
      return;
    }
  }
  packet.recovery.clear();
}

bool RecoverySender::make_complete(Packet& out, int64_t time_ns, size_t room) const {
  out.clear();
  out.recovery_kind = RecoveryKind::kComplete;
  for (int index = kMinFapIndex; index <= kMaxFapIndex; ++index) {
    const Fap entry = state_.recovery_entry(index, time_ns);
    if (entry.amplitude != 0) out.recovery.push_back(entry);
  }
  return encoded_size(out) <= room;
}

void RecoverySender::sent(const Packet& packet, int64_t time_ns) {
  std::vector<SentFap>* bookmarks = nullptr;  // this packet's place in the window
  if (window_.size() < depth_) {
    bookmarks = &window_.emplace_back();
  } else {
    whole_history_ = false;
    if (depth_ > 0) {
      // The oldest packet's place becomes the newest: its capacity is reused, so a stream
      // stops allocating here once every place has held its largest packet.
      std::rotate(window_.begin(), window_.begin() + 1, window_.end());
      bookmarks = &window_.back();
      bookmarks->clear();
    }
  }
  packet.for_each_phoneme(time_ns, [&](size_t i, int64_t start_ns) {
    for (const Fap& fap : packet.faps_of(i)) {
      if (bookmarks != nullptr) bookmarks->push_back({fap, start_ns});
      state_.apply(fap, start_ns);
    }
  });
}

void RecoverySender::set_depth(unsigned depth) {
  assert(depth == 0 || is_valid_coverage(depth));
  depth_ = depth;
  if (window_.size() > depth_) {
    window_.erase(window_.begin(), window_.end() - depth_);
    whole_history_ = false;
  }
}

void RecoverySender::reset() {
  window_.clear();
  whole_history_ = true;
  state_.reset();
}

ReceiveResult RecoveryReceiver::receive(const Packet& packet, uint16_t seqnum, int64_t time_ns) {
  ReceiveResult result;
  if (last_seqnum_) {
    const auto gap = static_cast<uint16_t>(seqnum - *last_seqnum_ - 1);
    result.lost = gap < 0x8000 ? gap : 0;
  }
  last_seqnum_ = seqnum;

  if (packet.recovery_kind == RecoveryKind::kComplete) {
    result.changed = state_.apply_complete(packet.recovery, time_ns);
    whole_ = true;
    result.recovery = ReceiveResult::Recovery::kComplete;
  } else if (result.lost > 0) {
    // Recovery information is applied only after a loss, so nothing is applied twice.
    if (packet.recovery_kind == RecoveryKind::kDynamic && packet.covered_packets >= result.lost) {
      for (const Fap& entry : packet.recovery) state_.apply(entry, time_ns);
      result.recovery = ReceiveResult::Recovery::kRecovered;
    } else if (whole_) {
      whole_ = false;
      last_request_ns_.reset();
    }
  }
  if (whole_) {
    last_request_ns_.reset();
  } else if (!last_request_ns_ || time_ns - *last_request_ns_ >= retry_ns_) {
    result.request_complete = true;
    last_request_ns_ = time_ns;
  }

  packet.for_each_phoneme(time_ns, [&](size_t i, int64_t start_ns) {
    for (const Fap& fap : packet.faps_of(i)) state_.apply(fap, start_ns);
  });
  result.state_whole = whole_;
  return result;
}

void RecoveryReceiver::lost_unknown() {
  if (!whole_) return;
  whole_ = false;
  last_request_ns_.reset();
}

void RecoveryReceiver::reset(bool joined_mid_stream) {
  state_.reset();
  last_seqnum_.reset();
  whole_ = !joined_mid_stream;
  last_request_ns_.reset();
}

}  // namespace pfap
